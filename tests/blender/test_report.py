"""``vg_batch.py --report`` end to end on sessions the project's own batch measured: a study
shaped like the paper's (scripts/replicate_study.py: drag sessions with jittered centres and
radii, xyz re-measurements of the first, manual goniometer tables, two observers), the IOV
checked against the session CSVs read here, the HTML self-contained, every figure present, and
bad input named in the report and the exit message."""

from __future__ import annotations

import base64
import csv
import itertools
import re
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path

import pytest

from vg_addon.formats import csvio

pytest.importorskip("scipy", reason="the report needs requirements/report.txt")

ROOT = Path(__file__).resolve().parents[2]


def run(*args) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, *map(str, args)], capture_output=True, text=True, check=False, timeout=900
    )


@pytest.fixture(scope="module")
def study(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("study")
    made = run(
        ROOT / "scripts" / "replicate_study.py",
        "--out",
        out,
        "--fragments",
        "1",
        "--observers",
        "2",
        "--spacing",
        "0.4",
    )
    assert made.returncode == 0, made.stdout + made.stderr
    return out


def table(path: Path) -> list[dict[str, str]]:
    with open(path, encoding="utf-8", newline="") as handle:
        return list(csv.DictReader(handle))


class Page(HTMLParser):
    """Every URL-bearing attribute and every image of a page."""

    def __init__(self):
        super().__init__()
        self.urls: list[str] = []
        self.images: list[str] = []

    def handle_starttag(self, tag, attrs):
        for name, value in attrs:
            if name in ("src", "href", "action", "data", "poster"):
                self.urls.append(value)
        if tag == "img":
            self.images.append(dict(attrs)["src"])


def sessions(study: Path) -> list[Path]:
    return sorted(study.glob("obs*_*.csv"))


def test_report_of_a_study_shaped_like_the_papers(study):
    report = study / "report"
    done = run(ROOT / "vg_batch.py", "--report", report, *sessions(study))
    assert done.returncode == 0, done.stdout + done.stderr
    # 2 observers x (3 drag + 2 xyz + 3 manual) sessions, 8 break sites each.
    assert "(16 sessions, 128 of 128 rows used," in done.stdout
    breaks = table(report / "breaks.csv")
    assert len(breaks) == 8
    # The IOV against the sessions read here with the export's own reader: equation 4.1 per
    # observer, averaged over the two observers.
    for row in breaks:
        number = int(row["Break #"])
        for method, reps in (("drag", 3), ("xyz", 2)):
            each = []
            for observer in ("obs1", "obs2"):
                angles = [
                    next(
                        r.angle for r in csvio.read_measurements_csv(p) if r.break_number == number
                    )
                    for p in sorted(study.glob(f"{observer}_{method}_*.csv"))
                ]
                assert len(angles) == reps
                pairs = [abs(a - b) for a, b in itertools.combinations(angles, 2)]
                each.append(sum(pairs) / len(pairs))
            assert float(row[f"{method} angle IOV"]) == pytest.approx(sum(each) / 2, rel=1e-12)
        # Within one build the xyz re-measurements are bit-identical: IOV exactly 0, also for
        # the centre, radius and vertex count.
        for quantity in ("angle", "centre", "radius", "vertices"):
            assert float(row[f"xyz {quantity} IOV"]) == 0.0
        assert float(row["drag angle IOV"]) > 0
        assert float(row["drag centre IOV"]) > 0
        assert float(row["manual angle IOV"]) >= 0
        assert row["manual centre IOV"] == ""  # a goniometer table has no centres
    summary = table(report / "summary.csv")
    shape = {(r["Table"], r["Method"], r["Quantity"]) for r in summary}
    for method in ("manual", "drag", "xyz"):
        assert ("angle IOV, breaks of every method", method, "angle") in shape
        assert ("inter-observer IOV", method, "angle") in shape
    for method in ("drag", "xyz"):
        for quantity in ("angle", "vertices", "radius", "centre"):
            assert ("IOV, every break of the method", method, quantity) in shape
    means = {r["Method"]: float(r["Mean"]) for r in summary if r["Table"].startswith("angle IOV")}
    assert means["xyz"] == 0.0 < means["drag"] < means["manual"]
    tukey = table(report / "tukey.csv")
    assert {(r["Group 1"], r["Group 2"]) for r in tukey} == {
        ("manual", "drag"),
        ("manual", "xyz"),
        ("drag", "xyz"),
    }
    terms = [r["Term"] for r in table(report / "regression.csv") if r["Method"] == "drag"]
    assert terms == ["(Intercept)", "vertices IOV", "radius IOV", "centre IOV"]
    agreement = {r["method"]: r for r in table(report / "agreement.csv")}
    assert set(agreement) == {"manual", "drag", "xyz"}
    assert float(agreement["xyz"]["ICC(A,1)"]) > float(agreement["manual"]["ICC(A,1)"])
    assert len(table(report / "bland_altman.csv")) == 6  # 3 method pairs, 3 observer pairs


def test_report_html_is_self_contained_with_every_figure(study):
    report = study / "html"
    assert run(ROOT / "vg_batch.py", "--report", report, *sessions(study)).returncode == 0
    text = (report / "report.html").read_text(encoding="utf-8")
    prose = re.sub(r"data:image/png;base64,[A-Za-z0-9+/=]+", "", text)
    assert not re.search(r"https?:|//[a-z]|<script|<link|@import|url\(", prose, re.IGNORECASE)
    page = Page()
    page.feed(text)
    assert all(url.startswith("data:image/png;base64,") for url in page.urls)
    pngs = sorted((report / "figures").glob("*.png"))
    names = {p.stem for p in pngs}
    assert {
        "iov_histograms",
        "ci_plot",
        "regression_drag",
        "angles_by_method",
        "angles_by_mesh",
        "angles_by_type",
        "bland_altman_1",
    } <= names
    assert {p.stem for p in (report / "figures").glob("*.svg")} == names
    embedded = sorted(base64.b64decode(src.split(",", 1)[1]) for src in page.images)
    assert embedded == sorted(p.read_bytes() for p in pngs)
    assert all(png.startswith(b"\x89PNG\r\n\x1a\n") for png in embedded)
    for heading in ("Angle IOV by method", "Inter-observer agreement", "Bland–Altman agreement"):
        assert f"<h2>{heading}</h2>" in text


def test_bad_input_is_counted_and_named(study, tmp_path):
    first = study / "obs1_drag_1.csv"
    text = first.read_text(encoding="utf-8").splitlines()
    # a non-numeric angle in a copy of a session (a second observer's), a break in one session
    # only, a file without a Break # column, and the same session twice.
    header = next(csv.reader([text[0]]))
    angle = header.index("Angle")
    rows = [next(csv.reader([line])) for line in text[1:]]
    rows[0][angle] = "n/a"
    extra = list(rows[1])
    extra[header.index("Break #")] = "99"
    bad = tmp_path / "obs3_drag_1.csv"
    with open(bad, "w", encoding="utf-8", newline="") as handle:
        csv.writer(handle, lineterminator="\n").writerows([header, *rows, extra])
    columns = tmp_path / "obs3_drag_2.csv"
    columns.write_text("Mesh,Angle\nfragment_1,90\n", encoding="utf-8")
    twice = tmp_path / "copy_of_obs1_drag_1.csv"
    twice.write_bytes(first.read_bytes())
    report = tmp_path / "report"
    done = run(ROOT / "vg_batch.py", "--report", report, *sessions(study), bad, columns, twice)
    assert done.returncode == 1, done.stdout + done.stderr
    expected = [
        "obs3_drag_1.csv: row 2: Angle is not a number ('n/a')",
        "fragment_1 break 99: only in obs3_drag_1.csv; no IOV",
        "'obs3_drag_2.csv': left out, it has no Break # column",
        "copy_of_obs1_drag_1.csv: left out, its rows (numbers and dates) are those of "
        "obs1_drag_1.csv",
    ]
    html = (report / "report.html").read_text(encoding="utf-8")
    left_out = (report / "left_out.csv").read_text(encoding="utf-8")
    for line in expected:
        assert line in done.stderr
        assert line.replace("'", "&#x27;") in html
        assert line.split(": ", 1)[1].replace("'", "") in left_out.replace("'", "")
    # 16 x 8 rows and the 9 of obs3_drag_1.csv; its "n/a" row and its break 99 left out.
    assert "(17 sessions, 135 of 137 rows used," in done.stdout
    assert "vg_batch: left out (4):" in done.stderr


def test_report_refuses_an_output_that_is_an_input_and_measuring_options(study, tmp_path):
    victim = tmp_path / "breaks.csv"
    victim.write_bytes((study / "obs1_drag_1.csv").read_bytes())
    before = victim.read_bytes()
    done = run(ROOT / "vg_batch.py", "--report", tmp_path, victim)
    assert done.returncode == 2
    assert "is one of the sessions given; the report would overwrite it" in done.stderr
    assert victim.read_bytes() == before and not (tmp_path / "report.html").exists()
    done = run(ROOT / "vg_batch.py", "--report", tmp_path / "r", victim, "--out", "x.csv")
    assert done.returncode == 2 and "--report takes session CSVs only, not --out" in done.stderr
    done = run(ROOT / "vg_batch.py", "--report", tmp_path / "r")
    assert done.returncode == 2 and "needs the session CSVs after it" in done.stderr


def test_help_documents_the_report():
    text = run(ROOT / "vg_batch.py", "--help").stdout
    for needed in (
        "--report DIR CSV...",
        "--method M",
        "--observer O",
        "--compare A B",
        "REPORT.md",
    ):
        assert needed in text, needed
    done = run(ROOT / "vg_batch.py", "x.ply", "--at", "0", "0", "0", "--method", "drag")
    assert done.returncode == 2 and "are for --report DIR CSV" in done.stderr
