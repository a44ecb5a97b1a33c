"""Benchmark the measuring core and print the numbers (no pass/fail: read them).

Run: ``.venv/bin/python scripts/benchmark.py`` (after ``bash scripts/setup.sh``), or with any
Python that has NumPy. Prints: spatial-index build for a 1M-vertex mesh, patch query time,
measurement time for 1k/10k/100k-vertex patches, measurements per second on the 1M-vertex mesh,
and WithinSS on 100k values; then the core's figures for a click on a 1M-vertex scan-like ridge
(Surface build with int64 and int32 triangles, winding, first and later geodesic measurement,
Euclidean measurement of a 2,000-vertex patch); Find Break Edges on a 1M-vertex bone shaft, and
the batch profiling every edge it finds (``--case find_edges`` runs only these two).
"""

from __future__ import annotations

import argparse
import importlib
import platform
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmark_drag import ridge_mesh  # scripts/ is on sys.path when run as a script

from vg_addon import GridIndex, Surface, withinss_split
from vg_addon.synthetic_meshes import wedge


def best_of(function, repeats: int) -> float:
    """Smallest wall time of ``repeats`` calls, in seconds."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return min(times)


def radius_for(surface: Surface, center, target: int) -> float:
    """A radius whose Euclidean patch around ``center`` holds about ``target`` vertices."""
    distances = np.sort(np.linalg.norm(surface.points - center, axis=1))
    return float(distances[min(target, distances.size) - 1]) * (1 + 1e-9)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vertices", type=int, default=1_000_000, help="size of the big mesh")
    parser.add_argument(
        "--case",
        choices=("all", "find_edges", "refinement"),
        default="all",
        help="run only this case",
    )
    args = parser.parse_args(argv)
    if args.case == "refinement":
        refinement_comparison(int(np.sqrt(args.vertices)))
        return
    if args.case == "find_edges":
        find_edges_figures(args.vertices)
        batch_find_edges_figures(args.vertices)
        return

    print(
        f"machine: {platform.machine()}, {platform.processor() or 'cpu'}, "
        f"Python {platform.python_version()}, NumPy {np.__version__}"
    )
    side = int(np.sqrt(args.vertices / 2))
    mesh = wedge(90, n=side, irregular=True, seed=0)
    print(f"mesh: 90° wedge, {len(mesh.points):,} vertices, {len(mesh.triangles):,} triangles")

    build = best_of(lambda: GridIndex(mesh.points), 3)
    print(f"index build ({len(mesh.points):,} vertices):        {build * 1e3:8.1f} ms")
    start = time.perf_counter()
    surface = Surface(mesh.points, mesh.triangles)
    print(
        f"surface build (normals + index):          {(time.perf_counter() - start) * 1e3:8.1f} ms"
    )

    center = np.zeros(3)
    for target in (1_000, 2_000, 10_000, 100_000):
        radius = radius_for(surface, center, target)
        repeats = 50 if target <= 10_000 else 5
        query = best_of(lambda r=radius: surface.index.ball(center, r), repeats)
        measure = best_of(lambda r=radius: surface.measure(center, r), repeats)
        m = surface.measure(center, radius)
        print(
            f"patch {m.n_vertices:>7,} vertices: query {query * 1e3:7.2f} ms, "
            f"query + measurement {measure * 1e3:7.2f} ms, angle {m.angle:.4f}°"
        )

    radius = radius_for(surface, center, 2_000)
    rng = np.random.default_rng(0)
    on_crease = mesh.points[np.abs(mesh.points[:, 1]) + np.abs(mesh.points[:, 2]) < 1e-12]
    centers = on_crease[rng.integers(0, len(on_crease), 500)]
    start = time.perf_counter()
    for c in centers:
        surface.measure(c, radius)
    elapsed = time.perf_counter() - start
    print(f"measurements per second (2k-vertex patches, 1M mesh): {len(centers) / elapsed:8.0f}")

    geodesic = best_of(lambda: surface.measure(center, radius, patch="geodesic"), 10)
    print(f"geodesic patch + measurement (2k vertices):  {geodesic * 1e3:7.2f} ms")

    values = rng.normal(size=100_000)
    print(
        f"WithinSS, 100k values:                   {best_of(lambda: withinss_split(values), 10) * 1e3:8.2f} ms"
    )
    core_figures(int(np.sqrt(args.vertices)))
    blas_path_comparison(int(np.sqrt(args.vertices)))
    refinement_comparison(int(np.sqrt(args.vertices)))
    find_edges_figures(args.vertices)
    batch_find_edges_figures(args.vertices)


def find_edges_figures(vertices: int) -> None:
    """Find Break Edges on a scan-sized bone shaft (mm, rough surface): the time from the call to
    the candidates (the ridge graph built inside it, as on a first click), the number of steps
    and the longest (what Esc waits for in Blender), the peak memory the finder allocates
    (tracemalloc, in a second run), and the finder before and after it was sped up, side by
    side."""
    import tracemalloc

    from vg_addon.method.break_edges import BreakEdgeFinder
    from vg_addon.synthetic_meshes import bone_fragment

    spacing = 0.1 * np.sqrt(988_000 / vertices)  # 0.1 mm gives 988,000 vertices
    bone = bone_fragment(spacing=spacing, roughness=0.02)
    print(f"\nfind break edges: bone shaft, {len(bone.points):,} vertices, edges {spacing:.3g} mm")
    for run in ("time", "memory"):
        surface = Surface(bone.points, bone.triangles)
        finder = BreakEdgeFinder(surface)
        if run == "memory":
            tracemalloc.start()
        start = last = time.perf_counter()
        shares = []
        for progress in finder.steps():
            now = time.perf_counter()
            shares.append((progress, now - last))
            last = now
        total = time.perf_counter() - start
        if run == "time":
            longest = max(shares, key=lambda share: share[1])
            print(
                f"call to candidates: {total:8.2f} s ({len(finder.result.candidates)} found) in "
                f"{len(shares)} steps, the longest {longest[1]:.2f} s (to {longest[0]:.2f})"
            )
            start = time.perf_counter()
            BreakEdgeFinder(surface).run()  # the ridge graph is kept with the surface
            again = time.perf_counter() - start
            print(f"again, the ridge graph already built (after tracing an edge): {again:6.2f} s")
        else:
            _, peak = tracemalloc.get_traced_memory()
            tracemalloc.stop()
            print(f"peak memory allocated by the finder: {peak / 2**20:8.0f} MiB")
    find_edges_before_after(bone)


FIND_EDGES_BEFORE = "ec2841d"
"""The last commit before the finder's ridge graph was built from packed sorts and its long
phases were split into steps."""


def find_edges_before_after(bone, rounds: int = 2) -> None:
    """The finder of :data:`FIND_EDGES_BEFORE` and today's on the same bone, interleaved round by
    round (best of ``rounds``): wall and CPU time from the call to the candidates, the steps
    and the longest step."""
    from vg_addon.method.break_edges import BreakEdgeFinder

    loaded = _core_at(FIND_EDGES_BEFORE, "vg_addon_find_before")
    if loaded is None:
        return
    before = importlib.import_module("vg_addon_find_before.method.break_edges").BreakEdgeFinder
    cores = {"today": (Surface, BreakEdgeFinder), FIND_EDGES_BEFORE: (loaded.Surface, before)}
    best = {}
    for _ in range(rounds):
        for name, (surface_type, finder_type) in cores.items():
            finder = finder_type(surface_type(bone.points, bone.triangles))
            wall, cpu = time.perf_counter(), time.process_time()
            last, longest, count = wall, 0.0, 0
            for _ in finder.steps():
                now = time.perf_counter()
                longest, last, count = max(longest, now - last), now, count + 1
            figures = (time.perf_counter() - wall, time.process_time() - cpu, longest, count)
            best[name] = tuple(map(min, zip(best.get(name, figures), figures, strict=True)))
    print(f"find break edges before ({FIND_EDGES_BEFORE}) and today, best of {rounds}:")
    for name, (wall, cpu, longest, count) in best.items():
        print(
            f"  {name:8s} call to candidates {wall:6.2f} s wall, {cpu:6.2f} s CPU; "
            f"{count:4d} steps, the longest {longest:5.2f} s"
        )
    (new_wall, new_cpu, new_longest, _), (old_wall, old_cpu, old_longest, _) = best.values()
    print(
        f"  ratios today/before: wall {new_wall / old_wall:5.2f}, CPU {new_cpu / old_cpu:5.2f}, "
        f"longest step {new_longest / old_longest:5.2f}"
    )


def batch_find_edges_figures(vertices: int, spacing: float = 2.0, radius: float = 2.5) -> None:
    """The batch end to end on the same bone shaft, written as a PLY file: ``vg_batch.py BONE
    --find-edges --spacing 2 --radius 2.5`` (every edge found profiled, its rows, edges CSV and
    plots written), its wall and CPU time, its peak memory (the process's largest resident
    set) and the batch's own lines on the finder and the import. Needs a Python with bpy."""
    import importlib.util
    import os
    import re
    import subprocess
    import tempfile

    from vg_addon.formats import meshio
    from vg_addon.synthetic_meshes import bone_fragment

    if importlib.util.find_spec("bpy") is None:
        print("\n(no batch figures: this Python has no bpy; run with .venv/bin/python)")
        return
    bone = bone_fragment(spacing=0.1 * np.sqrt(988_000 / vertices), roughness=0.02)
    script = Path(__file__).resolve().parents[1] / "vg_batch.py"
    with tempfile.TemporaryDirectory(prefix="vg-bench-batch-") as folder:
        mesh = Path(folder) / "bone.ply"
        meshio.write_ply(mesh, bone.points, bone.triangles)
        command = [sys.executable, str(script), str(mesh), "--find-edges", "--spacing",
                   f"{spacing:g}", "--radius", f"{radius:g}", "--out", str(Path(folder) / "o.csv")]  # fmt: skip
        log_path = Path(folder) / "log.txt"
        with open(log_path, "w") as log_file:
            start = time.perf_counter()
            process = subprocess.Popen(command, stdout=log_file, stderr=subprocess.STDOUT)
            # wait4: this child's own resource use (its peak memory, not the benchmark's).
            _, status, usage = os.wait4(process.pid, 0)
            wall = time.perf_counter() - start
        log = log_path.read_text(errors="replace")
    if os.waitstatus_to_exitcode(status) != 0:
        print(f"\nbatch --find-edges failed (exit {os.waitstatus_to_exitcode(status)}):\n{log}")
        return
    lines = [line for line in log.splitlines() if re.search(r"found \d+ break|mesh import", line)]
    print(
        f"\nbatch --find-edges --spacing {spacing:g} --radius {radius:g}, "
        f"{len(bone.points):,} vertices: {wall:6.2f} s wall, "
        f"{usage.ru_utime + usage.ru_stime:6.2f} s CPU, peak memory "
        f"{usage.ru_maxrss / 1024:6.0f} MiB (largest resident set)"
    )
    for line in lines:
        print(f"  {line.removeprefix('vg_batch: ')}")


def refinement_comparison(side: int, rounds: int = 5) -> None:
    """The refined rule (the default) against the oriented rule, with today's core, the core at
    :data:`REFINED_SPEED_BASE` (before the second speed pass) and the core at :data:`SPEED_BASE`
    (the issue's filing, whose oriented time is the aim), side by side in one run, interleaved
    round by round (best of ``rounds`` rounds of 30 calls): a 2,000-vertex measurement where the
    refinement has nothing to do (an exact ridge), where it runs and declines (a noisy ridge, as
    on a scan), and where it applies (a marched crease). Today's readings are checked to hold the
    same bits as both earlier cores'."""
    from benchmark_drag import ridge_mesh

    from vg_addon.reference_shapes import marched_wedge

    points, triangles = ridge_mesh(side)
    rng = np.random.default_rng(3)
    spacing = float(np.ptp(points[:, 0])) / side
    noisy = points + rng.normal(scale=0.05 * spacing, size=points.shape)
    marched, marched_triangles, _, direction = marched_wedge(90.0, 0.0075, turn_seed=3)
    along = np.abs(marched @ direction)
    off = np.linalg.norm(marched - np.outer(marched @ direction, direction), axis=1)
    old_cores = {
        when: _core_at(commit, f"vg_addon_{when}_{commit}")
        for when, commit in (("before", REFINED_SPEED_BASE), ("filing", SPEED_BASE))
    }
    old_cores = {when: core for when, core in old_cores.items() if core is not None}
    cases = [
        ("exact ridge", points, triangles),
        ("noisy ridge", noisy, triangles),
        ("marched crease", marched, marched_triangles),
    ]
    print(
        "\nrefined (default) against oriented rule, 2,000-vertex patches, best of rounds; "
        f"before: the core at {REFINED_SPEED_BASE}, filing: at {SPEED_BASE}:"
    )
    for name, where, faces in cases:
        cores = {"now": Surface(where, faces)}
        cores.update((when, core.Surface(where, faces)) for when, core in old_cores.items())
        if name == "marched crease":
            center = where[np.argmin(np.where(along < 0.05, off, np.inf))]
        else:
            center = where[
                np.argmin(np.abs(where[:, 1]) + np.abs(where[:, 2]) + np.abs(where[:, 0]))
            ]
        radius = radius_for(cores["now"], center, 2_000)
        times = dict.fromkeys(((when, rule) for when in cores for rule in RULES_TIMED), np.inf)
        for _ in range(rounds):
            for when, rule in list(times):
                seconds = best_of(
                    lambda s=cores[when], r=rule, c=center, rad=radius: s.measure(c, rad, rule=r),
                    30,
                )
                times[when, rule] = min(times[when, rule], seconds)
        m = cores["now"].measure(center, radius)
        applied = "applied" if m.split_angle is not None else "kept Algorithm 1's"
        print(f"  {name} ({len(where):,} vertices, refinement {applied}):")
        for when in cores:
            oriented, refined = times[when, "oriented"], times[when, "refined"]
            same = when == "now" or _same_reading(m, cores[when].measure(center, radius))
            print(
                f"    {when:7s} oriented {oriented * 1e3:5.2f} ms, refined {refined * 1e3:5.2f} ms "
                f"(ratio {refined / oriented:4.2f})"
                + ("" if when == "now" else f"; same bits as now: {'yes' if same else 'NO'}")
            )
        now = times["now", "refined"]
        ratios = [f"now/{when} {now / times[when, 'refined']:4.2f}" for when in old_cores]
        if "filing" in old_cores:
            ratios.append(f"now / oriented at filing {now / times['filing', 'oriented']:4.2f}")
        print(f"    refined: {', '.join(ratios)}")


RULES_TIMED = ("oriented", "refined")


def _same_reading(new, old) -> bool:
    """Whether two measurements hold the same bits in every field both have."""
    from dataclasses import fields

    for field in fields(old):
        a, b = getattr(new, field.name, None), getattr(old, field.name)
        if isinstance(b, np.ndarray):
            if not (
                isinstance(a, np.ndarray) and a.dtype == b.dtype and a.tobytes() == b.tobytes()
            ):
                return False
        elif isinstance(b, float):
            if not (isinstance(a, float) and a.hex() == b.hex()):
                return False
        elif not hasattr(b, "__dataclass_fields__") and a != b:
            return False
    return True


def core_figures(side: int, repeats: int = 3) -> None:
    """What the first click on a scan costs, and each measurement after it (best of ``repeats``)."""
    points, triangles = ridge_mesh(side)
    print(f"\ncore figures: ridge of {len(points):,} vertices, {len(triangles):,} triangles")
    radius = (2.0 / (side - 1)) * np.sqrt(2000 / np.pi)  # about 2,000 vertices
    centers = [(x, 0.0, 0.0) for x in np.random.default_rng(0).uniform(-0.8, 0.8, 200)]
    figures = {}
    for _ in range(repeats):
        for label, given in (("int64", triangles), ("int32", triangles.astype(np.int32))):
            start = time.perf_counter()
            surface = Surface(points, given)
            built = time.perf_counter()
            _ = surface.winding
            wound = time.perf_counter()
            surface.measure(centers[-1], radius)  # labels the mesh's parts
            parted = time.perf_counter()
            surface.measure(centers[0], radius, patch="geodesic")
            first = time.perf_counter()
            surface.measure(centers[1], radius, patch="geodesic")
            later = time.perf_counter()
            for center in centers:
                surface.measure(center, radius)
            done = time.perf_counter()
            for name, seconds in (
                (f"Surface build ({label} triangles)", built - start),
                (f"winding, first use ({label})", wound - built),
                (f"first Euclidean measurement ({label})", parted - wound),
                (f"first geodesic measurement ({label})", first - parted),
                (f"later geodesic measurement ({label})", later - first),
                (f"Euclidean measurement, 2k vertices ({label})", (done - later) / len(centers)),
            ):
                figures[name] = min(figures.get(name, np.inf), seconds)
    for name, seconds in figures.items():
        print(f"{name + ':':48s} {seconds * 1e3:9.2f} ms")


BLAS_COMMIT = "97179f7"
"""The last commit whose measuring path used BLAS and LAPACK (matrix products, ``eigh``)."""

SPEED_BASE = "ec2841d"
"""The last commit before the refined rule's cost was cut (issue 19, item 5): its oriented rule's
time is the issue's aim, and :func:`refinement_comparison` prints it as "filing"."""

REFINED_SPEED_BASE = "d4444ed"
"""The last commit before the second pass on the refined rule's cost (the band means' sums, the
side planes' gathers): the "before" of :func:`refinement_comparison`."""


def _blas_core():
    """The core as it was at :data:`BLAS_COMMIT` (None, with the reason printed, where git or
    that commit is not available), and its stability module."""
    core = _core_at(BLAS_COMMIT, "vg_addon_blas")
    if core is None:
        return None
    return core, importlib.import_module("vg_addon_blas.method.stability")


def _core_at(commit: str, alias: str):
    """The core as it was at ``commit``, imported as ``alias`` from ``git archive`` (None, with
    the reason printed, where git or that commit is not available)."""
    import atexit
    import shutil
    import subprocess
    import tempfile

    root = Path(__file__).resolve().parents[1]
    folder = Path(tempfile.mkdtemp(prefix=f"{alias}-"))
    # Removed when the script ends, not before: the old core imports its modules lazily.
    atexit.register(shutil.rmtree, folder, ignore_errors=True)
    try:
        archive = subprocess.run(
            ["git", "-C", str(root), "archive", commit, "vg_addon"],
            capture_output=True,
            check=True,
        ).stdout
        subprocess.run(["tar", "-x", "-C", str(folder)], input=archive, check=True)
    except (OSError, subprocess.CalledProcessError) as error:
        print(f"(no comparison with {commit}: git archive failed: {error})")
        return None
    (folder / "vg_addon").rename(folder / alias)
    sys.path.insert(0, str(folder))
    return importlib.import_module(alias)


def blas_path_comparison(side: int, rounds: int = 5) -> None:
    """Today's fixed-order arithmetic against the BLAS path of :data:`BLAS_COMMIT`, in one run,
    the two interleaved round by round (best of ``rounds``): a 2,000-vertex Euclidean measurement
    on a 1M-vertex ridge, and its stability figure."""
    from vg_addon.method.stability import estimate_stability

    loaded = _blas_core()
    if loaded is None:
        return
    old_core, old_stability = loaded
    points, triangles = ridge_mesh(side)
    radius = (2.0 / (side - 1)) * np.sqrt(2000 / np.pi)
    centers = [(x, 0.0, 0.0) for x in np.random.default_rng(1).uniform(-0.8, 0.8, 200)]
    paths = {
        "fixed order (today)": (Surface(points, triangles), estimate_stability),
        f"BLAS path ({BLAS_COMMIT})": (
            old_core.Surface(points, triangles),
            old_stability.estimate_stability,
        ),
    }
    best = {(name, what): np.inf for name in paths for what in ("measure", "stability")}
    for _ in range(rounds):
        for name, (surface, stability) in paths.items():
            start = time.perf_counter()
            for center in centers:
                surface.measure(center, radius)
            per_measurement = (time.perf_counter() - start) / len(centers)
            m = surface.measure(centers[0], radius)
            figure = best_of(lambda s=surface, f=stability, m=m: f(s, m), 5)
            best[name, "measure"] = min(best[name, "measure"], per_measurement)
            best[name, "stability"] = min(best[name, "stability"], figure)
    print(f"\nfixed-order arithmetic against the BLAS path, {len(points):,}-vertex ridge:")
    for what, label in (("measure", "measurement, 2k vertices"), ("stability", "stability figure")):
        new, old = (best[name, what] for name in paths)
        print(
            f"{label + ':':28s} today {new * 1e3:7.3f} ms, BLAS path {old * 1e3:7.3f} ms, "
            f"ratio {new / old:5.2f}"
        )


if __name__ == "__main__":
    main()
