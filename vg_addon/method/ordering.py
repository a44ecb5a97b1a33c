"""The canonical order of a surface's vertices, computed once so a patch sorts by one integer key."""

from __future__ import annotations

import numpy as np


def canonical_ranks(points: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """Rank of each vertex in the order of ``algorithm.canonical_order`` over all vertices.

    Sorting any subset by these ranks gives the order ``canonical_order`` gives that subset
    (by x, then y, z, then the normal's x, y, z; exact ties by vertex index), so a patch is put in
    canonical order by sorting small integers instead of six float keys.

    Parameters
    ----------
    points, normals : ndarray of float64, shape (n, 3)

    Returns
    -------
    ndarray of int32 (int64 beyond 2**31 vertices), shape (n,)

    Notes
    -----
    Sorted by x first (one key); only runs of equal x (rare on scans, common on grids) are
    sorted by the remaining five keys, then by vertex index.
    """
    n = points.shape[0]
    # Any order among equal x will do (faster than a stable sort): the runs of equal x are
    # sorted again below, with the vertex index as the last key.
    order = np.argsort(points[:, 0])
    x = points[order, 0]
    tied = np.zeros(n, dtype=bool)
    equal = x[1:] == x[:-1]
    tied[1:] |= equal
    tied[:-1] |= equal
    if tied.any():
        members = order[tied]
        run = np.cumsum(~np.concatenate(([False], equal)))[tied]  # run number, ascending in x
        p, q = points[members], normals[members]
        within = np.lexsort((members, q[:, 2], q[:, 1], q[:, 0], p[:, 2], p[:, 1], run))
        order[tied] = members[within]
    ranks = np.empty(n, dtype=np.int32 if n < 2**31 else np.int64)
    ranks[order] = np.arange(n, dtype=ranks.dtype)
    return ranks
