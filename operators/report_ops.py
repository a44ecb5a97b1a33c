"""The Report operator: the replication report (``vg_addon.analysis``) over the scene's
measurements and chosen session CSVs, as ``vg_batch.py --report`` writes it.

Blender's own Python has NumPy only; the report needs SciPy, statsmodels and matplotlib. Where
they are missing the operator refuses before writing anything, naming what to install and the
batch command that writes the same report.
"""

from __future__ import annotations

import os

import bpy
from bpy.props import CollectionProperty, StringProperty
from bpy.types import OperatorFileListElement
from bpy_extras.io_utils import ImportHelper

from ..bridge import replication
from ..vg_addon import GoniometerError
from ..vg_addon.analysis import missing_message
from ..vg_addon.analysis.report import write_report
from ..vg_addon.errors import bounded_list
from ..vg_addon.formats import csvio
from .common import absolute_path
from .csv_ops import offered_import_path

SCENE_SESSION = "scene_measurements.csv"


def batch_command(folder: str, paths: list[str]) -> str:
    """The ``vg_batch.py --report`` command that writes the same report."""
    quoted = " ".join(f'"{p}"' if " " in p else p for p in paths) or "SESSION.csv ..."
    return f"python vg_batch.py --report {folder or 'DIR'} {quoted}"


class VG_OT_report(bpy.types.Operator, ImportHelper):
    """Write the replication report (IOV per break and method, inter-observer ICC, Tukey HSD,
    regression, Bland-Altman, figures) over the chosen session CSVs and, if ticked, this
    scene's measurements: report.html and CSV tables in the report folder (the scene's report
    settings, ``Scene.vg_settings.report_*``)"""

    bl_idname = "vg.report"
    bl_label = "Replication Report"
    bl_options = {"REGISTER"}  # noqa: RUF012 (Blender wants a set)

    filename_ext = ".csv"
    filter_glob: StringProperty(default="*.csv", options={"HIDDEN"})
    files: CollectionProperty(type=OperatorFileListElement, options={"HIDDEN", "SKIP_SAVE"})
    directory: StringProperty(subtype="DIR_PATH", options={"HIDDEN", "SKIP_SAVE"})

    def _sessions(self) -> list[str]:
        folder = bpy.path.abspath(self.directory) if self.directory else ""
        names = [f.name for f in self.files if f.name]
        if not names and self.filepath and os.path.isfile(bpy.path.abspath(self.filepath)):
            return [bpy.path.abspath(self.filepath)]
        return [os.path.join(folder, name) for name in names]

    def draw(self, context):
        """The file browser's side panel: the scene's report settings (one home, saved in the
        .blend), so the next report starts from the same choices."""
        settings = context.scene.vg_settings
        layout = self.layout
        layout.prop(settings, "report_include_scene")
        row = layout.row()
        row.active = settings.report_include_scene
        row.prop(settings, "report_scene_method")
        layout.prop(settings, "report_folder")

    def _folder(self, context, sessions: list[str]) -> str:
        folder = context.scene.vg_settings.report_folder
        if folder:
            return absolute_path(folder)
        if sessions:
            return os.path.join(os.path.dirname(sessions[0]), "vg_report")
        if bpy.data.filepath:
            return os.path.join(os.path.dirname(bpy.data.filepath), "vg_report")
        return ""

    def invoke(self, context, event):
        """Refuse at once where the libraries are missing (no files to choose in vain), else
        open the file browser on CSV files, offering the CSV this session last exported or
        imported, as Import does."""
        missing = missing_message(batch_command(context.scene.vg_settings.report_folder, []))
        if missing:
            self.report({"ERROR"}, missing)
            return {"CANCELLED"}
        offered = offered_import_path(
            self.filepath if self.properties.is_property_set("filepath") else ""
        )
        if offered:
            self.filepath = offered
        self.filter_glob = "*.csv"
        context.window_manager.fileselect_add(self)
        return {"RUNNING_MODAL"}

    def execute(self, context):
        settings = context.scene.vg_settings
        sessions = self._sessions()
        try:
            folder = self._folder(context, sessions)
        except GoniometerError as error:
            self.report({"ERROR"}, f"{error} Nothing was written.")
            return {"CANCELLED"}
        missing = missing_message(batch_command(folder, sessions))
        if missing:
            self.report({"ERROR"}, missing)
            return {"CANCELLED"}
        if not folder:
            self.report(
                {"ERROR"}, "Choose a report folder (this .blend file has not been saved yet)."
            )
            return {"CANCELLED"}
        measured = [o for o in context.scene.objects if o.type == "MESH" and len(o.vg.measurements)]
        try:
            if settings.report_include_scene and measured:
                os.makedirs(folder, exist_ok=True)
                scene_csv = os.path.join(folder, SCENE_SESSION)
                if any(os.path.realpath(p) == os.path.realpath(scene_csv) for p in sessions):
                    raise GoniometerError(
                        f"{scene_csv} is one of the sessions chosen; the scene's measurements "
                        "would overwrite it. Choose another report folder."
                    )
                rows = replication.export_rows(
                    sorted(measured, key=lambda o: o.name),
                    context.scene,
                    depsgraph=context.evaluated_depsgraph_get(),
                )
                csvio.write_measurements_csv(scene_csv, rows)
                sessions = [*sessions, scene_csv]
            methods = [None] * len(sessions)
            if settings.report_include_scene and measured:
                methods[-1] = settings.report_scene_method
            if not sessions:
                raise GoniometerError(
                    "No sessions: choose session CSVs, or measure in this scene and tick "
                    "'This scene's measurements'."
                )
            outcome = write_report(sessions, folder, methods=_methods(methods))
        except GoniometerError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        except OSError as error:
            self.report({"ERROR"}, f"Could not write the report into {folder}: {error}")
            return {"CANCELLED"}
        left = f"; {len(outcome.left_out)} left out (all listed in the report):\n" + bounded_list(
            outcome.left_out, lines=True
        )
        self.report(
            {"WARNING"} if outcome.left_out else {"INFO"},
            f"Wrote {os.path.join(folder, 'report.html')}: {outcome.sessions} sessions, "
            f"{outcome.readings} of {outcome.rows} rows used" + (left if outcome.left_out else ""),
        )
        if outcome.to_check:
            self.report(
                {"WARNING"},
                f"{len(outcome.to_check)} session(s) to check:\n"
                + bounded_list(outcome.to_check, lines=True),
            )
        return {"FINISHED"}


def _methods(methods: list) -> list[str] | None:
    """Per-file methods for :func:`write_report`: ``None`` where every file names its own."""
    if all(m is None for m in methods):
        return None
    return [m or "" for m in methods]


classes = (VG_OT_report,)
