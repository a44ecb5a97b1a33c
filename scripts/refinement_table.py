"""Print the refined rule's table in docs/METHOD.md: creases between vertex rows, and walls that
must not get worse, each read by the oriented rule (Algorithm 1 with the oriented sign) and by the
refined rule (the default).

Run: .venv/bin/python scripts/refinement_table.py (a few minutes; the reference file rows need
../shared/data, and are skipped without it). With ``--variants``: how many of the stretched
wedges on four grids, upright, wound as valleys, turned at random and jittered off their faces,
each rule reads right (within 0.1°; 175°: 0.5°), wrong or refuses (the table's "Variants").
With ``--unseen``: the same count on stretched wedges of other grids, angles, jitters, seeds and
a turn that the rule was not tuned on, turned and wound as valleys.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from vg_addon import GoniometerError, Surface  # noqa: E402
from vg_addon.reference_shapes import (  # noqa: E402
    HALF_ANNULUS_EDGES,
    _turn,
    half_annulus,
    marched_wedge,
    stretched_wedge,
)
from vg_addon.synthetic_meshes import bone_fragment  # noqa: E402

ANGLES = (5, 20, 45, 90, 120, 150, 165, 170, 175)


def reading(surface, center, radius, rule, exact):
    try:
        return f"{surface.measure(center, radius, rule=rule).angle - exact:+.3f}"
    except GoniometerError:
        return "refused"


def crease_rows():
    print("| mesh | " + " | ".join(f"{a}°" for a in ANGLES) + " |")
    print("|---|" + "---|" * len(ANGLES))
    for spacing in (0.0067, 0.0106, 0.02):
        cells = {"oriented": [], "refined": []}
        for angle in ANGLES:
            points, triangles = stretched_wedge(angle, spacing)
            center = points[np.argmin(np.linalg.norm(points, axis=1))]
            for rule in cells:
                cells[rule].append(reading(Surface(points, triangles), center, 0.2, rule, angle))
        for rule, row in cells.items():
            print(f"| stretched, grid {spacing:g}, {rule} | " + " | ".join(row) + " |")
    for seed in (None, 3):
        cells = {"oriented": [], "refined": []}
        for angle in ANGLES:
            points, triangles, _, direction = marched_wedge(angle, 0.02, turn_seed=seed)
            along = np.abs(points @ direction)
            off = np.linalg.norm(points - np.outer(points @ direction, direction), axis=1)
            center = points[np.argmin(np.where(along < 0.05, off, np.inf))]
            for rule in cells:
                worst = []
                for faces in (triangles, triangles[:, ::-1]):  # ridge and valley
                    worst.append(reading(Surface(points, faces), center, 0.2, rule, angle))
                cells[rule].append(max(worst, key=lambda c: abs(float(c)) if c[0] in "+-" else 99))
        turned = "turned" if seed else "upright"
        for rule, row in cells.items():
            print(f"| marched, {turned}, ridge/valley worst, {rule} | " + " | ".join(row) + " |")


def wall_rows():
    print("\n| walls | sites | oriented: mean / max abs error | refined: mean / max | worse |")
    print("|---|---|---|---|---|")
    bone = bone_fragment(spacing=0.6, roughness=0.05, seed=1)
    cases = [
        ("bone shaft (demo), r 3 mm", Surface(bone.points, bone.triangles), s.point, 3.0, s.angle)
        for s in bone.sites
    ]
    ha = half_annulus()
    hs = Surface(ha.points, ha.triangles)
    for pair, exact in HALF_ANNULUS_EDGES.items():
        corner = ha.labels[ha.triangles]
        straddle = (
            np.isin(corner, pair).all(1) & (corner == pair[0]).any(1) & (corner == pair[1]).any(1)
        )
        vertices = np.unique(ha.triangles[straddle])
        middle = np.median(ha.points[vertices], axis=0)
        center = ha.points[
            vertices[np.argmin(np.linalg.norm(ha.points[vertices] - middle, axis=1))]
        ]
        for radius in (0.3, 0.4, 0.5):
            cases.append(("half annulus (project's), r 0.3-0.5", hs, center, radius, exact))
    groups = {}
    for name, surface, center, radius, exact in cases:
        errors = [
            abs(surface.measure(center, radius, rule=r).angle - exact)
            for r in ("oriented", "refined")
        ]
        groups.setdefault(name, []).append(errors)
    for name, errors in groups.items():
        e = np.array(errors)
        worse = int((e[:, 1] > e[:, 0] + 1e-9).sum())
        print(
            f"| {name} | {len(e)} | {e[:, 0].mean():.2f} / {e[:, 0].max():.2f} | {e[:, 1].mean():.2f} / {e[:, 1].max():.2f} | {worse} |"
        )


VARIANT_ANGLES = (5, 20, 45, 90, 120, 135, 150, 160, 165, 170, 172, 175)


def variants():
    """Yield (group, exact angle, points, triangles, centre) for the stretched variants."""
    for spacing in (0.0067, 0.0106, 0.015, 0.02):
        flat, triangles = stretched_wedge(90.0, spacing)  # one march; each angle stretches it
        for angle in VARIANT_ANGLES:
            points = flat.copy()
            points[:, 1] *= math.tan(math.radians(angle) / 2.0)
            center = points[np.argmin(np.linalg.norm(points, axis=1))]
            turn = _turn(7)
            yield "stretched", angle, points, triangles, center
            yield "stretched", angle, points, triangles[:, ::-1], center
            yield "stretched", angle, points @ turn.T, triangles, center @ turn.T
            rng = np.random.default_rng(int(angle * 10 + spacing * 1e4))
            for jitter in (0.01, 0.05):
                noisy = points + rng.normal(scale=jitter * spacing, size=points.shape)
                yield f"stretched, jittered {jitter:.0%}", angle, noisy, triangles, center


def variant_rows(cases=None):
    counts = {}
    for group, angle, points, triangles, center in cases or variants():
        surface = Surface(points, triangles)
        for rule in ("oriented", "refined"):
            cell = reading(surface, center, 0.2, rule, angle)
            right = cell != "refused" and abs(float(cell)) <= (0.5 if angle == 175 else 0.1)
            kind = "refused" if cell == "refused" else ("right" if right else "wrong")
            row = counts.setdefault((group, rule), {"right": 0, "wrong": 0, "refused": 0})
            row[kind] += 1
    print("\n| creases | rule | right | wrong | refused |\n|---|---|---|---|---|")
    for (group, rule), row in counts.items():
        print(f"| {group} | {rule} | {row['right']} | {row['wrong']} | {row['refused']} |")


def unseen():
    """Yield (group, exact angle, points, triangles, centre): stretched wedges on grids, angles,
    jitters and seeds that the variants do not use, turned by another rotation, as valleys."""
    turn = _turn(11)
    for spacing in (0.008, 0.0125, 0.017):
        flat, triangles = stretched_wedge(90.0, spacing)
        for angle in (10, 30, 60, 100, 140, 155, 168, 174):
            points = flat.copy()
            points[:, 1] *= math.tan(math.radians(angle) / 2.0)
            center = points[np.argmin(np.linalg.norm(points, axis=1))]
            for jitter in (0.0, 0.02, 0.05):
                seed = 1000 + angle + int(spacing * 1e4) + int(jitter * 100)
                noise = np.random.default_rng(seed).normal(
                    scale=jitter * spacing, size=points.shape
                )
                moved = points + noise if jitter else points
                group = f"unseen, jittered {jitter:.0%}"
                yield group, angle, moved @ turn.T, triangles[:, ::-1], center @ turn.T


if __name__ == "__main__":
    if "--unseen" in sys.argv:
        variant_rows(unseen())
    elif "--variants" in sys.argv:
        variant_rows()
    else:
        crease_rows()
        wall_rows()
