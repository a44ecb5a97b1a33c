"""Winding of closed meshes by signed volume: outward, inward, mixed faces, and open surfaces."""

import numpy as np
import pytest
from reference_data import REFERENCE_NAMES, reference_mesh

from vg_addon import Surface
from vg_addon.formats.meshio import read_mesh
from vg_addon.method.winding import mesh_winding
from vg_addon.reference_shapes import intersecting_spheres
from vg_addon.synthetic_meshes import bone_fragment, wedge

# A unit tetrahedron wound outward by hand: each face's corners run counter-clockwise seen from
# outside, i.e. away from the opposite vertex.
TETRA_POINTS = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
TETRA = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])


def test_hand_wound_tetrahedron():
    for face, opposite in zip(TETRA, [3, 2, 1, 0], strict=True):
        a, b, c = TETRA_POINTS[face]
        assert np.cross(b - a, c - a) @ (a - TETRA_POINTS[opposite]) > 0
    assert mesh_winding(TETRA_POINTS, TETRA) == "outward"
    assert mesh_winding(TETRA_POINTS, TETRA[:, ::-1]) == "inward"
    assert mesh_winding(TETRA_POINTS * 1e-150, TETRA) == "outward"  # no underflow
    assert mesh_winding(TETRA_POINTS + 1e9, TETRA) == "outward"  # no cancellation


def test_two_closed_pieces_and_mixed_faces():
    points = np.vstack([TETRA_POINTS, TETRA_POINTS + 5.0])
    both = np.vstack([TETRA, TETRA + 4])
    assert mesh_winding(points, both) == "outward"
    one_flipped = both.copy()
    one_flipped[1] = one_flipped[1, ::-1]
    assert mesh_winding(points, one_flipped) == "mixed"


def test_open_and_point_clouds():
    mesh = wedge(90, n=10)
    assert mesh_winding(mesh.points, mesh.triangles) == "open"
    assert mesh_winding(TETRA_POINTS, TETRA[:3]) == "open"  # a face missing
    assert mesh_winding(TETRA_POINTS, np.vstack([TETRA, TETRA[:1]])) == "open"  # 3 faces on edges
    assert Surface(mesh.points).winding == "open"


def test_bone_fragment_and_its_inward_copy():
    bone = bone_fragment(spacing=1.5)
    assert Surface(bone.points, bone.triangles).winding == "outward"
    assert Surface(bone.points, bone.triangles[:, ::-1]).winding == "inward"


@pytest.mark.parametrize("name", REFERENCE_NAMES)
def test_reference_meshes_are_closed_and_outward(name, request):
    mesh = reference_mesh(name, request)
    assert Surface(mesh.points, mesh.triangles).winding == "outward"
    assert mesh_winding(mesh.points, mesh.triangles[:, ::-1]) == "inward"


def test_inward_bone_reads_the_same_angles_with_swapped_labels():
    bone = bone_fragment(spacing=1.0)
    outward = Surface(bone.points, bone.triangles)
    inward = Surface(bone.points, bone.triangles[:, ::-1])
    for site in bone.sites:
        a = outward.measure(site.point, 4.0)
        b = inward.measure(site.point, 4.0)
        assert b.angle == pytest.approx(a.angle, abs=1e-9)
        swap = {"convex": "concave", "concave": "convex", "unclear": "unclear"}
        assert b.convexity == swap[a.convexity]


def reference_winding(points, triangles):
    """The first implementation (three sorts of every edge), kept as the oracle."""
    n = np.int64(points.shape[0])
    triangles = np.asarray(triangles, dtype=np.int64)
    start = triangles.ravel()
    end = triangles[:, [1, 2, 0]].ravel()
    keep = start != end
    start, end = start[keep], end[keep]
    low, high = np.minimum(start, end), np.maximum(start, end)
    _, uses = np.unique(low * n + high, return_counts=True)
    if not (uses == 2).all():
        return "open"
    directed = np.sort(start * n + end)
    if (np.diff(directed) == 0).any() or not np.array_equal(directed, np.sort(end * n + start)):
        return "mixed"
    used = np.unique(triangles)
    origin = points[used].mean(axis=0)
    scale = float(np.abs(points[used] - origin).max()) or 1.0
    a, b, c = ((points[triangles[:, k]] - origin) / scale for k in range(3))
    volume = float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum())
    if volume == 0.0:
        return "open"
    return "outward" if volume > 0 else "inward"


def edge_ids(triangles, n):
    """Each corner's undirected edge id, as Blender's ``.corner_edge`` numbers them (any
    numbering will do: here sparse, with ids no corner uses, like loose edges)."""
    start = np.asarray(triangles, dtype=np.int64).ravel()
    end = np.asarray(triangles, dtype=np.int64)[:, [1, 2, 0]].ravel()
    _, ids = np.unique(np.minimum(start, end) * n + np.maximum(start, end), return_inverse=True)
    return 3 * ids.reshape(-1) + 1


def perturbed(rng, case):
    """Closed tetrahedra, then one change that makes the mesh open, mixed or inward."""
    pieces = int(rng.integers(1, 5))
    points = np.vstack([TETRA_POINTS * rng.uniform(0.5, 2.0) + 5.0 * i for i in range(pieces)])
    faces = np.vstack([TETRA + 4 * i for i in range(pieces)])
    pick = int(rng.integers(len(faces)))
    if case == "inward":
        faces = faces[:, ::-1]
    elif case == "open":
        faces = np.delete(faces, pick, axis=0)
    elif case == "mixed":
        faces[pick] = faces[pick, ::-1]
    elif case == "collapsed":  # a corner repeated: that face adds one edge, used both ways
        faces[pick, int(rng.integers(3))] = faces[pick, int(rng.integers(3))]
    elif case == "non-manifold":  # a face repeated, one way or the other
        extra = faces[pick] if rng.random() < 0.5 else faces[pick, ::-1]
        faces = np.vstack([faces, extra])
    faces = faces[rng.permutation(len(faces))]
    faces = np.roll(faces, int(rng.integers(3)), axis=1)
    return points, faces


CASES = ["outward", "inward", "open", "mixed", "collapsed", "non-manifold"]


@pytest.mark.parametrize("case", CASES)
def test_classification_equals_the_reference(case, monkeypatch):
    from vg_addon.method import winding

    monkeypatch.setattr(winding, "_CHUNK", 3)  # many blocks: their seams are exercised
    rng = np.random.default_rng(CASES.index(case))
    for _ in range(60):
        points, faces = perturbed(rng, case)
        expected = reference_winding(points, faces)
        for given in (faces, faces.astype(np.int32)):
            assert mesh_winding(points, given) == expected
            assert mesh_winding(points, given, edge_ids(given, len(points))) == expected


@pytest.mark.parametrize("name", ["bone", "wedge", "project lens", "reference"])
def test_classification_equals_the_reference_on_larger_meshes(name, request):
    if name == "bone":
        mesh = bone_fragment(spacing=1.0)
    elif name == "wedge":
        mesh = wedge(60, n=30)
    elif name == "project lens":
        mesh = intersecting_spheres()
    else:
        mesh = read_mesh(request.getfixturevalue("shared_data") / "IntersectingSpheres.ply")
    points, faces = mesh.points, mesh.triangles
    for given in (faces, faces[:, ::-1], np.vstack([faces[:1, ::-1], faces[1:]])):
        expected = reference_winding(points, given)
        assert mesh_winding(points, given) == expected
        assert mesh_winding(points, given, edge_ids(given, len(points))) == expected
        assert Surface(points, given, corner_edges=edge_ids(given, len(points))).winding == expected
