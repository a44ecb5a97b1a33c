"""A batch run's picture of a measured mesh: Cycles on the CPU, the sides in their colours."""

from __future__ import annotations

import contextlib
from pathlib import Path

import bpy
import numpy as np

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


def render_object(obj, path: Path, options: dict, view) -> None:
    """Render ``obj`` alone with Cycles on the CPU: an orthographic camera framing it, looking
    along ``view`` (e.g. the sum of the measured patches' mean normals), a sun and a grey sky,
    every surface shown with the side colours."""
    import mathutils

    width, height = options.get("render_size", (640, 480))
    direction = mathutils.Vector(view)
    if direction.length < 1e-9:
        direction = mathutils.Vector((1.0, -1.0, 0.8))
    direction.normalize()
    # Look from ``direction`` but a little from above, so the sides read as 3D.
    direction = (direction + mathutils.Vector((0.0, 0.0, 0.35))).normalized()

    scene = bpy.data.scenes.new("VG Render")
    made = []
    try:
        scene.collection.objects.link(obj)
        material = add_sides_material(obj, "VG Sides")
        scene.view_layers[0].material_override = material

        camera_data = bpy.data.cameras.new("VG Camera")
        camera_data.type = "ORTHO"
        camera = bpy.data.objects.new("VG Camera", camera_data)
        made += [camera, camera_data]
        scene.collection.objects.link(camera)
        scene.camera = camera
        matrix = (-direction).to_track_quat("-Z", "Y").to_matrix()
        right, up, back = (np.array(matrix.col[i]) for i in range(3))
        corners = np.array([obj.matrix_world @ mathutils.Vector(c) for c in obj.bound_box])
        along = [corners @ axis for axis in (right, up, back)]
        extent = [a.max() - a.min() for a in along]
        if width != height and (extent[1] > extent[0]) == (width > height):
            # Roll the camera a quarter turn so the mesh's long side runs along the image's.
            right, up = up, -right
            along[0], along[1] = along[1], -along[0]
            extent[0], extent[1] = extent[1], extent[0]
        rotation = mathutils.Matrix(np.column_stack([right, up, back]).tolist()).to_quaternion()
        size = max(max(extent), 1e-6)
        aspect = width / height
        camera_data.ortho_scale = 1.1 * max(extent[0], extent[1] * aspect, size * 1e-3)
        camera_data.clip_start = size * 1e-3
        camera_data.clip_end = extent[2] + 2.0 * size
        centre = sum(
            axis * (a.max() + a.min()) / 2 for axis, a in zip((right, up), along[:2], strict=True)
        )
        camera.location = mathutils.Vector(centre + back * (along[2].max() + size))
        camera.rotation_euler = rotation.to_euler()

        sun_data = bpy.data.lights.new("VG Sun", "SUN")
        sun_data.energy = 3.0
        sun_data.angle = 0.2
        sun = bpy.data.objects.new("VG Sun", sun_data)
        made += [sun, sun_data]
        scene.collection.objects.link(sun)
        key = direction + mathutils.Vector(right) * 0.5 + mathutils.Vector(up) * 0.5
        sun.rotation_euler = (-key.normalized()).to_track_quat("-Z", "Y").to_euler()

        world = bpy.data.worlds.new("VG Sky")
        made.append(world)
        world.color = (0.8, 0.8, 0.8)
        if world.node_tree is None:
            world.use_nodes = True
        background = world.node_tree.nodes.get("Background")
        if background is not None:
            background.inputs["Color"].default_value = (0.85, 0.85, 0.85, 1.0)
            background.inputs["Strength"].default_value = 0.7
        scene.world = world

        scene.render.engine = "CYCLES"
        scene.cycles.device = "CPU"
        scene.cycles.samples = options.get("render_samples", 16)
        scene.cycles.use_denoising = False
        scene.cycles.use_adaptive_sampling = False
        scene.render.resolution_x, scene.render.resolution_y = width, height
        scene.render.resolution_percentage = 100
        scene.render.image_settings.file_format = "PNG"
        scene.view_settings.view_transform = "Standard"
        scene.render.filepath = str(Path(path).resolve())
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        with quiet_stdout():
            bpy.ops.render.render(write_still=True, scene=scene.name)
        if not Path(path).is_file():
            raise RuntimeError(f"Cycles wrote no image to {path}")
    finally:
        bpy.data.scenes.remove(scene)
        for block in made:
            with contextlib.suppress(ReferenceError, RuntimeError):
                if isinstance(block, bpy.types.Object):
                    bpy.data.objects.remove(block)
                elif isinstance(block, bpy.types.Camera):
                    bpy.data.cameras.remove(block)
                elif isinstance(block, bpy.types.Light):
                    bpy.data.lights.remove(block)
                elif isinstance(block, bpy.types.World):
                    bpy.data.worlds.remove(block)
