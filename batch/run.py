"""A batch run: plan the rows, measure mesh after mesh (or in worker processes), write the CSV."""

from __future__ import annotations

import dataclasses
import functools
import os
import shutil
import tempfile
import threading
import time
from pathlib import Path

import bpy

from ..vg_addon import GoniometerError
from ..vg_addon.errors import bounded_list
from ..vg_addon.formats import csvio, files
from ..vg_addon.method.edge_summary import sd_text
from ..vg_addon.method.winding import winding_message
from ..vg_addon.workflow import batchplan
from . import extension, replay_agreement, stopping
from .blend_file import append_objects, forget, save_blend
from .cli import UsageError, is_picked_points
from .edges import (
    STOPPED_EDGE,
    STOPPED_SEARCH,
    edge_specs,
    failed_rows_line,
    is_search_row,
    profiled,
    spec_applies,
    unmeasured_mesh_edges,
)
from .find_edges import find_options
from .flagged import flagged_lines
from .measure import MeshResult, error_row, run_units_label, safe_measure_mesh, set_units
from .outputs import (
    check_outputs,
    input_files,
    is_stream,
    keeps_earlier,
    make_folders,
    partial_paths,
    remove_partial,
    sweep_paths,
)
from .pictures import reason
from .sources import blend_objects, file_sources, start_file
from .stdio import say
from .workers import run_workers

STOPPED = "not measured: the run was stopped before this point"
"""The error of a row the run had not measured when it was stopped."""


class Run:
    """The state of a batch run in the parent process: results, progress, partial CSV writes."""

    def __init__(self, args, sources, tasks, meshes, options: dict | None = None):
        """A run of ``tasks`` (points) on ``sources``, measuring the meshes ``meshes`` (indices
        into ``sources``) with ``options`` (its edges, ``--find-edges``...)."""
        self.args, self.sources, self.tasks = args, sources, tasks
        self.meshes, self.options = list(meshes), options or {}
        self.total_meshes = len(self.meshes)
        self.jobs = 1  # processes measuring at once
        self.rows: dict[int, object] = {}
        self.sweep_rows: list = []  # (task index, cells), --sweep
        # Per mesh: edge profiles' stations (and failed edges), written after the rows, and one
        # summary per edge for OUT_edges.csv; in mesh order however the workers finish.
        self.edges_by_mesh: dict[int, tuple[list, list]] = {}
        self.results: list[MeshResult] = []
        self.bad_files: list[str] = []
        self.passed_over: list[str] = []  # lines naming .pp files that name no mesh given
        self.replayed = 0  # how many rows of a --points file the tasks were planned from
        self.replayed_export = False  # whether that file's header is this extension's export
        self.lock = threading.Lock()
        self.started = time.perf_counter()
        self.last_progress = 0.0
        self.last_write = 0.0  # when the CSV was last written (perf_counter seconds)
        self.write_seconds = 0.0  # how long that took
        # The header's write (mostly the disk's flush) says nothing of what rows cost: the first
        # measured rows are written at once, before any picture.
        self.wrote_rows = False  # a write of measured rows was tried
        self.in_flight: dict[int, int] = {}  # mesh -> points done so far (running meshes)
        self.units = run_units_label(getattr(args, "units", None))
        # A pipe or standard output gets the CSV once, at the end; a file is rewritten as the
        # meshes finish, so a run that is stopped keeps what it measured.
        self.stream = is_stream(args.out)
        # An earlier --out is the user's results: a run stopped part-way must not replace them
        # with fewer, so the rewrites go to a side file until the run completes.
        earlier = keeps_earlier(args.out)
        self.target = str(partial_paths(args.out)[0]) if earlier else args.out  # where it goes now
        self.failed_outputs: list[str] = []  # .blend or pictures that could not be written
        self.write_error = ""  # why the last write of the CSV failed ("" if it did not)
        # Each row's CSV line, formatted once: every rewrite of the growing CSV reuses them.
        self.csv_lines: dict = {}
        for task in tasks:
            if task.mesh < 0:
                self.rows[task.index] = error_row(task, task.mesh_name, task.error, self.units)

    @property
    def station_rows(self) -> list:
        """Every edge's station rows (and failed edges' rows), mesh after mesh."""
        return [row for mesh in sorted(self.edges_by_mesh) for row in self.edges_by_mesh[mesh][0]]

    @property
    def edge_rows(self) -> list:
        """Every edge's summary row (a failed edge's with its ``error``), mesh after mesh."""
        return [row for mesh in sorted(self.edges_by_mesh) for row in self.edges_by_mesh[mesh][1]]

    @property
    def profiled_edges(self) -> list:
        """The summary rows of the edges that were measured."""
        return profiled(self.edge_rows)

    @property
    def done_points(self) -> int:
        return len(self.rows) + sum(self.in_flight.values())

    def say(self, text: str) -> None:
        say(text)

    def say_agreement(self) -> None:
        """After re-measuring an export (this extension's or a batch run's): a line saying how
        the angles agree with the file's (``workflow.agreement``)."""
        if self.args.points and self.replayed:
            line = replay_agreement.points_line(
                Path(self.args.points), self.replayed, self.replayed_export, self.rows
            )
            if line:
                self.say(line)

    def say_edge_agreement(self) -> None:
        """After re-measuring an edge summary (``--edges CSV``): a line saying how the edges'
        figures agree with the file's (``workflow.agreement.edge_agreement``)."""
        path = self.args.edges_csv
        if path and not is_picked_points(path):
            line = replay_agreement.edges_line(Path(path), self.edge_rows)
            if line:
                self.say(line)

    def say_flagged(self, by_index: dict) -> None:
        """The summary's lines for unstable readings (see :func:`.flagged.flagged_lines`)."""
        for line in flagged_lines(self.rows, self.station_rows, by_index):
            self.say(line)

    def progress(self, mesh: int, done: int, force: bool = False) -> None:
        with self.lock:
            self.in_flight[mesh] = done
            now = time.perf_counter()
            if self.args.quiet or (not force and now - self.last_progress < 1.0):
                return
            self.last_progress = now
            failed = sum(1 for row in self.rows.values() if row.error)
            self.say(
                f"[{now - self.started:6.1f} s] {len(self.results)}/{self.total_meshes} meshes, "
                f"{self.done_points:,}/{len(self.tasks):,} points, {failed:,} failed"
            )

    def add(self, result: MeshResult, pictures_follow: bool = False) -> None:
        """Take a mesh's rows (before its pictures are drawn). A row that cannot be written
        costs only its own cells (``csvio.writable_row``); the CSV is rewritten now and then, so
        a run that is stopped keeps them: the first rows at once, then at least every 5 s, and
        before a mesh's pictures whenever the last rewrite took under 50 ms or under a tenth of
        the time since (the whole CSV is rewritten each time, so rewriting before every mesh's
        pictures would cost a run of many meshes time that grows with the square of their
        number)."""
        with self.lock:
            self.in_flight.pop(result.mesh, None)
            self.results.append(result)
            for index, row in result.rows:
                self.rows[index] = csvio.writable_row(row)
            self.sweep_rows.extend(result.sweep_rows)
            self.edges_by_mesh[result.mesh] = (
                [csvio.writable_row(row) for row in result.station_rows],
                [csvio.writable_row(row) for row in result.edge_rows],
            )
            if result.bad_file:
                self.bad_files.append(result.bad_file)
            # Each write costs more as rows accumulate; finish() always writes.
            since = time.perf_counter() - self.last_write
            due = not self.wrote_rows or since >= max(5.0, 10.0 * self.write_seconds)
            cheap = self.write_seconds < 0.05 or since >= 10.0 * self.write_seconds
            if not self.stream and (due or (pictures_follow and cheap)):
                self.try_write_csv()
                self.wrote_rows = True

    def pictures_done(self, result: MeshResult) -> None:
        """Take a mesh's pictures (after :meth:`add`): note those that failed, report the
        mesh."""
        with self.lock:
            for at, earlier in enumerate(self.results):
                if earlier.mesh == result.mesh:
                    self.results[at] = result  # a worker's final result: the same rows
            self.failed_outputs.extend(result.picture_errors)
        source = self.sources[result.mesh]
        rate = result.measured / result.measure_seconds if result.measure_seconds > 0 else 0
        failed = len(result.picture_errors)
        note = f", {failed} picture(s) not written" if failed else ""
        if not self.args.quiet:
            points = result.measured + result.failed
            measured_edges = profiled(result.edge_rows)
            stations = sum(edge.n_stations or 0 for edge in measured_edges)
            edges = f"{len(measured_edges)} edge(s) profiled ({stations:,} stations)"
            unprofiled = len(result.edge_rows) - len(measured_edges)
            edges += f", {unprofiled} failed" if unprofiled else ""
            if points or not result.edge_rows:  # an edges-only run has no points to count
                self.say(
                    f"{source.name}: {result.measured:,} measured, {result.failed:,} failed"
                    + (f" ({result.n_vertices:,} vertices, {rate:,.0f}/s)" if points else "")
                    + (f", {edges}" if result.edge_rows else "")
                    + note
                )
            else:
                self.say(f"{source.name}: {edges}, {result.n_vertices:,} vertices{note}")
        elif note:
            self.say(f"{source.name}{note}")
        if message := winding_message(result.object_name or source.name, result.winding):
            self.say(f"note: {message}")  # once per mesh, also with --quiet

    def try_write_csv(self) -> None:
        """:meth:`write_csv` during the run: a failure (the folder gone, a full disk) is said
        once and the run goes on; the CSV is written again at the end."""
        try:
            self.write_csv()
        except (OSError, GoniometerError) as error:
            if not self.write_error:
                self.say(
                    f"could not write {what_failed(error, self.target)}; measuring goes on, "
                    "and the CSV is written again at the end"
                )
            self.write_error = reason(error)
            self.last_write = time.perf_counter()
        else:
            self.write_error = ""

    def recover_csv(self, error) -> None:
        """The CSV could not be written at the end: write the rows into the temporary folder
        instead and say where, so nothing measured is lost."""
        stem = Path(self.target).stem if self.target != files.STDOUT else "out"
        handle, path = tempfile.mkstemp(prefix=f"vg_batch_{stem}_", suffix=".csv")
        os.close(handle)
        where = "standard output" if self.target == files.STDOUT else self.target
        try:
            self.write_csv(path)
        except csvio.SummaryWriteError as second:
            self.say(
                f"could not write the CSV to {where}: {reason(error)}; the rows are in {path} "
                f"(move it where it belongs), but not their edge summary: {reason(second.cause)}"
            )
            return
        except (OSError, GoniometerError) as second:
            Path(path).unlink(missing_ok=True)
            self.say(
                f"could not write the CSV to {where}: {reason(error)}; nor to {path}: "
                f"{reason(second)}. The rows are lost."
            )
            return
        self.say(
            f"could not write the CSV to {where}: {reason(error)}; the rows are in {path} "
            "(move it where it belongs)"
        )

    def recover_summary(self, error) -> None:
        """The CSV was written at the end but not its edge summary: keep the summary in the
        temporary folder and say where, so no edge row is lost."""
        handle, path = tempfile.mkstemp(
            prefix=f"vg_batch_{error.summary_path.stem}_", suffix=".csv"
        )
        with os.fdopen(handle, "wb") as stream:
            stream.write(error.summary_text)
        self.say(
            f"could not write {what_failed(error, self.target)}; the edge summary is in {path} "
            "(move it where it belongs)"
        )

    def write_csv(self, out=None) -> None:
        """Write the rows to ``out`` (default ``--out``, or its side file while a run to an earlier
        ``--out`` has not completed), and the edge summaries beside it (emptied where an earlier
        run left one and this one measures no edge)."""
        out = self.target if out is None else out
        start = time.perf_counter()
        rows = [self.rows[i] for i in sorted(self.rows)] + self.station_rows
        edges = any(getattr(self.args, name, None) for name in ("edge", "edges_csv", "find_edges"))
        csvio.write_export(out, rows, self.edge_rows, lines=self.csv_lines, summary=edges)
        self.last_write = time.perf_counter()
        self.write_seconds = self.last_write - start

    def write_sweep_csv(self) -> None:
        """Write ``<out>_sweep.csv``; a failure is a failed output (exit 2), the rows kept."""
        csv_path, plots = sweep_paths(self.target)[0], sweep_paths(self.args.out)[1]
        rows = [cells for _, cells in sorted(self.sweep_rows, key=lambda pair: pair[0])]
        try:
            files.replace_atomically(str(csv_path), csvio.format_sweep_rows(rows).encode("utf-8"))
        except (OSError, GoniometerError) as error:
            self.failed_outputs.append(f"sweep CSV {csv_path}: {reason(error, csv_path.parent)}")
            return
        drawn = sum(r.sweep_plots for r in self.results)
        self.say(f"wrote {csv_path} ({len(rows):,} sweep rows) and {drawn} plot(s) in {plots}")

    def empty_earlier_sweep(self) -> None:
        """An earlier run's ``<out>_sweep.csv`` beside this run's CSV is emptied to its header:
        left, it would pair this CSV with the sweep of other points. Said, as its plots left in
        ``<out>_sweep/`` are; a failure is a failed output (exit 2)."""
        if self.stream:  # standard output, a pipe or a device: nothing is written beside it
            return
        csv_path, plots = sweep_paths(self.target)[0], sweep_paths(self.args.out)[1]
        if not csvio.holds_sweep(csv_path):
            return
        try:
            files.replace_atomically(str(csv_path), csvio.format_sweep_rows([]).encode("utf-8"))
        except (OSError, GoniometerError) as error:
            self.failed_outputs.append(f"sweep CSV {csv_path}: {reason(error, csv_path.parent)}")
            return
        self.say(
            f"emptied {csv_path} to its header: it held an earlier run's radius sweep and this "
            f"run made none (the plots in {plots} are an earlier run's)"
        )

    def unmeasured(self, task, message: str):
        """A task's row without a measurement, saying why (a stopped run, a failed worker)."""
        name = self.sources[task.mesh].name if task.mesh >= 0 else task.mesh_name
        return error_row(task, name, message, self.units)

    def add_unmeasured(self, tasks, message: str) -> None:
        """Give each of ``tasks`` without a row one saying why it has no measurement."""
        with self.lock:
            for task in tasks:
                if task.index not in self.rows:
                    self.rows[task.index] = self.unmeasured(task, message)

    def say_why_edges_stopped(self, mesh: int, message: str) -> None:
        """Make the edge rows of mesh ``mesh`` that say the run was stopped before them say
        ``message`` instead: its worker was stopped alone, and the run went on."""
        with self.lock:
            self.edges_by_mesh[mesh] = tuple(
                [_stopped_saying(row, message) for row in rows]
                for rows in self.edges_by_mesh.get(mesh, ([], []))
            )

    def unmeasured_edges(self, mesh: int, message: str, search: str = "") -> tuple[list, list]:
        """The station rows and summary rows of the edges of mesh ``mesh`` when none of them was
        measured, saying why (``message``: a stopped run, a worker that failed its mesh), and
        its ``--find-edges`` row, saying ``search`` (default ``message``)."""
        source = self.sources[mesh]
        return unmeasured_mesh_edges(source, self.options, message, self.units, search=search)

    def finish(self, completed: bool = True) -> int:
        """Write the CSV (and the files beside it) with every row, those not measured saying
        why, and say what the run did; returns the exit status. ``completed``: the run was
        neither stopped nor failed, so its CSV replaces an earlier ``--out`` (else it stays in
        the side file, and the earlier one as it was)."""
        if completed:
            self.target = self.args.out
        # Locked: a slot thread that outlived a stop's wait (run_workers) may still add rows.
        with self.lock:
            missing = [t for t in self.tasks if t.index not in self.rows]
            for task in missing:  # e.g. a worker that could not even start
                self.rows[task.index] = self.unmeasured(task, STOPPED)
            for mesh in self.meshes:  # a mesh the run never reached, or lost with its worker
                if mesh not in self.edges_by_mesh:
                    stations, summaries = self.unmeasured_edges(mesh, STOPPED_EDGE, STOPPED_SEARCH)
                    self.edges_by_mesh[mesh] = (
                        [csvio.writable_row(row) for row in stations],
                        [csvio.writable_row(row) for row in summaries],
                    )
            try:
                self.write_csv()
            except csvio.SummaryWriteError as error:
                self.recover_summary(error)
                return 2
            except (OSError, GoniometerError) as error:
                self.recover_csv(error)
                return 2
        if self.args.sweep:
            self.write_sweep_csv()
        else:
            self.empty_earlier_sweep()
        if completed and not self.stream:
            for problem in remove_partial(self.args.out):
                self.say(f"could not remove a stopped run's partial results {problem}")
        failed = [(i, row) for i, row in sorted(self.rows.items()) if row.error]
        failed_edges = [row for row in self.station_rows if row.error]
        measured = len(self.rows) - len(failed)
        elapsed = time.perf_counter() - self.started
        load = sum(r.load_seconds for r in self.results)
        prepare = sum(r.prepare_seconds for r in self.results)
        measuring = sum(r.measure_seconds for r in self.results)
        tried = sum(r.measured + r.failed for r in self.results if r.measure_seconds > 0)
        rate = tried / measuring if measuring > 0 else 0.0
        edge_rows = self.profiled_edges
        if self.rows or not self.edge_rows:
            self.say(
                f"{measured:,} measured, {len(failed):,} failed, {len(self.rows):,} points on "
                f"{self.total_meshes:,} mesh(es) in {elapsed:.1f} s"
            )
        else:  # edges only: say what was done, not "0 measured"
            stations = sum(edge.n_stations or 0 for edge in edge_rows)
            self.say(
                f"{len(edge_rows):,} edge(s) profiled ({stations:,} stations), "
                f"{len(failed_edges):,} failed, on {self.total_meshes:,} mesh(es) in {elapsed:.1f} s"
            )
        per = f" per process, {self.jobs} processes" if self.jobs > 1 else ""
        speed = (
            f", measuring {measuring:.2f} s: {rate:,.0f} measurements/s{per} (import excluded)"
            if tried
            else ""  # no points: the edges' time is in the run's total
        )
        self.say(f"mesh import {load:.1f} s, surface preparation {prepare:.1f} s{speed}")
        by_index = {t.index: t for t in self.tasks}
        self.say_flagged(by_index)
        self.say_agreement()
        self.say_edge_agreement()
        for index, row in failed[:10]:
            task = by_index[index]
            where = f"row {task.source_row}" if task.source_row else f"point {task.number}"
            self.say(f"  failed: {where} on {row.mesh_name!r}: {row.error}")
        if len(failed) > 10:
            self.say(f"  ... and {len(failed) - 10} more failed rows (see the error column)")
        for edge in edge_rows:
            self.say(
                f"edge {edge.edge_number} on {edge.mesh_name!r}: {edge.n_stations} stations every "
                f"{edge.spacing:g} over {edge.length:.4g}: mean {edge.mean:.2f}° "
                f"(SD {sd_text(edge.std)}, min {edge.min:.2f}°, max {edge.max:.2f}°), "
                f"pooled {edge.pooled_angle:.2f}°"
                + (
                    f"; the path crosses no ridge at arc lengths {edge.flat_spans}"
                    if edge.flat_spans
                    else ""
                )
            )
        for row in failed_edges[:10]:
            if is_search_row(row):
                what = "finding edges"
            else:
                what = "an edge" if row.edge_number is None else f"edge {row.edge_number}"
            self.say(f"  failed: {what} on {row.mesh_name!r}: {row.error}")
        if len(failed_edges) > 10:
            self.say(f"  ... and {len(failed_edges) - 10} more failed edges (see the error column)")
        if self.edge_rows or failed_edges:
            self.say(f"wrote {csvio.edges_path_for(self.target)}")
        for message in self.bad_files:
            self.say(f"  unreadable mesh: {message}")
        for line in self.passed_over:
            self.say(line)
        nothing = [
            self.sources[m].name for m in sorted(r.mesh for r in self.results if r.found_edges == 0)
        ]
        if nothing:
            self.say(
                f"--find-edges found no break edge on {len(nothing)} mesh(es), which have no "
                f"edge rows: {bounded_list(nothing)}"
            )
        unswept = self.unswept_sites()
        if unswept:
            self.say(
                f"--sweep measured no radius at {unswept} site(s) (see the sweep CSV's error "
                "column)"
            )
        if self.target != self.args.out:
            self.say(
                f"the run did not complete: {self.args.out} is kept as it was, with the earlier "
                f"results; this run's results so far are in {self.target}"
            )
        else:
            where = "standard output" if self.args.out == files.STDOUT else self.args.out
            self.say(f"wrote the CSV to {where}")
        return batchplan.exit_code(len(failed) + len(failed_edges) + unswept, len(self.bad_files))

    def unswept_sites(self) -> int:
        """How many sites of ``--sweep`` have no radius measured (each radius refused)."""
        angle = csvio.SWEEP_COLUMNS.index("Angle")
        measured: dict[int, bool] = {}
        for index, cells in self.sweep_rows:
            measured[index] = measured.get(index, False) or bool(cells[angle])
        return sum(1 for any_radius in measured.values() if not any_radius)


def _stopped_saying(row, message: str):
    """``row``, or, if its error says the run was stopped before it, a copy saying ``message``."""
    error = row.error or ""
    for stopped in (STOPPED_EDGE, STOPPED_SEARCH):
        if stopped in error:
            return dataclasses.replace(row, error=error.replace(stopped, message))
    return row


def what_failed(error, out) -> str:
    """The file a failed CSV write did not write, and why: the CSV itself, or (a
    :class:`csvio.SummaryWriteError`) only the edge summary beside it."""
    if isinstance(error, csvio.SummaryWriteError):
        return (
            f"the edge summary {error.summary_path}: {reason(error.cause)} (the CSV {out} was "
            "written)"
        )
    return f"the CSV to {out}: {reason(error)}"


def run_batch(args, file_ready: bool = False) -> tuple[int, Run | None]:
    """Run a batch from parsed arguments; returns the exit status and the run's results.

    ``file_ready``: the caller has already opened the file to measure in (and activated the
    extension), as the demo does; otherwise the .blend among the inputs is opened here.
    """
    check_outputs(args)  # before anything is read or written
    blend = ""
    if file_ready:
        inputs = list(args.inputs)
    else:
        inputs, blend = start_file(list(args.inputs))
        extension.activate()
    bp = batchplan
    sources = blend_objects(list(args.object), blend) + file_sources(inputs)
    if not sources:
        raise UsageError("no mesh given: name mesh files, folders, or a .blend with --object.")
    seen = {}
    for source in sources:
        if source.name in seen:
            raise UsageError(f"two inputs are both named {source.name!r}: rename one.")
        seen[source.name] = source
    replayed = 0  # rows of a --points file, in order: task i is its row i
    replayed_export = False
    passed_over = []  # the summary's lines on input rows not measured again
    try:
        if args.at:
            tasks = bp.plan_points(
                len(sources),
                args.at,
                radius=args.radius,
                lam=args.lam,
                patch=args.patch,
                rule=args.rule,
            )
        elif not args.points:
            tasks = []  # edges only
        else:
            try:
                failed = []  # a batch run's failed rows, passed over: said in the summary
                rows = csvio.read_replication_csv(Path(args.points), failed)  # a path, whatever
                if failed:
                    passed_over.append(failed_rows_line(args.points, failed, edges=False))
            except OSError as error:
                raise UsageError(f"{args.points}: {error.strerror or error}") from None
            replayed = len(rows)
            replayed_export = csvio.read_from_export(rows)
            tasks = bp.plan_rows(
                [s.names for s in sources],
                rows,
                radius=args.radius,
                lam=args.lam,
                patch=args.patch,
                ignore_mesh_names=args.ignore_mesh_names,
                source=f"'{Path(args.points).name}'",
                rule=args.rule,
            )
        if args.shard:
            k, n = bp.parse_shard(args.shard)
            tasks = bp.shard(tasks, k, n)
    except GoniometerError as error:
        raise UsageError(str(error)) from None
    edges = edge_specs(args, sources, passed_over)
    groups = {mesh: ts for mesh, ts in bp.by_mesh(tasks).items() if mesh >= 0}
    if edges or args.find_edges:  # every mesh with edges is measured, with or without points
        groups = {
            mesh: groups.get(mesh, [])
            for mesh in range(len(sources))
            if mesh in groups
            or args.find_edges
            or any(spec_applies(spec, sources[mesh]) for spec in edges)
        }
    stems, renamed = files.picture_names([source.name for source in sources])
    units = args.units or ("none" if not blend else None)
    set_units(bpy.context.scene, units)
    make_folders(args)
    options = {
        "render": str(Path(args.render).resolve()) if args.render else "",
        "render_size": list(args.render_size),
        "render_samples": args.render_samples,
        "render_views": args.render_views.upper(),
        "render_edge_ends": args.render_edge_ends,
        "quiet": bool(args.quiet),
        "save_blend": bool(args.save_blend),
        "units": units,
        "units_given": bool(args.units),  # else each mesh takes the unit its CSV rows name
        "stability": bool(args.stability),
        "rule": args.rule,  # of the edge stations; the points' rule is each task's own
        "sweep": [*args.sweep[:2], int(args.sweep[2])] if args.sweep else None,
        "sweep_plots": str(sweep_paths(args.out)[1]) if args.sweep else "",
        "edges": edges,
        "find_edges": find_options(args),
        "picture_names": stems,
        "inputs": input_files(args),
        "plots": str(Path(args.out).absolute().with_name(Path(args.out).stem))
        if edges or args.find_edges
        else "",
    }
    if args.sweep:
        sweep_paths(args.out)[1].mkdir(parents=True, exist_ok=True)
    run = Run(args, sources, tasks, groups, options)
    run.passed_over = passed_over
    run.replayed = replayed
    run.replayed_export = replayed_export
    for note in renamed:
        run.say(f"note: {note}")
    if args.shard and not args.quiet:
        run.say(f"shard {args.shard}: {len(tasks):,} point(s) on {len(groups)} mesh(es)")
    if not run.stream:
        try:
            run.write_csv()  # the header now: a place that cannot be written fails here
        except (OSError, GoniometerError) as error:
            raise UsageError(f"could not write {what_failed(error, args.out)}") from None

    parallel = args.jobs > 1 and len(groups) > 1 and not blend
    if args.jobs > 1 and blend and not args.quiet:
        run.say("a .blend input is measured in this process (--jobs applies to mesh files only)")
    folder = tempfile.mkdtemp(prefix="vg-batch-") if parallel else ""
    kept = []  # objects measured in this process, kept for --save-blend
    pictures = bool(args.render or args.sweep or edges or args.find_edges)  # after the rows
    completed = False  # neither stopped nor failed: the CSV may replace an earlier --out
    try:
        try:
            if parallel:
                plan = {
                    "folder": folder,
                    "parent_session": bpy.app.tempdir,  # removed by the workers if this dies
                    # A worker still starting when this dies would take its new parent for it.
                    "parent": os.getpid(),
                    "sources": [dataclasses.asdict(s) for s in sources],
                    "tasks": {
                        str(m): [dataclasses.asdict(t) for t in ts] for m, ts in groups.items()
                    },
                    "options": options,
                    "pictures": pictures,
                }
                run.jobs = min(args.jobs, len(groups))
                run_workers(run, groups, plan, args.jobs)
            else:
                rows_ready = functools.partial(run.add, pictures_follow=pictures)
                for mesh, mesh_tasks in groups.items():
                    progress = functools.partial(run.progress, mesh)
                    result = safe_measure_mesh(
                        mesh, sources[mesh], mesh_tasks, options, progress, rows_ready
                    )
                    run.pictures_done(result)
                    if args.save_blend or not sources[mesh].path:
                        kept.append(result.object_name)
                    elif result.object_name:
                        forget(result.object_name)
            completed = not stopping.requested()  # a stop a Blender handler swallowed too
        finally:
            code = run.finish(completed)  # also after an error or Ctrl-C: write what was measured
        stopping.check()  # a stop a Blender handler swallowed: the run ends as stopped
        if args.save_blend:
            if parallel:
                objects = append_objects(run.results)
            else:
                objects = [bpy.data.objects.get(name) for name in kept if name]
            try:
                save_blend(args.save_blend, objects)
            except (RuntimeError, OSError) as error:
                where = Path(args.save_blend).resolve().parent
                run.failed_outputs.append(f".blend {args.save_blend}: {reason(error, where)}")
            else:
                run.say(f"wrote {args.save_blend}")
    finally:
        if folder:
            shutil.rmtree(folder, ignore_errors=True)
    if args.render:
        rendered = sum(1 for r in run.results if r.render)
        run.say(f"wrote {rendered} measurement map(s) to {args.render}")
    for message in run.failed_outputs:
        run.say(f"  could not write the {message}")
    if run.failed_outputs:
        code = max(code, 2)  # the CSV is complete, but an output asked for is missing
    stopping.check()  # stopped while the .blend was saved (its handlers swallow the stop)
    return code, run
