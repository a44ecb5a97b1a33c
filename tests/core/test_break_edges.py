"""Finding break edges: candidates along the known rims of synthetic fragments.

Oracles: the generators' own labels of which vertices lie on a rim (the exact geometry), and
``trace_edge`` for replication (a candidate's waypoints retrace its path).
"""

import math
from dataclasses import replace

import numpy as np
import pytest

from vg_addon import GoniometerError, Surface, fragments
from vg_addon.fragments import flake
from vg_addon.method.break_edges import (
    BreakEdgeFinder,
    BreakEdgeParameters,
    find_break_edges,
)
from vg_addon.method.candidate_parts import trim
from vg_addon.synthetic_meshes import REGION_RIM, bone_fragment


@pytest.fixture(scope="module")
def bone():
    # Edges 0.3 mm long: a scan's resolution, fine enough for the default scale (five edge
    # lengths) to see the 5 mm wide fracture faces as faces.
    fragment = bone_fragment(spacing=0.3)
    surface = Surface(fragment.points, fragment.triangles)
    return fragment, surface, surface.find_break_edges()


def test_the_four_rims_of_the_bone_shaft_are_found_as_closed_loops(bone):
    fragment, _, result = bone
    assert len(result.candidates) == 4
    rim = fragment.region == REGION_RIM
    for candidate in result.candidates:
        assert candidate.closed
        assert candidate.path.vertices[0] == candidate.path.vertices[-1]
        on_rim = rim[candidate.path.vertices].mean()
        assert on_rim >= 0.9, on_rim
        assert 0.5 < candidate.confidence <= 1.0
        # The true bends: 90° on the transverse rims, 55° to 125° round the oblique ones.
        assert 60.0 <= candidate.mean_bend_deg <= 100.0
    # Every rim vertex lies within one mesh edge of a candidate.
    found = np.vstack([c.path.points for c in result.candidates])
    h = result.candidates[0].path.mean_edge_length
    rim_points = fragment.points[rim]
    nearest = [np.linalg.norm(found - p, axis=1).min() for p in rim_points]
    assert (np.array(nearest) <= h).mean() >= 0.95


def test_numbers_follow_confidence(bone):
    _, _, result = bone
    assert [c.number for c in result.candidates] == list(range(1, len(result.candidates) + 1))
    confidences = [c.confidence for c in result.candidates]
    assert confidences == sorted(confidences, reverse=True)


def test_regions_are_the_four_surfaces(bone):
    fragment, _, result = bone
    assert result.region.dtype == np.int32 and result.region.shape == (len(fragment.points),)
    assert result.region_kind.shape == (4,)
    seen = set()
    for label in range(4):  # outer, inner, transverse, oblique
        truth = fragment.region == label
        found = result.region[truth]
        assert (found >= 0).mean() > 0.3  # the band near the rims is no region
        regions = np.unique(found[found >= 0])
        assert regions.size == 1, regions  # one region per face, and one face per region
        seen.add(int(regions[0]))
    assert len(seen) == 4
    assert (result.region[fragment.region == REGION_RIM] == -1).all()


def test_waypoints_retrace_each_candidate(bone):
    _, surface, result = bone
    for candidate in result.candidates:
        points = candidate.waypoint_points
        again = surface.trace_edge(points[0], points[-1], via=points[1:-1])
        assert np.array_equal(again.vertices, candidate.path.vertices)


def test_trim_keeps_a_part_that_retraces(bone):
    _, surface, result = bone
    candidate = result.candidates[0]
    part = trim(candidate, 10.0, 30.0)
    arc = candidate.path.arc_lengths
    first = int(np.argmin(np.abs(arc - 10.0)))
    last = int(np.argmin(np.abs(arc - 30.0)))
    assert part.bend_deg.shape == part.path.vertices.shape
    assert np.array_equal(part.path.vertices, candidate.path.vertices[first : last + 1])
    assert not part.closed
    assert part.length == pytest.approx(arc[last] - arc[first])
    points = part.waypoint_points
    again = surface.trace_edge(points[0], points[-1], via=points[1:-1])
    assert np.array_equal(again.vertices, part.path.vertices)
    # Arc lengths beyond the candidate are refused, not clamped to its ends; its own ends are
    # taken as given.
    length = float(arc[-1])
    for start, end in ((-1.0, 30.0), (10.0, length + 1.0), (float("nan"), 30.0)):
        with pytest.raises(GoniometerError, match="both within 0 to"):
            trim(candidate, start, end)
    whole = trim(candidate, 0.0, length)
    assert np.array_equal(whole.path.vertices, candidate.path.vertices)


def test_trim_of_a_loop_may_keep_the_part_through_its_start(bone):
    _, surface, result = bone
    loop = next(c for c in result.candidates if c.closed)
    arc = loop.path.arc_lengths
    start_arc, end_arc = 0.7 * loop.length, 0.2 * loop.length
    first = int(np.argmin(np.abs(arc - start_arc)))
    last = int(np.argmin(np.abs(arc - end_arc)))
    through = trim(loop, start_arc, end_arc)
    expected = np.concatenate([loop.path.vertices[first:], loop.path.vertices[1 : last + 1]])
    assert np.array_equal(through.path.vertices, expected)
    assert not through.closed and through.bend_deg.shape == expected.shape
    assert through.length == pytest.approx(loop.length - arc[first] + arc[last])
    # The two parts two cuts make are the whole loop.
    between = trim(loop, end_arc, start_arc)
    assert through.length + between.length == pytest.approx(loop.length)
    points = through.waypoint_points
    again = surface.trace_edge(points[0], points[-1], via=points[1:-1])
    assert np.array_equal(again.vertices, through.path.vertices)
    # An open candidate has no part through its start: the ends must come in order.
    opened = replace(loop, closed=False)
    with pytest.raises(GoniometerError, match="before the end"):
        trim(opened, start_arc, end_arc)


def test_steps_report_progress_and_leave_the_result(bone):
    _, surface, result = bone
    finder = BreakEdgeFinder(surface)
    assert finder.result is None
    progress = list(finder.steps())
    assert progress == sorted(progress) and progress[0] >= 0 and progress[-1] == 1.0
    assert [c.path.vertices.tolist() for c in finder.result.candidates] == [
        c.path.vertices.tolist() for c in result.candidates
    ]
    # Derived parameters are filled in, in the mesh's units.
    used = finder.result.parameters
    assert used.scale == pytest.approx(5 * result.candidates[0].path.mean_edge_length)
    assert used.min_length > 0 and used.min_region_area > 0


def test_bad_input_is_refused():
    fragment = bone_fragment(spacing=2.0)
    cloud = Surface(fragment.points)
    with pytest.raises(GoniometerError, match="point cloud"):
        find_break_edges(cloud)
    surface = Surface(fragment.points, fragment.triangles)
    for bend in (200, 0, 180):  # the message says what it takes: above 0, below 180
        with pytest.raises(GoniometerError, match=r"min_bend_deg must be .* above 0 and below 180"):
            find_break_edges(surface, min_bend_deg=bend)
    with pytest.raises(GoniometerError, match="scale"):
        find_break_edges(surface, scale=-1.0)
    with pytest.raises(GoniometerError, match="Unknown break-edge parameter"):
        find_break_edges(surface, bend=3)
    with pytest.raises(GoniometerError):
        BreakEdgeFinder(surface, BreakEdgeParameters(max_candidates=0))


def test_a_scale_or_length_beyond_the_mesh_is_refused_and_one_within_it_returns():
    """A scale of 1e12 once froze the finder; the oracle for the scale's bound is the bounding
    box, for the length's the mesh's distinct edges (each once) added up."""
    fragment = bone_fragment(spacing=2.0)
    surface = Surface(fragment.points, fragment.triangles)
    extent = surface.points.max(axis=0) - surface.points.min(axis=0)
    diagonal = float(np.sqrt(np.sum(extent**2)))
    for value in (1e12, 1.01 * diagonal):
        with pytest.raises(GoniometerError, match=r"scale.*larger than the whole mesh"):
            find_break_edges(surface, scale=value)
    triangles = np.asarray(fragment.triangles)
    pairs = np.unique(np.sort(triangles[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1), axis=0)
    points = np.asarray(fragment.points)
    edge_total = float(np.linalg.norm(points[pairs[:, 0]] - points[pairs[:, 1]], axis=1).sum())
    assert edge_total > 10 * diagonal
    # Beyond twice every edge (the bound counts an interior edge twice): nothing can reach it.
    with pytest.raises(GoniometerError, match=r"min_length.*no edge can reach it"):
        find_break_edges(surface, min_length=2.01 * edge_total)
    for name in ("scale", "min_length"):
        for value in (float("nan"), float("inf"), -1.0, 0.0):
            with pytest.raises(GoniometerError, match=name):
                find_break_edges(surface, **{name: value})
    # As large as allowed: one patch covers the mesh; it returns, with no candidate longer
    # than the mesh can hold.
    result = find_break_edges(surface, scale=0.99 * diagonal)
    assert result.parameters.scale == pytest.approx(0.99 * diagonal)
    assert result.region.shape == (surface.n_points,)
    result = find_break_edges(surface, min_length=0.99 * diagonal)
    assert all(c.length >= 0.99 * diagonal for c in result.candidates)
    result = find_break_edges(surface, min_length=1.01 * diagonal)  # allowed: finds none here
    assert all(c.length >= 1.01 * diagonal for c in result.candidates)


def test_a_min_length_beyond_the_bounding_box_finds_a_rim_that_long():
    """The flake's margin, the arc of a circle of radius 20 left by the platform at x = 14, is
    longer (93.8) than the flake is across (53.1); the oracle for its length is that arc."""
    fragment = flake()
    surface = Surface(fragment.points, fragment.triangles)
    extent = surface.points.max(axis=0) - surface.points.min(axis=0)
    diagonal = float(np.sqrt(np.sum(extent**2)))
    arc = 2 * (math.pi - math.acos(14 / 20)) * 20
    assert diagonal < 60 < arc
    result = find_break_edges(surface, min_length=60.0)
    (margin,) = result.candidates
    assert margin.length == pytest.approx(arc, rel=0.01)


def test_the_reference_lens_rim_is_found_as_one_loop(shared_data):
    """The intersecting spheres' rim is the circle x = 1 of radius √0.5 about (1, 1, 1)."""
    from vg_addon.formats.meshio import read_mesh
    from vg_addon.reference_shapes import SPHERE_CENTRES

    mesh = read_mesh(shared_data / "IntersectingSpheres.ply")
    surface = Surface(mesh.points, mesh.triangles)
    result = surface.find_break_edges()
    assert len(result.candidates) == 1
    rim = result.candidates[0]
    assert rim.closed
    centre = (np.array(SPHERE_CENTRES[0]) + SPHERE_CENTRES[1]) / 2
    offset = rim.path.points - centre
    radial = np.hypot(offset[:, 1], offset[:, 2])
    h = rim.path.mean_edge_length
    assert np.abs(offset[:, 0]).max() <= 2 * h
    assert np.abs(radial - np.sqrt(0.5)).max() <= 2 * h
    assert rim.length == pytest.approx(2 * np.pi * np.sqrt(0.5), rel=0.1)


def test_candidates_on_the_real_scan_retrace_and_follow_ridges(shared_data):
    from vg_addon.formats.meshio import read_mesh

    mesh = read_mesh(shared_data / "sample_mesh.ply")
    surface = Surface(mesh.points, mesh.triangles)
    result = surface.find_break_edges()
    assert result.candidates
    for candidate in result.candidates:
        points = candidate.waypoint_points
        again = surface.trace_edge(points[0], points[-1], via=points[1:-1])
        assert np.array_equal(again.vertices, candidate.path.vertices)
        assert candidate.length >= result.parameters.min_length
        assert 0.0 <= candidate.confidence <= 1.0
        # Most of the path bends at least the bar it was found with (judged at the scale).
        assert (candidate.bend_deg >= result.ridge_min_deg).mean() >= 0.8


def test_connected_parts_and_partial_pooling_match_plain_walks():
    """Oracles: a breadth-first search for the parts, whole-mesh pooling for the partial one."""
    from collections import deque

    from vg_addon.method.edge_profile import ridge_graph
    from vg_addon.method.mesh_regions import connected_parts
    from vg_addon.method.ridge_field import pooled_at

    fragment = bone_fragment(spacing=2.0)
    surface = Surface(fragment.points, fragment.triangles)
    graph = ridge_graph(surface)
    mask = fragment.region != REGION_RIM  # the rims cut the shaft into four faces
    labels = connected_parts(graph.starts, graph.target, mask)
    expected = np.full(mask.size, -1)
    for seed in np.flatnonzero(mask):
        if expected[seed] >= 0:
            continue
        queue, expected[seed] = deque([seed]), seed  # seeds in order: the least vertex
        while queue:
            v = queue.popleft()
            for w in graph.target[graph.starts[v] : graph.starts[v + 1]]:
                if mask[w] and expected[w] < 0:
                    expected[w] = seed
                    queue.append(w)
    assert np.array_equal(labels, expected) and np.unique(labels[mask]).size == 4
    values = np.random.default_rng(0).random((surface.n_points, 2))
    whole = values.copy()
    for _ in range(3):
        whole = whole + np.array(
            [whole[graph.target[graph.starts[v] : graph.starts[v + 1]]].sum(axis=0)
             for v in range(surface.n_points)]
        )  # fmt: skip
    rows = np.flatnonzero(fragment.region == REGION_RIM)
    partial = pooled_at(graph.starts, graph.target, values, 3, rows)
    assert np.allclose(partial[rows], whole[rows], rtol=1e-12)
    assert not partial[np.setdiff1d(np.arange(surface.n_points), rows)].any()


def test_dilate_by_more_rings_than_the_mesh_has_fills_the_seeds_part_and_returns():
    """Oracle: every vertex reachable from the seed (its connected part, by a plain walk)."""
    from vg_addon.method.edge_profile import ridge_graph
    from vg_addon.method.mesh_regions import connected_parts, dilate

    fragment = bone_fragment(spacing=2.0)
    surface = Surface(fragment.points, fragment.triangles)
    graph = ridge_graph(surface)
    seed = np.zeros(surface.n_points, dtype=bool)
    seed[0] = True
    everywhere = np.ones(surface.n_points, dtype=bool)
    part = connected_parts(graph.starts, graph.target, everywhere)
    grown = dilate(graph.starts, graph.target, seed, 10**12)
    assert np.array_equal(grown, part == part[0])


def test_a_scale_below_the_mesh_spacing_is_refused_and_one_just_above_it_runs():
    """The bound's oracle: the mesh's mean edge length, measured here from its edges."""
    fragment = bone_fragment(spacing=2.0)
    surface = Surface(fragment.points, fragment.triangles)
    edges = np.vstack([surface.triangles[:, [0, 1]], surface.triangles[:, [1, 2]],
                       surface.triangles[:, [2, 0]]])  # fmt: skip
    edges = np.unique(np.sort(edges, axis=1), axis=0)
    h = float(np.linalg.norm(np.diff(surface.points[edges], axis=1)[:, 0], axis=1).mean())
    for value in (1e-9, 0.5 * h, 0.95 * h):
        with pytest.raises(GoniometerError, match=r"scale.*smaller than the mesh's mean edge"):
            find_break_edges(surface, scale=value)
    result = find_break_edges(surface, scale=1.5 * h)
    assert result.parameters.scale == pytest.approx(1.5 * h)


def test_every_trim_of_a_marched_flakes_candidates_retraces():
    """On a mesh whose edges fall between vertices the cheapest ridge path between the two ends
    of one mesh edge can go round by a third vertex, which no via point can hold: 32 of these
    326 trims kept the direct edge (3 of 332 before the platform edge's ends were cut), so an edge file replayed the part one vertex apart from what
    was accepted. Oracle: ``trace_edge`` through each part's waypoints gives its vertices."""
    fragment = fragments.marched_flake()
    surface = Surface(fragment.points, fragment.triangles)
    trims = 0
    for candidate in surface.find_break_edges().candidates:
        arc = candidate.path.arc_lengths
        for k in range(1, arc.size - 2, 5):
            for start, end in ((arc[k], arc[-1]), (arc[0], arc[arc.size - 1 - k])):
                part = trim(candidate, start, end)
                points = part.waypoint_points
                again = surface.trace_edge(points[0], points[-1], via=points[1:-1])
                assert np.array_equal(again.vertices, part.path.vertices), (candidate.number, k)
                assert part.bend_deg.shape == part.path.vertices.shape
                trims += 1
    assert trims == 326
