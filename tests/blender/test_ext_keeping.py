"""What the extension keeps in step for the user: the selected list row across deletions, the
plots of deleted objects, files written only where asked, lengths shown in the mesh's units,
and the map's record of its pictures across undo."""

import importlib
import json

import bpy
import pytest
from bpy_helpers import wedge_object
from test_map import measured_annulus

from vg_addon.formats import csvio
from vg_addon.synthetic_meshes import varying_wedge


def selected_number(obj) -> int:
    return obj.vg.measurements[obj.vg.active_index].number


def test_deleting_another_row_keeps_the_selected_measurement_selected(vg):
    obj = wedge_object(100.0)
    for x in (-0.3, -0.1, 0.1, 0.3):
        bpy.ops.vg.measure_xyz(location=(x, 0.0, 0.0), radius=0.4)
    obj.vg.active_index = 2
    assert bpy.ops.vg.delete_measurement(index=0) == {"FINISHED"}
    assert selected_number(obj) == 3  # before: the row at position 2, measurement 4
    assert bpy.ops.vg.delete_measurement(index=2) == {"FINISHED"}  # after the selected one
    assert selected_number(obj) == 3
    assert bpy.ops.vg.delete_measurement() == {"FINISHED"}  # the selected one: the next
    assert [m.number for m in obj.vg.measurements] == [2]
    assert selected_number(obj) == 2


def ramp(name: str):
    from bpy_helpers import mesh_object

    shape = varying_wedge(80.0, 120.0, half_width=2.0, depth=1.0, n=20)
    return mesh_object(name, shape.points, shape.triangles)


def measure_edge(points, spacing=0.5):
    return bpy.ops.vg.measure_edge(points=json.dumps(points), spacing=spacing, radius=0.3)


def test_deleting_an_edge_keeps_the_selected_measurement_and_edge_selected(vg):
    obj = ramp("Ramp")
    measure_edge([[-1.5, 0.01, 0.0], [0.0, -0.01, 0.0], [1.5, 0.0, 0.0]])
    for x in (-0.5, 0.5):
        bpy.ops.vg.measure_xyz(location=(x, 0.0, 0.0), radius=0.3)
    measure_edge([[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    measure_edge([[-1.2, 0.0, 0.0], [1.2, 0.0, 0.0]], spacing=0.6)
    chosen = next(m for m in obj.vg.measurements if m.edge_number == 0)
    obj.vg.active_index = list(obj.vg.measurements).index(chosen)
    number = chosen.number
    obj.vg.active_edge_index = 2
    assert bpy.ops.vg.delete_edge(index=0) == {"FINISHED"}
    # Before: the rows at the old positions, a station of edge 3 and edge 2.
    assert selected_number(obj) == number
    assert obj.vg.edges[obj.vg.active_edge_index].number == 3


def test_a_deleted_objects_plots_leave_the_file_when_it_is_saved(vg, tmp_path):
    plots = importlib.import_module(f"{vg.__name__}.bridge.plots")
    gone, kept = ramp("Gone"), ramp("Kept")
    for obj in (gone, kept):
        bpy.context.view_layer.objects.active = obj
        measure_edge([[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    gone_plot = plots.plot_image(gone.vg.edges[0]).name
    kept_plot = plots.plot_image(kept.vg.edges[0]).name
    own = bpy.data.images.new("A picture of the user's", 4, 4)
    own.use_fake_user = True
    bpy.data.objects.remove(gone)
    path = tmp_path / "saved.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.open_mainfile(filepath=str(path))
    names = set(bpy.data.images.keys())
    assert gone_plot not in names  # before: kept packed in the file for good, out of Purge's reach
    assert {kept_plot, "A picture of the user's"} <= names
    assert plots.plot_image(bpy.data.objects["Kept"].vg.edges[0]).name == kept_plot


def test_a_measured_mesh_converted_to_a_curve_keeps_its_plots_when_saved(vg, tmp_path):
    plots = importlib.import_module(f"{vg.__name__}.bridge.plots")
    obj = ramp("Converted")
    measure_edge([[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    plot = plots.plot_image(obj.vg.edges[0]).name
    bpy.ops.object.select_all(action="DESELECT")
    obj.select_set(True)
    assert bpy.ops.object.convert(target="CURVE") == {"FINISHED"}
    assert obj.type == "CURVE" and len(obj.vg.edges) == 1  # its records stay with the object
    path = tmp_path / "saved.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.open_mainfile(filepath=str(path))
    assert plot in bpy.data.images  # before: removed at the save, the edge kept in the records
    assert plots.plot_image(bpy.data.objects["Converted"].vg.edges[0]).name == plot


def test_a_sweep_to_a_path_relative_to_an_unsaved_file_writes_nothing(vg, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    wedge_object(100.0)
    with pytest.raises(RuntimeError, match="has not been saved yet"):
        bpy.ops.vg.radius_sweep(filepath="//sweep.csv", start=0.1, stop=0.4, count=3)
    assert list(tmp_path.iterdir()) == []  # before: sweep.csv and sweep.png in the working folder


@pytest.mark.parametrize(
    ("operator", "names"),
    [
        ("measure_xyz", ("radius",)),
        ("measure_edge", ("radius", "spacing")),
        ("find_break_edges", ("radius", "spacing", "scale", "min_length")),
        ("radius_sweep", ("start", "stop")),
    ],
)
def test_lengths_of_the_adjust_panel_are_plain_numbers_as_in_the_sidebar(vg, operator, names):
    """The sidebar's Radius is a number in the mesh's units under "Radius (mm)"; with Blender's
    length unit the same radius read "5 m" in the Adjust Last Operation panel, and "5 mm" typed
    there was stored as 0.005."""
    properties = getattr(bpy.ops.vg, operator).get_rna_type().properties
    sidebar = bpy.context.scene.vg_settings.bl_rna.properties["radius"]
    for name in names:
        assert (properties[name].subtype, properties[name].unit) == (
            sidebar.subtype,
            sidebar.unit,
        ), name


def test_undo_after_a_map_keeps_its_record_of_the_pictures(vg, tmp_path):
    name = measured_annulus(vg).name
    bpy.ops.ed.undo_push(message="measured")
    folder = tmp_path / "maps"
    result = bpy.ops.vg.render_map(
        "EXEC_DEFAULT", True, directory=str(folder), views="FLAKE", width=120, height=90, samples=1
    )
    assert result == {"FINISHED"}
    recorded = bpy.data.objects[name].vg.map_pictures
    assert recorded and bpy.data.objects[name].vg.map_stem
    assert bpy.ops.vg.next_break("EXEC_DEFAULT", True) == {"FINISHED"}
    bpy.ops.ed.undo()  # the step after the map, not the map
    assert (
        bpy.data.objects[name].vg.map_pictures == recorded
    )  # before: the state before the map, no record


def test_an_export_after_deleting_the_edges_leaves_no_summary_listing_them(vg, tmp_path, capfd):
    # Before: the earlier site_edges.csv stayed beside the new CSV, listing the deleted edge,
    # and importing it measured the edge again.
    ramp("Ramp")
    measure_edge([[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    bpy.ops.vg.measure_xyz(location=(0.0, 0.0, 0.0), radius=0.3)
    out = tmp_path / "site.csv"
    assert bpy.ops.vg.export_csv(filepath=str(out)) == {"FINISHED"}
    summary = tmp_path / "site_edges.csv"
    assert [e.edge_number for e in csvio.read_edges_csv(summary)] == [1]
    assert bpy.ops.vg.delete_edge() == {"FINISHED"}
    capfd.readouterr()
    assert bpy.ops.vg.export_csv(filepath=str(out)) == {"FINISHED"}
    assert "site_edges.csv, from an earlier export, now lists no edge" in capfd.readouterr().out
    assert csvio.read_edges_csv(summary) == []
    assert [r.edge_number for r in csvio.read_measurements_csv(out)] == [None]
