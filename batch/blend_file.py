"""The .blend a batch run saves: measured objects gathered, framed and written as a copy."""

from __future__ import annotations

import errno
import os
from pathlib import Path

import bpy
import numpy as np

from ..bridge import measuring, mesh_data
from ..bridge.plots import plot_image
from .measure import MeshResult
from .pictures import disk_full
from .stdio import quiet_stdout


def prepare_saved_file(objects) -> None:
    """Make the saved .blend open on the measurements: the first object active, solid views
    showing attribute colours and framing the meshes."""
    import mathutils

    objects = [o for o in objects if o is not None]
    if not objects:
        return
    view_layer = bpy.context.view_layer
    view_layer.objects.active = objects[0]
    for obj in objects:
        obj.select_set(obj == objects[0])
    corners = np.array(
        [list(obj.matrix_world @ mathutils.Vector(c)) for obj in objects for c in obj.bound_box]
    )
    centre = (corners.min(axis=0) + corners.max(axis=0)) / 2
    size = float(np.linalg.norm(corners.max(axis=0) - corners.min(axis=0))) or 1.0
    for screen in bpy.data.screens:
        for area in screen.areas:
            for space in area.spaces:
                if space.type != "VIEW_3D":
                    continue
                space.shading.color_type = "VERTEX"
                space.clip_end = max(space.clip_end, size * 20)
                space.clip_start = min(space.clip_start, size * 1e-4)
                region = space.region_3d
                if region is not None:
                    region.view_location = centre
                    region.view_distance = size * 1.2


def save_blend(path: str, objects) -> None:
    """Save the file with ``objects`` as a copy at ``path``: written beside it under another
    name, read back, and only then moved over ``path`` in one step, so a failed save (a full
    disk) keeps any earlier file and leaves no half-written one.

    Raises
    ------
    OSError, RuntimeError
        Why the file was not saved (a full disk as "No space left on device").
    """
    objects = [obj for obj in objects if obj is not None]
    prepare_saved_file(objects)
    target = Path(path).resolve()
    target.parent.mkdir(parents=True, exist_ok=True)
    temporary = target.with_name(f".{target.stem}.saving.blend")
    try:
        with quiet_stdout():
            bpy.ops.wm.save_as_mainfile(filepath=str(temporary), copy=True)
        check_saved(temporary, [obj.name for obj in objects])
        os.replace(temporary, target)
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise


def check_saved(path: Path, names) -> None:
    """Raise OSError unless ``path`` is a .blend Blender can read, holding the objects
    ``names``: Blender can report a save as done that a full disk cut short."""
    try:
        with bpy.data.libraries.load(str(path), link=False) as (source, _target):
            found = set(source.objects)
    except (OSError, RuntimeError, ValueError) as error:
        found, why = None, str(error).strip()
    else:
        why = ""
    if found is None or not set(names) <= found:
        full = disk_full(path.parent)
        raise OSError(
            errno.ENOSPC if full else errno.EIO,
            "No space left on device" if full else f"the saved file cannot be read back {why}",
        )


def plot_images(obj) -> list:
    """The images holding the profile plots of ``obj``'s edges (only the edges name them)."""
    return [image for edge in obj.vg.edges if (image := plot_image(edge)) is not None]


def forget(object_name: str) -> None:
    """Remove an object, its mesh and its edges' plots, and the cached surfaces (frees memory
    between meshes)."""
    obj = bpy.data.objects.get(object_name)
    if obj is not None:
        for image in plot_images(obj):
            bpy.data.images.remove(image)
    if obj is not None:
        mesh = obj.data
        bpy.data.objects.remove(obj)
        if mesh is not None and mesh.users == 0:
            bpy.data.meshes.remove(mesh)
    mesh_data.clear_cache()
    measuring.clear_cache()


def append_objects(results: list[MeshResult]) -> list:
    """Bring the objects the workers saved into this file, in mesh order, with their edges'
    plots (a worker's file holds its object and those images only)."""
    objects = []
    for result in sorted(results, key=lambda r: r.mesh):
        if not result.blend or not Path(result.blend).is_file():
            continue
        with bpy.data.libraries.load(result.blend, link=False) as (source, target):
            target.objects = [name for name in source.objects if name == result.object_name]
            names = list(source.images)
            target.images = list(names)  # Blender turns this list's names into the images
        # An image whose name this file already has arrives renamed: the edges follow it. Only
        # the edges name the images, so a fake user keeps them in the saved file.
        renamed = {}
        for name, image in zip(names, target.images, strict=True):
            if image is not None:
                image.use_fake_user = True
                renamed[name] = image.name
        for obj in target.objects:
            if obj is not None:
                bpy.context.scene.collection.objects.link(obj)
                for edge in obj.vg.edges:
                    edge.plot = renamed.get(edge.plot, "")
                objects.append(obj)
    return objects
