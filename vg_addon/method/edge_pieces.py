"""The steps of the break-edge finder between the bend field and the candidates: smooth regions,
the pieces of ridge between them, and tracing each piece as an :class:`EdgePath`.

See :mod:`.break_edges` for the method as a whole. Everything here is vectorised over vertices;
the loops run over regions, pieces and the legs of a path.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from ..errors import GoniometerError
from .edge_profile import EdgePath, assemble_path, trace_leg
from .fixed_order import eigh3, moments, norm3, row_dot, rows_dot, total
from .mesh_regions import connected_part_steps, connected_parts, dilate, sorted_unique
from .ranges import expand_ranges
from .stepping import STEP

MIN_OFF_RUN = 3
"""A traced leg that leaves the crest for this many consecutive vertices gets a via point."""

MAX_VIA_DEPTH = 8
"""How many times a leg may be split by via points (at most ``2**depth`` legs per stretch)."""


def smooth_regions(graph, used, band, areas, min_area, block: int = STEP):
    """The smooth regions: the connected parts of the vertices off the band.

    Parameters
    ----------
    graph : RidgeGraph
    used, band : ndarray of bool, shape (n,)
        Vertices that take part; those on a ridge.
    areas : ndarray, shape (n,)
        Each vertex's share of the surface.
    min_area : float
        Smooth parts smaller than this are no region.
    block : int, optional
        Vertices per step.

    Returns
    -------
    ndarray of int64, shape (n,)
        Region numbers (largest area first), -1 on the band and in small parts. Stepwise (see
        :mod:`.stepping`): a generator that yields between chunks of work and returns them.
    """
    smooth = used & ~band
    parts = yield from connected_part_steps(graph.starts, graph.target, smooth, block)
    # Each part is labelled by its least vertex, its root: parts numbered in the roots' order.
    is_root = smooth & (parts == np.arange(smooth.size))
    roots = np.flatnonzero(is_root)
    inverse = (np.cumsum(is_root) - 1)[parts[smooth]]
    part_area = np.bincount(inverse, areas[smooth], minlength=roots.size)
    big = part_area >= min_area
    order = np.lexsort((roots, -part_area))  # largest first, ties by their least vertex
    number = np.full(roots.size, -1, dtype=np.int64)
    kept = order[big[order]]
    number[kept] = np.arange(kept.size)
    region = np.full(used.size, -1, dtype=np.int64)
    region[smooth] = number[inverse]
    return region


@dataclass(frozen=True, eq=False)
class Piece:
    """A stretch of ridge to trace.

    Attributes
    ----------
    vertices : ndarray of int64
        The crest: where the floods of the two regions meet (vertices on both sides), or for a
        ridge inside one region its band vertices.
    regions : tuple of int
        The two regions it parts, or (-1, -1) inside one region.
    ends : ndarray of int64
        Its vertices where a third region or the mesh's border comes in (none on a loop).
    """

    vertices: np.ndarray
    regions: tuple
    ends: np.ndarray


def _local_graph(graph, vertices: np.ndarray, lookup: np.ndarray):
    """The CSR graph induced on ``vertices`` in local numbering (``lookup`` all -1, restored)."""
    lookup[vertices] = np.arange(vertices.size)
    try:
        counts = graph.starts[vertices + 1] - graph.starts[vertices]
        sources = np.repeat(np.arange(vertices.size), counts)
        targets = lookup[graph.target[expand_ranges(graph.starts[vertices], counts)]]
    finally:
        lookup[vertices] = -1
    inside = targets >= 0
    sources, targets = sources[inside], targets[inside]
    starts = np.zeros(vertices.size + 1, dtype=np.int64)
    np.cumsum(np.bincount(sources, minlength=vertices.size), out=starts[1:])
    return starts, targets


def split_parts(graph, vertices: np.ndarray, lookup: np.ndarray) -> list[np.ndarray]:
    """``vertices`` split into their connected parts (each sorted), largest first."""
    starts, targets = _local_graph(graph, vertices, lookup)
    parts = connected_parts(starts, targets, np.ones(vertices.size, dtype=bool))
    order = np.argsort(parts, kind="stable")
    cuts = np.flatnonzero(np.diff(parts[order])) + 1
    groups = [vertices[group] for group in np.split(order, cuts)]
    return sorted(groups, key=lambda g: (-g.size, int(g[0])))


def _rows(graph, vertices: np.ndarray):
    """(source, neighbour) for every edge leaving ``vertices``."""
    counts = graph.starts[vertices + 1] - graph.starts[vertices]
    return np.repeat(vertices, counts), graph.target[expand_ranges(graph.starts[vertices], counts)]


def ridge_pieces(graph, flooded, band, border, reach: int) -> list[Piece]:
    """The crests between two regions, split where a third region or the border comes in,
    and the ridges inside one region (band more than ``reach`` rings from every such crest)."""
    n = flooded.size
    lookup = np.full(n, -1, dtype=np.int64)
    a, b = np.repeat(flooded, np.diff(graph.starts)), flooded[graph.target]
    meet = (a >= 0) & (b >= 0) & (a != b)
    sources = np.searchsorted(graph.starts, np.flatnonzero(meet), side="right") - 1
    n_regions = int(flooded.max()) + 1
    pair = np.minimum(a[meet], b[meet]) * n_regions + np.maximum(a[meet], b[meet])
    keys = sorted_unique(pair * n + sources)
    pairs, vertices = keys // n, keys % n
    # A crest vertex that sees three labels (or none, past the mesh's valid part) is an end.
    crest = np.unique(vertices)
    own, neighbour = _rows(graph, crest)
    seen = np.unique(np.concatenate([crest * (n_regions + 1) + flooded[crest] + 1,
                                     own * (n_regions + 1) + flooded[neighbour] + 1]))  # fmt: skip
    owner, label = seen // (n_regions + 1), seen % (n_regions + 1) - 1
    junction = np.zeros(n, dtype=bool)
    junction[owner[label < 0]] = True
    counts = np.bincount(owner, minlength=n)
    junction |= counts >= 3
    junction |= border
    pieces = []
    cuts = np.flatnonzero(np.diff(pairs)) + 1
    for group_pairs, group in zip(np.split(pairs, cuts), np.split(vertices, cuts), strict=True):
        if group.size == 0:
            continue
        first, second = divmod(int(group_pairs[0]), n_regions)
        for part in split_parts(graph, group, lookup):
            pieces.append(Piece(part, (first, second), part[junction[part]]))
    explained = np.zeros(n, dtype=bool)
    explained[crest] = True
    loose = np.flatnonzero(band & ~dilate(graph.starts, graph.target, explained, reach))
    if loose.size:
        for part in split_parts(graph, loose, lookup):
            pieces.append(Piece(part, (-1, -1), part[:0]))
    return pieces


def _squared(offsets: np.ndarray) -> np.ndarray:
    """Squared lengths of rows, summed in a fixed order (the same bits on every machine)."""
    return rows_dot(offsets, offsets)


def _farthest(points: np.ndarray, origin: np.ndarray) -> int:
    offsets = points - origin
    return int(np.argmax(rows_dot(offsets, offsets)))


def piece_stops(points: np.ndarray, piece: Piece) -> tuple[list[int], bool]:
    """Vertices to trace ``piece`` through (start, ..., end) and whether it is a loop.

    An open piece runs between the two of its ends farthest apart (or, with one end or none,
    from the vertex farthest from its middle to the vertex farthest from that); a loop runs
    from its first vertex through the farthest one and back, by the vertices farthest to
    either side of that chord (in the loop's own plane).
    """
    vertices = piece.vertices
    where = points[vertices]
    if piece.ends.size == 0 and piece.regions[0] >= 0:
        start = int(vertices[0])
        far = int(vertices[_farthest(where, points[start])])
        _, axes = eigh3(moments(where - where.mean(axis=0)))
        across = np.cross(axes[:, 0], points[far] - points[start])
        side = row_dot(where - (points[start] + points[far]) / 2.0, across)
        left, right = int(vertices[np.argmax(side)]), int(vertices[np.argmin(side)])
        return [start, left, far, right, start], True
    ends = piece.ends
    pool = ends if ends.size >= 2 else vertices
    first = int(pool[_farthest(points[pool], where.mean(axis=0))])
    if ends.size == 1:
        first = int(ends[0])
    last = int(pool[_farthest(points[pool], points[first])])
    # Through the crest vertex farthest from both ends: a crest bent like a U is followed
    # round its bend, not across it.
    to_first = _squared(where - points[first])
    to_last = _squared(where - points[last])
    middle = int(vertices[np.argmax(np.minimum(to_first, to_last))])
    return [first, middle, last], False


def follow(
    surface, graph, start: int, end: int, near: np.ndarray, crest_points, crest_ids, ahead=False
):
    """Legs from ``start`` to ``end`` along the crest: the cheapest ridge path, split by a via
    point on the crest wherever it strays off ``near`` for :data:`MIN_OFF_RUN` vertices.

    ``ahead``: take via points only between the two ends of the leg they split (see
    :func:`_via`); an open crest's path otherwise went back over itself. A loop's quarters
    keep the nearest crest vertex, which follows a loop round better."""
    legs = []
    pending = [(start, end, 0)]
    while pending:
        a, b, depth = pending.pop()
        if a == b:
            continue
        try:
            leg = trace_leg(surface, a, b)
        except GoniometerError:  # the crest between them leaves the corridor: split it
            if depth >= MAX_VIA_DEPTH:
                raise
            to_a = _squared(crest_points - surface.points[a])
            to_b = _squared(crest_points - surface.points[b])
            via = int(crest_ids[np.argmax(np.minimum(to_a, to_b))])
            pending += [(via, b, depth + 1), (a, via, depth + 1)]
            continue
        off = ~near[leg]
        run = _longest_run(off)
        if run is None or run[1] - run[0] < MIN_OFF_RUN or depth >= MAX_VIA_DEPTH:
            legs.append(leg)
            continue
        middle = surface.points[leg[(run[0] + run[1]) // 2]]
        if ahead:
            via = _via(surface.points, a, b, middle, crest_points, crest_ids)
        else:
            via = int(crest_ids[_nearest(crest_points, middle)])
        if via in (a, b):
            legs.append(leg)
            continue
        pending += [(via, b, depth + 1), (a, via, depth + 1)]
    return legs


def _via(points, a: int, b: int, middle, crest_points, crest_ids) -> int:
    """The crest vertex nearest ``middle`` among those nearer both ``a`` and ``b`` than they
    are to each other (a via point behind either end would send the path back over itself);
    ``a`` if there is none."""
    chord = _squared((points[b] - points[a])[None])[0]
    between = (_squared(crest_points - points[a]) < chord) & (
        _squared(crest_points - points[b]) < chord
    )
    if not between.any():
        return a
    return int(crest_ids[between][_nearest(crest_points[between], middle)])


def _nearest(points: np.ndarray, to: np.ndarray) -> int:
    offsets = points - to
    return int(np.argmin(rows_dot(offsets, offsets)))


def _longest_run(flags: np.ndarray):
    """(first, end) of the longest run of True in ``flags``, or None."""
    steps = np.diff(np.concatenate([[0], flags.astype(np.int8), [0]]))
    begins, ends = np.flatnonzero(steps == 1), np.flatnonzero(steps == -1)
    if begins.size == 0:
        return None
    k = int(np.argmax(ends - begins))
    return int(begins[k]), int(ends[k])


def trace_piece(surface, graph, piece: Piece, sharp=None) -> tuple[EdgePath, bool] | None:
    """The path along ``piece`` and whether it is a loop (None if it cannot be traced).

    The path may only stray off the piece's crest for a few vertices before a via point pulls
    it back. ``sharp`` (bool per vertex, optional): vertices with a mesh edge as sharp as a
    ridge; the ring beside the crest counts as on it where it is sharp."""
    stops, closed = piece_stops(surface.points, piece)
    if len(set(stops)) < 2:
        return None
    crest = np.zeros(surface.n_points, dtype=bool)
    crest[piece.vertices] = True
    near = crest
    if sharp is not None:
        # Where the floods meet is known to the fine field's two rings; a crease whose corner
        # the mesh cuts (edges between vertices) has two rows of bent edges, the sharper the
        # nearer the true edge, and the cheapest path keeps to it if allowed one ring.
        near = crest | (dilate(graph.starts, graph.target, crest, 1) & sharp)
    crest_points = surface.points[piece.vertices]
    legs = []
    try:
        for a, b in itertools.pairwise(stops):
            legs += follow(surface, graph, a, b, near, crest_points, piece.vertices, not closed)
    except GoniometerError:
        return None
    if not legs:
        return None
    if not closed:
        legs = _without_loops(surface, legs)
    return assemble_path(surface, _untied(surface, graph, legs)), closed


def _knot(vertices: np.ndarray, after: int = -1) -> tuple[int, int] | None:
    """(first, last) positions of the first stretch of ``vertices`` after position ``after``
    that the path passes twice (out and back over the same vertices, or round a little loop),
    or None."""
    _, inverse, counts = np.unique(vertices, return_inverse=True, return_counts=True)
    twice = np.flatnonzero(counts[inverse] > 1)
    twice = twice[twice > after]
    if twice.size == 0:
        return None
    last_at = np.zeros(counts.size, dtype=np.int64)
    np.maximum.at(last_at, inverse, np.arange(vertices.size))
    first = last = int(twice[0])
    reach = int(last_at[inverse[first]])
    while reach > last:  # widen until no vertex inside comes back after the stretch
        last, reach = reach, int(last_at[inverse[first : reach + 1]].max())
    return first, last


def _untied(surface, graph, legs: list[np.ndarray]) -> list[np.ndarray]:
    """``legs`` with each knot traced again in one leg between the waypoints either side of it.

    A via point a little off the crest can leave the path going out and back over the same
    vertices: measured there, one place would count twice. The legs that take part in a knot
    are replaced by the cheapest leg between the waypoint before it and the one after, which
    retraces by construction. Where that leg goes farther than one ring of neighbours from the
    stretch it replaces (a shortcut across the surface), or still passes a vertex twice, or no
    leg joins them (or the knot takes in a whole loop), the knot is left as it was, and the
    path's :attr:`~.edge_profile.EdgePath.warning` says so."""
    closing = len(legs) > 1 and bool(legs[0][0] == legs[-1][-1])
    after = -1
    while True:
        vertices = np.concatenate([legs[0], *(leg[1:] for leg in legs[1:])])
        knot = _knot(vertices[:-1] if closing else vertices, after)
        if knot is None:
            return legs
        ends = np.cumsum([0, *(leg.size - 1 for leg in legs)])
        # The legs from the last waypoint before the knot to the first one after it.
        k0 = max(int(np.searchsorted(ends, knot[0], side="left")) - 1, 0)
        k1 = min(int(np.searchsorted(ends, knot[1], side="right")), len(legs))
        leg = _knot_free_leg(surface, graph, legs[k0:k1])
        if leg is None:
            after = knot[1]
        else:
            legs = [*legs[:k0], leg, *legs[k1:]]
            after = int(ends[k0]) + leg.size - 1


def _knot_free_leg(surface, graph, legs: list[np.ndarray]) -> np.ndarray | None:
    """The cheapest leg from the start of ``legs`` to their end if it passes no vertex twice
    and keeps within one ring of neighbours of their vertices; otherwise None."""
    start, end = int(legs[0][0]), int(legs[-1][-1])
    if start == end:
        return None
    try:
        leg = trace_leg(surface, start, end)
    except GoniometerError:
        return None
    stretch = np.concatenate(legs)
    counts = graph.starts[stretch + 1] - graph.starts[stretch]
    beside = np.concatenate([stretch, graph.target[expand_ranges(graph.starts[stretch], counts)]])
    if _knot(leg) is not None or not np.isin(leg, beside).all():
        return None
    return leg


def _without_loops(surface, legs: list[np.ndarray]) -> list[np.ndarray]:
    """``legs`` with every stretch that comes back to a vertex it left cut out (a via point
    a little off the crest makes the path go out to it and back), if the rest retraces leg by
    leg; otherwise ``legs`` as they are."""
    kept: list[int] = []
    where: dict[int, int] = {}
    stops: set[int] = {0}
    for k, leg in enumerate(legs):
        for vertex in leg[1:] if k else leg:
            vertex = int(vertex)
            if vertex in where:  # a loop: back to where it was
                cut = where[vertex]
                for dropped in kept[cut + 1 :]:
                    del where[dropped]
                del kept[cut + 1 :]
                stops = {s for s in stops if s <= cut} | {cut}
            else:
                where[vertex] = len(kept)
                kept.append(vertex)
        stops.add(len(kept) - 1)
    if len(kept) == sum(leg.size - 1 for leg in legs) + 1:
        return legs
    vertices = np.array(kept, dtype=np.int64)
    out = retraced_legs(surface, vertices, sorted(stops))
    if all(
        np.array_equal(trace_leg(surface, leg[0], leg[-1]), leg) for leg in out if leg.size == 2
    ):
        return out
    return legs


def retraced_legs(surface, vertices: np.ndarray, stops: list[int]) -> list[np.ndarray]:
    """Legs along ``vertices`` between the positions ``stops``, each exactly what ``trace_leg``
    gives between its ends: a leg that does not retrace is split at its middle."""
    legs = []
    pending = list(itertools.pairwise(stops))[::-1]
    while pending:
        i, j = pending.pop()
        wanted = vertices[i : j + 1]
        if j - i <= 1 or np.array_equal(trace_leg(surface, vertices[i], vertices[j]), wanted):
            legs.append(wanted)
        else:
            middle = (i + j) // 2
            pending += [(middle, j), (i, middle)]
    return legs


FLAT_SIDE_MIN = 0.95
"""A side of a piece whose unit normals near it average to a vector this long (they spread
less than about 18°) is flat enough that the bisector of the two sides' normals marks the edge."""


def balanced_crest(graph, piece: Piece, flooded, band, normals, rings: int) -> Piece:
    """``piece`` with its crest moved to where the surface faces halfway between its two sides.

    Where the floods of two regions meet on a rounded edge (a fillet) the bend is about the
    same across it, so on a noisy scan the meeting line wanders from side to side. The middle
    of the rounding is where the normal turns halfway from one side's normal to the other's:
    there ``n·(nA − nB)`` changes sign, across a sharp crease as across a fillet (``nA``,
    ``nB``: the mean normals of the two regions near the piece). The new crest is, of each mesh
    edge across that sign change between vertices flooded by either side within ``rings`` of
    the old crest, the end nearer the balance: one vertex wide, so via points on it hold the
    path to the middle. Kept as it is: a ridge inside one region, a piece with a side that is
    curved near it (its mean normal would not stand for it), and one whose new crest would
    be empty.

    Parameters
    ----------
    graph : RidgeGraph
    piece : Piece
    flooded : ndarray of int, shape (n,)
        The regions flooded into the band.
    band : ndarray of bool, shape (n,)
        The ridge band (off it, each side's own region).
    normals : ndarray, shape (n, 3)
        Smoothed (area-weighted) vertex normals, not necessarily of unit length.
    rings : int
        How far from the old crest the new one may lie.
    """
    first, second = piece.regions
    if first < 0:
        return piece
    near = np.zeros(flooded.size, dtype=bool)
    near[piece.vertices] = True
    local = np.flatnonzero(dilate(graph.starts, graph.target, near, rings))
    local = local[(flooded[local] == first) | (flooded[local] == second)]
    unit = normals[local]
    length = np.sqrt(rows_dot(unit, unit))
    unit = unit / np.where(length > 0, length, 1.0)[:, None]
    axes = []
    for label in (first, second):
        own = (flooded[local] == label) & ~band[local] & (length > 0)
        if not own.any():
            return piece
        mean = np.array([total(unit[own, k]) for k in range(3)]) / own.sum()
        size = norm3(mean)
        if size < FLAT_SIDE_MIN:
            return piece
        axes.append(mean / size)
    balance = row_dot(unit, axes[0] - axes[1])
    lookup = np.full(flooded.size, -1, dtype=np.int64)
    lookup[local] = np.arange(local.size)
    own, neighbour = _rows(graph, local)
    other = lookup[neighbour]
    mine = lookup[own]
    inside = other >= 0
    own, mine, other = own[inside], mine[inside], other[inside]
    # Of the two ends of a mesh edge the sign change crosses, the one nearer the balance.
    across = ((balance[mine] >= 0) != (balance[other] >= 0)) & (
        np.abs(balance[mine]) <= np.abs(balance[other])
    )
    crest = sorted_unique(own[across])
    if crest.size < 2:
        return piece
    return Piece(crest, piece.regions, piece.ends)


def outer_crest(graph, piece: Piece, points: np.ndarray, outward: np.ndarray) -> Piece:
    """``piece`` with each crest vertex moved to the neighbour that stands out most beyond it
    along the crest's outward direction ``outward`` (if any does), on a convex crease.

    Used where :func:`balanced_crest` keeps the floods' meeting line (a side curved near the
    piece). The floods locate a crest to within the fine field's two rings; on a convex crease
    the mesh vertices nearest the true edge are those that stand out most along the bisector
    of its sides, whether the edge runs through vertices (a noisy crest's row) or between them
    (a reconstruction cuts its corner: the outer of the rows it leaves). A rounded edge's
    middle stands out by no more than the noise, which is why the balanced crest, not this,
    places it. Kept as it is: a ridge inside one region and a piece whose neighbours do not
    lie below it on the whole (a valley or a flat).

    Parameters
    ----------
    graph : RidgeGraph
    piece : Piece
    points : ndarray, shape (n, 3)
    outward : ndarray, shape (n, 3)
        A direction out of the surface at each crest vertex (need not be of unit length).
    """
    if piece.regions[0] < 0:
        return piece
    own, neighbour = _rows(graph, piece.vertices)
    if own.size == 0:
        return piece
    height = rows_dot(points[neighbour] - points[own], outward[own])
    if total(height) >= 0.0:
        return piece
    # The highest neighbour of each crest vertex standing out beyond it (ties: the least).
    up = height > 0.0
    own, neighbour, height = own[up], neighbour[up], height[up]
    order = np.lexsort((-neighbour, height, own))
    last = np.flatnonzero(np.diff(np.concatenate([own[order], [-1]])) != 0)
    vertices = piece.vertices  # sorted
    moved = vertices.copy()
    moved[np.searchsorted(vertices, own[order][last])] = neighbour[order][last]
    ends = moved[np.searchsorted(vertices, piece.ends)]
    return Piece(sorted_unique(moved), piece.regions, sorted_unique(ends))
