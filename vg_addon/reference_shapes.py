"""The reference shapes of the project's tests, made by its own code: a half annulus and two
intersecting spheres, marched from their implicit functions (see :mod:`marching_tetrahedra`).

They are the shapes of ``HalfAnnulus.ply`` and ``IntersectingSpheres.ply`` (the reference meshes
the original authors made by marching cubes), with the same exact angles, so a clone of the
repository without those files still tests the method on bevelled creases and curved faces.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .marching_tetrahedra import march
from .method.fixed_order import in_frame

# Faces of the half annulus: the cut plane x = 0.5 meets the ring twice (y > 0 and y < 0).
CUT, BOTTOM, OUTER, INNER, TOP, CUT_2 = range(6)
INNER_RADIUS, OUTER_RADIUS, HALF_HEIGHT, CUT_X = 1.5, 2.5, 0.5, 0.5

HALF_ANNULUS_EDGES = {
    (CUT, OUTER): math.degrees(math.acos(CUT_X / OUTER_RADIUS)),  # 78.46°
    (CUT_2, OUTER): math.degrees(math.acos(CUT_X / OUTER_RADIUS)),
    # 109.47°, where the cut meets the concave inner wall (a convex edge of the solid)
    (CUT, INNER): 180.0 - math.degrees(math.acos(CUT_X / INNER_RADIUS)),
    (CUT_2, INNER): 180.0 - math.degrees(math.acos(CUT_X / INNER_RADIUS)),
    (TOP, OUTER): 90.0,
    (BOTTOM, OUTER): 90.0,
    (TOP, INNER): 90.0,  # at the concave inner wall
    (BOTTOM, INNER): 90.0,
    (TOP, CUT): 90.0,
    (BOTTOM, CUT_2): 90.0,
}
"""The exact interior angle of each edge, by the pair of faces that meet there. Where the cut
plane meets a cylinder of radius ``R`` the normals are ``(-1, 0, 0)`` and ``(x, y, 0) / R`` with
``x = 0.5``, so the interior angle is ``arccos(0.5 / R)`` (inner wall: the open angle of a
concave edge, 180° minus that)."""

SPHERE_RADIUS = math.sqrt(1.5)
SPHERE_CENTRES = ((0.0, 1.0, 1.0), (2.0, 1.0, 1.0))
LENS_RIM_ANGLE = 180.0 - math.degrees(math.acos(-1.0 / 3.0))
"""70.53°: at the rim (x = 1) the outward normals are ``(±1, 0.5, 0.5) / √1.5``."""


@dataclass(frozen=True, eq=False)
class LabelledMesh:
    """A marched mesh and, per vertex, the face of the shape it lies on (the nearest one).

    Attributes
    ----------
    points : numpy.ndarray
        ``(n, 3)`` float64.
    triangles : numpy.ndarray
        ``(m, 3)`` int64, closed and wound outward.
    labels : numpy.ndarray
        ``(n,)`` int64 face numbers (for the half annulus :data:`CUT` … :data:`CUT_2`).
    """

    points: np.ndarray
    triangles: np.ndarray
    labels: np.ndarray


def _half_annulus_terms(p: np.ndarray) -> np.ndarray:
    """Signed distances to each face's plane or cylinder (positive outside), ``(n, 5)``:
    cut, bottom, outer, inner, top."""
    rho = np.hypot(p[:, 0], p[:, 1])
    return np.stack(
        [CUT_X - p[:, 0], -HALF_HEIGHT - p[:, 2], rho - OUTER_RADIUS, INNER_RADIUS - rho,
         p[:, 2] - HALF_HEIGHT],
        axis=1,
    )  # fmt: skip


def half_annulus(spacing: float = 0.05) -> LabelledMesh:
    """The half annulus: a ring of radii 1.5 and 2.5 and height 1 (``|z| ≤ 0.5``), the part
    with ``x ≥ 0.5``; edges of 78.46°, 109.47° (where the cut meets the concave inner wall) and
    90° (:data:`HALF_ANNULUS_EDGES`).

    ``spacing`` is the marching grid's step (0.05 gives about 11,000 vertices, like the
    reference file).
    """
    shift = 0.3183 * spacing  # the faces fall between grid planes, never on them
    lower = np.array([CUT_X, -OUTER_RADIUS, -HALF_HEIGHT]) - 2 * spacing + shift
    upper = np.array([OUTER_RADIUS, OUTER_RADIUS, HALF_HEIGHT]) + 2 * spacing
    points, triangles = march(lambda p: _half_annulus_terms(p).max(axis=1), lower, upper, spacing)
    nearest = np.argmin(np.abs(_half_annulus_terms(points)), axis=1)
    labels = np.where((nearest == CUT) & (points[:, 1] < 0), CUT_2, nearest)
    return LabelledMesh(points, triangles, labels.astype(np.int64))


def intersecting_spheres(spacing: float = 0.02) -> LabelledMesh:
    """The lens where two spheres of radius √1.5 centred at ``(0, 1, 1)`` and ``(2, 1, 1)``
    overlap: its rim, the circle ``x = 1`` of radius √0.5, has the interior angle 70.53°
    (:data:`LENS_RIM_ANGLE`). Labels: 0 on the cap of the first sphere (``x ≥ 1``), 1 on the
    other's.
    """
    centres = np.array(SPHERE_CENTRES)

    def terms(p):
        return np.stack([np.linalg.norm(p - c, axis=1) - SPHERE_RADIUS for c in centres], axis=1)

    reach = math.sqrt(SPHERE_RADIUS**2 - 1.0)
    half_width = SPHERE_RADIUS - 1.0
    shift = 0.3183 * spacing
    lower = np.array([1.0 - half_width, 1.0 - reach, 1.0 - reach]) - 2 * spacing + shift
    upper = np.array([1.0 + half_width, 1.0 + reach, 1.0 + reach]) + 2 * spacing
    points, triangles = march(lambda p: terms(p).max(axis=1), lower, upper, spacing)
    labels = np.argmax(terms(points), axis=1).astype(np.int64)
    return LabelledMesh(points, triangles, labels)


def _turn(seed: int) -> np.ndarray:
    """A rotation about a random axis by a random angle (Rodrigues' formula, element-wise, so the
    same bits on every machine)."""
    rng = np.random.default_rng(seed)
    axis = rng.normal(size=3)
    axis = axis / math.sqrt(float(axis[0] ** 2 + axis[1] ** 2 + axis[2] ** 2))
    angle = float(rng.uniform(0.3, 2.8))
    (x, y, z), c, s = axis.tolist(), math.cos(angle), math.sin(angle)
    return np.array(
        [
            [c + x * x * (1 - c), x * y * (1 - c) - z * s, x * z * (1 - c) + y * s],
            [y * x * (1 - c) + z * s, c + y * y * (1 - c), y * z * (1 - c) - x * s],
            [z * x * (1 - c) - y * s, z * y * (1 - c) + x * s, c + z * z * (1 - c)],
        ]
    )


def marched_wedge(
    angle_deg: float, spacing: float = 0.02, *, turn_seed: int | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A wedge of interior angle ``angle_deg`` marched by tetrahedra, as a scanner's
    reconstruction meshes a crease: the crease runs between rows of vertices, and the
    triangles across it cut the corner.

    The solid is ``|x| ≤ y tan(angle / 2)``, ``y ≤ 0.8``, ``|z| ≤ 0.4``, ``|x| ≤ 0.8``, turned by a
    random rotation drawn from ``turn_seed`` (none by default); its crease is the turned z axis.

    Returns
    -------
    points, triangles : ndarray
        The mesh, wound outward. Reverse the triangles for the valley of the same angle.
    crease_point, crease_direction : ndarray, shape (3,)
        The crease's point at the origin (the origin) and its unit direction.
    """
    half = math.tan(math.radians(angle_deg) / 2.0)
    turn = np.eye(3) if turn_seed is None else _turn(turn_seed)

    def inside(points):
        local = in_frame(points, turn.T)
        x, y, z = local[:, 0], local[:, 1], local[:, 2]
        across = (np.abs(x) - y * half) / math.sqrt(1.0 + half * half)
        return np.maximum.reduce([across, y - 0.8, np.abs(z) - 0.4, np.abs(x) - 0.8])

    offset = np.array([0.0123, 0.371, 0.6577]) * spacing  # no grid point on the crease
    points, triangles = march(inside, np.full(3, -1.25) + offset, np.full(3, 1.25), spacing)
    return points, triangles, np.zeros(3), turn[:, 2].copy()


def stretched_wedge(angle_deg: float, spacing: float = 0.0106) -> tuple[np.ndarray, np.ndarray]:
    """A wedge made the way the Virtual Goniometer's authors make their synthetic wedges: a
    right-angled wedge marched on a grid, then stretched across the crease to ``angle_deg``.

    The crease is the z axis; the faces are ``x = |y| / tan(angle / 2)`` for ``x ≤ 0.8``,
    ``|z| ≤ 0.4``. Stretching keeps every vertex on its face but spreads the rows of vertices
    apart across the crease (by ``tan(angle / 2)``), and the row the triangles cut the corner
    through lies on neither face: near-flat wedges hold few rows per side.

    Returns
    -------
    points, triangles : ndarray
        The mesh, wound outward.
    """

    def inside(points):
        x, y, z = points[:, 0], points[:, 1], points[:, 2]
        return np.maximum.reduce([np.abs(y) - x, x - 0.8, np.abs(z) - 0.4])

    offset = np.array([0.0123, 0.371, 0.6577]) * spacing  # no grid point on a face
    lower = np.array([-0.1, -0.85, -0.45]) + offset
    points, triangles = march(inside, lower, np.array([0.85, 0.85, 0.45]), spacing)
    points[:, 1] *= math.tan(math.radians(angle_deg) / 2.0)
    return points, triangles
