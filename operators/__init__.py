"""Blender operators (``vg.*``) and the helper modules that turn a bpy mesh into core input.

``measuring`` holds the one measuring pipeline every operator and tool calls.
"""

from . import csv_ops, drag, measure

classes = (*measure.classes, *csv_ops.classes, *drag.classes)
