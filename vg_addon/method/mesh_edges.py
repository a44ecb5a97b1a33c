"""The undirected edges of a triangle mesh, with the faces that share each, listed both ways.

:class:`MeshEdges` is the skeleton of the ridge graph (:class:`~.edge_profile.RidgeGraph`): its
edges sorted by their two vertices, the first two faces of each, and the compressed sparse row
listing of every vertex's neighbours. It is built from one in-place sort of packed integers
(both vertices and the face of each half-edge in one int64) and block-by-block passes whose
temporaries stay small: on a million-vertex scan no whole-mesh temporary is made besides the
packed keys and the results themselves, which matters as much as the arithmetic where fresh
memory is slow to come by.

The order of everything is that of a stable sort of the half-edges by ``(low, high)`` vertex,
and every number is worked out row by row, so the results have the same bits whatever the block
size. :meth:`MeshEdges.stepwise` builds them in steps (see :mod:`.stepping`).
"""

from __future__ import annotations

import numpy as np

from ..errors import GoniometerError
from .normals import face_normals
from .stepping import STEP, finish


def _bits(count: int) -> int:
    """Bits that hold every index below ``count``."""
    return max(1, int(count - 1).bit_length())


def _index_type(count: int):
    return np.int32 if count < 2**31 else np.int64


class MeshEdges:
    """The undirected edges of a triangle mesh between valid vertices, their lengths and bends.

    Parameters
    ----------
    points : ndarray, shape (n, 3)
    triangles : ndarray of int, shape (m, 3)
    valid : ndarray of bool, shape (n,)
        Edges with an end outside it are left out, as are edges from a vertex to itself.
    block : int, optional
        Faces or edges per block of work (the results do not depend on it).

    Attributes
    ----------
    low, high : ndarray of int, shape (k,)
        The two ends of each edge, ``low < high``, sorted by ``(low, high)``.
    first_face, second_face : ndarray of int, shape (k,)
        The two lowest-numbered faces that use each edge; ``second_face`` is -1 on an edge of one
        face (a border edge). A face that uses an edge twice (a degenerate triangle) counts
        twice.
    lengths : ndarray, shape (k,)
        Each edge's length, ``|points[low] - points[high]|``.
    bends : ndarray, shape (k,)
        The angle (radians) between the unit normals of each edge's two faces; 0 on a border
        edge (a face with no area has a zero normal: its edges bend by 90°).
    starts : ndarray of int64, shape (n + 1,)
        The entries of vertex ``v`` are ``starts[v]:starts[v + 1]``.
    target : ndarray of int64, shape (2 k,)
        The neighbour at each entry: first those above ``v``, then those below it, each in
        ascending order.
    edge : ndarray of int, shape (2 k,)
        The edge of each entry.
    """

    def __init__(self, points, triangles, valid, block: int = STEP):
        finish(self._build(points, triangles, valid, block))

    @classmethod
    def stepwise(cls, points, triangles, valid, block: int = STEP):
        """The same, built in steps: a generator that yields between blocks of work and returns
        the :class:`MeshEdges`."""
        edges = cls.__new__(cls)
        yield from edges._build(points, triangles, valid, block)
        return edges

    def _build(self, points, triangles, valid, block):
        n, m = points.shape[0], triangles.shape[0]
        vertex_bits, face_bits = _bits(n), _bits(m)
        # A half-edge packed as (low, high, face): one sort orders it as a stable sort of
        # (low, high) would, since a face's half-edges are adjacent in the triangle order.
        # Vertices are split into ranges of low whose packed keys fit in 63 bits (one range up
        # to about 1.6 million vertices).
        range_bits = min(vertex_bits, 63 - vertex_bits - face_bits)
        if range_bits < 1:
            raise GoniometerError(
                f"A mesh of {n} vertices and {m} faces is too large to trace edges on."
            )
        ids = _index_type(max(n, m))
        keys = np.empty(3 * m, dtype=np.int64)
        parts = []
        for first in range(0, n, 1 << range_bits):
            last = first + (1 << range_bits)
            part = yield from self._edges_of_range(triangles, valid, keys, first, last, ids, block)
            parts.append(part)
        del keys
        if len(parts) == 1:
            self.low, self.high, self.first_face, self.second_face = parts[0]
        else:
            columns = zip(*parts, strict=True)
            self.low, self.high, self.first_face, self.second_face = map(np.concatenate, columns)
        del parts
        yield
        self.starts, self.target, self.edge = yield from _both_ways(n, self.low, self.high, block)
        self.lengths = yield from self._lengths(points, block)
        self.bends = yield from self._bends(points, triangles, block)

    @staticmethod
    def _edges_of_range(triangles, valid, keys, first, last, ids, block):
        """The edges whose low end is in ``first:last``: (low, high, first_face, second_face)."""
        n = valid.size
        vertex_bits, face_bits = _bits(n), _bits(triangles.shape[0])
        count = 0
        for start in range(0, triangles.shape[0], block):
            faces = triangles[start : start + block]
            a = faces.reshape(-1)
            b = faces[:, [1, 2, 0]].reshape(-1)
            low, high = np.minimum(a, b), np.maximum(a, b)
            keep = valid[a] & valid[b] & (a != b) & (low >= first) & (low < last)
            face = np.repeat(np.arange(start, start + faces.shape[0], dtype=np.int64), 3)[keep]
            packed = (low[keep].astype(np.int64) - first) << vertex_bits
            packed |= high[keep]
            packed <<= face_bits
            packed |= face
            keys[count : count + packed.size] = packed
            count += packed.size
            yield
        keys = keys[:count]
        keys.sort()
        yield
        # A new edge starts where the packed (low, high) changes.
        starts_edge = np.empty(count + 1, dtype=bool)
        starts_edge[count] = True
        previous = -1
        for start in range(0, count, block):
            pair = keys[start : start + block] >> face_bits
            flags = starts_edge[start : start + pair.size]
            flags[0] = pair[0] != previous
            np.not_equal(pair[1:], pair[:-1], out=flags[1:])
            previous = pair[-1]
        yield
        runs = np.flatnonzero(starts_edge[:count])
        face_mask = (1 << face_bits) - 1
        firsts = keys[runs]
        first_face = (firsts & face_mask).astype(ids)
        firsts >>= face_bits
        high = (firsts & ((1 << vertex_bits) - 1)).astype(ids)
        firsts >>= vertex_bits
        firsts += first
        low = firsts.astype(ids)
        del firsts
        second_face = np.full(runs.size, -1, dtype=ids)
        shared = ~starts_edge[runs + 1]
        second_face[shared] = keys[runs[shared] + 1] & face_mask
        return low, high, first_face, second_face

    def both_ways(self, values: np.ndarray) -> np.ndarray:
        """Per-edge ``values`` listed per entry (each edge's value at both of its entries)."""
        return np.take(values, self.edge)

    def vertex_maximum(self, values: np.ndarray) -> np.ndarray:
        """For each vertex, the largest of the (non-negative) ``values`` of its edges; 0 for a
        vertex with no edge."""
        n = self.starts.size - 1
        out = np.zeros(n)
        for first in range(0, n, STEP):
            last = min(n, first + STEP)
            lo, hi = int(self.starts[first]), int(self.starts[last])
            if hi == lo:
                continue
            rows = self.starts[first:last] - lo
            nonempty = self.starts[first + 1 : last + 1] > self.starts[first:last]
            gathered = np.take(values, self.edge[lo:hi])
            out[first:last][nonempty] = np.maximum.reduceat(gathered, rows[nonempty])
        np.maximum(out, 0.0, out=out)
        return out

    def _lengths(self, points, block):
        # As sqrt(einsum('ij,ij->i', d, d)) of the whole mesh's offsets: the same bits by block.
        out = np.empty(self.low.size)
        for first in range(0, out.size, block):
            rows = slice(first, first + block)
            offsets = np.take(points, self.low[rows], axis=0)
            offsets -= np.take(points, self.high[rows], axis=0)
            np.sqrt(np.einsum("ij,ij->i", offsets, offsets), out=out[rows])
            yield
        return out

    def _bends(self, points, triangles, block):
        normals = yield from _unit_face_normals(points, triangles, block)
        out = np.zeros(self.low.size)
        shared = np.flatnonzero(self.second_face >= 0)
        for first in range(0, shared.size, block):
            rows = shared[first : first + block]
            one = np.take(normals, self.first_face[rows], axis=0)
            two = np.take(normals, self.second_face[rows], axis=0)
            cosine = np.einsum("ij,ij->i", one, two)
            out[rows] = np.arccos(np.clip(cosine, -1.0, 1.0))
            yield
        return out


def _unit_face_normals(points, triangles, block):
    """The faces' unit normals, shape (m, 3); zero for a face with no area (stepwise)."""
    out = np.zeros((triangles.shape[0], 3))
    for first in range(0, triangles.shape[0], block):
        rows = slice(first, first + block)
        block_normals = np.column_stack(face_normals(points, triangles[rows]))
        norm = np.linalg.norm(block_normals, axis=1)[:, None]
        np.divide(block_normals, norm, out=out[rows], where=norm > 0)
        yield
    return out


def _both_ways(n: int, low: np.ndarray, high: np.ndarray, block: int):
    """``starts``, ``target`` and ``edge`` of the CSR listing of the edges ``low``-``high``
    (sorted by ``(low, high)``): each vertex's neighbours above it, then those below it."""
    k = low.size
    ids = _index_type(k)
    below = np.bincount(high, minlength=n)  # entries of each vertex to lower neighbours
    above = np.bincount(low, minlength=n)
    starts = np.zeros(n + 1, dtype=np.int64)
    np.cumsum(above, out=starts[1:])
    starts[1:] += np.cumsum(below)
    target = np.empty(2 * k, dtype=np.int64)
    edge = np.empty(2 * k, dtype=ids)
    # The edges to higher neighbours come sorted by low: edge i sits at its rank in that run.
    shift = starts[:-1] - (np.cumsum(above) - above)
    for first in range(0, k, block):
        rows = np.arange(first, min(k, first + block), dtype=np.int64)
        at = rows + shift[low[rows]]
        edge[at] = rows
        target[at] = high[rows]
        yield
    # The edges to lower neighbours, grouped by high in edge order (a sort of packed keys).
    edge_bits = _bits(k)
    by_high = high.astype(np.int64) << edge_bits
    by_high |= np.arange(k, dtype=np.int64)
    by_high.sort()
    shift = starts[:-1] + above - (np.cumsum(below) - below)
    yield
    for first in range(0, k, block):
        packed = by_high[first : first + block]
        rows = packed & ((1 << edge_bits) - 1)
        at = np.arange(first, first + packed.size, dtype=np.int64) + shift[packed >> edge_bits]
        edge[at] = rows
        target[at] = low[rows]
        yield
    return starts, target, edge
