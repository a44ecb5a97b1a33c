"""What the click sessions in the 3D viewport share (the edge profile's and Find Break Edges'):
the viewport's main region and view the clicks are taken in, the overlay, the header and
status-bar texts, and their removal on every way out."""

from __future__ import annotations

from ..vg_addon import GoniometerError
from .common import clear_texts


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
        # taken in the area's main (WINDOW) region, with its view.
        self._region = next((r for r in area.regions if r.type == "WINDOW"), None)
        self._region_data = getattr(area.spaces.active, "region_3d", None)
        if self._region is None or self._region_data is None:
            raise GoniometerError(refusal)
        self.overlay = overlay
        self._area, self._workspace = area, context.workspace

    def region_coord(self, mouse) -> tuple | None:
        """Window-pixel ``mouse`` relative to the viewport's main region, or None if outside."""
        x, y = mouse[0] - self._region.x, mouse[1] - self._region.y
        inside = 0 <= x < self._region.width and 0 <= y < self._region.height
        return (x, y) if inside else None

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
        """Remove the drawing and the texts; safe to call more than once."""
        self.overlay.stop()
        area, self._area = self._area, None
        workspace, self._workspace = self._workspace, None
        clear_texts(area, workspace)
