"""Coordinates stored as float32 far from the mesh's origin: a patch whose rounding is too
coarse for its vertex spacing is refused with the reason, never read off the rounding."""

import numpy as np
import pytest

from vg_addon import GoniometerError, Surface
from vg_addon.synthetic_meshes import wedge

OFFSET = np.array([1.13, -0.71, 0.37])  # not along any symmetry of the wedge's faces


def far_wedge(distance, seed=1):
    """A 90° wedge (irregular, mean edge about 0.04) moved ``distance`` from the origin,
    in float64 and as float32 stores it."""
    shape = wedge(90.0, n=40, irregular=True, seed=seed)
    centre = OFFSET * distance
    points = np.asarray(shape.points, dtype=np.float64) + centre
    return points, points.astype(np.float32), np.asarray(shape.triangles), centre


def test_a_float32_patch_rounded_past_its_vertex_spacing_is_refused_with_the_reason():
    """With coordinates up to 1.13 million, float32 keeps coordinates to 0.125, more than the wedge's vertex
    spacing: the rounded mesh, measured as if exact, reads degrees off the true 90°. The
    oracle is the true angle of the synthetic wedge."""
    _, rounded, triangles, centre = far_wedge(1e6)
    off = Surface(rounded, triangles, precision="float64").measure(centre, 0.5).angle
    assert abs(off - 90.0) > 1.0  # what the refusal keeps from the user
    with pytest.raises(
        GoniometerError,
        match=r"float32.*coordinates up to 1,130,000 units.*steps of 0\.12.*vg_batch",
    ) as error:
        Surface(rounded, triangles).measure(centre, 0.5)
    assert "nan" not in str(error.value).lower()


def test_the_same_scan_at_float64_is_measured_exactly():
    points, _, triangles, centre = far_wedge(1e6)
    assert Surface(points, triangles).measure(centre, 0.5).angle == pytest.approx(90.0, abs=1e-6)


def test_float32_near_the_origin_is_measured():
    _, rounded, triangles, centre = far_wedge(100.0)
    surface = Surface(rounded, triangles)
    assert surface.precision == "float32"
    assert surface.measure(centre, 0.5).angle == pytest.approx(90.0, abs=0.01)


def test_float32_values_given_as_float64_are_checked_when_said_to_be_float32():
    """Blender's bridge hands the core float64 copies of its float32 positions."""
    _, rounded, triangles, centre = far_wedge(1e6)
    given = rounded.astype(np.float64)
    with pytest.raises(GoniometerError, match="stored as float32"):
        Surface(given, triangles, precision="float32").measure(centre, 0.5)
    assert Surface(given, triangles).precision == "float64"


def test_every_radius_is_refused_where_the_step_is_past_the_limit():
    """The limit is the rounding against the spacing of the vertices, not against the radius:
    at 1e5 units (steps of 0.0078, about a fifth of the spacing) every radius is refused."""
    _, rounded, triangles, centre = far_wedge(1e5)
    surface = Surface(rounded, triangles)
    for radius in (0.3, 0.5, 0.8):
        with pytest.raises(GoniometerError, match="stored as float32"):
            surface.measure(centre, radius)


def test_an_unknown_precision_is_refused():
    points, _, triangles, _ = far_wedge(0.0)
    with pytest.raises(GoniometerError, match="Unknown precision 'float16'"):
        Surface(points, triangles, precision="float16")
