"""The radius sweep operator: angle and fit error over a range of radii at one site, written as a
CSV and a plot PNG beside it (nothing is recorded on the object)."""

from __future__ import annotations

from pathlib import Path

import bpy
from bpy.props import (
    IntProperty,
    StringProperty,
)
from bpy_extras.io_utils import ExportHelper

from ..bridge import measuring, records
from ..vg_addon import GoniometerError
from ..vg_addon.formats import csvio, mpl_plots, sweep_plot
from .common import (
    LocationProperties,
    absolute_path,
    defaults_from_panel,
    length_property,
    poll_measurable,
    typed_value,
)


class VG_OT_radius_sweep(LocationProperties, bpy.types.Operator, ExportHelper):
    """Measure at the 3D cursor over a range of radii (the MeshLab plugin's burst) and write the
    angles and fit errors to a CSV, with a plot of them as a PNG of the same name"""

    bl_idname = "vg.radius_sweep"
    bl_label = "Radius Sweep"
    bl_options = {"REGISTER"}  # noqa: RUF012 (Blender wants a set)

    filename_ext = ".csv"
    filter_glob: StringProperty(default="*.csv", options={"HIDDEN"})
    start: length_property("From", "First radius, in mesh units; default: the panel's")
    stop: length_property("To", "Last radius, in mesh units; default: the panel's")
    count: IntProperty(name="Radii", description="Default: the panel's", min=2, max=1000)

    @classmethod
    def poll(cls, context):
        return poll_measurable(cls, context)

    def execute(self, context):
        settings = context.scene.vg_settings
        defaults_from_panel(
            self, context, {"start": "sweep_start", "stop": "sweep_stop", "count": "sweep_count"}
        )
        obj = context.active_object
        try:
            path = absolute_path(self.filepath)
            if not path:
                raise GoniometerError("No file name given: choose where to write the sweep CSV.")
            points = measuring.sweep(
                obj,
                [typed_value(v) for v in self.location],
                typed_value(self.start),
                typed_value(self.stop),
                self.count,
                typed_value(settings.seg_param),
                settings.patch,
                depsgraph=context.evaluated_depsgraph_get(),
                rule=settings.rule,
                space=self.space.lower(),
            )
            image = str(Path(path).with_suffix(".png"))
            csvio.write_sweep_csv(
                path, obj.name, points, units=records.units_label(context.scene, obj)
            )
            sweep_plot.write_sweep_png(
                image,
                points,
                units=records.unit_symbol(obj, context.scene),
                title=f"Radius sweep: {obj.name}",
            )
        except GoniometerError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        except OSError as error:
            self.report({"ERROR"}, f"Could not write the sweep: {error}")
            return {"CANCELLED"}
        measured = [p.measurement.angle for p in points if p.measurement is not None]
        self.report(
            {"INFO"},
            f"Sweep of {len(points)} radii on '{obj.name}' ({len(measured)} measured, "
            f"{min(measured):.2f}° to {max(measured):.2f}°): {path} and {image}"
            + ("" if mpl_plots.available() else f" ({mpl_plots.MISSING})"),
        )
        return {"FINISHED"}


classes = (VG_OT_radius_sweep,)
