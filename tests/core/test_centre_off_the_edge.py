"""A centre off the break edge: the refined rule reads the edge or refuses, never a wrong number.

With the centre on one face, most of the patch lies on that face, and Algorithm 1's split can
cut that face in two: the two planes then still meet near the centre, so no earlier check saw
it (a regular 90° wedge clicked 0.24 from its edge at radius 0.3 read 128.78°, the irregular
one here 131.04°). The oracle is the
wedge's construction: its crease is the x axis and its faces make the angle it was built with.
"""

import contextlib
import math

import numpy as np
import pytest

from vg_addon import GoniometerError, Surface
from vg_addon.synthetic_meshes import wedge

RADIUS = 0.3


def on_face(angle: float, distance: float, face: int) -> list:
    """A point on one face of the wedge ``angle``, ``distance`` from its crease."""
    half = math.radians(angle) / 2
    return [0.1, distance * math.sin(half), -face * distance * math.cos(half)]


@pytest.fixture(scope="module", params=[45.0, 60.0, 90.0, 120.0, 150.0])
def wedge_surface(request):
    angle = request.param
    shape = wedge(angle, n=60, irregular=True, seed=5)
    return angle, Surface(shape.points, shape.triangles)


def test_every_reading_off_the_edge_is_right_or_refused(wedge_surface):
    angle, surface = wedge_surface
    wrong_before = 0  # centres where Algorithm 1 (the oriented rule) reads over 2° off
    for distance in np.arange(0.0, 0.97 * RADIUS, 0.02):
        for face in (1, -1):
            centre = on_face(angle, distance, face)
            with contextlib.suppress(GoniometerError):
                oriented = surface.measure(centre, RADIUS, rule="oriented").angle
                wrong_before += abs(oriented - angle) > 2.0
            try:
                reading = surface.measure(centre, RADIUS).angle
            except GoniometerError as error:
                assert "times the radius from the centre" in str(error) or distance > 0.8 * RADIUS
                continue
            # Within the check's own bound (CROSSED_MOVE_DEG), and exact where the split holds.
            assert abs(reading - angle) < 2.0, (distance, face, reading)
            if distance <= 0.5 * RADIUS:
                assert abs(reading - angle) < 1e-6, (distance, face, reading)
    assert wrong_before >= 2 or angle < 60  # the sweep reaches the centres that read wrong


@pytest.mark.parametrize(("angle", "distance"), [(90.0, 0.24), (60.0, 0.26), (120.0, 0.18)])
def test_the_refusal_names_what_the_faces_read_and_how_far_the_edge_is(angle, distance):
    """The reviewer's cases (on regular wedges before: 128.78°, 63.16°, 145.5°): the reading the normals' sides
    give is the wedge's angle, and the edge's distance is where the centre was put."""
    shape = wedge(angle, n=60, irregular=True, seed=5)
    surface = Surface(shape.points, shape.triangles)
    with pytest.raises(GoniometerError, match="The split does not follow the faces") as caught:
        surface.measure(on_face(angle, distance, 1), RADIUS)
    text = str(caught.value)
    faces_read = float(text.split("given to it they read ")[1].split("°")[0])
    edge_off = float(text.split("with the edge ")[1].split(" times")[0])
    assert faces_read == pytest.approx(angle, abs=0.05)
    assert edge_off == pytest.approx(distance / RADIUS, abs=0.05)
    # The replication rules keep Algorithm 1's reading, as the earlier implementations gave it.
    for rule in ("oriented", "paper"):
        assert (
            abs(surface.measure(on_face(angle, distance, 1), RADIUS, rule=rule).angle - angle) > 2
        )
