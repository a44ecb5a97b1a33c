"""Re-measure the GUI's measurements with ``vg.measure_xyz`` in ``blender -b`` (same build).

    blender -b --python replay_check.py -- REQUESTS.json RESULTS.json

REQUESTS.json is a list of ``{"center", "radius", "lam", "patch"}``; the same wedge scene as
the GUI's is built (:mod:`scene`), ``vg.measure_xyz`` is run for each request, and the exact
numbers it recorded are written to RESULTS.json in the same order.
"""

from __future__ import annotations

import json
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import scene


def main() -> None:
    requests_path, results_path = sys.argv[sys.argv.index("--") + 1 :][:2]
    with open(requests_path) as handle:
        requests = json.load(handle)
    obj = scene.build_wedge()
    results = []
    for request in requests:
        before = len(obj.vg.measurements)
        outcome = bpy.ops.vg.measure_xyz(
            location=request["center"],
            radius=request["radius"],
            seg_param=request["lam"],
            patch=request["patch"],
        )
        if outcome != {"FINISHED"} or len(obj.vg.measurements) != before + 1:
            results.append(None)
            continue
        results.append(json.loads(obj.vg.measurements[-1].exact))
    with open(results_path, "w") as handle:
        json.dump(results, handle)


main()
