"""The second fault matrix of the batch (issues 24 and 25): no input overwritten, a bad row or a
failed picture never costs a good row, pictures of two meshes never share a file, resources
bounded before they are allocated, names as the user gave them. Run as a user runs it."""

from __future__ import annotations

import argparse
import dataclasses
import importlib
import math
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import bpy
import numpy as np
import pytest
from bpy_helpers import arguments, batch, mesh_object, outcome_of_check
from unprivileged import as_user

from vg_addon.formats import csvio, meshio
from vg_addon.method.edge_profile import MAX_STATIONS
from vg_addon.synthetic_meshes import wedge

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "vg_batch.py"
AT = ("--at", "0.05", "0", "0", "--radius", "0.3")
EDGE = ("--edge", "-0.4", "0", "0", "0.4", "0", "0", "--radius", "0.3")
SMALL_MAP = ("--render-size", "16", "16", "--render-samples", "1")


def ok(result, code=0) -> subprocess.CompletedProcess:
    assert result.returncode == code, result.stdout + result.stderr
    assert "Traceback" not in result.stderr, result.stderr
    return result


def write_wedge(path, angle=90.0, seed=3) -> Path:
    shape = wedge(angle, n=24, irregular=True, seed=seed)
    # Coordinates float32 holds exactly: Blender's mesh is the file's.
    points = shape.points.astype(np.float32).astype(np.float64)
    return meshio.write_ply(path, points, shape.triangles)


@pytest.fixture
def scan(tmp_path) -> Path:
    return write_wedge(tmp_path / "scan.ply")


# --------------------------------------------------------------------------- inputs kept


def test_an_edges_csv_is_never_overwritten_nor_taken_as_out(scan, tmp_path):
    ok(batch(scan, *EDGE, "--spacing", "0.2", "--out", tmp_path / "o.csv"))
    edges = tmp_path / "o_edges.csv"
    lines = edges.read_text().splitlines()
    edges.write_text(
        "\n".join([lines[0] + ",my column", lines[1] + ",keep me"]) + "\n", encoding="utf-8"
    )
    before = edges.read_bytes()
    # Its own OUT_edges.csv would be the input.
    result = ok(batch(scan, "--edges", edges, "--out", tmp_path / "o.csv"), 2)
    assert "is the edges CSV" in result.stderr and "nothing was read" in result.stderr
    result = ok(batch(scan, "--edges", edges, "--out", edges), 2)
    assert "--out" in result.stderr and "is the edges CSV" in result.stderr
    assert edges.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["o.csv", "o_edges.csv",
                                                          "o_scan_edge1.png", "scan.ply"]  # fmt: skip


def test_a_non_finite_edge_point_is_refused_before_anything_is_measured(scan, tmp_path):
    out = tmp_path / "o.csv"
    result = ok(batch(scan, *AT, "--edge", "nan", "0", "0", "0.4", "0", "0", "--spacing", "0.2",
                      "--out", out), 2)  # fmt: skip
    assert "finite" in result.stderr and not out.exists()
    ok(batch(scan, *EDGE, "--spacing", "0.2", "--out", tmp_path / "e.csv"))
    edges = tmp_path / "e_edges.csv"
    good = edges.read_text().splitlines()
    bad = good[1].replace("'-0.4 0.0 0.0", "'nan 0.0 0.0", 1)
    edges.write_text("\n".join([*good, bad]) + "\n", encoding="utf-8")
    result = ok(batch(scan, "--edges", edges, "--out", out), 2)
    assert "row 3: Points" in result.stderr and not out.exists()


@pytest.mark.parametrize("where", ["--spacing", "edges CSV"])
def test_a_spacing_making_too_many_stations_is_refused_naming_the_limit(scan, tmp_path, where):
    out = tmp_path / "o.csv"
    if where == "--spacing":
        result = batch(scan, *AT, *EDGE, "--spacing", "1e-9", "--out", out)
    else:
        ok(batch(scan, *EDGE, "--spacing", "0.2", "--out", tmp_path / "e.csv"))
        edges = tmp_path / "e_edges.csv"
        lines = edges.read_text().splitlines()
        header = lines[0].split(",")
        cells = lines[1].split(",")
        cells[header.index("Spacing")] = "1e-9"
        edges.write_text("\n".join([lines[0], ",".join(cells)]) + "\n", encoding="utf-8")
        result = batch(scan, "--edges", edges, "--out", out)
    ok(result, 2)
    assert f"{MAX_STATIONS:,}" in result.stderr and "stations" in result.stderr
    assert not out.exists()  # refused before measuring


def test_an_unclosed_quote_in_a_points_csv_stops_the_run_naming_its_line(scan, tmp_path):
    points = tmp_path / "points.csv"
    points.write_text('x,y,z,label\n0.05,0,0,"open\n0.1,0,0,b\n0.2,0,0,c\n0.3,0,0,d\n')
    out = tmp_path / "o.csv"
    result = ok(batch(scan, "--points", points, "--radius", "0.3", "--out", out), 2)
    assert "line 2 opens a quote" in result.stderr and not out.exists()


def test_negative_numbers_in_scientific_notation_are_numbers(scan, tmp_path):
    """-5e-2 (as the project's CSVs write small numbers) was read as an option: "--at: expected
    3 arguments". The oracle: the same run in plain notation."""
    rows = {}
    for name, x, ends in (("plain", "-0.05", ("-0.4", "0.4")), ("sci", "-5e-2", ("-4e-1", "4E-1"))):
        out = tmp_path / f"{name}.csv"
        ok(batch(scan, "--at", x, "0", "0", "--radius", "0.3", "--edge", ends[0], "0", "0",
                 ends[1], "0", "0", "--spacing", "0.2", "--out", out))  # fmt: skip
        rows[name] = [(r.requested, r.angle) for r in csvio.read_measurements_csv(out)]
    assert rows["sci"] == rows["plain"] and rows["sci"][0][0][0] == -0.05
    assert len(rows["sci"]) > 3  # the point and the edge's stations
    refused = batch(scan, "--at", "-inf", "0", "0", "--radius", "0.3", "--out", tmp_path / "i.csv")
    assert refused.returncode == 2 and "finite" in refused.stderr, refused.stderr


def test_paths_with_a_line_break_are_paths(scan, tmp_path):
    folder = tmp_path / "two\nlines"
    folder.mkdir()
    points = folder / "points.csv"
    points.write_text("x,y,z\n0.05,0,0\n", encoding="utf-8")
    ok(batch(scan, *EDGE, "--spacing", "0.2", "--out", folder / "e.csv"))
    out = tmp_path / "o.csv"
    ok(batch(scan, "--points", points, "--radius", "0.3", "--edges", folder / "e_edges.csv",
             "--out", out))  # fmt: skip
    rows = csvio.read_measurements_csv(out)
    assert len(rows) == 1 + sum(1 for r in rows if r.edge_number) and not rows[0].error


# --------------------------------------------------------------------------- names


def test_meshes_whose_file_names_collide_get_pictures_of_their_own(tmp_path):
    one = write_wedge(tmp_path / "bone 1.ply", 90.0, seed=3)
    two = write_wedge(tmp_path / "bone_1.ply", 60.0, seed=4)
    out = tmp_path / "o.csv"
    result = ok(batch(one, two, *AT, *EDGE, "--spacing", "0.2", "--sweep", "0.2", "0.3", "2",
                      "--render", tmp_path / "maps", *SMALL_MAP, "--out", out))  # fmt: skip
    assert "wrote 2 measurement map(s)" in result.stderr
    assert "'bone 1'" in result.stderr and "'bone_1'" in result.stderr  # said which name is which
    sheets = sorted(p.name for p in (tmp_path / "maps").glob("*_map.png"))
    assert len(sheets) == 2, sheets
    plots = sorted(p.name for p in tmp_path.glob("o_*_edge1.png"))
    assert len(plots) == 2, plots
    assert len(list((tmp_path / "o_sweep").glob("*.png"))) == 2


def test_a_file_name_that_is_not_utf8_costs_no_row(tmp_path):
    good = write_wedge(tmp_path / "good.ply")
    odd = os.fsdecode(bytes(tmp_path) + b"/caf\xe9.ply")
    write_wedge(odd, 60.0, seed=4)
    other = os.fsdecode(bytes(tmp_path) + b"/caf\xe8.ply")  # differs in the bad byte only
    write_wedge(other, 120.0, seed=5)
    out = tmp_path / "o.csv"
    ok(batch(good, odd, other, *AT, "--out", out))
    rows = csvio.read_measurements_csv(out)
    assert sorted(r.mesh_name for r in rows) == ["caf\\xe8", "caf\\xe9", "good"]
    angles = {r.mesh_name: r.angle for r in rows}
    assert abs(angles["good"] - 90) < 0.01 and abs(angles["caf\\xe9"] - 60) < 0.01
    assert abs(angles["caf\\xe8"] - 120) < 0.01
    # The CSV it wrote is read back on the same files: the rows find their meshes.
    again = tmp_path / "again.csv"
    ok(batch(good, odd, other, "--points", out, "--out", again))
    assert [r.angle for r in csvio.read_measurements_csv(again)] == [r.angle for r in rows]


@pytest.mark.parametrize("names", [(" lead", "trail "), ("both ", " both"), (" lead", "lead")])
def test_mesh_names_with_surrounding_spaces_round_trip(tmp_path, names):
    files = [write_wedge(tmp_path / f"{name}.ply", 90.0 - 30 * i, seed=3 + i)
             for i, name in enumerate(names)]  # fmt: skip
    out = tmp_path / "o.csv"
    ok(batch(*files, *AT, "--out", out))
    rows = csvio.read_measurements_csv(out)
    assert [r.mesh_name for r in rows] == list(names)
    again = tmp_path / "again.csv"
    ok(batch(*files, "--points", out, "--out", again))
    back = csvio.read_measurements_csv(again)
    assert [(r.mesh_name, r.angle) for r in back] == [(r.mesh_name, r.angle) for r in rows]


def test_rows_name_the_mesh_file_a_blend_already_has_an_object_of(vg, tmp_path):
    scan = write_wedge(tmp_path / "w90.ply")
    for name in ("w90", "other"):
        shape = wedge(70.0, n=12)
        mesh_object(name, shape.points, shape.triangles)
    blend = tmp_path / "study.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(blend), copy=True)
    out = tmp_path / "o.csv"
    ok(batch(blend, scan, "--object", "other", *AT, "--out", out))
    rows = csvio.read_measurements_csv(out)
    assert [r.mesh_name for r in rows] == ["other", "w90"]
    again = tmp_path / "again.csv"
    only = tmp_path / "only.csv"
    csvio.write_measurements_csv(only, [r for r in rows if r.mesh_name == "w90"])
    ok(batch(scan, "--points", only, "--out", again))
    assert csvio.read_measurements_csv(again)[0].angle == rows[1].angle


# --------------------------------------------------------------------------- pictures, disks


def test_a_plot_that_cannot_be_written_costs_no_row(scan, tmp_path):
    out = tmp_path / "o.csv"
    (tmp_path / "o_scan_edge1.png").mkdir()  # a folder where the profile plot goes
    (tmp_path / "o_sweep").mkdir()
    (tmp_path / "o_sweep" / "scan_1.png").mkdir()  # and where the sweep plot goes
    result = ok(batch(scan, *AT, *EDGE, "--spacing", "0.2", "--sweep", "0.2", "0.3", "2",
                      "--out", out), 2)  # fmt: skip
    rows = csvio.read_measurements_csv(out)
    assert rows and not any(r.error for r in rows), [r.error for r in rows]
    assert abs(rows[0].angle - 90.0) < 0.01 and any(r.edge_number for r in rows)
    assert "could not write" in result.stderr and "o_scan_edge1.png" in result.stderr
    assert "scan_1.png" in result.stderr
    assert csvio.read_edges_csv(tmp_path / "o_edges.csv")[0].n_stations > 1


@pytest.mark.skipif(os.name != "posix", reason="POSIX permissions")
def test_unprivileged_sweep_with_a_read_only_out_is_refused_like_without(vg, user_folder):
    out = user_folder / "o.csv"
    out.write_text("keep\n")
    out.chmod(0o444)
    outputs = importlib.import_module(f"{vg.__name__}.batch.outputs")
    for sweep in (None, [0.2, 0.3, 2.0]):
        kind, said = as_user(outcome_of_check, outputs, arguments(out=str(out), sweep=sweep))
        assert kind == "ok" and said.startswith("refused: --out") and "read-only" in said, said
    assert out.read_text() == "keep\n"


def test_the_out_folder_vanishing_mid_run_keeps_measuring_and_keeps_the_rows(vg, tmp_path):
    run_module = importlib.import_module(f"{vg.__name__}.batch.run")
    measure = importlib.import_module(f"{vg.__name__}.batch.measure")
    sources = importlib.import_module(f"{vg.__name__}.batch.sources")
    folder = tmp_path / "results"
    folder.mkdir()
    out = folder / "o.csv"
    args = argparse.Namespace(out=str(out), quiet=True, edge=[], edges_csv=None, sweep=None)
    said = []
    run = run_module.Run(args, [sources.MeshSource("a"), sources.MeshSource("b")], [], [0, 1])
    run.say = said.append
    run.write_csv()
    shutil.rmtree(folder)
    for mesh in (0, 1):
        row = csvio.MeasurementRow(mesh_name="ab"[mesh], angle=90.0 - mesh, x=0.0, y=0.0, z=0.0)
        run.last_write = -math.inf  # a periodic write is due
        run.add(measure.MeshResult(mesh=mesh, rows=[(mesh, row)], measured=1))
    assert sum("could not write the CSV" in text for text in said) == 1, said  # said once
    code = run.finish()
    assert code == 2
    recovered = [text for text in said if "the rows are in" in text]
    assert recovered, said
    path = Path(recovered[0].split("the rows are in ")[1].split(" ")[0].rstrip(".;:"))
    try:
        assert [r.angle for r in csvio.read_measurements_csv(path)] == [90.0, 89.0]
    finally:
        path.unlink(missing_ok=True)


def test_an_edge_summary_that_cannot_be_written_is_kept_and_said_as_such(vg, tmp_path, full_disk):
    run_module = importlib.import_module(f"{vg.__name__}.batch.run")
    measure = importlib.import_module(f"{vg.__name__}.batch.measure")
    sources = importlib.import_module(f"{vg.__name__}.batch.sources")
    out = tmp_path / "o.csv"
    (tmp_path / "o_edges.csv").symlink_to(full_disk / "o_edges.csv")  # its place: a full disk
    args = argparse.Namespace(out=str(out), quiet=True, edge=[EDGE], edges_csv=None, sweep=None)
    said = []
    run = run_module.Run(args, [sources.MeshSource("a")], [], [0])
    run.say = said.append
    rows = importlib.import_module(f"{vg.__name__}.vg_addon.formats.csvio")  # the run's classes
    station = rows.MeasurementRow(mesh_name="a", angle=91.5, x=0.0, y=0.0, z=0.0, edge_number=1)
    edge = rows.EdgeRow(mesh_name="a", edge_number=1, n_stations=1, mean=91.5)
    run.last_write = -math.inf  # a periodic write is due
    run.add(measure.MeshResult(mesh=0, station_rows=[station], edge_rows=[edge]))
    assert len(said) == 1 and "could not write the CSV" not in said[0], said
    assert "edge summary" in said[0] and "No space left" in said[0], said
    assert run.finish() == 2
    assert [r.angle for r in csvio.read_measurements_csv(out)] == [91.5]
    kept = [text for text in said if "the edge summary is in" in text]
    assert len(kept) == 1 and "could not write the CSV" not in kept[0], said
    path = Path(kept[0].split("the edge summary is in ")[1].split(" ")[0])
    try:
        assert [row.mean for row in csvio.read_edges_csv(path)] == [91.5]
    finally:
        path.unlink(missing_ok=True)


@pytest.fixture
def full_disk(tmp_path):
    """A small tmpfs, mounted for the test and filled up: every write into it fails with "No
    space left on device" (root only; unmounted afterwards)."""
    if os.geteuid() != 0:
        pytest.skip("mounting a tmpfs needs root")
    folder = tmp_path / "full"
    folder.mkdir()
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=256k", "tmpfs", str(folder)],
                             capture_output=True, text=True, check=False)  # fmt: skip
    if mounted.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs: {mounted.stderr.strip()}")
    try:
        (folder / "old.blend").write_bytes(b"BLENDER-v300 an earlier save")
        # Unbuffered: the write that fills the disk raises at once, and nothing is left for
        # close() to flush (Python 3.11 raises "No space left" again there).
        with open(folder / "filler", "wb", buffering=0) as handle:
            try:
                while True:
                    handle.write(b"\0" * 4096)
            except OSError:
                pass
        yield folder
    finally:
        subprocess.run(["umount", str(folder)], check=False)


def test_save_blend_onto_a_full_disk_keeps_the_earlier_file_and_says_why(scan, tmp_path, full_disk):
    out = tmp_path / "o.csv"
    saved = full_disk / "old.blend"
    filler = full_disk / "filler"
    os.truncate(filler, filler.stat().st_size - 16384)  # room for the start of a .blend only
    result = ok(batch(scan, *AT, "--out", out, "--save-blend", saved), 2)
    assert "could not write the .blend" in result.stderr and "No space left" in result.stderr
    assert f"wrote {saved}" not in result.stderr
    assert saved.read_bytes() == b"BLENDER-v300 an earlier save"
    assert sorted(p.name for p in full_disk.iterdir()) == ["filler", "old.blend"]
    assert abs(csvio.read_measurements_csv(out)[0].angle - 90.0) < 0.01


def test_render_onto_a_full_disk_says_no_space_left(scan, tmp_path, full_disk):
    out = tmp_path / "o.csv"
    result = ok(batch(scan, *AT, "--out", out, "--render", full_disk, *SMALL_MAP), 2)
    assert "could not write the render of scan" in result.stderr
    assert "No space left on device" in result.stderr
    assert abs(csvio.read_measurements_csv(out)[0].angle - 90.0) < 0.01


@pytest.mark.parametrize(
    "option, said",
    [
        (("--render-size", "60000", "60000"), "8,192"),
        (("--render-samples", "100000"), "4,096"),
        (("--render-edge-ends", "-1"), "--render-edge-ends must be 0 or more"),
    ],
)
def test_the_map_size_and_samples_are_bounded_before_anything_renders(scan, tmp_path, option,
                                                                      said):  # fmt: skip
    out = tmp_path / "o.csv"
    result = ok(batch(scan, *AT, "--out", out, "--render", tmp_path / "maps", *option), 2)
    assert said in result.stderr and not out.exists()


@pytest.mark.parametrize("sweep", [("0.2", "0.3", "inf"), ("0.2", "nan", "3")])
def test_a_sweep_with_a_value_that_is_not_finite_is_refused_clearly(tmp_path, sweep):
    mesh = write_wedge(tmp_path / "w.ply")
    result = batch(mesh, *AT, "--sweep", *sweep, "--out", tmp_path / "o.csv")
    assert result.returncode == 2, result.stderr
    assert "finite" in result.stderr and "Traceback" not in result.stderr
    assert not (tmp_path / "o.csv").exists()


# Runs the script with each flush to disk taking ``sys.argv[1]`` seconds longer, as on a busy or
# slow disk (a CI machine's, where this was seen).
SLOW_DISK = """
import os, runpy, sys, time
delay, flush = float(sys.argv[1]), os.fsync
os.fsync = lambda fd: (time.sleep(delay), flush(fd))[1]
sys.argv = sys.argv[2:]
runpy.run_path(sys.argv[0], run_name="__main__")
"""


@pytest.mark.parametrize(
    ("flush_delay", "unmatched"),
    [(0.0, False), (1.5, False), (1.5, True)],
    ids=["disk", "slow disk", "slow disk, a row for no mesh"],
)
def test_a_run_killed_while_its_map_renders_keeps_the_meshs_rows(tmp_path, flush_delay, unmatched):
    """Rows are written before pictures: SIGKILL the run as soon as a map has begun (its hidden
    folder appears in the render folder), and the CSV on disk holds that mesh's rows. On a slow
    disk the header's write once made the rows' write look too dear, so they were not written
    (also where the header's write holds a refused row: a --points row naming no mesh given)."""
    mesh = write_wedge(tmp_path / "w.ply")
    maps, out = tmp_path / "maps", tmp_path / "o.csv"
    where = list(AT)
    if unmatched:
        points = tmp_path / "points.csv"
        points.write_text("Mesh Name,x,y,z,Radius\nelsewhere,0.05,0,0,0.3\nw,0.05,0,0,0.3\n")
        where = ["--points", str(points)]
    process = subprocess.Popen(
        [sys.executable, "-c", SLOW_DISK, str(flush_delay), str(SCRIPT), str(mesh), *where,
         "--render", str(maps), "--render-size", "1200", "900", "--render-samples", "64",
         "--out", str(out)],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
    )  # fmt: skip
    try:
        deadline = time.monotonic() + 300
        while not list(maps.glob(".vg-map-*")) and process.poll() is None:
            assert time.monotonic() < deadline, "the map never began"
            time.sleep(0.02)
        assert process.poll() is None, "the run ended before it could be stopped mid-map"
        process.kill()
    finally:
        process.wait()
    rows = csvio.read_measurements_csv(out)
    measured = [row for row in rows if row.angle is not None]
    assert len(measured) == 1 and abs(measured[0].angle - 90.0) < 0.01
    assert len(rows) == 1 + unmatched
    assert not list(maps.glob("*.png"))  # no picture of the stopped map was kept in place


def test_a_row_of_another_object_is_not_taken_by_a_blend_objects_mesh_name(vg, tmp_path):
    """An object keeps its mesh's name when renamed: 'bone_left' has the mesh 'bone', and
    another object of the .blend is called 'bone'. With only 'bone_left' given, a row of 'bone'
    was once measured on 'bone_left' (its 100° read as 60°), as Blender's import once did.
    Oracle: the wedges' true angles."""
    bpy.ops.wm.read_homefile(use_empty=True)
    for name, angle in (("bone", 100.0), ("bone_left", 60.0)):
        shape = wedge(angle, n=30)
        mesh_object(name, shape.points, shape.triangles)
    bpy.data.objects["bone"].data.name = "bone_mesh"
    bpy.data.objects["bone_left"].data.name = "bone"
    source = tmp_path / "study.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(source))
    rows = tmp_path / "rows.csv"
    rows.write_text("Mesh Name,x,y,z,Radius\nbone,0.05,0,0,0.3\nbone_left,0.05,0,0,0.3\n")
    out = tmp_path / "out.csv"
    ok(batch(source, "--object", "bone_left", "--points", rows, "--out", out), 1)
    refused, measured = csvio.read_measurements_csv(out)
    assert refused.angle is None
    assert "names mesh 'bone', which is not among the meshes given" in refused.error
    assert (measured.mesh_name, round(measured.angle, 2)) == ("bone_left", 60.0)
    ok(batch(source, "--object", "bone_left", "--object", "bone", "--points", rows, "--out", out))
    assert sorted((r.mesh_name, round(r.angle, 2)) for r in csvio.read_measurements_csv(out)) == [
        ("bone", 100.0),
        ("bone_left", 60.0),
    ]


def test_a_spacing_for_an_edge_summarys_rows_is_refused_naming_why(scan, tmp_path):
    """Each row of an edge summary keeps its own Spacing: --spacing with --edges SUMMARY did
    nothing, silently (before). With .pp files it is their spacing, and it is used."""
    first = tmp_path / "first.csv"
    ok(batch(scan, *EDGE, "--spacing", "0.2", "--out", first))
    summary = csvio.edges_path_for(first)
    again = batch(scan, "--edges", summary, "--spacing", "0.1", "--out", tmp_path / "again.csv")
    assert again.returncode == 2 and "keeps its own Spacing and Radius" in again.stderr
    assert not (tmp_path / "again.csv").exists()
    replay = tmp_path / "replay.csv"
    ok(batch(scan, "--edges", summary, "--out", replay))
    assert [r.angle for r in csvio.read_measurements_csv(replay)] == [
        r.angle for r in csvio.read_measurements_csv(first)
    ]


def test_an_edge_summary_replayed_says_whether_its_figures_came_back(scan, tmp_path):
    """A replay of --edges CSV said nothing of the file's figures (before), so an edge that came
    back with other stations passed unnoticed. The oracle: the file's own cells, edited."""
    first = tmp_path / "first.csv"
    ok(batch(scan, *EDGE, "--spacing", "0.2", "--out", first))
    (row,) = csvio.read_edges_csv(csvio.edges_path_for(first))
    wider = tmp_path / "wider.csv"  # the same points at another radius: another edge
    ok(batch(scan, *EDGE[:-1], "0.4", "--spacing", "0.2", "--out", wider))
    (other,) = csvio.read_edges_csv(csvio.edges_path_for(wider))
    assert other.points == row.points and other.mean != row.mean
    both = tmp_path / "both_edges.csv"
    csvio.write_edges_csv(both, [row, other])
    same = ok(batch(scan, "--edges", both, "--out", tmp_path / "same.csv"))
    assert (
        "re-measured both_edges.csv: all 2 edges' stations, mean, min, max and pooled angle "
        "equal the file's exactly"
    ) in same.stderr
    # Points typed by hand (not as the run writes them), the mean edited; a row whose error was
    # cleared (no figures to compare); a Stale row.
    edited = tmp_path / "edited_edges.csv"
    typed = dataclasses.replace(row, points="-0.4 0 0;0.4 0 0", mean=row.mean + 0.5)
    cleared = dataclasses.replace(other, n_stations=None, mean=None, std=None, min=None,
                                  max=None, pooled_angle=None)  # fmt: skip
    csvio.write_edges_csv(edited, [typed, cleared, dataclasses.replace(row, stale=True)])
    moved = ok(batch(scan, "--edges", edited, "--out", tmp_path / "moved.csv"))
    assert (
        f"re-measured edited_edges.csv: 1 of 1 edges differ from the file's figures (row 2: "
        f"mean {row.mean + 0.5:.4f}° → {row.mean:.4f}°)"
    ) in moved.stderr
    assert "; 1 row(s) without figures in the file (not measured when it was written)" in (
        moved.stderr
    )
    assert "; 1 edge(s) marked Stale (measured before the mesh was edited) not compared" in (
        moved.stderr
    )
    # An edge that fails on the replay (a radius too small for a patch) is counted as such.
    failing = tmp_path / "failing_edges.csv"
    csvio.write_edges_csv(failing, [row, dataclasses.replace(other, radius=1e-6)])
    failed = ok(batch(scan, "--edges", failing, "--out", tmp_path / "failed.csv"), code=1)
    assert (
        "re-measured failing_edges.csv: its edge's stations, mean, min, max and pooled angle "
        "equal the file's exactly; 1 edge(s) could not be measured again (see their error)"
    ) in failed.stderr


def test_a_radius_for_an_edge_summarys_rows_is_refused_unless_points_take_it(scan, tmp_path):
    """Each row of an edge summary keeps its own Radius: --radius with only --edges SUMMARY did
    nothing, silently (before). Beside --at it is the points' radius, and it is used."""
    first = tmp_path / "first.csv"
    ok(batch(scan, *EDGE, "--spacing", "0.2", "--out", first))
    summary = csvio.edges_path_for(first)
    again = batch(scan, "--edges", summary, "--radius", "0.2", "--out", tmp_path / "again.csv")
    assert again.returncode == 2 and "keeps its own Spacing and Radius" in again.stderr
    assert "--radius is for" in again.stderr
    assert not (tmp_path / "again.csv").exists()
    both = tmp_path / "both.csv"
    ok(batch(scan, "--edges", summary, "--at", "0.05", "0", "0", "--radius", "0.2", "--out", both))
    rows = csvio.read_measurements_csv(both)
    edge_rows = csvio.read_measurements_csv(first)
    assert {r.radius for r in rows} == {0.2, edge_rows[0].radius}  # the point's and the edge's


def test_a_replay_says_which_failed_rows_of_its_file_it_passed_over(scan, tmp_path):
    """A run's failed row (no x, y, z) is passed over by a replay of its CSV, as documented; the
    replay said nothing of it ("all 2 angles equal the file's exactly", exit 0), so a point
    dropped out of the study without a word. The summary now names the row and what to do."""
    points = tmp_path / "points.csv"
    points.write_text("x,y,z,radius\n0,0,0,0.3\n0,0,0,1e-9\n0.2,0,0,0.3\n", encoding="utf-8")
    first = tmp_path / "first.csv"
    ok(batch(scan, "--points", points, "--out", first), code=1)  # the tiny radius fails
    rows = csvio.read_measurements_csv(first)
    assert [bool(r.error) for r in rows] == [False, True, False]
    replay = ok(batch(scan, "--points", first, "--out", tmp_path / "replay.csv"))
    assert (
        "passed over 1 row(s) of first.csv whose error says they were not measured (row 3): to "
        "measure one again, copy a point's Requested x, y, z into its x, y, z and clear its error"
    ) in replay.stderr
    assert len(csvio.read_measurements_csv(tmp_path / "replay.csv")) == 2


def test_an_edge_summary_row_with_settings_out_of_range_is_refused_before_the_run(scan, tmp_path):
    """An edited edge summary's row with a Patch Mode, SegParam, Radius or Spacing that cannot
    measure was traced and failed at every station, as error rows (before); now the run is
    refused before any mesh is read, naming each row, as for a row without a Spacing."""
    first = tmp_path / "first.csv"
    ok(batch(scan, *EDGE, "--spacing", "0.2", "--out", first))
    (row,) = csvio.read_edges_csv(csvio.edges_path_for(first))
    edited = tmp_path / "edited_edges.csv"
    bad = [
        dataclasses.replace(row, patch="spherical"),
        dataclasses.replace(row, lam=-1.0),
        dataclasses.replace(row, radius=0.0),
        dataclasses.replace(row, spacing=-0.2),
    ]
    csvio.write_edges_csv(edited, [row, *bad])
    out = tmp_path / "out.csv"
    result = ok(batch(scan, "--edges", edited, "--out", out), code=2)
    assert "4 edge row(s) cannot be measured" in result.stderr
    for number, words in zip(
        (3, 4, 5, 6),
        (
            "Unknown patch mode 'spherical'",
            "λ (SegParam) must be",
            "radius must be",
            "Spacing must",
        ),
        strict=True,
    ):
        (line,) = [line for line in result.stderr.splitlines() if f"row {number}: " in line]
        assert words in line
    assert not out.exists() and not csvio.edges_path_for(out).exists()


@pytest.mark.parametrize(
    ("arguments", "words"),
    [
        (("--at", 0, 0, 0, "--radius", 1, "--spacing", 1), "--spacing D is the distance between"),
        (("--at", 0, 0, 0, "--radius", 1, "--ignore-mesh-names"), "--ignore-mesh-names is for"),
        (
            ("--edge", 0, 0, 0, 1, 0, 0, "--spacing", 1, "--radius", 1, "--ignore-mesh-names"),
            "--ignore-mesh-names is for",
        ),
        (("--at", 0, 0, 0, "--radius", 1, "--save-blend", ""), "--save-blend needs a path"),
        (("--at", 0, 0, 0, "--radius", 1, "--render", " "), "--render needs a path"),
    ],
)
def test_an_option_that_would_do_nothing_is_refused(tmp_path, arguments, words):
    # Before: each was ignored without a word (no .blend, no map, the spacing unused) and the
    # run exited 0. The mesh does not exist: the refusal comes before anything is read.
    out = tmp_path / "out.csv"
    result = ok(batch(tmp_path / "none.ply", *arguments, "--out", out), 2)
    assert words in result.stderr
    assert not out.exists()


def test_a_mesh_given_twice_is_named_as_given_twice(tmp_path):
    shape = wedge(90.0, n=10)
    mesh = tmp_path / "w.ply"
    meshio.write_ply(mesh, shape.points, shape.triangles)
    out = tmp_path / "out.csv"
    result = ok(batch(mesh, tmp_path, "--at", 0, 0, 0, "--radius", 0.5, "--out", out), 2)
    assert "1 mesh file(s) given twice, as a file or in a folder given; give each once:" in (
        result.stderr
    )
    assert "share a name" not in result.stderr and not out.exists()


@pytest.mark.parametrize(
    ("arguments", "named"),
    [
        (("--save-blend", "x.blend"), "--save-blend"),
        (("--radius", "2", "--lambda", "1"), "--radius, --lambda"),
        (("--render", "maps", "--jobs", "2"), "--render, --jobs"),
        (("--rule", "paper", "--stability"), "--rule, --stability"),
    ],
)
def test_the_demo_refuses_every_option_it_would_ignore(tmp_path, arguments, named):
    # The demo sets up its own run: before, these were ignored and it exited 0 (no x.blend).
    result = ok(batch("--demo", "--out-dir", tmp_path / "demo", *arguments), 2)
    assert f"--demo takes no {named} (only --out-dir and --quiet)" in result.stderr
    assert not (tmp_path / "demo").exists()


# --------------------------------------------------------------------------- outputs together


def test_an_edge_row_naming_no_mesh_among_several_is_refused(tmp_path):
    """An edge summary row with a blank Mesh Name, replayed on two meshes, is refused as a
    points row is (before: traced on both, and the replay report compared the file's row with
    the other mesh's edge); so is --ignore-mesh-names with several meshes, for an edges CSV
    and for a .pp file."""
    a, b = write_wedge(tmp_path / "a.ply", 100.0), write_wedge(tmp_path / "b.ply", 60.0, seed=4)
    ok(batch(a, b, *EDGE, "--spacing", "0.2", "--out", tmp_path / "e.csv"))
    lines = (tmp_path / "e_edges.csv").read_text().splitlines()
    header = lines[0].split(",")
    cells = lines[1].split(",")
    cells[header.index("Mesh Name")] = ""
    blank = tmp_path / "blank_edges.csv"
    blank.write_text("\n".join([lines[0], ",".join(cells)]) + "\n")
    result = ok(batch(a, b, "--edges", blank, "--out", tmp_path / "r.csv"), code=2)
    assert "row 2 names no mesh, and several are given" in result.stderr
    result = ok(
        batch(a, b, "--edges", tmp_path / "e_edges.csv", "--ignore-mesh-names", "--out",
              tmp_path / "r.csv"),
        code=2,
    )  # fmt: skip
    assert "--ignore-mesh-names needs a single mesh" in result.stderr
    # A .pp file likewise (before: the option was passed over without a word, the file's name
    # choosing the mesh).
    picked = tmp_path / "a_1.pp"
    picked.write_text(
        '<PickedPoints>\n<point x="-0.4" y="0" z="0" name="1" active="1"/>\n'
        '<point x="0.4" y="0" z="0" name="2" active="1"/>\n</PickedPoints>\n',
        encoding="utf-8",
    )
    result = ok(
        batch(a, b, "--edges", picked, "--spacing", "0.2", "--radius", "0.3",
              "--ignore-mesh-names", "--out", tmp_path / "r.csv"),
        code=2,
    )  # fmt: skip
    assert "--ignore-mesh-names needs a single mesh" in result.stderr
    assert not (tmp_path / "r.csv").exists()
    ok(batch(a, "--edges", blank, "--out", tmp_path / "one.csv"))  # one mesh: measured on it


def test_a_run_without_a_sweep_empties_an_earlier_sweep_beside_its_csv(scan, tmp_path):
    """Before, ``<out>_sweep.csv`` of an earlier run stayed beside the new CSV, pairing it with
    the sweep of other points; a file of that name that is not a sweep is left alone."""
    out = tmp_path / "o.csv"
    ok(batch(scan, *AT, "--sweep", "0.2", "0.4", "3", "--out", out))
    sweep = tmp_path / "o_sweep.csv"
    assert len(sweep.read_text().splitlines()) == 4
    result = ok(batch(scan, *AT, "--out", out))
    assert sweep.read_text() == csvio.format_sweep_rows([])
    assert f"emptied {sweep} to its header" in result.stdout + result.stderr
    sweep.write_text("x,y,z\n1,2,3\n")  # the user's own file of that name
    ok(batch(scan, *AT, "--out", out))
    assert sweep.read_text() == "x,y,z\n1,2,3\n"


def test_every_output_beside_a_linked_out_is_beside_the_link(scan, tmp_path):
    """``--out`` a symbolic link into another folder: the edge summary, the edge plots and the
    sweep all go beside the link, named after it (before: three places under two names)."""
    (tmp_path / "sub").mkdir()
    link = tmp_path / "lk.csv"
    link.symlink_to(tmp_path / "sub" / "real.csv")
    ok(batch(scan, *EDGE, "--spacing", "0.2", "--sweep", "0.2", "0.4", "3", "--out", link))
    assert (tmp_path / "sub" / "real.csv").is_file()  # the CSV through the link
    beside = {p.name for p in tmp_path.iterdir()}
    assert {"lk_edges.csv", "lk_sweep.csv", "lk_sweep", "lk_scan_edge1.png"} <= beside
    assert sorted(p.name for p in (tmp_path / "sub").iterdir()) == ["real.csv"]
