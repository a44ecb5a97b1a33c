"""A scanned surface, prepared once, measured many times."""

from __future__ import annotations

import operator
from dataclasses import replace

import numpy as np

from ..errors import GoniometerError
from .algorithm import DEFAULT_RULE, MIN_SIDE_VERTICES, check_rule, measure_patch
from .geodesic import EdgeGraph
from .inputs import as_center, as_flag, as_lambda, as_normals, as_points, as_radius
from .normals import pca_normals, vertex_normals
from .ordering import canonical_ranks
from .parts import crumb_vertices, measured_part, mesh_parts, mesh_rims, touching
from .precision import check_rounding, precision_of
from .refinement import mean_edge_length
from .result import Measurement
from .spatial import GridIndex, estimate_spacing
from .stability import SMALL_PATCH_VERTICES, estimate_stability
from .winding import edge_census, mesh_winding

PATCH_MODES = ("euclidean", "geodesic")


def _as_triangles(triangles, n_points: int) -> np.ndarray:
    try:
        given = np.asarray(triangles)
    except ValueError as error:  # ragged nested lists
        raise GoniometerError(
            f"The triangles must be an (m, 3) array of vertex indices: {error}"
        ) from None
    if given.size and not np.issubdtype(given.dtype, np.integer):
        raise GoniometerError(
            f"The triangles must be integer vertex indices; got {given.dtype} values."
        )
    if given.size and given.dtype == np.uint64 and int(given.max()) >= n_points:
        # Checked before the cast to int64, which would wrap an index of 2⁶³ or more negative.
        raise GoniometerError(
            f"A triangle refers to vertex {int(given.max())}, but the mesh has vertices 0 to "
            f"{n_points - 1}: the face list does not match the points."
        )
    # int32 indices are kept as they are (every index fits; no copy of the largest array).
    dtype = np.int32 if given.dtype == np.int32 else np.int64
    array = np.ascontiguousarray(given, dtype=dtype)
    if array.size == 0:
        return array.reshape(0, 3)
    if array.ndim != 2 or array.shape[1] != 3:
        raise GoniometerError(
            f"The triangles must be an (m, 3) array of vertex indices; got shape {array.shape}."
        )
    low, high = int(array.min()), int(array.max())
    if low < 0 or high >= n_points:
        raise GoniometerError(
            f"A triangle refers to vertex {high if high >= n_points else low},"
            f" but the mesh has vertices 0 to {n_points - 1}: the face list does not match the points."
        )
    return array


def _as_corner_edges(corner_edges, n_triangles: int) -> np.ndarray:
    given = np.asarray(corner_edges)
    if given.size != 3 * n_triangles or not np.issubdtype(given.dtype, np.integer):
        raise GoniometerError(
            f"The corner edges must be one integer edge id per corner ({3 * n_triangles} for "
            f"{n_triangles} triangles); got {given.size} {given.dtype} values."
        )
    if given.size and given.min() < 0:
        raise GoniometerError("The corner edges must be edge ids from 0 up; got a negative one.")
    given = given.reshape(-1)
    if given.size and int(given.max()) >= given.size:
        # Ids only name edges: numbered from 0 in order, the counts per edge need no more room
        # than there are corners (a mesh with loose edges, or ids of another numbering).
        given = np.unique(given, return_inverse=True)[1].reshape(-1)
    return given


CRUMB_CHANGE = 0.1
"""Degrees: a Euclidean patch holding crumbs of the mesh (see :mod:`.parts`) is refused where
leaving them out moves the reading by more than this. A crumb can be a bead of the edge itself
(a thin edge meshed by marching cubes breaks into beads along the crease) or scan debris off it,
and nothing in its shape or size tells which: a loose triangle 0.05 above a 90° edge read 85.94°,
a 9-vertex speck 81.02°, under every rule."""

TOUCHING = 2.0
"""A large part left out of a Euclidean patch runs along the part measured where a vertex of its
rim lies within this many mean edge lengths of one of the patch's rim; the patch is then
refused. Split along its crease with the seam's copies 1e-5 to 0.01 apart (beyond rounding, at
spacing 0.02), a marched 60° wedge read 175.36° under the oriented rule, on the face the centre
was on."""

TOUCHING_RADIUS = 0.5
"""And at least this fraction of the radius: a crack along the crease as wide as 2.5 edges
(0.05 at spacing 0.02, r 0.2) left one face and the triangles across the crease, which read a
60° wedge as 149.03° and a 120° one as 179.27° (a review). A part left out for lying over the
face measured (a fragment, debris) has its rim beyond the ball, or none in it."""

TOUCHING_CENTRE = 0.5
"""Only the measured part's rim within this fraction of the radius of the centre counts: a crack
or seam along the edge runs by the centre (its nearest rim vertex 0.26 r away where the
triangles across the crease stayed with the centre's face, and 60° read 149.03°), and a part
lying beside a scan's open rim farther from the centre (a stand, a support scanned with the
fragment) leaves the reading alone (a review: with the rim anywhere in the ball, 470 to 1,006
of 2,400 correct readings beside such a part were refused)."""

SEAM_COPIES = 3
"""A geodesic patch is refused for a seam where at least this many of its vertices have copies
it does not reach: a seam through a patch has many, two parts touching at a vertex or two (a
refitted fragment) few; an STL's triangle, its three corners."""


def _unmerged_copies(points: np.ndarray, reached: np.ndarray, beyond: np.ndarray) -> int:
    """How many of the vertices ``reached`` share their exact coordinates with a vertex
    ``beyond`` (a copy the mesh's edges do not join them to)."""
    if not reached.size or not beyond.size:
        return 0
    # x alone first: on a merged mesh few vertices share it, and the whole rows are compared
    # for those few (as bytes, -0.0 made 0.0).
    candidates = reached[np.isin(np.take(points[:, 0], reached), np.take(points[:, 0], beyond))]
    if not candidates.size:
        return 0
    row = np.dtype((np.void, 3 * points.itemsize))

    def keys(indices):
        return (np.take(points, indices, axis=0) + 0.0).view(row).reshape(-1)

    return int(np.isin(keys(candidates), keys(beyond)).sum())


class Surface:
    """A mesh or point cloud, prepared once (normals, spatial index) and measured many times.

    Parameters
    ----------
    points : array_like, shape (n, 3)
        Vertex coordinates (converted to float64).
    triangles : array_like of int, shape (m, 3), optional
        Faces, wound counter-clockwise seen from outside. Needed for the geodesic patch mode.
        int32 indices are used without a copy (other integer types are converted to int64).
    normals : array_like, shape (n, 3), optional
        Outward vertex normals. Default: area-weighted normals from ``triangles``, or for a point
        cloud, local-PCA normals oriented outward.
    corner_edges : array_like of int, shape (m, 3) or (3 m,), optional
        Each corner's edge id, aligned with ``triangles`` (Blender's ``.corner_edge`` of an
        all-triangle mesh): lets :attr:`winding` count edge uses instead of sorting the edges.
        See :func:`~vg_addon.method.winding.mesh_winding`.
    precision : {"float32", "float64"}, optional
        The precision the coordinates were stored at before they reached here (Blender keeps
        every mesh as float32). Default: ``"float32"`` for a float32 array, else ``"float64"``.
        A patch whose rounding at that precision is too coarse for its vertex spacing is refused
        (see :func:`~vg_addon.method.precision.check_rounding`).

    Notes
    -----
    Vertices without a normal (used by no face, or whose faces are all degenerate) are left out
    of every patch; ``valid`` marks the vertices that take part.
    """

    def __init__(self, points, triangles=None, normals=None, corner_edges=None, precision=None):
        self.precision = precision_of(points, precision)
        self.points = as_points("points", points)
        n = self.points.shape[0]
        self.triangles = None if triangles is None else _as_triangles(triangles, n)
        if self.triangles is not None and self.triangles.shape[0] == 0:
            self.triangles = None
        self._graph = None
        self._winding = None
        self._census = None
        self._fins = None
        self._parts = None
        self._part_sizes = None
        self._rims = None  # the rims' vertices and their median edge, once a part is left out
        self._left_out = None  # (measurement, labels): see _left_out_parts
        self._corner_edges = None
        if self.triangles is not None and corner_edges is not None:
            self._corner_edges = _as_corner_edges(corner_edges, self.triangles.shape[0])
        full_index = None
        # A point cloud's normals are estimated, and their orientation can fail (see measure).
        self.estimated_orientation = normals is None and self.triangles is None
        if normals is not None:
            self.normals = as_normals(normals, n)
            self.valid = np.ones(n, dtype=bool)
        elif self.triangles is not None:
            self.normals, self.valid = vertex_normals(self.points, self.triangles)
        else:
            full_index = _cloud_index(self.points)
            self.normals, self.valid = pca_normals(self.points, full_index)
        self.valid_ids = np.flatnonzero(self.valid)
        if self.valid_ids.size == 0:
            cause = ""
            if full_index is not None and n:
                distinct = np.unique(self.points, axis=0).shape[0]
                if 2 * distinct <= n:  # most points repeated: their neighbourhoods are copies
                    cause = (
                        f" The cloud repeats its points ({distinct:,} distinct of {n:,}): merge "
                        "the duplicates and measure again."
                    )
            largest = float(np.abs(self.points).max()) if n else 0.0
            step = float(np.spacing(np.float32(largest)))
            extent = float(np.ptp(self.points, axis=0).max()) if n else 0.0
            # The rounding can have collapsed the faces only where the mesh spans few steps.
            if self.precision == "float32" and n and not cause and extent <= 100 * step:
                cause = (
                    f" Its coordinates are float32 and reach {largest:.3g}, where float32 keeps "
                    f"steps of {step:.2g}, and the whole mesh spans {extent:.2g}: the rounding "
                    "has collapsed its faces; move the mesh near the origin (subtract an offset "
                    "from its coordinates)."
                )
            if full_index is not None and n >= 3 and not cause:
                cause = (
                    f" Each point's neighbours within {full_index.cell_size:.3g} (about twice the "
                    "points' typical spacing) are fewer than three or lie on a line: a cloud "
                    "sampled in rows farther apart than its points along them (a laser "
                    "scanner's lines) gives no plane to take a normal from. Resample the cloud "
                    "to an even spacing, or measure a mesh made from it."
                )
            what = (
                "No point of this cloud has a normal"
                if full_index is not None and n
                else "No vertex of this mesh has a normal (no faces with area, or an empty point "
                "cloud)"
            )
            raise GoniometerError(f"{what}: nothing can be measured.{cause}")
        if full_index is not None and self.valid_ids.size == n:
            self.index = full_index  # the same points: the normals' index serves the queries
        elif self.valid_ids.size == n:
            self.index = GridIndex(self.points)  # every vertex: no copy of the points needed
        else:
            self.index = GridIndex(self.points[self.valid_ids], ids=self.valid_ids)
        self.ranks = canonical_ranks(self.points, self.normals)
        # The vertex of each rank: a patch in canonical order is by_rank[sort(ranks[patch])].
        self._by_rank = np.empty(n, dtype=self.ranks.dtype)
        self._by_rank[self.ranks] = np.arange(n, dtype=self.ranks.dtype)

    @property
    def n_points(self) -> int:
        """Number of vertices (including any without a normal)."""
        return self.points.shape[0]

    @property
    def winding(self) -> str:
        """``"outward"``, ``"inward"``, ``"mixed"`` or ``"open"`` (see ``winding.WINDINGS``);
        computed on first use. On an ``"inward"`` surface convex edges are labelled concave."""
        if self._winding is None:
            census = None if self.triangles is None else self._edge_census()
            self._winding = mesh_winding(self.points, self.triangles, census=census)
        return self._winding

    def _edge_census(self):
        """How the faces use the edges (one sort, taken once); marks the vertices of fins."""
        if self._census is None:
            self._census = edge_census(self.points, self.triangles, self._corner_edges)
            if self._census.fin_vertices.size:
                self._fins = np.zeros(self.n_points, dtype=bool)
                self._fins[self._census.fin_vertices] = True
        return self._census

    def _check_no_fin(self, patch: np.ndarray) -> None:
        """Refuse a patch holding a vertex of an edge of three or more faces (see :mod:`.fins`)."""
        if self.triangles is None:
            return
        self._edge_census()
        if self._fins is None:
            return
        count = int(np.count_nonzero(np.take(self._fins, patch)))
        if count:
            raise GoniometerError(
                f"The patch holds {count} vertices of edges shared by three or more faces (a fin "
                "or an inner wall standing on the surface, or a face given twice): their normals "
                "belong to neither face of the break, and such a reading can be degrees off (a "
                "90° edge with a fin on it read 69.65°). Remove the extra faces (Blender: Select > "
                "Select All by Trait > Non Manifold, with only Multiple Faces on) and measure "
                "again, or measure away from them."
            )

    def _measured_part(self, ball: np.ndarray, center_index: int, radius: float) -> np.ndarray:
        """The vertices of a Euclidean ``ball`` on the part measured (see :mod:`.parts`)."""
        if self.triangles is None:
            return ball
        self._label_parts()
        patch = measured_part(self._parts, self._part_sizes, ball, center_index)
        if patch is None:
            raise GoniometerError(
                "The vertex measured is on a crumb of the mesh that no face joins to the rest "
                f"(it has fewer vertices than the rest of the {ball.size} within radius "
                f"{radius:g}), and the radius reaches several larger parts (fragments kept in one "
                "mesh, or scan debris): which surface to measure cannot be told. Measure nearer "
                "the surface meant, or separate the parts (Blender: Edit Mode > Mesh > Separate > "
                "By Loose Parts) and delete the debris; where the parts are one surface whose "
                "vertices were not merged, merge them by distance (Mesh > Clean Up > Merge by "
                "Distance)."
            )
        if patch.size < ball.size:
            self._check_rims(patch, np.setdiff1d(ball, patch), center_index, radius)
        return patch

    def _check_rims(self, patch, left_out, center_index: int, radius: float) -> None:
        """Refuse a patch that leaves out a large part whose rim runs along its own near the
        centre (see :data:`TOUCHING`): a seam not merged, or a crack, where a face of the edge
        is cut away."""
        if not left_out.size:
            return
        if self._rims is None:
            self._rims = mesh_rims(self.points, self.triangles)
        rim, rim_edge = self._rims
        # The larger of two estimates of an edge: the patch's disk, which a marched mesh's
        # diagonals make short, and the rims' own edges.
        edge = max(mean_edge_length(radius, max(patch.size, 1)), rim_edge)
        gap = max(TOUCHING * edge, TOUCHING_RADIUS * radius)
        offsets = np.take(self.points, patch, axis=0) - self.points[center_index]
        near = np.einsum("ij,ij->i", offsets, offsets) <= (TOUCHING_CENTRE * radius) ** 2
        if count := touching(self.points, rim, patch[near], left_out, gap):
            raise GoniometerError(
                f"The radius reaches another part of the mesh, which no face joins to the "
                f"one measured but whose rim runs along its rim: {count} of its rim's "
                f"vertices lie within {gap:.3g} of the measured part's. That "
                "is a seam whose vertices were not merged, a crack, or another part lying "
                "along its rim, and leaving it out could cut a face of the edge away. Where "
                "it is one surface, "
                "merge the vertices by distance (Blender: Mesh > Clean Up > Merge by "
                "Distance); where it is another fragment, separate the parts (Edit Mode > "
                "Mesh > Separate > By Loose Parts) and measure each alone."
            )

    def _label_parts(self) -> None:
        """Label the mesh's parts (see :mod:`.parts`), once."""
        if self._parts is None:
            parts = mesh_parts(self.points, self.triangles)
            # The labels last: another thread takes them as the sign the rest is there.
            self._part_sizes = parts.sizes
            self._parts = parts.labels

    def on_measured_parts(self, ids: np.ndarray, m) -> np.ndarray | None:
        """Which of ``ids`` are not on a part that the Euclidean measurement ``m`` left out of
        its ball (for the stability figure's pool and moved centres); ``None`` where none is (a
        geodesic patch, which follows the faces, leaves no part out of its reach).
        """
        if m.patch != "euclidean" or self.triangles is None:  # a point cloud has no parts
            return None
        self._label_parts()
        labels = np.take(self._parts, ids)
        if not labels.size or (labels == labels[0]).all():
            return None
        left_out = self._left_out_parts(m)
        return None if left_out is None else ~np.isin(labels, left_out)

    def _left_out_parts(self, m) -> np.ndarray | None:
        """The labels of the parts that ``m``'s ball reached and its patch left out; ``None``
        where it left out nothing. The last answer is kept: the stability figure asks twice."""
        kept = self._left_out  # read once: another thread may measure on this surface
        if kept is not None and kept[0] is m:
            return kept[1]
        ball, _ = self.index.ball(self.points[m.center_index], m.radius)
        left_out = None
        if ball.size != m.indices.size:
            left_out = np.setdiff1d(np.take(self._parts, ball), np.take(self._parts, m.indices))
        self._left_out = (m, left_out)
        return left_out

    def _check_crumbs(self, fields, indices, ball_size, center_index, radius, lam, rule):
        """Refuse a reading that crumbs in the patch move by more than :data:`CRUMB_CHANGE`."""
        crumbs = crumb_vertices(self._parts, self._part_sizes, ball_size, indices)
        if crumbs is None:
            return
        kept = np.compress(~crumbs, indices)  # still in the canonical order
        try:
            without = measure_patch(
                np.take(self.points, kept, axis=0),
                np.take(self.normals, kept, axis=0),
                self.points[center_index],
                radius,
                lam,
                rule,
            )["angle"]
        except GoniometerError as error:
            change = f"without them it is refused ({str(error).rstrip('.')})"
        else:
            if abs(without - fields["angle"]) <= CRUMB_CHANGE:
                return
            change = f"without them it is {without:.2f}°"
        count = int(crumbs.sum())
        raise GoniometerError(
            f"{count} of the patch's {indices.size} vertices lie on loose crumbs of the mesh that "
            "no face joins to the surface measured (scan debris, or beads that a thin edge broke "
            f"into when it was meshed), and they move the reading: with them it is "
            f"{fields['angle']:.2f}°, {change}. Which is right cannot be told. Delete the debris "
            "(Blender: Edit Mode, point at it and press L, then X), mesh the edge again finer, "
            "or measure where no crumb lies within the radius."
        )

    def _whole_ball(self, ball: np.ndarray, patch: np.ndarray) -> None:
        """Refuse the paper rule where the Euclidean patch is not the whole ball."""
        if patch.size != ball.size:
            raise GoniometerError(
                f"{ball.size - patch.size} of the {ball.size} vertices within the radius lie on "
                "a separate part of the mesh, which no face joins to the one measured (another "
                "fragment kept in the same mesh, or scan debris). Algorithm 1 as printed (the "
                "paper rule) takes every vertex within the radius, and such a reading can be "
                "degrees off. Measure with the refined or oriented rule, which take the measured "
                "part alone, or separate the parts (Blender: Edit Mode > Mesh > Separate > By "
                "Loose Parts)."
            )

    def snap(self, center, radius: float) -> tuple[int, float]:
        """Index of the vertex nearest ``center`` and its distance; an error if farther than ``radius``."""
        center = as_center(center)
        radius = as_radius(radius)
        vertex, distance = self.index.nearest(center, radius)
        if vertex < 0:
            raise _too_far(center, radius)
        return vertex, distance

    def patch(self, center_index: int, radius: float, patch: str = "euclidean") -> np.ndarray:
        """Indices of the vertices in the patch of ``radius`` around vertex ``center_index``.

        ``"euclidean"``: within straight-line distance ``radius``, on the part of the mesh measured
        (see :mod:`.parts`). ``"geodesic"``: reachable along mesh edges by a path no longer than
        ``radius`` (needs triangles).
        """
        radius = as_radius(radius)
        mode = check_patch_mode(patch)
        index = operator.index(center_index) if _is_vertex_number(center_index) else -1
        if not (0 <= index < self.n_points and self.valid[index]):
            raise GoniometerError(
                f"Vertex {center_index!r} cannot be a patch centre: it is not a vertex of this "
                "surface with a normal (a whole number from 0). Use Surface.snap to find one."
            )
        indices, _ = self.index.ball(self.points[index], radius)
        return self._restrict(indices, index, radius, mode)

    def _restrict(self, indices: np.ndarray, center_index: int, radius: float, mode: str):
        """The patch within the Euclidean ball ``indices``: the part of the mesh measured (see
        :mod:`.parts`), or the geodesic patch."""
        if mode == "euclidean":
            return self._measured_part(indices, center_index, radius)
        if mode == "geodesic":
            if self.triangles is None:
                raise GoniometerError(
                    "The geodesic patch follows mesh edges, and this surface is a point cloud with no "
                    "faces: use patch='euclidean', or give the triangles."
                )
            if self._graph is None:
                self._graph = EdgeGraph(self.points, self.triangles)
            distance = self._graph.distances(indices, center_index, radius)
            indices = indices[distance <= radius]
        return indices

    def _check_no_seam(self, ball, patch, center_index: int, radius: float) -> None:
        """Refuse a geodesic ``patch`` stopped by a seam: :data:`SEAM_COPIES` or more of its
        vertices have copies at the same coordinates in the ``ball`` that it does not reach (the
        mesh not merged there); or the ball holds another part whose rim runs along the patch's
        (copies a little apart, a crack; see :meth:`_check_rims`). Only the measured patch is checked: the stability figure's moved
        patches stop at a seam as before."""
        if ball.size == patch.size:
            return
        beyond = np.setdiff1d(ball, patch, assume_unique=True)
        copies = _unmerged_copies(self.points, patch, beyond)
        if copies >= SEAM_COPIES:
            raise GoniometerError(
                f"The geodesic patch stops at a seam: {copies} of the vertices it reaches have "
                "copies at the same places, within the radius, that it does not reach (the mesh "
                "is not merged there, as exports with split edges or joined parts keep it), so "
                "it would hold only what lies on its side of the seam. Merge the mesh's vertices "
                "by distance (Blender: Mesh > Clean Up > Merge by Distance), or use the "
                "Euclidean patch."
            )
        self._label_parts()
        others = beyond[self._parts[beyond] != self._parts[center_index]]
        self._check_rims(patch, others, center_index, radius)

    def measure(
        self,
        center,
        radius: float,
        lam: float = 2.0,
        patch: str = "euclidean",
        rule: str = DEFAULT_RULE,
        stability: bool = False,
    ) -> Measurement:
        """Measure the break angle at ``center`` (Algorithm 1 on the patch around it).

        Parameters
        ----------
        center : array_like, shape (3,)
            Where to measure; snapped to the nearest vertex, which becomes ``x̄``.
        radius : float
            Patch radius, in the surface's units; also the ``r`` of the projection.
        lam : float, optional
            Segmentation parameter λ ≥ 0 (default 2).
        patch : {"euclidean", "geodesic"}, optional
            How the patch is chosen (default ``"euclidean"``).
        rule : {"refined", "oriented", "paper"}, optional
            How the measurement is taken (default ``"refined"``; ``"paper"`` is Algorithm 1 as
            printed, for replicating old measurements; see ``algorithm.RULES``).
        stability : bool, optional
            Also compute :attr:`Measurement.stability` (about as costly as a dozen measurements,
            batched; default ``False``). A patch of fewer than
            :data:`~vg_addon.method.stability.SMALL_PATCH_VERTICES` vertices always gets it: a
            reading there can be degrees off with nothing else to show it.

        Returns
        -------
        Measurement

        Raises
        ------
        GoniometerError
            Centre farther than ``radius`` from the surface, bad radius or λ, unknown patch mode,
            too few vertices, float32 coordinates rounded too coarsely for the patch, a patch
            holding an edge of three or more faces (see :mod:`.fins`), a centre on a crumb of
            the mesh with several larger parts in reach, crumbs that move the reading by more
            than :data:`CRUMB_CHANGE`, a geodesic patch stopped by a seam, or (paper rule) a
            Euclidean ball
            reaching a large separate part (see :mod:`.parts`), a flat patch, a side
            that is a line, or (refined rule) two fitted planes that meet farther than the
            radius from the centre or sides whose normals face opposite ways (a face wound
            against the other; for point clouds under every rule).
        """
        requested = as_center(center)
        radius = as_radius(radius)
        lam = as_lambda(lam)
        stability = as_flag("stability", stability)
        mode = check_patch_mode(patch)
        rule = check_rule(rule)
        # The snap looks up the few cells around the click, the ball those around the snapped
        # vertex: cheaper than one lookup of a box large enough for both (measured).
        center_index, snap_distance = self.index.nearest(requested, radius)
        if center_index < 0:
            raise _too_far(requested, radius)
        ball, _ = self.index.ball(self.points[center_index], radius)
        indices = self._restrict(ball, center_index, radius, mode)
        if indices.size < 2 * MIN_SIDE_VERTICES:
            # Far from the origin rounding merges vertices: say so, not "too few" (nor "a
            # seam"), where its step is a tenth of the radius or more (else the radius is simply
            # too small).
            largest = np.abs(self.points[center_index]).max()
            step = float(np.spacing(np.dtype(self.precision).type(largest)))
            if step >= 0.1 * radius:
                check_rounding(np.take(self.points, indices, axis=0), radius, self.precision)
            if mode == "geodesic":
                self._check_no_seam(ball, indices, center_index, radius)
            if mode == "euclidean" and indices.size < ball.size:
                raise GoniometerError(
                    f"The patch of radius {radius:g} holds only {indices.size} vertices; at "
                    f"least {2 * MIN_SIDE_VERTICES} are needed.{_left_out(ball, indices)}"
                )
            if ball.size >= 2 * max(indices.size, 2 * MIN_SIDE_VERTICES):  # geodesic: far fewer
                raise GoniometerError(
                    f"The geodesic patch of radius {radius:g} reaches only {indices.size} of the "
                    f"{ball.size} vertices within the radius; along the mesh's edges the others "
                    "lie farther. Where the mesh is not connected (separate pieces, or seams "
                    "whose vertices are not merged, as STL files keep each triangle's own "
                    "corners), merge its vertices by distance (Blender: Mesh > Clean Up > Merge "
                    "by Distance); else use a larger radius, or the Euclidean patch."
                )
            raise GoniometerError(
                f"The patch of radius {radius:g} holds only {indices.size} vertices; at least "
                f"{2 * MIN_SIDE_VERTICES} are needed: use a larger radius."
            )
        # The canonical order (see algorithm.canonical_order), from the ranks sorted at build.
        indices = self._by_rank[np.sort(self.ranks[indices])].astype(np.int64)
        patch_points = np.take(self.points, indices, axis=0)
        check_rounding(patch_points, radius, self.precision)
        if mode == "geodesic":
            self._check_no_seam(ball, indices, center_index, radius)
        elif rule == "paper":
            self._whole_ball(ball, indices)
        self._check_no_fin(indices)
        try:
            fields = measure_patch(
                patch_points,
                np.take(self.normals, indices, axis=0),
                self.points[center_index],
                radius,
                lam,
                rule,
                estimated_normals=self.estimated_orientation,
            )
        except GoniometerError as error:
            if mode == "euclidean" and indices.size < ball.size:
                raise GoniometerError(f"{error}{_left_out(ball, indices)}") from None
            raise
        if mode == "euclidean" and self.triangles is not None:
            self._check_crumbs(fields, indices, ball.size, center_index, radius, lam, rule)
        measurement = Measurement(
            **fields,
            indices=indices,
            center=self.points[center_index].copy(),
            requested_center=requested,
            snap_distance=snap_distance,
            center_index=int(center_index),
            radius=radius,
            lam=lam,
            patch=mode,
        )
        if stability or indices.size < SMALL_PATCH_VERTICES:
            measurement = replace(measurement, stability=estimate_stability(self, measurement))
        return measurement

    def trace_edge(self, start, end, via=()):
        """The break edge from ``start`` through ``via`` to ``end``, as an ``EdgePath`` of mesh
        vertices following the ridge; see :func:`vg_addon.method.edge_profile.trace_edge`."""
        from .edge_profile import trace_edge

        return trace_edge(self, start, end, via)

    def measure_along(
        self, path, spacing, radius, lam=2.0, patch="euclidean", rule=DEFAULT_RULE, stability=False
    ):
        """Measure stations every ``spacing`` along ``path`` with ``rule`` (and each station's
        stability figure if ``stability``): an ``EdgeProfile``; see
        :func:`vg_addon.method.edge_profile.measure_along`."""
        from .edge_profile import measure_along

        return measure_along(self, path, spacing, radius, lam, patch, rule, stability)

    def find_break_edges(self, **parameters):
        """Find the break edges of this mesh: a ``BreakEdgeResult`` of candidates and regions.

        Keyword arguments are fields of ``BreakEdgeParameters``; see
        :func:`vg_addon.method.break_edges.find_break_edges`."""
        from .break_edges import find_break_edges

        return find_break_edges(self, **parameters)


def _left_out(ball: np.ndarray, patch: np.ndarray) -> str:
    """What a refusal adds where the Euclidean patch left another part of the mesh out."""
    return (
        f" {ball.size - patch.size} of the {ball.size} vertices within the radius were left out: "
        "they are on another part of the mesh, which no face joins to the one measured (see "
        "the Euclidean patch in METHOD.md). Where that part is the same surface (two scans' "
        "shells, a seam whose vertices are a little apart), merge the vertices by distance "
        "(Blender: Mesh > Clean Up > Merge by Distance)."
    )


def _too_far(center: np.ndarray, radius: float) -> GoniometerError:
    return GoniometerError(
        f"The centre ({center[0]:g}, {center[1]:g}, {center[2]:g}) is farther than the radius "
        f"{radius:g} from every vertex of the surface: pick a point on the surface, or check "
        "that the coordinates are in the mesh's units and frame."
    )


def _is_vertex_number(value) -> bool:
    """Whether ``value`` is a whole number (a NumPy integer or a 0-d integer array too), not a
    bool or a float."""
    if isinstance(value, np.ndarray):
        return value.ndim == 0 and value.dtype.kind in "iu"
    return isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))


def check_patch_mode(patch) -> str:
    """Return the patch mode in lower case, or raise if it is not one of :data:`PATCH_MODES`."""
    mode = str(patch).lower()
    if mode not in PATCH_MODES:
        raise GoniometerError(f"Unknown patch mode {patch!r}: use one of {', '.join(PATCH_MODES)}.")
    return mode


def _cloud_index(points: np.ndarray) -> GridIndex:
    """The index a point cloud's normals are estimated over: cells twice the point spacing.

    Refused where the grid cannot make cells that small (its cells per axis are capped, so a
    cloud that spans more than about four million spacings: a point far from the rest, or a
    coordinate gone wrong): each point's neighbourhood would then pool whole cells of points,
    enough to exhaust the memory."""
    spacing = estimate_spacing(points)
    index = GridIndex(points, 2.0 * spacing)
    if index.cell_size > 4.0 * spacing:
        extent = float(np.ptp(points, axis=0).max())
        raise GoniometerError(
            f"This point cloud spans {extent:.6g}, {extent / spacing:,.0f} times its point "
            f"spacing ({spacing:.3g}): some points lie far from the rest (stray points, or a "
            "coordinate gone wrong). Remove them and measure again."
        )
    return index
