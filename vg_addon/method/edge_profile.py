"""A whole break edge: trace it along the mesh, measure it every ``spacing``, summarise it.

``trace_edge`` finds the ridge between clicked points as a cheapest path along mesh edges whose
cost favours sharp edges; ``measure_along`` runs Algorithm 1 (``Surface.measure``) at stations
spaced along that path and returns an :class:`EdgeProfile`: the stations, their arc lengths and
the summary figures of the whole edge.

The ridge cost
--------------
Each mesh edge ``e`` costs ``|e| * (FLOOR + exp(-bend(e) / BEND_SCALE))`` where ``bend(e)`` is
the angle between the normals of the two triangles that share it (0 on a flat surface, the
break's ``180° - angle`` on a crease that runs along mesh edges). Along a sharp ridge an edge
costs a few percent of its length, across a flat face its full length, so the cheapest path
follows the ridge and takes at most ``1 / FLOOR`` times the straight route's length in detours.

Limits: the cost only sees the sharpness of single edges. A ridge gentler than
:data:`RIDGE_MIN_DEG` per edge (or than the scan's noise, see :data:`NOISE_FACTOR`), or rounded
over so many triangles that no edge bends much, looks flat; where two clicks have no ridge
between them the path is the plain shortest route. Such stretches are not hidden:
:attr:`EdgePath.flat_spans` lists them and :attr:`EdgePath.warning` says so, and measuring a
station on truly flat surface is refused as a flat patch. A ridge that leaves the
corridor (the ellipsoid around two consecutive clicks, :data:`CORRIDOR_STRETCH`) or that meets a
sharper one nearby can be missed: add a via point on it. Faces wound against their neighbours
look like the sharpest ridge of all (a bend near 180°): repair the winding first.
"""

from __future__ import annotations

import itertools
import weakref
from dataclasses import dataclass

import numpy as np

from ..errors import GoniometerError, bounded_list
from .algorithm import DEFAULT_RULE
from .edge_summary import EdgeSummary, sd_text, summarize
from .inputs import as_center, as_flag, as_radius
from .mesh_edges import MeshEdges
from .ranges import expand_ranges

FLOOR = 0.02
"""Smallest cost per unit length (on the sharpest edges): bounds the detour a ridge can draw."""

BEND_SCALE = np.radians(10.0)
"""Bend at which an edge's extra cost has fallen to 1/e."""

RIDGE_MIN_DEG = 5.0
"""A path vertex none of whose edges bends more than this is on no ridge. On a noisy scan the
bar is higher: :data:`NOISE_FACTOR` times the median of the mesh's vertex bends."""

NOISE_FACTOR = 2.0
"""On a scan whose every vertex has bent edges, a ridge must bend this many times the median."""

MIN_FLAT_RUN = 3
"""Fewest consecutive off-ridge path vertices that make a flat span (one or two are the
zig-zag of a ridge that runs across triangles, or a click a vertex off the edge)."""

CORRIDOR_STRETCH = 2.0
"""A leg between two clicks ``a, b`` runs among the vertices with ``|x-a| + |x-b|`` at most this
times ``|a-b|`` (plus a few edge lengths): room for a half-circle, not for a loop."""

_graphs: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
_extents: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
_searches: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


class RidgeGraph:
    """The directed mesh edges of a surface in CSR form with their ridge costs.

    Built once per surface (see :func:`ridge_graph`).

    Attributes
    ----------
    starts : ndarray of int64, shape (n + 1,)
        The edges leaving vertex ``v`` are ``starts[v]:starts[v + 1]``.
    target : ndarray of int64
        Where each directed edge goes (each undirected edge appears both ways).
    costs : ndarray of float64
        The ridge cost ``length * (FLOOR + exp(-bend / BEND_SCALE))``; ``bend`` is the angle
        between the normals of the edge's two faces (0 on a boundary edge).
    vertex_bend : ndarray of float64, shape (n,)
        The largest bend of the edges at each vertex (radians).
    ridge_min : float
        The bend (radians) a path vertex needs to count as on a ridge: :data:`RIDGE_MIN_DEG`, or
        :data:`NOISE_FACTOR` times the median vertex bend if that is more.
    mean_edge_length, longest_edge_length : float
    """

    def __init__(self, points: np.ndarray, triangles: np.ndarray, valid: np.ndarray, edges=None):
        if edges is None:
            edges = MeshEdges(points, triangles, valid)
        # An edge shared by two faces bends by the angle between their normals; boundary edges
        # (one face) and the extra faces of a non-manifold edge do not count.
        bend, lengths = edges.bends, edges.lengths
        self.starts, self.target = edges.starts, edges.target
        self.costs = edges.both_ways(lengths * (FLOOR + np.exp(-bend / BEND_SCALE)))
        self.vertex_bend = edges.vertex_maximum(bend)
        used = self.starts[1:] > self.starts[:-1]
        noise = float(np.median(self.vertex_bend[used])) if used.any() else 0.0
        self.ridge_min = max(np.radians(RIDGE_MIN_DEG), NOISE_FACTOR * noise)
        self.mean_edge_length = float(lengths.mean()) if lengths.size else 0.0
        self.longest_edge_length = float(lengths.max()) if lengths.size else 0.0


def ridge_graph(surface, edges=None) -> RidgeGraph:
    """The :class:`RidgeGraph` of ``surface``, built on first use and kept with it.

    ``edges``: the surface's :class:`~.mesh_edges.MeshEdges`, where the caller has built them
    already (the break-edge finder does, in steps); otherwise they are built here.
    """
    graph = _graphs.get(surface)
    if graph is None:
        if surface.triangles is None:
            raise GoniometerError(
                "Tracing a break edge follows mesh edges, and this surface is a point cloud with "
                "no faces: give the triangles, or measure the edge point by point."
            )
        graph = RidgeGraph(surface.points, surface.triangles, surface.valid, edges)
        _graphs[surface] = graph
    return graph


def has_ridge_graph(surface) -> bool:
    """Whether the :class:`RidgeGraph` of ``surface`` is built already."""
    return surface in _graphs


@dataclass(frozen=True, eq=False)
class EdgePath:
    """A traced break edge: a polyline of mesh vertices.

    Attributes
    ----------
    vertices : ndarray of int64, shape (k,)
        Vertex indices along the path, start to end.
    points : ndarray, shape (k, 3)
        Their coordinates.
    arc_lengths : ndarray, shape (k,)
        Arc length from the start to each vertex (0 at the start).
    waypoints : ndarray of int64
        Position in ``vertices`` of the start, each via point and the end.
    vertex_bend_deg : ndarray, shape (k,)
        Largest bend of the mesh edges at each path vertex, in degrees.
    ridge_min_deg : float
        The bend a path vertex needs to count as on a ridge (see ``RidgeGraph.ridge_min``).
    flat_spans : tuple of (float, float)
        Arc-length intervals of at least :data:`MIN_FLAT_RUN` consecutive path vertices on no
        ridge: there the path is a plain shortest route, not a break edge.
    mean_edge_length : float
        Mean length of the surface's mesh edges (the path's resolution).
    """

    vertices: np.ndarray
    points: np.ndarray
    arc_lengths: np.ndarray
    waypoints: np.ndarray
    vertex_bend_deg: np.ndarray
    ridge_min_deg: float
    flat_spans: tuple
    mean_edge_length: float

    @property
    def length(self) -> float:
        """Total arc length."""
        return float(self.arc_lengths[-1])

    @property
    def ridge_fraction(self) -> float:
        """Fraction of the path vertices that lie on a ridge."""
        return float(np.mean(self.vertex_bend_deg >= self.ridge_min_deg))

    @property
    def revisited_spans(self) -> tuple:
        """Arc-length intervals of the runs of path vertices the path passes more than once
        (it doubles back or crosses itself there; a loop's closing vertex does not count)."""
        vertices = self.vertices[:-1] if is_loop(self) else self.vertices
        _, inverse, counts = np.unique(vertices, return_inverse=True, return_counts=True)
        return _spans(counts[inverse] > 1, self.arc_lengths, 1)

    @property
    def warning(self) -> str:
        """Sentences naming the stretches the path passes twice and the flat spans, or ``""``
        when the path follows a ridge and never turns back."""
        sentences = []
        if revisited := self.revisited_spans:
            spans = bounded_list(f"{a:.4g} to {b:.4g}" for a, b in revisited)
            sentences.append(
                f"The traced path passes the same vertices twice at arc lengths {spans} of "
                f"{self.length:.4g} (it doubles back or crosses itself): a station there would "
                "measure one place twice. Undo the click that turned back, or click farther "
                "along the edge."
            )
        if self.flat_spans:
            spans = bounded_list(f"{a:.4g} to {b:.4g}" for a, b in self.flat_spans)
            sentences.append(
                f"The traced path crosses surface with no ridge (every mesh edge there bends less "
                f"than {self.ridge_min_deg:.3g}°) at arc lengths {spans} of {self.length:.4g}: "
                "there it is a plain shortest route, not a break edge. Check the clicks or add a "
                "via point on the edge."
            )
        return " ".join(sentences)


_BATCH = 512
"""Open vertices expanded per step of the search: enough to amortise NumPy's per-call cost,
few enough that little is expanded before its cost is final."""


def _leg(surface, graph: RidgeGraph, start: int, end: int) -> np.ndarray:
    """Cheapest path from vertex ``start`` to ``end`` under the ridge cost, inside the corridor.

    A* search, vectorised per step: each step expands the ``_BATCH`` open vertices of least
    ``cost + FLOOR * |x - end|`` (a consistent lower bound of the remaining cost, since no edge
    costs less than ``FLOOR`` times its length); a vertex whose cost improves later is opened
    again, so the result is the exact cheapest path. The search stops when no open vertex can
    still lead to a cheaper path to ``end``.
    """
    if start == end:
        return np.array([start], dtype=np.int64)
    arrays = _search_arrays(graph, surface.n_points)
    touched = [np.array([start], dtype=np.int64)]
    try:
        return _search(surface, graph, start, end, arrays, touched)
    finally:
        # Back to "not reached" where this leg wrote: the next leg finds the arrays as new.
        cost, remaining, previous = arrays
        reset = np.concatenate(touched)
        cost[reset] = np.inf
        remaining[reset] = 0.0
        previous[reset] = -1


def _search_arrays(graph: RidgeGraph, n: int) -> tuple:
    """The cost, lower bound and previous vertex of every vertex, for a leg's search on
    ``graph``: made once per graph and reset after each leg where it wrote (a fresh set per leg
    cost a pass over every vertex, a fifth of a leg's time on a 1M-vertex scan)."""
    arrays = _searches.get(graph)
    if arrays is None or arrays[0].size != n:
        arrays = (np.full(n, np.inf), np.zeros(n), np.full(n, -1, dtype=np.int64))
        _searches[graph] = arrays
    return arrays


def _search(surface, graph: RidgeGraph, start: int, end: int, arrays, touched: list) -> np.ndarray:
    """The A* search of :func:`_leg` in ``arrays`` (:func:`_search_arrays`, as new); every
    vertex it writes is appended to ``touched``."""
    points = surface.points
    a, b = points[start], points[end]
    reach = CORRIDOR_STRETCH * float(np.linalg.norm(b - a)) + 4.0 * graph.mean_edge_length

    def distances(targets, to):
        offsets = points[targets] - to
        return np.sqrt(np.einsum("ij,ij->i", offsets, offsets))

    # remaining: the lower bound FLOOR * |x - end|, once reached
    cost, remaining, previous = arrays
    cost[start] = 0.0
    remaining[start] = FLOOR * float(np.linalg.norm(b - a))
    open_ids = np.array([start], dtype=np.int64)

    def relax(batch):
        """Relax the edges of ``batch``; the vertices whose cost improved."""
        counts = graph.starts[batch + 1] - graph.starts[batch]
        edges = expand_ranges(graph.starts[batch], counts)
        sources = np.repeat(batch, counts)
        targets = graph.target[edges]
        candidate = cost[sources] + graph.costs[edges]
        useful = candidate < cost[targets]
        sources, targets, candidate = sources[useful], targets[useful], candidate[useful]
        to_end = distances(targets, b)
        useful = (distances(targets, a) + to_end <= reach) & (
            candidate + FLOOR * to_end < cost[end]
        )
        sources, targets, candidate = sources[useful], targets[useful], candidate[useful]
        remaining[targets] = FLOOR * to_end[useful]
        touched.append(targets)
        order = np.lexsort((sources, candidate, targets))  # the best per target, ties by vertex
        sources, targets, candidate = sources[order], targets[order], candidate[order]
        best = np.ones(targets.size, dtype=bool)
        best[1:] = targets[1:] != targets[:-1]
        targets = targets[best]
        cost[targets] = candidate[best]
        previous[targets] = sources[best]
        return targets

    while open_ids.size:
        estimate = cost[open_ids] + remaining[open_ids]
        if cost[end] <= estimate.min():
            break
        if open_ids.size > _BATCH:
            pick = np.argpartition(estimate, _BATCH)[:_BATCH]
            rest = np.ones(open_ids.size, dtype=bool)
            rest[pick] = False
            batch, open_ids = open_ids[pick], open_ids[rest]
        else:
            pick = np.arange(open_ids.size)
            batch, open_ids = open_ids, open_ids[:0]
        # Improved vertices no worse than the batch are expanded at once (a cheap ridge is
        # followed hop after hop on small arrays); the others wait in the open set.
        threshold = estimate[pick].max()
        waiting = [open_ids]
        while batch.size:
            improved = relax(batch)
            now = cost[improved] + remaining[improved] <= threshold
            waiting.append(improved[~now])
            batch = improved[now]
        open_ids = np.unique(np.concatenate(waiting))
    if not np.isfinite(cost[end]):
        raise GoniometerError(
            "No path along mesh edges joins the clicked points within the corridor around them "
            "(they lie on separate pieces of the mesh, or the edge between them curves back on "
            "itself): click points on one connected surface, or add a via point."
        )
    path = [end]
    while path[-1] != start:
        path.append(int(previous[path[-1]]))
    return np.array(path[::-1], dtype=np.int64)


def _flat_spans(on_ridge: np.ndarray, arc: np.ndarray) -> tuple:
    """Arc-length intervals of the runs of at least MIN_FLAT_RUN path vertices off any ridge."""
    return _spans(~on_ridge, arc, MIN_FLAT_RUN)


def _spans(marked: np.ndarray, arc: np.ndarray, shortest: int) -> tuple:
    """Arc-length intervals of the runs of at least ``shortest`` consecutive marked vertices."""
    steps = np.diff(np.concatenate([[0], marked.astype(np.int8), [0]]))
    begins = np.flatnonzero(steps == 1)
    ends = np.flatnonzero(steps == -1) - 1
    return tuple(
        (float(arc[i]), float(arc[j]))
        for i, j in zip(begins, ends, strict=True)
        if j - i + 1 >= shortest
    )


def surface_extent(surface) -> float:
    """The largest side of the surface's bounding box, computed once per surface (a pass over
    every vertex: per click it cost more than the snap itself on a 1M-vertex scan)."""
    extent = _extents.get(surface)
    if extent is None:
        extent = _extents[surface] = float(np.ptp(surface.points, axis=0).max())
    return extent


def snap_click(surface, click, number: int = 1) -> int:
    """The vertex a click on the edge snaps to (the nearest one, however far).

    ``number`` names the click in the message (1 = the start).
    """
    click = as_center(click)
    graph = ridge_graph(surface)
    reach = max(surface_extent(surface), graph.mean_edge_length, 1e-300)
    vertex, _ = surface.index.nearest(click, reach)
    if vertex < 0:
        raise GoniometerError(
            f"Point {number} of the edge ({click[0]:g}, {click[1]:g}, {click[2]:g}) is far from "
            "every vertex of the surface: check that the coordinates are in the mesh's units and "
            "frame."
        )
    return int(vertex)


def trace_leg(surface, start: int, end: int) -> np.ndarray:
    """Vertices of the cheapest ridge path from vertex ``start`` to vertex ``end`` (both included)."""
    return _leg(surface, ridge_graph(surface), int(start), int(end))


def assemble_path(surface, legs) -> EdgePath:
    """The :class:`EdgePath` made of consecutive legs (each starts where the previous ended).

    Parameters
    ----------
    legs : sequence of ndarray of int64
        Vertex arrays from :func:`trace_leg`; a single one-vertex array is a path not yet long
        enough (an error).
    """
    graph = ridge_graph(surface)
    pieces = [np.asarray(legs[0], dtype=np.int64)]
    waypoints = [0, pieces[0].size - 1]
    for leg in legs[1:]:
        pieces.append(np.asarray(leg[1:], dtype=np.int64))
        waypoints.append(waypoints[-1] + len(leg) - 1)
    vertices = np.concatenate(pieces)
    if vertices.size < 2:
        raise GoniometerError(
            "The start and end of the edge snap to the same vertex: click two different points "
            "along the break edge."
        )
    points = surface.points[vertices]
    steps = np.linalg.norm(np.diff(points, axis=0), axis=1)
    arc = np.concatenate([[0.0], np.cumsum(steps)])
    bend_deg = np.degrees(graph.vertex_bend[vertices])
    ridge_min_deg = float(np.degrees(graph.ridge_min))
    return EdgePath(
        vertices=vertices,
        points=points,
        arc_lengths=arc,
        waypoints=np.array(waypoints, dtype=np.int64),
        vertex_bend_deg=bend_deg,
        ridge_min_deg=ridge_min_deg,
        flat_spans=_flat_spans(bend_deg >= ridge_min_deg, arc),
        mean_edge_length=graph.mean_edge_length,
    )


def trace_edge(surface, start, end, via=()) -> EdgePath:
    """Trace the break edge from ``start`` through each ``via`` point to ``end``.

    Parameters
    ----------
    surface : Surface
        A triangle mesh.
    start, end : array_like, shape (3,)
        Points on (or near) the break edge; each snaps to the nearest vertex.
    via : sequence of array_like, shape (3,), optional
        Points the path must pass through, in order.

    Returns
    -------
    EdgePath

    Raises
    ------
    GoniometerError
        A point cloud (no faces), a point far from the surface, or points no path joins.
    """
    clicks = [start, *via, end]
    snapped = [snap_click(surface, click, number) for number, click in enumerate(clicks, 1)]
    legs = [trace_leg(surface, a, b) for a, b in itertools.pairwise(snapped)]
    return assemble_path(surface, legs)


@dataclass(frozen=True, eq=False)
class EdgeProfile:
    """The angle of a break edge along its length.

    Attributes
    ----------
    path : EdgePath
        The traced path the stations lie on.
    spacing, radius, lam : float
    patch : str
        The measuring settings of every station.
    stations : tuple of Measurement
        One measurement per station, in order along the path; each centre is a path vertex.
    arc_lengths : ndarray, shape (s,)
        Arc length of each station's centre along the path.
    figures : EdgeSummary
        Mean, standard deviation, min, max and pooled angle (also read-only properties of the
        profile: ``profile.mean`` is ``profile.figures.mean``).
    """

    path: EdgePath
    spacing: float
    radius: float
    lam: float
    patch: str
    stations: tuple
    arc_lengths: np.ndarray
    figures: EdgeSummary

    n_stations = property(lambda self: self.figures.n_stations, doc="Number of stations.")
    mean = property(lambda self: self.figures.mean, doc="Mean station angle (degrees).")
    std = property(
        lambda self: self.figures.std,
        doc="Sample standard deviation (degrees); None for one station.",
    )
    min = property(lambda self: self.figures.min, doc="Smallest station angle (degrees).")
    max = property(lambda self: self.figures.max, doc="Largest station angle (degrees).")
    pooled_angle = property(lambda self: self.figures.pooled_angle, doc="Whole-edge angle.")
    pooled_fit_error = property(
        lambda self: self.figures.pooled_fit_error, doc="Fit error of the pooled planes."
    )

    @property
    def angles(self) -> np.ndarray:
        """The stations' angles (degrees), in order along the path."""
        return np.array([m.angle for m in self.stations])

    def summary(self) -> str:
        """One line for reports."""
        f = self.figures
        return (
            f"{f.n_stations} stations every {self.spacing:g} over {self.path.length:.4g}: "
            f"mean {f.mean:.2f}° (SD {sd_text(f.std)}, min {f.min:.2f}°, max {f.max:.2f}°), "
            f"pooled {f.pooled_angle:.2f}° (r={self.radius:g}, λ={self.lam:g})"
        )


#: The most stations one edge is measured at. A spacing that would make more is refused before
#: anything is allocated for them (a spacing of 1e-9 on an edge of length 1 would ask for about
#: 12 GiB): 100,000 stations is far more than a profile plot or a reader can use.
MAX_STATIONS = 100_000


def station_count(length: float, spacing: float) -> int:
    """How many stations ``spacing`` apart fit on an edge of arc ``length`` (at least one)."""
    return int(np.floor(length / spacing * (1 + 1e-12))) + 1


def check_station_count(length: float, spacing: float) -> None:
    """Refuse a ``spacing`` that would make more than :data:`MAX_STATIONS` stations on an edge
    of arc ``length``, before anything is allocated for them.

    Raises
    ------
    GoniometerError
        Naming the number of stations, the limit and the finest spacing allowed.
    """
    stations = length / spacing  # a float: may be far too large for an int array, or inf
    if not np.isfinite(stations) or station_count(length, spacing) > MAX_STATIONS:
        finest = length / (MAX_STATIONS - 1)
        raise GoniometerError(
            f"The spacing {spacing:g} would make {stations:,.0f} stations along this edge "
            f"(length {length:.6g}); at most {MAX_STATIONS:,} are measured (MAX_STATIONS). Use "
            f"a spacing of at least {finest:.4g}."
        )


def is_loop(path: EdgePath) -> bool:
    """Whether ``path`` ends on the vertex it starts from (a closed edge)."""
    return path.vertices.size > 1 and bool(path.vertices[0] == path.vertices[-1])


def _as_spacing(spacing) -> float:
    try:
        return as_radius(spacing)
    except GoniometerError:
        raise GoniometerError(
            f"The spacing must be a finite number greater than 0; got {spacing!r}."
        ) from None


def station_positions(path: EdgePath, spacing: float) -> np.ndarray:
    """Positions in ``path.vertices`` of the stations ``spacing`` apart.

    On an open path, :func:`station_count` stations ``spacing`` apart in arc length, centred on
    the path (the leftover length is split between both ends). On a loop, whose last vertex is
    its first, the stations go evenly round it from its start, as many as come nearest to
    ``spacing`` apart (at least one): a station at each end would measure one place twice.
    Each station snaps to the path vertex nearest its arc length.

    Raises
    ------
    GoniometerError
        A spacing not positive, one that would make more than :data:`MAX_STATIONS` stations,
        one so fine that two stations snap to one vertex, or a path that passes a station's
        vertex twice.
    """
    spacing = _as_spacing(spacing)
    check_station_count(path.length, spacing)
    arc = path.arc_lengths
    loop = is_loop(path)
    if loop:
        count = max(1, int(np.floor(path.length / spacing + 0.5)))
        targets = path.length * np.arange(count) / count
    else:
        count = station_count(path.length, spacing)
        targets = (path.length - (count - 1) * spacing) / 2.0 + spacing * np.arange(count)
    right = np.clip(np.searchsorted(arc, targets), 1, arc.size - 1)
    left = right - 1
    positions = np.where(targets - arc[left] <= arc[right] - targets, left, right)
    vertices = path.vertices[positions]
    if np.unique(vertices).size == count:
        return positions
    neighbours = vertices[1:] == vertices[:-1]
    longest = float(np.diff(arc).max())
    if spacing < longest and (
        (loop and count > 1 and vertices[0] == vertices[-1]) or neighbours.any()
    ):
        raise GoniometerError(
            f"The spacing {spacing:g} is finer than the mesh along this edge (its segments are up "
            f"to {longest:.4g} long), so two stations would share a vertex: use a spacing of at "
            f"least {longest:.4g}."
        )
    raise GoniometerError(
        "The traced edge passes through the same vertex twice (it doubles back or crosses "
        "itself), and two stations fall on it: one place would be measured twice. Trace the edge "
        "again with points that do not turn back along it."
    )


def _check_single_pass(path: EdgePath, spacing: float) -> None:
    """Refuse a path that passes a stretch of half a spacing or more twice (it doubles back,
    or its points are out of order): stations there would measure that stretch twice over, and
    the edge's figures would weigh it twice. A shorter revisit (a spur of a vertex or two, as
    a noisy ridge can leave) is measured, unless two stations fall on its vertex
    (:func:`station_positions` refuses that)."""
    twice = [(a, b) for a, b in path.revisited_spans if b - a >= spacing / 2]
    if twice:
        spans = bounded_list(f"{a:.4g} to {b:.4g}" for a, b in twice)
        raise GoniometerError(
            f"The traced path passes the same stretch twice, at arc lengths {spans} of "
            f"{path.length:.4g} (it doubles back or crosses itself): its stations there would "
            "measure one place twice, and count it twice in the edge's mean. Give the points in "
            "their order along the edge (start, the via points as they come, end), or undo the "
            "click that turned back."
        )


def measure_along(
    surface, path, spacing, radius, lam=2.0, patch="euclidean", rule=DEFAULT_RULE, stability=False
) -> EdgeProfile:
    """Measure the break angle at stations every ``spacing`` along ``path``.

    Parameters
    ----------
    surface : Surface
    path : EdgePath or array_like, shape (k, 3)
        A traced edge (see :func:`trace_edge`), or a polyline of points on the surface, which is
        traced through (start, its inner points as via points, end) first.
    spacing : float
        Arc length between stations, in the surface's units.
    radius, lam, patch, rule, stability
        As for ``Surface.measure``; the same for every station (``stability=True`` gives each
        station its :attr:`Measurement.stability` figure).

    Returns
    -------
    EdgeProfile

    Raises
    ------
    GoniometerError
        Bad settings, a spacing finer than the mesh, or stations that cannot be measured (all
        of them listed with their arc lengths and reasons; nothing is returned then).
    """
    stability = as_flag("stability", stability)
    if not isinstance(path, EdgePath):
        polyline = np.asarray(path, dtype=np.float64)
        if polyline.ndim != 2 or polyline.shape[0] < 2 or polyline.shape[1] != 3:
            raise GoniometerError(
                "The path must be a traced EdgePath or at least two x, y, z points."
            )
        path = trace_edge(surface, polyline[0], polyline[-1], via=polyline[1:-1])
    spacing = _as_spacing(spacing)
    _check_single_pass(path, spacing)
    positions = station_positions(path, spacing)
    stations, failures = [], []
    for position in positions:
        try:
            stations.append(
                surface.measure(path.points[position], radius, lam, patch, rule, stability)
            )
        except GoniometerError as error:
            failures.append(f"station at arc length {path.arc_lengths[position]:.6g}: {error}")
    if failures:
        hint = f"\n{path.warning}" if path.warning else ""
        first = failures[0].splitlines()[0]
        raise GoniometerError(
            f"{len(failures)} of {positions.size} stations along the edge could not be "
            f"measured (the first, {first}); nothing was measured.\n"
            + bounded_list(failures, lines=True)
            + hint
        )
    first = stations[0]
    return EdgeProfile(
        path=path,
        spacing=float(spacing),
        radius=first.radius,
        lam=first.lam,
        patch=first.patch,
        stations=tuple(stations),
        arc_lengths=path.arc_lengths[positions].copy(),
        figures=summarize(surface, stations),
    )
