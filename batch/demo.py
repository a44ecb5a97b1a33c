"""``--demo``: a bone-shaft fragment with known break angles, measured by a batch run."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import bpy
import numpy as np

from ..vg_addon import synthetic_meshes
from ..vg_addon.formats import meshio
from ..vg_addon.method.edge_summary import sd_text
from . import extension
from .cli import build_parser
from .run import run_batch
from .stdio import say

DEMO_DIR = "vg_demo_output"

# mm: the demo's patch radius. Larger patches average more of the curved cylinder walls, which
# pulls the measured angles away from the ideal ones at the rims (about 1° at 1 mm, 3° at 2 mm).
DEMO_RADIUS = 1.0

# The whole edge the demo profiles: the oblique fracture face's outer rim, from its acute side
# through the side site to its obtuse side, where the angle runs from 55° through 90° to 125°.
EDGE_SITES = ("oblique/outer acute", "oblique/outer side", "oblique/outer obtuse")
EDGE_SPACING = 2.0  # mm of arc length between stations


def oblique_rim_angle(points, oblique_deg: float = 35.0) -> np.ndarray:
    """The exact interior angle at points of the oblique face's outer rim: 180° minus the angle
    between the outer cylinder's normal ``(x, y, 0) / R`` and the oblique plane's outward normal
    ``(-tan a, 0, 1) / |...|``."""
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    radial = points[:, :2] / np.linalg.norm(points[:, :2], axis=1)[:, None]
    plane = np.array([-math.tan(math.radians(oblique_deg)), 0.0, 1.0])
    plane /= np.linalg.norm(plane)
    cosine = radial @ plane[:2]
    return 180.0 - np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0)))


def run_demo(args) -> int:
    """Generate a bone-shaft fragment with known break angles, measure its break sites in a
    batch run, print true against measured angles and name the output folder."""
    bpy.ops.wm.read_homefile(use_empty=True)
    extension.activate()
    out = Path(args.out_dir or DEMO_DIR).resolve()
    out.mkdir(parents=True, exist_ok=True)

    say("generating a long-bone shaft fragment (millimetres) ...")
    fragment = synthetic_meshes.bone_fragment()
    ply = out / "bone_fragment.ply"
    meshio.write_ply(ply, fragment.points, fragment.triangles)
    say(f"{len(fragment.points):,} vertices, {len(fragment.sites)} break sites -> {ply}")
    points = out / "break_sites.csv"
    with open(points, "w", encoding="utf-8", newline="") as handle:
        writer = csv.writer(handle, lineterminator="\n")
        writer.writerow(["mesh", "label", "break", "x", "y", "z", "radius", "true angle"])
        for number, site in enumerate(fragment.sites, start=1):
            writer.writerow(
                [
                    "bone_fragment",
                    site.label,
                    number,
                    *(repr(float(v)) for v in site.point),
                    repr(DEMO_RADIUS),
                    repr(site.angle),
                ]
            )

    outputs = {
        "--out": out / "measurements.csv",
        "--save-blend": out / "bone_fragment.blend",
        "--render": out,
    }
    by_label = {site.label: site for site in fragment.sites}
    start, via, end = (by_label[label].point for label in EDGE_SITES)
    edge = ["--edge", *map(repr, start), *map(repr, end), "--via", *map(repr, via)]
    edge += ["--spacing", repr(EDGE_SPACING), "--radius", repr(DEMO_RADIUS)]
    argv = [str(ply), "--points", str(points), "--units", "mm", "--render-size", "800", "600"]
    argv += edge
    argv += [str(value) for option in outputs.items() for value in option]
    batch = build_parser().parse_args([*argv, "--jobs", "1"])  # an edge runs in-process
    batch.quiet = args.quiet
    code, run = run_batch(batch, file_ready=True)

    rows = [run.rows[i] for i in sorted(run.rows)]
    width = max(len("break site"), *(len(site.label) for site in fragment.sites))
    print(f"\n{'break site':<{width}}  true angle    measured  difference  fit error")
    for site, row in zip(fragment.sites, rows, strict=True):
        if row.error:
            print(f"{site.label:<{width}}  {site.angle:9.2f}°      failed  {row.error}")
            continue
        print(
            f"{site.label:<{width}}  {site.angle:9.2f}°  {row.angle:9.2f}°  "
            f"{row.angle - site.angle:+9.2f}°  {row.fit:.2g}"
        )
    print_edge(run)
    print(
        f"\nPatch radius {DEMO_RADIUS:g} mm. Measured and true angles differ because each side's "
        "plane is fitted to a patch\nof a curved cylinder wall; a larger radius averages more of "
        "the curvature.\n"
    )
    print(f"Output folder: {out}")
    for path in (
        ply,
        points,
        *(p for p in outputs.values() if p != out),
        out / "bone_fragment_map.png",
        out / "measurements_edges.csv",
        *sorted(out.glob("measurements_*_edge*.png")),
    ):
        if path.is_file():
            print(f"  {path.name}")
    return code


def print_edge(run) -> None:
    """The whole-edge profile beside the point measurements: summary and every few stations."""
    stations = [row for row in run.station_rows if not row.error]
    failed = [row for row in run.station_rows if row.error]
    print(f"\nWhole edge: {' -> '.join(EDGE_SITES)}, a station every {EDGE_SPACING:g} mm")
    for row in failed:
        print(f"  failed: {row.error}")
    for edge in run.profiled_edges:
        print(
            f"  {edge.n_stations} stations over {edge.length:.1f} mm: mean {edge.mean:.2f}° "
            f"(SD {sd_text(edge.std)}), min {edge.min:.2f}°, max {edge.max:.2f}°, pooled "
            f"{edge.pooled_angle:.2f}°"
        )
    if not stations:
        return
    true = oblique_rim_angle([(row.x, row.y, row.z) for row in stations])
    errors = np.array([row.angle for row in stations]) - true
    print(f"  {'arc length':>10}  true angle    measured  difference")
    step = max(1, len(stations) // 8)
    for row, exact in list(zip(stations, true, strict=True))[::step]:
        print(
            f"  {row.arc_length:8.2f} mm  {exact:9.2f}°  {row.angle:9.2f}°  "
            f"{row.angle - exact:+9.2f}°"
        )
    print(f"  largest difference over all {len(stations)} stations: {np.abs(errors).max():.2f}°")
