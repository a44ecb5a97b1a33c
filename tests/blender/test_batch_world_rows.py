"""Rows of exports of earlier versions, in world space (no Coordinates column), re-measured by
the batch on a scaled .blend object as Blender's import re-measures them."""

from __future__ import annotations

import bpy
import numpy as np
from bpy_helpers import batch, exact, mesh_object

from vg_addon.formats import csvio
from vg_addon.synthetic_meshes import wedge


def test_a_world_row_without_a_radius_takes_the_default_in_mesh_units(vg, tmp_path):
    """A default radius (``--radius``, the panel's Radius) is in mesh units; only a row's own
    world-space radius is divided by the object's scale. The batch divided the default too:
    on an object scaled by 2 it measured with radius 0.3 where Blender's import used 0.6.
    Oracle: Blender's import of the same file on the same object."""
    shape = wedge(75.0, n=30, irregular=True, seed=5)
    obj = mesh_object("Bone", shape.points, shape.triangles, location=(10.0, -2.0, 3.0),
                      rotation=(0.3, -0.2, 1.1), scale=(2.0, 2.0, 2.0))  # fmt: skip
    source = tmp_path / "study.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(source))
    matrix = np.array(obj.matrix_world, dtype=np.float64)
    centre = matrix[:3, :3] @ np.array([0.1, 0.0, 0.0]) + matrix[:3, 3]
    header = [c for c in csvio.EXPORT_COLUMNS if c != "Coordinates"]
    values = {"Mesh Name": "Bone", "SegParam": "2.0", "Patch Mode": "euclidean"}
    values.update({axis: repr(float(v)) for axis, v in zip("xyz", centre, strict=True)})
    old = tmp_path / "old.csv"
    old.write_text(",".join(header) + "\n" + ",".join(values.get(c, "") for c in header) + "\n")
    out = tmp_path / "out.csv"
    result = batch(source, "--object", "Bone", "--points", old, "--radius", "0.6", "--out", out)
    assert result.returncode == 0, result.stdout + result.stderr
    (row,) = csvio.read_measurements_csv(out)
    bpy.context.scene.vg_settings.radius = 0.6
    bpy.ops.vg.import_csv(filepath=str(old))
    item = exact(obj.vg.measurements[0])
    assert row.radius == item["radius"] == 0.6
    assert row.angle == item["angle"]


def test_a_world_row_without_a_radius_on_a_stretched_object_is_measured(vg, tmp_path):
    """A default radius needs no scaling, so a world row without one was refused on an object
    scaled (1, 1, 2) for a radius "with no single length on the mesh". Oracle: measure_xyz at
    the same mesh point with the panel's radius."""
    bpy.ops.wm.read_homefile(use_empty=True)
    shape = wedge(75.0, n=30, irregular=True, seed=5)
    obj = mesh_object("Bone", shape.points, shape.triangles, scale=(1.0, 1.0, 2.0))
    matrix = np.array(obj.matrix_world, dtype=np.float64)
    local = np.array([0.1, 0.0, 0.0])
    centre = matrix[:3, :3] @ local + matrix[:3, 3]
    header = [c for c in csvio.EXPORT_COLUMNS if c != "Coordinates"]
    values = {"Mesh Name": "Bone", "SegParam": "2.0", "Patch Mode": "euclidean"}
    values.update({axis: repr(float(v)) for axis, v in zip("xyz", centre, strict=True)})
    old = tmp_path / "old.csv"
    old.write_text(",".join(header) + "\n" + ",".join(values.get(c, "") for c in header) + "\n")
    bpy.context.scene.vg_settings.radius = 0.3
    bpy.ops.vg.import_csv(filepath=str(old))
    bpy.ops.vg.measure_xyz(location=tuple(local), space="MESH", radius=0.3)
    imported, direct = (exact(m) for m in obj.vg.measurements)
    assert imported["radius"] == 0.3 and imported["angle"] == direct["angle"]
