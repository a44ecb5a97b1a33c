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

# Faces of the half annulus: the cut plane x = 0.5 meets the ring twice (y > 0 and y < 0).
CUT, BOTTOM, OUTER, INNER, TOP, CUT_2 = range(6)
INNER_RADIUS, OUTER_RADIUS, HALF_HEIGHT, CUT_X = 1.5, 2.5, 0.5, 0.5

HALF_ANNULUS_EDGES = {
    (CUT, OUTER): math.degrees(math.acos(CUT_X / OUTER_RADIUS)),  # 78.46°
    (CUT_2, OUTER): math.degrees(math.acos(CUT_X / OUTER_RADIUS)),
    (CUT, INNER): 180.0 - math.degrees(math.acos(CUT_X / INNER_RADIUS)),  # 109.47°, concave
    (CUT_2, INNER): 180.0 - math.degrees(math.acos(CUT_X / INNER_RADIUS)),
    (TOP, OUTER): 90.0,
    (BOTTOM, OUTER): 90.0,
    (TOP, INNER): 90.0,  # concave
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
    with ``x ≥ 0.5``; edges of 78.46°, 109.47° (concave) and 90° (:data:`HALF_ANNULUS_EDGES`).

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
