"""Every kind of number the core reports, on shapes the project makes, as exact hex strings.

``python tests/core/determinism_probe.py`` prints one JSON document. ``test_determinism.py`` runs
it in fresh processes under other BLAS kernels (``OPENBLAS_CORETYPE``), thread counts
(``OPENBLAS_NUM_THREADS``) and with NumPy's run-time SIMD paths switched off
(``NPY_DISABLE_CPU_FEATURES``), and requires the same document bit for bit each time. The cases
cover Algorithm 1 under both rules (meshes and point clouds, convex, concave, inward, noisy), the
stability figure and its parts, a radius sweep, an edge profile with its summary, and the break
edges found on a rough bone fragment (waypoint vertices, confidences, bends).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from vg_addon import GoniometerError, Surface  # noqa: E402
from vg_addon.method.fixed_order import row_dot, rows_dot  # noqa: E402
from vg_addon.method.sweep import radius_sweep  # noqa: E402
from vg_addon.reference_shapes import marched_wedge  # noqa: E402
from vg_addon.synthetic_meshes import bone_fragment, wedge  # noqa: E402


def _hex(values) -> list[str]:
    return [float(v).hex() for v in np.ravel(values)]


def measurement_record(m) -> dict:
    """Every number of a measurement, as hex."""
    entry = {
        "angle": float(m.angle).hex(),
        "fit": _hex([m.fit_error, m.fit_error_plus, m.fit_error_minus]),
        "vectors": _hex([*m.normal_plus, *m.normal_minus, *m.tangent, *m.mean_normal]),
        "threshold": float(m.threshold).hex(),
        "correlation": float(m.correlation).hex(),
        "counts": [m.n_vertices, m.n_plus, m.n_minus, m.n_shared, m.orientation],
        "labels": int(np.flatnonzero(m.labels).sum()),
        "convexity": m.convexity,
    }
    if m.split_angle is not None:  # the refined rule replaced Algorithm 1's planes
        entry["refined"] = [float(m.split_angle).hex(), m.n_left_out]
    if m.stability is not None:
        s = m.stability
        entry["stability"] = _hex([s.spread, s.center, s.radius, s.lam, s.bootstrap])
        entry["stability_runs"] = [s.n_runs, s.n_failed]
        entry["stability_crease"] = [float(s.crease).hex(), s.crease_refused]
    return entry


def _measure(surface, center, radius, **options) -> dict:
    try:
        return measurement_record(surface.measure(center, radius, **options))
    except GoniometerError as error:
        return {"error": str(error)}


def probe() -> dict:
    """The probe's document: a dict of case name to exact outputs."""
    out: dict = {}
    for angle in (20.0, 78.0, 135.0, 172.0):
        for kind in ("convex", "concave", "inward"):
            mesh = wedge(angle, n=40, irregular=True, seed=int(angle))
            points, triangles = mesh.points, mesh.triangles
            if kind == "concave":
                points = points * np.array([1.0, 1.0, -1.0])
            if kind == "inward":
                triangles = triangles[:, [0, 2, 1]]
            surface = Surface(points, triangles)
            for rule in ("oriented", "paper"):
                out[f"wedge {kind} {angle:g} {rule}"] = _measure(
                    surface, [0.1, 0.0, 0.0], 0.4, rule=rule, stability=rule == "oriented"
                )
    noisy = wedge(120.0, n=50, irregular=True, seed=7)
    rng = np.random.default_rng(11)
    points = noisy.points + rng.normal(scale=0.004, size=noisy.points.shape)
    surface = Surface(points, noisy.triangles)
    cloud = Surface(points)
    for k, x in enumerate(np.linspace(-0.6, 0.6, 7)):
        center = [x, 0.0, 0.0]
        out[f"noisy {k} stability"] = _measure(surface, center, 0.3, stability=True)
        out[f"noisy {k} geodesic"] = _measure(surface, center, 0.3, patch="geodesic", lam=1.5)
        out[f"noisy {k} cloud"] = _measure(cloud, center, 0.3, rule="paper")
    for angle in (35.0, 100.0, 160.0):  # creases between vertex rows: the refinement applies
        points, triangles, _, direction = marched_wedge(angle, 0.03, turn_seed=5)
        marched = Surface(points, triangles)
        along = np.abs(row_dot(points, direction))
        off = np.sqrt(rows_dot(points, points) - along * along)
        center = points[np.argmin(np.where(along < 0.06, off, np.inf))]
        out[f"marched {angle:g}"] = _measure(marched, center, 0.25, stability=True)
    bone = bone_fragment(spacing=0.6, roughness=0.05, seed=1)
    bone_surface = Surface(bone.points, bone.triangles)
    for k, site in enumerate(bone.sites[:4]):
        out[f"bone site {k}"] = _measure(bone_surface, site.point, 3.0, stability=k % 2 == 0)
    # Break edges: their waypoints become an Edge Profile's stored Points.
    found = bone_surface.find_break_edges()
    out["break edges"] = {
        "ridge_min_deg": float(found.ridge_min_deg).hex(),
        "regions": np.unique(found.region, return_counts=True)[1].tolist(),
        "candidates": [
            {
                "waypoints": c.path.vertices[c.path.waypoints].tolist(),
                "n_vertices": int(c.path.vertices.size),
                "closed": c.closed,
                "confidence": float(c.confidence).hex(),
                "mean_bend_deg": float(c.mean_bend_deg).hex(),
            }
            for c in found.candidates
        ],
    }
    sweep = radius_sweep(surface, [0.0, 0.0, 0.0], 0.1, 0.4, 7)
    out["sweep"] = [
        measurement_record(point.measurement) if point.measurement else point.error
        for point in sweep
    ]
    path = surface.trace_edge([-0.7, 0.0, 0.0], [0.7, 0.0, 0.0])
    profile = surface.measure_along(path, 0.2, 0.25)
    out["profile"] = {
        "path": _hex(path.points),
        "stations": [measurement_record(m) for m in profile.stations],
        "figures": {
            name: _hex(value)
            if isinstance(value, float)
            else [bool(v) for v in value]
            if isinstance(value, tuple)
            else value
            for name, value in sorted(vars(profile.figures).items())
        },
    }
    return out


if __name__ == "__main__":
    json.dump(probe(), sys.stdout, indent=1, sort_keys=True)
    sys.stdout.write("\n")
