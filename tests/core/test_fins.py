"""A patch holding an edge of three or more faces (a fin on the break edge) is refused."""

from collections import Counter

import numpy as np
import pytest
from defect_meshes import wedge_with_fin

from vg_addon import GoniometerError, Surface
from vg_addon.method.winding import edge_census
from vg_addon.synthetic_meshes import wedge

FIN_MESSAGE = r"shared by three or more faces.*Non Manifold"


@pytest.mark.parametrize("angle", [60.0, 90.0, 135.0])
def test_a_patch_on_a_fin_is_refused_and_the_edge_beyond_it_reads_its_angle(angle):
    """Before the check a 90° wedge with a fin ten spacings high on its crease read 69.65° here
    (60°: 53.7°, 135°: 95.6°), fit errors below 0.001 and nothing to show it."""
    points, triangles = wedge_with_fin(angle, rows=10)
    surface = Surface(points, triangles)
    with pytest.raises(GoniometerError, match=FIN_MESSAGE):
        surface.measure([-0.6, 0, 0], 0.3)
    with pytest.raises(GoniometerError, match=FIN_MESSAGE):
        surface.measure([-0.6, 0, 0], 0.3, rule="paper")
    assert surface.measure([0.5, 0, 0], 0.3).angle == pytest.approx(angle, abs=1e-6)


def test_a_face_given_twice_is_refused_and_a_face_without_area_is_not():
    mesh = wedge(90.0, n=40)
    points, triangles = np.asarray(mesh.points), np.asarray(mesh.triangles)
    near = np.flatnonzero(np.linalg.norm(points[triangles].mean(axis=1), axis=1) < 0.05)
    twice = Surface(points, np.vstack([triangles, triangles[near[:1]]]))
    with pytest.raises(GoniometerError, match=FIN_MESSAGE):
        twice.measure([0, 0, 0], 0.3)
    a, b, _ = triangles[near[0]]  # faces without area on an edge of two faces: no third face
    flat = Surface(points, np.vstack([triangles, [[a, a, b], [b, a, b]]]))
    assert flat.measure([0, 0, 0], 0.3).angle == pytest.approx(90.0, abs=1e-6)


def test_faces_in_a_line_along_the_crease_are_not_a_fin():
    """Triangles of three crease vertices in a line (no area, as decimation can leave them):
    each crease edge then has four faces, two of them without area. Refused as a fin by the
    first version of the check (a review); they turn no normal, and the wedge reads its angle."""
    mesh = wedge(120.0, n=50, irregular=True, seed=4)
    points, triangles = np.asarray(mesh.points), np.asarray(mesh.triangles)
    crease = np.flatnonzero(mesh.side == 0)
    crease = crease[np.argsort(points[crease, 0])]
    in_line = np.column_stack([crease[:-2], crease[1:-1], crease[2:]])
    surface = Surface(points, np.vstack([triangles, in_line]))
    assert surface.measure([0.01, 0, 0], 0.2).angle == pytest.approx(120.0, abs=1e-6)


def fins_counted(points, triangles):
    """The oracle: the vertices of edges that three or more faces with area use, by counting
    (integer coordinates: a face has no area where its cross product is exactly zero)."""
    uses = Counter()
    for face in triangles.tolist():
        a, b, c = (np.array(points[k], dtype=np.int64) for k in face)
        if np.cross(b - a, c - a).any():
            uses.update(frozenset((face[k], face[(k + 1) % 3])) for k in range(3))
    return sorted({v for edge, count in uses.items() if count >= 3 for v in edge})


def corner_edge_ids(triangles, n):
    start = triangles.ravel().astype(np.int64)
    end = triangles[:, [1, 2, 0]].ravel().astype(np.int64)
    _, ids = np.unique(np.minimum(start, end) * n + np.maximum(start, end), return_inverse=True)
    return 2 * ids.reshape(-1) + 5  # sparse ids, as a mesh with loose edges numbers them


@pytest.mark.parametrize("seed", range(40))
def test_fin_vertices_match_a_count_of_each_edges_faces(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(4, 25))
    points = rng.integers(-2, 3, size=(n, 3)).astype(np.float64)  # some faces in a line
    triangles = rng.integers(0, n, size=(int(rng.integers(1, 60)), 3))
    if seed % 3 == 0:  # faces given twice, or flipped
        triangles = np.vstack([triangles, triangles[: int(rng.integers(1, 5)), ::-1]])
    expected = fins_counted(points, triangles)
    assert edge_census(points, triangles).fin_vertices.tolist() == expected
    ids = corner_edge_ids(triangles, n)
    assert edge_census(points, triangles, ids).fin_vertices.tolist() == expected
