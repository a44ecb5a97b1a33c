"""Spatial index, patch selection (Euclidean and geodesic), snapping and normals."""

import heapq

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vg_addon import GoniometerError, GridIndex, Surface
from vg_addon.method.normals import vertex_normals
from vg_addon.method.spatial import estimate_spacing
from vg_addon.synthetic_meshes import wedge


@settings(max_examples=60, deadline=None)
@given(
    n=st.integers(1, 400),
    seed=st.integers(0, 1000),
    radius=st.floats(0.001, 3.0),
    flat=st.booleans(),
)
def test_ball_equals_brute_force(n, seed, radius, flat):
    rng = np.random.default_rng(seed)
    points = rng.uniform(-1, 1, size=(n, 3))
    if flat:
        points[:, 2] = 0.0
    index = GridIndex(points)
    center = rng.uniform(-1.5, 1.5, size=3)
    ids, distances = index.ball(center, radius)
    expected = np.flatnonzero(np.linalg.norm(points - center, axis=1) <= radius)
    assert np.array_equal(np.sort(ids), expected)
    assert np.allclose(distances, np.linalg.norm(points[ids] - center, axis=1))


@settings(max_examples=60, deadline=None)
@given(n=st.integers(1, 300), seed=st.integers(0, 1000), limit=st.floats(0.01, 5.0))
def test_nearest_equals_brute_force(n, seed, limit):
    rng = np.random.default_rng(seed)
    points = rng.normal(size=(n, 3))
    center = rng.normal(size=3)
    vertex, distance = GridIndex(points).nearest(center, limit)
    all_distances = np.linalg.norm(points - center, axis=1)
    if all_distances.min() > limit:
        assert vertex == -1
    else:
        assert distance == pytest.approx(all_distances.min())
        assert all_distances[vertex] == pytest.approx(all_distances.min())


def dijkstra(points, triangles, source, radius):
    """Textbook Dijkstra along mesh edges, for checking the vectorised version."""
    neighbours = {}
    for a, b, c in triangles:
        for u, v in ((a, b), (b, c), (c, a)):
            neighbours.setdefault(u, set()).add(v)
            neighbours.setdefault(v, set()).add(u)
    distance = {source: 0.0}
    queue = [(0.0, source)]
    while queue:
        d, u = heapq.heappop(queue)
        if d > distance.get(u, np.inf):
            continue
        for v in neighbours.get(u, ()):
            candidate = d + float(np.linalg.norm(points[u] - points[v]))
            if candidate <= radius and candidate < distance.get(v, np.inf):
                distance[v] = candidate
                heapq.heappush(queue, (candidate, v))
    return distance


@pytest.mark.parametrize("seed", range(4))
def test_geodesic_patch_equals_dijkstra(seed):
    mesh = wedge(60 + 20 * seed, n=24, irregular=True, seed=seed)
    surface = Surface(mesh.points, mesh.triangles)
    center_index, _ = surface.snap([0.02, 0.0, 0.0], 1.0)
    radius = 0.45
    patch = surface.patch(center_index, radius, "geodesic")
    expected = dijkstra(mesh.points, mesh.triangles, center_index, radius)
    assert set(patch.tolist()) == set(expected)


def test_geodesic_patch_is_inside_the_euclidean_patch():
    mesh = wedge(30, n=40, irregular=True, seed=2)
    surface = Surface(mesh.points, mesh.triangles)
    center_index, _ = surface.snap([0.0, 0.0, 0.0], 1.0)
    geodesic = set(surface.patch(center_index, 0.5, "geodesic").tolist())
    euclidean = set(surface.patch(center_index, 0.5, "euclidean").tolist())
    assert geodesic < euclidean


def test_geodesic_measure_reads_the_angle():
    mesh = wedge(75, n=60, irregular=True, seed=4)
    m = Surface(mesh.points, mesh.triangles).measure([0, 0, 0], 0.5, patch="geodesic")
    assert m.patch == "geodesic"
    assert m.angle == pytest.approx(75, abs=0.5)


def test_geodesic_needs_faces():
    mesh = wedge(75, n=30)
    surface = Surface(mesh.points, normals=np.tile([0.0, 0.0, 1.0], (len(mesh.points), 1)))
    with pytest.raises(GoniometerError, match="point cloud"):
        surface.patch(0, 0.5, "geodesic")


def test_centre_snaps_to_the_nearest_vertex():
    mesh = wedge(90, n=40)
    surface = Surface(mesh.points, mesh.triangles)
    target = mesh.points[123]
    m = surface.measure(target + np.array([0.001, 0.0, 0.0]), 0.5)
    nearest = np.argmin(np.linalg.norm(mesh.points - m.requested_center, axis=1))
    assert np.array_equal(m.center, mesh.points[nearest])
    assert m.snap_distance == pytest.approx(np.linalg.norm(m.requested_center - m.center))
    replay = surface.measure(m.center, 0.5)
    assert replay.snap_distance == 0.0
    assert replay.angle == m.angle


def test_area_weighted_normals_point_outward_on_a_wedge():
    mesh = wedge(90, n=20)
    normals, valid = vertex_normals(mesh.points, mesh.triangles)
    assert valid.all()
    assert np.allclose(np.linalg.norm(normals, axis=1), 1.0)
    plus = mesh.side > 0
    assert np.allclose(normals[plus], normals[plus][0])
    assert (normals[:, 2] > 0).all()


def test_unreferenced_vertices_and_zero_area_faces_never_give_nan():
    mesh = wedge(90, n=20)
    points = np.vstack([mesh.points, [[5.0, 5.0, 5.0]]])  # unreferenced
    degenerate = [[0, 0, 1], [2, 2, 2]]  # zero area
    triangles = np.vstack([mesh.triangles, degenerate])
    normals, valid = vertex_normals(points, triangles)
    assert np.isfinite(normals).all()
    assert not valid[-1]
    surface = Surface(points, triangles)
    with pytest.raises(GoniometerError, match="farther"):
        surface.measure([5.0, 5.0, 5.0], 0.1)  # the stray vertex is never snapped to
    assert np.isfinite(surface.measure([0, 0, 0], 0.5).angle)


@pytest.mark.parametrize("angle", [30, 45, 60, 100, 150])
@pytest.mark.parametrize("offset", [0.0, 1e6])
def test_point_cloud_normals_are_consistent_and_measure(angle, offset):
    mesh = wedge(angle, n=50, irregular=True, seed=1)
    cloud = Surface(mesh.points + offset)  # no faces: PCA normals
    with_faces = Surface(mesh.points, mesh.triangles)
    agree = np.einsum("ij,ij->i", cloud.normals, with_faces.normals)
    away_from_crease = np.abs(mesh.points[:, 1]) > 0.1 * np.abs(mesh.points[:, 1]).max()
    assert (agree[cloud.valid & away_from_crease] > 0.9).mean() > 0.95
    m = cloud.measure(np.full(3, offset), 0.5)
    assert m.angle == pytest.approx(angle, abs=1.5)


def test_point_cloud_normals_point_outward_on_a_sphere():
    rng = np.random.default_rng(0)
    points = rng.normal(size=(4000, 3))
    points /= np.linalg.norm(points, axis=1, keepdims=True)
    surface = Surface(points + np.array([3.0, -1.0, 2.0]))
    outward = np.einsum("ij,ij->i", surface.normals, points)
    assert (outward[surface.valid] > 0.9).all()


def test_point_cloud_normals_face_outward_on_a_hollow_shaft():
    """The medullary wall of a shaft faces its centroid: a centroid rule alone would flip it."""
    from vg_addon.synthetic_meshes import bone_fragment

    fragment = bone_fragment()
    cloud = Surface(fragment.points)
    mesh = Surface(fragment.points, fragment.triangles)
    agree = np.einsum("ij,ij->i", cloud.normals, mesh.normals)[cloud.valid]
    assert (agree > 0.5).mean() > 0.99
    for site in fragment.sites:
        assert cloud.measure(site.point, 1.0).angle == pytest.approx(site.angle, abs=2.5)


def _restricted_dijkstra(points, triangles, vertices, source, radius):
    """Textbook Dijkstra on the edges between ``vertices``; inf where farther than ``radius``.

    Each edge's length is ``np.linalg.norm(points[low] - points[high], axis=1)`` over the edge
    list (low < high), the definition the patches use (the norm of a single 3-vector rounds
    differently)."""
    inside = set(vertices.tolist())
    edges = {
        (min(u, v), max(u, v))
        for a, b, c in np.asarray(triangles).tolist()
        for u, v in ((a, b), (b, c), (c, a))
        if u in inside and v in inside
    }
    low, high = np.array(sorted(edges), dtype=np.int64).reshape(-1, 2).T
    lengths = np.linalg.norm(points[low] - points[high], axis=1)
    neighbours = {}
    for u, v, w in zip(low.tolist(), high.tolist(), lengths.tolist(), strict=True):
        neighbours.setdefault(u, []).append((v, w))
        neighbours.setdefault(v, []).append((u, w))
    distance = {source: 0.0}
    queue = [(0.0, source)]
    while queue:
        d, u = heapq.heappop(queue)
        if d > distance[u]:
            continue
        for v, w in neighbours.get(u, ()):
            candidate = d + w
            if candidate <= radius and candidate < distance.get(v, np.inf):
                distance[v] = candidate
                heapq.heappush(queue, (candidate, v))
    return np.array([distance.get(v, np.inf) for v in vertices.tolist()])


@pytest.mark.parametrize("case", ["wedge", "int32", "open", "collapsed", "non-manifold"])
def test_geodesic_distances_equal_dijkstra_bit_for_bit(case, monkeypatch):
    """Every distance, not just the patch: the per-patch edge list gives the same edges, with
    the same lengths, as a graph over the whole mesh."""
    from vg_addon.method import geodesic
    from vg_addon.method.geodesic import EdgeGraph

    monkeypatch.setattr(geodesic, "_CHUNK", 7)  # the table is built in many blocks

    mesh = wedge(70, n=30, irregular=True, seed=5)
    points, triangles = mesh.points, mesh.triangles
    if case == "int32":
        triangles = triangles.astype(np.int32)
    elif case == "open":  # holes: some faces missing
        triangles = triangles[np.random.default_rng(0).random(len(triangles)) > 0.2]
    elif case == "collapsed":
        triangles = triangles.copy()
        triangles[::7, 1] = triangles[::7, 0]
    elif case == "non-manifold":  # a fin on existing edges, and a face repeated
        extra = len(points)
        points = np.vstack([points, points[:40] + np.array([0.0, 0.0, 0.05])])
        fins = np.column_stack([triangles[:40, 0], triangles[:40, 1], extra + np.arange(40)])
        triangles = np.vstack([triangles, fins, triangles[:10]])
    graph = EdgeGraph(points, triangles)
    index = GridIndex(points)
    for center, radius in (([0.0, 0.0, 0.0], 0.4), ([0.3, 0.2, -0.1], 0.25), ([-0.5, 0, 0], 1e-3)):
        source, _ = index.nearest(np.array(center), 1.0)
        vertices, _ = index.ball(points[source], radius)
        got = graph.distances(vertices, source, radius)
        expected = _restricted_dijkstra(points, triangles, vertices, source, radius)
        assert got.tobytes() == expected.tobytes()


def test_int32_triangles_are_used_without_a_copy_and_measure_the_same():
    mesh = wedge(80, n=40, irregular=True, seed=3)
    given = mesh.triangles.astype(np.int32)
    narrow = Surface(mesh.points, given)
    wide = Surface(mesh.points, mesh.triangles)
    assert narrow.triangles is given
    assert wide.triangles.dtype == np.int64
    assert narrow.normals.tobytes() == wide.normals.tobytes()
    for patch in ("euclidean", "geodesic"):
        a = narrow.measure([0.1, 0.0, 0.0], 0.4, patch=patch)
        b = wide.measure([0.1, 0.0, 0.0], 0.4, patch=patch)
        assert (a.angle, a.fit_error, a.threshold) == (b.angle, b.fit_error, b.threshold)
        assert a.indices.dtype == np.int64
        assert a.indices.tobytes() == b.indices.tobytes()


def test_corner_edges_are_checked():
    mesh = wedge(80, n=10)
    with pytest.raises(GoniometerError, match="corner edges"):
        Surface(mesh.points, mesh.triangles, corner_edges=np.arange(5))
    with pytest.raises(GoniometerError, match="negative"):
        Surface(mesh.points, mesh.triangles, corner_edges=-np.ones(mesh.triangles.shape, dtype=int))


@pytest.mark.parametrize("far", [1e308, -1e308, 1.7e308])
def test_a_centre_as_far_as_a_double_reaches_is_refused_not_a_traceback(far):
    """Before, a finite centre 1e308 away made the grid's cell number infinite, and turning it
    into an integer raised OverflowError through measure, measure_along and the operators."""
    shape = wedge(90.0, n=20)
    surface = Surface(shape.points, shape.triangles)
    for axis in range(3):
        center = [0.0, 0.0, 0.0]
        center[axis] = far
        with pytest.raises(GoniometerError, match="farther than the radius"):
            surface.measure(center, 0.3)
        with pytest.raises(GoniometerError):
            surface.measure_along([center, [0.5, 0.0, 0.0]], 0.2, 0.3)
    grid = GridIndex(shape.points, 0.1)
    assert grid.ball([far, 0.0, 0.0], 0.3)[0].size == 0
    assert grid.nearest([far, 0.0, 0.0], 1.0) == (-1, float("inf"))


@pytest.mark.parametrize("far", [1e2, 1e4])
def test_a_stray_point_far_from_a_point_cloud_changes_no_other_normal(far):
    # Before, a stray point set the extent the spacing estimate's grid starts from: 1,000 object
    # sizes away it made the estimate 5 times too large, the normals pooled whole regions (25 s
    # for a 45,000-point cloud) and 100,000 away the memory ran out. Oracle: the same cloud
    # without the stray point, and a brute-force nearest-neighbour distance.
    mesh = wedge(100, n=60, irregular=True, seed=1)
    clean = Surface(mesh.points)
    stray = Surface(np.vstack([mesh.points, [[far, -far, far]]]))
    # The same up to rounding: the grid's cells start elsewhere, so sums run in another order.
    assert np.abs(stray.normals[:-1] - clean.normals).max() < 1e-12 and not stray.valid[-1]
    angle = stray.measure([0, 0, 0], 0.5).angle
    assert angle == pytest.approx(clean.measure([0, 0, 0], 0.5).angle, abs=1e-9)
    some = mesh.points[:: mesh.points.shape[0] // 400]
    gaps = np.linalg.norm(some[:, None] - mesh.points[None], axis=2)
    gaps[gaps == 0.0] = np.inf  # each point's distance to itself
    nearest = float(np.median(gaps.min(axis=1)))
    estimate = estimate_spacing(np.vstack([mesh.points, [[far, -far, far]]]))
    assert nearest / 2 < estimate < 2 * nearest, (estimate, nearest)


def test_a_point_cloud_too_wide_for_its_grid_is_refused_not_left_to_exhaust_memory():
    mesh = wedge(100, n=60, irregular=True, seed=1)
    with pytest.raises(GoniometerError, match="far from the rest"):
        Surface(np.vstack([mesh.points, [[1e9, 0.0, 0.0]]]))


def test_an_unsigned_index_past_the_vertices_is_named_as_given():
    """A uint64 index of 2⁶³ or more wrapped negative in the cast to int64, and the refusal
    named "vertex -9223372036854775808"."""
    shape = wedge(100, n=10)
    triangles = shape.triangles.astype(np.uint64)
    triangles[-1, 2] = np.uint64(2**63 + 5)
    with pytest.raises(GoniometerError, match=f"refers to vertex {2**63 + 5}, but the mesh"):
        Surface(shape.points, triangles)


def test_a_geodesic_patch_on_an_unwelded_mesh_says_why_it_is_small():
    """An STL keeps each triangle's own corners: no edge joins one triangle to the next, so a
    geodesic patch holds one triangle whatever the radius. It was refused as "holds only 3
    vertices ... use a larger radius", which no radius helps; the Euclidean patch reads it."""
    shape = wedge(100.0, n=30)
    corners = shape.points[shape.triangles.ravel()]  # every triangle its own three vertices
    triangles = np.arange(corners.shape[0]).reshape(-1, 3)
    surface = Surface(corners, triangles)
    with pytest.raises(GoniometerError, match=r"stops at a seam: 3 of the vertices.*Merge by"):
        surface.measure([0.0, 0.0, 0.0], 0.4, patch="geodesic")
    assert abs(surface.measure([0.0, 0.0, 0.0], 0.4).angle - 100.0) < 0.01


def seamed_wedge(angle, bend):
    """A wedge whose faces bend away from the crease (``bend · t²``, level at the crease, so
    the angle there stays ``angle``), its crease vertices copied for the minus face's
    triangles: a seam along the break edge, as an export with split sharp edges writes it."""
    shape = wedge(angle, n=60, irregular=True, seed=4)
    side = shape.side
    across = np.hypot(shape.points[:, 1], shape.points[:, 2])
    normal = np.where(side[:, None] == 1, shape.normal_plus, shape.normal_minus)
    points = shape.points + np.where(side[:, None] == 0, 0.0, normal) * (bend * across**2)[:, None]
    crease = np.flatnonzero(side == 0)
    copy = np.arange(len(points))
    copy[crease] = len(points) + np.arange(crease.size)
    triangles = shape.triangles.copy()
    on_minus = (side[shape.triangles] == -1).any(axis=1)
    triangles[on_minus] = copy[shape.triangles[on_minus]]
    return shape, np.vstack([points, points[crease]]), triangles


@pytest.mark.parametrize("bend", [0.05, 0.3])
def test_a_geodesic_patch_stopped_by_a_seam_along_the_edge_is_refused(bend):
    """A mesh unmerged along its break edge: the geodesic patch never crosses it and holds one
    face, which Algorithm 1 split in two. A 60° edge read 179.44° (bend 0.05) and 176.64° (0.3),
    fit errors smaller than the merged mesh's, no flag. Oracle: the wedge's construction, and
    the same patch on the merged mesh (the seam's copies joined), which reads 61.0° and 65.9°
    (its walls curve away from the edge: the planes are secants), nowhere near flat."""
    shape, points, triangles = seamed_wedge(60.0, bend)
    merged = Surface(points[: len(shape.points)], shape.triangles)
    assert 60.0 < merged.measure([0.005, 0, 0], 0.2, patch="geodesic").angle < 67.0
    seamed = Surface(points, triangles)
    with pytest.raises(GoniometerError, match=r"stops at a seam: \d+ of the vertices.*Merge by"):
        seamed.measure([0.005, 0, 0], 0.2, patch="geodesic")
    assert (
        abs(seamed.measure([0.005, 0, 0], 0.2).angle - merged.measure([0.005, 0, 0], 0.2).angle)
        < 0.5
    )


def test_a_seam_the_measured_patch_does_not_reach_refuses_nothing():
    """A seam along a row 0.24 from the crease, beyond a geodesic patch of radius 0.24 (it
    reaches the row's vertices, not their copies' faces): the reading and its stability figure
    are those of the merged mesh; the figure's moved and widened patches, which reach the seam,
    stop there as before instead of refusing the click (a review found them refusing it). Two
    parts touching at one vertex (a refitted fragment) refuse nothing either."""
    shape = wedge(100.0, n=60)
    across = np.hypot(shape.points[:, 1], shape.points[:, 2])
    rows = np.unique(np.round(across[shape.side == 1], 9))
    row = rows[np.argmin(np.abs(rows - 0.25))]
    on_row = np.flatnonzero((shape.side == 1) & (np.abs(across - row) < 1e-9))
    copy = np.arange(len(shape.points))
    copy[on_row] = len(shape.points) + np.arange(on_row.size)
    beyond = (shape.side[shape.triangles] == 1).all(axis=1) & (
        across[shape.triangles] > row - 1e-9
    ).all(axis=1)
    triangles = shape.triangles.copy()
    triangles[beyond] = copy[shape.triangles[beyond]]
    seamed = Surface(np.vstack([shape.points, shape.points[on_row]]), triangles)
    merged = Surface(shape.points, shape.triangles)
    readings = [
        surface.measure([0, 0, 0], 0.24, patch="geodesic", stability=True)
        for surface in (seamed, merged)
    ]
    assert abs(readings[0].angle - 100.0) < 1e-6
    assert readings[0].stability.spread < 1e-6 and readings[1].stability.spread < 1e-6
    vertex = shape.points[np.argmin(np.linalg.norm(shape.points - [0.1, 0.1, -0.1], axis=1))]
    corners = vertex + np.array([[0, 0, 0], [0.05, 0, 0.3], [-0.05, 0, 0.3]])
    touching = np.vstack([shape.points, corners])
    extra = len(shape.points) + np.arange(3)
    part = Surface(touching, np.vstack([shape.triangles, extra]))
    assert abs(part.measure([0, 0, 0], 0.3, patch="geodesic").angle - 100.0) < 1e-6
