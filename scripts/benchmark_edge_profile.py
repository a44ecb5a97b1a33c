"""Benchmark whole-edge measuring and print the numbers (no pass/fail: read them).

Run: ``.venv/bin/python scripts/benchmark_edge_profile.py``. On a ~1M-vertex wedge whose angle
changes along its crease, prints: the surface build, the one-time ridge graph, tracing the whole
edge, and measuring a 200-station profile along it (best of a few runs), with the time per
station.
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
from vg_addon.method.edge_profile import ridge_graph
from vg_addon.synthetic_meshes import varying_wedge


def timed(function):
    start = time.perf_counter()
    value = function()
    return value, time.perf_counter() - start


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vertices", type=int, default=1_000_000, help="size of the mesh")
    parser.add_argument("--stations", type=int, default=200)
    parser.add_argument("--patch-vertices", type=int, default=1500, help="about, per station")
    args = parser.parse_args(argv)
    print(
        f"machine: {platform.machine()}, Python {platform.python_version()}, NumPy {np.__version__}"
    )
    half_width = 5.0
    n = round(np.sqrt(args.vertices / (4 * half_width)))  # vertices per unit length
    shape, _ = timed(lambda: varying_wedge(80, 130, half_width=half_width, n=n))
    surface, build = timed(lambda: Surface(shape.points, shape.triangles))
    print(f"mesh: {shape.points.shape[0]:,} vertices, {shape.triangles.shape[0]:,} triangles")
    print(f"surface build (normals + index):   {build * 1e3:8.1f} ms")
    _, graph = timed(lambda: ridge_graph(surface))
    print(f"ridge graph (once per surface):    {graph * 1e3:8.1f} ms")
    start, end = [-half_width + 0.02, 0, 0], [half_width - 0.02, 0, 0]
    path, trace = timed(lambda: surface.trace_edge(start, end))
    print(
        f"trace ({path.vertices.size:,} path vertices, length {path.length:.3g}): {trace * 1e3:8.1f} ms"
    )
    spacing = path.length / (args.stations - 0.5)
    # The radius whose patch holds about --patch-vertices: two faces of density n^2.
    radius = float(np.sqrt(args.patch_vertices / (np.pi * n * n)))
    times = []
    for _ in range(3):
        profile, seconds = timed(lambda: surface.measure_along(path, spacing, radius))
        times.append(seconds)
    best = min(times)
    sizes = [m.n_vertices for m in profile.stations]
    print(
        f"profile: {profile.n_stations} stations, r={radius:.3g} ({int(np.mean(sizes))} vertices "
        f"per patch): {best * 1e3:8.1f} ms best of 3 ({best / profile.n_stations * 1e3:.2f} ms "
        "per station)"
    )
    print(f"summary: {profile.summary()}")


if __name__ == "__main__":
    main()
