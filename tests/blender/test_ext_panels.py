"""What the sidebar shows: the list row texts, the Selected panel's exact numbers, and the break
counter after recorded breaks arrive from a CSV import or a batch run."""

import importlib

import bpy
import numpy as np
import pytest
from bpy_helpers import batch, exact, wedge_object
from test_ext_csv import MESHLAB_HEADER, meshlab_row

# A centre with many digits: a wedge moved so its crease point is at these (inexact) coordinates.
OFFSET = (-7.098512345, 3.1234567891, 0.70710678118)


@pytest.fixture
def panels(vg):
    return importlib.import_module(f"{vg.__name__}.ui.panels")


@pytest.fixture
def lists(vg):
    return importlib.import_module(f"{vg.__name__}.ui.lists")


def measured(obj=None, at=OFFSET):
    obj = obj or wedge_object(100.0, location=at)
    bpy.ops.vg.measure_xyz(location=at, radius=0.5)
    return obj, obj.vg.measurements[-1]


def mark_stale(obj):
    """Edit the mesh (a move would not do: measurements are in mesh coordinates)."""
    co = np.empty(len(obj.data.vertices) * 3, dtype=np.float32)
    obj.data.vertices.foreach_get("co", co)
    obj.data.vertices.foreach_set("co", co * np.float32(1.01))
    obj.data.update()
    bpy.context.view_layer.update()
    bpy.ops.vg.repaint()
    assert all(item.stale for item in obj.vg.measurements)


def test_list_row_starts_with_the_angle_and_stale_rows_keep_their_number(vg, lists):
    obj, _ = measured()
    bpy.ops.vg.next_break()
    _, second = measured(obj)
    stored = exact(second)["angle"]
    assert lists.row_texts(second) == (f"{stored:.2f}°", "#2")
    assert abs(float(lists.row_texts(second)[0][:-1]) - stored) <= 0.005
    mark_stale(obj)
    assert [lists.row_texts(i)[1] for i in obj.vg.measurements] == ["#1", "#2"]


def selected_value(rows, label, axis=None):
    """The text of the row called ``label`` (for vectors: of its ``axis`` component)."""
    texts = [text for name, text in rows if name == label]
    if axis is None:
        (text,) = texts
        return text
    index = next(i for i, (name, _) in enumerate(rows) if name == label)
    text = rows[index + "XYZ".index(axis)][1]
    assert text.startswith(f"{axis}  ")
    return text[3:]


def test_selected_panel_shows_every_number_exactly_as_stored(vg, panels):
    bpy.context.scene.unit_settings.system = "METRIC"
    bpy.context.scene.unit_settings.scale_length = 0.001
    _, item = measured()
    numbers = exact(item)
    rows = panels.selected_rows(item, bpy.context.scene)
    # Every text reads back to the stored float64, bit for bit (the oracle: the stored JSON).
    assert float(selected_value(rows, "Angle").removesuffix("°")) == numbers["angle"]
    for label, key in (
        ("Fit error", "fit"),
        ("Fit error +", "fit_plus"),
        ("Fit error −", "fit_minus"),
        ("Radius", "radius"),
        ("λ (SegParam)", "lam"),
        ("Snapped", "snap_distance"),
    ):
        assert float(selected_value(rows, label)) == numbers[key], label
    for label, key in (
        ("Centre", "center"),
        ("Requested", "requested"),
        ("Normal +", "normal_plus"),
        ("Normal −", "normal_minus"),
    ):
        for i, axis in enumerate("XYZ"):
            assert float(selected_value(rows, label, axis)) == numbers[key][i], (label, axis)
    # The centre is a vertex of the moved wedge: far more digits than a rounded field shows.
    assert len(selected_value(rows, "Centre", "X")) > 8
    assert selected_value(rows, "Lengths in") == "BU (1 BU = 0.001 m)"
    assert selected_value(rows, "Number") == f"{item.number}, break {item.break_number}"
    assert selected_value(rows, "Vertices") == (
        f"{item.n_vertices} ({item.n_plus} +, {item.n_minus} −)"
    )


def test_csv_import_moves_the_current_break_past_the_imported_ones(vg, tmp_path):
    obj = wedge_object(100.0)
    rows = [
        meshlab_row("Wedge", 0.0, 0.0, 0.0, 0.5, 2, number=1, break_number=3),
        meshlab_row("Wedge", 0.3, 0.0, 0.0, 0.3, 2, number=2, break_number=7),
        meshlab_row("Wedge", -0.3, 0.0, 0.0, 0.3, 2, number=3, break_number=2),
    ]
    path = tmp_path / "breaks.csv"
    path.write_text("\n".join([MESHLAB_HEADER, *rows]) + "\n", encoding="utf-8")
    assert bpy.ops.vg.import_csv(filepath=str(path)) == {"FINISHED"}
    assert [i.break_number for i in obj.vg.measurements] == [3, 7, 2]
    assert obj.vg.break_number == 8  # one past the highest in use
    measured(obj, at=(0.1, 0.0, 0.0))
    assert obj.vg.measurements[-1].break_number == 8
    bpy.ops.vg.next_break()
    assert obj.vg.break_number == 9


def test_next_break_skips_breaks_already_recorded(vg):
    # A .blend written before the counter followed recorded breaks: break 5 in use, counter at 1.
    obj, item = measured()
    item.break_number = 5
    assert obj.vg.break_number == 1
    bpy.ops.vg.next_break()
    assert obj.vg.break_number == 6


def test_batch_blend_continues_after_its_breaks(vg, tmp_path):
    from vg_addon.synthetic_meshes import wedge

    shape = wedge(75.0, n=30)
    ply = tmp_path / "wedge.ply"
    ply.write_text(
        "ply\nformat ascii 1.0\n"
        f"element vertex {len(shape.points)}\nproperty double x\nproperty double y\n"
        f"property double z\nelement face {len(shape.triangles)}\n"
        "property list uchar int vertex_indices\nend_header\n"
        + "".join(f"{x!r} {y!r} {z!r}\n" for x, y, z in shape.points.tolist())
        + "".join(f"3 {a} {b} {c}\n" for a, b, c in shape.triangles.tolist()),
        encoding="ascii",
    )
    saved = tmp_path / "study.blend"
    result = batch(
        ply, "--at", "0", "0", "0", "--at", "0.2", "0", "0", "--at", "-0.2", "0", "0",
        "--radius", "0.3", "--out", tmp_path / "out.csv", "--save-blend", saved,
    )  # fmt: skip
    assert result.returncode == 0, result.stdout + result.stderr
    bpy.ops.wm.open_mainfile(filepath=str(saved))
    obj = bpy.data.objects["wedge"]
    used = [i.break_number for i in obj.vg.measurements]
    assert len(used) == 3
    assert obj.vg.break_number == max(used) + 1
    bpy.context.view_layer.objects.active = obj
    bpy.ops.vg.next_break()
    assert obj.vg.break_number == max(used) + 2


def test_list_row_texts_fit_the_default_sidebar_at_ui_scale_1(vg, lists):
    # Real font metrics (blf, Blender's UI font at the widget size); the list's row at the default
    # sidebar width is about 170 pixels, an icon 20, a label's padding about 10. Worst cases: the
    # widest angle with the longest edge word, a stale row's icon with the widest angle, and a
    # three-digit number.
    import blf

    points = bpy.context.preferences.ui_styles[0].widget.points
    blf.size(0, points)
    row, icon, padding = 170.0, 20.0, 10.0
    angle_room = lists.ANGLE_SHARE * row - padding
    number_room = (1 - lists.ANGLE_SHARE) * lists.NUMBER_SHARE * row - padding
    assert blf.dimensions(0, "179.99° concave")[0] <= angle_room
    assert blf.dimensions(0, "179.99°")[0] + icon <= angle_room
    assert blf.dimensions(0, "#999")[0] <= number_room


def test_an_unstable_reading_is_flagged_in_its_list_row(vg, lists, panels, capfd):
    """A 90° wedge measured off its crease with a small radius moves by 78.7°, and without the
    vertices near its planes' crease line a side is no plane ("± ?"): its row shows the warning
    icon and the flag, its tooltip and the panel both reasons, the report a warning; a reading on
    the crease is not flagged."""
    obj = wedge_object(90.0)
    bpy.ops.vg.measure_xyz(location=(0.0, 0.0, 0.0), radius=0.3)
    bpy.ops.vg.measure_xyz(location=(0.0, 0.1, -0.02), radius=0.12)
    stable, unstable = obj.vg.measurements
    assert exact(unstable)["stability"]["spread"] > 5.0 > exact(stable)["stability"]["spread"]

    assert stable.stability_warning == "" and lists.row_flag(stable) == ""
    assert unstable.stability_warning.startswith("Unstable: the angle moves by up to 78.")
    assert "more than 5°" in unstable.stability_warning
    assert "Undetermined: without the vertices next to the crease" in unstable.stability_warning
    assert lists.row_flag(unstable) == "±?"  # undetermined: no number that looks steady
    assert lists.flagged_text(unstable) == f"{exact(unstable)['angle']:.1f}° ±?"
    assert f"{unstable.stability_text}" == "± ?"
    # The row's tooltip: the reason, the same words.
    operator = bpy.types.VG_OT_stability_warning
    assert operator.description(bpy.context, type("P", (), {"index": 1})) == (
        unstable.stability_warning
    )
    assert bpy.ops.vg.stability_warning(index=1) == {"FINISHED"}
    assert obj.vg.active_index == 1
    assert "Measurement 2: Unstable: the angle moves" in capfd.readouterr().out
    # The viewport label (and the map's) says it too: the figure after the angle, in red.
    label_of = {label.number: label for label in vg.bridge.label_data.labels_of(obj)}
    assert not label_of[stable.number].unstable
    assert label_of[stable.number].text == f"{stable.number}: {exact(stable)['angle']:.2f}°"
    assert label_of[unstable.number].unstable
    assert label_of[unstable.number].text.endswith("° ±?")
    viewport = importlib.import_module(f"{vg.__name__}.ui.labels")
    red = viewport.label_colour(label_of[unstable.number])
    assert red[0] > 0.9 and red[1] < 0.6 and red[2] < 0.6
    assert viewport.label_colour(label_of[stable.number]) != red


def test_an_undetermined_figure_shows_no_number_that_looks_steady(vg, lists, tmp_path):
    """More than a tenth of the figure's runs refused, or a band along the crease that leaves a
    face without a plane: the row says "±?", not a small "±0°", and the export's Stability Flag
    says why beside the number."""
    import json

    from vg_addon.formats import csvio

    wedge_object(90.0)
    bpy.ops.vg.measure_xyz(location=(0.0, 0.0, 0.0), radius=0.3)
    item = bpy.context.active_object.vg.measurements[0]
    recorded = item.exact
    try:
        for spread, runs, refused, crease_refused, noise, shown, reason in (
            (0.2, 83, 79, 0, False, "±?", "79 of 83 perturbed measurements were refused"),
            (0.2, 83, 0, 2, False, "±?", "a face keeps too few vertices off it"),
            (0.2, 83, 0, 0, True, "±?", "the vertex normals' noise is larger than the turn"),
            (0.2, 83, 0, 1, None, "±?", "or the vertex normals' noise"),  # an older record
            (150.0, 83, 0, 0, False, "±150°", "moves by up to 150.0°"),
        ):
            numbers = json.loads(recorded)
            numbers["stability"].update(
                spread=spread, runs=runs, refused=refused, crease_refused=crease_refused
            )
            numbers["stability"].pop("noise_hides_crease", None)
            if noise is not None:
                numbers["stability"]["noise_hides_crease"] = noise
            item.exact = json.dumps(numbers)
            assert item.stability_warning and lists.row_flag(item) == shown
            assert reason in item.stability_warning
            path = tmp_path / "flag.csv"
            assert bpy.ops.vg.export_csv(filepath=str(path)) == {"FINISHED"}
            (row,) = csvio.read_measurements_csv(path)
            assert row.stability == spread and reason in row.stability_flag
            kind = "Unstable" if spread > 5 else "Undetermined"
            assert row.stability_flag.startswith(kind)
    finally:
        item.exact = recorded  # the record as measured, for the checks after the test


def test_the_flagged_row_fits_the_default_sidebar(vg, lists):
    # As test_list_row_texts_fit_the_default_sidebar_at_ui_scale_1: the widest angle, the widest
    # figure and the warning icon.
    import blf

    blf.size(0, bpy.context.preferences.ui_styles[0].widget.points)
    row, icon, padding = 170.0, 20.0, 10.0
    for widest in ("180.0° ±180°", "180.0° ±?"):
        assert blf.dimensions(0, widest)[0] + icon <= lists.ANGLE_SHARE * row - padding


def test_panel_texts_fit_the_default_sidebar_or_are_wrapped(vg, panels):
    """Issue 20, item 8: at the default sidebar width every fixed label fits (Blender's own
    font metrics), and long help text is wrapped into lines that each fit."""
    import blf

    text = importlib.import_module(f"{vg.__name__}.ui.text")
    points = bpy.context.preferences.ui_styles[0].widget.points
    blf.size(0, points)

    def width(t):
        return text.DRAWN * blf.dimensions(0, t)[0]

    sidebar = text.SIDEBAR  # as Blender opens it (test_gui_session.py checks it in a window)
    panel = sidebar - text.MARGIN
    _obj, item = measured()
    rows = panels.selected_rows(item, bpy.context.scene)
    beside = set()
    for label, value in rows:
        # Every label fits its share; a value that does not fit beside it gets a row of its own.
        assert width(label) <= panels.LABEL_SHARE * panel - 8, label
        if text.fits_beside(label, value, sidebar, panels.LABEL_SHARE, width):
            beside.add(label)
            assert width(value) <= (1 - panels.LABEL_SHARE) * panel - 8, value
        else:
            assert width(value) + text.ICON <= panel, value
    assert {"Number", "Edge", "Rule", "Stability", "Patch", "Vertices", "Date"} <= beside
    assert width("Import (Re-measure)") + 20 <= panel  # a row of its own, with its icon
    hint = "3D cursor on the edge: Shift + Right-click"
    room = panel - text.ICON
    lines = text.wrap(hint, room, width)
    assert all(width(line) <= room for line in lines) and " ".join(lines) == hint
    long = "word " * 40
    lines = text.wrap(long, 150.0, width)
    assert len(lines) > 3 and all(width(line) <= 150.0 for line in lines)
    assert " ".join(lines) == long.strip()
