"""The edge-profile preview in the 3D viewport: the traced path and the clicked points.

It belongs to the edge operator's modal session, which installs and removes it (like the drag
tool's overlay beside its operator). Clicks only hand over new NumPy arrays; GPU batches are
built lazily in the draw callback, the one place a GPU context is guaranteed.
"""

from __future__ import annotations

import bpy
import gpu
import numpy as np
from gpu_extras.batch import batch_for_shader

from ..bridge.mesh_data import world_points
from .drag_overlay import ViewOverlay, over_everything, point_shader

PATH_COLOR = (1.0, 0.85, 0.1, 1.0)
CLICK_COLOR = (1.0, 1.0, 1.0, 1.0)
FLAT_COLOR = (0.9, 0.2, 0.1, 1.0)  # stretches of the path on no ridge
LINE_WIDTH = 3.0
CLICK_SIZE = 8.0


def path_segments(points: np.ndarray, arc_lengths: np.ndarray, flat_spans) -> tuple:
    """The path as float32 line-segment endpoints, split into ridge and flat stretches:
    ``(ridge_pairs, flat_pairs)``, each ``(2k, 3)`` for the ``LINES`` primitive."""
    points = np.asarray(points, dtype=np.float64)
    if points.shape[0] < 2:
        empty = np.zeros((0, 3), dtype=np.float32)
        return empty, empty
    middle = (arc_lengths[:-1] + arc_lengths[1:]) / 2.0
    flat = np.zeros(middle.size, dtype=bool)
    for low, high in flat_spans:
        flat |= (middle >= low) & (middle <= high)
    pairs = np.stack([points[:-1], points[1:]], axis=1).astype(np.float32)
    return pairs[~flat].reshape(-1, 3), pairs[flat].reshape(-1, 3)


class EdgeOverlay(ViewOverlay):
    """The viewport drawing of one edge session (``start``/``stop``: ``ViewOverlay``)."""

    def __init__(self):
        self._handle = None
        self._clicks: np.ndarray | None = None
        self._ridge = self._flat = None
        self._batches = None

    def _drop(self) -> None:
        self._clicks = self._ridge = self._flat = self._batches = None

    def update(self, clicks, path, matrix) -> None:
        """New data: the clicked points and the traced ``EdgePath`` (or ``None``), in mesh
        coordinates, drawn where the object's ``matrix`` (``matrix_world``) places them."""
        matrix = np.asarray(matrix, dtype=np.float64)
        clicks = np.asarray(clicks, dtype=np.float64).reshape(-1, 3)
        self._clicks = world_points(clicks, matrix).astype(np.float32)
        if path is None:
            self._ridge = self._flat = None
        else:
            self._ridge, self._flat = path_segments(
                world_points(path.points, matrix), path.arc_lengths, path.flat_spans
            )
        self._batches = None

    def _build(self, lines, points) -> list:
        batches = []
        for pairs, color in ((self._ridge, PATH_COLOR), (self._flat, FLAT_COLOR)):
            if pairs is not None and len(pairs):
                batch = batch_for_shader(lines, "LINES", {"pos": pairs})
                batches.append(("LINES", batch, color, LINE_WIDTH))
        if self._clicks is not None and len(self._clicks):
            batch = batch_for_shader(points, "POINTS", {"pos": self._clicks})
            batches.append(("POINTS", batch, CLICK_COLOR, CLICK_SIZE))
        return batches

    def _draw(self) -> None:
        if self._clicks is not None:
            draw_batches(self)


def draw_batches(overlay) -> None:
    """Draw ``overlay._batches``, built by ``overlay._build(lines, points)`` when None: each
    ``(kind, batch, colour, size)``, kind ``"LINES"`` (size: the width) or ``"POINTS"``, over
    everything (no depth test), in the region being drawn."""
    region = bpy.context.region
    if bpy.context.region_data is None or region is None:
        return
    # Line width and point size as shader uniforms (Metal and Vulkan ignore line_width_set);
    # the points' shader falls back on 4.2 (drag_overlay.PointShader).
    lines = gpu.shader.from_builtin("POLYLINE_UNIFORM_COLOR")
    with over_everything(), point_shader() as points:
        if overlay._batches is None:
            overlay._batches = overlay._build(lines, points.shader)
        for kind, batch, color, size in overlay._batches:
            if kind == "POINTS":
                points.draw(batch, color, size)
                continue
            lines.bind()
            lines.uniform_float("viewportSize", (region.width, region.height))
            lines.uniform_float("lineWidth", size)
            lines.uniform_float("color", color)
            batch.draw(lines)
