"""The Find Break Edges review in the 3D viewport: every candidate drawn over the mesh, coloured
by its confidence, numbered, with the analyst's decisions shown.

It belongs to the Find Break Edges operator's modal session, which installs and removes it (like
the edge operator's overlay beside its operator). The lines are drawn in the view
(``POST_VIEW``), the numbers over it in pixels (``POST_PIXEL``, a second handler). Updates only
hand over NumPy arrays; GPU batches are built lazily in the draw callback, the one place a GPU
context is guaranteed.
"""

from __future__ import annotations

import itertools

import blf
import bpy
import numpy as np
from bpy_extras import view3d_utils
from gpu_extras.batch import batch_for_shader

from ..bridge.mesh_data import world_points
from .drag_overlay import ViewOverlay
from .edge_overlay import draw_batches

# Confidence colours, low to high: red, amber, green (linear RGB as the viewport draws them).
CONFIDENCE_STOPS = (
    (0.0, (0.95, 0.12, 0.08)),
    (0.5, (1.0, 0.72, 0.05)),
    (1.0, (0.15, 0.9, 0.25)),
)
REJECTED_COLOR = (0.08, 0.08, 0.08, 0.9)  # dark: seen on the grey mesh, not in the way
REJECTED_TEXT = (0.7, 0.7, 0.7, 1.0)
HALO_COLOR = (1.0, 1.0, 1.0, 1.0)  # under the selected candidate
TRIM_COLOR = (0.2, 0.75, 1.0, 1.0)  # the first trim click
WIDTH = {"pending": 3.0, "accepted": 5.0, "rejected": 2.0}
HALO_EXTRA = 4.0
TEXT_SIZE = 15
POINT_SIZE = 10.0
LABEL_SPOTS = 48


def confidence_color(confidence: float) -> tuple:
    """The RGBA drawing colour of a candidate of ``confidence`` (0 red, 0.5 amber, 1 green)."""
    c = float(np.clip(confidence, 0.0, 1.0))
    for (low, a), (high, b) in itertools.pairwise(CONFIDENCE_STOPS):
        if c <= high:
            t = (c - low) / (high - low)
            return (*(x + t * (y - x) for x, y in zip(a, b, strict=True)), 1.0)
    return (*CONFIDENCE_STOPS[-1][1], 1.0)


def label_text(number: int, confidence: float, decision: str) -> str:
    """What is written beside a candidate: its number, then its confidence or its verdict."""
    if decision == "pending":
        return f"{number} ({confidence:.0%})"
    return f"{number} {decision}"


def label_spots(points: np.ndarray, count: int = LABEL_SPOTS) -> np.ndarray:
    """Where a candidate's label may go: ``count`` of its points, the middle one first, then
    outwards (the first one in view and clear of other labels is used)."""
    k = len(points)
    order = np.argsort(np.abs(np.arange(k) - (k - 1) / 2.0), kind="stable")
    return points[order[:: max(k // count, 1)]]


def view_right(region) -> float:
    """The region's right edge left of a sidebar drawn over it (region overlap)."""
    area = bpy.context.area
    ui = next((r for r in area.regions if r.type == "UI"), None) if area else None
    if ui is not None and ui.width > 1 and region.x <= ui.x < region.x + region.width:
        return float(ui.x - region.x)
    return float(region.width)


class FindEdgesOverlay(ViewOverlay):
    """The viewport drawing of one review (``start``/``stop`` add and remove both handlers)."""

    def __init__(self):
        self._handle = None
        self._text_handle = None
        self._items: list | None = None
        self._selected: int | None = None
        self._trim_points: np.ndarray | None = None
        self._batches = None

    def start(self) -> None:
        """Install the line and the number handlers (no-op when installed)."""
        super().start()
        if self._text_handle is None:
            self._text_handle = bpy.types.SpaceView3D.draw_handler_add(
                self._draw_text, (), "WINDOW", "POST_PIXEL"
            )

    def stop(self) -> None:
        """Remove both handlers and drop the data; safe to call more than once."""
        handle, self._text_handle = self._text_handle, None
        if handle is not None:
            bpy.types.SpaceView3D.draw_handler_remove(handle, "WINDOW")
        super().stop()

    def _drop(self) -> None:
        self._items = self._batches = self._trim_points = None
        self._selected = None

    def update(self, candidates, decisions, selected, matrix, trim_points=None) -> None:
        """New data: the candidates (each with ``number``, ``confidence`` and a ``path`` in mesh
        coordinates), their decisions (``"pending"``, ``"accepted"``, ``"rejected"``), the
        selected index (or None) and the trim clicks so far (mesh coordinates, or None), drawn
        where the object's ``matrix`` (``matrix_world``) places them."""
        matrix = np.asarray(matrix, dtype=np.float64)
        items = []
        for candidate, decision in zip(candidates, decisions, strict=True):
            points = world_points(candidate.path.points, matrix)
            colour = (
                REJECTED_COLOR if decision == "rejected" else confidence_color(candidate.confidence)
            )
            text = label_text(candidate.number, candidate.confidence, str(decision))
            items.append(
                (points.astype(np.float32), colour, WIDTH[str(decision)], label_spots(points), text)
            )
        self._items = items
        self._selected = selected
        self._trim_points = (
            None
            if trim_points is None
            else world_points(np.reshape(trim_points, (-1, 3)), matrix).astype(np.float32)
        )
        self._batches = None

    def _build(self, lines, points) -> list:
        batches = []
        for index, (strip, colour, width, _spots, _text) in enumerate(self._items):
            if len(strip) < 2:
                continue
            # One strip per candidate: its segments join without the gaps of separate lines.
            batch = batch_for_shader(lines, "LINE_STRIP", {"pos": strip})
            if index == self._selected:
                batches.append(("LINES", batch, HALO_COLOR, width + HALO_EXTRA))
            batches.append(("LINES", batch, colour, width))
        if self._trim_points is not None:
            batch = batch_for_shader(points, "POINTS", {"pos": self._trim_points})
            batches.append(("POINTS", batch, TRIM_COLOR, POINT_SIZE))
        return batches

    def _draw(self) -> None:
        if self._items:
            draw_batches(self)

    def _draw_text(self) -> None:
        region, region_data = bpy.context.region, bpy.context.region_data
        if region_data is None or region is None or not self._items:
            return
        scale = bpy.context.preferences.system.ui_scale
        font = 0
        blf.size(font, TEXT_SIZE * scale)
        blf.enable(font, blf.SHADOW)
        blf.shadow(font, 5, 0.0, 0.0, 0.0, 1.0)
        blf.shadow_offset(font, 1, -1)
        right, top = view_right(region) - 110 * scale, region.height - 30 * scale
        placed = []
        for index, (_pairs, colour, _width, spots, text) in enumerate(self._items):
            for spot in spots:
                xy = view3d_utils.location_3d_to_region_2d(region, region_data, spot)
                if xy is None or not (10 < xy.x < right and 10 < xy.y < top):
                    continue
                if all(abs(xy.x - x) > 90 * scale or abs(xy.y - y) > 22 * scale for x, y in placed):
                    break
            else:
                continue  # not in view
            placed.append((xy.x, xy.y))
            shown = colour if colour != REJECTED_COLOR else REJECTED_TEXT
            shown = HALO_COLOR if index == self._selected else shown
            blf.color(font, *shown[:3], 1.0)
            blf.position(font, xy.x + 8 * scale, xy.y + 6 * scale, 0.0)
            blf.draw(font, f"[{text}]" if index == self._selected else text)
        blf.disable(font, blf.SHADOW)
