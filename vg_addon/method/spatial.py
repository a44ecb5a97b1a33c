"""A uniform-grid spatial index for ball queries, built once per surface."""

from __future__ import annotations

import math

import numpy as np

from ..errors import GoniometerError
from .ranges import expand_ranges

_MAX_CELLS_PER_AXIS = 1 << 20


def bounds(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``points.min(axis=0)`` and ``points.max(axis=0)`` of finite (n, 3) points, faster.

    One column at a time is several times faster than the row-wise reduction; the values are the
    same, except possibly the sign of a zero, so a zero bound is taken from the row-wise one.
    """
    low = np.array([points[:, axis].min() for axis in range(3)])
    high = np.array([points[:, axis].max() for axis in range(3)])
    if not low.all():
        low = points.min(axis=0)
    if not high.all():
        high = points.max(axis=0)
    return low, high


def estimate_spacing(points: np.ndarray) -> float:
    """Typical distance between neighbouring points of a sampled surface (or volume).

    Counts the occupied cells of a grid coarse enough to hold several points per cell: a surface
    of area A sampled by n points at spacing h occupies about A / c^2 cells of size c, so
    h ~ c * sqrt(occupied / n).
    """
    if points.shape[0] > 200_000:  # a subsample estimates the same density faster
        stride = points.shape[0] // 100_000
        return estimate_spacing(points[_sample_by_position(points, stride)]) / np.sqrt(stride)
    points = bulk(points)
    n = points.shape[0]
    origin, top = bounds(points)
    extent = float((top - origin).max())
    if n < 2 or extent == 0.0:
        return max(extent, 1.0)
    cell = extent / 128.0
    while True:
        ijk = np.floor((points - origin) / cell).astype(np.int64)
        side = int(ijk.max()) + 1
        keys = np.sort((ijk[:, 0] * side + ijk[:, 1]) * side + ijk[:, 2])
        # np.unique(keys).size, without NumPy 2's hashing (slow on such structured keys)
        occupied = 1 + int(np.count_nonzero(keys[1:] != keys[:-1]))
        if occupied <= n / 4 or cell >= extent:
            return cell * float(np.sqrt(occupied / n))
        cell *= 2.0


BULK_QUANTILE = 0.01
"""The bulk of a point set lies between this quantile of each coordinate and its complement."""


def bulk(points: np.ndarray) -> np.ndarray:
    """``points`` without those far outside their bulk: the box between the 1% and 99% quantile
    of each coordinate, widened on every side by its longest side. The same array where no
    point lies outside (a scan without stray points), and at least the box's own points.

    A stray point far from the rest (a speck of debris, a coordinate gone wrong) once set the
    extent that the spacing estimate's grid starts from: 1,000 times the object's size away it
    made the estimate 5 times too large, and a point cloud's normals then pooled whole regions
    (a 45,000-point cloud took 25 s, and with the point 100,000 away ran out of memory)."""
    low = np.quantile(points, BULK_QUANTILE, axis=0, method="lower")
    high = np.quantile(points, 1.0 - BULK_QUANTILE, axis=0, method="higher")
    pad = float((high - low).max())
    inside = ((points >= low - pad) & (points <= high + pad)).all(axis=1)
    return points if inside.all() else points[inside]


def _sample_by_position(points: np.ndarray, stride: int) -> np.ndarray:
    """About one point in ``stride``, chosen by a hash of its coordinates: the same points
    whatever order they come in."""
    bits = np.ascontiguousarray(points, dtype=np.float64).view(np.uint64)
    mixed = (
        bits[:, 0] * np.uint64(0x9E3779B97F4A7C15)
        ^ bits[:, 1] * np.uint64(0xC2B2AE3D27D4EB4F)
        ^ bits[:, 2] * np.uint64(0x165667B19E3779F9)
    )
    return (mixed >> np.uint64(33)) % np.uint64(stride) == 0


def _cell_within(position: float, top: int) -> int:
    """``floor(position)`` clamped to the cells 0 to ``top`` (``position`` may be infinite)."""
    if position <= 0:
        return 0
    if position >= top:
        return top
    return math.floor(position)


class GridIndex:
    """Points sorted by the cell of a uniform grid they fall in, for fast ball queries.

    The index is built once (a sort of the cell keys); a query visits only the grid columns that
    overlap the ball's bounding box, so its cost depends on the size of the answer, not of the mesh.

    Parameters
    ----------
    points : ndarray, shape (n, 3)
        Finite float64 coordinates.
    cell_size : float, optional
        Grid cell edge; default twice the estimated point spacing.
    ids : ndarray of int64, shape (n,), optional
        What a query returns for each point (default ``arange(n)``): lets a caller index a subset.
    """

    def __init__(self, points: np.ndarray, cell_size: float | None = None, ids=None):
        points = np.asarray(points, dtype=np.float64)
        if points.ndim != 2 or points.shape[1] != 3 or points.shape[0] == 0:
            raise GoniometerError("A spatial index needs a non-empty (n, 3) array of points.")
        self.origin, top = bounds(points)
        extent = top - self.origin
        if cell_size is None:
            cell_size = 2.0 * estimate_spacing(points)
        cell_size = max(float(cell_size), float(extent.max()) / _MAX_CELLS_PER_AXIS, 1e-300)
        self.cell_size = cell_size
        self.dims = (np.floor(extent / cell_size).astype(np.int64) + 1).astype(np.int64)
        self._top = tuple(int(d) - 1 for d in self.dims)
        # The key (i * dims[1] + j) * dims[2] + k of each point's cell, one axis at a time:
        # what _cells gives, without (n, 3) temporaries.
        keys = np.zeros(points.shape[0], dtype=np.int64)
        for axis in range(3):
            scaled = points[:, axis] - self.origin[axis]
            scaled /= self.cell_size
            cell = np.floor(scaled, out=scaled).astype(np.int64)
            del scaled
            keys *= self.dims[axis]
            keys += np.clip(cell, 0, self._top[axis], out=cell)
        order = np.argsort(keys, kind="stable")
        self.keys = keys[order]
        del keys
        self.points = np.ascontiguousarray(points[order])
        self.ids = order if ids is None else np.asarray(ids)[order]

    def _cells(self, coordinates: np.ndarray) -> np.ndarray:
        scaled = coordinates - self.origin
        scaled /= self.cell_size
        ijk = np.floor(scaled, out=scaled).astype(np.int64)
        return np.clip(ijk, 0, self.dims - 1, out=ijk)

    def _candidates(self, center, radius: float) -> np.ndarray:
        """Positions (into the sorted arrays) of the points in the cells the ball's box overlaps."""
        # Plain float arithmetic: the same IEEE operations as NumPy's on 3-vectors, without the
        # per-call overhead of tiny arrays.
        # Cell coordinates stay floats until clamped: a centre 1e308 away is +inf cells away,
        # beyond the grid, not an integer overflow.
        size = self.cell_size
        low, high = [], []
        for axis in range(3):
            c, o, top = float(center[axis]), float(self.origin[axis]), self._top[axis]
            lo = (c - radius - o) / size if math.isfinite(radius) else -math.inf
            hi = (c + radius - o) / size if math.isfinite(radius) else math.inf
            if hi < 0 or lo >= top + 1:  # floor(hi) < 0 or floor(lo) > top
                return np.empty(0, dtype=np.int64)
            low.append(_cell_within(lo, top))
            high.append(_cell_within(hi, top))
        ix = np.arange(low[0], high[0] + 1, dtype=np.int64)
        iy = np.arange(low[1], high[1] + 1, dtype=np.int64)
        column = ((ix[:, None] * self.dims[1] + iy[None, :]) * self.dims[2]).ravel()
        starts = np.searchsorted(self.keys, column + low[2], side="left")
        ends = np.searchsorted(self.keys, column + high[2], side="right")
        return expand_ranges(starts, ends - starts)

    def ball(self, center, radius: float) -> tuple[np.ndarray, np.ndarray]:
        """Ids of the points within ``radius`` of ``center`` (boundary included), and their distances."""
        center = np.asarray(center, dtype=np.float64)
        positions = self._candidates(center, radius)
        offsets = np.take(self.points, positions, axis=0)  # faster than fancy indexing
        offsets -= center
        squared = np.einsum("ij,ij->i", offsets, offsets)
        inside = squared <= radius * radius
        return self.ids[positions[inside]], np.sqrt(squared[inside])

    def nearest(self, center, max_distance: float) -> tuple[int, float]:
        """Id of the point nearest ``center`` within ``max_distance``, or ``(-1, inf)`` if none.

        Ties are broken by coordinates, so the answer does not depend on the points' order.
        """
        center = np.asarray(center, dtype=np.float64)
        radius = min(self.cell_size, max_distance)
        while True:
            positions = self._candidates(center, radius)
            if positions.size:
                offsets = np.take(self.points, positions, axis=0)
                offsets -= center
                squared = np.einsum("ij,ij->i", offsets, offsets)
                inside = squared <= radius * radius
                if inside.any():
                    best = self._closest(positions[inside], squared[inside])
                    return int(self.ids[best[0]]), best[1]
            if radius >= max_distance:
                return -1, float("inf")
            radius = min(radius * 4.0, max_distance)

    def _closest(self, positions: np.ndarray, squared: np.ndarray) -> tuple[int, float]:
        """The position with the smallest squared distance (ties broken by x, y, z), and its
        distance."""
        smallest = squared.min()
        tied = np.flatnonzero(squared == smallest)
        best = tied[0]
        if tied.size > 1:
            coords = self.points[positions[tied]]
            best = tied[np.lexsort((coords[:, 2], coords[:, 1], coords[:, 0]))[0]]
        return int(positions[best]), math.sqrt(float(smallest))


def neighbour_pairs(index: GridIndex, radius: float, chunk: int = 20_000):
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
