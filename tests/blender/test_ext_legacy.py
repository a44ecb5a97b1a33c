"""Files from versions that measured in world space: their records are brought into mesh
coordinates on load where they still match the object, and kept as world-space records (stale,
exported as such) where they do not."""

import hashlib
import json
import shutil
from pathlib import Path

import bpy
import numpy as np
import pytest
from bpy_helpers import colours, exact, expected_colours, local_points, wedge_object, world

from vg_addon import Surface
from vg_addon.formats import csvio


def old_fingerprint(obj) -> str:
    """The fingerprint the world-space versions stored: the evaluated mesh and the transform."""
    mesh = obj.data
    mesh.calc_loop_triangles()
    triangles = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", triangles)
    digest = hashlib.blake2b(digest_size=16)
    matrix = np.array(obj.matrix_world, dtype=np.float64)
    for array in (local_points(obj), triangles.reshape(-1, 3), matrix):
        array = np.ascontiguousarray(array)
        digest.update(f"{array.dtype.str}{array.shape}".encode())
        digest.update(memoryview(array).cast("B"))
    return digest.hexdigest()


def old_record(obj, requested_world, radius_world, lam=2.0):
    """A measurement recorded as the world-space versions did, measured here with the core on
    the object's world-space mesh."""
    mesh = obj.data
    mesh.calc_loop_triangles()
    triangles = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", triangles)
    m = Surface(world(local_points(obj), obj), triangles.reshape(-1, 3).astype(np.int64)).measure(
        requested_world,
        radius_world,
        lam,
        rule="paper",  # the only rule there was then
    )
    data = obj.vg
    item = data.measurements.add()
    item.number = data.next_number
    data.next_number += 1
    item.break_number = 1
    numbers = {
        "angle": m.angle,
        "fit": m.fit_error,
        "fit_plus": m.fit_error_plus,
        "fit_minus": m.fit_error_minus,
        "radius": m.radius,
        "lam": m.lam,
        "snap_distance": m.snap_distance,
        "center": m.center.tolist(),
        "requested": m.requested_center.tolist(),
        "normal_plus": m.normal_plus.tolist(),
        "normal_minus": m.normal_minus.tolist(),
    }
    item.exact = json.dumps(numbers)
    item.patch = "euclidean"
    item.n_vertices, item.n_plus, item.n_minus = m.n_vertices, m.n_plus, m.n_minus
    item.date = "2025-01-01T00:00:00+00:00"
    item.colors = "orange/blue"
    item.fingerprint = old_fingerprint(obj)
    return numbers


def test_an_old_blend_file_is_migrated_on_load(vg, tmp_path):
    kept = wedge_object(
        80.0, "Kept", location=(1.0, 2.0, -1.0), rotation=(0.4, 0.1, -0.7), scale=(3.0, 3.0, 3.0)
    )
    origin = world(np.zeros((1, 3)), kept)[0] + 0.01
    old = old_record(kept, origin, 1.2)  # 0.4 mesh units at a scale of 3
    kept.vg.measurements[0].stale = True  # flagged while it was elsewhere, now back in place
    moved = wedge_object(80.0, "Moved", location=(5.0, 0.0, 0.0))
    old_moved = old_record(moved, world(np.zeros((1, 3)), moved)[0], 0.4)
    moved.location.x += 1.0  # moved after measuring, as the old versions could not follow
    path = tmp_path / "old.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.read_homefile(use_empty=True)

    bpy.ops.wm.open_mainfile(filepath=str(path))  # the load_post handler migrates
    kept, moved = bpy.data.objects["Kept"], bpy.data.objects["Moved"]
    item = kept.vg.measurements[0]
    numbers = exact(item)
    assert numbers["space"] == "mesh" and not item.stale
    assert numbers["world_record"] == old  # the old numbers, kept for the record
    # The world-space angle carried the rounding of the transform (float32 in Blender):
    # a few 1e-6° here, far below the 0.01° the angles are reported to.
    assert abs(numbers["angle"] - old["angle"]) < 1e-4
    assert abs(numbers["angle"] - 80.0) <= abs(old["angle"] - 80.0)
    assert numbers["radius"] == 1.2 / 3.0
    # The migrated record is what the core measures in mesh coordinates at the same vertex.
    vertex = int(np.argmin(np.linalg.norm(world(local_points(kept), kept) - old["center"], axis=1)))
    m = Surface(local_points(kept).astype(np.float64), _triangles(kept)).measure(
        local_points(kept)[vertex].astype(np.float64), 1.2 / 3.0, rule="paper"
    )
    assert numbers["rule"] == "paper"
    assert (numbers["center"], numbers["angle"]) == (m.center.tolist(), m.angle)
    painted = expected_colours(len(kept.data.vertices), [(m.indices, m.labels, 1)])
    np.testing.assert_array_equal(colours(kept), painted)  # and painted again
    # It now follows the object.
    kept.location.z += 4.0
    bpy.context.view_layer.update()
    bpy.ops.vg.repaint()
    assert not kept.vg.measurements[0].stale

    stale = moved.vg.measurements[0]
    assert exact(stale) == old_moved  # left exactly as it was: world space
    assert stale.stale  # flagged on load
    bpy.context.view_layer.objects.active = moved
    bpy.ops.vg.repaint()
    assert stale.stale
    out = tmp_path / "old.csv"
    bpy.ops.vg.export_csv(filepath=str(out), all_objects=True)
    rows = {row.mesh_name: row for row in csvio.read_measurements_csv(out)}
    assert (rows["Moved"].coordinates, rows["Moved"].stale) == ("world", True)
    assert [rows["Moved"].x, rows["Moved"].y, rows["Moved"].z] == old_moved["center"]
    assert (rows["Kept"].coordinates, rows["Kept"].stale) == ("mesh", False)


def _triangles(obj):
    mesh = obj.data
    mesh.calc_loop_triangles()
    triangles = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", triangles)
    return triangles.reshape(-1, 3).astype(np.int64)


def test_file_load_clears_the_caches(vg, tmp_path):
    wedge_object(90.0)
    bpy.ops.vg.measure_xyz(location=(0, 0, 0), radius=0.5)
    painting = vg.bridge.painting
    assert vg.bridge.mesh_data._surfaces and painting._kept and painting._states
    path = tmp_path / "plain.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.open_mainfile(filepath=str(path))
    assert not vg.bridge.mesh_data._surfaces and not vg.bridge.mesh_data._geometries
    assert not painting._kept and not painting._states
    assert len(bpy.data.objects["Wedge"].vg.measurements) == 1


BEFORE_RENAME = Path(__file__).resolve().parent / "data" / "before_lam_rename.blend"


def test_a_blend_saved_before_lam_was_one_name_loads_and_replays(vg, tmp_path):
    """tests/blender/data/before_lam_rename.blend was saved by bpy 4.2 with this extension as
    it was before λ became ``lam`` in every Python name (the tree of the record-codec commit):
    the scene's λ of 1.7, measurements at λ 1.5 and 1.7 and an edge profile at λ 1.25 on an 80°
    wedge. The saved properties still read, the CSV export says SegParam, and each record
    replays bit for bit."""
    copy = tmp_path / "old.blend"
    shutil.copyfile(BEFORE_RENAME, copy)
    bpy.ops.wm.open_mainfile(filepath=str(copy))
    settings = bpy.context.scene.vg_settings
    assert settings.seg_param == pytest.approx(1.7, abs=1e-6)
    obj = bpy.data.objects["OldWedge"]
    items = list(obj.vg.measurements)
    assert len(items) == 7 and len(obj.vg.edges) == 1
    assert [exact(item)["lam"] for item in items] == [1.5, 1.7] + [1.25] * 5
    assert items[0].seg_param == pytest.approx(1.5)
    assert all(not item.stale for item in items)
    assert exact(obj.vg.edges[0])["lam"] == 1.25
    bpy.context.view_layer.objects.active = obj
    out = tmp_path / "old.csv"
    assert bpy.ops.vg.export_csv(filepath=str(out)) == {"FINISHED"}
    rows = csvio.read_measurements_csv(out)
    assert [row.lam for row in rows] == [1.5, 1.7] + [1.25] * 5
    assert "SegParam" in out.read_text(encoding="utf-8").splitlines()[0].split(",")
    mesh = obj.data
    mesh.calc_loop_triangles()
    triangles = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", triangles)
    surface = Surface(local_points(obj).astype(np.float64), triangles.reshape(-1, 3))
    for item in items:
        numbers = exact(item)
        again = surface.measure(
            numbers["center"], numbers["radius"], numbers["lam"], rule=numbers["rule"]
        )
        assert again.angle == numbers["angle"] and abs(again.angle - 80.0) < 1e-4


def test_a_world_space_csv_of_an_edge_imported_on_a_scaled_object_keeps_mesh_lengths(vg, tmp_path):
    """A measurement CSV of an earlier version (Coordinates world) of an object scaled by 2:
    the stations' centres and radius were taken to mesh units, the rebuilt edge's spacing,
    length and arc lengths were not (before: twice the edge's). The oracle: the same edge
    measured on the mesh, exported and written as that version wrote it, the lengths doubled."""
    import csv

    obj = wedge_object(100.0)
    bpy.ops.vg.measure_edge(
        points=json.dumps([[-0.6, 0.0, 0.0], [0.6, 0.0, 0.0]]), space="MESH", spacing=0.2,
        radius=0.4,
    )  # fmt: skip
    first = exact(obj.vg.edges[0])
    mesh_csv = tmp_path / "mesh.csv"
    bpy.ops.vg.export_csv(filepath=str(mesh_csv))
    with open(mesh_csv, encoding="utf-8-sig", newline="") as handle:
        rows = list(csv.DictReader(handle))
    for row in rows:
        for name in ("x", "y", "z", "Radius", "Arc Length", "Spacing"):
            if row[name]:
                row[name] = repr(2.0 * float(row[name]))
        row["Coordinates"] = "world"
    world_csv = tmp_path / "world.csv"
    with open(world_csv, "w", encoding="utf-8", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    bpy.ops.vg.clear_measurements()
    assert bpy.ops.vg.import_csv(filepath=str(mesh_csv)) == {"FINISHED"}
    rebuilt = exact(obj.vg.edges[0])  # an edge rebuilt from stations, in mesh coordinates
    bpy.ops.vg.clear_measurements()
    obj.scale = (2.0, 2.0, 2.0)
    bpy.context.view_layer.update()
    assert bpy.ops.vg.import_csv(filepath=str(world_csv)) == {"FINISHED"}
    again = exact(obj.vg.edges[0])
    assert again["spacing"] == first["spacing"] == rebuilt["spacing"]
    assert again["arc_lengths"] == pytest.approx(first["arc_lengths"], abs=1e-12)
    assert again["length"] == pytest.approx(rebuilt["length"], abs=1e-12)
    assert again["angles"] == first["angles"]
