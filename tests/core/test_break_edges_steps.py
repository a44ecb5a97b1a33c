"""The break-edge finder in steps, and the mesh edges its ridge graph is built from.

Oracles: a stable sort of the half-edges (how the ridge graph used to be built) for the edges,
their faces and the neighbour lists; plain NumPy geometry for the lengths and bends; for the
steps, the finder's own result when run in one go, which the stepping must not change.
"""

import numpy as np
import pytest

from vg_addon import GoniometerError, Surface
from vg_addon.method.break_edges import BreakEdgeFinder, find_break_edges
from vg_addon.method.edge_profile import RidgeGraph
from vg_addon.method.mesh_edges import MeshEdges
from vg_addon.method.mesh_regions import sorted_unique
from vg_addon.method.stepping import finish
from vg_addon.synthetic_meshes import bone_fragment, wedge


def sorted_edges(n, triangles, valid):
    """(low, high, first face, second face or -1, starts, target) by stable sorts."""
    first = triangles.reshape(-1).astype(np.int64)
    second = triangles[:, [1, 2, 0]].reshape(-1).astype(np.int64)
    face = np.repeat(np.arange(triangles.shape[0]), 3)
    keep = valid[first] & valid[second] & (first != second)
    low, high = np.minimum(first, second)[keep], np.maximum(first, second)[keep]
    face = face[keep]
    order = np.argsort(low * n + high, kind="stable")
    low, high, face = low[order], high[order], face[order]
    new = np.ones(low.size, dtype=bool)
    new[1:] = (low[1:] != low[:-1]) | (high[1:] != high[:-1])
    runs = np.flatnonzero(new)
    shared = np.append(~new[1:], False)[runs]
    second_face = np.full(runs.size, -1)
    second_face[shared] = face[runs[shared] + 1]
    low, high = low[runs], high[runs]
    source = np.concatenate([low, high])
    order = np.argsort(source, kind="stable")
    starts = np.searchsorted(source[order], np.arange(n + 1))
    target = np.concatenate([high, low])[order]
    return low, high, face[runs], second_face, starts, target


def awkward_mesh():
    """A wedge with repeated faces (edges of four faces), degenerate faces, faces wound the
    other way, a vertex no face uses, and a few vertices left out."""
    mesh = wedge(60, n=12, irregular=True, seed=3)
    t = mesh.triangles
    triangles = np.concatenate([t, t[:5], t[10:13, [0, 0, 1]], t[20:23, [0, 2, 1]], t[40:41]])
    points = np.concatenate([mesh.points, [[3.0, 3.0, 3.0]]])
    valid = np.ones(len(points), dtype=bool)
    valid[::17] = False
    return points, triangles, valid


def assert_like_sorted(edges, points, triangles, valid):
    low, high, face1, face2, starts, target = sorted_edges(len(points), triangles, valid)
    for name, got, want in (
        ("low", edges.low, low),
        ("high", edges.high, high),
        ("first_face", edges.first_face, face1),
        ("second_face", edges.second_face, face2),
        ("starts", edges.starts, starts),
        ("target", edges.target, target),
    ):
        assert np.array_equal(got, want), name
    assert np.array_equal(edges.low[edges.edge], np.minimum(edges.target, np.repeat(
        np.arange(len(points)), np.diff(edges.starts))))  # fmt: skip
    assert np.allclose(edges.lengths, np.linalg.norm(points[low] - points[high], axis=1))


def test_mesh_edges_are_the_sorted_edges_with_their_first_two_faces():
    points, triangles, valid = awkward_mesh()
    edges = MeshEdges(points, triangles, valid)
    assert_like_sorted(edges, points, triangles, valid)
    assert (edges.second_face >= 0).sum() > 0 and (edges.second_face < 0).sum() > 0
    # Bends: the angle between the two faces' unit normals (zero normals on degenerate faces).
    normals = np.cross(*(points[triangles[:, k]] - points[triangles[:, 0]] for k in (1, 2)))
    length = np.linalg.norm(normals, axis=1, keepdims=True)
    normals = np.divide(normals, length, out=np.zeros_like(normals), where=length > 0)
    shared = edges.second_face >= 0
    cosine = (normals[edges.first_face[shared]] * normals[edges.second_face[shared]]).sum(axis=1)
    assert np.allclose(edges.bends[shared], np.arccos(np.clip(cosine, -1, 1)), atol=1e-7)
    assert not edges.bends[~shared].any()


def test_mesh_edges_and_ridge_graph_have_the_same_bits_whatever_the_block():
    points, triangles, valid = awkward_mesh()
    whole = MeshEdges(points, triangles, valid)
    steps = MeshEdges.stepwise(points, triangles, valid, block=5)
    count = 0
    while True:
        try:
            next(steps)
            count += 1
        except StopIteration as done:
            chunked = done.value
            break
    assert count > 3 * len(triangles) / 5  # a step per block of five faces or edges, at least
    for name in ("low", "high", "first_face", "second_face", "lengths", "bends", "starts"):
        assert np.array_equal(getattr(whole, name), getattr(chunked, name)), name
    assert np.array_equal(whole.target, chunked.target)
    one, other = RidgeGraph(points, triangles, valid), RidgeGraph(points, triangles, valid, chunked)
    for name in ("starts", "target", "costs", "vertex_bend"):
        assert np.array_equal(getattr(one, name), getattr(other, name)), name
    assert (one.ridge_min, one.mean_edge_length) == (other.ridge_min, other.mean_edge_length)


def test_mesh_edges_of_a_mesh_too_large_for_one_packed_sort_agree_with_the_sorted_ones():
    """5.2 million vertex numbers and 131,073 faces need 23 + 23 + 18 bits a half-edge: more than
    63, so the vertices are split into two ranges (only the numbers used have coordinates)."""
    n, m = 2**22 + 2**20, 2**17 + 1
    rng = np.random.default_rng(5)
    used = np.concatenate([np.arange(2**15), 2**22 + np.arange(2**15)])
    triangles = used[rng.integers(0, used.size, size=(m, 3))]
    points = np.zeros((n, 3))
    points[used] = rng.normal(size=(used.size, 3))
    valid = np.ones(n, dtype=bool)
    edges = MeshEdges(points, triangles, valid)
    assert edges.low.min() < 2**22 <= edges.low.max()  # edges from both ranges
    assert_like_sorted(edges, points, triangles, valid)


def test_sorted_unique_is_numpys_unique():
    values = np.random.default_rng(2).integers(-50, 50, size=1000)
    assert np.array_equal(sorted_unique(values), np.unique(values))
    assert sorted_unique(values[:0]).size == 0 and np.array_equal(
        sorted_unique(values[:1]), values[:1]
    )


@pytest.fixture(scope="module")
def rough_bone():
    fragment = bone_fragment(spacing=0.6, roughness=0.05, seed=1)
    return fragment, Surface(fragment.points, fragment.triangles).find_break_edges()


def same(result, other) -> bool:
    def key(r):
        return [
            (c.path.vertices.tolist(), c.path.waypoints.tolist(), c.confidence, c.bend_deg.tolist())
            for c in r.candidates
        ]

    return (
        key(result) == key(other)
        and np.array_equal(result.region, other.region)
        and np.array_equal(result.region_kind, other.region_kind)
        and result.ridge_min_deg == other.ridge_min_deg
    )


def test_the_result_does_not_depend_on_how_the_finder_is_stepped(rough_bone):
    fragment, result = rough_bone
    assert len(result.candidates) >= 2
    # Small steps: every phase chunked into many more steps.
    surface = Surface(fragment.points, fragment.triangles)
    small = BreakEdgeFinder(surface, step=64)
    count = sum(1 for _ in small.steps())
    assert same(small.result, result)
    assert count > 2 * sum(1 for _ in BreakEdgeFinder(Surface(fragment.points,
                                                              fragment.triangles)).steps())  # fmt: skip
    # Stopped halfway (Esc), then started again on the same surface; and two finders stepped
    # in turn, each building the ridge graph until the first one keeps it.
    surface = Surface(fragment.points, fragment.triangles)
    for _, _ in zip(range(count // 2), BreakEdgeFinder(surface, step=64).steps(), strict=False):
        pass
    assert same(find_break_edges(surface), result)
    surface = Surface(fragment.points, fragment.triangles)
    first, second = BreakEdgeFinder(surface, step=100), BreakEdgeFinder(surface, step=1000)
    pending = [iter(first.steps()), iter(second.steps())]
    while pending:
        for work in list(pending):
            if next(work, None) is None:
                pending.remove(work)
    assert same(first.result, result) and same(second.result, result)


def test_steps_grow_with_the_mesh():
    counts = []
    for spacing in (2.0, 1.0):
        fragment = bone_fragment(spacing=spacing)
        finder = BreakEdgeFinder(Surface(fragment.points, fragment.triangles), step=512)
        progress = list(finder.steps())
        assert progress == sorted(progress) and progress[-1] == 1.0
        counts.append((len(fragment.points), len(progress)))
    (small_n, small_steps), (large_n, large_steps) = counts
    assert large_n > 3 * small_n and large_steps > small_steps + large_n // 512


@pytest.mark.parametrize("step", [0, -5, 2.5, True, "10"])
def test_a_bad_step_is_refused(step):
    fragment = bone_fragment(spacing=2.0)
    with pytest.raises(GoniometerError, match="step"):
        BreakEdgeFinder(Surface(fragment.points, fragment.triangles), step=step)


def test_stepwise_helpers_finish_to_the_plain_result():
    from vg_addon.method.edge_profile import ridge_graph
    from vg_addon.method.ridge_field import vertex_moments

    fragment = bone_fragment(spacing=1.5)
    surface = Surface(fragment.points, fragment.triangles)
    graph = ridge_graph(surface)
    args = (surface.points, surface.triangles, graph.starts, graph.target)
    whole = finish(vertex_moments(*args))
    assert np.array_equal(finish(vertex_moments(*args, block=33)), whole)
    assert whole.shape == (surface.n_points, 10)
    assert np.allclose(whole[:, 0].sum(), np.linalg.norm(np.cross(
        *(fragment.points[fragment.triangles[:, k]] - fragment.points[fragment.triangles[:, 0]]
          for k in (1, 2))), axis=1).sum() / 2)  # fmt: skip
