"""Check that a change to the measuring core left every reading's bits as they were.

Run: ``.venv/bin/python scripts/compare_core_bits.py [--commit d4444ed] [--quick]``. The core at
``--commit`` is extracted with ``git archive`` and imported beside today's; both measure the same
patches and every field of every :class:`~vg_addon.Measurement` (or the text of every refusal) is
compared bit for bit. Prints the count of measurements, refusals, refinements applied and
differences, and the first few differences; exits 1 if any differ. No pass/fail beyond that: a
change meant to keep the readings (a faster path through the same arithmetic) runs this before it
is committed, under each NumPy line.

The patches: a jittered ridge exact and with noise of 5% and 30% of its spacing; marched wedges
from 5° to 175°, upright and turned, and their valleys (the triangles reversed); the authors'
stretched wedges; irregular wedges convex and concave, as meshes and as point clouds; the half
annulus, the intersecting spheres, the rough bone fragment, and ``sample_mesh.ply`` where
``../shared/data`` has it. On each, centres near the crease (or anywhere, on the curved shapes) at
two or three radii, under the three rules and at λ 0.5, one geodesic patch, and ``goniometer`` on
one patch given as points.
"""

from __future__ import annotations

import argparse
import dataclasses
import importlib
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "scripts"))

from benchmark import REFINED_SPEED_BASE, _core_at  # noqa: E402
from benchmark_drag import ridge_mesh  # noqa: E402

SAMPLE = ROOT.parent / "shared" / "data" / "sample_mesh.ply"


def _record(measurement) -> tuple:
    """Every field of a measurement as bytes or text, nested results included."""
    fields = []
    for field in dataclasses.fields(measurement):
        value = getattr(measurement, field.name)
        if isinstance(value, np.ndarray):
            fields.append((field.name, value.dtype.str, value.shape, value.tobytes()))
        elif isinstance(value, float):
            fields.append((field.name, value.hex()))
        elif dataclasses.is_dataclass(value):
            fields.append((field.name, _record(value)))
        else:
            fields.append((field.name, repr(value)))
    return tuple(fields)


def _surfaces(package: str, quick: bool) -> list:
    """(name, Surface, candidate centres, radii) of every case, built with ``package``."""
    surface = importlib.import_module(package).Surface
    shapes = importlib.import_module(package + ".reference_shapes")
    synthetic = importlib.import_module(package + ".synthetic_meshes")
    meshio = importlib.import_module(package + ".formats.meshio")
    cases = []
    points, triangles = ridge_mesh(200)
    spacing = 2.0 / 199
    for scale in (0.0, 0.05, 0.3):
        noisy = points + np.random.default_rng(5).normal(scale=scale * spacing, size=points.shape)
        near = noisy[np.abs(noisy[:, 1]) < 0.5 * spacing]
        cases.append((f"ridge {scale}", surface(noisy, triangles), near, [0.05, 0.1, 0.2]))
    for angle in (90, 150) if quick else (5, 30, 60, 90, 120, 150, 165, 175):
        for seed in (None, 3):
            p, t, _, d = shapes.marched_wedge(angle, 0.03, turn_seed=seed)
            off = np.linalg.norm(p - np.outer(p @ d, d), axis=1)
            near = p[np.argsort(off + 0.1 * np.abs(p @ d))[:60]]
            cases.append((f"marched {angle} {seed}", surface(p, t), near, [0.15, 0.25]))
            cases.append((f"valley {angle} {seed}", surface(p, t[:, ::-1]), near, [0.25]))
    for angle in (60, 120, 170):
        p, t = shapes.stretched_wedge(angle, 0.02)
        near = p[np.argsort(np.hypot(p[:, 0], p[:, 1]) + 0.01 * np.abs(p[:, 2]))[:40]]
        cases.append((f"stretched {angle}", surface(p, t), near, [0.1, 0.2]))
    for angle, concave in ((45, False), (135, True)):
        w = synthetic.wedge(angle, n=60, irregular=True, seed=2, concave=concave)
        near = w.points[np.abs(w.points[:, 1]) + np.abs(w.points[:, 2]) < 0.05]
        cases.append((f"wedge {angle} {concave}", surface(w.points, w.triangles), near, [0.2, 0.4]))
        cases.append((f"cloud {angle} {concave}", surface(w.points), near, [0.3]))
    annulus = shapes.half_annulus(0.05)
    cases.append(("half annulus", surface(annulus.points, annulus.triangles), annulus.points, [0.3, 0.5]))  # fmt: skip
    spheres = shapes.intersecting_spheres(0.03)
    cases.append(("spheres", surface(spheres.points, spheres.triangles), spheres.points, [0.2]))
    bone = synthetic.bone_fragment(spacing=0.4, roughness=0.03)
    cases.append(("bone", surface(bone.points, bone.triangles), bone.points, [1.0, 2.0]))
    if SAMPLE.exists():
        mesh = meshio.read_mesh(SAMPLE)
        size = float(np.ptp(mesh.points, axis=0).max())
        cases.append(("sample", surface(mesh.points, mesh.triangles), mesh.points, [0.01 * size, 0.03 * size]))  # fmt: skip
    return cases


def readings(package: str, quick: bool) -> list:
    """Every case's readings (records, or ``("refused", text)``) with the core ``package``, each
    with what was measured: ``(case, radius, call)``."""
    refused = importlib.import_module(package + ".errors").GoniometerError
    goniometer = importlib.import_module(package + ".method.algorithm").goniometer
    out = []

    def take(measure, *args, **kwargs):
        what = (name, None if measure is goniometer else args[1], kwargs)
        try:
            out.append((what, _record(measure(*args, **kwargs))))
        except refused as error:
            out.append((what, ("refused", str(error))))

    for name, surface, where, radii in _surfaces(package, quick):
        draw = np.random.default_rng(len(name)).integers(0, len(where), 6 if quick else 14)
        centres = where[draw]
        for centre in centres:
            for radius in radii:
                for rule in ("refined", "oriented", "paper"):
                    take(surface.measure, centre, radius, rule=rule)
                take(surface.measure, centre, radius, lam=0.5)
        if surface.triangles is not None:
            take(surface.measure, centres[0], radii[0], patch="geodesic")
        patch = surface.patch(surface.snap(centres[0], radii[-1])[0], radii[-1])
        take(goniometer, surface.points[patch], surface.normals[patch])
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--commit", default=REFINED_SPEED_BASE, help="the core to compare with")
    parser.add_argument("--quick", action="store_true", help="fewer cases (about a quarter)")
    parser.add_argument("--show", type=int, default=5, help="how many differences to print")
    args = parser.parse_args(argv)
    name = "vg_addon_at_" + "".join(c for c in args.commit if c.isalnum())
    if _core_at(args.commit, name) is None:
        return 1
    before, now = readings(name, args.quick), readings("vg_addon", args.quick)
    cases = [what for what, _ in now]
    before, now = [record for _, record in before], [record for _, record in now]
    differ = [k for k, (a, b) in enumerate(zip(before, now, strict=True)) if a != b]
    refusals = sum(1 for record in before if record[0] == "refused")
    applied = sum(
        1
        for record in before
        if record[0] != "refused"
        and dict((f[0], f[1:]) for f in record)["split_angle"] != ("None",)
    )
    print(
        f"NumPy {np.__version__}: {len(before)} measurements ({refusals} refusals, the refinement "
        f"applied in {applied}) against {args.commit}: {len(differ)} differ"
    )
    for k in differ[: args.show]:
        case, radius, options = cases[k]
        at = "a given patch" if radius is None else f"radius {radius:.3g}"
        where = f"  measurement {k} ({case}, {at}, {options or 'defaults'}):"
        if "refused" in (before[k][0], now[k][0]):
            print(where, " -> ".join(record[1][:90] if record[0] == "refused" else "measured"
                                     for record in (before[k], now[k])))  # fmt: skip
            continue
        fields = [a[0] for a, b in zip(before[k], now[k], strict=False) if a != b]
        print(where, ", ".join(map(str, fields)))
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
