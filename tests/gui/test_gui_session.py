"""An analyst's session in a real Blender window, pressed with real mouse and key events
(xdotool): a long break of seven measurements, an unstable reading and its flagged row, the
sidebar at its default width, the Radius Sweep through its file browser, the measurement map,
and Delete and Clear. Screenshots of each are kept (``VG_GUI_PICTURES=DIR``) to be looked at.

One GUI Blender per Debian suite on the 100° wedge of ``scene.py``, the tests in file order;
every test also fails on an error from the extension in Blender's console.
"""

from __future__ import annotations

import csv

import pytest
from test_gui_buttons import (
    OBJ,
    WEDGE_ANGLE,
    home,
    keep_picture,
    map_running,
    open_browser,
    point,
    press_browser_button,
    sidebar_shot,
    window_shot,
)

# Seven places along the crease, left to right (points of conftest.POINTS).
ALONG = ("crease_-7", "crease_-5", "crease_left", "crease_+0", "crease", "crease_+5", "crease_+7")
UNSTABLE_RADIUS = "0.12"


@pytest.fixture(scope="module")
def places(gui):
    """Screen places found once per window and shared by the tests (filled as they go)."""
    return {}


def items(gui) -> list[dict]:
    return gui.measurements(OBJ)


def measure_at(gui, places, name: str) -> None:
    """Shift + right-click puts the 3D cursor on ``name``; the Measure at 3D Cursor button."""
    before = len(items(gui))
    gui.click(point(gui, name), button=3, modifier="shift")
    gui.click(places["measure"])
    gui.wait_for(lambda s: len(s["objects"][OBJ]["measurements"]) == before + 1, 30, "a reading")


def test_a_long_break_of_seven_measurements_keeps_one_colour_per_face(gui, places):
    gui.open_goniometer_tab()
    places["measure"] = gui.find_button("UI", "vg.measure_xyz")
    for name in ALONG:
        measure_at(gui, places, name)
    readings = items(gui)
    assert len(readings) == 7 and {m["break_number"] for m in readings} == {1}
    assert all(abs(m["exact"]["angle"] - WEDGE_ANGLE) < 1e-6 for m in readings)
    # One face, one colour: the colour of the face at y > 0 is the same for all seven.
    face_colour = set()
    for m in readings:
        plus, minus = m["colors"].split("/")
        face_colour.add(plus if m["exact"]["normal_plus"][1] > 0 else minus)
    assert len(face_colour) == 1, readings
    window_shot(gui, "long_break")


def test_the_sidebar_is_its_default_width_and_its_texts_are_drawn(gui, places):
    """The sidebar as Blender opens it: the width the headless text checks assume
    (``test_ext_panels.py::test_panel_texts_fit_the_default_sidebar_or_are_wrapped``, 291
    pixels at UI scale 1), and the panel shot to be looked at."""
    _left, top, width, height = gui.state()["regions"]["UI"]
    assert width >= 291, width
    shot = sidebar_shot(gui, "panel", top, height)
    assert shot.stat().st_size > 5000


def test_an_unstable_reading_is_flagged_in_the_list(gui, places):
    """The Radius field typed to 0.12 as a user does (double-click, type, Enter), a reading
    just off the crease: its stability figure is over 5°, and the list row shows it."""
    field = gui.find_button("UI", "vg_settings.radius", key="ctrl+shift+c")
    gui.click(field)
    gui.click(field)  # a double click edits the field, its text selected
    gui.key("ctrl+a")
    gui.type_text(UNSTABLE_RADIUS)
    gui.key("Return")
    gui.settle(5)
    measure_at(gui, places, "off_crease")
    reading = items(gui)[-1]
    assert reading["exact"]["radius"] == float(UNSTABLE_RADIUS)
    assert reading["exact"]["stability"]["spread"] > 5.0, reading["exact"]["stability"]
    places["list"] = gui.find_button("UI", "active_index", key="ctrl+shift+c")
    sidebar_shot(gui, "unstable_row", places["list"][1] - 120, 260)


def test_the_flagged_rows_button_selects_its_reading(gui, places):
    """The flagged row's angle is a button (its tooltip the reason): another row selected
    first, pressing it selects the flagged reading again."""
    flagged = len(items(gui)) - 1
    y = int(places["list"][1])
    span = gui.list_span("active_index", range(y - 150, y + 150, 4))
    left, _top, width, _height = gui.state()["regions"]["UI"]
    # Hovered, the flagged row's button copies no index: the row is just below the span.
    rows = range(span[0], span[-1] + 40, 3)
    button = gui.find_button("UI", "vg.stability_warning", rows=rows)
    other = next(row for row in span if abs(row - button[1]) > 14)
    gui.click((left + width // 3, other))
    state = gui.wait_for(lambda s: s["objects"][OBJ]["active_index"] != flagged, 20, "a row")
    assert state["objects"][OBJ]["active_index"] < flagged
    gui.move(button)
    gui.settle(30)  # the tooltip shows after a pause
    sidebar_shot(gui, "flagged_row_tooltip", button[1] - 120, 300)
    gui.click(button)
    gui.wait_for(lambda s: s["objects"][OBJ]["active_index"] == flagged, 20, "the flagged row")


def test_the_radius_sweep_writes_its_csv_and_plot_through_the_file_browser(gui, places):
    gui.click(point(gui, "crease"), button=3, modifier="shift")
    # Radius Sweep: second from the sidebar's foot (CSV, Radius Sweep, Measurement Map).
    sweep = gui.open_foot_panel("vg.radius_sweep", 2)
    before = set(home(gui).glob("*.csv"))
    press_browser_button(gui, open_browser(gui, sweep))
    gui.wait_for(lambda s: set(home(gui).glob("*.csv")) - before, 60, "the sweep's CSV")
    (written,) = set(home(gui).glob("*.csv")) - before
    with written.open(newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == 16  # the panel's Radii
    measured = [float(row["Angle"]) for row in rows if row["Angle"]]
    assert measured and all(abs(a - WEDGE_ANGLE) < 1e-3 for a in measured)
    plot = written.with_suffix(".png")
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    keep_picture(plot)


def test_the_map_shows_the_session(gui, places):
    """Ctrl+S first (the map's folder, //vg_map, is beside the .blend), then Render Map."""
    gui.move(point(gui, "plus_out"))
    gui.key("ctrl+s")
    browser = gui.wait_for(lambda s: s["file_browser"], 20, "the save file browser")
    press_browser_button(gui, browser["file_browser"])
    gui.wait_for(lambda s: s["blend"], 20, "the .blend to be saved")
    render = gui.open_last_panel_with("vg.render_map")
    folder = home(gui) / "vg_map"
    gui.click(render)
    gui.wait_for(lambda s: map_running(s) or folder.exists(), 30, "the map")
    state = gui.wait_for(lambda s: not map_running(s), 900, "the map to be rendered")
    assert state["map_blocks"] == [] and state["scenes"] == ["Scene"]
    sheets = list(folder.glob("*_map.png"))
    assert len(sheets) == 1 and sheets[0].stat().st_size > 10000
    copy = gui.tmp / f"session_map_{gui.suite}.png"
    copy.write_bytes(sheets[0].read_bytes())
    keep_picture(copy)


def list_button(gui, copied: str) -> tuple[float, float]:
    """The list's side button whose Ctrl+C copies ``copied``: hovered down the column at the
    list's right (the middle columns ``find_button`` tries hold the list itself)."""
    left, top, width, height = gui.state()["regions"]["UI"]
    x = left + width - 50
    for y in range(top + 4, top + min(height, 700), 5):
        text = gui.copies((x, y))
        if text is not None and copied in text:
            return x, y
    raise LookupError(f"no list button copying {copied!r}")


def test_the_refresh_button_beside_the_list_checks_the_colours(gui, places):
    """The refresh button beside the list (Update Colours) runs and says the colours of the
    unchanged mesh are up to date; every reading is kept, none stale."""
    gui.scroll_sidebar(-30)
    before = items(gui)
    start = gui.log_size()

    def reported(_state) -> bool:
        text = (gui.tmp / "blender.log").read_bytes()[start:].decode(errors="replace")
        return f"Colours of '{OBJ}' are up to date" in text

    gui.click(list_button(gui, "vg.repaint"))
    gui.wait_for(reported, 20, "its report")
    after = items(gui)
    assert [m["exact"] for m in after] == [m["exact"] for m in before]
    assert not any(m["stale"] for m in after)


def test_delete_and_clear_from_the_list_buttons(gui, places):
    """The list's − button deletes the selected reading; the bin asks, and Return clears all."""
    gui.scroll_sidebar(-30)
    count = len(items(gui))
    gui.click(list_button(gui, "vg.delete_measurement"))
    gui.wait_for(lambda s: len(s["objects"][OBJ]["measurements"]) == count - 1, 20, "a delete")
    gui.click(list_button(gui, "vg.clear_measurements"))
    gui.settle(5)
    window_shot(gui, "clear_confirm")
    gui.key("Return")
    gui.wait_for(lambda s: not s["objects"][OBJ]["measurements"], 20, "the list to be cleared")
