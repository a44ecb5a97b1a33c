"""Compare the refined rule with the oriented rule on real scans, and three vertex-normal weightings.

Run: ``.venv/bin/python scripts/compare_rules.py [--pictures]`` (the scans are read from
``../shared/data``; without it, only the synthetic cases run). Its output is kept in
``docs/REFINEMENT_STUDY.md``.

1. Real scans (issue 19, item 4): on each mesh, 300 break-edge points drawn with a fixed seed, each
   measured with rule "refined" and rule "oriented" at a radius of 4% of the mesh's size (its
   bounding box's longest side, as ``scripts/validate.py`` does) and λ = 2. Break-edge points are
   the sharpest vertices: a vertex's sharpness is ``1 - |mean of the unit normals|`` over the
   vertices within three median edge lengths of it (0 on a flat or smoothly curved piece, growing
   with the angle between the faces that meet in the ball), and the 300 are drawn from the
   sharpest 15%. Ranking by normal disagreement finds edges whatever their direction, and the
   15% keeps the draw on edges rather than on the few sharpest spikes of the scan's noise.
   ``--pictures`` draws the largest moves on ``sample_mesh.ply`` into
   ``docs/images/refinement_*.png``.
2. Normals (item 2): area-weighted, angle-weighted and uniform (mean of unit face normals) vertex
   normals, each passed to ``Surface(points, triangles, normals=...)``, measured with both rules
   on creases with exact angles; mean and max absolute error per weighting and rule.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from validate import edge_midpoint

from vg_addon import GoniometerError, Surface
from vg_addon.formats.meshio import read_mesh
from vg_addon.method.refinement import mean_edge_length, refine_sides
from vg_addon.reference_shapes import (
    HALF_ANNULUS_EDGES,
    LENS_RIM_ANGLE,
    marched_wedge,
    stretched_wedge,
)
from vg_addon.synthetic_meshes import bone_fragment

DATA = Path(__file__).resolve().parents[2] / "shared" / "data"
IMAGES = Path(__file__).resolve().parents[1] / "docs" / "images"
RULES = ("refined", "oriented")
N_SITES = 300
SHARPEST = 0.15  # the share of vertices break-edge points are drawn from
BALL_EDGES = 3.0  # the sharpness ball's radius, in median edge lengths
SIZE_SHARE = 0.04  # the measuring radius, of the mesh's size
WEDGE_ANGLES = (20, 45, 90, 120, 150, 165, 175)
WEDGE_RADIUS = 0.2
NOISE = (0.0, 0.001, 0.01)  # of the radius


# ---------------------------------------------------------------------------- vertex normals
def _unit(vectors: np.ndarray) -> np.ndarray:
    lengths = np.linalg.norm(vectors, axis=1)
    return vectors / np.where(lengths > 0, lengths, 1.0)[:, None]


def _accumulate(n: int, triangles: np.ndarray, weighted_per_corner) -> np.ndarray:
    summed = np.zeros((n, 3))
    for k in range(3):
        np.add.at(summed, triangles[:, k], weighted_per_corner[k])
    return _unit(summed)


def normals_by(weighting: str, points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Vertex normals: the sum of the faces' normals around each vertex weighted by the face's
    area (``"area"``), by the face's angle at the vertex (``"angle"``) or equally
    (``"uniform"``, the mean of unit face normals), normalised."""
    a, b, c = (points[triangles[:, k]] for k in range(3))
    cross = np.cross(b - a, c - a)  # length: twice the area
    unit = _unit(cross)
    if weighting == "area":
        return _accumulate(len(points), triangles, (cross, cross, cross))
    if weighting == "uniform":
        return _accumulate(len(points), triangles, (unit, unit, unit))
    corners = ((b - a, c - a), (c - b, a - b), (a - c, b - c))
    weights = []
    for u, v in corners:
        cosine = np.einsum("ij,ij->i", _unit(u), _unit(v))
        weights.append(unit * np.arccos(np.clip(cosine, -1.0, 1.0))[:, None])
    return _accumulate(len(points), triangles, weights)


WEIGHTINGS = ("area", "angle", "uniform")


# ---------------------------------------------------------------------------- real scans
def size_of(points: np.ndarray) -> float:
    return float(np.ptp(points, axis=0).max())


def sharpness(surface: Surface, triangles: np.ndarray) -> np.ndarray:
    """``1 - |mean unit normal|`` over each vertex's ball of three median edge lengths."""
    points = surface.points
    edges = np.linalg.norm(points[triangles[:, 0]] - points[triangles[:, 1]], axis=1)
    ball = BALL_EDGES * float(np.median(edges))
    out = np.zeros(len(points))
    for vertex in surface.valid_ids:
        ids, _ = surface.index.ball(points[vertex], ball)
        out[vertex] = 1.0 - np.linalg.norm(surface.normals[ids].mean(axis=0))
    return out


def break_edge_points(surface: Surface, triangles: np.ndarray, seed: int = 19) -> np.ndarray:
    """300 vertices drawn (fixed seed) from the sharpest 15%."""
    sharp = sharpness(surface, triangles)
    ranked = surface.valid_ids[np.argsort(-sharp[surface.valid_ids], kind="stable")]
    pool = np.sort(ranked[: int(SHARPEST * ranked.size)])
    return np.random.default_rng(seed).choice(pool, min(N_SITES, pool.size), replace=False)


def both_rules(surface, center, radius):
    """The refined and the oriented measurements, or None where either refuses."""
    try:
        return tuple(surface.measure(center, radius, rule=rule) for rule in RULES)
    except GoniometerError:
        return None


def compare_on(name: str, points: np.ndarray, triangles: np.ndarray):
    """Rows of the comparison table for one mesh, and its per-site readings."""
    surface = Surface(points, triangles)
    radius = SIZE_SHARE * size_of(points)
    sites = break_edge_points(surface, triangles)
    readings = []
    for vertex in sites:
        pair = both_rules(surface, points[vertex], radius)
        if pair is not None:
            readings.append((int(vertex), *pair))
    moves = np.array([abs(r.angle - o.angle) for _, r, o in readings])
    changed = np.array([r.split_angle is not None for _, r, _ in readings])
    share_left_out = np.array([r.n_left_out / r.n_vertices for _, r, _ in readings])
    far = [
        crease_distance(surface, r, ~_left_out_mask(surface, o, radius)) > radius
        for _, r, o in readings
        if r.split_angle is not None
    ]

    def stats(values):
        if values.size == 0:
            return "– | – | –"
        return " | ".join(f"{v:.3f}" for v in (np.median(values), np.percentile(values, 95),
                                               values.max()))  # fmt: skip

    row = (
        f"| {name} | {len(points):,} | {radius:.3g} | {len(readings)} of {len(sites)} | "
        f"{int(changed.sum())} | {stats(moves)} | {stats(moves[changed])} | "
        f"{f'{np.median(share_left_out[changed]):.0%}' if changed.any() else '–'} | "
        f"{sum(far)} |"
    )
    return row, surface, radius, readings


def crease_distance(surface: Surface, m, used) -> float:
    """How far the centre lies from the line where the two planes meet (see
    :func:`crease_distance_of`)."""
    return crease_distance_of(surface.points[m.indices] - m.center, m, used)


def crease_distance_of(points, m, used) -> float:
    """How far the centre lies from the line where the measurement's two planes meet (each plane
    through the centroid of its side's used vertices): near 0 when the planes are the two faces
    that meet at the centre. ``points``: the patch, relative to the centre."""
    normals = np.array([m.normal_plus, m.normal_minus])
    offsets = np.array(
        [normals[0] @ points[m.labels & used].mean(axis=0),
         normals[1] @ points[~m.labels & used].mean(axis=0)]
    )  # fmt: skip
    # The point of the line nearest the centre: the least-norm solution of the two plane equations.
    return float(np.linalg.norm(np.linalg.lstsq(normals, offsets, rcond=None)[0]))


# ---------------------------------------------------------------------------- pictures
def _left_out_mask(surface: Surface, oriented, radius: float) -> np.ndarray:
    """Which patch vertices the refinement left out (re-run on the oriented split, as the rule
    does: the Measurement keeps only their count)."""
    points = surface.points[oriented.indices]
    normals = surface.normals[oriented.indices]
    spacing = mean_edge_length(radius, points.shape[0])
    found = refine_sides(
        points, normals, oriented.labels, oriented.center, radius, spacing, oriented.fit_error
    )
    return np.zeros(points.shape[0], dtype=bool) if found is None else ~found["used"]


def _panel(ax, points, m, used, title) -> None:
    """One rule's view: the patch seen along that rule's crease (the cross product of its two
    plane normals), so each of its planes is a line; vertices coloured by that rule's sides."""
    crease = np.cross(m.normal_plus, m.normal_minus)
    crease /= np.linalg.norm(crease)
    up = m.normal_plus + m.normal_minus
    up /= np.linalg.norm(up)
    across = np.cross(crease, up)
    u, v = points @ across, points @ up
    for side, colour, name in ((m.labels, "tab:orange", "+"), (~m.labels, "tab:blue", "−")):
        ax.scatter(u[side], v[side], s=9, c=colour, label=f"side {name}")
    ax.scatter([0.0], [0.0], s=120, marker="*", c="black", label="centre", zorder=3)
    if not used.all():
        ax.scatter(u[~used], v[~used], s=50, marker="x", c="red", label="left out")
    for normal, side in ((m.normal_plus, m.labels), (m.normal_minus, ~m.labels)):
        side = side & used
        centroid = np.array([u[side].mean(), v[side].mean()])
        direction = np.array([-(normal @ up), normal @ across])
        direction /= np.linalg.norm(direction)
        reach = (np.stack([u[side], v[side]], axis=1) - centroid) @ direction
        ends = centroid + np.outer([reach.min(), reach.max()], direction)
        ax.plot(ends[:, 0], ends[:, 1], "-", c="black", lw=1.2)
    ax.set_aspect("equal")
    distance = crease_distance_of(points, m, used)
    ax.set_title(f"{title}: {m.angle:.2f}°, crease {distance:.1f} mm from the centre", fontsize=9)
    ax.set_xlabel("across the crease (mm)", fontsize=8)
    ax.tick_params(labelsize=7)
    ax.legend(fontsize=6, loc="best")


def picture(surface: Surface, refined, oriented, radius: float, path: Path, title: str) -> None:
    """Two views of one patch, each along one rule's crease: the oriented rule's split and planes
    (left) and the refined rule's, with the vertices it left out (right)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    points = surface.points[refined.indices] - refined.center
    left_out = _left_out_mask(surface, oriented, radius)
    fig, axes = plt.subplots(1, 2, figsize=(8.4, 3.9), dpi=80)
    _panel(axes[0], points, oriented, np.ones(len(points), dtype=bool), "oriented")
    _panel(axes[1], points, refined, ~left_out, "refined")
    axes[0].set_ylabel("along the mean normal (mm)", fontsize=8)
    fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


# ---------------------------------------------------------------------------- normals study
def _on_crease(points, direction):
    """The vertex nearest the crease among those near its middle."""
    along = np.abs(points @ direction)
    off = np.linalg.norm(points - np.outer(points @ direction, direction), axis=1)
    return points[np.argmin(np.where(along < 0.05, off, np.inf))]


def normal_cases():
    """(group, points, triangles, centre, radius, exact angle) for every exact crease."""
    for angle in WEDGE_ANGLES:
        for seed in (3, 4):
            points, triangles, _, direction = marched_wedge(angle, 0.02, turn_seed=seed)
            center = _on_crease(points, direction)
            yield "marched", points, triangles, center, WEDGE_RADIUS, angle
            yield "marched", points, triangles[:, ::-1], center, WEDGE_RADIUS, angle
        points, triangles = stretched_wedge(angle)
        center = _on_crease(points, np.array([0.0, 0.0, 1.0]))
        yield "stretched", points, triangles, center, WEDGE_RADIUS, angle
    bone = bone_fragment(spacing=0.5)
    for site in bone.sites:
        yield "bone fragment", bone.points, bone.triangles, site.point, 3.0, site.angle
    if DATA.is_dir():
        mesh = read_mesh(DATA / "HalfAnnulus.ply")
        labels = np.load(DATA / "HalfAnnulus_Labels.npz")["labels"]
        for pair, exact in HALF_ANNULUS_EDGES.items():
            center = edge_midpoint(mesh, labels, pair)
            yield "HalfAnnulus", mesh.points, mesh.triangles, center, 0.3, exact
        mesh = read_mesh(DATA / "IntersectingSpheres.ply")
        centred = mesh.points - mesh.points.mean(axis=0)
        axis = np.linalg.svd(centred, full_matrices=False)[2][2]
        rim = mesh.points[
            np.argmax(np.linalg.norm(centred - np.outer(centred @ axis, axis), axis=1))
        ]
        yield (
            "IntersectingSpheres",
            mesh.points,
            mesh.triangles,
            rim,
            0.06 * size_of(mesh.points),
            LENS_RIM_ANGLE,
        )


def normals_study():
    """errors[(group, noise, weighting, rule)] = list of |error| (refusals counted apart)."""
    errors, refused = {}, {}
    rng = np.random.default_rng(2)
    for group, points, triangles, center, radius, exact in normal_cases():
        for level in NOISE:
            noisy = (
                points + rng.normal(scale=level * radius, size=points.shape) if level else points
            )
            for weighting in WEIGHTINGS:
                surface = Surface(noisy, triangles, normals=normals_by(weighting, noisy, triangles))
                for rule in RULES:
                    key = (group, level, weighting, rule)
                    try:
                        m = surface.measure(center, radius, rule=rule)
                    except GoniometerError:
                        refused[key] = refused.get(key, 0) + 1
                        continue
                    errors.setdefault(key, []).append(abs(m.angle - exact))
    return errors, refused


def print_normals_table(errors, refused) -> None:
    groups = list(dict.fromkeys(key[0] for key in errors))
    header = ["case", "noise"] + [f"{w} {r}" for w in WEIGHTINGS for r in RULES]
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    overall = {}
    for group in groups:
        for level in NOISE:
            cells = []
            for weighting in WEIGHTINGS:
                for rule in RULES:
                    key = (group, level, weighting, rule)
                    values = errors.get(key, [])
                    overall.setdefault((weighting, rule), []).extend(values)
                    text = f"{np.mean(values):.3f} / {max(values):.3f}" if values else "–"
                    if refused.get(key):
                        text += f" ({refused[key]} refused)"
                    cells.append(text)
            print(f"| {group} | {level:.1%} | " + " | ".join(cells) + " |")
    wedges = {}
    for (group, _, weighting, rule), values in errors.items():
        if group in ("marched", "stretched"):
            wedges.setdefault((weighting, rule), []).extend(values)
    for name, pooled in (("wedges, all noise levels", wedges), ("all", overall)):
        cells = [
            f"**{np.mean(pooled[(w, r)]):.3f} / {max(pooled[(w, r)]):.3f}**"
            for w in WEIGHTINGS
            for r in RULES
        ]
        print(f"| **{name}** | | " + " | ".join(cells) + " |")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pictures", action="store_true", help="draw the largest moves")
    parser.add_argument("--skip-normals", action="store_true")
    parser.add_argument("--skip-scans", action="store_true")
    args = parser.parse_args(argv)
    if not args.skip_scans:
        meshes = []
        if DATA.is_dir():
            for name in ("sample_mesh.ply", "HalfAnnulus.ply", "IntersectingSpheres.ply"):
                mesh = read_mesh(DATA / name)
                meshes.append((name, mesh.points, mesh.triangles))
        else:
            print(f"{DATA} is absent: the real scans are skipped (only the synthetic mesh runs).")
        bone = bone_fragment(spacing=0.5)
        meshes.append(("bone_fragment() 0.5 mm", bone.points, bone.triangles))
        print("| mesh | vertices | radius | measured by both | changed | all: median | 95% | max "
              "| changed: median | 95% | max | left out (median share) "
              "| refined crease > r from centre |")  # fmt: skip
        print("|" + "---|" * 13)
        for name, points, triangles in meshes:
            row, surface, radius, readings = compare_on(name, points, triangles)
            print(row)
            if args.pictures and name == "sample_mesh.ply":
                largest = sorted(readings, key=lambda r: -abs(r[1].angle - r[2].angle))[:3]
                for rank, (vertex, refined, oriented) in enumerate(largest, 1):
                    path = IMAGES / f"refinement_{rank}.png"
                    title = (f"sample_mesh.ply, vertex {vertex}: refined {refined.angle:.2f}°, "
                             f"oriented {oriented.angle:.2f}°")  # fmt: skip
                    picture(surface, refined, oriented, radius, path, title)
                    print(f"  {path.name}: vertex {vertex}, refined {refined.angle:.2f}°, "
                          f"oriented {oriented.angle:.2f}°, re-assigned "
                          f"{int((refined.labels != oriented.labels).sum())}, left out "
                          f"{refined.n_left_out} of {refined.n_vertices}")  # fmt: skip
        print()
    if not args.skip_normals:
        print_normals_table(*normals_study())


if __name__ == "__main__":
    main()
