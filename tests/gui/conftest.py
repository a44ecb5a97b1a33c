"""Fixtures of the GUI lane: the extension zip, the Blender roots, one GUI Blender per root.

A root that cannot be made here (not root, no debootstrap, no network to the Debian mirror, the
package not installable) skips that root's tests with the provisioning script's own reason.
"""

from __future__ import annotations

import contextlib
import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from driver import REPO, GuiBlender

SUITES = ("trixie", "unstable")  # Debian's Blender 4.3 and 5.2

_S, _C = math.sin(math.radians(50.0)), math.cos(math.radians(50.0))  # the wedge's half angle


def face_point(x: float, t: float, side: int) -> list[float]:
    """The point at distance ``t`` from the crease on the wedge face ``side`` (+1: y > 0)."""
    return [x, side * t * _S, -t * _C]


#: 3D points (world space) the harness projects to the screen for the test.
POINTS = {
    "crease": [0.15, 0.0, 0.0],
    "crease_left": [-0.45, 0.0, 0.0],
    "plus_in": face_point(0.15, 0.1, +1),
    "minus_in": face_point(0.15, 0.1, -1),
    "plus_out": face_point(0.15, 0.8, +1),
    "minus_out": face_point(0.15, 0.8, -1),
    # Just off the crease on the + face: a small patch there barely reaches the edge (an
    # unstable reading).
    "off_crease": face_point(0.35, 0.08, +1),
    # Along the crease, for edge profiles clicked start to end.
    **{f"crease_{round(10 * x):+d}": [x, 0.0, 0.0] for x in (-0.7, -0.5, 0.0, 0.1, 0.5, 0.7)},
}


_provisioned: dict[str, str | None] = {}


def provision(script: str, suite: str, **env) -> str | None:
    """Run ``scripts/SCRIPT SUITE`` (it reuses what it made before); None, or why it failed."""
    result = subprocess.run(
        ["bash", str(REPO / "scripts" / script), suite],
        capture_output=True,
        text=True,
        check=False,
        timeout=1800,
        env={**os.environ, **env},
    )
    return (
        None
        if result.returncode == 0
        else f"scripts/{script} {suite} failed:\n{result.stderr[-2000:]}"
    )


def blender_root(suite: str) -> None:
    """Make (or reuse) the root of ``suite``; skip, saying why, where it cannot be made."""
    if suite not in _provisioned:
        if os.geteuid() != 0:
            _provisioned[suite] = (
                "the GUI lane needs root (debootstrap, chroot, mounts); run the tests as root"
            )
        else:
            _provisioned[suite] = provision("provision_blender.sh", suite)
    if _provisioned[suite] is not None:
        pytest.skip(f"no real Blender from Debian {suite}: {_provisioned[suite]}")


_report_libs: dict[str, str | None] = {}


def report_libraries(suite: str) -> tuple[Path | None, str]:
    """The replication report's libraries for the Python of ``suite``'s root
    (``scripts/provision_report_libs.sh``, made once and cached beside the root): their folder,
    or None and why they could not be made."""
    if suite not in _report_libs:
        _report_libs[suite] = provision(
            "provision_report_libs.sh", suite, PIP_PYTHON=sys.executable
        )
    if _report_libs[suite] is not None:
        return None, _report_libs[suite]
    cache = Path(os.environ.get("VG_BLENDER_CACHE", "/var/cache/vg-blender"))
    return cache / f"{suite}-report-libs", ""


@pytest.fixture(autouse=True)
def console_stays_clean(request):
    """Every GUI test fails on a Python traceback or error from the extension in Blender's
    console (a failing draw, a modal operator that raised, a list class not found) printed
    while it ran, even when what it asserts came out right."""
    if "gui" not in request.fixturenames:
        yield
        return
    session = request.getfixturevalue("gui")
    start = session.log_size()
    yield
    with contextlib.suppress(Exception):
        session.settle(3)  # let Blender redraw, and print what a redraw prints
    errors = session.console_errors(start)
    assert not errors, "Blender's console has errors from the extension:\n" + "\n".join(errors)


@pytest.fixture(scope="module", params=SUITES)
def gui(request, extension_zip):
    """A GUI Blender of one Debian suite, extension installed, the wedge scene set up (or the
    scene a test module names in ``GUI_SCENE``: ``"fragment"``, the bone fragment). A module
    with ``REPORT_LIBS = True`` gets the report's libraries bound into the root (not on
    ``sys.path`` until a test asks); ``session.report_libs_missing`` says why they are not."""
    blender_root(request.param)
    failed_before = request.session.testsfailed
    scene = getattr(request.module, "GUI_SCENE", "wedge")
    libs, missing = (
        report_libraries(request.param)
        if getattr(request.module, "REPORT_LIBS", False)
        else (None, "the test module does not ask for them (REPORT_LIBS)")
    )
    session = GuiBlender(request.param, extension_zip, POINTS, scene=scene, report_libs=libs)
    session.report_libs_missing = missing
    try:
        yield session
    finally:
        session.close()
        # Keep screenshots and logs of failures (a console error found in the last test's
        # teardown is not counted yet).
        if request.session.testsfailed == failed_before and not session.console_errors():
            shutil.rmtree(session.tmp, ignore_errors=True)
