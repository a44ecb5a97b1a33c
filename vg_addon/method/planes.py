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


__all__ = ["RANK_TOLERANCE", "crease_line", "distance_to_line", "side_plane"]
