"""The same inputs give the same bits on any machine: whatever BLAS kernel, thread count or SIMD
instructions the CPU runs, and under NumPy 1.26 and 2.x alike.

``determinism_probe.py`` computes every kind of number the core reports (Algorithm 1 under both
rules, meshes and point clouds, the stability figure and its parts, a sweep, an edge profile and
its summary). Its output is pinned in ``data/determinism_pins.json``; here it is computed again in
this process and in fresh processes under other OpenBLAS kernels (``OPENBLAS_CORETYPE``: the
kernels of older and newer CPUs, those this CPU can run), one and two BLAS threads, and NumPy's
run-time SIMD paths switched off (``NPY_DISABLE_CPU_FEATURES``: what a CPU without AVX-512, or
without AVX2, runs). Each must equal the pins bit for bit.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from determinism_probe import probe

HERE = Path(__file__).resolve().parent
PROBE = HERE / "determinism_probe.py"
PINS = HERE / "data" / "determinism_pins.json"

# Each OpenBLAS kernel with the CPU flags it needs; one this CPU lacks would crash the process.
# (/proc/cpuinfo names SSE3 "pni".)
KERNELS = {"Prescott": {"pni"}, "Sandybridge": {"avx"}, "Haswell": {"avx2", "fma"}}

# The BLAS control: products shaped like the ones the measuring path used to hand to BLAS (a
# weight matrix times per-vertex features, a patch's 3×3 moments); their last bits depend on the
# kernel, which shows that the kernel did change.
CONTROL = (
    "import hashlib, numpy as np; r = np.random.default_rng(1); w = r.normal(size=(90, 3000)); "
    "f = r.normal(size=(3000, 15)); x = r.normal(size=(2000, 3)); "
    "print(hashlib.sha256((w @ f).tobytes() + (x.T @ x).tobytes()).hexdigest())"
)


def _cpu_flags() -> set[str]:
    try:
        text = Path("/proc/cpuinfo").read_text()
    except OSError:
        return set()
    for line in text.splitlines():
        if line.startswith("flags"):
            return set(line.split(":", 1)[1].split())
    return set()


def _simd_features() -> tuple[list[str], list[str]]:
    """NumPy's run-time (dispatched) CPU features this CPU has: the AVX-512 ones, and AVX2/FMA3."""
    try:
        from numpy._core import _multiarray_umath as umath
    except ImportError:  # NumPy 1.x
        from numpy.core import _multiarray_umath as umath
    baseline = set(umath.__cpu_baseline__)
    present = [name for name, on in umath.__cpu_features__.items() if on and name not in baseline]
    avx512 = [name for name in present if name.startswith("AVX512")]
    avx2 = [name for name in present if name in ("AVX2", "FMA3")]
    return avx512, avx2


def _environments() -> dict[str, dict[str, str]]:
    flags = _cpu_flags()
    envs = {
        f"OPENBLAS_CORETYPE={kernel}": {"OPENBLAS_CORETYPE": kernel}
        for kernel, needs in KERNELS.items()
        if needs <= flags
    }
    envs["OPENBLAS_NUM_THREADS=1"] = {"OPENBLAS_NUM_THREADS": "1"}
    envs["OPENBLAS_NUM_THREADS=2"] = {"OPENBLAS_NUM_THREADS": "2"}
    avx512, avx2 = _simd_features()
    if avx512:
        envs["no AVX-512"] = {"NPY_DISABLE_CPU_FEATURES": " ".join(avx512)}
    if avx2:
        envs["no AVX2, no AVX-512"] = {"NPY_DISABLE_CPU_FEATURES": " ".join(avx512 + avx2)}
    return envs


ENVIRONMENTS = _environments()


def _run(code_or_script: list[str], extra: dict[str, str]) -> str:
    env = {
        key: value
        for key, value in os.environ.items()
        if key not in ("OPENBLAS_CORETYPE", "OPENBLAS_NUM_THREADS", "NPY_DISABLE_CPU_FEATURES")
    }
    env.update(extra)
    done = subprocess.run(
        [sys.executable, *code_or_script], env=env, capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 0, done.stderr
    return done.stdout


@pytest.fixture(scope="module")
def pinned() -> dict:
    return json.loads(PINS.read_text())


def test_the_probe_in_this_process_equals_the_pins(pinned):
    assert probe() == pinned


@pytest.mark.parametrize("name", sorted(ENVIRONMENTS))
def test_the_probe_under_another_kernel_thread_count_or_cpu_equals_the_pins(name, pinned):
    got = json.loads(_run([str(PROBE)], ENVIRONMENTS[name]))
    differing = sorted(case for case in pinned if got.get(case) != pinned[case])
    assert not differing, f"under {name}, {len(differing)} cases differ: {differing[:5]}"


def test_the_kernels_tried_do_compute_differently():
    """Otherwise the kernel test above would prove nothing: under the kernels tried, a plain BLAS
    product rounds differently (it did for every pair of kernels on the machines we ran)."""
    kernels = [name for name in ENVIRONMENTS if name.startswith("OPENBLAS_CORETYPE")]
    if len(kernels) < 2:
        pytest.skip(f"this CPU runs fewer than two of the kernels {sorted(KERNELS)}")
    controls = {name: _run(["-c", CONTROL], ENVIRONMENTS[name]) for name in kernels}
    assert len(set(controls.values())) == len(kernels), controls
