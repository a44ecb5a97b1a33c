"""Vertex normals: from triangles (area-weighted) or, for a point cloud, from local PCA."""

from __future__ import annotations

import numpy as np

from .fixed_order import dot3, eigh3_batched
from .ranges import expand_ranges
from .spatial import GridIndex, bounds, neighbour_pairs

_CHUNK = 1 << 18  # triangles per block: the temporaries stay small and in cache


def face_normals(points: np.ndarray, triangles: np.ndarray) -> tuple[np.ndarray, ...]:
    """Unnormalised face normals: the cross product of two edges, of length twice the face's area.

    Returns the x, y and z components as three contiguous arrays of shape (m,).
    """
    # Written out, block by block (np.cross is several times slower on millions of rows, and
    # whole-mesh temporaries cost memory and cache); the arithmetic is the same element for
    # element whatever the block size.
    m = triangles.shape[0]
    out = tuple(np.empty(m, dtype=np.float64) for _ in range(3))
    for start in range(0, m, _CHUNK):
        block = triangles[start : start + _CHUNK]
        a = np.take(points, block[:, 0], axis=0)
        u = np.take(points, block[:, 1], axis=0)
        u -= a
        v = np.take(points, block[:, 2], axis=0)
        v -= a
        rows = slice(start, start + block.shape[0])
        out[0][rows] = u[:, 1] * v[:, 2] - u[:, 2] * v[:, 1]
        out[1][rows] = u[:, 2] * v[:, 0] - u[:, 0] * v[:, 2]
        out[2][rows] = u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]
    return out


def vertex_normals(points: np.ndarray, triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Area-weighted vertex normals of a triangle mesh.

    Each vertex gets the sum of the (area-weighted) normals of the faces around it, normalised:
    large faces count more than slivers, which is what a scan's irregular triangulation needs.
    Zero-area faces add nothing. A vertex no face uses, or whose face normals cancel, has no
    normal: it gets ``(0, 0, 0)`` and ``False`` in the returned mask, never NaN.

    Parameters
    ----------
    points : ndarray, shape (n, 3)
    triangles : ndarray of int, shape (m, 3)
        Counter-clockwise seen from outside, so the normals point outward.

    Returns
    -------
    normals : ndarray, shape (n, 3)
        Unit normals (zero where undefined).
    valid : ndarray of bool, shape (n,)
        Where the normal is defined.
    """
    n = points.shape[0]
    # In units of the mesh's extent (min and max do not depend on vertex order), so that a scan
    # in kilometres or in nanometres neither overflows nor underflows the cross products.
    origin, top = bounds(points)
    extent = float(np.max(top - origin))
    scaled = points - origin
    if extent > 0:
        scaled /= extent
    weighted = face_normals(scaled, triangles)
    del scaled  # a copy of the points: free it before the sums need their own memory
    # Per axis, the sum of corner 0's contributions, plus corner 1's, plus corner 2's, in that
    # order (the order fixes the rounding); one corner column at a time keeps one index copy.
    summed = [None, None, None]
    for k in range(3):
        corner = np.ascontiguousarray(triangles[:, k], dtype=np.intp)
        for axis in range(3):
            part = np.bincount(corner, weights=weighted[axis], minlength=n)
            if k == 0:
                summed[axis] = part
            else:
                summed[axis] += part
    del weighted, corner, part
    # sqrt((x^2 + y^2) + z^2): what np.linalg.norm(axis=1) computes, on contiguous columns.
    lengths = summed[0] * summed[0]
    lengths += summed[1] * summed[1]
    lengths += summed[2] * summed[2]
    np.sqrt(lengths, out=lengths)
    valid = lengths > 1e-150
    normals = np.zeros((n, 3), dtype=np.float64)
    for axis in range(3):
        np.divide(summed[axis], lengths, out=normals[:, axis], where=valid)
    return normals, valid


def pca_normals(points: np.ndarray, index: GridIndex, radius: float | None = None):
    """Normals of a point cloud from the PCA of each point's neighbourhood, oriented outward.

    Parameters
    ----------
    points : ndarray, shape (n, 3)
    index : GridIndex
        An index over ``points`` (ids = row numbers).
    radius : float, optional
        Neighbourhood radius, at most (and by default) the index's cell size: about twice the
        point spacing.

    Returns
    -------
    normals : ndarray, shape (n, 3)
        Unit normals, zero where a neighbourhood has fewer than three non-collinear points.
    valid : ndarray of bool, shape (n,)

    Notes
    -----
    Orientation: spread from the point farthest from the centroid (whose outward normal points
    away from it) through the most reliable neighbour links first (see :func:`orient_normals`).
    """
    n = points.shape[0]
    radius = index.cell_size if radius is None else min(radius, index.cell_size)
    sums = np.zeros((n, 3))
    moments = np.zeros((n, 3, 3))
    counts = np.zeros(n)
    pair_rows, pair_cols = [], []
    for rows, cols in neighbour_pairs(index, radius):
        neighbours = points[cols] - points[rows]  # relative: no cancellation far from the origin
        counts += np.bincount(rows, minlength=n)
        for a in range(3):
            sums[:, a] += np.bincount(rows, weights=neighbours[:, a], minlength=n)
            for b in range(a, 3):
                moments[:, a, b] += np.bincount(
                    rows, weights=neighbours[:, a] * neighbours[:, b], minlength=n
                )
        keep = rows < cols
        pair_rows.append(rows[keep])
        pair_cols.append(cols[keep])
    for a in range(3):
        for b in range(a):
            moments[:, a, b] = moments[:, b, a]
    means = sums / np.maximum(counts, 1)[:, None]
    covariance = (
        moments / np.maximum(counts, 1)[:, None, None] - means[:, :, None] * means[:, None, :]
    )
    values, vectors = eigh3_batched(covariance)
    normals = vectors[:, :, 0]
    valid = (counts >= 3) & (values[:, 1] > 1e-12 * np.maximum(values[:, 2], 1e-300))
    normals[~valid] = 0.0
    rows = np.concatenate(pair_rows)
    cols = np.concatenate(pair_cols)
    # Surface variation: 0 on a flat neighbourhood, up to 1/3 where it straddles a crease, whose
    # PCA normal belongs to neither face: such points make poor seeds.
    variation = values[:, 0] / np.maximum(values.sum(axis=1), 1e-300)
    orient_normals(points, normals, valid, rows, cols, seedable=variation <= 0.01)
    return normals, valid


def orient_normals(
    points,
    normals,
    valid,
    rows,
    cols,
    seedable=None,
    tiers=(0.95, 0.85, 0.7, 0.5, 0.0),
    max_seeds: int = 64,
) -> None:
    """Flip normals in place so that neighbours agree and closed surfaces face outward.

    Two neighbours ``i, j`` are consistently oriented when ``n_i`` agrees with ``n_j`` mirrored
    in the plane halfway between them: ``a = n_i . n_j - 2 (n_i . d)(n_j . d)`` with ``d`` the
    unit vector from ``p_i`` to ``p_j`` is then positive. On a flat piece this is the plain dot
    product; across a crease, convex or concave, and between the two faces of a thin plate it
    stays right where the dot product is not. ``|a|`` is the link's reliability.

    Orientation starts at the point farthest from the centroid (among the ``seedable`` ones, the
    smooth points, when there are any), where the outward normal of a closed surface points away
    from the centroid, and spreads breadth-first through links of
    reliability at least 0.95, then 0.85, and so on, so that the most reliable links decide
    first (an approximation of Hoppe et al.'s minimum spanning tree, vectorised per step). A
    piece no link reaches gets its own seed; after ``max_seeds`` seeds, the remaining points
    are oriented away from the centroid one by one.
    """
    n = points.shape[0]
    if not valid.any():
        return
    gap = points[cols] - points[rows]
    unit = gap / np.maximum(np.linalg.norm(gap, axis=1), 1e-300)[:, None]
    first_normals, second_normals = normals[rows], normals[cols]
    agreement = np.einsum("ij,ij->i", first_normals, second_normals) - 2.0 * np.einsum(
        "ij,ij->i", first_normals, unit
    ) * np.einsum("ij,ij->i", second_normals, unit)
    link = valid[rows] & valid[cols] & (agreement != 0)
    source = np.concatenate([rows[link], cols[link]])
    target = np.concatenate([cols[link], rows[link]])
    sign = np.tile(np.sign(agreement[link]), 2)
    weight = np.tile(np.abs(agreement[link]), 2)
    order = np.lexsort((-weight, source))
    source, target, sign, weight = source[order], target[order], sign[order], weight[order]
    starts = np.searchsorted(source, np.arange(n + 1))

    flips = np.zeros(n)  # +1 keep, -1 flip, 0 not decided yet
    flips[~valid] = 1.0
    centre = points[valid].mean(axis=0)

    def spread(frontier, min_weight):
        while frontier.size:
            links = expand_ranges(starts[frontier], starts[frontier + 1] - starts[frontier])
            links = links[(weight[links] >= min_weight) & (flips[target[links]] == 0)]
            if links.size == 0:
                return
            links = links[np.lexsort((-weight[links], target[links]))]
            best = np.ones(links.size, dtype=bool)
            best[1:] = target[links[1:]] != target[links[:-1]]
            links = links[best]
            flips[target[links]] = flips[source[links]] * sign[links]
            frontier = target[links]

    for _ in range(max_seeds):
        free = np.flatnonzero(flips == 0)
        if free.size == 0:
            break
        if seedable is not None and seedable[free].any():
            free = free[seedable[free]]
        away = points[free] - centre
        pick = int(np.argmax(np.einsum("ij,ij->i", away, away)))
        seed = free[pick]
        decided_before = flips != 0  # finished pieces have no links left to undecided points
        flips[seed] = 1.0 if dot3(normals[seed], away[pick]) >= 0 else -1.0
        for tier in tiers:
            spread(np.flatnonzero((flips != 0) & ~decided_before), tier)
    rest = np.flatnonzero(flips == 0)
    if rest.size:
        outward = np.einsum("ij,ij->i", normals[rest], points[rest] - centre)
        flips[rest] = np.where(outward >= 0, 1.0, -1.0)
    normals *= flips[:, None]
