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
