"""Area-weighted vertex normals: bit for bit what the first implementation computed."""

import numpy as np
import pytest
from reference_data import REFERENCE_NAMES, reference_mesh

from vg_addon.method.normals import face_normals, vertex_normals
from vg_addon.method.spatial import bounds
from vg_addon.synthetic_meshes import bone_fragment, wedge


def reference_vertex_normals(points, triangles):
    """The implementation before the per-column rewrite, kept as the oracle."""
    n = points.shape[0]
    origin = points.min(axis=0)
    extent = float(np.max(points.max(axis=0) - origin))
    scaled = (points - origin) / extent if extent > 0 else points - origin
    weighted = face_normals(scaled, triangles)
    corners = [np.ascontiguousarray(triangles[:, k]) for k in range(3)]
    summed = np.zeros((n, 3), dtype=np.float64)
    for axis in range(3):
        for corner in corners:
            summed[:, axis] += np.bincount(corner, weights=weighted[axis], minlength=n)
    lengths = np.linalg.norm(summed, axis=1)
    valid = lengths > 1e-150
    normals = np.zeros_like(summed)
    normals[valid] = summed[valid] / lengths[valid, None]
    return normals, valid


def _meshes():
    w = wedge(70, n=60, irregular=True, seed=2)
    yield "wedge", w.points, w.triangles
    b = bone_fragment(spacing=1.0)
    yield "bone", b.points, b.triangles
    rng = np.random.default_rng(1)
    points = rng.normal(size=(3000, 3)) * np.exp(rng.normal(size=(3000, 1)) * 4)
    triangles = rng.integers(0, 3000, size=(9000, 3))
    triangles[::11, 2] = triangles[::11, 0]  # zero-area faces
    yield "random", points, triangles
    yield (
        "flat, signed zeros",
        np.array([[-0.0, 0.0, 0.0], [1, -0.0, 0], [0, 1, -0.0]]),
        [[0, 1, 2]],
    )
    yield "one point", np.array([[1.0, 2.0, 3.0]] * 3), [[0, 1, 2]]


@pytest.mark.parametrize("name, points, triangles", list(_meshes()))
def test_vertex_normals_are_bit_identical_to_the_reference(name, points, triangles):
    triangles = np.asarray(triangles, dtype=np.int64)
    expected = reference_vertex_normals(points, triangles)
    for given in (triangles, triangles.astype(np.int32)):
        normals, valid = vertex_normals(points, given)
        assert normals.tobytes() == expected[0].tobytes()
        assert np.array_equal(valid, expected[1])


@pytest.mark.parametrize("name", REFERENCE_NAMES)
def test_reference_mesh_normals_are_bit_identical(name, request):
    mesh = reference_mesh(name, request)
    normals, valid = vertex_normals(mesh.points, mesh.triangles)
    expected = reference_vertex_normals(mesh.points, mesh.triangles)
    assert normals.tobytes() == expected[0].tobytes()
    assert np.array_equal(valid, expected[1])


def test_bounds_are_min_and_max_with_their_signed_zeros():
    rng = np.random.default_rng(0)
    for points in (
        rng.normal(size=(500, 3)),
        np.array([[0.0, -0.0, 1.0], [-0.0, 0.0, 2.0]]),
        np.array([[-0.0, 0.0, -1.0], [0.0, -0.0, -2.0]]),
    ):
        low, high = bounds(points)
        assert low.tobytes() == points.min(axis=0).tobytes()
        assert high.tobytes() == points.max(axis=0).tobytes()
