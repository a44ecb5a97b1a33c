"""The record codec (vg_addon/formats/record_codec.py): a measurement's and an edge profile's
float64 numbers written as a record's text and read back bit for bit, without Blender."""

import math
import struct

import numpy as np
import pytest

from vg_addon import Surface
from vg_addon.formats import record_codec
from vg_addon.synthetic_meshes import wedge


@pytest.fixture(scope="module")
def surface():
    shape = wedge(75.0, n=30, irregular=True, seed=7)
    return Surface(shape.points, shape.triangles)


def bits(value: float) -> bytes:
    return struct.pack("<d", value)


@pytest.mark.parametrize("stability", [False, True])
def test_a_measurement_reads_back_bit_for_bit(surface, stability):
    m = surface.measure((0.013, 0.0, 0.0), 0.3 + 1e-9, 1.7, stability=stability)
    numbers = record_codec.decode(record_codec.encode(record_codec.measurement_numbers(m)))
    for key, value in (
        ("angle", m.angle),
        ("fit", m.fit_error),
        ("radius", m.radius),
        ("lam", m.lam),
        ("correlation", m.correlation),
        ("snap_distance", m.snap_distance),
    ):
        assert bits(numbers[key]) == bits(float(value)), key
    for key, vector in (
        ("center", m.center),
        ("requested", m.requested_center),
        ("normal_plus", m.normal_plus),
        ("normal_minus", m.normal_minus),
    ):
        assert [bits(v) for v in numbers[key]] == [bits(float(v)) for v in vector], key
    assert numbers["space"] == "mesh" and numbers["rule"] == m.rule
    assert numbers["convexity"] == m.convexity
    if stability:
        assert bits(numbers["stability"]["spread"]) == bits(float(m.stability.spread))
        assert numbers["stability"]["runs"] == m.stability.n_runs
    else:
        assert numbers["stability"] is None
    assert abs(numbers["angle"] - 75.0) < 0.5  # the wedge's true angle: the numbers are its own


def test_a_station_keeps_its_place_on_its_edge(surface):
    m = surface.measure((0.0, 0.0, 0.0), 0.3)
    numbers = record_codec.measurement_numbers(m, (2, 0.1 + 0.2, 0.05, False))
    assert numbers["arc_length"] == 0.1 + 0.2 and numbers["spacing"] == 0.05
    assert numbers["plus_left"] is False


def test_an_edge_profile_reads_back_bit_for_bit(surface):
    path = surface.trace_edge((-0.5, 0.0, 0.0), (0.5, 0.0, 0.0))
    profile = surface.measure_along(path, 0.25, 0.3)
    clicks = [np.array([-0.5, 0.0, 0.0]), np.array([0.5, 0.0, 0.0])]
    numbers = record_codec.decode(record_codec.encode(record_codec.edge_numbers(profile, clicks)))
    assert [bits(a) for a in numbers["angles"]] == [bits(float(a)) for a in profile.angles]
    assert bits(numbers["mean"]) == bits(float(profile.figures.mean))
    assert numbers["path"] == np.asarray(profile.path.points, dtype=np.float64).tolist()
    assert len(numbers["angles"]) == len(numbers["arc_lengths"]) >= 4
    assert all(abs(a - 75.0) < 1.0 for a in numbers["angles"])


@pytest.mark.parametrize("text", ["", "{not json", "[1, 2]", "null"])
def test_a_damaged_text_reads_as_no_numbers(text):
    assert record_codec.decode(text) == {}


def test_a_record_of_an_earlier_version_reads_as_written():
    """Records before the oriented rule have no rule, and world-space ones no space: their
    absence is what tells them apart, so decoding adds nothing."""
    old = '{"angle": 91.25, "radius": 0.5, "lam": 2.0, "center": [1.0, 2.0, 3.0]}'
    numbers = record_codec.decode(old)
    assert numbers == {"angle": 91.25, "radius": 0.5, "lam": 2.0, "center": [1.0, 2.0, 3.0]}
    assert "rule" not in numbers and "space" not in numbers
    assert math.isclose(numbers["angle"], 91.25)
