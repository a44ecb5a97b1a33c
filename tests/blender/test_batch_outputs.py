"""Where a batch run writes: inputs are never outputs, '-' is standard output, places that
cannot be written are refused before anything is read or written, and an output that fails late
(a .blend, a picture) makes the exit status say so. Run as a user runs it, and the checks that
depend on permissions also as an unprivileged user."""

from __future__ import annotations

import importlib
import os
import signal
import subprocess
import sys
from pathlib import Path

import bpy
import pytest
from bpy_helpers import BATCH_SCRIPT, arguments, batch, outcome_of_check
from unprivileged import as_user

from vg_addon.formats import csvio, meshio
from vg_addon.synthetic_meshes import wedge

AT = ("--at", "0.05", "0", "0", "--radius", "0.3")


def ocio_set() -> dict:
    """The OCIO variable set, as in many studios: Blender then logs a line on start-up."""
    config = Path(bpy.utils.resource_path("LOCAL")) / "datafiles/colormanagement/config.ocio"
    return {"OCIO": str(config)}


@pytest.fixture
def scan(tmp_path) -> Path:
    shape = wedge(90.0, n=24, irregular=True, seed=3)
    return meshio.write_ply(tmp_path / "scan.ply", shape.points, shape.triangles)


def refused(result, *phrases):
    assert result.returncode == 2, result.stdout + result.stderr
    assert "Traceback" not in result.stderr
    for phrase in phrases:
        assert phrase in result.stderr, result.stderr


def test_out_onto_the_input_mesh_is_refused_and_the_scan_kept(scan):
    before = scan.read_bytes()
    refused(batch(scan, *AT, "--out", scan), f"--out {scan} is the mesh file", "nothing was read")
    assert scan.read_bytes() == before


def test_out_onto_a_mesh_found_in_a_given_folder_or_through_a_link_is_refused(scan, tmp_path):
    before = scan.read_bytes()
    link = tmp_path / "link.csv"
    link.symlink_to(scan)
    hard = tmp_path / "hard.csv"
    os.link(scan, hard)
    for out in (link, hard):
        refused(batch(tmp_path / "scan.ply", *AT, "--out", out), "is the mesh file")
        refused(batch(tmp_path, *AT, "--out", out), "is the mesh file")
    assert scan.read_bytes() == before and link.is_symlink()


def test_out_onto_the_points_csv_is_refused_and_its_columns_kept(scan, tmp_path):
    points = tmp_path / "points.csv"
    points.write_text("x,y,z,site,notes\n0.05,0,0,A,keep me\n")
    before = points.read_bytes()
    refused(batch(scan, "--points", points, "--radius", "0.3", "--out", points),
            "is the points CSV")  # fmt: skip
    assert points.read_bytes() == before


def test_a_points_csv_named_like_outs_edge_summary_is_left_alone(scan, tmp_path):
    # A first version of the export emptied any site_edges.csv beside --out site.csv, this
    # input too, before anything was measured.
    points = tmp_path / "site_edges.csv"
    points.write_text("x,y,z,site,notes\n0.05,0,0,A,keep me\n")
    before = points.read_bytes()
    out = tmp_path / "site.csv"
    result = batch(scan, "--points", points, "--radius", "0.3", "--out", out)
    assert result.returncode == 0, result.stderr
    assert points.read_bytes() == before
    assert len(csvio.read_measurements_csv(out)) == 1


def test_an_earlier_edge_summary_given_as_points_is_refused_not_emptied(scan, tmp_path):
    out = tmp_path / "site.csv"
    summary = tmp_path / "site_edges.csv"
    summary.write_text(csvio.format_edges_csv([csvio.EdgeRow(mesh_name="scan", edge_number=1)]))
    before = summary.read_bytes()
    refused(batch(scan, "--points", summary, "--radius", "0.3", "--out", out),
            "--out's edge summary", "would destroy an input")  # fmt: skip
    assert summary.read_bytes() == before


def test_save_blend_onto_an_input_or_onto_the_out_csv_is_refused(scan, tmp_path):
    before = scan.read_bytes()
    refused(batch(scan, *AT, "--out", tmp_path / "o.csv", "--save-blend", scan),
            f"--save-blend {scan} is the mesh file")  # fmt: skip
    assert scan.read_bytes() == before
    same = tmp_path / "both"
    refused(batch(scan, *AT, "--out", same, "--save-blend", same), "are the same file")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scan.ply"]


def test_out_dash_writes_the_csv_to_standard_output_once(scan, tmp_path):
    result = batch(scan, *AT, "--out", "-", cwd=tmp_path, env=ocio_set())
    assert result.returncode == 0, result.stderr
    rows = csvio.parse_measurements_csv(result.stdout)
    assert len(rows) == 1 and abs(rows[0].angle - 90.0) < 0.01
    assert result.stdout.count("Mesh Name,") == 1
    assert "wrote the CSV to standard output" in result.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scan.ply"]  # no file named "-"


def test_out_dash_with_jobs(scan, tmp_path):
    other = wedge(60.0, n=24, irregular=True, seed=4)
    meshio.write_ply(tmp_path / "other.ply", other.points, other.triangles)
    result = batch(scan, tmp_path / "other.ply", *AT, "--jobs", "2", "--out", "-", cwd=tmp_path,
                   env=ocio_set())  # fmt: skip
    assert result.returncode == 0, result.stderr
    rows = csvio.parse_measurements_csv(result.stdout)
    assert [row.mesh_name for row in rows] == ["scan", "other"]


def test_save_blend_to_a_folder_is_refused_before_measuring(scan, tmp_path):
    out = tmp_path / "o.csv"
    refused(batch(scan, *AT, "--out", out, "--save-blend", tmp_path),
            "--save-blend", "is a folder: give a file name")  # fmt: skip
    assert not out.exists()


def test_render_to_a_file_is_refused_before_measuring(scan, tmp_path):
    out, picture = tmp_path / "o.csv", tmp_path / "picture.png"
    picture.write_bytes(b"not a folder")
    refused(batch(scan, *AT, "--out", out, "--render", picture), "--render takes a folder")
    assert not out.exists() and picture.read_bytes() == b"not a folder"


def test_out_into_a_folder_that_is_a_file_is_refused(scan, tmp_path):
    refused(batch(scan, *AT, "--out", tmp_path / "scan.ply" / "x.csv"), "is a file, not a folder")


def test_a_render_that_fails_late_gives_a_nonzero_exit_and_keeps_the_csv(scan, tmp_path):
    renders, out = tmp_path / "renders", tmp_path / "o.csv"
    # The map cannot write its contact sheet there.
    (renders / "scan_map.png").mkdir(parents=True)
    result = batch(scan, *AT, "--out", out, "--render", renders, "--render-size", 16, 16,
                   "--render-samples", 1)  # fmt: skip
    assert result.returncode == 2, result.stderr
    assert "could not write the render of scan" in result.stderr
    assert "Traceback" not in result.stderr
    assert abs(csvio.read_measurements_csv(out)[0].angle - 90.0) < 0.01


def test_a_blend_that_fails_late_gives_a_nonzero_exit_and_keeps_the_csv(scan, tmp_path):
    saved, out = tmp_path / "saved.blend", tmp_path / "o.csv"
    # The batch saves to ".saved.saving.blend" first, for which Blender writes "<name>@" and
    # renames it: a folder there makes the save fail late.
    blocker = tmp_path / ".saved.saving.blend@"
    blocker.mkdir()
    (blocker / "keep").write_text("x")
    result = batch(scan, *AT, "--out", out, "--save-blend", saved)
    assert result.returncode == 2, result.stderr
    assert "could not write the .blend" in result.stderr and "Traceback" not in result.stderr
    assert abs(csvio.read_measurements_csv(out)[0].angle - 90.0) < 0.01
    assert (blocker / "keep").read_text() == "x"


# --------------------------------------------------------------------------- as a normal user


@pytest.mark.skipif(os.name != "posix", reason="POSIX permissions")
def test_unprivileged_outputs_in_a_read_only_folder_are_refused_early(vg, user_folder):
    read_only = user_folder / "ro"
    read_only.mkdir()
    (read_only / "old.blend").write_bytes(b"BLENDER")
    (read_only / "old.blend").chmod(0o444)
    read_only.chmod(0o555)
    cases = {
        "out": arguments(out=str(read_only / "sub" / "x.csv")),
        "out here": arguments(out=str(read_only / "x.csv")),
        "blend": arguments(save_blend=str(read_only / "s.blend")),
        "old blend": arguments(save_blend=str(read_only / "old.blend")),
        "render": arguments(render=str(read_only / "renders")),
        "fine": arguments(out=str(user_folder / "x.csv"), render=str(user_folder / "r")),
    }
    # Imported here: the unprivileged child cannot read the installed extension's files.
    outputs = importlib.import_module(f"{vg.__name__}.batch.outputs")
    results = {name: as_user(outcome_of_check, outputs, args) for name, args in cases.items()}
    assert all(kind == "ok" for kind, _ in results.values()), results
    said = {name: text for name, (_, text) in results.items()}
    assert said["out"].startswith("refused: --out") and "no permission to create" in said["out"]
    assert "no permission to write into" in said["out here"]
    assert "no permission to write into" in said["blend"]
    assert "is read-only; it is left as it is" in said["old blend"]
    assert "no permission to create" in said["render"]
    assert said["fine"] == "accepted"
    assert sorted(p.name for p in read_only.iterdir()) == ["old.blend"]


@pytest.mark.parametrize("cell", ["2147483648", "abc", "1.5"])
def test_a_break_number_blender_cannot_store_refuses_the_points_csv(scan, tmp_path, cell):
    points = tmp_path / "points.csv"
    points.write_text(f"x,y,z,Break #\n0.05,0,0,1\n0.1,0,0,{cell}\n")
    out = tmp_path / "o.csv"
    refused(batch(scan, "--points", points, "--radius", "0.3", "--out", out),
            f"row 3: Break # must be a whole number from 1 to 2147483647 (got '{cell}')")  # fmt: skip
    assert not out.exists()


def test_edges_need_a_file_out_not_standard_output_or_a_stream(scan, tmp_path):
    """The edge summary and the plots are written beside --out: with standard output or a pipe
    as --out the run is refused before anything is read (before: "-" wrote -_edges.csv and
    -_scan_edge1.png into the current folder, and a pipe failed at the end, blaming the CSV)."""
    edge = ("--edge", "-0.4", "0", "0", "0.4", "0", "0", "--spacing", "0.2", "--radius", "0.3")
    for option in (edge, ("--find-edges", "--spacing", "0.2", "--radius", "0.3")):
        refused(batch(scan, *option, "--out", "-", cwd=tmp_path), f"{option[0]} writes the edge summary",
                "must be a file name, not standard output or a stream")  # fmt: skip
        piped = subprocess.run(  # --out /dev/stdout into a pipe: a stream
            [sys.executable, str(BATCH_SCRIPT), str(scan), *option, "--out", "/dev/stdout"],
            capture_output=True, text=True, cwd=tmp_path, check=False,
        )  # fmt: skip
        refused(piped, "must be a file name, not standard output or a stream")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scan.ply"]


def test_sweep_outputs_are_checked_like_the_others(scan, tmp_path):
    sweep = ("--sweep", "0.2", "0.4", "3")
    refused(
        batch(scan, *AT, *sweep, "--out", "-", cwd=tmp_path), "--sweep writes", "must be a file"
    )
    # <out>_sweep.csv would be the input scan: refused before anything is written.
    victim = tmp_path / "o_sweep.csv"
    victim.write_text("x,y,z\n0.05,0,0\n")
    refused(batch(scan, "--points", victim, "--radius", "0.3", *sweep, "--out", tmp_path / "o.csv"),
            "--sweep's CSV", "is the points CSV")  # fmt: skip
    assert victim.read_text() == "x,y,z\n0.05,0,0\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["o_sweep.csv", "scan.ply"]


def test_an_earlier_sweep_given_as_points_is_refused_not_emptied(scan, tmp_path):
    """A run without --sweep empties an earlier <out>_sweep.csv beside --out: where that file is
    the points CSV (a sweep's rows have x, y and z), the run is refused and the file kept."""
    out = tmp_path / "site.csv"
    made = batch(scan, *AT, "--sweep", "0.2", "0.4", "3", "--out", out)
    assert made.returncode == 0, made.stderr
    sweep = tmp_path / "site_sweep.csv"
    before = sweep.read_bytes()
    assert before.count(b"\n") == 4  # the header and three radii
    refused(batch(scan, "--points", sweep, "--radius", "0.3", "--out", out),
            "--out's earlier sweep CSV", "is the points CSV", "would destroy an input")  # fmt: skip
    assert sweep.read_bytes() == before
    # Given under another --out, the sweep's points are measured and the file is left alone.
    result = batch(scan, "--points", sweep, "--radius", "0.3", "--out", tmp_path / "other.csv")
    assert result.returncode == 0, result.stderr
    assert sweep.read_bytes() == before


@pytest.mark.parametrize("what", ["mesh", "points CSV"])
def test_out_dash_onto_standard_output_appended_to_an_input_is_refused(scan, tmp_path, what):
    """``--out - >> INPUT`` would append the CSV to the input (``--out /dev/stdout >> INPUT``
    was refused already): refused, the input byte for byte as it was."""
    points = tmp_path / "points.csv"
    points.write_text("x,y,z,site\n0.05,0,0,A\n")
    victim = scan if what == "mesh" else points
    before = victim.read_bytes()
    with open(victim, "ab") as appended:
        result = subprocess.run(
            [sys.executable, str(BATCH_SCRIPT), str(scan), "--points", str(points),
             "--radius", "0.3", "--out", "-"],
            stdout=appended, stderr=subprocess.PIPE, text=True, timeout=600, check=False,
        )  # fmt: skip
    assert result.returncode == 2, result.stderr
    assert "Traceback" not in result.stderr
    assert "writes to standard output, which goes to the" in result.stderr, result.stderr
    assert victim.read_bytes() == before


def test_a_sweep_beside_a_named_pipe_out_is_not_emptied(scan, tmp_path):
    """Nothing is written beside a stream: with --out a named pipe, a file named like its sweep
    CSV (here the points CSV) is measured and left as it was (before: emptied to its header)."""
    made = batch(scan, *AT, "--sweep", "0.2", "0.4", "3", "--out", tmp_path / "first.csv")
    assert made.returncode == 0, made.stderr
    sweep = (tmp_path / "first_sweep.csv").rename(tmp_path / "pipe_sweep.csv")
    before = sweep.read_bytes()
    pipe = tmp_path / "pipe"
    os.mkfifo(pipe)
    with subprocess.Popen(["cat", str(pipe)], stdout=subprocess.PIPE) as reader:
        result = batch(scan, "--points", sweep, "--radius", "0.3", "--out", pipe)
        received = reader.communicate(timeout=60)[0].decode()
    assert result.returncode == 0, result.stderr
    assert len(csvio.parse_measurements_csv(received)) == 3
    assert sweep.read_bytes() == before


SLOW_ROWS = 3_000  # ~1 ms each: a re-run is stopped while the slow mesh is measured


def _rerun_stopped(command, stop) -> tuple[int, str]:
    """Run the batch ``command`` and send it ``stop`` once it said the fast mesh is measured
    (its rows are then in the CSV: they are written before the mesh's pictures)."""
    process = subprocess.Popen(
        [sys.executable, str(BATCH_SCRIPT), *(str(a) for a in command)],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    said = []
    for line in process.stderr:
        said.append(line)
        if "fast: 3 measured" in line:
            break
    assert process.poll() is None, "the run ended before it was stopped:\n" + "".join(said)
    process.send_signal(stop)
    _, rest = process.communicate(timeout=600)
    return process.returncode, "".join(said) + rest


def test_a_rerun_stopped_part_way_keeps_the_earlier_out_and_its_summary(tmp_path):
    """A re-run to an existing --out replaced the earlier, complete CSV (and its edge summary)
    at its first rewrite: stopped part-way, the earlier rows were lost. Now the earlier files
    stay byte for byte until the run completes; a stopped re-run's rows go to
    ``out.partial.csv`` (and ``out.partial_edges.csv``), said in one line; a run while they
    are there is refused; and a completed re-run replaces the earlier files and leaves no side
    file."""
    fast, slow = (
        wedge(90.0, n=24, irregular=True, seed=3),
        wedge(60.0, n=60, irregular=True, seed=4),
    )
    meshio.write_ply(tmp_path / "fast.ply", fast.points, fast.triangles)
    meshio.write_ply(tmp_path / "slow.ply", slow.points, slow.triangles)
    points = tmp_path / "points.csv"
    xs = [f"{-0.4 + 0.8 * (i % 997) / 997:.6f}" for i in range(SLOW_ROWS)]
    points.write_text(
        "mesh,x,y,z\n" + "".join(f"fast,{x},0,0\n" for x in ("-0.3", "0", "0.3"))
        + "".join(f"slow,{x},0,0\n" for x in xs)
    )  # fmt: skip
    out, summary = tmp_path / "out.csv", tmp_path / "out_edges.csv"
    partial, partial_summary = tmp_path / "out.partial.csv", tmp_path / "out.partial_edges.csv"
    command = [tmp_path / "fast.ply", tmp_path / "slow.ply", "--points", points, "--radius",
               "0.3", "--edge", "-0.4", "0", "0", "0.4", "0", "0", "--spacing", "0.2",
               "--out", out]  # fmt: skip
    first = batch(*command, "--quiet")
    assert first.returncode == 0, first.stderr
    earlier, earlier_summary = out.read_bytes(), summary.read_bytes()
    assert not partial.exists()

    code, stderr = _rerun_stopped(command, signal.SIGINT)
    assert code == 130 and "Traceback" not in stderr, stderr
    assert out.read_bytes() == earlier and summary.read_bytes() == earlier_summary
    assert (
        f"the run did not complete: {out} is kept as it was, with the earlier results; this "
        f"run's results so far are in {partial}"
    ) in stderr, stderr
    rows = csvio.read_measurements_csv(partial)
    assert len(rows) == 3 + SLOW_ROWS + 5 + 1  # the points, the fast edge's stations, the slow's
    assert all(row.angle is not None for row in rows[:3])
    stopped = [row for row in rows[3 : 3 + SLOW_ROWS] if row.error]
    assert stopped and all("the run was stopped before this point" in r.error for r in stopped)
    edges = csvio.read_edges_csv(partial_summary)
    assert [bool(edge.error) for edge in edges] == [False, True], edges

    # The stopped run's results are the user's now: a run that would replace them is refused,
    # nothing touched (a review: the next run's header replaced them at once).
    stopped_rows = partial.read_bytes()
    refused(batch(*command), f"{partial} is there", "move it away")
    assert partial.read_bytes() == stopped_rows and out.read_bytes() == earlier
    kept = tmp_path / "kept"
    kept.mkdir()
    for side in (partial, partial_summary):
        side.rename(kept / side.name)

    code, stderr = _rerun_stopped(command, signal.SIGKILL)  # after its first rewrite
    assert code == -signal.SIGKILL, stderr
    assert out.read_bytes() == earlier and summary.read_bytes() == earlier_summary
    assert [row.mesh_name for row in csvio.read_measurements_csv(partial)][:3] == ["fast"] * 3
    for side in tmp_path.glob("out.partial*"):
        side.unlink()

    again = batch(*command, "--quiet")
    assert again.returncode == 0, again.stderr
    rows = csvio.read_measurements_csv(out)
    assert len(rows) == 3 + SLOW_ROWS + 5 + 4 and not any(row.error for row in rows)
    assert len(csvio.read_edges_csv(summary)) == 2
    left = [p.name for p in tmp_path.iterdir() if ".partial" in p.name or p.suffix == ".tmp"]
    assert left == []


def test_a_file_named_like_the_sweep_csv_that_is_not_one_is_refused_not_replaced(scan, tmp_path):
    """``--sweep`` writes ``<out>_sweep.csv``: where the user keeps another file of that name
    (notes), the run is refused, the file kept byte for byte (before: silently replaced; found
    by a review), as a file named like the edge summary is. An earlier sweep there is replaced."""
    notes = tmp_path / "res_sweep.csv"
    notes.write_bytes(b"my notes,important\n1,2\n")
    sweep = ("--sweep", "0.2", "0.3", "2")
    refused(batch(scan, *AT, *sweep, "--out", tmp_path / "res.csv"),
            "--sweep writes", "not a radius-sweep CSV")  # fmt: skip
    assert notes.read_bytes() == b"my notes,important\n1,2\n"
    assert not (tmp_path / "res.csv").exists()
    notes.unlink()
    for _ in range(2):  # the second run replaces the first one's sweep
        result = batch(scan, *AT, *sweep, "--out", tmp_path / "res.csv")
        assert result.returncode == 0, result.stderr
    assert notes.read_bytes().count(b"\n") == 3  # the header and two radii


def test_a_file_of_the_users_named_like_the_side_file_is_refused_not_replaced(scan, tmp_path):
    """``results.partial.csv`` beside an earlier ``results.csv`` is where a re-run writes until
    it completes: where the user keeps a file of that name, the run is refused and the file
    kept byte for byte (before: replaced by the run's header, then deleted when it completed;
    found by a review)."""
    out = tmp_path / "results.csv"
    assert batch(scan, *AT, "--out", out).returncode == 0
    notes = tmp_path / "results.partial.csv"
    notes.write_bytes(b"my notes,important\n1,2\n")
    before = out.read_bytes()
    refused(batch(scan, *AT, "--out", out), f"{notes} is there", "move it away")
    assert notes.read_bytes() == b"my notes,important\n1,2\n" and out.read_bytes() == before
