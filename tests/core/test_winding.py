"""Winding of closed meshes by signed volume: outward, inward, mixed faces, and open surfaces."""

import numpy as np
import pytest

from vg_addon import Surface
from vg_addon.formats.meshio import read_mesh
from vg_addon.method.winding import mesh_winding
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


@pytest.mark.parametrize("name", ["HalfAnnulus", "IntersectingSpheres", "sample_mesh"])
def test_reference_meshes_are_closed_and_outward(shared_data, name):
    mesh = read_mesh(shared_data / f"{name}.ply")
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
