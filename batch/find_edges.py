"""``--find-edges``: every break edge the finder sees on a mesh, as edges to profile.

Each candidate of ``vg_addon.method.break_edges.find_break_edges`` becomes an edge spec like an
``--edge``'s: its waypoints (start, via points, end) are the edge's points, which
``trace_edge`` follows back to the candidate's path, and it is measured by the same pipeline
(``bridge.edges.measure_edge_on_object``) with ``--spacing``, ``--radius``, ``--lambda`` and
``--patch``. So the edge's row of ``OUT_edges.csv`` re-measures it identically with ``--edges``.
"""

from __future__ import annotations

import time

from ..vg_addon.method.break_edges import find_break_edges
from .stdio import say


def found_edge_specs(surface, options: dict, name: str) -> list[dict]:
    """The edges found on ``surface`` (the mesh ``name``), most confident first, as edge specs
    (see ``batch.edges.edge_specs``); their note (the edge's User Data) says which candidate
    each is, with its confidence and mean bend.

    Raises
    ------
    GoniometerError
        When the finder cannot run on this surface (a point cloud, a ``--min-length`` or
        ``--find-scale`` out of the mesh's range).
    """
    found = options["find_edges"]
    overrides = {name: value for name, value in found["parameters"].items() if value is not None}
    start = time.perf_counter()
    result = find_break_edges(surface, **overrides)
    seconds = time.perf_counter() - start
    specs = [
        {
            "points": candidate.waypoint_points.tolist(),
            "spacing": found["spacing"],
            "radius": found["radius"],
            "lam": found["lam"],
            "patch": found["patch"],
            "mesh_name": "",
            "note": (
                f"found edge {candidate.number}: confidence {candidate.confidence:.2f}, mean "
                f"bend {candidate.mean_bend_deg:.1f}°, length {candidate.length:.4g}"
                + (", closed" if candidate.closed else "")
            ),
        }
        for candidate in result.candidates
    ]
    if not options.get("quiet"):
        used = result.parameters
        say(
            f"{name}: found {len(specs)} break edge(s) in {seconds:.1f} s (scale "
            f"{used.scale:.4g}, bend at least {used.min_bend_deg:g}°, length at least "
            f"{used.min_length:.4g})"
        )
    return specs


def find_options(args) -> dict | None:
    """What the workers need to find and profile edges (None without ``--find-edges``)."""
    if not args.find_edges:
        return None
    return {
        "spacing": args.spacing,
        "radius": args.radius,
        "lam": args.lam,
        "patch": args.patch,
        "parameters": {
            "min_length": args.min_length,
            "scale": args.find_scale,
            "min_bend_deg": args.min_bend,
        },
    }
