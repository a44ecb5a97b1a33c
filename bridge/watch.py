"""Keep the geometry caches, stale flags and colours in step with the mesh while the user edits it.

Every depsgraph update of an object's geometry drops its kept geometry
(``mesh_data.invalidate``), except the update our own colour write causes
(``mesh_data.own_write``). After an edit of the mesh or its modifiers of an object that has
measurements, and once the edits pause, the object's measurements are checked against its
geometry; if a stale flag no longer matches, the object is repainted, so the colours never show
sides of a mesh that has changed. Moving, rotating or scaling the object changes no measurement
(they are in mesh coordinates) and triggers nothing. The check runs from a timer, not inside the
depsgraph handler (writing data there would re-trigger it), and not in Edit Mode (leaving Edit
Mode triggers it again). Undo and redo drop every kept geometry. A frame change that moves an
animated mesh (shape keys, armatures, animated modifiers) sends no depsgraph update, only the
frame-change handlers: it is handled as an edit.

The timer writes only what follows from the mesh the user edited (the stale flags and the "VG
Sides" colours), never the viewport shading or the active colour attribute: undoing the edit
brings the mesh back, and the next check brings the flags and colours back with it, so there is
nothing of the timer's own for the user to undo. Its writes join the edit's undo step.

An edge's plot names the unit of its axis, which follows the object's Scan Units, and, where
they are the scene's, its scale and the scene's unit system: after the object is scaled or the
scene's units change, the same timer draws again each plot whose axis names another unit
(``edges.redraw_plots``), so a plot never names a unit its numbers are not in.

On file load (``on_load``) the caches are emptied and measurements recorded in world space by
earlier versions are brought into mesh coordinates (see ``legacy``). Before a save
(``on_save``) the plot images of deleted objects' edges are removed.
"""

from __future__ import annotations

import bpy
from bpy.app.handlers import persistent

from ..vg_addon import GoniometerError
from . import edges, legacy, mesh_data, painting, plots, records
from .measuring import forget_paint, migrate_fingerprints, repaint
from .mesh_data import check_measurable, evaluated_geometry

_DELAY = 0.5  # seconds of quiet after the last edit before checking
_pending: set[str] = set()
_plots_pending: set[str] = set()  # objects with edges whose plots' unit may have changed
_scene_units: dict[int, tuple] = {}  # each scene's unit system and scale, as last seen


def refresh(obj, depsgraph=None) -> bool:
    """Repaint ``obj`` if its stale flags disagree with its current geometry.

    Returns True if it was repainted. Objects that cannot be measured now (Edit Mode, linked,
    emptied) are left as they are. Fingerprints written by earlier versions that match are
    rewritten in the current format.
    """
    if obj is None or obj.type != "MESH" or not len(obj.vg.measurements):
        return False
    try:
        check_measurable(obj)
        geometry = evaluated_geometry(obj, depsgraph)
    except GoniometerError:
        return False
    migrate_fingerprints(obj, geometry)
    if all(
        (item.fingerprint != geometry.fingerprint) == item.stale for item in obj.vg.measurements
    ):
        return False
    repaint(obj, depsgraph=depsgraph, geometry=geometry, verify=True)
    return True


def _check_pending():
    names = sorted(_pending)
    _pending.clear()
    for name in names:
        refresh(bpy.data.objects.get(name))
    names = sorted(_plots_pending)
    _plots_pending.clear()
    for name in names:
        _redraw_plots(bpy.data.objects.get(name))
    return None  # do not repeat


def _redraw_plots(obj) -> None:
    """Draw again the plots of ``obj`` whose axis names another unit than its lengths are in
    now; an object that cannot be changed here (linked, an override) is left as it is."""
    if obj is None or obj.type != "MESH" or not len(obj.vg.edges):
        return
    if not mesh_data.is_changeable(obj):
        return
    try:
        edges.redraw_plots(obj)
    except (RuntimeError, ValueError, MemoryError) as error:  # a plot is not worth a traceback
        print(f"Virtual Goniometer: the plots of '{obj.name}' were not drawn again: {error}")


def _remember_scene_units() -> None:
    """Note every scene's units as they are now (a file loaded, an undo): a change from here
    on is one the plots must follow."""
    _scene_units.clear()
    for scene in bpy.data.scenes:
        settings = scene.unit_settings
        _scene_units[scene.as_pointer()] = (settings.system, settings.scale_length)


def _schedule_check() -> None:
    """Run the check once the edits pause (:data:`_DELAY` after the last call)."""
    if bpy.app.timers.is_registered(_check_pending):
        bpy.app.timers.unregister(_check_pending)
    bpy.app.timers.register(_check_pending, first_interval=_DELAY)


def _note_plot_units(update) -> None:
    """Note the objects whose plots may name another unit after ``update``: one with edges
    transformed (its scale), every one with edges in a scene whose units changed."""
    changed = update.id.original
    if isinstance(changed, bpy.types.Scene):
        settings = changed.unit_settings
        seen = (settings.system, settings.scale_length)
        if _scene_units.setdefault(changed.as_pointer(), seen) != seen:
            _scene_units[changed.as_pointer()] = seen
            _plots_pending.update(
                obj.name for obj in changed.objects if obj.type == "MESH" and len(obj.vg.edges)
            )
    elif (
        update.is_updated_transform
        and isinstance(changed, bpy.types.Object)
        and changed.type == "MESH"
        and len(changed.vg.edges)
    ):
        _plots_pending.add(changed.name)


@persistent
def on_depsgraph_update(scene, depsgraph):
    """Drop the kept geometry of objects whose geometry changed (not a mere move); note the
    measured ones, to check them soon, and those whose plots may name another unit."""
    for update in depsgraph.updates:
        _note_plot_units(update)
        if not update.is_updated_geometry:
            continue
        obj = update.id.original
        if not isinstance(obj, bpy.types.Object) or obj.type != "MESH":
            continue
        if mesh_data.is_own_write(obj):
            continue
        mesh_data.invalidate(obj)
        vg = getattr(obj, "vg", None)
        if vg is not None and len(vg.measurements):
            _pending.add(obj.name)
    if _pending or _plots_pending:
        _schedule_check()


@persistent
def on_undo_or_redo(*_args):
    """Undo and redo may restore any geometry and any records: read them again before
    trusting what was kept. They may also bring back plots drawn before a scale or a unit
    change that the step they return to keeps (the plots were drawn after it was stored): every
    object's plots are checked once the edits pause."""
    mesh_data.invalidate_all()
    painting.new_generation()
    _remember_scene_units()
    _plots_pending.update(
        obj.name for obj in bpy.data.objects if obj.type == "MESH" and len(obj.vg.edges)
    )
    if _plots_pending:
        _schedule_check()


def clear_caches() -> None:
    """Forget every kept geometry, surface, paint state and measurement, and every pending
    check."""
    mesh_data.clear_cache()
    forget_paint()
    _pending.clear()
    _plots_pending.clear()
    _scene_units.clear()
    if bpy.app.timers.is_registered(_check_pending):
        bpy.app.timers.unregister(_check_pending)


@persistent
def on_load(*_args):
    """Another file: forget everything kept for the previous one, and bring world-space
    measurements of earlier versions into mesh coordinates."""
    clear_caches()
    _remember_scene_units()
    for obj in bpy.data.objects:
        if obj.type != "MESH":
            continue
        if legacy.has_world_records(obj):
            migrate(obj)
        if obj.library is None:  # a linked object's data is read-only
            records.update_changed_edges(obj)  # files saved before the flag was kept


@persistent
def on_save(*_args):
    """Before the file is written: drop the plots of edges whose object is gone, so a deleted
    object's plots do not stay packed in the file for good."""
    plots.remove_orphaned_plots()


def migrate(obj) -> list[int]:
    """Bring ``obj``'s world-space records into mesh coordinates where they still match, and
    repaint it if any were; returns their numbers. Objects that cannot be measured now are
    left as they are."""
    try:
        check_measurable(obj)
        geometry = evaluated_geometry(obj)
    except GoniometerError:
        return []
    migrated = legacy.migrate(obj, geometry, mesh_data.surface_for(obj, geometry))
    if migrated:
        repaint(obj, geometry=geometry, verify=True)
    else:
        refresh(obj)  # the flags of records that stay in world space
    return migrated


_HANDLERS = (
    ("depsgraph_update_post", on_depsgraph_update),
    ("frame_change_post", on_depsgraph_update),  # animation: no depsgraph update is sent
    ("undo_post", on_undo_or_redo),
    ("redo_post", on_undo_or_redo),
    ("load_post", on_load),
    ("save_pre", on_save),
)


def register() -> None:
    for name, handler in _HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        if handler not in handlers:
            handlers.append(handler)
    mesh_data.set_watching(True)


def unregister() -> None:
    mesh_data.set_watching(False)
    for name, handler in _HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        if handler in handlers:
            handlers.remove(handler)
    if bpy.app.timers.is_registered(_check_pending):
        bpy.app.timers.unregister(_check_pending)
    _pending.clear()
    _plots_pending.clear()
    _scene_units.clear()
