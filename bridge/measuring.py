"""The measuring pipeline shared by every way of measuring (operators, batch runs, the drag tool).

``measure_on_object`` validates, measures, records and repaints; ``repaint`` redoes the colours
from the recorded measurements; ``replicate_rows`` re-measures a CSV's rows, all or nothing. Each
raises :class:`GoniometerError` for bad input before changing anything.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..vg_addon import GoniometerError, Measurement
from ..vg_addon.errors import bounded_list
from ..vg_addon.formats import csvio
from ..vg_addon.method.sweep import radius_sweep
from . import colors, painting, records
from .mesh_data import Geometry, check_measurable, evaluated_geometry, own_write, surface_for


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
    rule="oriented",
    stability=False,
):
    """Measure ``obj`` without recording anything: ``(Measurement, Geometry)``.

    The building block for previews (e.g. a drag tool) and for :func:`measure_on_object`.
    """
    check_measurable(obj)
    geometry = evaluated_geometry(obj, depsgraph)
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
    rule="oriented",
):
    """A radius sweep at ``location`` on ``obj`` (nothing is recorded): ``SweepPoint`` list."""
    check_measurable(obj)
    geometry = evaluated_geometry(obj, depsgraph)
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
    rule="oriented",
    stability=False,
):
    """Measure the active mesh at ``location``, record the measurement and repaint the sides.

    Parameters
    ----------
    obj : bpy.types.Object
        The mesh object; its evaluated mesh (modifiers applied) is measured in world space.
    location : array_like, shape (3,)
        Requested centre, world space, scene units (float64 is kept exactly); it snaps to the
        nearest vertex within ``radius``.
    radius : float
        Patch radius, world space, scene units.
    lam : float
        Segmentation parameter λ (MeshLab's SegParam).
    patch : {"euclidean", "geodesic"}
    depsgraph : bpy.types.Depsgraph, optional
        Default: the context's evaluated depsgraph.
    note : str
        Free text stored with the measurement (the CSV's User Data).
    rule : {"oriented", "paper"}
        How the projection is signed (``vg_addon.method.algorithm.RULES``).
    stability : bool
        Also compute and record the stability figure.

    Returns
    -------
    The new ``VG_Measurement`` item on ``obj.vg.measurements`` (now the active one).

    Raises
    ------
    GoniometerError
        No object, not a mesh, linked data, Edit Mode, an empty mesh, a location farther than
        ``radius`` from the surface, too few vertices, ...; nothing is changed then.
    """
    m, geometry = measure(
        obj, location, radius, lam, patch, depsgraph=depsgraph, rule=rule, stability=stability
    )
    item = records.add_measurement(obj, m, geometry.fingerprint, note=note)
    keep_sides(obj, geometry, item, m)
    repaint(obj, depsgraph=depsgraph, geometry=geometry)
    return obj.vg.measurements[obj.vg.active_index]


# Per measurement, what changes whenever it is replaced by another one; read for the whole list
# at once (foreach_get) to recognise the measurements already painted without reading them.
_SIGNATURE = ("number", "break_number", "n_vertices", "n_plus", "n_minus")


def _signatures(items) -> list[tuple]:
    columns = []
    for name in _SIGNATURE:
        values = np.empty(len(items), dtype=np.int64)
        items.foreach_get(name, values)
        columns.append(values.tolist())
    stale = np.empty(len(items), dtype=bool)
    items.foreach_get("stale", stale)
    columns.append(stale.tolist())
    return list(zip(*columns, strict=True))


def repaint(
    obj, *, depsgraph=None, geometry: Geometry | None = None, verify: bool = False
) -> list[int]:
    """Update the stale flags and repaint the "VG Sides" colours of ``obj`` from its records.

    Every measurement whose geometry fingerprint still matches the evaluated mesh is painted,
    later measurements over earlier ones, with the sides it has at its exact stored centre,
    radius, λ and patch mode (kept from when it was measured, or measured again once). The
    others are flagged stale and left unpainted. Only what changed since the last painting of
    this object is repainted (see ``painting``).

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
    known = state.known if trusted else {}
    keys, sides, stale, remembered = [], {}, [], {}
    for position, signature in enumerate(_signatures(items)):
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
            signature = (*signature[:-1], is_stale)
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
    with own_write(mesh, depsgraph):
        colors.write_attribute(mesh, state.colours)
    colors.show_in_viewports()
    return stale


def migrate_fingerprints(obj, geometry: Geometry) -> int:
    """Rewrite in the current format the fingerprints of ``obj``'s measurements that an earlier
    version wrote and that match ``geometry``; returns how many. Ones that do not match are
    left as they are (their measurements are stale either way)."""
    migrated = 0
    for item in obj.vg.measurements:
        if item.fingerprint != geometry.fingerprint and geometry.matches(item.fingerprint):
            item.fingerprint = geometry.fingerprint
            migrated += 1
    return migrated


def stale_numbers(obj, *, depsgraph=None) -> set[int]:
    """Numbers of ``obj``'s measurements taken on other geometry than its current evaluated mesh
    (computed, not read from the flags; nothing is changed)."""
    if not len(obj.vg.measurements):
        return set()
    try:
        current = evaluated_geometry(obj, depsgraph)
    except GoniometerError:  # e.g. every vertex deleted since
        current = None
    return {
        item.number
        for item in obj.vg.measurements
        if current is None or not current.matches(item.fingerprint)
    }


def replicate_rows(
    obj,
    rows,
    *,
    ignore_mesh_names=False,
    radius=None,
    lam=2.0,
    patch="euclidean",
    depsgraph=None,
    source="the CSV",
    rule="oriented",
    stability=False,
):
    """Re-measure every replication row on ``obj`` and record them all, or nothing.

    Parameters
    ----------
    rows : list of csvio.ReplicationRow
    ignore_mesh_names : bool
        Accept rows whose mesh name is neither this object's nor its mesh's.
    radius, lam, patch, rule
        Used for rows that do not give their own (a plain points CSV); a row without a radius
        is an error when ``radius`` is None. Rows of MeshLab and earlier add-on files carry the
        paper's rule (see ``csvio.ReplicationRow.rule``).
    stability : bool
        Also compute and record each measurement's stability figure.
    source : str
        How to name the rows' origin in messages (e.g. the file name).

    Each new measurement keeps the row's break number when it has one (else the object's
    current break) and takes the row's label or User Data as its note. Rows that are stations
    of an edge profile (an ``Edge #``) are grouped back into one edge per edge number, with a
    new edge record whose summary is recomputed from the re-measured stations.

    Returns
    -------
    list of int
        Numbers of the new measurements.

    Raises
    ------
    GoniometerError
        Listing every row that names another mesh or cannot be measured; nothing is recorded.
    """
    check_measurable(obj)
    if not rows:
        raise GoniometerError(f"{source} has no measurement rows: nothing to import.")
    if not ignore_mesh_names:
        csvio.check_mesh_names(rows, (obj.name, obj.data.name), source=source)
    geometry = evaluated_geometry(obj, depsgraph)
    surface = surface_for(obj, geometry)
    note_winding(obj, surface)
    results, failures = [], []
    for row in rows:
        try:
            row_radius = radius if row.radius is None else row.radius
            if row.break_number is not None and not (
                1 <= row.break_number <= csvio.MAX_BREAK_NUMBER
            ):
                raise GoniometerError(
                    f"Break # {row.break_number} is not from 1 to {csvio.MAX_BREAK_NUMBER}"
                )
            if row_radius is None:
                raise GoniometerError("no radius (the CSV has no Radius for this row)")
            m = surface.measure(
                (row.x, row.y, row.z),
                row_radius,
                lam if row.lam is None else row.lam,
                row.patch or patch,
                rule=row.rule or rule,
                stability=stability,
            )
        except GoniometerError as error:
            failures.append(f"row {row.row_number}: {error}")
            continue
        results.append((row, m))
    if failures:
        raise GoniometerError(
            f"{len(failures)} of {len(rows)} rows of {source} could not be measured on "
            f"'{obj.name}'; nothing was imported.\n" + bounded_list(failures, lines=True)
        )
    numbers = []
    stations: dict[int, list] = {}
    for row, m in results:
        station = None
        if row.edge_number is not None:  # numbered and oriented when its edge is rebuilt
            station = (0, row.arc_length or 0.0, row.spacing or 0.0, True)
        item = records.add_measurement(
            obj,
            m,
            geometry.fingerprint,
            note=row.label or "",
            break_number=row.break_number,
            station=station,
        )
        keep_sides(obj, geometry, item, m)
        numbers.append(item.number)
        if station is not None:
            stations.setdefault(row.edge_number, []).append(
                (item.number, m, station[1], station[2])
            )
    if stations:
        from . import edges  # edges records through this module: imported when needed

        by_number = {item.number: item for item in obj.vg.measurements}
        edges.edges_from_stations(
            obj,
            {
                key: [(by_number[entry[0]], *entry[1:]) for entry in group]
                for key, group in stations.items()
            },
            geometry,
        )
    records.continue_after_recorded_breaks(obj)
    repaint(obj, depsgraph=depsgraph, geometry=geometry)
    return numbers


def import_csv(obj, path, *, depsgraph=None, **options) -> list[int]:
    """Read a measurement CSV (ours, MeshLab's, the earlier add-on's or plain x, y, z points) and
    replicate it on ``obj``; ``options`` as for :func:`replicate_rows`."""
    rows = csvio.read_replication_csv(Path(path))
    return replicate_rows(obj, rows, depsgraph=depsgraph, source=f"'{Path(path).name}'", **options)


def export_rows(objects, scene, *, depsgraph=None) -> list:
    """CSV rows of every measurement of ``objects`` (stale ones flagged), in list order."""
    units = records.units_label(scene)
    rows = []
    for obj in objects:
        stale = stale_numbers(obj, depsgraph=depsgraph)
        rows.extend(
            records.to_row(obj, item, stale=item.number in stale, units=units)
            for item in obj.vg.measurements
        )
    return rows


def forget_paint() -> None:
    """Forget what was painted and the kept sides (file load, unregister)."""
    painting.forget()


def export_edge_rows(objects, scene) -> list:
    """Edge summary CSV rows of every edge profile of ``objects``, in list order."""
    units = records.units_label(scene)
    return [records.edge_row(obj, edge, units=units) for obj in objects for edge in obj.vg.edges]


def clear_cache() -> None:
    """Forget the kept sides and paint states (called on unregister)."""
    painting.forget()
