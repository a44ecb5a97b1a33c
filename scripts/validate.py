"""Validate the measuring method against exact angles and print one table (Markdown).

Run: ``.venv/bin/python scripts/validate.py`` (any Python with NumPy; the reference meshes are read
from ``../shared/data`` when present). Its output is kept in ``docs/VALIDATION.md``.

Rows: convex and concave wedges from 5° to 175° (exact planes; the concave angle is the open
wedge's), and the edges of the reference meshes and the synthetic bone fragment. Columns: the same
edge meshed regularly, remeshed irregularly, wound inward, rounded by a fillet of 5% of the radius,
and with Gaussian noise of 0.1% and 1% of the radius on every vertex; each cell reads ``default rule / paper rule`` in degrees. Then the
convex/concave label and the stability figure of the default rule (on the 1% noise copy), and the
largest error of each rule over the row. Nothing passes or fails here: read the numbers.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from vg_addon import GoniometerError, Surface
from vg_addon.formats.meshio import read_mesh
from vg_addon.synthetic_meshes import bevelled_wedge, bone_fragment, wedge

ANGLES = (5, 10, 20, 30, 45, 60, 75, 90, 105, 120, 135, 150, 165, 170, 175)
RADIUS = 0.5
CENTER = (0.013, 0.0, 0.0)
NOISE = (0.001, 0.01)  # of the radius
BEVEL = 0.05  # fillet radius, of the patch radius
DATA = Path(__file__).resolve().parents[2] / "shared" / "data"
# The HalfAnnulus labels (HalfAnnulus_Labels.npz): the cut face is 0 and 5, 1 the bottom,
# 2 the outer and 3 the inner cylinder, 4 the top.
HALF_ANNULUS_EDGES = (
    ("HalfAnnulus cut/outer", (0, 2), 78.46),
    ("HalfAnnulus cut/inner (concave wall)", (0, 3), 109.47),
    ("HalfAnnulus top/outer", (4, 2), 90.0),
    ("HalfAnnulus bottom/inner", (1, 3), 90.0),
    ("HalfAnnulus top/cut", (4, 0), 90.0),
)


def reading(surface, center, radius, rule, stability=False):
    """The measurement, or the refusal's first words."""
    try:
        return surface.measure(center, radius, rule=rule, stability=stability)
    except GoniometerError as error:
        return str(error)


def cell(oriented, paper) -> str:
    def text(m):
        return f"{m.angle:.2f}" if not isinstance(m, str) else "refused"

    return f"{text(oriented)} / {text(paper)}"


def error_of(m, exact) -> float:
    return abs(m.angle - exact) if not isinstance(m, str) else float("inf")


def wedge_variants(angle: float, concave: bool):
    """(column name, Surface[, centre]) for one wedge: regular, irregular, inward, bevelled and
    noisy copies; the centre is :data:`CENTER` unless given."""
    regular = wedge(angle, n=60, concave=concave)
    irregular = wedge(angle, n=60, irregular=True, seed=int(angle), concave=concave)
    yield "regular", Surface(regular.points, regular.triangles)
    yield "irregular", Surface(irregular.points, irregular.triangles)
    yield "inward", Surface(irregular.points, irregular.triangles[:, ::-1])
    bevelled = bevelled_wedge(angle, BEVEL * RADIUS, spacing=0.024, concave=concave)
    # Centred on the top of the rounding, which lies below the sharp crease.
    drop = BEVEL * RADIUS * (1.0 / np.sin(np.radians(angle) / 2.0) - 1.0)
    top = (CENTER[0], 0.0, drop if concave else -drop)
    yield "bevel", Surface(bevelled.points, bevelled.triangles), top
    rng = np.random.default_rng(int(angle) + 1000 * concave)
    for level in NOISE:
        noisy = irregular.points + rng.normal(scale=level * RADIUS, size=irregular.points.shape)
        yield f"noise {level:.1%}", Surface(noisy, irregular.triangles)


def row(name, exact, variants, center, radius):
    """One table row: the readings of every variant, the label, the figure, the worst errors."""
    cells, worst = [], {"oriented": [], "paper": []}
    label = figure = ""
    for column, surface, *own in variants:
        center_here = own[0] if own else center
        noisiest = column == f"noise {NOISE[-1]:.1%}"
        oriented = reading(surface, center_here, radius, "oriented", stability=noisiest)
        paper = reading(surface, center_here, radius, "paper")
        cells.append(cell(oriented, paper))
        worst["oriented"].append(error_of(oriented, exact))
        worst["paper"].append(error_of(paper, exact))
        if column in ("regular", "as given") and not isinstance(oriented, str):
            label = oriented.convexity
        if noisiest and not isinstance(oriented, str):
            figure = oriented.stability.text()
    return [name, f"{exact:.2f}", *cells, label, figure, *(_worst(worst[r]) for r in worst)]


def _worst(errors) -> str:
    """The largest error of the measured cells, and how many were refused."""
    measured = [e for e in errors if np.isfinite(e)]
    text = f"{max(measured):.2f}" if measured else "–"
    refused = len(errors) - len(measured)
    return text + (f" ({refused} refused)" if refused else "")


def edge_midpoint(mesh, labels, pair):
    """The vertex nearest the middle of the boundary between two labelled faces."""
    corner = labels[mesh.triangles]
    straddling = (corner == pair[0]).any(axis=1) & (corner == pair[1]).any(axis=1)
    vertices = np.unique(mesh.triangles[straddling])
    middle = np.median(mesh.points[vertices], axis=0)
    return mesh.points[vertices[np.argmin(np.linalg.norm(mesh.points[vertices] - middle, axis=1))]]


def reference_variants(points, triangles, radius):
    """The reference edges: as given, inward, and noisy copies (no remeshing of a scan)."""
    yield "as given", Surface(points, triangles)
    yield "inward", Surface(points, triangles[:, ::-1])
    rng = np.random.default_rng(7)
    for level in NOISE:
        noisy = points + rng.normal(scale=level * radius, size=points.shape)
        yield f"noise {level:.1%}", Surface(noisy, triangles)


def reference_row(name, exact, points, triangles, center, radius):
    values = row(name, exact, reference_variants(points, triangles, radius), center, radius)
    return [*values[:3], "–", values[3], "–", *values[4:]]  # no remeshing or bevel of a scan


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.parse_args(argv)
    header = ["edge", "exact", "regular", "irregular", "inward", "bevel 5%", "noise 0.1%", "noise 1%",
              "label", "± (1%)", "worst default", "worst paper"]  # fmt: skip
    rows = []
    for concave in (False, True):
        for angle in ANGLES:
            kind = "concave" if concave else "convex"
            rows.append(row(f"{kind} wedge {angle}°", angle, wedge_variants(angle, concave),
                            CENTER, RADIUS))  # fmt: skip

    bone = bone_fragment(spacing=0.5)
    for site in bone.sites:
        rows.append(reference_row(f"bone fragment {site.label}", site.angle, bone.points,
                                  bone.triangles, site.point, 3.0))  # fmt: skip
    if DATA.is_dir():
        mesh = read_mesh(DATA / "HalfAnnulus.ply")
        labels = np.load(DATA / "HalfAnnulus_Labels.npz")["labels"]
        for name, pair, exact in HALF_ANNULUS_EDGES:
            center = edge_midpoint(mesh, labels, pair)
            rows.append(reference_row(name, exact, mesh.points, mesh.triangles, center, 0.3))
        mesh = read_mesh(DATA / "IntersectingSpheres.ply")
        centred = mesh.points - mesh.points.mean(axis=0)
        axis = np.linalg.svd(centred, full_matrices=False)[2][2]
        rim = mesh.points[
            np.argmax(np.linalg.norm(centred - np.outer(centred @ axis, axis), axis=1))
        ]
        radius = 0.06 * float(np.ptp(mesh.points, axis=0).max())
        rows.append(reference_row("IntersectingSpheres rim", 70.53, mesh.points, mesh.triangles,
                                  rim, radius))  # fmt: skip

    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    for values in rows:
        print("| " + " | ".join(values) + " |")
    print()
    print(f"Wedges: radius {RADIUS}, centre {CENTER} (on the crease), λ = 2, about 7,200 vertices;")
    print("bone fragment: radius 3 mm at its rim sites (0.5 mm spacing); HalfAnnulus: radius 0.3;")
    print("IntersectingSpheres: 6% of its size. Cells: oriented rule / paper rule, °.")
    if DATA.is_dir():
        print()
        print(sample_scan_summary())


def sample_scan_summary() -> str:
    """How often the two rules differ on the real bone scan (no exact angles there)."""
    mesh = read_mesh(DATA / "sample_mesh.ply")
    surface = Surface(mesh.points, mesh.triangles)
    radius = 0.04 * float(np.ptp(mesh.points, axis=0).max())
    rng = np.random.default_rng(0)
    negative, differences, labels = 0, [], {"convex": 0, "concave": 0, "unclear": 0}
    measured = 0
    for vertex in rng.choice(surface.valid_ids, 300, replace=False):
        oriented = reading(surface, surface.points[vertex], radius, "oriented")
        paper = reading(surface, surface.points[vertex], radius, "paper")
        if isinstance(oriented, str) or isinstance(paper, str):
            continue
        measured += 1
        labels[oriented.convexity] += 1
        if oriented.correlation < 0:
            negative += 1
            differences.append(abs(oriented.angle - paper.angle))
    return (
        f"sample_mesh.ply, 300 random vertices, r = 4% of its size: {measured} measured by both "
        f"rules; {negative} have a negative correlation (sign -1), where the rules differ by a "
        f"median {np.median(differences):.2f}° and at most {max(differences):.2f}°; labels: "
        f"{labels['convex']} convex, {labels['concave']} concave, {labels['unclear']} unclear."
    )


if __name__ == "__main__":
    main()
