"""``--jobs N``: meshes measured in worker processes, each a Blender or bpy process of its own.

A worker reads mesh indices on stdin, up to the parent's last line ``end``, and, per mesh,
writes its rows as JSON into the run's temporary folder and says ``MARK rows N`` on stdout (the
parent writes them into the CSV at once), draws the mesh's pictures, then writes its whole
result and says ``MARK done N``. A worker that dies while drawing costs the pictures, never the
rows.

Nothing outlives the run: a worker watches its parent and, when the parent is gone (killed, even
with SIGKILL), removes the run's temporary folder and exits; Ctrl-C is the parent's to handle
(workers ignore SIGINT), and an interrupted parent stops its workers (SIGTERM) and waits for them
before it removes the folder, so no worker writes into a folder that is gone. A worker stopped
while it measures a mesh hands over the rows it measured, as a run in one process does, then
quits.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import os
import shutil
import signal
import subprocess
import sys
import threading
import time
from collections import deque
from pathlib import Path
from typing import TYPE_CHECKING, NoReturn

import bpy

from ..vg_addon.formats import csvio
from ..vg_addon.workflow import batchplan
from . import child_process, extension, map_process, stopping
from .blend_file import forget, plot_images
from .measure import MeshResult, safe_measure_mesh, set_units
from .sources import MeshSource
from .stdio import quiet_stdout

if TYPE_CHECKING:
    from .run import Run

PARENT_POLL_SECONDS = 0.2  # how often a worker checks that its parent is still there
STOP_SECONDS = 10.0  # how long a stopped worker may take to end before it is killed
ORPHAN_WAIT_SECONDS = 10.0  # how long a worker whose parent's pipes closed waits to be re-parented
MARK = child_process.MARK  # prefix of the lines a worker sends to its parent on stdout
END = "end"  # the parent's last line to a worker; stdin ending without it means the parent died
_writing = threading.RLock()  # held while a worker writes into the run's folder


def run_workers(run: Run, groups: dict, plan: dict, jobs: int) -> None:
    """Measure the meshes in ``groups`` in up to ``jobs`` worker processes, handing each idle
    worker the next mesh. A worker that dies loses only the mesh it was on; a new one takes
    over the rest."""
    folder = plan["folder"]
    plan_path = str(Path(folder) / "plan.json")
    with open(plan_path, "w", encoding="utf-8") as handle:
        json.dump(plan, handle)
    queue = deque(groups)
    lock = threading.Lock()
    row_type = csvio.MeasurementRow
    processes: set[subprocess.Popen] = set()
    ending = threading.Event()  # the parent is stopping its workers

    def start():
        # Blender makes a session folder in the temporary directory of every process: the
        # workers' go inside the run's folder, so removing it removes them, however one ended.
        process = child_process.start(["--worker", plan_path], folder)
        with lock:
            processes.add(process)
            if ending.is_set():  # started as the run was stopped: stopped with the others
                process.terminate()
        return process

    rows_in: set[int] = set()  # meshes whose rows the parent has (their pictures may follow)

    def fail(mesh: int, message: str) -> None:
        name = run.sources[mesh].name
        result = MeshResult(mesh=mesh, failed=len(groups[mesh]))
        if mesh in rows_in:  # the rows are written: only the pictures are lost
            result = next(r for r in run.results if r.mesh == mesh)
            if _would_draw(result, plan["options"]):
                result.picture_errors.append(f"pictures of {name}: {message}")
            # A worker stopped alone (SIGTERM to it, the run going on) hands over the rows it
            # measured: the others say why they have none (its edges not reached said the run
            # was stopped: a worker cannot tell who sent the signal).
            run.add_unmeasured(groups[mesh], message)
            run.say_why_edges_stopped(mesh, message)
        else:
            result.rows = [(t.index, run.unmeasured(t, message)) for t in groups[mesh]]
            result.station_rows, result.edge_rows = run.unmeasured_edges(mesh, message)
            run.add(result)
        run.pictures_done(result)

    def load(mesh: int, suffix: str) -> MeshResult:
        with open(Path(folder) / f"mesh-{mesh}{suffix}", encoding="utf-8") as handle:
            return MeshResult.from_json(json.load(handle), row_type)

    def slot():
        process = None
        while True:
            with lock:
                if not queue or ending.is_set():
                    break
                mesh = queue.popleft()
            if process is None:
                try:
                    process = start()
                except OSError as error:
                    fail(mesh, f"could not start a worker process: {error}")
                    continue
            finished = False
            try:
                process.stdin.write(f"{mesh}\n")
                process.stdin.flush()
                for line in process.stdout:
                    at = line.find(MARK)
                    if at < 0:
                        continue
                    words = line[at + len(MARK) :].split()
                    if words[:1] == ["progress"]:
                        run.progress(mesh, int(words[2]))
                    elif words[:1] == ["rows"]:
                        run.add(load(mesh, ".rows.json"), pictures_follow=plan["pictures"])
                        rows_in.add(mesh)
                    elif words[:1] == ["done"]:
                        finished = True
                        break
            except (OSError, ValueError):  # a broken pipe, or a result file gone or damaged
                if process.poll() is None:  # the worker waits for its next mesh: end it
                    process.kill()
            if finished:
                try:
                    result = load(mesh, ".json")
                except (OSError, ValueError) as error:
                    fail(mesh, f"the worker's result could not be read back: {error}")
                    continue
                if mesh not in rows_in:
                    run.add(result)
                run.pictures_done(result)
                continue
            code = process.wait()
            process = None
            # A stop to the whole process group reaches the workers as it reaches the run: one
            # that ends first is not a worker stopped alone.
            if ending.is_set() or stopping.requested():
                break  # the run is being stopped: rows not handed over are "not measured"
            fail(
                mesh,
                f"the worker process measuring this mesh stopped (exit status {code}); see its "
                "messages above. The other meshes are not affected.",
            )
        if process is not None:
            with contextlib.suppress(OSError):
                process.stdin.write(f"{END}\n")
            with contextlib.suppress(OSError):
                process.stdin.close()
            process.wait()

    # Each slot says when it is done with an event, not by its thread's join: under Python 3.11
    # a join that Ctrl-C interrupts marks the thread ended while it still runs, so waiting on it
    # again returned at once and the CSV was written while a worker's rows were still coming in
    # (measured: rows a stopped worker had handed over written as "not measured").
    done = [threading.Event() for _ in range(min(jobs, len(queue)))]

    def run_slot(finished: threading.Event) -> None:
        try:
            slot()
        finally:
            finished.set()

    for finished in done:
        threading.Thread(target=run_slot, args=(finished,), daemon=True).start()
    try:
        for finished in done:
            finished.wait()
    except BaseException:
        # Ctrl-C (or any error) in the parent: stop every worker before the caller writes the
        # CSV and removes the temporary folder they write into.
        with lock:  # a worker started from now on is stopped as it starts (start())
            ending.set()
            running = list(processes)
        for process in running:
            with contextlib.suppress(OSError):
                process.terminate()
        for process in running:
            try:
                process.wait(timeout=STOP_SECONDS)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait()
        for finished in done:  # they end once their worker has: none may outlive the run
            finished.wait(timeout=STOP_SECONDS)
        raise


def _quit(folders, status: int) -> NoReturn:
    map_process.kill()  # a map being rendered: its child ends with this worker, at once
    # Never in the middle of this worker's own write into the folder: a file made after the
    # removal would be left behind. Reentrant, for SIGTERM arriving during such a write.
    _writing.acquire(timeout=STOP_SECONDS)
    for folder in folders:
        if folder:
            shutil.rmtree(folder, ignore_errors=True)
    os._exit(status)


class Parent:
    """In a worker: the process that started it (``pid``, from the plan: a worker whose parent
    died while it was starting would otherwise take its new parent for it), and what the
    worker does when it is gone.

    When the parent is gone (killed, even with SIGKILL, so it cannot clean up after itself),
    the worker removes the run's temporary folder (with its own Blender session folder inside)
    and the parent's Blender session folder, and exits at once. It learns of it from whichever
    comes first: a thread that checks the parent every :data:`PARENT_POLL_SECONDS`, the end of
    stdin without the parent's last word (:data:`END`), or a broken pipe when it reports.
    SIGTERM (the parent stopping its workers) stops the worker as a stop signal stops a run
    (``stopping.on_stop_signal``): the rows of the mesh it measures are handed over, then
    :func:`worker_main` quits without a traceback.
    """

    def __init__(self, pid: int, folder: str, parent_session: str):
        self.pid = pid
        self.folders = [folder, parent_session]
        signal.signal(signal.SIGTERM, stopping.on_stop_signal)
        self._stop = threading.Event()
        self._watcher = threading.Thread(target=self._watch, name="vg-parent-watch", daemon=True)
        self._watcher.start()

    def _watch(self) -> None:
        while not self._stop.wait(PARENT_POLL_SECONDS):
            if os.getppid() != self.pid:
                _quit(self.folders, 1)

    def stop_watching(self) -> None:
        """Call before the worker exits normally (a thread still running at exit makes some
        bpy versions, e.g. 4.5, hang in their shutdown)."""
        self._stop.set()
        self._watcher.join()

    def tell(self, message: str) -> None:
        """Send ``message`` to the parent on stdout; a pipe that broke means it is gone."""
        try:
            print(f"{MARK} {message}", flush=True)
        except OSError:
            self.gone()

    def gone(self) -> NoReturn:
        """The parent's pipes closed: it is ending. The kernel closes a dying process's files
        before it hands its children to another parent, so wait for that, then clean up."""
        deadline = time.monotonic() + ORPHAN_WAIT_SECONDS
        while os.getppid() == self.pid and time.monotonic() < deadline:
            time.sleep(0.01)
        if os.getppid() != self.pid:
            _quit(self.folders, 1)
        _quit([bpy.app.tempdir], 1)  # the parent lives and left this worker: its folder is its own


def _would_draw(result: MeshResult, options: dict) -> bool:
    """Whether the mesh whose rows are ``result`` has pictures to draw after them: its map
    (``--render``), a radius sweep's plots, or an edge profiled."""
    profiled = any(not row.error for row in result.edge_rows)
    return bool(options.get("render") or result.sweep_rows or profiled)


def worker_main(plan_path: str) -> int:
    """A worker: measure the meshes whose indices arrive on stdin, one JSON result each."""
    # Ctrl-C in a terminal reaches the whole process group; the parent handles it and stops
    # the workers itself.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    with open(plan_path, encoding="utf-8") as handle:
        plan = json.load(handle)
    parent = None
    try:
        parent = Parent(plan["parent"], plan["folder"], plan.get("parent_session", ""))
        return _measure_from_stdin(plan, parent)
    except KeyboardInterrupt:  # stopped: the rows of the mesh measured, if any, are handed over
        _quit([bpy.app.tempdir], 143)
    finally:
        if parent is not None:
            parent.stop_watching()


def _measure_from_stdin(plan: dict, parent: Parent) -> int:
    bpy.ops.wm.read_homefile(use_empty=True)
    extension.activate()
    set_units(bpy.context.scene, plan["options"]["units"])
    sources = [MeshSource(**s) for s in plan["sources"]]
    tasks = {int(k): [batchplan.Task(**t) for t in v] for k, v in plan["tasks"].items()}
    for t in tasks.values():
        for i, task in enumerate(t):
            requested = None if task.requested is None else tuple(task.requested)
            t[i] = dataclasses.replace(task, center=tuple(task.center), requested=requested)
    options = plan["options"]
    for line in sys.stdin:
        line = line.strip()
        if line == END:
            return 0
        if not line:
            continue
        mesh = int(line)

        def progress(done, mesh=mesh):
            parent.tell(f"progress {mesh} {done}")

        def send_rows(result, mesh=mesh):
            if _write_result(Path(plan["folder"]) / f"mesh-{mesh}.rows.json", result):
                parent.tell(f"rows {mesh}")

        result = safe_measure_mesh(mesh, sources[mesh], tasks[mesh], options, progress, send_rows)
        if options.get("save_blend") and result.object_name:
            obj = bpy.data.objects.get(result.object_name)
            if obj is not None:
                path = str(Path(plan["folder"]) / f"mesh-{mesh}.blend")
                with _writing, quiet_stdout():
                    bpy.data.libraries.write(path, {obj, *plot_images(obj)})
                result.blend = path
        if result.object_name:
            forget(result.object_name)
        if not _write_result(Path(plan["folder"]) / f"mesh-{mesh}.json", result):
            return 1  # the run is over and its folder removed: nobody waits for this result
        parent.tell(f"done {mesh}")
        stopping.check()  # a stop a Blender handler swallowed: do not wait for another mesh
    parent.gone()  # stdin ended without the parent's last word


def _write_result(target: Path, result: MeshResult) -> bool:
    """Write ``result`` as JSON to ``target`` in one step; False when the run's folder is gone."""
    temporary = target.with_name(target.name + ".tmp")
    text = json.dumps(result.to_json())
    try:
        with _writing:
            temporary.write_text(text, encoding="utf-8")
            temporary.replace(target)
    except FileNotFoundError:
        return False
    return True
