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
