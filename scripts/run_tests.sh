#!/usr/bin/env bash
# Set everything up and run every check: lint, the core on NumPy 2 and on NumPy 1.26, the extension
# on every Blender line (bpy 5.2 LTS, 5.3, 4.5 LTS, 4.2 LTS), then real Blender binaries (Debian's
# 4.3 and 5.2, provisioned by scripts/provision_blender.sh): the GUI driven with real mouse and key
# events, and `blender -b` batch runs (tests/gui; they skip, saying why, where the roots cannot be
# made). Extra arguments go to every pytest run (e.g. -x, -k name).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh all

status=0
echo "== ruff" >&2
.venv/bin/ruff check . || status=1
.venv/bin/ruff format --check . || status=1

run() {  # run LABEL PYTHON PYTEST-ARGS...
    local label=$1 python=$2
    shift 2
    echo "== $label" >&2
    "$python" -m pytest -p no:cacheprovider "$@" || status=1
}
# The core in processes of its own (no bpy loaded), on both NumPy lines; then the extension on
# every Blender line.
run "core, Python 3.13, NumPy 2" .venv/bin/python tests/core "$@"
run "core, Python 3.11, NumPy 1.26" .venv-bpy42/bin/python tests/core "$@"
run "extension, bpy 5.2 LTS (Python 3.13, NumPy 2)" .venv/bin/python tests/blender "$@"
run "extension, bpy 5.3 (Python 3.13, NumPy 2)" .venv-bpy53/bin/python tests/blender "$@"
run "extension, bpy 4.5 LTS (Python 3.11, NumPy 1.26)" .venv-bpy45/bin/python tests/blender "$@"
run "extension, bpy 4.2 LTS (Python 3.11, NumPy 1.26)" .venv-bpy42/bin/python tests/blender "$@"
run "real Blender 4.3 and 5.2: GUI and blender -b" .venv/bin/python tests/gui "$@"
exit $status
