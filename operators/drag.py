"""Click-and-drag measuring: the modal operator ``vg.measure_drag`` and its viewport tool.

Press on the active mesh, drag out the radius while the patch is previewed, release to measure.
The interaction itself is :class:`~vg_addon.workflow.drag_state.DragMachine` (pure, tested without a
screen); this module ray-casts, turns events into machine events, draws and records. A release
records the measurement it took (not a second one) through the bridge's one recording step,
``measuring.record``, as ``vg.measure_xyz`` does; with the snapped centre vertex stored, so
``vg.measure_xyz`` with the recorded numbers reproduces the measurement bit for bit.
"""

from __future__ import annotations

import bpy
import numpy as np
from bpy_extras import view3d_utils
from mathutils import Matrix, Vector

from ..bridge import measuring
from ..bridge.mesh_data import (
    check_measurable,
    evaluated_geometry,
    mesh_points,
    ray_tree_for,
    surface_for,
    world_points,
)
from ..bridge.records import MESH_UNITS, colours_as_painted, is_shown_at_own_size, unit_symbol
from ..vg_addon import GoniometerError
from ..vg_addon.units import length_text
from ..vg_addon.workflow.drag_state import DragMachine, Phase, surface_callbacks
from .common import clear_texts, poll_measurable, status_hints, typed_value
from .drag_overlay import DragOverlay, patch_vertex_data
from .measure import MeasureProperties, VG_OT_measure_xyz, report_measurement

TOOL_ID = "vg.measure_drag_tool"

# Running / pass-through / finished statuses of DragSession.handle.
RUNNING, PASS, DONE = "running", "pass", "done"

_DIGITS = {
    **{
        name: str(i)
        for i, name in enumerate(
            ("ZERO", "ONE", "TWO", "THREE", "FOUR", "FIVE", "SIX", "SEVEN", "EIGHT", "NINE")
        )
    },
    **{f"NUMPAD_{i}": str(i) for i in range(10)},
    "PERIOD": ".",
    "NUMPAD_PERIOD": ".",
}
# Events that move the view: passed through to Blender while a tool is running.
NAVIGATION_EVENTS = {
    "MIDDLEMOUSE",
    "WHEELUPMOUSE",
    "WHEELDOWNMOUSE",
    "WHEELINMOUSE",
    "WHEELOUTMOUSE",
    "TRACKPADPAN",
    "TRACKPADZOOM",
    "NDOF_MOTION",
    "MOUSEROTATE",
    "MOUSESMARTZOOM",
}

# Status bar hints: (icons, text). Only icons that exist in Blender 4.2 and 5.0.
HINTS = (
    (("MOUSE_LMB",), "Release: measure"),
    (("EVENT_ESC", "MOUSE_RMB"), "Cancel"),
    ((), "0-9 .  type the radius"),
    (("EVENT_BACKSPACE",), "Erase"),
    (("EVENT_RETURN",), "Measure typed"),
    (("EVENT_L",), "λ +"),
    (("EVENT_SHIFT", "EVENT_L"), "λ −"),
    (("EVENT_CTRL", "MOUSE_MMB"), "Wheel: λ"),
    (("MOUSE_MMB",), "Navigate"),
)


def translate_event(event_type: str, value: str, *, ctrl=False, shift=False, alt=False):
    """What a Blender event means to the drag: ``(action, argument)``.

    Actions: ``"move"``, ``"release"``, ``"enter"``, ``"cancel"``, ``"type"`` (argument: the
    character), ``"backspace"``, ``"lam"`` (argument: steps of λ), ``"pass"`` (navigation, let
    Blender have it), ``"ignore"`` (swallow it, so no shortcut fires mid-drag).
    """
    if event_type == "MOUSEMOVE":
        return "move", None
    if event_type == "LEFTMOUSE":
        return ("release", None) if value == "RELEASE" else ("ignore", None)
    if event_type in ("WHEELUPMOUSE", "WHEELDOWNMOUSE") and ctrl:
        return "lam", (1 if event_type == "WHEELUPMOUSE" else -1)
    if event_type in NAVIGATION_EVENTS:
        return "pass", None
    if event_type == "WINDOW_DEACTIVATE":
        return "cancel", "The window lost focus: nothing was recorded."
    if value != "PRESS":
        return "ignore", None
    if event_type in ("ESC", "RIGHTMOUSE"):
        return "cancel", None
    if event_type in ("RET", "NUMPAD_ENTER"):
        return "enter", None
    if event_type == "BACK_SPACE":
        return "backspace", None
    if event_type == "L" and not (ctrl or alt):
        return "lam", (-1 if shift else 1)
    if event_type in _DIGITS and not (ctrl or alt or shift):
        return "type", _DIGITS[event_type]
    return "ignore", None


def format_length(scene, value: float, obj=None) -> str:
    """``value`` in ``obj``'s Scan Units when it has them (mesh units: ``"0.3 mm"``), else
    (Blender units) in the scene's length units, e.g. ``"2.5 mm"``."""
    if getattr(getattr(obj, "vg", None), "unit", "SCENE") != "SCENE":
        return length_text(value, unit_symbol(obj, scene))
    units = scene.unit_settings
    if units.system == "NONE":
        return f"{value:.5g}"
    return bpy.utils.units.to_string(
        units.system,
        "LENGTH",
        value * units.scale_length,
        precision=5,
        split_unit=units.use_separate,
        compatible_unit=False,
    )


def mesh_length_text(scene, value: float, obj) -> str:
    """A length in ``obj``'s mesh units as a header shows it: in its Scan Units, or the
    scene's length units where those measure it (an unscaled object); on a scaled object
    without Scan Units, "N mesh units" (the scene's units measure world lengths)."""
    if obj.vg.unit != "SCENE" or is_shown_at_own_size(obj):
        return format_length(scene, value, obj)
    return f"{value:.5g} {MESH_UNITS}"


def ray_cast_object(obj, depsgraph, region, region_data, coord):
    """Point where the view ray through region pixel ``coord`` first hits ``obj``, in mesh
    coordinates (object space, where it is measured).

    Only ``obj`` is tested (its evaluated mesh, through its kept ray-cast tree); ``None`` when
    the ray misses.
    """
    coord = Vector(coord)
    origin = view3d_utils.region_2d_to_origin_3d(region, region_data, coord)
    direction = view3d_utils.region_2d_to_vector_3d(region, region_data, coord)
    geometry = evaluated_geometry(obj, depsgraph)
    to_local = Matrix(geometry.matrix.tolist()).inverted_safe()
    location = ray_tree_for(obj, geometry, depsgraph).ray_cast(
        to_local @ origin, to_local.to_3x3() @ direction
    )[0]
    return None if location is None else np.array(location, dtype=np.float64)


def view_plane_radius(region, region_data, coord, center, matrix) -> float:
    """Distance, in mesh units, from ``center`` (mesh coordinates) to the point under ``coord``
    on the view plane through it; ``matrix`` is the object's ``matrix_world``."""
    matrix = np.asarray(matrix, dtype=np.float64)
    world_center = world_points(center, matrix)
    point = view3d_utils.region_2d_to_location_3d(
        region, region_data, Vector(coord), Vector(world_center)
    )
    local = mesh_points(np.array(point, dtype=np.float64), matrix)
    return float(np.linalg.norm(local - center))


def object_alive(context, obj) -> bool:
    """Whether ``obj`` still exists and is in the scene (it may be deleted mid-drag)."""
    try:
        name = obj.name
    except ReferenceError:
        return False
    return context.scene.objects.get(name) == obj


def _contains(region, x, y) -> bool:
    return region.x <= x < region.x + region.width and region.y <= y < region.y + region.height


def pointer_in_view(area, region, coord) -> bool:
    """Whether region pixel ``coord`` of the 3D view's WINDOW ``region`` is on the view itself.

    A modal operator gets every pointer position relative to the region it started in, and with
    Region Overlap (Blender's default) that region spans the whole area: the sidebar, the toolbar,
    the header and the tool settings are drawn over it. So a pixel inside ``region`` is on the view
    only if no other shown region of ``area`` covers it. Hidden regions are 1 pixel or less and
    are ignored.
    """
    if coord is None or not (0 <= coord[0] < region.width and 0 <= coord[1] < region.height):
        return False
    x, y = region.x + coord[0], region.y + coord[1]  # window pixels, like every region's x, y
    return not any(
        other.type != "WINDOW" and other.width > 1 and other.height > 1 and _contains(other, x, y)
        for other in area.regions
    )


class DragSession:
    """One drag on one object: the machine, the prepared surface, the overlay and the hints.

    Created by :meth:`start` at the press; fed events by :meth:`handle`; :meth:`finish` (safe to
    call repeatedly) removes the drawing and the header and status texts on every way out.
    """

    def __init__(
        self,
        obj,
        surface,
        patch: str,
        lam: float,
        rule: str = "refined",
        matrix=None,
        *,
        stability: bool = False,
        fingerprint=None,
    ):
        self.obj = obj
        self.surface = surface
        self.matrix = np.eye(4) if matrix is None else np.asarray(matrix, dtype=np.float64)
        self.patch = patch
        self.rule = rule
        self.stability = stability
        self.fingerprint = fingerprint  # of the geometry ``surface`` was made from
        self.machine = DragMachine(
            **surface_callbacks(surface, patch, rule, stability), lam=lam, quantize=typed_value
        )
        self.overlay = DragOverlay()
        self._area = None
        self._workspace = None

    @classmethod
    def start(cls, context, coord) -> DragSession:
        """Ray-cast at region pixel ``coord`` on the active object and start dragging there.

        Raises
        ------
        GoniometerError
            Not a 3D viewport, a press over the sidebar, toolbar or header, no measurable
            active mesh, or the press missed it.
        """
        region, region_data = context.region, context.region_data
        if (
            context.area is None
            or context.area.type != "VIEW_3D"
            or region is None
            or (region.type != "WINDOW" or region_data is None)
        ):
            raise GoniometerError(
                "Drag measuring works in the 3D viewport: choose the Goniometer tool in its "
                "toolbar and press on the mesh."
            )
        if not pointer_in_view(context.area, region, coord):
            raise GoniometerError(
                "Press on the mesh in the 3D view itself, not over the sidebar, toolbar or "
                "header drawn over it."
            )
        obj = context.active_object
        check_measurable(obj)
        settings = context.scene.vg_settings
        depsgraph = context.evaluated_depsgraph_get()
        geometry = evaluated_geometry(obj, depsgraph)
        surface = surface_for(obj, geometry)
        session = cls(
            obj,
            surface,
            settings.patch,
            typed_value(settings.seg_param),
            settings.rule,
            matrix=geometry.matrix,
            stability=settings.stability,
            fingerprint=geometry.fingerprint,
        )
        hit = ray_cast_object(obj, depsgraph, region, region_data, coord)
        if not session.machine.press(hit):
            raise GoniometerError(session.machine.message)
        session._area, session._workspace = context.area, context.workspace
        session.overlay.start()
        try:
            session.refresh(context)
        except BaseException:
            session.finish(context)
            raise
        return session

    def handle(self, context, action: str, argument=None, coord=None) -> str:
        """Apply one translated event; returns ``"running"``, ``"pass"`` or ``"done"``.

        ``coord`` is the pointer position relative to the region (needed for ``"move"`` and
        ``"release"``): a move or release off the view (outside the region, or over the sidebar,
        toolbar or header drawn over it) cancels the drag, so it records nothing.
        """
        machine = self.machine
        if not object_alive(context, self.obj):
            machine.cancel("The object was deleted: nothing was recorded.")
            return DONE
        region, region_data = context.region, context.region_data
        if region is None or region_data is None or context.area != self._area:
            machine.cancel("Left the 3D view: nothing was recorded.")
            return DONE
        if action == "pass":
            return PASS
        if action in ("move", "release") and not pointer_in_view(self._area, region, coord):
            machine.cancel("Left the 3D view: nothing was recorded.")
            return DONE
        if action == "move":
            machine.move(view_plane_radius(region, region_data, coord, machine.center, self.matrix))
        elif action == "type":
            machine.type_character(argument)
        elif action == "backspace":
            machine.backspace()
        elif action == "lam":
            machine.change_lam(argument)
        elif action == "release":
            machine.release()
        elif action == "enter":
            machine.enter()
        elif action == "cancel":
            machine.cancel(*((argument,) if argument else ()))
        else:
            return RUNNING
        if machine.phase is Phase.DRAGGING:
            self.refresh(context)
            return RUNNING
        return DONE

    def refresh(self, context) -> None:
        """Hand the preview to the overlay and update the header; redraw the viewport."""
        machine = self.machine
        measurement = machine.measurement
        colours = None
        if measurement is not None:
            coords = patch_vertex_data(self.surface.points, measurement.indices)
            labels = measurement.labels
            colours = colours_as_painted(self.obj, measurement)  # what the release paints
        else:
            coords, labels = patch_vertex_data(self.surface.points, machine.indices), None
        self.overlay.update(
            machine.center, machine.radius, coords, labels, matrix=self.matrix, colours=colours
        )
        if self._area is not None:
            self._area.header_text_set(self.header_text(context.scene))
            self._area.tag_redraw()
        if self._workspace is not None:
            self._workspace.status_text_set(status_hints(HINTS))

    def header_text(self, scene) -> str:
        """The header line: radius, vertex count, λ, the angle after a λ change, and any hint."""
        machine = self.machine
        parts = [f"Goniometer radius {mesh_length_text(scene, machine.radius, self.obj)}"]
        if machine.typed:
            parts[0] += f" (typed {machine.typed})"
        parts.append(f"{machine.n_vertices} vertices")
        parts.append(f"λ {machine.lam:g}")
        if machine.measurement is not None:
            parts.append(f"angle {machine.measurement.angle:.2f}°")
        if machine.message:
            parts.append(machine.message)
        return "  ·  ".join(parts)

    def finish(self, context=None) -> None:
        """Remove the drawing and the texts; safe to call more than once."""
        self.overlay.stop()
        area, self._area = self._area, None
        workspace, self._workspace = self._workspace, None
        clear_texts(area, workspace)


def record_properties(session: DragSession) -> dict | None:
    """The operator properties that record a finished drag (None when it recorded nothing).

    ``location`` is the snapped centre vertex in mesh coordinates, so ``vg.measure_xyz`` with
    these values snaps to the same vertex and measures the same patch wherever the object is.
    """
    record = session.machine.record
    if session.machine.phase is not Phase.MEASURED or record is None:
        return None
    return {
        "location": tuple(record.center),
        "space": "MESH",
        "radius": record.radius,
        "seg_param": record.lam,
        "patch": session.patch,
        "rule": session.rule,
    }


def record_drag(context, session: DragSession, note: str = ""):
    """Record the measurement a finished drag's release took (the preview's own result, not
    a second measurement of the same patch); returns the new item, or None when the mesh
    changed since the press (it is then measured again through ``vg.measure_xyz``'s way).

    The result equals, bit for bit, what ``vg.measure_xyz`` records with
    :func:`record_properties`: the same surface, snapped vertex, radius, λ, patch, rule and
    stability setting.
    """
    record, obj = session.machine.record, session.obj
    check_measurable(obj)
    depsgraph = context.evaluated_depsgraph_get()
    geometry = evaluated_geometry(obj, depsgraph)
    if record is None or geometry.fingerprint != session.fingerprint:
        return None
    measuring.note_winding(obj, session.surface)
    return measuring.record(obj, record.measurement, geometry, note=note, depsgraph=depsgraph)


class VG_OT_measure_drag(MeasureProperties, bpy.types.Operator):
    """Press on a break edge of the active mesh, drag out the patch radius, release to measure"""

    bl_idname = "vg.measure_drag"
    bl_label = "Measure by Dragging"
    bl_options = {"REGISTER", "UNDO"}  # noqa: RUF012 (Blender reads a set)

    @classmethod
    def poll(cls, context):
        return poll_measurable(cls, context)

    def invoke(self, context, event):
        try:
            self._session = DragSession.start(context, (event.mouse_region_x, event.mouse_region_y))
        except GoniometerError as error:
            self.report({"WARNING"}, str(error))
            return {"CANCELLED"}
        context.window_manager.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        session = self._session
        try:
            action, argument = translate_event(
                event.type, event.value, ctrl=event.ctrl, shift=event.shift, alt=event.alt
            )
            coord = None
            if context.region is not None:
                coord = (event.mouse_x - context.region.x, event.mouse_y - context.region.y)
            status = session.handle(context, action, argument, coord)
        except BaseException:
            session.finish(context)
            raise
        if status == PASS:
            return {"PASS_THROUGH"}
        if status == RUNNING:
            return {"RUNNING_MODAL"}
        session.finish(context)
        return self.commit(context, session)

    def cancel(self, context):
        """Blender ends the modal operator (file load, window closed, ...): clean up."""
        session = getattr(self, "_session", None)
        if session is not None:
            session.finish(context)

    def commit(self, context, session: DragSession):
        """Record the finished drag's measurement (:func:`record_drag`), or report why nothing
        was; the values are stored for redo (Adjust Last Operation), which measures through
        :meth:`execute`."""
        values = record_properties(session)
        if values is None:
            self.report({"INFO"}, session.machine.message or "Nothing was recorded.")
            return {"CANCELLED"}
        for name, value in values.items():
            setattr(self, name, value)
        self.stability = session.stability
        try:
            item = record_drag(context, session, self.note)
        except GoniometerError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        if item is None:
            return self.execute(context)
        report_measurement(self, session.obj, item)
        return {"FINISHED"}

    def execute(self, context):
        return VG_OT_measure_xyz.execute(self, context)


class VG_WT_measure_drag(bpy.types.WorkSpaceTool):
    bl_space_type = "VIEW_3D"
    bl_context_mode = "OBJECT"
    bl_idname = TOOL_ID
    bl_label = "Goniometer"
    bl_description = (
        "Measure a break angle: press on the edge, drag out the radius, release.\n"
        "Type digits for an exact radius, L / Shift L or Ctrl wheel to change λ, Esc to cancel"
    )
    bl_icon = "ops.generic.select_circle"
    bl_widget = None
    bl_keymap = (("vg.measure_drag", {"type": "LEFTMOUSE", "value": "PRESS"}, None),)

    def draw_settings(context, layout, tool):  # noqa: N805 (Blender's signature: no self)
        settings = context.scene.vg_settings
        layout.prop(settings, "seg_param")
        layout.prop(settings, "patch")


classes = (VG_OT_measure_drag,)


_tool = {"registered": False}


def tool_registered() -> bool:
    """Whether :func:`register_tool` has added the tool (and :func:`unregister_tool` not yet
    removed it)."""
    return _tool["registered"]


def register_tool() -> None:
    """Add the Goniometer tool to the 3D viewport toolbar (Object Mode), after Measure."""
    if not _tool["registered"]:
        bpy.utils.register_tool(VG_WT_measure_drag, after={"builtin.measure"}, separator=True)
        _tool["registered"] = True


def unregister_tool() -> None:
    """Remove the Goniometer tool from the toolbar (a no-op when it is not there)."""
    if _tool["registered"]:
        bpy.utils.unregister_tool(VG_WT_measure_drag)
        _tool["registered"] = False
