"""Blender-native behaviour: poll() with reasons, the handlers registered and removed with the
extension, the labels' content, the progress of a long import."""

import addon_utils
import bpy
import numpy as np
import pytest
from bpy_helpers import exact, local_points, wedge_object, world
from conftest import MODULE, enable_extension

OPERATORS = (
    "measure_xyz",
    "measure_drag",
    "next_break",
    "delete_measurement",
    "clear_measurements",
    "repaint",
    "export_csv",
    "import_csv",
    "render_map",
    "radius_sweep",
)


def test_every_operator_has_a_poll_that_greys_it_out_without_a_mesh(vg):
    bpy.context.view_layer.objects.active = None
    for name in OPERATORS:
        operator = getattr(bpy.ops.vg, name)
        assert not operator.poll(), name
    with pytest.raises(RuntimeError, match="No active object: click the mesh"):
        bpy.ops.vg.measure_xyz(location=(0, 0, 0), radius=0.5)


def test_poll_says_why_in_edit_mode_and_without_measurements(vg):
    wedge_object(90.0)
    assert bpy.ops.vg.measure_xyz.poll() and not bpy.ops.vg.repaint.poll()
    with pytest.raises(RuntimeError, match="'Wedge' has no measurements yet"):
        bpy.ops.vg.render_map(directory="/tmp")
    bpy.ops.object.mode_set(mode="EDIT")
    try:
        assert not bpy.ops.vg.measure_xyz.poll() and not bpy.ops.vg.next_break.poll()
        with pytest.raises(RuntimeError, match="is in Edit Mode: switch to Object Mode"):
            bpy.ops.vg.next_break()
    finally:
        bpy.ops.object.mode_set(mode="OBJECT")


def test_handlers_come_and_go_with_the_extension(vg):
    def ours():
        return {
            "load_post": [h for h in bpy.app.handlers.load_post if h.__module__.startswith(MODULE)],
            "depsgraph": [
                h for h in bpy.app.handlers.depsgraph_update_post if h.__module__.startswith(MODULE)
            ],
        }

    assert all(len(found) == 1 for found in ours().values()), ours()
    assert vg.ui.labels.registered()
    addon_utils.disable(MODULE, default_set=True)
    try:
        assert not any(ours().values())
        assert not vg.ui.labels.registered()
    finally:
        enable_extension()
    assert all(len(found) == 1 for found in ours().values())


def test_labels_follow_the_object_and_skip_stale_ones(vg):
    obj = wedge_object(90.0, location=(1.0, 0.0, 0.0))
    bpy.ops.vg.measure_xyz(location=(1.0, 0.0, 0.0), radius=0.4)
    bpy.ops.vg.next_break()
    bpy.ops.vg.measure_xyz(location=(1.2, 0.0, 0.0), radius=0.3)
    labels = vg.bridge.label_data.labels_of(obj)
    assert [label.text for label in labels] == [
        f"{item.number}: {exact(item)['angle']:.2f}°" for item in obj.vg.measurements
    ]
    assert [label.active for label in labels] == [False, True]
    assert [
        label.number for label in vg.bridge.label_data.labels_of(obj, active_break_only=True)
    ] == [2]
    obj.location = (0.0, 5.0, 0.0)
    obj.rotation_euler = (0.0, 0.0, 1.0)
    bpy.context.view_layer.update()
    moved = vg.bridge.label_data.labels_of(obj)
    for label, item in zip(moved, obj.vg.measurements, strict=True):
        expected = world(np.array([exact(item)["center"]]), obj)[0]
        np.testing.assert_allclose(label.position, expected, atol=1e-6)
    co = local_points(obj).copy()
    co[:, 2] += 0.05  # an edit: both become stale
    obj.data.vertices.foreach_set("co", co.ravel())
    obj.data.update()
    bpy.ops.vg.repaint()
    assert all(item.stale for item in obj.vg.measurements)
    assert vg.bridge.label_data.labels_of(obj) == []


def test_csv_import_reports_progress_and_can_be_cancelled(vg, tmp_path):
    obj = wedge_object(100.0)
    path = tmp_path / "points.csv"
    rows = [f"{x!r},0.0,0.0" for x in np.linspace(-0.3, 0.3, 25).tolist()]
    path.write_text("x,y,z\n" + "\n".join(rows) + "\n", encoding="utf-8")
    seen = []

    def progress(done, total):
        seen.append((done, total))
        return True

    numbers = vg.bridge.replication.import_csv(obj, path, radius=0.3, progress=progress)
    assert seen == [(i, 25) for i in range(25)] and len(numbers) == 25

    def stop_at_ten(done, total):
        return done < 10

    with pytest.raises(vg.vg_addon.GoniometerError, match="cancelled after 10 of 25 rows"):
        vg.bridge.replication.import_csv(obj, path, radius=0.3, progress=stop_at_ten)
    assert len(obj.vg.measurements) == 25  # nothing of the cancelled import was recorded
