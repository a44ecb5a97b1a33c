"""The Edge Profile and Find Break Edges sessions in the startup screen's 3D viewport (headless
bpy): what they hold survives what a user does around them, keys held down decide nothing, and
the extension going away ends them. From a review of the modal tools; each test failed before."""

from __future__ import annotations

import importlib

import bpy
import numpy as np
import pytest
from test_drag import N, drag, pixel, ridge_vertex, view  # noqa: F401  (fixtures)


@pytest.fixture
def edge(vg):
    """The Edge Profile operator's module, with its session and translator."""
    return importlib.import_module(f"{vg.__name__}.operators.edge")


def window_pixel(view, point):  # noqa: F811
    x, y = pixel(view, point)
    return (view.region.x + x, view.region.y + y)


def two_clicks(edge, view):  # noqa: F811
    session = edge.EdgeSession(bpy.context, view.obj)
    for k in (10, N - 10):
        point = view.points[ridge_vertex(view, k)]
        assert session.handle(bpy.context, "click", window_pixel(view, point)) == "running"
    assert len(session.machine.clicks) == 2, session.machine.message
    return session


def test_keys_held_down_decide_nothing_and_focus_lost_cancels_nothing(vg, edge):
    find = importlib.import_module(f"{vg.__name__}.operators.find_edges")
    t = edge.translate_edge_event
    assert t("BACK_SPACE", "PRESS") == "undo" and t("BACK_SPACE", "PRESS", repeat=True) == "ignore"
    assert t("Z", "PRESS", ctrl=True) == "undo"
    assert t("Z", "PRESS", ctrl=True, shift=True) == "ignore"  # redo drops no click
    assert t("WINDOW_DEACTIVATE", "NOTHING") == "pass"  # Alt+Tab keeps the clicks
    f = find.translate_find_event
    assert f("A", "PRESS") == "accept" and f("A", "PRESS", repeat=True) == "ignore"
    assert f("X", "PRESS", repeat=True) == "ignore" and f("RET", "PRESS", repeat=True) == "ignore"


def test_a_right_click_off_the_viewport_reaches_blender_during_a_review(vg, view):  # noqa: F811
    """Every right-click was swallowed while a review ran, so no header's or sidebar's menu
    opened (Close Area among them). Off the viewport it now passes; on it, it does nothing."""
    find = importlib.import_module(f"{vg.__name__}.operators.find_edges")
    assert find.translate_find_event("RIGHTMOUSE", "PRESS") == "menu"
    assert find.translate_find_event("RIGHTMOUSE", "PRESS", ctrl=True) == "ignore"
    with bpy.context.temp_override(window=view.window, area=view.area, region=view.region):
        session = find.FindEdgesSession(bpy.context, view.obj, find.BreakEdgeParameters())
    try:
        header = next(r for r in view.area.regions if r.type == "HEADER" and r.width > 1)
        on_header = (header.x + header.width // 2, header.y + header.height // 2)
        middle = (view.region.x + view.region.width // 2, view.region.y + view.region.height // 2)
        assert session.handle(bpy.context, "menu", on_header) == "pass"
        assert session.handle(bpy.context, "menu", middle) == "running"
        assert session.machine.working  # the finding goes on either way
    finally:
        session.finish()


def test_another_scene_shown_keeps_the_clicks(edge, view):  # noqa: F811
    """Switching the window to another scene ended the session at the next mouse move, as "The
    object was deleted", with every click lost."""
    session = two_clicks(edge, view)
    home, other = view.window.scene, bpy.data.scenes.new("Other")
    try:
        view.window.scene = other
        assert session.handle(bpy.context, "pass", (0, 0)) == "pass"
        assert session.handle(bpy.context, "confirm") == "running"
        assert "not in this scene" in session.machine.message
        assert len(session.machine.clicks) == 2
    finally:
        view.window.scene = home
        bpy.data.scenes.remove(other)
    assert session.handle(bpy.context, "confirm") == "done"
    assert session.machine.phase is edge.EdgePhase.CONFIRMED
    session.finish()


def test_an_object_disabled_mid_session_says_why_and_keeps_the_clicks(edge, view):  # noqa: F811
    """Disable in Viewports (the monitor icon) mid-session: Blender then hands back the original
    object, without the modifiers the clicks were picked on. A click says why instead of tracing
    on that mesh, Enter records nothing, and once enabled again the session goes on."""
    session = two_clicks(edge, view)
    point = view.points[ridge_vertex(view, N // 2)]
    view.obj.hide_viewport = True
    try:
        assert not view.obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).is_evaluated
        assert session.handle(bpy.context, "click", window_pixel(view, point)) == "running"
        assert "disabled in the viewports" in session.machine.message
        assert len(session.machine.clicks) == 2
        assert session.handle(bpy.context, "confirm") == "running"
        assert "disabled in the viewports" in session.machine.message
        assert not len(view.obj.vg.edges)
    finally:
        view.obj.hide_viewport = False
    assert session.handle(bpy.context, "click", window_pixel(view, point)) == "running"
    assert len(session.machine.clicks) == 3, session.machine.message
    session.finish()


def test_enter_on_an_object_in_edit_mode_keeps_the_clicks(edge, view):  # noqa: F811
    """Enter with the object in Edit Mode ended the session, and then the record was refused:
    every click lost. Now Enter says why and the session goes on."""
    session = two_clicks(edge, view)
    bpy.ops.object.mode_set(mode="EDIT")
    try:
        assert session.handle(bpy.context, "confirm") == "running"
        assert "Edit Mode" in session.machine.message and len(session.machine.clicks) == 2
    finally:
        bpy.ops.object.mode_set(mode="OBJECT")
    assert session.handle(bpy.context, "confirm") == "done"
    session.finish()


def test_a_click_on_the_toolbar_is_not_a_click_on_the_mesh(edge, view):  # noqa: F811
    session = edge.EdgeSession(bpy.context, view.obj)
    tools = next(r for r in view.area.regions if r.type == "TOOLS" and r.width > 1)
    inside = (tools.x + tools.width // 2, tools.y + tools.height // 2)
    assert session.handle(bpy.context, "click", inside) == "pass"
    assert len(session.machine.clicks) == 0
    session.finish()


def test_the_extension_disabled_mid_session_takes_its_drawing_with_it(vg, edge, view):  # noqa: F811
    """Blender frees a running modal operator on unregister without calling its cancel(): the
    overlay's draw handler stayed installed until Blender quit."""
    session = two_clicks(edge, view)
    assert session.overlay.active
    vg.unregister()
    try:
        assert not session.overlay.active
    finally:
        vg.register()


def test_another_workspace_shown_keeps_the_session(edge, view):  # noqa: F811
    """A session waits while another workspace is shown (its viewport still exists), and ends
    only when its viewport is closed; Enter records once back."""
    session = two_clicks(edge, view)
    home = view.window.workspace
    other = next(w for w in bpy.data.workspaces if w != home)
    view.window.workspace = other
    try:
        assert session.area is not None  # the viewport kept, in the other workspace's screen
        assert session.handle(bpy.context, "pass", (0, 0)) == "pass"
    finally:
        view.window.workspace = home
    assert session.handle(bpy.context, "confirm") == "done"
    assert session.machine.phase is edge.EdgePhase.CONFIRMED
    session.finish()


def test_headers_give_a_scaled_objects_lengths_in_mesh_units(edge, view):  # noqa: F811
    """On an object scaled by 0.001 the Edge Profile header showed its path and spacing in the
    scene's units as if they were world lengths ("path 3.3 km" for a 3.3 m path); the drag's
    header already said "mesh units". Oracle: the lengths the panel holds."""
    session = two_clicks(edge, view)
    settings = bpy.context.scene.vg_settings
    plain = session.header_text(bpy.context.scene)
    view.obj.scale = (0.001, 0.001, 0.001)
    bpy.context.view_layer.update()
    try:
        header = session.header_text(bpy.context.scene)
        assert f"every {settings.edge_spacing:.5g} mesh units" in header
        assert f"r {settings.radius:.5g} mesh units" in header and "mesh units" not in plain
    finally:
        view.obj.scale = (1.0, 1.0, 1.0)
        session.finish()


def test_the_drawing_follows_the_object_moved_mid_session(edge, view):  # noqa: F811
    """The overlay kept the object's place at the last click: moved in the Properties editor,
    the clicks were drawn where it had been while the next click's ray cast used the new place.
    Oracle: the clicks (mesh coordinates) placed by the new matrix."""
    session = two_clicks(edge, view)
    view.obj.location = view.obj.location + view.obj.matrix_world.col[2].xyz * 0.5
    bpy.context.view_layer.update()
    assert session.handle(bpy.context, "pass", (0, 0)) == "pass"  # a mouse move anywhere
    matrix = np.array(view.obj.matrix_world, dtype=np.float64)
    clicks = np.array(session.machine.clicks)
    expected = clicks @ matrix[:3, :3].T + matrix[:3, 3]
    np.testing.assert_allclose(session.overlay._clicks, expected, atol=1e-5)
    session.finish()
