"""The panel's file-browser, modal and list buttons in a real Blender window, pressed with real
mouse and key events (xdotool): CSV Import (Re-measure), Replication Report (refused in the
distribution's Blender, then written once its libraries are importable), Render Map, the Edge
Profiles list.

One GUI Blender per Debian suite (trixie: Blender 4.3, unstable: 5.2) on the 100° wedge of
``scene.py``, the tests in file order on that one window, as one user session: measure, save the
.blend, export, re-import, trace three edge profiles and pick them in their list, cancel and
render the map, and last write the report once its libraries are importable. Every test also
fails on an error from the extension in Blender's console (``conftest.console_stays_clean``).
``VG_GUI_PICTURES=DIR`` keeps the screenshots and the map.
"""

from __future__ import annotations

import csv
import os
import re
import shutil
from pathlib import Path

import numpy as np
import pytest

from vg_addon import units

OBJ = "Wedge"
REPORT_LIBS = True  # conftest binds the report's libraries into the root (one test uses them)
WEDGE_ANGLE = 100.0
VIEWS = ("front", "back", "right", "left", "top", "bottom")
EXTRA_VIEWS = (f"{OBJ}_map_close-up_", f"{OBJ}_map_measurement_")  # see bridge.measurement_map
# Three edge profiles along the crease (start, end: points of conftest.POINTS).


# -- helpers -------------------------------------------------------------------------------------
def point(gui, name: str) -> tuple[float, float]:
    xy = gui.state()["points"][name]
    assert xy is not None, f"{name} is not in view"
    return tuple(xy)


def edges_in_view(gui) -> tuple:
    """Three (start, end) pairs of crease points the viewer can click: on the view, left of the
    sidebar drawn over it (a click there is the sidebar's, not the mesh's)."""
    state = gui.state()
    sidebar_left = state["regions"]["UI"][0]
    names = sorted(
        (n for n, xy in state["points"].items()
         if re.fullmatch(r"crease_[+-]?\d+", n) and xy is not None and xy[0] < sidebar_left - 20),
        key=lambda n: int(n.split("_")[1]),
    )  # fmt: skip
    assert len(names) >= 5, f"too few crease points left of the sidebar: {names}"
    middle = len(names) // 2
    return ((names[0], names[-1]), (names[1], names[middle + 1]), (names[middle], names[-1]))


def measurements(gui) -> list[dict]:
    return gui.measurements(OBJ)


def keep_picture(path: Path) -> None:
    """Copy a picture to ``$VG_GUI_PICTURES`` (when set), named after the Blender build."""
    folder = os.environ.get("VG_GUI_PICTURES")
    if folder:
        Path(folder).mkdir(parents=True, exist_ok=True)
        shutil.copy(path, Path(folder) / path.name)


def sidebar_shot(gui, name: str, top: float, height: float) -> Path:
    """A screenshot of the sidebar from screen row ``top``, ``height`` rows, kept as PNG."""
    left, region_top, width, region_height = gui.state()["regions"]["UI"]
    top = max(top, region_top)
    height = min(height, region_top + region_height - top)
    path = gui.tmp / f"{name}_{gui.suite}.png"
    gui.save_png(name, path, crop=(left, top, width, height))
    keep_picture(path)
    return path


def window_shot(gui, name: str) -> Path:
    """A screenshot of the whole window, kept as PNG."""
    path = gui.tmp / f"{name}_{gui.suite}.png"
    gui.save_png(name, path)
    keep_picture(path)
    return path


def open_browser(gui, button) -> dict:
    gui.click(button)
    return gui.wait_for(lambda s: s["file_browser"], 20, "the file browser")["file_browser"]


def press_browser_button(gui, browser) -> None:
    """Click the file browser's confirm button (bottom right) and wait for it to close."""
    left, top, width, height = browser["EXECUTE"]
    gui.click((left + width - 60, top + height / 2))
    gui.wait_for(lambda s: s["file_browser"] is None, 20, "the file browser to close")


def type_file_name(gui, browser, name: str) -> None:
    """Type ``name`` into the file browser's file name field, as a user would."""
    left, top, width, height = browser["EXECUTE"]
    gui.click((left + width * 0.3, top + height / 2))  # edits the field, its text selected
    gui.key("ctrl+a")
    gui.type_text(name)
    gui.key("Return")


def map_running(state) -> bool:
    return any("render_map" in op.lower() for op in state["modal_operators"])


def home(gui) -> Path:
    return gui.tmp / "home"


# -- the session ---------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def places(gui):
    """Screen places found once per window and shared by the tests (filled as they go)."""
    return {}


def test_goniometer_tab_and_two_measurements(gui, places):
    gui.open_goniometer_tab()
    measure = gui.find_button("UI", "vg.measure_xyz")
    for name in ("crease_left", "crease"):
        before = len(measurements(gui))
        gui.click(point(gui, name), button=3, modifier="shift")  # the 3D cursor on the crease
        gui.click(measure)
        gui.wait_for(lambda s, n=before: len(s["objects"][OBJ]["measurements"]) == n + 1, 20, "")
    items = measurements(gui)
    assert len(items) == 2
    assert all(abs(item["exact"]["angle"] - WEDGE_ANGLE) < 1e-6 for item in items)


def test_save_the_blend_with_ctrl_s(gui):
    """Ctrl+S in an unsaved file: the file browser, its Save button; the map's default folder
    (//vg_map) and the Import dialog's offer now have a .blend beside them."""
    gui.move(point(gui, "plus_out"))
    gui.key("ctrl+s")
    browser = gui.wait_for(lambda s: s["file_browser"], 20, "the save file browser")
    press_browser_button(gui, browser["file_browser"])
    state = gui.wait_for(lambda s: s["blend"], 20, "the .blend to be saved")
    assert Path(state["blend"]).suffix == ".blend"


def test_export_through_the_file_browser(gui, places):
    # The CSV panel: third from the sidebar's foot (the Selected panel above is long).
    export = gui.open_foot_panel("vg.export_csv", 3)
    before = {p.name for p in home(gui).glob("*.csv")}
    press_browser_button(gui, open_browser(gui, export))

    def written(_state):
        return sorted(set(p.name for p in home(gui).glob("*.csv")) - before)

    gui.wait_for(written, 20, "the exported CSV")
    (name,) = written(None)
    places["csv"] = home(gui) / name
    places["export"] = export
    with places["csv"].open(newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert [float(row["Angle"]) for row in rows] == [m["exact"]["angle"] for m in measurements(gui)]


def test_import_dialog_offers_the_exported_csv_filtered_to_csv(gui, places):
    """Issue 20, item 9: the Import dialog offers the last exported CSV, not the .blend, and
    shows only *.csv files."""
    export = places["export"]
    places["import"] = gui.find_button(
        "UI", "vg.import_csv", rows=range(export[1], export[1] + 60, 6)
    )
    browser = open_browser(gui, places["import"])
    params = browser["params"]
    gui.key("Escape")
    gui.wait_for(lambda s: s["file_browser"] is None, 20, "the file browser to close")
    assert params["filename"] == places["csv"].name
    assert Path(params["directory"]).resolve() == Path("/vg/tmp/home").resolve()
    assert params["filter_glob"] == "*.csv"
    assert params["use_filter"]


def test_import_remeasures_every_row_through_the_file_browser(gui, places):
    """Issue 20, item 1: Import (Re-measure) from the panel, the CSV chosen in the file browser:
    every row is measured again, and the angles are the exported ones, exactly."""
    with places["csv"].open(newline="") as handle:
        rows = list(csv.DictReader(handle))
    before = measurements(gui)
    browser = open_browser(gui, places["import"])
    if browser["params"]["filename"] != places["csv"].name:  # choose it, as a user would
        type_file_name(gui, browser, places["csv"].name)
    if gui.state()["file_browser"] is not None:
        press_browser_button(gui, gui.state()["file_browser"])
    gui.wait_for(
        lambda s: (
            len(s["objects"][OBJ]["measurements"]) == len(before) + len(rows)
            or not any("import_csv" in op.lower() for op in s["modal_operators"])
        ),
        60,
        "the import to end",
    )
    items = gui.settle()["objects"][OBJ]["measurements"]
    assert len(items) == len(before) + len(rows), "every row of the CSV was re-measured"
    again = items[len(before) :]
    assert [m["exact"]["angle"] for m in again] == [float(row["Angle"]) for row in rows]
    assert [m["exact"]["angle"] for m in again] == [m["exact"]["angle"] for m in before]
    assert [m["exact"]["center"] for m in again] == [m["exact"]["center"] for m in before]
    assert not any("import_csv" in op.lower() for op in gui.state()["modal_operators"])


def test_repeat_last_after_the_import_measures_the_rows_once_more(gui, places):
    """Repeat Last (Shift+R over the view) after the file-browser import runs the import once
    more, to its end, with the rows' angles exact; Blender goes on (no operator left running,
    nothing in the console)."""
    with places["csv"].open(newline="") as handle:
        rows = list(csv.DictReader(handle))
    before = measurements(gui)
    gui.move(point(gui, "crease"))
    gui.key("shift+r")
    gui.wait_for(
        lambda s: len(s["objects"][OBJ]["measurements"]) >= len(before) + len(rows),
        60,
        "the repeated import",
    )
    items = gui.settle(5)["objects"][OBJ]["measurements"]
    assert len(items) == len(before) + len(rows), "the repeat imported the rows once"
    assert [m["exact"]["angle"] for m in items[len(before) :]] == [
        float(row["Angle"]) for row in rows
    ]
    assert not any("import_csv" in op.lower() for op in gui.state()["modal_operators"])
    gui.key("ctrl+z")  # the repeat is one undo step: the measurements before it are back
    state = gui.wait_for(
        lambda s: len(s["objects"][OBJ]["measurements"]) == len(before), 20, "the undo"
    )
    assert [m["exact"]["angle"] for m in state["objects"][OBJ]["measurements"]] == [
        m["exact"]["angle"] for m in before
    ]


def test_replication_report_refuses_without_its_libraries(gui, places):
    """Issue 23: Replication Report from the CSV panel in a distribution's Blender, whose Python
    has NumPy only: refused when pressed, naming what to install and the vg_batch.py --report
    command; nothing is written."""
    if "import" not in places:  # run alone (-k): open the CSV panel as the tests before do
        gui.open_goniometer_tab()
        export = gui.open_panel_with("vg.export_csv", below=gui.state()["regions"]["UI"][1])
        rows = range(export[1], export[1] + 60, 6)
        places["import"] = gui.find_button("UI", "vg.import_csv", rows=rows)
    rows = range(places["import"][1], places["import"][1] + 80, 6)  # just under Import
    button = gui.find_button("UI", "vg.report", rows=rows)
    gui.click(button)  # refused at once: no file browser to choose files in vain
    gui.settle(2)
    window_shot(gui, "report_refused")
    assert gui.state()["file_browser"] is None
    gui.key("Escape")  # the refusal's popup
    seq = gui.state()["seq"]
    Path(f"{gui.state_path}.reports").touch()  # the harness copies the Info log's reports
    state = gui.wait_for(
        lambda s: any(n >= seq and "report needs" in t for n, t in s["clipboard"]), 20, "reports"
    )
    reports = "\n".join(t for n, t in state["clipboard"] if n >= seq)
    assert "The report needs scipy, statsmodels, matplotlib" in reports
    assert "python vg_batch.py --report" in reports
    assert "sudo apt install python3-scipy python3-statsmodels python3-matplotlib" in reports
    assert not list(gui.tmp.rglob("report.html"))
    assert not any("vg.report" in op.lower() for op in gui.state()["modal_operators"])


def test_edge_profiles_list_shows_each_edge_and_picks_by_click(gui, places):
    """Issue 20, item 3: three edge profiles traced with the Edge Profile button (click start,
    click end, Enter); their list draws a row for each, and clicking a row selects that edge."""
    button = gui.find_button("UI", "vg.measure_edge", upward=True)
    pairs = edges_in_view(gui)
    for start, end in pairs:
        count = len(gui.state()["objects"][OBJ]["edges"])
        # The Selected panel above changes once a station is selected (a row more, no
        # stability rows): find the button again.
        y = int(button[1])
        button = gui.find_button("UI", "vg.measure_edge", rows=range(y - 160, y + 100, 6))
        gui.click(button)
        gui.click(point(gui, start))
        gui.click(point(gui, end))
        gui.key("Return")
        gui.wait_for(lambda s, n=count: len(s["objects"][OBJ]["edges"]) == n + 1, 60, "an edge")
    edges = gui.settle()["objects"][OBJ]["edges"]
    assert len(edges) == len(pairs)
    assert all(abs(edge["mean"] - WEDGE_ANGLE) < 1e-6 for edge in edges)
    # The list is below the button, its hint line, Find Break Edges and its folded settings:
    # where hovering copies its index property. Clicking down it selects each edge in turn.
    below = int(button[1])
    span = gui.list_span("active_edge_index", range(below + 16, below + 240, 4))
    shot = sidebar_shot(gui, "edge_list", below - 100, 420)
    assert span, f"no edge list is drawn ({shot})"
    left, _top, width, _height = gui.state()["regions"]["UI"]
    picked = {}  # edge index -> the screen rows whose click selected it
    for y in range(span[0] + 2, span[-1] - 1, 5):
        gui.click((left + width // 3, y))
        picked.setdefault(gui.settle()["objects"][OBJ]["active_edge_index"], []).append(y)
    assert sorted(picked) == list(range(len(pairs))), f"rows clicked: {picked} ({shot})"
    middles = [float(np.mean(picked[index])) for index in range(len(pairs))]
    assert middles == sorted(middles), "the edges are listed in order, one row each"
    # Each row shows its texts (number, mean angle, stations): bright pixels in every row.
    picture = gui.screenshot("edge_rows")
    for index, y in enumerate(middles):
        band = picture[int(y) - 6 : int(y) + 6, int(left) + 10 : int(left + width) - 60]
        assert (band.min(axis=2) > 170).sum() > 20, f"row {index + 1} has no text ({shot})"
    # Issue 22, item 5: below the list, the selected edge's figures (study figures among them),
    # its plot and, last, its note: scrolled into view, the note is the selected edge's.
    gui.scroll_sidebar(6)
    _left, top, _width, height = gui.state()["regions"]["UI"]
    sidebar_shot(gui, "edge_figures", top, height)
    gui.scroll_sidebar(12)  # on to the plot (its preview made on demand) and the note
    gui.settle(3)
    figures = sidebar_shot(gui, "edge_plot", top, height)
    selected = gui.state()["objects"][OBJ]["active_edge_index"]
    try:
        gui.find_button("UI", f"edges[{selected}].note", key="ctrl+shift+c", upward=True, step=6)
    except LookupError:
        pytest.fail(f"the Edge Profiles panel does not draw down to the edge's note ({figures})")


def test_choosing_scan_units_draws_the_edges_plots_again_in_that_unit(gui, places):
    """The Scan Units menu at the head of the panel, changed as a user can (Ctrl+wheel over it):
    every edge's plot is drawn again, its axis in the unit chosen (the unit's symbol from the
    project's table of units), and the plot shows in the panel."""
    gui.scroll_sidebar(-40)
    state = gui.state()
    before = state["objects"][OBJ]
    assert before["edges"] and all(edge["plot_units"] for edge in before["edges"])
    menu = gui.find_button("UI", "vg.unit", key="ctrl+shift+c", step=6)
    gui.click(menu, button=5, modifier="ctrl")  # the next unit of the menu
    state = gui.wait_for(lambda s: s["objects"][OBJ]["unit"] != before["unit"], 20, "a unit")
    chosen = state["objects"][OBJ]["unit"]
    assert chosen in units.SYMBOLS, f"Ctrl+wheel chose {chosen}"
    state = gui.settle(3)
    assert [e["plot_units"] for e in state["objects"][OBJ]["edges"]] == [
        units.SYMBOLS[chosen]
    ] * len(before["edges"])
    _left, top, _width, height = state["regions"]["UI"]
    sidebar_shot(gui, "scan_units", top, height)
    gui.scroll_sidebar(40)
    gui.settle(3)
    sidebar_shot(gui, "edge_plot_in_chosen_unit", top, height)


def side_button(gui, copied: str) -> tuple[float, float]:
    """The button beside a list whose Ctrl+C copies ``copied``: hovered down the column at the
    sidebar's right (``find_button`` tries the middle columns, where the list itself is)."""
    left, top, width, height = gui.state()["regions"]["UI"]
    for y in range(top + 4, top + height - 4, 5):
        text = gui.copies((left + width - 50, y))
        if text is not None and copied in text:
            return left + width - 50, y
    raise LookupError(f"no button copying {copied!r} beside a list")


def test_scaling_the_object_draws_its_plots_again_and_undo_puts_them_back(gui, places):
    """With Scan Units "Scene Units", a plot's axis names the scene's unit; once the object is
    scaled (S 2 Enter over the view, as a user scales it) its lengths are mesh units, and every
    plot is drawn again naming them, once the edit pauses (before: the plot kept naming the
    scene's unit). Ctrl+Z puts the scale and the plots back."""
    gui.scroll_sidebar(-40)
    menu = gui.find_button("UI", "vg.unit", key="ctrl+shift+c", step=6)
    for _ in range(len(units.SYMBOLS) + 1):  # Ctrl+wheel steps round the menu's items
        if gui.state()["objects"][OBJ]["unit"] == "SCENE":
            break
        gui.click(menu, button=4, modifier="ctrl")
        gui.settle(3)
    scene_unit = units.scene_symbol("METRIC", 1.0)  # the test scene's: Blender's default
    state = gui.wait_for(
        lambda s: (
            s["objects"][OBJ]["unit"] == "SCENE"
            and {e["plot_units"] for e in s["objects"][OBJ]["edges"]} == {scene_unit}
        ),
        20,
        "Scene Units, the plots naming the scene's unit",
    )
    count = len(state["objects"][OBJ]["edges"])
    gui.scroll_sidebar(40)
    sidebar_left = gui.state()["regions"]["UI"][0]
    face, crease = point(gui, "plus_out"), point(gui, "crease")
    assert max(face[0], crease[0]) < sidebar_left - 20, "the wedge is under the sidebar"
    gui.click(face)  # selected, with the Select tool, as a user selects it
    gui.move(crease)  # keys go to the view under the pointer
    gui.key("s")
    gui.type_text("2")
    gui.key("Return")
    gui.wait_for(
        lambda s: (
            s["objects"][OBJ]["scale"] == [2.0, 2.0, 2.0]
            and [e["plot_units"] for e in s["objects"][OBJ]["edges"]] == ["mesh units"] * count
        ),
        20,
        "the object scaled by 2 and its plots naming mesh units",
    )
    gui.move(crease)
    gui.key("ctrl+z")
    gui.wait_for(
        lambda s: (
            s["objects"][OBJ]["scale"] == [1.0, 1.0, 1.0]
            and [e["plot_units"] for e in s["objects"][OBJ]["edges"]] == [scene_unit] * count
        ),
        20,
        "the scale and the plots put back",
    )


def test_the_edge_lists_minus_deletes_the_selected_edge_and_its_stations(gui, places):
    """The − beside the Edge Profiles list: the selected edge goes, with its stations (the
    measurements recorded for it); the other edges and measurements stay as they were."""
    before = gui.state()["objects"][OBJ]
    selected = before["edges"][before["active_edge_index"]]
    gui.click(side_button(gui, "vg.delete_edge"))
    state = gui.wait_for(
        lambda s: len(s["objects"][OBJ]["edges"]) == len(before["edges"]) - 1, 20, "a delete"
    )
    after = state["objects"][OBJ]
    assert [e["number"] for e in after["edges"]] == [
        e["number"] for e in before["edges"] if e["number"] != selected["number"]
    ]
    kept = [m for m in before["measurements"] if m["edge_number"] != selected["number"]]
    assert len(kept) == len(before["measurements"]) - selected["n_stations"]
    assert [m["number"] for m in after["measurements"]] == [m["number"] for m in kept]


def test_an_edge_profile_is_recorded_only_on_the_object_its_clicks_are_on(gui, places):
    """Clicks outside the viewport reach Blender during an Edge Profile session, so another
    object can become active (a click in the Outliner). Before, Enter then recorded the clicks
    on that object: the stations of one scan on another, with no error."""
    count = len(gui.state()["objects"][OBJ]["edges"])
    gui.click(gui.find_button("UI", "vg.measure_edge", upward=True))
    start, end = edges_in_view(gui)[0]
    gui.click(point(gui, start))
    gui.click(point(gui, end))
    other = f"{OBJ}.other"
    Path(f"{gui.state_path}.activate").write_text(other)
    gui.wait_for(lambda s: s["active"] == other, 20, "the other object made active")
    gui.key("Return")
    state = gui.settle(5)
    assert any("measure_edge" in op.lower() for op in state["modal_operators"]), (
        "refused, the session goes on with its clicks"
    )
    assert len(state["objects"][OBJ]["edges"]) == count
    assert not state["objects"][other]["edges"] and not state["objects"][other]["measurements"]
    Path(f"{gui.state_path}.activate").write_text(OBJ)
    gui.wait_for(lambda s: s["active"] == OBJ, 20, "the clicked object active again")
    gui.key("Return")
    state = gui.wait_for(
        lambda s: len(s["objects"][OBJ]["edges"]) == count + 1, 60, "the edge on its object"
    )
    assert not state["objects"][other]["edges"]
    assert abs(state["objects"][OBJ]["edges"][-1]["mean"] - WEDGE_ANGLE) < 1e-6


def test_render_map_cancelled_with_escape_keeps_nothing(gui, places):
    """Issue 20, item 2: Esc while the map renders: no picture, no folder it made, no "VG Map"
    scene or data-block left in the file, the operator ended."""
    render = gui.open_last_panel_with("vg.render_map")  # the sidebar is full: scrolled down
    places["render"] = render
    folder = home(gui) / "vg_map"
    assert not folder.exists()
    gui.click(render)
    gui.wait_for(lambda s: "VG Map" in s["scenes"], 60, "the map's scene")
    gui.key("Escape")
    state = gui.wait_for(lambda s: not map_running(s), 120, "the map to be cancelled")
    window_shot(gui, "map_cancelled")  # the status bar: no "Esc cancels" left
    assert state["map_blocks"] == []
    assert state["scenes"] == ["Scene"]
    assert not folder.exists() or not any(folder.iterdir()), "a cancelled map keeps no picture"
    assert not folder.exists(), "the folder the cancelled map made is removed"


def test_render_map_writes_every_view_and_leaves_no_scene(gui, places):
    """Issue 20, item 2: Render Map from the panel writes a PNG per view and the contact sheet
    into //vg_map, and leaves nothing of its scene in the file."""
    folder = home(gui) / "vg_map"
    gui.click(places["render"])
    gui.wait_for(
        lambda s: map_running(s) or "VG Map" in s["scenes"] or folder.exists(), 30, "the map"
    )
    state = gui.wait_for(lambda s: not map_running(s), 600, "the map to be rendered")
    window_shot(gui, "map_done")
    assert state["map_blocks"] == []
    assert state["scenes"] == ["Scene"]
    expected = {f"{OBJ}_map_{view}.png" for view in VIEWS} | {f"{OBJ}_map.png"}
    written = {p.name for p in folder.iterdir()}
    # Labels crowded out of the six views (the edge profiles' stations along the crease) get
    # close-ups of their own: every reading is labelled somewhere (test_map.py checks how).
    extra = written - expected
    assert expected <= written and all(n.startswith(EXTRA_VIEWS) for n in extra), extra
    for name in written:
        data = (folder / name).read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 2000, name
    sheet = gui.tmp / f"map_{gui.suite}.png"
    shutil.copy(folder / f"{OBJ}_map.png", sheet)
    keep_picture(sheet)


def report_button(gui) -> tuple[float, float]:
    """The Replication Report button: in the CSV panel if it is open, else opened."""
    try:
        return gui.find_button("UI", "vg.report", upward=True)
    except LookupError:
        export = gui.open_panel_with("vg.export_csv", below=gui.state()["regions"]["UI"][1])
        return gui.find_button("UI", "vg.report", rows=range(export[1], export[1] + 140, 6))


def test_replication_report_writes_the_report_once_its_libraries_are_there(gui, places):
    """Replication Report pressed again once SciPy, statsmodels and matplotlib are importable
    (``scripts/provision_report_libs.sh``'s wheels for this Blender's Python, put on its
    ``sys.path`` as a user who installed them would have them): the file browser opens on the
    exported CSV, its button pressed, and the report is written beside it with this scene's
    measurements as one more session. Oracles: the scene's measurements (their exact angles,
    from the harness) for the scene's session CSV, and the chosen file's name in the page. Last
    in the file: with the libraries importable the window is no longer the distribution's
    Blender the tests before it are about."""
    if gui.report_libs is None:
        pytest.skip(f"no report libraries for this Blender's Python: {gui.report_libs_missing}")
    Path(f"{gui.state_path}.report_libs").touch()
    gui.wait_for(lambda s: s.get("report_libs"), 20, "the report's libraries on sys.path")
    browser = open_browser(gui, report_button(gui))
    params = browser["params"]
    assert (params["filename"], params["filter_glob"]) == (places["csv"].name, "*.csv")
    press_browser_button(gui, browser)  # the exported CSV, offered as Import offers it
    folder = places["csv"].parent / "vg_report"  # beside the first CSV chosen
    gui.wait_for(lambda s: (folder / "report.html").exists(), 180, "report.html")
    gui.wait_for(
        lambda s: not any("vg.report" in op.lower() for op in s["modal_operators"]), 60, ""
    )
    seq = gui.state()["seq"]
    Path(f"{gui.state_path}.reports").touch()
    state = gui.wait_for(
        lambda s: any(n >= seq and "report.html" in t for n, t in s["clipboard"]), 20, "reports"
    )
    reports = "\n".join(t for n, t in state["clipboard"] if n >= seq)
    assert "Wrote /vg/tmp/home/vg_report/report.html: " in reports, reports
    with (folder / "scene_measurements.csv").open(newline="") as handle:
        scene_rows = list(csv.DictReader(handle))
    assert [float(row["Angle"]) for row in scene_rows] == [
        m["exact"]["angle"] for m in measurements(gui)
    ]
    page = (folder / "report.html").read_text(encoding="utf-8")
    assert places["csv"].name in page and "scene_measurements.csv" in page
    assert places["csv"].exists()  # the chosen session is read, never written
