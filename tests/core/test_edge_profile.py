"""Whole-edge measuring: tracing the ridge, stations along it, the profile's summary.

Oracles: the exact geometry of the shapes (a crease whose angle changes linearly along the x
axis, the circular rim of two intersecting spheres), a textbook Dijkstra for the cheapest path,
and on the real scan Algorithm 1's own split of each patch (the ridge is where the sides meet).
"""

import heapq

import numpy as np
import pytest

from vg_addon import GoniometerError, Surface
from vg_addon.formats.meshio import read_mesh
from vg_addon.method.given_points import check_given_points
from vg_addon.synthetic_meshes import lens, varying_wedge, wedge


@pytest.fixture(scope="module")
def ramp():
    shape = varying_wedge(80.0, 130.0, half_width=4.0, depth=1.0, n=30)
    return shape, Surface(shape.points, shape.triangles)


@pytest.fixture(scope="module")
def rim():
    shape = lens(70.53, radius=1.0, n_around=600)
    return shape, Surface(shape.points, shape.triangles)


def mean_edge_length(points, triangles):
    edges = np.vstack([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    edges = np.unique(np.sort(edges, axis=1), axis=0)
    return float(np.linalg.norm(points[edges[:, 0]] - points[edges[:, 1]], axis=1).mean())


def test_varying_wedge_path_follows_the_crease_and_stations_match_the_local_angle(ramp):
    shape, surface = ramp
    h = mean_edge_length(shape.points, shape.triangles)
    # Clicks a little off the crease, as a user's would be.
    path = surface.trace_edge([-3.5, 0.01, -0.005], [3.5, -0.01, -0.005])
    off_crease = np.linalg.norm(path.points[:, 1:], axis=1)
    assert off_crease.max() <= h
    assert path.flat_spans == () and path.warning == ""
    profile = surface.measure_along(path, spacing=0.5, radius=0.3)
    assert profile.n_stations == int(np.floor(path.length / 0.5)) + 1
    exact = shape.angle_at(np.array([m.center for m in profile.stations]))
    assert np.abs(profile.angles - exact).max() < 1.0, profile.angles - exact
    # The angle rises along the edge: the profile is a ramp of the right slope.
    slope = np.polyfit(profile.arc_lengths, profile.angles, 1)[0]
    assert slope == pytest.approx(50.0 / 8.0, rel=0.03)


def test_summary_equals_what_the_stations_say(ramp):
    _, surface = ramp
    profile = surface.measure_along([[-3, 0, 0], [3, 0, 0]], spacing=0.75, radius=0.3)
    angles = [m.angle for m in profile.stations]
    assert profile.angles.tolist() == angles
    assert profile.mean == pytest.approx(sum(angles) / len(angles), abs=1e-12)
    assert profile.min == min(angles) and profile.max == max(angles)
    mean = sum(angles) / len(angles)
    sample_std = (sum((a - mean) ** 2 for a in angles) / (len(angles) - 1)) ** 0.5
    assert profile.std == pytest.approx(sample_std, rel=1e-12)
    # One plane pair over all the sides averages the ramp: near the mean, inside the range.
    assert profile.min < profile.pooled_angle < profile.max
    assert profile.pooled_angle == pytest.approx(profile.mean, abs=1.0)
    assert f"{profile.n_stations} stations" in profile.summary()


@pytest.mark.parametrize("patch", ["euclidean", "geodesic"])
def test_stations_replay_bit_for_bit(ramp, patch):
    _, surface = ramp
    profile = surface.measure_along(
        [[-2, 0, 0], [2, 0, 0]], spacing=1.0, radius=0.3, lam=1.5, patch=patch
    )
    fresh = Surface(surface.points, surface.triangles)  # nothing cached
    for station in profile.stations:
        assert station.patch == patch
        again = fresh.measure(station.center, 0.3, 1.5, patch)
        assert again.angle == station.angle
        assert again.fit_error == station.fit_error
        assert np.array_equal(again.indices, station.indices)
        assert station.snap_distance == 0.0  # the centre is a path vertex


def test_stations_are_evenly_spaced_path_vertices(ramp):
    _, surface = ramp
    path = surface.trace_edge([-3, 0, 0], [3, 0, 0])
    profile = surface.measure_along(path, spacing=0.4, radius=0.3)
    on_path = {tuple(p) for p in path.points}
    assert all(tuple(m.center) in on_path for m in profile.stations)
    gaps = np.diff(profile.arc_lengths)
    step = path.length / (path.vertices.size - 1)
    assert np.abs(gaps - 0.4).max() <= step + 1e-12
    # Centred: the leftover length is split between both ends.
    assert abs(profile.arc_lengths[0] - (path.length - profile.arc_lengths[-1])) <= step + 1e-12


def test_lens_rim_constant_angle_all_round(rim):
    shape, surface = rim
    h = mean_edge_length(shape.points, shape.triangles)
    rho = np.linalg.norm(shape.points[shape.edge[0]])
    start, via, end = (shape.points[shape.edge[i]] for i in (0, 100, 200))
    path = surface.trace_edge(start, end, via=[via])
    # Distance of each path vertex to the rim circle (z = 0, radius rho).
    radial = np.linalg.norm(path.points[:, :2], axis=1)
    assert np.hypot(radial - rho, path.points[:, 2]).max() <= h
    assert path.length == pytest.approx(rho * 2 * np.pi * 200 / 600, rel=0.01)
    profile = surface.measure_along(path, spacing=0.1, radius=0.02)
    assert np.abs(profile.angles - 70.53).max() < 1.0, profile.angles
    assert profile.std < 0.1
    # Pooled in each station's own frame, a curved edge pools like a straight one.
    assert profile.pooled_angle == pytest.approx(profile.mean, abs=0.2)


def test_reference_lens_rim_is_traced_within_an_edge(shared_data):
    # The file's marching-cubes rim; the project's marching-tetrahedra lens bevels its rim about
    # three edge lengths wide, too wide for this bound.
    mesh = read_mesh(shared_data / "IntersectingSpheres.ply")
    surface = Surface(mesh.points, mesh.triangles)
    h = mean_edge_length(mesh.points, mesh.triangles)
    centred = surface.points - surface.points.mean(axis=0)
    axes = np.linalg.svd(centred, full_matrices=False)[2]
    axis = axes[2]  # the lens is thin along its axis
    height = centred @ axis
    radial = np.linalg.norm(centred - np.outer(height, axis), axis=1)
    rho = radial.max()
    ring = np.flatnonzero(radial > rho - h)
    in_plane = centred[ring] @ axes[:2].T
    angle = np.arctan2(in_plane[:, 1], in_plane[:, 0])
    start, end = ring[np.argmin(angle)], ring[np.argmin(np.abs(angle - 1.5))]
    path = surface.trace_edge(surface.points[start], surface.points[end])
    off_rim = np.hypot(radial[path.vertices] - rho, height[path.vertices])
    assert off_rim.max() <= h, (off_rim.max(), h)


def split_boundary_distance(surface, m):
    """Distance from ``m.center`` to where Algorithm 1's two sides meet: the nearest midpoint of
    a mesh edge inside the patch whose ends are on different sides."""
    side = np.full(surface.n_points, -1)
    side[m.indices] = m.labels.astype(int)
    t = surface.triangles
    edges = np.vstack([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    ends = side[edges]
    mixed = (ends >= 0).all(axis=1) & (ends[:, 0] != ends[:, 1])
    middles = surface.points[edges[mixed]].mean(axis=1)
    return np.linalg.norm(middles - m.center, axis=1).min()


def test_real_scan_path_stays_on_the_ridge(shared_data):
    mesh = read_mesh(shared_data / "sample_mesh.ply")
    surface = Surface(mesh.points, mesh.triangles)
    h = mean_edge_length(mesh.points, mesh.triangles)
    # The broken end: the sharpest vertices at the far end of the long axis (bends by brute force).
    centred = surface.points - surface.points.mean(axis=0)
    axes = np.linalg.svd(centred, full_matrices=False)[2]
    along, across = centred @ axes[0], centred @ axes[1]
    normals = np.cross(
        mesh.points[mesh.triangles[:, 1]] - mesh.points[mesh.triangles[:, 0]],
        mesh.points[mesh.triangles[:, 2]] - mesh.points[mesh.triangles[:, 0]],
    )
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    faces_of = {}
    for face, tri in enumerate(mesh.triangles):
        for k in range(3):
            faces_of.setdefault(tuple(sorted((tri[k], tri[(k + 1) % 3]))), []).append(face)
    sharpness = np.zeros(surface.n_points)
    for (a, b), faces in faces_of.items():
        if len(faces) == 2:
            bend = np.degrees(np.arccos(np.clip(normals[faces[0]] @ normals[faces[1]], -1, 1)))
            sharpness[a] = max(sharpness[a], bend)
            sharpness[b] = max(sharpness[b], bend)
    end_ridge = np.flatnonzero((sharpness > 60) & (along < along.min() + 6))
    a, b = end_ridge[np.argmin(across[end_ridge])], end_ridge[np.argmax(across[end_ridge])]
    path = surface.trace_edge(surface.points[a], surface.points[b])
    assert path.vertices.size > 20
    # The ridge as Algorithm 1 sees it in the smallest patches (radius about 2.3 mean edge
    # lengths): every path vertex within one edge length of it; larger patches blur the corner
    # at the path's end, but still place nearly all of the path on the ridge.
    local = [split_boundary_distance(surface, surface.measure(p, 1.5)) for p in path.points]
    assert max(local) <= h
    wider = [split_boundary_distance(surface, surface.measure(p, 2.0)) for p in path.points]
    assert np.mean(np.array(wider) <= h) >= 0.95
    profile = surface.measure_along(path, spacing=2.0, radius=3.0)
    assert 0.0 < profile.min <= profile.mean <= profile.max < 180.0


def textbook_dijkstra(points, triangles, costs_of, source, target):
    """Cheapest path by heapq Dijkstra over the mesh edges with a given edge-cost function."""
    neighbours = {}
    for tri in triangles:
        for k in range(3):
            u, v = int(tri[k]), int(tri[(k + 1) % 3])
            neighbours.setdefault(u, set()).add(v)
            neighbours.setdefault(v, set()).add(u)
    best = {source: 0.0}
    queue = [(0.0, source)]
    while queue:
        d, u = heapq.heappop(queue)
        if u == target:
            return d
        if d > best[u]:
            continue
        for v in neighbours[u]:
            candidate = d + costs_of(u, v)
            if candidate < best.get(v, np.inf):
                best[v] = candidate
                heapq.heappush(queue, (candidate, v))
    return np.inf


def test_traced_path_is_the_cheapest_under_the_documented_cost():
    mesh = wedge(120, n=14, irregular=True, seed=3)
    surface = Surface(mesh.points, mesh.triangles)
    normals = np.cross(
        mesh.points[mesh.triangles[:, 1]] - mesh.points[mesh.triangles[:, 0]],
        mesh.points[mesh.triangles[:, 2]] - mesh.points[mesh.triangles[:, 0]],
    )
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    faces_of = {}
    for face, tri in enumerate(mesh.triangles):
        for k in range(3):
            faces_of.setdefault(tuple(sorted((tri[k], tri[(k + 1) % 3]))), []).append(face)

    def cost(u, v):
        faces = faces_of[tuple(sorted((u, v)))]
        bend = 0.0
        if len(faces) == 2:
            bend = np.arccos(np.clip(normals[faces[0]] @ normals[faces[1]], -1, 1))
        length = np.linalg.norm(mesh.points[u] - mesh.points[v])
        return length * (0.02 + np.exp(-bend / np.radians(10.0)))

    rng = np.random.default_rng(7)
    for _ in range(6):
        a, b = rng.choice(mesh.points.shape[0], size=2, replace=False)
        path = surface.trace_edge(mesh.points[a], mesh.points[b])
        total = sum(cost(u, v) for u, v in zip(path.vertices[:-1], path.vertices[1:], strict=True))
        expected = textbook_dijkstra(mesh.points, mesh.triangles, cost, int(a), int(b))
        assert total == pytest.approx(expected, rel=1e-9)


def test_a_path_across_a_flat_face_is_reported():
    mesh = wedge(100, n=30)
    surface = Surface(mesh.points, mesh.triangles)
    c = np.cos(np.radians(50.0))
    s = np.sin(np.radians(50.0))
    # Both clicks on face +, far from the crease: no ridge joins them.
    path = surface.trace_edge([-0.8, 0.8 * s, -0.8 * c], [0.8, 0.8 * s, -0.8 * c])
    assert path.flat_spans and "no ridge" in path.warning
    with pytest.raises(GoniometerError, match="could not be measured") as caught:
        surface.measure_along(path, spacing=0.3, radius=0.2)
    assert "no ridge" in str(caught.value)  # the refusal carries the tracer's warning


def test_refusals_name_what_to_change(ramp):
    shape, surface = ramp
    with pytest.raises(GoniometerError, match="point cloud"):
        Surface(shape.points).trace_edge([-1, 0, 0], [1, 0, 0])
    with pytest.raises(GoniometerError, match="same vertex"):
        surface.trace_edge([0, 0, 0], [0.001, 0, 0])
    with pytest.raises(GoniometerError, match="spacing"):
        surface.measure_along([[-1, 0, 0], [1, 0, 0]], spacing=0.0, radius=0.3)
    with pytest.raises(GoniometerError, match="finer than the mesh"):
        surface.measure_along([[-1, 0, 0], [1, 0, 0]], spacing=0.001, radius=0.3)
    with pytest.raises(GoniometerError, match="at least two"):
        surface.measure_along([[0, 0, 0]], spacing=0.5, radius=0.3)
    with pytest.raises(GoniometerError, match="far from every vertex"):
        surface.trace_edge([0, 0, 0], [1e6, 0, 0])


def test_profile_does_not_depend_on_vertex_order(ramp):
    shape, surface = ramp
    rng = np.random.default_rng(1)
    order = rng.permutation(shape.points.shape[0])
    inverse = np.argsort(order)
    shuffled = Surface(shape.points[order], inverse[shape.triangles])
    a = surface.measure_along([[-2, 0, 0], [2, 0, 0]], spacing=0.5, radius=0.3)
    b = shuffled.measure_along([[-2, 0, 0], [2, 0, 0]], spacing=0.5, radius=0.3)
    assert a.angles.tolist() == b.angles.tolist()
    assert np.array_equal(a.path.points, b.path.points)
    assert a.pooled_angle == b.pooled_angle


def test_given_points_off_the_mesh_are_refused_with_their_distance(ramp):
    shape, surface = ramp
    h = mean_edge_length(shape.points, shape.triangles)
    crease = shape.points[(np.abs(shape.points[:, 1]) < 1e-12) & (shape.points[:, 2] == 0.0)]
    start = crease[np.argmin(np.abs(crease[:, 0] + 3.0))]
    end = crease[np.argmin(np.abs(crease[:, 0] - 3.0))]
    # On the mesh: accepted (a vertex, and a point half a mean edge length off the crease).
    check_given_points(surface, [start, end + np.array([0.0, 0.5 * h, 0.0])], 0.3, "ok.pp")
    # Picked on a copy 1.5 above: the crease is the wedge's top, so each point is exactly 1.5
    # from its own vertex and nearer no other.
    up = np.array([0.0, 0.0, 1.5])
    shifted = [start + up, end + up]
    with pytest.raises(GoniometerError) as error:
        check_given_points(surface, shifted, 0.3, "shifted.pp")
    message = str(error.value)
    assert message.startswith("shifted.pp: point 1 (")
    assert message.count(" is 1.5 from the mesh") == 2
    assert f"farther than {max(0.3, 3 * h):.6g}" in message
    # The limit is the radius when that is larger: 1.5 away is accepted with a radius of 2.
    check_given_points(surface, shifted, 2.0, "wide.pp")


@pytest.mark.parametrize("spacing", [2.0, 5.0])
def test_the_pooled_angle_lies_within_its_stations_range(spacing):
    """The whole-edge mean angle of a found edge, on the flake whose margin curves round a
    spherical cap and whose platform edges turn: one plane pair fitted to every station's
    vertices read 42.23° for the margin's stations of 43.06° to 45.12°, and 120.35° for stations
    of 45.69° to 118.28°. The oracle is the stations' own readings."""
    from vg_addon import fragments

    fragment = fragments.flake(spacing=0.5)
    surface = Surface(fragment.points, fragment.triangles)
    profiled = 0
    for candidate in surface.find_break_edges().candidates:
        try:
            profile = surface.measure_along(candidate.path, spacing, 2.5)
        except GoniometerError:
            continue  # a spacing finer than one of the path's segments: refused, said why
        profiled += 1
        assert profile.min <= profile.pooled_angle <= profile.max, profile.figures
        if profile.max - profile.min < 3.0:  # the margin: the pooled angle is its mean's
            assert profile.pooled_angle == pytest.approx(profile.mean, abs=0.5)
    assert profiled >= 2


@pytest.fixture(scope="module")
def concave():
    """A concave 100° crease on an irregular mesh: the paper's rule misreads it (about 134°)."""
    shape = wedge(100.0, half_width=2.0, n=40, irregular=True, concave=True)
    return Surface(shape.points, shape.triangles)


def test_stations_are_measured_with_the_rule_asked_for(concave):
    path = [[-1.5, 0, 0], [1.5, 0, 0]]
    paper = concave.measure_along(path, spacing=0.5, radius=0.4, rule="paper")
    default = concave.measure_along(path, spacing=0.5, radius=0.4)
    # Oracle: single measurements at each station's centre, each on a fresh surface.
    fresh = Surface(concave.points, concave.triangles)
    for station in paper.stations:
        single = fresh.measure(station.center, 0.4, rule="paper")
        assert station.rule == "paper"
        assert station.angle == single.angle and station.stability is None
    for station in default.stations:
        assert station.rule == "refined"
        assert station.angle == fresh.measure(station.center, 0.4).angle
    # The rule changed the reading: the concave edge reads 100° only under the refined rule.
    assert np.abs(default.angles - 100.0).max() < 0.01
    assert np.abs(paper.angles - 100.0).min() > 20.0


def test_stations_carry_the_stability_figure_when_asked(concave):
    path = [[-1.0, 0, 0], [1.0, 0, 0]]
    profile = concave.measure_along(path, spacing=1.0, radius=0.4, rule="oriented", stability=True)
    fresh = Surface(concave.points, concave.triangles)
    assert profile.n_stations >= 2
    for station in profile.stations:
        single = fresh.measure(station.center, 0.4, rule="oriented", stability=True)
        assert station.stability is not None
        assert station.stability == single.stability
        assert station.angle == single.angle


@pytest.mark.parametrize("stations", [1, 2, 3, 10, 40, 41, 109])
def test_a_loop_is_measured_once_round_at_each_place(stations):
    # The rim of two intersecting spheres traced from a point back to it: a loop. Before, a
    # spacing of length / k put a station at each end, on the same vertex, so that place was
    # counted twice in the mean, median and SD, and the chord length read 0.
    shape = lens(70.53, radius=1.0, n_around=240)
    surface = Surface(shape.points, shape.triangles)
    start, a, b = (shape.points[shape.edge[i]] for i in (0, 80, 160))
    path = surface.trace_edge(start, start, via=[a, b])
    assert path.vertices[0] == path.vertices[-1]
    assert path.revisited_spans == () and path.warning == ""  # closing on its start is no revisit
    profile = surface.measure_along(path, path.length / stations, radius=0.05)
    centres = np.array([m.center for m in profile.stations])
    assert profile.n_stations == stations
    assert len(np.unique(centres, axis=0)) == stations
    # Evenly round the loop, the seam included: each gap, the one from the last station back
    # to the first too, within one path segment of length / stations.
    gaps = np.diff(np.append(profile.arc_lengths, path.length + profile.arc_lengths[0]))
    segment = float(np.diff(path.arc_lengths).max())
    assert np.abs(gaps - path.length / stations).max() <= segment
    assert profile.mean == pytest.approx(np.mean([m.angle for m in profile.stations]), abs=1e-12)


def test_a_path_that_turns_back_is_not_measured_twice_at_one_vertex(ramp):
    _, surface = ramp
    there_and_back = surface.trace_edge([-3, 0, 0], [-2, 0, 0], via=[[3, 0, 0]])
    assert np.unique(there_and_back.vertices).size < there_and_back.vertices.size
    with pytest.raises(GoniometerError, match=r"same stretch twice, at arc lengths 1 to 5\.967"):
        surface.measure_along(there_and_back, spacing=0.5, radius=0.3)


@pytest.mark.parametrize("spacing", [0.35, 0.37, 0.41, 0.43])
def test_points_out_of_order_are_refused_whatever_the_spacing(spacing):
    """Picked points out of their order along the edge (-3.9, -1, 3, then 0.5): the path runs
    from x = 0.5 to 3 and back. At spacings 0.35, 0.41 and 0.43 no two stations met on a vertex,
    and the edge was measured with that stretch counted twice (a review: mean 90.96° where the
    points in order read 86.49°, the 60° to 120° ramp's mean over x from -3.9 to 3 being
    86.625°); at 0.37 it was refused, saying the spacing was finer than the mesh (its segments
    0.05 long). Now each is refused for what it is, and the points in order are measured."""
    shape = varying_wedge(60.0, 120.0, n=20)
    surface = Surface(shape.points, shape.triangles)
    with pytest.raises(GoniometerError, match="same stretch twice") as refused:
        surface.measure_along([[-3.9, 0, 0], [-1.0, 0, 0], [3.0, 0, 0], [0.5, 0, 0]], spacing, 0.4)
    assert "finer than the mesh" not in str(refused.value)
    in_order = surface.measure_along([[-3.9, 0, 0], [3.0, 0, 0]], spacing, 0.4)
    along = np.column_stack([np.linspace(-3.9, 3.0, 1001), np.zeros((1001, 2))])
    assert in_order.mean == pytest.approx(shape.angle_at(along).mean(), abs=0.3)


@pytest.mark.parametrize("spacing", ["0.2", None, 10**400, -1.0, 0.0, float("nan")])
def test_a_bad_spacing_is_refused_as_such_on_a_path_passed_twice(spacing):
    """The check of a stretch passed twice divided the spacing before it was checked: a text
    or None raised a TypeError, 10**400 an OverflowError, and -1 or 0 were refused as a path
    passed twice (a review of the change)."""
    shape = varying_wedge(60.0, 120.0, n=20)
    surface = Surface(shape.points, shape.triangles)
    with pytest.raises(GoniometerError, match="spacing must be a finite number greater than 0"):
        surface.measure_along([[-3.9, 0, 0], [3.0, 0, 0], [0.5, 0, 0]], spacing, 0.4)


def test_a_spur_shorter_than_half_a_spacing_is_measured(ramp):
    """A path out to a vertex and back (a spur, as a noisy ridge can leave): at most one station
    stands on it, so the edge is measured, its warning naming the spur."""
    shape, surface = ramp
    crease = np.sort(shape.points[shape.edge, 0])
    step = float(np.diff(crease).min())  # one edge along the crease
    path = surface.trace_edge([-3, 0, 0], [0, 0, 0], via=[[-1.0, 0, 0], [-1.0 - step, 0, 0]])
    assert path.revisited_spans and "passes the same vertices twice" in path.warning
    assert max(b - a for a, b in path.revisited_spans) < 0.25
    profile = surface.measure_along(path, spacing=0.5, radius=0.3)
    assert profile.path is path and len(profile.stations) == int(path.length // 0.5) + 1


def test_a_point_on_a_large_face_is_on_the_mesh_however_far_its_vertices():
    """A click recorded on a face much larger than the mesh's mean (a decimated flat region)
    lay farther than three mean edge lengths from every vertex, so the edge's own export was
    refused on re-import. Any point on a face is within its longest edge of one of its
    vertices: that is the limit's floor. A point off the mesh is still refused."""
    xs, ys = np.meshgrid(np.linspace(0.0, 1.0, 51), np.linspace(0.0, 1.0, 51))
    fine = np.column_stack([xs.ravel(), ys.ravel(), np.zeros(xs.size)])
    quads = [(j * 51 + i, j * 51 + i + 1, (j + 1) * 51 + i) for j in range(50) for i in range(50)]
    quads += [(j * 51 + i + 1, (j + 1) * 51 + i + 1, (j + 1) * 51 + i) for j in range(50)
              for i in range(50)]  # fmt: skip
    big = np.array([[2.0, 0.0, 0.0], [4.0, 0.0, 0.0], [3.0, 2.0, 0.0]])
    points = np.vstack([fine, big])
    triangles = np.array([*quads, (len(fine), len(fine) + 1, len(fine) + 2)])
    surface = Surface(points, triangles)
    centroid = big.mean(axis=0)
    nearest = np.linalg.norm(points - centroid, axis=1).min()
    assert nearest > 3 * mean_edge_length(points, triangles) and nearest > 0.1
    check_given_points(surface, [fine[0], centroid], 0.1, "clicked.csv")
    with pytest.raises(GoniometerError, match=r"point 2 .* from the mesh"):
        check_given_points(surface, [fine[0], centroid + np.array([0.0, 0.0, 2.5])], 0.1, "off.csv")


def test_a_one_station_profile_has_no_sd_and_says_so(ramp):
    """One station has no spread to speak of: its SD was given as 0°, as if the edge were
    known to be uniform. The oracle: ``statistics.stdev`` refuses one value."""
    import statistics

    from vg_addon.formats import csvio
    from vg_addon.formats.record_codec import figure_numbers

    _, surface = ramp
    profile = surface.measure_along([[-0.3, 0, 0], [0.3, 0, 0]], spacing=2.0, radius=0.3)
    assert profile.n_stations == 1
    with pytest.raises(statistics.StatisticsError):
        statistics.stdev(profile.angles.tolist())
    assert profile.std is None
    assert "SD undefined (one station)" in profile.summary()
    assert figure_numbers(profile.figures)["std"] is None
    text = csvio.format_edges_csv([csvio.EdgeRow(mesh_name="Ramp", edge_number=1, std=None)])
    header, row = text.splitlines()[:2]
    cells = dict(zip(header.split(","), row.split(","), strict=True))
    assert cells["SD Angle"] == ""
    (back,) = csvio.parse_edges_csv(text)
    assert back.std is None
