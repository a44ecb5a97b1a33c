"""Exact geodesic patches: shortest paths along mesh edges, truncated at the radius."""

from __future__ import annotations

import numpy as np

from .ranges import expand_ranges

_CHUNK = 1 << 18  # corners per block
_NEXT = np.array([1, 2, 0])  # the corner after corner k of a face, and the one before it
_PREVIOUS = np.array([2, 0, 1])


class EdgeGraph:
    """The edges of a triangle mesh around any patch, from a vertex-to-corner table built once.

    For each vertex, the corners at it (compressed sparse row form), each with the other two
    vertices of its face: one ``argsort`` of the corners, far cheaper than sorting every edge of
    the mesh. A patch's edges are read from the corners of its own vertices.

    Parameters
    ----------
    points : ndarray, shape (n, 3)
    triangles : ndarray of int, shape (m, 3)
    """

    def __init__(self, points: np.ndarray, triangles: np.ndarray):
        n = points.shape[0]
        self.points = points
        corners = triangles.reshape(-1)  # corner 3 t + k is vertex k of triangle t
        # Within a vertex's row the corners are in no particular order: the distances do not
        # depend on it (the relaxation below reaches the same least fixed point in any order).
        order = np.argsort(corners)
        ids = np.int32 if n < 2**31 else np.int64
        # The next and the previous vertex of each corner's face, in row order (block by block:
        # no whole-mesh temporaries beside the order itself).
        self.ends = np.empty((order.size, 2), dtype=ids)
        for first in range(0, order.size, _CHUNK):
            corner = order[first : first + _CHUNK]
            face = corner // 3 * 3
            turn = corner - face
            rows = slice(first, first + corner.size)
            self.ends[rows, 0] = corners[face + _NEXT[turn]]
            self.ends[rows, 1] = corners[face + _PREVIOUS[turn]]
        del order
        self.starts = np.zeros(n + 1, dtype=np.int64)
        step = 16 * _CHUNK  # bincount copies int32 indices: in blocks, each copy stays small
        for first in range(0, corners.size, step):
            self.starts[1:] += np.bincount(corners[first : first + step], minlength=n)
        np.cumsum(self.starts, out=self.starts)
        self._local = np.full(n, -1, dtype=np.int64)

    def _patch_edges(self, vertices: np.ndarray):
        """The edges between ``vertices``, both ways, as local (source, target, length), sorted."""
        local = self._local
        local[vertices] = np.arange(vertices.size)
        try:
            counts = self.starts[vertices + 1] - self.starts[vertices]
            ends = np.take(self.ends, expand_ranges(self.starts[vertices], counts), axis=0)
            ends = ends.ravel()
            v = local[ends]
        finally:
            local[vertices] = -1
        # Each edge once each way, sorted by source: (source, target) as one sortable key.
        keys = np.repeat(np.arange(vertices.size, dtype=np.int64) << 32, 2 * counts)
        keys |= v
        keys = np.sort(keys[v >= 0])
        first = np.ones(keys.size, dtype=bool)
        first[1:] = keys[1:] != keys[:-1]
        keys = keys[first]
        u, v = keys >> 32, keys & 0xFFFFFFFF
        ends = vertices[v]
        # Each edge's length from its lower-numbered end, as np.linalg.norm(points[low] -
        # points[high], axis=1) gives it for the whole mesh's edges: sqrt((x^2 + y^2) + z^2).
        starts = vertices[u]
        offset = np.take(self.points, np.minimum(starts, ends), axis=0)
        offset -= np.take(self.points, np.maximum(starts, ends), axis=0)
        lengths = offset[:, 0] * offset[:, 0]
        lengths += offset[:, 1] * offset[:, 1]
        lengths += offset[:, 2] * offset[:, 2]
        np.sqrt(lengths, out=lengths)
        return u, v, lengths

    def distances(self, vertices: np.ndarray, source: int, radius: float) -> np.ndarray:
        """Shortest edge-path distance from ``source`` to each of ``vertices`` (inf if unreachable).

        Only paths inside ``vertices`` are considered; pass the Euclidean ball of the same radius,
        which holds every path no longer than the radius, because a path along edges is never
        shorter than the straight line. Label-correcting relaxation that only re-examines the
        edges of vertices whose distance just improved: exact, and vectorised per sweep.
        """
        u, v, w = self._patch_edges(vertices)
        edge_starts = np.searchsorted(u, np.arange(vertices.size + 1))
        distance = np.full(vertices.size, np.inf)
        start = int(np.flatnonzero(vertices == source)[0])
        distance[start] = 0.0
        changed = np.array([start])
        while changed.size:
            active = expand_ranges(
                edge_starts[changed], edge_starts[changed + 1] - edge_starts[changed]
            )
            candidate = distance[u[active]] + w[active]
            useful = (candidate < distance[v[active]]) & (candidate <= radius)
            if not useful.any():
                break
            targets, candidate = v[active][useful], candidate[useful]
            before = distance[targets].copy()
            np.minimum.at(distance, targets, candidate)
            improved = np.zeros(vertices.size, dtype=bool)
            improved[targets[distance[targets] < before]] = True
            changed = np.flatnonzero(improved)  # np.unique, without its cost on small arrays
        return distance
