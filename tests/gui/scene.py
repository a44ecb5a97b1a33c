"""The test scene of the GUI lane, built the same way in the GUI Blender and in ``blender -b``.

Runs inside a real Blender (imported by ``harness_startup.py`` and ``replay_check.py``). The mesh
is an exact wedge from the installed extension's own ``synthetic_meshes``: two planar faces whose
interior angle is :data:`WEDGE_ANGLE` degrees, with the crease along the x axis through the
origin, so every measurement on the crease has an oracle independent of the code measuring it.
"""

from __future__ import annotations

import importlib
import math
import os
import sys

import bpy

# The tests' own mesh builder (tests/bpy_mesh.py), shared with the Blender lane.
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from bpy_mesh import linked_mesh_object

OBJECT_NAME = "Wedge"
WEDGE_ANGLE = 100.0
PANEL_RADIUS = 0.3
EXTENSION = "bl_ext.user_default.virtual_goniometer"


def extension():
    """The installed extension's package (installed from the zip, as a user would)."""
    return importlib.import_module(EXTENSION)


def replace_meshes_with(name: str, points, triangles):
    """Remove the scene's mesh objects and add one made of ``points`` and ``triangles``,
    active and selected; return it."""
    for obj in list(bpy.data.objects):
        if obj.type == "MESH":
            bpy.data.objects.remove(obj)
    return linked_mesh_object(name, points, triangles)


def build_wedge():
    """Replace the startup scene's objects by the wedge, active and selected; return it."""
    synthetic = importlib.import_module(EXTENSION + ".vg_addon.synthetic_meshes")
    shape = synthetic.wedge(WEDGE_ANGLE, n=40, irregular=True, seed=3)
    obj = replace_meshes_with(OBJECT_NAME, shape.points, shape.triangles)
    scene = bpy.context.scene
    scene.vg_settings.radius = PANEL_RADIUS
    bpy.context.view_layer.update()
    return obj


def frame_view(space) -> None:
    """Look down at the crease, both faces in view, the sidebar open (the Goniometer tab is
    chosen by clicking, as a user would)."""
    from mathutils import Euler, Vector

    region_3d = space.region_3d
    region_3d.view_perspective = "PERSP"
    region_3d.view_rotation = Euler((math.radians(15.0), 0.0, 0.0)).to_quaternion()
    region_3d.view_location = Vector((0.0, 0.0, -0.3))
    region_3d.view_distance = 3.5
    space.show_region_ui = True
    space.show_region_toolbar = True
    space.overlay.show_floor = False
    space.overlay.show_axis_x = False
    space.overlay.show_axis_y = False


FRAGMENT_NAME = "BoneFragment"


def build_fragment():
    """A synthetic long-bone fragment (mm), for the README's pictures; return it and its sites."""
    synthetic = importlib.import_module(EXTENSION + ".vg_addon.synthetic_meshes")
    fragment = synthetic.bone_fragment(spacing=0.4)
    obj = replace_meshes_with(FRAGMENT_NAME, fragment.points, fragment.triangles)
    scene = bpy.context.scene
    scene.unit_settings.system = "METRIC"
    scene.unit_settings.scale_length = 0.001
    scene.unit_settings.length_unit = "MILLIMETERS"
    scene.vg_settings.radius = 1.5
    bpy.context.view_layer.update()
    return obj, fragment.sites


def frame_fragment(space) -> None:
    """Look at the fragment's oblique break face from above its outer acute rim, the sidebar
    open."""
    from mathutils import Vector

    region_3d = space.region_3d
    region_3d.view_perspective = "PERSP"
    towards_viewer = Vector((0.35, 0.55, 0.85)).normalized()
    region_3d.view_rotation = towards_viewer.to_track_quat("Z", "Y")
    region_3d.view_location = Vector((5.0, 4.0, 60.0))
    region_3d.view_distance = 62.0
    space.clip_end = 10000.0
    space.show_region_ui = True
    space.show_region_toolbar = True
    space.overlay.show_floor = False
    space.overlay.show_axis_x = False
    space.overlay.show_axis_y = False
