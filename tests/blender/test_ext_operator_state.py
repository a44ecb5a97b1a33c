"""What an operator records or removes comes from its own call: never the values Blender keeps
from the last call of the same operator, a mesh with no vertices left still lets the records
go, a point as far as a double reaches is refused, and a linked object is not changed.

Oracles: the records' counts and numbers before and after each call, and the refusal's text.
"""

import json

import bmesh
import bpy
import pytest
from bpy_helpers import exact, linked_object, snapshot, wedge_object

EDGE = [[-0.6, 0.0, 0.0], [0.6, 0.0, 0.0]]


def test_a_call_that_names_nothing_is_refused_not_given_the_last_calls_edges(vg):
    """Calls with an undo push (as the UI makes them) are given the last call's values for
    properties they do not set. Before, a Find Break Edges or Edge Profile call naming no edges
    recorded the last call's edges again, and a note or a list position carried over."""
    obj = wedge_object(90.0, "A")
    edges = json.dumps([EDGE])
    made = bpy.ops.vg.find_break_edges("EXEC_DEFAULT", True, edges=edges, spacing=0.2, radius=0.2)
    assert made == {"FINISHED"} and len(obj.vg.edges) == 1
    before = snapshot(obj)
    with pytest.raises(RuntimeError, match="Name the candidates"):
        bpy.ops.vg.find_break_edges("EXEC_DEFAULT", True)
    with pytest.raises(RuntimeError, match="No candidate numbered 9"):
        bpy.ops.vg.find_break_edges("EXEC_DEFAULT", True, accept="9")
    assert snapshot(obj) == before and len(obj.vg.edges) == 1

    points = json.dumps(EDGE)
    done = bpy.ops.vg.measure_edge(
        "EXEC_DEFAULT", True, points=points, spacing=0.2, radius=0.2, space="MESH", note="rim"
    )
    assert done == {"FINISHED"} and len(obj.vg.edges) == 2
    before = snapshot(obj)
    with pytest.raises(RuntimeError, match="edge points must be JSON"):
        bpy.ops.vg.measure_edge("EXEC_DEFAULT", True)
    assert snapshot(obj) == before

    bpy.ops.vg.measure_xyz("EXEC_DEFAULT", True, location=(0.3, 0, 0), radius=0.3, note="first")
    bpy.ops.vg.measure_xyz("EXEC_DEFAULT", True, location=(-0.3, 0, 0), radius=0.3)
    assert [m.note for m in obj.vg.measurements][-2:] == ["first", ""]

    # A list position given once is not the next call's: the selected row is deleted.
    numbers = [m.number for m in obj.vg.measurements]
    assert bpy.ops.vg.delete_measurement("EXEC_DEFAULT", True, index=0) == {"FINISHED"}
    obj.vg.active_index = len(obj.vg.measurements) - 1
    assert bpy.ops.vg.delete_measurement("EXEC_DEFAULT", True) == {"FINISHED"}
    assert [m.number for m in obj.vg.measurements] == numbers[1:-1]


def test_records_go_even_when_every_vertex_was_deleted(vg):
    """Before, Delete, Delete Edge Profile and Clear refused ("has no vertices"), so records of a
    mesh emptied by an edit could never be removed."""
    obj = wedge_object(90.0, "W")
    bpy.ops.vg.measure_xyz(location=(0, 0, 0), radius=0.3)
    bpy.ops.vg.measure_xyz(location=(0.3, 0, 0), radius=0.3)
    bpy.ops.vg.measure_edge(points=json.dumps(EDGE), spacing=0.2, radius=0.2, space="MESH")
    stations = obj.vg.edges[0].n_stations
    mesh = bmesh.new()
    mesh.from_mesh(obj.data)
    bmesh.ops.delete(mesh, geom=list(mesh.verts), context="VERTS")
    mesh.to_mesh(obj.data)
    mesh.free()
    obj.data.update()
    assert len(obj.data.vertices) == 0 and len(obj.vg.measurements) == 2 + stations
    obj.vg.active_index = 0
    assert bpy.ops.vg.delete_measurement() == {"FINISHED"}
    assert len(obj.vg.measurements) == 1 + stations
    assert bpy.ops.vg.delete_edge() == {"FINISHED"}
    assert len(obj.vg.edges) == 0 and len(obj.vg.measurements) == 1
    assert bpy.ops.vg.clear_measurements("EXEC_DEFAULT") == {"FINISHED"}
    assert len(obj.vg.measurements) == 0


def test_an_edge_point_as_far_as_a_double_reaches_is_refused_clearly(vg):
    obj = wedge_object(90.0, "W")
    for space in ("MESH", "WORLD"):
        points = json.dumps([[1e308, 0.0, 0.0], [0.6, 0.0, 0.0]])
        with pytest.raises(RuntimeError) as error:
            bpy.ops.vg.measure_edge(points=points, spacing=0.2, radius=0.2, space=space)
        assert "Traceback" not in str(error.value) and "far from every vertex" in str(error.value)
    assert len(obj.vg.measurements) == 0


def test_the_flag_button_on_a_linked_object_changes_nothing(vg, tmp_path):
    """The row's warning button selects the row it was clicked on, except on a linked object,
    whose data cannot be changed here (before: its selected row moved)."""
    obj = wedge_object(100.0, "W")
    for x in (0.0, 0.2, 0.4):
        bpy.ops.vg.measure_xyz(location=(x, 0, 0), radius=0.3)
    obj.vg.active_index = 2
    library = tmp_path / "lib.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(library))
    linked = linked_object(library, "W")
    before = [exact(item) for item in linked.vg.measurements]
    assert bpy.ops.vg.stability_warning(index=0) == {"FINISHED"}
    assert linked.vg.active_index == 2
    assert [exact(item) for item in linked.vg.measurements] == before
