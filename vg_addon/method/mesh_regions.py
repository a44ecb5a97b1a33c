"""Vectorised walks over a mesh's vertex graph: connected parts and flooding labels outwards.

Both work on the compressed sparse row form of :class:`~vg_addon.method.edge_profile.RidgeGraph`
(``starts``, ``target``): every step is a handful of whole-array NumPy operations, never a
Python loop over vertices.
"""

from __future__ import annotations

import numpy as np

from .ranges import expand_ranges
from .stepping import STEP, finish


def _row_minimum(starts, target, values: np.ndarray, rows: np.ndarray, empty) -> np.ndarray:
    """The least of ``values`` over the neighbours of each of ``rows`` (``empty`` if none)."""
    counts = starts[rows + 1] - starts[rows]
    out = np.full(rows.size, empty, dtype=values.dtype)
    nonzero = counts > 0
    if nonzero.any():
        gathered = values[target[expand_ranges(starts[rows[nonzero]], counts[nonzero])]]
        firsts = np.cumsum(counts[nonzero]) - counts[nonzero]
        out[nonzero] = np.minimum.reduceat(gathered, firsts)
    return out


def connected_parts(starts: np.ndarray, target: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """Label the connected parts of the vertices in ``mask`` (edges between two of them).

    Parameters
    ----------
    starts, target : ndarray of int64
        The graph in CSR form: the neighbours of ``v`` are ``target[starts[v]:starts[v + 1]]``.
    mask : ndarray of bool, shape (n,)

    Returns
    -------
    ndarray of int64, shape (n,)
        For each vertex in ``mask`` the smallest vertex index of its part; -1 elsewhere.
    """
    return finish(connected_part_steps(starts, target, mask))


def connected_part_steps(starts, target, mask: np.ndarray, block: int = STEP):
    """:func:`connected_parts` in steps (see :mod:`.stepping`): yields after each block of
    ``block`` vertices and each round."""
    ends = []
    for first in range(0, mask.size, block):
        members = np.flatnonzero(mask[first : first + block]) + first
        counts = starts[members + 1] - starts[members]
        sources = np.repeat(members, counts)
        neighbours = target[expand_ranges(starts[members], counts)]
        once = mask[neighbours] & (sources < neighbours)  # each edge once: hooking takes both
        ends.append((sources[once], neighbours[once]))
        yield
    sources, neighbours = (np.concatenate(column) for column in zip(*ends, strict=True))
    del ends
    labels = yield from edge_component_steps(mask.size, sources, neighbours)
    labels[~mask] = -1
    return labels


def edge_components(n: int, sources: np.ndarray, targets: np.ndarray) -> np.ndarray:
    """The connected parts of the graph on ``n`` vertices with the edges ``sources[k]``,
    ``targets[k]``: for each vertex the smallest vertex index of its part (itself if alone).

    Min-label propagation with pointer jumping (each vertex's label is a vertex index, so
    ``label[label]`` jumps ahead along chains of labels): rounds grow like the logarithm of a
    part's diameter on meshes whose vertices are numbered in any spatially coherent order.
    """
    return finish(edge_component_steps(n, sources, targets))


def edge_component_steps(n: int, sources: np.ndarray, targets: np.ndarray):
    """:func:`edge_components` in steps (see :mod:`.stepping`): yields after each hooking and
    each jumping, returns the labels."""
    label = np.arange(n, dtype=np.int64)
    touched = np.zeros(n, dtype=bool)
    touched[sources] = True
    touched[targets] = True
    touched = np.flatnonzero(touched)
    while True:
        before = label[touched].copy()
        # Hook: each vertex, and the root its label names, take the least label next to it.
        offered = np.minimum(label[sources], label[targets])
        np.minimum.at(label, label[sources], offered)
        np.minimum.at(label, label[targets], offered)
        np.minimum.at(label, sources, offered)
        np.minimum.at(label, targets, offered)
        del offered
        yield
        jump_to_roots(label, touched)
        yield
        if np.array_equal(before, label[touched]):
            return label


def jump_to_roots(label: np.ndarray, active: np.ndarray) -> None:
    """Follow the labels of the vertices ``active`` to their roots (a root is its own label), in
    place, by pointer jumping. A vertex whose label names a root keeps it (roots do not move
    while jumping), so only the others are looked at again."""
    while active.size:
        current = label[active]
        jumped = label[current]
        moved = jumped != current
        active = active[moved]
        label[active] = jumped[moved]


def flood_labels(
    starts: np.ndarray,
    target: np.ndarray,
    labels: np.ndarray,
    mask: np.ndarray,
    heights: np.ndarray | None = None,
    levels: int = 24,
) -> np.ndarray:
    """Spread ``labels`` (-1 = none) into the unlabelled vertices of ``mask``, ring by ring.

    Each round, an unlabelled vertex of ``mask`` with a labelled neighbour takes the least of its
    neighbours' labels; rounds go on until no such vertex is left. With ``heights``, the flood
    rises like water (a watershed): first into the lowest ``1/levels`` of the unlabelled
    vertices, then the next, so that floods from two sides of a ridge meet on its crest.

    Returns
    -------
    ndarray of int64
        A copy of ``labels`` with the flooded vertices filled in.
    """
    labels = labels.astype(np.int64, copy=True)
    pending = np.flatnonzero(mask & (labels < 0))
    big = np.iinfo(np.int64).max
    keyed = np.where(labels < 0, big, labels)
    if heights is None or pending.size == 0:
        ceilings = [np.inf]
    else:
        ceilings = [*np.quantile(heights[pending], np.arange(1, levels) / levels), np.inf]
    for ceiling in ceilings:
        while pending.size:
            low = pending if ceiling == np.inf else pending[heights[pending] <= ceiling]
            offered = _row_minimum(starts, target, keyed, low, big)
            reached = offered < big
            if not reached.any():
                break
            labels[low[reached]] = offered[reached]
            keyed[low[reached]] = offered[reached]
            pending = pending[keyed[pending] == big]
    return labels


def sorted_unique(values: np.ndarray) -> np.ndarray:
    """``np.unique(values)`` of an integer array by one sort (NumPy 2's hashing ``np.unique`` is
    several times slower on millions of distinct values)."""
    values = np.sort(values)
    if values.size > 1:
        values = values[np.concatenate(([True], values[1:] != values[:-1]))]
    return values


def dilate(starts: np.ndarray, target: np.ndarray, mask: np.ndarray, rings: int) -> np.ndarray:
    """``mask`` grown by ``rings`` rings of neighbours."""
    grown = mask.copy()
    frontier = np.flatnonzero(mask)
    for _ in range(rings):
        if frontier.size == 0:  # nothing left to grow into: more rings change nothing
            break
        counts = starts[frontier + 1] - starts[frontier]
        reached = target[expand_ranges(starts[frontier], counts)]
        reached = reached[~grown[reached]]
        grown[reached] = True
        frontier = sorted_unique(reached)
    return grown
