"""The "VG Sides" colour attribute: each measurement's two sides in a palette pair, the rest grey.

Only this one attribute is ever written; the user's own colour attributes are left alone. The
"VG Sides" attribute is made the active one, and solid viewports are switched to attribute
colours, once per object, on its first measurement (:func:`show_sides_once`); a repaint never
changes either, so a user who picks another attribute or shading keeps it.
"""

from __future__ import annotations

import bpy
import numpy as np

from ..vg_addon import palette
from .mesh_data import read_positions

ATTRIBUTE_NAME = "VG Sides"

# Rows of candidate vertices matched against a patch at once (bounds the temporary matrix).
_CHUNK = 1024


def side_colours(n: int, sides) -> np.ndarray:
    """RGBA (scene-linear float32, shape (n, 4)) of ``n`` vertices painted by ``sides``.

    Parameters
    ----------
    n : int
        Number of vertices.
    sides : iterable of (indices, labels, break_number)
        Per measurement, in painting order (later over earlier): the patch vertex indices, their
        side labels (True = "+") and the break number that picks the colour pair.
    """
    colours = np.tile(palette.neutral_linear(), (n, 1))
    for indices, labels, break_number in sides:
        plus, minus = palette.pair_linear(break_number)
        colours[indices[labels]] = plus
        colours[indices[~labels]] = minus
    return colours.astype(np.float32)


def _nearest_labels(candidates: np.ndarray, patch_points: np.ndarray, labels: np.ndarray):
    """Side label of the nearest patch point to each candidate point (brute force, in chunks)."""
    out = np.empty(candidates.shape[0], dtype=bool)
    squared_patch = np.einsum("ij,ij->i", patch_points, patch_points)
    for start in range(0, candidates.shape[0], _CHUNK):
        block = candidates[start : start + _CHUNK]
        squared = squared_patch[None, :] - 2.0 * block @ patch_points.T
        out[start : start + _CHUNK] = labels[np.argmin(squared, axis=1)]
    return out


def original_vertex_colours(obj, geometry, measured) -> np.ndarray:
    """RGBA for the vertices of ``obj.data`` (the original mesh) from measurements on the
    evaluated mesh.

    Parameters
    ----------
    obj : bpy.types.Object
    geometry : mesh_data.Geometry
        The evaluated geometry the measurements were taken on.
    measured : list of (Measurement, break_number)
        In painting order.

    Notes
    -----
    When the modifiers keep the vertex count (no modifier, or deforming ones), evaluated vertex
    ``i`` is original vertex ``i``. When they change it (e.g. Subdivision Surface), each original
    vertex within a patch's radius takes the side of the nearest evaluated patch vertex: the
    colours then approximate the measured sides, the numbers are unaffected.
    """
    mesh = obj.data
    n_original = len(mesh.vertices)
    n_evaluated = geometry.points.shape[0]
    if n_original == n_evaluated:
        return side_colours(n_original, [(m.indices, m.labels, b) for m, b in measured])
    original = read_positions(mesh).astype(np.float64)
    sides = []
    for m, break_number in measured:
        offsets = original - m.center
        inside = np.flatnonzero(np.einsum("ij,ij->i", offsets, offsets) <= m.radius * m.radius)
        labels = _nearest_labels(original[inside], geometry.points[m.indices], m.labels)
        sides.append((inside, labels, break_number))
    return side_colours(n_original, sides)


def write_attribute(mesh, rgba: np.ndarray) -> None:
    """Write ``rgba`` into the mesh's "VG Sides" point colour attribute (the active colour
    attribute is left as it is)."""
    existing = mesh.attributes.get(ATTRIBUTE_NAME)
    if existing is not None and (existing.domain != "POINT" or existing.data_type != "FLOAT_COLOR"):
        mesh.attributes.remove(existing)
        existing = None
    if existing is None:
        mesh.color_attributes.new(ATTRIBUTE_NAME, "FLOAT_COLOR", "POINT")
    attribute = mesh.color_attributes[ATTRIBUTE_NAME]
    attribute.data.foreach_set("color", np.ascontiguousarray(rgba, dtype=np.float32).ravel())
    mesh.update()


def show_sides_once(obj, context=None) -> bool:
    """On an object's first measurement, make "VG Sides" its active colour attribute and switch
    solid viewports to attribute colours; afterwards do nothing (the user's choice stands).

    Returns True when it switched.
    """
    if obj.vg.sides_shown:
        return False
    attribute = obj.data.color_attributes.get(ATTRIBUTE_NAME)
    if attribute is None:
        return False
    obj.data.color_attributes.active_color = attribute
    obj.vg.sides_shown = True
    show_in_viewports(context)
    return True


def read_attribute(mesh) -> np.ndarray | None:
    """The "VG Sides" colours (float32, shape (n, 4)), or None if the mesh has none."""
    attribute = mesh.color_attributes.get(ATTRIBUTE_NAME)
    if attribute is None:
        return None
    rgba = np.empty(len(attribute.data) * 4, dtype=np.float32)
    attribute.data.foreach_get("color", rgba)
    return rgba.reshape(-1, 4)


def show_in_viewports(context=None) -> None:
    """Switch every solid-shaded 3D viewport to attribute colours, so the sides are visible."""
    context = context or bpy.context
    window_manager = getattr(context, "window_manager", None)
    if window_manager is None:
        return
    for window in window_manager.windows:
        for area in window.screen.areas:
            if area.type != "VIEW_3D":
                continue
            for space in area.spaces:
                if space.type == "VIEW_3D" and space.shading.type == "SOLID":
                    space.shading.color_type = "VERTEX"
            area.tag_redraw()
