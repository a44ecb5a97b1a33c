#!/usr/bin/env bash
# Set everything up and run every check: lint, the core on NumPy 1.26 and 2, the extension on
# bpy 5.0 and on bpy 4.2 LTS. Extra arguments go to every pytest run (e.g. -x, -k name).
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
run "core, NumPy 2" .venv-numpy2/bin/python tests/core "$@"
run "core and extension, bpy 5.0 (NumPy 1.26)" .venv/bin/python tests "$@"
run "extension, bpy 4.2 LTS" .venv-bpy42/bin/python tests/blender "$@"
exit $status
