"""The measurement map's edge lines: each edge profile's traced path drawn as a thin magenta tube.

A map of a fragment whose edges were profiled (clicked, imported from a CSV or ``.pp`` file, or
found by ``--find-edges``) shows where each edge runs. The tubes are curve objects of the map's
throwaway scene, made here and removed with it.

An edge's stations are numbered in order along its line, a few millimetres apart, so most views
have room for only some of their labels. Of a label no chosen view draws, the map makes a
close-up (or a view of its own) only for the first and last station of an edge, and only for
the first ``EDGE_ENDS`` edges by number (:func:`stations_without_views` names the others): at
most two extra views per edge and ``2 * EDGE_ENDS`` in all. The numbers between them follow
along the magenta line, and each station's angle is in the CSV and the edge's profile plot. One
close-up per crowded station made the map of a bone with four found edges 36 views long (30
close-ups, two minutes of rendering at 1M vertices); two per edge with no cap would make a
scan with 60 found edges 120 close-ups long.
"""

from __future__ import annotations

import bpy
import numpy as np
from mathutils import Matrix

from ..vg_addon.formats import record_codec

LINE_WIDTH = 0.003
"""The tube's radius, as a fraction of the object's bounding-box diagonal."""

EDGE_ENDS = 10
"""How many edges (the lowest-numbered) may have their first and last stations given views of
their own: the batch's ``--render-edge-ends`` default and Render Map's. The first edges by number,
not a choice by the stations' numbers: an edge's number is the order it was made in (clicked,
an edges CSV's rows) or, for ``--find-edges``, the finder's order, most confident first, so the
cap keeps the edges an analyst made first or trusts most, and which ones it keeps is read off
the CSV's ``Edge #`` column, whatever crowds the views."""

LINE_COLOUR = (0.9, 0.0, 0.9, 1.0)
"""Magenta: in no side colour pair (Okabe-Ito), so it stands out on every side and the sky."""


def edge_paths(obj) -> list[tuple[int, np.ndarray, bool]]:
    """``(edge number, points, in_mesh_coordinates)`` of each edge record's traced path, for
    the edges with a current station: an edge whose stations are all stale (the mesh was
    edited under it) is no longer where the line would show it, and its stations get no label.
    Records without a path (damaged outside the extension) are skipped."""
    current = {
        item.edge_number for item in obj.vg.measurements if item.edge_number > 0 and not item.stale
    }
    paths = []
    for edge in obj.vg.edges:
        if edge.number not in current:
            continue
        numbers = record_codec.exact_numbers(edge)
        points = np.asarray(numbers.get("path", []), dtype=np.float64)
        if points.ndim == 2 and points.shape[0] >= 2 and points.shape[1] == 3:
            paths.append((edge.number, points, numbers.get("space") == record_codec.MESH))
    return paths


def stations_without_views(obj, edge_ends: int = EDGE_ENDS) -> set[int]:
    """The numbers of ``obj``'s edge stations that get no view of their own, only a label where
    a view has room: of the first ``edge_ends`` edges (by number) those that are neither the
    first nor the last (by arc length) of their edge's current stations, of the later edges
    every station."""
    by_edge: dict[int, list[tuple[float, int]]] = {}
    for item in obj.vg.measurements:
        if item.edge_number > 0 and not item.stale:
            arc = float(record_codec.exact_numbers(item).get("arc_length", 0.0))
            by_edge.setdefault(item.edge_number, []).append((arc, item.number))
    unviewed = set()
    for rank, edge_number in enumerate(sorted(by_edge)):
        stations = sorted(by_edge[edge_number])
        kept = stations[1:-1] if rank < edge_ends else stations
        unviewed.update(number for _arc, number in kept)
    return unviewed


def add_edge_lines(scene, obj, material, size: float, keep) -> int:
    """Draw each edge of ``obj`` with a current station (see :func:`edge_paths`) into ``scene``
    as a tube of radius ``LINE_WIDTH * size``, named by its number.

    Parameters
    ----------
    scene : bpy.types.Scene
        The map's throwaway scene.
    obj : bpy.types.Object
        The measured object (its edges' paths are in its mesh coordinates).
    material : bpy.types.Material
        What the tubes show.
    size : float
        The object's bounding-box diagonal (world units).
    keep : callable
        Called with every data-block made, so the map removes it afterwards.

    Returns
    -------
    int
        How many edges were drawn.
    """
    paths = edge_paths(obj)
    for number, points, in_mesh in paths:
        curve = keep(bpy.data.curves.new(f"VG Map edge {number}", type="CURVE"))
        curve.dimensions = "3D"
        curve.bevel_depth = LINE_WIDTH * size
        curve.bevel_resolution = 2
        curve.materials.append(material)
        spline = curve.splines.new("POLY")
        spline.points.add(points.shape[0] - 1)
        homogeneous = np.column_stack([points, np.ones(points.shape[0])])
        spline.points.foreach_set("co", homogeneous.astype(np.float32).ravel())
        line = keep(bpy.data.objects.new(f"VG Map edge {number}", curve))
        line.matrix_world = obj.matrix_world if in_mesh else Matrix.Identity(4)
        scene.collection.objects.link(line)
    return len(paths)
