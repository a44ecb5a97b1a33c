"""The "VG Sides" colour attribute: each measurement's two sides in a palette pair, the rest grey.

Only this one attribute is ever written; the user's own colour attributes are left alone. The
"VG Sides" attribute is made the active one, and solid viewports are switched to attribute
colours, once per object, on its first measurement (:func:`show_sides_once`); a repaint never
changes either, so a user who picks another attribute or shading keeps it.
"""

from __future__ import annotations

import bpy
import numpy as np

from .mesh_data import own_write, read_positions

ATTRIBUTE_NAME = "VG Sides"

# Rows of candidate vertices matched against a patch at once (bounds the temporary matrix).
_CHUNK = 1024


def new_sides_material(name: str, roughness: float):
    """A new material showing the side colours (the "VG Sides" attribute through a Color
    Attribute node into the Principled BSDF's base colour), ``roughness`` its roughness."""
    material = bpy.data.materials.new(name)
    if material.node_tree is None:  # Blender < 5: nodes are off by default
        material.use_nodes = True
    nodes = material.node_tree.nodes
    shader = next(n for n in nodes if n.type == "BSDF_PRINCIPLED")
    shader.inputs["Roughness"].default_value = roughness
    colour = nodes.new("ShaderNodeVertexColor")
    colour.layer_name = ATTRIBUTE_NAME
    colour.location = (shader.location.x - 300, shader.location.y)
    material.node_tree.links.new(colour.outputs["Color"], shader.inputs["Base Color"])
    return material


def _nearest_labels(candidates: np.ndarray, patch_points: np.ndarray, labels: np.ndarray):
    """Side label of the nearest patch point to each candidate point (brute force, in chunks)."""
    out = np.empty(candidates.shape[0], dtype=bool)
    squared_patch = np.einsum("ij,ij->i", patch_points, patch_points)
    for start in range(0, candidates.shape[0], _CHUNK):
        block = candidates[start : start + _CHUNK]
        squared = squared_patch[None, :] - 2.0 * block @ patch_points.T
        out[start : start + _CHUNK] = labels[np.argmin(squared, axis=1)]
    return out


def original_sides(obj, geometry, m) -> tuple[np.ndarray, np.ndarray]:
    """The vertices of ``obj.data`` (the original mesh) that measurement ``m``, taken on the
    evaluated ``geometry``, paints, and their side labels (True = "+").

    Notes
    -----
    When the modifiers keep the vertex count (no modifier, or deforming ones), evaluated vertex
    ``i`` is original vertex ``i``. When they change it (e.g. Subdivision Surface), each original
    vertex within the patch's radius takes the side of the nearest evaluated patch vertex: the
    colours then approximate the measured sides, the numbers are unaffected.
    """
    mesh = obj.data
    if len(mesh.vertices) == geometry.points.shape[0]:
        return m.indices, m.labels
    original = read_positions(mesh).astype(np.float64)
    offsets = original - m.center
    inside = np.flatnonzero(np.einsum("ij,ij->i", offsets, offsets) <= m.radius * m.radius)
    return inside, _nearest_labels(original[inside], geometry.points[m.indices], m.labels)


def _ours(mesh):
    """The "VG Sides" attribute if it is a point FLOAT_COLOR one, else None.

    Looked up among the colour attributes: looking up ``mesh.attributes`` makes every attribute
    array of the mesh writable, which copies them all after an undo step (milliseconds at 1M).
    """
    attribute = mesh.color_attributes.get(ATTRIBUTE_NAME)
    if (
        attribute is not None
        and attribute.domain == "POINT"
        and attribute.data_type == "FLOAT_COLOR"
    ):
        return attribute
    return None


def write_attribute(mesh, rgba: np.ndarray) -> None:
    """Write ``rgba`` into the mesh's "VG Sides" point colour attribute (the active colour
    attribute is left as it is; see :func:`show_sides_once`)."""
    attribute = _ours(mesh)
    if attribute is None:
        existing = mesh.attributes.get(ATTRIBUTE_NAME)  # of another domain or type
        if existing is not None:
            mesh.attributes.remove(existing)
        attribute = mesh.color_attributes.new(ATTRIBUTE_NAME, "FLOAT_COLOR", "POINT")
    attribute.data.foreach_set("color", np.ascontiguousarray(rgba, dtype=np.float32).ravel())
    mesh.update()


def has_attribute(mesh) -> bool:
    """Whether the mesh has the "VG Sides" attribute as :func:`write_attribute` makes it."""
    return _ours(mesh) is not None


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
    with own_write(obj.data):  # not an edit: wakes no staleness check, keeps the geometry
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
