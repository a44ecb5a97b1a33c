"""Keep stale flags and colours in step with the mesh while the user edits it.

After an edit (or a move) of an object that has measurements, and once the edits pause, the
object's measurements are checked against its geometry; if a stale flag no longer matches, the
object is repainted, so the colours never show sides of a mesh that has changed. The check runs
from a timer, not inside the depsgraph handler (writing data there would re-trigger it), and not
in Edit Mode (leaving Edit Mode triggers it again).
"""

from __future__ import annotations

import bpy
from bpy.app.handlers import persistent

from ..vg_addon import GoniometerError
from .measuring import repaint
from .mesh_data import check_measurable, evaluated_geometry

_DELAY = 0.5  # seconds of quiet after the last edit before checking
_pending: set[str] = set()


def refresh(obj, depsgraph=None) -> bool:
    """Repaint ``obj`` if its stale flags disagree with its current geometry.

    Returns True if it was repainted. Objects that cannot be measured now (Edit Mode, linked,
    emptied) are left as they are.
    """
    if obj is None or obj.type != "MESH" or not len(obj.vg.measurements):
        return False
    try:
        check_measurable(obj)
        geometry = evaluated_geometry(obj, depsgraph)
    except GoniometerError:
        return False
    if all(
        (item.fingerprint != geometry.fingerprint) == item.stale for item in obj.vg.measurements
    ):
        return False
    repaint(obj, depsgraph=depsgraph, geometry=geometry)
    return True


def _check_pending():
    names = sorted(_pending)
    _pending.clear()
    for name in names:
        refresh(bpy.data.objects.get(name))
    return None  # do not repeat


@persistent
def on_depsgraph_update(scene, depsgraph):
    """Note the measured objects whose geometry or transform changed; check them soon."""
    for update in depsgraph.updates:
        if not (update.is_updated_geometry or update.is_updated_transform):
            continue
        obj = update.id.original
        if isinstance(obj, bpy.types.Object) and obj.type == "MESH":
            vg = getattr(obj, "vg", None)
            if vg is not None and len(vg.measurements):
                _pending.add(obj.name)
    if _pending:
        if bpy.app.timers.is_registered(_check_pending):
            bpy.app.timers.unregister(_check_pending)
        bpy.app.timers.register(_check_pending, first_interval=_DELAY)


def register() -> None:
    if on_depsgraph_update not in bpy.app.handlers.depsgraph_update_post:
        bpy.app.handlers.depsgraph_update_post.append(on_depsgraph_update)


def unregister() -> None:
    if on_depsgraph_update in bpy.app.handlers.depsgraph_update_post:
        bpy.app.handlers.depsgraph_update_post.remove(on_depsgraph_update)
    if bpy.app.timers.is_registered(_check_pending):
        bpy.app.timers.unregister(_check_pending)
    _pending.clear()
