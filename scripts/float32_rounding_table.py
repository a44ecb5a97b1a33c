"""Print the tables of docs/METHOD.md, "Coordinates far from the origin": how far float32
rounding moves a reading, by the rounding step as a share of the patch's vertex spacing, and by
the patch's vertex count.

Irregular synthetic wedges are moved away from the origin (at random, six or eight moves a
cell) until float32 rounds their coordinates to the step asked, stored as float32 and measured
as if the rounded coordinates were exact (``precision="float64"``, which the extension does not
do). In the first table a cell is the largest error in degrees against the wedge's true angle;
in the second, the largest move against the same patch measured at float64 (the rounding's own
effect), with the sensitivity ``move * n / share`` that ``precision.ROUNDING_SENSITIVITY``
bounds.

Run: .venv/bin/python scripts/float32_rounding_table.py (about a minute).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from vg_addon import GoniometerError, Surface  # noqa: E402
from vg_addon.method.precision import (  # noqa: E402
    MAX_MOVE,
    MAX_ROUNDING,
    ROUNDING_SENSITIVITY,
    rounding_limit,
)
from vg_addon.synthetic_meshes import wedge  # noqa: E402

RATIOS = (0.003, 0.01, 0.03, 0.1, 0.3, 1.0)
CASES = ((90.0, 60, 0.5), (90.0, 30, 0.5), (130.0, 60, 0.3), (60.0, 40, 0.5))
MOVES = 6


SENSITIVITY_ANGLES = (60.0, 90.0, 130.0, 160.0)
SENSITIVITY_PATCHES = ((25, 0.15), (15, 0.3), (25, 0.3), (40, 0.3), (25, 0.6), (40, 0.6), (60, 0.6))
SENSITIVITY_RATIOS = (0.01, 0.03, 0.1)
SENSITIVITY_MOVES = 8


def measured_patch_size(points, triangles, radius: float) -> int:
    """The vertex count of the patch measured: the one round the vertex nearest the wedge's
    centre (the origin), where each reading is taken."""
    centre_vertex = int(np.argmin(np.linalg.norm(points, axis=1)))
    return int(Surface(points, triangles).patch(centre_vertex, radius).size)


def far_centre(ratio: float, size: float, rng) -> np.ndarray:
    """A random centre far enough from the origin that float32 keeps coordinates there to a
    step of at most ``ratio * size`` and at least half of it."""
    # float32 keeps a number in [2**e, 2**(e+1)) to steps of 2**(e-23).
    exponent = np.floor(np.log2(ratio * size)) + 23
    signs = rng.choice([-1.0, 1.0], 3)
    return 2.0**exponent * rng.uniform(1.0, 1.9) * np.array([1.0, -0.5, 0.3]) * signs


def largest_move(angle: float, grid: int, radius: float, ratio: float, rng) -> tuple[int, float]:
    """The patch's vertex count and the largest move of its reading that rounding makes."""
    shape = wedge(angle, n=grid, irregular=True, seed=3)
    points = np.asarray(shape.points, dtype=np.float64)
    triangles = np.asarray(shape.triangles)
    count = measured_patch_size(points, triangles, radius)
    size = radius * np.sqrt(np.pi / count)
    worst = 0.0
    for _ in range(SENSITIVITY_MOVES):
        centre = far_centre(ratio, size, rng)
        moved = points + centre
        try:
            exact = Surface(moved, triangles).measure(centre, radius).angle
            rounded = moved.astype(np.float32)
            reading = Surface(rounded, triangles, precision="float64").measure(centre, radius)
        except GoniometerError:
            continue  # refused for another reason (too few vertices on a side): no move to show
        worst = max(worst, abs(reading.angle - exact))
    return count, worst


def sensitivity_table(rng) -> None:
    print("\nCells: the largest move (°) over four angles / the sensitivity, move × n / share.\n")
    header = " | ".join(f"step ≤ {r:g} × spacing" for r in SENSITIVITY_RATIOS)
    print(f"| patch vertices n | {header} |")
    print("|---|" + "---|" * len(SENSITIVITY_RATIOS))
    highest = 0.0
    for grid, radius in SENSITIVITY_PATCHES:
        cells = []
        count = 0
        for ratio in SENSITIVITY_RATIOS:
            moves = []
            for angle in SENSITIVITY_ANGLES:
                count, move = largest_move(angle, grid, radius, ratio, rng)
                moves.append(move)
            sensitivity = max(moves) * count / ratio
            highest = max(highest, sensitivity)
            cells.append(f"{max(moves):.3f} / {sensitivity:.0f}")
        print(f"| {count} | " + " | ".join(cells) + " |")
    print(
        f"\nHighest sensitivity {highest:.0f} (bounded by {ROUNDING_SENSITIVITY:g}); the limit "
        f"keeps the move under {MAX_MOVE:g}°: a step of "
        + ", ".join(f"{rounding_limit(n):.3g} × at {n}" for n in (13, 100, 400, 1000, 2000))
        + " vertices."
    )


def largest_error(angle: float, n: int, radius: float, ratio: float, rng) -> float:
    shape = wedge(angle, n=n, irregular=True)
    points = np.asarray(shape.points, dtype=np.float64)
    triangles = np.asarray(shape.triangles)
    size = radius * np.sqrt(np.pi / measured_patch_size(points, triangles, radius))
    worst = 0.0
    for _ in range(MOVES):
        centre = far_centre(ratio, size, rng)
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
    print(f"\nRefused above a step of {MAX_ROUNDING:g} × the spacing at most.")
    sensitivity_table(rng)


if __name__ == "__main__":
    main()
