"""CSV export and import (replication): the MeshLab header, bit-identical angles, all or nothing."""

import csv
import dataclasses
import math
import os
import tomllib

import bpy
import numpy as np
import pytest
from bpy_helpers import (
    exact,
    half_annulus_with_edge_vertices,
    local_points,
    mesh_object,
    snapshot,
    wedge_object,
    world,
)
from conftest import ROOT

from vg_addon import Surface
from vg_addon.formats import csvio, meshio

with open(ROOT / "blender_manifest.toml", "rb") as _handle:
    MANIFEST = tomllib.load(_handle)

MESHLAB_HEADER = (
    "Mesh Name,Date,Measurement #,Break #,Colors,User Data,Angle,Number of Vertices,Radius,"
    "x,y,z,fit,SegParam"
)


def measured_wedge(name="Wedge", angle=100.0):
    obj = wedge_object(angle, name)
    bpy.ops.vg.measure_xyz(location=(0, 0, 0), radius=0.5, note="=SUM(A1)")
    bpy.ops.vg.measure_xyz(location=(0.3, 0.01, 0), radius=0.35, seg_param=1.5)
    bpy.ops.vg.next_break()
    bpy.ops.vg.measure_xyz(location=(-0.3, 0.05, 0), radius=0.4, patch="geodesic")
    return obj


def read_rows(path):
    with open(path, newline="", encoding="utf-8") as handle:
        return list(csv.reader(handle))


def test_export_starts_with_the_meshlab_columns(vg, tmp_path):
    obj = measured_wedge()
    path = tmp_path / "out.csv"
    assert bpy.ops.vg.export_csv(filepath=str(path)) == {"FINISHED"}
    header, *rows = read_rows(path)
    assert ",".join(header[:14]) == MESHLAB_HEADER
    assert tuple(header) == csvio.EXPORT_COLUMNS
    assert len(rows) == 3
    exported = csvio.read_measurements_csv(path)
    for row, item in zip(exported, obj.vg.measurements, strict=True):
        numbers = exact(item)
        assert row.mesh_name == "Wedge"
        assert (row.number, row.break_number) == (item.number, item.break_number)
        assert row.angle == numbers["angle"] and row.radius == numbers["radius"]
        assert [row.x, row.y, row.z] == numbers["center"]
        assert row.lam == numbers["lam"] and row.patch == item.patch
        assert (row.n_vertices, row.n_plus, row.n_minus) == (
            item.n_vertices,
            item.n_plus,
            item.n_minus,
        )
        assert list(row.normal_plus) == numbers["normal_plus"]
        assert row.stale is False
        assert row.blender_version == bpy.app.version_string
        assert row.extension_version == MANIFEST["version"]
        assert row.units
    assert exported[0].user_data == "=SUM(A1)"
    assert rows[0][5] == "'=SUM(A1)"  # the spreadsheet sees text, not a formula
    assert exported[2].colors == csvio.format_colors("vermillion/sky blue")


def test_export_then_import_replicates_exactly(vg, tmp_path):
    obj = measured_wedge()
    path = tmp_path / "out.csv"
    bpy.ops.vg.export_csv(filepath=str(path))
    bpy.ops.vg.import_csv(filepath=str(path))
    assert len(obj.vg.measurements) == 6
    originals, replicas = obj.vg.measurements[:3], obj.vg.measurements[3:]
    spread = 0.0
    for original, replica in zip(originals, replicas, strict=True):
        a, b = exact(original), exact(replica)
        spread = max(spread, abs(a["angle"] - b["angle"]))
        for key in ("angle", "fit", "radius", "lam", "center", "normal_plus", "normal_minus"):
            assert a[key] == b[key], key
        assert replica.patch == original.patch
        assert replica.break_number == original.break_number
        assert replica.n_vertices == original.n_vertices
    assert spread == 0.0
    assert [m.number for m in replicas] == [4, 5, 6]
    assert replicas[0].note == "=SUM(A1)"


def test_an_import_keeps_where_each_measurement_was_asked_for(vg, tmp_path):
    """A replication measures at the stored centre (x, y, z); it once recorded that centre as
    the requested one, with a snap distance of 0, losing where the user had clicked. Now the
    file's Requested x/y/z come back, with their snap distance; a row whose x, y, z were edited
    (its Snap Distance no longer theirs) asks for its new x, y, z. Oracle: the clicks made."""
    obj = measured_wedge()
    path = tmp_path / "out.csv"
    bpy.ops.vg.export_csv(filepath=str(path))
    originals = [exact(item) for item in obj.vg.measurements]
    assert all(o["snap_distance"] > 0 for o in originals[1:])  # clicks off a vertex
    bpy.ops.vg.import_csv(filepath=str(path))
    for original, replica in zip(originals, obj.vg.measurements[3:], strict=True):
        copy = exact(replica)
        assert copy["requested"] == original["requested"]
        assert copy["snap_distance"] == original["snap_distance"]
    rows = read_rows(path)
    header = rows[0]
    x, snap = header.index("x"), header.index("Snap Distance")
    rows[3][x] = repr(float(rows[3][x]) + 0.02)  # the third measurement moved by hand
    edited = tmp_path / "edited.csv"
    with open(edited, "w", newline="", encoding="utf-8") as handle:
        csv.writer(handle).writerows(rows)
    assert float(rows[3][snap]) > 0
    bpy.ops.vg.import_csv(filepath=str(edited))
    moved = exact(obj.vg.measurements[-1])
    assert moved["requested"][0] == float(rows[3][x])
    assert moved["snap_distance"] < originals[2]["snap_distance"]


def test_export_all_objects(vg, tmp_path):
    measured_wedge("A")
    measured_wedge("B", angle=70.0)
    wedge_object(50.0, "Unmeasured")
    path = tmp_path / "all.csv"
    bpy.ops.vg.export_csv(filepath=str(path), all_objects=True)
    names = [row.mesh_name for row in csvio.read_measurements_csv(path)]
    assert names == ["A"] * 3 + ["B"] * 3
    only = tmp_path / "active.csv"
    with pytest.raises(RuntimeError, match="'Unmeasured' has no measurements"):
        bpy.ops.vg.export_csv(filepath=str(only))  # the active object: the last one made
    assert not only.exists()


def test_export_marks_stale_measurements(vg, tmp_path):
    obj = measured_wedge()
    co = local_points(obj).copy()
    co[:, 2] += 0.01  # an edit of the mesh, not a move of the object
    obj.data.vertices.foreach_set("co", co.ravel())
    obj.data.update()
    bpy.context.view_layer.update()
    path = tmp_path / "stale.csv"
    bpy.ops.vg.export_csv(filepath=str(path))
    assert [row.stale for row in csvio.read_measurements_csv(path)] == [True] * 3


def test_export_is_in_mesh_coordinates_and_replicates_on_the_file_with_the_core(vg, tmp_path):
    """A scan imported Y-up (a rotation on the object), moved and scaled: the CSV carries the
    file's coordinates, and the core re-measures it on the file itself, bit for bit."""
    # Scanners write float32 coordinates, which Blender keeps exactly: the scan file here holds
    # the half annulus in float32.
    points, triangles, picks = half_annulus_with_edge_vertices()
    scan = meshio.write_ply(tmp_path / "HalfAnnulus.ply", points, triangles)
    mesh = meshio.read_mesh(scan)
    obj = mesh_object(
        "HalfAnnulus",
        mesh.points,
        mesh.triangles,
        location=(2.0, -5.0, 1.0),
        rotation=(math.pi / 2, 0.0, 0.3),
        scale=(0.01, 0.01, 0.01),
    )
    obj.vg.unit = "SCENE"  # chosen: the label tells mesh units by the scene's (no mm guess)
    for vertex in picks:  # the 3D cursor on a vertex, in world space
        cursor = world(mesh.points[vertex : vertex + 1], obj)[0]
        bpy.ops.vg.measure_xyz(location=cursor.tolist(), radius=0.3, seg_param=2.0)
    obj.location.x += 3.0  # moved again after measuring
    bpy.context.view_layer.update()
    path = tmp_path / "half_annulus.csv"
    bpy.ops.vg.export_csv(filepath=str(path))
    rows = csvio.read_measurements_csv(path)
    assert {row.coordinates for row in rows} == {"mesh"}
    assert not any(row.stale for row in rows)
    assert [[r.x, r.y, r.z] for r in rows] == mesh.points[picks].tolist()
    assert [r.radius for r in rows] == [0.3] * 3  # mesh units, not the object's 0.003
    assert {r.units for r in rows} == {
        "mesh units (1 unit = 0.01 m in the scene, object scale 0.01)"
    }
    surface = Surface(mesh.points, mesh.triangles)  # the file, float64 as written
    for row, exported in zip(csvio.read_replication_csv(path), rows, strict=True):
        m = surface.measure((row.x, row.y, row.z), row.radius, row.lam, row.patch)
        assert m.center_index == picks[exported.number - 1]
        assert (m.n_vertices, m.angle, m.fit_error) == (
            exported.n_vertices,
            exported.angle,
            exported.fit,
        )


def test_an_old_world_space_csv_is_read_as_world_space(vg, tmp_path):
    """An export of a version that wrote world coordinates (no Coordinates column) replicates
    on the object where it stands."""
    obj = wedge_object(100.0, location=(1.0, 2.0, 3.0), rotation=(0.0, 0.0, math.pi / 2))
    bpy.ops.vg.measure_xyz(location=(0.1, 0.0, 0.0), space="MESH", radius=0.5)
    item = obj.vg.measurements[0]
    centre_world = world(np.array([exact(item)["center"]]), obj)[0]
    header = ",".join(h for h in csvio.EXPORT_COLUMNS if h != "Coordinates")
    old = tmp_path / "old.csv"
    old.write_text(
        f"{header}\nWedge,2024-01-01T00:00:00+00:00,1,1,,,100.0,10,0.5,"
        + ",".join(repr(float(v)) for v in centre_world)
        + ",0.0,2.0,euclidean"
        + "," * (len(header.split(",")) - 15)
        + "\n",
        encoding="utf-8",
    )
    assert csvio.read_replication_csv(old)[0].coordinates == "world"
    bpy.ops.vg.import_csv(filepath=str(old))
    replica = exact(obj.vg.measurements[1])
    assert replica["center"] == exact(item)["center"]
    assert replica["angle"] == exact(item)["angle"]


def write(path, text):
    path.write_text(text, encoding="utf-8")
    return str(path)


def meshlab_row(obj_name, x, y, z, radius, lam, number=1, break_number=1, fit="0.001"):
    return (
        f"{obj_name},2019-05-03 10:12,{number},{break_number},red/blue,,95.1,400,{radius},"
        f"{x},{y},{z},{fit},{lam}"
    )


@pytest.mark.parametrize("fit", ["0.0012", "fill"], ids=["meshlab", "earlier-blender-add-on"])
def test_import_meshlab_and_earlier_add_on_files(vg, tmp_path, fit):
    obj = wedge_object(100.0)
    text = "\n".join(
        [
            MESHLAB_HEADER,
            meshlab_row("Wedge.ply", 0.0, 0.0, 0.0, 0.5, 2, fit=fit),
            meshlab_row("Wedge.ply", 0.3, 0.0, 0.0, 0.3, 1.5, number=2, break_number=2, fit=fit),
        ]
    )
    bpy.ops.vg.import_csv(filepath=write(tmp_path / "meshlab.csv", text))
    first, second = obj.vg.measurements
    assert exact(first)["radius"] == 0.5 and exact(first)["lam"] == 2.0
    assert exact(second)["requested"] == [0.3, 0.0, 0.0] and second.break_number == 2
    bpy.ops.vg.measure_xyz(location=(0.3, 0.0, 0.0), radius=0.3, seg_param=1.5)
    assert exact(obj.vg.measurements[2])["angle"] == exact(second)["angle"]


def test_import_plain_points_takes_the_panel_settings(vg, tmp_path):
    obj = wedge_object(100.0)
    bpy.context.scene.vg_settings.radius = 0.45
    bpy.ops.vg.import_csv(filepath=write(tmp_path / "p.csv", "x,y,z\n0,0,0\n0.2,0,0\n"))
    assert [exact(m)["radius"] for m in obj.vg.measurements] == [0.45, 0.45]


BAD_CSVS = {
    "missing column": (
        "Mesh Name,Radius,x,y\nWedge,0.5,0,0\n",
        r"missing the required column\(s\) z",
    ),
    "garbage row": (
        "Mesh Name,Radius,x,y,z\nWedge,0.5,0,0,0\nWedge,0.5,abc,0,0\nWedge,zero,0,0,0\n",
        r"row 3: x is not a number(.|\n)*row 4: Radius is not a number",
    ),
    "another mesh": (
        "Mesh Name,Radius,x,y,z\nWedge,0.5,0,0,0\nFemur_12.ply,0.5,0,0,0\n",
        r"row\(s\) of 'bad.csv' name another mesh than 'Wedge': rows 3 \('Femur_12.ply'\)",
    ),
    "semicolon delimiter": (
        "Mesh Name;Radius;x;y;z\nWedge;0,5;0;0;0\n",
        r"(;|delimiter|semicolon)",
    ),
    "row off the surface": (
        "Mesh Name,Radius,x,y,z\nWedge,0.5,0,0,0\nWedge,0.5,0,0,7\nWedge,0.001,{x!r},{y!r},{z!r}\n",
        r"2 of 3 rows(.|\n)*row 3: .*farther than(.|\n)*row 4: .*larger radius",
    ),
    "break number beyond 32 bits": (
        "Mesh Name,Radius,x,y,z,Break #\nWedge,0.5,{x!r},{y!r},{z!r},2\n"
        "Wedge,0.5,{x!r},{y!r},{z!r},2147483648\n",
        r"row 3: Break # must be a whole number from 1 to 2147483647 \(got '2147483648'\)",
    ),
    "break number text": (
        "Mesh Name,Radius,x,y,z,Break #\nWedge,0.5,{x!r},{y!r},{z!r},abc\n",
        r"row 2: Break # must be a whole number .*'abc'",
    ),
    "break number fraction": (
        "Mesh Name,Radius,x,y,z,Break #\nWedge,0.5,{x!r},{y!r},{z!r},1.5\n",
        r"row 2: Break # must be a whole number .*'1\.5'",
    ),
    "empty file": ("", r"empty"),
    "header only": ("x,y,z\n", r"no data rows"),
}


@pytest.mark.parametrize("case", BAD_CSVS)
def test_bad_csv_is_refused_with_row_numbers_and_nothing_changes(vg, tmp_path, case):
    obj = measured_wedge()
    before = snapshot(obj)
    text, message = BAD_CSVS[case]
    x, y, z = exact(obj.vg.measurements[0])["center"]  # on a vertex: only the radius is wrong
    text = text.format(x=x, y=y, z=z)
    with pytest.raises(RuntimeError, match=message):
        bpy.ops.vg.import_csv(filepath=write(tmp_path / "bad.csv", text))
    assert snapshot(obj) == before


def test_missing_file(vg, tmp_path):
    obj = measured_wedge()
    before = snapshot(obj)
    with pytest.raises(RuntimeError, match="Could not read"):
        bpy.ops.vg.import_csv(filepath=str(tmp_path / "nowhere.csv"))
    assert snapshot(obj) == before


def test_ignore_mesh_names(vg, tmp_path):
    source = measured_wedge("Original")
    path = tmp_path / "original.csv"
    bpy.ops.vg.export_csv(filepath=str(path))
    copy = wedge_object(100.0, "Copy")
    with pytest.raises(RuntimeError, match="name another mesh"):
        bpy.ops.vg.import_csv(filepath=str(path))
    bpy.ops.vg.import_csv(filepath=str(path), ignore_mesh_names=True)
    assert [exact(m)["angle"] for m in copy.vg.measurements] == [
        exact(m)["angle"] for m in source.vg.measurements
    ]


def test_export_with_nothing_to_export(vg, tmp_path):
    wedge_object(100.0)
    assert not bpy.ops.vg.export_csv.poll()  # greyed out, the reason in the tooltip
    with pytest.raises(RuntimeError, match="No object in this scene has measurements"):
        bpy.ops.vg.export_csv(filepath=str(tmp_path / "x.csv"))
    with pytest.raises(RuntimeError, match="No object in this scene has measurements"):
        bpy.ops.vg.export_csv(filepath=str(tmp_path / "x.csv"), all_objects=True)
    assert not (tmp_path / "x.csv").exists()


def test_export_to_a_missing_folder(vg, tmp_path):
    measured_wedge()
    with pytest.raises(RuntimeError, match=r"folder .* does not exist.*was not written"):
        bpy.ops.vg.export_csv(filepath=str(tmp_path / "no such folder" / "x.csv"))


def test_a_damaged_record_is_reported_not_crashed_on(vg, tmp_path):
    obj = measured_wedge()
    obj.vg.measurements[1].exact = '{"angle": 1.0}'  # e.g. edited by a script
    bpy.ops.vg.repaint()
    assert [m.stale for m in obj.vg.measurements] == [False, True, False]
    with pytest.raises(RuntimeError, match="Measurement 2 has lost its stored numbers"):
        bpy.ops.vg.export_csv(filepath=str(tmp_path / "x.csv"))
    assert not (tmp_path / "x.csv").exists()


def test_export_after_a_refused_break_number_still_works(vg, tmp_path):
    obj = measured_wedge()
    x, y, z = exact(obj.vg.measurements[0])["center"]
    bad = write(
        tmp_path / "bad.csv", f"Mesh Name,Radius,x,y,z,Break #\nWedge,0.5,{x},{y},{z},{2**31}\n"
    )
    with pytest.raises(RuntimeError, match="Break #"):
        bpy.ops.vg.import_csv(filepath=bad)
    bpy.ops.vg.export_csv(filepath=str(tmp_path / "after.csv"))
    assert len(read_rows(tmp_path / "after.csv")) == 1 + len(obj.vg.measurements) == 4


@pytest.mark.parametrize("operator", ["export_csv", "import_csv"])
def test_a_blend_relative_path_in_an_unsaved_file_is_refused(vg, tmp_path, monkeypatch, operator):
    obj = measured_wedge()
    bpy.ops.vg.export_csv(filepath=str(tmp_path / "m.csv"))
    before = snapshot(obj)
    monkeypatch.chdir(tmp_path)  # where "//" would silently land
    assert not bpy.data.filepath
    with pytest.raises(RuntimeError, match=r"'//m\.csv' is relative to the \.blend file .*save"):
        getattr(bpy.ops.vg, operator)(filepath="//m.csv")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.csv"]
    assert snapshot(obj) == before


def test_replicating_rows_with_a_break_number_blender_cannot_store_records_nothing(vg):
    obj = measured_wedge()
    before = snapshot(obj)
    x, y, z = exact(obj.vg.measurements[0])["center"]
    row = vg.vg_addon.formats.csvio.ReplicationRow
    rows = [row(2, "Wedge", x, y, z, radius=0.5), row(3, "Wedge", x, y, z, 0.5, break_number=2**31)]
    with pytest.raises(vg.vg_addon.GoniometerError, match=r"row 3: Break # 2147483648"):
        vg.bridge.replication.replicate_rows(obj, rows)
    assert snapshot(obj) == before


def test_export_through_a_symbolic_link_updates_its_target_and_keeps_the_link(vg, tmp_path):
    obj = measured_wedge()
    target = tmp_path / "real.csv"
    target.write_text("old\n")
    link = tmp_path / "link.csv"
    link.symlink_to(target)
    bpy.ops.vg.export_csv(filepath=str(link))
    assert link.is_symlink() and os.readlink(link) == str(target)
    assert len(read_rows(target)) == 1 + len(obj.vg.measurements)


def test_rows_of_another_object_are_not_taken_by_this_ones_mesh_name(vg, tmp_path):
    """An object keeps its mesh's name when renamed: 'bone_left', imported as bone.ply, has the
    mesh 'bone', and another object is called 'bone'. A CSV row of that object was once
    re-measured on 'bone_left' with no word (its 100° came back as 60°). Oracle: the wedges'
    true angles and the refusal naming the other mesh."""
    bone = wedge_object(100.0, "bone")
    bpy.ops.vg.measure_xyz(location=(0, 0, 0), radius=0.5)
    left = wedge_object(60.0, "bone_left")
    bpy.ops.vg.measure_xyz(location=(0, 0, 0), radius=0.5)
    bone.data.name, left.data.name = "bone_mesh", "bone"
    path = tmp_path / "all.csv"
    bpy.ops.vg.export_csv(filepath=str(path), all_objects=True)
    bpy.context.view_layer.objects.active = left
    before = snapshot(left)
    with pytest.raises(RuntimeError, match="name another mesh"):
        bpy.ops.vg.import_csv(filepath=str(path))
    assert snapshot(left) == before
    own = tmp_path / "left.csv"
    bpy.ops.vg.export_csv(filepath=str(own))
    bpy.ops.vg.import_csv(filepath=str(own))  # its own rows still come back, by either name
    first, again = (exact(m)["angle"] for m in left.vg.measurements)
    assert again == first == pytest.approx(60.0, abs=0.01)


def test_an_imported_break_at_the_largest_number_leaves_the_next_break_there(vg, tmp_path):
    """Break # 2147483647 (the largest a CSV may give) was read, recorded, and then the next
    break, one past it, overflowed Blender's integer: a traceback, with the row already
    recorded and nothing repainted. Oracle: the limit itself and the recorded rows."""
    obj = measured_wedge()
    x, y, z = exact(obj.vg.measurements[0])["center"]
    last = csvio.MAX_BREAK_NUMBER
    path = write(
        tmp_path / "max.csv", f"Mesh Name,Radius,x,y,z,Break #\nWedge,0.5,{x},{y},{z},{last}\n"
    )
    assert bpy.ops.vg.import_csv(filepath=path) == {"FINISHED"}
    assert obj.vg.measurements[-1].break_number == last and obj.vg.break_number == last
    assert bpy.ops.vg.next_break() == {"FINISHED"} and obj.vg.break_number == last


def test_an_import_says_which_failed_rows_it_passed_over(vg, tmp_path, capfd):
    """A batch run's failed row (error filled, no x, y, z) is skipped by the import, as
    documented; the report said only how many rows it re-measured, so the point dropped out
    without a word. It now names the rows passed over, as a warning."""
    wedge_object(100.0, "scan")
    good = "scan,,1,1,,,,,0.5,0,0,0,,2,"
    failed = "scan,,2,1,,,,,1e-9,,,,,2,The centre is farther than the radius from every vertex"
    header = MESHLAB_HEADER + ",error"
    path = write(tmp_path / "run.csv", f"{header}\n{good}\n{failed}\n")
    capfd.readouterr()
    assert bpy.ops.vg.import_csv(filepath=path) == {"FINISHED"}
    said = capfd.readouterr()
    assert "Re-measured 1 row(s) of run.csv on 'scan' (measurements 1–1); " in said.out
    assert (
        "passed over 1 row(s) a batch run could not measure (rows 3: no x, y, z; their error "
        "column says why)"
    ) in said.out + said.err
    # Its header has columns of an export, not all: its angles were not compared, as it says.
    assert "its angles were not compared with the file's" in said.out


def test_an_edge_note_edited_after_measuring_comes_back_with_the_export(vg, tmp_path, capfd):
    """An edge's note edited in the panel is written to its summary row (NAME_edges.csv); its
    stations keep the note they were measured with. Importing the export's main CSV rebuilt
    the edge with its first station's note (before): the edit was lost. The oracle: the note
    typed, and the summary file as exported."""
    import json

    obj = wedge_object(100.0, "scan")
    bpy.ops.vg.measure_edge(
        points=json.dumps([[-0.6, 0.0, 0.0], [0.6, 0.0, 0.0]]), space="MESH", spacing=0.2,
        radius=0.4, note="as measured",
    )  # fmt: skip
    obj.vg.edges[0].note = "edited: spiral fracture, fresh"
    path = tmp_path / "out.csv"
    bpy.ops.vg.export_csv(filepath=str(path))
    (summary,) = csvio.read_edges_csv(csvio.edges_path_for(path))
    assert summary.user_data == "edited: spiral fracture, fresh"
    assert {row.user_data for row in csvio.read_measurements_csv(path)} == {"as measured"}
    bpy.ops.vg.clear_measurements()
    capfd.readouterr()
    assert bpy.ops.vg.import_csv(filepath=str(path)) == {"FINISHED"}
    assert obj.vg.edges[0].note == "edited: spiral fracture, fresh"
    assert {item.note for item in obj.vg.measurements} == {"as measured"}  # the stations' own
    said = capfd.readouterr()
    assert "; 1 edge(s) take their note from out_edges.csv" in said.out + said.err
    # A summary of other stations (left from an earlier export) names no rebuilt edge.
    other = dataclasses.replace(summary, n_stations=summary.n_stations + 1, user_data="stale")
    csvio.write_edges_csv(csvio.edges_path_for(path), [other])
    bpy.ops.vg.clear_measurements()
    assert bpy.ops.vg.import_csv(filepath=str(path)) == {"FINISHED"}
    assert obj.vg.edges[0].note == "as measured"
    # Without the summary beside it the stations' note names the edge, as before.
    alone = tmp_path / "alone" / "out.csv"
    alone.parent.mkdir()
    alone.write_bytes(path.read_bytes())
    bpy.ops.vg.clear_measurements()
    assert bpy.ops.vg.import_csv(filepath=str(alone)) == {"FINISHED"}
    assert obj.vg.edges[0].note == "as measured"


def test_an_export_of_an_edge_with_a_station_deleted_says_its_summary_keeps_it(vg, tmp_path, capfd):
    """A station deleted from an edge: the CSV holds one station row fewer while the summary
    row keeps the figures of every station (as the panel says), and importing the summary
    measures the deleted station again. The export said nothing (before); it now warns."""
    import json

    obj = wedge_object(100.0, "scan")
    bpy.ops.vg.measure_edge(
        points=json.dumps([[-0.6, 0.0, 0.0], [0.6, 0.0, 0.0]]), space="MESH", spacing=0.2,
        radius=0.4,
    )  # fmt: skip
    stations = obj.vg.edges[0].n_stations
    bpy.ops.vg.delete_measurement(index=2)
    path = tmp_path / "out.csv"
    capfd.readouterr()
    assert bpy.ops.vg.export_csv(filepath=str(path)) == {"FINISHED"}
    said = capfd.readouterr()
    assert len(csvio.read_measurements_csv(path)) == stations - 1
    assert csvio.read_edges_csv(csvio.edges_path_for(path))[0].n_stations == stations
    assert (
        "1 edge(s) lost stations after they were measured ('scan' edge 1): their summary rows "
        "keep the figures of every station as recorded"
    ) in said.out + said.err


def test_an_export_that_does_not_read_back_in_full_says_its_angles_were_not_compared(
    vg, tmp_path, capfd
):
    """German LibreOffice re-saves ``FALSE`` as ``FALSCH``: the import re-measured the rows and
    said nothing of the file's angles (the strict reader refused the file, and the report took
    it for a file of another kind), nor that its Units and Colors were not taken. It now says
    the angles were not compared, and why; the batch's replay says the same."""
    measured_wedge()
    path = tmp_path / "out.csv"
    assert bpy.ops.vg.export_csv(filepath=str(path)) == {"FINISHED"}
    header, *rows = read_rows(path)
    stale = header.index("Stale")
    assert {row[stale] for row in rows} == {"FALSE"}
    edited = tmp_path / "resaved.csv"
    with edited.open("w", newline="", encoding="utf-8") as handle:
        csv.writer(handle).writerows(
            [header, *([*r[:stale], "FALSCH", *r[stale + 1 :]] for r in rows)]
        )
    capfd.readouterr()
    assert bpy.ops.vg.import_csv(filepath=str(edited)) == {"FINISHED"}
    said = capfd.readouterr()
    assert "its angles were not compared with the file's" in said.out + said.err
    assert "(row 2: Stale is not TRUE or FALSE)" in said.out + said.err
    from bpy_helpers import batch

    from vg_addon.synthetic_meshes import wedge

    shape = wedge(100.0, n=40, irregular=True)  # wedge_object's, as a file
    mesh = meshio.write_ply(tmp_path / "Wedge.ply", shape.points, shape.triangles)
    replay = batch(mesh, "--points", edited, "--out", tmp_path / "again.csv")
    assert replay.returncode == 0, replay.stderr
    assert "re-measured resaved.csv: its angles were not compared" in replay.stderr
