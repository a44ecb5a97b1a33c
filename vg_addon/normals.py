"""Vertex normals: from triangles (area-weighted) or, for a point cloud, from local PCA."""

from __future__ import annotations

import numpy as np

from .ranges import expand_ranges
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
    # In units of the mesh's extent (min and max do not depend on vertex order), so that a scan
    # in kilometres or in nanometres neither overflows nor underflows the cross products.
    origin = points.min(axis=0)
    extent = float(np.max(points.max(axis=0) - origin))
    scaled = (points - origin) / extent if extent > 0 else points - origin
    weighted = face_normals(scaled, triangles)
    summed = np.zeros((n, 3), dtype=np.float64)
    for axis in range(3):
        for corner in range(3):
            summed[:, axis] += np.bincount(
                triangles[:, corner], weights=weighted[:, axis], minlength=n
            )
    lengths = np.linalg.norm(summed, axis=1)
    valid = lengths > 1e-150
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
            if not lengths.any():
                continue
            cols = expand_ranges(lo, lengths)
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
    Orientation: made consistent along smooth, in-plane links, then each connected piece is turned
    to point away from the cloud's centroid by a majority vote (see :func:`orient_normals`).
    """
    n = points.shape[0]
    radius = index.cell_size if radius is None else min(radius, index.cell_size)
    sums = np.zeros((n, 3))
    moments = np.zeros((n, 3, 3))
    counts = np.zeros(n)
    pair_rows, pair_cols = [], []
    for rows, cols in _neighbour_pairs(index, radius):
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
    values, vectors = np.linalg.eigh(covariance)
    normals = vectors[:, :, 0]
    valid = (counts >= 3) & (values[:, 1] > 1e-12 * np.maximum(values[:, 2], 1e-300))
    normals[~valid] = 0.0
    rows = np.concatenate(pair_rows)
    cols = np.concatenate(pair_cols)
    # Surface variation: near 0 on a smooth piece, larger where the neighbourhood straddles a
    # crease, whose PCA normal belongs to neither face and must not carry orientation across.
    variation = values[:, 0] / np.maximum(values.sum(axis=1), 1e-300)
    orient_normals(points, normals, valid & (variation <= 0.01), rows, cols)
    crease = valid & (variation > 0.01)
    if crease.any():
        _orient_from_neighbours(normals, crease, rows, cols)
    return normals, valid


def orient_normals(
    points, normals, valid, rows, cols, smooth: float = 0.9, planar: float = 0.3
) -> None:
    """Flip normals in place so that they agree within each smooth piece and point outward.

    Orientation spreads breadth-first only along links between nearly parallel normals
    (``|n_i . n_j| >= smooth``) that lie in each other's tangent plane (``|n . d| <= planar |d|``
    at both ends, for ``d = p_j - p_i``), so it never jumps between the two faces of a sharp
    wedge. Each piece is then flipped as a whole if most of its normals point towards the
    centroid of the whole cloud: the outward direction of a closed or wedge-shaped scan.
    """
    n = points.shape[0]
    gap = points[cols] - points[rows]
    length = np.linalg.norm(gap, axis=1)
    link = valid[rows] & valid[cols]
    link &= np.abs(np.einsum("ij,ij->i", normals[rows], normals[cols])) >= smooth
    link &= np.abs(np.einsum("ij,ij->i", normals[rows], gap)) <= planar * length
    link &= np.abs(np.einsum("ij,ij->i", normals[cols], gap)) <= planar * length
    source = np.concatenate([rows[link], cols[link]])
    target = np.concatenate([cols[link], rows[link]])
    order = np.argsort(source, kind="stable")
    source, target = source[order], target[order]
    starts = np.searchsorted(source, np.arange(n + 1))
    piece = np.full(n, -1, dtype=np.int64)
    has_links = starts[1:] > starts[:-1]
    pieces = 0
    seeds = np.flatnonzero(has_links)
    position = 0
    while True:
        unassigned = piece[seeds[position:]] < 0
        if not unassigned.any():
            break
        position += int(np.argmax(unassigned))
        seed = seeds[position]
        piece[seed] = pieces
        frontier = np.array([seed])
        while frontier.size:
            links = expand_ranges(starts[frontier], starts[frontier + 1] - starts[frontier])
            links = links[piece[target[links]] < 0]
            if links.size == 0:
                break
            reached, first = np.unique(target[links], return_index=True)
            origin = source[links][first]
            flip = np.einsum("ij,ij->i", normals[origin], normals[reached]) < 0
            normals[reached[flip]] = -normals[reached[flip]]
            piece[reached] = pieces
            frontier = reached
        pieces += 1
    alone = valid & (piece < 0)
    piece[alone] = pieces + np.arange(int(alone.sum()))
    members = valid & (piece >= 0)
    outward = np.einsum("ij,ij->i", normals[members], points[members] - points[valid].mean(axis=0))
    votes = np.bincount(piece[members], weights=outward, minlength=int(piece.max()) + 1)
    flip = members & (votes[np.maximum(piece, 0)] < 0)
    normals[flip] = -normals[flip]


def _orient_from_neighbours(normals, todo, rows, cols) -> None:
    """Orient each ``todo`` normal like the sum of its already oriented neighbours' normals."""
    source = np.concatenate([rows, cols])
    target = np.concatenate([cols, rows])
    use = todo[target] & ~todo[source]
    total = np.zeros_like(normals)
    for axis in range(3):
        total[:, axis] = np.bincount(
            target[use], weights=normals[source[use], axis], minlength=normals.shape[0]
        )
    flip = todo & (np.einsum("ij,ij->i", normals, total) < 0)
    normals[flip] = -normals[flip]
