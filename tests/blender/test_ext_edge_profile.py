"""vg.measure_edge against the core: one break of stations, bit-identical to Surface.measure_along
and replayable with vg.measure_xyz; its record, plot, CSV rows, re-import, undo and delete."""

import csv
import dataclasses
import importlib
import json

import bpy
import numpy as np
import pytest
from bpy_helpers import edited_csv, exact, local_points, mesh_object, world
from test_ext_measure import core_surface

from vg_addon import Surface
from vg_addon.formats import csvio
from vg_addon.synthetic_meshes import lens, varying_wedge, wedge

POINTS = [[-1.5, 0.01, 0.0], [0.0, -0.01, 0.0], [1.5, 0.0, 0.0]]


def ramp_object(name="Ramp", **transform):
    shape = varying_wedge(80.0, 120.0, half_width=2.0, depth=1.0, n=20)
    return mesh_object(name, shape.points, shape.triangles, **transform), shape


def measure_edge(*args, points=POINTS, spacing=0.5, radius=0.3, **options):
    return bpy.ops.vg.measure_edge(
        *args, points=json.dumps(points), spacing=spacing, radius=radius, **options
    )


def test_stations_are_the_core_profile_bit_for_bit_and_one_break(vg):
    """Measured in mesh coordinates (the object moved and rotated changes nothing): the core's
    profile on the mesh's own coordinates, bit for bit."""
    obj, shape = ramp_object(location=(0.25, -1.0, 0.5), rotation=(0.3, 0.0, 0.2))
    points = np.array(POINTS)
    bpy.ops.vg.measure_xyz(location=tuple(points[0]), radius=0.3, space="MESH")  # break 1
    assert measure_edge(points=points.tolist(), space="MESH") == {"FINISHED"}
    profile = core_surface(obj).measure_along(points, 0.5, 0.3)
    stations = [item for item in obj.vg.measurements if item.edge_number == 1]
    assert len(stations) == profile.n_stations == len(obj.vg.measurements) - 1
    for item, m, arc in zip(stations, profile.stations, profile.arc_lengths, strict=True):
        numbers = exact(item)
        assert (numbers["angle"], numbers["fit"]) == (m.angle, m.fit_error)
        assert numbers["center"] == m.center.tolist()
        assert (numbers["arc_length"], numbers["spacing"]) == (arc, 0.5)
    assert {item.break_number for item in stations} == {2}  # its own break, its own colours
    assert obj.vg.break_number == 3
    edge = obj.vg.edges[0]
    assert (edge.number, edge.break_number, edge.n_stations) == (1, 2, profile.n_stations)
    numbers = exact(edge)
    assert numbers["mean"] == profile.mean and numbers["pooled_angle"] == profile.pooled_angle
    assert numbers["angles"] == profile.angles.tolist()
    assert numbers["points"] == points.tolist()
    # Each station is within 1° of the exact local angle of the ramp.
    exact_angles = shape.angle_at(np.array([exact(i)["center"] for i in stations]))
    assert np.abs(np.array([exact(i)["angle"] for i in stations]) - exact_angles).max() < 1.0
    # The same clicks in world space (the default, like vg.measure_xyz's) snap to the same
    # vertices: the same stations, bit for bit.
    first = [(exact(i)["angle"], exact(i)["center"]) for i in stations]
    assert measure_edge(points=world(points, obj).tolist()) == {"FINISHED"}
    again = [exact(item) for item in obj.vg.measurements if item.edge_number == 2]
    assert [(n["angle"], n["center"]) for n in again] == first


def test_stations_replay_with_measure_xyz(vg):
    obj, _ = ramp_object(location=(0.5, 0.25, -1.0), rotation=(0.0, 0.4, 0.1))
    measure_edge(spacing=0.75, radius=0.35, seg_param=1.5, space="MESH")
    stations = [exact(item) for item in obj.vg.measurements]
    for numbers in stations:
        bpy.ops.vg.measure_xyz(
            location=numbers["center"],
            radius=numbers["radius"],
            seg_param=numbers["lam"],
            space="MESH",
        )
    replayed = [exact(item) for item in obj.vg.measurements[len(stations) :]]
    for a, b in zip(stations, replayed, strict=True):
        assert (a["angle"], a["fit"], a["center"]) == (b["angle"], b["fit"], b["center"])


def test_plot_image_is_made_packed_and_saved(vg, tmp_path):
    from vg_addon import units
    from vg_addon.formats import profile_plot

    obj, _ = ramp_object()
    measure_edge()
    edge = obj.vg.edges[0]
    image = bpy.data.images[edge.plot]
    assert tuple(image.size) == (480, 240) and image.packed_file is not None
    numbers = exact(edge)
    expected = profile_plot.render_profile(
        numbers["arc_lengths"],
        numbers["angles"],
        units=units.SYMBOLS.get(obj.vg.unit, "m"),  # the Scan Units, else the scene's metre
        title="Ramp, edge 1",
        pooled=numbers["pooled_angle"],
    )
    path = tmp_path / "edge.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.read_homefile(use_empty=True)
    bpy.ops.wm.open_mainfile(filepath=str(path))
    edge = bpy.data.objects["Ramp"].vg.edges[0]
    image = bpy.data.images[edge.plot]
    pixels = np.empty(480 * 240 * 4, dtype=np.float32)
    image.pixels.foreach_get(pixels)
    rgba = np.round(pixels.reshape(240, 480, 4)[::-1] * 255).astype(np.uint8)
    assert np.array_equal(rgba, expected)  # the plot drawn from the recorded numbers
    # The panel's picture: drawn at the size the sidebar shows it and saved with the file (before:
    # Blender's own 128-pixel preview of the plot, stretched, its tick labels specks).
    preview = image.preview
    assert preview.is_image_custom and tuple(preview.image_size) == (256, 192)
    pixels = np.empty(256 * 192 * 4, dtype=np.float32)
    preview.image_pixels_float.foreach_get(pixels)
    shown = np.round(pixels.reshape(192, 256, 4)[::-1] * 255).astype(np.uint8)
    drawn = profile_plot.draw_profile(
        numbers["arc_lengths"], numbers["angles"], width=256, height=192
    )
    assert np.array_equal(shown, drawn)


def test_each_edge_shows_and_deletes_only_its_own_plot(vg, tmp_path):
    """Names are not identities. A duplicated object shares its edge's plot: deleting the copy's
    edge keeps the original's (before: removed for good). An object appended from another file,
    whose plot's name this file's object of the same name already holds, shows no plot rather
    than the other object's, and deleting its edge leaves that plot alone."""
    plots = importlib.import_module(f"{vg.__name__}.bridge.plots")
    obj, _ = ramp_object("Bone")
    measure_edge()
    original = bpy.data.images[obj.vg.edges[0].plot]
    original_name = original.name
    bpy.ops.object.select_all(action="DESELECT")
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.duplicate()
    copy = bpy.context.active_object
    assert copy is not obj and plots.plot_image(copy.vg.edges[0]) == original
    assert bpy.ops.vg.delete_edge() == {"FINISHED"}
    assert not copy.vg.edges and plots.plot_image(obj.vg.edges[0]) == original
    assert original.name in bpy.data.images

    other = tmp_path / "other.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(other), copy=True)
    bpy.data.objects.remove(copy)
    bpy.context.view_layer.objects.active = obj
    bpy.ops.vg.clear_measurements("EXEC_DEFAULT")
    assert original_name not in bpy.data.images  # no other edge showed it
    measure_edge(spacing=0.6)  # this file's Bone: another edge 1, whose plot takes the name
    mine = plots.plot_image(obj.vg.edges[0])
    with bpy.data.libraries.load(str(other), link=False) as (_source, target):
        target.objects = ["Bone"]
    appended = target.objects[0]
    bpy.context.scene.collection.objects.link(appended)
    assert appended.vg.edges[0].plot == mine.name  # the same name, another edge's plot
    assert plots.plot_image(appended.vg.edges[0]) is None
    bpy.context.view_layer.objects.active = appended
    assert bpy.ops.vg.delete_edge() == {"FINISHED"}
    assert plots.plot_image(obj.vg.edges[0]) == mine and mine.name in bpy.data.images


def test_refusals_record_nothing(vg):
    obj, _ = ramp_object()
    with pytest.raises(RuntimeError, match="could not be measured"):
        measure_edge(radius=0.001)
    with pytest.raises(RuntimeError, match="at least two points"):
        bpy.ops.vg.measure_edge(points="[[0, 0, 0]]", spacing=0.5, radius=0.3)
    with pytest.raises(RuntimeError, match="JSON"):
        bpy.ops.vg.measure_edge(points="start", spacing=0.5, radius=0.3)
    with pytest.raises(RuntimeError, match="finer than the mesh"):
        measure_edge(spacing=0.001)
    assert len(obj.vg.measurements) == 0 and len(obj.vg.edges) == 0
    assert len(bpy.data.images) == 0


def test_one_undo_removes_the_whole_profile(vg):
    ramp_object()
    bpy.ops.ed.undo_push(message="start")
    measure_edge("EXEC_DEFAULT", True)
    obj = bpy.data.objects["Ramp"]
    assert len(obj.vg.measurements) > 3 and len(obj.vg.edges) == 1
    bpy.ops.ed.undo()
    obj = bpy.data.objects["Ramp"]  # undo reloads the data
    assert len(obj.vg.measurements) == 0 and len(obj.vg.edges) == 0
    bpy.ops.ed.redo()
    obj = bpy.data.objects["Ramp"]
    assert len(obj.vg.edges) == 1


def test_delete_edge_removes_its_stations_only(vg):
    obj, _ = ramp_object()
    bpy.ops.vg.measure_xyz(location=(0.0, 0.0, 0.0), radius=0.3)
    measure_edge()
    measure_edge(points=[[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    first = obj.vg.edges[0].plot
    assert bpy.ops.vg.delete_edge(index=0) == {"FINISHED"}
    assert [e.number for e in obj.vg.edges] == [2]
    assert {item.edge_number for item in obj.vg.measurements} == {0, 2}
    assert first not in bpy.data.images


def changed_by_definition(obj) -> list[bool]:
    """Per edge: a station stale, or fewer or more stations than were measured (a plain walk over
    the measurements, the definition the stored flag must keep)."""
    flags = []
    for edge in obj.vg.edges:
        stations = [m for m in obj.vg.measurements if m.edge_number == edge.number]
        flags.append(len(stations) != edge.n_stations or any(m.stale for m in stations))
    return flags


def test_an_edge_is_flagged_once_a_station_is_deleted_or_stale_and_the_flag_is_kept(vg, tmp_path):
    """The list and panel warn from each edge's stored ``stations_changed`` (no walk over the
    measurements per redraw): it follows a station's deletion and its undo, an edit of the mesh,
    a save and reload, and is recomputed on load for a file saved without it."""
    obj, _ = ramp_object()
    measure_edge()
    measure_edge(points=[[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    flags = lambda o: [edge.stations_changed for edge in o.vg.edges]  # noqa: E731
    assert flags(obj) == changed_by_definition(obj) == [False, False]
    first = next(i for i, m in enumerate(obj.vg.measurements) if m.edge_number == 1)
    bpy.ops.ed.undo_push(message="before the deletion")
    assert bpy.ops.vg.delete_measurement("EXEC_DEFAULT", True, index=first) == {"FINISHED"}
    assert flags(obj) == changed_by_definition(obj) == [True, False]
    bpy.ops.ed.undo()
    obj = bpy.data.objects["Ramp"]
    assert flags(obj) == changed_by_definition(obj) == [False, False]
    obj.data.vertices[0].co.z += 0.25  # the mesh changed: every station is stale
    obj.data.update()
    assert bpy.ops.vg.repaint() == {"FINISHED"}
    assert flags(obj) == changed_by_definition(obj) == [True, True]
    path = tmp_path / "changed.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.open_mainfile(filepath=str(path))
    obj = bpy.data.objects["Ramp"]
    assert flags(obj) == [True, True]
    for edge in obj.vg.edges:  # as a file from before the flag was kept
        edge.stations_changed = False
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.open_mainfile(filepath=str(path))
    obj = bpy.data.objects["Ramp"]
    assert flags(obj) == changed_by_definition(obj) == [True, True]


def test_export_writes_station_rows_and_the_edge_file_and_import_rebuilds_the_edge(vg, tmp_path):
    obj, _ = ramp_object()
    measure_edge()
    path = tmp_path / "m.csv"
    assert bpy.ops.vg.export_csv(filepath=str(path)) == {"FINISHED"}
    rows = csvio.read_measurements_csv(path)
    stations = [exact(item) for item in obj.vg.measurements]
    assert [r.edge_number for r in rows] == [1] * len(stations)
    assert [r.arc_length for r in rows] == [s["arc_length"] for s in stations]
    assert {r.spacing for r in rows} == {0.5}
    (edge_row,) = csvio.read_edges_csv(csvio.edges_path_for(path))
    edge = exact(obj.vg.edges[0])
    assert (edge_row.mean, edge_row.pooled_angle, edge_row.n_stations) == (
        edge["mean"],
        edge["pooled_angle"],
        len(stations),
    )
    assert csvio.parse_points(edge_row.points) == [tuple(p) for p in edge["points"]]

    # Re-import on a copy: every station re-measured, grouped back into one edge.
    copy, _ = ramp_object("Ramp.copy")
    assert bpy.ops.vg.import_csv(filepath=str(path), ignore_mesh_names=True) == {"FINISHED"}
    again = [exact(item) for item in copy.vg.measurements]
    assert [a["angle"] for a in again] == [s["angle"] for s in stations]
    assert [a["arc_length"] for a in again] == [s["arc_length"] for s in stations]
    (rebuilt,) = copy.vg.edges
    assert {item.edge_number for item in copy.vg.measurements} == {rebuilt.number}
    numbers = exact(rebuilt)
    assert numbers["mean"] == edge["mean"] and numbers["angles"] == edge["angles"]
    assert numbers["pooled_angle"] == pytest.approx(edge["pooled_angle"], abs=1e-9)


def test_edge_session_event_translation(vg):
    from importlib import import_module

    edge_module = import_module(f"{vg.__name__}.operators.edge")
    translate = edge_module.translate_edge_event
    assert translate("LEFTMOUSE", "PRESS") == "click"
    assert translate("LEFTMOUSE", "RELEASE") == "ignore"
    assert translate("RET", "PRESS") == "confirm"
    assert translate("BACK_SPACE", "PRESS") == "undo"
    assert translate("Z", "PRESS", ctrl=True) == "undo"
    assert translate("ESC", "PRESS") == "cancel"
    assert translate("MIDDLEMOUSE", "PRESS") == "pass"
    assert translate("MOUSEMOVE", "NOTHING") == "pass"
    points = edge_module.parse_points_json(edge_module.format_points_json(np.array(POINTS) / 3.0))
    assert points.tolist() == (np.array(POINTS) / 3.0).tolist()


def test_world_points_on_a_scaled_object_are_measured_in_mesh_coordinates(vg):
    obj, _ = ramp_object(location=(1.0, 0.0, 0.0), scale=(2.0, 2.0, 2.0))
    points = world(np.array(POINTS), obj)
    measure_edge(points=points.tolist(), spacing=0.5, radius=0.3)  # mesh units
    local = local_points(obj).astype(np.float64).tolist()
    assert all(exact(i)["center"] in local for i in obj.vg.measurements)
    assert {exact(i)["radius"] for i in obj.vg.measurements} == {0.3}
    np.testing.assert_allclose(exact(obj.vg.edges[0])["points"], POINTS, atol=1e-12)


def test_each_side_of_a_curved_edge_is_painted_in_one_colour(vg):
    from bpy_helpers import colours

    from vg_addon import palette
    from vg_addon.synthetic_meshes import lens

    shape = lens(70.53, n_around=300)
    obj = mesh_object("Lens", shape.points, shape.triangles)
    rim = shape.points[shape.edge]
    measure_edge(points=rim[[0, 150, 299]].tolist(), spacing=0.1, radius=0.04)
    stations = [item for item in obj.vg.measurements if item.edge_number == 1]
    # The binormal turns over somewhere along the rim: some stations' "+" side is the lower cap.
    assert len({exact(item)["plus_left"] for item in stations}) == 2
    rgba = colours(obj)
    plus, minus = (np.asarray(c, dtype=np.float32) for c in palette.pair_linear(1))
    painted = ~np.all(np.isclose(rgba, palette.neutral_linear()), axis=1)
    upper = painted & (shape.points[:, 2] > 1e-9)
    lower = painted & (shape.points[:, 2] < -1e-9)
    for side in (upper, lower):
        assert len(np.unique(rgba[side], axis=0)) == 1  # one colour along the whole rim
    assert not np.array_equal(rgba[upper][0], rgba[lower][0])
    assert {tuple(rgba[upper][0]), tuple(rgba[lower][0])} == {tuple(plus), tuple(minus)}


def test_panel_shows_only_for_a_mesh_and_the_settings_have_lengths(vg):
    panel = bpy.types.VIEW3D_PT_vg_edges
    assert not panel.poll(bpy.context)  # no active mesh
    ramp_object()
    assert panel.poll(bpy.context)
    settings = bpy.context.scene.vg_settings
    assert settings.edge_spacing > 0
    # A length in the mesh's own units: the panel labels it with the object's Scan Units, not
    # the scene's (which measure Blender units).
    assert settings.bl_rna.properties["edge_spacing"].unit == "NONE"
    assert bpy.types.VG_OT_measure_edge.poll(bpy.context)
    assert not bpy.types.VG_OT_delete_edge.poll(bpy.context)  # no edge yet


def test_importing_an_edge_file_says_whether_its_edges_came_back(vg, tmp_path, capfd):
    """An edge file imported said how many edges it re-measured, not whether they came back as
    the file has them (before). The oracle: the file's own cells, edited. Two edges through the
    same points (two radii) are each compared with their own row."""
    measure_obj, _ = ramp_object()
    measure_edge()
    measure_edge(radius=0.4)
    path = tmp_path / "m.csv"
    bpy.ops.vg.export_csv(filepath=str(path))
    edge_file = csvio.edges_path_for(path)
    ramp_object("Ramp.copy")
    capfd.readouterr()
    assert bpy.ops.vg.import_csv(filepath=str(edge_file), ignore_mesh_names=True) == {"FINISHED"}
    said = capfd.readouterr()
    assert (
        "all 2 edges' stations, mean, min, max and pooled angle equal the file's exactly"
        in said.out + said.err
    )
    first, second = csvio.read_edges_csv(edge_file)
    assert first.points == second.points and first.mean != second.mean
    edited = tmp_path / "edited_edges.csv"
    more = dataclasses.replace(second, n_stations=second.n_stations + 1)
    csvio.write_edges_csv(edited, [first, more])
    ramp_object("Ramp.other")
    assert bpy.ops.vg.import_csv(filepath=str(edited), ignore_mesh_names=True) == {"FINISHED"}
    said = capfd.readouterr()
    assert (
        f"1 of 2 edges differ from the file's figures (row 3: stations "
        f"{second.n_stations + 1} → {second.n_stations})"
    ) in said.out + said.err
    assert measure_obj.vg.edges[1].n_stations == second.n_stations


def test_importing_an_edge_file_retraces_every_edge_or_none(vg, tmp_path):
    obj, _ = ramp_object()
    measure_edge(note="ridge A")
    measure_edge(points=[[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]], spacing=0.4, radius=0.25)
    path = tmp_path / "m.csv"
    bpy.ops.vg.export_csv(filepath=str(path))
    edge_file = csvio.edges_path_for(path)
    before = [exact(item) for item in obj.vg.measurements]

    copy, _ = ramp_object("Ramp.copy")
    assert bpy.ops.vg.import_csv(filepath=str(edge_file), ignore_mesh_names=True) == {"FINISHED"}
    assert [e.note for e in copy.vg.edges] == ["ridge A", ""]
    after = [exact(item) for item in copy.vg.measurements]
    assert [(a["angle"], a["arc_length"]) for a in after] == [
        (b["angle"], b["arc_length"]) for b in before
    ]
    assert [exact(e)["points"] for e in copy.vg.edges] == [exact(e)["points"] for e in obj.vg.edges]
    # An edge file of an earlier version: world-space points, no Coordinates column. Read as
    # world space and brought onto the moved object's mesh: the same stations.
    moved, _ = ramp_object("Moved", location=(1.0, 2.0, 3.0), rotation=(0.2, 0.0, 0.3))
    with open(edge_file, newline="", encoding="utf-8") as handle:
        table = list(csv.DictReader(handle))
    for row in table:
        row.pop("Coordinates")
        # Cells starting with "-" are written behind an apostrophe, which the reader removes.
        clicks = world(np.array(csvio.parse_points(row["Points"].removeprefix("'"))), moved)
        text = csvio.format_points(clicks)
        row["Points"] = "'" + text if text.startswith("-") else text
    old_file = tmp_path / "old_edges.csv"
    with open(old_file, "w", newline="", encoding="utf-8") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(table[0]))
        writer.writeheader()
        writer.writerows(table)
    assert bpy.ops.vg.import_csv(filepath=str(old_file), ignore_mesh_names=True) == {"FINISHED"}
    assert [(exact(a)["angle"], exact(a)["center"]) for a in moved.vg.measurements] == [
        (b["angle"], b["center"]) for b in before
    ]
    # Another object's name without Ignore Names: refused, nothing recorded.
    other, _ = ramp_object("Other")
    with pytest.raises(RuntimeError, match="names the mesh 'Ramp'"):
        bpy.ops.vg.import_csv(filepath=str(edge_file))
    assert len(other.vg.edges) == 0 and len(other.vg.measurements) == 0
    # Points picked on another mesh (here 3 units above this one): refused as the batch's
    # --edges refuses them, not snapped to the nearest vertex and measured; nothing recorded.
    vertices = np.array([v.co for v in other.data.vertices], dtype=np.float64)

    def lift(row):
        lifted = np.array(csvio.parse_points(row["Points"].removeprefix("'")))
        lifted[:, 2] += 3.0
        assert np.linalg.norm(vertices[:, None] - lifted[None], axis=2).min() > 2.9
        text = csvio.format_points(lifted)
        row["Points"] = "'" + text if text.startswith("-") else text

    far_file = edited_csv(edge_file, tmp_path / "far_edges.csv", lift)
    with pytest.raises(RuntimeError, match="from the mesh"):
        bpy.ops.vg.import_csv(filepath=str(far_file), ignore_mesh_names=True)
    assert len(other.vg.edges) == 0 and len(other.vg.measurements) == 0
    # A row whose error says the run that wrote it could not measure it (a batch run's failed
    # edge; here one that would be refused if measured) is passed over; the rest is imported.

    def fail_the_second(row):
        if row["Edge #"] == "2":
            lift(row)
            row["error"] = "edge not measured: no vertex within the radius"

    failed_file = edited_csv(edge_file, tmp_path / "failed_edges.csv", fail_the_second)
    assert bpy.ops.vg.import_csv(filepath=str(failed_file), ignore_mesh_names=True) == {"FINISHED"}
    assert [e.note for e in other.vg.edges] == ["ridge A"]
    first_edge = [m for m in obj.vg.measurements if m.edge_number == obj.vg.edges[0].number]
    assert [exact(a)["angle"] for a in other.vg.measurements] == [
        exact(b)["angle"] for b in first_edge
    ]
    none_file = edited_csv(
        edge_file, tmp_path / "none_edges.csv", lambda row: row.update(error="x")
    )
    with pytest.raises(RuntimeError, match="could not measure any of its 2 edge"):
        bpy.ops.vg.import_csv(filepath=str(none_file), ignore_mesh_names=True)
    assert len(other.vg.edges) == 1


def test_stations_take_the_panels_rule_and_stability_and_an_import_the_panels_rule(vg, tmp_path):
    # A concave crease: the paper's rule reads it about 134°, the default rule 100°.
    shape = wedge(100.0, half_width=2.0, n=40, irregular=True, concave=True)
    obj = mesh_object("Concave", shape.points, shape.triangles)
    settings = bpy.context.scene.vg_settings
    settings.rule, settings.stability = "paper", True
    points = [[-1.5, 0.0, 0.0], [1.5, 0.0, 0.0]]
    assert measure_edge(points=points, spacing=0.5, radius=0.4, space="MESH") == {"FINISHED"}
    surface = core_surface(obj)
    stations = [exact(item) for item in obj.vg.measurements]
    assert len(stations) >= 5
    for numbers in stations:
        # Oracle: a single measurement at the station's centre with the panel's settings.
        alone = surface.measure(numbers["center"], 0.4, rule="paper", stability=True)
        assert numbers["rule"] == "paper" and numbers["angle"] == alone.angle > 120.0
        assert numbers["stability"]["spread"] == alone.stability.spread
    path = tmp_path / "m.csv"
    bpy.ops.vg.export_csv(filepath=str(path))
    # The edge file records each edge's rule: an import measures with it, whatever the panel's.
    settings.stability = False
    settings.rule = "refined"
    edge_file = csvio.edges_path_for(path)
    copy = mesh_object("Replayed", shape.points, shape.triangles)
    assert bpy.ops.vg.import_csv(filepath=str(edge_file), ignore_mesh_names=True) == {"FINISHED"}
    again = [exact(item) for item in copy.vg.measurements]
    assert [(a["rule"], a["angle"]) for a in again] == [("paper", s["angle"]) for s in stations]
    # An edge file of an earlier version (no Rule column): an import takes the panel's Rule.
    older = edited_csv(edge_file, tmp_path / "older_edges.csv", drop=["Rule"])
    for rule, name in (("paper", "Paper"), ("refined", "Refined")):
        settings.rule = rule
        copy = mesh_object(name, shape.points, shape.triangles)
        assert bpy.ops.vg.import_csv(filepath=str(older), ignore_mesh_names=True) == {"FINISHED"}
        again = [exact(item) for item in copy.vg.measurements]
        assert {a["rule"] for a in again} == {rule}
        assert all(a["stability"] is None for a in again)
        if rule == "paper":
            assert [a["angle"] for a in again] == [s["angle"] for s in stations]
        else:
            assert all(abs(a["angle"] - 100.0) < 0.01 for a in again)


def rim_object(shared_data):
    """The intersecting spheres and the points of their rim, a loop, as the core finds it."""
    from vg_addon.formats.meshio import read_mesh
    from vg_addon.method.break_edges import find_break_edges

    mesh = read_mesh(shared_data / "IntersectingSpheres.ply")
    (rim,) = find_break_edges(Surface(mesh.points, mesh.triangles)).candidates
    assert rim.closed

    def copy(name):
        return mesh_object(name, mesh.points, mesh.triangles)

    return copy, rim.waypoint_points.tolist(), 0.1, 0.06


def ramp_copies(shared_data):
    shape = varying_wedge(80.0, 120.0, half_width=2.0, depth=1.0, n=20)

    def copy(name):
        return mesh_object(name, shape.points, shape.triangles)

    # Bent, so the centres are more than the two ends: the edge must pass through each.
    return copy, [[-1.5, 0.01, 0.0], [-0.2, -0.01, 0.0], [1.5, 0.0, 0.0]], 0.37, 0.3


@pytest.mark.parametrize("shape", [ramp_copies, rim_object], ids=["open ramp", "rim loop"])
def test_an_edge_rebuilt_from_its_stations_replays_through_them(vg, tmp_path, shared_data, shape):
    # Export, import the station CSV, export again, replay that edges CSV: the edge goes
    # through every station centre of the first measurement (the core's vertices), with as
    # many stations. The rebuilt edge once kept only its first and last centre as its points:
    # the rim's loop replayed as one station.
    copy, points, spacing, radius = shape(shared_data)
    obj = copy("Edge")
    assert measure_edge(points=points, spacing=spacing, radius=radius) == {"FINISHED"}
    (first,) = [exact(e) for e in obj.vg.edges]
    centres = [tuple(exact(item)["center"]) for item in obj.vg.measurements]
    assert len(centres) > 3
    stations_csv, again_csv = tmp_path / "m.csv", tmp_path / "again.csv"
    assert bpy.ops.vg.export_csv(filepath=str(stations_csv)) == {"FINISHED"}

    copy("Edge.stations")
    assert bpy.ops.vg.import_csv(filepath=str(stations_csv), ignore_mesh_names=True) == {"FINISHED"}
    assert bpy.ops.vg.export_csv(filepath=str(again_csv)) == {"FINISHED"}
    (row,) = csvio.read_edges_csv(csvio.edges_path_for(again_csv))
    rebuilt_points = csvio.parse_points(row.points)
    # In order, the loop closed again on its first centre.
    closed = shape is rim_object
    assert rebuilt_points == centres + centres[:1] if closed else rebuilt_points == centres

    replay = copy("Edge.replay")
    edges_csv = csvio.edges_path_for(again_csv)
    assert bpy.ops.vg.import_csv(filepath=str(edges_csv), ignore_mesh_names=True) == {"FINISHED"}
    (replayed,) = [exact(e) for e in replay.vg.edges]
    path = {tuple(p) for p in replayed["path"]}
    assert all(c in path for c in centres)
    assert len(replayed["angles"]) == len(first["angles"])
    assert replayed["mean"] == pytest.approx(first["mean"], abs=0.5)


@pytest.mark.parametrize("closed", [False, True], ids=["open, ending next to its start", "loop"])
def test_the_station_csv_says_which_edge_is_a_loop_and_the_import_rebuilds_it_so(
    vg, tmp_path, closed
):
    # An edge rebuilt from a station CSV is the loop or the open path that was measured, as
    # each station's Edge Closed says. Before that column the import judged a loop by how near
    # the last station is to the first, and closed an open edge that stops one vertex short
    # of its start.
    import importlib

    station_points = importlib.import_module(f"{vg.__name__}.bridge.edges").station_points
    shape = lens(70.53)
    rim = shape.points[shape.edge]
    n = len(rim)
    ends = [0, n // 3, 2 * n // 3, 0 if closed else n - 1]
    obj = mesh_object("Lens", shape.points, shape.triangles)
    assert measure_edge(points=rim[ends].tolist(), spacing=0.1, radius=0.08) == {"FINISHED"}
    centres = [tuple(exact(item)["center"]) for item in obj.vg.measurements]
    stations_csv, again_csv = tmp_path / "m.csv", tmp_path / "again.csv"
    assert bpy.ops.vg.export_csv(filepath=str(stations_csv)) == {"FINISHED"}
    rows = csvio.read_measurements_csv(stations_csv)
    assert len(rows) == len(centres) > 30 and {row.edge_closed for row in rows} == {closed}
    loop = [*centres, centres[0]]
    if not closed:
        # The case the judging got wrong: this open edge's ends are closer than a spacing.
        assert station_points(centres, rows[0].arc_length, rows[0].spacing) == loop

    mesh_object("Lens.stations", shape.points, shape.triangles)
    assert bpy.ops.vg.import_csv(filepath=str(stations_csv), ignore_mesh_names=True) == {"FINISHED"}
    assert bpy.ops.vg.export_csv(filepath=str(again_csv)) == {"FINISHED"}
    (row,) = csvio.read_edges_csv(csvio.edges_path_for(again_csv))
    assert csvio.parse_points(row.points) == (loop if closed else centres)
    assert {r.edge_closed for r in csvio.read_measurements_csv(again_csv)} == {closed}


def test_the_panel_shows_the_study_figures_of_the_edge(vg, tmp_path):
    """Issue 22, item 5, in the Edge Profiles panel: median, range, arc and chord length and arc
    angle, as the stations' own angles and centres give them (oracle: the standard library and
    NumPy's SVD on the stored stations), lengths in the Scan Units; an older record says they
    are not recorded."""
    import importlib
    import itertools
    import math
    import statistics

    codec = importlib.import_module(f"{vg.__name__}.vg_addon.formats.record_codec")
    panels = importlib.import_module(f"{vg.__name__}.ui.panels")
    assert panels.study_texts is codec.study_texts  # what the panel draws its rows with
    obj, _ = ramp_object()
    assert measure_edge() == {"FINISHED"}
    (edge,) = obj.vg.edges
    stations = [exact(m) for m in obj.vg.measurements if m.edge_number == edge.number]
    angles = [s["angle"] for s in stations]
    centres = [s["center"] for s in stations]
    arc = sum(math.dist(a, b) for a, b in itertools.pairwise(centres))

    def axis(points):
        points = np.asarray(points, dtype=np.float64)
        return np.linalg.svd(points - points.mean(axis=0), full_matrices=False)[2][0]

    cosine = abs(float(np.dot(axis(centres), axis(local_points(obj)))))
    arc_angle = math.degrees(math.acos(min(cosine, 1.0)))
    median, spread = statistics.median(angles), max(angles) - min(angles)
    rows = dict(codec.study_texts(exact(edge), "mm"))
    assert rows == {
        "Median, range": f"{median:.2f}°, {spread:.2f}°",
        "Arc, chord": f"{arc:.4g}, {math.dist(centres[0], centres[-1]):.4g} mm",
        "Arc angle": f"{arc_angle:.2f}°",
    }
    older = {k: v for k, v in exact(edge).items() if k not in codec.STUDY_FIGURES}
    assert codec.study_texts(older, "mm") == [
        ("Study figures", "not recorded (an older version): measure again")
    ]


def test_an_export_of_all_objects_imported_on_one_keeps_each_objects_edges_apart(vg, tmp_path):
    """Edge numbers start at 1 on every object: the stations of A's edge 1 and B's edge 1 are
    two edges on the object they are imported on, each as it was (before: one edge of both)."""
    first, _ = ramp_object("A")
    measure_edge()
    second, _ = ramp_object("B")
    measure_edge(spacing=0.4)
    path = tmp_path / "both.csv"
    assert bpy.ops.vg.export_csv(filepath=str(path), all_objects=True) == {"FINISHED"}
    target, _ = ramp_object("C")
    assert bpy.ops.vg.import_csv(filepath=str(path), ignore_mesh_names=True) == {"FINISHED"}
    assert len(target.vg.edges) == 2
    for edge, source in zip(target.vg.edges, (first, second), strict=True):
        (original,) = source.vg.edges
        assert edge.n_stations == original.n_stations
        keys = ("arc_lengths", "angles", "spacing")
        assert [exact(edge)[k] for k in keys] == [exact(original)[k] for k in keys]


def test_the_edge_file_says_which_edges_have_stale_stations(vg, tmp_path):
    """After the mesh changed under one edge's stations, their rows say Stale and so does that
    edge's row of the edge file (before: the edge row looked as before); an edge file of an
    earlier version, without the column, reads "not known"."""
    obj, _ = ramp_object()
    measure_edge()
    measure_edge(points=[[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]], spacing=0.4, radius=0.25)
    path = tmp_path / "m.csv"
    bpy.ops.vg.export_csv(filepath=str(path))
    assert [e.stale for e in csvio.read_edges_csv(csvio.edges_path_for(path))] == [False, False]
    obj.data.vertices[0].co.z += 0.5  # a far corner: every record's geometry changed
    obj.data.update()
    bpy.ops.vg.export_csv(filepath=str(path))
    rows = csvio.read_measurements_csv(path)
    edges = csvio.read_edges_csv(csvio.edges_path_for(path))
    assert all(r.stale for r in rows) and [e.stale for e in edges] == [True, True]
    older = edited_csv(csvio.edges_path_for(path), tmp_path / "old_edges.csv", drop=["Stale"])
    assert [e.stale for e in csvio.read_edges_csv(older)] == [None, None]


def test_a_one_station_edge_records_no_sd_and_exports_a_blank_cell(vg, tmp_path):
    """An edge shorter than its spacing has one station: its SD was exported and reported as
    0°, as if the edge were known to be uniform. Now the record holds none and the edges CSV
    cell is blank."""
    obj, _ = ramp_object()
    assert measure_edge(points=[[-0.3, 0.0, 0.0], [0.3, 0.0, 0.0]], spacing=2.0) == {"FINISHED"}
    (edge,) = obj.vg.edges
    assert edge.n_stations == 1 and exact(edge)["std"] is None
    path = tmp_path / "m.csv"
    assert bpy.ops.vg.export_csv(filepath=str(path)) == {"FINISHED"}
    with open(csvio.edges_path_for(path), newline="") as handle:
        (row,) = list(csv.DictReader(handle))
    assert row["SD Angle"] == "" and float(row["Mean Angle"]) == exact(edge)["mean"]
