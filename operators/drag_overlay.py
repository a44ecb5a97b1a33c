"""The drag preview in the 3D viewport: the patch's outline circle and its vertices.

It belongs to the drag tool's modal operator, which installs and removes it (the pattern of
Blender's modal-draw operator template), so it lives beside the operator, not in ``ui/``.

The operator owns one :class:`DragOverlay`; it starts drawing when the drag starts and must be
stopped on every way out (release, cancel, error, the window manager cancelling the operator).
Mouse moves only hand over new data (NumPy arrays, in mesh coordinates, drawn through the
object's ``matrix_world``); the GPU batch is built lazily in the draw callback, the one place a
GPU context is guaranteed.

Lines use the ``POLYLINE_UNIFORM_COLOR`` shader and points ``POINT_UNIFORM_COLOR``, which set
their width and size as uniforms and so work on Metal and Vulkan (where ``line_width_set`` and
``point_size_set`` do nothing); Blender 4.2 has no ``POINT_UNIFORM_COLOR``, so points fall back
to ``UNIFORM_COLOR`` with ``point_size_set`` there.
"""

from __future__ import annotations

import contextlib

import bpy
import gpu
import numpy as np
from gpu_extras.batch import batch_for_shader
from mathutils import Matrix

from ..vg_addon import palette

# The patch before its sides are measured: a neutral light grey (a pale yellow read as the first
# break's yellow side; white would hide the radius circle that runs through it).
PATCH_COLOR = (0.72, 0.72, 0.72, 0.85)


def side_colours(pair) -> tuple:
    """The drawing colours (RGBA, 0-1) of an 8-bit sRGB ("+", "-") pair."""
    return tuple((*(c / 255.0 for c in rgb), 0.95) for rgb in pair)


SIDE_COLORS = side_colours(palette.pair_srgb8(1))
CIRCLE_COLOR = (1.0, 1.0, 1.0, 0.9)
POINT_SIZE = 4.0
LINE_WIDTH = 2.0
CIRCLE_SEGMENTS = 96


class PointShader:
    """The built-in shader for points of a chosen size on every Blender the extension supports:
    ``POINT_UNIFORM_COLOR`` (its size a uniform), else Blender 4.2's ``UNIFORM_COLOR`` sized by
    ``gpu.state.point_size_set``. Used as a context manager, it sets the global point size back
    to 1 on the way out where it changed it."""

    def __init__(self):
        try:
            self.shader = gpu.shader.from_builtin("POINT_UNIFORM_COLOR")
            self.uniform_size = True
        except (ValueError, TypeError):  # 4.2: not one of its built-in shaders
            self.shader = gpu.shader.from_builtin("UNIFORM_COLOR")
            self.uniform_size = False

    def draw(self, batch, color, size: float) -> None:
        """Draw ``batch`` (built for :attr:`shader`) as points of ``size`` pixels in ``color``."""
        self.shader.bind()
        if self.uniform_size:
            self.shader.uniform_float("size", size)
        else:
            gpu.state.point_size_set(size)
        self.shader.uniform_float("color", color)
        batch.draw(self.shader)

    def __enter__(self) -> PointShader:
        return self

    def __exit__(self, *exc) -> None:
        if not self.uniform_size:
            gpu.state.point_size_set(1.0)


@contextlib.contextmanager
def over_everything():
    """Draw blended and with no depth test (a patch or path is drawn whole, hidden side
    included), and leave the GPU state as it was for what draws next (other add-ons')."""
    blend, depth = gpu.state.blend_get(), gpu.state.depth_test_get()
    gpu.state.blend_set("ALPHA")
    gpu.state.depth_test_set("NONE")
    try:
        yield
    finally:
        gpu.state.blend_set(blend)
        gpu.state.depth_test_set(depth)


def point_shader() -> PointShader:
    """A :class:`PointShader` for one drawing (the overlays' and the labels' points)."""
    return PointShader()


def patch_vertex_data(points: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """The patch vertices as the contiguous float32 (k, 3) array a GPU vertex buffer takes."""
    return np.ascontiguousarray(points[indices], dtype=np.float32)


def circle_points(center, radius: float, right, up, segments: int = CIRCLE_SEGMENTS) -> np.ndarray:
    """A closed polyline (``segments + 1`` float32 points): the circle in the plane ``right, up``.

    Drawn in the view plane, it is the outline of the ball the Euclidean patch is cut from.
    """
    angles = np.linspace(0.0, 2.0 * np.pi, segments + 1)
    right = np.asarray(right, dtype=np.float64)
    up = np.asarray(up, dtype=np.float64)
    ring = np.cos(angles)[:, None] * right + np.sin(angles)[:, None] * up
    return (np.asarray(center, dtype=np.float64) + radius * ring).astype(np.float32)


class ViewOverlay:
    """A drawing in every 3D viewport: a draw handler (``POST_VIEW``) plus the data it draws.

    ``start`` adds the handler (once), ``stop`` removes it and drops the data (:meth:`_drop`;
    safe to call any number of times). A subclass draws in its ``_draw``.
    """

    _handle = None

    @property
    def active(self) -> bool:
        """Whether the draw handler is installed."""
        return self._handle is not None

    @property
    def handle(self):
        """Blender's handle of the installed draw handler, or None."""
        return self._handle

    def start(self) -> None:
        """Install the draw handler in every 3D viewport (a no-op when already installed)."""
        if self._handle is None:
            self._handle = bpy.types.SpaceView3D.draw_handler_add(
                self._draw, (), "WINDOW", "POST_VIEW"
            )

    def stop(self) -> None:
        """Remove the draw handler and drop the data; safe to call more than once."""
        handle, self._handle = self._handle, None
        self._drop()
        if handle is not None:
            bpy.types.SpaceView3D.draw_handler_remove(handle, "WINDOW")

    def _drop(self) -> None:
        """Forget the data drawn (the handler is gone); each overlay drops its own."""


class DragOverlay(ViewOverlay):
    """The viewport drawing of one drag: the patch's points in their side colours, the radius
    ring and the centre (``start``/``stop``: :class:`ViewOverlay`)."""

    def __init__(self):
        self._handle = None
        self._coords: np.ndarray | None = None
        self._labels: np.ndarray | None = None
        self._batches = None
        self.center: np.ndarray | None = None
        self.radius = 0.0
        self.matrix = np.eye(4)
        self.side_colours = SIDE_COLORS

    def _drop(self) -> None:
        self._coords = self._labels = self._batches = self.center = None

    def update(
        self,
        center,
        radius: float,
        coords: np.ndarray | None,
        labels=None,
        *,
        matrix=None,
        colours=None,
    ) -> None:
        """New preview: the circle ``center``/``radius`` and the patch vertices.

        ``coords`` is a float32 (k, 3) array (see :func:`patch_vertex_data`); ``labels``, when a
        measurement of the patch exists, is its bool "+" side per vertex, drawn in two colours.
        Everything is in mesh coordinates; ``matrix`` (the object's ``matrix_world``, default
        the identity) places it in the viewport. ``colours``: the 8-bit sRGB ("+", "-") pair the
        release will paint (default: the first break's).
        """
        self.side_colours = SIDE_COLORS if colours is None else side_colours(colours)
        self.matrix = np.eye(4) if matrix is None else np.asarray(matrix, dtype=np.float64)
        self.center = None if center is None else np.asarray(center, dtype=np.float64)
        self.radius = float(radius)
        self._coords = coords
        self._labels = None if labels is None else np.asarray(labels, dtype=bool)
        self._batches = None

    def _build_batches(self, shader) -> list:
        coords, labels = self._coords, self._labels
        if coords is None or not len(coords):
            return []
        if labels is None:
            groups = [(coords, PATCH_COLOR)]
        else:
            plus, minus = self.side_colours
            groups = [(coords[labels], plus), (coords[~labels], minus)]
        return [
            (batch_for_shader(shader, "POINTS", {"pos": group}), color)
            for group, color in groups
            if len(group)
        ]

    def _draw(self) -> None:
        region_data = bpy.context.region_data
        region = bpy.context.region
        if region_data is None or region is None or self.center is None:
            return
        # the whole patch is measured, hidden side included
        with over_everything(), gpu.matrix.push_pop(), point_shader() as points:
            gpu.matrix.multiply_matrix(Matrix(self.matrix.tolist()))
            if self._batches is None:
                self._batches = self._build_batches(points.shader)
            for batch, color in self._batches:
                points.draw(batch, color, POINT_SIZE)
            if self.radius > 0.0:
                # The view plane's axes, brought into mesh coordinates: the circle is drawn
                # there, so it is the patch's outline under any object transform.
                to_mesh = np.linalg.inv(self.matrix[:3, :3])
                view = np.array(region_data.view_rotation.to_matrix())
                right, up = (to_mesh @ view[:, i] for i in (0, 1))
                right /= np.linalg.norm(right)
                up -= right * (up @ right)
                up /= np.linalg.norm(up)
                ring = circle_points(self.center, self.radius, right, up)
                lines = gpu.shader.from_builtin("POLYLINE_UNIFORM_COLOR")
                lines.bind()
                lines.uniform_float("viewportSize", (region.width, region.height))
                lines.uniform_float("lineWidth", LINE_WIDTH)
                lines.uniform_float("color", CIRCLE_COLOR)
                batch_for_shader(lines, "LINE_STRIP", {"pos": ring}).draw(lines)
