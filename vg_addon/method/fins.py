"""Edges of three or more faces: a fin or an inner face standing on the surface.

A scan's surface has at most two faces on each edge. A third one (a fin of triangles standing on
the break edge, an inner wall left by a bad merge, a face given twice) adds vertices whose
normals belong to neither face of the break: a 90° wedge with a fin ten vertex spacings high on
its crease read 69.65° at radius 0.3, with a small fit error and nothing else to show it. The
measured patch is refused where it holds a vertex of such an edge (``Surface.measure``).

Faces without area (a repeated vertex, or corners in a line to within :data:`FLAT` of their
longest side) are passed over: they turn no normal, and a decimated scan can leave them lying
along an edge of two faces.
"""

from __future__ import annotations

import numpy as np

from .normals import face_normals

#: A face whose height is at most this share of its longest side counts as without area.
FLAT = 1e-6

_CHUNK = 1 << 18  # faces per block


def from_sorted_edges(edges: np.ndarray, points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """The vertices of edges used by three or more faces with area.

    Parameters
    ----------
    edges : ndarray of int64
        Each corner's undirected edge ``low * n + high`` (``n`` vertices), sorted; collapsed
        corners (both ends one vertex) left out.
    points : ndarray, shape (n, 3)
    triangles : ndarray of int, shape (m, 3)
        The faces the corners are of.

    Returns
    -------
    ndarray of int64
        Sorted, each vertex once; empty where every edge has one or two faces.
    """
    third = edges[2:][edges[2:] == edges[:-2]]
    if third.size == 0:
        return np.empty(0, dtype=np.int64)
    n = np.int64(points.shape[0])
    candidates = np.unique(third)
    involved = []  # the faces on a candidate edge, block by block: the temporaries stay small
    for first in range(0, triangles.shape[0], _CHUNK):
        start, end = corner_ends(triangles[first : first + _CHUNK])
        keys = np.minimum(start, end) * n + np.maximum(start, end)
        slot = np.minimum(np.searchsorted(candidates, keys), candidates.size - 1)
        involved.append(first + np.flatnonzero((candidates[slot] == keys).reshape(-1, 3).any(1)))
    start, end = _flat_corner_edges(points, triangles[np.concatenate(involved)])
    flat = np.sort(np.minimum(start, end) * n + np.maximum(start, end))
    uses = _count(edges, candidates) - _count(flat, candidates)
    kept = candidates[uses >= 3]
    return np.unique(np.concatenate([kept // n, kept % n]))


def from_edge_uses(
    uses: np.ndarray, ids: np.ndarray, points: np.ndarray, triangles: np.ndarray
) -> np.ndarray:
    """:func:`from_sorted_edges` from each edge id's count of corners (collapsed corners left
    out) and each corner's edge id ``ids`` (aligned with ``triangles.ravel()``)."""
    candidates = uses >= 3
    if not candidates.any():
        return np.empty(0, dtype=np.int64)
    ids = ids.reshape(-1, 3)
    involved = candidates[ids].any(axis=1)
    faces, face_ids = triangles[involved], ids[involved].reshape(-1)
    start, end = corner_ends(faces)
    corners = np.repeat(_flat(points, faces), 3) & (start != end)
    fin = uses - np.bincount(face_ids[corners], minlength=uses.size) >= 3
    if not fin.any():
        return np.empty(0, dtype=np.int64)
    corners = fin[face_ids]
    return np.unique(np.concatenate([start[corners], end[corners]]))


def _count(sorted_keys: np.ndarray, values: np.ndarray) -> np.ndarray:
    """How many times each of ``values`` is in ``sorted_keys``."""
    right = np.searchsorted(sorted_keys, values, side="right")
    return right - np.searchsorted(sorted_keys, values, side="left")


def _flat(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Which triangles have no area: height at most :data:`FLAT` times their longest side, so
    twice their area at most ``FLAT`` times its square (a repeated vertex among them)."""
    x, y, z = face_normals(points, triangles)
    twice_area = np.sqrt(x * x + y * y + z * z)
    a, b, c = (np.take(points, triangles[:, k], axis=0) for k in range(3))
    longest = np.max([np.einsum("ij,ij->i", v, v) for v in (b - a, c - b, a - c)], axis=0)
    return twice_area <= FLAT * longest


def corner_ends(triangles: np.ndarray):
    """Start and end vertex (int64) of each corner's edge (corner k to corner k + 1) of some
    triangles, aligned with ``triangles.ravel()``."""
    triangles = triangles.astype(np.int64, copy=False)
    return triangles.reshape(-1), triangles[:, [1, 2, 0]].reshape(-1)


def _flat_corner_edges(points: np.ndarray, triangles: np.ndarray):
    """Start and end vertex of each corner edge of the faces without area, collapsed corners
    left out."""
    start, end = corner_ends(triangles[_flat(points, triangles)])
    return start[start != end], end[start != end]
