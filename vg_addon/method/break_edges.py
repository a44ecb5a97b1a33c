"""Find the break edges of a fragment: ridges between smooth regions, traced as Edge Profiles.

The method, in four steps (docs/EDGE_DETECTION.md shows it at work):

1. **Bend at a scale.** Each vertex gets the bend (180° minus the angle) of the surface around
   it, judged over a neighbourhood of radius about ``scale`` (see :mod:`.ridge_field`).
2. **Smooth regions.** Vertices bending less than ``min_bend_deg`` are smooth; their connected
   parts larger than ``min_region_area`` are the regions (fracture faces, the original outer and
   inner surfaces); the thin band of ridge vertices between them is left out (``region`` -1).
3. **Edges between regions.** The band is flooded from both sides; where two regions' floods
   meet lies the break edge between them, open (ending where a third region or the mesh's border
   comes in) or closed (a loop). Ridges that fade into a single region are found as long pieces of
   band that no region pair explains.
4. **Tracing.** Each edge is traced from end to end (via points on loops) with the cheapest ridge
   path of :mod:`.edge_profile`, so it is an :class:`~.edge_profile.EdgePath` whose waypoints
   retrace it exactly through ``trace_edge``: an accepted candidate is an ordinary Edge Profile.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterator
from dataclasses import dataclass, field, fields, replace

import numpy as np

from ..errors import GoniometerError
from .edge_profile import EdgePath, assemble_path, ridge_graph, trace_leg
from .fixed_order import eigh3, moments
from .mesh_regions import connected_parts, flood_labels
from .ranges import expand_ranges

SCALE_EDGES = 3.0
"""Default ``scale``: this many mean edge lengths."""

MIN_LENGTH_SCALES = 5.0
"""Default ``min_length``: this many times ``scale``."""

MIN_REGION_SCALES = 2.0
"""Default ``min_region_area``: a disc of this many times ``scale`` in radius."""


@dataclass(frozen=True)
class BreakEdgeParameters:
    """How break edges are found; every length is in the mesh's units (mm for scans).

    Attributes
    ----------
    scale : float or None
        The size of the neighbourhood a bend is judged over, and the unit of the other derived
        lengths. None: :data:`SCALE_EDGES` mean edge lengths (0.3 mm on a scan with 0.1 mm edges).
        Larger values see past scan noise and find rounded edges, smaller ones separate close
        edges.
    min_bend_deg : float
        A ridge bends at least this much (degrees, 180° minus the interior angle). Default 30°:
        break edges of bone and stone are rarely blunter than 150°.
    min_length : float or None
        Candidates shorter than this are dropped. None: :data:`MIN_LENGTH_SCALES` times ``scale``.
    min_region_area : float or None
        Smooth parts smaller than this (mesh units squared) are not regions of their own (noise,
        small scars); their vertices join the band. None: the area of a disc of radius
        :data:`MIN_REGION_SCALES` times ``scale``.
    max_candidates : int
        At most this many candidates are returned (the most confident).
    """

    scale: float | None = None
    min_bend_deg: float = 30.0
    min_length: float | None = None
    min_region_area: float | None = None
    max_candidates: int = 200

    def check(self) -> BreakEdgeParameters:
        """The parameters, or a :class:`GoniometerError` naming the first bad one."""
        for name in ("scale", "min_length", "min_region_area"):
            value = getattr(self, name)
            if value is not None and not (_is_number(value) and math.isfinite(value) and value > 0):
                raise GoniometerError(
                    f"The break-edge parameter {name} must be a positive number (or None for the "
                    f"default); got {value!r}."
                )
        bend = self.min_bend_deg
        if not (_is_number(bend) and 0 < bend < 180):
            raise GoniometerError(
                f"min_bend_deg must be a number of degrees between 0 and 180; got {bend!r}."
            )
        count = self.max_candidates
        if isinstance(count, bool) or not isinstance(count, (int, np.integer)) or count < 1:
            raise GoniometerError(f"max_candidates must be a whole number ≥ 1; got {count!r}.")
        return self

    def resolved(self, mean_edge_length: float) -> BreakEdgeParameters:
        """These parameters with every ``None`` replaced by its default for this mesh."""
        scale = self.scale if self.scale is not None else SCALE_EDGES * mean_edge_length
        min_length = self.min_length if self.min_length is not None else MIN_LENGTH_SCALES * scale
        area = self.min_region_area
        if area is None:
            area = math.pi * (MIN_REGION_SCALES * scale) ** 2
        return replace(
            self,
            scale=float(scale),
            min_length=float(min_length),
            min_region_area=float(area),
            max_candidates=int(self.max_candidates),
            min_bend_deg=float(self.min_bend_deg),
        )


def _is_number(value) -> bool:
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)


@dataclass(frozen=True)
class BreakEdgeCandidate:
    """One break edge found: a traced path with how sure the finder is of it.

    Attributes
    ----------
    number : int
        1-based rank, by confidence (highest first).
    path : EdgePath
        The traced edge; ``path.waypoints`` (start, via points, end) retrace it exactly through
        ``trace_edge``.
    confidence : float
        In [0, 1]: the share of the path on a ridge times how far its bend clears
        ``min_bend_deg`` (see :func:`confidence`).
    mean_bend_deg : float
        Mean bend (180° minus the angle) along the path, in degrees.
    closed : bool
        The edge is a loop (its start and end are one vertex).
    regions : tuple of int
        The regions on either side (-1 for a ridge inside one region).
    min_bend_deg : float
        The ``min_bend_deg`` it was found with (the confidence of a trimmed part uses it).
    surface : Surface
        The surface it lies on (:func:`trim` retraces parts on it).
    """

    number: int
    path: EdgePath
    confidence: float
    mean_bend_deg: float
    closed: bool
    regions: tuple = field(default=(-1, -1))
    min_bend_deg: float = field(default=30.0, repr=False)
    surface: object = field(default=None, repr=False, compare=False)

    @property
    def length(self) -> float:
        """The path's arc length."""
        return self.path.length

    @property
    def waypoint_points(self) -> np.ndarray:
        """Coordinates of the start, via points and end (the Points of an Edge Profile row)."""
        return self.path.points[self.path.waypoints]


@dataclass(frozen=True, eq=False)
class BreakEdgeResult:
    """What the finder found.

    Attributes
    ----------
    candidates : tuple of BreakEdgeCandidate
        Ordered by confidence, highest first (``number`` 1, 2, ...).
    region : ndarray of int32, shape (n_points,)
        The smooth region of each vertex, -1 on a ridge or unassigned.
    region_kind : ndarray of int8, shape (n_regions,)
        0 unknown, 1 original (outer or inner) surface, 2 fracture surface (see
        :func:`region_kinds`).
    parameters : BreakEdgeParameters
        The parameters used, derived ones filled in.
    """

    candidates: tuple
    region: np.ndarray
    region_kind: np.ndarray
    parameters: BreakEdgeParameters


def vertex_areas(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """A third of the area of each vertex's triangles (the vertex's share of the surface)."""
    a = points[triangles[:, 1]] - points[triangles[:, 0]]
    b = points[triangles[:, 2]] - points[triangles[:, 0]]
    cross = np.cross(a, b)
    area = np.sqrt(np.einsum("ij,ij->i", cross, cross)) / 6.0
    return np.bincount(triangles.ravel(), np.repeat(area, 3), minlength=points.shape[0])


def confidence(ridge_fraction: float, mean_bend_deg: float, min_bend_deg: float) -> float:
    """How sure a candidate is: ``ridge_fraction * (1 - exp(-(mean - min) / min))`` (0 below)."""
    clear = max(0.0, mean_bend_deg - min_bend_deg) / min_bend_deg
    return float(ridge_fraction * (1.0 - math.exp(-2.0 * clear)))


class BreakEdgeFinder:
    """Find break edges step by step (a modal operator steps it on a timer).

    Parameters
    ----------
    surface : Surface
        A triangle mesh.
    parameters : BreakEdgeParameters, optional

    Attributes
    ----------
    result : BreakEdgeResult or None
        Set once :meth:`steps` is exhausted.
    """

    def __init__(self, surface, parameters: BreakEdgeParameters = BreakEdgeParameters()):
        if not isinstance(parameters, BreakEdgeParameters):
            raise GoniometerError("The parameters must be a BreakEdgeParameters.")
        self.surface = surface
        self.parameters = parameters.check()
        self.result: BreakEdgeResult | None = None

    def steps(self) -> Iterator[float]:
        """Do the work in chunks, yielding the progress (0 to 1) after each.

        Stopping early leaves nothing changed: the surface is only read.
        """
        surface = self.surface
        graph = ridge_graph(surface)  # raises for a point cloud
        yield 0.1
        params = self.parameters.resolved(graph.mean_edge_length)
        bend = graph.vertex_bend
        areas = vertex_areas(surface.points, surface.triangles)
        yield 0.3
        region, flooded = _regions(graph, surface.valid, bend, areas, params)
        yield 0.5
        pieces = _pieces(graph, flooded, bend >= math.radians(params.min_bend_deg), surface)
        yield 0.6
        traced = []
        for k, piece in enumerate(pieces):
            candidate = _trace_piece(surface, piece, params)
            if candidate is not None:
                traced.append(candidate)
            yield 0.6 + 0.4 * (k + 1) / max(len(pieces), 1)
        traced.sort(key=lambda c: (-c.confidence, -c.length, int(c.path.vertices[0])))
        numbered = tuple(
            replace(c, number=k + 1) for k, c in enumerate(traced[: params.max_candidates])
        )
        n_regions = int(region.max()) + 1 if region.size else 0
        self.result = BreakEdgeResult(
            candidates=numbered,
            region=region.astype(np.int32),
            region_kind=np.zeros(n_regions, dtype=np.int8),
            parameters=params,
        )
        yield 1.0

    def run(self) -> BreakEdgeResult:
        """Run every step; the result."""
        for _ in self.steps():
            pass
        return self.result


def _regions(graph, valid, bend, areas, params):
    """The smooth regions (-1 on the band) and the same labels flooded over the band."""
    starts, target = graph.starts, graph.target
    used = valid & (starts[1:] > starts[:-1])
    smooth = used & (bend < math.radians(params.min_bend_deg))
    parts = connected_parts(starts, target, smooth)
    roots, inverse = np.unique(parts[smooth], return_inverse=True)
    part_area = np.bincount(inverse, areas[smooth], minlength=roots.size)
    big = part_area >= params.min_region_area
    # Regions numbered by area, largest first (ties by their least vertex).
    order = np.lexsort((roots, -part_area))
    number = np.full(roots.size, -1, dtype=np.int64)
    kept = order[big[order]]
    number[kept] = np.arange(kept.size)
    region = np.full(bend.size, -1, dtype=np.int64)
    region[smooth] = number[inverse]
    flooded = flood_labels(starts, target, region, used)
    return region, flooded


@dataclass(frozen=True, eq=False)
class _Piece:
    """A stretch of band to trace: its vertices, the regions it parts, its end vertices."""

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


def _split(graph, vertices: np.ndarray, lookup: np.ndarray) -> list[np.ndarray]:
    """``vertices`` split into their connected parts (each sorted)."""
    starts, targets = _local_graph(graph, vertices, lookup)
    parts = connected_parts(starts, targets, np.ones(vertices.size, dtype=bool))
    order = np.argsort(parts, kind="stable")
    cuts = np.flatnonzero(np.diff(parts[order])) + 1
    return [vertices[group] for group in np.split(order, cuts)]


def _pieces(graph, flooded, ridge, surface) -> list[_Piece]:
    """The stretches of band between two regions, and the long band stretches inside one."""
    n = flooded.size
    starts, target = graph.starts, graph.target
    sources = np.repeat(np.arange(n, dtype=np.int64), np.diff(starts))
    a, b = flooded[sources], flooded[target]
    meet = (a >= 0) & (b >= 0) & (a != b)
    pair_a, pair_b = np.minimum(a[meet], b[meet]), np.maximum(a[meet], b[meet])
    n_regions = int(flooded.max()) + 1
    keys = (pair_a * n_regions + pair_b) * n + sources[meet]
    keys = np.unique(keys)
    pairs, vertices = keys // n, keys % n
    cuts = np.flatnonzero(np.diff(pairs)) + 1
    lookup = np.full(n, -1, dtype=np.int64)
    # Vertices where a third region (or the mesh's border) comes in end an edge.
    border = np.zeros(n, dtype=bool)
    lowest = np.full(n, n_regions, dtype=np.int64)
    np.minimum.at(lowest, sources, np.where(b >= 0, b, n_regions))
    highest = np.full(n, -1, dtype=np.int64)
    np.maximum.at(highest, sources, b)
    pieces = []
    explained = np.zeros(n, dtype=bool)
    for group_pairs, group in zip(np.split(pairs, cuts), np.split(vertices, cuts), strict=True):
        if group.size == 0:
            continue
        first, second = divmod(int(group_pairs[0]), n_regions)
        explained[group] = True
        for part in _split(graph, group, lookup):
            own = (lowest[part] >= first) & (highest[part] <= second)
            around = lowest[part], highest[part]
            third = ~own | ((around[0] != first) & (around[0] != second))
            third |= (around[1] != first) & (around[1] != second)
            pieces.append(_Piece(part, (first, second), part[third | border[part]]))
    # Ridges inside one region: band vertices far from every region pair's meeting line.
    near = explained.copy()
    for _ in range(2):
        near[target[expand_ranges(starts[np.flatnonzero(near)], np.diff(starts)[near])]] = True
    loose = np.flatnonzero(ridge & ~near & surface.valid)
    if loose.size:
        for part in _split(graph, loose, lookup):
            pieces.append(_Piece(part, (-1, -1), part[:0]))
    return pieces


def _farthest(points: np.ndarray, origin: np.ndarray) -> int:
    offsets = points - origin
    return int(np.argmax(np.einsum("ij,ij->i", offsets, offsets)))


def _trace_piece(surface, piece: _Piece, params) -> BreakEdgeCandidate | None:
    """The candidate traced along ``piece``, or None if it is too short."""
    vertices = piece.vertices
    points = surface.points[vertices]
    extent = float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))
    if extent < params.min_length / math.pi:  # not even a loop of min_length fits
        return None
    ends = piece.ends if piece.ends.size else None
    closed = ends is None and piece.regions[0] >= 0
    if closed:
        start = int(vertices[0])
        far = int(vertices[_farthest(points, surface.points[start])])
        centred = points - points.mean(axis=0)
        _, axes = eigh3(moments(centred))
        across = np.cross(axes[:, 0], surface.points[far] - surface.points[start])
        side = (points - (surface.points[start] + surface.points[far]) / 2.0) @ across
        stops = [start, int(vertices[np.argmax(side)]), far, int(vertices[np.argmin(side)]), start]
    else:
        pool = surface.points[ends] if ends is not None else points
        pool_ids = ends if ends is not None else vertices
        first = int(pool_ids[_farthest(pool, points.mean(axis=0))])
        last = int(vertices[_farthest(points, surface.points[first])])
        if ends is not None:
            last_end = int(ends[_farthest(pool, surface.points[first])])
            if np.linalg.norm(
                surface.points[last_end] - surface.points[first]
            ) > 0.5 * np.linalg.norm(surface.points[last] - surface.points[first]):
                last = last_end
        stops = [first, last]
    if len(set(stops)) < 2:
        return None
    legs = [trace_leg(surface, a, b) for a, b in itertools.pairwise(stops)]
    path = assemble_path(surface, legs)
    if path.length < params.min_length:
        return None
    bends = path.vertex_bend_deg
    mean_bend = float(bends.mean())
    return BreakEdgeCandidate(
        number=0,
        path=path,
        confidence=confidence(path.ridge_fraction, mean_bend, params.min_bend_deg),
        mean_bend_deg=mean_bend,
        closed=closed,
        regions=piece.regions,
        min_bend_deg=params.min_bend_deg,
        surface=surface,
    )


def find_break_edges(surface, parameters: BreakEdgeParameters | None = None, **overrides):
    """Find the break edges of ``surface`` (all steps of :class:`BreakEdgeFinder` at once).

    Parameters
    ----------
    surface : Surface
        A triangle mesh.
    parameters : BreakEdgeParameters, optional
        Default: ``BreakEdgeParameters()``.
    **overrides
        Fields of :class:`BreakEdgeParameters` to change, e.g. ``min_bend_deg=40``.

    Returns
    -------
    BreakEdgeResult

    Raises
    ------
    GoniometerError
        A point cloud (no faces) or a bad parameter.
    """
    parameters = parameters if parameters is not None else BreakEdgeParameters()
    known = {f.name for f in fields(BreakEdgeParameters)}
    unknown = sorted(set(overrides) - known)
    if unknown:
        raise GoniometerError(
            f"Unknown break-edge parameter {', '.join(unknown)}: use {', '.join(sorted(known))}."
        )
    return BreakEdgeFinder(surface, replace(parameters, **overrides)).run()


def _retraced_legs(surface, vertices: np.ndarray, stops: list[int]) -> list[np.ndarray]:
    """Legs along ``vertices`` between the positions ``stops``, each one exactly what
    ``trace_leg`` gives between its ends: a leg that does not retrace is split at its middle."""
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


def trim(candidate: BreakEdgeCandidate, start_arc: float, end_arc: float) -> BreakEdgeCandidate:
    """The part of ``candidate`` between arc lengths ``start_arc`` and ``end_arc``.

    Each end snaps to the path vertex nearest its arc length. The part keeps the candidate's
    waypoints that fall inside it, plus via points where the part would not otherwise retrace
    identically through ``trace_edge``. Its confidence and mean bend are those of the part.

    Raises
    ------
    GoniometerError
        Arc lengths out of order or leaving less than one mesh edge.
    """
    path = candidate.path
    arc = path.arc_lengths
    try:
        start_arc, end_arc = float(start_arc), float(end_arc)
    except (TypeError, ValueError):
        raise GoniometerError("The trim's arc lengths must be numbers.") from None
    if not (math.isfinite(start_arc) and math.isfinite(end_arc) and start_arc < end_arc):
        raise GoniometerError(
            f"Trim from arc length {start_arc:g} to {end_arc:g}: the start must come before the "
            f"end, both within 0 to {path.length:.6g}."
        )
    first = int(np.argmin(np.abs(arc - start_arc)))
    last = int(np.argmin(np.abs(arc - end_arc)))
    if last <= first:
        raise GoniometerError(
            f"Trimming from {start_arc:g} to {end_arc:g} leaves less than one mesh edge of this "
            "candidate: keep a longer part."
        )
    surface = candidate.surface
    inside = [int(w) - first for w in path.waypoints if first < w < last]
    stops = [0, *inside, last - first]
    legs = _retraced_legs(surface, path.vertices[first : last + 1], stops)
    part = assemble_path(surface, legs)
    mean_bend = float(part.vertex_bend_deg.mean())
    min_bend = candidate.min_bend_deg
    return replace(
        candidate,
        path=part,
        mean_bend_deg=mean_bend,
        confidence=confidence(part.ridge_fraction, mean_bend, min_bend),
        closed=bool(part.vertices[0] == part.vertices[-1]),
    )
