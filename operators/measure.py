"""Operators that measure and manage the measurement list (thin: the work is in ``measuring``)."""

from __future__ import annotations

import bpy
import numpy as np
from bpy.props import (
    IntProperty,
    StringProperty,
)

from ..bridge import measuring, plots, records
from ..bridge.mesh_data import (
    NotEvaluatedError,
    check_measurable,
    evaluated_geometry,
    uniform_scale,
)
from ..vg_addon import GoniometerError
from ..vg_addon.formats.record_codec import exact_numbers
from ..vg_addon.method.result import fit_text
from .common import (
    LocationProperties,
    PatchProperties,
    RuleProperties,
    defaults_from_panel,
    poll_measurable,
    poll_measured,
    typed_value,
)


def _stale_warning(obj) -> str:
    items = obj.vg.measurements
    flags = np.zeros(len(items), dtype=bool)
    items.foreach_get("stale", flags)  # no Python loop over every stored measurement
    if not flags.any():
        return ""
    numbers = np.zeros(len(items), dtype=np.int64)
    items.foreach_get("number", numbers)
    stale = [str(number) for number in numbers[flags]]
    return (
        f"Measurement(s) {', '.join(stale)} of '{obj.name}' are stale: the mesh or its modifiers "
        "changed since they were taken. Their numbers are kept; they are no longer painted."
    )


def non_uniform_scale_note(obj) -> str:
    """A warning for an object whose scale is not uniform, else ''."""
    if obj is None or uniform_scale(np.array(obj.matrix_world, dtype=np.float64)) is not None:
        return ""
    return (
        f"'{obj.name}' has a non-uniform scale: angles are measured on the mesh as stored "
        "(its file's shape), not as scaled in the viewport. Apply the scale (Ctrl A) if it is "
        "meant to change the shape."
    )


class MeasureProperties(LocationProperties, PatchProperties, RuleProperties):
    """The inputs of a measurement, shared by every operator that records one (a mixin, so
    the drag tool's recorded values mean exactly what xyz entry's do)."""

    note: StringProperty(
        name="Note", description="Free text stored with the measurement", options={"SKIP_SAVE"}
    )


class VG_OT_measure_xyz(MeasureProperties, bpy.types.Operator):
    """Measure the break angle on the active mesh at a point (default: the 3D cursor)"""

    bl_idname = "vg.measure_xyz"
    bl_label = "Measure at 3D Cursor"
    bl_options = {"REGISTER", "UNDO"}  # noqa: RUF012 (Blender wants a set)

    @classmethod
    def poll(cls, context):
        return poll_measurable(cls, context)

    def execute(self, context):
        defaults_from_panel(
            self,
            context,
            {name: name for name in ("radius", "seg_param", "patch", "rule", "stability")},
        )
        obj = context.active_object
        try:
            item = measuring.measure_on_object(
                obj,
                [typed_value(v) for v in self.location],
                typed_value(self.radius),
                typed_value(self.seg_param),
                self.patch,
                depsgraph=context.evaluated_depsgraph_get(),
                note=self.note,
                space=self.space.lower(),
                rule=self.rule,
                stability=self.stability,
            )
        except GoniometerError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        report_measurement(self, obj, item)
        return {"FINISHED"}


def report_measurement(operator, obj, item) -> None:
    """Say what a measuring operator just recorded (``item`` on ``obj``), and warn of stale
    measurements, an unstable reading and a non-uniform scale."""
    computed = exact_numbers(item).get("stability")  # asked for, or a small patch's own
    spread = f" {item.stability_text}" if computed else ""
    operator.report(
        {"INFO"},
        f"Measurement {item.number} (break {item.break_number}) on '{obj.name}': "
        f"{item.angle:.2f}°{spread}, {item.convexity} edge "
        f"(fit error {fit_text(item.fit_error, item.radius)}, "
        f"{item.n_vertices} vertices)",
    )
    if item.stability_warning:
        operator.report({"WARNING"}, f"Measurement {item.number}: {item.stability_warning}")
    for warning in (_stale_warning(obj), non_uniform_scale_note(obj)):
        if warning:
            operator.report({"WARNING"}, warning)


def _active_measurable(operator, context):
    """The active object if it can be measured, else report why and return None."""
    obj = context.active_object
    try:
        check_measurable(obj)
    except GoniometerError as error:
        operator.report({"ERROR"}, str(error))
        return None
    return obj


def _removing(operator, context):
    """The measurable active object whose records are to be removed, and its evaluated geometry
    to repaint with: ``(None, None)`` after reporting why the object cannot be changed, or
    ``(obj, None)`` where its mesh cannot be read now (every vertex deleted): records can always
    be removed, and then there is nothing to repaint. An object disabled in the viewports is
    refused: its records' colours could not be taken off its mesh."""
    obj = _active_measurable(operator, context)
    if obj is None:
        return None, None
    try:
        return obj, evaluated_geometry(obj, context.evaluated_depsgraph_get(), purpose="to repaint")
    except NotEvaluatedError as error:
        operator.report({"ERROR"}, str(error))
        return None, None
    except GoniometerError:
        return obj, None


class VG_OT_next_break(bpy.types.Operator):
    """Start a new break: the next measurements get a break number no measurement has yet, and
    its colour pair"""

    bl_idname = "vg.next_break"
    bl_label = "Next Break"
    bl_options = {"REGISTER", "UNDO"}  # noqa: RUF012 (Blender wants a set)

    @classmethod
    def poll(cls, context):
        return poll_measurable(cls, context)

    def execute(self, context):
        obj = _active_measurable(self, context)
        if obj is None:
            return {"CANCELLED"}
        obj.vg.break_number = records.next_free_break(obj)
        self.report({"INFO"}, f"Break {obj.vg.break_number} on '{obj.name}'")
        return {"FINISHED"}


class VG_OT_delete_measurement(bpy.types.Operator):
    """Delete a measurement from the list and repaint the others"""

    bl_idname = "vg.delete_measurement"
    bl_label = "Delete Measurement"
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
        return poll_measured(cls, context)

    def execute(self, context):
        obj = context.active_object
        data = getattr(obj, "vg", None)
        index = -1 if data is None else (data.active_index if self.index < 0 else self.index)
        if data is not None and not 0 <= index < len(data.measurements):
            self.report({"ERROR"}, f"'{obj.name}' has no measurement at list position {index}.")
            return {"CANCELLED"}
        obj, geometry = _removing(self, context)
        if obj is None:
            return {"CANCELLED"}
        data = obj.vg
        number = data.measurements[index].number
        data.measurements.remove(index)
        data.active_index = records.position_after_removal(
            data.active_index, [index], len(data.measurements)
        )
        if geometry is not None:
            measuring.repaint(obj, geometry=geometry)
        self.report({"INFO"}, f"Deleted measurement {number} of '{obj.name}'")
        return {"FINISHED"}


class VG_OT_clear_measurements(bpy.types.Operator):
    """Delete every measurement and edge profile of the active object and paint it grey"""

    bl_idname = "vg.clear_measurements"
    bl_label = "Clear Measurements"
    bl_options = {"REGISTER", "UNDO"}  # noqa: RUF012 (Blender wants a set)

    @classmethod
    def poll(cls, context):
        return poll_measured(cls, context)

    def invoke(self, context, event):
        return context.window_manager.invoke_confirm(self, event)

    def execute(self, context):
        obj, geometry = _removing(self, context)
        if obj is None:
            return {"CANCELLED"}
        count = len(obj.vg.measurements)
        plots.remove_plots(list(obj.vg.edges))  # the edge profiles go with their stations
        obj.vg.edges.clear()
        obj.vg.active_edge_index = 0
        obj.vg.next_edge_number = 1
        obj.vg.measurements.clear()
        obj.vg.active_index = 0
        obj.vg.next_number = 1
        obj.vg.break_number = 1
        if geometry is not None:
            measuring.repaint(obj, geometry=geometry)
        self.report({"INFO"}, f"Cleared {count} measurement(s) of '{obj.name}'")
        return {"FINISHED"}


class VG_OT_repaint(bpy.types.Operator):
    """Check which measurements are stale and repaint the sides of the others"""

    bl_idname = "vg.repaint"
    bl_label = "Update Colours"
    bl_options = {"REGISTER", "UNDO"}  # noqa: RUF012 (Blender wants a set)

    @classmethod
    def poll(cls, context):
        return poll_measured(cls, context)

    def execute(self, context):
        obj = _active_measurable(self, context)
        if obj is None:
            return {"CANCELLED"}
        try:
            measuring.repaint(obj, depsgraph=context.evaluated_depsgraph_get(), verify=True)
        except GoniometerError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        self.report(
            {"WARNING"} if _stale_warning(obj) else {"INFO"},
            _stale_warning(obj) or f"Colours of '{obj.name}' are up to date",
        )
        return {"FINISHED"}


def _listed_item(context, index: int):
    """The active object's measurement at list position ``index``, or None."""
    data = getattr(context.active_object, "vg", None)
    if data is None or not 0 <= index < len(data.measurements):
        return None
    return data.measurements[index]


class VG_OT_stability_warning(bpy.types.Operator):
    """Why this reading is flagged: its stability figure is large or undetermined"""

    bl_idname = "vg.stability_warning"
    bl_label = "Unstable Reading"
    bl_options = {"INTERNAL", "UNDO"}  # noqa: RUF012 (Blender wants a set)

    index: IntProperty(name="Index", description="Position in the list", default=0, min=0)

    @classmethod
    def poll(cls, context):
        data = getattr(context.active_object, "vg", None)
        if data is None or not len(data.measurements):
            cls.poll_message_set("The active object has no measurements.")
            return False
        return True

    @classmethod
    def description(cls, context, properties):
        """The flagged row's tooltip: the reason, in the words of every other place."""
        item = _listed_item(context, properties.index)
        return (item.stability_warning if item is not None else "") or cls.__doc__

    def execute(self, context):
        item = _listed_item(context, self.index)
        if item is None:
            self.report({"ERROR"}, f"No measurement at list position {self.index}.")
            return {"CANCELLED"}
        obj = context.active_object
        if obj.is_editable and obj.library is None and obj.override_library is None:
            obj.vg.active_index = self.index  # select the row clicked (linked data stays as is)
        warning = item.stability_warning or "not flagged: its stability figure is small."
        self.report({"WARNING"}, f"Measurement {item.number}: {warning}")
        return {"FINISHED"}


classes = (
    VG_OT_measure_xyz,
    VG_OT_next_break,
    VG_OT_delete_measurement,
    VG_OT_clear_measurements,
    VG_OT_repaint,
    VG_OT_stability_warning,
)
