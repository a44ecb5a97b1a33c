"""Build and validate the extension zip with Blender's own extension tool, without Blender.

The bpy wheel from PyPI ships Blender's extension command line (``blender_ext.py``, the code
behind ``blender --command extension build``); this script runs it with the current Python:

    .venv/bin/python scripts/build_extension.py            # -> dist/virtual_goniometer-<ver>.zip

It builds from the repository root (the manifest's ``[build]`` table says what goes in), checks the
manifest tags against Blender's list of valid tags, validates the finished zip, and prints the zip's
path as the last line of output. Exit status 0 on success.
"""

from __future__ import annotations

import argparse
import importlib.util
import subprocess
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def bpy_scripts_dir() -> Path:
    """``bpy/<version>/scripts`` of the installed bpy wheel (found without importing bpy)."""
    spec = importlib.util.find_spec("bpy")
    if spec is None or not spec.submodule_search_locations:
        raise SystemExit(
            "error: the bpy module is not installed in this Python; run this script with the "
            "project's environment, e.g. .venv/bin/python scripts/build_extension.py"
        )
    for package_dir in spec.submodule_search_locations:
        found = sorted(Path(package_dir).glob("*/scripts/addons_core/bl_pkg/cli/blender_ext.py"))
        if found:
            return found[-1].parents[3]
    raise SystemExit("error: blender_ext.py not found inside the bpy wheel")


def run(command: list[str]) -> None:
    print("+", " ".join(command), flush=True)
    result = subprocess.run(command, check=False)
    if result.returncode != 0:
        raise SystemExit(f"error: {command[2]} failed (exit status {result.returncode})")


def build(output_dir: Path) -> Path:
    """Build the zip into ``output_dir``, validate it, and return its path."""
    scripts = bpy_scripts_dir()
    tool = scripts / "addons_core" / "bl_pkg" / "cli" / "blender_ext.py"
    tags = scripts / "modules" / "_bpy_internal" / "extensions" / "tags.py"
    with open(ROOT / "blender_manifest.toml", "rb") as handle:
        manifest = tomllib.load(handle)
    output_dir.mkdir(parents=True, exist_ok=True)
    archive = output_dir / f"{manifest['id']}-{manifest['version']}.zip"
    archive.unlink(missing_ok=True)
    command = [sys.executable, str(tool)]
    valid_tags = [f"--valid-tags={tags}"] if tags.is_file() else []
    run(
        [*command, "build", "--source-dir", str(ROOT), "--output-dir", str(output_dir), *valid_tags]
    )
    if not archive.is_file():
        raise SystemExit(f"error: the build did not write {archive}")
    run([*command, "validate", *valid_tags, str(archive)])
    return archive


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--output-dir", type=Path, default=ROOT / "dist", help="where to write the zip (dist/)"
    )
    args = parser.parse_args(argv)
    print(build(args.output_dir.resolve()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
