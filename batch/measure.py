"""Measuring one mesh's rows in a batch run, through the extension's own pipeline."""

from __future__ import annotations

import dataclasses
import time
import traceback
from pathlib import Path
from typing import NoReturn

import bpy
import numpy as np

from ..bridge import colors, measuring, mesh_data, records
from ..vg_addon import GoniometerError, Surface
from ..vg_addon import units as units_module
from ..vg_addon.formats import csvio, files, sweep_plot
from ..vg_addon.method.sweep import SweepPoint, radius_sweep, sweep_radii
from . import stopping
from .cli import UNITS
from .edges import EdgesToDo, edges_of, measure_edges, unmeasured_mesh_edges
from .map_process import draw_map
from .pictures import reason, try_picture
from .render import add_sides_material
from .sources import MeshSource, import_mesh

_BLOCK = 64  # tasks measured before they are recorded


@dataclasses.dataclass
class MeshResult:
    """What measuring one mesh produced (sent from a worker to its parent as JSON)."""

    mesh: int
    rows: list = dataclasses.field(default_factory=list)  # [(task index, MeasurementRow)]
    station_rows: list = dataclasses.field(default_factory=list)  # edges' stations
    edge_rows: list = dataclasses.field(default_factory=list)  # edges' summaries
    object_name: str = ""
    bad_file: str = ""  # why the mesh file could not be read
    n_vertices: int = 0
    measured: int = 0
    failed: int = 0
    load_seconds: float = 0.0
    prepare_seconds: float = 0.0
    measure_seconds: float = 0.0
    render: str = ""
    picture_errors: list = dataclasses.field(default_factory=list)  # pictures not written
    blend: str = ""  # a worker's one-object .blend, for --save-blend
    winding: str = ""  # see vg_addon.method.winding.WINDINGS
    sweep_rows: list = dataclasses.field(default_factory=list)  # [(task index, [cells])]
    sweep_plots: int = 0
    found_edges: int = -1  # edges --find-edges found (-1: not looked for)

    def to_json(self) -> dict:
        out = dataclasses.asdict(self)
        out["rows"] = [[index, dataclasses.asdict(row)] for index, row in self.rows]
        return out

    @classmethod
    def from_json(cls, data: dict, row_type) -> MeshResult:
        def row(fields):
            for key in ("normal_plus", "normal_minus", "requested"):
                if fields.get(key) is not None:
                    fields[key] = tuple(fields[key])
            return row_type(**fields)

        rows = [(index, row(fields)) for index, fields in data.pop("rows")]
        stations = [row(fields) for fields in data.pop("station_rows")]
        edges = [csvio.EdgeRow(**fields) for fields in data.pop("edge_rows")]
        return cls(rows=rows, station_rows=stations, edge_rows=edges, **data)


def error_row(task, mesh_name: str, message: str, units: str):
    """The output row of a task that could not be measured."""
    return csvio.MeasurementRow(
        mesh_name=mesh_name,
        date=csvio.now_iso(),
        number=task.number or None,
        break_number=task.break_number,
        user_data=task.label,
        radius=task.radius,
        lam=task.lam,
        patch=task.patch,
        rule=task.rule,  # a retry of the row is measured as the run was asked to
        requested=tuple(task.center),
        units=units,
        extension_version=records.extension_version(),
        blender_version=bpy.app.version_string,
        error=message,
    )


def measure_mesh(index: int, source: MeshSource, tasks, options, progress=None, rows_ready=None):
    """Load (or find) one mesh, measure its tasks, record them on the object, colour it, then
    draw its pictures (map, sweep and profile plots). Never raises for a problem of this mesh:
    it becomes the rows' error; a picture that cannot be written is one of
    ``result.picture_errors``, never a row's.

    ``rows_ready(result)`` is called once, when every row is known and before any picture is
    drawn: the caller writes the rows then, so a run stopped while drawing keeps them; a run
    stopped while measuring hands over the rows measured so far and a row for each edge not
    recorded, saying the run was stopped before it (nothing if stopped while the mesh loads: the
    run then writes every row of the mesh as not measured). An unexpected error (a bug) while
    measuring keeps the rows measured before it too: its traceback goes to stderr, and each
    point and edge not measured has a row saying so. Rows name the mesh as the user gave it (``source.name``: a mesh file's stem), whatever name
    Blender gave its object.

    The numbers come from the extension's own pipeline: the object's evaluated mesh in its own
    coordinates (``mesh_data.evaluated_geometry``), its cached ``Surface``
    (``mesh_data.surface_for``) and ``measuring.record``, the step a click records through; a
    mesh file whose float64 coordinates float32 would round is measured at the file's
    coordinates instead (:func:`exact_surface`, ``Precision`` float64 in the CSV). The colours are painted once per
    mesh at the end by ``measuring.repaint``, the extension's own painter, from the sides kept
    while measuring.
    """
    result = MeshResult(mesh=index)
    units = run_units_label(options.get("units"))
    name = source.name

    def fail_all(message: str) -> MeshResult:
        result.rows = [(t.index, error_row(t, name, message, units)) for t in tasks]
        result.failed = len(tasks)
        result.station_rows, result.edge_rows = unmeasured_mesh_edges(
            source, options, message, units, numbered=True
        )
        if rows_ready is not None:
            rows_ready(result)
        return result

    start = time.perf_counter()
    exact_points = None
    try:
        stopping.check()
        if source.path:
            obj, exact_points = import_mesh(source)
        else:
            obj = bpy.data.objects[source.name]
    except GoniometerError as error:
        result.bad_file = str(error)
        return fail_all(f"could not read the mesh: {error}")
    except MemoryError:
        result.bad_file = f"'{source.path}' is too large for this machine's memory"
        return fail_all(f"could not read the mesh: {result.bad_file}")
    result.object_name = obj.name
    result.load_seconds = time.perf_counter() - start

    start = time.perf_counter()
    try:
        mesh_data.check_measurable(obj)
        geometry = mesh_data.evaluated_geometry(obj)
        if exact_points is None:
            surface, precision = mesh_data.surface_for(obj, geometry), "float32"
        else:
            surface, precision = exact_surface(source, exact_points, geometry), "float64"
    except GoniometerError as error:
        return fail_all(str(error))
    result.n_vertices = int(geometry.points.shape[0])
    result.prepare_seconds = time.perf_counter() - start
    if not options.get("units_given"):
        # A replayed export's rows say what unit the scan is in, as Blender's import takes it.
        named = [task.units for task in tasks if task.units]
        named += [spec["units"] for spec in edges_of(source, options) if spec.get("units")]
        if named:
            records.adopt_file_units(obj, named)
    elif key := SCAN_UNITS.get(options["units"]):
        records.choose_unit(obj, key)  # what the user said the scan is in
    units = records.units_label(bpy.context.scene, obj)  # a .blend object may be scaled
    result.winding = surface.winding
    measuring.note_winding(obj, surface)

    stem = picture_stem(index, source, options)
    handed, todo = False, EdgesToDo.of(source, options)
    try:
        with stopping.deferred():  # a stop is acted on between points: nothing measured is lost
            _measure_points(
                result, obj, name, tasks, options, progress, (surface, geometry, precision, units)
            )
        stopping.check()
        plots = _sites_and_edges(
            (result, todo), obj, source, tasks, options, stem, (surface, geometry, precision, units)
        )
        with stopping.deferred():  # the rows are handed over whole, before any picture
            handed = True
            if rows_ready is not None:
                rows_ready(result)
        stopping.check()
    except KeyboardInterrupt as stop:  # the rows so far are kept; the rest is not done
        if not handed:
            with stopping.deferred():
                todo.add_not_done(result, options, name, units)
            _stop_with(result, rows_ready, stop)
        raise
    except Exception as error:  # a bug: the rows so far are kept, the rest say what happened
        if handed:
            raise  # only the pictures are lost (safe_measure_mesh says so)
        with stopping.deferred():  # a stop now must not cost the rows measured
            traceback.print_exc()
            message = internal_error(error)
            _fail_the_rest(result, todo, tasks, options, (name, units, message))
            if _makes_outputs(source, options):  # not made after a bug: the run says so
                result.picture_errors.append(f"pictures and colours of {name}: {message}")
            if rows_ready is not None:
                rows_ready(result)
        stopping.check()
        return result
    draw_pictures(result, obj, options, stem, plots, name)
    return result


def internal_error(error: Exception) -> str:
    """The row error of what an unexpected error (a bug) kept from being measured."""
    return (
        f"internal error while measuring this mesh ({type(error).__name__}: {error}); "
        "please report it with the traceback printed on stderr"
    )


def _makes_outputs(source: MeshSource, options) -> bool:
    """Whether the run makes pictures or keeps colours of the mesh ``source`` once its rows are
    handed over: a map, sweep or profile plots, a saved .blend, or a .blend input's object."""
    asked = ("render", "sweep", "edges", "find_edges", "save_blend")
    return any(options.get(key) for key in asked) or not source.path


def _fail_the_rest(result: MeshResult, todo, tasks, options, why) -> None:
    """Give each task of ``tasks`` with no row in ``result``, each ``--sweep`` site not swept
    and each edge of ``todo`` not done a row saying ``why`` (the mesh's name, its units label
    and the message)."""
    name, units, message = why
    done = {index for index, _ in result.rows}
    rest = [task for task in tasks if task.index not in done]
    result.rows += [(task.index, error_row(task, name, message, units)) for task in rest]
    result.failed += len(rest)
    if options.get("sweep"):
        swept = {index for index, _ in result.sweep_rows}
        result.sweep_rows += [
            (task.index, csvio.sweep_cells(name, task.number, SweepPoint(float(r), None, message), units))
            for task in tasks
            if task.index not in swept
            for r in sweep_radii(*options["sweep"])
        ]  # fmt: skip
    todo.add_not_done(result, options, name, units, message)


def _measure_points(result, obj, name, tasks, options, progress, measured_on) -> None:
    """Measure the mesh's points and record them into ``result``, a block at a time.

    Run inside ``stopping.deferred()``: a stop is acted on before the next point, once every
    point already measured is recorded, by raising KeyboardInterrupt. ``measured_on``: the
    surface, geometry, precision and units label, as for :func:`_sites_and_edges`."""
    surface, geometry, precision, units = measured_on
    data = obj.vg
    base = data.next_number - 1  # measurements already on a .blend object keep their numbers
    last_report = start = time.perf_counter()
    try:
        for first in range(0, len(tasks), _BLOCK):
            # Measure a block, then record it: alternating one measurement with one record costs
            # about a tenth more (measured), the records' writes evicting the measuring's data.
            block = tasks[first : first + _BLOCK]
            measured = []
            for task in block:
                if stopping.requested():
                    break
                measured.append(_measure_task(surface, geometry, task, options))
                now = time.perf_counter()  # once a second however slow the block (a task each)
                if progress is not None and now - last_report >= 1.0:
                    progress(first + len(measured))
                    last_report = now
            for task, m in zip(block, measured, strict=False):
                if isinstance(m, GoniometerError):
                    result.rows.append((task.index, error_row(task, name, str(m), units)))
                    result.failed += 1
                    continue
                data.next_number = base + task.number
                # The bridge's one record step, as a click takes; painted once at the end.
                row = measuring.record_row(
                    obj,
                    m,
                    geometry,
                    units=units,
                    precision=precision,
                    note=task.label,
                    break_number=task.break_number,
                )
                result.rows.append((task.index, dataclasses.replace(row, mesh_name=name)))
                result.measured += 1
            stopping.check()
    finally:
        result.measure_seconds = time.perf_counter() - start


def _sites_and_edges(kept, obj, source, tasks, options, stem, measured_on) -> list:
    """After the points of :func:`measure_mesh`: the radius sweeps, the colours and the edges,
    into ``kept``, the mesh's ``(MeshResult, EdgesToDo)``; returns the plots to draw.
    ``measured_on``: the points' surface, geometry, precision and units label."""
    result = kept[0]
    surface, geometry, precision, units = measured_on
    name, data = source.name, obj.vg
    sweep_plots = []
    if options.get("sweep"):
        sweep_plots = sweep_sites(
            result, surface, name, stem, tasks, options, geometry.matrix, units
        )
    if len(data.measurements):
        data.next_number = max(item.number for item in data.measurements) + 1
        records.continue_after_recorded_breaks(obj)

    if result.measured:
        measuring.repaint(obj, geometry=geometry)
        add_sides_material(obj)
        colors.show_sides_once(obj)

    profile_plots = []
    if options.get("edges") or options.get("find_edges"):
        profile_plots, result.found_edges = measure_edges(
            obj, source, options, units, stem, surface, precision, kept
        )
    return sweep_plots + profile_plots


def _stop_with(result, rows_ready, stop) -> NoReturn:
    """Hand over the rows measured before the run was stopped (the run writes them with the
    rest, and each task without a row as not measured), then stop. Nothing else is finished:
    a stopped run saves no .blend and draws no picture."""
    if rows_ready is not None:
        rows_ready(result)
    raise stop


def picture_stem(index: int, source: MeshSource, options) -> str:
    """The file-name stem of this mesh's pictures, unique within the run."""
    stems = options.get("picture_names") or []
    return stems[index] if index < len(stems) else files.safe_file_name(source.name)


def draw_pictures(result: MeshResult, obj, options, stem: str, plots, name: str) -> None:
    """Write the mesh ``name``'s plots (``(what, path, png bytes function)``) and its map; each
    failure is one line of ``result.picture_errors``, never a lost row."""
    inputs = options.get("inputs", ())
    for what, path, data in plots:
        written = try_picture(result.picture_errors, what, path, data, inputs)
        result.sweep_plots += written and what == "sweep plot"
    if options.get("render"):
        folder = Path(options["render"])
        try:
            result.render = str(draw_map(obj, folder, options, stem, name))
        except Exception as error:  # a render problem must not lose the measurements
            result.picture_errors.append(f"render of {name}: {reason(error, folder)}")


def _measure_task(surface, geometry, task, options):
    """The measurement of one task, or the GoniometerError saying why it cannot be taken."""
    try:
        return measuring.replicate_measurement(
            surface,
            geometry.matrix,
            task.center,
            task.radius,
            requested=task.requested,
            world=task.coordinates == records.WORLD,  # a row of an export of earlier versions
            scale_radius=not task.default_radius,
            lam=task.lam,
            patch=task.patch,
            rule=task.rule,
            stability=bool(options.get("stability")),
        )
    except GoniometerError as error:
        return error


def sweep_sites(result: MeshResult, surface, name: str, stem: str, tasks, options, matrix, units):
    """``--sweep``: each task's site at the sweep's radii, as CSV cells, and the plot of each
    site to draw (``(what, path, png bytes function)``). ``matrix`` is the object's
    ``matrix_world`` (for world-space rows of older exports); ``units`` labels the plot's axes."""
    start, stop, count = options["sweep"]
    folder = Path(options["sweep_plots"])
    plots = []
    for task in tasks:
        try:
            center = task.center
            if task.coordinates == records.WORLD:
                center, _ = measuring.from_world(center, None, matrix)
            points = radius_sweep(
                surface, center, start, stop, count, task.lam, task.patch, task.rule
            )
        except GoniometerError as error:
            points = [
                SweepPoint(float(r), None, str(error)) for r in sweep_radii(start, stop, count)
            ]
        else:
            path = folder / f"{stem}_{task.number}.png"
            title = f"Radius sweep: {name}, site {task.number}"
            plots.append(("sweep plot", path, _sweep_png(points, units, title)))
        cells = [
            (task.index, csvio.sweep_cells(name, task.number, point, units)) for point in points
        ]
        with stopping.deferred():  # a site's radii are kept whole or not at all
            result.sweep_rows.extend(cells)
        stopping.check()
    return plots


def _sweep_png(points, units: str, title: str):
    return lambda: sweep_plot.sweep_png(points, units=units, title=title)


def exact_surface(source: MeshSource, points: np.ndarray, geometry) -> Surface:
    """The surface of a mesh file at its own float64 coordinates, with the faces Blender kept.

    The imported object is untransformed, and measurements are taken in mesh coordinates, so the
    file's coordinates are the ones measured in; Blender's float32 copy would round them (by up to a few
    thousandths of a unit at a thousand units from the origin, which tilts small patches).
    """
    if points.shape != geometry.points.shape:
        raise GoniometerError(
            f"'{source.path}' has float64 coordinates that Blender's float32 mesh rounds, and "
            f"Blender's import changed its vertices ({points.shape[0]} in the file, "
            f"{geometry.points.shape[0]} in Blender), so it cannot be measured at the file's "
            "precision. Move the mesh near the origin (subtract an offset) and measure again."
        )
    triangles = geometry.triangles if geometry.triangles.size else None
    return Surface(points, triangles)


#: ``--units`` as an object's Scan Units: the CSV's Units cell then names the unit as every
#: replay and import of it does ("mm"; "m" too, which a scene of 1 BU = 1 m cannot say).
SCAN_UNITS = {"m": "M", "cm": "CM", "mm": "MM", "um": "UM", "in": "IN"}


def run_units_label(unit: str | None) -> str:
    """The Units cell of a row with no object to label it (a row that failed before one was
    measured on): the symbol of the run's ``--units`` ``unit``, else the scene's label."""
    key = SCAN_UNITS.get(unit or "")
    return units_module.SYMBOLS[key] if key else records.units_label(bpy.context.scene)


def set_units(scene, unit: str | None) -> None:
    """Set the scene's length units to ``unit`` (a key of :data:`UNITS`); None: leave them."""
    if not unit:
        return
    system, scale, length = UNITS[unit]
    settings = scene.unit_settings
    settings.system = system
    settings.scale_length = scale
    if length is not None:
        settings.length_unit = length


def safe_measure_mesh(index: int, source: MeshSource, tasks, options, progress, rows_ready=None):
    """:func:`measure_mesh`, with an unexpected error (a bug) turned into failed rows for this
    mesh only, its traceback on stderr, so the other meshes are still measured. An error after
    the rows were handed to ``rows_ready`` costs only the pictures. ``rows_ready`` is called
    exactly once either way (twice only if it raises itself: the second time with every row
    failed), unless the run is stopped while the mesh loads (the run then writes
    each of its rows as not measured). An unexpected error while the mesh loads gives each of
    its points and edges a row saying so (one while measuring keeps the rows measured before
    it: :func:`measure_mesh`)."""
    sent = []

    def ready(result):
        if rows_ready is not None:
            rows_ready(result)
        sent.append(result)  # only rows the run has taken count as delivered

    try:
        return measure_mesh(index, source, tasks, options, progress, ready)
    except Exception as error:
        traceback.print_exc()
        message = internal_error(error)
        if sent:  # the rows are out: only the pictures are lost
            sent[0].picture_errors.append(f"pictures of {source.name}: {message}")
            return sent[0]
        units = run_units_label(options.get("units"))
        result = MeshResult(mesh=index, failed=len(tasks))
        result.rows = [(t.index, error_row(t, source.name, message, units)) for t in tasks]
        result.station_rows, result.edge_rows = unmeasured_mesh_edges(
            source, options, message, units
        )
        ready(result)
        return result
