"""vg.measure_edge with a spacing that would make more stations than the core measures
(issue 25 item 2): refused before anything is allocated for them, naming the limit, nothing
recorded; the user's Blender keeps running."""

import json
import tracemalloc

import bpy
import pytest
from bpy_helpers import mesh_object

from vg_addon.method.edge_profile import MAX_STATIONS
from vg_addon.synthetic_meshes import varying_wedge

POINTS = [[-1.5, 0.01, 0.0], [0.0, -0.01, 0.0], [1.5, 0.0, 0.0]]


@pytest.mark.parametrize("spacing", [1e-9, 1e-6])
def test_a_spacing_making_too_many_stations_is_refused_naming_the_limit(vg, spacing):
    shape = varying_wedge(80.0, 120.0, half_width=2.0, depth=1.0, n=20)
    obj = mesh_object("Ramp", shape.points, shape.triangles)
    tracemalloc.start()
    try:
        with pytest.raises(RuntimeError) as caught:
            bpy.ops.vg.measure_edge(
                points=json.dumps(POINTS), space="MESH", spacing=spacing, radius=0.3
            )
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    message = str(caught.value)
    assert f"at most {MAX_STATIONS:,}" in message and "spacing of at least" in message
    assert peak < 16 * 2**20, peak
    assert len(obj.vg.measurements) == 0 and len(obj.vg.edges) == 0
    assert bpy.ops.vg.measure_edge(
        points=json.dumps(POINTS), space="MESH", spacing=0.5, radius=0.3
    ) == {"FINISHED"}
