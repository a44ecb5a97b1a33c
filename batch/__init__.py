"""Headless batch runs: measure break angles on many meshes and points, write a CSV.

Entered from ``vg_batch.py`` (``blender -b --python vg_batch.py -- ARGS`` or
``python vg_batch.py ARGS`` with the PyPI ``bpy``). ``cli`` parses, ``run`` plans and drives a
run, ``sources`` imports the meshes, ``measure`` measures one mesh through the bridge,
``workers`` runs ``--jobs`` processes, ``render`` and ``blend_file`` write the pictures and the
.blend (``map_process`` renders the maps in a child process that a stop signal ends at once),
``demo`` is ``--demo``. Imports run batch → bridge → vg_addon.
"""

from __future__ import annotations

import sys

from ..vg_addon import GoniometerError
from . import extension, stopping
from .cli import UsageError, build_parser, check_args


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
        stopping.handle_stop_signals()
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
        print(
            "vg_batch: interrupted; what was measured so far is kept (see the lines above)",
            file=sys.stderr,
        )
        return 130
    finally:
        map_process.close()


__all__ = ["extension", "main"]
