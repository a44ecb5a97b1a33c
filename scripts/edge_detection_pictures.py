"""Pictures and the quality table of docs/EDGE_DETECTION.md: what Find Break Edges finds.

    .venv-bpy53/bin/python scripts/edge_detection_pictures.py      # needs matplotlib

Draws each synthetic fragment of ``vg_addon.fragments`` (clean and noisy) with its true edges
dashed and the candidates numbered, coloured by confidence, over the regions found; prints the
recall / false-length table (``tests/core/edge_truth.score``), the harder cases' table, the
noisy marched fragments' with other noise seeds and the demo shaft's at coarse spacings; then the same pictures, without truth, of the real meshes in
../shared/data when they are there.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT), str(ROOT / "tests" / "core")]

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from edge_truth import found_on, mean_edge_length, score  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402

from vg_addon import Surface  # noqa: E402
from vg_addon.formats.meshio import read_mesh  # noqa: E402
from vg_addon.fragments import (  # noqa: E402
    bevelled_cube,
    bone_shaft,
    flake,
    marched_bevelled_cube,
    marched_flake,
    with_noise,
)

OUT = ROOT / "docs" / "images"
DATA = ROOT.parent / "shared" / "data"
MAX_DRAWN = 60_000  # triangles drawn per view (a random sample of a bigger mesh)
MARCH_STEP = 0.4  # the marched fragments' grid step: how far marching cuts a corner, at most
KIND_COLOURS = {0: (0.80, 0.80, 0.62), 1: (0.55, 0.70, 0.88), 2: (0.93, 0.62, 0.45)}


def draw(
    points, triangles, result, path: Path, title: str, truth=(), views=((25, -60), (-30, 120))
):
    """Two views of the mesh: regions shaded by kind (blue original, orange fracture, sand
    unknown, grey band), true edges dashed, candidates numbered and coloured by confidence."""
    rng = np.random.default_rng(0)
    drawn = (
        triangles
        if len(triangles) <= MAX_DRAWN
        else triangles[rng.choice(len(triangles), MAX_DRAWN, replace=False)]
    )
    corners = points[drawn]
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True) + 1e-300
    region = result.region[drawn[:, 0]]
    colour = np.full((len(drawn), 3), 0.78)
    for kind, rgb in KIND_COLOURS.items():
        colour[(region >= 0) & (result.region_kind[np.maximum(region, 0)] == kind)] = rgb
    fig = plt.figure(figsize=(12, 6))
    low, high = points.min(axis=0), points.max(axis=0)
    centre, reach = (low + high) / 2, (high - low).max() / 2
    for k, (elevation, azimuth) in enumerate(views):
        ax = fig.add_subplot(1, len(views), k + 1, projection="3d")
        ax.view_init(elevation, azimuth)
        e, a = np.radians(elevation), np.radians(azimuth)
        light = np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])  # the viewer
        shade = 0.45 + 0.55 * np.abs(normal @ light)
        ax.add_collection3d(
            Poly3DCollection(
                corners, facecolors=colour * shade[:, None], edgecolors="none", alpha=0.45
            )
        )
        for edge in truth:
            ax.plot(*edge.T, color="k", lw=0.9, ls="--")
        for c in result.candidates:
            p = c.path.points
            ax.plot(*p.T, color=plt.get_cmap("plasma")(0.9 * c.confidence), lw=2.0)
            ax.text(*p[len(p) // 2], str(c.number), fontsize=9)
        for axis, set_lim in enumerate((ax.set_xlim, ax.set_ylim, ax.set_zlim)):
            set_lim(centre[axis] - reach, centre[axis] + reach)
        ax.set_axis_off()
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def synthetic() -> None:
    print(
        "| fragment | vertices | mean edge (mm) | true length (mm) | found (mm) | recall | false | candidates | time (s) |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    for name, make in (
        ("bone", lambda: bone_shaft(0.3)),
        ("cube", bevelled_cube),
        ("flake", flake),
    ):
        clean = make()
        h = mean_edge_length(clean.points, clean.triangles)
        for fragment, tag in ((clean, ""), (with_noise(clean, 0.1 * h, seed=1), "_noisy")):
            surface = Surface(fragment.points, fragment.triangles)
            start = time.perf_counter()
            result = surface.find_break_edges()
            seconds = time.perf_counter() - start
            f = score(fragment, [c.path.points for c in result.candidates])
            print(
                f"| {fragment.name} | {surface.n_points:,} | {f['tolerance']:.3f} | {f['true_length']:.0f} | "
                f"{f['found_length']:.0f} | {100 * f['recall']:.1f}% | {100 * f['false']:.1f}% | "
                f"{len(result.candidates)} | {seconds:.2f} |"
            )
            draw(
                fragment.points,
                fragment.triangles,
                result,
                OUT / f"edge_detection_{name}{tag}.png",
                f"{fragment.name}: {len(result.candidates)} candidates (true edges dashed)",
                fragment.edges,
            )


def harder() -> None:
    """The limits table: noise of 0.3 mean edge lengths, and fragments meshed by marching
    tetrahedra (edges between vertices), scored at one mean edge and at the marching step."""
    print("| fragment | vertices | tolerance (mm) | found (mm) | recall | false | bar |")
    print("|---|---|---|---|---|---|---|")
    cases = [(make, 0.3, None) for make in (lambda: bone_shaft(0.3), bevelled_cube, flake)]
    cases += [(make, noise, tolerance) for make in (marched_bevelled_cube, marched_flake)
              for noise in (0.0, 0.1) for tolerance in (None, MARCH_STEP)]  # fmt: skip
    for make, noise, tolerance in cases:
        fragment, surface, _, f = found_on(make, noise, tolerance)
        passed = f["recall"] >= 0.95 and f["false"] <= 0.05
        print(
            f"| {fragment.name} | {surface.n_points:,} | {f['tolerance']:.3f} | {f['found_length']:.0f} | "
            f"{100 * f['recall']:.1f}% | {100 * f['false']:.1f}% | {'pass' if passed else 'FAIL'} |"
        )


def seeds() -> None:
    """The noisy marched fragments with other noise seeds, at the default scale and, for the
    cube, at a scale of its fillets' size (2 mm)."""
    print(
        "| fragment | scale | seed | candidates | within one edge | within the step | bar (one edge) |"
    )
    print("|---|---|---|---|---|---|---|")
    cases = [
        ("bevelled cube, marched", marched_bevelled_cube, {}),
        ("flake, marched", marched_flake, {}),
        ("bevelled cube, marched", marched_bevelled_cube, {"scale": 2.0}),
    ]
    for label, make, parameters in cases:
        for seed in range(1, 7):
            fragment, _, result, f = found_on(make, 0.1, None, seed, **parameters)
            step = score(fragment, [c.path.points for c in result.candidates], MARCH_STEP)
            passed = f["recall"] >= 0.95 and f["false"] <= 0.05
            print(
                f"| {label}, noise 0.1 edge | {result.parameters.scale:.2f} | {seed} | "
                f"{len(result.candidates)} of {len(fragment.edges)} | "
                f"{100 * f['recall']:.1f}% / {100 * f['false']:.1f}% | "
                f"{100 * step['recall']:.1f}% / {100 * step['false']:.1f}% | "
                f"{'pass' if passed else 'FAIL'} |"
            )


def demo() -> None:
    """The README demo's shaft at coarse spacings: a 5 mm transverse face, narrower than the
    band the default scale leaves round its rims from 0.5 mm up (the narrow-face rule)."""
    print("| spacing (mm) | roughness (mm) | vertices | scale (mm) | recall | false | candidates |")
    print("|---|---|---|---|---|---|---|")
    for spacing in (0.5, 0.6, 0.7, 0.8, 1.0):
        for roughness in (0.0, 0.05):
            fragment = bone_shaft(spacing, roughness=roughness, seed=1)
            surface = Surface(fragment.points, fragment.triangles)
            result = surface.find_break_edges()
            f = score(fragment, [c.path.points for c in result.candidates])
            print(
                f"| {spacing:g} | {roughness:g} | {surface.n_points:,} | {result.parameters.scale:.2f} | "
                f"{100 * f['recall']:.1f}% | {100 * f['false']:.1f}% | {len(result.candidates)} |"
            )


def real() -> None:
    for file in ("sample_mesh.ply", "HalfAnnulus.ply", "IntersectingSpheres.ply"):
        if not (DATA / file).exists():
            print(f"{file}: not in {DATA}, skipped")
            continue
        mesh = read_mesh(DATA / file)
        surface = Surface(mesh.points, mesh.triangles)
        start = time.perf_counter()
        result = surface.find_break_edges()
        seconds = time.perf_counter() - start
        print(
            f"\n{file}: {surface.n_points:,} vertices, {seconds:.2f} s, {len(result.candidates)} candidates, "
            f"parameters {result.parameters}, ridge_min_deg {result.ridge_min_deg:.1f}"
        )
        for c in result.candidates:
            print(
                f"  {c.number:3d} length {c.length:7.2f} confidence {c.confidence:.2f} bend {c.mean_bend_deg:5.1f}"
                f" closed {c.closed} regions {c.regions} waypoints {len(c.path.waypoints)}"
            )
        draw(
            mesh.points,
            mesh.triangles,
            result,
            OUT / f"edge_detection_{Path(file).stem}.png",
            f"{file}: {len(result.candidates)} candidates",
        )


if __name__ == "__main__":
    synthetic()
    harder()
    seeds()
    demo()
    real()
