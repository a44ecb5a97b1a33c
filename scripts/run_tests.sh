#!/usr/bin/env bash
# Set everything up and run every check: lint, the core on NumPy 2 and on NumPy 1.26, the extension
# on every Blender line (bpy 5.2 LTS, 5.3, 4.5 LTS, 4.2 LTS), then real Blender binaries (Debian's
# 4.3 and 5.2, provisioned by scripts/provision_blender.sh): the GUI driven with real mouse and key
# events, and `blender -b` batch runs (tests/gui; they skip, saying why, where the roots cannot be
# made). Extra arguments go to every pytest run (e.g. -x, -k name).
#
# The core and bpy lanes run two at a time: each keeps one core busy for most of its run and
# waits on child processes for the rest, so a pair takes about two thirds of their time one after
# the other. Each lane is a process of its own with its own temporary and Blender user folders.
# The first lane of a pair prints as it goes, the second when it ends. The real-Blender lane runs
# alone: its windows are driven with timeouts.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh all

status=0
logs=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$logs"' EXIT
trap 'exit 130' INT TERM

echo "== ruff" >&2
.venv/bin/ruff check . || status=1
.venv/bin/ruff format --check . || status=1

lane() {  # lane LABEL PYTHON PYTEST-ARGS...: one lane, in the foreground
    local label=$1 python=$2 start=$SECONDS
    shift 2
    echo "== $label" >&2
    "$python" -m pytest -p no:cacheprovider "$@" || status=1
    echo "== $label: $((SECONDS - start)) s" >&2
}

pair() {  # pair LABEL1 PYTHON1 TESTS1 LABEL2 PYTHON2 TESTS2 PYTEST-ARGS...: two lanes at once
    local first=("$1" "$2" "$3") second=("$4" "$5" "$6") start=$SECONDS code=0
    shift 6
    local log
    log=$(mktemp "$logs/lane.XXXXXX")
    # A shell without job control starts background commands with Ctrl-C and SIGQUIT ignored,
    # and a process inherits that: the stop tests' runs would not stop. Restored first.
    (trap - INT QUIT && exec "${second[1]}" -m pytest -p no:cacheprovider "${second[2]}" "$@") \
        > "$log" 2>&1 &
    local background=$!
    lane "${first[0]}" "${first[1]}" "${first[2]}" "$@"
    wait "$background" || code=$?
    echo "== ${second[0]} (ran beside the lane above)" >&2
    cat "$log"
    [ "$code" -eq 0 ] || status=1
    echo "== ${second[0]}: $((SECONDS - start)) s" >&2
}

# The core in processes of its own (no bpy loaded), on both NumPy lines; then the extension on
# every Blender line.
pair "core, Python 3.13, NumPy 2" .venv/bin/python tests/core \
     "core, Python 3.11, NumPy 1.26" .venv-bpy42/bin/python tests/core "$@"
pair "extension, bpy 5.2 LTS (Python 3.13, NumPy 2)" .venv/bin/python tests/blender \
     "extension, bpy 4.5 LTS (Python 3.11, NumPy 1.26)" .venv-bpy45/bin/python tests/blender "$@"
pair "extension, bpy 5.3 (Python 3.13, NumPy 2)" .venv-bpy53/bin/python tests/blender \
     "extension, bpy 4.2 LTS (Python 3.11, NumPy 1.26)" .venv-bpy42/bin/python tests/blender "$@"
lane "real Blender 4.3 and 5.2: GUI and blender -b" .venv/bin/python tests/gui "$@"
exit $status
