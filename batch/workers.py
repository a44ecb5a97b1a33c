"""``--jobs N``: meshes measured in worker processes, each a Blender or bpy process of its own.

A worker reads mesh indices on stdin and, per mesh, writes its rows as JSON into the run's
temporary folder and says ``MARK rows N`` on stdout (the parent writes them into the CSV at
once), draws the mesh's pictures, then writes its whole result and says ``MARK done N``. A
worker that dies while drawing costs the pictures, never the rows.

Nothing outlives the run: a worker watches its parent and, when the parent is gone (killed, even
with SIGKILL), removes the run's temporary folder and exits; Ctrl-C is the parent's to handle
(workers ignore SIGINT), and an interrupted parent stops its workers before it removes the
folder, so no worker writes into a folder that is gone.
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
from collections import deque
from pathlib import Path
from typing import TYPE_CHECKING

import bpy

from ..vg_addon.formats import csvio
from ..vg_addon.workflow import batchplan
from . import child_process, extension, map_process
from .blend_file import forget, plot_images
from .measure import MeshResult, error_row, safe_measure_mesh, set_units
from .sources import MeshSource
from .stdio import quiet_stdout

if TYPE_CHECKING:
    from .run import Run

PARENT_POLL_SECONDS = 0.2  # how often a worker checks that its parent is still there
STOP_SECONDS = 10.0  # how long a stopped worker may take to end before it is killed
MARK = child_process.MARK  # prefix of the lines a worker sends to its parent on stdout


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
    stopping = threading.Event()

    def start():
        # Blender makes a session folder in the temporary directory of every process: the
        # workers' go inside the run's folder, so removing it removes them, however one ended.
        process = child_process.start(["--worker", plan_path], folder)
        with lock:
            processes.add(process)
        return process

    rows_in: set[int] = set()  # meshes whose rows the parent has (their pictures may follow)

    def fail(mesh: int, message: str) -> None:
        name = run.sources[mesh].name
        result = MeshResult(mesh=mesh, failed=len(groups[mesh]))
        if mesh in rows_in:  # the rows are written: only the pictures are lost
            result = next(r for r in run.results if r.mesh == mesh)
            result.picture_errors.append(f"pictures of {name}: {message}")
        else:
            result.rows = [(t.index, error_row(t, name, message, run.units)) for t in groups[mesh]]
            run.add(result)
        run.pictures_done(result)

    def load(mesh: int, suffix: str) -> MeshResult:
        with open(Path(folder) / f"mesh-{mesh}{suffix}", encoding="utf-8") as handle:
            return MeshResult.from_json(json.load(handle), row_type)

    def slot():
        process = None
        while True:
            with lock:
                if not queue or stopping.is_set():
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
            if stopping.is_set():
                break  # the run is being interrupted: its rows are "not measured"
            fail(
                mesh,
                f"the worker process measuring this mesh stopped (exit status {code}); see its "
                "messages above. The other meshes are not affected.",
            )
        if process is not None:
            with contextlib.suppress(OSError):
                process.stdin.close()
            process.wait()

    threads = [threading.Thread(target=slot, daemon=True) for _ in range(min(jobs, len(queue)))]
    for thread in threads:
        thread.start()
    try:
        for thread in threads:
            thread.join()
    except BaseException:
        # Ctrl-C (or any error) in the parent: stop every worker before the caller writes the
        # CSV and removes the temporary folder they write into.
        stopping.set()
        with lock:
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
        for thread in threads:  # they end once their worker has: none may outlive the run
            thread.join(timeout=STOP_SECONDS)
        raise


def _quit(folders, status: int) -> None:
    map_process.kill()  # a map being rendered: its child ends with this worker, at once
    for folder in folders:
        if folder:
            shutil.rmtree(folder, ignore_errors=True)
    os._exit(status)


def watch_parent(folder: str, parent_session: str):
    """In a worker: when the parent process is gone, remove the run's temporary folder (with
    this worker's Blender session folder inside it) and the parent's Blender session folder,
    and exit at once: a parent killed with SIGKILL cannot clean up after itself. SIGTERM (the
    parent stopping its workers) ends the worker the same way, without a traceback.

    Returns a function that stops the watching; call it before the worker exits normally (a
    thread still running at exit makes some bpy versions, e.g. 4.5, hang in their shutdown).
    """
    parent = os.getppid()
    signal.signal(signal.SIGTERM, lambda signum, frame: _quit([bpy.app.tempdir], 143))
    stop = threading.Event()

    def watch():
        while not stop.wait(PARENT_POLL_SECONDS):
            if os.getppid() != parent:
                _quit([folder, parent_session], 1)

    watcher = threading.Thread(target=watch, name="vg-parent-watch", daemon=True)
    watcher.start()

    def stop_watching():
        stop.set()
        watcher.join()

    return stop_watching


def worker_main(plan_path: str) -> int:
    """A worker: measure the meshes whose indices arrive on stdin, one JSON result each."""
    # Ctrl-C in a terminal reaches the whole process group; the parent handles it and stops
    # the workers itself.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    with open(plan_path, encoding="utf-8") as handle:
        plan = json.load(handle)
    stop_watching = watch_parent(plan["folder"], plan.get("parent_session", ""))
    try:
        return _measure_from_stdin(plan)
    finally:
        stop_watching()


def _measure_from_stdin(plan: dict) -> int:
    bpy.ops.wm.read_homefile(use_empty=True)
    extension.activate()
    set_units(bpy.context.scene, plan["options"]["units"])
    sources = [MeshSource(**s) for s in plan["sources"]]
    tasks = {int(k): [batchplan.Task(**t) for t in v] for k, v in plan["tasks"].items()}
    for t in tasks.values():
        for i, task in enumerate(t):
            t[i] = dataclasses.replace(task, center=tuple(task.center))
    options = plan["options"]
    for line in sys.stdin:
        line = line.strip()
        if not line:
            continue
        mesh = int(line)

        def progress(done, mesh=mesh):
            print(f"{MARK} progress {mesh} {done}", flush=True)

        def send_rows(result, mesh=mesh):
            if _write_result(Path(plan["folder"]) / f"mesh-{mesh}.rows.json", result):
                print(f"{MARK} rows {mesh}", flush=True)

        result = safe_measure_mesh(mesh, sources[mesh], tasks[mesh], options, progress, send_rows)
        if options.get("save_blend") and result.object_name:
            obj = bpy.data.objects.get(result.object_name)
            if obj is not None:
                path = str(Path(plan["folder"]) / f"mesh-{mesh}.blend")
                with quiet_stdout():
                    bpy.data.libraries.write(path, {obj, *plot_images(obj)})
                result.blend = path
        if result.object_name:
            forget(result.object_name)
        if not _write_result(Path(plan["folder"]) / f"mesh-{mesh}.json", result):
            return 1  # the run is over and its folder removed: nobody waits for this result
        print(f"{MARK} done {mesh}", flush=True)
    return 0


def _write_result(target: Path, result: MeshResult) -> bool:
    """Write ``result`` as JSON to ``target`` in one step; False when the run's folder is gone."""
    temporary = target.with_name(target.name + ".tmp")
    try:
        temporary.write_text(json.dumps(result.to_json()), encoding="utf-8")
        temporary.replace(target)
    except FileNotFoundError:
        return False
    return True
