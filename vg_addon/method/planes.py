"""Planes of a patch's sides and the line where two of them meet, in a fixed order.

Shared by the refinement (:mod:`.refinement`), which fits each side's plane to the vertices on
it, and the stability figure's crease part (:mod:`.crease_band`), which fits them again without
the vertices next to the crease. Every sum runs in a fixed order (:mod:`.fixed_order`), so the
same inputs give the same bits on every machine.
"""

from __future__ import annotations

import numpy as np

from .fixed_order import (
    column_moments,
    columns_dot,
    cross3,
    dot3,
    eigh3_entries,
    norm3,
    offset_columns,
    solve,
)

RANK_TOLERANCE = 1e-10
"""Points span a plane when their covariance's middle eigenvalue is more than this fraction of
the largest; below it they lie on a line (Algorithm 1's test for a side, and every refit's)."""


def side_plane(points, normals, mask):
    """The PCA plane of the points ``mask`` selects.

    Parameters
    ----------
    points, normals : ndarray, shape (n, 3)
        The patch's vertices and their unit normals.
    mask : ndarray of bool, shape (n,)
        The side's vertices (at least one).

    Returns
    -------
    tuple or None
        ``(normal, centroid, mean_squared_distance)``: the unit normal, oriented to agree with
        the side's mean vertex normal, the centroid, and the mean squared distance of the points
        to the plane; ``None`` where the points do not span a plane (:data:`RANK_TOLERANCE`).
    """
    # Sums row after row, each column on its own (joining points and normals costs more).
    rows = np.compress(mask, points, axis=0)
    count = rows.shape[0]
    centroid = np.add.reduce(rows, axis=0) / count
    centred = np.empty((3, count))
    np.subtract(rows.T, centroid[:, None], out=centred)
    xx, xy, xz, yy, yz, zz = (value / count for value in column_moments(centred))
    values, vectors = eigh3_entries(xx, xy, xz, yy, yz, zz)
    if not values[1] > RANK_TOLERANCE * max(values[2], np.finfo(float).tiny):
        return None
    normal = vectors[:, 0]
    if dot3(normal, np.add.reduce(np.compress(mask, normals, axis=0), axis=0)) < 0:
        normal = -normal
    return normal, centroid, max(float(values[0]), 0.0)


def crease_line(planes, center):
    """The line where two planes meet.

    Parameters
    ----------
    planes : pair of tuples
        Each ``(unit normal, a point on the plane, ...)``, as :func:`side_plane` gives them.
    center : array_like, shape (3,)
        The point the line's point is chosen nearest to.

    Returns
    -------
    tuple or None
        ``(point, direction)``: the line's point nearest ``center`` and its unit direction;
        ``None`` when the planes are parallel.
    """
    (normal_plus, centroid_plus, *_), (normal_minus, centroid_minus, *_) = planes
    direction = cross3(normal_plus, normal_minus)
    length = norm3(direction)
    if length <= 1e-12:
        return None
    direction = direction / length
    rows = np.array([normal_plus, normal_minus, direction])
    offsets = [dot3(normal_plus, centroid_plus), dot3(normal_minus, centroid_minus)]
    offsets.append(dot3(direction, center))
    on_line = solve(rows, offsets)
    if on_line is None:
        return None
    return np.array(on_line), direction


def distance_to_line(points, on_line, direction) -> np.ndarray:
    """Each point's distance to a line.

    Parameters
    ----------
    points : ndarray, shape (n, 3)
    on_line, direction : ndarray, shape (3,)
        A point on the line and its unit direction.

    Returns
    -------
    ndarray, shape (n,)
    """
    relative = offset_columns(points, on_line)
    along = columns_dot(relative, direction)
    squares = relative * relative
    return np.sqrt(np.maximum(squares[0] + squares[1] + squares[2] - along * along, 0.0))


SIDE_REACH = 0.1
"""A side shows which way its face runs from the crease only where its centroid lies at least
this fraction of the patch radius from the crease line (:func:`sides_contradict_normals`)."""

LINE_REACH = 0.25
"""The sides show how their faces meet only where the planes' line passes within this fraction
of the patch radius of the centre: near-parallel planes meet far off, with both sides on one
side of their line (:func:`sides_contradict_normals`)."""


def sides_contradict_normals(points, labels, normal_plus, normal_minus, center, radius) -> bool:
    """Whether the two sides' plane normals face each other the wrong way round for where the
    sides lie: the angle between the planes would then read as its supplement.

    Each face runs from the crease line, within its plane, towards its side's centroid, along
    ``±(d × n)`` (``d`` the line's direction, ``n`` the face's normal). With both normals facing
    out of the material (or both into it), the two signs differ: the faces' directions then make
    the angle ``180° − arccos(n₊·n₋)`` that is reported. Equal signs mean that one face's
    normals were oriented the wrong way round (a point cloud's estimated normals across an
    acute crease). ``False`` (no verdict) where the planes are parallel, their line passes
    farther than :data:`LINE_REACH` radii from the centre, or a centroid lies within
    :data:`SIDE_REACH` radii of the line.
    """
    if labels.all() or not labels.any():
        return False
    centroids = [
        np.add.reduce(np.compress(side, points, axis=0), axis=0) / np.count_nonzero(side)
        for side in (labels, ~labels)
    ]
    line = crease_line([(normal_plus, centroids[0]), (normal_minus, centroids[1])], center)
    if line is None:
        return False
    on_line, direction = line
    if norm3(np.asarray(center, dtype=np.float64) - on_line) > LINE_REACH * radius:
        return False  # on_line is the line's point nearest the centre
    reach = [
        dot3(cross3(direction, normal), centroid - on_line)
        for normal, centroid in zip((normal_plus, normal_minus), centroids, strict=True)
    ]
    if min(abs(value) for value in reach) < SIDE_REACH * radius:
        return False
    return (reach[0] > 0) == (reach[1] > 0)


def contradicting_normals_message(angle: float, *, cloud: bool = False) -> str:
    """The refusal where :func:`sides_contradict_normals`: why, what the reading would have been
    (``angle``) and what to do, for a point cloud's estimated normals or a mesh's (or given)
    normals."""
    if cloud:
        return (
            "The point cloud's estimated normals face opposite ways on the two sides of this "
            "crease (one face's were oriented the wrong way round, as can happen across an "
            f"acute edge), so the angle would read {angle:.2f}° (the edge would then be "
            f"{180.0 - angle:.2f}°): measure the scan as a mesh, or give the cloud normals you "
            "trust."
        )
    return (
        "The two sides' normals face opposite ways for where the sides lie, so this reading, "
        f"{angle:.2f}°, is not the edge's angle. Either one face's normals point the other way "
        "(its triangles wound against the rest, or given normals pointing into the material: "
        f"the edge would then be {180.0 - angle:.2f}°; make the normals consistent, e.g. in "
        "Blender's Edit Mode with Mesh > Normals > Recalculate Outside), or the split did not "
        "follow an edge (a flat, rounded or noisy patch: move the centre onto the edge or use a "
        "larger radius). The 'oriented' rule replicates a reading taken with it."
    )


__all__ = [
    "LINE_REACH",
    "RANK_TOLERANCE",
    "SIDE_REACH",
    "contradicting_normals_message",
    "crease_line",
    "distance_to_line",
    "side_plane",
    "sides_contradict_normals",
]
