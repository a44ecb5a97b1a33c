"""Blender operators (``vg.*``): thin wrappers that check their input, call the bpy bridge
(``bridge.measuring``) and report. ``drag`` is the click-and-drag tool's modal operator, with
its viewport preview in ``drag_overlay``; ``sweep`` writes a radius sweep's CSV and plot;
``edge`` measures whole edges (edge profiles), with its path preview in ``edge_overlay``;
``report_ops`` writes the replication report."""

from . import csv_ops, drag, edge, map_ops, measure, report_ops, sweep

classes = (
    *measure.classes,
    *csv_ops.classes,
    *drag.classes,
    *sweep.classes,
    *edge.classes,
    *map_ops.classes,
    *report_ops.classes,
)
