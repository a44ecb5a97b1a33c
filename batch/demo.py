"""``--demo``: a bone-shaft fragment with known break angles, measured by a batch run."""

from __future__ import annotations

import csv
from pathlib import Path

import bpy

from ..vg_addon import synthetic_meshes
from ..vg_addon.formats import meshio
from . import extension
from .cli import build_parser
from .run import run_batch
from .stdio import say

DEMO_DIR = "vg_demo_output"

# mm: the demo's patch radius. Larger patches average more of the curved cylinder walls, which
# pulls the measured angles away from the ideal ones at the rims (about 1° at 1 mm, 3° at 2 mm).
DEMO_RADIUS = 1.0


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
    argv = [str(ply), "--points", str(points), "--units", "mm", "--render-size", "800", "600"]
    argv += [str(value) for option in outputs.items() for value in option]
    batch = build_parser().parse_args([*argv, "--jobs", str(args.jobs)])
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
    ):
        if path.is_file():
            print(f"  {path.name}")
    return code
