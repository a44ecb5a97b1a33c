"""Kept geometry, incremental painting and fingerprint migration (issue 10).

Every check compares with an oracle computed here from scratch: the core's Surface of the
object's own vertices for the sides, and the old fingerprint format for migration.
"""

import hashlib
import json

import bpy
import numpy as np
import pytest
from bpy_helpers import (
    colours,
    evaluated_surface,
    expected_colours,
    local_points,
    wedge_object,
    world,
)

from vg_addon import Surface


def triangles_of(obj) -> np.ndarray:
    mesh = obj.data
    mesh.calc_loop_triangles()
    tris = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", tris)
    return tris.reshape(-1, 3)


def painted_from_scratch(vg, obj) -> np.ndarray:
    """The colours the records should give: each current measurement re-measured on a Surface
    built here (mesh coordinates), painted later over earlier."""
    surface = Surface(local_points(obj).astype(np.float64), triangles_of(obj).astype(np.int64))
    sides = []
    for item in obj.vg.measurements:
        if item.stale:
            continue
        args = vg.bridge.records.replay_args(item)
        m = surface.measure(**args)
        sides.append((m.indices, m.labels, item.break_number))
    return expected_colours(len(obj.data.vertices), sides)


def measure_at(x, radius=0.3, **kwargs):
    assert bpy.ops.vg.measure_xyz(location=(x, 0.0, 0.0), radius=radius, **kwargs) == {"FINISHED"}


def test_repeat_clicks_reuse_the_geometry(vg):
    mesh_data = vg.bridge.mesh_data
    obj = wedge_object(80.0)
    vg.bridge.watch._pending.clear()  # left by earlier tests (timers do not run in bpy)
    measure_at(0.1)
    first = mesh_data.evaluated_geometry(obj)
    measure_at(-0.2)
    # Painting (our own write) left the kept geometry current: the very same object comes back.
    assert mesh_data.evaluated_geometry(obj) is first
    assert not vg.bridge.watch._pending  # and woke no staleness check
    # A move changes no measurement (mesh coordinates): the same geometry, the new transform,
    # no staleness check.
    obj.location.z += 0.5
    bpy.context.view_layer.update()
    moved = mesh_data.evaluated_geometry(obj)
    assert moved.fingerprint == first.fingerprint and moved.points is first.points
    assert np.array_equal(moved.matrix, np.array(obj.matrix_world, dtype=np.float64))
    assert not vg.bridge.watch._pending
    # An edit of the mesh is read again.
    co = local_points(obj).copy()
    co[:, 2] *= 1.01
    obj.data.vertices.foreach_set("co", co.ravel())
    obj.data.update()
    bpy.context.view_layer.update()
    edited = mesh_data.evaluated_geometry(obj)
    assert edited.fingerprint != first.fingerprint
    assert np.array_equal(edited.points, local_points(obj))


def test_an_edit_between_two_scripted_clicks_is_seen(vg):
    """No depsgraph evaluation between the paint and the edit: the edit must still count."""
    obj = wedge_object(80.0)
    measure_at(0.1)
    co = local_points(obj).copy()
    co[:, 2] *= 1.01
    obj.data.vertices.foreach_set("co", co.ravel())
    obj.data.update()
    measure_at(-0.2)
    assert [item.stale for item in obj.vg.measurements] == [True, False]
    # The second measurement is the one the edited mesh gives.
    m = Surface(world(local_points(obj), obj), triangles_of(obj).astype(np.int64)).measure(
        [-0.2, 0, 0], 0.3
    )
    assert vg.bridge.records.numbers_of(obj.vg.measurements[1])["angle"] == m.angle
    np.testing.assert_array_equal(colours(obj), painted_from_scratch(vg, obj))


def test_undo_restores_a_geometry_that_is_read_again(vg):
    obj = wedge_object(80.0)
    bpy.ops.ed.undo_push(message="start")
    bpy.ops.vg.measure_xyz("EXEC_DEFAULT", True, location=(0.1, 0, 0), radius=0.3)
    co = local_points(obj).copy()
    co[:, 2] *= 1.01  # an edit of the mesh (a move would change no measurement)
    obj.data.vertices.foreach_set("co", co.ravel())
    obj.data.update()
    bpy.ops.ed.undo_push(message="edited")
    bpy.context.view_layer.update()
    obj = bpy.data.objects["Wedge"]
    bpy.ops.vg.repaint()
    assert obj.vg.measurements[0].stale
    bpy.ops.ed.undo()
    obj = bpy.data.objects["Wedge"]
    bpy.ops.vg.repaint()
    assert not obj.vg.measurements[0].stale
    np.testing.assert_array_equal(colours(obj), painted_from_scratch(vg, obj))


def test_undone_measurements_are_unpainted_by_the_next_click(vg):
    obj = wedge_object(80.0)
    bpy.ops.ed.undo_push(message="start")
    for x in (-0.3, 0.0, 0.3):
        bpy.ops.vg.measure_xyz("EXEC_DEFAULT", True, location=(x, 0, 0), radius=0.3)
    bpy.ops.vg.delete_measurement("EXEC_DEFAULT", True, index=0)
    bpy.ops.ed.undo()  # the delete
    bpy.ops.ed.undo()  # the third measurement
    obj = bpy.data.objects["Wedge"]
    assert [item.number for item in obj.vg.measurements] == [1, 2]
    bpy.ops.vg.measure_xyz(location=(0.15, 0, 0), radius=0.25)  # number 3 again, elsewhere
    assert [item.number for item in obj.vg.measurements] == [1, 2, 3]
    np.testing.assert_array_equal(colours(obj), painted_from_scratch(vg, obj))


@pytest.mark.parametrize("seed", [0, 1])
def test_incremental_painting_equals_painting_from_scratch(vg, seed):
    """Measures, deletes (first, middle, last, active), next breaks and a stale measurement in
    a random order; after each, the colours are what the records give from scratch."""
    rng = np.random.default_rng(seed)
    obj = wedge_object(70.0, n=50)
    bpy.ops.ed.undo_push(message="start")
    for step in range(40):
        action = rng.choice(["measure", "measure", "measure", "delete", "break", "undo"])
        if action == "measure" or not len(obj.vg.measurements):
            x, radius = float(rng.uniform(-0.8, 0.8)), float(rng.uniform(0.15, 0.5))
            result = bpy.ops.vg.measure_xyz(
                "EXEC_DEFAULT", True, location=(x, 0.0, 0.0), radius=radius
            )
            assert result == {"FINISHED"}
        elif action == "delete":
            index = int(rng.integers(len(obj.vg.measurements)))
            result = bpy.ops.vg.delete_measurement("EXEC_DEFAULT", True, index=index)
            assert result == {"FINISHED"}
        elif action == "undo":  # brings back a deleted measurement, or removes a new one
            bpy.ops.ed.undo()
            obj = bpy.data.objects["Wedge"]
            bpy.context.view_layer.objects.active = obj
        else:
            bpy.ops.vg.next_break()
        if step == 20:  # an edit: everything so far goes stale and grey
            co = local_points(obj).copy()
            co[0, 2] += 0.05
            obj.data.vertices.foreach_set("co", co.ravel())
            obj.data.update()
            bpy.ops.vg.repaint()
            assert all(item.stale for item in obj.vg.measurements)
        np.testing.assert_array_equal(colours(obj), painted_from_scratch(vg, obj), f"step {step}")


def test_clicks_do_not_measure_the_stored_measurements_again(vg, monkeypatch):
    obj = wedge_object(80.0)
    for x in (-0.5, 0.0, 0.5):
        measure_at(x)
    calls = []
    surface_type = type(
        vg.bridge.mesh_data.surface_for(obj, vg.bridge.mesh_data.evaluated_geometry(obj))
    )
    original = surface_type.measure
    monkeypatch.setattr(
        surface_type, "measure", lambda self, *a, **k: calls.append(a) or original(self, *a, **k)
    )
    measure_at(0.25)
    bpy.ops.vg.delete_measurement(index=1)
    assert len(calls) == 1  # the new click only
    np.testing.assert_array_equal(colours(obj), painted_from_scratch(vg, obj))


def old_fingerprint(obj) -> str:
    """The fingerprint format of files written before issue 10, written out from its
    definition: BLAKE2b-128 over (dtype, shape, bytes) of the float32 positions, the int32 loop
    triangles and the float64 world matrix."""
    digest = hashlib.blake2b(digest_size=16)
    for array in (
        local_points(obj),
        triangles_of(obj),
        np.array(obj.matrix_world, dtype=np.float64),
    ):
        array = np.ascontiguousarray(array)
        digest.update(f"{array.dtype.str}{array.shape}".encode())
        digest.update(array.tobytes())
    return digest.hexdigest()


def test_old_fingerprints_are_migrated_not_marked_stale(vg, tmp_path):
    """Files written before issue 10 hold BLAKE2b fingerprints, and (before issue 12) world-space
    records: on load, the records whose mesh and transform still match are brought into mesh
    coordinates with the current fingerprint, not marked stale."""
    obj = wedge_object(80.0, location=(0.5, 0, 0))
    for x in (0.3, 0.6, 0.9):
        measure_at(x)
    legacy = old_fingerprint(obj)
    items = obj.vg.measurements
    for item in items:  # written back as the world-space record an old version kept
        numbers = json.loads(item.exact)
        del numbers["space"]
        for key in ("center", "requested"):
            numbers[key] = world(numbers[key], obj).tolist()
        item.exact = json.dumps(numbers)
        item.content_id = 0  # old versions wrote none
    items[0].fingerprint = legacy
    items[1].fingerprint = legacy
    items[2].fingerprint = "0123456789abcdef0123456789abcdef"  # an old file, another geometry
    path = tmp_path / "old.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.open_mainfile(filepath=str(path))
    obj = bpy.data.objects["Wedge"]
    bpy.context.view_layer.update()
    vg.bridge.watch.refresh(obj)
    items = obj.vg.measurements
    assert [item.stale for item in items] == [False, False, True]
    current = vg.bridge.mesh_data.evaluated_geometry(obj).fingerprint
    assert [item.fingerprint for item in items][:2] == [current, current]
    assert [json.loads(item.exact).get("space") for item in items] == ["mesh", "mesh", None]
    assert items[2].fingerprint == "0123456789abcdef0123456789abcdef"
    np.testing.assert_array_equal(colours(obj), painted_from_scratch(vg, obj))


def test_fingerprint_follows_faces_not_only_positions(vg):
    """Flipping the faces keeps every position but turns the normals: measurements go stale."""
    obj = wedge_object(80.0)
    measure_at(0.1)
    bpy.ops.object.mode_set(mode="EDIT")
    bpy.ops.mesh.select_all(action="SELECT")
    bpy.ops.mesh.flip_normals()
    bpy.ops.object.mode_set(mode="OBJECT")
    bpy.ops.vg.repaint()
    assert obj.vg.measurements[0].stale


def test_a_reread_geometry_is_compared_bit_for_bit(vg):
    """After an invalidation the mesh is compared with the kept one instead of hashed again;
    a change the fingerprint sees (here 0.0 to -0.0, equal as numbers) must still give a new
    fingerprint. Oracle: the fingerprint computed here from the mesh's own arrays."""
    mesh_data = vg.bridge.mesh_data
    obj = wedge_object(80.0)
    measure_at(0.1)
    kept = mesh_data.evaluated_geometry(obj)
    mesh_data.invalidate(obj)
    assert mesh_data.evaluated_geometry(obj) is kept  # unchanged: the kept geometry itself
    co = local_points(obj).copy()
    zero = np.flatnonzero(co.ravel() == 0.0)[0]
    assert not np.signbit(co.ravel()[zero])
    co.ravel()[zero] = -0.0
    obj.data.vertices.foreach_set("co", co.ravel())
    obj.data.update()
    bpy.context.view_layer.update()
    changed = mesh_data.evaluated_geometry(obj)
    corners, faces = mesh_data.read_corners(obj.data)
    assert changed.fingerprint == mesh_data.fingerprint(co, corners, faces)
    assert changed.fingerprint != kept.fingerprint
    bpy.ops.vg.repaint()
    assert obj.vg.measurements[0].stale


@pytest.mark.parametrize("seed", range(4))
def test_paint_state_updates_equal_painting_from_scratch(vg, seed):
    """Removals, insertions (a delete undone) and additions, in random mixes: the colours and
    owners are those of painting the wanted entries from blank, in order."""
    painting = vg.bridge.painting
    rng = np.random.default_rng(seed)
    n = 400
    pool = {}
    for k in range(30):  # overlapping patches of random vertices, random sides and breaks
        vertices = np.unique(rng.integers(0, n, int(rng.integers(5, 120)))).astype(np.int32)
        pool[k] = painting.Sides(
            vertices, rng.random(vertices.size) < 0.5, int(rng.integers(1, 6)), np.zeros(3), 1.0
        )
    keys = rng.permutation(len(pool))[:10].tolist()
    state = painting.PaintState.blank("f", n)
    assert state.update_to(keys, pool.__getitem__)
    incremental = 0
    for _ in range(60):
        target = [key for key in keys if rng.random() > 0.15]  # some removed
        for _ in range(int(rng.integers(0, 4))):  # some inserted anywhere, or added at the end
            new = int(rng.integers(len(pool)))
            if new not in target:
                target.insert(int(rng.integers(0, len(target) + 1)), new)
        if state.update_to(target, pool.__getitem__):
            incremental += 1
        else:
            state = painting.PaintState.blank("f", n)
            assert state.update_to(target, pool.__getitem__)
        scratch = painting.PaintState.blank("f", n)
        for key in target:
            scratch.add(key, pool[key])
        np.testing.assert_array_equal(state.colours, scratch.colours)
        np.testing.assert_array_equal(state.owner, scratch.owner)
        assert state.painted == target
        keys = target
    assert incremental > 30  # the incremental path, not only full repaints, was tested


def test_a_frame_change_that_moves_the_mesh_is_seen(vg):
    """An animated shape key moves the mesh on a frame change, which sends no depsgraph update
    (only the frame-change handlers run): the next measurement must still be taken on the mesh
    as it now is, and the earlier one, taken on the mesh of frame 1, must go stale and grey.
    Oracle: a Surface of the evaluated mesh's positions, read here."""
    obj = wedge_object(80.0)
    obj.shape_key_add(name="Basis")
    key = obj.shape_key_add(name="Larger")
    key.data.foreach_set("co", (local_points(obj) * np.float32(1.3)).ravel())
    for frame, value in ((1, 0.0), (10, 1.0)):
        key.value = value
        key.keyframe_insert("value", frame=frame)
    scene = bpy.context.scene
    scene.frame_set(1)
    vg.bridge.watch._pending.clear()
    measure_at(0.1)
    scene.frame_set(10)
    measure_at(-0.1)
    m = evaluated_surface(obj).measure([-0.1, 0.0, 0.0], 0.3)
    second = vg.bridge.records.numbers_of(obj.vg.measurements[1])
    assert second["center"] == m.center.tolist()
    assert obj.vg.measurements[1].n_vertices == m.n_vertices
    vg.bridge.watch._check_pending()  # the staleness check (timers do not run in bpy)
    assert [item.stale for item in obj.vg.measurements] == [True, False]
    expected = expected_colours(len(obj.data.vertices), [(m.indices, m.labels, 1)])
    np.testing.assert_array_equal(colours(obj), expected)
