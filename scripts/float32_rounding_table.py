"""Print the table of docs/METHOD.md, "Coordinates far from the origin": how far float32
rounding moves a reading, by the rounding step as a share of the patch's vertex spacing.

Irregular synthetic wedges are moved away from the origin (at random, six moves a cell) until
float32 rounds their coordinates to the step asked, stored as float32 and measured as if the
rounded coordinates were exact (``precision="float64"``, which the extension does not do). The
cell is the largest error in degrees against the wedge's true angle.

Run: .venv/bin/python scripts/float32_rounding_table.py (about half a minute).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from vg_addon import Surface  # noqa: E402
from vg_addon.method.precision import MAX_ROUNDING  # noqa: E402
from vg_addon.synthetic_meshes import wedge  # noqa: E402

RATIOS = (0.003, 0.01, 0.03, 0.1, 0.3, 1.0)
CASES = ((90.0, 60, 0.5), (90.0, 30, 0.5), (130.0, 60, 0.3), (60.0, 40, 0.5))
MOVES = 6


def largest_error(angle: float, n: int, radius: float, ratio: float, rng) -> float:
    shape = wedge(angle, n=n, irregular=True)
    points = np.asarray(shape.points, dtype=np.float64)
    triangles = np.asarray(shape.triangles)
    size = radius * np.sqrt(np.pi / Surface(points, triangles).patch(0, radius).size)
    worst = 0.0
    for _ in range(MOVES):
        # float32 keeps a number in [2**e, 2**(e+1)) to steps of 2**(e-23): at most the
        # share asked, at least half of it.
        exponent = np.floor(np.log2(ratio * size)) + 23
        centre = 2.0**exponent * rng.uniform(1.0, 1.9) * np.array([1.0, -0.5, 0.3])
        stored = (points + centre).astype(np.float32)
        reading = Surface(stored, triangles, precision="float64").measure(centre, radius)
        worst = max(worst, abs(reading.angle - angle))
    return worst


def main() -> None:
    rng = np.random.default_rng(1)
    print("| wedge | " + " | ".join(f"step {r:g} × spacing" for r in RATIOS) + " |")
    print("|---|" + "---|" * len(RATIOS))
    for angle, n, radius in CASES:
        cells = [largest_error(angle, n, radius, ratio, rng) for ratio in RATIOS]
        label = f"{angle:g}°, {n}×{n} grid, r {radius:g}"
        print(f"| {label} | " + " | ".join(f"{c:.3f}" for c in cells) + " |")
    print(f"\nRefused above a step of {MAX_ROUNDING:g} × the spacing.")


if __name__ == "__main__":
    main()
