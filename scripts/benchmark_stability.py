"""Benchmark the stability figure and print the numbers (no pass/fail: read them).

Run: ``.venv/bin/python scripts/benchmark_stability.py``. On a 1M-vertex wedge, for patches of
about 2,000 and 10,000 vertices: a plain measurement, the stability figure alone, and their ratio.
The target is at most 20 ms for the stability figure of a 2,000-vertex patch.
"""

from __future__ import annotations

import argparse
import platform
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from vg_addon import Surface
from vg_addon.method.stability import estimate_stability
from vg_addon.synthetic_meshes import wedge

CENTER = (0.013, 0.0, 0.0)


def best_of(function, repeats: int) -> float:
    """Smallest wall time of ``repeats`` calls, in seconds."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return min(times)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vertices", type=int, default=1_000_000, help="size of the mesh")
    parser.add_argument("--repeats", type=int, default=7, help="best of this many runs")
    args = parser.parse_args(argv)
    print(
        f"machine: {platform.machine()}, Python {platform.python_version()}, NumPy {np.__version__}"
    )
    side = int(np.sqrt(args.vertices / 2))
    mesh = wedge(90, n=side, irregular=True, seed=0)
    surface = Surface(mesh.points, mesh.triangles)
    spacing = np.sqrt(4.0 / len(mesh.points))  # the wedge's two unit faces hold all vertices
    print(f"mesh: 90° wedge, {len(mesh.points):,} vertices")
    for target in (2_000, 10_000):
        radius = spacing * np.sqrt(target / np.pi)
        m = surface.measure(CENTER, radius)
        plain = best_of(lambda radius=radius: surface.measure(CENTER, radius), args.repeats)
        figure = best_of(lambda m=m: estimate_stability(surface, m), args.repeats)
        s = estimate_stability(surface, m)
        print(
            f"patch {m.n_vertices:6,} vertices: measure {plain * 1e3:6.2f} ms, stability "
            f"{figure * 1e3:6.2f} ms ({figure / plain:4.1f}x), {s.n_runs} runs, "
            f"angle {m.angle:.4f}° {s.text()}"
        )


if __name__ == "__main__":
    main()
