"""A batch run's pictures of a measured mesh: the extension's measurement map (Cycles on the
CPU, the sides in their colours, numbered labels), and the material the saved .blend shows the
sides with."""

from __future__ import annotations

from pathlib import Path

import bpy

from ..bridge import measurement_map
from .stdio import quiet_stdout


def add_sides_material(obj, attribute: str):
    """Give a mesh without materials one that shows the side colours (Color Attribute node)."""
    material = bpy.data.materials.get("VG Sides")
    if material is None:
        material = bpy.data.materials.new("VG Sides")
        if material.node_tree is None:  # Blender < 5: nodes are off by default
            material.use_nodes = True
        nodes = material.node_tree.nodes
        shader = next(n for n in nodes if n.type == "BSDF_PRINCIPLED")
        shader.inputs["Roughness"].default_value = 0.6
        colour = nodes.new("ShaderNodeVertexColor")
        colour.layer_name = attribute
        colour.location = (shader.location.x - 300, shader.location.y)
        material.node_tree.links.new(colour.outputs["Color"], shader.inputs["Base Color"])
    if not obj.data.materials:
        obj.data.materials.append(material)
    return material


def render_map(obj, directory: Path, options: dict) -> Path:
    """Render the measurement map of ``obj`` into ``directory`` (the extension's own,
    ``bridge.measurement_map``: the views' PNGs and a contact sheet); returns the sheet."""
    with quiet_stdout():
        _views, sheet = measurement_map.render_map(
            obj,
            directory,
            views=options.get("render_views", "SIX"),
            size=tuple(options.get("render_size", (640, 480))),
            samples=options.get("render_samples", 16),
        )
    return sheet
