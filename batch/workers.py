"""``--jobs N``: meshes measured in worker processes, each a Blender or bpy process of its own.

A worker reads mesh indices on stdin and, per mesh, writes its result as JSON into the run's
temporary folder, then a line ``MARK done N`` on stdout.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import os
import subprocess
import sys
import threading
from collections import deque
from pathlib import Path
from typing import TYPE_CHECKING

import bpy

from ..vg_addon.formats import csvio
from ..vg_addon.workflow import batchplan
from . import extension
from .blend_file import forget
from .measure import MeshResult, error_row, safe_measure_mesh, set_units
from .sources import MeshSource
from .stdio import quiet_stdout

if TYPE_CHECKING:
    from .run import Run

# Testing aid: a worker process aborts, as a native crash would, when it starts on the mesh named
# by this environment variable.
ABORT_VARIABLE = "VG_BATCH_ABORT_ON_MESH"
MARK = "@@vg-batch@@"  # prefix of the lines a worker sends to its parent on stdout


def worker_command(plan_path: str) -> list[str]:
    """The command line of a worker: the same Blender binary, or the same Python with bpy."""
    script = str(extension.package_folder() / "vg_batch.py")
    if bpy.app.binary_path:
        return [
            bpy.app.binary_path,
            "-b",
            "--factory-startup",
            "-noaudio",
            "--python",
            script,
            "--",
            "--worker",
            plan_path,
        ]
    return [sys.executable, script, "--worker", plan_path]


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

    # One BLAS/OpenMP thread per worker: the workers are the parallelism.
    env = dict(os.environ)
    for name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        env.setdefault(name, "1")

    def start():
        return subprocess.Popen(
            worker_command(plan_path),
            env=env,
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
            encoding="utf-8",
            errors="replace",
            bufsize=1,
        )

    def fail(mesh: int, message: str) -> None:
        name = run.sources[mesh].name
        result = MeshResult(mesh=mesh, failed=len(groups[mesh]))
        result.rows = [(t.index, error_row(t, name, message, run.units)) for t in groups[mesh]]
        run.add(result)

    def slot():
        process = None
        while True:
            with lock:
                if not queue:
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
                    elif words[:1] == ["done"]:
                        finished = True
                        break
            except (BrokenPipeError, OSError):
                pass
            if finished:
                with open(Path(folder) / f"mesh-{mesh}.json", encoding="utf-8") as handle:
                    run.add(MeshResult.from_json(json.load(handle), row_type))
                continue
            code = process.wait()
            process = None
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
    for thread in threads:
        thread.join()


def worker_main(plan_path: str) -> int:
    """A worker: measure the meshes whose indices arrive on stdin, one JSON result each."""
    bpy.ops.wm.read_homefile(use_empty=True)
    extension.activate()
    with open(plan_path, encoding="utf-8") as handle:
        plan = json.load(handle)
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
        if os.environ.get(ABORT_VARIABLE) == sources[mesh].name:
            os.abort()  # a stand-in for a crash in native code, to test crash isolation

        def progress(done, mesh=mesh):
            print(f"{MARK} progress {mesh} {done}", flush=True)

        result = safe_measure_mesh(mesh, sources[mesh], tasks[mesh], options, progress)
        if options.get("save_blend") and result.object_name:
            obj = bpy.data.objects.get(result.object_name)
            if obj is not None:
                path = str(Path(plan["folder"]) / f"mesh-{mesh}.blend")
                with quiet_stdout():
                    bpy.data.libraries.write(path, {obj})
                result.blend = path
        if result.object_name:
            forget(result.object_name)
        target = Path(plan["folder"]) / f"mesh-{mesh}.json"
        temporary = target.with_suffix(".tmp")
        temporary.write_text(json.dumps(result.to_json()), encoding="utf-8")
        temporary.replace(target)
        print(f"{MARK} done {mesh}", flush=True)
    return 0
