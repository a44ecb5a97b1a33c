"""``blender -b --python vg_batch.py`` in real Blender builds (Debian's 4.3 and 5.2), end to end.

Both README forms are run in each root: on PLY files, and on an object of a .blend that Blender
itself made with its own PLY importer. Within one Blender build the two give the same numbers
bit for bit. Across builds (the real Blender, with Debian's Python and NumPy, against the PyPI bpy
module of this test's Python) too: the same rows, snapped centres, vertex counts, angles and fit
errors, since no sum is left to BLAS or LAPACK; the true angle of the exact wedges is the
independent oracle for all of them.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest
from conftest import SUITES, blender_root
from driver import GUEST_REPO, GUEST_TMP, REPO, RootShell

from vg_addon.formats import csvio, meshio
from vg_addon.synthetic_meshes import wedge

ANGLES = {"wedge100": 100.0, "wedge70": 70.0}
AT = [("0.05", "0", "0"), ("-0.4", "0", "0")]  # on the crease, as a user types them
RADIUS = "0.3"


@pytest.fixture(scope="module")
def inputs(tmp_path_factory) -> Path:
    """The wedges as PLY files whose float64 coordinates are float32 values (as in Blender)."""
    folder = tmp_path_factory.mktemp("meshes")
    for name, angle in ANGLES.items():
        shape = wedge(angle, n=30, irregular=True, seed=5)
        points = shape.points.astype(np.float32).astype(np.float64)
        meshio.write_ply(folder / f"{name}.ply", points, shape.triangles)
    return folder


@pytest.fixture(scope="module")
def module_run(inputs) -> list[csvio.MeasurementRow]:
    """The same batch with the PyPI bpy module (this Python), the README's first form."""
    out = inputs / "module.csv"
    at = [a for point in AT for a in ("--at", *point)]
    result = subprocess.run(
        [
            sys.executable,
            str(REPO / "vg_batch.py"),
            str(inputs),
            *at,
            "--radius",
            RADIUS,
            "--out",
            str(out),
            "--quiet",
        ],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert result.returncode == 0, result.stdout + result.stderr
    return csvio.read_measurements_csv(out)


@pytest.fixture(scope="module", params=SUITES)
def real(request, inputs):
    """A shell in one Blender root with the meshes under /vg/tmp/in."""
    blender_root(request.param)
    tmp = Path(tempfile.mkdtemp(prefix=f"vg-batch-{request.param}-"))
    os.chmod(tmp, 0o755)
    shutil.copytree(inputs, tmp / "in")
    shell = RootShell(request.param, tmp, tmp / "shell.log")
    shell.check(f"mkdir -p {GUEST_TMP}/home && export HOME={GUEST_TMP}/home && cd {GUEST_TMP}")
    try:
        yield shell, tmp
    finally:
        shell.close()
        shutil.rmtree(tmp, ignore_errors=True)


def at_args() -> str:
    return " ".join(f"--at {x} {y} {z}" for x, y, z in AT)


def check_against_truth(rows) -> None:
    for row in rows:
        assert abs(row.angle - ANGLES[row.mesh_name]) < 1e-6, (row.mesh_name, row.angle)


def test_ply_files_and_blend_objects_agree_bit_for_bit(real, module_run):
    shell, tmp = real
    shell.check(
        f"blender -b --python {GUEST_REPO}/vg_batch.py -- {GUEST_TMP}/in {at_args()} "
        f"--radius {RADIUS} --out {GUEST_TMP}/ply.csv --quiet",
        timeout=600,
    )
    ply_rows = csvio.read_measurements_csv(tmp / "ply.csv")
    assert len(ply_rows) == len(ANGLES) * len(AT)
    check_against_truth(ply_rows)

    # A .blend made by this Blender with its own PLY importer, measured by object name.
    shell.check(
        f"blender -b --python {GUEST_REPO}/tests/gui/import_ply.py -- "
        f"{GUEST_TMP}/wedges.blend {GUEST_TMP}/in/wedge100.ply {GUEST_TMP}/in/wedge70.ply",
        timeout=300,
    )
    before = hashlib.sha256((tmp / "wedges.blend").read_bytes()).hexdigest()
    shell.check(
        f"blender -b {GUEST_TMP}/wedges.blend --python {GUEST_REPO}/vg_batch.py -- "
        f"--object wedge100 --object wedge70 {at_args()} --radius {RADIUS} "
        f"--out {GUEST_TMP}/blend.csv --quiet",
        timeout=600,
    )
    assert hashlib.sha256((tmp / "wedges.blend").read_bytes()).hexdigest() == before
    blend_rows = csvio.read_measurements_csv(tmp / "blend.csv")
    key = lambda row: (row.mesh_name, row.requested)  # noqa: E731
    ply_rows, blend_rows = sorted(ply_rows, key=key), sorted(blend_rows, key=key)
    assert [key(r) for r in blend_rows] == [key(r) for r in ply_rows]
    for a, b in zip(ply_rows, blend_rows, strict=True):
        assert (a.angle, a.fit, (a.x, a.y, a.z), a.n_vertices) == (
            b.angle,
            b.fit,
            (b.x, b.y, b.z),
            b.n_vertices,
        ), f"{a.mesh_name} at {a.requested}: PLY and .blend differ in one build"

    # Across builds: the PyPI bpy module of this Python.
    module_rows = sorted(module_run, key=key)
    assert [key(r) for r in module_rows] == [key(r) for r in ply_rows]
    for a, b in zip(ply_rows, module_rows, strict=True):
        assert ((a.x, a.y, a.z), a.n_vertices, a.n_plus, a.n_minus) == (
            (b.x, b.y, b.z),
            b.n_vertices,
            b.n_plus,
            b.n_minus,
        )
        # No sum is left to BLAS or LAPACK (docs/METHOD.md#reproducibility): Debian's NumPy and
        # the wheel's give the same bits.
        assert (a.angle, a.fit) == (b.angle, b.fit), (a.mesh_name, a.angle, b.angle)
