"""Edge profiles: ``vg.measure_edge`` (click along a break edge, or give the points) and
``vg.delete_edge``.

Invoked from the panel, ``vg.measure_edge`` runs a modal session: click the start, any via
points and the end on the active mesh; the path is traced along the ridge and drawn as it is
found; Enter measures every station and records them, Backspace drops the last click, Esc
cancels. The interaction is :class:`~vg_addon.workflow.edge_state.EdgeMachine` (pure, tested
without a screen); a confirmed session records through ``execute`` with its clicks, the same
call a script makes, so the stations are the same bit for bit, and one undo step removes the
whole profile.
"""

from __future__ import annotations

import json

import bpy
import numpy as np
from bpy.props import EnumProperty, IntProperty, StringProperty

from ..bridge import edges
from ..bridge.mesh_data import check_measurable, evaluated_geometry, surface_for
from ..vg_addon import GoniometerError
from ..vg_addon.method.edge_summary import sd_text
from ..vg_addon.workflow.edge_state import EdgeMachine, EdgePhase
from .common import (
    EDGE_SETTINGS,
    SPACE_ITEMS,
    PatchProperties,
    RuleProperties,
    defaults_from_panel,
    length_property,
    poll_measurable,
    status_hints,
    typed_value,
)
from .drag import NAVIGATION_EVENTS, mesh_length_text, ray_cast_object
from .edge_overlay import EdgeOverlay
from .view_session import ViewSession, modifiers

# The drag tool's view navigation, and plain mouse moves (a click session has no drag).
_NAVIGATION = NAVIGATION_EVENTS | {"MOUSEMOVE"}

HINTS = (
    (("MOUSE_LMB",), "Click start, via points, end"),
    (("EVENT_RETURN",), "Measure"),
    (("EVENT_BACKSPACE",), "Undo click"),
    (("EVENT_ESC", "MOUSE_RMB"), "Cancel"),
    (("MOUSE_MMB",), "Navigate"),
)


def translate_edge_event(
    event_type: str, value: str, *, ctrl=False, alt=False, shift=False, repeat=False
):
    """What a Blender event means to the edge session: ``"click"``, ``"confirm"``, ``"undo"``,
    ``"cancel"``, ``"pass"`` (navigation, and the window losing focus: Blender's) or
    ``"ignore"`` (a key held down repeating: each step is one deliberate press)."""
    if event_type in _NAVIGATION or event_type == "WINDOW_DEACTIVATE":
        return "pass"
    if value != "PRESS" or repeat:
        return "ignore"
    if event_type == "LEFTMOUSE" and not (ctrl or alt):
        return "click"
    if event_type in ("RET", "NUMPAD_ENTER", "SPACE"):
        return "confirm"
    if event_type == "BACK_SPACE" or (event_type == "Z" and ctrl and not shift):
        return "undo"
    if event_type in ("ESC", "RIGHTMOUSE"):
        return "cancel"
    return "ignore"


def parse_points_json(text: str) -> np.ndarray:
    """The ``points`` property: JSON ``[[x, y, z], ...]`` (float64, exactly as written); not
    the CSV's ``"x y z; ..."`` text (``csvio.parse_points``)."""
    try:
        points = np.array(json.loads(text), dtype=np.float64)
    except (ValueError, TypeError):
        raise GoniometerError(
            f"The edge points must be JSON like [[x, y, z], [x, y, z]]; got {text!r}."
        ) from None
    if points.ndim != 2 or points.shape[1] != 3 or points.shape[0] < 2:
        raise GoniometerError(
            "The edge needs at least two points [[x, y, z], [x, y, z]] (start and end, with any "
            f"via points between); got {text!r}."
        )
    if not np.isfinite(points).all():
        raise GoniometerError(f"The edge points must be finite numbers; got {text!r}.")
    return points


def format_points_json(points) -> str:
    """JSON text of ``points`` that :func:`parse_points_json` reads back bit for bit (the
    operator's property; the CSV's ``"x y z; ..."`` text is ``csvio.format_points``)."""
    return json.dumps([[float(v) for v in point] for point in np.asarray(points)])


class EdgeSession(ViewSession):
    """One edge-picking session on one object: the machine, the overlay and the texts."""

    def __init__(self, context, obj):
        super().__init__(context, obj, EdgeOverlay(), "Edge profiles are picked in a 3D viewport.")
        geometry = evaluated_geometry(obj, context.evaluated_depsgraph_get())
        self.fingerprint = geometry.fingerprint
        self.machine = EdgeMachine(surface_for(obj, geometry))
        self.overlay.start()
        self.refresh(context)

    def handle(self, context, action: str, mouse=None) -> str:
        """Apply one translated event (``mouse``: window pixel coordinates); returns
        ``"running"``, ``"pass"`` or ``"done"``."""
        machine = self.machine
        if ending := self.closed():
            machine.cancel(ending)
            return "done"
        if self.moved():
            self.refresh(context)
        if action == "pass":
            return "pass"
        if action == "click":
            view = self.view_at(mouse)
            if view is None:  # on the toolbar, sidebar or a header: let Blender have it
                return "pass"
            if refusal := self.absent(context):
                machine.message = refusal
            else:
                region, region_data, coord = view
                depsgraph = context.evaluated_depsgraph_get()
                machine.click(ray_cast_object(self.obj, depsgraph, region, region_data, coord))
        elif action == "undo":
            machine.undo()
        elif action == "confirm" and (refusal := self.unrecordable(context)):
            machine.message = refusal
        elif action == "confirm":
            settings = context.scene.vg_settings
            machine.confirm(
                typed_value(settings.edge_spacing),
                typed_value(settings.radius),
                typed_value(settings.seg_param),
                settings.patch,
                settings.rule,  # the stations' failures depend on it; their stability does not
            )
        elif action == "cancel":
            machine.cancel()
        else:
            return "running"
        if machine.phase is EdgePhase.PICKING:
            self.refresh(context)
            return "running"
        return "done"

    def refresh(self, context) -> None:
        """Hand the clicks and path to the overlay; update header and status bar."""
        self.overlay.update(self.machine.clicks, self.machine.path, self.drawn_at())
        if (area := self.area) is not None:
            area.header_text_set(self.header_text(context.scene))
            area.tag_redraw()
        if self._workspace is not None:
            self._workspace.status_text_set(status_hints(HINTS))

    def header_text(self, scene) -> str:
        """The header while tracing: short enough for a viewport's header (a longer line was
        cut at both ends); the keys are in the status bar, the settings in the panel."""
        machine = self.machine
        parts = [f"Edge Profile: {len(machine.clicks)} point(s)"]
        if machine.path is not None:
            parts.append(f"path {mesh_length_text(scene, machine.path.length, self.obj)}")
        settings = scene.vg_settings
        parts.append(
            f"every {mesh_length_text(scene, settings.edge_spacing, self.obj)}, r "
            f"{mesh_length_text(scene, settings.radius, self.obj)}"
        )
        if machine.message:
            parts.append(machine.message.splitlines()[0])
        return " · ".join(parts)


class VG_OT_measure_edge(PatchProperties, RuleProperties, bpy.types.Operator):
    """Measure a whole break edge: click its start, any via points and its end on the active
    mesh, then Enter; every station is recorded as a measurement of one new break"""

    bl_idname = "vg.measure_edge"
    bl_label = "Edge Profile"
    bl_options = {"REGISTER", "UNDO"}  # noqa: RUF012 (Blender wants a set)

    points: StringProperty(
        name="Points",
        description="Start, via points and end of the edge, as JSON [[x, y, z], ...] (exact "
        "float64) in the coordinates Space says; each snaps to the nearest vertex",
        options={"SKIP_SAVE"},  # never the last call's edge: a call without points is refused
    )
    space: EnumProperty(
        name="Space",
        items=SPACE_ITEMS,
        default="WORLD",
        description="The coordinates Points are given in (clicks are recorded in mesh coordinates)",
    )
    spacing: length_property(
        "Spacing", "Arc length between stations, in mesh units; default: the panel's"
    )
    note: StringProperty(
        name="Note", description="Free text stored with the edge", options={"SKIP_SAVE"}
    )

    @classmethod
    def poll(cls, context):
        return poll_measurable(cls, context)

    def execute(self, context):
        defaults_from_panel(
            self,
            context,
            EDGE_SETTINGS,
        )
        obj = context.active_object
        try:
            edge = edges.measure_edge_on_object(
                obj,
                parse_points_json(self.points),
                typed_value(self.spacing),
                typed_value(self.radius),
                typed_value(self.seg_param),
                self.patch,
                depsgraph=context.evaluated_depsgraph_get(),
                note=self.note,
                space=self.space.lower(),
                rule=self.rule,
                stability=self.stability,
                given="Edge Profile",  # typed points, or clicks: those are on the surface
            )
        except GoniometerError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        self.report(
            {"INFO"},
            f"Edge {edge.number} (break {edge.break_number}) on '{obj.name}': {edge.n_stations} "
            f"stations, mean {edge.mean:.2f}° (SD {sd_text(json.loads(edge.exact).get('std'))}, min "
            f"{edge.min:.2f}°, max "
            f"{edge.max:.2f}°), pooled {edge.pooled_angle:.2f}°",
        )
        warning = json.loads(edge.exact).get("flat_spans")
        if warning:
            self.report(
                {"WARNING"},
                f"Part of edge {edge.number}'s path crosses surface with no ridge (arc lengths "
                + ", ".join(f"{a:.4g}-{b:.4g}" for a, b in warning)
                + "); check those stations.",
            )
        return {"FINISHED"}

    def invoke(self, context, event):
        if self.properties.is_property_set("points"):
            return self.execute(context)
        if context.area is None or context.area.type != "VIEW_3D":
            self.report({"WARNING"}, "Edge profiles are picked in the 3D viewport.")
            return {"CANCELLED"}
        obj = context.active_object
        try:
            check_measurable(obj)
            self._session = EdgeSession(context, obj)
        except GoniometerError as error:
            self.report({"WARNING"}, str(error))
            return {"CANCELLED"}
        context.window_manager.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        session = self._session
        try:
            action = translate_edge_event(event.type, event.value, **modifiers(event))
            status = session.handle(context, action, (event.mouse_x, event.mouse_y))
        except BaseException:
            session.finish()
            raise
        if status == "pass":
            return {"PASS_THROUGH"}
        if status == "running":
            return {"RUNNING_MODAL"}
        session.finish()
        machine = session.machine
        if machine.phase is not EdgePhase.CONFIRMED:
            self.report({"INFO"}, machine.message or "Nothing was recorded.")
            return {"CANCELLED"}
        self.points = format_points_json(machine.clicks)  # stored for redo as well
        self.space = "MESH"  # clicks are taken on the mesh, in its coordinates
        return self.execute(context)

    def cancel(self, context):
        """Blender ends the modal operator (file load, window closed, ...): clean up."""
        session = getattr(self, "_session", None)
        if session is not None:
            session.finish()


class VG_OT_delete_edge(bpy.types.Operator):
    """Delete an edge profile with all its stations"""

    bl_idname = "vg.delete_edge"
    bl_label = "Delete Edge Profile"
    bl_options = {"REGISTER", "UNDO"}  # noqa: RUF012 (Blender wants a set)

    index: IntProperty(
        name="Index",
        description="Position in the list; -1: the selected one",
        default=-1,
        min=-1,
        options={"SKIP_SAVE"},  # the panel's button deletes the selected one, never the last index
    )

    @classmethod
    def poll(cls, context):
        if not poll_measurable(cls, context):
            return False
        if not len(context.active_object.vg.edges):
            cls.poll_message_set(f"'{context.active_object.name}' has no edge profiles.")
            return False
        return True

    def execute(self, context):
        obj = context.active_object
        index = obj.vg.active_edge_index if self.index < 0 else self.index
        try:
            check_measurable(obj)
            number = edges.delete_edge(obj, index, depsgraph=context.evaluated_depsgraph_get())
        except GoniometerError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        self.report({"INFO"}, f"Deleted edge profile {number} of '{obj.name}' and its stations")
        return {"FINISHED"}


classes = (VG_OT_measure_edge, VG_OT_delete_edge)
