"""Find Break Edges in a real Blender window, pressed with real mouse and key events (xdotool).

One GUI Blender per Debian suite (trixie: Blender 4.3, unstable: 5.2) on the synthetic bone
fragment of ``scene.py`` (its rims are the break edges the finder finds), the tests in file
order on that one window: Esc at the review records nothing; a candidate accepted with a click
and A, another rejected with a click and X, a third trimmed with T and two clicks (left
undecided), Enter: one Edge Profile with its stations; Ctrl+Z
removes all of it in one step. The harness reports the running review (phase, candidates on
screen, decisions). ``VG_GUI_PICTURES=DIR`` keeps the screenshots; ``VG_GUI_DOC_PICTURE=PATH``
writes the review's picture, one candidate accepted and one rejected
(docs/images/find_edges.png).
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import numpy as np
import pytest

from vg_addon.formats.png import encode_png

OBJ = "BoneFragment"
GUI_SCENE = "fragment"  # conftest's gui fixture builds this scene


@pytest.fixture(scope="module")
def places(gui):
    """Screen places found once per window and shared by the tests. Next Break is pressed
    first: an undo step of its own, so the undo test below finds the file as it was before the
    review (the scene is built by the harness, not by an undo step)."""
    gui.open_goniometer_tab()
    gui.click(gui.find_button("UI", "vg.next_break"))
    gui.wait_for(lambda s: s["objects"][OBJ]["break_number"] == 2, 20, "Next Break")
    return {"button": gui.find_button("UI", "vg.find_break_edges", upward=True)}


# -- helpers -------------------------------------------------------------------------------------
def edges(gui) -> list[dict]:
    return gui.state()["objects"][OBJ]["edges"]


def review(state):
    found = state.get("find_edges")
    return found if found and found["phase"] == "REVIEW" else None


def running(state) -> bool:
    return any("find_break_edges" in op.lower() for op in state["modal_operators"])


def start_review(gui, places) -> dict:
    gui.click(places["button"])
    return review(gui.wait_for(review, 60, "the candidates"))


def clear_spot(found, index) -> tuple[float, float]:
    """A screen point on candidate ``index`` as far as can be from every other candidate."""
    spots = [xy for xy in found["candidates"][index]["screen"] if xy]
    assert spots, f"candidate {index + 1} is not in view"
    best = max(spots, key=lambda xy: clear_of(found, index, xy))
    assert clear_of(found, index, best) > 25, f"candidate {index + 1} is not clear of the others"
    return tuple(best)


def decide(gui, found, index: int, key: str, decision: str) -> dict:
    """Click candidate ``index`` (a real click on its line), press ``key``; the review after."""
    gui.click(clear_spot(found, index))
    assert review(gui.settle())["selected"] == index
    gui.key(key)
    return review(
        gui.wait_for(lambda s: review(s)["candidates"][index]["decision"] == decision, 10, key)
    )


def trim_third(gui, found) -> dict:
    """T on candidate 3 and two clicks on it a third of the way along apart (on a loop, a third
    click between them picks that part): it is replaced by the part between them, still
    undecided (so nothing of it is recorded)."""
    before = found["candidates"][2]
    clear = [k for k, xy in enumerate(before["screen"]) if xy and clear_of(found, 2, xy) > 25]
    ends = [clear[0], next((k for k in clear if k - clear[0] >= 8), None)]
    assert ends[1] is not None, "candidate 3 is not clear to trim"
    gui.click(tuple(before["screen"][ends[0]]))
    assert review(gui.settle())["selected"] == 2
    gui.key("t")
    says_once(gui.settle()["find_edges"], "TRIMMING", "click the first end of the part to keep")
    gui.click(tuple(before["screen"][ends[1]]))  # either order
    says_once(gui.settle()["find_edges"], "TRIMMING", "click the second end of the part to keep")
    gui.click(tuple(before["screen"][ends[0]]))
    if before["closed"]:
        trimming = says_once(gui.settle()["find_edges"], "TRIMMING", "part of the loop to keep")
        assert trimming["message"] == "Click the part of the loop to keep."
        between = next((k for k in clear if ends[0] < k < ends[1]), None)
        assert between is not None, "no clear point on candidate 3 between the trim's ends"
        gui.click(tuple(before["screen"][between]))
    after = review(
        gui.wait_for(
            lambda s: review(s)["candidates"][2]["length"] < before["length"], 20, "the trim"
        )
    )
    trimmed = after["candidates"][2]
    assert trimmed["decision"] == "pending" and trimmed["number"] == 3
    # The screen points are evenly spaced path vertices: the part kept is about their share.
    share = (ends[1] - ends[0]) / len(before["screen"])
    assert abs(trimmed["length"] / before["length"] - share) < 0.08
    return after


def says_once(found, phase: str, hint: str) -> dict:
    """The review is in ``phase`` and its header (the text over the viewport) gives ``hint``
    once, with Esc's way back once and no review keys; the review."""
    assert found["phase"] == phase
    header = found["header"].lower()
    assert header.count(hint) == 1, found["header"]
    assert header.count("esc") == 1 and "a accept" not in header, found["header"]
    return found


def clear_of(found, index, xy) -> float:
    """How far (pixels) the screen point ``xy`` is from every candidate but ``index``."""
    others = [o for k, c in enumerate(found["candidates"]) if k != index for o in c["screen"] if o]
    return min((float(np.hypot(xy[0] - o[0], xy[1] - o[1])) for o in others), default=1e9)


def keep_picture(path: Path) -> None:
    folder = os.environ.get("VG_GUI_PICTURES")
    if folder:
        Path(folder).mkdir(parents=True, exist_ok=True)
        shutil.copy(path, Path(folder) / path.name)


def overlay_shot(gui, name: str) -> Path:
    """The viewport left of the sidebar, below the header, as PNG."""
    regions = gui.state()["regions"]
    left, top, width, height = regions["WINDOW"]
    width = regions["UI"][0] - left
    path = gui.tmp / f"{name}_{gui.suite}.png"
    gui.save_png(name, path, crop=(left, top, width, height))
    keep_picture(path)
    return path


def review_picture(gui, found, name: str) -> Path:
    """The viewport's header rows (the review's counts and keys) over the part of the viewport
    the candidates are drawn in, as one PNG (kept like the screenshots)."""
    regions = gui.state()["regions"]
    shot = gui.screenshot(name)
    left, right = regions["WINDOW"][0], regions["UI"][0]
    headers = [regions[k] for k in ("HEADER", "TOOL_HEADER") if k in regions]
    top = min(r[1] for r in headers)
    bottom = max(r[1] + r[3] for r in headers)
    spots = np.array([xy for c in found["candidates"] for xy in c["screen"] if xy])
    y0, y1 = spots[:, 1].min() - 70, spots[:, 1].max() + 70
    view = shot[max(int(y0), bottom) : int(y1), left:right]
    head = shot[top:bottom, left:right]
    path = gui.tmp / f"{name}_{gui.suite}.png"
    path.write_bytes(encode_png(np.vstack([head, view])))
    keep_picture(path)
    return path


def coloured(shot: np.ndarray, box) -> int:
    """Pixels in ``box`` drawn in a saturated colour (the candidates' lines: red to green)."""
    left, top, width, height = (int(v) for v in box)
    cut = shot[top : top + height, left : left + width].astype(int)
    return int(((cut.max(axis=2) - cut.min(axis=2)) > 120).sum())


# -- the session ---------------------------------------------------------------------------------
def test_esc_at_the_review_records_nothing(gui, places):
    before = gui.state()["objects"][OBJ]
    found = start_review(gui, places)
    assert len(found["candidates"]) >= 2
    confidences = [c["confidence"] for c in found["candidates"]]
    assert confidences == sorted(confidences, reverse=True)
    assert [c["number"] for c in found["candidates"]] == list(range(1, len(confidences) + 1))
    gui.move(clear_spot(found, 0))
    gui.key("Escape")
    state = gui.wait_for(lambda s: not running(s), 20, "the review to end")
    assert state["find_edges"] is None
    after = state["objects"][OBJ]
    assert after["edges"] == before["edges"] == []
    assert after["measurements"] == before["measurements"]


def test_candidates_are_drawn_numbered_and_coloured(gui, places):
    """The overlay over the viewport: the lines in their confidence colours where the
    candidates are (none before the review, none after it)."""
    region = gui.state()["regions"]["WINDOW"]
    plain = coloured(gui.screenshot("plain"), region)
    found = start_review(gui, places)
    gui.settle(3)
    shot = gui.screenshot("overlay")
    picture = overlay_shot(gui, "find_edges")
    assert coloured(shot, region) > plain + 500, f"no candidate lines drawn ({picture})"
    # Along each candidate, a coloured pixel close by on screen.
    for candidate in found["candidates"]:
        near = 0
        for xy in candidate["screen"]:
            if xy is not None:
                near += coloured(shot, (xy[0] - 4, xy[1] - 4, 9, 9)) > 0
        assert near >= 12, f"candidate {candidate['number']} is not drawn ({picture})"
    gui.key("Escape")
    gui.wait_for(lambda s: not running(s), 20, "the review to end")
    gui.settle(3)
    assert coloured(gui.screenshot("after"), region) <= plain + 50, "the overlay is removed"


def test_accept_one_reject_one_and_enter_records_one_edge_profile(gui, places):
    found = start_review(gui, places)
    n = len(found["candidates"])
    decide(gui, found, 1, "a", "accepted")
    found = decide(gui, found, 0, "x", "rejected")
    assert [c["decision"] for c in found["candidates"]] == (
        ["rejected", "accepted"] + ["pending"] * (n - 2)
    )
    found = trim_third(gui, found) if n >= 3 else found
    gui.settle(3)
    picture = review_picture(gui, found, "find_edges_review")
    target = os.environ.get("VG_GUI_DOC_PICTURE")
    if target:
        shutil.copy(picture, target)
    accepted_length = found["candidates"][1]["length"]
    gui.key("Return")
    state = gui.wait_for(lambda s: not running(s) and s["objects"][OBJ]["edges"], 120, "the edge")
    (edge,) = state["objects"][OBJ]["edges"]
    stations = [m for m in state["objects"][OBJ]["measurements"] if "arc_length" in m["exact"]]
    spacing = stations[0]["exact"]["spacing"]
    assert edge["n_stations"] == len(stations) >= accepted_length / spacing - 1
    assert {m["break_number"] for m in stations} == {edge["break_number"]}
    assert np.isfinite(edge["mean"]) and 0.0 < edge["mean"] < 180.0
    assert len(state["objects"][OBJ]["measurements"]) == len(stations)
    assert state["objects"][OBJ]["break_number"] == edge["break_number"] + 1 == 3


def test_ctrl_z_undoes_the_whole_acceptance_in_one_step(gui, places):
    before = gui.state()["objects"][OBJ]
    assert len(before["edges"]) == 1 and len(before["measurements"]) > 2
    assert before["break_number"] == 3
    left, top, width, height = gui.state()["regions"]["WINDOW"]
    gui.move((left + width // 2, top + height // 2))
    gui.key("ctrl+z")
    state = gui.wait_for(lambda s: not s["objects"][OBJ]["edges"], 20, "the undo")
    after = state["objects"][OBJ]
    assert after["measurements"] == [] and after["break_number"] == 2, "as after Next Break"
    gui.key("ctrl+shift+z")
    state = gui.wait_for(lambda s: s["objects"][OBJ]["edges"], 20, "the redo")
    assert state["objects"][OBJ]["measurements"] == before["measurements"]


def test_closing_the_viewport_mid_review_ends_it_recording_nothing(gui, places):
    """The last test of the window: it closes the 3D viewport. A right-click on a header button
    (let through during the review since right-clicks off the view reach Blender), then its
    menu's Header > Close Area, by keys: the review ends at once, nothing recorded, no error."""
    before = gui.state()["objects"][OBJ]
    # The tests before opened the Selected Measurement panel above the button: found again.
    gui.scroll_sidebar(30)
    places = {"button": gui.find_button("UI", "vg.find_break_edges", upward=True)}
    found = start_review(gui, places)
    assert found["candidates"]
    left, top, _width, height = gui.state()["regions"]["HEADER"]
    gui.click((left + 20, top + height // 2), button=3)  # the editor-type button
    gui.settle(3)
    for key in ("Up", "Right", "Up"):  # the menu's last item, Header; its last, Close Area
        gui.key(key)
        gui.settle(2)
    gui.screenshot("close_area_menu")
    gui.key("Return")
    state = gui.wait_for(lambda s: not running(s), 20, "the review to end")
    assert state["find_edges"] is None and state["regions"] == {}, "the viewport is closed"
    after = state["objects"][OBJ]
    assert after["edges"] == before["edges"]
    assert after["measurements"] == before["measurements"]
