"""Measurements whose exact outputs are pinned in ``data/replay_pins.json``.

The pins were computed by ``python tests/core/replay_cases.py`` with the arithmetic of issue 18
(no BLAS or LAPACK in the measuring path): the same bits under NumPy 1.26 and 2.x, on every CPU,
BLAS kernel and thread count. Recorded measurements replay by re-measuring at their stored
centre, radius, λ and patch mode, so these outputs must stay bit for bit what that code gave.
Each case records the patch (snapped vertex, snap distance, the vertex indices in the order
Algorithm 1 summed them, their labels) apart from the numbers Algorithm 1 derived from it, so a
change to the algorithm's own arithmetic shows as a change of numbers only.

``data/replay_pins_5ffee72.json`` holds the same cases as commit 5ffee72 computed them (NumPy
1.26.4, BLAS and LAPACK): the patches must still be those, and the numbers within 1e-9°.
"""

from __future__ import annotations

import hashlib
import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from vg_addon import GoniometerError, Surface  # noqa: E402
from vg_addon.formats.meshio import read_mesh  # noqa: E402
from vg_addon.reference_shapes import half_annulus, intersecting_spheres  # noqa: E402
from vg_addon.synthetic_meshes import bone_fragment, wedge  # noqa: E402

PINS = Path(__file__).with_name("data") / "replay_pins.json"
PINS_5FFEE72 = Path(__file__).with_name("data") / "replay_pins_5ffee72.json"
SHARED_DATA = ROOT.parent / "shared" / "data"


def _digest(array: np.ndarray) -> str:
    array = np.ascontiguousarray(array)
    return hashlib.sha256(array.dtype.str.encode() + memoryview(array).cast("B")).hexdigest()


def _hex(values) -> list[str]:
    return [float(v).hex() for v in np.ravel(values)]


def surfaces() -> dict[str, Surface]:
    """The surfaces the cases are measured on (reference meshes only when present)."""
    found = {}
    w = wedge(78.0, n=70, irregular=True, seed=3)
    found["wedge78"] = Surface(w.points, w.triangles)
    found["wedge78-cloud"] = Surface(w.points)
    b = bone_fragment(spacing=0.6, roughness=0.05, seed=1)
    found["bone"] = Surface(b.points, b.triangles)
    for name, shape in (("half-annulus", half_annulus()), ("lens", intersecting_spheres())):
        found[name] = Surface(shape.points, shape.triangles)  # the project's, in every clone
    for name in ("HalfAnnulus", "IntersectingSpheres", "sample_mesh"):
        path = SHARED_DATA / f"{name}.ply"
        if path.is_file():
            mesh = read_mesh(path)
            found[name] = Surface(mesh.points, mesh.triangles)
    return found


def cases(surface: Surface, name: str):
    """``(center, radius, lam, patch)`` tuples spread over ``surface``, chosen by position."""
    points = surface.points
    extent = float(np.ptp(points, axis=0).max())
    rng = np.random.default_rng(sum(name.encode()))
    picks = rng.choice(points.shape[0], size=12, replace=False)
    modes = ("euclidean", "geodesic") if surface.triangles is not None else ("euclidean",)
    for k, vertex in enumerate(picks):
        offset = rng.normal(size=3) * extent * 1e-3
        if name.startswith("wedge"):  # on the crease (the x axis), where there is an edge
            offset -= points[vertex] * np.array([0.0, 1.0, 1.0])
        radius = extent * (0.05 + 0.05 * (k % 3))
        yield points[vertex] + offset, radius, (0.5, 2.0, 7.0)[k % 3], modes[k % len(modes)]


def record(surface: Surface, center, radius, lam, patch) -> dict:
    """The pinned outputs of one measurement (or its refusal message)."""
    entry = {"center": _hex(center), "radius": float(radius).hex(), "lam": lam, "patch": patch}
    try:
        # The pins predate the oriented rule: they replay with the rule they were made with.
        m = surface.measure(center, radius, lam, patch, rule="paper")
    except GoniometerError as error:
        entry["error"] = str(error)
        return entry
    entry["patch_part"] = {
        "center_index": m.center_index,
        "snap_distance": float(m.snap_distance).hex(),
        "indices": _digest(m.indices.astype(np.int64)),
        "labels": _digest(m.labels.astype(bool)),
        "n": [m.n_vertices, m.n_plus, m.n_minus],
    }
    entry["numbers"] = {
        "angle": float(m.angle).hex(),
        "fit": _hex([m.fit_error, m.fit_error_plus, m.fit_error_minus]),
        "normals": _hex([*m.normal_plus, *m.normal_minus]),
        "threshold": float(m.threshold).hex(),
    }
    return entry


def compute_all() -> dict:
    pins = {
        name: [record(surface, *case) for case in cases(surface, name)]
        for name, surface in surfaces().items()
    }
    pins["numpy"] = np.__version__
    return pins


if __name__ == "__main__":
    PINS.write_text(json.dumps(compute_all(), indent=1, sort_keys=True) + "\n")
    print(f"wrote {PINS}")
