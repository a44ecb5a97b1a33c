"""Refusals that name their cause, where the message gave advice that could not help: float32
coordinates far from the origin, rounded so coarsely that vertices merge ("holds only 4
vertices ... use a larger radius", "no faces with area"), and a point cloud that repeats its
points ("an empty point cloud")."""

import numpy as np
import pytest

from vg_addon import GoniometerError, Surface
from vg_addon.synthetic_meshes import wedge


def far(offset: float):
    shape = wedge(100, n=30)
    return (shape.points + offset).astype(np.float32), shape.triangles


@pytest.mark.parametrize("patch", ["euclidean", "geodesic"])
def test_a_patch_whose_vertices_rounding_merged_is_refused_for_the_rounding(patch):
    """Also for the geodesic patch, whose merged vertices look like a seam's copies: "merge by
    distance" would be the wrong advice (a review found the seam's refusal answering first)."""
    points, triangles = far(1e7)  # float32 steps of 1 there; the wedge's spacing is about 0.07
    with pytest.raises(GoniometerError, match="stored as float32") as refused:
        Surface(points, triangles).measure([1e7] * 3, 0.4, patch=patch)
    assert "holds only" not in str(refused.value) and "seam" not in str(refused.value)
    # Near the origin the same small patch is refused for its vertex count, as before.
    near, _ = far(0.0)
    with pytest.raises(GoniometerError, match="holds only"):
        Surface(near, triangles).measure([0, 0, 0], 0.05)


def test_a_mesh_whose_faces_rounding_collapsed_says_so():
    points, triangles = far(1e12)
    with pytest.raises(GoniometerError, match="the rounding has collapsed its faces"):
        Surface(points, triangles)


def test_a_degenerate_mesh_near_the_origin_is_not_blamed_on_float32():
    """Collinear triangles (no area) at coordinates up to 3: no rounding hint there."""
    points = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0]], dtype=np.float32)
    with pytest.raises(GoniometerError, match="No vertex of this mesh has a normal") as refused:
        Surface(points, [[0, 1, 2], [1, 2, 3]])
    assert "float32" not in str(refused.value)


def test_a_tiny_radius_near_the_origin_is_refused_for_its_vertex_count():
    """Radii far below the spacing, on a float32 mesh near the origin or 1,000 units out: "holds
    only N vertices", not the float32 rounding (whose step is far below the radius there)."""
    for offset, radius in ((0.0, 1e-4), (100.0, 0.03), (1000.0, 0.05)):
        points, triangles = far(offset)
        with pytest.raises(GoniometerError, match="holds only"):
            Surface(points, triangles).measure(points[0], radius)


def test_a_cloud_of_repeated_points_is_refused_for_the_repeats():
    """Every point of a cloud given five times: each point's neighbourhood held only its own
    copies, and the refusal spoke of "an empty point cloud"."""
    shape = wedge(100, n=30)
    with pytest.raises(GoniometerError, match="repeats its points"):
        Surface(np.repeat(shape.points, 5, axis=0))
    # One point given twice is no cause to name.
    once = np.vstack([shape.points, shape.points[:1]])
    assert Surface(once).measure(shape.points[0], 0.4).angle > 0


def test_a_cloud_sampled_in_rows_far_apart_is_refused_for_its_rows():
    """A cloud sampled in rows ten times farther apart than its points along them (a laser
    scanner's lines), folded into a 90° wedge: each point's neighbourhood is its own row, a
    line, and the refusal spoke of "no faces with area, or an empty point cloud" (a review)."""
    along, across = 0.002, 0.02
    u = np.arange(-250, 251) * along
    v = (np.arange(-25, 26) + 0.37) * across
    uu, vv = (grid.ravel() for grid in np.meshgrid(u, v, indexing="ij"))
    half = np.radians(45.0)
    points = np.column_stack([uu, vv * np.sin(half), -np.abs(vv) * np.cos(half)])
    with pytest.raises(GoniometerError, match=r"lie on a line: a cloud sampled in rows") as refused:
        Surface(points)
    assert str(refused.value).startswith("No point of this cloud has a normal")
