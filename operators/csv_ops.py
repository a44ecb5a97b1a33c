"""CSV export and import (replication) operators."""

from __future__ import annotations

import contextlib
import dataclasses
import os
import time

import bpy
from bpy.props import BoolProperty, StringProperty
from bpy_extras.io_utils import ExportHelper, ImportHelper

from ..bridge import edges, measuring, records, replication
from ..bridge.mesh_data import check_measurable
from ..vg_addon import GoniometerError, units
from ..vg_addon.errors import bounded_list
from ..vg_addon.formats import csvio
from ..vg_addon.workflow import agreement
from .common import absolute_path, poll_measurable, typed_value
from .progress import Progress, own_timer_tick

# The CSV this session last exported or imported: what the Import dialog offers (Blender's
# file browser would otherwise offer the .blend's own name).
_last_csv = ""


def _remember(path: str) -> None:
    global _last_csv  # one value for the session, read by the next Import
    _last_csv = path


def offered_import_path(given: str = "") -> str:
    """The path the Import dialog opens with: ``given`` when it is a CSV or text file (a
    script's, or the last import's), else the last CSV this session exported or imported, else
    the .blend's folder with no file name; ``""`` when there is none of these (the browser keeps
    its own folder)."""
    if os.path.splitext(given)[1].lower() in (".csv", ".txt"):
        return given
    if _last_csv:
        if os.path.isfile(_last_csv):
            return _last_csv
        if os.path.isdir(os.path.dirname(_last_csv)):
            return os.path.join(os.path.dirname(_last_csv), "")
    if bpy.data.filepath:
        return os.path.join(os.path.dirname(bpy.data.filepath), "")
    return ""


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
        try:
            path = absolute_path(self.filepath)
        except GoniometerError as error:
            self.report({"ERROR"}, f"{error} Nothing was written.")
            return {"CANCELLED"}
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
            rows, edge_rows = replication.export_tables(
                objects, context.scene, depsgraph=context.evaluated_depsgraph_get()
            )
        except GoniometerError as error:
            self.report({"ERROR"}, f"{error} ({path} was not written)")
            return {"CANCELLED"}
        try:
            summary = csvio.write_export(path, rows, edge_rows)
        except OSError as error:
            self.report({"ERROR"}, f"Could not write {path}: {error}")
            return {"CANCELLED"}
        except csvio.SummaryWriteError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        except GoniometerError as error:
            self.report({"ERROR"}, f"{error} ({path} was not written)")
            return {"CANCELLED"}
        _remember(path)
        stale = sum(row.stale for row in rows)
        note = f" ({stale} stale)" if stale else ""
        if edge_rows:
            edges = f" and {len(edge_rows)} edge profile(s) to {summary}"
        elif summary is not None:
            edges = f"; {summary}, from an earlier export, now lists no edge"
        else:
            edges = ""
        short = replication.short_edges(rows, edge_rows)
        if short:
            edges += (
                f"; {len(short)} edge(s) lost stations after they were measured "
                f"({bounded_list(short)}): their summary rows keep the figures of every station "
                "as recorded, and importing the summary traces and measures them all again"
            )
        self.report(
            {"WARNING" if short else "INFO"},
            f"Wrote {len(rows)} measurement(s){note} to {path}{edges}",
        )
        return {"FINISHED"}


class VG_OT_import_csv(bpy.types.Operator, ImportHelper):
    """Re-measure every row of a measurement CSV on the active mesh (the paper's xyz method).
    Reads this extension's CSVs, the MeshLab plugin's, the earlier Blender add-on's and plain
    x, y, z point lists (rows without radius, λ or patch mode take the panel's; MeshLab and
    earlier add-on rows are re-measured with the paper's rule they were taken with); an edge
    summary file (NAME_edges.csv) has each of its edges traced and measured again"""

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
    interactive: BoolProperty(
        name="Interactive",
        description="Started from the file browser: measure in steps, with progress, and let "
        "Esc cancel (scripts measure in one go)",
        default=False,
        options={"HIDDEN", "SKIP_SAVE"},
    )

    # Rows measured per timer step: a step stays short enough for Esc to be noticed.
    STEP_SECONDS = 0.1

    @classmethod
    def poll(cls, context):
        return poll_measurable(cls, context)

    def invoke(self, context, event):
        """Open the file browser on the last exported CSV (Blender's own offer is the .blend's
        name), showing only CSV files."""
        self.interactive = True
        offered = offered_import_path(
            self.filepath if self.properties.is_property_set("filepath") else ""
        )
        if offered:
            self.filepath = offered
        self.filter_glob = "*.csv"
        context.window_manager.fileselect_add(self)
        return {"RUNNING_MODAL"}

    def _start(self, context):
        """Read the file and prepare the steps; report and return None on a problem (an edge
        summary file is imported at once: the operator's result)."""
        path = self.filepath
        obj = context.active_object
        try:
            path = absolute_path(self.filepath)
            check_measurable(obj)
            if not path:
                raise GoniometerError("No file name given: choose the CSV to import.")
            settings = context.scene.vg_settings
            if csvio.is_edges_csv(path):  # an edge summary file: re-trace its edges
                edge_numbers = edges.import_edges_csv(
                    obj,
                    path,
                    ignore_mesh_names=self.ignore_mesh_names,
                    lam=typed_value(settings.seg_param),
                    patch=settings.patch,
                    depsgraph=context.evaluated_depsgraph_get(),
                    rule=settings.rule,
                    stability=settings.stability,
                )
                summaries = csvio.read_edges_csv(path)
                extra = adopt_units(obj, [row.units for row in summaries])
                extra += edge_agreement_text(obj, summaries, edge_numbers)
                failed = sum(1 for row in summaries if row.error)
                if failed:
                    extra += (
                        f"; passed over {failed} edge(s) the run that wrote it could not "
                        "measure (their error column)"
                    )
                self.report(
                    {"WARNING" if failed else "INFO"},
                    f"Re-measured {len(edge_numbers)} edge profile(s) of "
                    f"{bpy.path.basename(path)} on '{obj.name}'{extra}",
                )
                _remember(path)
                return {"FINISHED"}
            self._passed_over = []
            rows, source = replication.read_rows(path, self._passed_over)
            edge_notes, self._notes_from = replication.edge_notes_beside(path, rows)
            self._notes_taken = []
            steps = replication.replicate_steps(
                obj,
                rows,
                ignore_mesh_names=self.ignore_mesh_names,
                radius=typed_value(settings.radius),
                lam=typed_value(settings.seg_param),
                patch=settings.patch,
                depsgraph=context.evaluated_depsgraph_get(),
                source=source,
                rule=settings.rule,
                stability=settings.stability,
                edge_notes=edge_notes,
                notes_taken=self._notes_taken,
            )
        except GoniometerError as error:
            self.report({"ERROR"}, str(error))
            return None
        except OSError as error:
            self.report({"ERROR"}, f"Could not read {path}: {error}")
            return None
        self._obj, self._path_name, self._steps = obj, bpy.path.basename(path), steps
        self._full_path = path
        self._export = csvio.read_from_export(rows)
        return steps

    def execute(self, context):
        steps = self._start(context)
        if steps is None:
            return {"CANCELLED"}
        if isinstance(steps, set):  # an edge summary file, imported at once
            return steps
        if self.interactive and context.window is not None:
            wm = context.window_manager
            self._progress = Progress(context, f"Re-measuring {self._path_name} (Esc cancels)")
            self._timer = wm.event_timer_add(0.01, window=context.window)
            wm.modal_handler_add(self)
            # Blender registers this very operator when it ends, and Repeat Last or Adjust Last
            # Operation call its execute again: started modal a second time, it crashed Blender
            # 4.3 as it ended. Those repeats run in one go.
            self.interactive = False
            return {"RUNNING_MODAL"}
        self._progress = Progress(context, f"Re-measuring {self._path_name}")
        try:
            return self._advance(self._progress, until=None)
        finally:
            self._finish(context)

    def _advance(self, progress, until):
        """Measure rows until the time ``until`` (None: to the end); the operator's result, or
        None to go on."""
        try:
            while True:
                done, total = next(self._steps)
                progress.step(done, total)
                if until is not None and time.perf_counter() > until:
                    return None
        except StopIteration as finished:
            numbers = finished.value
        except GoniometerError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        extra, differing = follow_export(self._obj, self._full_path, numbers, self._export)
        if taken := getattr(self, "_notes_taken", []):
            extra += (
                f"; {len(taken)} edge(s) take their note from {self._notes_from} (edited after "
                "they were measured: their stations keep theirs)"
            )
        passed = getattr(self, "_passed_over", [])
        if passed:
            extra += (
                f"; passed over {len(passed)} row(s) a batch run could not measure (rows "
                f"{bounded_list(passed)}: no x, y, z; their error column says why)"
            )
        self.report(
            {"WARNING" if differing or passed else "INFO"},
            f"Re-measured {len(numbers)} row(s) of {self._path_name} on '{self._obj.name}' "
            f"(measurements {numbers[0]}–{numbers[-1]}){extra}",
        )
        _remember(self._full_path)
        return {"FINISHED"}

    def modal(self, context, event):
        """A step of rows per tick of this operator's timer; Esc cancels. Whatever goes wrong
        ends the import with nothing imported, the timer and status line removed, and a report
        (never a traceback)."""
        try:
            if event.type == "ESC":
                self._finish(context)
                self.report(
                    {"INFO"}, f"Import of {self._path_name} cancelled: nothing was imported."
                )
                return {"CANCELLED"}
            if not own_timer_tick(self, event):
                return {"RUNNING_MODAL"}
            until = time.perf_counter() + self.STEP_SECONDS
            result = self._advance(self._progress, until=until)
        except ReferenceError:  # the object was deleted meanwhile
            result = {"CANCELLED"}
            self.report({"ERROR"}, "The object was deleted: nothing was imported.")
        except Exception as error:  # a modal step must end cleanly, and say why
            result = {"CANCELLED"}
            self.report(
                {"ERROR"},
                f"Import of {self._path_name} failed ({type(error).__name__}: {error}): "
                "nothing was imported.",
            )
        if result is None:
            return {"RUNNING_MODAL"}
        self._finish(context)
        return result

    def cancel(self, context):
        """Blender ends the operator (the file browser cancelled, file load, window closed):
        nothing is imported."""
        self._finish(context)

    def _finish(self, context) -> None:
        """End the steps, the timer and the progress display; safe to call more than once, and
        before any of them was made (the file browser cancelled)."""
        steps, self._steps = getattr(self, "_steps", None), None
        if steps is not None:
            steps.close()
        timer, self._timer = getattr(self, "_timer", None), None
        if timer is not None:
            with contextlib.suppress(ReferenceError, RuntimeError, ValueError):
                context.window_manager.event_timer_remove(timer)
        progress, self._progress = getattr(self, "_progress", None), None
        if progress is not None:
            progress.__exit__(None, None, None)


def adopt_units(obj, texts) -> str:
    """:func:`records.adopt_file_units`, then redraw ``obj``'s edges' plots (their axes name the
    unit); returns what to add to the report ("" where nothing changed)."""
    key = records.adopt_file_units(obj, texts)
    if key is None:
        return ""
    edges.redraw_plots(obj)
    return f"; Scan Units {units.SYMBOLS[key]}, as the file says"


def edge_agreement_text(obj, summaries, edge_numbers) -> str:
    """How the edges just measured again from an edge summary file agree with the file's rows
    (``summaries``): what to add to the report. ``edge_numbers``: the new edges, one for each
    row without an error, in order (as ``edges.import_edges_csv`` records them)."""
    by_number = {edge.number: edge for edge in obj.vg.edges}
    measured_rows = [row for row in summaries if not row.error]
    if len(measured_rows) != len(edge_numbers):
        return ""  # the file changed since it was read: its rows are not these edges'
    replayed = [
        dataclasses.replace(
            records.edge_row(obj, by_number[number], units=""), row_number=row.row_number
        )
        for row, number in zip(measured_rows, edge_numbers, strict=True)
    ]
    return agreement.edge_agreement(summaries, replayed).text


def follow_export(obj, path, numbers, export: bool) -> tuple[str, bool]:
    """After re-measuring an export of this extension: take its Units as ``obj``'s Scan Units
    (unless the user chose them), paint each new measurement's sides the way round its Colors
    cell says, and compare the new angles with the file's; returns what to add to the report
    ("" for a file of another kind) and whether it is a warning: an angle came back different,
    or none could be compared. ``export``: the file's header has columns of this extension's
    export (a file that then does not read back as one is said to be so)."""
    try:
        rows = csvio.read_measurements_csv(path)
    except (GoniometerError, OSError, ValueError) as error:
        # else MeshLab's, the earlier add-on's or a points file: no Units, no Colors
        return (agreement.not_compared(error), True) if export else ("", False)
    rows = csvio.replayed_rows(rows)
    if len(rows) != len(numbers):
        return "", False
    extra = adopt_units(obj, [row.units for row in rows])
    by_number = {item.number: item for item in obj.vg.measurements}
    found = [(by_number[n], row) for n, row in zip(numbers, rows, strict=True) if n in by_number]
    agreed = agreement.agreement_of_rows(
        [row for _, row in found],
        [records.numbers_of(item)["angle"] for item, _ in found],
        ["float32"] * len(found),  # Blender's vertices
    )
    turned = sum(records.honour_colours(item, row.colors) for item, row in found)
    if turned:
        measuring.repaint(obj)
        extra += f"; {turned} painted the other way round, as its Colors say"
    return extra + agreed.text, agreed.differing > 0


classes = (VG_OT_export_csv, VG_OT_import_csv)
