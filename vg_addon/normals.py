"""Vertex normals: from triangles (area-weighted) or, for a point cloud, from local PCA."""

from __future__ import annotations

import numpy as np

from .spatial import GridIndex


def face_normals(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Unnormalised face normals: the cross product of two edges, of length twice the face's area."""
    a = points[triangles[:, 0]]
    u = points[triangles[:, 1]] - a
    v = points[triangles[:, 2]] - a
    # Written out: np.cross is several times slower on millions of rows.
    normals = np.empty_like(u)
    normals[:, 0] = u[:, 1] * v[:, 2] - u[:, 2] * v[:, 1]
    normals[:, 1] = u[:, 2] * v[:, 0] - u[:, 0] * v[:, 2]
    normals[:, 2] = u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]
    return normals


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
    weighted = face_normals(points, triangles)
    summed = np.zeros((n, 3), dtype=np.float64)
    for axis in range(3):
        for corner in range(3):
            summed[:, axis] += np.bincount(
                triangles[:, corner], weights=weighted[:, axis], minlength=n
            )
    lengths = np.linalg.norm(summed, axis=1)
    scale = np.sqrt(np.finfo(np.float64).tiny)
    valid = lengths > scale * max(float(np.abs(points).max(initial=0.0)) ** 2, scale)
    normals = np.zeros_like(summed)
    normals[valid] = summed[valid] / lengths[valid, None]
    return normals, valid


def _neighbour_pairs(index: GridIndex, radius: float, chunk: int = 20_000):
    """Yield chunks of (i, j) id pairs with ``|p_i - p_j| <= radius <= index.cell_size``.

    For each point and each of the 27 cells around its own, the points of that cell are one
    contiguous run of the index's sorted arrays, found with ``searchsorted``; runs are expanded
    with ``repeat`` and filtered by distance, so no Python loop runs per point.
    """
    dims = index.dims
    total = index.points.shape[0]
    offsets = np.array([(a, b, c) for a in (-1, 0, 1) for b in (-1, 0, 1) for c in (-1, 0, 1)])
    for start in range(0, total, chunk):
        stop = min(start + chunk, total)
        own = np.arange(start, stop, dtype=np.int64)
        ijk = index._cells(index.points[start:stop])
        rows_out, cols_out = [], []
        for offset in offsets:
            neighbour = ijk + offset
            inside = ((neighbour >= 0) & (neighbour < dims)).all(axis=1)
            key = (neighbour[:, 0] * dims[1] + neighbour[:, 1]) * dims[2] + neighbour[:, 2]
            lo = np.searchsorted(index.keys, key, side="left")
            hi = np.searchsorted(index.keys, key, side="right")
            lengths = np.where(inside, hi - lo, 0)
            count = int(lengths.sum())
            if count == 0:
                continue
            firsts = np.cumsum(lengths) - lengths
            cols = np.repeat(lo - firsts, lengths) + np.arange(count, dtype=np.int64)
            rows = np.repeat(own, lengths)
            gap = index.points[rows] - index.points[cols]
            close = np.einsum("ij,ij->i", gap, gap) <= radius * radius
            rows_out.append(index.ids[rows[close]])
            cols_out.append(index.ids[cols[close]])
        yield np.concatenate(rows_out), np.concatenate(cols_out)


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
    Orientation: each connected piece of the neighbourhood graph is seeded at its point farthest
    from the piece's centroid, where the outward normal of a closed surface points away from the
    centroid, and spread to neighbours through smooth links (see :func:`orient_normals`).
    """
    n = points.shape[0]
    radius = index.cell_size if radius is None else min(radius, index.cell_size)
    sums = np.zeros((n, 3))
    moments = np.zeros((n, 3, 3))
    counts = np.zeros(n)
    pair_rows, pair_cols = [], []
    for rows, cols in _neighbour_pairs(index, radius):
        neighbours = points[cols]
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
    values, vectors = np.linalg.eigh(covariance)
    normals = vectors[:, :, 0]
    valid = (counts >= 3) & (values[:, 1] > 1e-12 * np.maximum(values[:, 2], 1e-300))
    normals[~valid] = 0.0
    rows = np.concatenate(pair_rows)
    cols = np.concatenate(pair_cols)
    orient_normals(points, normals, valid, rows, cols)
    return normals, valid


def orient_normals(points, normals, valid, rows, cols, smooth: float = 0.5) -> None:
    """Flip normals in place so that neighbours agree, spreading outward from extreme points.

    Breadth-first over the neighbour links whose normals are nearly parallel (``|n_i . n_j| >=
    smooth``), each newly reached point copying the orientation of its smoothest link to the
    frontier. Each unreached piece is seeded at its point farthest from the centroid of the
    unreached points, oriented away from that centroid.
    """
    n = points.shape[0]
    link = valid[rows] & valid[cols]
    rows, cols = rows[link], cols[link]
    weight = np.abs(np.einsum("ij,ij->i", normals[rows], normals[cols]))
    strong = weight >= smooth
    source = np.concatenate([rows[strong], cols[strong]])
    target = np.concatenate([cols[strong], rows[strong]])
    weight = np.concatenate([weight[strong], weight[strong]])
    order = np.lexsort((-weight, source))
    source, target, weight = source[order], target[order], weight[order]
    starts = np.searchsorted(source, np.arange(n + 1))
    oriented = ~valid
    while not oriented.all():
        free = np.flatnonzero(~oriented)
        outward = points[free] - points[free].mean(axis=0)
        pick = int(np.argmax(np.einsum("ij,ij->i", outward, outward)))
        seed = free[pick]
        if normals[seed] @ outward[pick] < 0:
            normals[seed] = -normals[seed]
        oriented[seed] = True
        frontier = np.array([seed])
        while frontier.size:
            lengths = starts[frontier + 1] - starts[frontier]
            count = int(lengths.sum())
            firsts = np.cumsum(lengths) - lengths
            links = np.repeat(starts[frontier] - firsts, lengths) + np.arange(count)
            links = links[~oriented[target[links]]]
            if links.size == 0:
                break
            pick = np.lexsort((-weight[links], target[links]))
            links = links[pick]
            first = np.ones(links.size, dtype=bool)
            first[1:] = target[links[1:]] != target[links[:-1]]
            links = links[first]
            reached, origin = target[links], source[links]
            flip = np.einsum("ij,ij->i", normals[origin], normals[reached]) < 0
            normals[reached[flip]] = -normals[reached[flip]]
            oriented[reached] = True
            frontier = reached
