"""Benchmark the extension in Blender at 10k, 1M and 5M vertices and print every figure of
issue 10 side by side, with the ratios between sizes and between 1 and 1,000 measurements.

Run with the bpy module: ``.venv/bin/python scripts/benchmark_blender.py``, or in a real Blender:
``blender -b --factory-startup --python scripts/benchmark_blender.py -- [options]``.
No pass/fail: read the numbers. Each size runs in its own process (so its peak memory is its
own); times are the minimum (and median) of repeats, since the machine may be shared.

Per size: the first click (mesh read, Surface build, measure, record, paint, undo step) and the
process's peak memory; a repeat click (``vg.measure_xyz`` with its undo step) with 1 and with
1,000 measurements stored, without and with the stability figure (the panel's default); drag
press (evaluate, kept Surface, ray cast on the kept tree, snap) and release (measure, then
``vg.measure_xyz``); delete, undo, the click after an undo and clear at 1,000 measurements; the
first geodesic measurement. At 1M also: the core's time per 2,000-vertex measurement, the
batch's measurements per second (mesh import excluded) and the import of a 1M-vertex binary PLY.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "scripts"))

from benchmark_drag import load_extension, ridge_mesh  # noqa: E402

SIZES = {"10k": 10_000, "1M": 1_000_000, "5M": 5_000_000}
PATCH_VERTICES = 2_000


def rss_mb() -> float:
    """Current resident memory of this process, MB (Linux; 0 elsewhere)."""
    try:
        with open("/proc/self/statm") as handle:
            return int(handle.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 1e6
    except OSError:
        return 0.0


def peak_rss_mb() -> float:
    """Peak resident memory of this process since it started or since :func:`reset_peak`."""
    try:
        with open("/proc/self/status") as handle:
            line = next(line for line in handle if line.startswith("VmHWM:"))
        return int(line.split()[1]) * 1024 / 1e6  # kB
    except (OSError, StopIteration):
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        return peak / 1e6 if sys.platform == "darwin" else peak * 1024 / 1e6  # bytes / KiB


def reset_peak() -> bool:
    """Start the peak of :func:`peak_rss_mb` again from the current memory (Linux), so that a
    step's peak is not the benchmark's own setup's; False where that is not possible."""
    try:
        with open("/proc/self/clear_refs", "w") as handle:
            handle.write("5")
        return True
    except OSError:
        return False


def timed(function) -> float:
    start = time.perf_counter()
    function()
    return time.perf_counter() - start


def stats(times) -> dict:
    times = np.asarray(times) * 1e3
    return {"min": float(times.min()), "median": float(np.median(times)), "n": int(times.size)}


def crease_centers(count, seed=0):
    """Points on the ridge's crease (the x axis), where there is an edge to measure."""
    x = np.random.default_rng(seed).uniform(-0.8, 0.8, count)
    return np.column_stack([x, np.zeros(count), np.zeros(count)])


def run_size(label: str, stored: int, repeats: int) -> dict:
    """Every figure for one mesh size, in this process."""
    import bpy

    extension = load_extension()
    from virtual_goniometer.bridge import measuring, mesh_data

    bpy.ops.wm.read_homefile(use_empty=True)
    bpy.context.preferences.edit.undo_steps = 32
    out = {"label": label}
    side = round(float(np.sqrt(SIZES[label])))
    points, triangles = ridge_mesh(side)
    out["vertices"] = len(points)
    start = time.perf_counter()
    obj = mesh_data.new_mesh_object("Scan", points, triangles)
    bpy.context.view_layer.update()
    out["mesh_build_s"] = time.perf_counter() - start
    if label != "1M":  # only the 1M run writes them to a file again: free the memory now
        del points, triangles
        points = triangles = None
    spacing = 2.0 / (side - 1)
    # A radius whose patch holds about PATCH_VERTICES vertices: the ridge's faces are a grid of
    # this spacing, and a ball on the crease cuts a half disc from each.
    radius = spacing * float(np.sqrt(PATCH_VERTICES / np.pi))
    centers = crease_centers(8 * repeats + stored + 400)
    next_center = iter(centers)
    bpy.ops.ed.undo_push(message="start")
    out["rss_before_first_click_mb"] = rss_mb()

    def click(stability=False):
        c = next(next_center)
        result = bpy.ops.vg.measure_xyz(
            "EXEC_DEFAULT",
            True,
            location=tuple(c),
            radius=radius,
            seg_param=2.0,
            stability=stability,
        )
        assert result == {"FINISHED"}, result

    def stable_click():
        click(stability=True)

    out["peak_rss_setup_mb"] = peak_rss_mb()
    peak_reset = reset_peak()
    out["first_click_ms"] = timed(click) * 1e3
    out["peak_rss_mb"] = peak_rss_mb() if peak_reset else None
    out["patch_vertices"] = int(obj.vg.measurements[-1].n_vertices)
    out["repeat_click_1"] = stats([timed(click) for _ in range(repeats)])
    out["stable_click_1"] = stats([timed(stable_click) for _ in range(repeats)])

    depsgraph = bpy.context.evaluated_depsgraph_get()

    def press():
        mesh_data.check_measurable(obj)
        dg = bpy.context.evaluated_depsgraph_get()
        surface = mesh_data.surface_for(obj, mesh_data.evaluated_geometry(obj, dg))
        geometry = mesh_data.evaluated_geometry(obj, dg)
        c = next(next_center)
        tree = mesh_data.ray_tree_for(obj, geometry, dg)  # what the drag tool casts on
        location = tree.ray_cast(c + np.array([0, 0, 1.0]), (0, 0, -1.0))[0]
        surface.index.nearest(np.array(c if location is None else location), np.inf)
        return surface

    def release():
        surface = mesh_data.surface_for(obj, mesh_data.evaluated_geometry(obj, depsgraph))
        c = next(next_center)
        surface.measure(c, radius)
        result = bpy.ops.vg.measure_xyz(
            "EXEC_DEFAULT", True, location=tuple(c), radius=radius, seg_param=2.0, stability=False
        )
        assert result == {"FINISHED"}, result

    def drags(count):
        """Press and release times of ``count`` drags in a row (each press follows the previous
        release's repaint, as when measuring one break after another)."""
        presses, releases = [], []
        for _ in range(count):
            presses.append(timed(press))
            releases.append(timed(release))
        return stats(presses), stats(releases)

    press()  # the first press builds Blender's ray-cast tree
    out["press_1"], out["release_1"] = drags(repeats)

    # Fill up to `stored` measurements (no undo steps: a script, not clicks).
    start = time.perf_counter()
    while len(obj.vg.measurements) < stored:
        measuring.measure_on_object(obj, next(next_center), radius, depsgraph=depsgraph)
    out["fill_s"] = time.perf_counter() - start
    out["stored"] = len(obj.vg.measurements)
    bpy.ops.ed.undo_push(message="filled")
    out[f"repeat_click_{stored}"] = stats([timed(click) for _ in range(repeats)])
    out[f"stable_click_{stored}"] = stats([timed(stable_click) for _ in range(repeats)])
    out[f"press_{stored}"], out[f"release_{stored}"] = drags(repeats)

    deletes, undos, after_undo = [], [], []
    for k in range(repeats):
        index = (k * 37) % len(obj.vg.measurements)
        deletes.append(
            timed(lambda i=index: bpy.ops.vg.delete_measurement("EXEC_DEFAULT", True, index=i))
        )
        undos.append(timed(bpy.ops.ed.undo))
        obj = bpy.data.objects["Scan"]
        # An undo may restore any mesh and any records: the next click reads them again.
        after_undo.append(timed(click))
        bpy.ops.ed.undo()
        obj = bpy.data.objects["Scan"]
    out[f"delete_{stored}"] = stats(deletes)
    out[f"undo_{stored}"] = stats(undos)
    out[f"after_undo_{stored}"] = stats(after_undo)
    bpy.context.view_layer.objects.active = obj
    out[f"clear_{stored}"] = stats(
        [timed(lambda: bpy.ops.vg.clear_measurements("EXEC_DEFAULT", True))]
    )

    if label == "1M" or SIZES[label] <= 1_000_000:
        out["first_geodesic_ms"] = (
            timed(
                lambda: bpy.ops.vg.measure_xyz(
                    "EXEC_DEFAULT",
                    True,
                    location=tuple(next(next_center)),
                    radius=radius,
                    patch="geodesic",
                )
            )
            * 1e3
        )
    if label == "1M":
        out.update(core_and_batch(bpy, obj, points, triangles, radius, centers, repeats))
    out["peak_rss_end_mb"] = peak_rss_mb()
    extension.unregister()
    return out


def core_and_batch(bpy, obj, points, triangles, radius, centers, repeats) -> dict:
    from virtual_goniometer.batch.measure import measure_mesh
    from virtual_goniometer.batch.sources import MeshSource, import_mesh
    from virtual_goniometer.bridge import mesh_data
    from virtual_goniometer.vg_addon.formats.meshio import write_ply
    from virtual_goniometer.vg_addon.workflow.batchplan import Task

    out = {}
    surface = mesh_data.surface_for(obj, mesh_data.evaluated_geometry(obj))
    sample = centers[:300]
    per = []
    for _ in range(max(3, repeats // 2)):
        start = time.perf_counter()
        for c in sample:
            surface.measure(c, radius)
        per.append((time.perf_counter() - start) / len(sample))
    out["core_per_measurement"] = stats(per)

    tasks = [
        Task(
            index=i,
            mesh=0,
            center=tuple(map(float, c)),
            radius=radius,
            lam=2.0,
            patch="euclidean",
            number=i + 1,
        )
        for i, c in enumerate(centers[:1000])
    ]
    obj.vg.measurements.clear()
    obj.vg.next_number = 1
    result = measure_mesh(0, MeshSource(obj.name), tasks, {})
    out["batch_per_s"] = result.measured / result.measure_seconds
    out["batch_measured"] = result.measured

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "scan.ply"
        write_ply(path, points, triangles)
        times = []
        for k in range(3):
            times.append(timed(lambda k=k: import_mesh(MeshSource(f"Imported{k}", str(path)))))
        out["ply_import"] = stats(times)
    return out


def machine() -> str:
    import bpy

    cpu = ""
    try:
        with open("/proc/cpuinfo") as handle:
            cpu = next(
                (line.split(":", 1)[1].strip() for line in handle if "model name" in line), ""
            )
    except OSError:
        pass
    where = "Blender" if bpy.app.binary_path else "bpy module"
    return (
        f"{platform.machine()} {cpu or platform.processor()}, {os.cpu_count()} cores; "
        f"{where} {bpy.app.version_string}, Python {platform.python_version()}, "
        f"NumPy {np.__version__}"
    )


def child_command(label: str, stored: int, repeats: int) -> list[str]:
    import bpy

    args = ["--one", label, "--stored", str(stored), "--repeats", str(repeats)]
    if bpy.app.binary_path:  # a real Blender: run the script in another Blender
        return [bpy.app.binary_path, "-b", "--factory-startup", "--python", __file__, "--", *args]
    return [sys.executable, __file__, *args]


def table(results: list[dict]) -> None:
    labels = [r["label"] for r in results]
    print(f"\n{'figure':<46}" + "".join(f"{label:>14}" for label in labels))

    def row(name, key, unit="ms", sub="min"):
        values = []
        for r in results:
            v = r.get(key)
            values.append(v.get(sub) if isinstance(v, dict) else v)
        cells = "".join(f"{'—':>14}" if v is None else f"{v:>11.1f} {unit:<2}" for v in values)
        print(f"{name:<46}{cells}")

    stored = results[0]["stored"]
    row("vertices (k)", "vertices_k", "")
    row("first click", "first_click_ms")
    row("memory before the first click", "rss_before_first_click_mb", "MB")
    row("peak memory during the first click", "peak_rss_mb", "MB")
    row("peak memory of the setup (mesh made here)", "peak_rss_setup_mb", "MB")
    row("repeat click, 1 stored (min)", "repeat_click_1")
    row("repeat click, 1 stored (median)", "repeat_click_1", sub="median")
    row(f"repeat click, {stored} stored (min)", f"repeat_click_{stored}")
    row(f"repeat click, {stored} stored (median)", f"repeat_click_{stored}", sub="median")
    row("click with the stability figure, 1 stored", "stable_click_1")
    row(f"click with the stability figure, {stored} stored", f"stable_click_{stored}")
    row("drag press, 1 stored", "press_1")
    row("drag release, 1 stored", "release_1")
    row(f"drag press, {stored} stored", f"press_{stored}")
    row(f"drag release, {stored} stored", f"release_{stored}")
    row(f"delete one, {stored} stored", f"delete_{stored}")
    row(f"undo of a delete, {stored} stored", f"undo_{stored}")
    row(f"click after an undo, {stored} stored", f"after_undo_{stored}")
    row(f"clear {stored}", f"clear_{stored}")
    row("first geodesic measurement", "first_geodesic_ms")
    row("core, per 2,000-vertex measurement", "core_per_measurement")
    row("batch measurements / s (import excluded)", "batch_per_s", "/s")
    row("import of a binary PLY (float64)", "ply_import")

    by = {r["label"]: r for r in results}
    print("\nratios (repeat click, min):")
    if "1M" in by:
        base = by["1M"]["repeat_click_1"]["min"]
        print(
            "  10k : 1M : 5M = "
            + " : ".join(
                f"{by[k]['repeat_click_1']['min'] / base:.2f}" if k in by else "—"
                for k in ("10k", "1M", "5M")
            )
        )
    for r in results:
        one, many = r["repeat_click_1"]["min"], r[f"repeat_click_{stored}"]["min"]
        print(f"  {r['label']}: 1 : {stored} stored = 1 : {many / one:.2f}")


def main(argv=None) -> None:
    if "--" in sys.argv:  # run by a real Blender: our arguments follow "--"
        argv = sys.argv[sys.argv.index("--") + 1 :] if argv is None else argv
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="10k,1M,5M", help="comma-separated, of 10k, 1M, 5M")
    parser.add_argument("--stored", type=int, default=1000, help="measurements stored")
    parser.add_argument("--repeats", type=int, default=7, help="repeats per figure")
    parser.add_argument("--one", help=argparse.SUPPRESS)  # a child process: one size
    args = parser.parse_args(argv)

    if args.one:
        result = run_size(args.one, args.stored, args.repeats)
        result["vertices_k"] = result["vertices"] / 1e3
        print("RESULT " + json.dumps(result), flush=True)
        return

    print(f"machine: {machine()}")
    results = []
    for label in args.sizes.split(","):
        start = time.perf_counter()
        done = subprocess.run(
            child_command(label, args.stored, args.repeats),
            capture_output=True,
            text=True,
            check=False,
        )
        lines = [line for line in done.stdout.splitlines() if line.startswith("RESULT ")]
        if done.returncode != 0 or not lines:
            print(f"{label}: failed\n{done.stdout[-3000:]}\n{done.stderr[-3000:]}")
            continue
        results.append(json.loads(lines[-1][len("RESULT ") :]))
        print(f"{label}: done in {time.perf_counter() - start:.0f} s", flush=True)
    if results:
        table(results)


if __name__ == "__main__":
    main()
