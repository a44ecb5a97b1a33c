"""Sessions in different coordinate spaces: centres and radii in Blender's world space (rows whose
Coordinates say world) are never compared with ones in mesh coordinates; the report refuses them,
naming each file and its space. Files written before the column are compared as mesh
coordinates, with a note saying when that is wrong."""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest
from csv_rows import MESHLAB_HEADER

from vg_addon import GoniometerError
from vg_addon.analysis import iov
from vg_addon.analysis.matching import match_sessions
from vg_addon.analysis.sessions import load_sessions, spaces_apart

# The object sits at x = 1000 in the scene, scaled 10: the same place and patch in both spaces.
HEADER = "Mesh Name,Break #,Angle,x,y,z,Radius,Number of Vertices,Coordinates"
WORLD_ROW = "bone,1,100.0,1010.0,20.0,30.0,20.0,500,world"
MESH_ROW = "bone,1,100.5,1.0,2.0,3.0,2.0,500,mesh"

# An export of a version before the Coordinates column: MeshLab's 14 columns and this
# extension's Patch Mode after them, no Coordinates (world, as docs/CSV.md says).
OLD_EXPORT = (
    MESHLAB_HEADER + ",Patch Mode\n"
    "bone,2024-05-01T14:03:11+02:00,1,1,#E69F00/#0072B2,,100.0,500,20.0,1010.0,20.0,30.0,"
    "0.01,2.0,euclidean\n"
)


def write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.write_text(textwrap.dedent(text).lstrip(), encoding="utf-8")
    return path


def refusal(paths) -> str:
    with pytest.raises(GoniometerError) as info:
        load_sessions(paths)
    return str(info.value)


def test_world_and_mesh_sessions_of_one_break_are_refused_naming_each_file(tmp_path):
    world = write(tmp_path, "obs1_drag_1.csv", f"{HEADER}\n{WORLD_ROW}\n")
    mesh = write(tmp_path, "obs1_drag_2.csv", f"{HEADER}\n{MESH_ROW}\n")
    message = refusal([world, mesh])
    # Before: read as two readings 1,009 units apart with radii 20 and 2 (a centre IOV of 1009
    # and a radius IOV of 18), not a word said.
    assert "different coordinate spaces" in message
    assert (
        "bone: obs1_drag_1.csv has 1 row in world coordinates; obs1_drag_2.csv has 1 row in mesh "
        "coordinates"
    ) in message
    assert "Export those measurements again with the current version" in message
    assert "set their Coordinates cells to mesh" in message


def test_an_export_without_the_coordinates_column_is_compared_as_mesh_saying_so(tmp_path):
    """Exports and batch runs written before the Coordinates column hold world coordinates, the
    mesh's own for a batch run (its object is never transformed) and for an object never moved:
    refusing them beside a current file blocked a right report (a first version of this rule).
    They are compared as mesh coordinates, and the report's notes say so and when it is wrong."""
    old = write(tmp_path, "obs1_drag_1.csv", OLD_EXPORT.replace("1010.0,20.0,30.0", "1.0,2.0,3.0"))
    mesh = write(tmp_path, "obs1_drag_2.csv", f"{HEADER}\n{MESH_ROW}\n")
    loaded = load_sessions([old, mesh])
    readings = [r for s in loaded.sessions for r in s.readings]
    assert [(r.coordinates, r.space_assumed) for r in readings] == [
        ("mesh", True),
        ("mesh", False),
    ]
    (note,) = loaded.notes
    assert note.startswith("obs1_drag_1.csv: written before the Coordinates column, so its 1 ")
    assert "export it again with the current version" in note
    stats = iov.break_stats(match_sessions(loaded.sessions).units, loaded.sessions)
    assert stats[0].methods["drag"].iov["centre"] == 0.0


def test_a_blank_coordinates_cell_is_assumed_in_an_export_and_mesh_elsewhere(tmp_path):
    # In this extension's export an empty cell means world (docs/CSV.md), compared as mesh with
    # a note; in any other file (a points table, a batch-like table without MeshLab's columns
    # first) it is the mesh's own, and nothing is said.
    export = write(
        tmp_path,
        "obs1_drag_1.csv",
        MESHLAB_HEADER + ",Patch Mode,Coordinates\n"
        "bone,,1,1,,,100.0,500,20.0,1010.0,20.0,30.0,0.01,2.0,euclidean,\n",
    )
    table = write(tmp_path, "obs1_drag_2.csv", f"{HEADER}\n{WORLD_ROW.removesuffix('world')}\n")
    mesh = write(tmp_path, "obs1_drag_3.csv", f"{HEADER}\n{MESH_ROW}\n")
    assert [r.space_assumed for s in load_sessions([export]).sessions for r in s.readings] == [True]
    loaded = load_sessions([table, mesh])
    assert [r.coordinates for s in loaded.sessions for r in s.readings] == ["mesh", "mesh"]
    assert not loaded.notes


def test_a_session_in_both_spaces_is_named_with_its_rows_in_each(tmp_path):
    both = write(
        tmp_path,
        "obs1_drag_1.csv",
        f"""
        {HEADER}
        {WORLD_ROW}
        bone,2,80.0,1.0,5.0,3.0,2.0,400,mesh
        bone,3,70.0,1.0,9.0,3.0,2.0,400,Mesh
        """,
    )
    message = refusal([both])
    assert "bone: obs1_drag_1.csv has 2 rows in mesh and 1 row in world coordinates" in message


def test_sessions_in_one_space_or_without_centres_are_compared_as_before(tmp_path):
    world_1 = write(tmp_path, "obs1_drag_1.csv", f"{HEADER}\n{WORLD_ROW}\n")
    world_2 = write(
        tmp_path, "obs1_drag_2.csv", f"{HEADER}\n{WORLD_ROW.replace('100.0', '101.0')}\n"
    )
    manual = write(tmp_path, "obs1_manual_1.csv", "Mesh,Break #,Angle\nbone,1,98\n")
    loaded = load_sessions([world_1, world_2, manual])
    assert not loaded.refused and spaces_apart(loaded.sessions) == []
    stats = iov.break_stats(match_sessions(loaded.sessions).units, loaded.sessions)
    drag = stats[0].methods["drag"]
    assert drag.iov["angle"] == 1.0 and drag.iov["centre"] == 0.0 and drag.iov["radius"] == 0.0


def test_different_meshes_in_different_spaces_are_never_compared_so_not_refused(tmp_path):
    world = write(tmp_path, "obs1_drag_1.csv", f"{HEADER}\n{WORLD_ROW.replace('bone', 'rib')}\n")
    mesh = write(tmp_path, "obs1_drag_2.csv", f"{HEADER}\n{MESH_ROW}\n")
    loaded = load_sessions([world, mesh])
    assert [r.coordinates for s in loaded.sessions for r in s.readings] == ["world", "mesh"]


def test_an_unknown_coordinate_space_leaves_its_row_out_and_says_why(tmp_path):
    odd = write(tmp_path, "obs1_drag_1.csv", f"{HEADER}\n{WORLD_ROW.replace('world', 'local')}\n")
    loaded = load_sessions([odd])
    assert loaded.sessions[0].left_out == [
        "row 2: Coordinates 'local' is not mesh or world, so its centre and radius cannot be "
        "compared"
    ]


def test_the_report_is_refused_and_nothing_written(tmp_path):
    pytest.importorskip("matplotlib", reason="the report's figures need requirements/report.txt")
    pytest.importorskip("statsmodels", reason="the report's regression needs statsmodels")
    from vg_addon.analysis.report import write_report

    world = write(tmp_path, "obs1_drag_1.csv", f"{HEADER}\n{WORLD_ROW}\n")
    mesh = write(tmp_path, "obs1_drag_2.csv", f"{HEADER}\n{MESH_ROW}\n")
    with pytest.raises(GoniometerError, match="different coordinate spaces"):
        write_report([world, mesh], tmp_path / "out")
    assert not (tmp_path / "out").exists()
