"""A batch run's edges as the saved .blend keeps them: every edge with its stations (the items
the edge appended, in order) and its plot, drawn from its own numbers, also when edges follow
measurements recorded before them; a run that saves no .blend still writes each edge's plot
file.

Oracles: the core's ``Surface.measure_along`` for the stations, and the extension's plot
drawing (``profile_plot.render_profile``) of the edge's stored numbers for the plot's pixels.
"""

from __future__ import annotations

import bpy
import numpy as np
from bpy_helpers import batch, edited_csv, exact, mesh_object

from vg_addon import Surface
from vg_addon.formats import csvio, meshio, profile_plot
from vg_addon.synthetic_meshes import wedge

EDGES = ([-0.8, 0.0, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.8, 0.0, 0.0], [-0.6, 0, 0, 0.6, 0, 0])


def run(tmp_path, *extra):
    shape = wedge(90.0, n=30, irregular=True, seed=2)
    mesh = meshio.write_ply(tmp_path / "w.ply", shape.points, shape.triangles)
    edges = [arg for points in EDGES for arg in ("--edge", *points)]
    result = batch(mesh, "--at", 0.3, 0, 0, *edges, "--spacing", 0.1, "--radius", 0.2,
                   "--out", tmp_path / "out.csv", *extra)  # fmt: skip
    assert result.returncode == 0, result.stdout + result.stderr
    return mesh


def test_saved_edges_keep_their_stations_and_plots(vg, tmp_path):
    mesh = run(tmp_path, "--save-blend", tmp_path / "saved.blend")
    bpy.ops.wm.open_mainfile(filepath=str(tmp_path / "saved.blend"))
    obj = bpy.data.objects["w"]
    data = meshio.read_mesh(mesh)
    surface = Surface(data.points, data.triangles)
    assert [e.number for e in obj.vg.edges] == [1, 2, 3]
    for edge, points in zip(obj.vg.edges, EDGES, strict=True):
        profile = surface.measure_along(np.reshape(points, (2, 3)), 0.1, 0.2)
        items = [item for item in obj.vg.measurements if item.edge_number == edge.number]
        assert [exact(item)["angle"] for item in items] == profile.angles.tolist()
        numbers = exact(edge)
        image = bpy.data.images[edge.plot]
        assert image.packed_file is not None and tuple(image.size) == (480, 240)
        pixels = np.empty(480 * 240 * 4, dtype=np.float32)
        image.pixels.foreach_get(pixels)
        drawn = profile_plot.render_profile(
            numbers["arc_lengths"], numbers["angles"], width=480, height=240, units="BU",
            title=f"{obj.name}, edge {edge.number}", pooled=numbers["pooled_angle"],
        )  # fmt: skip
        want = (drawn[::-1].astype(np.float32) / 255.0).ravel()
        assert np.abs(pixels - want).max() < 1.0 / 255.0


def plot_pixels(edge) -> np.ndarray:
    image = bpy.data.images[edge.plot]
    pixels = np.empty(image.size[0] * image.size[1] * 4, dtype=np.float32)
    image.pixels.foreach_get(pixels)
    return pixels


def test_a_runs_units_come_back_with_its_csvs(vg, tmp_path):
    """A run with --units cm writes "cm" (before: the scene's description, "BU (1 BU = 0.01 m,
    ...)", which a replay wrote as "cm"); its CSV and its edges CSV imported in Blender take cm
    as the Scan Units, and every edge's plot names cm on its axis (before: Scan Units untouched,
    the plots in "BU")."""
    run(tmp_path, "--units", "cm")
    out = tmp_path / "out.csv"
    assert csvio.read_measurements_csv(out)[0].units == "cm"
    shape = wedge(90.0, n=30, irregular=True, seed=2)
    for name, path in (("stations", out), ("edges", csvio.edges_path_for(out))):
        obj = mesh_object(name, shape.points, shape.triangles)
        assert bpy.ops.vg.import_csv(filepath=str(path), ignore_mesh_names=True) == {"FINISHED"}
        assert obj.vg.unit == "CM", name
        assert len(obj.vg.edges) == 3 and len(bpy.data.images) == 3 * (1 + (name == "edges"))
        for edge in obj.vg.edges:
            numbers = exact(edge)
            drawn = profile_plot.render_profile(
                numbers["arc_lengths"], numbers["angles"], width=480, height=240, units="cm",
                title=f"{obj.name}, edge {edge.number}", pooled=numbers["pooled_angle"],
            )  # fmt: skip
            want = (drawn[::-1].astype(np.float32) / 255.0).ravel()
            assert np.abs(plot_pixels(edge) - want).max() < 1.0 / 255.0, (name, edge.number)


def test_a_run_not_saved_still_writes_every_edges_plot_file(vg, tmp_path):
    run(tmp_path)  # the plot kept in Blender is skipped; the run's own files are not
    assert sorted(p.name for p in tmp_path.glob("out_w_edge*.png")) == [
        f"out_w_edge{n}.png" for n in (1, 2, 3)
    ]


def test_edge_stations_take_the_runs_rule_and_stability(tmp_path):
    # A concave crease: the paper's rule reads it about 134°, the default rule 100°.
    shape = wedge(100.0, half_width=2.0, n=40, irregular=True, concave=True)
    mesh = meshio.write_ply(tmp_path / "c.ply", shape.points, shape.triangles)
    data = meshio.read_mesh(mesh)
    surface = Surface(data.points, data.triangles)
    edge = ("--edge", -1.5, 0, 0, 1.5, 0, 0, "--spacing", 0.5, "--radius", 0.4)
    out = tmp_path / "paper.csv"
    result = batch(mesh, *edge, "--rule", "paper", "--stability", "--out", out)
    assert result.returncode == 0, result.stdout + result.stderr
    rows = csvio.read_measurements_csv(out)
    assert len(rows) >= 5 and all(r.edge_number == 1 for r in rows)
    fresh = Surface(data.points, data.triangles)
    flagged = 0
    for row in rows:
        # Oracle: a single measurement at the station's centre with the run's settings.
        alone = fresh.measure((row.x, row.y, row.z), 0.4, rule="paper", stability=True)
        assert row.rule == "paper"
        assert row.angle == alone.angle and row.angle > 120.0
        assert row.stability == alone.stability.spread
        flagged += bool(alone.stability.warning)
    # The paper's misreading of a concave edge is unstable (about ± 75°) at every station: the
    # summary counts flagged stations like flagged points, naming each by edge and arc length.
    assert flagged == len(rows)
    assert f"{flagged} flagged reading(s)" in result.stderr, result.stderr
    assert "flagged: edge 1 station at arc length " in result.stderr
    profile = surface.measure_along([[-1.5, 0, 0], [1.5, 0, 0]], 0.5, 0.4, rule="paper")
    assert [r.angle for r in rows] == profile.angles.tolist()

    # The edges CSV records each edge's rule: a replay measures with it, whatever --rule says.
    edges_csv = csvio.edges_path_for(out)
    assert [e.rule for e in csvio.read_edges_csv(edges_csv)] == ["paper"]
    again = tmp_path / "again.csv"
    result = batch(mesh, "--edges", edges_csv, "--out", again)  # --rule refined by default
    assert result.returncode == 0, result.stdout + result.stderr
    replayed = csvio.read_measurements_csv(again)
    assert [(r.angle, r.x, r.y, r.z) for r in replayed] == [(r.angle, r.x, r.y, r.z) for r in rows]
    assert all(r.rule == "paper" and r.stability is None for r in replayed)
    # An edges CSV of an earlier version (no Rule column): a replay takes the run's --rule.
    older = edited_csv(edges_csv, tmp_path / "older_edges.csv", drop=["Rule"])
    by_run = {}
    for rule in ("paper", "refined"):
        target = tmp_path / f"{rule}.csv"
        result = batch(mesh, "--edges", older, "--rule", rule, "--out", target)
        assert result.returncode == 0, result.stdout + result.stderr
        by_run[rule] = csvio.read_measurements_csv(target)
    assert [r.angle for r in by_run["paper"]] == [r.angle for r in rows]
    assert all(r.rule == "refined" and abs(r.angle - 100.0) < 0.01 for r in by_run["refined"])


def test_failed_edges_are_listed_up_to_ten_then_counted(tmp_path):
    """Twelve edges picked off the mesh: every one refused (its own error row), the summary
    names ten and counts the rest, as it does for failed points."""
    shape = wedge(90.0, n=30, irregular=True, seed=2)
    mesh = meshio.write_ply(tmp_path / "w.ply", shape.points, shape.triangles)
    far = [arg for k in range(12) for arg in ("--edge", 50, k, 0, 51, k, 0)]
    out = tmp_path / "far.csv"
    result = batch(mesh, *far, "--spacing", 0.1, "--radius", 0.2, "--out", out)
    rows = csvio.read_measurements_csv(out)
    assert len(rows) == 12 and all(r.error.startswith("edge not measured") for r in rows)
    listed = [line for line in result.stderr.splitlines() if "  failed: edge " in line]
    assert len(listed) == 10, result.stderr
    assert "... and 2 more failed edges (see the error column)" in result.stderr


def test_an_edges_csv_row_is_measured_on_the_mesh_it_names_most_closely(tmp_path):
    """Two meshes whose names both fit the row's " lead" (one exactly, one without the space):
    the edge is measured on the exact one only, as a --points row is (before: on both)."""
    shape = wedge(90.0, n=30, irregular=True, seed=2)
    exact_name = meshio.write_ply(tmp_path / " lead.ply", shape.points, shape.triangles)
    trimmed = meshio.write_ply(tmp_path / "lead.ply", shape.points, shape.triangles)
    first = tmp_path / "first.csv"
    result = batch(exact_name, "--edge", *EDGES[0], "--spacing", 0.1, "--radius", 0.2,
                   "--out", first)  # fmt: skip
    assert result.returncode == 0, result.stdout + result.stderr
    stations = csvio.read_measurements_csv(first)
    replay = tmp_path / "replay.csv"
    result = batch(trimmed, exact_name, "--edges", csvio.edges_path_for(first), "--out", replay)
    assert result.returncode == 0, result.stdout + result.stderr
    rows = csvio.read_measurements_csv(replay)
    assert [(r.mesh_name, r.angle) for r in rows] == [(" lead", r.angle) for r in stations]


def test_units_given_leave_a_scaled_or_already_unitised_blend_object_as_it_was(vg, tmp_path):
    """--units m says what a Blender unit is; an object scaled by 0.001 has mesh units of
    0.001 m, so its rows keep saying so (before: "m", and Scan Units m saved in its .blend),
    and one whose Scan Units were chosen (cm) keeps them."""
    shape = wedge(90.0, n=30, irregular=True, seed=2)
    scaled = mesh_object("scaled", shape.points * 1000.0, shape.triangles)
    scaled.scale = (0.001, 0.001, 0.001)
    chosen = mesh_object("chosen", shape.points, shape.triangles)
    chosen.vg.unit = "CM"
    source, saved = tmp_path / "in.blend", tmp_path / "saved.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(source))
    out = tmp_path / "out.csv"
    result = batch(source, "--object", "scaled", "--object", "chosen", "--at", 300, 0, 0,
                   "--radius", 200, "--units", "m",
                   "--out", out, "--save-blend", saved)  # fmt: skip
    assert result.returncode == 1, result.stdout + result.stderr  # 300 mm is off "chosen"
    units = {row.mesh_name: row.units for row in csvio.read_measurements_csv(out)}
    assert units["scaled"] == "mesh units (1 unit = 0.001 m in the scene, object scale 0.001)"
    assert units["chosen"] == "cm"
    bpy.ops.wm.open_mainfile(filepath=str(saved))
    # Not set to m by --units (its size guesses mm, rightly, as a first measurement does).
    assert bpy.data.objects["scaled"].vg.unit != "M"
    assert bpy.data.objects["chosen"].vg.unit == "CM"


def test_a_replay_without_units_takes_the_unit_its_files_name(tmp_path):
    """An export of a scan in mm (Units "mm", as Blender's export of an object with Scan Units
    mm writes) replayed by a run without --units: its rows and its edges' rows say mm, as the
    file did (before: "BU"), with the same numbers. --units given is the user's choice and
    wins; rows that disagree name no unit, and the run's own label stays."""
    mesh = run(tmp_path)
    out = tmp_path / "out.csv"
    in_mm = edited_csv(out, tmp_path / "mm.csv", lambda row: row.update(Units="mm"))
    edges_in_mm = edited_csv(
        csvio.edges_path_for(out), tmp_path / "mm_edges.csv", lambda row: row.update(Units="mm")
    )
    first = csvio.read_measurements_csv(out)

    def replay(name, *extra, points=in_mm):
        target = tmp_path / name
        result = batch(mesh, "--points", points, "--edges", edges_in_mm, "--out", target, *extra)
        assert result.returncode == 0, result.stdout + result.stderr
        return csvio.read_measurements_csv(target), csvio.read_edges_csv(
            csvio.edges_path_for(target)
        )

    rows, edge_rows = replay("again.csv")
    assert rows and all(row.units == "mm" for row in rows)
    assert len(edge_rows) == 3 and all(row.units == "mm" for row in edge_rows)
    single = [(r.x, r.y, r.z, r.angle) for r in first if r.edge_number is None]
    assert single and single == [(r.x, r.y, r.z, r.angle) for r in rows[: len(single)]]

    rows, edge_rows = replay("chosen.csv", "--units", "cm")
    assert all(row.units == "cm" for row in [*rows, *edge_rows])
    # Metres, chosen: said as "m", which a replay keeps (before: the scene's "1 BU = 1 m",
    # Blender's default, which says nothing, so the replay wrote "BU").
    in_metres, _ = replay("metres.csv", "--units", "m")
    assert all(row.units == "m" for row in in_metres)
    metres = tmp_path / "metres.csv"
    again = tmp_path / "metres_again.csv"
    result = batch(
        mesh, "--points", metres, "--edges", csvio.edges_path_for(metres), "--out", again
    )
    assert result.returncode == 0, result.stdout + result.stderr
    rows = [*csvio.read_measurements_csv(again), *csvio.read_edges_csv(csvio.edges_path_for(again))]
    assert len(rows) > 3 and all(row.units == "m" for row in rows)

    marks = iter(["cm"] + ["mm"] * len(first))
    mixed = edited_csv(out, tmp_path / "mixed.csv", lambda row: row.update(Units=next(marks)))
    rows, _ = replay("mixed_again.csv", points=mixed)
    assert all(row.units == "BU" for row in rows)


def test_an_old_world_space_edge_file_replays_in_mesh_units_on_a_scaled_blend_object(vg, tmp_path):
    """An edge file of an earlier version (no Coordinates column: points, spacing and radius in
    world units) replayed by the batch on a .blend object scaled by 2. The points were brought
    into mesh coordinates but the spacing and radius were not: 7 stations every 0.2 with radius
    0.6 where Blender's import measures 13 every 0.1 with radius 0.3. Oracle: Blender's import
    of the same file on the same object, and the wedge's angle."""
    shape = wedge(70.0, n=40, irregular=True, seed=5)
    obj = mesh_object("Bone", shape.points, shape.triangles, location=(1.0, 2.0, 3.0),
                      rotation=(0.2, 0.5, 0.9), scale=(2.0, 2.0, 2.0))  # fmt: skip
    source = tmp_path / "study.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(source))
    matrix = np.array(obj.matrix_world, dtype=np.float64)
    ends = np.array([[-0.6, 0.0, 0.0], [0.6, 0.0, 0.0]])
    world = ends @ matrix[:3, :3].T + matrix[:3, 3]
    header = [c for c in csvio.EDGE_COLUMNS if c != "Coordinates"]
    values = {"Mesh Name": "Bone", "Edge #": "1", "Spacing": "0.2", "Radius": "0.6",
              "SegParam": "2.0", "Patch Mode": "euclidean",
              "Points": "; ".join(" ".join(repr(float(v)) for v in p) for p in world)}  # fmt: skip
    old = tmp_path / "old_edges.csv"
    old.write_text(",".join(header) + "\n" + ",".join(values.get(c, "") for c in header) + "\n")
    out = tmp_path / "out.csv"
    result = batch(source, "--object", "Bone", "--edges", old, "--out", out)
    assert result.returncode == 0, result.stdout + result.stderr
    (row,) = csvio.read_edges_csv(csvio.edges_path_for(out))
    vg.bridge.edges.import_edges_csv(obj, old)  # Blender's import of the same file
    (edge,) = obj.vg.edges
    assert (row.spacing, row.radius) == (0.1, 0.3) and edge.n_stations == 13
    assert row.n_stations == edge.n_stations
    # Bit for bit with the edge's exact numbers (its ``mean`` property is float32, for display).
    assert row.mean == exact(edge)["mean"] and abs(row.mean - 70.0) < 1e-6
