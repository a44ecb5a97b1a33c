"""vg_batch.py, run as a user runs it (a subprocess of this Python, which has bpy): inputs, point
lists, outputs, errors and exit codes, sharding, parallel jobs, .blend and PNG outputs, the demo;
and the batch numbers against the extension's own bpy.ops.vg.measure_xyz, bit for bit."""

from __future__ import annotations

import csv
import dataclasses
import importlib
import struct
import subprocess
from pathlib import Path
from types import SimpleNamespace

import bpy
import numpy as np
import pytest
from bpy_helpers import batch, colours, exact, expected_colours, mesh_object

from vg_addon import Surface
from vg_addon.formats import csvio, meshio, mpl_plots
from vg_addon.synthetic_meshes import bone_fragment, wedge

#: A batch profile plot's size: matplotlib's where it runs, else the NumPy drawing's
#: (test_ext_no_matplotlib.py runs the batch without matplotlib).
PROFILE_PNG = (768, 408) if mpl_plots.available() else (480, 240)

RADIUS = 0.3
# Points on the crease (the x axis) of the synthetic wedges, as the decimals a user would type.
CREASE = [("-0.4", "0", "0"), ("0.05", "0", "0"), ("0.35", "0", "0")]


def ok(result: subprocess.CompletedProcess, code: int = 0) -> subprocess.CompletedProcess:
    assert result.returncode == code, result.stdout + result.stderr
    return result


def rows_of(path) -> list[csvio.MeasurementRow]:
    """The rows of an export, read back with the schema's own reader (bit-exact numbers)."""
    return csvio.read_measurements_csv(Path(path))


def without_dates(rows) -> list[dict]:
    return [{k: v for k, v in dataclasses.asdict(r).items() if k != "date"} for r in rows]


def write_obj(path, points, triangles) -> Path:
    with open(path, "w", encoding="ascii") as handle:
        handle.writelines(f"v {x!r} {y!r} {z!r}\n" for x, y, z in points.tolist())
        handle.writelines(f"f {a} {b} {c}\n" for a, b, c in (triangles + 1).tolist())
    return Path(path)


def write_stl(path, points, triangles) -> Path:
    record = np.dtype([("normal", "<f4", (3,)), ("corners", "<f4", (3, 3)), ("attr", "<u2")])
    records = np.zeros(len(triangles), record)
    records["corners"] = points[triangles]
    with open(path, "wb") as handle:
        handle.write(b"binary STL written by test_batch".ljust(80, b" "))
        handle.write(struct.pack("<I", len(records)))
        handle.write(records.tobytes())
    return Path(path)


def write_csv(path, header, rows) -> Path:
    with open(path, "w", encoding="utf-8", newline="") as handle:
        writer = csv.writer(handle, lineterminator="\n")
        writer.writerow(header)
        writer.writerows(rows)
    return Path(path)


def png_size(path) -> tuple[int, int]:
    data = Path(path).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", f"{path} is not a PNG"
    return struct.unpack(">II", data[16:24])


def exact_in_float32(shape):
    return dataclasses.replace(shape, points=shape.points.astype(np.float32).astype(np.float64))


@pytest.fixture(scope="module")
def meshes(tmp_path_factory) -> dict:
    """Wedges of 90° (as PLY, OBJ and STL) and 60° (PLY), with their true angles."""
    folder = tmp_path_factory.mktemp("meshes")
    # Coordinates that float32 holds exactly: every format then gives Blender the same mesh,
    # and the batch measures it as the extension does (float64 files that float32 would round
    # are measured at the file's precision: test_batch_precision.py).
    w90 = exact_in_float32(wedge(90.0, n=24, irregular=True, seed=3))
    w60 = exact_in_float32(wedge(60.0, n=24, irregular=True, seed=4))
    return {
        "ply": meshio.write_ply(folder / "w90.ply", w90.points, w90.triangles),
        "obj": write_obj(folder / "w90_obj.obj", w90.points, w90.triangles),
        "stl": write_stl(folder / "w90_stl.stl", w90.points, w90.triangles),
        "ply60": meshio.write_ply(folder / "w60.ply", w60.points, w60.triangles),
        "angles": {"w90": w90.angle, "w60": w60.angle},
    }


@pytest.fixture(scope="module")
def two_meshes(meshes, tmp_path_factory) -> dict:
    """A points CSV over both wedges, rows interleaved, and the unsharded single-job run."""
    folder = tmp_path_factory.mktemp("two")
    rows = []
    for i, x in enumerate(["-0.45", "-0.3", "-0.1", "0.0", "0.2", "0.4", "0.45"]):
        rows.append(["w60" if i % 3 == 1 else "w90", x, "0", "0", f"p{i}"])
    points = write_csv(folder / "points.csv", ["mesh", "x", "y", "z", "label"], rows)
    out = folder / "whole.csv"
    result = ok(batch(meshes["ply"], meshes["ply60"], "--points", points, "--radius", RADIUS,
                      "--out", out))  # fmt: skip
    return {"points": points, "out": out, "rows": rows_of(out), "stderr": result.stderr}


# --------------------------------------------------------------------------- command line


def test_help_documents_every_option():
    text = ok(batch("--help")).stdout
    for needed in (
        "blender -b", "--python vg_batch.py --", "--object", "--at X Y Z", "--points CSV",
        "--radius", "--lambda", "--patch", "--out CSV", "--save-blend", "--render DIR",
        "--jobs", "--shard K/N", "--demo", "--out-dir", "--units", "exit status", "MeshLab",
    ):  # fmt: skip
        assert needed in text, needed


def test_points_given_with_at_on_ply_obj_and_stl(meshes, tmp_path):
    at = [arg for point in CREASE for arg in ("--at", *point)]
    results = {}
    for kind in ("ply", "obj", "stl"):
        out = tmp_path / f"{kind}.csv"
        ok(batch(meshes[kind], *at, "--radius", RADIUS, "--out", out))
        results[kind] = rows_of(out)
    rows = results["ply"]
    assert [r.mesh_name for r in rows] == ["w90"] * 3
    assert [r.number for r in rows] == [1, 2, 3]
    assert [r.requested for r in rows] == [tuple(float(v) for v in p) for p in CREASE]
    for r in rows:
        assert not r.error
        assert abs(r.angle - 90.0) < 0.01
        assert (r.radius, r.lam, r.patch) == (RADIUS, 2.0, "euclidean")
        assert r.units == "BU" and r.extension_version and r.blender_version
    # The same surface in three file formats: the same float32 vertices and faces in Blender,
    # hence the same numbers, bit for bit.
    for kind in ("obj", "stl"):
        assert [r.angle for r in results[kind]] == [r.angle for r in rows]
        assert [r.normal_plus for r in results[kind]] == [r.normal_plus for r in rows]


def test_points_csv_plain_our_export_and_meshlab_replicate_the_same_angles(meshes, tmp_path):
    plain = write_csv(
        tmp_path / "plain.csv",
        ["x", "y", "z", "radius", "lambda", "label"],
        [[*p, RADIUS, "2", f"site {i}"] for i, p in enumerate(CREASE, start=1)],
    )
    first = tmp_path / "first.csv"
    ok(batch(meshes["ply"], "--points", plain, "--out", first))
    original = rows_of(first)
    assert [r.user_data for r in original] == ["site 1", "site 2", "site 3"]

    # Our own export, fed back: every row re-measured at its snapped centre, same numbers, and
    # where each was asked for kept (it once became the snapped centre, with a snap of 0); in
    # worker processes too.
    assert any(r.snap_distance > 0 for r in original)
    for jobs in ("1", "2"):
        again = tmp_path / f"again{jobs}.csv"
        ok(batch(meshes["ply"], "--points", first, "--out", again, "--jobs", jobs))
        for a, b in zip(original, rows_of(again), strict=True):
            assert (b.angle, b.fit, b.x, b.y, b.z, b.n_vertices) == (a.angle, a.fit, a.x, a.y, a.z,
                                                                     a.n_vertices)  # fmt: skip
            assert b.requested == a.requested
            assert b.snap_distance == a.snap_distance

    # The MeshLab plugin's CSV: its 14 columns, the file name as Mesh Name, its own radius and
    # SegParam per row (here a different radius on the second row).
    meshlab_rows = [
        ["w90.ply", "2021-03-04", str(i), "1", "", f"m{i}", "90.1", "500",
         repr(r.radius if i != 2 else 0.25), repr(r.x), repr(r.y), repr(r.z), "0.001", "2"]
        for i, r in enumerate(original, start=1)
    ]  # fmt: skip
    meshlab = write_csv(tmp_path / "meshlab.csv", csvio.MESHLAB_COLUMNS, meshlab_rows)
    replicated = tmp_path / "replicated.csv"
    ok(batch(meshes["ply"], "--points", meshlab, "--out", replicated))
    rows = rows_of(replicated)
    assert [r.radius for r in rows] == [RADIUS, 0.25, RADIUS]
    assert [r.user_data for r in rows] == ["m1", "m2", "m3"]
    assert rows[0].angle == original[0].angle and rows[2].angle == original[2].angle
    assert abs(rows[1].angle - 90.0) < 0.01


def test_several_meshes_rows_matched_by_mesh_column_in_input_order(two_meshes, meshes):
    rows = two_meshes["rows"]
    assert [r.user_data for r in rows] == [f"p{i}" for i in range(7)]
    assert [r.mesh_name for r in rows] == ["w90", "w60", "w90", "w90", "w60", "w90", "w90"]
    for r in rows:
        assert not r.error
        assert abs(r.angle - meshes["angles"][r.mesh_name]) < 0.01
    # Measurement numbers count per mesh, in input order.
    assert [r.number for r in rows] == [1, 1, 2, 3, 2, 4, 5]
    assert "measurements/s" in two_meshes["stderr"]
    assert "7 measured, 0 failed" in two_meshes["stderr"]


def test_shards_concatenate_to_the_unsharded_run(two_meshes, meshes, tmp_path):
    shards = []
    for k in (1, 2):
        out = tmp_path / f"shard{k}.csv"
        ok(batch(meshes["ply"], meshes["ply60"], "--points", two_meshes["points"],
                 "--radius", RADIUS, "--shard", f"{k}/2", "--out", out))  # fmt: skip
        shards.append(rows_of(out))
    assert [len(s) for s in shards] == [3, 4]
    assert without_dates(shards[0] + shards[1]) == without_dates(two_meshes["rows"])


def test_jobs_2_equals_jobs_1_and_saves_every_mesh(vg, two_meshes, meshes, tmp_path):
    out, blend = tmp_path / "jobs2.csv", tmp_path / "jobs2.blend"
    folder = meshes["ply"].parent  # also holds the OBJ and STL copies, which no row names
    ok(batch(folder, "--points", two_meshes["points"],
             "--radius", RADIUS, "--jobs", "2", "--out", out, "--save-blend", blend))  # fmt: skip
    rows = rows_of(out)
    assert without_dates(rows) == without_dates(two_meshes["rows"])

    bpy.ops.wm.open_mainfile(filepath=str(blend))
    for name, count in (("w90", 5), ("w60", 2)):
        obj = bpy.data.objects[name]
        items = list(obj.vg.measurements)
        assert len(items) == count
        mine = [r for r in rows if r.mesh_name == name]
        assert [exact(i)["angle"] for i in items] == [r.angle for r in mine]
        assert colours(obj) is not None
    assert "w90_obj" not in bpy.data.objects  # meshes no row refers to are not loaded


def test_a_row_that_fails_gets_its_error_and_the_run_goes_on(meshes, tmp_path):
    points = write_csv(
        tmp_path / "points.csv",
        ["mesh", "x", "y", "z"],
        [["w90", "0", "0", "0"], ["w90", "0", "0", "5"], ["w91", "0", "0", "0"],
         ["w90", "0.2", "0", "0"]],
    )  # fmt: skip
    out = tmp_path / "out.csv"
    result = ok(batch(meshes["ply"], "--points", points, "--radius", RADIUS, "--out", out), 1)
    rows = rows_of(out)
    assert [bool(r.error) for r in rows] == [False, True, True, False]
    assert "farther than the radius" in rows[1].error
    assert rows[1].requested == (0.0, 0.0, 5.0) and rows[1].angle is None
    assert rows[1].number == 2 and rows[3].number == 3  # a failed row keeps its number
    assert "'w91', which is not among the meshes given" in rows[2].error
    assert abs(rows[3].angle - 90.0) < 0.01
    assert "2 measured, 2 failed" in result.stderr
    assert "row 3 on 'w90'" in result.stderr


def test_missing_file_malformed_csv_and_bad_arguments_exit_2(meshes, tmp_path):
    out = tmp_path / "out.csv"
    result = ok(batch(tmp_path / "nope.ply", "--at", 0, 0, 0, "--radius", 1, "--out", out), 2)
    assert "nope.ply: no such file or folder" in result.stderr
    assert "Traceback" not in result.stderr
    assert not out.exists()

    bad = tmp_path / "bad.csv"
    bad.write_text("x,y,z\n0,0,0\n1,abc,0\n", encoding="utf-8")
    result = ok(batch(meshes["ply"], "--points", bad, "--radius", 1, "--out", out), 2)
    assert "row 3: y is not a number ('abc')" in result.stderr

    result = ok(batch(meshes["ply"], "--at", 0, 0, 0, "--out", out), 2)
    assert "--at needs --radius" in result.stderr
    result = ok(batch(meshes["ply"], "--radius", 1, "--out", out), 2)
    assert "--at X Y Z" in result.stderr and "--points CSV" in result.stderr


def test_an_unreadable_mesh_fails_alone_with_exit_2(meshes, tmp_path):
    broken = tmp_path / "broken.ply"
    broken.write_bytes(b"ply\nformat ascii 1.0\nelement vertex 3\nend_header\n1 2\n")
    out = tmp_path / "out.csv"
    result = ok(batch(broken, meshes["ply"], *("--at", *CREASE[1]), "--radius", RADIUS,
                      "--out", out), 2)  # fmt: skip
    rows = rows_of(out)
    assert [r.mesh_name for r in rows] == ["broken", "w90"]
    assert "could not read the mesh" in rows[0].error and "broken.ply" in rows[0].error
    assert not rows[1].error and abs(rows[1].angle - 90.0) < 0.01
    assert "unreadable mesh" in result.stderr


def test_render_writes_the_measurement_map_per_mesh(meshes, tmp_path):
    renders = tmp_path / "renders"
    result = ok(batch(meshes["ply"], *("--at", *CREASE[1]), "--radius", RADIUS, "--out",
                      tmp_path / "out.csv", "--render", renders, "--render-size", 48, 32,
                      "--render-samples", 1))  # fmt: skip
    views = ("front", "back", "right", "left", "top", "bottom")
    for view in views:
        assert png_size(renders / f"w90_map_{view}.png") == (48, 32)
    assert png_size(renders / "w90_map.png") == (3 * 48, 2 * 32)  # the contact sheet
    assert sorted(p.name for p in renders.iterdir()) == sorted(
        ["w90_map.png", *(f"w90_map_{view}.png" for view in views)]
    )
    assert "wrote 1 measurement map(s)" in result.stderr


def test_render_views_flake(meshes, tmp_path):
    renders = tmp_path / "renders"
    ok(batch(meshes["ply"], *("--at", *CREASE[1]), "--radius", RADIUS, "--out",
             tmp_path / "out.csv", "--render", renders, "--render-views", "flake",
             "--render-size", 48, 32, "--render-samples", 1))  # fmt: skip
    assert png_size(renders / "w90_map.png") == (2 * 48, 32)


def test_render_edge_ends_caps_the_edges_close_ups(meshes, tmp_path):
    """``--render-edge-ends`` reaches the map drawn in the batch's child process: two edges
    meeting end to end (their ends crowd each other out of the six views) get close-ups by
    default, none with 0 (the six views and the contact sheet only)."""
    names = {}
    for ends in (None, 0):
        renders = tmp_path / f"renders{ends}"
        cap = () if ends is None else ("--render-edge-ends", ends)
        ok(batch(meshes["ply"], "--edge", -0.45, 0, 0, -0.02, 0, 0, "--edge", 0.02, 0, 0, 0.45,
                 0, 0, "--spacing", 0.1, "--radius", RADIUS, "--out", tmp_path / f"out{ends}.csv", "--render", renders,
                 "--render-size", 160, 120, "--render-samples", 1, *cap))  # fmt: skip
        names[ends] = sorted(p.name for p in renders.iterdir())
    views = ("front", "back", "right", "left", "top", "bottom")
    assert names[0] == sorted(["w90_map.png", *(f"w90_map_{view}.png" for view in views)])
    extra = set(names[None]) - set(names[0])
    assert extra and all("close-up" in n or "measurement" in n for n in extra), names[None]


# --------------------------------------------------------------------------- against the extension


def test_batch_angle_equals_measure_xyz_on_blenders_own_ply_import(vg, tmp_path):
    # Coordinates float32 holds exactly: Blender's mesh is then the file (a float64 file that
    # float32 rounds is measured at the file's precision by the batch, not by Blender).
    shape = wedge(90.0, n=24, irregular=True, seed=3)
    ply = meshio.write_ply(tmp_path / "w90.ply", shape.points.astype(np.float32), shape.triangles)
    out = tmp_path / "out.csv"
    ok(batch(ply, *("--at", *CREASE[1]), "--radius", RADIUS, "--lambda", "1.5",
             "--out", out))  # fmt: skip
    row = rows_of(out)[0]
    assert row.precision == "float32"

    bpy.ops.wm.ply_import(filepath=str(ply))
    obj = bpy.data.objects["w90"]
    bpy.context.view_layer.objects.active = obj
    location = tuple(float(v) for v in CREASE[1])
    bpy.ops.vg.measure_xyz(location=location, radius=RADIUS, seg_param=1.5)
    numbers = exact(obj.vg.measurements[0])
    assert numbers["angle"] == row.angle
    assert numbers["fit"] == row.fit
    assert tuple(numbers["normal_plus"]) == row.normal_plus
    assert tuple(numbers["normal_minus"]) == row.normal_minus
    assert tuple(numbers["center"]) == (row.x, row.y, row.z)
    assert tuple(numbers["requested"]) == row.requested
    assert obj.vg.measurements[0].n_vertices == row.n_vertices


def test_blend_input_mesh_coordinates_and_saved_measurements(vg, tmp_path):
    """An object of a .blend, moved, turned and scaled: the batch measures it in its mesh
    coordinates exactly as measure_xyz does, and the saved .blend lists the measurements,
    painted."""
    shape = wedge(75.0, n=30, irregular=True, seed=5)
    obj = mesh_object("Bone", shape.points, shape.triangles, location=(10.0, -2.0, 3.0),
                      rotation=(0.3, -0.2, 1.1), scale=(2.0, 2.0, 2.0))  # fmt: skip
    source = tmp_path / "study.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(source))
    point = ["0.1", "0.0", "0.0"]  # mesh coordinates, as in a CSV of this mesh

    out, saved = tmp_path / "out.csv", tmp_path / "saved.blend"
    ok(batch(source, "--object", "Bone", "--at", *point, "--radius", "0.6", "--out", out,
             "--save-blend", saved))  # fmt: skip
    row = rows_of(out)[0]
    assert abs(row.angle - 75.0) < 0.01

    bpy.ops.vg.measure_xyz(location=[float(v) for v in point], space="MESH", radius=0.6)
    mine = exact(obj.vg.measurements[0])
    assert (mine["angle"], mine["fit"]) == (row.angle, row.fit)
    assert tuple(mine["center"]) == (row.x, row.y, row.z)

    bpy.ops.wm.open_mainfile(filepath=str(saved))
    stored = bpy.data.objects["Bone"]
    assert bpy.context.view_layer.objects.active == stored
    assert [exact(i)["angle"] for i in stored.vg.measurements] == [row.angle]
    painted = colours(stored)
    assert painted is not None
    # The extension's own repaint, from the stored records, gives the same colours: the stored
    # measurement is not stale and the batch painted it as the extension does.
    bpy.ops.vg.repaint()
    assert not stored.vg.measurements[0].stale
    np.testing.assert_array_equal(colours(stored), painted)


def test_an_old_world_space_csv_on_a_moved_blend_object(vg, tmp_path):
    """An export of a version that wrote world coordinates (no Coordinates column), re-measured
    by the batch on the .blend object where it stands: the same vertex, the radius in mesh
    units, the same angle as measuring there in mesh coordinates."""
    shape = wedge(75.0, n=30, irregular=True, seed=5)
    obj = mesh_object("Bone", shape.points, shape.triangles, location=(10.0, -2.0, 3.0),
                      rotation=(0.3, -0.2, 1.1), scale=(2.0, 2.0, 2.0))  # fmt: skip
    source = tmp_path / "study.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(source))
    vertex = int(np.argmin(np.linalg.norm(shape.points - [0.1, 0.0, 0.0], axis=1)))
    matrix = np.array(obj.matrix_world, dtype=np.float64)
    local = np.float32(shape.points[vertex]).astype(np.float64)
    centre = matrix[:3, :3] @ local + matrix[:3, 3]
    header = [c for c in csvio.EXPORT_COLUMNS if c != "Coordinates"]
    values = {"Mesh Name": "Bone", "Radius": "1.2", "SegParam": "2.0", "Patch Mode": "euclidean"}
    values.update({axis: repr(float(v)) for axis, v in zip("xyz", centre, strict=True)})
    old = tmp_path / "old.csv"
    old.write_text(",".join(header) + "\n" + ",".join(values.get(c, "") for c in header) + "\n")
    out = tmp_path / "out.csv"
    ok(batch(source, "--object", "Bone", "--points", old, "--out", out))
    row = rows_of(out)[0]
    assert (row.x, row.y, row.z) == tuple(local) and row.radius == 0.6
    bpy.ops.vg.measure_xyz(location=tuple(local), space="MESH", radius=0.6)
    assert exact(obj.vg.measurements[0])["angle"] == row.angle


def test_blend_input_errors_exit_2(tmp_path):
    bpy.ops.wm.read_homefile(use_empty=True)
    shape = wedge(75.0, n=8)
    mesh_object("A", shape.points, shape.triangles)
    mesh_object("B", shape.points, shape.triangles)
    source = tmp_path / "two.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(source))
    out = tmp_path / "out.csv"
    result = ok(batch(source, "--at", 0, 0, 0, "--radius", 1, "--out", out), 2)
    assert "2 mesh objects (A, B): name the ones to measure with --object" in result.stderr
    result = ok(batch(source, "--object", "C", "--at", 0, 0, 0, "--radius", 1, "--out", out), 2)
    assert "has no object named 'C'" in result.stderr
    # Disabled in the viewports, an object has no evaluated mesh: its rows would read its mesh
    # without modifiers, so the run is refused naming it before anything is measured.
    bpy.data.objects["B"].hide_viewport = True
    bpy.ops.wm.save_as_mainfile(filepath=str(source))
    result = ok(batch(source, "--object", "B", "--at", 0, 0, 0, "--radius", 1, "--out", out), 2)
    assert "'B' is disabled in the viewports" in result.stderr
    assert not out.exists()


def test_sample_scan_in_millimetres_matches_measure_xyz(vg, shared_data, tmp_path):
    path = shared_data / "sample_mesh.ply"
    if not path.is_file():
        pytest.skip(f"{path} is not there")
    data = meshio.read_mesh(path)
    size = float(np.linalg.norm(data.points.max(axis=0) - data.points.min(axis=0)))
    radius = repr(round(size * 0.03, 3))
    picks = [str(np.float32(v)) for i in (100, 5000, 12000) for v in data.points[i]]
    at = [arg for i in range(3) for arg in ("--at", *picks[3 * i : 3 * i + 3])]
    out = tmp_path / "out.csv"
    ok(batch(path, *at, "--radius", radius, "--units", "mm", "--out", out))
    rows = rows_of(out)
    assert all(not r.error for r in rows)
    assert all(r.units == "mm" for r in rows)

    bpy.ops.wm.ply_import(filepath=str(path))
    obj = bpy.data.objects["sample_mesh"]
    bpy.context.view_layer.objects.active = obj
    for i, row in enumerate(rows):
        location = [float(v) for v in picks[3 * i : 3 * i + 3]]
        bpy.ops.vg.measure_xyz(location=location, radius=float(radius))
        numbers = exact(obj.vg.measurements[i])
        assert (numbers["angle"], numbers["fit"]) == (row.angle, row.fit)


# --------------------------------------------------------------------------- the demo


def test_demo_measures_the_bone_fragment_and_writes_its_outputs(tmp_path):
    out = tmp_path / "demo"
    result = ok(batch("--demo", "--out-dir", out))
    sites = bone_fragment().sites
    every_row = rows_of(out / "measurements.csv")
    rows = [row for row in every_row if row.edge_number is None]
    assert len(rows) == len(sites)
    for site, row in zip(sites, rows, strict=True):
        assert not row.error
        assert row.user_data == site.label
        assert abs(row.angle - site.angle) < 2.0, (site.label, row.angle, site.angle)
        assert site.label in result.stdout
    assert rows[0].units == "mm"
    assert len({r.break_number for r in rows}) == len(sites)  # one colour pair per site
    assert "true angle" in result.stdout and f"Output folder: {out}" in result.stdout
    assert png_size(out / "bone_fragment_map_front.png") == (800, 600)
    # The contact sheet: every view (the six standard ones, and close-ups where labels crowd),
    # three to a row.
    views = sorted(out.glob("bone_fragment_map_*.png"))
    assert len(views) >= 6
    rows = -(-len(views) // 3)
    assert png_size(out / "bone_fragment_map.png") == (3 * 800, rows * 600)
    assert (out / "bone_fragment.blend").stat().st_size > 0
    # The whole oblique outer rim, profiled: every station within 1° of the exact local angle
    # (180° minus the angle between the cylinder's and the oblique plane's outward normals).
    stations = [row for row in every_row if row.edge_number == 1]
    assert len(stations) > 15 and not any(row.error for row in stations)
    tilt = np.radians(35.0)
    plane = np.array([-np.tan(tilt), 0.0, 1.0]) / np.hypot(np.tan(tilt), 1.0)
    for row in stations:
        radial = np.array([row.x, row.y]) / np.hypot(row.x, row.y)
        exact = 180.0 - np.degrees(np.arccos(radial @ plane[:2]))
        assert abs(row.angle - exact) < 1.0, (row.arc_length, row.angle, exact)
    (edge,) = csvio.read_edges_csv(out / "measurements_edges.csv")
    assert edge.n_stations == len(stations)
    assert edge.mean == pytest.approx(np.mean([row.angle for row in stations]), abs=1e-12)
    assert "Whole edge" in result.stdout and f"pooled {edge.pooled_angle:.2f}°" in result.stdout
    assert png_size(out / "measurements_bone_fragment_edge1.png") == PROFILE_PNG
    assert meshio.read_mesh(out / "bone_fragment.ply").n_vertices > 200_000


def test_batch_paints_as_the_extension_does(vg, meshes, tmp_path):
    """The batch paints through the extension's own painter: every measured row is painted,
    later over earlier (break 0, which the batch's former painter skipped, is now refused on
    input: a break number is 1 or more)."""
    points = write_csv(
        tmp_path / "points.csv",
        ["x", "y", "z", "break", "label"],
        [["-0.3", "0", "0", "1", "a"], ["-0.1", "0", "0", "2", "b"], ["0.05", "0", "0", "1", "c"]],
    )
    out, saved = tmp_path / "out.csv", tmp_path / "saved.blend"
    ok(batch(meshes["ply"], "--points", points, "--radius", RADIUS, "--out", out,
             "--save-blend", saved))  # fmt: skip
    bpy.ops.wm.open_mainfile(filepath=str(saved))
    obj = bpy.data.objects["w90"]
    assert [i.break_number for i in obj.vg.measurements] == [1, 2, 1]
    co = np.empty(len(obj.data.vertices) * 3, dtype=np.float32)
    obj.data.vertices.foreach_get("co", co)
    mesh = meshio.read_mesh(meshes["ply"])
    surface = Surface(co.reshape(-1, 3).astype(np.float64), mesh.triangles)
    sides = []
    for item in obj.vg.measurements:
        m = surface.measure(exact(item)["center"], RADIUS)
        sides.append((m.indices, m.labels, item.break_number))
    np.testing.assert_array_equal(colours(obj), expected_colours(len(obj.data.vertices), sides))


@pytest.mark.parametrize("flaw", ["none", "degenerate", "duplicate"])
def test_imported_mesh_is_blenders_own_ply_import(vg, tmp_path, flaw):
    """The batch's import gives the mesh File > Import > PLY gives (Blender's C++ importer),
    for a clean triangle list and for ones Blender has to repair."""
    sources = importlib.import_module(f"{vg.__name__}.batch.sources")
    shape = wedge(70.0, n=12, irregular=True, seed=1)
    triangles = shape.triangles.copy()
    if flaw == "degenerate":
        triangles = np.vstack([triangles, [[3, 3, 7]]])
    elif flaw == "duplicate":
        triangles = np.vstack([triangles, triangles[5][[1, 2, 0]]])
    path = meshio.write_ply(tmp_path / f"{flaw}.ply", shape.points, triangles)
    ours, _ = sources.import_mesh(sources.MeshSource("ours", str(path)))
    assert bpy.ops.wm.ply_import(filepath=str(path)) == {"FINISHED"}
    blenders = bpy.context.selected_objects[0]
    assert blenders != ours
    for attribute, kind, width in (("position", "vector", 3), (".corner_vert", "value", 1)):
        got, want = (
            np.empty(len(o.data.attributes[attribute].data) * width) for o in (ours, blenders)
        )
        ours.data.attributes[attribute].data.foreach_get(kind, got)
        blenders.data.attributes[attribute].data.foreach_get(kind, want)
        np.testing.assert_array_equal(got, want, attribute)
    assert len(ours.data.polygons) == len(shape.triangles)  # the flaw is gone


def test_face_flaws_agree_with_brute_force(vg):
    sources = importlib.import_module(f"{vg.__name__}.batch.sources")
    rng = np.random.default_rng(0)
    for n in (6, 40, 3_000_000):  # the last packs no key into 63 bits
        for mixed in (False, True):
            for _ in range(30):
                count = int(rng.integers(1, 12))
                sizes = rng.integers(3, 6, size=count) if mixed else np.full(count, 3)
                corners = rng.integers(0, min(n, 40), size=int(sizes.sum()))
                corners[0] = n - 1  # fixes the largest index
                faces = np.split(corners, np.cumsum(sizes)[:-1])
                seen, repeated, duplicated = set(), False, False
                for face in (f.tolist() for f in faces):
                    repeated |= len(set(face)) < len(face)
                    duplicated |= tuple(sorted(face)) in seen
                    seen.add(tuple(sorted(face)))
                got = sources.face_flaws(corners, sizes)
                assert got == (repeated, duplicated), faces


# --------------------------------------------------------------------------- whole edges


def test_edges_write_station_rows_summaries_and_plots_equal_to_the_core(tmp_path):
    from vg_addon import Surface
    from vg_addon.synthetic_meshes import varying_wedge

    shape = varying_wedge(80.0, 120.0, half_width=2.0, depth=1.0, n=20)
    mesh = tmp_path / "ramp.ply"
    meshio.write_ply(mesh, shape.points, shape.triangles)
    out = tmp_path / "out.csv"
    result = ok(
        batch(
            mesh, "--at", 0, 0, 0,
            "--edge", -1.5, 0.01, 0, 1.5, 0, 0, "--via", 0, -0.01, 0,
            "--edge", -1, 0, 0, 1, 0, 0,
            "--spacing", 0.5, "--radius", 0.3, "--out", out,
        )
    )  # fmt: skip
    rows = rows_of(out)
    assert rows[0].edge_number is None and rows[0].number == 1
    # The file's float64 coordinates, which float32 would round, are measured as they are (as
    # --at rows are): the core on the file's own coordinates gives the same numbers.
    surface = Surface(meshio.read_mesh(mesh).points, shape.triangles)
    edges = csvio.read_edges_csv(out.with_name("out_edges.csv"))
    clicks = [[[-1.5, 0.01, 0], [0, -0.01, 0], [1.5, 0, 0]], [[-1, 0, 0], [1, 0, 0]]]
    for number, (edge, points) in enumerate(zip(edges, clicks, strict=True), start=1):
        profile = surface.measure_along(points, 0.5, 0.3)
        stations = [row for row in rows if row.edge_number == number]
        assert [r.angle for r in stations] == profile.angles.tolist()
        assert [r.arc_length for r in stations] == profile.arc_lengths.tolist()
        assert [(r.x, r.y, r.z) for r in stations] == [tuple(m.center) for m in profile.stations]
        assert (edge.mean, edge.pooled_angle) == (profile.mean, profile.pooled_angle)
        assert len({r.break_number for r in stations}) == 1
        assert {r.precision for r in stations} == {"float64"}
        assert (
            np.abs(
                np.array([r.angle for r in stations])
                - shape.angle_at(np.array([(r.x, r.y, r.z) for r in stations]))
            ).max()
            < 1.0
        )
        assert png_size(tmp_path / f"out_ramp_edge{number}.png") == PROFILE_PNG
        assert f"edge {number} on 'ramp'" in result.stderr + result.stdout

    # The edge file replicates: --edges re-measures every edge with its own settings.
    again = tmp_path / "again.csv"
    ok(batch(mesh, "--edges", out.with_name("out_edges.csv"), "--out", again))
    replayed = rows_of(again)
    stations = [row for row in rows if row.edge_number is not None]
    assert [(r.edge_number, r.angle, r.arc_length) for r in replayed] == [
        (r.edge_number, r.angle, r.arc_length) for r in stations
    ]
    result = ok(batch(mesh, "--edges", out, "--out", again), 2)  # not an edge file
    assert "missing the column(s)" in result.stderr


def test_a_failed_edge_is_an_error_row_and_exit_1(tmp_path):
    shape = wedge(90.0, n=20)
    mesh = tmp_path / "w.ply"
    meshio.write_ply(mesh, shape.points, shape.triangles)
    out = tmp_path / "out.csv"
    ok(batch(mesh, "--edge", -0.5, 0, 0, 0.5, 0, 0, "--spacing", 0.2, "--radius", 1e-4,
             "--out", out), 1)  # fmt: skip
    (row,) = rows_of(out)
    assert row.edge_number == 1 and "edge not measured" in row.error and "radius" in row.error


def test_edge_arguments_are_checked(tmp_path):
    out = tmp_path / "out.csv"
    result = ok(batch("x.ply", "--edge", 0, 0, 0, 1, 0, 0, "--radius", 1, "--out", out), 2)
    assert "--edge needs --spacing D and --radius R" in result.stderr
    result = ok(batch("x.ply", "--via", 0, 0, 0, "--out", out), 2)
    assert "--via X Y Z must follow the --edge" in result.stderr
    result = ok(
        batch("x.ply", "--edge", 0, 0, 0, 1, 0, 0, "--spacing", 1, "--radius", 1, "--jobs", 2,
              "--out", out), 2
    )  # fmt: skip
    assert "drop --jobs and --shard" in result.stderr
    result = ok(batch("--demo", "--edge", 0, 0, 0, 1, 0, 0), 2)
    assert "--demo takes no --edge" in result.stderr


def test_progress_is_reported_each_second_while_measuring(vg, monkeypatch):
    """``progress(done)`` comes at most once a second, but at least once a second of measuring
    however slow each measurement is: with a clock that advances a second per reading, after
    every task, in order (failed ones included). Oracle: the task count, one by one."""
    measure = importlib.import_module(f"{vg.__name__}.batch.measure")
    sources = importlib.import_module(f"{vg.__name__}.batch.sources")
    batchplan = importlib.import_module(f"{vg.__name__}.vg_addon.workflow.batchplan")
    shape = wedge(80.0, n=20, irregular=True, seed=2)
    mesh_object("Wedge", shape.points, shape.triangles)
    tasks = [
        batchplan.Task(
            index=k,
            mesh=0,
            center=(float(x), 0.0, 0.0),
            radius=0.3 if k % 7 else 1e-9,  # every seventh fails: too few vertices
            lam=2.0,
            patch="euclidean",
            number=k + 1,
        )
        for k, x in enumerate(np.linspace(-0.6, 0.6, 70))
    ]
    clock = iter(range(10**6))
    monkeypatch.setattr(measure, "time", SimpleNamespace(perf_counter=lambda: float(next(clock))))
    reported = []
    result = measure.measure_mesh(0, sources.MeshSource("Wedge"), tasks, {}, reported.append)
    assert result.failed == 10 and result.measured == 60
    assert reported == list(range(1, len(tasks) + 1))
