"""Measuring ``--edge`` profiles on one mesh of a batch run, through the extension's pipeline."""

from __future__ import annotations

import dataclasses
import functools
import itertools
import math
from pathlib import Path

import bpy

from ..bridge import edges, measuring, records
from ..vg_addon import GoniometerError
from ..vg_addon.errors import bounded_list
from ..vg_addon.formats import csvio, picked_points, profile_plot
from ..vg_addon.formats.record_codec import exact_numbers
from ..vg_addon.method.algorithm import DEFAULT_RULE, check_rule
from ..vg_addon.method.edge_profile import check_station_count
from ..vg_addon.method.inputs import as_lambda, as_radius
from ..vg_addon.method.surface import check_patch_mode
from ..vg_addon.workflow import batchplan
from . import stopping
from .cli import UsageError, is_picked_points
from .find_edges import found_edge_specs
from .sources import readable_name


def edge_specs(args, sources, passed_over: list | None = None) -> list[dict]:
    """The edges of a run: ``--edge`` (with ``--via``, on every mesh) and the rows of
    ``--edges CSV`` (each on the mesh its Mesh Name names), as dicts of ``points``, ``spacing``,
    ``radius``, ``lam``, ``patch``, ``mesh_name`` ("" for every mesh) and ``note`` (its User
    Data; an edges CSV row's own). A line naming the
    ``.pp`` files of an ``--edges`` folder that name no mesh given is appended to
    ``passed_over`` (for the run's summary).

    Raises
    ------
    UsageError
        An unreadable edges CSV, a row without Points, Spacing or Radius, or naming no mesh
        given; a Spacing, Radius, SegParam or Patch Mode a row cannot be measured with, or a
        spacing that would make more than ``edge_profile.MAX_STATIONS`` stations
        (:func:`check_edge_spec`).
    """
    specs = [
        args_spec(args, [spec["start"], *spec["via"], spec["end"]], given=f"--edge {number}")
        for number, spec in enumerate(args.edge, start=1)
    ]
    for number, spec in enumerate(specs, start=1):
        try:
            check_edge_spec(spec)
        except GoniometerError as error:
            raise UsageError(f"--edge {number} with --spacing {args.spacing:g}: {error}") from None
    if not args.edges_csv:
        return specs
    if len(sources) > 1 and args.ignore_mesh_names:
        raise UsageError(
            "--ignore-mesh-names needs a single mesh: with several, each edge row's Mesh Name "
            "(each .pp file's name) says which one to measure it on."
        )
    if is_picked_points(args.edges_csv):
        return specs + picked_point_specs(args, sources, passed_over)
    try:
        rows = csvio.read_edges_csv(Path(args.edges_csv))
    except OSError as error:
        raise UsageError(f"{args.edges_csv}: {error.strerror or error}") from None
    except GoniometerError as error:
        raise UsageError(str(error)) from None
    problems, failed = [], []
    for row in rows:
        number = row.row_number
        if row.error:
            failed.append(number)  # a run could not measure it: nothing to replicate
            continue
        try:
            points = csvio.parse_points(row.points)
        except GoniometerError as error:
            problems.append(f"row {number}: {error}")
            continue
        if row.spacing is None or row.radius is None or len(points) < 2:
            problems.append(f"row {number}: an edge needs two Points, a Spacing and a Radius")
            continue
        name = "" if args.ignore_mesh_names else row.mesh_name
        mesh, why = closest_source(name, sources, f"row {number}")
        if why:
            problems.append(why)
            continue
        spec = {
            "points": [list(p) for p in points],
            "spacing": row.spacing,
            "radius": row.radius,
            "lam": args.lam if row.lam is None else row.lam,
            "patch": row.patch or args.patch,
            "mesh_name": name,
            "mesh": mesh,
            "note": row.user_data,  # kept on the replayed edge, as Blender's import keeps it
            "rule": row.rule.strip().lower(),  # "" (a file of an earlier version): the run's
            # Files of earlier versions hold world-space points (a mesh file's object is
            # untransformed: the same numbers).
            "space": "world" if row.coordinates == csvio.WORLD_COORDINATES else "mesh",
            "given": f"{Path(args.edges_csv).name} row {number}",
            "units": row.units,
            "file_row": number,  # the replay's summary row names it, to compare with the file
        }
        add_checked(specs, problems, spec, f"row {number}")
    if problems:
        raise UsageError(
            f"{args.edges_csv}: {len(problems)} edge row(s) cannot be measured:\n"
            + bounded_list(problems, lines=True)
        )
    if failed and passed_over is not None:
        passed_over.append(failed_rows_line(args.edges_csv, failed))
    return specs


def failed_rows_line(path, numbers: list[int], *, edges: bool = True) -> str:
    """The summary's line naming the rows of an edges CSV (or, ``edges=False``, of a points or
    measurements CSV) passed over because their ``error`` says the run that wrote them could
    not measure them."""
    rows = ", ".join(str(n) for n in numbers[:10]) + (", ..." if len(numbers) > 10 else "")
    what, advice = (
        ("edge row(s)", "clear a row's error cell")
        if edges
        else (
            "row(s)",
            "copy a point's Requested x, y, z into its x, y, z and clear its error (an edge's "
            "rows come back through its edges file, --edges NAME_edges.csv)",
        )
    )
    return (
        f"passed over {len(numbers)} {what} of {Path(path).name} whose error says they were "
        f"not measured (row {rows}): to measure one again, {advice}"
    )


def args_spec(args, points, *, mesh_name: str = "", note: str = "", given: str = "") -> dict:
    """An edge through ``points`` measured with the command line's spacing, radius, λ and patch
    mode, on the mesh ``mesh_name`` ("" for every mesh); ``note`` is stored as its User Data,
    ``given`` names where the points came from (points far from the mesh are refused)."""
    return {
        "points": points,
        "spacing": args.spacing,
        "radius": args.radius,
        "lam": args.lam,
        "patch": args.patch,
        "mesh_name": mesh_name,
        "note": note,
        "given": given,
    }


def add_checked(specs: list, problems: list, spec: dict, where: str) -> None:
    """Append ``spec`` to ``specs``, or, if :func:`check_edge_spec` refuses it, the reason (after
    ``where``) to ``problems``."""
    try:
        check_edge_spec(spec)
    except GoniometerError as error:
        problems.append(f"{where}: {error}")
    else:
        specs.append(spec)


def picked_point_specs(args, sources, passed_over: list | None = None) -> list[dict]:
    """The edges of ``--edges`` given as a ``.pp`` file or a folder of them: each file's active
    points in order (start, via points, end), measured with ``--spacing``, ``--radius``,
    ``--lambda`` and ``--patch`` on the mesh its file name names (``NAME.pp`` or
    ``NAME_*.pp`` for the mesh ``NAME``; any single mesh with ``--ignore-mesh-names``). In a
    folder, files that name no mesh given are passed over (one line appended to
    ``passed_over`` names them); a file named directly must name one.

    Raises
    ------
    UsageError
        No ``--spacing`` or ``--radius``, an unreadable or malformed file, a file with fewer
        than two active points, or one naming no mesh given: every problem listed at once.
    """
    given = args.edges_csv
    if args.spacing is None or args.radius is None:
        raise UsageError(
            f"--edges {given}: picked points are measured with --spacing D and --radius R (in "
            "the mesh's units); give both."
        )
    folder = Path(given).is_dir()
    try:
        paths = picked_points.files_in(given) if folder else [Path(given)]
    except GoniometerError as error:
        raise UsageError(str(error)) from None
    if not paths:
        raise UsageError(f"--edges {given}: the folder has no {picked_points.SUFFIX} files.")
    names = [source.name for source in sources]
    specs, problems, unmatched = [], [], []
    for path in paths:
        shown = readable_name(path.name)  # as mesh names are: every output can hold it
        # --ignore-mesh-names comes with a single mesh (edge_specs)
        name = (
            sources[0].name if args.ignore_mesh_names else picked_points.mesh_for_file(shown, names)
        )
        if name is None:
            if folder:
                unmatched.append(shown)
            else:
                problems.append(
                    f"{shown}: no mesh given is named by it (NAME.pp or NAME_*.pp belongs "
                    "to the mesh NAME)"
                )
            continue
        try:
            points = picked_points.edge_points(picked_points.read_picked_points(path))
        except GoniometerError as error:
            problems.append(readable_name(str(error)))
            continue
        mesh, why = closest_source(name, sources, shown)
        if why:
            problems.append(why)
            continue
        spec = args_spec(args, points.tolist(), mesh_name=name, note=shown, given=shown)
        add_checked(specs, problems, {**spec, "mesh": mesh}, shown)
    if problems:
        raise UsageError(
            f"--edges {given}: {len(problems)} picked-points file(s) cannot be measured:\n"
            + bounded_list(problems, lines=True)
        )
    if unmatched and passed_over is not None:
        passed_over.append(
            f"--edges {given}: {len(unmatched)} file(s) name no mesh given and are passed "
            f"over: {bounded_list(unmatched)}"
        )
    return specs


def check_edge_spec(spec: dict) -> None:
    """Refuse an edge whose settings cannot measure it, before any mesh is read: a spacing,
    radius, λ, patch mode or rule out of range (an edges CSV row's own cells; otherwise each of
    its stations failed alike), or a spacing that would make more stations than the core
    measures (the traced path is at least as long as the straight lines through its points, so
    their length already bounds the count from below)."""
    spacing = spec["spacing"]
    if not (isinstance(spacing, float | int) and math.isfinite(spacing) and spacing > 0):
        raise GoniometerError(
            f"the Spacing must be a finite number greater than 0; got {spacing!r}."
        )
    as_radius(spec["radius"])
    as_lambda(spec["lam"])
    check_patch_mode(spec["patch"])
    if spec.get("rule"):
        check_rule(spec["rule"])
    points = spec["points"]
    length = sum(math.dist(a, b) for a, b in itertools.pairwise(points))
    check_station_count(length, spacing)


def profiled(edge_rows: list) -> list:
    """The summary rows of the edges that were measured (a failed edge's row has an ``error``)."""
    return [row for row in edge_rows if not row.error]


def closest_source(name: str, sources, where: str) -> tuple[list | None, str]:
    """The mesh an edge naming the mesh ``name`` is measured on, as its key for
    :func:`spec_applies`, and why there is none ("" when there is): the closest match among
    ``sources``, as for points (``batchplan.closest_mesh``: an empty name is the one mesh given,
    and refused among several)."""
    names = [source.names for source in sources]
    index, why = batchplan.closest_mesh(name or "", names, where)
    if index < 0:
        return None, why
    return [sources[index].name, sources[index].path], ""


def spec_applies(spec: dict, source) -> bool:
    """Whether edge ``spec`` is measured on the mesh ``source``: the one its name names most
    closely (:func:`closest_source`), or every mesh where it names none."""
    mesh = spec.get("mesh")
    if mesh is None:
        return csvio.mesh_name_matches(spec["mesh_name"], source.names)
    return [source.name, source.path] == list(mesh)


def not_found_row(options: dict, mesh_name: str, message: str, units):
    """The output row of a mesh whose edges ``--find-edges`` could not look for."""
    spec = {key: options["find_edges"][key] for key in ("spacing", "radius", "lam", "patch")}
    row = failed_edge_row(None, {**spec, "points": [None]}, mesh_name, message, units)
    return dataclasses.replace(row, error=NOT_FOUND + message)


def _failure_fields(spec: dict, mesh_name: str, message: str, units) -> dict:
    """What the station row and the edges CSV row of an edge that failed have in common."""
    return {
        "mesh_name": mesh_name,
        "date": csvio.now_iso(),
        "user_data": spec.get("note", ""),
        "radius": spec["radius"],
        "lam": spec["lam"],
        "patch": spec["patch"],
        "spacing": spec["spacing"],
        "units": units,
        "extension_version": records.extension_version(),
        "blender_version": bpy.app.version_string,
        "error": f"edge not measured: {message}",
    }


def failed_edge_row(number: int | None, spec: dict, mesh_name: str, message: str, units):
    """The output row of an edge that could not be measured."""
    first = spec["points"][0]
    return csvio.MeasurementRow(
        **_failure_fields(spec, mesh_name, message, units),
        requested=None if first is None else tuple(float(v) for v in first),
        edge_number=number,
    )


def failed_edge_summary(
    number: int | None, spec: dict, mesh_name: str, message: str, units, rule: str
):
    """The edges CSV row of an edge that could not be measured: its points and settings, so the
    edge can be looked at or measured again, and why it failed; no figures. It keeps the number
    of the row of an edges file it was given by (``spec["file_row"]``), as a measured edge does."""
    return csvio.EdgeRow(
        **_failure_fields(spec, mesh_name, message, units),
        edge_number=number,
        rule=rule,
        row_number=spec.get("file_row"),
        points=csvio.format_points(spec["points"]),
        coordinates=(
            csvio.WORLD_COORDINATES if spec.get("space") == "world" else csvio.MESH_COORDINATES
        ),
    )


STOPPED_EDGE = batchplan.STOPPED_EDGE

STOPPED_SEARCH = "the run was stopped before they were looked for"
"""Why ``--find-edges`` has no edges for a mesh the run was stopped before it searched."""

NOT_FOUND = "edges not found: "
"""How the error of the row of a mesh whose edges ``--find-edges`` could not look for begins."""


def is_search_row(row) -> bool:
    """Whether a failed row is ``--find-edges``' row for a mesh it could not search, not an
    edge's."""
    return bool(row.error) and row.error.startswith(NOT_FOUND)


def edges_of(source, options: dict) -> list[dict]:
    """The edges of the run (``options["edges"]``) that are measured on the mesh ``source``."""
    return [spec for spec in options.get("edges", ()) if spec_applies(spec, source)]


def edge_rule(spec: dict, options: dict) -> str:
    """The rule an edge's stations are measured with: its edges CSV row's ``Rule``, else the
    run's."""
    return spec.get("rule") or options.get("rule", DEFAULT_RULE)


def unmeasured_edges(
    specs, options: dict, mesh_name: str, message: str, units, *, numbered=False, search=None
) -> tuple:
    """The station rows and summary rows of the edges ``specs`` of the mesh ``mesh_name`` that
    were not measured, saying why (``message``), each with its points and settings.

    ``numbered=True`` numbers them 1, 2, ... (a mesh none of whose edges could be measured);
    otherwise they have no edge number. ``search``, if given, adds the row saying why
    ``--find-edges`` found no edge on the mesh.
    """
    stations, summaries = [], []
    for number, spec in enumerate(specs, start=1):
        number = number if numbered else None
        stations.append(failed_edge_row(number, spec, mesh_name, message, units))
        rule = edge_rule(spec, options)
        summaries.append(failed_edge_summary(number, spec, mesh_name, message, units, rule))
    if search is not None:
        stations.append(not_found_row(options, mesh_name, search, units))
    return stations, summaries


def unmeasured_mesh_edges(source, options: dict, message: str, units, *, numbered=False, search=""):
    """:func:`unmeasured_edges` for every edge of the mesh ``source`` (none of them measured),
    and, with ``--find-edges``, its row saying ``search`` (default ``message``)."""
    found = (search or message) if options.get("find_edges") else None
    return unmeasured_edges(
        edges_of(source, options), options, source.name, message, units, numbered=numbered,
        search=found,
    )  # fmt: skip


@dataclasses.dataclass
class EdgesToDo:
    """A mesh's edges and how far the run has measured them, so that a stop can give each edge
    it came before a row: ``specs[:done]`` are recorded; ``search``: whether ``--find-edges``
    has still to look for the mesh's edges (the edges it finds are appended to ``specs``)."""

    specs: list
    search: bool
    done: int = 0

    @classmethod
    def of(cls, source, options: dict) -> EdgesToDo:
        """The edges of ``source`` before any is measured."""
        return cls(edges_of(source, options), bool(options.get("find_edges")))

    def add_not_done(self, kept, options: dict, mesh_name: str, units, message="") -> None:
        """Add to ``kept`` (a ``MeshResult``) the rows of the edges not recorded, saying
        ``message`` (default: the run was stopped before them), and mark them done."""
        search = (message or STOPPED_SEARCH) if self.search else None
        stations, summaries = unmeasured_edges(
            self.specs[self.done :], options, mesh_name, message or STOPPED_EDGE, units,
            search=search,
        )  # fmt: skip
        kept.station_rows.extend(stations)
        kept.edge_rows.extend(summaries)
        self.done, self.search = len(self.specs), False


def measure_edges(obj, source, options: dict, units: str, safe_name: str, surface, precision, kept):
    """Measure the run's edges that apply to ``source`` on its object ``obj`` (on ``surface``,
    the surface the points are measured on: the file's float64 coordinates where Blender's
    float32 copy would round them), and record each as one break of stations, each station
    measured with the edge's rule (an edges CSV row's ``Rule``; else the options' ``rule``) and,
    with ``--stability``, its stability figure.

    ``kept`` is the mesh's ``(MeshResult, EdgesToDo)``. Each edge's rows go into the result as
    soon as the edge is recorded, and it is counted done: ``station_rows``, every edge's
    stations in order, or one error row for an edge that failed; ``edge_rows``, one summary per
    edge (an edge that failed has its points, settings and ``error`` and no figures); rows name
    the mesh as the user gave it (``source.name``). On a stop (KeyboardInterrupt) the caller
    gives the edges not done their rows (``EdgesToDo.add_not_done``).

    Returns
    -------
    plots : list of (what, path, png bytes function)
        Each profile's plot, to draw beside the output CSV once the rows are written.
    found : int
        How many edges ``--find-edges`` found on the mesh (-1: not looked for, or the finder
        could not run, which is an error row).
    """
    result, todo = kept
    plots, found, name = [], -1, source.name
    painted = None  # the geometry the edges were measured on, once one is recorded
    if todo.search:
        try:
            found_specs, not_found = found_edge_specs(surface, options, name), None
        except GoniometerError as error:
            found_specs, not_found = [], not_found_row(options, name, str(error), units)
        with stopping.deferred():  # what the finder found is kept whole
            todo.specs += found_specs
            found = -1 if not_found is not None else len(found_specs)
            result.station_rows.extend([] if not_found is None else [not_found])
            todo.search = False
        stopping.check()
    for spec in todo.specs:
        outcome = _measure_edge(obj, spec, options, surface)
        with stopping.deferred():  # the edge is recorded and its rows kept, or neither
            stations, summary, edge, numbers, geometry = _record_edge(
                obj, spec, options, units, precision, name, outcome
            )
            result.station_rows.extend(stations)
            result.edge_rows.append(summary)
            todo.done += 1
        stopping.check()
        if edge is None:
            continue
        painted = geometry
        path = f"{options['plots']}_{safe_name}_edge{edge.number}.png"
        data = functools.partial(
            profile_plot.profile_png,
            numbers["arc_lengths"],
            numbers["angles"],
            units=units,
            title=f"Edge profile: {name}, edge {edge.number}",
            pooled=numbers["pooled_angle"],
        )
        plots.append(("profile plot", path, data))
    if painted is not None:
        measuring.repaint(obj, geometry=painted)
    return plots, found


def _measure_edge(obj, spec, options, surface):
    """Measure one edge on ``obj`` (the slow part, which a stop may cut short): its profile, the
    geometry and the clicks it was measured from, or the GoniometerError saying why it cannot
    be."""
    try:
        spacing, radius = spec["spacing"], spec["radius"]
        if spec.get("space") == "world":  # an edge file of an earlier version
            spacing, radius = edges.mesh_lengths(obj, spacing, radius)
        return edges.measure_edge(
            obj,
            spec["points"],
            spacing,
            radius,
            spec["lam"],
            spec["patch"],
            space=spec.get("space", "mesh"),
            surface=surface,
            given=spec.get("given", ""),
            rule=edge_rule(spec, options),
            stability=bool(options.get("stability")),
        )
    except GoniometerError as error:
        return error


def _record_edge(obj, spec, options, units, precision, name, outcome):
    """Record the edge ``outcome`` of :func:`_measure_edge` on ``obj`` (under the next edge
    number, which a failed edge keeps too); returns its station rows, its summary, the edge
    record (None for an edge that failed), its numbers and the geometry it was measured on."""
    number = obj.vg.next_edge_number
    if not isinstance(outcome, GoniometerError):
        profile, geometry, clicks = outcome
        try:
            # Recorded without repainting: the colours are painted once, after every edge. The
            # plot kept in the object is drawn only for a .blend that is saved (--save-blend);
            # the run writes its own plot file.
            edge = edges.record_profile(
                obj,
                profile,
                geometry,
                clicks,
                note=spec.get("note", ""),
                plot=bool(options.get("save_blend")),
            )
        except GoniometerError as error:
            outcome = error
    if isinstance(outcome, GoniometerError):
        obj.vg.next_edge_number = number + 1  # the number stays with the failed edge
        rule, message = edge_rule(spec, options), str(outcome)
        return (
            [failed_edge_row(number, spec, name, message, units)],
            failed_edge_summary(number, spec, name, message, units, rule),
            None,
            None,
            None,
        )
    # The edge's stations are the items it just appended: read those, not every stored one.
    measurements = obj.vg.measurements
    numbers = exact_numbers(edge)
    closed = records.edge_is_closed(numbers)
    stations = [
        dataclasses.replace(
            records.to_row(
                obj,
                measurements[i],
                stale=False,
                units=units,
                precision=precision,
                edge_closed=closed,
            ),
            mesh_name=name,
        )
        for i in range(len(measurements) - edge.n_stations, len(measurements))
    ]
    summary = dataclasses.replace(
        records.edge_row(obj, edge, units=units),
        mesh_name=name,
        row_number=spec.get("file_row"),
    )
    return stations, summary, edge, numbers, geometry
