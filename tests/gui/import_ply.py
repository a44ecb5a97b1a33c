"""Make a .blend with Blender's own PLY importer (run by ``blender -b`` in a Blender root).

    blender -b --python import_ply.py -- OUT.blend MESH.ply...

Each PLY becomes an object named after its file (no axis conversion), in a new empty file.
"""

from __future__ import annotations

import sys
from pathlib import Path

import bpy

out, *plys = sys.argv[sys.argv.index("--") + 1 :]
bpy.ops.wm.read_factory_settings(use_empty=True)
for ply in plys:
    bpy.ops.wm.ply_import(filepath=ply, forward_axis="Y", up_axis="Z")
    bpy.context.selected_objects[0].name = Path(ply).stem
bpy.ops.wm.save_as_mainfile(filepath=out)
