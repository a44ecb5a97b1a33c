"""A Euclidean patch reaching a separate part of the mesh (another fragment, loose debris) is
refused; parts joined by vertices at the same coordinates (a seam not merged) are one surface."""

import re

import numpy as np
import pytest
from defect_meshes import wedge_with_debris, wedge_with_fragment

from vg_addon import GoniometerError, Surface
from vg_addon.method.parts import measured_part, mesh_parts, part_labels
from vg_addon.method.stability import estimate_stability
from vg_addon.reference_shapes import marched_wedge
from vg_addon.synthetic_meshes import wedge

PAPER_MESSAGE = r"lie on a separate part of the mesh.*paper rule.*By Loose Parts"
RULES = ("refined", "oriented", "paper")


@pytest.mark.parametrize("angle", [90.0, 120.0])
def test_a_fragment_set_against_a_face_is_left_out_of_the_patch(angle):
    """Before, the Euclidean patch took the fragment's sheet (0.005 from the +1 face) too: the
    refined rule read 45.00° for 90° and 30.00° for 120°, with nothing to show it. The patch is
    the wedge's part alone, as the geodesic patch reads it; the paper rule, which takes the
    whole ball, is refused."""
    points, triangles = wedge_with_fragment(angle, 0.005)
    surface = Surface(points, triangles)
    wedge_vertices = len(wedge(angle, n=60).points)
    for rule in ("refined", "oriented"):
        m = surface.measure([-0.3, 0, 0], 0.3, rule=rule, stability=True)
        assert m.angle == pytest.approx(angle) and m.stability.spread < 1e-6
        assert m.indices.max() < wedge_vertices
        ball = np.linalg.norm(points - m.center, axis=1) <= 0.3
        assert m.n_vertices == np.count_nonzero(ball[:wedge_vertices])
        # The figure of a surface not measured yet leaves the fragment out too (second review).
        assert estimate_stability(Surface(points, triangles), m) == m.stability
    with pytest.raises(GoniometerError, match=PAPER_MESSAGE):
        surface.measure([-0.3, 0, 0], 0.3, rule="paper")
    assert surface.measure([-0.3, 0, 0], 0.3, patch="geodesic").angle == pytest.approx(angle)
    assert surface.measure([0.6, 0, 0], 0.3, rule="paper").angle == pytest.approx(angle)


@pytest.mark.parametrize(("count", "extent"), [(2500, 0.5), (900, 0.3)])
def test_a_large_sheet_of_debris_is_left_out(count, extent):
    """A crumpled sheet of debris 0.05 above a 90° edge: before, every rule read 92.21° (2,500
    vertices reaching past the ball, 662 of the 1,163 in it) and 66.56° (900, 640 of 1,141).
    Now the refined and oriented rules read the wedge alone, and the paper rule, which takes
    the whole ball, is refused."""
    points, triangles = wedge_with_debris(90.0, count, extent=extent)
    surface = Surface(points, triangles)
    wedge_vertices = len(wedge(90.0, n=60).points)
    for rule in ("refined", "oriented"):
        m = surface.measure([0, 0, 0], 0.3, rule=rule)
        assert m.angle == pytest.approx(90.0) and m.indices.max() < wedge_vertices
    with pytest.raises(GoniometerError, match=PAPER_MESSAGE):
        surface.measure([0, 0, 0], 0.3, rule="paper")


def _joined_by_faces_without_area(points, triangles):
    """The same mesh made one part by a face without area from each part's least vertex to
    vertex 0 (a repeated corner): its normals are the same bits, and no vertex is left out."""
    labels, _ = mesh_parts(points, triangles)
    used = np.unique(triangles)
    firsts = used[np.unique(labels[used], return_index=True)[1]]
    extra = np.column_stack([np.zeros_like(firsts), firsts, firsts])
    return Surface(points, np.vstack([triangles, extra]))


def test_crumbs_stay_in_the_patch_as_before():
    """A part with fewer vertices in all than the rest of the ball holds is a crumb: debris, or
    a bead of a thin edge, which can lie on the surface measured (the beads of a marched 20°
    wedge's crease carry it, `test_refinement.py`). It is kept, under every rule, wherever the
    click lands: the measurement, its stability figure too, is the one taken where faces join
    the crumbs to the rest (a 36-vertex sheet over a 90° edge: 90.00° refined, 81.06° oriented
    and paper, a limit the stability figure flags; the beads of a turned 5° marched wedge)."""
    points, triangles = wedge_with_debris(90.0, 36)
    first = len(points) - 36
    crumb = points[first:][np.argmin(np.linalg.norm(points[first:], axis=1))]
    beads, bead_faces, _, direction = marched_wedge(5, 0.03, turn_seed=3)
    near = beads[np.argsort(np.linalg.norm(np.cross(beads, direction), axis=1))[:40:8]]
    cases = [(points, triangles, [[0, 0, 0], crumb], 0.3), (beads, bead_faces, near, 0.15)]
    for points, triangles, centres, radius in cases:
        surface = Surface(points, triangles)
        assert np.unique(mesh_parts(points, triangles)[0]).size > 1
        joined = _joined_by_faces_without_area(points, triangles)
        for where in centres:
            for rule in RULES:
                try:
                    expected = joined.measure(where, radius, rule=rule, stability=True)
                except GoniometerError as error:
                    with pytest.raises(GoniometerError, match=re.escape(str(error))):
                        surface.measure(where, radius, rule=rule, stability=True)
                    continue
                m = surface.measure(where, radius, rule=rule, stability=True)
                assert repr(m) == repr(expected)


def test_the_large_parts_other_than_the_measured_one_are_left_out():
    """The rule on labels made by hand: 20 vertices in the ball, each part with ``inside`` of
    them in it and ``outside`` beyond it; a crumb has fewer vertices in all than the rest of the
    ball (the ball's vertices not on it).
    The part measured is the centre's, or where that is a crumb the one large part."""
    ball = np.arange(20)

    def chosen(inside, outside, center=0):
        labels = np.concatenate(
            [np.repeat(np.arange(len(inside)), inside), np.repeat(np.arange(len(outside)), outside)]
        )
        labels = np.concatenate([labels, np.full(100 - labels.size, 99)])
        first = {int(k): int(np.flatnonzero(labels == k)[0]) for k in np.unique(labels)}
        labels = np.array([first[int(k)] for k in labels])  # each part's least vertex
        sizes = np.bincount(labels, minlength=100)
        kept = measured_part(labels, sizes, ball, center)
        return None if kept is None else sorted({int(labels[k]) for k in kept})

    assert chosen([20], [0]) == [0]
    assert chosen([2, 18], [30, 0]) == [0]  # 18 in all, but more than the rest of the ball
    assert chosen([10, 10], [20, 20]) == [0]  # the other part is not: left out
    assert chosen([5, 10, 5], [20, 20, 0]) == [0, 15]  # the crumb kept, the large part not
    assert chosen([2, 18], [0, 5]) == [0, 2]  # the centre on a crumb: the one large part
    assert chosen([2, 9, 9], [0, 30, 30]) is None  # two large parts: which cannot be told
    assert chosen([2, 9, 9], [0, 0, 0]) == [0, 2, 11]  # all crumbs: the whole ball


def test_a_click_on_a_crumb_among_several_parts_is_refused():
    """Five stacked sheets 0.01 apart, each its own part reaching beyond the radius, clicked
    on a crumb of debris between them."""
    sheets = [np.asarray(wedge_with_debris(90.0, 36)[0][-36:]) for _ in range(5)]
    points, triangles = [], []
    _, sheet_triangles = wedge_with_debris(90.0, 36)
    first = sheet_triangles[sheet_triangles.min(axis=1) >= len(wedge(90.0, n=60).points)]
    first = first - first.min()
    for k, sheet in enumerate(sheets):
        flat = sheet.copy()
        flat[:, 2] = 0.01 * k
        triangles.append(first + 36 * k)
        points.append(flat)
    speck = np.array([[0.0, 0.0, 0.005], [0.002, 0.0, 0.005], [0.0, 0.002, 0.005]])
    points = np.vstack([*points, speck])
    triangles = np.vstack([*triangles, [[180, 181, 182]]])
    surface = Surface(points, triangles)
    with pytest.raises(GoniometerError, match=r"on a crumb of the mesh.*several larger parts"):
        surface.measure([0.0, 0.0, 0.005], 0.05)


def _split_at_x0(points, triangles):
    """The faces with x > 0 moved onto copies of their vertices: two parts along a seam."""
    right = points[triangles].mean(axis=1)[:, 0] > 0
    triangles = triangles.copy()
    triangles[right] += len(points)
    used = np.unique(triangles)
    renumber = np.full(2 * len(points), -1)
    renumber[used] = np.arange(used.size)
    return np.vstack([points, points])[used], renumber[triangles]


def test_parts_joined_by_copies_are_one_surface():
    """A seam whose vertices were not merged (the mesh split in two at x = 0, and an STL's loose
    triangles) is one surface: measured, and as the merged mesh reads it."""
    mesh = wedge(120.0, n=60)
    points, triangles = np.asarray(mesh.points), np.asarray(mesh.triangles)
    split = _split_at_x0(points, triangles)
    loose = (points[triangles].reshape(-1, 3), np.arange(3 * len(triangles)).reshape(-1, 3))
    merged = Surface(points, triangles)
    assert np.unique(part_labels(len(split[0]), split[1])).size == 2
    for pieces in (split, loose):
        surface = Surface(*pieces)
        assert np.unique(mesh_parts(*pieces)[0]).size == 1
        for rule in RULES:
            reading = surface.measure([0, 0, 0], 0.3, rule=rule).angle
            assert reading == pytest.approx(merged.measure([0, 0, 0], 0.3, rule=rule).angle)
            assert reading == pytest.approx(120.0)


def test_loose_triangles_of_a_mesh_with_a_fragment_read_as_the_merged_mesh():
    """An STL's loose triangles (each face its own vertices) of the wedge and its refitted
    fragment, and of the wedge under a large sheet of debris: the coordinates join each into
    its parts (before the weld, the fragment's soup read 149.13° and the paper rule measured)."""
    for (points, triangles), where in (
        (wedge_with_fragment(120.0, 0.005), [-0.3, 0, 0]),
        (wedge_with_debris(90.0, 2500, extent=0.5), [0, 0, 0]),
    ):
        soup = Surface(
            points[triangles].reshape(-1, 3), np.arange(3 * len(triangles)).reshape(-1, 3)
        )
        merged = Surface(points, triangles)
        assert np.unique(mesh_parts(soup.points, soup.triangles)[0]).size == 2
        for rule in ("refined", "oriented"):
            reading = soup.measure(where, 0.3, rule=rule, stability=True)
            assert reading.angle == pytest.approx(merged.measure(where, 0.3, rule=rule).angle)
            assert reading.stability.spread < 1e-6
        with pytest.raises(GoniometerError, match=PAPER_MESSAGE):
            soup.measure(where, 0.3, rule="paper")


def test_a_refusal_says_what_was_left_out():
    """Two shells of a 120° wedge whose seam at the crease is 1e-9 apart (not merged): each
    ball measures the centre's shell, one face, refused as flat, saying that a part was left
    out and how to merge it (before: read 120.00° from both shells)."""
    mesh = wedge(120.0, n=60)
    points, triangles = np.asarray(mesh.points), np.asarray(mesh.triangles)
    minus = (mesh.side[triangles] <= 0).all(axis=1) & (mesh.side[triangles] < 0).any(axis=1)
    copies = points.copy()
    copies[:, 0] += 1e-9
    faces = triangles.copy()
    faces[minus] += len(points)
    surface = Surface(np.vstack([points, copies]), faces)
    assert np.unique(mesh_parts(surface.points, faces)[0][np.unique(faces)]).size == 2
    with pytest.raises(GoniometerError, match=r"were left out.*Merge by Distance"):
        surface.measure([0, 0, 0], 0.3)


def test_a_point_cloud_has_no_parts_to_refuse():
    points, _ = wedge_with_debris(90.0, 36)
    surface = Surface(points[: len(wedge(90.0, n=60).points)])
    assert surface.measure([0, 0, 0], 0.3).angle == pytest.approx(90.0, abs=0.5)


@pytest.mark.parametrize("seed", range(12))
def test_part_labels_match_scipys_connected_components(seed):
    """The oracle: SciPy's connected components of the vertex graph, on random meshes of several
    parts with their vertices and faces numbered at random; each label is its part's least
    vertex."""
    sparse = pytest.importorskip("scipy.sparse")
    csgraph = pytest.importorskip("scipy.sparse.csgraph")
    rng = np.random.default_rng(seed)
    n = int(rng.integers(5, 3000))
    parts = rng.integers(0, int(rng.integers(1, 12)), n)
    triangles = []
    for part in np.unique(parts):
        members = np.flatnonzero(parts == part)
        count = int(rng.integers(0, 2 * members.size))
        triangles.append(rng.choice(members, size=(count, 3)))
    triangles = np.vstack(triangles)
    triangles = triangles[rng.permutation(len(triangles))].astype(rng.choice([np.int32, np.int64]))
    labels = part_labels(n, triangles)
    edges = np.vstack([triangles[:, [0, 1]], triangles[:, [1, 2]]])
    graph = sparse.coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(n, n))
    _, expected = csgraph.connected_components(graph, directed=False)
    least = np.full(expected.max() + 1, n)
    np.minimum.at(least, expected, np.arange(n))
    assert labels.tolist() == least[expected].tolist()
