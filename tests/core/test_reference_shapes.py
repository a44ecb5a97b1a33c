"""The reference shapes the project makes itself (``vg_addon/reference_shapes.py``): a half
annulus and two intersecting spheres marched from their implicit functions, with bevelled creases
and curved faces like the reference files, and exact angles known from their geometry.

These run in every clone; ``test_reference_meshes.py`` checks the original files where
``../shared`` is present.
"""

import numpy as np
import pytest
from test_reference_meshes import edge_midpoint, plane_angle_from_labels

from vg_addon import Surface
from vg_addon.marching_tetrahedra import march
from vg_addon.reference_shapes import (
    HALF_ANNULUS_EDGES,
    LENS_RIM_ANGLE,
    SPHERE_CENTRES,
    SPHERE_RADIUS,
    _half_annulus_terms,
    half_annulus,
    intersecting_spheres,
)


@pytest.fixture(scope="module")
def annulus():
    mesh = half_annulus()
    return Surface(mesh.points, mesh.triangles), mesh


@pytest.fixture(scope="module")
def spheres():
    mesh = intersecting_spheres()
    return Surface(mesh.points, mesh.triangles), mesh


def _edges_shared(triangles) -> np.ndarray:
    """How many triangles share each undirected edge."""
    edges = np.sort(triangles[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    return counts


def test_a_marched_sphere_is_closed_outward_and_on_the_sphere():
    points, triangles = march(
        lambda p: np.linalg.norm(p, axis=1) - 1.0, [-1.1683] * 3, [1.2] * 3, 0.1
    )
    assert set(_edges_shared(triangles)) == {2}  # every edge between exactly two triangles
    assert Surface(points, triangles).winding == "outward"
    radius = np.linalg.norm(points, axis=1)
    assert np.abs(radius - 1.0).max() < 0.01  # linear interpolation across a cell of 0.1
    # The enclosed volume (divergence theorem) is the ball's, to the chords' shortfall.
    a, b, c = (points[triangles[:, k]] for k in range(3))
    volume = np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0
    assert volume == pytest.approx(4.0 / 3.0 * np.pi, rel=0.02)


def test_the_shapes_are_closed_and_wound_outward(annulus, spheres):
    for surface, mesh in (annulus, spheres):
        assert set(_edges_shared(mesh.triangles)) == {2}
        assert surface.winding == "outward"


def test_half_annulus_vertices_lie_on_its_faces(annulus):
    _, mesh = annulus
    distance = np.abs(_half_annulus_terms(mesh.points).max(axis=1))
    assert np.median(distance) < 0.05 * 0.01  # on the faces, where the function is linear
    assert distance.max() < 0.05 * 0.5  # the bevel cuts each crease within a cell
    assert set(np.unique(mesh.labels)) == set(range(6))


@pytest.mark.parametrize("radius", [0.3, 0.4, 0.5])
@pytest.mark.parametrize("pair", sorted(HALF_ANNULUS_EDGES))
def test_half_annulus_edges_read_the_geometry(annulus, pair, radius):
    """The measured angle equals that of planes fitted to the true faces (the labels) within
    1.5°, or is nearer the exact angle than they are (the refinement leaves the bevel's vertices
    out, which the labels' planes keep): what remains of the error against the exact angle is
    the shape's (bevel, curvature), which is bounded by the curvature of the patch."""
    surface, mesh = annulus
    exact = HALF_ANNULUS_EDGES[pair]
    m = surface.measure(edge_midpoint(mesh, mesh.labels, pair), radius)
    truth = plane_angle_from_labels(surface, m.indices, mesh.labels, pair)
    assert abs(m.angle - truth) < 1.5 or abs(m.angle - exact) < abs(truth - exact)
    assert abs(m.angle - HALF_ANNULUS_EDGES[pair]) < 12.0 * radius / 0.5


def test_half_annulus_plane_edges_are_near_exact(annulus):
    """Where two planes meet (top and bottom with the cut) only the bevel is in the way: the
    reading is within 2° of 90°."""
    surface, mesh = annulus
    for pair in ((4, 0), (1, 5)):
        center = edge_midpoint(mesh, mesh.labels, pair)
        errors = [abs(surface.measure(center, r).angle - 90.0) for r in (0.3, 0.4, 0.5)]
        assert max(errors) < 2.0


def test_lens_rim_approaches_its_exact_angle_as_the_radius_shrinks(spheres):
    surface, mesh = spheres
    points = mesh.points
    rim = points[np.argmax(np.hypot(points[:, 1] - 1.0, points[:, 2] - 1.0))]
    extent = float(np.ptp(points, axis=0).max())
    errors = [
        abs(surface.measure(rim, extent * f).angle - LENS_RIM_ANGLE) for f in (0.2, 0.12, 0.06)
    ]
    assert errors[0] > errors[1] > errors[2]
    assert errors[2] < 2.0


def test_lens_vertices_lie_on_the_spheres(spheres):
    _, mesh = spheres
    distance = np.min(
        [np.abs(np.linalg.norm(mesh.points - c, axis=1) - SPHERE_RADIUS) for c in SPHERE_CENTRES],
        axis=0,
    )
    assert distance.max() < 0.02 * 0.2


@pytest.mark.parametrize("shape", ["annulus", "spheres"])
def test_point_cloud_normals_agree_with_the_mesh(shape, request):
    """Dropping the faces: PCA normals, oriented without them, match the mesh's normals."""
    surface, mesh = request.getfixturevalue(shape)
    cloud = Surface(mesh.points)
    both = cloud.valid & surface.valid
    agree = np.einsum("ij,ij->i", cloud.normals[both], surface.normals[both])
    assert (agree > 0.5).mean() > 0.98
