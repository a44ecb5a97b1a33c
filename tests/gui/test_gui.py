"""The extension in a real Blender window, driven with real mouse and key events (xdotool).

One GUI Blender per Debian suite (trixie: Blender 4.3, unstable: 5.2), the extension installed
from the zip with ``blender --command extension install-file``; the scene is an exact wedge
whose interior angle is 100° (see ``scene.py``). The tests run in file order on that one window.
"""

from __future__ import annotations

import csv
import json
import math

import numpy as np
import pytest
from conftest import POINTS
from driver import GUEST_REPO, GUEST_TMP

OBJ = "Wedge"
TOOL = "vg.measure_drag_tool"
WEDGE_ANGLE = 100.0


# -- helpers -------------------------------------------------------------------------------------
def count(gui) -> int:
    return len(gui.measurements(OBJ))


def point(gui, name: str) -> tuple[float, float]:
    xy = gui.state()["points"][name]
    assert xy is not None, f"{name} is not in view"
    return tuple(xy)


def inside(rect, xy) -> bool:
    left, top, width, height = rect
    return left <= xy[0] < left + width and top <= xy[1] < top + height


def press(gui, xy) -> dict:
    """Move to ``xy``, press the left button, and wait until the drag is running."""
    gui.move(xy)
    gui.xdotool("mousedown", "1")
    return gui.wait_for(lambda s: s["drag"] is not None, 20, "the drag to start")


def glide(gui, start, end, steps: int = 6) -> dict:
    """Move the pointer from ``start`` to ``end`` in steps, letting Blender see each."""
    for i in range(1, steps + 1):
        f = i / steps
        gui.move((start[0] + f * (end[0] - start[0]), start[1] + f * (end[1] - start[1])))
    return gui.settle(2)


def release(gui) -> dict:
    gui.xdotool("mouseup", "1")
    gui.wait_for(lambda s: s["drag"] is None, 20, "the drag to end")
    return gui.settle()


def ensure_tool(gui) -> None:
    if gui.state()["tool"] != TOOL:
        gui.click(gui.find_button("TOOLS", TOOL))
        gui.wait_for(lambda s: s["tool"] == TOOL, 10, "the Goniometer tool")


def drag_measure(gui, distance: float = 70.0) -> dict:
    """Press on the crease, drag ``distance`` pixels along it, release; the new measurement."""
    ensure_tool(gui)
    before = count(gui)
    start = point(gui, "crease")
    press(gui, start)
    glide(gui, start, (start[0] + distance, start[1]))
    release(gui)
    items = gui.measurements(OBJ)
    assert len(items) == before + 1, "a drag released in the viewport records one measurement"
    return items[-1]


# -- the tests -----------------------------------------------------------------------------------
def test_blender_starts_with_the_extension_and_scene(gui):
    state = gui.state()
    assert state["active"] == OBJ
    assert state["objects"][OBJ]["measurements"] == []
    assert {"WINDOW", "UI", "TOOLS", "HEADER"} <= set(state["regions"])
    # The first click after start-up is swallowed: spend it on the empty foot of the sidebar.
    left, top, width, height = state["regions"]["UI"]
    gui.click((left + width // 2, top + height - 15))
    # The Goniometer tab, clicked as a user would (in Blender 4.3 the tab cannot be set from
    # Python): the tabs stand on the sidebar's right edge, ours is found by trying them.
    for y in range(top + 10, top + height - 10, 12):
        gui.click((left + width - 12, y))
        if gui.state()["sidebar_category"] == "Goniometer":
            break
    assert gui.state()["sidebar_category"] == "Goniometer"


def test_tool_is_picked_from_the_toolbar(gui):
    where = gui.find_button("TOOLS", TOOL)
    gui.click(where)
    assert gui.wait_for(lambda s: s["tool"] == TOOL, 10, "the Goniometer tool")["tool"] == TOOL


def test_drag_draws_the_overlay_and_records_one_measurement(gui):
    start = point(gui, "crease")
    baseline = gui.screenshot("before_drag").astype(int)
    press(gui, start)
    distance = 70.0
    end = (start[0] + distance, start[1])
    glide(gui, start, end)
    during = gui.screenshot("during_drag").astype(int)
    drag = gui.state()["drag"]
    release(gui)
    assert drag is not None and drag["radius"] > 0
    # The overlay: a bright (white) circle through the pointer, around the snapped centre.
    centre = drag["center_screen"]
    angles = np.linspace(0.0, 2.0 * math.pi, 48, endpoint=False)
    hits = 0
    for a in angles:
        ring = [
            (centre[0] + r * math.cos(a), centre[1] + r * math.sin(a))
            for r in np.arange(drag["radius_px"] - 4, drag["radius_px"] + 4.5, 1.0)
        ]
        bright = [
            during[round(y), round(x)].min() >= 200 and baseline[round(y), round(x)].min() < 200
            for x, y in ring
        ]
        hits += any(bright)
    assert hits >= 0.75 * len(angles), f"the circle shows at {hits} of {len(angles)} angles"
    # Well inside the circle nothing is white (the patch points are coloured, not white).
    core = during[int(start[1]) - 20 : int(start[1]) + 20, int(start[0]) - 20 : int(start[0]) + 20]
    assert (core.min(axis=2) >= 235).mean() < 0.2

    items = gui.measurements(OBJ)
    assert len(items) == 1
    exact = items[0]["exact"]
    assert abs(exact["angle"] - WEDGE_ANGLE) < 1e-6
    assert abs(exact["center"][1]) < 0.05 and abs(exact["center"][2]) < 1e-6  # on the crease


def test_painted_sides_show_in_the_viewport(gui):
    shot = gui.screenshot("painted").astype(int)
    item = gui.measurements(OBJ)[-1]
    plus_face = +1 if item["exact"]["normal_plus"][1] > 0 else -1
    names = {+1: ("plus_in", "plus_out"), -1: ("minus_in", "minus_out")}

    def colour(name):
        x, y = (round(v) for v in point(gui, name))
        return shot[y - 2 : y + 3, x - 2 : x + 3].reshape(-1, 3).mean(axis=0)

    warm = colour(names[plus_face][0])  # the + side: yellow (240, 228, 66)
    cool = colour(names[-plus_face][0])  # the − side: blue (0, 114, 178)
    # Yellow, not the orange of Blender's selection outline: green nearly as strong as red.
    assert warm[0] - warm[2] > 60 and warm[1] > 0.8 * warm[0], f"+ side {warm} is not yellow"
    assert cool[2] - cool[0] > 60, f"− side pixel {cool} is not blue"
    for name in ("plus_out", "minus_out"):  # outside the patch: the neutral grey
        rgb = colour(name)
        assert np.ptp(rgb) < 25, f"{name} pixel {rgb} is not grey"


def test_escape_and_right_click_record_nothing(gui):
    before = count(gui)
    start = point(gui, "crease")
    for cancel in (["key", "Escape"], ["click", "3"]):
        press(gui, start)
        glide(gui, start, (start[0] + 60, start[1]))
        gui.xdotool(*cancel)
        gui.wait_for(lambda s: s["drag"] is None, 20, "the drag to be cancelled")
        gui.xdotool("mouseup", "1")
        gui.settle()
        assert count(gui) == before, f"{cancel} recorded a measurement"


@pytest.mark.parametrize("region", ["UI", "HEADER", "TOOLS"])
def test_release_outside_the_viewport_records_nothing(gui, region):
    """Released over the sidebar, the header or the toolbar: nothing is recorded."""
    ensure_tool(gui)
    before = count(gui)
    left, top, width, height = gui.state()["regions"][region]
    start = point(gui, "crease")
    press(gui, start)
    target = (left + width // 2, top + height // 2)
    glide(gui, start, target, steps=8)
    release(gui)
    assert inside(gui.state()["regions"][region], target)
    assert count(gui) == before, f"a release over the {region} region recorded a measurement"


def test_typed_radius_and_lam_key(gui):
    ensure_tool(gui)
    before = count(gui)
    start = point(gui, "crease")
    press(gui, start)
    glide(gui, start, (start[0] + 40, start[1]), steps=3)
    gui.type_text("0.25")
    gui.wait_for(lambda s: s["drag"] and s["drag"]["typed"] == "0.25", 10, "the typed radius")
    lam = gui.state()["drag"]["lam"]
    gui.key("l")
    gui.wait_for(lambda s: s["drag"] and s["drag"]["lam"] == lam + 0.25, 10, "λ to step up")
    gui.key("Return")
    gui.wait_for(lambda s: s["drag"] is None, 20, "the typed measurement")
    gui.xdotool("mouseup", "1")
    gui.settle()
    items = gui.measurements(OBJ)
    assert len(items) == before + 1
    exact = items[-1]["exact"]
    assert exact["radius"] == 0.25
    assert exact["lam"] == lam + 0.25
    assert abs(exact["angle"] - WEDGE_ANGLE) < 1e-6


def test_ctrl_z_undoes_the_last_measurement(gui):
    drag_measure(gui)
    before = count(gui)
    gui.move(point(gui, "crease_left"))
    gui.key("ctrl+z")
    gui.wait_for(lambda s: len(s["objects"][OBJ]["measurements"]) == before - 1, 20, "the undo")
    gui.key("ctrl+shift+z")
    gui.wait_for(lambda s: len(s["objects"][OBJ]["measurements"]) == before, 20, "the redo")


def test_measure_at_cursor_after_shift_right_click(gui):
    before = count(gui)
    where = point(gui, "crease_left")
    gui.click(where, button=3, modifier="shift")
    cursor = gui.state()["cursor"]
    assert abs(cursor[0] - POINTS["crease_left"][0]) < 0.05
    assert abs(cursor[1]) < 0.05, "Shift+right-click put the 3D cursor on the crease"
    gui.click(gui.find_button("UI", "vg.measure_xyz"))
    gui.wait_for(lambda s: len(s["objects"][OBJ]["measurements"]) == before + 1, 20, "measuring")
    exact = gui.measurements(OBJ)[-1]["exact"]
    assert exact["requested"] == pytest.approx(cursor, abs=1e-6)  # 32-bit operator property
    assert exact["radius"] == 0.3  # the panel's radius
    assert abs(exact["angle"] - WEDGE_ANGLE) < 1e-6


def test_csv_export_through_the_file_browser(gui):
    """Open the CSV panel, press Export, name the file in the file browser, export."""
    items = gui.measurements(OBJ)
    # The CSV panel is closed, third from the sidebar's foot (then Radius Sweep, Measurement
    # Map), below the long Selected panel.
    export = gui.open_foot_panel("vg.export_csv", 3)
    gui.click(export)
    # The harness's preferences open the browser as a maximized area of the main window.
    browser = gui.wait_for(lambda s: s["file_browser"], 20, "the file browser")["file_browser"]
    # Keep the name the browser offers; the Export Measurements CSV button at the right.
    left, top, width, height = browser["EXECUTE"]
    gui.click((left + width - 60, top + height / 2))
    gui.wait_for(lambda s: s["file_browser"] is None, 20, "the file browser to close")

    def written(_state):
        return [p for p in (gui.tmp / "home").glob("*.csv") if p.is_file()]

    gui.wait_for(written, 20, "the CSV file in the folder the browser showed")
    (path,) = written(None)
    with path.open(newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert [float(row["Angle"]) for row in rows] == [item["exact"]["angle"] for item in items]
    assert [row["Mesh Name"] for row in rows] == [OBJ] * len(items)


def test_replay_with_measure_xyz_is_bit_for_bit(gui):
    """Every measurement the GUI recorded, re-measured by ``vg.measure_xyz`` at its recorded
    centre, radius and λ in ``blender -b`` of the same build: the same numbers, bit for bit."""
    items = gui.measurements(OBJ)
    assert len(items) >= 3
    requests = [
        {
            "center": item["exact"]["center"],
            "radius": item["exact"]["radius"],
            "lam": item["exact"]["lam"],
            "patch": item["patch"],
        }
        for item in items
    ]
    (gui.tmp / "requests.json").write_text(json.dumps(requests))
    gui.shell.check(
        f"blender -b --python {GUEST_REPO}/tests/gui/replay_check.py -- "
        f"{GUEST_TMP}/requests.json {GUEST_TMP}/replayed.json",
        timeout=300,
    )
    replayed = json.loads((gui.tmp / "replayed.json").read_text())
    for item, again in zip(items, replayed, strict=True):
        assert again is not None
        for key in ("angle", "fit", "fit_plus", "fit_minus", "center", "normal_plus"):
            assert again[key] == item["exact"][key], (key, item["number"])
