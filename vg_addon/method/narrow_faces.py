"""Faces narrower than the scale: recovered from the band with the fine bend field.

The coarse bend field judges each vertex over a patch about ``1.5 × scale`` wide, so a vertex
counts as ridge while any part of its patch reaches over a crease: the band round a crease is
about ``2 × scale`` wide, and a face narrower than that between two creases (the 5 mm wall of a
bone shaft meshed at 0.8 mm, the platform of a small flake) is band from rim to rim. The fine
field (two rings) sees the same face as flat a few edges in from each rim. Each connected part
of band vertices that the fine field calls flat and that touches no region becomes a region of
its own if it is large enough (a swallowed face). A flat part touching a region is left in the
band: it is that region's margin beside its crease, or a rounded edge, and joining it would move
where the floods of two regions meet (off the middle of a rounded edge on a noisy scan).

Everything is vectorised over vertices; see :mod:`.break_edges` for the method as a whole.
"""

from __future__ import annotations

import numpy as np

from .mesh_regions import connected_parts
from .ranges import expand_ranges


def flat_band(fine_spread, fine_second, rows, floor: float, corner_floor: float) -> np.ndarray:
    """The vertices of ``rows`` that the fine field calls flat: neither its crease part nor its
    corner part reaches its bar (``floor``, ``corner_floor``)."""
    flat = np.zeros(fine_spread.size, dtype=bool)
    flat[rows] = (fine_spread[rows] < floor) & (fine_second[rows] < corner_floor)
    return flat


def recovered_regions(graph, region, flat, areas, min_new_area: float) -> np.ndarray:
    """``region`` with each flat part of the band that touches no region made a region of its
    own if at least ``min_new_area``; renumbered by area, largest first (ties by their least
    vertex), -1 left on the band.

    Parameters
    ----------
    graph : RidgeGraph
    region : ndarray of int, shape (n,)
        The smooth regions, -1 on the band.
    flat : ndarray of bool, shape (n,)
        Band vertices the fine field calls flat (see :func:`flat_band`).
    areas : ndarray, shape (n,)
        Each vertex's share of the surface.
    min_new_area : float
        A flat part must be this large to become a region.
    """
    flat = flat & (region < 0)
    out = region.astype(np.int64, copy=True)
    if not flat.any():
        return out
    parts = connected_parts(graph.starts, graph.target, flat)
    members = np.flatnonzero(flat)
    roots, part_of = np.unique(parts[members], return_inverse=True)
    counts = graph.starts[members + 1] - graph.starts[members]
    neighbour = graph.target[expand_ranges(graph.starts[members], counts)]
    touching = np.repeat(part_of, counts)
    touches = np.zeros(roots.size, dtype=bool)
    touches[touching[out[neighbour] >= 0]] = True
    part_area = np.bincount(part_of, areas[members], minlength=roots.size)
    alone = np.flatnonzero(~touches & (part_area >= min_new_area))
    number = np.full(roots.size, -1, dtype=np.int64)
    number[alone] = int(out.max()) + 1 + np.arange(alone.size)
    out[members] = number[part_of]
    return _by_area(out, areas)


def _by_area(region: np.ndarray, areas: np.ndarray) -> np.ndarray:
    """Regions renumbered by area, largest first, ties by their least vertex."""
    inside = region >= 0
    if not inside.any():
        return region
    count = int(region.max()) + 1
    area = np.bincount(region[inside], areas[inside], minlength=count)
    least = np.full(count, region.size, dtype=np.int64)
    np.minimum.at(least, region[inside], np.flatnonzero(inside))
    present = least < region.size
    order = np.lexsort((least, -area))
    order = order[present[order]]
    number = np.full(count, -1, dtype=np.int64)
    number[order] = np.arange(order.size)
    out = np.full(region.size, -1, dtype=np.int64)
    out[inside] = number[region[inside]]
    return out
