"""Blender operators (``vg.*``): thin wrappers that check their input, call the bpy bridge
(``bridge.measuring``) and report. ``drag`` is the click-and-drag tool's modal operator, with
its viewport preview in ``drag_overlay``; ``sweep`` writes a radius sweep's CSV and plot;
``edge`` measures whole edges (edge profiles), with its path preview in ``edge_overlay``;
``find_edges`` finds break edges for review (its drawing in ``find_edges_overlay``) and
``picked_points_ops`` makes edges of MeshLab ``.pp`` files;
``report_ops`` writes the replication report."""

from . import (
    csv_ops,
    drag,
    edge,
    find_edges,
    map_ops,
    measure,
    picked_points_ops,
    report_ops,
    sweep,
    view_session,
)

classes = (
    *measure.classes,
    *csv_ops.classes,
    *drag.classes,
    *sweep.classes,
    *edge.classes,
    *find_edges.classes,
    *picked_points_ops.classes,
    *map_ops.classes,
    *report_ops.classes,
)
