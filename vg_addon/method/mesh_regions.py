"""Vectorised walks over a mesh's vertex graph: connected parts and flooding labels outwards.

Both work on the compressed sparse row form of :class:`~vg_addon.method.edge_profile.RidgeGraph`
(``starts``, ``target``): every step is a handful of whole-array NumPy operations, never a
Python loop over vertices.
"""

from __future__ import annotations

import numpy as np

from .ranges import expand_ranges


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

    Notes
    -----
    Min-label propagation with pointer jumping (each vertex's label is a vertex index, so
    ``label[label]`` jumps ahead along chains of labels): rounds grow like the logarithm of a
    part's diameter on meshes whose vertices are numbered in any spatially coherent order.
    """
    n = mask.size
    members = np.flatnonzero(mask)
    label = np.full(n, -1, dtype=np.int64)
    label[members] = members
    # Each member's neighbours inside the mask, once: the edges propagation runs over.
    counts = starts[members + 1] - starts[members]
    edges = expand_ranges(starts[members], counts)
    sources = np.repeat(members, counts)
    neighbours = target[edges]
    inside = mask[neighbours]
    sources, neighbours = sources[inside], neighbours[inside]
    while True:
        before = label[members].copy()
        # Hook: each vertex, and the root its label names, take the least label next to it.
        offered = label[neighbours]
        np.minimum.at(label, label[sources], offered)
        np.minimum.at(label, sources, offered)
        # Jump: follow labels to their root.
        while True:
            jumped = label[label[members]]
            if np.array_equal(jumped, label[members]):
                break
            label[members] = jumped
        if np.array_equal(before, label[members]):
            break
    out = np.full(n, -1, dtype=np.int64)
    out[members] = label[members]
    return out


def flood_labels(starts: np.ndarray, target: np.ndarray, labels: np.ndarray, mask: np.ndarray):
    """Spread ``labels`` (-1 = none) into the unlabelled vertices of ``mask``, ring by ring.

    Each round, an unlabelled vertex of ``mask`` with a labelled neighbour takes the least of its
    neighbours' labels; rounds go on until no such vertex is left.

    Returns
    -------
    ndarray of int64
        A copy of ``labels`` with the flooded vertices filled in.
    """
    labels = labels.astype(np.int64, copy=True)
    pending = np.flatnonzero(mask & (labels < 0))
    big = np.iinfo(np.int64).max
    keyed = np.where(labels < 0, big, labels)
    while pending.size:
        offered = _row_minimum(starts, target, keyed, pending, big)
        reached = offered < big
        if not reached.any():
            break
        labels[pending[reached]] = offered[reached]
        keyed[pending[reached]] = offered[reached]
        pending = pending[~reached]
    return labels
