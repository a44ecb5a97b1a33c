"""Print the stability figure's tables in docs/METHOD.md ("What the figure covers"): on wedges of
known angle, how many readings the figure covers (error at most the figure), calls undetermined,
or does not cover, with and without its crease part; and how the crease part changes the figure
on the cases read right (creases through a row of vertices, marched wedges), on curved walls and
on the real scan's break-edge points of docs/REFINEMENT_STUDY.md.

Run: .venv/bin/python scripts/stability_table.py (about ten minutes; the scan rows need
../shared/data and are skipped without it). Every reading is the default (refined) rule's, at
r = 0.2 and λ = 2 on the wedges, centre the vertex nearest the crease.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "scripts"))

from refinement_table import variants  # noqa: E402
from validate import edge_midpoint  # noqa: E402

from vg_addon import GoniometerError, Surface  # noqa: E402
from vg_addon.reference_shapes import (  # noqa: E402
    HALF_ANNULUS_EDGES,
    half_annulus,
    marched_wedge,
    stretched_wedge,
)
from vg_addon.synthetic_meshes import bone_fragment, wedge  # noqa: E402


def figures(surface, center, radius):
    """The measurement and its figure without and with the crease part (``None``: refused)."""
    try:
        m = surface.measure(center, radius, stability=True)
    except GoniometerError:
        return None
    s = m.stability
    before = max(s.center, s.radius, s.lam, s.bootstrap, s.orientation)
    return m, before, s


def verdict(error, figure, undetermined):
    if undetermined:
        return "undetermined"
    return "covered" if abs(error) <= figure else "not covered"


def held_out():
    """Stretched wedges on grids, angles and jitter seeds the variants table does not use."""
    for spacing in (0.0085, 0.0125, 0.0175):
        flat, triangles = stretched_wedge(90.0, spacing)
        for angle in (10, 30, 60, 100, 140, 155, 162, 168, 171, 174):
            points = flat.copy()
            points[:, 1] *= math.tan(math.radians(angle) / 2.0)
            center = points[np.argmin(np.linalg.norm(points, axis=1))]
            yield "held out, valley", angle, points, triangles[:, ::-1], center
            for jitter, seed in ((0.005, 101), (0.02, 202), (0.03, 303), (0.05, 404)):
                rng = np.random.default_rng(seed + angle)
                noisy = points + rng.normal(scale=jitter * spacing, size=points.shape)
                yield f"held out, jittered {jitter:.1%}", angle, noisy, triangles, center


def coverage_rows():
    counts = {}
    for group, angle, points, triangles, center in [*variants(), *held_out()]:
        found = figures(Surface(points, triangles), center, 0.2)
        if found is None:
            continue
        m, before, s = found
        error = m.angle - angle
        old = verdict(error, before, s.n_failed > 0.1 * s.n_runs)
        new = verdict(error, s.spread, s.text() == "± ?")
        row = counts.setdefault(group, {})
        for key in (f"before {old}", f"after {new}"):
            row[key] = row.get(key, 0) + 1
    print("| wedges | measured | covered before → after | undetermined | not covered |")
    print("|---|---|---|---|---|")
    for group, row in counts.items():
        total = sum(v for k, v in row.items() if k.startswith("before"))

        def pair(kind, row=row):
            return f"{row.get('before ' + kind, 0)} → {row.get('after ' + kind, 0)}"

        print(
            f"| {group} | {total} | {pair('covered')} | {pair('undetermined')} | "
            f"{pair('not covered')} |"
        )


def right_cases():
    for angle in range(10, 171, 10):
        for concave in (False, True):
            for irregular in (False, True):
                mesh = wedge(angle, n=50, irregular=irregular, seed=angle, concave=concave)
                surface = Surface(mesh.points, mesh.triangles)
                yield "crease on a vertex row", surface, [0.02, 0.01, 0.0], 0.5, angle
    for spacing in (0.013, 0.02, 0.03):
        for seed in (None, 3):
            for angle in (20, 45, 90, 120, 150, 165, 170, 175):
                points, triangles, _, direction = marched_wedge(angle, spacing, turn_seed=seed)
                along = np.abs(points @ direction)
                off = np.linalg.norm(points - np.outer(points @ direction, direction), axis=1)
                center = points[np.argmin(np.where(along < 0.05, off, np.inf))]
                for faces in (triangles, triangles[:, ::-1]):
                    yield "marched wedge", Surface(points, faces), center, 0.2, angle
    bone = bone_fragment(spacing=0.6, roughness=0.05, seed=1)
    surface = Surface(bone.points, bone.triangles)
    for site in bone.sites:
        yield "bone shaft wall (demo), r 3 mm", surface, site.point, 3.0, site.angle
    ha = half_annulus()
    surface = Surface(ha.points, ha.triangles)
    for pair, exact in HALF_ANNULUS_EDGES.items():
        center = edge_midpoint(ha, ha.labels, pair)
        for radius in (0.3, 0.4, 0.5):
            yield "half annulus walls, r 0.3-0.5", surface, center, radius, exact


def scan_cases():
    data = ROOT.parent / "shared" / "data" / "sample_mesh.ply"
    if not data.exists():
        return
    from compare_rules import SIZE_SHARE, break_edge_points, size_of

    from vg_addon.formats.meshio import read_mesh

    mesh = read_mesh(data)
    surface = Surface(mesh.points, mesh.triangles)
    radius = SIZE_SHARE * size_of(mesh.points)
    for vertex in break_edge_points(surface, mesh.triangles):
        yield "sample_mesh.ply, 300 break-edge points", surface, mesh.points[vertex], radius, None


def change_rows():
    groups = {}
    for group, surface, center, radius, exact in [*right_cases(), *scan_cases()]:
        found = figures(surface, center, radius)
        if found is not None:
            groups.setdefault(group, []).append((found, exact))
    print(
        "\n| cases | measured | figure before: median / max | after: median / max | "
        "crease part: median / 95th pct / max | newly undetermined | over 5° before → after | "
        "error covered before → after |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for group, rows in groups.items():
        before = np.array([b for (_, b, _), _ in rows])
        after = np.array([s.spread for (_, _, s), _ in rows])
        crease = np.array([s.crease for (_, _, s), _ in rows])
        newly = sum(
            (s.crease_refused > 0 or s.noise_hides_crease) and s.n_failed <= 0.1 * s.n_runs
            for (_, _, s), _ in rows
        )
        errors = [(abs(m.angle - e), b, s) for (m, b, s), e in rows if e is not None]
        covered = (
            f"{sum(err <= b for err, b, _ in errors)} → "
            f"{sum(err <= s.spread or s.text() == '± ?' for err, _, s in errors)}"
            if errors
            else "–"
        )
        print(
            f"| {group} | {len(rows)} | {np.median(before):.2f} / {before.max():.2f} | "
            f"{np.median(after):.2f} / {after.max():.2f} | {np.median(crease):.2f} / "
            f"{np.percentile(crease, 95):.2f} / {crease.max():.2f} | {newly} | "
            f"{int((before > 5).sum())} → {int((after > 5).sum())} | {covered} |"
        )


if __name__ == "__main__":
    coverage_rows()
    change_rows()
