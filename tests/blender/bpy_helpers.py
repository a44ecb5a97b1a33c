"""Small helpers for the Blender tests: meshes from NumPy, world coordinates, state snapshots,
and the batch run as a user runs it."""

from __future__ import annotations

import csv
import json
import os
import subprocess
import sys
from pathlib import Path

import bpy
import numpy as np
from bpy_mesh import linked_mesh_object

from vg_addon import Surface

COLOUR_ATTRIBUTE = "VG Sides"
BATCH_SCRIPT = Path(__file__).resolve().parents[2] / "vg_batch.py"


def batch(*args, cwd=None, env=None, timeout=600) -> subprocess.CompletedProcess:
    """Run ``python vg_batch.py ARGS`` with this test's Python (the one with bpy), as a user
    would; arguments may be paths, numbers or bytes (file names that are not UTF-8)."""
    return subprocess.run(
        [sys.executable, str(BATCH_SCRIPT),
         *(os.fsdecode(a) if isinstance(a, bytes) else str(a) for a in args)],
        capture_output=True,
        text=True,
        errors="replace",
        timeout=timeout,
        cwd=cwd,
        env=None if env is None else {**os.environ, **env},
        check=False,
    )  # fmt: skip


def edited_csv(source, target, edit_row=None, drop=()) -> Path:
    """Copy the CSV file ``source`` to ``target`` without the columns ``drop``, each row (a dict
    of its cells) first passed to ``edit_row`` if given; as a file of another version or tool
    would hold it."""
    with open(source, newline="", encoding="utf-8") as handle:
        table = list(csv.DictReader(handle))
    for row in table:
        if edit_row is not None:
            edit_row(row)
        for column in drop:
            del row[column]
    with open(target, "w", newline="", encoding="utf-8") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(table[0]))
        writer.writeheader()
        writer.writerows(table)
    return Path(target)


def linked_object(library, name):
    """The object ``name`` of the .blend ``library``, linked (not appended) into a fresh empty
    file's scene and made active: data this file cannot change."""
    bpy.ops.wm.read_homefile(use_empty=True)
    with bpy.data.libraries.load(str(library), link=True) as (_source, target):
        target.objects = [name]
    obj = target.objects[0]
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    return obj


def mesh_object(
    name, points, triangles, *, location=(0, 0, 0), rotation=(0, 0, 0), scale=(1, 1, 1)
):
    """A new mesh object in the scene, made active and selected, with the given transform."""
    obj = linked_mesh_object(name, points, triangles)
    obj.location, obj.rotation_euler, obj.scale = location, rotation, scale
    bpy.context.view_layer.update()
    return obj


def local_points(obj) -> np.ndarray:
    """The object's own (unevaluated) vertex coordinates, float32 as Blender stores them."""
    co = np.empty(len(obj.data.vertices) * 3, dtype=np.float32)
    obj.data.vertices.foreach_get("co", co)
    return co.reshape(-1, 3)


def evaluated_surface(obj) -> Surface:
    """A core Surface of the object's evaluated mesh (shape keys and modifiers applied), read
    here: an oracle for what the extension measures on."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    obj_eval = obj.evaluated_get(depsgraph)
    mesh = obj_eval.to_mesh()
    co = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", co)
    mesh.calc_loop_triangles()
    tris = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", tris)
    obj_eval.to_mesh_clear()
    return Surface(co.reshape(-1, 3).astype(np.float64), tris.reshape(-1, 3))


def world(points, obj) -> np.ndarray:
    """``points`` (object space) in world space, float64, by the object's matrix_world."""
    matrix = np.array(obj.matrix_world, dtype=np.float64)
    return np.asarray(points, dtype=np.float64) @ matrix[:3, :3].T + matrix[:3, 3]


def exact(item) -> dict:
    """The exact float64 numbers recorded for a measurement item."""
    return json.loads(item.exact)


def colours(obj) -> np.ndarray | None:
    """The "VG Sides" colours per vertex (float32 RGBA), or None."""
    attribute = obj.data.color_attributes.get(COLOUR_ATTRIBUTE)
    if attribute is None:
        return None
    rgba = np.empty(len(attribute.data) * 4, dtype=np.float32)
    attribute.data.foreach_get("color", rgba)
    return rgba.reshape(-1, 4)


def snapshot(obj) -> dict:
    """Everything the extension may change on an object: to check that nothing changed."""
    data = obj.vg
    items = [
        {
            key: getattr(item, key)
            for key in (
                "number",
                "break_number",
                "exact",
                "patch",
                "n_vertices",
                "n_plus",
                "n_minus",
                "date",
                "note",
                "colors",
                "fingerprint",
                "stale",
            )
        }
        for item in data.measurements
    ]
    rgba = colours(obj)
    return {
        "items": items,
        "active_index": data.active_index,
        "break_number": data.break_number,
        "next_number": data.next_number,
        "attributes": sorted(a.name for a in obj.data.attributes),
        "active_colour": obj.data.color_attributes.active_color_name,
        "colours": None if rgba is None else rgba.tobytes(),
    }


# The colours as documented, not as the extension computes them: the Okabe-Ito palette as
# published (Okabe & Ito 2008, "Color Universal Design"), the break pairs in the rotation
# docs/USER_GUIDE.md lists, and a mid grey for everything else, all 8-bit sRGB.
OKABE_ITO_HEX = {
    "orange": "#E69F00",
    "sky blue": "#56B4E9",
    "bluish green": "#009E73",
    "yellow": "#F0E442",
    "blue": "#0072B2",
    "vermillion": "#D55E00",
    "reddish purple": "#CC79A7",
}
BREAK_PAIRS = [
    ("yellow", "blue"),
    ("vermillion", "sky blue"),
    ("reddish purple", "bluish green"),
    ("orange", "blue"),
]
GREY_HEX = "#808080"


def linear_rgba(hex_colour: str) -> np.ndarray:
    """Scene-linear RGBA of an sRGB hex colour, by the sRGB transfer function (IEC 61966-2-1)."""
    srgb = np.array([int(hex_colour[i : i + 2], 16) for i in (1, 3, 5)]) / 255.0
    linear = np.where(srgb <= 0.04045, srgb / 12.92, ((srgb + 0.055) / 1.055) ** 2.4)
    return np.append(linear, 1.0)


def expected_colours(n, sides) -> np.ndarray:
    """Colours the extension should paint: grey, then each (indices, labels, break) in order,
    "+" side first, from the documented palette (never from the extension's own code)."""
    rgba = np.tile(linear_rgba(GREY_HEX), (n, 1))
    for indices, labels, break_number in sides:
        plus, minus = BREAK_PAIRS[(break_number - 1) % len(BREAK_PAIRS)]
        rgba[indices[labels]] = linear_rgba(OKABE_ITO_HEX[plus])
        rgba[indices[~labels]] = linear_rgba(OKABE_ITO_HEX[minus])
    return rgba.astype(np.float32)


def wedge_object(angle, name="Wedge", *, n=40, irregular=True, **transform):
    """A synthetic wedge (two planes meeting at ``angle`` degrees along an edge through the
    origin) as a mesh object; the true angle is in ``obj["true_angle"]``."""
    from vg_addon.synthetic_meshes import wedge

    shape = wedge(angle, n=n, irregular=irregular)
    obj = mesh_object(name, shape.points, shape.triangles, **transform)
    obj["true_angle"] = float(shape.angle)
    return obj


def half_annulus_with_edge_vertices():
    """The project's half annulus (``vg_addon.reference_shapes``; the shape of the reference file
    ``HalfAnnulus.ply``) in float32 coordinates, as a scanner writes them and Blender keeps them,
    and three vertices on its edges (top/outer, cut/outer, bottom/inner), where a 0.3 patch holds
    an edge."""
    from vg_addon.reference_shapes import BOTTOM, CUT, INNER, OUTER, TOP, half_annulus

    mesh = half_annulus()
    points = mesh.points.astype(np.float32).astype(np.float64)
    picks = []
    for pair in ((TOP, OUTER), (CUT, OUTER), (BOTTOM, INNER)):
        on_edge = np.flatnonzero(np.isin(mesh.labels, pair))
        corner = mesh.labels[mesh.triangles]
        touching = np.isin(corner, pair[0]).any(axis=1) & np.isin(corner, pair[1]).any(axis=1)
        on_edge = np.intersect1d(on_edge, mesh.triangles[touching])
        middle = np.median(points[on_edge], axis=0)
        picks.append(int(on_edge[np.argmin(np.linalg.norm(points[on_edge] - middle, axis=1))]))
    return points, mesh.triangles, picks


def arguments(**given):
    """Parsed ``vg_batch.py`` options as the output checks read them: none given but ``given``."""
    import argparse

    values = {"inputs": [], "points": None, "out": None, "save_blend": None, "render": None,
              "sweep": None, "edge": [], "edges_csv": None}  # fmt: skip
    return argparse.Namespace(**(values | given))


def outcome_of_check(outputs, args) -> str:
    """``"accepted"``, or ``"refused: <message>"``, from the batch's output checks on ``args``."""
    try:
        outputs.check_outputs(args)
    except outputs.UsageError as error:
        return f"refused: {error}"
    return "accepted"
