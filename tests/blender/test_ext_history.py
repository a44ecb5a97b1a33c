"""Measurements over time: saved and reopened, opened without the extension, undone and redone,
deleted; the colours always match the list."""

import addon_utils
import bpy
import numpy as np
from bpy_helpers import colours, expected_colours, snapshot, wedge_object
from conftest import MODULE, enable_extension

from vg_addon import Surface

CENTRES = [((0.0, 0.0, 0.0), 0.4), ((0.25, 0.0, 0.0), 0.3), ((-0.2, 0.05, 0.0), 0.35)]


def measure_three(undo=False):
    """Three overlapping measurements, the third on break 2. ``undo``: push an undo step for each,
    as a click in the UI does (scripted calls are not undo steps by default)."""
    args = ("EXEC_DEFAULT", True) if undo else ()
    for i, (location, radius) in enumerate(CENTRES):
        if i == 2:
            bpy.ops.vg.next_break(*args)
        bpy.ops.vg.measure_xyz(*args, location=location, radius=radius)


def painted_by(vg, obj, keep):
    """The colours the measurements ``keep`` (indices into CENTRES) must give, from the core."""
    from bpy_helpers import local_points, world

    mesh = obj.data
    mesh.calc_loop_triangles()
    tris = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", tris)
    surface = Surface(world(local_points(obj), obj), tris.reshape(-1, 3))
    sides = []
    for i in keep:
        m = surface.measure(*CENTRES[i])
        sides.append((m.indices, m.labels, 2 if i == 2 else 1))
    return expected_colours(len(mesh.vertices), sides)


def test_save_and_reopen_keeps_everything(vg, tmp_path):
    obj = wedge_object(105.0)
    measure_three()
    obj.vg.measurements[1].note = "checked twice"
    before = snapshot(obj)
    path = tmp_path / "measured.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.read_homefile(use_empty=True)
    bpy.ops.wm.open_mainfile(filepath=str(path))
    obj = bpy.data.objects["Wedge"]
    assert snapshot(obj) == before
    assert [m.note for m in obj.vg.measurements] == ["", "checked twice", ""]
    bpy.context.view_layer.objects.active = obj
    bpy.ops.vg.repaint()  # the same sides again from the stored numbers
    assert snapshot(obj) == before
    np.testing.assert_array_equal(colours(obj), painted_by(vg, obj, [0, 1, 2]))


def test_file_opens_without_the_extension(vg, tmp_path):
    obj = wedge_object(105.0)
    measure_three()
    before = snapshot(obj)
    path, resaved = tmp_path / "measured.blend", tmp_path / "resaved.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))

    addon_utils.disable(MODULE, default_set=True)
    assert not hasattr(bpy.types.Object, "vg")
    bpy.ops.wm.open_mainfile(filepath=str(path))  # no error
    obj = bpy.data.objects["Wedge"]
    assert not hasattr(obj, "vg")
    assert colours(obj) is not None  # the painted sides stay visible
    # The measurements are kept as plain ID properties Python does not know about; saving the
    # file without the extension keeps them (checked by reopening with it below).
    bpy.ops.wm.save_as_mainfile(filepath=str(resaved))

    enable_extension()
    bpy.ops.wm.open_mainfile(filepath=str(resaved))
    assert snapshot(bpy.data.objects["Wedge"]) == before


def test_undo_and_redo_restore_list_and_colours(vg):
    obj = wedge_object(105.0)
    bpy.ops.ed.undo_push(message="start")
    measure_three(undo=True)
    all_three = snapshot(obj)

    def current():
        return bpy.data.objects["Wedge"]  # undo reloads the data: old references go stale

    bpy.ops.ed.undo()  # the third measurement
    assert [m.number for m in current().vg.measurements] == [1, 2]
    assert current().vg.break_number == 2
    np.testing.assert_array_equal(colours(current()), painted_by(vg, current(), [0, 1]))
    bpy.ops.ed.undo()  # next break
    bpy.ops.ed.undo()  # the second measurement
    assert [m.number for m in current().vg.measurements] == [1]
    np.testing.assert_array_equal(colours(current()), painted_by(vg, current(), [0]))
    bpy.ops.ed.undo()  # the first
    assert len(current().vg.measurements) == 0
    assert colours(current()) is None

    for _ in range(4):
        bpy.ops.ed.redo()
    assert snapshot(current()) == all_three


def test_delete_repaints_and_undo_brings_it_back(vg):
    obj = wedge_object(105.0)
    measure_three()
    bpy.ops.ed.undo_push(message="measured")
    all_three = snapshot(obj)
    obj.vg.active_index = 1
    bpy.ops.vg.delete_measurement("EXEC_DEFAULT", True)
    assert [m.number for m in obj.vg.measurements] == [1, 3]
    np.testing.assert_array_equal(colours(obj), painted_by(vg, obj, [0, 2]))
    bpy.ops.vg.delete_measurement(index=0)
    np.testing.assert_array_equal(colours(obj), painted_by(vg, obj, [2]))
    bpy.ops.ed.undo_push(message="deleted")
    bpy.ops.ed.undo()
    bpy.ops.ed.undo()
    assert snapshot(bpy.data.objects["Wedge"]) == all_three


def test_clear_paints_grey_and_restarts_numbering(vg):
    obj = wedge_object(105.0)
    measure_three()
    bpy.ops.vg.clear_measurements()
    assert len(obj.vg.measurements) == 0
    np.testing.assert_array_equal(colours(obj), painted_by(vg, obj, []))
    bpy.ops.vg.measure_xyz(location=(0, 0, 0), radius=0.4)
    assert (obj.vg.measurements[0].number, obj.vg.measurements[0].break_number) == (1, 1)
