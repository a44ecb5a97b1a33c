"""``vg.render_map``: the measurement map of the active object (thin: the work is in
``bridge.measurement_map``)."""

from __future__ import annotations

import bpy
from bpy.props import EnumProperty, IntProperty, StringProperty

from ..bridge import measurement_map
from ..properties import BLEND_RELATIVE
from ..vg_addon import GoniometerError
from .measure import poll_measured
from .progress import Progress

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
    bl_options = {"REGISTER"}  # noqa: RUF012 (Blender wants a set)

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
        if self.directory.startswith("//") and not bpy.data.filepath:
            raise GoniometerError(
                "The map folder is relative to the .blend file (//), which is not saved yet: "
                "save the file or choose an absolute folder."
            )
        folder = bpy.path.abspath(self.directory)
        if not folder:
            raise GoniometerError("No folder given: choose where to write the map.")
        return folder

    def _start(self, context):
        return measurement_map.MapJob(
            context.active_object,
            self._folder(),
            views=self.views,
            size=(self.width, self.height),
            samples=self.samples,
        )

    def execute(self, context):
        try:
            self._job = self._start(context)
        except (GoniometerError, OSError) as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        job = self._job
        try:
            with Progress(context, f"Measurement map of '{job.obj.name}'") as progress:
                while not job.done:
                    progress.step(len(job.written), len(job.views))
                    job.render_next()
            job.finish()
        except (GoniometerError, OSError, RuntimeError, ReferenceError) as error:
            return self._stop(context, f"The map failed: {error}")
        return self._done(context)

    def invoke(self, context, event):
        """Render a view per timer step, so Esc can stop the map between views."""
        if context.window is None:
            return self.execute(context)
        try:
            self._job = self._start(context)
        except (GoniometerError, OSError) as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        wm = context.window_manager
        wm.progress_begin(0, len(self._job.views))
        self._timer = wm.event_timer_add(0.05, window=context.window)
        wm.modal_handler_add(self)
        self._show_progress(context)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        if event.type == "ESC":
            return self._stop(context, "The map was cancelled: no picture was kept.", "INFO")
        if event.type != "TIMER" or event.timer is not self._timer:
            return {"RUNNING_MODAL"}
        try:
            self._job.render_next()
            if not self._job.done:
                self._show_progress(context)
                return {"RUNNING_MODAL"}
            self._job.finish()
        except (GoniometerError, OSError, RuntimeError, ReferenceError) as error:
            return self._stop(context, f"The map failed: {error}")
        return self._done(context)

    def cancel(self, context):
        """Blender ends the operator (file load, window closed): keep nothing half-done."""
        self._stop(context, None)

    def _show_progress(self, context) -> None:
        job = self._job
        name = job.views[len(job.written)][0]
        text = f"Measurement map of '{job.obj.name}': {name} ({len(job.written) + 1} of "
        text += f"{len(job.views)}); Esc cancels"
        if context.workspace is not None:
            context.workspace.status_text_set(text)
        if context.window_manager.windows:
            context.window_manager.progress_update(len(job.written))

    def _clear_status(self, context) -> None:
        timer = getattr(self, "_timer", None)
        if timer is not None:
            context.window_manager.event_timer_remove(timer)
            self._timer = None
            context.window_manager.progress_end()
        if context.workspace is not None:
            context.workspace.status_text_set(None)

    def _stop(self, context, message, level="ERROR"):
        job = getattr(self, "_job", None)
        if job is not None:
            job.abort()
            job.close()
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


classes = (VG_OT_render_map,)
