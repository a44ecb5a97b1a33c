"""``vg.render_map``: the measurement map of the active object (thin: the work is in
``bridge.measurement_map``)."""

from __future__ import annotations

import contextlib
from pathlib import Path

import bpy
from bpy.props import EnumProperty, IntProperty, StringProperty

from ..bridge import measurement_map
from ..properties import BLEND_RELATIVE
from ..vg_addon import GoniometerError
from .common import absolute_path, poll_measured
from .progress import Progress, own_timer_tick

VIEW_ITEMS = (
    ("SIX", "Six Views", "Front, back, right, left, top and bottom, orthographic"),
    ("FLAKE", "Two Faces", "The two faces of a flat piece, seen along its thinnest axis"),
)


class VG_OT_render_map(bpy.types.Operator):
    """Render the active object from chosen views with its coloured sides and numbered labels,
    one PNG per view and a contact sheet, to print and keep beside the CSV (Esc cancels between
    views; a cancelled map keeps no picture)"""

    bl_idname = "vg.render_map"
    bl_label = "Render Measurement Map"
    bl_options = {"REGISTER", "UNDO"}  # noqa: RUF012 (Blender wants a set)

    views: EnumProperty(name="Views", items=VIEW_ITEMS, default="SIX")
    directory: StringProperty(
        name="Folder",
        description="Where the pictures go",
        default="//vg_map",
        subtype="DIR_PATH",
        options=BLEND_RELATIVE,
    )
    width: IntProperty(name="Width", default=800, min=16, max=8192)
    height: IntProperty(name="Height", default=600, min=16, max=8192)
    samples: IntProperty(name="Samples", description="Cycles samples", default=16, min=1, max=4096)

    @classmethod
    def poll(cls, context):
        return poll_measured(cls, context)

    def _folder(self) -> str:
        folder = absolute_path(self.directory)
        if not folder:
            raise GoniometerError("No folder given: choose where to write the map.")
        return folder

    def _start(self, context):
        """Make the map's job (its throwaway scene); remember whether its folder is new, so a
        map that is not completed leaves no empty folder behind."""
        folder = Path(self._folder())
        self._new_folder = None if folder.exists() else folder
        self._workspace = context.workspace
        try:
            self._job = measurement_map.MapJob(
                context.active_object,
                folder,
                views=self.views,
                size=(self.width, self.height),
                samples=self.samples,
            )
        except BaseException:
            self._remove_new_folder()
            raise

    def _refused(self, context, error) -> set:
        """The map could not start (its settings, its folder): say why, keep nothing."""
        self._stop(context, None)
        self.report({"ERROR"}, str(error))
        return {"CANCELLED"}

    def execute(self, context):
        try:
            self._start(context)
        except (GoniometerError, OSError) as error:
            return self._refused(context, error)
        except Exception as error:  # whatever went wrong: keep nothing, say why
            return self._stop(context, failure(error))
        job = self._job
        try:
            with Progress(context, f"Measurement map of '{job.obj.name}'") as progress:
                while not job.done:
                    progress.step(len(job.written), len(job.views))
                    job.render_next()
            job.finish()
        except Exception as error:  # whatever went wrong: keep nothing, say why
            return self._stop(context, failure(error))
        return self._done(context)

    def invoke(self, context, event):
        """Render a view per timer step, so Esc can stop the map between views."""
        if context.window is None:
            return self.execute(context)
        try:
            self._start(context)
        except (GoniometerError, OSError) as error:
            return self._refused(context, error)
        except Exception as error:  # whatever went wrong: keep nothing, say why
            return self._stop(context, failure(error))
        try:
            wm = context.window_manager
            wm.progress_begin(0, len(self._job.views))
            self._progress_begun = True
            self._timer = wm.event_timer_add(0.05, window=context.window)
            wm.modal_handler_add(self)
            self._show_progress(context)
        except Exception as error:  # whatever went wrong: keep nothing, say why
            return self._stop(context, failure(error))
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        """A view per tick of this operator's timer; Esc cancels. On a cancel or any failure the
        pictures written, the folder made for them, the throwaway scene with its objects and
        data, the timer and the status line are all removed, and a report says why (never a
        traceback)."""
        try:
            if event.type == "ESC":
                return self._stop(context, "The map was cancelled: no picture was kept.", "INFO")
            if not own_timer_tick(self, event):
                return {"RUNNING_MODAL"}
            self._job.render_next()
            if not self._job.done:
                self._show_progress(context)
                return {"RUNNING_MODAL"}
            self._job.finish()
        except Exception as error:  # whatever went wrong: keep nothing, say why
            return self._stop(context, failure(error))
        return self._done(context)

    def cancel(self, context):
        """Blender ends the operator (file load, window closed): keep nothing half-done."""
        self._stop(context, None)

    def _show_progress(self, context) -> None:
        job = self._job
        name = job.views[len(job.written)][0]
        text = f"Measurement map of '{job.obj.name}': {name} ({len(job.written) + 1} of "
        text += f"{len(job.views)}); Esc cancels"
        if self._workspace is not None:
            self._workspace.status_text_set(text)
        if context.window_manager.windows:
            context.window_manager.progress_update(len(job.written))

    def _clear_status(self, context) -> None:
        """Remove the timer, the progress cursor and the status line (of the workspace the map
        was started in, whichever is shown now); safe to call more than once."""
        wm = context.window_manager
        timer, self._timer = getattr(self, "_timer", None), None
        if timer is not None:
            with contextlib.suppress(ReferenceError, RuntimeError, ValueError):
                wm.event_timer_remove(timer)
        if getattr(self, "_progress_begun", False):
            self._progress_begun = False
            with contextlib.suppress(ReferenceError, RuntimeError):
                wm.progress_end()
        workspace, self._workspace = getattr(self, "_workspace", None), None
        if workspace is not None:
            with contextlib.suppress(ReferenceError, RuntimeError, AttributeError):
                workspace.status_text_set(None)

    def _remove_new_folder(self) -> None:
        """Remove the folder this map made, if nothing is in it."""
        folder, self._new_folder = getattr(self, "_new_folder", None), None
        if folder is not None:
            with contextlib.suppress(OSError):
                folder.rmdir()

    def _stop(self, context, message, level="ERROR"):
        """End a map that is not completed: no picture, folder, scene, timer or status line of
        it is left; report ``message`` (None: say nothing)."""
        job, self._job = getattr(self, "_job", None), None
        try:
            if job is not None:
                job.abort()
                job.close()
            self._remove_new_folder()
        finally:
            self._clear_status(context)
        if message:
            self.report({level}, message)
        return {"CANCELLED"}

    def _done(self, context):
        job = self._job
        job.close()
        self._clear_status(context)
        self.report(
            {"INFO"},
            f"Measurement map of '{job.obj.name}': {len(job.written)} view(s) and the contact "
            f"sheet {job.sheet}",
        )
        return {"FINISHED"}


def failure(error: BaseException) -> str:
    """The report of a map that failed: the message of an expected error; the type too of an
    unexpected one (a bug to report)."""
    if isinstance(error, (GoniometerError, OSError, RuntimeError, ReferenceError)):
        return f"The map failed: {error}"
    return f"The map failed ({type(error).__name__}: {error}); no picture was kept."


classes = (VG_OT_render_map,)
