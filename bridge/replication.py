"""A CSV's rows re-measured on an object (all recorded, or nothing), and the measurements and
edge profiles written back out as CSV rows: the replication step of the paper's workflow, on
top of the measuring pipeline (``measuring``) and the edge records (``edges``)."""

from __future__ import annotations

from collections import Counter
from pathlib import Path

from ..vg_addon import GoniometerError
from ..vg_addon.errors import bounded_list
from ..vg_addon.formats import csvio
from ..vg_addon.method.algorithm import DEFAULT_RULE
from . import colors, edges, measuring, records
from .mesh_data import check_measurable, evaluated_geometry, names_of, surface_for


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
    rule=DEFAULT_RULE,
    stability=False,
    progress=None,
    edge_notes=None,
    notes_taken=None,
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
    progress : callable, optional
        Called as ``progress(done, total)`` before each row is measured; returning False
        cancels the import (a GoniometerError; nothing is recorded).
    edge_notes : dict, optional
        The edge summary's rows beside the CSV (:func:`edge_notes_beside`): a rebuilt edge whose
        stations agree with its row takes the row's note, any other its first station's.
    notes_taken : list, optional
        Where :func:`replicate_steps` appends the keys of the edges whose note came from
        ``edge_notes`` and differs from their stations'.

    Rows in mesh coordinates (``row.coordinates == "mesh"``: every file but this extension's
    exports from before it measured in mesh coordinates) are measured as they are. Rows in
    world space are brought into mesh coordinates by the object's current transform, the radius
    divided by its scale; that needs a transform that scales every direction alike.

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
    steps = replicate_steps(
        obj,
        rows,
        ignore_mesh_names=ignore_mesh_names,
        radius=radius,
        lam=lam,
        patch=patch,
        depsgraph=depsgraph,
        source=source,
        rule=rule,
        stability=stability,
        edge_notes=edge_notes,
        notes_taken=notes_taken,
    )
    try:
        while True:
            done, total = next(steps)
            if progress is not None and progress(done, total) is False:
                steps.close()
                raise GoniometerError(
                    f"Import of {source} cancelled after {done} of {total} rows: nothing was "
                    "imported."
                )
    except StopIteration as finished:
        return finished.value


def replicate_steps(
    obj,
    rows,
    *,
    ignore_mesh_names=False,
    radius=None,
    lam=2.0,
    patch="euclidean",
    depsgraph=None,
    source="the CSV",
    rule=DEFAULT_RULE,
    stability=False,
    edge_notes=None,
    notes_taken=None,
):
    """:func:`replicate_rows` a row at a time: a generator that yields ``(done, total)`` before
    each row is measured and returns the new measurements' numbers (``StopIteration.value``)
    once all are recorded. Closing it before the end records nothing; so does a mesh that
    changed between steps (a GoniometerError)."""
    check_measurable(obj)
    if not rows:
        raise GoniometerError(f"{source} has no measurement rows: nothing to import.")
    if not ignore_mesh_names:
        csvio.check_mesh_names(rows, names_of(obj), source=source)
    geometry = evaluated_geometry(obj, depsgraph)
    surface = surface_for(obj, geometry)
    measuring.note_winding(obj, surface)
    results, failures = [], []
    for done, row in enumerate(rows):
        yield done, len(rows)
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
            world = row.coordinates == records.WORLD
            m = measuring.replicate_measurement(
                surface,
                geometry.matrix,
                (row.x, row.y, row.z),
                row_radius,
                requested=row.requested,
                world=world,
                scale_radius=row.radius is not None,
                lam=lam if row.lam is None else row.lam,
                patch=row.patch or patch,
                rule=row.rule or rule,
                stability=stability,
            )
            lengths = (row.arc_length or 0.0, row.spacing or 0.0)  # an edge station's
            if world and row.edge_number is not None:
                lengths = edges.mesh_lengths(obj, *lengths)
        except GoniometerError as error:
            failures.append(f"row {row.row_number}: {error}")
            continue
        results.append((row, m, lengths))
    if failures:
        raise GoniometerError(
            f"{len(failures)} of {len(rows)} rows of {source} could not be measured on "
            f"'{obj.name}'; nothing was imported.\n" + bounded_list(failures, lines=True)
        )
    check_measurable(obj)
    if evaluated_geometry(obj, depsgraph).fingerprint != geometry.fingerprint:
        raise GoniometerError(
            f"'{obj.name}' changed while {source} was being measured; nothing was imported."
        )
    with edges.recorded_whole(obj):  # a failure part way records no row
        numbers = []
        stations: dict[tuple[str, int], list] = {}  # by mesh and edge: files may hold several
        settings: dict[tuple[str, int], set] = {}  # each edge's Spacing and Radius cells
        for row, m, (arc_length, spacing) in results:
            station = None
            if row.edge_number is not None:  # numbered and oriented when its edge is rebuilt
                station = (0, arc_length, spacing, True)
            item = measuring.record(
                obj,
                m,
                geometry,
                note=row.label or "",
                break_number=row.break_number,
                station=station,
                paint=False,
            )
            numbers.append(item.number)
            if station is not None:
                key = (row.mesh_name or "", row.edge_number)
                stations.setdefault(key, []).append(
                    (item.number, m, station[1], station[2], row.edge_closed)
                )
                settings.setdefault(key, set()).add((row.spacing, row.radius))
        if stations:
            by_number = {item.number: item for item in obj.vg.measurements}
            notes = _matching_notes(edge_notes or {}, stations, settings)
            edges.edges_from_stations(
                obj,
                {
                    key: [(by_number[entry[0]], *entry[1:]) for entry in group]
                    for key, group in stations.items()
                },
                geometry,
                note_of=notes,
            )
            if notes_taken is not None:
                notes_taken.extend(
                    key
                    for key, note in notes.items()
                    if note != by_number[stations[key][0][0]].note
                )
    records.continue_after_recorded_breaks(obj)
    measuring.repaint(obj, depsgraph=depsgraph, geometry=geometry)
    colors.show_sides_once(obj)
    return numbers


def _matching_notes(edge_notes: dict, stations: dict, settings: dict) -> dict:
    """The notes of :func:`edge_notes_beside` for the rebuilt edges whose summary row is of
    the same edge: as many stations, with the Spacing and Radius its station rows carry (a
    summary left from an earlier export of other edges does not rename them)."""
    return {
        key: note
        for key, (count, spacing, radius, note) in edge_notes.items()
        if key in stations and len(stations[key]) == count and settings[key] == {(spacing, radius)}
    }


def edge_notes_beside(path, rows) -> tuple[dict, str]:
    """The notes of the edges in the edge summary an export wrote beside the measurement CSV
    ``path`` (``NAME_edges.csv``), and that file's name; ``({}, "")`` where its ``rows`` hold no
    edge station, or there is no summary or it cannot be read (the stations' own notes then name
    the edges). An edge's note edited after it was measured is only there: its stations keep the
    note they were measured with.

    Returns
    -------
    dict, str
        ``{(mesh name, edge number): (stations, spacing, radius, note)}`` (the import uses a
        note only for an edge whose stations agree with the row), and the file's name.
    """
    if all(row.edge_number is None for row in rows):
        return {}, ""
    beside = csvio.edges_path_for(Path(path))
    if not csvio.holds_edge_summary(beside):
        return {}, ""
    try:
        rows = csvio.read_edges_csv(beside)
    except (OSError, GoniometerError):
        return {}, ""
    notes = {
        (row.mesh_name or "", row.edge_number): (
            row.n_stations,
            row.spacing,
            row.radius,
            row.user_data,
        )
        for row in rows
        if not row.error
    }
    return notes, beside.name


def read_rows(path, passed_over: list | None = None) -> tuple[list, str]:
    """The replication rows of the CSV at ``path`` and how messages name it; the numbers of a
    batch run's failed rows, skipped, are appended to ``passed_over`` if given."""
    return csvio.read_replication_csv(Path(path), passed_over), f"'{Path(path).name}'"


def import_csv(obj, path, *, depsgraph=None, **options) -> list[int]:
    """Read a measurement CSV (ours, MeshLab's, the earlier add-on's or plain x, y, z points) and
    replicate it on ``obj``; ``options`` as for :func:`replicate_rows`. Rebuilt edges take
    their notes from the edge summary beside it (:func:`edge_notes_beside`)."""
    rows, source = read_rows(path)
    notes, _ = edge_notes_beside(path, rows)
    return replicate_rows(
        obj, rows, depsgraph=depsgraph, source=source, edge_notes=notes, **options
    )


def export_rows(objects, scene, *, depsgraph=None) -> list:
    """CSV rows of every measurement of ``objects`` (stale ones flagged), in list order."""
    return export_tables(objects, scene, depsgraph=depsgraph)[0]


def export_tables(objects, scene, *, depsgraph=None) -> tuple[list, list]:
    """The measurement rows and the edge summary rows of ``objects``, in list order.

    Stale measurements are flagged, and so is an edge with a stale station. Whether a record is
    stale needs the object's current geometry hashed, so it is worked out once per object for
    both tables.
    """
    rows, edge_rows = [], []
    for obj in objects:
        units = records.units_label(scene, obj)
        stale = measuring.stale_numbers(obj, depsgraph=depsgraph)
        closed = records.closed_edges(obj)
        rows.extend(
            records.to_row(
                obj,
                item,
                stale=item.number in stale,
                units=units,
                edge_closed=closed.get(item.edge_number),
            )
            for item in obj.vg.measurements
        )
        stale_edges = {item.edge_number for item in obj.vg.measurements if item.number in stale}
        edge_rows.extend(
            records.edge_row(obj, edge, units=units, stale=edge.number in stale_edges)
            for edge in obj.vg.edges
        )
    return rows, edge_rows


def short_edges(rows, edge_rows) -> list[str]:
    """The edges of ``edge_rows`` (as "'mesh' edge N") with fewer station rows in ``rows``
    than they were measured with: stations deleted since."""
    held = Counter((row.mesh_name, row.edge_number) for row in rows if row.edge_number is not None)
    return [
        f"'{edge.mesh_name}' edge {edge.edge_number}"
        for edge in edge_rows
        if held[edge.mesh_name, edge.edge_number] < (edge.n_stations or 0)
    ]
