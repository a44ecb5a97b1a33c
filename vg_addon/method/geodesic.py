"""Exact geodesic patches: shortest paths along mesh edges, truncated at the radius."""

from __future__ import annotations

import numpy as np

from .ranges import expand_ranges


class EdgeGraph:
    """The undirected edges of a triangle mesh in compressed sparse row form, built once.

    Within a vertex's row the edges are in no particular order: the distances do not depend on
    it (the relaxation below reaches the same least fixed point in any order).

    Parameters
    ----------
    points : ndarray, shape (n, 3)
    triangles : ndarray of int64, shape (m, 3)
    """

    def __init__(self, points: np.ndarray, triangles: np.ndarray):
        n = points.shape[0]
        a = triangles.ravel()
        b = triangles[:, [1, 2, 0]].ravel()
        # Each undirected edge once (low end, high end), then both directions grouped by source:
        # two sorts of half the length of one sort of every directed edge.
        keys = np.unique(np.minimum(a, b) * np.int64(n) + np.maximum(a, b))
        low, high = keys // n, keys % n
        lengths = np.linalg.norm(points[low] - points[high], axis=1)
        source = np.concatenate([low, high])
        order = np.argsort(source, kind="stable")
        self.source = source[order]
        self.target = np.concatenate([high, low])[order]
        self.lengths = np.concatenate([lengths, lengths])[order]
        self.starts = np.searchsorted(self.source, np.arange(n + 1, dtype=np.int64))
        self._local = np.full(n, -1, dtype=np.int64)

    def distances(self, vertices: np.ndarray, source: int, radius: float) -> np.ndarray:
        """Shortest edge-path distance from ``source`` to each of ``vertices`` (inf if unreachable).

        Only paths inside ``vertices`` are considered; pass the Euclidean ball of the same radius,
        which holds every path no longer than the radius, because a path along edges is never
        shorter than the straight line. Label-correcting relaxation that only re-examines the
        edges of vertices whose distance just improved: exact, and vectorised per sweep.
        """
        local = self._local
        local[vertices] = np.arange(vertices.size)
        try:
            lengths = self.starts[vertices + 1] - self.starts[vertices]
            edges = expand_ranges(self.starts[vertices], lengths)
            u = np.repeat(np.arange(vertices.size), lengths)
            v = local[self.target[edges]]
            keep = v >= 0
            u, v, w = u[keep], v[keep], self.lengths[edges[keep]]
        finally:
            local[vertices] = -1
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
            improved = distance[targets] < before
            changed = np.unique(targets[improved])
        return distance
