"""The stability figure's crease part: how far the reading moves when the vertices next to the
crease are left out of the plane fits.

Every perturbed run of the figure (centre, radius, λ, bootstrap) keeps the vertices next to the
crease, so where the mesh's triangles cut the corner all of them share the tilt those vertices
give the planes: their spread stays small while the reading is off. Leaving out a band along the
line where the two planes meet and fitting each side's plane again to what is left measures that
tilt: on faces that are planes, with every vertex on its face, nothing moves; where the vertices
next to the crease lie off the faces, the reading moves towards the faces' own angle. Each band
is two plane fits on the patch, in a fixed order (:mod:`.fixed_order`).
"""

from __future__ import annotations

import math

import numpy as np

from .algorithm import MIN_SIDE_VERTICES
from .fixed_order import acos_degrees, dot3, norm3, row_dot, total
from .planes import crease_line, distance_to_line, side_plane
from .refinement import mean_edge_length

BAND_SPACINGS = (1.0, 2.0)
"""Bands of this many mesh spacings either side of the crease line: the vertices of the
triangles that cut the corner, and of the ring beside them."""

BAND_RADII = (0.25, 0.5)
"""Bands of this share of the radius either side of the crease line: on a mesh whose rows lie
far apart across the crease (a near-flat edge on a coarse or stretched mesh) the strip off the
faces is wider than two mesh spacings, and only the far part of each face is on it."""

MIN_REACH = 1.0
"""What is left of a side must reach this many mesh spacings across the crease (from its vertex
nearest the crease line to its farthest): else it is one row of vertices, which any plane through
it fits, noise or none."""


def _acute_reach(normal_plus, normal_minus) -> float:
    """How many times farther from the crease line than a mesh spacing a vertex of one face lies
    within a mesh spacing of the other face: ``1 / sin(angle)`` at an acute crease (a vertex at
    distance ``d`` from the line is ``d sin(angle)`` from the other face), 1 at a right or obtuse
    one (the other face's nearest point is then the crease line itself). A cell of the mesh that
    holds both faces is that far from the line, and its vertices can lie on either face or on
    neither; on a thin wedge that is the whole patch."""
    if dot3(normal_plus, normal_minus) >= 0.0:
        return 1.0  # normals 90° or less apart (the angle is 180° less theirs): not acute
    opening = norm3(np.cross(normal_plus, normal_minus))
    return 1.0 / max(opening, 1e-12)


def _normals_hide_the_crease(normals, tangent, angle) -> bool:
    """Whether the vertex normals' noise is larger than the turn that tells the faces apart.

    On any crease both faces' normals are perpendicular to the tangent, so the normals' root mean
    square component along it is noise alone; each face's normal turns ``(180 - angle) / 2`` from
    their mean. Where that noise is the larger, a vertex's normal does not say which face it is
    on, the tangent Algorithm 1 draws the split along is the noise's, and its sides can be mixed
    across the whole patch (every perturbed run and every band shares that)."""
    along = row_dot(normals, tangent)
    noise = math.sqrt(total(along * along) / along.size)
    return noise > math.sin(math.radians(180.0 - angle) / 2.0)


def _plane_normal(points, normals, side) -> np.ndarray | None:
    """The PCA plane's unit normal of the ``side`` vertices, oriented by their mean normal;
    ``None`` where the side has too few vertices or they lie on a line."""
    if int(np.count_nonzero(side)) < MIN_SIDE_VERTICES:
        return None
    plane = side_plane(points, normals, side)
    return None if plane is None else plane[0]


def _distance_to_crease(points, sides, normal_plus, normal_minus) -> np.ndarray | None:
    """Each point's distance to the line where the two planes meet (each plane through its
    side's centroid); ``None`` where the planes do not meet in a line."""
    planes = [
        (normal, np.add.reduce(points[side], axis=0) / int(side.sum()))
        for normal, side in zip((normal_plus, normal_minus), sides, strict=True)
    ]
    # The line's point nearest the centre (the origin of ``points``).
    line = crease_line(planes, np.zeros(3))
    return None if line is None else distance_to_line(points, *line)


def _reaches(to_line, spacing) -> bool:
    """Whether a side's vertices (their distances to the crease line) reach across it by
    :data:`MIN_REACH` mesh spacings."""
    return to_line.size > 0 and float(to_line.max() - to_line.min()) >= MIN_REACH * spacing


def crease_change(surface, m) -> tuple[float, int, bool]:
    """The crease part of a measurement's stability figure.

    Parameters
    ----------
    surface, m : Surface, Measurement
        A measurement taken by ``surface.measure`` (it holds the patch's ``indices``).

    Returns
    -------
    change : float
        The largest change of the angle, in degrees, when the vertices within each band of
        :data:`BAND_SPACINGS` mesh spacings (at an acute crease, of the other face: ``1 /
        sin(angle)`` times farther from the line) and :data:`BAND_RADII` radii of the crease
        line are left out and each side's plane is fitted again to the rest (no spacing band
        wider than the widest of :data:`BAND_RADII` at a right or obtuse crease). Also where the
        planes fit their vertices exactly: two rows of vertices always fit a plane, on the face
        or not.
    refused : int
        How many distinct bands left a side too few vertices, a line, or a band narrower than
        :data:`MIN_REACH` to fit its plane: then how far the reading is off is not known.
    noise_hides_crease : bool
        Whether the vertex normals' noise is larger than the turn between the faces
        (:func:`_normals_hide_the_crease`): the sides can be mixed across the whole patch, and
        how far the reading is off is not known either.
    """
    spacing = mean_edge_length(m.radius, m.n_vertices)
    points = surface.points[m.indices] - m.center
    normals = surface.normals[m.indices]
    used = np.ones(m.n_vertices, dtype=bool) if m.left_out is None else ~m.left_out
    sides = (m.labels & used, ~m.labels & used)
    # On a patch of few vertices two spacings can be more than half the radius: no band is wider.
    widest = max(BAND_RADII) * m.radius
    # At an acute crease the cells that hold both faces reach farther from the line (no cap
    # there: where they cover the patch, the mesh does not resolve the two faces at all).
    reach = _acute_reach(m.normal_plus, m.normal_minus)
    widths = [min(k * spacing, widest) * reach for k in BAND_SPACINGS]
    # A small patch clamps both spacing bands to the widest: that is one band, counted once.
    widths = list(dict.fromkeys(widths + [k * m.radius for k in BAND_RADII]))
    to_line = _distance_to_crease(points, sides, m.normal_plus, m.normal_minus)
    noise_hides_crease = _normals_hide_the_crease(normals, m.tangent, m.angle)
    if to_line is None:
        return 0.0, len(widths), noise_hides_crease
    change, refused = 0.0, 0
    for width in widths:
        kept = [side & (to_line > width) for side in sides]
        fitted = [
            _plane_normal(points, normals, side) if _reaches(to_line[side], spacing) else None
            for side in kept
        ]
        if fitted[0] is None or fitted[1] is None:
            refused += 1
            continue
        angle = 180.0 - acos_degrees(dot3(fitted[0], fitted[1]))
        change = max(change, abs(angle - m.angle))
    return change, refused, noise_hides_crease


__all__ = ["BAND_RADII", "BAND_SPACINGS", "MIN_REACH", "crease_change"]
