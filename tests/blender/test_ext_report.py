"""The Report operator (vg.report) in the extension: the scene's measurements and chosen CSVs
as sessions, the report written where asked; the refusal where the libraries are missing is
pressed in real Blender (tests/gui/test_gui_buttons.py)."""

import csv

import bpy
import pytest
from bpy_helpers import wedge_object

pytest.importorskip("scipy", reason="the report needs requirements/report.txt")


def test_report_operator_over_the_scene_and_csv_sessions(vg, tmp_path):
    wedge_object(100.0, "Wedge")
    bpy.ops.vg.measure_xyz(location=(0, 0, 0), radius=0.5)
    bpy.ops.vg.next_break()
    bpy.ops.vg.measure_xyz(location=(0.3, 0.01, 0), radius=0.4)
    drag = tmp_path / "obs1_drag_1.csv"
    assert bpy.ops.vg.export_csv(filepath=str(drag)) == {"FINISHED"}
    for rep, (a, b) in enumerate(((98, 103), (101, 99)), start=1):
        (tmp_path / f"obs1_manual_{rep}.csv").write_text(
            f"Mesh,Break #,Angle\nWedge,1,{a}\nWedge,2,{b}\n", encoding="utf-8"
        )
    folder = tmp_path / "report"
    settings = bpy.context.scene.vg_settings  # the report's choices live with the scene
    settings.report_include_scene = True
    settings.report_scene_method = "xyz"
    settings.report_folder = str(folder)
    result = bpy.ops.vg.report(
        directory=str(tmp_path),
        files=[{"name": n} for n in ("obs1_drag_1.csv", "obs1_manual_1.csv", "obs1_manual_2.csv")],
    )
    assert result == {"FINISHED"}
    assert (folder / "report.html").is_file()
    with open(folder / "sessions.csv", encoding="utf-8", newline="") as handle:
        sessions = {row["Session"]: row["Method"] for row in csv.DictReader(handle)}
    assert sessions == {
        "obs1_drag_1.csv": "drag",
        "obs1_manual_1.csv": "manual",
        "obs1_manual_2.csv": "manual",
        "scene_measurements.csv": "xyz",
    }
    with open(folder / "breaks.csv", encoding="utf-8", newline="") as handle:
        breaks = list(csv.DictReader(handle))
    assert [float(b["manual angle IOV"]) for b in breaks] == [3.0, 4.0]  # |98-101|, |103-99|
    # The scene's rows are the exported ones: the same angles under another method.
    assert [b["drag mean angle"] for b in breaks] == [b["xyz mean angle"] for b in breaks]


def test_report_operator_without_sessions_says_what_to_choose(vg, tmp_path):
    with pytest.raises(RuntimeError, match="No sessions: choose session CSVs, or measure"):
        settings = bpy.context.scene.vg_settings
        settings.report_include_scene = True
        settings.report_folder = str(tmp_path / "r")
        bpy.ops.vg.report(directory=str(tmp_path), files=[])
    assert not (tmp_path / "r" / "report.html").exists()


def test_report_operator_names_what_it_left_out(vg, tmp_path, capfd):
    # Bad input from the file browser: a non-numeric cell, a break in one session only, a file
    # without a Break # column, the same (dated) session twice. The report is written; the
    # operator's warning names each one, as the batch's exit message does.
    dated = "Mesh,Break #,Angle,Date\nm,1,98,2026-01-05\nm,2,n/a,2026-01-05\n"
    (tmp_path / "obs1_manual_1.csv").write_text(dated, encoding="utf-8")
    (tmp_path / "obs1_manual_2.csv").write_text(
        "Mesh,Break #,Angle\nm,1,101\nm,2,99\nm,3,90\n", encoding="utf-8"
    )
    (tmp_path / "obs1_manual_3.csv").write_text("Mesh,Angle\nm,90\n", encoding="utf-8")
    (tmp_path / "copy_manual.csv").write_bytes((tmp_path / "obs1_manual_1.csv").read_bytes())
    settings = bpy.context.scene.vg_settings
    settings.report_include_scene = False
    settings.report_folder = str(tmp_path / "report")
    names = ("obs1_manual_1.csv", "obs1_manual_2.csv", "obs1_manual_3.csv", "copy_manual.csv")
    capfd.readouterr()
    result = bpy.ops.vg.report(directory=str(tmp_path), files=[{"name": n} for n in names])
    assert result == {"FINISHED"}
    out = capfd.readouterr()
    said = out.out + out.err
    # Break 1 in both sessions is used; break 2's n/a leaves it in one session, like break 3.
    assert "2 sessions, 2 of 5 rows used; 5 left out" in said
    for line in (
        "obs1_manual_1.csv: row 3: Angle is not a number ('n/a')",
        "m break 2: only in obs1_manual_2.csv; no IOV",
        "m break 3: only in obs1_manual_2.csv; no IOV",
        "'obs1_manual_3.csv': left out, it has no Break # column",
        "copy_manual.csv: left out, its rows (numbers and dates) are those of obs1_manual_1.csv",
    ):
        assert line in said, said
    assert (tmp_path / "report" / "report.html").is_file()

    # Two undated manual tables that read the same: both used, and the operator says to check.
    (tmp_path / "obs1_manual_4.csv").write_bytes((tmp_path / "obs1_manual_2.csv").read_bytes())
    settings.report_folder = str(tmp_path / "again")
    names = ("obs1_manual_2.csv", "obs1_manual_4.csv")
    result = bpy.ops.vg.report(directory=str(tmp_path), files=[{"name": n} for n in names])
    assert result == {"FINISHED"}
    out = capfd.readouterr()
    said = out.out + out.err
    assert "2 sessions, 6 of 6 rows used" in said
    assert "1 session(s) to check:" in said
    assert "obs1_manual_4.csv: kept, though its readings are those of obs1_manual_2.csv" in said


def test_a_report_folder_relative_to_an_unsaved_file_writes_nothing(vg, tmp_path, monkeypatch):
    # '//' is the .blend file's folder; this file has none, so it would mean the working folder.
    monkeypatch.chdir(tmp_path)
    (tmp_path / "obs1_manual_1.csv").write_text("Mesh,Break #,Angle\nm,1,98\n", encoding="utf-8")
    settings = bpy.context.scene.vg_settings
    settings.report_include_scene = False
    settings.report_folder = "//report"
    with pytest.raises(RuntimeError, match="has not been saved yet"):
        bpy.ops.vg.report(directory=str(tmp_path), files=[{"name": "obs1_manual_1.csv"}])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["obs1_manual_1.csv"]
