"""vg_batch.py --edges with MeshLab picked-points files, run as a user runs it: each .pp file's
active points are an edge on the mesh its file name names, measured as the core measures them.

The .pp files are written here as MeshLab writes them (text), the oracle is the core's
``Surface.measure_along`` on the file's coordinates.
"""

from __future__ import annotations

import os

import numpy as np
from bpy_helpers import batch

from vg_addon import Surface
from vg_addon.formats import csvio, meshio
from vg_addon.synthetic_meshes import varying_wedge


def ok(result, code=0):
    assert result.returncode == code, result.stdout + result.stderr
    return result


def write_pp(path, points, inactive=()):
    """A picked-points file as MeshLab's PickPoints tool saves it; ``inactive`` points are
    listed with ``active="0"`` after the first point."""
    lines = [
        "<!DOCTYPE PickedPoints>",
        "<PickedPoints>",
        " <DocumentData>",
        '  <DateTime time="10:00:00" date="2021-05-06"/>',
        f'  <DataFileName name="{path.stem}.ply"/>',
        " </DocumentData>",
    ]
    listed = [(points[0], 1), *((p, 0) for p in inactive), *((p, 1) for p in points[1:])]
    lines += [
        f' <point x="{x!r}" y="{y!r}" z="{z!r}" name="{n}" active="{a}"/>'
        for n, ((x, y, z), a) in enumerate(listed)
    ]
    path.write_text("\n".join([*lines, "</PickedPoints>", ""]), encoding="utf-8")
    return path


def test_a_folder_of_pp_files_measures_each_on_the_mesh_its_name_names(tmp_path):
    shape = varying_wedge(80.0, 120.0, half_width=2.0, depth=1.0, n=20)
    scans = tmp_path / "scans"
    scans.mkdir()
    mesh = scans / "ramp.ply"
    meshio.write_ply(mesh, shape.points, shape.triangles)
    picks = {
        "ramp_break1.pp": [[-1.5, 0.01, 0.0], [0.0, -0.01, 0.0], [1.5, 0.0, 0.0]],
        "ramp.pp": [[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]],
    }
    write_pp(scans / "ramp_break1.pp", picks["ramp_break1.pp"], inactive=[[9.0, 9.0, 9.0]])
    write_pp(scans / "ramp.pp", picks["ramp.pp"])
    write_pp(scans / "other.pp", picks["ramp.pp"])  # names no mesh given: passed over
    out = tmp_path / "out.csv"
    result = ok(batch(mesh, "--edges", scans, "--spacing", 0.5, "--radius", 0.3, "--out", out))
    assert "1 file(s) name no mesh given and are passed over: other.pp" in result.stderr

    rows = csvio.read_measurements_csv(out)
    edges = csvio.read_edges_csv(out.with_name("out_edges.csv"))
    surface = Surface(meshio.read_mesh(mesh).points, shape.triangles)
    assert [e.user_data for e in edges] == ["ramp.pp", "ramp_break1.pp"]  # sorted by file name
    for edge in edges:
        points = picks[edge.user_data]
        assert csvio.parse_points(edge.points) == [tuple(p) for p in points]
        profile = surface.measure_along(points, 0.5, 0.3)
        stations = [row for row in rows if row.edge_number == edge.edge_number]
        assert [r.angle for r in stations] == profile.angles.tolist()
        assert [r.arc_length for r in stations] == profile.arc_lengths.tolist()
        assert (edge.mean, edge.n_stations) == (profile.mean, len(profile.stations))
        assert {r.mesh_name for r in stations} == {"ramp"}

    # One .pp file named directly, on the one mesh whatever its name with --ignore-mesh-names.
    single = tmp_path / "single.csv"
    ok(batch(mesh, "--edges", scans / "other.pp", "--spacing", 0.5, "--radius", 0.3,
             "--ignore-mesh-names", "--out", single))  # fmt: skip
    again = csvio.read_measurements_csv(single)
    first = [r.angle for r in rows if r.edge_number == edges[0].edge_number]
    assert [r.angle for r in again] == first


def test_a_pp_file_whose_name_is_not_utf8_is_measured_with_the_others(tmp_path):
    """A file name with a Latin-1 byte (``caf\\xe9``, as older archives keep them) was written
    into the edge's note as Python holds it (a surrogate), which Blender refused with a
    TypeError: an internal error, that edge and every edge after it on the mesh not measured,
    exit 2. Now its name is written as the mesh names are (``\\xe9``), and all three edges are
    measured as the core measures them."""
    shape = varying_wedge(80.0, 120.0, half_width=2.0, depth=1.0, n=20)
    scans = tmp_path / "scans"
    scans.mkdir()
    mesh = scans / "ramp.ply"
    meshio.write_ply(mesh, shape.points, shape.triangles)
    points = [[-1.5, 0.0, 0.0], [1.5, 0.0, 0.0]]
    for name in (b"ramp_a.pp", b"ramp_caf\xe9.pp", b"ramp_z.pp"):
        os.rename(write_pp(scans / "picked.pp", points), bytes(scans) + b"/" + name)
    out = tmp_path / "out.csv"
    ok(batch(mesh, "--edges", scans, "--spacing", 0.5, "--radius", 0.3, "--out", out))
    edges = csvio.read_edges_csv(out.with_name("out_edges.csv"))
    assert [e.user_data for e in edges] == ["ramp_a.pp", "ramp_caf\\xe9.pp", "ramp_z.pp"]
    profile = Surface(meshio.read_mesh(mesh).points, shape.triangles).measure_along(
        points, 0.5, 0.3
    )
    assert [(e.mean, e.n_stations, e.error) for e in edges] == [
        (profile.mean, len(profile.stations), "")
    ] * 3


def test_bad_pp_files_stop_the_run_before_anything_is_measured(tmp_path):
    shape = varying_wedge(80.0, 120.0, half_width=2.0, depth=1.0, n=10)
    mesh = tmp_path / "ramp.ply"
    meshio.write_ply(mesh, shape.points, shape.triangles)
    out = tmp_path / "out.csv"
    bad = tmp_path / "ramp_a.pp"
    bad.write_text('<PickedPoints>\n<point x="1" y="2"/>\n</PickedPoints>\n', encoding="utf-8")
    one = write_pp(tmp_path / "ramp_b.pp", [[0.0, 0.0, 0.0]])
    result = ok(batch(mesh, "--edges", tmp_path, "--spacing", 0.5, "--radius", 0.3,
                      "--out", out), 2)  # fmt: skip
    assert "2 picked-points file(s) cannot be measured" in result.stderr
    assert "line 2: <point> no z" in result.stderr
    assert f"'{one}' has 1 picked point(s)" in result.stderr
    assert not out.exists()

    result = ok(batch(mesh, "--edges", one, "--radius", 0.3, "--out", out), 2)
    assert "--spacing D and --radius R" in result.stderr
    stray = write_pp(tmp_path / "flake.pp", [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    result = ok(batch(mesh, "--edges", stray, "--spacing", 0.5, "--radius", 0.3, "--out", out), 2)
    assert "flake.pp: no mesh given is named by it" in result.stderr
    assert not out.exists()


def test_a_pp_file_picked_on_a_shifted_copy_is_refused_naming_it(tmp_path):
    shape = varying_wedge(80.0, 120.0, half_width=2.0, depth=1.0, n=20)
    mesh = tmp_path / "ramp.ply"
    meshio.write_ply(mesh, shape.points, shape.triangles)
    # Crease vertices (the wedge's top): 1.5 above each, no vertex is nearer than 1.5.
    crease = shape.points[(np.abs(shape.points[:, 1]) < 1e-12) & (shape.points[:, 2] == 0.0)]
    ends = [crease[np.argmin(np.abs(crease[:, 0] - x))] for x in (-1.5, 1.5)]
    # Named in another case than the mesh: still its file.
    write_pp(tmp_path / "Ramp_Good.PP", [p.tolist() for p in ends])
    write_pp(tmp_path / "other.pp", [p.tolist() for p in ends])  # names no mesh given
    write_pp(tmp_path / "ramp_shifted.pp", [(p + np.array([0.0, 0.0, 1.5])).tolist() for p in ends])
    out = tmp_path / "out.csv"
    result = batch(mesh, "--edges", tmp_path, "--spacing", 0.5, "--radius", 0.3, "--out", out,
                   "--quiet")  # fmt: skip
    assert result.returncode == 1, result.stdout + result.stderr
    # --quiet still says which files were passed over and which edge failed.
    assert "1 file(s) name no mesh given and are passed over: other.pp" in result.stderr
    assert "failed: edge 2 on 'ramp': edge not measured: ramp_shifted.pp" in result.stderr
    rows = csvio.read_measurements_csv(out)
    failed = [row for row in rows if row.error]
    assert len(failed) == 1, [row.error for row in rows]
    assert "ramp_shifted.pp: point 1 (" in failed[0].error
    assert failed[0].error.count(" is 1.5 from the mesh") == 2
    edges = csvio.read_edges_csv(out.with_name("out_edges.csv"))
    # The good file is still measured; the failed one keeps its points and why it failed.
    assert [(e.user_data, bool(e.error)) for e in edges] == [
        ("Ramp_Good.PP", False),
        ("ramp_shifted.pp", True),
    ]
    assert edges[1].error == failed[0].error and edges[1].n_stations is None
    shifted = [tuple((p + np.array([0.0, 0.0, 1.5])).tolist()) for p in ends]
    assert csvio.parse_points(edges[1].points) == shifted

    # The same points typed as --edge and --via: the via point is the one refused.
    typed = tmp_path / "typed.csv"
    up = (ends[0] + ends[1]) / 2 + np.array([0.0, 0.0, 1.5])
    result = batch(mesh, "--edge", *ends[0], *ends[1], "--via", *up, "--spacing", 0.5,
                   "--radius", 0.3, "--out", typed)  # fmt: skip
    assert result.returncode == 1, result.stdout + result.stderr
    (row,) = csvio.read_measurements_csv(typed)
    assert "--edge 1: point 2 (" in row.error and " is 1.5 from the mesh" in row.error
    assert "point 1 " not in row.error and "point 3 " not in row.error


def test_a_pp_file_in_the_edges_folder_is_never_overwritten(tmp_path):
    """--out naming a picked-points file of the --edges folder (or the summary beside it) is
    refused before anything is read, as an edges CSV given by name is (before: the MeshLab file
    was replaced by the run's CSV)."""
    shape = varying_wedge(80.0, 120.0, half_width=2.0, depth=1.0, n=20)
    mesh = meshio.write_ply(tmp_path / "ramp.ply", shape.points, shape.triangles)
    pick = write_pp(tmp_path / "ramp_a.pp", [[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    before = pick.read_bytes()
    for out in (pick, tmp_path / "ramp.pp"):  # the second's summary would be ramp_edges.pp
        if out != pick:
            write_pp(tmp_path / "ramp_edges.pp", [[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
        result = ok(batch(mesh, "--edges", tmp_path, "--spacing", 0.5, "--radius", 0.3,
                          "--out", out), 2)  # fmt: skip
        assert "is the picked-points file" in result.stderr and "nothing was read" in result.stderr
    assert pick.read_bytes() == before and not (tmp_path / "ramp.pp").exists()
