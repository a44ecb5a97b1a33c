"""Virtual Goniometer batch runs: measure break angles on many meshes and points, headless.

Runs inside Blender or with the ``bpy`` module from PyPI, with the same arguments and results:

    blender -b [file.blend] --python vg_batch.py -- ARGS
    python vg_batch.py ARGS

The repository root is the extension package: this script imports it from the folder it sits in
and registers it, so the measurements are taken, stored and coloured exactly as the extension
does it (see docs/BATCH.md).
"""

import signal
import sys

STOPPED_WHILE_STARTING: list[int] = []
"""Stop signals (Ctrl-C) that came while the script was starting: an interrupt raised inside an
import (bpy's, NumPy's) leaves a module half-imported, and bpy swallows it. They are kept here
and acted on once the imports are done (:func:`main`)."""


def _stop_while_starting(signum, frame) -> None:
    STOPPED_WHILE_STARTING.append(signum)


if __name__ == "__main__":
    # Before any other import: a Ctrl-C in the first tens of milliseconds (while shutil was being
    # imported) was a KeyboardInterrupt traceback. A worker's Ctrl-C is its parent's to handle
    # (the parent stops it): ignored from the start.
    _CHILD = any(flag in sys.argv for flag in ("--worker", "--map-worker"))
    signal.signal(signal.SIGINT, signal.SIG_IGN if _CHILD else _stop_while_starting)

import importlib.util  # noqa: E402 (after the stop handler, above)
import os  # noqa: E402
import shutil  # noqa: E402
import traceback  # noqa: E402
from pathlib import Path  # noqa: E402

ROOT = Path(__file__).resolve().parent
PACKAGE = (
    "virtual_goniometer"  # the name this folder is imported under when Blender does not run it
)
# Blender's own Python has imported bpy before it runs a --python script; a plain Python has not.
IN_BLENDER = "bpy" in sys.modules


def script_argv() -> list[str]:
    """The script's own arguments: after ``--`` under Blender, else after the script name."""
    if IN_BLENDER:
        return sys.argv[sys.argv.index("--") + 1 :] if "--" in sys.argv else []
    return sys.argv[1:]


def import_bpy() -> None:
    """Import the bpy module with what it prints while starting sent to stderr: bpy 5.x logs on
    stdout (e.g. "Using OCIO=..." where the OCIO variable is set, as it is in any child of a
    process that runs bpy 5.x), and stdout may be the CSV (``--out -``)."""
    if "bpy" in sys.modules:
        return
    sys.stdout.flush()
    saved = os.dup(1)
    try:
        os.dup2(2, 1)
        import bpy  # noqa: F401
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(saved)


def extension_package():
    """The extension package this script belongs to: the copy Blender already runs when it is
    this folder, else this folder imported as ``virtual_goniometer``."""
    import bpy

    for addon in bpy.context.preferences.addons:
        name = addon.module
        module = sys.modules.get(name)
        if (
            name.rpartition(".")[2] == PACKAGE
            and module is not None
            and Path(module.__file__).resolve().parent == ROOT
        ):
            return module
    if PACKAGE not in sys.modules:
        spec = importlib.util.spec_from_file_location(
            PACKAGE, ROOT / "__init__.py", submodule_search_locations=[str(ROOT)]
        )
        package = importlib.util.module_from_spec(spec)
        sys.modules[PACKAGE] = package
        spec.loader.exec_module(package)
    return sys.modules[PACKAGE]


def main() -> int:
    if importlib.util.find_spec("bpy") is None:
        print(
            "vg_batch: error: the bpy module is not installed in this Python. Run "
            "`bash scripts/setup.sh` and use .venv/bin/python vg_batch.py ..., or run it in "
            "Blender: blender -b --python vg_batch.py -- ...",
            file=sys.stderr,
        )
        return 2
    import_bpy()
    package = extension_package()
    if package.numpy_import_error is not None:  # a distribution's Blender without NumPy
        error = package.numpy_missing.message(str(package.numpy_import_error))
        print(f"vg_batch: error: {error}", file=sys.stderr)
        return 2
    importlib.import_module(f"{package.__name__}.batch")
    if signal.getsignal(signal.SIGINT) is _stop_while_starting:  # a worker's stays ignored
        # From here a stop raises KeyboardInterrupt; the run installs its own handler at once.
        signal.signal(signal.SIGINT, signal.default_int_handler)
    if STOPPED_WHILE_STARTING:  # checked after the switch: no stop falls between the two
        print(
            "vg_batch: interrupted while starting; nothing was measured or written",
            file=sys.stderr,
        )
        return 130
    try:
        return package.batch.main(script_argv())
    finally:
        package.batch.extension.deactivate()


if __name__ == "__main__":
    try:
        status = main()
    except SystemExit as stop:  # argparse: --help (0) and usage errors (2)
        status = stop.code if isinstance(stop.code, int) else 2
    except KeyboardInterrupt:  # outside the run's own handling (parsing the arguments, ...)
        print("vg_batch: interrupted", file=sys.stderr)
        status = 130
    except Exception:
        traceback.print_exc()
        status = 2
    sys.stdout.flush()
    sys.stderr.flush()
    if "bpy" in sys.modules:
        # All written and closed. Blender would carry on and exit with 0, and the bpy 4.x modules
        # fail at exit (4.2 can crash; 4.5 hangs once a .blend was read or written): end here,
        # removing Blender's session folder (blender_XXXXXX) as its own exit would.
        session = Path(sys.modules["bpy"].app.tempdir or ".").resolve()
        if session.name.startswith("blender_"):
            shutil.rmtree(session, ignore_errors=True)
        os._exit(status)
    sys.exit(status)
