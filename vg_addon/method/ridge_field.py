"""How much the surface bends around each vertex, judged over a neighbourhood: the spread of
the face normals near it.

Around each vertex the area-weighted face normals within a few rings are pooled: their mean
``m`` and second moment ``T``, whose difference ``C = T - m mᵀ`` is the normals' covariance. Where
two flat faces with normals ``n1``, ``n2`` meet at a bend ``β`` (180° minus the interior angle)
and share the neighbourhood in proportions ``w`` and ``1 - w``, ``C`` has the single large
eigenvalue ``4 w (1 - w) sin²(β / 2)``: ``sin²(β / 2)`` on the crease itself (``w = 1/2``) for any
bend up to 180°, less off it, nothing on a flat face. Scan noise spreads the normals equally in
every direction along the surface and adds the same amount to both eigenvalues in the tangent
plane, so the *anisotropy* ``λ1 - λ2`` keeps only the bend; a gently curved surface (a bone's
cylinder) spreads its normals by the neighbourhood's size over its radius, which is small.

``λ1 - λ2`` is computed from the invariants of ``C`` (``sqrt(tr² - 4 · minors)``, exact when
``λ3 = 0`` and close otherwise): additions, products and square roots only, so the field is the
same on every machine.
"""

from __future__ import annotations

import math

import numpy as np

from .fixed_order import rows_dot
from .mesh_regions import dilate, edge_component_steps, sorted_unique
from .normals import face_normals
from .ranges import expand_ranges
from .stepping import STEP

_COLUMNS = 10  # area, area·n (3), area·n nᵀ (6: xx, yy, zz, xy, xz, yz)


def rings_for(scale: float, mean_edge_length: float) -> int:
    """Rings of neighbours pooled for a neighbourhood of radius ``scale`` (1 to 12)."""
    if mean_edge_length <= 0:
        return 1
    return int(min(12, max(1, round(scale / mean_edge_length))))


def _moments(weight, nx, ny, nz) -> tuple:
    """The ten columns: weight, weight·n, weight·n nᵀ (xx, yy, zz, xy, xz, yz)."""
    first = (weight, weight * nx, weight * ny, weight * nz)
    return (
        *first,
        first[1] * nx,
        first[2] * ny,
        first[3] * nz,
        first[1] * ny,
        first[1] * nz,
        first[2] * nz,
    )


def vertex_moments(points, triangles, starts, target, smoothing: int = 1, block: int = STEP):
    """Per vertex, its area (a third of its faces') and the moments of its *smoothed* normal
    (``(n, 10)``): what :func:`ring_spread` and :func:`cell_spread` pool.

    The smoothed normal is the mean face normal within ``smoothing`` rings: a single face's
    normal carries the scan's noise at full strength, and on a regular grid that noise is
    spread unevenly between directions (it would read as a crease); averaged over a ring or
    two it is a few times weaker, while a crease stays a crease.

    Stepwise (see :mod:`.stepping`): yields between blocks of ``block`` faces or vertices and
    returns the moments; the numbers do not depend on ``block``.
    """
    m, n = triangles.shape[0], points.shape[0]
    nx, ny, nz = (np.empty(m) for _ in range(3))
    for first in range(0, m, block):
        rows = slice(first, first + block)
        nx[rows], ny[rows], nz[rows] = face_normals(points, triangles[rows])
        yield
    doubled = np.sqrt(nx * nx + ny * ny + nz * nz)
    corners = triangles.reshape(-1)
    # Face normals of length twice the area: their sum over a vertex's faces is area-weighted.
    normals = np.empty((n, 3))
    for column, values in enumerate((nx, ny, nz)):
        normals[:, column] = np.bincount(corners, np.repeat(values, 3), minlength=n)
        yield
    area = np.bincount(corners, np.repeat(doubled, 3), minlength=n) / 6.0
    del nx, ny, nz, doubled
    yield
    for _ in range(smoothing):
        normals = yield from _pool(starts, target, normals, block)
    out = np.empty((n, _COLUMNS))
    for first in range(0, n, block):
        rows = slice(first, first + block)
        part = normals[rows]
        length = np.sqrt(rows_dot(part, part))
        part /= np.where(length > 0, length, 1.0)[:, None]
        weight = area[rows]
        weight[length <= 0] = 0.0
        out[rows] = np.column_stack(_moments(weight, part[:, 0], part[:, 1], part[:, 2]))
        yield
    return out


def _pool(starts: np.ndarray, target: np.ndarray, values: np.ndarray, block: int):
    """Each vertex's values plus its neighbours' (one ring of pooling), stepwise."""
    out = values.copy()
    n = values.shape[0]
    for first in range(0, n, block):
        last = min(n, first + block)
        lo, hi = int(starts[first]), int(starts[last])
        if hi == lo:
            continue
        gathered = np.take(values, target[lo:hi], axis=0)
        rows = starts[first:last] - lo
        nonempty = starts[first + 1 : last + 1] > starts[first:last]
        sums = np.add.reduceat(gathered, rows[nonempty], axis=0)
        out[first:last][nonempty] += sums
        yield
    return out


def spread_of(sums: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Of pooled :func:`vertex_moments` sums: the crease part ``λ1 - λ2`` and the trace of the normals' covariance, from pooled sums."""
    weight = sums[:, 0]
    safe = np.where(weight > 0, weight, 1.0)
    m = sums[:, 1:4] / safe[:, None]
    t = sums[:, 4:10] / safe[:, None]
    cxx = t[:, 0] - m[:, 0] * m[:, 0]
    cyy = t[:, 1] - m[:, 1] * m[:, 1]
    czz = t[:, 2] - m[:, 2] * m[:, 2]
    cxy = t[:, 3] - m[:, 0] * m[:, 1]
    cxz = t[:, 4] - m[:, 0] * m[:, 2]
    cyz = t[:, 5] - m[:, 1] * m[:, 2]
    trace = cxx + cyy + czz
    minors = (cxx * cyy - cxy * cxy) + (cxx * czz - cxz * cxz) + (cyy * czz - cyz * cyz)
    crease = np.sqrt(np.maximum(trace * trace - 4.0 * minors, 0.0))
    crease[weight <= 0] = 0.0
    trace[weight <= 0] = 0.0
    return crease, np.maximum(trace, 0.0)


def pooled_at(starts, target, values: np.ndarray, rings: int, rows: np.ndarray) -> np.ndarray:
    """``values`` pooled ``rings`` rings of neighbours deep (each ring: a vertex's values plus
    its neighbours'), worked out only where needed for the vertices ``rows``; the result is
    full-size and zero elsewhere."""
    wanted = np.zeros(values.shape[0], dtype=bool)
    wanted[rows] = True
    levels = [wanted]
    for _ in range(rings - 1):
        levels.append(dilate(starts, target, levels[-1], 1))
    current = values
    for level in reversed(levels):
        at = np.flatnonzero(level)
        counts = starts[at + 1] - starts[at]
        out = np.zeros_like(values)
        out[at] = current[at]
        nonempty = counts > 0
        gathered = np.take(current, target[expand_ranges(starts[at], counts)], axis=0)
        firsts = (np.cumsum(counts) - counts)[nonempty]
        if firsts.size:
            out[at[nonempty]] += np.add.reduceat(gathered, firsts, axis=0)
        current = out
    return current


def ring_spread(sums: np.ndarray, starts, target, rings: int, rows: np.ndarray):
    """The spread of the normals pooled ``rings`` rings of neighbours around each of the
    vertices ``rows`` (a neighbourhood a few edges wide, weighted towards the vertex: it
    locates crests); full-size arrays, zero elsewhere.

    Parameters
    ----------
    sums : ndarray, shape (n, 10)
        :func:`vertex_moments`.
    starts, target : ndarray of int64
        The vertex graph in CSR form (``RidgeGraph.starts`` and ``.target``).
    rings : int
    rows : ndarray of int64
        The vertices wanted.

    Returns
    -------
    crease, total : ndarray, shape (n,)
        The crease part ``λ1 - λ2`` (``sin²(β/2)`` on a crease of bend ``β``, 0 where flat; see
        the module's text) and the trace ``λ1 + λ2 + λ3`` (large on creases and corners alike:
        where three faces meet, ``λ1 ≈ λ2``); in [0, 1], 0 for a vertex with no faces.
    """
    pooled = pooled_at(starts, target, sums, rings, rows)[rows]
    crease, total = np.zeros(sums.shape[0]), np.zeros(sums.shape[0])
    crease[rows], total[rows] = spread_of(pooled)  # row by row: the same as on every vertex
    return crease, total


def cell_spread(points, sums, scale: float, starts, target, block: int = STEP):
    """The spread of the normals over a patch about ``1.5 * scale`` wide around each vertex.

    The mesh is cut into *cells*: the connected pieces of the surface inside each cube of a grid
    of step ``scale / 2`` (the two sides of a thin flake in one cube are two cells, being
    joined only through other cubes). Each vertex reads its cell's sums pooled with those of
    the cells next to it along the mesh: a patch of about three cubes across, which the cost
    does not grow with, and which never reaches through a thin part to its other side. Every
    vertex of a cell reads the same value.

    Stepwise (see :mod:`.stepping`): yields between chunks of work (blocks of ``block``
    vertices, rounds) and returns ``(crease, total)`` as :func:`ring_spread` does; ``sums`` is
    :func:`vertex_moments`.
    """
    n = points.shape[0]
    cells = np.floor((points - points.min(axis=0)) / (scale / 2.0)).astype(np.int64)
    dims = cells.max(axis=0) + 1
    cube = (cells[:, 0] * dims[1] + cells[:, 1]) * dims[2] + cells[:, 2]
    del cells
    degree = np.diff(starts)
    inside = np.empty(target.size, dtype=bool)  # both ends in one cube
    ends = []
    for first in range(0, n, block):
        last = min(n, first + block)
        lo, hi = int(starts[first]), int(starts[last])
        sources = np.repeat(np.arange(first, last, dtype=np.int64), degree[first:last])
        targets = target[lo:hi]
        inside[lo:hi] = cube[sources] == cube[targets]
        once = inside[lo:hi] & (sources < targets)  # each edge once: the hooking takes both
        ends.append((sources[once], targets[once]))
        yield
    del cube
    sources, targets = (np.concatenate(column) for column in zip(*ends, strict=True))
    del ends
    root = yield from edge_component_steps(n, sources, targets)
    del sources, targets
    # Cells numbered in the order of their least vertex (each part's label, the root).
    number = np.cumsum(root == np.arange(n)) - 1
    cell = number[root]
    del root, number
    count = int(cell.max()) + 1
    per_cell = np.empty((count, _COLUMNS))
    for column in range(_COLUMNS):
        per_cell[:, column] = np.bincount(cell, sums[:, column], minlength=count)
    yield
    pairs = []
    for first in range(0, n, block):
        last = min(n, first + block)
        lo, hi = int(starts[first]), int(starts[last])
        across = ~inside[lo:hi]
        near = cell[target[lo:hi][across]]
        pairs.append(np.repeat(cell[first:last], degree[first:last])[across] * count + near)
        yield
    del inside
    pairs = sorted_unique(np.concatenate(pairs))  # each pair of touching cells, both ways
    yield
    pooled = per_cell.copy()
    first, second = pairs // count, pairs % count
    for column in range(_COLUMNS):
        pooled[:, column] += np.bincount(first, per_cell[second, column], minlength=count)
    crease, total = spread_of(pooled)
    return crease[cell], total[cell]


def blurred(values: np.ndarray, starts, target, rings: int, rows: np.ndarray) -> np.ndarray:
    """``values`` averaged over ``rings`` rings of neighbours at the vertices ``rows`` (each
    ring a plain mean of a vertex and its neighbours; zero elsewhere): smooths the steps of a
    field that is constant per cell."""
    pair = pooled_at(starts, target, np.column_stack([values, np.ones(values.size)]), rings, rows)
    return np.divide(pair[:, 0], pair[:, 1], out=np.zeros(values.size), where=pair[:, 1] > 0)


def anisotropy_of_bend(bend_deg: float) -> float:
    """The anisotropy a crease of ``bend_deg`` shows on itself: ``sin²(bend / 2)``."""
    return math.sin(math.radians(bend_deg) / 2.0) ** 2


def bend_of_anisotropy(spread: np.ndarray) -> np.ndarray:
    """The bend (degrees) a crease with this anisotropy on itself has: ``2 asin(sqrt(a))``."""
    clipped = np.clip(np.asarray(spread, dtype=np.float64), 0.0, 1.0)
    return np.degrees(2.0 * np.array([math.asin(math.sqrt(v)) for v in clipped.ravel()]))
