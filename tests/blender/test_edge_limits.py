"""vg.measure_edge with a spacing that would make more stations than the core measures
(issue 25 item 2): refused before anything is allocated for them, naming the limit, nothing
recorded; the user's Blender keeps running."""

import json
import tracemalloc

import bpy
import pytest
from bpy_helpers import exact, mesh_object

from vg_addon.formats import csvio
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


def test_an_edge_file_whose_edges_run_out_of_break_numbers_records_none_of_them(vg, tmp_path):
    """Every edge takes a break number of its own. An object whose breaks reach the largest
    number Blender's integer holds (an imported Break #) has room for one more edge: importing a
    file of three once recorded one or two of them and then failed (a traceback, as the next
    break overflowed). Oracle: the records before the import, and the limit."""
    shape = varying_wedge(80.0, 120.0, half_width=2.0, depth=1.0, n=20)
    obj = mesh_object("Ramp", shape.points, shape.triangles)
    for offset in (-0.2, 0.0, 0.2):
        points = [[-1.5, offset, 0.0], [1.5, offset, 0.0]]
        bpy.ops.vg.measure_edge(points=json.dumps(points), spacing=0.5, radius=0.3, space="MESH")
    bpy.ops.vg.export_csv(filepath=str(tmp_path / "ramp.csv"))
    edges_file = csvio.edges_path_for(tmp_path / "ramp.csv")
    assert len(csvio.read_edges_csv(edges_file)) == 3
    x, y, z = exact(obj.vg.measurements[0])["center"]
    near_last = tmp_path / "near_last.csv"
    near_last.write_text(
        f"Mesh Name,Radius,x,y,z,Break #\nRamp,0.3,{x},{y},{z},{csvio.MAX_BREAK_NUMBER - 2}\n"
    )
    bpy.ops.vg.import_csv(filepath=str(near_last))
    before = [(m.number, m.break_number, m.exact) for m in obj.vg.measurements]
    counters = (obj.vg.break_number, obj.vg.next_number, obj.vg.next_edge_number)
    edges = [(edge.number, edge.plot) for edge in obj.vg.edges]
    images = len(bpy.data.images)
    with pytest.raises(RuntimeError, match="no Break # left for a new edge"):
        bpy.ops.vg.import_csv(filepath=str(edges_file))
    assert [(m.number, m.break_number, m.exact) for m in obj.vg.measurements] == before
    assert [(edge.number, edge.plot) for edge in obj.vg.edges] == edges
    assert len(bpy.data.images) == images  # no plot of an edge not kept
    assert (obj.vg.break_number, obj.vg.next_number, obj.vg.next_edge_number) == counters


def test_typed_points_off_the_mesh_are_refused_as_in_a_file(vg, tmp_path):
    """A typed point 0.37 off the mesh snapped to the nearest vertex and the edge was measured,
    but its own export was then refused on re-import as "farther than the radius". Typed
    points now meet the file's rule. Oracle: the ramp's geometry (its crease is its top, so a
    point above it is that far from every vertex) and the records."""
    shape = varying_wedge(80.0, 120.0, half_width=2.0, depth=1.0, n=20)
    obj = mesh_object("Ramp", shape.points, shape.triangles)
    above = [[-1.5, 0.0, 0.5], [1.5, 0.0, 0.0]]
    with pytest.raises(RuntimeError, match=r"Edge Profile: point 1 \(-1.5, 0, 0.5\) is 0.5 from"):
        bpy.ops.vg.measure_edge(points=json.dumps(above), spacing=0.5, radius=0.3, space="MESH")
    assert len(obj.vg.measurements) == 0 and len(obj.vg.edges) == 0
    on = [[-1.5, 0.0, 0.0], [1.5, 0.0, 0.0]]
    bpy.ops.vg.measure_edge(points=json.dumps(on), spacing=0.5, radius=0.3, space="MESH")
    path = tmp_path / "ramp.csv"
    bpy.ops.vg.export_csv(filepath=str(path))
    bpy.ops.vg.import_csv(filepath=str(csvio.edges_path_for(path)))  # its own file reads back
    assert len(obj.vg.edges) == 2


def test_find_break_edges_on_an_object_out_of_break_numbers_says_so(vg, tmp_path):
    """The recording of Find Break Edges (and of .pp files) raised the "no Break # left"
    refusal as a traceback. Oracle: the records before and after."""
    shape = varying_wedge(80.0, 120.0, half_width=2.0, depth=1.0, n=20)
    obj = mesh_object("Ramp", shape.points, shape.triangles)
    bpy.ops.vg.measure_xyz(location=(0.0, 0.0, 0.0), radius=0.3, space="MESH")
    obj.vg.measurements[0].break_number = obj.vg.break_number = csvio.MAX_BREAK_NUMBER
    before = [(m.number, m.exact) for m in obj.vg.measurements]
    edges = json.dumps([[[-1.5, 0.0, 0.0], [1.5, 0.0, 0.0]]])
    with pytest.raises(RuntimeError, match="no Break # left") as error:
        bpy.ops.vg.find_break_edges(edges=edges, spacing=0.5, radius=0.3)
    assert "Traceback" not in str(error.value)
    assert [(m.number, m.exact) for m in obj.vg.measurements] == before
    assert len(obj.vg.edges) == 0
