"""Virtual Goniometer batch runs: measure break angles on many meshes and points, headless.

Runs inside Blender or with the ``bpy`` module from PyPI, with the same arguments and results:

    blender -b [file.blend] --python vg_batch.py -- ARGS
    python vg_batch.py ARGS

The repository root is the extension package: this script imports it from the folder it sits in
and registers it, so the measurements are taken, stored and coloured exactly as the extension
does it (see docs/BATCH.md).
"""

import importlib.util
import os
import sys
import traceback
from pathlib import Path

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
    package = extension_package()
    importlib.import_module(f"{package.__name__}.batch")
    try:
        return package.batch.main(script_argv())
    finally:
        package.batch.extension.deactivate()


if __name__ == "__main__":
    try:
        status = main()
    except SystemExit as stop:  # argparse: --help (0) and usage errors (2)
        status = stop.code if isinstance(stop.code, int) else 2
    except Exception:
        traceback.print_exc()
        status = 2
    sys.stdout.flush()
    sys.stderr.flush()
    if IN_BLENDER:
        # Blender would otherwise carry on and exit with 0; end the process with our status.
        os._exit(status)
    sys.exit(status)
