"""vg_batch.py --find-edges, run as a user runs it: every break edge the finder sees is profiled
into the CSV, the edges CSV (with the study's per-break figures), a plot per edge and the map
with the edges drawn; each edge re-measures identically with --edges; --jobs gives the serial
run's rows.

Oracles: the core (``find_break_edges`` and ``Surface.measure_along`` on the file's own
coordinates) for the numbers, the standard library and NumPy's SVD for the per-break figures,
and the map's pixels for the drawn edges (a map of the same mesh without edges has none).
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import statistics
from pathlib import Path

import bpy
import numpy as np
import pytest
from bpy_helpers import batch, colours, edited_csv, exact, expected_colours

from vg_addon import Surface
from vg_addon.formats import csvio, meshio
from vg_addon.fragments import bevelled_cube, bone_shaft
from vg_addon.marching_tetrahedra import march
from vg_addon.method.break_edges import find_break_edges

SPACING, RADIUS = 6.0, 2.5


def ok(result, code=0):
    assert result.returncode == code, result.stdout + result.stderr
    return result


def magenta_pixels(path: Path) -> int:
    """Pixels of the edge lines' colour (strong red and blue, no green: no side colour, label,
    mesh grey or sky has it)."""
    image = bpy.data.images.load(str(path), check_existing=False)
    try:
        rgba = np.empty(image.size[0] * image.size[1] * 4, dtype=np.float32)
        image.pixels.foreach_get(rgba)
    finally:
        bpy.data.images.remove(image)
    r, g, b = (rgba.reshape(-1, 4)[:, k] for k in range(3))
    return int(((r > 0.6) & (b > 0.6) & (g < 0.2)).sum())


def first_axis(points) -> np.ndarray | None:
    """The direction of largest spread, or None where the next spread is within 1 % of it (a
    ring's stations, evenly round it: docs/EDGE_PROFILES.md's arc angle)."""
    points = np.asarray(points, dtype=np.float64)
    _, spread, axes = np.linalg.svd(points - points.mean(axis=0), full_matrices=False)
    return None if spread[0] ** 2 <= 1.01 * spread[1] ** 2 else axes[0]


BONE_SPACING = 0.3
"""The bone shaft the finder's quality is measured on (tests/core/test_break_edges_quality.py):
fine enough that each fracture face is wider than the finder's ridge band (2.5 × its scale of 5
mean edge lengths); on a coarser mesh a face's outer and inner rims merge or are missed, a limit
docs/EDGE_DETECTION.md states."""


def write_bone(path: Path, **options) -> Path:
    shape = bone_shaft(spacing=BONE_SPACING, **options)
    meshio.write_ply(path, shape.points, shape.triangles)
    return path


@pytest.fixture(scope="module")
def found(tmp_path_factory):
    """One --find-edges run with a map, on the bone shaft fragment (its two fracture faces' four
    rims are the break edges)."""
    folder = tmp_path_factory.mktemp("find")
    mesh = write_bone(folder / "bone.ply")
    out = folder / "out.csv"
    result = ok(batch(mesh, "--find-edges", "--spacing", SPACING, "--radius", RADIUS,
                      "--out", out, "--render", folder / "maps", "--render-size", 160, 120,
                      "--render-samples", 1, "--save-blend", folder / "found.blend"))  # fmt: skip
    return mesh, out, result


def test_every_edge_found_is_profiled_as_the_core_profiles_it(found):
    mesh, out, result = found
    data = meshio.read_mesh(mesh)
    surface = Surface(data.points, data.triangles)
    candidates = find_break_edges(surface).candidates
    # The fracture faces' rims at least (how the finder splits them is the finder's own;
    # tests/core/test_break_edges*.py measure it against the true edges).
    assert len(candidates) >= 4
    assert f"bone: found {len(candidates)} break edge(s)" in result.stderr
    rows = csvio.read_measurements_csv(out)
    # An edges-only run says what it did, not "0 measured, 0 failed, 0 points".
    done = f"{len(candidates)} edge(s) profiled ({len(rows)} stations)"
    assert (
        f"bone: {done}, " in result.stderr and f"{done}, 0 failed, on 1 mesh(es)" in result.stderr
    )
    assert "0 measured" not in result.stderr and "measurements/s" not in result.stderr
    edges = csvio.read_edges_csv(csvio.edges_path_for(out))
    assert [e.edge_number for e in edges] == list(range(1, len(candidates) + 1))
    for edge, candidate in zip(edges, candidates, strict=True):
        points = candidate.waypoint_points
        assert csvio.parse_points(edge.points) == [tuple(p) for p in points.tolist()]
        assert edge.user_data.startswith(f"found edge {candidate.number}: confidence ")
        profile = surface.measure_along(points, SPACING, RADIUS)
        np.testing.assert_array_equal(profile.path.vertices, candidate.path.vertices)
        stations = [r for r in rows if r.edge_number == edge.edge_number]
        assert [r.angle for r in stations] == profile.angles.tolist()
        assert [r.arc_length for r in stations] == profile.arc_lengths.tolist()
        assert {r.edge_closed for r in stations} == {bool(candidate.closed)}
        assert (edge.mean, edge.std, edge.pooled_angle) == (
            profile.mean, profile.std, profile.pooled_angle
        )  # fmt: skip
        assert (mesh.parent / f"out_bone_edge{edge.edge_number}.png").stat().st_size > 1000

        # The study's per-break figures, from the station rows alone.
        angles = [r.angle for r in stations]
        centres = [(r.x, r.y, r.z) for r in stations]
        assert edge.n_stations == len(stations)
        assert edge.mean == pytest.approx(statistics.fmean(angles), rel=1e-12)
        assert edge.std == pytest.approx(statistics.stdev(angles), rel=1e-9)
        assert edge.median == pytest.approx(statistics.median(angles), rel=1e-12)
        assert edge.range == pytest.approx(max(angles) - min(angles), rel=1e-12)
        arc = sum(math.dist(a, b) for a, b in itertools.pairwise(centres))
        assert edge.arc_length == pytest.approx(arc, rel=1e-12)
        assert edge.chord_length == pytest.approx(math.dist(centres[0], centres[-1]), abs=1e-9)
        along, fragment = first_axis(centres), first_axis(data.points)
        if along is None or fragment is None:
            assert edge.arc_angle is None
        else:
            cosine = abs(float(np.dot(along, fragment)))
            expected = math.degrees(math.acos(min(cosine, 1.0)))
            assert edge.arc_angle == pytest.approx(expected, abs=1e-6)


def test_each_found_edge_re_measures_identically_from_the_edges_csv(found, tmp_path):
    mesh, out, _ = found
    again = tmp_path / "again.csv"
    ok(batch(mesh, "--edges", csvio.edges_path_for(out), "--out", again))
    first = [r for r in csvio.read_measurements_csv(out) if r.edge_number]
    second = csvio.read_measurements_csv(again)
    # The User Data ("found edge 2: confidence ...") stays with each edge and its stations.
    assert first and all(r.user_data.startswith("found edge ") for r in first)
    keys = ("edge_number", "angle", "arc_length", "x", "y", "z", "fit", "n_vertices", "user_data")
    assert [[getattr(r, k) for k in keys] for r in second] == [
        [getattr(r, k) for k in keys] for r in first
    ]
    assert all(e.user_data for e in csvio.read_edges_csv(csvio.edges_path_for(out)))
    skip = {"date"}

    def summaries(path):
        rows = csvio.read_edges_csv(csvio.edges_path_for(path))
        return [{k: v for k, v in dataclasses.asdict(e).items() if k not in skip} for e in rows]

    assert summaries(again) == summaries(out)


def test_an_edge_found_but_not_measured_keeps_its_points_in_the_edges_csv(found, tmp_path):
    """A radius too small for any patch: every found edge fails. Each keeps a row of the edges
    CSV with the finder's points, its note and why it failed (no figures), a replay passes those
    rows over and says so, and a row whose error is cleared and radius mended measures the edge
    as a run with that radius did."""
    mesh, good_out, _ = found
    out = tmp_path / "tiny.csv"
    result = ok(batch(mesh, "--find-edges", "--spacing", SPACING, "--radius", 1e-4,
                      "--out", out), 1)  # fmt: skip
    data = meshio.read_mesh(mesh)
    candidates = find_break_edges(Surface(data.points, data.triangles)).candidates
    failed = csvio.read_edges_csv(csvio.edges_path_for(out))
    assert [e.edge_number for e in failed] == list(range(1, len(candidates) + 1))
    for edge, candidate in zip(failed, candidates, strict=True):
        assert csvio.parse_points(edge.points) == [tuple(p) for p in candidate.waypoint_points]
        assert edge.user_data.startswith(f"found edge {candidate.number}: confidence ")
        assert edge.error.startswith("edge not measured: ") and "radius" in edge.error
        assert (edge.spacing, edge.radius, edge.rule) == (SPACING, 1e-4, "refined")
        assert edge.n_stations is None and edge.mean is None and edge.length is None
    rows = csvio.read_measurements_csv(out)
    assert [(r.edge_number, r.user_data) for r in rows] == [
        (e.edge_number, e.user_data) for e in failed
    ]
    assert f"0 edge(s) profiled (0 stations), {len(candidates)} failed" in result.stderr

    replay = tmp_path / "replay.csv"
    result = ok(batch(mesh, "--edges", csvio.edges_path_for(out), "--out", replay))
    assert (
        f"passed over {len(candidates)} edge row(s) of tiny_edges.csv whose error says they were "
        "not measured" in result.stderr
    )
    assert csvio.read_measurements_csv(replay) == []

    def mend_the_first(row):
        if row["Edge #"] == "1":
            row["Radius"], row["error"] = repr(RADIUS), ""

    mended = edited_csv(csvio.edges_path_for(out), tmp_path / "mended.csv", mend_the_first)
    result = ok(batch(mesh, "--edges", mended, "--out", replay))
    assert f"passed over {len(candidates) - 1} edge row(s) of mended.csv" in result.stderr
    keys = ("edge_number", "angle", "arc_length", "x", "y", "z", "user_data")
    first = [r for r in csvio.read_measurements_csv(good_out) if r.edge_number == 1]
    assert [[getattr(r, k) for k in keys] for r in csvio.read_measurements_csv(replay)] == [
        [getattr(r, k) for k in keys] for r in first
    ]


def test_found_edges_are_painted_as_the_extension_paints_stations(vg, found):
    """Every station's sides in its break's colours, later over earlier, a station whose "+"
    side lies right of the path with its pair the other way round (painted once per mesh)."""
    mesh, _, _ = found
    bpy.ops.wm.open_mainfile(filepath=str(mesh.parent / "found.blend"))
    obj = bpy.data.objects["bone"]
    data = meshio.read_mesh(mesh)
    surface = Surface(data.points, data.triangles)
    sides = []
    for item in obj.vg.measurements:
        numbers = exact(item)
        m = surface.measure(numbers["center"], RADIUS)
        labels = m.labels if numbers["plus_left"] else ~m.labels
        sides.append((m.indices, labels, item.break_number))
    assert len(sides) == sum(edge.n_stations for edge in obj.vg.edges) > 20
    np.testing.assert_array_equal(colours(obj), expected_colours(len(obj.data.vertices), sides))


def test_the_map_draws_the_edges(found, tmp_path):
    mesh, _, _ = found
    maps = mesh.parent / "maps"
    drawn = {view: magenta_pixels(maps / f"bone_map_{view}.png") for view in ("top", "front")}
    assert drawn["top"] > 200 and drawn["front"] > 10, drawn  # rings from above, rims edge-on
    assert magenta_pixels(maps / "bone_map.png") > 200  # the contact sheet too
    # The same mesh measured at one point, no edges: no pixel of that colour.
    plain = tmp_path / "plain"
    ok(batch(mesh, "--at", 12, 0, 30, "--radius", RADIUS, "--out", tmp_path / "p.csv",
             "--render", plain, "--render-size", 160, 120, "--render-samples", 1))  # fmt: skip
    assert magenta_pixels(plain / "bone_map_top.png") == 0


def saved_edges(path: Path) -> dict:
    """Each object's edges in a saved .blend: number, stations, and its plot's size and pixels
    (None where the edge names no image the file holds)."""
    bpy.ops.wm.open_mainfile(filepath=str(path))
    found = {}
    for obj in bpy.data.objects:
        for edge in obj.vg.edges:
            image = bpy.data.images.get(edge.plot)
            plot = None
            if image is not None:
                pixels = np.empty(image.size[0] * image.size[1] * 4, dtype=np.float32)
                image.pixels.foreach_get(pixels)
                plot = (tuple(image.size), image.packed_file is not None, pixels.tobytes())
            found[(obj.name, edge.number)] = (edge.n_stations, plot)
    return found


def test_find_edges_with_jobs_writes_the_serial_runs_rows(vg, tmp_path):
    meshes = [write_bone(tmp_path / "a.ply"), write_bone(tmp_path / "b.ply", oblique_deg=20.0)]
    common = ("--find-edges", "--spacing", SPACING, "--radius", RADIUS)
    ok(batch(*meshes, *common, "--out", tmp_path / "serial.csv",
             "--save-blend", tmp_path / "serial.blend"))  # fmt: skip
    ok(batch(*meshes, *common, "--jobs", 2, "--out", tmp_path / "jobs.csv",
             "--save-blend", tmp_path / "jobs.blend"))  # fmt: skip
    # The saved file keeps every edge with its plot, as the serial run's does.
    serial_blend = saved_edges(tmp_path / "serial.blend")
    assert len(serial_blend) >= 8 and all(plot for _, plot in serial_blend.values())
    assert saved_edges(tmp_path / "jobs.blend") == serial_blend

    def dated(rows):
        return [{k: v for k, v in dataclasses.asdict(r).items() if k != "date"} for r in rows]

    serial, jobs = (csvio.read_measurements_csv(tmp_path / f"{n}.csv") for n in ("serial", "jobs"))
    assert {r.mesh_name for r in serial} == {"a", "b"}
    assert dated(jobs) == dated(serial)
    edges = [csvio.read_edges_csv(tmp_path / f"{n}_edges.csv") for n in ("serial", "jobs")]
    assert {e.mesh_name for e in edges[0]} == {"a", "b"} and dated(edges[1]) == dated(edges[0])
    assert all(
        (tmp_path / f"jobs_{e.mesh_name}_edge{e.edge_number}.png").exists() for e in edges[0]
    )


def test_a_min_length_longer_than_every_edge_finds_none(tmp_path):
    # The bevelled cube: its edges (about 20 long) are shorter than its diagonal (35), so a min
    # length between the two is longer than every edge the core finds.
    shape = bevelled_cube()
    mesh = tmp_path / "cube.ply"
    meshio.write_ply(mesh, shape.points, shape.triangles)
    found = find_break_edges(Surface(shape.points, shape.triangles)).candidates
    longest = max(c.length for c in found)
    diagonal = float(np.linalg.norm(shape.points.max(axis=0) - shape.points.min(axis=0)))
    assert found and longest < diagonal
    min_length = f"{(longest + diagonal) / 2:.6g}"
    out = tmp_path / "out.csv"
    result = ok(batch(mesh, "--find-edges", "--spacing", SPACING, "--radius", RADIUS,
                      "--min-length", min_length, "--out", out))  # fmt: skip
    assert "cube: found 0 break edge(s)" in result.stderr
    assert f"length at least {float(min_length):.4g}" in result.stderr
    assert csvio.read_measurements_csv(out) == []
    assert csvio.read_edges_csv(csvio.edges_path_for(out)) == []


def test_the_finders_scale_and_bend_reach_the_finder(tmp_path):
    # The oracle is the core finder with the same settings; the default finds other candidates
    # on this cube, so settings dropped on the way would show.
    shape = bevelled_cube()
    mesh = tmp_path / "cube.ply"
    meshio.write_ply(mesh, shape.points, shape.triangles)
    surface = Surface(shape.points, shape.triangles)
    default = find_break_edges(surface).candidates
    wanted = find_break_edges(surface, scale=2.0, min_bend_deg=40.0).candidates
    assert wanted and [c.waypoint_points.tolist() for c in wanted] != [
        c.waypoint_points.tolist() for c in default
    ]
    out = tmp_path / "out.csv"
    result = ok(batch(mesh, "--find-edges", "--spacing", SPACING, "--radius", RADIUS,
                      "--find-scale", 2, "--min-bend", 40, "--out", out))  # fmt: skip
    assert f"cube: found {len(wanted)} break edge(s)" in result.stderr
    assert "(scale 2, bend at least 40°" in result.stderr
    edges = csvio.read_edges_csv(csvio.edges_path_for(out))
    assert [csvio.parse_points(e.points) for e in edges] == [
        [tuple(p) for p in c.waypoint_points.tolist()] for c in wanted
    ]


def test_quiet_still_names_the_meshes_where_no_edge_was_found(tmp_path):
    # A smooth ball has no break edge (the finder finds none on it: the oracle is the core's
    # answer on the same mesh); the bone has some.
    points, triangles = march(
        lambda p: np.linalg.norm(p, axis=1) - 10.0, [-11.3] * 3, [11.6] * 3, 0.8
    )
    assert len(Surface(points, triangles).find_break_edges().candidates) == 0
    balls = [tmp_path / "ball.ply", tmp_path / "Ball2.ply"]
    for ball in balls:
        meshio.write_ply(ball, points, triangles)
    bone = write_bone(tmp_path / "bone.ply")
    out = tmp_path / "out.csv"
    # Measured in two processes, so the count crosses from the workers too.
    result = ok(batch(*balls, bone, "--find-edges", "--spacing", SPACING, "--radius", RADIUS,
                      "--quiet", "--jobs", 2, "--out", out))  # fmt: skip
    assert "found 0 break edge(s)" not in result.stderr  # the per-mesh line is quiet
    line = "--find-edges found no break edge on 2 mesh(es), which have no edge rows: ball, Ball2"
    assert line in result.stderr
    assert {e.mesh_name for e in csvio.read_edges_csv(csvio.edges_path_for(out))} == {"bone"}


def test_a_point_cloud_is_one_failed_row_saying_why(tmp_path):
    shape = bone_shaft(spacing=2.0)
    cloud = tmp_path / "cloud.ply"
    meshio.write_ply(cloud, shape.points, np.zeros((0, 3), dtype=np.int64))
    out = tmp_path / "out.csv"
    result = ok(batch(cloud, "--find-edges", "--spacing", SPACING, "--radius", RADIUS,
                      "--out", out), 1)  # fmt: skip
    (row,) = csvio.read_measurements_csv(out)
    assert row.error.startswith("edges not found: ") and "point cloud" in row.error
    assert (row.mesh_name, row.spacing, row.radius, row.angle) == ("cloud", SPACING, RADIUS, None)
    assert "failed: finding edges on 'cloud': edges not found" in result.stderr
    assert csvio.read_edges_csv(csvio.edges_path_for(out)) == []


@pytest.mark.parametrize(
    ("arguments", "words"),
    [
        (("--find-edges", "--radius", 1), "--find-edges needs --spacing D and --radius R"),
        (("--find-edges", "--spacing", 1, "--radius", 1, "--shard", "1/2"), "drop --shard"),
        (("--find-edges", "--spacing", 1, "--radius", 1, "--min-length", -1), "positive"),
        (("--at", 0, 0, 0, "--radius", 1, "--min-length", 2), "--min-length L is for"),
        (("--at", 0, 0, 0, "--radius", 1, "--find-scale", 2), "--find-scale S is for"),
        (("--at", 0, 0, 0, "--radius", 1, "--min-bend", 40), "--min-bend DEG is for"),
        *[
            (("--find-edges", "--spacing", 1, "--radius", 1, "--find-scale", scale), "positive")
            for scale in ("0", "-1", "nan", "inf")
        ],
        *[
            (
                ("--find-edges", "--spacing", 1, "--radius", 1, "--min-bend", bend),
                "--min-bend must be a number of degrees above 0 and below 180",
            )
            for bend in ("0", "180", "-5", "nan")
        ],
        *[
            (
                (*how, "--spacing", spacing, "--radius", 1),
                f"--spacing must be a positive, finite number (got {spacing})",
            )
            for how in (("--find-edges",), ("--edge", 0, 0, 0, 1, 0, 0), ("--edges", "e.pp"))
            for spacing in ("0", "-1", "nan", "inf")
        ],
        *[
            (
                (*how, "--spacing", 1, "--radius", radius),
                f"--radius must be a positive, finite number (got {radius})",
            )
            for how in (("--find-edges",), ("--edge", 0, 0, 0, 1, 0, 0), ("--edges", "e.pp"))
            for radius in ("0", "-1", "nan")
        ],
        *[
            (
                # An edge summary's rows keep their own spacing and radius: none given with it.
                (
                    *how,
                    *(() if "e.csv" in how else ("--spacing", 1, "--radius", 1)),
                    "--lambda",
                    -1,
                ),
                "--lambda: λ (SegParam) must be a number from 0 to",
            )
            for how in (("--find-edges",), ("--edge", 0, 0, 0, 1, 0, 0), ("--edges", "e.csv"))
        ],
    ],
)
def test_bad_find_edges_arguments_are_refused_before_anything_runs(tmp_path, arguments, words):
    # Each before any mesh or edges file is read: neither exists.
    out = tmp_path / "out.csv"
    result = ok(batch(tmp_path / "none.ply", *arguments, "--out", out), 2)
    assert words in result.stderr
    assert not out.exists()
