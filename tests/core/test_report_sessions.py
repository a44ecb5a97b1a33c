"""Sessions, matching and the IOV on hand-built CSVs: the paper's IOV by hand, rows matched by
mesh and break and by nearest centre, the ambiguous cases reported, bad input named."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from vg_addon.analysis import iov, missing_message
from vg_addon.analysis.matching import match_sessions
from vg_addon.analysis.sessions import load_sessions, method_word, observer_word

ROOT = Path(__file__).resolve().parents[2]


def write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.write_text(textwrap.dedent(text).lstrip(), encoding="utf-8")
    return path


def test_iov_is_the_papers_mean_absolute_pairwise_difference():
    # Equation 4.1: (|t-p| + |t-s| + |p-s|) / 3 for t, p, s = 90, 93, 88 -> (3 + 2 + 5) / 3.
    assert iov.mean_abs_difference([90.0, 93.0, 88.0]) == pytest.approx(10 / 3)
    assert iov.mean_abs_difference([42.5, 42.5]) == 0.0
    assert iov.mean_abs_difference([42.5]) is None
    # Centres: the mean distance over pairs (3-4-5 triangles).
    assert iov.mean_distance([(0, 0, 0), (3, 4, 0), (0, 0, 0)]) == pytest.approx(10 / 3)
    # Between observers: pairs across groups only: |1-4|, |1-6|, |3-4|, |3-6| -> 12 / 4.
    assert iov.cross_difference([[1.0, 3.0], [4.0, 6.0]]) == 3.0


def test_names_give_the_method_and_observer():
    assert method_word("obs2_drag_3") == "drag"
    assert method_word("Manual goniometer") == "manual"
    assert method_word("dragon_1") is None
    assert observer_word("obs2_drag_3.csv") == "obs2"
    assert observer_word("drag_3.csv") is None


def test_sessions_match_by_mesh_and_break_and_give_the_iov(tmp_path):
    a = write(
        tmp_path,
        "obs1_drag_1.csv",
        """
        Mesh Name,Break #,Angle,x,y,z,Radius,Number of Vertices
        bone_1,1,90,0,0,0,2,100
        bone_1,2,120,5,0,0,2,200
        """,
    )
    b = write(
        tmp_path,
        "obs1_drag_2.csv",
        """
        Mesh Name,Break #,Angle,x,y,z,Radius,Number of Vertices
        bone_1.ply,1,93,0.3,0.4,0,2.5,130
        bone_1,2,118,5,0,0,2,200
        """,
    )
    manual = write(tmp_path, "goniometer.csv", "Mesh,Break #,Angle\nbone_1,1,85\nbone_1,2,125\n")
    loaded = load_sessions([a, b, manual], methods=["drag", "drag", "manual"])
    assert loaded.refused == []
    assert [s.method for s in loaded.sessions] == ["drag", "drag", "manual"]
    assert [s.observer for s in loaded.sessions] == ["obs1", "obs1", "observer 1"]
    matched = match_sessions(loaded.sessions)
    assert matched.unmatched == []
    assert [u.label for u in matched.units] == ["bone_1 break 1", "bone_1 break 2"]
    stats = iov.break_stats(matched.units, loaded.sessions)
    drag = stats[0].methods["drag"]
    assert drag.iov["angle"] == 3.0
    assert drag.iov["centre"] == pytest.approx(0.5)
    assert drag.iov["radius"] == 0.5
    assert drag.iov["vertices"] == 30.0
    assert drag.angle.mean == 91.5 and drag.angle.n == 2
    assert stats[0].methods["manual"].iov["angle"] is None  # one manual reading: no IOV
    assert stats[1].methods["drag"].iov["centre"] == 0.0


def stations(folder: Path, name: str, *rows: str) -> Path:
    """A session of rows ``angle,x,y,z`` on mesh m, break 1, radius 3."""
    lines = "".join(f"m,1,{row},3\n" for row in rows)
    return write(folder, name, "Mesh,Break #,Angle,x,y,z,Radius\n" + lines)


def test_stations_on_one_break_match_by_nearest_centre_and_ambiguity_is_reported(tmp_path):
    # The anchor session has two stations on break 1, 4 apart, radius 3.
    anchor = stations(tmp_path, "obs1_drag_1.csv", "100,0,0,0", "110,4,0,0")
    near = stations(tmp_path, "obs1_drag_2.csv", "111,3.8,0.2,0", "101,0.1,0,0")
    # Exactly between the two stations: which one cannot be told.
    midway = stations(tmp_path, "obs1_drag_3.csv", "105,2,0,0")
    far = stations(tmp_path, "obs1_drag_4.csv", "99,0,9,0")
    both_near_one = stations(tmp_path, "obs1_drag_5.csv", "100.5,0.2,0,0", "100.7,0.3,0,0")
    no_centre = write(tmp_path, "manual.csv", "Mesh,Break #,Angle\nm,1,104\n")
    loaded = load_sessions([anchor, near, midway, far, both_near_one, no_centre])
    matched = match_sessions(loaded.sessions)
    assert [u.label for u in matched.units] == ["m break 1 station 1", "m break 1 station 2"]
    first, second = matched.units
    assert sorted(r.angle for r in first.readings.values()) == [100.0, 100.5, 101.0]
    assert sorted(r.angle for r in second.readings.values()) == [110.0, 111.0]
    lines = "\n".join(matched.unmatched)
    assert "obs1_drag_3.csv row 2: m break 1: ambiguous, as near to rows 2 and 3" in lines
    assert "obs1_drag_4.csv row 2: m break 1: ambiguous, no station" in lines
    assert "obs1_drag_5.csv row 3: m break 1: ambiguous, another row of this session" in lines
    assert "manual.csv row 2: m break 1 has 2 stations" in lines
    assert len(matched.unmatched) == 4


def test_bad_input_is_named_not_dropped(tmp_path):
    dated = "Mesh,Break #,Angle,Date\nm,1,90,2026-01-05\nm,2,91,2026-01-05\nm,3,92,2026-01-05\n"
    good = write(tmp_path, "obs1_drag_1.csv", dated)
    same = write(tmp_path, "copy_drag.csv", dated)
    cells = write(
        tmp_path,
        "obs1_drag_2.csv",
        """
        Mesh,Break #,Angle,x,y,z,error
        m,1,abc,,,,
        m,2,"91,5",,,,
        m,3,93,1,2,,
        m,4,95,,,,
        m,,96,,,,
        m,5,,,,,batch: no vertex within the radius
        """,
    )
    columns = write(tmp_path, "obs1_drag_3.csv", "Mesh,Angle\nm,90\n")
    unknown = write(tmp_path, "session.csv", "Mesh,Break #,Angle\nm,1,90\n")
    semicolons = write(tmp_path, "obs1_xyz_1.csv", "Mesh;Break #;Angle\nm;1;90\n")
    loaded = load_sessions([good, same, cells, columns, unknown, semicolons, good])
    refused = "\n".join(loaded.refused)
    assert "copy_drag.csv: left out, its rows (numbers and dates) are those of obs1_drag_1.csv" in (
        refused
    )
    assert "'obs1_drag_3.csv': left out, it has no Break # column (its columns: Mesh, Angle)" in (
        refused
    )
    assert "session.csv: left out, its method is unknown" in refused
    assert "semicolon" in refused
    assert "'obs1_drag_1.csv': left out, it was given twice" in refused
    assert len(loaded.refused) == 5
    session = loaded.sessions[1]
    assert session.rows == 6
    assert [r.break_number for r in session.readings] == [4]
    assert session.left_out == [
        "row 2: Angle is not a number ('abc')",
        "row 3: Angle is not a number ('91,5'; use a point as the decimal separator)",
        "row 4: x, y, z must be all filled or all empty",
        "row 6: no Break #",
        "row 7: not measured in its run (batch: no vertex within the radius)",
    ]


def test_method_and_observer_columns_split_a_file_into_sessions(tmp_path):
    path = write(
        tmp_path,
        "all.csv",
        """
        Mesh,Break #,Angle,Method,Observer
        m,1,90,drag,A
        m,1,92,drag,B
        m,1,91,Manual,A
        """,
    )
    loaded = load_sessions([path])
    assert [(s.name, s.method, s.observer) for s in loaded.sessions] == [
        ("all.csv [drag/A]", "drag", "A"),
        ("all.csv [drag/B]", "drag", "B"),
        ("all.csv [manual/A]", "manual", "A"),
    ]
    stats = iov.break_stats(match_sessions(loaded.sessions).units, loaded.sessions)
    drag = stats[0].methods["drag"]
    assert drag.iov["angle"] is None  # each observer read it once
    assert drag.inter_iov == 2.0
    assert drag.observer_means == {"A": 90.0, "B": 92.0}


def test_analysis_imports_without_scipy_and_says_what_to_install():
    # The package is NumPy-only at import: run it where SciPy, statsmodels and matplotlib cannot
    # be imported, as in Blender's own Python.
    code = textwrap.dedent(
        """
        import sys
        class Block:
            def find_spec(self, name, path=None, target=None):
                if name.split(".")[0] in ("scipy", "statsmodels", "matplotlib", "pandas"):
                    raise ImportError("blocked: " + name)
        sys.meta_path.insert(0, Block())
        import importlib.util
        real = importlib.util.find_spec
        def find_spec(name, package=None):
            if name.split(".")[0] in ("scipy", "statsmodels", "matplotlib"):
                return None
            return real(name, package)
        importlib.util.find_spec = find_spec
        from vg_addon.analysis import iov, matching, missing_message, report, sessions
        from vg_addon.analysis import figures, icc, stats
        try:
            report.write_report(["x.csv"], "out")
        except Exception as error:
            print(type(error).__name__, error)
        """
    )
    run = subprocess.run(
        [sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, check=False
    )
    assert run.returncode == 0, run.stderr
    assert "GoniometerError The report needs scipy, statsmodels, matplotlib" in run.stdout
    assert "python vg_batch.py --report DIR" in run.stdout
    assert not (ROOT / "out").exists()
    assert missing_message() == ""  # here they are installed (requirements/report.txt)


def test_manual_repetitions_that_read_the_same_are_kept_and_angles_are_checked(tmp_path):
    """Three manual repetitions of three breaks, the second reading as the first (whole degrees:
    chance, not a copy, since nothing dates them): kept, with a note to check, and the IOV is
    the paper's equation 4.1 over all three (break 1: 40, 40, 42 -> (0 + 2 + 2) / 3; before: the
    second left out as "the same session given twice", IOV 2.0). An angle outside 0 to 180
    degrees is left out with its reason (before: -5 and 400 used, 1e308 a traceback)."""
    rows = ["m,1,40\nm,2,50\nm,3,60", "m,1,40\nm,2,50\nm,3,60", "m,1,42\nm,2,50\nm,3,61"]
    paths = [
        write(tmp_path, f"obs1_manual_{n}.csv", "Mesh,Break #,Angle\n" + text + "\n")
        for n, text in enumerate(rows, start=1)
    ]
    odd = write(tmp_path, "obs2_manual_1.csv", "Mesh,Break #,Angle\nm,1,-5\nm,2,400\nm,3,1e308\n")
    loaded = load_sessions([*paths, odd])
    assert [s.name for s in loaded.sessions][:3] == [p.name for p in paths]
    assert loaded.notes == [
        "obs1_manual_2.csv: kept, though its readings are those of obs1_manual_1.csv: without "
        "dates or centres a repetition that read the same cannot be told from a copy; leave the "
        "file out if it is one"
    ]
    assert loaded.sessions[3].readings == []
    assert loaded.sessions[3].left_out == [
        f"row {row}: Angle {value} is not an angle between two faces (0° to 180°)"
        for row, value in ((2, "-5"), (3, "400"), (4, "1e+308"))
    ]
    matched = match_sessions(loaded.sessions[:3])
    angles = {unit.label: sorted(r.angle for r in unit.readings.values()) for unit in matched.units}
    assert iov.mean_abs_difference(angles["m break 1"]) == pytest.approx(4 / 3)
