"""Build a study shaped like the paper's on synthetic fragments and report on it.

    .venv/bin/python scripts/replicate_study.py --out study/ [--fragments 2] [--observers 2]

Writes the fragments (PLY), every session's point list and measurements CSV (each measured by a
run of vg_batch.py, as a user's batch would), the manual goniometer tables, and the report
(study/report/report.html) from ``vg_batch.py --report``. The xyz sessions re-measure each
observer's first drag session with ``--points``: within one build their IOV is 0.
"""

from __future__ import annotations

import argparse
import csv
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from vg_addon.analysis.study import fragments, plan_study  # noqa: E402
from vg_addon.formats import meshio  # noqa: E402


def batch(*args) -> int:
    """One run of vg_batch.py in this Python; its output shown only when it fails."""
    run = subprocess.run(
        [sys.executable, str(ROOT / "vg_batch.py"), *map(str, args)],
        capture_output=True,
        text=True,
        check=False,
    )
    if run.returncode not in (0, 1):
        sys.stderr.write(run.stdout + run.stderr)
        raise SystemExit(f"vg_batch.py {' '.join(map(str, args[:3]))} ... failed")
    return run.returncode


def _next_second() -> None:
    """Wait until the wall clock turns to its next second (the CSV's Date is to the second)."""
    time.sleep(1.0 - time.time() % 1.0 + 0.01)


def write_plan(path: Path, plan) -> None:
    with open(path, "w", encoding="utf-8", newline="") as handle:
        writer = csv.writer(handle, lineterminator="\n")
        writer.writerow(plan.header)
        writer.writerows([repr(v) if isinstance(v, float) else v for v in row] for row in plan.rows)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, type=Path, help="the study's folder")
    parser.add_argument("--fragments", type=int, default=2)
    parser.add_argument("--observers", type=int, default=1)
    parser.add_argument("--xyz-repetitions", type=int, default=2)
    parser.add_argument("--spacing", type=float, default=0.3, help="mesh vertex spacing (mm)")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    out = args.out.resolve()
    (out / "plans").mkdir(parents=True, exist_ok=True)
    meshes = fragments(args.fragments, seed=args.seed, spacing=args.spacing)
    plys = []
    for name, fragment in meshes.items():
        plys.append(out / f"{name}.ply")
        meshio.write_ply(plys[-1], fragment.points, fragment.triangles)
    sessions = []
    start = time.perf_counter()
    for plan in plan_study(meshes, observers=args.observers, seed=args.seed):
        if plan.method == "manual":
            sessions.append(out / f"{plan.name}.csv")
            write_plan(sessions[-1], plan)
            continue
        points = out / "plans" / f"{plan.name}.csv"
        write_plan(points, plan)
        sessions.append(out / f"{plan.name}.csv")
        batch(*plys, "--points", points, "--units", "mm", "--out", sessions[-1], "--quiet")
        if plan.name.endswith("_drag_1"):
            for rep in range(1, args.xyz_repetitions + 1):
                # Each repetition is a session of its own, taken later: its Date (to the second)
                # must differ, or the report rightly takes two identical files as one session.
                _next_second()
                sessions.append(out / f"{plan.observer}_xyz_{rep}.csv")
                first = out / f"{plan.name}.csv"
                batch(*plys, "--points", first, "--units", "mm", "--out", sessions[-1], "--quiet")
        print(f"{plan.name}: measured ({time.perf_counter() - start:.0f} s)", flush=True)
    code = batch("--report", out / "report", *sessions)
    print(f"report: {out / 'report' / 'report.html'} (vg_batch.py exit status {code})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
