#!/usr/bin/env bash
# Create (or reuse) the virtual environments the project runs in, one per Blender line:
#   scripts/setup.sh      -> .venv        bpy 5.2 LTS (Python 3.13, NumPy 2): the product, the demo,
#                                         the linters, the core on NumPy 2
#   scripts/setup.sh all  -> also .venv-bpy42 (4.2 LTS, Python 3.11, NumPy 1.26; also the core on
#                            NumPy 1.26), .venv-bpy45 (4.5 LTS, Python 3.11) and .venv-bpy53
#                            (5.3, Python 3.13)
# The bpy wheels exist for one Python each: 4.x for 3.11, 5.1 and newer for 3.13. Interpreters are
# looked for on PATH, then in pyenv's versions folder; PYTHON311=/path or PYTHON313=/path override.
# An environment is rebuilt only when its requirements or interpreter changed (a stamp records a
# hash of both).
set -euo pipefail
cd "$(dirname "$0")/.."

find_python() {  # find_python 3.11|3.13 -> path of a working interpreter of that version
    local want=$1 override candidate
    local version_tuple="${want/./, }"
    override="PYTHON${want/./}"
    local candidates=("${!override:-}" "python$want")
    local pyenv_root="${PYENV_ROOT:-$HOME/.pyenv}"
    for candidate in "$pyenv_root"/versions/"$want".*/bin/"python$want"; do
        [ -e "$candidate" ] && candidates+=("$candidate")
    done
    for candidate in "${candidates[@]}"; do
        [ -n "$candidate" ] || continue
        # Run it: a pyenv shim is on PATH even when it cannot run that version.
        if "$candidate" -c "import sys; sys.exit(sys.version_info[:2] != ($version_tuple))" \
            >/dev/null 2>&1; then
            command -v "$candidate"
            return
        fi
    done
    echo "error: Python $want is needed (the bpy wheels of these Blender lines exist for it only)" \
        "and none was found on PATH or in $pyenv_root/versions; install it (e.g. 'pyenv install $want')" \
        "or set $override=/path/to/python$want" >&2
    exit 2
}

# An environment takes about 1.5 GB (bpy alone 0.9); pip needs some room besides. A disk that
# fills half-way through an install leaves a broken environment and pip's own OSError, so the
# space is looked at first.
NEEDED_MB=2048
check_space() {  # check_space DIR: refuse, saying why, when DIR's disk has too little room
    local free_mb old_mb=0
    # Where DIR is made: beside it (a link in its place is removed, not followed). An outdated
    # environment there is removed first, and its room counts.
    free_mb=$(df -Pm "$(dirname "$1")" | awk 'NR == 2 { print $4 }')
    if [ -d "$1" ] && [ ! -L "$1" ]; then
        old_mb=$(du -sm "$1" | cut -f1)
    fi
    [ -n "$free_mb" ] || return 0 # df could not tell: pip will
    free_mb=$((free_mb + old_mb))
    if [ "$free_mb" -lt "$NEEDED_MB" ]; then
        echo "error: setting up $1 needs about $NEEDED_MB MB free on its disk, and $free_mb MB" \
            "are (with the outdated environment it replaces); make room (each environment of" \
            "a clone of this project, .venv*, takes about 1.5 GB) and run again" >&2
        exit 2
    fi
}

make_env() {  # make_env DIR PYTHON-VERSION REQUIREMENTS
    local dir=$1 want=$2 requirements=$3 python stamp
    python=$(find_python "$want")
    stamp=$( (
        cat requirements/dev.txt requirements/report.txt "$requirements"
        "$python" -VV
    ) | sha256sum | cut -c1-16)
    if [ -f "$dir/.vg-stamp" ] && [ "$(cat "$dir/.vg-stamp")" = "$stamp" ]; then
        return
    fi
    check_space "$dir"
    echo "setting up $dir from $requirements with $python" \
        "(the bpy wheels are large: a few minutes the first time)" >&2
    rm -rf "$dir" # a symlinked environment loses only its link
    "$python" -m venv "$dir"
    "$dir/bin/python" -m pip install --quiet --disable-pip-version-check -r "$requirements"
    echo "$stamp" >"$dir/.vg-stamp"
}

make_env .venv 3.13 requirements/bpy52.txt
if [ "${1:-}" = "all" ]; then
    make_env .venv-bpy42 3.11 requirements/bpy42.txt
    make_env .venv-bpy45 3.11 requirements/bpy45.txt
    make_env .venv-bpy53 3.13 requirements/bpy53.txt
fi
