#!/usr/bin/env bash
# Create (or reuse) the virtual environments the project runs in.
#   scripts/setup.sh            -> .venv          (bpy 5.0.1: the product, demo and most tests)
#   scripts/setup.sh all        -> also .venv-bpy42 (bpy 4.2 LTS) and .venv-numpy2 (core on NumPy 2)
# An environment is rebuilt only when its requirements file changed (a stamp records its hash).
set -euo pipefail
cd "$(dirname "$0")/.."

pick_python() {
    for candidate in "${PYTHON:-}" python3.11 python3; do
        [ -n "$candidate" ] || continue
        if command -v "$candidate" >/dev/null 2>&1 &&
            "$candidate" -c 'import sys; sys.exit(sys.version_info[:2] != (3, 11))'; then
            echo "$candidate"
            return
        fi
    done
    echo "error: Python 3.11 is needed (the bpy wheels exist for 3.11 only); set PYTHON=/path/to/python3.11" >&2
    exit 2
}

make_env() {  # make_env DIR REQUIREMENTS
    local dir=$1 requirements=$2 stamp
    stamp=$(cat requirements/dev.txt "$requirements" | sha256sum | cut -c1-16)
    if [ -f "$dir/.vg-stamp" ] && [ "$(cat "$dir/.vg-stamp")" = "$stamp" ]; then
        return
    fi
    echo "setting up $dir from $requirements (the bpy wheels are large: a few minutes the first time)" >&2
    rm -rf "$dir"
    "$PYTHON_BIN" -m venv "$dir"
    "$dir/bin/python" -m pip install --quiet --disable-pip-version-check -r "$requirements"
    echo "$stamp" >"$dir/.vg-stamp"
}

PYTHON_BIN=$(pick_python)
make_env .venv requirements/bpy50.txt
if [ "${1:-}" = "all" ]; then
    make_env .venv-bpy42 requirements/bpy42.txt
    make_env .venv-numpy2 requirements/numpy2.txt
fi
