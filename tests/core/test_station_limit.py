"""A spacing that would make more stations than the stated limit is refused before anything is
allocated for them (issue 24 item 12), naming the limit."""

from __future__ import annotations

import tracemalloc

import pytest

from vg_addon import GoniometerError, Surface
from vg_addon.method import edge_profile
from vg_addon.synthetic_meshes import wedge


@pytest.fixture(scope="module")
def surface():
    shape = wedge(90.0, n=24)
    return Surface(shape.points, shape.triangles)


@pytest.mark.parametrize("spacing", [1e-9, 1e-7, 1e-300])
def test_a_spacing_making_too_many_stations_is_refused_before_allocating(surface, spacing):
    path = edge_profile.trace_edge(surface, [-0.4, 0, 0], [0.4, 0, 0])
    tracemalloc.start()
    try:
        with pytest.raises(GoniometerError) as caught:
            surface.measure_along(path, spacing, 0.3)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    message = str(caught.value)
    assert f"{edge_profile.MAX_STATIONS:,}" in message and "stations" in message
    assert "spacing of at least" in message
    assert peak < 8 * 2**20, peak


def test_the_limit_itself_is_allowed(surface):
    path = edge_profile.trace_edge(surface, [-0.4, 0, 0], [0.4, 0, 0])
    count = edge_profile.station_count(path.length, path.length / 3)
    assert count == 4
    edge_profile.check_station_count(path.length, path.length / (edge_profile.MAX_STATIONS - 1))
    with pytest.raises(GoniometerError, match="at most"):
        edge_profile.check_station_count(path.length, path.length / edge_profile.MAX_STATIONS)
