"""Import .pp in a real Blender window, pressed with real mouse and key events (xdotool).

One GUI Blender per Debian suite (trixie: Blender 4.3, unstable: 5.2) on the 100° wedge of
``scene.py``: a MeshLab picked-points file named after the wedge's mesh, three vertices of its
crease (the break edge) in the mesh's own coordinates, chosen in the file browser the Edge
Profiles panel's **.pp** button opens. One Edge Profile is recorded, its stations the core's
``Surface.measure_along`` on the same points, as Blender stores the mesh (float32), bit for bit.
"""

from __future__ import annotations

import numpy as np
from test_gui_buttons import open_browser, press_browser_button, type_file_name

from vg_addon.method.surface import Surface
from vg_addon.synthetic_meshes import wedge

OBJ = "Wedge"  # the object's and its mesh's name (scene.OBJECT_NAME)
WEDGE_ANGLE = 100.0
RADIUS = 0.3  # scene.PANEL_RADIUS
SPACING, LAM, PATCH = 1.0, 2.0, "euclidean"  # the panel's defaults (properties.py)


def wedge_as_stored():
    """The scene's wedge (``scene.build_wedge``) as Blender stores it: float32 coordinates."""
    shape = wedge(WEDGE_ANGLE, n=40, irregular=True, seed=3)
    return shape.points.astype(np.float32).astype(np.float64), shape.triangles


def crease_points(points) -> np.ndarray:
    """The crease vertices (y = z = 0) nearest x = -0.6, 0 and 0.6: start, via and end."""
    crease = points[(points[:, 1] == 0.0) & (points[:, 2] == 0.0)]
    return np.array([crease[np.argmin(np.abs(crease[:, 0] - x))] for x in (-0.6, 0.0, 0.6)])


def write_pp(path, points) -> None:
    rows = "\n".join(
        f' <point x="{x!r}" y="{y!r}" z="{z!r}" name="{k}" active="1"/>'
        for k, (x, y, z) in enumerate(points.tolist())
    )
    path.write_text(
        "<!DOCTYPE PickedPoints>\n<PickedPoints>\n <DocumentData>\n"
        f'  <DataFileName name="{OBJ}.ply"/>\n </DocumentData>\n{rows}\n</PickedPoints>\n'
    )


def test_import_pp_button_records_the_cores_edge_profile(gui):
    """The .pp button pressed, Wedge.pp typed in its file browser and confirmed: one Edge
    Profile whose stations are the core's profile along the file's crease points."""
    points, triangles = wedge_as_stored()
    picked = crease_points(points)
    assert picked[-1, 0] - picked[0, 0] > 1.0, "the crease vertices span more than a station"
    home = gui.tmp / "home"  # /vg/tmp/home in the root: Blender's home, where its browser opens
    write_pp(home / f"{OBJ}.pp", picked)
    profile = Surface(points, triangles).measure_along(picked, SPACING, RADIUS, LAM, PATCH)

    gui.open_goniometer_tab()
    find = gui.find_button("UI", "vg.find_break_edges", upward=True)
    y = int(find[1])
    button = gui.find_button("UI", "vg.import_picked_points", rows=range(y - 6, y + 7, 3))
    before = gui.state()["objects"][OBJ]
    assert before["edges"] == [] and before["measurements"] == []
    browser = open_browser(gui, button)
    assert browser["params"]["filter_glob"] == "*.pp"
    assert browser["params"]["directory"].rstrip("/") == "/vg/tmp/home"
    if browser["params"]["filename"] != f"{OBJ}.pp":  # choose it, as a user would
        type_file_name(gui, browser, f"{OBJ}.pp")
    if gui.state()["file_browser"] is not None:
        press_browser_button(gui, gui.state()["file_browser"])
    state = gui.wait_for(lambda s: s["objects"][OBJ]["edges"], 60, "the edge profile")

    (edge,) = state["objects"][OBJ]["edges"]
    stations = state["objects"][OBJ]["measurements"]
    assert edge["n_stations"] == len(stations) == profile.n_stations >= 1
    got = [(m["exact"]["angle"], m["exact"]["center"], m["exact"]["arc_length"]) for m in stations]
    want = [
        (m.angle, m.center.tolist(), float(arc))
        for m, arc in zip(profile.stations, profile.arc_lengths, strict=True)
    ]
    assert got == want
    assert all(abs(angle - WEDGE_ANGLE) < 1e-6 for angle, _, _ in got)
    assert edge["mean"] == float(np.float32(profile.mean))  # a FloatProperty: float32
    assert {m["break_number"] for m in stations} == {edge["break_number"]}
