#!/usr/bin/env bash
# Provision the replication report's libraries (requirements/report.txt: SciPy, statsmodels,
# matplotlib and what they need) for the Python of a Blender root made by provision_blender.sh:
#   scripts/provision_report_libs.sh trixie          # one suite (its root must exist)
# They go into $VG_BLENDER_CACHE/SUITE-report-libs (default cache /var/cache/vg-blender), outside
# the root, so the root's own Python still lacks them: the GUI lane shows the Report button
# refusing there, then adds this folder to the GUI Blender's sys.path (as a user who installs the
# libraries would) and presses it again to write a report. The wheels are those pip picks for the
# root's Python version, resolved against the root's own NumPy, which stays the one imported
# (the NumPy pip installs with them is removed). A finished folder is reused as it is.
# PIP_PYTHON: the Python whose pip downloads them (default python3).
# Exit status: 0 ready; 1 pip failed (its last lines are printed); 2 no root for the suite.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
cache=${VG_BLENDER_CACHE:-/var/cache/vg-blender}
pip_python=${PIP_PYTHON:-python3}
suite=${1:?usage: provision_report_libs.sh SUITE}
root="$cache/$suite"
target="$cache/$suite-report-libs"

python=$(readlink "$root/usr/bin/python3" 2>/dev/null || true)
version=${python#python}
numpy=$(find "$root/usr/lib/python3/dist-packages" -maxdepth 1 -name 'numpy-*.dist-info' 2>/dev/null |
    sed -n 's/.*numpy-\(.*\)\.dist-info/\1/p' | head -n 1)
if [ -z "$version" ] || [ -z "$numpy" ]; then
    echo "provision_report_libs: no Blender root with Python and NumPy in $root (run scripts/provision_blender.sh $suite)" >&2
    exit 2
fi
stamp="vg-report-libs v1: python $version, numpy $numpy, $(grep -v '^#' "$here/../requirements/report.txt" | tr '\n' ' ')"

exec 9>"$cache/.lock-$suite-report-libs"
flock 9
if [ -f "$target/.vg-report-libs" ] && [ "$(cat "$target/.vg-report-libs")" = "$stamp" ]; then
    echo "provision_report_libs: $suite: cached in $target" >&2
    exit 0
fi
work="$target.partial"
rm -rf "$work"
log="$cache/$suite-report-libs.log"
if ! "$pip_python" -m pip install --quiet --disable-pip-version-check --target "$work" \
    --python-version "$version" --only-binary=:all: --implementation cp \
    --platform manylinux_2_28_x86_64 --platform manylinux_2_17_x86_64 --platform manylinux2014_x86_64 \
    -r "$here/../requirements/report.txt" "numpy==$numpy" >"$log" 2>&1; then
    echo "provision_report_libs: $suite: pip failed; last lines of $log:" >&2
    tail -n 15 "$log" >&2
    rm -rf "$work"
    exit 1
fi
rm -rf "$work"/numpy "$work"/numpy-*.dist-info "$work"/numpy.libs "$work"/bin
echo "$stamp" >"$work/.vg-report-libs"
rm -rf "$target"
mv "$work" "$target"
echo "provision_report_libs: $suite: ready in $target (Python $version, NumPy $numpy of the root)" >&2
