"""How much the coarse bend field depends on where its grid's cubes fall (docs/EDGE_DETECTION.md,
*Where the marched rows miss*).

    .venv/bin/python scripts/coarse_field_phase.py

On the marched bevelled cube (``vg_addon.fragments.marched_bevelled_cube``) at the default scale,
moves the cells' grid by a quarter, a half and three quarters of a cube and prints, for each of
the two 1.5 mm fillets, the median bend the coarse field reads in the middle third of its arc and
the share of those vertices below the 30° bar.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from vg_addon import Surface, fragments
from vg_addon.method.break_edges import BreakEdgeParameters
from vg_addon.method.edge_profile import ridge_graph
from vg_addon.method.ridge_field import (
    anisotropy_of_bend,
    bend_of_anisotropy,
    cell_spread,
    vertex_moments,
)

SIZE, FILLET = 20.0, 1.5  # the cube's defaults


def finished(steps):
    """The value a stepwise generator returns."""
    try:
        while True:
            next(steps)
    except StopIteration as done:
        return done.value


def fillet_middles(points: np.ndarray) -> list[np.ndarray]:
    """Each fillet's vertices 30° to 60° round its arc, 2 mm or more from the cube's ends."""
    inner = SIZE / 2 - FILLET
    middles = []
    for side in (1.0, -1.0):
        turn = np.degrees(np.arctan2(points[:, 2] - inner, side * points[:, 0] - inner))
        middles.append(
            (side * points[:, 0] > inner)
            & (points[:, 2] > inner)
            & (turn > 30)
            & (turn < 60)
            & (np.abs(points[:, 1]) < SIZE / 2 - 2)
        )
    return middles


def main() -> None:
    cube = fragments.marched_bevelled_cube(SIZE, FILLET)
    surface = Surface(cube.points, cube.triangles)
    graph = ridge_graph(surface)
    scale = BreakEdgeParameters().resolved(graph.mean_edge_length).scale
    sums = finished(vertex_moments(surface.points, surface.triangles, graph.starts, graph.target))
    middles = fillet_middles(surface.points)
    bar = anisotropy_of_bend(30.0)
    cube_step = scale / 2.0
    print(
        f"marched cube: {surface.n_points:,} vertices, scale {scale:.3f} mm, cubes {cube_step:.3f} mm"
    )
    print("grid moved by | fillet +x: median bend, below 30° | fillet -x: median bend, below 30°")
    for share in (0.0, 0.25, 0.5, 0.75):
        # The grid is anchored at the least corner: a vertex beyond it moves the grid back.
        shifted = np.vstack([surface.points, surface.points.min(axis=0) - share * cube_step])
        padded = np.vstack([sums, np.zeros((1, sums.shape[1]))])
        starts = np.append(graph.starts, graph.starts[-1])
        crease, _ = finished(cell_spread(shifted, padded, scale, starts, graph.target))
        cells = [
            f"{np.median(bend_of_anisotropy(crease[:-1][m])):5.1f}°, {np.mean(crease[:-1][m] < bar):4.0%}"
            for m in middles
        ]
        print(f"{share:13.2f} | {cells[0]:>34} | {cells[1]:>34}")


if __name__ == "__main__":
    main()
