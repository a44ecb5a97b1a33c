"""A Blender mesh object made from arrays, the tests' own way: independent of the extension's
``bridge.mesh_data.new_mesh_object``, whose meshes the tests check. Used by the Blender lane
(``bpy_helpers.mesh_object``) and by the GUI lane's scene (``gui/scene.py``, inside a real
Blender); it needs only ``bpy`` and NumPy."""

from __future__ import annotations

import bpy
import numpy as np


def linked_mesh_object(name: str, points, triangles):
    """A new object ``name`` of a new mesh of ``points`` (stored as float32, as Blender does) and
    ``triangles``, linked to the scene's collection, active and selected."""
    points = np.asarray(points, dtype=np.float32)
    triangles = np.asarray(triangles, dtype=np.int32)
    mesh = bpy.data.meshes.new(name)
    mesh.vertices.add(points.shape[0])
    mesh.vertices.foreach_set("co", points.ravel())
    mesh.loops.add(triangles.size)
    mesh.loops.foreach_set("vertex_index", triangles.ravel())
    mesh.polygons.add(triangles.shape[0])
    mesh.polygons.foreach_set("loop_start", np.arange(0, triangles.size, 3, dtype=np.int32))
    mesh.update(calc_edges=True)
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    return obj
