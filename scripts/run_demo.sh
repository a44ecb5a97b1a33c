#!/usr/bin/env bash
# The README's main command: set up .venv (bpy 5.2 LTS), then run the bundled demo. It generates a
# long-bone shaft fragment with known break angles, measures its break sites in a headless batch
# run, prints true against measured angles, and writes the CSV, a .blend and a PNG into
# ./vg_demo_output/ (or the folder given with --out-dir DIR). Extra arguments go to vg_batch.py.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
bash "$root/scripts/setup.sh"
exec "$root/.venv/bin/python" "$root/vg_batch.py" --demo "$@"
