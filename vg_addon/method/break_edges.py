"""Find the break edges of a fragment: ridges between smooth regions, traced as Edge Profiles.

The method, in four steps (docs/EDGE_DETECTION.md shows it at work):

1. **Bend at a scale.** Each vertex gets the bend (180° minus the angle) of the surface around
   it, judged over a neighbourhood of radius about ``scale`` (see :mod:`.ridge_field`).
2. **Smooth regions.** Vertices bending less than ``min_bend_deg`` are smooth; their connected
   parts larger than ``min_region_area`` are the regions (fracture faces, the original outer and
   inner surfaces); the thin band of ridge vertices between them is left out (``region`` -1).
   Where the fine bend field (two rings) calls a part of the band flat and it touches no
   region, it becomes a region of its own: a face narrower than the band the scale leaves (see
   :mod:`.narrow_faces`).
3. **Edges between regions.** The band is flooded from both sides; where two regions' floods
   meet lies the break edge between them, open (ending where a third region or the mesh's border
   comes in) or closed (a loop). Ridges that fade into a single region are found as long pieces of
   band that no region pair explains.
4. **Tracing.** Between two regions flat near it, an edge's crest is first moved to where the
   surface faces halfway between them (the middle of a rounded edge; see
   :func:`.edge_pieces.balanced_crest`). Each edge is traced from end to end (via points on
   loops) with the cheapest ridge path of :mod:`.edge_profile`, so it is an
   :class:`~.edge_profile.EdgePath` whose waypoints retrace it exactly through ``trace_edge``:
   an accepted candidate is an ordinary Edge Profile. A candidate that does not stand out from
   the noise of the regions round it (:data:`LOCAL_NOISE_FACTOR`) is dropped, and an end that
   runs along a more confident candidate is cut back to where they part, so no stretch of ridge
   is in two candidates (:func:`.candidate_parts.without_shared_ends`).
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass, field, fields, replace

import numpy as np

from ..errors import GoniometerError
from .candidate_parts import rated, trim, without_shared_ends  # noqa: F401 (trim: public here)
from .edge_pieces import (
    balanced_crest,
    outer_crest,
    ridge_pieces,
    smooth_regions,
    trace_piece,
)
from .edge_profile import EdgePath, has_ridge_graph, ridge_graph
from .fixed_order import rows_dot, total
from .mesh_edges import MeshEdges
from .mesh_regions import dilate, flood_labels
from .narrow_faces import flat_band, recovered_regions
from .ridge_field import (
    anisotropy_of_bend,
    bend_of_anisotropy,
    blurred,
    cell_spread,
    pooled_at,
    ring_spread,
    spread_of,
    vertex_moments,
)
from .stepping import STEP

SCALE_EDGES = 5.0
"""Default ``scale``: this many mean edge lengths."""

MIN_LENGTH_SCALES = 5.0
"""Default ``min_length``: this many times ``scale``."""

FRACTURE_MAX_SPREAD = 0.05
"""A region whose normals spread less than this (the trace of their covariance, about their
mean squared angle from the mean normal: 0.05 is some 13°) is near plane: a fracture face."""

ORIGINAL_MIN_SPREAD = 0.1
"""A region whose normals spread more than this (some 18°) is curved: original surface."""

FINE_RINGS = 2
"""Rings of neighbours of the fine bend field, whose crests the edges are traced along."""

NOISE_SAMPLES = 20_000
"""The fine field's typical bend on a noisy scan is judged on about this many region vertices."""

FLAT_SHARE = 0.5
"""A band vertex is flat by the fine field below this share of the ridge bar: only clearly flat
vertices join a region (half the bar keeps a noisy scan's crest in the band)."""

MIN_SCALE_EDGES = 1.0
"""A ``scale`` below this many mean edge lengths is refused: its neighbourhood would hold no
neighbours, so every vertex would read flat."""

NEW_FACE_RINGS = 4.0
"""A face the coarse field swallowed becomes a region if at least as large as a disc of this
many mean edge lengths in radius."""

LOCAL_NOISE_FACTOR = 20.0
"""A candidate's mean crease part (coarse field) along its path must be at least this many times
the median isotropic spread (the second eigenvalue, which noise raises and curvature does not)
of the region vertices round it: a chain of noise bumps on a noisy face does not stand out from
the noise around it, a true edge stands out by more. Measured on the noisy cube and flake
(noise 0.2 and 0.3 mean edges, seeds 1 to 12): noise ridges 0 to 12.7, true edges 28 and up;
20 is about the middle of that gap on a log scale (docs/EDGE_DETECTION.md)."""

OUTWARD_RINGS = 4
"""A crest's outward direction (for :func:`.edge_pieces.outer_crest`) is the smoothed normal
pooled this many rings deep: one ring reads the noise, four the crease as a whole."""

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
        edges. A scale below :data:`MIN_SCALE_EDGES` mean edge lengths is refused.
    min_bend_deg : float
        A ridge bends at least this much (degrees, 180° minus the interior angle). Default 30°:
        break edges of bone and stone are rarely blunter than 150°.
    min_length : float or None
        Candidates shorter than this are dropped. None: :data:`MIN_LENGTH_SCALES` times ``scale``.
    min_region_area : float or None
        Smooth parts smaller than this (mesh units squared) are not regions of their own (noise,
        small scars); their vertices join the band. None: the area of a disc of radius
        :data:`MIN_REGION_SCALES` times ``scale``.
    noise_factor : float
        On a noisy scan a ridge must also bend more than this many times the typical (median)
        bend of the whole surface at ``scale``, in the field's terms (see
        :mod:`.ridge_field`); the bar actually used is ``BreakEdgeResult.ridge_min_deg``.
    max_candidates : int
        At most this many candidates are returned (the most confident).
    """

    scale: float | None = None
    min_bend_deg: float = 30.0
    min_length: float | None = None
    min_region_area: float | None = None
    noise_factor: float = 4.0
    max_candidates: int = 200

    def check(
        self, diagonal: float | None = None, edge_total: float | None = None
    ) -> BreakEdgeParameters:
        """The parameters, or a :class:`GoniometerError` naming the first bad one.

        Parameters
        ----------
        diagonal : float, optional
            The mesh's bounding-box diagonal: ``scale`` may not exceed it (a neighbourhood
            larger than the whole mesh means a slip of the units, and would only cost time).
        edge_total : float, optional
            The length of all the mesh's edges together: ``min_length`` may not exceed it (no
            edge, which runs along mesh edges, can be longer). Not the diagonal: a loop or a
            curved rim is longer than the bounding box is across.
        """
        if not (_is_number(self.noise_factor) and 0 <= self.noise_factor < math.inf):
            raise GoniometerError(f"noise_factor must be a number ≥ 0; got {self.noise_factor!r}.")
        for name in ("scale", "min_length", "min_region_area"):
            value = getattr(self, name)
            if value is not None and not (_is_number(value) and math.isfinite(value) and value > 0):
                raise GoniometerError(
                    f"The break-edge parameter {name} must be a positive number (or None for the "
                    f"default); got {value!r}."
                )
        if diagonal is not None and self.scale is not None and self.scale > diagonal:
            raise GoniometerError(
                f"The break-edge parameter scale ({self.scale:g}) is larger than the whole mesh "
                f"(its bounding box is {diagonal:g} across); choose a smaller one or None for the "
                "default."
            )
        length = self.min_length
        if edge_total is not None and length is not None and length > edge_total:
            raise GoniometerError(
                f"The break-edge parameter min_length ({length:g}) is longer than all the mesh's "
                f"edges together ({edge_total:g}): no edge can reach it; choose a smaller one or "
                "None for the default."
            )
        bend = self.min_bend_deg
        if not (_is_number(bend) and 0 < bend < 180):
            raise GoniometerError(
                f"min_bend_deg must be a number of degrees above 0 and below 180 (a ridge that "
                f"bends 0° is no ridge); got {bend!r}."
            )
        count = self.max_candidates
        if isinstance(count, bool) or not isinstance(count, (int, np.integer)) or count < 1:
            raise GoniometerError(f"max_candidates must be a whole number ≥ 1; got {count!r}.")
        return self

    def resolved(self, mean_edge_length: float) -> BreakEdgeParameters:
        """These parameters with every ``None`` replaced by its default for this mesh.

        Raises
        ------
        GoniometerError
            ``scale`` below :data:`MIN_SCALE_EDGES` times ``mean_edge_length``.
        """
        scale = self.scale if self.scale is not None else SCALE_EDGES * mean_edge_length
        if scale < MIN_SCALE_EDGES * mean_edge_length:
            raise GoniometerError(
                f"The break-edge parameter scale ({scale:g}) is smaller than the mesh's mean edge "
                f"length ({mean_edge_length:g}): a neighbourhood that small holds no neighbours to "
                "judge a bend by; choose a larger one or None for the default."
            )
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
            noise_factor=float(self.noise_factor),
        )


def _local_noise(graph, vertices, region, isotropic, rings: int) -> float:
    """Median of ``isotropic`` over the region vertices within ``rings`` rings of ``vertices``."""
    seen = np.zeros(region.size, dtype=bool)
    seen[vertices] = True
    seen = dilate(graph.starts, graph.target, seen, rings)
    return _median(isotropic[seen & (region >= 0)])


def _median(values: np.ndarray) -> float:
    return float(np.median(values)) if values.size else 0.0


def _rank(candidate) -> tuple:
    """The order of candidates: most confident first, then longest, then by first vertex."""
    return (-candidate.confidence, -candidate.length, int(candidate.path.vertices[0]))


def _is_number(value) -> bool:
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)


@dataclass(frozen=True, eq=False)
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
        Mean bend (180° minus the angle) along the path at ``scale``, in degrees.
    closed : bool
        The edge is a loop (its start and end are one vertex).
    regions : tuple of int
        The regions on either side (-1, -1 for a ridge inside one region).
    bend_deg : ndarray, shape (k,)
        The bend at ``scale`` at each path vertex (degrees; see :mod:`.ridge_field`).
    ridge_min_deg : float
        The bend a path vertex needed to count as on a ridge.
    min_bend_deg : float
        The ``min_bend_deg`` it was found with (the confidence of a trimmed part uses both).
    surface : Surface
        The surface it lies on (:func:`.candidate_parts.trim` retraces parts on it).
    bend_field : ndarray, shape (n_points,)
        The field ``bend_deg`` was read from (the larger of the anisotropy at ``scale`` and the
        fine field's; see :func:`.ridge_field.bend_of_anisotropy`), shared by every candidate of
        a run: a trimmed part reads the bend of each of its vertices there.
    """

    number: int
    path: EdgePath
    confidence: float
    mean_bend_deg: float
    closed: bool
    regions: tuple = (-1, -1)
    bend_deg: np.ndarray = field(default=None, repr=False)
    ridge_min_deg: float = field(default=30.0, repr=False)
    min_bend_deg: float = field(default=30.0, repr=False)
    surface: object = field(default=None, repr=False)
    bend_field: np.ndarray = field(default=None, repr=False)

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
    ridge_min_deg : float
        The bend at ``scale`` a vertex needed to be on a ridge: ``min_bend_deg``, or more on a
        noisy scan (see ``BreakEdgeParameters.noise_factor``).
    """

    candidates: tuple
    region: np.ndarray
    region_kind: np.ndarray
    parameters: BreakEdgeParameters
    ridge_min_deg: float = 0.0


def region_kinds(region: np.ndarray, sums: np.ndarray, n_regions: int) -> np.ndarray:
    """What each region probably is: 2 fracture surface, 1 original surface, 0 unknown.

    A heuristic for shaft fragments and flakes: a fracture face is near plane (its normals
    spread less than :data:`FRACTURE_MAX_SPREAD`), the original outer and inner surfaces of a
    bone and the dorsal face of a flake are curved (more than :data:`ORIGINAL_MIN_SPREAD`), and
    the largest region is original surface. Spiral fractures and flat cortex defeat it: the
    kinds are a hint for the analyst, not a measurement.
    """
    kinds = np.zeros(n_regions, dtype=np.int8)
    if n_regions == 0:
        return kinds
    inside = region >= 0
    pooled = np.stack(
        [np.bincount(region[inside], sums[inside, k], minlength=n_regions) for k in range(10)],
        axis=1,
    )
    _, spread = spread_of(pooled)
    kinds[spread < FRACTURE_MAX_SPREAD] = 2
    kinds[spread > ORIGINAL_MIN_SPREAD] = 1
    kinds[0] = 1  # regions are numbered by area, largest first
    return kinds


def _phase(work, low: float, high: float):
    """Run the stepwise ``work`` (see :mod:`.stepping`), yielding a progress that climbs from
    ``low`` towards ``high`` with each of its steps; its result."""
    progress = low
    while True:
        try:
            next(work)
        except StopIteration as done:
            return done.value
        progress += (high - progress) / 8.0
        yield progress


def _mesh_edge_total(surface) -> float | None:
    """The length of every triangle's three sides together (``None`` without triangles): an
    interior mesh edge counts twice, so no path along the mesh's edges is longer."""
    triangles = surface.triangles
    if triangles is None or len(triangles) == 0:
        return None
    points = surface.points
    sides = [points[triangles[:, k]] - points[triangles[:, k - 1]] for k in range(3)]
    return sum(total(np.sqrt(rows_dot(side, side))) for side in sides)


class BreakEdgeFinder:
    """Find break edges step by step (a modal operator steps it on a timer).

    Parameters
    ----------
    surface : Surface
        A triangle mesh.
    parameters : BreakEdgeParameters, optional
    step : int, optional
        Faces, vertices or edges worked through per step of the long phases (default
        :data:`~.stepping.STEP`): smaller steps let a caller stop sooner, at some cost in time.
        The result does not depend on it.

    Attributes
    ----------
    result : BreakEdgeResult or None
        Set once :meth:`steps` is exhausted.
    """

    def __init__(
        self, surface, parameters: BreakEdgeParameters = BreakEdgeParameters(), *, step: int = STEP
    ):
        if not isinstance(parameters, BreakEdgeParameters):
            raise GoniometerError("The parameters must be a BreakEdgeParameters.")
        if isinstance(step, bool) or not isinstance(step, (int, np.integer)) or step < 1:
            raise GoniometerError(f"The finder's step must be a whole number ≥ 1; got {step!r}.")
        self.step = int(step)
        self.surface = surface
        points = surface.points
        diagonal = math.hypot(*(points.max(axis=0) - points.min(axis=0))) if len(points) else None
        self.parameters = parameters.check(diagonal, _mesh_edge_total(surface))
        self.result: BreakEdgeResult | None = None

    def steps(self) -> Iterator[float]:
        """Do the work in chunks, yielding the progress (0 to 1) after each.

        A chunk is a block of ``step`` faces, vertices or edges, a round of a
        walk over the mesh, or one candidate traced, so a chunk takes a fraction of a second
        even on a million vertices and more chunks come with a larger mesh; the result does
        not depend on how the work is chunked. Stopping early leaves nothing changed: the
        surface is only read (its ridge graph, once complete, is kept with it).
        """
        surface = self.surface
        edges = None
        if surface.triangles is not None and not has_ridge_graph(surface):
            work = MeshEdges.stepwise(surface.points, surface.triangles, surface.valid, self.step)
            edges = yield from _phase(work, 0.0, 0.1)
        graph = ridge_graph(surface, edges)  # raises for a point cloud
        del edges
        yield 0.1
        params = self.parameters.resolved(graph.mean_edge_length)
        work = vertex_moments(
            surface.points, surface.triangles, graph.starts, graph.target, block=self.step
        )
        sums = yield from _phase(work, 0.1, 0.2)
        work = cell_spread(
            surface.points, sums, params.scale, graph.starts, graph.target, block=self.step
        )
        spread, total = yield from _phase(work, 0.2, 0.3)
        yield 0.3
        degree = np.diff(graph.starts)
        used = surface.valid & (degree > 0)
        # Creases show in the crease part of the spread, corners (three faces) in the second
        # eigenvalue; on a noisy scan both bars rise with the typical value of each.
        second = (total - spread) / 2.0
        bar = anisotropy_of_bend(params.min_bend_deg)
        floor = max(bar, params.noise_factor * _median(spread[used]))
        corner_floor = max(bar, params.noise_factor * _median(second[used]))
        band = used & ((spread >= floor) | (second >= corner_floor))
        del second
        ridge_min_deg = float(bend_of_anisotropy(np.array([floor]))[0])
        yield 0.32
        work = smooth_regions(
            graph, used, band, sums[:, 0], params.min_region_area, block=self.step
        )
        region = yield from _phase(work, 0.32, 0.45)
        yield 0.45
        # The fine field only where the flood goes (the band and the parts too small to be
        # regions). The flood rises by the bend at scale (where a broad bevel peaks), its steps
        # from cell to cell smoothed, plus the fine bend (where a sharp crease peaks).
        rows = np.flatnonzero(used & (region < 0))
        fine_spread, fine_total = ring_spread(sums, graph.starts, graph.target, FINE_RINGS, rows)
        yield 0.5
        region = self._narrow_faces(graph, sums, region, rows, fine_spread, fine_total, bar, params)
        rows = np.flatnonzero(used & (region < 0))
        heights = blurred(total, graph.starts, graph.target, 2 * FINE_RINGS, rows) + fine_total
        flooded = flood_labels(graph.starts, graph.target, region, used, heights=heights)
        bend_field = np.maximum(spread, fine_spread)
        del heights, fine_total, fine_spread
        yield 0.6
        # A vertex with more neighbours than faces lies on the mesh's border.
        faces = np.bincount(surface.triangles.ravel(), minlength=surface.n_points)
        reach = math.ceil(1.5 * params.scale / graph.mean_edge_length) + 2
        pieces = ridge_pieces(graph, flooded, band, used & (degree != faces), reach)
        # A mesh edge as sharp as a ridge (on a noisy scan, clear of the noise as the bar is).
        edge_bar = max(
            math.radians(params.min_bend_deg),
            params.noise_factor * _median(graph.vertex_bend[used]),
        )
        sharp = graph.vertex_bend >= edge_bar
        yield 0.7
        traced = []
        # The outward direction of each crest: its smoothed normals pooled a few rings deep.
        crests = [p.vertices for p in pieces if p.regions[0] >= 0]
        outward = (
            pooled_at(
                graph.starts, graph.target, sums[:, 1:4], OUTWARD_RINGS, np.concatenate(crests)
            )
            if crests
            else sums[:, 1:4]
        )
        for k, piece in enumerate(pieces):
            balanced = balanced_crest(graph, piece, flooded, band, sums[:, 1:4], reach)
            if balanced is piece:
                balanced = outer_crest(graph, piece, self.surface.points, outward)
            piece = balanced
            candidate = self._candidate(graph, piece, bend_field, ridge_min_deg, params, sharp)
            if candidate is not None:
                traced.append(candidate)
            yield 0.7 + 0.25 * (k + 1) / len(pieces)
        isotropic = (total - spread) / 2.0
        traced = [
            c
            for c in traced
            if float(spread[c.path.vertices].mean())
            >= LOCAL_NOISE_FACTOR * _local_noise(graph, c.path.vertices, region, isotropic, reach)
        ]
        traced.sort(key=_rank)
        traced = without_shared_ends(traced, graph.starts, graph.target, params.min_length)
        traced.sort(key=_rank)  # a cut candidate's confidence is its part's
        numbered = tuple(
            replace(c, number=k + 1) for k, c in enumerate(traced[: params.max_candidates])
        )
        n_regions = int(region.max()) + 1 if region.size else 0
        self.result = BreakEdgeResult(
            candidates=numbered,
            region=region.astype(np.int32),
            region_kind=region_kinds(region, sums, n_regions),
            parameters=params,
            ridge_min_deg=ridge_min_deg,
        )
        yield 1.0

    def _narrow_faces(self, graph, sums, region, rows, fine_spread, fine_total, bar, params):
        """``region`` with the band's flat parts (by the fine field) that touch no region made
        regions of their own (see :mod:`.narrow_faces`)."""
        inside = np.flatnonzero(region >= 0)
        sample = inside[:: max(1, inside.size // NOISE_SAMPLES)]
        if sample.size:
            s_spread, s_total = ring_spread(sums, graph.starts, graph.target, FINE_RINGS, sample)
            # Noise spreads the normals in every direction (the second eigenvalue), a bone's
            # curvature in one (the crease part): only the noise should raise the bar.
            second = (s_total[sample] - s_spread[sample]) / 2.0
            floor = max(bar, params.noise_factor * _median(second))
        else:
            floor = bar
        bar_flat = FLAT_SHARE * floor
        flat = flat_band(fine_spread, (fine_total - fine_spread) / 2.0, rows, bar_flat, bar_flat)
        h = graph.mean_edge_length
        min_area = math.pi * (NEW_FACE_RINGS * h) ** 2
        return recovered_regions(graph, region, flat, sums[:, 0], min_area)

    def _candidate(self, graph, piece, spread, ridge_min_deg, params, sharp=None):
        """The candidate traced along ``piece``, or None if it is too short."""
        points = self.surface.points[piece.vertices]
        extent = math.hypot(*(points.max(axis=0) - points.min(axis=0)))  # fixed order, no BLAS
        if extent < params.min_length / math.pi:  # not even a loop of min_length fits
            return None
        traced = trace_piece(self.surface, graph, piece, sharp)
        if traced is None or traced[0].length < params.min_length:
            return None
        path, closed = traced
        blank = BreakEdgeCandidate(
            number=0,
            path=path,
            confidence=0.0,
            mean_bend_deg=0.0,
            closed=closed,
            regions=piece.regions,
            ridge_min_deg=ridge_min_deg,
            min_bend_deg=params.min_bend_deg,
            surface=self.surface,
            bend_field=spread,
        )
        return rated(blank, path, bend_of_anisotropy(spread[path.vertices]))

    def run(self) -> BreakEdgeResult:
        """Run every step; the result."""
        for _ in self.steps():
            pass
        return self.result


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
