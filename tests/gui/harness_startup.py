"""Startup script of the GUI Blender in the GUI test lane (``blender --python`` this file).

It only sets the scene up and reports; the test drives Blender with real X events (xdotool).
On its first timer tick it builds the wedge scene (:mod:`scene`; ``VG_GUI_SCENE=fragment``: the
bone fragment of the README's pictures, its break sites written to ``$VG_GUI_POINTS``); then, ten times a second, it
writes what the test needs to read to ``$VG_GUI_STATE`` (JSON, replaced atomically): the
measurements of every mesh object with their exact numbers, the active tool, the 3D view's
regions in X screen pixels, the sidebar's tab, the 3D cursor, the running drag (found by
looking, read-only, at the live ``DragSession`` objects), the running Find Break Edges review
(its ``FindEdgesSession``, likewise, with the header text it shows), what a Ctrl+Shift+C copied, the
regions of an open file browser and what it offers (folder, file name, filter), the screen
positions of the 3D points listed in ``$VG_GUI_POINTS``, each mesh's edge profiles and active
list rows, the scenes and every "VG Map" data-block in the file, the window's running modal
operators and the .blend's path; on request, the Info log's reports (as copied text), the
replication report's libraries put on ``sys.path``, and another object made active.
"""

from __future__ import annotations

import gc
import importlib
import json
import os
import sys
import traceback

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import scene

STATE = os.environ["VG_GUI_STATE"]
POINTS = os.environ.get("VG_GUI_POINTS", "")
REPORT_LIBS = "/vg/report-libs"
_status = {"seq": 0, "ready": False, "errors": [], "clipboard": [], "report_libs": False}


def _view3d(window):
    for area in window.screen.areas:
        if area.type == "VIEW_3D":
            return area
    return None


def _to_screen(window, wx: float, wy: float) -> list[float]:
    """Blender window coordinates (origin bottom left) to X screen pixels (origin top left)."""
    return [window.x + wx, window.y + window.height - 1 - wy]


def _regions(window, area) -> dict:
    rects = {}
    for region in area.regions:
        if region.width <= 1 or region.height <= 1:
            continue
        left, top = _to_screen(window, region.x, region.y + region.height - 1)
        rects[region.type] = [left, top, region.width, region.height]
    return rects


def _file_browser() -> dict | None:
    """The regions of an open file browser (its own window, or an area of the main one), and
    what it offers: its folder, the file name field and the filter."""
    for window in bpy.context.window_manager.windows:
        for area in window.screen.areas:
            if area.type == "FILE_BROWSER":
                regions = _regions(window, area)
                params = area.spaces.active.params
                if params is not None:
                    regions["params"] = {
                        "directory": params.directory.decode(errors="replace")
                        if isinstance(params.directory, bytes)
                        else params.directory,
                        "filename": params.filename,
                        "filter_glob": params.filter_glob,
                        "use_filter": params.use_filter,
                    }
                return regions
    return None


def _projections(window, area) -> dict:
    if not POINTS or not os.path.exists(POINTS):
        return {}
    from bpy_extras import view3d_utils

    with open(POINTS) as handle:
        points = json.load(handle)
    region = next(r for r in area.regions if r.type == "WINDOW")
    region_3d = area.spaces.active.region_3d
    out = {}
    for name, xyz in points.items():
        xy = view3d_utils.location_3d_to_region_2d(region, region_3d, xyz)
        out[name] = None if xy is None else _to_screen(window, region.x + xy.x, region.y + xy.y)
    return out


def _drag(window, area):
    """The running drag: its machine's numbers and its circle's centre and radius on screen."""
    from bpy_extras import view3d_utils
    from mathutils import Vector

    drag = scene.extension().operators.drag
    region = next(r for r in area.regions if r.type == "WINDOW")
    region_3d = area.spaces.active.region_3d
    for obj in gc.get_objects():
        # type(), not isinstance(): an ended operator's Python object raises ReferenceError on
        # any attribute look-up, __class__ included.
        if type(obj) is drag.DragSession:
            machine = obj.machine
            if machine.phase.name == "DRAGGING":
                centre = Vector(machine.center)
                right = region_3d.view_rotation @ Vector((1.0, 0.0, 0.0))
                ends = [
                    view3d_utils.location_3d_to_region_2d(region, region_3d, point)
                    for point in (centre, centre + machine.radius * right)
                ]
                return {
                    "center_screen": _to_screen(window, region.x + ends[0].x, region.y + ends[0].y),
                    "radius_px": (ends[1] - ends[0]).length,
                    "phase": machine.phase.name,
                    "radius": machine.radius,
                    "lam": machine.lam,
                    "typed": machine.typed,
                    "n_vertices": machine.n_vertices,
                }
    return None


def _find_edges(window, area):
    """The running Find Break Edges review (found, read-only, among the live
    ``FindEdgesSession`` objects): its phase, selection, message and header text, and each candidate's
    number, confidence, decision and 24 points along it on screen (None: not in view)."""
    from bpy_extras import view3d_utils
    from mathutils import Matrix, Vector

    find_edges = scene.extension().operators.find_edges
    region = next(r for r in area.regions if r.type == "WINDOW")
    region_3d = area.spaces.active.region_3d
    for obj in gc.get_objects():
        if type(obj) is not find_edges.FindEdgesSession:
            continue
        machine = obj.machine
        if machine.phase.name in ("DONE", "CANCELLED"):
            continue
        matrix = Matrix(obj.obj.matrix_world)
        candidates = []
        for candidate, decision in zip(machine.candidates, machine.decisions, strict=True):
            path = candidate.path
            picks = [round(f * (len(path.points) - 1)) for f in [(k + 0.5) / 24 for k in range(24)]]
            screen = []
            for index in picks:
                xy = view3d_utils.location_3d_to_region_2d(
                    region, region_3d, matrix @ Vector(path.points[index])
                )
                inside = xy is not None and 0 <= xy.x < region.width and 0 <= xy.y < region.height
                screen.append(
                    _to_screen(window, region.x + xy.x, region.y + xy.y) if inside else None
                )
            candidates.append(
                {
                    "number": candidate.number,
                    "confidence": candidate.confidence,
                    "length": candidate.length,
                    "closed": candidate.closed,
                    "decision": str(decision),
                    "screen": screen,
                }
            )
        return {
            "phase": machine.phase.name,
            "progress": machine.progress,
            "selected": machine.selected,
            "message": machine.message,
            "header": obj.header_text(bpy.context.scene),
            "candidates": candidates,
        }
    return None


def _plot_units(name: str):
    image = bpy.data.images.get(name) if name else None
    return None if image is None else image.get("vg_plot_units")


def _objects(scene_) -> dict:
    objects = {}
    for obj in scene_.objects:
        if obj.type != "MESH":
            continue
        objects[obj.name] = {
            "break_number": obj.vg.break_number,
            "measurements": [
                {
                    "number": item.number,
                    "break_number": item.break_number,
                    "edge_number": item.edge_number,
                    "exact": json.loads(item.exact) if item.exact else {},
                    "patch": item.patch,
                    "n_vertices": item.n_vertices,
                    "stale": item.stale,
                    "colors": item.colors,
                }
                for item in obj.vg.measurements
            ],
            "active_index": obj.vg.active_index,
            "unit": obj.vg.unit,
            "scale": list(obj.scale),
            "edges": [
                {
                    "number": edge.number,
                    "break_number": edge.break_number,
                    "n_stations": edge.n_stations,
                    "mean": edge.mean,
                    # The unit its plot's axis names (the image's custom property).
                    "plot_units": _plot_units(edge.plot),
                }
                for edge in obj.vg.edges
            ],
            "active_edge_index": obj.vg.active_edge_index,
        }
    return objects


def _map_blocks() -> list[str]:
    """Every data-block of the measurement map's throwaway scene still in the file."""
    names = []
    for collection in (
        bpy.data.scenes,
        bpy.data.objects,
        bpy.data.meshes,
        bpy.data.cameras,
        bpy.data.lights,
        bpy.data.worlds,
        bpy.data.materials,
        bpy.data.curves,
        bpy.data.images,
    ):
        names += [block.name for block in collection if block.name.startswith("VG Map")]
    return names


def _setup(window) -> None:
    area = _view3d(window)
    with bpy.context.temp_override(window=window, area=area):
        if os.environ.get("VG_GUI_SCENE") == "fragment":
            _obj, sites = scene.build_fragment()
            scene.frame_fragment(area.spaces.active)
            with open(POINTS, "w") as handle:
                json.dump({site.label: list(site.point) for site in sites}, handle)
        else:
            scene.build_wedge()
            scene.frame_view(area.spaces.active)


def _copy_reports(window) -> None:
    """On the test's request (the file ``$VG_GUI_STATE.reports``), copy the reports of the Info
    log to the clipboard, where the state passes them on: a report of a refused operator goes
    to the Info log and a popup, not to the console. The 3D view is the Info editor for that
    moment only."""
    os.remove(STATE + ".reports")
    area = _view3d(window)
    area.type = "INFO"
    try:
        region = next(r for r in area.regions if r.type == "WINDOW")
        with bpy.context.temp_override(window=window, area=area, region=region):
            bpy.ops.info.select_all(action="SELECT")
            bpy.ops.info.report_copy()
    finally:
        area.type = "VIEW_3D"


def _add_report_libraries() -> None:
    """On the test's request (the file ``$VG_GUI_STATE.report_libs``), put the report's
    libraries (``scripts/provision_report_libs.sh``, bound at ``/vg/report-libs``) on
    ``sys.path`` after Blender's own entries, as a user who installs them would: the root's
    NumPy stays the one imported."""
    os.remove(STATE + ".report_libs")
    if REPORT_LIBS not in sys.path:
        sys.path.append(REPORT_LIBS)
        importlib.invalidate_caches()
    _status["report_libs"] = True


def _activate(window) -> None:
    """On the test's request (the file ``$VG_GUI_STATE.activate``, naming an object), make that
    object the active one, as a click on it in the Outliner does; a name not in the file is
    made first, a copy of the scene's mesh object with a mesh of its own."""
    with open(STATE + ".activate") as handle:
        name = handle.read().strip()
    os.remove(STATE + ".activate")
    obj = bpy.data.objects.get(name)
    if obj is None:
        original = bpy.data.objects[scene.OBJECT_NAME]
        obj = bpy.data.objects.new(name, original.data.copy())  # none of its measurements
        obj.matrix_world = original.matrix_world
        window.scene.collection.objects.link(obj)
    window.view_layer.objects.active = obj


def _tick():
    try:
        window = bpy.context.window_manager.windows[0]
        if not _status["ready"]:
            _setup(window)
            _status["ready"] = True
        wm = bpy.context.window_manager
        if os.path.exists(STATE + ".reports") and _view3d(window):
            _copy_reports(window)
        if os.path.exists(STATE + ".report_libs"):
            _add_report_libraries()
        if os.path.exists(STATE + ".activate"):
            _activate(window)
        if wm.clipboard:
            _status["clipboard"].append([_status["seq"], wm.clipboard])
            wm.clipboard = ""
        # None while a maximized file browser stands in for the window's screen.
        area = _view3d(window)
        sidebar = next((r for r in area.regions if r.type == "UI"), None) if area else None
        tool = window.workspace.tools.from_space_view3d_mode("OBJECT", create=False)
        _status["seq"] += 1
        state = {
            "seq": _status["seq"],
            "ready": True,
            "version": list(bpy.app.version),
            "window": [window.x, window.y, window.width, window.height],
            "regions": _regions(window, area) if area else {},
            "file_browser": _file_browser(),
            "sidebar_category": sidebar.active_panel_category if sidebar else None,
            "tool": tool.idname if tool else None,
            "cursor": list(window.scene.cursor.location),
            "active": getattr(window.view_layer.objects.active, "name", None),
            "objects": _objects(window.scene),
            "drag": _drag(window, area) if area else None,
            "find_edges": _find_edges(window, area) if area else None,
            "points": _projections(window, area) if area else {},
            "clipboard": _status["clipboard"][-20:],
            "report_libs": _status["report_libs"],
            "blend": bpy.data.filepath,
            "scenes": [s.name for s in bpy.data.scenes],
            "map_blocks": _map_blocks(),
            "modal_operators": [op.bl_idname for op in window.modal_operators],
            "errors": _status["errors"][-5:],
        }
    except Exception:
        _status["errors"].append(traceback.format_exc())
        state = {"seq": _status["seq"], "ready": False, "errors": _status["errors"][-5:]}
    partial = STATE + ".part"
    with open(partial, "w") as handle:
        json.dump(state, handle)
    os.replace(partial, STATE)
    return 0.1


bpy.app.timers.register(_tick, first_interval=0.5, persistent=True)
