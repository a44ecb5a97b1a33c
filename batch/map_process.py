"""A batch run's measurement maps, rendered in a child process that a stop ends at once.

Cycles renders a view without returning to Python, and bpy swallows the KeyboardInterrupt a
signal handler raises inside a render: a run stopped (Ctrl-C, SIGTERM) while a map renders would
go on for every remaining view and end as if nothing happened. So this process hands each map
to a child process (the same Blender, or the same Python with bpy, started on the first map and
kept for the next ones) and waits for its answer in Python, where a stop signal is handled at
once: the child is killed, the map's hidden folder and the child's temporary folder removed, and
the run ends with the rows it measured. No picture of the stopped map reaches its final name
(each is moved there whole, see ``bridge.measurement_map.MapJob``).

The child gets the object in a one-object .blend (its mesh, side colours and stored
measurements) and the map's settings as one JSON line on its stdin; it answers with one line on
its stdout. It is killed when the process that started it ends, however that ends
(``child_process.end_with_parent``).
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
from pathlib import Path

import bpy

from ..bridge.map_edges import EDGE_ENDS
from ..vg_addon import GoniometerError
from . import child_process, extension
from .pictures import reason
from .render import render_map
from .stdio import quiet_stdout, say

MAP_WORKER = "--map-worker"  # the (hidden) option that makes a process a map child

_child: MapProcess | None = None  # this process's map child, once started


class MapProcess:
    """A running map child, its temporary folder, and the map it is drawing."""

    def __init__(self):
        # Inside this process's Blender session folder, which the run removes at its end.
        self.folder = tempfile.mkdtemp(prefix="vg-map-", dir=bpy.app.tempdir or None)
        try:
            self.process = child_process.start([MAP_WORKER, str(os.getpid())], self.folder)
        except BaseException:
            shutil.rmtree(self.folder, ignore_errors=True)
            raise
        self.staging = ""  # the hidden folder of the map being drawn

    def draw(self, obj, job: dict) -> str:
        """Have the child draw ``obj``'s map as ``job`` says; returns the contact sheet's path.

        Raises
        ------
        GoniometerError
            Why the map was not made (the child's reason, or the child stopped).
        """
        blend = Path(self.folder) / "map.blend"
        with quiet_stdout():
            bpy.data.libraries.write(str(blend), {obj})
        directory = Path(job["directory"])
        directory.mkdir(parents=True, exist_ok=True)
        self.staging = tempfile.mkdtemp(prefix=".vg-map-", dir=directory)
        job = {**job, "blend": str(blend), "object": obj.name, "staging": self.staging}
        self.process.stdin.write(json.dumps(job) + "\n")
        self.process.stdin.flush()
        for line in self.process.stdout:
            at = line.find(child_process.MARK)
            if at >= 0:
                answer = json.loads(line[at + len(child_process.MARK) :])
                self.staging = ""
                if answer.get("error"):
                    raise GoniometerError(answer["error"])
                return answer["sheet"]
        code = self.process.wait()
        raise GoniometerError(f"the process drawing the map stopped (exit status {code})")

    def kill(self) -> None:
        """End the child now, and remove its folder and the hidden folder of its map."""
        with contextlib.suppress(OSError):
            self.process.kill()
        self.process.wait()
        self._remove_folders()

    def close(self) -> None:
        """End the child once it is idle (its stdin closed), then remove its folders."""
        with contextlib.suppress(OSError):
            self.process.stdin.close()
        try:
            self.process.wait(timeout=30)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
        self._remove_folders()

    def _remove_folders(self) -> None:
        for folder in (self.staging, self.folder):
            if folder:
                shutil.rmtree(folder, ignore_errors=True)
        self.staging = ""


def draw_map(obj, directory: Path, options: dict, stem: str, name: str) -> Path:
    """Render the measurement map of ``obj`` into ``directory`` in this process's map child;
    returns the contact sheet. ``name``: the mesh's name in progress lines. A stop signal (any exception) while it renders kills the child
    at once and leaves no picture of this map; the next map starts a new child."""
    global _child
    if _child is None:
        _child = MapProcess()
    job = {
        "directory": str(directory),
        "stem": stem,
        "name": name,
        "inputs": list(options.get("inputs", ())),
        "render_views": options.get("render_views", "SIX"),
        "render_size": list(options.get("render_size", (640, 480))),
        "render_samples": options.get("render_samples", 16),
        "render_edge_ends": options.get("render_edge_ends", EDGE_ENDS),
        "quiet": bool(options.get("quiet")),
    }
    try:
        return Path(_child.draw(obj, job))
    except BaseException:
        kill()
        raise


def kill() -> None:
    """End this process's map child at once (a stop, an error); safe to call at any time."""
    global _child
    child, _child = _child, None
    if child is not None:
        child.kill()


def close() -> None:
    """End this process's map child when the run is over."""
    global _child
    child, _child = _child, None
    if child is not None:
        child.close()


# -- the child ------------------------------------------------------------------------------------


def map_worker_main(parent: str) -> int:
    """A map child: draw the maps whose jobs arrive on stdin, one answer line each."""
    # Ctrl-C in a terminal reaches the whole process group: the parent stops this child.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    child_process.end_with_parent(int(parent), lambda: os._exit(1))
    bpy.ops.wm.read_homefile(use_empty=True)
    extension.activate()
    for line in sys.stdin:
        if not line.strip():
            continue
        job = json.loads(line)
        try:
            answer = {"sheet": str(_draw_job(job))}
        except Exception as error:  # the parent reports it as this map's failure
            answer = {"error": reason(error, Path(job["directory"]))}
        print(child_process.MARK + json.dumps(answer), flush=True)
    return 0


def _draw_job(job: dict) -> Path:
    with bpy.data.libraries.load(job["blend"], link=False) as (_source, target):
        target.objects = [job["object"]]
    obj = target.objects[0]
    if obj is None:
        raise GoniometerError(f"the object {job['object']!r} was not in the map's .blend")
    bpy.context.scene.collection.objects.link(obj)
    options = {**job, "inputs": [tuple(pair) for pair in job["inputs"]]}

    def progress(done: int, total: int, view: str) -> None:
        if not job["quiet"]:
            say(f"{job['name']}: rendering the map, view {done + 1} of {total} ({view})")

    try:
        return render_map(obj, Path(job["directory"]), options, job["stem"], progress)
    finally:
        bpy.data.objects.remove(obj)
        bpy.data.orphans_purge(do_recursive=True)  # its mesh and materials
