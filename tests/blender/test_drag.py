"""The drag tool in real bpy: ray cast through a real 3D-view region, the drag session driven by
translated events, EXEC_DEFAULT equal to vg.measure_xyz, and clean exits.

Headless limits (see docs/ARCHITECTURE.md, "Tests"): ``INVOKE_DEFAULT`` cannot run without an event loop,
so ``invoke``/``modal`` themselves are not called; they only forward to ``DragSession`` and
``translate_event``, which are tested here. The view matrices cannot be recomputed in background
mode, so the test mesh is placed in front of the startup file's saved perspective view.
"""

import dataclasses
import importlib
from types import SimpleNamespace

import bpy
import numpy as np
import pytest
from bpy_extras import view3d_utils
from bpy_helpers import exact, local_points, mesh_object, snapshot
from mathutils import Matrix, Vector

from vg_addon.method.stability import SMALL_PATCH_VERTICES

N = 31  # grid vertices per side
SCALE = 2.0


def folded_grid(n: int = N):
    """A square grid folded at 90° along the x axis, ridge at z = 0, faces going down to -z,
    wound so the normals point out (+z side): the method needs outward normals."""
    s = np.linspace(-1.0, 1.0, n)
    x, t = np.meshgrid(s, s, indexing="ij")
    x, t = x.ravel(), t.ravel()
    points = np.column_stack([x, t * np.sqrt(0.5), -np.abs(t) * np.sqrt(0.5)])
    grid = np.arange(n * n).reshape(n, n)
    a, b = grid[:-1, :-1].ravel(), grid[1:, :-1].ravel()
    c, d = grid[1:, 1:].ravel(), grid[:-1, 1:].ravel()
    triangles = np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    return points, triangles


@pytest.fixture
def drag(vg):
    """The drag module, its operator registered (by the extension, or here until it is)."""
    module = importlib.import_module(f"{vg.__name__}.operators.drag")
    registered_here = not hasattr(bpy.types, "VG_OT_measure_drag")
    if registered_here:
        bpy.utils.register_class(module.VG_OT_measure_drag)
    yield module
    if registered_here:
        bpy.utils.unregister_class(module.VG_OT_measure_drag)


@pytest.fixture
def view(drag):
    """The startup screen's 3D viewport, as the context, with a ridge mesh facing its camera."""
    windows = bpy.context.window_manager.windows
    if not len(windows):
        pytest.skip("this bpy build has no window in background mode: no 3D view to test with")
    window = windows[0]
    area = next((a for a in window.screen.areas if a.type == "VIEW_3D"), None)
    if area is None:
        pytest.skip("the startup screen has no 3D viewport")
    region = next(r for r in area.regions if r.type == "WINDOW")
    rv3d = area.spaces.active.region_3d
    with bpy.context.temp_override(window=window, area=area, region=region):
        # Put the mesh at the middle of the view, its +z towards the camera.
        middle = (region.width / 2, region.height / 2)
        target = view3d_utils.region_2d_to_location_3d(region, rv3d, middle, rv3d.view_location)
        camera = rv3d.view_matrix.inverted().to_3x3()
        points, triangles = folded_grid()
        obj = mesh_object("Ridge", points * SCALE, triangles)
        obj.matrix_world = Matrix.Translation(target) @ camera.to_4x4()
        bpy.context.view_layer.update()
        world = np.array(obj.matrix_world)
        world_points = (points * SCALE) @ world[:3, :3].T + world[:3, 3]
        yield SimpleNamespace(
            window=window,
            area=area,
            region=region,
            rv3d=rv3d,
            obj=obj,
            points=world_points,
            local=local_points(obj).astype(np.float64),
            matrix=world,
            right=np.array(camera.col[0]),
        )


def to_local(view, point) -> np.ndarray:
    """Mesh coordinates of a world point of the view's object."""
    return np.linalg.inv(view.matrix) @ np.append(np.asarray(point, dtype=np.float64), 1.0)


def pixel(view, point):
    """Region pixel coordinates of a world point."""
    coord = view3d_utils.location_3d_to_region_2d(view.region, view.rv3d, Vector(point))
    assert coord is not None
    return (float(coord[0]), float(coord[1]))


def ridge_vertex(view, k: int = N // 2) -> int:
    """Index of vertex ``k`` along the ridge (t = 0)."""
    return k * N + N // 2


def start(drag, view, vertex: int, offset=(0.3, -0.2)):
    x, y = pixel(view, view.points[vertex])
    return drag.DragSession.start(bpy.context, (x + offset[0], y + offset[1]))


def send(drag, session, event_type, value="PRESS", coord=None, **modifiers):
    action, argument = drag.translate_event(event_type, value, **modifiers)
    return session.handle(bpy.context, action, argument, coord)


def handler_removed(handle) -> bool:
    """True if Blender no longer has the draw handler (removing it again is an error)."""
    try:
        bpy.types.SpaceView3D.draw_handler_remove(handle, "WINDOW")
    except ValueError:
        return True
    return False


def record_fields(item) -> dict:
    """Everything a measurement records, except its number and date."""
    keys = ("exact", "patch", "n_vertices", "n_plus", "n_minus", "fingerprint", "note")
    return {key: getattr(item, key) for key in keys}


# -- the ray cast and the radius through a real region ---------------------------------------


def pixel_size(drag, view, point) -> float:
    """World size of one pixel on the view plane through ``point``."""
    x, y = pixel(view, point)
    return drag.view_plane_radius(
        view.region, view.rv3d, (x + 1.0, y), to_local(view, point)[:3], view.matrix
    )


def test_ray_cast_from_region_pixels_hits_the_projected_vertices(drag, view):
    # view3d_utils un-projects with float32 matrices, so a hit is exact to a fraction of a
    # pixel, not to float64: well within the vertex spacing that snapping resolves.
    depsgraph = bpy.context.evaluated_depsgraph_get()
    spacing = 2.0 * SCALE / (N - 1)
    for vertex in (ridge_vertex(view), ridge_vertex(view, 5), 7 * N + 3, 20 * N + 25):
        point = view.points[vertex]
        coord = pixel(view, point)
        hit = drag.ray_cast_object(view.obj, depsgraph, view.region, view.rv3d, coord)
        assert hit is not None  # in mesh coordinates, where it is measured
        local = view.local[vertex]
        assert np.linalg.norm(hit - local) < min(pixel_size(drag, view, point), spacing / 10)
        nearest = np.argmin(np.linalg.norm(view.local - hit, axis=1))
        assert nearest == vertex
    assert drag.ray_cast_object(view.obj, depsgraph, view.region, view.rv3d, (3, 3)) is None


def blender_hit(view, coord) -> np.ndarray:
    """Where Blender's own ray cast on the evaluated object hits it through region pixel
    ``coord``, in mesh coordinates: the oracle of the kept ray-cast tree."""
    obj_eval = view.obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
    to_local_matrix = obj_eval.matrix_world.inverted_safe()
    origin = view3d_utils.region_2d_to_origin_3d(view.region, view.rv3d, Vector(coord))
    direction = view3d_utils.region_2d_to_vector_3d(view.region, view.rv3d, Vector(coord))
    hit, location, _n, _f = obj_eval.ray_cast(
        to_local_matrix @ origin, to_local_matrix.to_3x3() @ direction
    )
    assert hit
    return np.array(location)


def test_ray_tree_survives_measuring_and_follows_edits(drag, view, vg):
    """The press after a measurement must not wait for a new ray-cast tree (the colour write
    makes Blender rebuild its own), yet an edited mesh must be hit where it now is. Oracle:
    Blender's own ray cast on the evaluated object."""
    mesh_data = importlib.import_module(f"{vg.__name__}.bridge.mesh_data")
    obj = view.obj
    vertex = ridge_vertex(view)
    coord = pixel(view, view.points[vertex])

    def tree():
        depsgraph = bpy.context.evaluated_depsgraph_get()
        return mesh_data.ray_tree_for(obj, mesh_data.evaluated_geometry(obj, depsgraph))

    depsgraph = bpy.context.evaluated_depsgraph_get()
    first = drag.ray_cast_object(obj, depsgraph, view.region, view.rv3d, coord)
    # The same surface point, to float32 ray-cast precision (bpy 5.3's own ray cast can differ
    # from the tree's in the last bits).
    np.testing.assert_allclose(first, blender_hit(view, coord), rtol=0, atol=1e-5)
    kept = tree()
    bpy.context.view_layer.objects.active = obj
    result = bpy.ops.vg.measure_xyz(
        "EXEC_DEFAULT", location=tuple(view.points[vertex]), radius=0.5, stability=False
    )
    assert result == {"FINISHED"}
    assert tree() is kept  # painting the sides kept it
    # Lift the whole mesh by 0.25 along its own z (towards the camera): the ray must hit the
    # moved surface, not the kept tree's.
    positions = np.empty(len(obj.data.vertices) * 3, dtype=np.float32)
    obj.data.vertices.foreach_get("co", positions)
    positions[2::3] += 0.25
    obj.data.vertices.foreach_set("co", positions)
    obj.data.update()
    depsgraph = bpy.context.evaluated_depsgraph_get()
    moved = drag.ray_cast_object(obj, depsgraph, view.region, view.rv3d, coord)
    assert tree() is not kept
    np.testing.assert_allclose(moved, blender_hit(view, coord), rtol=0, atol=1e-5)
    assert moved[2] == pytest.approx(first[2] + 0.25, abs=1e-3)


def test_ray_cast_follows_a_mesh_moved_by_a_frame_change(drag, view, vg):
    """An animated shape key lifts the mesh between two frames; a frame change sends no
    depsgraph update, yet the press must hit the mesh where it now is, not the kept ray-cast
    tree of the earlier frame. Oracle: Blender's own ray cast on the evaluated object."""
    obj = view.obj
    coord = pixel(view, view.points[ridge_vertex(view)])
    obj.shape_key_add(name="Basis")
    key = obj.shape_key_add(name="Lifted")
    lifted = local_points(obj).copy()
    lifted[:, 2] += 0.25  # along the mesh's own z, towards the camera
    key.data.foreach_set("co", lifted.ravel())
    for frame, value in ((1, 0.0), (10, 1.0)):
        key.value = value
        key.keyframe_insert("value", frame=frame)
    scene = bpy.context.scene
    scene.frame_set(1)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    first = drag.ray_cast_object(obj, depsgraph, view.region, view.rv3d, coord)
    scene.frame_set(10)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    moved = drag.ray_cast_object(obj, depsgraph, view.region, view.rv3d, coord)
    np.testing.assert_allclose(moved, blender_hit(view, coord), rtol=0, atol=1e-5)
    assert moved[2] == pytest.approx(first[2] + 0.25, abs=1e-3)


def test_radius_is_measured_on_the_view_plane(drag, view):
    center = view.points[ridge_vertex(view)]
    tolerance = pixel_size(drag, view, center)
    assert 0 < tolerance < 0.05
    for radius in (0.05, 0.4, 1.3):
        coord = pixel(view, center + radius * view.right)
        measured = drag.view_plane_radius(
            view.region, view.rv3d, coord, to_local(view, center)[:3], view.matrix
        )
        assert measured == pytest.approx(radius, abs=tolerance)


def test_radius_is_in_mesh_units_on_a_scaled_object(drag, view):
    view.obj.scale = (2.0, 2.0, 2.0)
    bpy.context.view_layer.update()
    matrix = np.array(view.obj.matrix_world, dtype=np.float64)
    center = view.local[ridge_vertex(view)]
    center_world = matrix[:3, :3] @ center + matrix[:3, 3]
    x, y = pixel(view, center_world)
    one_pixel = drag.view_plane_radius(view.region, view.rv3d, (x + 1.0, y), center, matrix)
    coord = pixel(view, center_world + 0.8 * view.right)  # 0.8 in the world: 0.4 on the mesh
    measured = drag.view_plane_radius(view.region, view.rv3d, coord, center, matrix)
    assert measured == pytest.approx(0.4, abs=one_pixel)


# -- the drag session, driven by translated events --------------------------------------------


def test_drag_and_release_records_exactly_what_measure_xyz_records(drag, view):
    center_vertex = ridge_vertex(view)
    session = start(drag, view, center_vertex)
    assert np.array_equal(session.machine.center, view.local[center_vertex])  # snapped
    handle = session.overlay.handle
    assert session.overlay.active
    far = pixel(view, view.points[center_vertex] + 0.7 * view.right)
    assert send(drag, session, "MOUSEMOVE", "NOTHING", far) == drag.RUNNING
    assert session.machine.n_vertices > 50 and session.machine.message == ""
    assert "vertices" in session.header_text(bpy.context.scene)
    assert send(drag, session, "LEFTMOUSE", "RELEASE", far) == drag.DONE
    session.finish(bpy.context)
    assert handler_removed(handle) and not session.overlay.active

    values = drag.record_properties(session)
    record = session.machine.record
    tolerance = pixel_size(drag, view, view.points[center_vertex])
    assert values["radius"] == record.radius == pytest.approx(0.7, abs=tolerance)
    assert bpy.ops.vg.measure_drag("EXEC_DEFAULT", **values) == {"FINISHED"}
    assert bpy.ops.vg.measure_xyz("EXEC_DEFAULT", **values) == {"FINISHED"}
    dragged, typed = view.obj.vg.measurements
    assert record_fields(dragged) == record_fields(typed)
    numbers = exact(dragged)
    assert numbers["angle"] == record.measurement.angle  # the preview measured the same thing
    assert numbers["center"] == list(view.local[center_vertex])
    assert values["space"] == "MESH"
    assert dragged.n_vertices == session.machine.n_vertices
    assert abs(numbers["angle"] - 90.0) < 1e-3


@pytest.mark.parametrize("stability", [False, True])
def test_the_release_records_its_own_measurement_equal_to_measure_xyz(drag, view, stability):
    """A finished drag records the measurement its release took (no second measurement), and
    it equals bit for bit what vg.measure_xyz records with the drag's stored values."""
    bpy.context.scene.vg_settings.stability = stability
    try:
        session = start(drag, view, ridge_vertex(view))
        far = pixel(view, view.points[ridge_vertex(view)] + 0.6 * view.right)
        send(drag, session, "MOUSEMOVE", "NOTHING", far)
        assert send(drag, session, "LEFTMOUSE", "RELEASE", far) == drag.DONE
        session.finish(bpy.context)
        released = session.machine.record.measurement
        dragged = drag.record_drag(bpy.context, session)
        assert exact(dragged)["angle"] == released.angle
        small = released.n_vertices < SMALL_PATCH_VERTICES  # carries its figure unasked
        assert (released.stability is not None) == (stability or small)
        values = drag.record_properties(session)
        assert bpy.ops.vg.measure_xyz("EXEC_DEFAULT", stability=stability, **values) == {"FINISHED"}
        first, typed = view.obj.vg.measurements
        assert record_fields(first) == record_fields(typed)
        assert exact(first) | {"date": None} == exact(typed) | {"date": None}
    finally:
        bpy.context.scene.vg_settings.stability = False


def test_typed_radius_is_recorded_exactly(drag, view):
    session = start(drag, view, ridge_vertex(view))
    far = pixel(view, view.points[ridge_vertex(view)] + 0.2 * view.right)
    send(drag, session, "MOUSEMOVE", "NOTHING", far)
    for key in ("ZERO", "PERIOD", "FOUR", "THREE", "NUMPAD_7"):
        assert send(drag, session, key) == drag.RUNNING
    assert session.machine.radius == 0.437
    assert "typed 0.437" in session.header_text(bpy.context.scene)
    send(drag, session, "MOUSEMOVE", "NOTHING", far)  # typing wins over the mouse
    assert session.machine.radius == 0.437
    assert send(drag, session, "RET") == drag.DONE
    session.finish(bpy.context)
    bpy.ops.vg.measure_drag("EXEC_DEFAULT", **drag.record_properties(session))
    assert exact(view.obj.vg.measurements[0])["radius"] == 0.437


def test_lam_keys_and_ctrl_wheel_remeasure_and_are_recorded(drag, view):
    session = start(drag, view, ridge_vertex(view))
    far = pixel(view, view.points[ridge_vertex(view)] + 0.6 * view.right)
    send(drag, session, "MOUSEMOVE", "NOTHING", far)
    assert send(drag, session, "L") == drag.RUNNING
    assert send(drag, session, "WHEELUPMOUSE", ctrl=True) == drag.RUNNING
    assert send(drag, session, "L", shift=True) == drag.RUNNING
    assert session.machine.lam == 2.25
    assert session.machine.measurement is not None and session.machine.measurement.lam == 2.25
    assert "angle" in session.header_text(bpy.context.scene)
    # navigation passes through, without changing anything
    for event_type in ("WHEELUPMOUSE", "MIDDLEMOUSE"):
        assert send(drag, session, event_type) == drag.PASS
    assert session.machine.lam == 2.25
    send(drag, session, "LEFTMOUSE", "RELEASE", far)
    session.finish(bpy.context)
    values = drag.record_properties(session)
    assert values["seg_param"] == 2.25
    bpy.ops.vg.measure_drag("EXEC_DEFAULT", **values)
    assert exact(view.obj.vg.measurements[0])["lam"] == 2.25


@pytest.mark.parametrize("cancel", [("ESC", "PRESS"), ("RIGHTMOUSE", "PRESS")])
def test_cancel_changes_nothing_and_removes_the_draw_handler(drag, view, cancel):
    before = snapshot(view.obj)
    session = start(drag, view, ridge_vertex(view))
    handle = session.overlay.handle
    far = pixel(view, view.points[ridge_vertex(view)] + 0.5 * view.right)
    send(drag, session, "MOUSEMOVE", "NOTHING", far)
    assert send(drag, session, *cancel) == drag.DONE
    session.finish(bpy.context)
    assert session.machine.phase == "cancelled" and drag.record_properties(session) is None
    assert handler_removed(handle)
    assert snapshot(view.obj) == before
    session.finish(bpy.context)  # a second finish is harmless


def test_small_drag_previews_too_few_and_records_nothing(drag, view):
    before = snapshot(view.obj)
    session = start(drag, view, ridge_vertex(view))
    near = pixel(view, view.points[ridge_vertex(view)] + 0.01 * view.right)
    send(drag, session, "MOUSEMOVE", "NOTHING", near)
    assert session.machine.n_vertices < 6
    assert "Too few vertices" in session.header_text(bpy.context.scene)
    assert send(drag, session, "LEFTMOUSE", "RELEASE", near) == drag.DONE
    session.finish(bpy.context)
    assert drag.record_properties(session) is None
    assert "Nothing was recorded" in session.machine.message
    assert snapshot(view.obj) == before


def test_press_that_misses_the_mesh_says_why(drag, view):
    with pytest.raises(ValueError, match="Missed the mesh"):
        drag.DragSession.start(bpy.context, (view.region.width - 5, 5))  # a corner of the view


def test_non_mesh_active_object_is_refused(drag, view):
    empty = bpy.data.objects.new("Empty", None)
    bpy.context.scene.collection.objects.link(empty)
    bpy.context.view_layer.objects.active = empty
    with pytest.raises(ValueError, match="not a mesh"):
        start(drag, view, ridge_vertex(view))


def test_object_deleted_mid_drag_ends_cleanly(drag, view):
    session = start(drag, view, ridge_vertex(view))
    handle = session.overlay.handle
    bpy.data.objects.remove(view.obj)
    far = (view.region.width / 2 + 40, view.region.height / 2)
    assert send(drag, session, "MOUSEMOVE", "NOTHING", far) == drag.DONE
    session.finish(bpy.context)
    assert session.machine.phase == "cancelled" and "deleted" in session.machine.message
    assert handler_removed(handle)


def test_leaving_the_region_ends_cleanly(drag, view):
    before = snapshot(view.obj)
    session = start(drag, view, ridge_vertex(view))
    handle = session.overlay.handle
    assert send(drag, session, "MOUSEMOVE", "NOTHING", (-5.0, 10.0)) == drag.DONE
    session.finish(bpy.context)
    assert session.machine.phase == "cancelled" and "Left the 3D view" in session.machine.message
    assert handler_removed(handle) and snapshot(view.obj) == before


def shown_regions_over_the_view(view):
    """The area's other shown regions (toolbar, header, ...) whose rectangle meets the view's."""
    view_box = (view.region.x, view.region.y, view.region.width, view.region.height)
    regions = []
    for other in view.area.regions:
        if other.type == "WINDOW" or other.width <= 1 or other.height <= 1:
            continue
        box = (other.x, other.y, other.width, other.height)
        overlap_x = min(box[0] + box[2], view_box[0] + view_box[2]) - max(box[0], view_box[0])
        overlap_y = min(box[1] + box[3], view_box[1] + view_box[3]) - max(box[1], view_box[1])
        if overlap_x > 0 and overlap_y > 0:
            regions.append(other)
    return regions


def test_release_over_a_region_drawn_over_the_view_records_nothing(drag, view):
    # With Region Overlap the toolbar (and, in 5.x, the header) lie inside the view's own
    # rectangle, so region-relative coordinates there look like view pixels. The startup screen
    # shows the toolbar; the sidebar works the same way (checked in the real GUI).
    regions = shown_regions_over_the_view(view)
    assert "TOOLS" in {r.type for r in regions}
    before = snapshot(view.obj)
    for region in regions:
        # The middle of that region, in pixels of the view's region (as a modal operator gets it).
        coord = (
            region.x + region.width / 2 - view.region.x,
            region.y + region.height / 2 - view.region.y,
        )
        assert 0 <= coord[0] < view.region.width and 0 <= coord[1] < view.region.height
        for events in (["release"], ["move", "release"]):
            session = start(drag, view, ridge_vertex(view))
            far = pixel(view, view.points[ridge_vertex(view)] + 0.6 * view.right)
            assert send(drag, session, "MOUSEMOVE", "NOTHING", far) == drag.RUNNING
            status = None
            for event in events:
                event_type, value = (
                    ("MOUSEMOVE", "NOTHING")
                    if event == "move"
                    else (
                        "LEFTMOUSE",
                        "RELEASE",
                    )
                )
                status = send(drag, session, event_type, value, coord)
                if status == drag.DONE:
                    break
            session.finish(bpy.context)
            assert status == drag.DONE, (region.type, events)
            assert drag.record_properties(session) is None, (region.type, events)
            assert "Left the 3D view" in session.machine.message
        # A press there (where Blender passes it through to the view) does not start a drag.
        with pytest.raises(ValueError, match="not over the sidebar, toolbar or header"):
            drag.DragSession.start(bpy.context, coord)
    assert snapshot(view.obj) == before


def test_other_keys_are_swallowed_mid_drag(drag, view):
    session = start(drag, view, ridge_vertex(view))
    for event_type in ("X", "DEL", "TAB", "G"):
        assert send(drag, session, event_type) == drag.RUNNING
    assert session.machine.phase == "dragging"
    session.finish(bpy.context)


# -- execute() with explicit values -----------------------------------------------------------


@pytest.mark.parametrize("patch", ["euclidean", "geodesic"])
def test_exec_default_equals_measure_xyz(drag, view, patch):
    values = {
        "location": tuple(view.points[ridge_vertex(view, 9)] + [0.01, -0.02, 0.015]),
        "radius": 0.55,
        "seg_param": 1.5,
        "patch": patch,
    }
    assert bpy.ops.vg.measure_drag("EXEC_DEFAULT", **values) == {"FINISHED"}
    assert bpy.ops.vg.measure_xyz("EXEC_DEFAULT", **values) == {"FINISHED"}
    dragged, typed = view.obj.vg.measurements
    assert record_fields(dragged) == record_fields(typed)
    assert dragged.number == 1 and typed.number == 2
    assert exact(dragged)["radius"] == 0.55 and exact(dragged)["lam"] == 1.5


def test_exec_default_bad_input_reports_and_records_nothing(drag, view):
    before = snapshot(view.obj)
    far_away = tuple(view.points[0] + 100.0)
    with pytest.raises(RuntimeError, match="farther than the radius"):
        bpy.ops.vg.measure_drag("EXEC_DEFAULT", location=far_away, radius=0.5, seg_param=2.0)
    assert snapshot(view.obj) == before


# -- pieces: events, hints, units, overlay, tool ----------------------------------------------


def test_translate_event(drag):
    t = drag.translate_event
    assert t("MOUSEMOVE", "NOTHING") == ("move", None)
    assert t("INBETWEEN_MOUSEMOVE", "NOTHING") == ("ignore", None)
    assert t("LEFTMOUSE", "RELEASE") == ("release", None)
    assert t("LEFTMOUSE", "PRESS") == ("ignore", None)
    assert t("ESC", "PRESS")[0] == t("RIGHTMOUSE", "PRESS")[0] == "cancel"
    assert t("ESC", "RELEASE") == ("ignore", None)
    assert t("RET", "PRESS") == t("NUMPAD_ENTER", "PRESS") == ("enter", None)
    assert t("FIVE", "PRESS") == t("NUMPAD_5", "PRESS") == ("type", "5")
    assert t("PERIOD", "PRESS") == ("type", ".")
    assert t("FIVE", "PRESS", ctrl=True) == ("ignore", None)
    assert t("BACK_SPACE", "PRESS") == ("backspace", None)
    assert t("L", "PRESS") == ("lam", 1)
    assert t("L", "PRESS", shift=True) == ("lam", -1)
    assert t("WHEELUPMOUSE", "PRESS", ctrl=True) == ("lam", 1)
    assert t("WHEELDOWNMOUSE", "PRESS", ctrl=True) == ("lam", -1)
    assert t("WHEELUPMOUSE", "PRESS") == t("MIDDLEMOUSE", "PRESS") == ("pass", None)
    assert t("TRACKPADPAN", "NOTHING") == t("NDOF_MOTION", "NOTHING") == ("pass", None)
    assert t("WINDOW_DEACTIVATE", "NOTHING")[0] == "cancel"


def test_status_hint_icons_exist(drag):
    icons = bpy.types.UILayout.bl_rna.functions["label"].parameters["icon"].enum_items.keys()
    used = {icon for hint_icons, _ in drag.HINTS for icon in hint_icons}
    assert used <= set(icons)


def test_radius_is_shown_in_scene_units(drag, vg):
    units = bpy.context.scene.unit_settings
    units.system = "METRIC"
    units.scale_length = 0.001
    assert drag.format_length(bpy.context.scene, 2.5).replace(" ", "") == "2.5mm"
    units.system = "NONE"
    assert drag.format_length(bpy.context.scene, 0.4) == "0.4"


def test_overlay_data_and_handler_lifecycle(vg, drag):
    overlay_module = importlib.import_module(f"{vg.__name__}.operators.drag_overlay")
    points = np.random.default_rng(0).normal(size=(50, 3))
    data = overlay_module.patch_vertex_data(points, np.array([3, 1, 4]))
    assert data.dtype == np.float32 and data.flags.c_contiguous and data.shape == (3, 3)
    assert np.array_equal(data, points[[3, 1, 4]].astype(np.float32))
    ring = overlay_module.circle_points([1, 2, 3], 0.5, [1, 0, 0], [0, 0, 1], segments=16)
    assert ring.shape == (17, 3) and np.allclose(ring[0], ring[-1])
    assert np.allclose(np.linalg.norm(ring - [1, 2, 3], axis=1), 0.5, atol=1e-6)
    assert np.allclose(ring[:, 1], 2.0)
    overlay = overlay_module.DragOverlay()
    overlay.start()
    handle = overlay.handle
    overlay.start()  # once only
    assert overlay.handle is handle
    overlay.update([0, 0, 0], 0.5, data, labels=np.array([True, False, True]))
    overlay.stop()
    overlay.stop()
    assert handler_removed(handle) and not overlay.active


def test_tool_registers_in_the_toolbar(drag, view):
    registered_here = not drag.tool_registered()  # the extension may have done it already
    drag.register_tool()
    drag.register_tool()  # a second call is a no-op
    try:
        bindings = {
            (item.idname, item.type, item.value)
            for config in bpy.context.window_manager.keyconfigs
            for keymap in config.keymaps
            if keymap.name.endswith(drag.VG_WT_measure_drag.bl_label)
            for item in keymap.keymap_items
        }
        assert ("vg.measure_drag", "LEFTMOUSE", "PRESS") in bindings
        assert bpy.ops.wm.tool_set_by_id(name=drag.TOOL_ID) == {"FINISHED"}
        active = bpy.context.workspace.tools.from_space_view3d_mode("OBJECT")
        assert active.idname == drag.TOOL_ID
        bpy.ops.wm.tool_set_by_id(name="builtin.select_box")
    finally:
        if registered_here:
            drag.unregister_tool()
            assert not drag.tool_registered()


def test_the_preview_shows_the_colours_the_release_paints(drag, view, vg):
    """Issue 20: the drag's preview draws each side in the colour the release then paints (its
    break's pair, the way round that agrees with the break's earlier measurements), read back
    from the painted "VG Sides" attribute, for drags in two breaks (the sides show once a λ
    key has measured the patch)."""
    from bpy_helpers import colours

    def linear(rgb8):  # sRGB to scene-linear, IEC 61966-2-1, as the attribute holds it
        c = np.asarray(rgb8, dtype=np.float64)
        c = c / 255.0 if c.max() > 1.0 else c
        return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)

    for k, offset, break_number in ((10, 0.5, 1), (16, 0.6, 1), (21, 0.45, 1), (12, 0.5, 2)):
        if break_number != view.obj.vg.break_number:
            bpy.ops.vg.next_break()
        vertex = ridge_vertex(view, k)
        session = start(drag, view, vertex)
        far = pixel(view, view.points[vertex] + offset * view.right)
        send(drag, session, "MOUSEMOVE", "NOTHING", far)
        send(drag, session, "L")  # a λ step: the preview measures and shows the two sides
        preview = [np.array(c[:3]) for c in session.overlay.side_colours]
        plus_side = session.machine.measurement.labels
        indices = session.machine.measurement.indices
        send(drag, session, "LEFTMOUSE", "RELEASE", far)
        session.finish(bpy.context)
        assert bpy.ops.vg.measure_drag("EXEC_DEFAULT", **drag.record_properties(session)) == {
            "FINISHED"
        }
        painted = colours(view.obj)[:, :3]
        for side, colour in ((plus_side, preview[0]), (~plus_side, preview[1])):
            got = painted[indices[side]]
            np.testing.assert_allclose(got, np.broadcast_to(linear(colour), got.shape), atol=2e-3)
    records = vg.bridge.records
    # A measurement whose "+" side lies on the face its break painted in the second colour:
    # the preview says swapped, as recording it does.
    item = view.obj.vg.measurements[-1]
    first = session.machine.measurement
    turned = dataclasses.replace(
        first, normal_plus=first.normal_minus, normal_minus=first.normal_plus
    )
    expected = records.colours_as_painted(view.obj, turned)
    assert expected == records.colours_as_painted(view.obj, first)[::-1]
    recorded = records.add_measurement(view.obj, turned, item.fingerprint)
    names = recorded.colors.split("/")
    assert tuple(vg.vg_addon.palette.OKABE_ITO[n] for n in names) == expected
