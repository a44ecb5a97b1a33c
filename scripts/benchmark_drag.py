"""Benchmark the drag tool's per-mouse-move cost on a million-vertex mesh and print the numbers.

Run: ``.venv/bin/python scripts/benchmark_drag.py`` (or any Python with NumPy; with the bpy
module it also times the Blender-side steps that run headless). No pass/fail: read the numbers.
The target is 16 ms per mouse move (one frame at 60 Hz).

A mouse move costs: the radius from the mouse (view3d_utils, with bpy), one patch query
(``DragMachine.move``), and the preview's vertex data (the float32 (k, 3) array handed to the
GPU). Building the GPU batch itself needs a GPU context, which background bpy does not have; the
script tries and says whether it could.
"""

from __future__ import annotations

import argparse
import importlib.util
import platform
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from vg_addon import Surface  # noqa: E402
from vg_addon.workflow.drag_state import DragMachine, surface_callbacks  # noqa: E402


def ridge_mesh(side: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """A ``side`` x ``side`` grid folded at 90° along its middle, jittered like a scan."""
    rng = np.random.default_rng(seed)
    s = np.linspace(-1.0, 1.0, side)
    x, t = np.meshgrid(s, s, indexing="ij")
    spacing = 2.0 / (side - 1)
    x = x.ravel() + rng.uniform(-0.3, 0.3, x.size) * spacing
    t = t.ravel() + rng.uniform(-0.3, 0.3, t.size) * spacing
    points = np.column_stack([x, t * np.sqrt(0.5), -np.abs(t) * np.sqrt(0.5)])
    grid = np.arange(side * side, dtype=np.int64).reshape(side, side)
    a, b = grid[:-1, :-1].ravel(), grid[1:, :-1].ravel()
    c, d = grid[1:, 1:].ravel(), grid[:-1, 1:].ravel()
    triangles = np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    return points, triangles


def radius_for(surface: Surface, center, target: int) -> float:
    """A radius whose Euclidean patch around ``center`` holds about ``target`` vertices."""
    distances = np.sort(np.linalg.norm(surface.points - center, axis=1))
    return float(distances[min(target, distances.size) - 1])


def patch_vertex_data(points: np.ndarray, indices: np.ndarray) -> np.ndarray:
    # The same as ui.drag_overlay.patch_vertex_data (which imports bpy, so it is not used here).
    return np.ascontiguousarray(points[indices], dtype=np.float32)


def drag(surface, patch: str, center, final_radius: float, moves: int) -> np.ndarray:
    """Per-move times (s) of a drag from the centre out to ``final_radius``."""
    machine = DragMachine(**surface_callbacks(surface, patch))
    machine.press(center)
    times = []
    for radius in np.linspace(final_radius / moves, final_radius, moves):
        start = time.perf_counter()
        machine.move(radius)
        patch_vertex_data(surface.points, machine.indices)
        times.append(time.perf_counter() - start)
    return np.array(times), machine.n_vertices


def gpu_batch_cost(coords: np.ndarray) -> str:
    """Time building the preview's GPU batch, if this Python has a GPU context."""
    try:
        import gpu
        from gpu_extras.batch import batch_for_shader
    except ImportError:
        return "not measured: no bpy/gpu module in this Python"
    try:
        shader = gpu.shader.from_builtin("UNIFORM_COLOR")
        start = time.perf_counter()
        batch_for_shader(shader, "POINTS", {"pos": coords})
        return f"{(time.perf_counter() - start) * 1e3:.2f} ms for {len(coords):,} points"
    except (SystemError, RuntimeError) as error:
        return f"not measured: {error}"


def view_radius_cost(repeats: int = 200) -> str:
    """Time the radius-from-mouse step (view3d_utils on the startup file's 3D view)."""
    try:
        import bpy
        from bpy_extras import view3d_utils
        from mathutils import Vector
    except ImportError:
        return "not measured: no bpy module in this Python"
    windows = bpy.context.window_manager.windows
    if not len(windows):
        return "not measured: no window in this bpy"
    area = next(a for a in windows[0].screen.areas if a.type == "VIEW_3D")
    region = next(r for r in area.regions if r.type == "WINDOW")
    rv3d = area.spaces.active.region_3d
    center = np.array(rv3d.view_location)
    start = time.perf_counter()
    for i in range(repeats):
        point = view3d_utils.region_2d_to_location_3d(
            region, rv3d, Vector((100.0 + i, 200.0)), Vector(center)
        )
        float(np.linalg.norm(np.array(point) - center))
    return f"{(time.perf_counter() - start) / repeats * 1e6:.1f} µs"


def load_extension():
    """This checkout as the ``virtual_goniometer`` extension package, registered (needs bpy)."""
    spec = importlib.util.spec_from_file_location(
        "virtual_goniometer", ROOT / "__init__.py", submodule_search_locations=[str(ROOT)]
    )
    extension = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = extension
    spec.loader.exec_module(extension)
    extension.register()
    return extension


def extension_costs(points, triangles, center, radius) -> None:
    """With bpy: the press (mesh evaluation + cached Surface) and release (record) costs."""
    try:
        import bpy
    except ImportError:
        print("press / release in Blender: not measured: no bpy module in this Python")
        return
    extension = load_extension()
    from virtual_goniometer.bridge import measuring, mesh_data

    obj = mesh_data.new_mesh_object("Benchmark", points, triangles)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    for label in ("first press (evaluate mesh, build Surface)", "later press (Surface cached)"):
        start = time.perf_counter()
        mesh_data.surface_for(obj, mesh_data.evaluated_geometry(obj, depsgraph))
        print(f"{label}: {(time.perf_counter() - start) * 1e3:.0f} ms")
    start = time.perf_counter()
    try:
        measuring.measure_on_object(obj, center, radius, depsgraph=depsgraph)
    except Exception as error:  # report, the other numbers still stand
        print(f"release (measure_on_object): not measured: {error!r}")
    else:
        print(
            "release (measure_on_object: evaluate, measure, record, repaint): "
            f"{(time.perf_counter() - start) * 1e3:.0f} ms"
        )
    extension.unregister()


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vertices", type=int, default=1_000_000, help="size of the mesh")
    parser.add_argument("--moves", type=int, default=60, help="mouse moves per drag")
    args = parser.parse_args(argv)

    print(
        f"machine: {platform.machine()}, Python {platform.python_version()}, NumPy {np.__version__}"
    )
    side = round(float(np.sqrt(args.vertices)))
    points, triangles = ridge_mesh(side)
    print(f"mesh: jittered 90° ridge, {len(points):,} vertices, {len(triangles):,} triangles")
    start = time.perf_counter()
    surface = Surface(points, triangles)
    print(f"tool start, Surface build (once per mesh, cached): {time.perf_counter() - start:.2f} s")

    center = points[(side // 2) * side + side // 2]
    print(f"\nper mouse move over a drag of {args.moves} moves (query + preview vertex data):")
    print(f"{'patch':>10} {'final patch':>12} {'median':>10} {'max':>10}")
    for patch in ("euclidean", "geodesic"):
        if patch == "geodesic":
            start = time.perf_counter()
            surface.patch(int(np.argmin(np.linalg.norm(points - center, axis=1))), 1e-3, patch)
            print(f"  (geodesic edge graph, built once: {time.perf_counter() - start:.2f} s)")
        for target in (2_000, 20_000, 100_000):
            radius = radius_for(surface, center, target)
            times, count = drag(surface, patch, center, radius, args.moves)
            print(
                f"{patch:>10} {count:>12,} {np.median(times) * 1e3:>8.2f} ms "
                f"{times.max() * 1e3:>7.2f} ms"
            )

    machine = DragMachine(**surface_callbacks(surface))
    machine.press(center)
    machine.move(radius_for(surface, center, 2_000))
    start = time.perf_counter()
    machine.change_lam(1)
    print(
        f"\nλ change (re-measure a {machine.n_vertices:,}-vertex patch): "
        f"{(time.perf_counter() - start) * 1e3:.2f} ms"
    )
    print(f"radius from the mouse (view3d_utils): {view_radius_cost()}")
    coords = patch_vertex_data(surface.points, machine.indices)
    print(f"GPU batch of the preview points: {gpu_batch_cost(coords)}")
    extension_costs(points, triangles, center, machine.radius)


if __name__ == "__main__":
    main()
