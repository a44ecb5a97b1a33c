"""Coordinates stored as float32 far from the mesh's origin: a patch whose rounding is too
coarse for its vertex spacing is refused with the reason, never read off the rounding."""

import numpy as np
import pytest

from vg_addon import GoniometerError, Surface
from vg_addon.method.precision import check_rounding
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


def test_a_small_patch_takes_a_finer_step_than_a_large_one():
    """8,000 units out, float32 keeps coordinates to steps of about 0.03 of the wedge's vertex
    spacing. A patch of 26 vertices read as if exact is 0.13° off the true 90° (measured before
    the limit depended on the vertex count); it is refused, pointing to a larger radius. A patch
    of about 630 vertices at the same place reads within 0.05° of the true angle."""
    _, rounded, triangles, centre = far_wedge(8e3)
    small = Surface(rounded, triangles, precision="float64").measure(centre, 0.1)
    assert small.n_vertices == 26
    assert abs(small.angle - 90.0) > 0.1  # what the refusal keeps from the user
    surface = Surface(rounded, triangles)
    with pytest.raises(GoniometerError, match=r"patch of 26 vertices.*larger radius"):
        surface.measure(centre, 0.1)
    large = surface.measure(centre, 0.5)
    assert large.n_vertices > 600
    assert large.angle == pytest.approx(90.0, abs=0.05)


# The limit docs/METHOD.md states: a step of 0.05° × n / 1000 of the spacing, at most 0.1.
DOCUMENTED_LIMITS = {13: 0.00065, 40: 0.002, 400: 0.02, 2000: 0.1, 5000: 0.1}


@pytest.mark.parametrize("n_vertices", sorted(DOCUMENTED_LIMITS))
def test_the_limit_is_the_documented_share_of_the_spacing(n_vertices):
    """A patch of ``n`` vertices 1.5 million units out (float32 steps of 0.125), its radius
    chosen so the step is 0.95 and 1.05 times the documented limit's share of the spacing:
    measured just inside it, refused just past it."""
    rng = np.random.default_rng(n_vertices)
    points = 1.5e6 + rng.uniform(0.0, 1.0, (n_vertices, 3))
    step = float(np.spacing(np.float32(points.max())))
    assert step == 0.125
    limit = DOCUMENTED_LIMITS[n_vertices]
    for factor, refused in ((0.95, False), (1.05, True)):
        spacing = step / (limit * factor)
        radius = spacing / np.sqrt(np.pi / n_vertices)
        if refused:
            with pytest.raises(GoniometerError, match="stored as float32"):
                check_rounding(points, radius, "float32")
        else:
            check_rounding(points, radius, "float32")
        check_rounding(points, radius, "float64")  # float64's step here is 2.3e-10


def test_float64_trillions_of_units_out_is_measured_relative_to_its_centre():
    """Sums of float64 coordinates 2.3e12 units out round by up to the vertex count times
    float64's step there (0.0005): a 90° wedge's patch of about 8,800 vertices read 94.56°, fit error
    small, no flag. The oracle is the wedge's true angle, and the same vertices moved back to
    the origin (an exact subtraction: both terms are within a factor two of each other)."""
    shape = wedge(90.0, n=150, irregular=True, seed=2)
    centre = OFFSET * 2e12
    points = np.asarray(shape.points, dtype=np.float64) + centre
    far = Surface(points, shape.triangles).measure(centre, 0.5)
    near = Surface(points - centre, shape.triangles).measure(np.zeros(3), 0.5)
    assert far.n_vertices > 8000
    assert far.angle == pytest.approx(90.0, abs=0.01)
    assert far.angle == pytest.approx(near.angle, abs=1e-3)


def test_float64_rounded_past_its_vertex_spacing_is_refused_with_the_reason():
    """1.1e14 units out float64 keeps coordinates to steps of 0.016, half the wedge's vertex
    spacing: the rounded vertices, moved back to the origin exactly, read 0.32° off the true 90°.
    The same limit as float32's refuses it, saying to subtract an offset."""
    points, _, triangles, centre = far_wedge(1e14)
    near = Surface(points - centre, triangles).measure(np.zeros(3), 0.5).angle
    assert abs(near - 90.0) > 0.3  # what the refusal keeps from the user
    with pytest.raises(
        GoniometerError,
        match=r"reach 113,000,000,000,000 units from its origin, where even float64 rounds them "
        r"to steps of 0\.016.*Subtract an offset",
    ):
        Surface(points, triangles).measure(centre, 0.5)


def test_float16_coordinates_are_refused_not_checked_as_float32():
    """float16 keeps about three digits: a 150° wedge 100 units out read 153.21° with no flag,
    its rounding checked against float32's step, some 8,000 times finer. Oracle: the wedge's
    true angle, read from the same coordinates as float32."""
    shape = wedge(150.0, n=47)
    offset = np.array([100.0, -50.0, 25.0])
    points = shape.points + offset
    assert (
        abs(Surface(points.astype(np.float32), shape.triangles).measure(offset, 0.3).angle - 150.0)
        < 0.05
    )
    with pytest.raises(GoniometerError, match=r"stored as float16.*float32 or float64"):
        Surface(points.astype(np.float16), shape.triangles)
