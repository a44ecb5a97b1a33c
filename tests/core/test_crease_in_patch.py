"""The refined rule refuses a reading whose two planes meet outside the patch.

A patch that reaches past the two faces at an edge fits other faces of the fragment, and
Algorithm 1 reads the angle between those: a wrong number that its fit error does not show. The
oracles are the shapes' construction: the crease of a wedge is the x axis, and the half annulus
(a ring of radii 1.5 and 2.5, height 1, cut by the plane x = 0.5) has a 78.46° edge where the
cut meets the outer wall, at y = √6.
"""

import numpy as np
import pytest

from vg_addon import GoniometerError, Surface, goniometer
from vg_addon.reference_shapes import half_annulus
from vg_addon.synthetic_meshes import wedge

RADIUS = 0.5


@pytest.fixture(scope="module")
def wedge_patch():
    mesh = wedge(90, n=60)
    surface = Surface(mesh.points, mesh.triangles)
    ids = surface.patch(surface.snap([0.0, 0.0, 0.0], RADIUS)[0], RADIUS)
    return surface.points[ids], surface.normals[ids]


@pytest.mark.parametrize("side", [1.0, -1.0])
@pytest.mark.parametrize("reach", [0.5, 0.9, 0.99])
def test_a_centre_within_the_radius_of_the_crease_is_measured(wedge_patch, reach, side):
    # The centre moves the projection by a constant only, so the split and the angle stay exact.
    center = [0.1, 0.0, side * reach * RADIUS]  # reach·r from the x axis, the crease
    m = goniometer(*wedge_patch, center=center, radius=RADIUS)
    assert m.angle == pytest.approx(90.0, abs=1e-9)


@pytest.mark.parametrize("side", [1.0, -1.0])
@pytest.mark.parametrize("reach", [1.01, 1.5])
def test_a_centre_farther_than_the_radius_from_the_crease_is_refused(wedge_patch, reach, side):
    center = [0.1, 0.0, side * reach * RADIUS]
    with pytest.raises(GoniometerError, match="outside the patch") as refusal:
        goniometer(*wedge_patch, center=center, radius=RADIUS)
    # The message gives the distance, which the construction knows.
    assert f"meet {reach * RADIUS:.3g} from the centre" in str(refusal.value)


@pytest.mark.parametrize("rule", ["oriented", "paper"])
def test_the_replication_rules_keep_their_readings(wedge_patch, rule):
    m = goniometer(*wedge_patch, center=[0.1, 0.0, 1.5 * RADIUS], radius=RADIUS, rule=rule)
    assert m.angle == pytest.approx(90.0, abs=1e-9)


@pytest.fixture(scope="module")
def annulus():
    mesh = half_annulus(0.05)
    return Surface(mesh.points, mesh.triangles)


CUT_OUTER = (0.5, np.sqrt(6.0), 0.0)  # on the edge where the cut meets the outer wall
CUT_OUTER_ANGLE = 78.46


def test_a_patch_on_the_two_faces_reads_the_edge(annulus):
    # Marching cubes bevels the edge, so the reading is a few degrees off (docs/VALIDATION.md).
    assert annulus.measure(CUT_OUTER, 0.3).angle == pytest.approx(CUT_OUTER_ANGLE, abs=3.0)


@pytest.mark.parametrize("radius", [1.5, 2.0, 3.0])
def test_a_patch_past_the_edges_faces_is_refused_not_read(annulus, radius):
    # The oriented rule shows what the patch reads: the top and bottom faces, nearly parallel.
    wrong = annulus.measure(CUT_OUTER, radius, rule="oriented").angle
    assert abs(wrong - CUT_OUTER_ANGLE) > 40.0
    with pytest.raises(GoniometerError, match="outside the patch"):
        annulus.measure(CUT_OUTER, radius)


def test_the_refusal_says_how_far_in_radii(wedge_patch):
    with pytest.raises(GoniometerError, match=r"1\.50 times the radius"):
        goniometer(*wedge_patch, center=[0.1, 0.0, 1.5 * RADIUS], radius=RADIUS)


def test_a_near_flat_reading_refused_advises_a_larger_radius():
    # A 176° wedge measured from a centre beside its crease, out of the patch's reach: the
    # advice for near-flat planes is another radius, not a smaller patch.
    mesh = wedge(176, n=60)
    surface = Surface(mesh.points, mesh.triangles)
    ids = surface.patch(surface.snap([0.0, 0.0, 0.0], RADIUS)[0], RADIUS)
    with pytest.raises(GoniometerError, match="nearly parallel") as refusal:
        goniometer(surface.points[ids], surface.normals[ids], center=[0, 0, -0.6], radius=RADIUS)
    assert "larger radius" in str(refusal.value)


def test_a_centre_beyond_the_coordinate_limit_is_refused_as_such(wedge_patch):
    with pytest.raises(GoniometerError, match="The centre reaches 1e\\+200"):
        goniometer(*wedge_patch, center=[1e200, 0.0, 0.0], radius=1.0)
