"""Measurement labels in the 3D viewport: each current measurement's number and angle beside
its centre, white with a dark outline so they read on dark and light backgrounds alike; an
unstable reading in red with its stability figure ("3: 71.01° ±78°"), as its list row.

A ``POST_PIXEL`` draw handler, added on register; it only reads the records (through
``bridge.label_data``) and the scene's label settings. The active object's measurements are
labelled; with many, a label goes to the left of its centre where the right is taken, and is
left out where both are (the selected measurement, then the newest, are placed first); or the
labels are limited to the current break.
"""

from __future__ import annotations

import blf
import bpy
import gpu
import numpy as np
from bpy_extras import view3d_utils
from gpu_extras.batch import batch_for_shader

from ..bridge.label_data import labels_of
from ..operators.drag_overlay import point_shader
from ..vg_addon.workflow.labels import place_labels

FONT_ID = 0
TEXT_COLOR = (1.0, 1.0, 1.0, 1.0)
ACTIVE_COLOR = (1.0, 0.85, 0.2, 1.0)
UNSTABLE_COLOR = (1.0, 0.45, 0.4, 1.0)  # the list's alert red: an unstable reading
OUTLINE_COLOR = (0.0, 0.0, 0.0, 0.9)
OUTLINE_OFFSETS = ((-1, -1), (-1, 0), (-1, 1), (0, -1), (0, 1), (1, -1), (1, 0), (1, 1))

_handle = {"draw": None}


def _draw() -> None:
    context = bpy.context
    scene = context.scene
    settings = getattr(scene, "vg_settings", None)
    obj = context.active_object
    region, region_data = context.region, context.region_data
    if settings is None or not settings.show_labels or obj is None or obj.type != "MESH":
        return
    if region is None or region_data is None or obj.mode == "EDIT":
        return
    labels = labels_of(obj, active_break_only=settings.labels_active_break)
    if not labels:
        return
    size = max(11, round(13 * context.preferences.system.ui_scale))
    placed = []
    for label in labels:
        coord = view3d_utils.location_3d_to_region_2d(region, region_data, label.position)
        if coord is not None and 0 <= coord.x < region.width and 0 <= coord.y < region.height:
            placed.append((label, (coord.x, coord.y)))
    if not placed:
        return
    priority = [(2 * len(placed) if label.active else 0) + i for i, (label, _) in enumerate(placed)]
    positions = np.array([coord for _, coord in placed])
    blf.size(FONT_ID, size)
    widths = [blf.dimensions(FONT_ID, label.text)[0] for label, _ in placed]
    gap = 0.6 * size
    shown = place_labels(
        positions, widths, size, priority, gap=gap, right_edge=_visible_right(context, region)
    )
    _dots(positions[[index for index, _ in shown]], 0.5 * size)
    for index, side in shown:
        label, (x, y) = placed[index]
        x = x + gap if side > 0 else x - gap - widths[index]
        _outlined(label.text, x, y - 0.35 * size, label_colour(label))


def label_colour(label):
    """White; the selected measurement yellow; an unstable reading red (its text carries the
    stability figure, as its list row does)."""
    if label.unstable:
        return UNSTABLE_COLOR
    return ACTIVE_COLOR if label.active else TEXT_COLOR


def _visible_right(context, region) -> float:
    """Where the view stops being visible on the right: the region's edge, or the left edge of
    a sidebar drawn over it (Region Overlap)."""
    right = float(region.width)
    area = context.area
    for other in area.regions if area is not None else ():
        if other.type == "UI" and other.width > 1 and other.x > region.x:
            right = min(right, float(other.x - region.x))
    return right


def _dots(positions: np.ndarray, diameter: float) -> None:
    """A white dot ringed in black at each labelled centre (pixel coordinates)."""
    coords = np.column_stack([positions, np.zeros(len(positions))]).astype(np.float32)
    gpu.state.blend_set("ALPHA")
    with point_shader() as points:
        batch = batch_for_shader(points.shader, "POINTS", {"pos": coords})
        for color, size in ((OUTLINE_COLOR, diameter + 3.0), (TEXT_COLOR, diameter)):
            points.draw(batch, color, size)
    gpu.state.blend_set("NONE")


def _outlined(text: str, x: float, y: float, color) -> None:
    blf.color(FONT_ID, *OUTLINE_COLOR)
    for dx, dy in OUTLINE_OFFSETS:
        blf.position(FONT_ID, x + dx, y + dy, 0)
        blf.draw(FONT_ID, text)
    blf.color(FONT_ID, *color)
    blf.position(FONT_ID, x, y, 0)
    blf.draw(FONT_ID, text)


def register() -> None:
    """Add the draw handler to every 3D viewport (once)."""
    if _handle["draw"] is None:
        _handle["draw"] = bpy.types.SpaceView3D.draw_handler_add(_draw, (), "WINDOW", "POST_PIXEL")


def unregister() -> None:
    """Remove the draw handler (a no-op when it is not there)."""
    handle, _handle["draw"] = _handle["draw"], None
    if handle is not None:
        bpy.types.SpaceView3D.draw_handler_remove(handle, "WINDOW")


def registered() -> bool:
    """Whether the draw handler is installed."""
    return _handle["draw"] is not None
