"""The core gives the same bits with a Linux distribution's Python and NumPy as with the PyPI
builds the pins were made with: Debian trixie (the NumPy and Python that Blender 4.3 runs there)
and unstable (those of Blender 5.2), in the roots the GUI lane provisions.

This is the check behind docs/RELIABILITY.md's table of what is identical across what: another
NumPy build, another Python, Debian's BLAS, the same numbers."""

from __future__ import annotations

import json
import subprocess

import pytest
from conftest import SUITES, blender_root
from driver import REPO

PINS = REPO / "tests" / "core" / "data" / "determinism_pins.json"


@pytest.mark.parametrize("suite", SUITES)
def test_the_core_in_a_distributions_numpy_gives_the_pinned_bits(suite):
    blender_root(suite)
    command = (
        "cd /vg/repo && python3 -c 'import numpy, sys; print(numpy.__version__, sys.version)' "
        "&& python3 tests/core/determinism_probe.py"
    )
    done = subprocess.run(
        ["bash", str(REPO / "scripts" / "blender_root.sh"), suite, "--ro-bind", str(REPO),
         "/vg/repo", "--", "sh", "-c", command],
        capture_output=True, text=True, timeout=600, check=False,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr[-2000:]
    versions, _, document = done.stdout.partition("\n")
    got, pinned = json.loads(document), json.loads(PINS.read_text())
    differing = sorted(case for case in pinned if got.get(case) != pinned[case])
    assert not differing, f"NumPy/Python {versions}: {len(differing)} cases differ: {differing[:5]}"


PLOTS_WITHOUT_MATPLOTLIB = """
import json, struct
from vg_addon import Surface
from vg_addon.analysis import missing_message
from vg_addon.formats import mpl_plots, profile_plot, sweep_plot
from vg_addon.method.sweep import radius_sweep
from vg_addon.synthetic_meshes import wedge
mesh = wedge(75, n=40, irregular=True, seed=4, concave=True)
points = radius_sweep(Surface(mesh.points, mesh.triangles), [0.01, 0.0, 0.0], 0.02, 0.6, 5)
pngs = [profile_plot.profile_png([0.0, 0.5, 1.0], [91.0, 92.0, 90.5]), sweep_plot.sweep_png(points)]
print(json.dumps({
    "matplotlib": mpl_plots.available(),
    "sizes": [list(struct.unpack(">II", png[16:24])) for png in pngs],
    "message": missing_message(),
}))
"""


@pytest.mark.parametrize("suite", SUITES)
def test_a_distributions_python_without_matplotlib_draws_plainly_and_says_how_to_get_it(suite):
    # Debian's Blender runs the system Python, which has NumPy (python3-numpy) but no matplotlib,
    # SciPy or statsmodels unless their packages are installed: the roots have none of them.
    blender_root(suite)
    done = subprocess.run(
        ["bash", str(REPO / "scripts" / "blender_root.sh"), suite, "--ro-bind", str(REPO),
         "/vg/repo", "--", "sh", "-c", "cd /vg/repo && python3 -c \"$0\"",
         PLOTS_WITHOUT_MATPLOTLIB],
        capture_output=True, text=True, timeout=600, check=False,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr[-2000:]
    report = json.loads(done.stdout.strip().splitlines()[-1])
    assert report["matplotlib"] is False
    assert report["sizes"] == [[480, 240], [640, 430]]  # the NumPy drawings
    assert "The report needs scipy, statsmodels, matplotlib" in report["message"]
    assert (
        "sudo apt install python3-scipy python3-statsmodels python3-matplotlib"
        in (report["message"])
    )
