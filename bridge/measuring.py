"""The measuring pipeline shared by every way of measuring (operators, batch runs, the drag tool).

``measure_on_object`` validates, measures, records and repaints (``measure`` then ``record``);
``repaint`` redoes the colours from the recorded measurements. Each raises
:class:`GoniometerError` for bad input before changing anything. Re-measuring a CSV and
exporting one is ``replication``.
"""

from __future__ import annotations

import bpy
import numpy as np

from ..vg_addon import GoniometerError, Measurement
from ..vg_addon.formats import record_codec
from ..vg_addon.method.algorithm import DEFAULT_RULE
from ..vg_addon.method.sweep import radius_sweep
from . import colors, legacy, painting, records
from .mesh_data import (
    Geometry,
    check_measurable,
    evaluated_geometry,
    is_evaluated,
    mesh_points,
    own_write,
    surface_for,
    uniform_scale,
)


def _sides_key(obj, geometry: Geometry, item) -> tuple:
    """What a measurement's painted sides depend on: the geometry, its exact inputs and break
    (and the object's own mesh, when modifiers change the vertex count)."""
    mapped = None if len(obj.data.vertices) == geometry.points.shape[0] else obj.data.session_uid
    return (geometry.fingerprint, item.exact, item.patch, item.break_number, mapped)


def _sides(obj, geometry: Geometry, m: Measurement, item) -> painting.Sides:
    vertices, plus = colors.original_sides(obj, geometry, m)
    if not records.plus_on_pair_side(item):  # an edge station, painted edge-wise
        plus = ~plus
    return painting.Sides(
        vertices.astype(np.int32), plus, int(item.break_number), m.center.copy(), float(m.radius)
    )


def keep_sides(obj, geometry: Geometry, item, m: Measurement) -> None:
    """Keep the sides of ``m``, just recorded as ``item``, so that painting it measures
    nothing again."""
    painting.keep(_sides_key(obj, geometry, item), _sides(obj, geometry, m, item))


def _sides_of_item(obj, geometry: Geometry, item, key: tuple) -> painting.Sides:
    sides = painting.kept_sides(key)
    if sides is None:
        # Deterministic: re-measuring at the exact stored inputs gives the sides it had.
        m = surface_for(obj, geometry).measure(**records.replay_args(item))
        sides = _sides(obj, geometry, m, item)
        painting.keep(key, sides)
    return sides


def measure(
    obj,
    location,
    radius,
    lam=2.0,
    patch="euclidean",
    *,
    depsgraph=None,
    rule=DEFAULT_RULE,
    stability=False,
    space="mesh",
):
    """Measure ``obj`` without recording anything: ``(Measurement, Geometry)``.

    The building block for previews (e.g. a drag tool) and for :func:`measure_on_object`;
    the arguments are those of :func:`measure_on_object`.
    """
    check_measurable(obj)
    geometry = evaluated_geometry(obj, depsgraph)
    if space == "world":
        location = mesh_points(location, geometry.matrix)
    elif space != "mesh":
        raise GoniometerError(f"Unknown coordinate space {space!r}: use 'mesh' or 'world'.")
    surface = surface_for(obj, geometry)
    m = surface.measure(location, radius, lam, patch, rule=rule, stability=stability)
    note_winding(obj, surface)
    return m, geometry


def note_winding(obj, surface) -> None:
    """Keep the surface's winding on the object, for the panel to say once if it is inward."""
    if obj.vg.winding != surface.winding:
        obj.vg.winding = surface.winding


def sweep(
    obj,
    location,
    start,
    stop,
    count,
    lam=2.0,
    patch="euclidean",
    *,
    depsgraph=None,
    rule=DEFAULT_RULE,
    space="mesh",
):
    """A radius sweep at ``location`` on ``obj`` (nothing is recorded): ``SweepPoint`` list.

    ``location`` is in mesh coordinates, or world space with ``space="world"``; the radii are
    in mesh units."""
    check_measurable(obj)
    geometry = evaluated_geometry(obj, depsgraph)
    if space == "world":
        location = mesh_points(location, geometry.matrix)
    surface = surface_for(obj, geometry)
    note_winding(obj, surface)
    return radius_sweep(surface, location, start, stop, count, lam, patch, rule)


def measure_on_object(
    obj,
    location,
    radius,
    lam=2.0,
    patch="euclidean",
    *,
    depsgraph=None,
    note="",
    rule=DEFAULT_RULE,
    stability=False,
    space="mesh",
):
    """Measure the active mesh at ``location``, record the measurement and repaint the sides.

    Parameters
    ----------
    obj : bpy.types.Object
        The mesh object; its evaluated mesh (modifiers applied) is measured in its own
        coordinates (object space), so the object's transform changes nothing.
    location : array_like, shape (3,)
        Requested centre, in mesh coordinates (float64 is kept exactly) or, with
        ``space="world"``, in world space (converted by the object's ``matrix_world``); it snaps
        to the nearest vertex within ``radius``.
    radius : float
        Patch radius, in mesh units (the units of the mesh's coordinates, whatever the object's
        scale).
    lam : float
        Segmentation parameter λ (MeshLab's SegParam).
    patch : {"euclidean", "geodesic"}
    depsgraph : bpy.types.Depsgraph, optional
        Default: the context's evaluated depsgraph.
    note : str
        Free text stored with the measurement (the CSV's User Data).
    space : {"mesh", "world"}
        The coordinates ``location`` is given in.
    rule : {"refined", "oriented", "paper"}
        How the measurement is taken (``vg_addon.method.algorithm.RULES``).
    stability : bool
        Also compute and record the stability figure.

    Returns
    -------
    The new ``VG_Measurement`` item on ``obj.vg.measurements`` (now the active one). The first
    measurement of an object also shows the sides in the viewports (``colors.show_sides_once``),
    once per object.

    Raises
    ------
    GoniometerError
        No object, not a mesh, linked data, Edit Mode, an empty mesh, a location farther than
        ``radius`` from the surface, too few vertices, ...; nothing is changed then.
    """
    m, geometry = measure(
        obj,
        location,
        radius,
        lam,
        patch,
        depsgraph=depsgraph,
        rule=rule,
        stability=stability,
        space=space,
    )
    return record(obj, m, geometry, note=note, depsgraph=depsgraph)


def record(
    obj,
    m: Measurement,
    geometry: Geometry,
    *,
    note="",
    break_number=None,
    station=None,
    depsgraph=None,
    paint=True,
):
    """Record ``m``, taken on ``geometry`` (``obj``'s evaluated mesh now), and keep its sides
    for painting: the one step after measuring that every way of measuring goes through (a
    click, the drag tool, a CSV import, an edge profile's stations, a batch row).

    ``note``, ``break_number`` and ``station`` are those of ``records.add_measurement``.
    ``paint``: also repaint the sides now (a click); callers that record many measurements
    repaint once at the end instead (:func:`repaint`).

    Returns the new ``VG_Measurement`` item (now the active one); the first measurement of an
    object painted here also shows the sides in the viewports (``colors.show_sides_once``).
    """
    item = records.add_measurement(
        obj, m, geometry.fingerprint, note=note, break_number=break_number, station=station
    )
    keep_sides(obj, geometry, item, m)
    if paint:
        repaint(obj, depsgraph=depsgraph, geometry=geometry)
        colors.show_sides_once(obj)
    return obj.vg.measurements[obj.vg.active_index]


def record_row(
    obj,
    m: Measurement,
    geometry: Geometry,
    *,
    units: str,
    precision: str = "float32",
    note="",
    break_number=None,
):
    """:func:`record` ``m`` without painting (the caller repaints once at the end) and return
    its CSV row (``records.measurement_row``), made from the numbers just recorded rather than
    read back from the record's text: a batch row.
    """
    item = record(obj, m, geometry, note=note, break_number=break_number, paint=False)
    numbers = record_codec.measurement_numbers(m)
    return records.measurement_row(
        obj, item, numbers, stale=False, units=units, precision=precision
    )


# Per measurement, what changes whenever it is replaced by another one; read for the whole list
# at once (foreach_get) to recognise the measurements already painted without reading them.
_SIGNATURE = ("number", "break_number", "n_vertices", "n_plus", "n_minus", "content_id", "stale")
_STALE = len(_SIGNATURE) - 1
_CONTENT = _SIGNATURE.index("content_id")


def _signatures(items) -> np.ndarray:
    """One row of :data:`_SIGNATURE` values per record, int32 ``(n, 7)``."""
    rows = np.empty((len(_SIGNATURE), len(items)), dtype=np.int32)  # IntProperty's own type
    stale = np.empty(len(items), dtype=bool)
    for row, name in zip(rows[:_STALE], _SIGNATURE[:_STALE], strict=True):
        items.foreach_get(name, row)
    items.foreach_get("stale", stale)
    rows[_STALE] = stale
    return rows.T.copy()


def repaint(
    obj, *, depsgraph=None, geometry: Geometry | None = None, verify: bool = False
) -> list[int]:
    """Update the stale flags and repaint the "VG Sides" colours of ``obj`` from its records.

    Every measurement whose geometry fingerprint still matches the evaluated mesh is painted,
    later measurements over earlier ones, with the sides it has at its exact stored centre,
    radius, λ and patch mode (kept from when it was measured, or measured again once). The
    others are flagged stale and left unpainted. Only what changed since the last painting of
    this object is repainted (see ``painting``). Records from versions that measured in world
    space are first brought into mesh coordinates where they still match (see ``legacy``). The
    viewports' shading is left as the user set it.

    Parameters
    ----------
    verify : bool
        Read every record again, instead of recognising the ones painted last time (on the
        same geometry, with no undo or file load since) by their number, break and vertex
        counts. For records changed by other means than this module's functions.

    Returns
    -------
    list of int
        The numbers of the stale measurements.
    """
    check_measurable(obj)
    if geometry is None:
        geometry = evaluated_geometry(obj, depsgraph)
    mesh = obj.data
    n = len(mesh.vertices)
    items = obj.vg.measurements
    state = painting.state_for(obj)
    usable = (
        state is not None
        and state.fingerprint == geometry.fingerprint
        and state.colours.shape[0] == n
        and colors.has_attribute(mesh)
    )
    trusted = usable and not verify and state.generation == painting.generation()
    rows = _signatures(items)
    keys, stale, start = [], [], 0
    known = state.known if usable and not verify else {}
    if trusted:
        before = state.rows.shape[0]
        if before <= rows.shape[0] and np.array_equal(state.rows, rows[:before]):
            # Records only added since (the usual click): the earlier ones are as painted.
            keys, stale, start = list(state.painted), list(state.stale), before
    elif known:
        # After an undo or redo, a record is recognised only by its content id (the same
        # exact numbers, patch mode and fingerprint); unstamped ones are read again.
        known = {signature: entry for signature, entry in known.items() if signature[_CONTENT]}
    if not trusted and legacy.has_world_records(obj, rows, known):
        # Only a file load or an undo brings world-space records, and neither is trusted.
        legacy.migrate(obj, geometry, surface_for(obj, geometry))
        rows = _signatures(items)
    # The records as painted now: the ones kept unread join the map they were recognised by.
    remembered, sides = (known if start else {}), {}
    for position in range(start, rows.shape[0]):
        signature = tuple(rows[position].tolist())
        entry = known.get(signature)
        if entry is None:
            item = items[position]
            is_stale, key = not geometry.matches(item.fingerprint), None
            if not is_stale:
                key = _sides_key(obj, geometry, item)
                try:
                    sides[key] = _sides_of_item(obj, geometry, item, key)
                except GoniometerError:
                    is_stale, key = True, None
            if item.stale != is_stale:
                item.stale = is_stale
            content = records.content_id(item)
            if signature[_CONTENT] != content:  # an older version's record, or a script's edit
                item.content_id = content
            rows[position, _CONTENT], rows[position, _STALE] = content, is_stale
            signature = (*signature[:_CONTENT], content, int(is_stale))
            entry = (key, sides.get(key))
        remembered[signature] = entry
        key, kept = entry
        if key is None:
            stale.append(signature[0])
        else:
            keys.append(key)
            sides[key] = kept
    if not usable or not state.update_to(keys, sides.__getitem__):
        state = painting.PaintState.blank(geometry.fingerprint, n)
        for key in keys:
            state.add(key, sides[key])
        painting.set_state(obj, state)
    state.known, state.generation = remembered, painting.generation()
    state.rows, state.stale = rows, stale
    if start == 0 or rows[start:, _STALE].any():  # records only added, all fresh: no edge changed
        records.update_changed_edges(obj)
    with own_write(mesh, depsgraph):
        colors.write_attribute(mesh, state.colours)
    return list(stale)


def migrate_fingerprints(obj, geometry: Geometry) -> int:
    """Rewrite in the current format the fingerprints of ``obj``'s measurements that an earlier
    version wrote and that match ``geometry``; returns how many. Ones that do not match are
    left as they are (their measurements are stale either way)."""
    migrated = 0
    for item in obj.vg.measurements:
        if item.fingerprint != geometry.fingerprint and geometry.matches(item.fingerprint):
            item.fingerprint = geometry.fingerprint
            records.stamp(item)
            migrated += 1
    return migrated


def stale_numbers(obj, *, depsgraph=None) -> set[int]:
    """Numbers of ``obj``'s measurements taken on other geometry than its current evaluated mesh
    (computed, not read from the flags; nothing is changed)."""
    if not len(obj.vg.measurements):
        return set()
    graph = depsgraph or bpy.context.evaluated_depsgraph_get()
    if not is_evaluated(obj, graph):
        # Disabled in the viewports: its mesh as the user sees it cannot be read, so the flags
        # set when it was last evaluated stand (not every record stale).
        return {item.number for item in obj.vg.measurements if item.stale}
    try:
        current = evaluated_geometry(obj, graph)
    except GoniometerError:  # e.g. every vertex deleted since
        current = None
    return {
        item.number
        for item in obj.vg.measurements
        if current is None or not current.matches(item.fingerprint)
    }


def from_world(location, radius, matrix, *, scale_radius=True):
    """A world-space centre and radius in mesh coordinates: ``(location, radius)``.

    The radius is divided by the object's scale (when ``scale_radius``; a default radius given
    in mesh units is kept, and then any invertible transform will do).

    Raises
    ------
    GoniometerError
        The object's scale is not uniform: a world-space radius has no single length on the
        mesh.
    """
    scale = uniform_scale(matrix)
    scaled = scale_radius and radius is not None
    if scaled and scale is None:
        raise GoniometerError(
            "its coordinates are in world space and the object's scale is not uniform, so its "
            "radius has no single length on the mesh: re-export the CSV in mesh coordinates, or "
            "set a uniform scale"
        )
    location = mesh_points(np.asarray(location, dtype=np.float64), matrix)
    return location, (radius / scale if scaled else radius)


def replicate_measurement(
    surface,
    matrix,
    center,
    radius,
    *,
    requested=None,
    world=False,
    scale_radius=True,
    lam,
    patch,
    rule,
    stability=False,
) -> Measurement:
    """A stored measurement taken again on ``surface``: at its stored ``center`` (world space
    where ``world``, mapped by ``matrix`` as :func:`from_world` does), recorded as asked for at
    ``requested`` (where the click was, or ``None`` for the centre itself) with the snap's own
    distance. Shared by Blender's import and the batch's replication.

    Raises
    ------
    GoniometerError
        Why it cannot be taken (the message of :func:`from_world` or ``Surface.measure``).
    """
    if world:
        center, radius = from_world(center, radius, matrix, scale_radius=scale_radius)
        if requested is not None:
            requested = mesh_points(np.asarray(requested, np.float64), matrix)
    m = surface.measure(center, radius, lam, patch, rule=rule, stability=stability)
    # measured at the stored centre, asked for where it was
    return m if requested is None else m.with_requested(requested)


def forget_paint() -> None:
    """Forget what was painted and the kept sides (file load, unregister)."""
    painting.forget()


def clear_cache() -> None:
    """Forget the kept sides and paint states (called on unregister)."""
    painting.forget()
