"""What the click sessions in the 3D viewport share (the edge profile's and Find Break Edges'):
the viewport's main region and view the clicks are taken in, the overlay, the header and
status-bar texts, and their removal on every way out."""

from __future__ import annotations

import contextlib
import weakref

import bpy
import numpy as np

from ..bridge.mesh_data import check_evaluated, check_measurable, evaluated_geometry
from ..vg_addon import GoniometerError
from .common import clear_texts
from .drag import object_alive, pointer_in_view

# The sessions running now: ended by :func:`end_all` when the extension is disabled, as
# Blender then frees their operators without calling ``cancel``.
_LIVE: weakref.WeakSet = weakref.WeakSet()


def modifiers(event) -> dict:
    """The keyword arguments of an event the sessions' translators read: the modifier keys
    held, and whether it is a held key's repeat."""
    return {"ctrl": event.ctrl, "alt": event.alt, "shift": event.shift, "repeat": event.is_repeat}


def end_all() -> None:
    """End every running session (its drawing, texts and timer), as the extension goes away."""
    for session in list(_LIVE):
        session.finish()


class ViewSession:
    """A modal session of clicks in the 3D viewport of ``context`` on ``obj``.

    Parameters
    ----------
    context : bpy.types.Context
        The operator's, in a 3D viewport.
    obj : bpy.types.Object
        The mesh object the session works on.
    overlay : ViewOverlay
        Its drawing; started by the subclass once it has data, stopped by :meth:`finish`.
    refusal : str
        The sentence raised when the area has no 3D view.

    Raises
    ------
    GoniometerError
        The area is not a 3D viewport with a main region.
    """

    def __init__(self, context, obj, overlay, refusal: str):
        self.obj = obj
        area = context.area
        # Started from the sidebar's button, the context's region is the sidebar: clicks are
        # taken in the area's main (WINDOW) regions, each with its own view (:meth:`view_at`).
        region = next((r for r in area.regions if r.type == "WINDOW"), None)
        if region is None or getattr(area.spaces.active, "region_3d", None) is None:
            raise GoniometerError(refusal)
        self.overlay = overlay
        self._area, self._workspace = area, context.workspace
        self._area_pointer = area.as_pointer()
        self.timer = None  # a window-manager timer the operator runs the session with
        self.fingerprint = None  # the geometry the session's clicks were taken on
        _LIVE.add(self)

    @property
    def area(self):
        """The session's 3D viewport, or None once it is closed (or joined into another):
        Blender frees a closed area, and touching it then may crash Blender."""
        if self._area is None:
            return None
        # Every screen's (another workspace shown keeps its areas: the session waits for it).
        screens = bpy.data.screens
        if any(a.as_pointer() == self._area_pointer for s in screens for a in s.areas):
            return self._area
        return None

    def view_at(self, mouse) -> tuple | None:
        """The view under window-pixel ``mouse``: ``(region, region_3d, region pixel)`` of the
        area's main region it is in (each quadrant of Quad View is one, with its own view), or
        None where the pointer is off the view (another area, or the toolbar, header or
        sidebar drawn over it), or the view is not shown (another workspace) or no longer a 3D
        view (the area switched to another editor)."""
        area, window = self.area, bpy.context.window
        if (
            area is None
            or window is None
            or window.workspace != self._workspace  # another workspace shown
            or area not in list(window.screen.areas)
            or area.type != "VIEW_3D"  # the area made another editor
        ):
            return None
        for region in area.regions:
            if region.type != "WINDOW":
                continue
            coord = (mouse[0] - region.x, mouse[1] - region.y)
            if pointer_in_view(area, region, coord):
                # region.data: the view of this quadrant (unset in a background Blender)
                view = region.data or area.spaces.active.region_3d
                return region, view, coord
        return None

    def absent(self, context) -> str:
        """Why the session's object cannot be clicked on now: it is not in this scene (another
        scene is shown), or it was disabled in the viewports; ``""`` when it can."""
        if not object_alive(context, self.obj):
            return f"'{self.obj.name}' is not in this scene: go back to its scene to go on, or Esc."
        try:
            check_evaluated(self.obj, context.evaluated_depsgraph_get(), "to click on")
        except GoniometerError as error:
            return str(error)
        return ""

    def closed(self) -> str:
        """Why the session must end though the user did not end it (``""`` while it can go
        on): its object was deleted, or its viewport closed."""
        if self.deleted():
            return "The object was deleted: nothing was recorded."
        if self.area is None:
            return "The viewport was closed: nothing was recorded."
        return ""

    def drawn_at(self) -> np.ndarray:
        """The object's ``matrix_world`` now, remembered as the one the overlay draws with."""
        self._drawn_matrix = np.array(self.obj.matrix_world, dtype=np.float64)
        return self._drawn_matrix

    def moved(self) -> bool:
        """Whether the object moved since the overlay was drawn (the Properties editor, a
        driver, playback): the drawing must follow it, as the next click's ray cast does."""
        drawn = getattr(self, "_drawn_matrix", None)
        return drawn is not None and not np.array_equal(
            drawn, np.array(self.obj.matrix_world, dtype=np.float64)
        )

    def deleted(self) -> bool:
        """Whether the session's object is gone from the file."""
        try:
            name = self.obj.name
        except ReferenceError:
            return True
        return bpy.data.objects.get(name) != self.obj

    def unrecordable(self, context) -> str:
        """Why what the session holds cannot be recorded now (``""`` when it can): the object
        is not the active one or not in this scene, cannot be measured (Edit Mode, ...), or its
        mesh changed since the session began. The session goes on, so nothing is lost."""
        reason = self.absent(context) or self.not_active(context)
        if reason:
            return reason
        try:
            check_measurable(self.obj)
            geometry = evaluated_geometry(self.obj, context.evaluated_depsgraph_get())
        except GoniometerError as error:
            return f"{error} Then press Enter again, or Esc."
        if self.fingerprint is not None and geometry.fingerprint != self.fingerprint:
            return (
                f"'{self.obj.name}' changed since this began (an edit, a modifier): what is "
                "shown is on the old mesh; Esc and start again."
            )
        return ""

    def not_active(self, context) -> str:
        """Why the session cannot record now: its object is no longer the active one (a click
        in the Outliner passes through to Blender); ``""`` when it is.

        What is recorded goes to the active object, and so does the redo of the last operation:
        recording clicks taken on one object while another is active would put them on it.
        """
        if context.active_object is self.obj:
            return ""
        return (
            f"The clicks are on '{self.obj.name}', which is no longer the active object: make it "
            "active again to record, or Esc."
        )

    def finish(self) -> None:
        """Remove the drawing, the texts and the timer; safe to call more than once."""
        _LIVE.discard(self)
        timer, self.timer = self.timer, None
        if timer is not None:
            with contextlib.suppress(ReferenceError, RuntimeError, ValueError):
                bpy.context.window_manager.event_timer_remove(timer)
        self.overlay.stop()
        area, self._area = self.area, None
        workspace, self._workspace = self._workspace, None
        clear_texts(area, workspace)
