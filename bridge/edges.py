"""Edge profiles on Blender objects: measure a whole edge, record its stations as one break,
keep its summary and plot, rebuild an edge from re-measured stations, delete one.

Each raises :class:`GoniometerError` for bad input before changing anything.
"""

from __future__ import annotations

import contextlib
import math
from pathlib import Path

import bpy
import numpy as np

from ..vg_addon import GoniometerError
from ..vg_addon.errors import bounded_list
from ..vg_addon.formats import csvio, record_codec
from ..vg_addon.formats.record_codec import exact_numbers
from ..vg_addon.method.algorithm import DEFAULT_RULE
from ..vg_addon.method.edge_profile import summarize
from ..vg_addon.method.given_points import check_given_points
from . import measuring, records
from .mesh_data import (
    NotEvaluatedError,
    check_measurable,
    evaluated_geometry,
    mesh_points,
    names_of,
    surface_for,
    uniform_scale,
)
from .plots import UNIT_KEY, make_plot, plot_image, remove_plots


def free_break(obj) -> int:
    """The object's current break number if no measurement uses it yet, else the next unused."""
    # Read at once (foreach_get): a batch recording hundreds of edges would otherwise read every
    # stored measurement's break again for each new edge.
    measurements = obj.vg.measurements
    breaks = np.zeros(len(measurements), dtype=np.int32)
    measurements.foreach_get("break_number", breaks)
    used = set(breaks.tolist())
    number = obj.vg.break_number
    while number in used:
        number += 1
    if number > csvio.MAX_BREAK_NUMBER:
        raise GoniometerError(
            f"'{obj.name}' has no Break # left for a new edge: its breaks reach "
            f"{csvio.MAX_BREAK_NUMBER}, the largest Blender can hold (an imported Break #). "
            "Nothing was recorded."
        )
    return number


def measure_edge(
    obj,
    points,
    spacing,
    radius,
    lam=2.0,
    patch="euclidean",
    *,
    depsgraph=None,
    space="mesh",
    surface=None,
    given="",
    rule=DEFAULT_RULE,
    stability=False,
):
    """Trace and measure the edge through ``points`` on ``obj`` without recording anything:
    ``(EdgeProfile, Geometry, points)``, the last the points in mesh coordinates.

    ``points`` are in mesh coordinates, or world space with ``space="world"`` (converted by the
    object's ``matrix_world``); ``spacing`` and ``radius`` are in mesh units either way, like
    ``measuring.measure_on_object``'s radius. ``surface``: the ``Surface`` to measure on instead
    of the object's cached one (the batch's float64 file coordinates, with the same vertices).
    A spacing that would make more than ``edge_profile.MAX_STATIONS`` stations is refused
    before anything is allocated for them. ``given``: where points read from a file came from
    (a file or edge name); if set, points far from the mesh are refused naming it
    (``edge_profile.check_given_points``) instead of snapping to the nearest vertex. ``rule``
    and ``stability``: how every station is measured (as for ``Surface.measure``).
    """
    check_measurable(obj)
    points = np.asarray(points, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] != 3 or points.shape[0] < 2:
        raise GoniometerError(
            "An edge needs at least two points (start and end, optionally via points between), "
            "each x, y, z."
        )
    if space not in ("mesh", "world"):
        raise GoniometerError(f"Unknown coordinate space {space!r}: use 'mesh' or 'world'.")
    geometry = evaluated_geometry(obj, depsgraph)
    if space == "world":
        points = mesh_points(points, geometry.matrix)
    if surface is None:
        surface = surface_for(obj, geometry)
    if given:
        check_given_points(surface, points, radius, given)
    profile = surface.measure_along(points, spacing, radius, lam, patch, rule, stability)
    return profile, geometry, points


def measure_edge_on_object(
    obj,
    points,
    spacing,
    radius,
    lam=2.0,
    patch="euclidean",
    *,
    depsgraph=None,
    note="",
    space="mesh",
    surface=None,
    rule=DEFAULT_RULE,
    stability=False,
    given="",
):
    """Measure the edge through ``points`` and record every station as a measurement of one new
    break (its own colour pair), plus the edge's record with its summary and plot.

    Parameters
    ----------
    obj : bpy.types.Object
    points : array_like, shape (k, 3)
        Start, via points and end, in mesh coordinates (float64 is kept exactly); each snaps
        to the nearest vertex and the path is traced along the ridge between them.
    spacing, radius, lam, patch
        Station spacing (arc length) and the measuring settings of every station, lengths in
        mesh units. Every station replays with ``vg.measure_xyz(..., space="MESH")`` at its
        stored centre, radius, λ, patch mode and rule.
    note : str
        Free text stored with the edge and each station.
    space : {"mesh", "world"}
        The coordinates ``points`` are given in; the edge records them in mesh coordinates.
    surface : Surface, optional
        Measure on this surface instead of the object's (see :func:`measure_edge`).
    rule : {"refined", "oriented", "paper"}
        The rule every station is measured with (default ``"refined"``).
    stability : bool
        Also compute every station's stability figure.
    given : str
        Where the points came from, if not clicked on the surface: points far from the mesh
        are then refused naming it (see :func:`measure_edge`).

    Returns
    -------
    The new ``VG_EdgeProfile`` item (now the active edge).

    Raises
    ------
    GoniometerError
        Anything that stops the edge being traced or any station being measured; nothing is
        recorded then.
    """
    profile, geometry, clicks = measure_edge(
        obj,
        points,
        spacing,
        radius,
        lam,
        patch,
        depsgraph=depsgraph,
        space=space,
        surface=surface,
        rule=rule,
        stability=stability,
        given=given,
    )
    (edge,) = record_profiles(obj, [(clicks, profile)], geometry, note)
    return edge


def record_profile(obj, profile, geometry, clicks, *, note="", plot=True):
    """Record a measured ``profile`` on ``obj``: every station as a measurement of one new
    break, and the edge's record with its summary and plot; the colours are not repainted
    (``measuring.repaint`` once after several edges).

    Parameters
    ----------
    profile : EdgeProfile
        Measured on ``geometry``'s surface from ``clicks``
        (``Surface.measure_along(clicks, ...)``), so the edge replays from its record.
    geometry : Geometry
        The object's evaluated geometry (``evaluated_geometry``).
    clicks : ndarray, shape (k, 3)
        The start, via points and end the profile was traced through, in mesh coordinates.
    note : str
        Free text stored with the edge and each station.
    plot : bool
        Also draw the edge's plot as a packed image (:func:`make_plot`); a batch run whose
        object is never saved skips it (it writes its own plot files).

    Returns
    -------
    The new ``VG_EdgeProfile`` item (now the active edge).
    """
    break_number = free_break(obj)
    edge_number = obj.vg.next_edge_number
    sides = profile.figures.plus_left
    for m, arc, left in zip(profile.stations, profile.arc_lengths, sides, strict=True):
        measuring.record(
            obj,
            m,
            geometry,
            note=note,
            break_number=break_number,
            station=(edge_number, arc, profile.spacing, left),
            paint=False,
        )
    edge = records.add_edge(
        obj, profile, clicks, geometry.fingerprint, break_number=break_number, note=note
    )
    # the next measurement starts a new break (none follows the largest: free_break says so)
    obj.vg.break_number = min(break_number + 1, csvio.MAX_BREAK_NUMBER)
    if plot:
        edge.plot = make_plot(obj, edge).name
    return edge


def record_profiles(obj, measured, geometry, notes) -> list:
    """Record measured edges on ``obj``, all of them or none, and repaint once.

    Parameters
    ----------
    measured : list of (clicks, EdgeProfile)
        Each edge's start, via points and end in mesh coordinates, and its profile measured on
        ``geometry``'s surface through them (see :func:`record_profile`).
    geometry : Geometry
    notes : str or list of str
        One text for every edge, or one per edge.

    Returns
    -------
    list
        The new ``VG_EdgeProfile`` items.

    Raises
    ------
    GoniometerError
        An edge that cannot be recorded (no break number left); nothing is recorded then.
    """
    notes = [notes] * len(measured) if isinstance(notes, str) else list(notes)
    with recorded_whole(obj):
        numbers = [
            record_profile(obj, profile, geometry, clicks, note=note).number
            for (clicks, profile), note in zip(measured, notes, strict=True)
        ]
    measuring.repaint(obj, geometry=geometry)
    by_number = {edge.number: edge for edge in obj.vg.edges}
    return [by_number[number] for number in numbers]


@contextlib.contextmanager
def recorded_whole(obj):
    """Record on ``obj`` inside this block as one: where the block raises, every measurement,
    edge and plot it added is removed and the object's counters are put back before the error
    goes on."""
    data = obj.vg
    measurements, edge_count = len(data.measurements), len(data.edges)
    counters = ("break_number", "next_number", "next_edge_number")
    kept = {name: getattr(data, name) for name in counters}
    active = (data.active_index, data.active_edge_index)
    try:
        yield
    except BaseException:
        # The records first (nothing here can fail); the new edges' plot images last, as
        # finding them looks at every image.
        images = []
        with contextlib.suppress(Exception):
            images = [plot_image(data.edges[i]) for i in range(edge_count, len(data.edges))]
        for position in reversed(range(edge_count, len(data.edges))):
            data.edges.remove(position)
        for position in reversed(range(measurements, len(data.measurements))):
            data.measurements.remove(position)
        for name, value in kept.items():
            setattr(data, name, value)
        data.active_index, data.active_edge_index = active
        for image in images:
            with contextlib.suppress(Exception):
                if image is not None:
                    bpy.data.images.remove(image)
        raise


def import_edges_csv(
    obj,
    path,
    *,
    ignore_mesh_names=False,
    lam=2.0,
    patch="euclidean",
    depsgraph=None,
    rule=DEFAULT_RULE,
    stability=False,
):
    """Re-measure every edge of an edge summary file on ``obj``: all of them, or none.

    Each row's ``Points`` are traced again and measured with its ``Spacing``, ``Radius``,
    ``SegParam`` and ``Patch Mode`` (``lam`` and ``patch`` for blank cells), and recorded like
    an edge measured here, with the row's User Data as its note. Every station is measured with
    the row's ``Rule`` (``rule``, the panel's, where the file is of a version without that
    column), and with its stability figure if ``stability``.

    Returns
    -------
    list of int
        The new edges' numbers.

    Rows whose ``error`` is filled (edges the batch run that wrote the file could not measure)
    are passed over.

    Raises
    ------
    GoniometerError
        Listing every row that names another mesh or cannot be measured; nothing is recorded.
    """
    check_measurable(obj)
    rows = csvio.read_edges_csv(path)
    source = f"'{Path(path).name}'"
    if not rows:
        raise GoniometerError(f"{source} has no edges: nothing to import.")
    if all(row.error for row in rows):
        raise GoniometerError(
            f"{source} has no measured edges: the run that wrote it could not measure any of its "
            f"{len(rows)} edge(s) (their error column says why); clear a row's error to try it."
        )
    names = names_of(obj)
    failures, measured, notes = [], [], []
    for row in rows:
        number = row.row_number
        if row.error:
            continue  # an edge the run that wrote the file could not measure: nothing to repeat
        try:
            if not ignore_mesh_names and not csvio.mesh_name_matches(row.mesh_name, names):
                raise GoniometerError(
                    f"it names the mesh {row.mesh_name!r}, not '{obj.name}' (tick Ignore Names "
                    "to measure it here)"
                )
            if row.spacing is None or row.radius is None:
                raise GoniometerError("it has no Spacing or no Radius")
            points = csvio.parse_points(row.points)
            spacing, radius = row.spacing, row.radius
            if row.coordinates == csvio.WORLD_COORDINATES:  # a file of an earlier version
                spacing, radius = mesh_lengths(obj, spacing, radius)
                points = mesh_points(points, np.array(obj.matrix_world, dtype=np.float64))
            settings = (
                spacing,
                radius,
                lam if row.lam is None else row.lam,
                row.patch or patch,
            )
            # A row without a Rule (a file of an earlier version) takes the panel's. Every edge
            # is measured before anything is recorded: points picked on another mesh are refused.
            profile, geometry, clicks = measure_edge(
                obj,
                points,
                *settings,
                depsgraph=depsgraph,
                rule=row.rule.strip().lower() or rule,
                stability=stability,
                given=source,
            )
        except GoniometerError as error:
            failures.append(f"row {number}: {error}")
            continue
        measured.append((clicks, profile))
        notes.append(row.user_data)
    if failures:
        raise GoniometerError(
            f"{len(failures)} of {len(rows)} edges of {source} could not be measured on "
            f"'{obj.name}'; nothing was imported.\n" + bounded_list(failures, lines=True)
        )
    return [edge.number for edge in record_profiles(obj, measured, geometry, notes)]


def mesh_lengths(obj, *lengths: float) -> tuple[float, ...]:
    """World-space ``lengths`` (an edge file's spacing and radius from an earlier version) in
    ``obj``'s mesh units: divided by its uniform scale.

    Raises
    ------
    GoniometerError
        The object's scale is not uniform: a world length has no single size on the mesh.
    """
    scale = uniform_scale(np.array(obj.matrix_world, dtype=np.float64))
    if scale is None:
        raise GoniometerError(
            "its points are in world space and the object's scale is not uniform, so its "
            "lengths have no single size on the mesh"
        )
    return tuple(length / scale for length in lengths)


def station_points(centers: list, first_arc: float, spacing: float, closed=None) -> list:
    """The Points of an edge rebuilt from its stations: every centre in order (start, via
    points, end), so the edge retraces through them, closed again (ending on its first centre)
    where the stations went round a loop: where ``closed`` (the CSV's ``Edge Closed``) says so.

    A file written before that column leaves ``closed`` None, and the loop is judged by the
    stations. They sit ``spacing`` apart with the same gap ``g`` (under a spacing) at both
    ends of the path; the first is ``g`` from the start. On a loop the last one is then at most
    ``2g`` (plus the snap to a vertex at each) from the first, across the loop's start; an open
    edge's ends are as far apart as the edge is long (an open edge that nearly closes on itself
    may be taken for a loop).
    """
    if len(centers) < 3:
        return centers
    if closed is None:
        gap = math.dist(centers[-1], centers[0])
        closed = gap <= 2.0 * first_arc + 0.5 * spacing and gap < spacing
    return [*centers, centers[0]] if closed else centers


def edges_from_stations(obj, stations, geometry, *, note_of=None) -> list[int]:
    """Rebuild edge records from re-measured stations (a CSV import).

    Parameters
    ----------
    stations : dict
        ``{(csv mesh name, csv edge number): [(measurement item, Measurement, arc length,
        spacing, closed), ...]}``, ``closed`` the CSV's ``Edge Closed`` (None where the file
        lacks it); the items are already recorded, in the order the CSV listed them. Edges are
        made in the order of the keys.
    note_of : dict, optional
        ``{(csv mesh name, csv edge number): note}``: each edge's own note (the User Data of the
        edge summary written beside the CSV, where it may have been edited after the stations
        were measured); an edge not in it takes its first station's note.

    Returns
    -------
    list of int
        The new edges' numbers. Each item's ``edge_number`` is set to its new edge.
    """
    surface = surface_for(obj, geometry)
    numbers_made = []
    note_of = note_of or {}
    for key, group in sorted(stations.items()):
        group = sorted(group, key=lambda entry: entry[2])
        items, measurements = [g[0] for g in group], [g[1] for g in group]
        figures = summarize(surface, measurements)
        centers = [[float(v) for v in m.center] for m in measurements]
        numbers = {
            "points": station_points(centers, float(group[0][2]), float(group[0][3]), group[0][4]),
            "path": centers,
            "spacing": float(group[0][3]),
            "radius": float(measurements[0].radius),
            "lam": float(measurements[0].lam),
            "length": float(group[-1][2] - group[0][2]),
            "arc_lengths": [float(g[2]) for g in group],
            "angles": [float(m.angle) for m in measurements],
            **record_codec.figure_numbers(figures),
            "flat_spans": [],
            "space": records.MESH,
            "rule": measurements[0].rule,
        }
        edge = records.add_edge_from_numbers(
            obj,
            numbers,
            measurements[0].patch,
            geometry.fingerprint,
            break_number=items[0].break_number,
            note=note_of.get(key, items[0].note),
        )
        for item, left in zip(items, figures.plus_left, strict=True):
            item.edge_number = edge.number
            numbers = exact_numbers(item)
            numbers["plus_left"] = bool(left)
            item.exact = record_codec.encode(numbers)
            records.stamp(item)
            item.colors = "/".join(records.station_colours(item.break_number, left))
        edge.plot = make_plot(obj, edge).name
        numbers_made.append(edge.number)
    return numbers_made


def redraw_plots(obj) -> None:
    """Draw again every edge's plot of ``obj`` whose axis names another unit than its Scan
    Units now do (after they changed), each replacing the image it had."""
    # A batch run's object that is never saved has none. The old images go first, so the new
    # ones take their names (kept where a duplicate shows them); one look over every edge.
    units = records.unit_symbol(obj, bpy.context.scene)
    drawn = [
        edge
        for edge in obj.vg.edges
        if (image := plot_image(edge)) is not None and image.get(UNIT_KEY) != units
    ]
    remove_plots(drawn)
    for edge in drawn:
        edge.plot = make_plot(obj, edge).name


def delete_edge(obj, index: int, *, depsgraph=None) -> int:
    """Delete the edge at list position ``index``, its stations and its plot; repaint (where
    the mesh can be read: with every vertex deleted the records still go).

    Returns the deleted edge's number.
    """
    data = obj.vg
    if not 0 <= index < len(data.edges):
        raise GoniometerError(f"'{obj.name}' has no edge profile at list position {index}.")
    try:
        geometry = evaluated_geometry(obj, depsgraph, purpose="to repaint")
    except NotEvaluatedError:
        raise  # its colours could not be taken off: the edge stays
    except GoniometerError:
        geometry = None  # every vertex deleted: the records still go, and nothing is painted
    edge = data.edges[index]
    number = edge.number
    remove_plots([edge])
    stations = [p for p, m in enumerate(data.measurements) if m.edge_number == number]
    for position in reversed(stations):
        data.measurements.remove(position)
    data.active_index = records.position_after_removal(
        data.active_index, stations, len(data.measurements)
    )
    data.edges.remove(index)
    data.active_edge_index = records.position_after_removal(
        data.active_edge_index, [index], len(data.edges)
    )
    if geometry is not None:
        measuring.repaint(obj, geometry=geometry)
    return number
