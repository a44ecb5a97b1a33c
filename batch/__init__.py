"""Headless batch runs: measure break angles on many meshes and points, write a CSV.

Entered from ``vg_batch.py`` (``blender -b --python vg_batch.py -- ARGS`` or
``python vg_batch.py ARGS`` with the PyPI ``bpy``). ``cli`` parses, ``run`` plans and drives a
run, ``sources`` imports the meshes, ``measure`` measures one mesh through the bridge,
``workers`` runs ``--jobs`` processes, ``render`` and ``blend_file`` write the pictures and the
.blend (``map_process`` renders the maps in a child process that a stop signal ends at once),
``demo`` is ``--demo``. Imports run batch → bridge → vg_addon.
"""

from __future__ import annotations

import signal
import sys

from ..vg_addon import GoniometerError
from . import extension, stopping
from .cli import UsageError, build_parser, check_args


def _stop(signum, frame):
    # SIGINT (Ctrl-C) and SIGTERM (`kill PID`, a job scheduler's stop) end the run at once: a
    # map being rendered is killed with its child process, the workers are stopped, the CSV is
    # written with what was measured, the temporary folders are removed, exit status 130. A
    # second signal must not cut that short, so it is ignored from now on.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    stopping.request()  # raised again between steps where a Blender handler swallowed it
    if stopping.deferring():  # the run acts on it at its next check, losing nothing done
        return
    if not _in_blenders_scripts(frame):  # there bpy would print it as an error, and go on
        raise KeyboardInterrupt


def _in_blenders_scripts(frame) -> bool:
    """Whether ``frame`` runs code of Blender's own add-ons or startup scripts, where its
    handlers live (not its ``modules``: ``bpy.ops`` wrappers raise to their caller)."""
    import os

    import bpy

    scripts = bpy.utils.system_resource("SCRIPTS")
    if not scripts or frame is None:
        return False
    path = frame.f_code.co_filename
    modules = os.path.join(scripts, "modules") + os.sep
    return path.startswith(scripts) and not path.startswith(modules)


def main(argv: list[str]) -> int:
    """Run the batch command with the script's arguments; returns the process exit status."""
    from . import map_process
    from .demo import run_demo
    from .run import run_batch
    from .workers import worker_main

    args = build_parser().parse_args(argv)
    try:
        if args.map_worker:
            return map_process.map_worker_main(args.map_worker)
        if args.worker:
            return worker_main(args.worker)
        # Set here, not left to Python: Blender's own SIGINT handler (blender -b) only asks a
        # render to stop.
        signal.signal(signal.SIGINT, _stop)
        signal.signal(signal.SIGTERM, _stop)
        if args.report:
            from .report import check_report_args, run_report

            check_report_args(args)
            return run_report(args)
        check_args(args)
        if args.demo:
            return run_demo(args)
        code, _ = run_batch(args)
        return code
    except (UsageError, GoniometerError) as error:
        print(f"vg_batch: error: {error}", file=sys.stderr, flush=True)
        return 2
    except OSError as error:  # a file or folder the run needs, gone or refused
        where = f" ({error.filename})" if error.filename else ""
        print(f"vg_batch: error: {error.strerror or error}{where}", file=sys.stderr, flush=True)
        return 2
    except KeyboardInterrupt:
        print("vg_batch: interrupted; the CSV holds what was measured so far", file=sys.stderr)
        return 130
    finally:
        map_process.close()


__all__ = ["extension", "main"]
