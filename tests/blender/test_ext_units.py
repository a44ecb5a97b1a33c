"""Scan Units (issue 20, item 7): the unit of an object's coordinates, said once per object or
guessed from its size, shown in the panel, the drag header and the CSV; stored numbers never
change."""

import functools
import importlib
import json

import bpy
import numpy as np
from bpy_helpers import colours, exact, wedge_object

from vg_addon.formats import csvio


def modules(vg):
    return (
        importlib.import_module(f"{vg.__name__}.ui.panels"),
        importlib.import_module(f"{vg.__name__}.operators.drag"),
    )


def measured(vg, scale, name="Wedge"):
    """A 100° wedge whose coordinates are ``scale`` times the unit wedge's (2 units across at
    scale 1), measured twice at radius ``0.4 * scale``."""
    obj = wedge_object(100.0, name)
    points = np.empty(len(obj.data.vertices) * 3, dtype=np.float32)
    obj.data.vertices.foreach_get("co", points)
    obj.data.vertices.foreach_set("co", points * np.float32(scale))
    obj.data.update()
    bpy.context.view_layer.update()
    for x in (0.0, 0.3):
        bpy.ops.vg.measure_xyz(location=(x * scale, 0.0, 0.0), radius=0.4 * scale)
    return obj


def lengths_in(panels, obj):
    rows = panels.selected_rows(obj.vg.measurements[0], bpy.context.scene)
    return next(text for label, text in rows if label == "Lengths in")


def test_a_scan_tens_of_units_across_is_guessed_millimetres_and_shown_so(vg, tmp_path):
    panels, drag = modules(vg)
    obj = measured(vg, 15.0)  # 30 units across: a 30 mm flake
    assert (obj.vg.unit, obj.vg.unit_guessed, obj.vg.unit_chosen) == ("MM", True, False)
    assert lengths_in(panels, obj) == "mm"
    assert drag.format_length(bpy.context.scene, 6.0, obj) == "6 mm"
    path = tmp_path / "mm.csv"
    bpy.ops.vg.export_csv(filepath=str(path))
    rows = csvio.read_measurements_csv(path)
    assert [r.units for r in rows] == ["mm", "mm"]
    assert [r.radius for r in rows] == [6.0, 6.0]  # the stored number, not converted


def test_a_small_mesh_is_guessed_metres_and_a_chosen_unit_is_never_replaced(vg):
    panels, _drag = modules(vg)
    small = measured(vg, 0.2, "Small")  # 0.4 units across
    assert small.vg.unit == "M" and small.vg.unit_guessed
    chosen = wedge_object(100.0, "Chosen")
    chosen.vg.unit = "IN"  # as the panel's menu sets it
    assert chosen.vg.unit_chosen and not chosen.vg.unit_guessed
    bpy.ops.vg.measure_xyz(location=(0.0, 0.0, 0.0), radius=0.4)
    assert chosen.vg.unit == "IN" and lengths_in(panels, chosen) == "in"
    small.vg.unit = "CM"  # changing a guess: only the label changes
    assert not small.vg.unit_guessed and lengths_in(panels, small) == "cm"
    assert exact(small.vg.measurements[0])["radius"] == 0.08  # as typed, unchanged


def test_a_scene_with_its_own_units_is_not_second_guessed(vg):
    """An old file, or a scene set up in millimetres: Scene Units stay, shown as before."""
    panels, drag = modules(vg)
    units = bpy.context.scene.unit_settings
    units.system, units.scale_length, units.length_unit = "METRIC", 0.001, "MILLIMETERS"
    obj = measured(vg, 15.0)
    assert (obj.vg.unit, obj.vg.unit_guessed) == ("SCENE", False)
    assert lengths_in(panels, obj) == "BU (1 BU = 0.001 m)"
    assert drag.format_length(bpy.context.scene, 2.5, obj).replace(" ", "") == "2.5mm"


def test_the_csv_round_trip_keeps_the_units_and_the_colours(vg, tmp_path):
    """Export from a scan said to be in centimetres, edit one row's Colors to its pair the other
    way round, import on a fresh copy (whose guess from its size is mm): the copy takes the
    file's cm, the same numbers bit for bit, and paints that row's sides the other way round."""
    obj = measured(vg, 15.0)
    obj.vg.unit = "CM"
    path = tmp_path / "cm.csv"
    bpy.ops.vg.export_csv(filepath=str(path))
    text = path.read_text(encoding="utf-8")
    first = csvio.read_measurements_csv(path)[0].colors
    plus, minus = first.split("/")
    edited = path.with_name("edited.csv")
    edited.write_text(text.replace(first, f"{minus}/{plus}", 1), encoding="utf-8")
    copy = obj.copy()
    copy.data = obj.data.copy()
    copy.vg.measurements.clear()
    bpy.context.scene.collection.objects.link(copy)
    for target, source in ((obj, path), (copy, edited)):
        bpy.context.view_layer.objects.active = target
        if target is copy:
            copy.vg.unit = "SCENE"
            copy.vg.unit_chosen = False
        else:
            bpy.ops.vg.clear_measurements()
        assert bpy.ops.vg.import_csv(filepath=str(source), ignore_mesh_names=True) == {"FINISHED"}
    assert copy.vg.unit == "CM" and not copy.vg.unit_guessed
    for a, b in zip(obj.vg.measurements, copy.vg.measurements, strict=True):
        numbers_a, numbers_b = exact(a), exact(b)
        swapped = numbers_b.pop("painted_swapped", False) != numbers_a.pop("painted_swapped", False)
        assert numbers_a == numbers_b
        assert swapped == (a.number == obj.vg.measurements[0].number)
    assert (
        copy.vg.measurements[0].colors.split("/") == obj.vg.measurements[0].colors.split("/")[::-1]
    )
    # The painted sides follow: where the original shows one colour, the copy shows the other.
    painted_a, painted_b = colours(obj), colours(copy)
    differ = np.any(painted_a[:, :3] != painted_b[:, :3], axis=1)
    assert differ.sum() > 20


def test_the_edge_file_and_a_file_with_failed_rows_carry_the_scan_units_on_import(vg, tmp_path):
    """The edge file says the object's Scan Units as the measurement file does (before: the
    scene's Blender units), and each import takes them; so does a measurement file holding a
    batch run's failed row (an error, no coordinates), which before kept the guess."""
    obj = measured(vg, 15.0)
    obj.vg.unit = "CM"
    points = json.dumps([[-9.0, 0.0, 0.0], [9.0, 0.0, 0.0]])
    assert bpy.ops.vg.measure_edge(points=points, spacing=3.0, radius=6.0) == {"FINISHED"}
    path = tmp_path / "cm.csv"
    bpy.ops.vg.export_csv(filepath=str(path))
    rows = csvio.read_measurements_csv(path)
    edge_file = csvio.edges_path_for(path)
    assert {r.units for r in rows} == {e.units for e in csvio.read_edges_csv(edge_file)} == {"cm"}
    failed = csvio.MeasurementRow(
        mesh_name=obj.name, radius=6.0, lam=2.0, units="cm", error="edge not measured: why"
    )
    with_failed = tmp_path / "with_failed.csv"
    csvio.write_measurements_csv(with_failed, [*rows, failed])
    for source in (edge_file, with_failed):
        copy = measured(vg, 15.0, f"Copy of {source.stem}")
        copy.vg.measurements.clear()
        assert copy.vg.unit == "MM" and copy.vg.unit_guessed
        assert bpy.ops.vg.import_csv(filepath=str(source), ignore_mesh_names=True) == {"FINISHED"}
        assert copy.vg.unit == "CM", source.name


def test_a_scaled_object_without_scan_units_is_labelled_in_mesh_units(vg, tmp_path):
    """Scene in millimetres (Unit Scale 0.001, so nothing is guessed), the object shown at a
    tenth: one mesh unit is 0.1 mm. The panel's labels, Selected Measurement, the plot's axis
    and the drag header said "mm" and "BU (1 BU = 0.001 m)" (before), while the CSV said
    "mesh units (1 unit = 0.0001 m ...)". The oracle: the CSV's Units and the transform."""
    panels, drag = modules(vg)
    records = importlib.import_module(f"{vg.__name__}.bridge.records")
    units = bpy.context.scene.unit_settings
    units.system, units.scale_length, units.length_unit = "METRIC", 0.001, "MILLIMETERS"
    obj = wedge_object(100.0)
    obj.scale = (0.1, 0.1, 0.1)
    bpy.context.view_layer.update()
    bpy.ops.vg.measure_xyz(location=(0.0, 0.0, 0.0), space="MESH", radius=0.4)
    assert obj.vg.unit == "SCENE"  # the scene names its unit: no guess
    path = tmp_path / "scaled.csv"
    bpy.ops.vg.export_csv(filepath=str(path))
    (row,) = csvio.read_measurements_csv(path)
    assert row.units.startswith("mesh units (1 unit = 0.0001 m")
    assert records.unit_symbol(obj, bpy.context.scene) == "mesh units"
    assert lengths_in(panels, obj) == row.units
    assert drag.mesh_length_text(bpy.context.scene, 0.4, obj) == "0.4 mesh units"
    obj.scale = (1.0, 1.0, 1.0)  # at its own size the scene's unit measures it
    bpy.context.view_layer.update()
    assert records.unit_symbol(obj, bpy.context.scene) == "mm"
    assert lengths_in(panels, obj) == "BU (1 BU = 0.001 m)"


def _profiled(obj):
    """``obj``'s edge along the wedge's crease, profiled by the extension's operator."""
    bpy.ops.vg.measure_edge(
        points=json.dumps([[-0.6, 0.0, 0.0], [0.6, 0.0, 0.0]]), space="MESH", spacing=0.2,
        radius=0.4,
    )  # fmt: skip
    return obj.vg.edges[0]


def _drawn_with(plots, obj, edge, unit):
    """The plot of ``edge`` with ``unit`` on its axis, drawn by the plotting module itself
    from the edge's own numbers (the oracle)."""
    from vg_addon.formats import profile_plot
    from vg_addon.formats.record_codec import exact_numbers

    numbers = exact_numbers(edge)
    width, height = plots.PLOT_SIZE
    rgba = profile_plot.render_profile(
        numbers["arc_lengths"], numbers["angles"], width=width, height=height, units=unit,
        title=f"{obj.name}, edge {edge.number}", pooled=numbers.get("pooled_angle"),
    )  # fmt: skip
    return rgba[::-1].ravel().astype(np.int64)


def _shown(plots, edge):
    """The pixels of the plot image ``edge`` shows."""
    image = plots.plot_image(edge)
    pixels = np.empty(len(image.pixels), dtype=np.float32)
    image.pixels.foreach_get(pixels)
    return np.rint(pixels * 255.0).astype(np.int64)  # the image keeps bytes


def test_choosing_scan_units_draws_the_edges_plots_again_naming_them(vg):
    """The plot's axis names the unit; choosing Scan Units in the panel kept the plot drawn
    with the guessed one (before). The oracle: the plot drawn from the edge's own numbers with
    each unit by the plotting module."""
    plots = importlib.import_module(f"{vg.__name__}.bridge.plots")
    from vg_addon.units import SYMBOLS

    obj = wedge_object(100.0)
    edge = _profiled(obj)
    drawn_with = functools.partial(_drawn_with, plots, obj, edge)
    shown = functools.partial(_shown, plots, edge)

    guessed = obj.vg.unit
    assert obj.vg.unit_guessed and np.array_equal(shown(), drawn_with(SYMBOLS[guessed]))
    obj.vg.unit = "CM"  # as the panel's menu sets it
    assert np.array_equal(shown(), drawn_with("cm"))
    assert not np.array_equal(shown(), drawn_with(SYMBOLS[guessed]))
    assert len([i for i in bpy.data.images if plots.PLOT_KEY in i]) == 1  # replaced, not added
    kept = plots.plot_image(edge)
    obj.vg.unit = "CM"  # the same unit chosen again: nothing to draw
    assert plots.plot_image(edge) == kept and kept.name in bpy.data.images


def test_scaling_the_object_or_changing_the_scenes_units_draws_its_plots_again(vg):
    """A plot's axis names the unit its numbers are in: with Scan Units "Scene", the scene's
    unit, and "mesh units" for a scaled object. After the scene's unit scale changed, or the
    object was scaled, the plot kept naming the unit it was drawn with (before). The watcher
    draws it again once the edits pause; the oracle: the plot drawn with each unit by the
    plotting module."""
    plots = importlib.import_module(f"{vg.__name__}.bridge.plots")
    watch = importlib.import_module(f"{vg.__name__}.bridge.watch")
    units = bpy.context.scene.unit_settings
    units.system, units.scale_length, units.length_unit = "METRIC", 0.001, "MILLIMETERS"
    obj = wedge_object(100.0)
    bpy.context.view_layer.update()
    edge = _profiled(obj)
    assert obj.vg.unit == "SCENE"  # the scene names its unit: no guess
    drawn_with = functools.partial(_drawn_with, plots, obj, edge)
    assert np.array_equal(_shown(plots, edge), drawn_with("mm"))

    units.scale_length = 1.0
    bpy.context.view_layer.update()
    watch._check_pending()  # the watcher's timer, once the edits pause (timers do not run in bpy)
    assert np.array_equal(_shown(plots, edge), drawn_with("m"))

    obj.scale = (2.0, 2.0, 2.0)
    bpy.context.view_layer.update()
    watch._check_pending()
    assert np.array_equal(_shown(plots, edge), drawn_with("mesh units"))
    assert len([i for i in bpy.data.images if plots.PLOT_KEY in i]) == 1  # replaced, not added
    kept = plots.plot_image(edge)
    obj.location = (1.0, 0.0, 0.0)  # a move: the unit stays, nothing is drawn again
    bpy.context.view_layer.update()
    watch._check_pending()
    assert plots.plot_image(edge) == kept


def test_an_undo_to_a_step_stored_before_the_plots_were_drawn_again_draws_them_again(vg):
    """The watcher draws the plots again after the edit's undo step was stored: that step holds
    the new scale with the old plots. Undoing back to it (a later step undone) showed plots
    naming the scene's unit on a scaled object (before); the undo now has them checked."""
    plots = importlib.import_module(f"{vg.__name__}.bridge.plots")
    watch = importlib.import_module(f"{vg.__name__}.bridge.watch")
    units = bpy.context.scene.unit_settings
    units.system, units.scale_length, units.length_unit = "METRIC", 1.0, "METERS"
    wedge_object(100.0)
    bpy.context.view_layer.update()
    bpy.context.active_object.vg.unit = "SCENE"  # the unit the scene says
    _profiled(bpy.context.active_object)

    def current():
        return bpy.data.objects["Wedge"]  # undo reloads the data: old references go stale

    def drawn_in(unit) -> bool:
        edge = current().vg.edges[0]
        return np.array_equal(_shown(plots, edge), _drawn_with(plots, current(), edge, unit))

    assert drawn_in("m")
    bpy.ops.ed.undo_push(message="profiled")
    current().scale = (2.0, 2.0, 2.0)
    bpy.context.view_layer.update()
    bpy.ops.ed.undo_push(message="scaled")  # stored before the watcher's timer runs
    watch._check_pending()  # the timer (timers do not run in bpy)
    assert drawn_in("mesh units")
    current().location = (0.5, 0.0, 0.0)
    bpy.context.view_layer.update()
    bpy.ops.ed.undo_push(message="moved")
    watch._check_pending()
    bpy.ops.ed.undo()  # back to "scaled": scale 2, with the plot stored then
    assert tuple(current().scale) == (2.0, 2.0, 2.0)
    assert drawn_in("m")  # the plot the step stored
    watch._check_pending()
    assert drawn_in("mesh units")
