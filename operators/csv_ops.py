"""CSV export and import (replication) operators."""

from __future__ import annotations

import bpy
from bpy.props import BoolProperty, StringProperty
from bpy_extras.io_utils import ExportHelper, ImportHelper

from ..bridge import measuring
from ..bridge.mesh_data import check_measurable
from ..vg_addon import GoniometerError
from ..vg_addon.formats import csvio
from .measure import poll_measurable, typed_value
from .progress import Progress


def _path(operator) -> str:
    return bpy.path.abspath(operator.filepath) if operator.filepath else ""


class VG_OT_export_csv(bpy.types.Operator, ExportHelper):
    """Write the measurements to a CSV file (MeshLab Virtual Goniometer columns first)"""

    bl_idname = "vg.export_csv"
    bl_label = "Export Measurements CSV"
    bl_options = {"REGISTER"}  # noqa: RUF012 (Blender wants a set)

    filename_ext = ".csv"
    filter_glob: StringProperty(default="*.csv", options={"HIDDEN"})
    all_objects: BoolProperty(
        name="All objects",
        description="Export the measurements of every object in the scene, not only the active one",
        default=False,
    )

    @classmethod
    def poll(cls, context):
        if any(o.type == "MESH" and len(o.vg.measurements) for o in context.scene.objects):
            return True
        cls.poll_message_set("No object in this scene has measurements to export.")
        return False

    def execute(self, context):
        path = _path(self)
        if not path:
            self.report({"ERROR"}, "No file name given: choose where to write the CSV.")
            return {"CANCELLED"}
        if self.all_objects:
            objects = [
                obj
                for obj in sorted(context.scene.objects, key=lambda o: o.name)
                if obj.type == "MESH" and len(obj.vg.measurements)
            ]
            if not objects:
                self.report({"ERROR"}, "No object in this scene has measurements to export.")
                return {"CANCELLED"}
        else:
            obj = context.active_object
            if obj is None or obj.type != "MESH":
                self.report(
                    {"ERROR"},
                    "No active mesh object: select the measured mesh, or tick 'All objects'.",
                )
                return {"CANCELLED"}
            if not len(obj.vg.measurements):
                self.report({"ERROR"}, f"'{obj.name}' has no measurements to export.")
                return {"CANCELLED"}
            objects = [obj]
        try:
            rows = measuring.export_rows(
                objects, context.scene, depsgraph=context.evaluated_depsgraph_get()
            )
            csvio.write_measurements_csv(path, rows)
        except OSError as error:
            self.report({"ERROR"}, f"Could not write {path}: {error}")
            return {"CANCELLED"}
        except GoniometerError as error:
            self.report({"ERROR"}, f"{error} ({path} was not written)")
            return {"CANCELLED"}
        stale = sum(row.stale for row in rows)
        note = f" ({stale} stale)" if stale else ""
        self.report({"INFO"}, f"Wrote {len(rows)} measurement(s){note} to {path}")
        return {"FINISHED"}


class VG_OT_import_csv(bpy.types.Operator, ImportHelper):
    """Re-measure every row of a measurement CSV on the active mesh (the paper's xyz method).
    Reads this extension's CSVs, the MeshLab plugin's, the earlier Blender add-on's and plain
    x, y, z point lists (rows without radius, λ or patch mode take the panel's)"""

    bl_idname = "vg.import_csv"
    bl_label = "Import Measurements CSV"
    bl_options = {"REGISTER", "UNDO"}  # noqa: RUF012 (Blender wants a set)

    filename_ext = ".csv"
    filter_glob: StringProperty(default="*.csv", options={"HIDDEN"})
    ignore_mesh_names: BoolProperty(
        name="Ignore mesh names",
        description="Measure rows whose Mesh Name is not this object's on this object too",
        default=False,
    )

    @classmethod
    def poll(cls, context):
        return poll_measurable(cls, context)

    def execute(self, context):
        path = _path(self)
        obj = context.active_object
        try:
            check_measurable(obj)
            if not path:
                raise GoniometerError("No file name given: choose the CSV to import.")
            settings = context.scene.vg_settings
            with Progress(context, f"Re-measuring {bpy.path.basename(path)}") as progress:
                numbers = measuring.import_csv(
                    obj,
                    path,
                    ignore_mesh_names=self.ignore_mesh_names,
                    radius=typed_value(settings.radius),
                    lam=typed_value(settings.seg_param),
                    patch=settings.patch,
                    depsgraph=context.evaluated_depsgraph_get(),
                    progress=progress.step,
                )
        except GoniometerError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        except OSError as error:
            self.report({"ERROR"}, f"Could not read {path}: {error}")
            return {"CANCELLED"}
        self.report(
            {"INFO"},
            f"Re-measured {len(numbers)} row(s) of {bpy.path.basename(path)} on '{obj.name}' "
            f"(measurements {numbers[0]}–{numbers[-1]})",
        )
        return {"FINISHED"}


classes = (VG_OT_export_csv, VG_OT_import_csv)
