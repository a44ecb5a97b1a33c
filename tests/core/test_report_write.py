"""write_report on hand-built sessions in any Python with the report's libraries: stations of
one break plotted as an edge profile, what was left out counted, the outputs never an input."""

from __future__ import annotations

import csv
import re

import pytest

pytest.importorskip("matplotlib", reason="the report's figures need requirements/report.txt")
pytest.importorskip("statsmodels", reason="the report's regression needs statsmodels")

from vg_addon import GoniometerError
from vg_addon.analysis.report import write_report


def session(folder, name, rows):
    path = folder / name
    lines = ["Mesh,Break #,Angle,x,y,z,Radius"] + [f"m,1,{r}" for r in rows]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def test_stations_make_an_edge_profile_and_the_ambiguous_row_is_counted(tmp_path):
    paths = [
        session(tmp_path, "obs1_drag_1.csv", ["100,0,0,0,3", "110,4,0,0,3", "120,8,0,0,3"]),
        session(tmp_path, "obs1_drag_2.csv", ["101,0.2,0,0,3", "111,4.1,0,0,3", "119,8,0.3,0,3"]),
        session(tmp_path, "obs1_drag_3.csv", ["99,0,0.1,0,3", "112,3.9,0,0,3", "115,6,0,0,3"]),
    ]
    outcome = write_report(paths, tmp_path / "out")
    # 6,0,0 is as near to the stations at 4 and 8: ambiguous, left out, said.
    assert outcome.left_out == [
        "obs1_drag_3.csv row 4: m break 1: ambiguous, as near to rows 3 and 4 of obs1_drag_1.csv "
        "(2); left out"
    ]
    assert outcome.code == 1 and outcome.sessions == 3
    assert "profile_1" in outcome.figures
    assert (tmp_path / "out" / "figures" / "profile_1.svg").is_file()
    with open(tmp_path / "out" / "breaks.csv", encoding="utf-8", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert [(r["Station"], r["drag n"]) for r in rows] == [("1", "3"), ("2", "3"), ("3", "2")]
    assert float(rows[0]["drag angle IOV"]) == pytest.approx((1 + 1 + 2) / 3)
    assert float(rows[2]["drag angle IOV"]) == 1.0
    left = (tmp_path / "out" / "left_out.csv").read_text(encoding="utf-8")
    assert "obs1_drag_3.csv row 4" in left


def test_nothing_usable_writes_nothing(tmp_path):
    bad = tmp_path / "obs1_drag_1.csv"
    bad.write_text("Mesh,Angle\nm,90\n", encoding="utf-8")
    with pytest.raises(GoniometerError, match="no session could be used; nothing was written"):
        write_report([bad], tmp_path / "out")
    assert not (tmp_path / "out").exists()
    blocker = tmp_path / "file"
    blocker.write_text("x", encoding="utf-8")
    with pytest.raises(GoniometerError, match="is not a folder"):
        write_report([bad], blocker)


def test_an_iov_of_exactly_zero_is_drawn_without_an_axis_below_zero():
    # The xyz method's IOV is 0 at every break: its histogram is one bar on 0 and its CI plot a
    # point on 0, neither with an axis reaching negative IOVs (which cannot be).
    from vg_addon.analysis import figures, stats

    histogram = figures.iov_histograms({"drag": [0.4, 1.2, 0.9], "xyz": [0.0] * 5}, "angle", "°")
    drag, xyz = histogram.axes
    assert xyz.get_xlim()[0] == 0.0 and drag.get_xlim()[0] < 0.4
    assert [p.get_height() for p in xyz.patches] == [5]
    assert abs(xyz.patches[0].get_x()) < 1e-12  # the bar starts on 0
    drag = [0.9, 1.1, 1.0, 1.2, 0.95, 1.05]
    summaries = {"drag": stats.summarise(drag), "xyz": stats.summarise([0.0] * 5)}
    ci = figures.ci_plot(summaries, "°")
    drag, xyz = ci.axes
    assert xyz.get_ylim()[0] == 0.0 and drag.get_ylim()[0] > 0.0


def test_a_compare_name_that_several_sessions_share_is_refused_with_its_reason(tmp_path):
    """Two folders each with a drag_1.csv (two observers): --compare other.csv drag_1.csv took
    the first one silently. It is now not computed, saying the name is shared and by whom."""
    paths = []
    for folder, observer, shift in (("a", "obs1", 0), ("b", "obs2", 2), ("c", "obs3", 1)):
        (tmp_path / folder).mkdir()
        name = "other_drag.csv" if folder == "c" else "drag_1.csv"
        text = "Mesh,Break #,Angle,Observer\n" + "".join(
            f"m,{b},{90 + b + shift},{observer}\n" for b in range(1, 5)
        )
        (tmp_path / folder / name).write_text(text, encoding="utf-8")
        paths.append(tmp_path / folder / name)
    outcome = write_report(paths, tmp_path / "out", compare=[("other_drag.csv", "drag_1.csv")])
    assert (
        "Bland–Altman other_drag.csv against drag_1.csv: not computed, 'drag_1.csv' names 2 "
        "sessions (of observers obs1, obs2): give the files names of their own"
    ) in outcome.not_computed


def test_a_compare_name_that_is_both_a_method_and_a_session_is_refused(tmp_path):
    """A session file named as another session's method: --compare caliper drag_1.csv meant
    the method silently. It is now not computed, saying the name is both."""
    paths = []
    for name, method, shift in (("caliper", "drag", 0), ("drag_1.csv", "caliper", 2)):
        text = "Mesh,Break #,Angle,Method\n" + "".join(
            f"m,{b},{90 + b + shift},{method}\n" for b in range(1, 5)
        )
        (tmp_path / name).write_text(text, encoding="utf-8")
        paths.append(tmp_path / name)
    outcome = write_report(paths, tmp_path / "out", compare=[("caliper", "drag_1.csv")])
    assert (
        "Bland–Altman caliper against drag_1.csv: not computed, 'caliper' names both a method "
        "and a session file: rename the file, or give the method another name (--method)"
    ) in outcome.not_computed


def drag_sessions(folder, rows_of):
    """Two drag sessions of one observer on three breaks; ``rows_of(repetition, break)`` gives
    each row's x, radius and vertex count (and y, else 0)."""
    paths = []
    for repetition in (1, 2):
        lines = ["Mesh,Break #,Angle,x,y,z,Radius,Number of Vertices"]
        for number in (1, 2, 3):
            x, radius, vertices, *y = rows_of(repetition, number)
            y = y[0] if y else 0
            lines.append(f"m,{number},{90 + repetition + number},{x},{y},0,{radius},{vertices}")
        path = folder / f"obs1_drag_{repetition}.csv"
        path.write_text("\n".join(lines) + "\n", encoding="utf-8")
        paths.append(path)
    return paths


@pytest.mark.parametrize(
    ("case", "rows_of"),
    [
        # Squares of centre distances past 1e154 overflowed: OverflowError out of the report.
        ("far centres", lambda rep, _: (1e200 if rep == 1 else -1e200, 1, 100)),
        ("centres at the float limit", lambda rep, _: (1e308 if rep == 1 else -1e308, 1, 100)),
        # Finite squares whose sum overflows: fsum raised instead of giving inf.
        (
            "squares summing past the limit",
            lambda rep, _: (1.2e154 * (rep == 1), 1, 100, 1.2e154 * (rep == 1)),
        ),
        # Radius IOVs near the float limit: fsum's running sum of them overflowed the same way.
        ("huge radii", lambda rep, number: (0.1 * rep, 1e308 if rep == 1 else 1, 100 + number)),
    ],
)
def test_numbers_near_the_float_limit_give_a_report_not_a_traceback(tmp_path, case, rows_of):
    outcome = write_report(drag_sessions(tmp_path, rows_of), tmp_path / "out")
    assert (tmp_path / "out" / "report.html").is_file(), case
    assert outcome.sessions == 2
    for name in ("breaks.csv", "sessions.csv", "report.html"):
        text = (tmp_path / "out" / name).read_text(encoding="utf-8")
        text = re.sub(r"data:[^\"')]*", "", text)  # the figures' pixels, base64
        assert not re.search(r"\b(nan|inf|infinity)\b", text, re.IGNORECASE), (case, name)


def test_a_vertex_count_no_patch_can_have_is_left_out_and_said(tmp_path):
    counts = {1: 0, 2: "1e308", 3: -5}  # 1e308 crashed the report; -5 was taken as a count
    outcome = write_report(
        drag_sessions(
            tmp_path, lambda rep, number: (0.1 * rep, 1, counts[number] if rep == 2 else 50)
        ),
        tmp_path / "out",
    )
    left = "\n".join(outcome.left_out)
    assert "obs1_drag_2.csv: row 3: Number of Vertices 1e+308 is not a count" in left, left
    assert "obs1_drag_2.csv: row 4: Number of Vertices -5 is not a count" in left, left
    assert "row 2" not in left  # 0 vertices is a count (a refused patch)
    assert (tmp_path / "out" / "report.html").is_file()
