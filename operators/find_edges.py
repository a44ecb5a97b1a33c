"""Find Break Edges: ``vg.find_break_edges`` finds the break edges of the active mesh, the
analyst reviews them, and the accepted ones become Edge Profiles.

Invoked from the Edge Profiles panel it runs a modal session: the detector
(``BreakEdgeFinder``) is stepped on a timer with a progress bar (Esc stops it, nothing
changed); then every candidate is drawn over the mesh, numbered and coloured by confidence
(``find_edges_overlay``), and the analyst clicks one to select it, accepts it (A), rejects it
(X) or trims it (T, then two clicks on it, and on a loop a third on the part kept); Enter measures every accepted candidate with the
panel's Spacing, Radius, λ and Patch and records each as an Edge Profile, all in one undo step.
Esc during the review records nothing. The interaction is
:class:`~vg_addon.workflow.find_edges_state.FindEdgesMachine` (pure, tested without a screen).

Called from a script (``EXEC``), ``edges`` (JSON, each edge's start, via points and end in mesh
coordinates, as a finished review stores them for redo) records those edges; ``accept`` ("ALL"
or candidate numbers) finds the candidates and records the ones named.
"""

from __future__ import annotations

import json
import time

import bpy
import numpy as np
from bpy.props import FloatProperty, StringProperty

from ..bridge import edges
from ..bridge.mesh_data import check_measurable, evaluated_geometry, surface_for
from ..vg_addon import GoniometerError
from ..vg_addon.errors import bounded_list
from ..vg_addon.method.break_edges import BreakEdgeFinder, BreakEdgeParameters
from ..vg_addon.workflow.find_edges_state import (
    Decision,
    FindEdgesMachine,
    FindPhase,
    edge_points,
    project,
)
from .common import (
    EDGE_SETTINGS,
    FIND_SETTINGS,
    PatchProperties,
    RuleProperties,
    defaults_from_panel,
    length_property,
    poll_measurable,
    status_hints,
    typed_value,
)
from .drag import NAVIGATION_EVENTS, mesh_length_text
from .find_edges_overlay import FindEdgesOverlay
from .progress import Progress, own_timer_tick
from .view_session import ViewSession, modifiers

# Work done per timer tick before the review gets the events again (seconds).
TICK_BUDGET = 0.08
TIMER_INTERVAL = 0.02
_NAVIGATION = NAVIGATION_EVENTS | {"MOUSEMOVE", "INBETWEEN_MOUSEMOVE"}

HINTS = (
    (("MOUSE_LMB",), "Select"),
    (("EVENT_A",), "Accept"),
    (("EVENT_SHIFT", "EVENT_A"), "Accept all undecided"),
    (("EVENT_X",), "Reject"),
    (("EVENT_T",), "Trim (2 clicks)"),
    (("EVENT_TAB",), "Next"),
    (("EVENT_RETURN",), "Record accepted"),
    (("EVENT_ESC",), "Cancel"),
    (("MOUSE_MMB",), "Navigate"),
)
KEYS = "Click select · A accept · X reject · T trim · Tab next · Enter record · Esc cancel"

_KEYS = {
    "A": "accept",
    "X": "reject",
    "DEL": "reject",
    "T": "trim",
    "TAB": "next",
    "RET": "finish",
    "NUMPAD_ENTER": "finish",
    "ESC": "cancel",
}


def translate_find_event(
    event_type: str, value: str, *, shift=False, ctrl=False, alt=False, repeat=False
):
    """What a Blender event means to the review: ``"click"``, ``"accept"``, ``"accept_all"``,
    ``"reject"``, ``"trim"``, ``"next"``, ``"previous"``, ``"finish"``, ``"cancel"``,
    ``"menu"`` (a right-click: Blender's menus off the viewport, nothing on it), ``"pass"``
    (navigation: Blender's) or ``"ignore"`` (a key held down repeating: each decision is one
    deliberate press, so holding A never accepts candidates not looked at)."""
    if event_type in _NAVIGATION:
        return "pass"
    if value != "PRESS" or ctrl or alt or repeat:
        return "ignore"
    if event_type == "LEFTMOUSE":
        return "click"
    if event_type == "RIGHTMOUSE":
        return "menu"
    action = _KEYS.get(event_type, "ignore")
    if shift and action in ("accept", "next"):
        return {"accept": "accept_all", "next": "previous"}[action]
    return action


def parse_edges_json(text: str) -> list[np.ndarray]:
    """The ``edges`` property: JSON ``[[[x, y, z], ...], ...]``, each edge two or more points
    (float64, exactly as written)."""
    try:
        raw = json.loads(text)
        found = [np.array(edge, dtype=np.float64) for edge in raw]
    except (ValueError, TypeError):
        raise GoniometerError(
            f"The edges must be JSON like [[[x, y, z], [x, y, z]], ...]; got {text[:200]!r}."
        ) from None
    for number, points in enumerate(found, start=1):
        if points.ndim != 2 or points.shape[1:] != (3,) or points.shape[0] < 2:
            raise GoniometerError(
                f"Edge {number} needs two or more x, y, z points (start, via points, end)."
            )
        if not np.isfinite(points).all():
            raise GoniometerError(f"Edge {number}'s points must be finite numbers.")
    if not found:
        raise GoniometerError("No edges were given: nothing to record.")
    return found


def format_edges_json(found) -> str:
    """JSON text of the edges' points that :func:`parse_edges_json` reads back bit for bit."""
    return json.dumps([[[float(v) for v in p] for p in np.asarray(e)] for e in found])


def parse_accept(text: str, numbers) -> list[int]:
    """The candidate numbers ``accept`` names ("ALL", or numbers like "1 3, 4"), refusing any
    that ``numbers`` (the candidates found) does not have."""
    words = text.replace(",", " ").split()
    if [w.upper() for w in words] == ["ALL"]:
        return sorted(numbers)
    try:
        named = [int(w) for w in words]
    except ValueError:
        raise GoniometerError(
            f"accept must be ALL or candidate numbers like '1 3 4'; got {text!r}."
        ) from None
    missing = sorted(set(named) - set(numbers))
    if missing:
        raise GoniometerError(
            f"No candidate numbered {', '.join(map(str, missing))}: {len(numbers)} were found."
        )
    return sorted(set(named))


def measure_all(surface, found, settings, names=None) -> list:
    """Measure each edge of ``found`` (its points) on ``surface`` with ``settings`` (spacing,
    radius, λ, patch, rule, stability): ``(points, EdgeProfile)`` pairs, all of them or none.

    Raises
    ------
    GoniometerError
        Naming every edge that cannot be measured (``names``: how, default "edge N").
    """
    names = [f"edge {n}" for n in range(1, len(found) + 1)] if names is None else names
    measured, failures = [], []
    for name, points in zip(names, found, strict=True):
        try:
            measured.append((points, surface.measure_along(points, *settings)))
        except GoniometerError as error:
            failures.append(f"{name}: {error}")
    if failures:
        raise GoniometerError(
            f"{len(failures)} of {len(found)} edges cannot be measured; nothing was recorded.\n"
            + bounded_list(failures, lines=True)
        )
    return measured


class FindEdgesSession(ViewSession):
    """One review on one object: the machine, the timer's work, the overlay and the texts."""

    def __init__(self, context, obj, parameters: BreakEdgeParameters):
        super().__init__(
            context, obj, FindEdgesOverlay(), "Break edges are reviewed in a 3D viewport."
        )
        self.geometry = evaluated_geometry(obj, context.evaluated_depsgraph_get())
        self.fingerprint = self.geometry.fingerprint
        surface = surface_for(obj, self.geometry)
        self.machine = FindEdgesMachine(surface, BreakEdgeFinder(surface, parameters))
        self.progress: Progress | None = None
        self.overlay.start()
        self.refresh(context)

    def work(self, context) -> None:
        """Step the finder (or the measuring) for up to :data:`TICK_BUDGET` seconds."""
        machine = self.machine
        phase = machine.phase
        end = time.perf_counter() + TICK_BUDGET
        while machine.step() and time.perf_counter() < end:
            pass
        if machine.working:
            if self.progress is None:
                label = "Finding break edges" if machine.phase is FindPhase.FINDING else "Measuring"
                self.progress = Progress(context, label)
            self.progress.step(round(100 * machine.progress), 100)
        else:
            self._end_progress()
        if machine.phase is not phase or machine.working:
            self.refresh(context)

    def _end_progress(self) -> None:
        progress, self.progress = self.progress, None
        if progress is not None:
            progress.__exit__(None, None, None)

    def projected(self, region, region_data) -> list[np.ndarray]:
        """Each candidate's path in ``region``'s pixels (NaN behind the viewer)."""
        to_clip = np.array(region_data.perspective_matrix, dtype=np.float64) @ np.array(
            self.obj.matrix_world, dtype=np.float64
        )
        width, height = region.width, region.height
        return [project(c.path.points, to_clip, width, height) for c in self.machine.candidates]

    def handle(self, context, action: str, mouse=None) -> str:
        """Apply one translated event; returns ``"running"``, ``"pass"`` or ``"done"``."""
        machine = self.machine
        if ending := self.closed():
            machine.cancel(ending)
            return "done"
        if self.moved():
            self.refresh(context)
        if action == "pass":
            return "pass"
        if action == "cancel":
            if machine.back():
                self._end_progress()  # back to the review: the measuring's progress ends
            else:
                machine.cancel()
        elif action == "menu":
            # Off the viewport (a header, the sidebar, another editor) Blender's menus open, as
            # a left-click there passes: the review must not lock the rest of the window.
            return "running" if self.view_at(mouse) is not None else "pass"
        elif machine.working:
            return "running"  # only Esc and navigation while the work runs
        elif action == "click":
            view = self.view_at(mouse)
            if view is None:  # on the toolbar, sidebar or a header: let Blender have it
                return "pass"
            region, region_data, coord = view
            if refusal := self.absent(context):
                machine.message = refusal
            else:
                machine.pick(self.projected(region, region_data), coord)
        elif action in ("accept", "reject", "next", "previous", "accept_all", "trim"):
            {
                "accept": machine.accept,
                "reject": machine.reject,
                "next": machine.select_next,
                "previous": lambda: machine.select_next(-1),
                "accept_all": machine.accept_pending,
                "trim": machine.start_trim,
            }[action]()
        elif action == "finish" and (refusal := self.unrecordable(context)):
            machine.message = refusal
        elif action == "finish":
            settings = context.scene.vg_settings
            machine.finish(
                typed_value(settings.edge_spacing),
                typed_value(settings.radius),
                typed_value(settings.seg_param),
                settings.patch,
                settings.rule,
                settings.stability,
            )
        else:
            return "running"
        if machine.phase in (FindPhase.DONE, FindPhase.CANCELLED):
            return "done"
        self.refresh(context)
        return "running"

    def refresh(self, context) -> None:
        """Hand the candidates to the overlay; update header and status bar."""
        machine = self.machine
        trim_points = None
        if machine.trim_arcs and machine.selected is not None:
            path = machine.candidates[machine.selected].path
            at = np.searchsorted(path.arc_lengths, machine.trim_arcs)
            trim_points = path.points[np.minimum(at, len(path.points) - 1)]
        self.overlay.update(
            machine.candidates,
            [str(d) for d in machine.decisions],
            machine.selected,
            self.drawn_at(),
            trim_points,
        )
        if (area := self.area) is not None:
            area.header_text_set(self.header_text(context.scene))
            area.tag_redraw()
        if self._workspace is not None and not machine.working:
            self._workspace.status_text_set(status_hints(HINTS))

    def header_text(self, scene) -> str:
        """The header: the work's progress, or the review's counts, the selected candidate and
        the keys."""
        machine = self.machine
        if machine.phase is FindPhase.FINDING:
            return f"Finding break edges… {machine.progress:.0%} · Esc cancels"
        if machine.phase is FindPhase.MEASURING:
            return f"Measuring the accepted edges… {machine.progress:.0%} · Esc back to review"
        parts = [
            f"{len(machine.candidates)} candidates, {machine.count(Decision.ACCEPTED)} accepted, "
            f"{machine.count(Decision.REJECTED)} rejected"
        ]
        if machine.selected is not None:
            c = machine.candidates[machine.selected]
            parts.append(
                f"#{c.number} {c.confidence:.0%} {mesh_length_text(scene, c.length, self.obj)} "
                f"bend {c.mean_bend_deg:.0f}°"
            )
        message = machine.message.splitlines()[0] if machine.message else ""
        if machine.phase is FindPhase.TRIMMING:
            # The machine's message, when it has one (a loop's third click, a miss), is the
            # trim's next step: said once, as the hint.
            ends = "first" if not machine.trim_arcs else "second"
            hint = message or f"Click the {ends} end of the part to keep."
            parts.append(f"Trim: {hint[0].lower()}{hint[1:].rstrip('.')} · Esc back")
        else:
            parts.append(KEYS)
            if message:
                parts.append(message)
        return " · ".join(parts)

    def finish(self) -> None:
        """Remove the drawing, the progress and the texts; safe to call more than once."""
        self._end_progress()
        super().finish()


def _optional(value: float) -> float | None:
    """0 means "derived from the mesh"; a negative value goes on to be refused, not replaced."""
    return None if value == 0.0 else typed_value(value)


class VG_OT_find_break_edges(PatchProperties, RuleProperties, bpy.types.Operator):
    """Find the break edges of the active mesh, review them (click, A accept, X reject, T trim)
    and record the accepted ones as Edge Profiles with stations every Spacing"""

    bl_idname = "vg.find_break_edges"
    bl_label = "Find Break Edges"
    bl_options = {"REGISTER", "UNDO"}  # noqa: RUF012 (Blender wants a set)

    # What to record is never taken from an earlier call (SKIP_SAVE): a call that names
    # nothing is refused, not given the last call's edges.
    edges: StringProperty(
        name="Edges",
        description="The edges to record, as JSON [[[x, y, z], ...], ...] in mesh coordinates "
        "(each its start, via points and end); set by a finished review",
        options={"SKIP_SAVE"},
    )
    accept: StringProperty(
        name="Accept",
        description="Without Edges: find the candidates and record these, ALL or numbers like "
        "'1 3 4' (the numbers the review shows)",
        options={"SKIP_SAVE"},
    )
    spacing: length_property(
        "Spacing", "Arc length between stations, in mesh units; default: the panel's"
    )
    scale: length_property(
        "Scale",
        "The neighbourhood a bend is judged at, in mesh units; 0: derived from the mesh; "
        "default: the panel's",
    )
    min_length: length_property(
        "Min Length",
        "Shorter candidates are dropped, in mesh units; 0: derived from the mesh; default: the "
        "panel's",
    )
    min_bend: FloatProperty(
        name="Min Bend (°)",
        description="A ridge bends at least this much (180° minus its angle); default: the panel's",
        default=BreakEdgeParameters().min_bend_deg,
        soft_min=0.0,
        soft_max=90.0,
    )
    note: StringProperty(
        name="Note", description="Free text stored with each edge", options={"SKIP_SAVE"}
    )

    @classmethod
    def poll(cls, context):
        return poll_measurable(cls, context)

    def parameters(self) -> BreakEdgeParameters:
        """The detector's parameters from the operator's (0: derived from the mesh)."""
        return BreakEdgeParameters(
            scale=_optional(self.scale),
            min_bend_deg=typed_value(self.min_bend),
            min_length=_optional(self.min_length),
        )

    def settings(self) -> tuple:
        return (
            typed_value(self.spacing),
            typed_value(self.radius),
            typed_value(self.seg_param),
            self.patch,
            self.rule,
            self.stability,
        )

    def execute(self, context):
        defaults_from_panel(self, context, {**EDGE_SETTINGS, **FIND_SETTINGS})
        obj = context.active_object
        try:
            check_measurable(obj)
            geometry = evaluated_geometry(obj, context.evaluated_depsgraph_get())
            surface = surface_for(obj, geometry)
            found = parse_edges_json(self.edges) if self.edges else self.find(surface)
            measured = measure_all(surface, found, self.settings())
            made = edges.record_profiles(obj, measured, geometry, self.note)
        except GoniometerError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        # Edges found by Accept are not written back: a redo with another Accept, Scale, Min
        # Length or Min Bend finds them again.
        return self.recorded(obj, made)

    def find(self, surface) -> list[np.ndarray]:
        """Run the detector to the end; the points of the candidates ``accept`` names."""
        if not self.accept.strip():
            raise GoniometerError(
                "Name the candidates to record: accept='ALL' or numbers like '1 3' (or give "
                "edges); the panel's button reviews them first."
            )
        result = BreakEdgeFinder(surface, self.parameters()).run()
        candidates = {c.number: c for c in result.candidates}
        return [edge_points(candidates[n]) for n in parse_accept(self.accept, candidates)]

    def recorded(self, obj, made):
        if not made:
            self.report({"INFO"}, "No break edge was found: nothing was recorded.")
            return {"CANCELLED"}
        stations = sum(edge.n_stations for edge in made)
        self.report(
            {"INFO"},
            f"Recorded {len(made)} edge profile(s) on '{obj.name}' ({stations} stations): "
            + ", ".join(f"{e.number} (mean {e.mean:.1f}°)" for e in made),
        )
        return {"FINISHED"}

    def invoke(self, context, event):
        given = self.properties.is_property_set
        if given("edges") or given("accept"):
            return self.execute(context)
        if context.area is None or context.area.type != "VIEW_3D":
            self.report({"WARNING"}, "Break edges are reviewed in the 3D viewport.")
            return {"CANCELLED"}
        defaults_from_panel(self, context, FIND_SETTINGS)
        obj = context.active_object
        try:
            check_measurable(obj)
            self._session = FindEdgesSession(context, obj, self.parameters())
        except GoniometerError as error:
            self.report({"WARNING"}, str(error))
            return {"CANCELLED"}
        wm = context.window_manager
        self._timer = wm.event_timer_add(TIMER_INTERVAL, window=context.window)
        self._session.timer = self._timer  # removed with the session if the extension goes
        wm.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        session = self._session
        try:
            if own_timer_tick(self, event):
                if ending := session.closed():
                    session.machine.cancel(ending)
                elif session.machine.working:
                    session.work(context)
                status = "done" if session.machine.phase is FindPhase.DONE else "running"
                if session.machine.phase is FindPhase.CANCELLED:
                    status = "done"
            else:
                action = translate_find_event(event.type, event.value, **modifiers(event))
                status = session.handle(context, action, (event.mouse_x, event.mouse_y))
        except BaseException:
            self._end(context)
            raise
        if status == "pass":
            return {"PASS_THROUGH"}
        if status == "running":
            return {"RUNNING_MODAL"}
        self._end(context)
        return self._conclude(context, session)

    def _conclude(self, context, session):
        machine = session.machine
        if machine.phase is not FindPhase.DONE or not machine.profiles:
            self.report({"INFO"}, machine.message or "Nothing was recorded.")
            return {"CANCELLED"}
        obj = session.obj
        try:
            check_measurable(obj)
            geometry = evaluated_geometry(obj, context.evaluated_depsgraph_get())
            if geometry.fingerprint != session.geometry.fingerprint:
                raise GoniometerError(
                    f"'{obj.name}' changed during the review: nothing was recorded; run Find "
                    "Break Edges again."
                )
        except GoniometerError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        settings = context.scene.vg_settings
        self.spacing, self.radius = settings.edge_spacing, settings.radius
        self.seg_param, self.patch = settings.seg_param, settings.patch
        self.rule, self.stability = settings.rule, settings.stability
        self.edges = format_edges_json([points for points, _ in machine.profiles])  # for redo
        try:
            made = edges.record_profiles(obj, machine.profiles, geometry, self.note)
        except GoniometerError as error:  # recorded none (no break number left)
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        return self.recorded(obj, made)

    def _end(self, context) -> None:
        self._timer = None
        session = getattr(self, "_session", None)
        if session is not None:
            session.finish()  # its timer too

    def cancel(self, context):
        """Blender ends the modal operator (file load, window closed, ...): clean up."""
        self._end(context)


classes = (VG_OT_find_break_edges,)
