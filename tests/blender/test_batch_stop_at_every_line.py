"""A batch run's stop (Ctrl-C) loses no point already measured, wherever it lands.

A real SIGINT, handled by the run's own stop handler, is sent to this process at each line of
``measure_mesh`` and ``_measure_points``, the code that measures and records a mesh's points, in
turn (a tracer sees the line run and sends the signal there); then of the code that measures its
edges and its radius sweeps. CI once caught a stop landing on a line of the record loop outside
its guard: the whole mesh's rows were written as "not measured" although 1,057 of them had been
measured. Each edge the stop comes before must have a row saying so.

Oracles, independent of the code under test: how many times the measuring step returned (seen by
the tracer) and the measurements Blender holds on the object afterwards.
"""

from __future__ import annotations

import importlib
import signal
import sys

import bpy
import numpy as np
import pytest
from bpy_helpers import mesh_object

from vg_addon.synthetic_meshes import wedge

STOPPED_EDGE = "the run was stopped before this edge"  # a stopped edge's error says it
EDGE = {"points": [[-0.6, 0.0, 0.0], [0.6, 0.0, 0.0]], "spacing": 0.15, "radius": 0.3, "lam": 2.0,
        "patch": "euclidean", "mesh_name": "", "note": ""}  # fmt: skip
TASKS = 90  # two blocks of the run's 64: the stop comes while the second block is under way
FIRST_BLOCK_DONE = 66  # measurements returned before the signal is sent


def _code_lines(function) -> list[int]:
    """The lines of ``function`` and of the functions defined inside it."""
    lines, codes = set(), [function.__code__]
    while codes:
        code = codes.pop()
        lines |= {line for _, _, line in code.co_lines() if line and line > code.co_firstlineno}
        codes += [const for const in code.co_consts if hasattr(const, "co_lines")]
    return sorted(lines)


class _SignalAtLine:
    """A tracer that sends SIGINT to this process the first time ``line`` of ``filename`` runs
    once the measuring step has returned :data:`FIRST_BLOCK_DONE` times; counts those returns."""

    def __init__(self, filename: str, line: int):
        self.filename, self.line = filename, line
        self.returned = 0
        self.sent = False
        self.returned_when_sent = None

    def __call__(self, frame, event, arg):
        if frame.f_code.co_filename != self.filename:
            return None
        return self._local

    def _local(self, frame, event, arg):
        if event == "return" and frame.f_code.co_name == "_measure_task":
            self.returned += 1
        elif (
            event == "line"
            and not self.sent
            and frame.f_lineno == self.line
            and self.returned >= FIRST_BLOCK_DONE
        ):
            self.sent = True
            self.returned_when_sent = self.returned
            signal.raise_signal(signal.SIGINT)
        return self._local


def _measure_under(tracer, stop_handler, measure, sources, obj, tasks, options):
    """``measure_mesh`` on ``obj`` with ``tracer`` watching and the run's stop handler set;
    returns whether it was stopped and the results it handed over."""
    handed = []
    stop_handler()
    earlier_tracer = sys.gettrace()  # a debugger's or coverage's, put back after
    sys.settrace(tracer)
    try:
        measure.measure_mesh(0, sources.MeshSource(obj.name), tasks, options, None, handed.append)
        stopped = False
    except KeyboardInterrupt:
        stopped = True
    finally:
        sys.settrace(earlier_tracer)
    return stopped, handed


@pytest.fixture
def stop_handler(vg):
    """The run's own stop handler on SIGINT and SIGTERM (pytest's put back after)."""
    stopping = importlib.import_module(f"{vg.__name__}.batch.stopping")
    saved = signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM)

    def install():
        stopping._requested = False  # a fresh run's state
        stopping.handle_stop_signals()

    yield install
    signal.signal(signal.SIGINT, saved[0])
    signal.signal(signal.SIGTERM, saved[1])
    stopping._requested = False


def test_a_stop_at_any_line_of_the_points_loop_keeps_every_point_measured(
    vg, stop_handler, tmp_path
):
    measure = importlib.import_module(f"{vg.__name__}.batch.measure")
    sources = importlib.import_module(f"{vg.__name__}.batch.sources")
    batchplan = importlib.import_module(f"{vg.__name__}.vg_addon.workflow.batchplan")
    shape = wedge(80.0, n=20, irregular=True, seed=2)
    tasks = [
        batchplan.Task(
            index=k,
            mesh=0,
            center=(float(x), 0.0, 0.0),
            radius=0.3 if k % 9 else 1e-9,  # every ninth fails (too few vertices): a row too
            lam=2.0,
            patch="euclidean",
            number=k + 1,
        )
        for k, x in enumerate(np.linspace(-0.6, 0.6, TASKS))
    ]
    functions = [measure.measure_mesh]
    if hasattr(measure, "_measure_points"):
        functions.append(measure._measure_points)
    targets = [line for function in functions for line in _code_lines(function)]
    # Two edges after the points: a stop before them gives each a row saying so.
    options = {"edges": [dict(EDGE) for _ in range(2)], "plots": str(tmp_path / "o")}
    stopped_at = []
    for line in targets:
        obj = mesh_object("Wedge", shape.points, shape.triangles)
        tracer = _SignalAtLine(measure.__file__, line)
        stopped, handed = _measure_under(
            tracer, stop_handler, measure, sources, obj, tasks, options
        )
        assert stopped == tracer.sent, (line, stopped, tracer.sent)
        assert len(handed) == 1, (line, len(handed))  # the rows are handed over once
        result = handed[0]
        # Every point measured has its row, once; a stop is acted on before the next point.
        assert len(result.rows) == tracer.returned, (line, len(result.rows), tracer.returned)
        if tracer.sent and tracer.returned_when_sent < len(tasks):
            assert tracer.returned <= tracer.returned_when_sent + 1, (line, tracer.returned)
        measured = [row for _, row in result.rows if not row.error]
        points = [item for item in obj.vg.measurements if not item.edge_number]  # no stations
        recorded = sorted(item.angle for item in points)
        assert sorted(row.angle for row in measured) == pytest.approx(recorded, abs=1e-4), line
        assert len(measured) == result.measured
        assert len(result.edge_rows) == 2, (line, result.edge_rows)
        stopped_edges = [row for row in result.edge_rows if row.error]
        assert len(stopped_edges) == 2 - len(obj.vg.edges), (line, stopped_edges)
        assert all(STOPPED_EDGE in row.error for row in stopped_edges), (line, stopped_edges)
        assert sum(bool(row.error) for row in result.station_rows) == len(stopped_edges), line
        if tracer.sent:
            stopped_at.append(line)
        bpy.data.objects.remove(obj)
    # The signal landed in both loops (measuring and recording), not only between meshes.
    assert len(stopped_at) >= 10, stopped_at


class _SignalAtEdgeLine(_SignalAtLine):
    """Sends SIGINT at ``line`` once ``obj`` holds an edge; ``returned_when_sent``: how many."""

    def __init__(self, filename: str, line: int, obj):
        super().__init__(filename, line)
        self.obj = obj

    def _local(self, frame, event, arg):
        if event == "line" and not self.sent and frame.f_lineno == self.line:
            recorded = len(self.obj.vg.edges)
            if recorded:
                self.sent = True
                self.returned_when_sent = recorded
                signal.raise_signal(signal.SIGINT)
        return self._local


EDGES = 4


def test_a_stop_at_any_line_of_the_edges_loop_keeps_every_edge_recorded(vg, stop_handler, tmp_path):
    """A stop while a run profiles edges kept none of them: the edges recorded before it were
    handed over only when every edge was done. Now each edge recorded on the object has its
    summary and stations in the rows, each edge not recorded says the run was stopped before it,
    and no edge is recorded after the stop but the one under way."""
    edges_module = importlib.import_module(f"{vg.__name__}.batch.edges")
    measure = importlib.import_module(f"{vg.__name__}.batch.measure")
    sources = importlib.import_module(f"{vg.__name__}.batch.sources")
    shape = wedge(80.0, n=20, irregular=True, seed=2)
    options = {"edges": [dict(EDGE) for _ in range(EDGES)], "plots": str(tmp_path / "o")}
    targets = [
        (function.__code__.co_filename, line)
        for function in (
            edges_module.measure_edges,
            getattr(edges_module, "_measure_edge", None),
            getattr(edges_module, "_record_edge", None),
        )
        if function is not None
        for line in _code_lines(function)
    ]
    stopped_at = []
    for filename, line in targets:
        obj = mesh_object("Wedge", shape.points, shape.triangles)
        tracer = _SignalAtEdgeLine(filename, line, obj)
        stopped, handed = _measure_under(tracer, stop_handler, measure, sources, obj, [], options)
        assert stopped == tracer.sent, (line, stopped, tracer.sent)
        assert len(handed) == 1, (line, len(handed))
        result = handed[0]
        recorded = {edge.number: edge.n_stations for edge in obj.vg.edges}
        summaries = {row.edge_number: row.n_stations for row in result.edge_rows if not row.error}
        assert summaries == recorded, line  # every edge on the object has its summary, and no other
        for number, count in recorded.items():
            assert sum(row.edge_number == number for row in result.station_rows) == count, line
        assert len(result.edge_rows) == EDGES, line  # an edge not recorded has its row, saying why
        for row in result.edge_rows:
            assert not row.error or STOPPED_EDGE in row.error, (line, row.error)
        if tracer.sent:
            assert 1 <= len(recorded) <= tracer.returned_when_sent + 1, (line, len(recorded))
            stopped_at.append(line)
        bpy.data.objects.remove(obj)
    assert len(stopped_at) >= 10, stopped_at


class _SignalAtSweepLine(_SignalAtLine):
    """Sends SIGINT at ``line`` once the run's result holds a swept site."""

    result = None  # the run's result, once a frame of sweep_sites shows it

    def _local(self, frame, event, arg):
        if self.result is None and frame.f_code.co_name == "sweep_sites":
            self.result = frame.f_locals.get("result")
        if (
            event == "line"
            and not self.sent
            and frame.f_lineno == self.line
            and self.result is not None
            and self.result.sweep_rows
        ):
            self.sent = True
            signal.raise_signal(signal.SIGINT)
        return self._local


def test_a_stop_at_any_line_of_the_sweeps_keeps_each_site_whole(vg, stop_handler, tmp_path):
    """``--sweep``: a stop in the middle of a site's radii kept the radii done so far, a site cut
    short in the sweep CSV without a word. Now a site is kept with every radius or not at all."""
    measure = importlib.import_module(f"{vg.__name__}.batch.measure")
    sources = importlib.import_module(f"{vg.__name__}.batch.sources")
    batchplan = importlib.import_module(f"{vg.__name__}.vg_addon.workflow.batchplan")
    shape = wedge(80.0, n=20, irregular=True, seed=2)
    tasks = [
        batchplan.Task(index=k, mesh=0, center=(x, 0.0, 0.0), radius=0.3, lam=2.0,
                       patch="euclidean", number=k + 1)
        for k, x in enumerate((-0.4, -0.2, 0.0, 0.2))
    ]  # fmt: skip
    radii = 6
    options = {"sweep": (0.2, 0.45, radii), "sweep_plots": str(tmp_path)}
    targets = _code_lines(measure.sweep_sites)
    stopped_at = []
    for line in targets:
        obj = mesh_object("Wedge", shape.points, shape.triangles)
        tracer = _SignalAtSweepLine(measure.__file__, line)
        stopped, handed = _measure_under(
            tracer, stop_handler, measure, sources, obj, tasks, options
        )
        assert stopped == tracer.sent and len(handed) == 1, (line, stopped, tracer.sent)
        sites = [index for index, _ in handed[0].sweep_rows]
        assert all(sites.count(index) == radii for index in set(sites)), (line, sites)
        assert sites, line  # the first site, swept before the signal, is kept
        if tracer.sent:
            stopped_at.append(line)
        bpy.data.objects.remove(obj)
    assert len(stopped_at) >= 5, stopped_at


def test_a_stop_inside_a_handler_blender_calls_is_noted_and_acted_on_after(vg, stop_handler, capfd):
    """A stop signal that lands inside a function Blender calls from ``bpy.app.handlers`` (the
    extension's geometry watcher is one) must not be raised there: bpy would print it as an
    error with its traceback and carry on. It is noted, and the run acts on it at its next
    check (before: only Blender's own scripts were recognised as such places)."""
    stopping = importlib.import_module(f"{vg.__name__}.batch.stopping")
    seen = []

    def handler(*args):
        seen.append("in")
        signal.raise_signal(signal.SIGINT)
        seen.append("after")

    stop_handler()
    bpy.app.handlers.depsgraph_update_post.append(handler)
    try:
        bpy.ops.mesh.primitive_cube_add()  # a depsgraph update: Blender calls the handler
    finally:
        bpy.app.handlers.depsgraph_update_post.remove(handler)
        bpy.data.objects.remove(bpy.context.object)
    assert seen[:2] == ["in", "after"], seen
    assert "KeyboardInterrupt" not in capfd.readouterr().err
    assert stopping.requested()
    with pytest.raises(KeyboardInterrupt):
        stopping.check()
