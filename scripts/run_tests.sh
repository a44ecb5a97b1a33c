#!/usr/bin/env bash
# Set everything up and run every check: lint, the core on NumPy 2 and on NumPy 1.26, the extension
# on every Blender line (bpy 5.2 LTS, 5.3, 4.5 LTS, 4.2 LTS), then real Blender binaries (Debian's
# 4.3 and 5.2, provisioned by scripts/provision_blender.sh): the GUI driven with real mouse and key
# events, and `blender -b` batch runs (tests/gui; they skip, saying why, where the roots cannot be
# made). Extra arguments go to every pytest run (e.g. -x, -k name).
#
# The core and bpy lanes run two at a time: a lane keeps one core busy for most of its run and
# waits on its child processes for the rest (on 2 cores, the pair of bpy 5.2 and 4.5 took 13.5
# min against 25 one after the other). Each lane is a process of its own with its own temporary
# and Blender user folders. The first lane of a pair prints as it goes, the second when it ends.
# The real-Blender lane runs alone: its windows are driven with timeouts.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh all

status=0
logs=$(mktemp -d)
trap 'rm -rf "$logs"' EXIT

echo "== ruff" >&2
.venv/bin/ruff check . || status=1
.venv/bin/ruff format --check . || status=1

# Every lane runs in the background, so that a stop signal reaches this script while one runs
# (bash runs a trap only once the command in the foreground has ended). A shell without job
# control starts background commands with Ctrl-C and SIGQUIT ignored, and a process inherits
# that (the stop tests' runs would not stop): restored first.
pids=() outputs=() labels=()
start_lane() {  # start_lane OUTPUT LABEL PYTHON TESTS PYTEST-ARGS...; OUTPUT "-": as it goes
    local output=$1 label=$2 python=$3 tests=$4
    shift 4
    if [ "$output" = - ]; then
        echo "== $label" >&2
        (trap - INT QUIT && exec "$python" -m pytest -p no:cacheprovider "$tests" "$@") &
    else
        (trap - INT QUIT && exec "$python" -m pytest -p no:cacheprovider "$tests" "$@") \
            > "$output" 2>&1 &
    fi
    pids+=($!) outputs+=("$output") labels+=("$label")
}

end_lanes() {  # wait for the lanes started; print the output of each that ran beside another
    local i code start=$SECONDS
    for i in "${!pids[@]}"; do
        code=0
        wait "${pids[$i]}" || code=$?
        [ "$code" -eq 0 ] || status=1
        if [ "${outputs[$i]}" != - ]; then
            echo "== ${labels[$i]} (ran beside the lane above)" >&2
            cat "${outputs[$i]}"
        fi
        echo "== ${labels[$i]}: ended after $((SECONDS - start)) s, exit status $code" >&2
    done
    pids=() outputs=() labels=()
}

stop() {  # stop SIGNAL STATUS: pass a SIGTERM on (Ctrl-C reaches the lanes by itself), give
    # the lanes a minute to tear down (their runs and temporary folders), print what they said
    trap '' INT TERM
    local pid alive i
    if [ "$1" = TERM ]; then
        for pid in "${pids[@]}"; do kill -TERM "$pid" 2>/dev/null || true; done
    fi
    for _ in $(seq 120); do
        alive=0
        for pid in "${pids[@]}"; do kill -0 "$pid" 2>/dev/null && alive=1; done
        [ "$alive" -eq 1 ] || break
        sleep 0.5
    done
    for pid in "${pids[@]}"; do kill -KILL "$pid" 2>/dev/null || true; done
    for i in "${!outputs[@]}"; do
        [ "${outputs[$i]}" = - ] || cat "${outputs[$i]}"
    done
    exit "$2"
}
trap 'stop INT 130' INT
trap 'stop TERM 143' TERM

# The core in processes of its own (no bpy loaded), on both NumPy lines; then the extension on
# every Blender line; then real Blender, alone.
start_lane - "core, Python 3.13, NumPy 2" .venv/bin/python tests/core "$@"
start_lane "$logs/core311" "core, Python 3.11, NumPy 1.26" .venv-bpy42/bin/python tests/core "$@"
end_lanes
start_lane - "extension, bpy 5.2 LTS (Python 3.13, NumPy 2)" .venv/bin/python tests/blender "$@"
start_lane "$logs/bpy45" "extension, bpy 4.5 LTS (Python 3.11, NumPy 1.26)" \
    .venv-bpy45/bin/python tests/blender "$@"
end_lanes
start_lane - "extension, bpy 5.3 (Python 3.13, NumPy 2)" .venv-bpy53/bin/python tests/blender "$@"
start_lane "$logs/bpy42" "extension, bpy 4.2 LTS (Python 3.11, NumPy 1.26)" \
    .venv-bpy42/bin/python tests/blender "$@"
end_lanes
start_lane - "real Blender 4.3 and 5.2: GUI and blender -b" .venv/bin/python tests/gui "$@"
end_lanes
exit $status
