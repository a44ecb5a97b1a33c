"""``vg.import_picked_points``: edges from MeshLab picked-points files (``.pp``).

Each file's active points, in order, are an edge's start, via points and end (the break-agent
study kept each break's endpoints this way); the edge is traced between them and measured with
the panel's Spacing, Radius, λ and Patch, as an Edge Profile. A file belongs to the mesh it is
named after (``NAME.pp`` or ``NAME_anything.pp``: ``formats.picked_points.mesh_for_file``);
several files are imported together, all of them or none, in one undo step.
"""

from __future__ import annotations

from pathlib import Path

import bpy
from bpy.props import BoolProperty, CollectionProperty, StringProperty
from bpy_extras.io_utils import ImportHelper

from ..bridge import edges
from ..bridge.mesh_data import (
    check_measurable,
    evaluated_geometry,
    names_of,
    other_names,
    surface_for,
)
from ..vg_addon import GoniometerError
from ..vg_addon.errors import bounded_list
from ..vg_addon.formats import picked_points
from ..vg_addon.method.given_points import check_given_points
from .common import absolute_path, poll_measurable, typed_value
from .find_edges import measure_all


def picked_edges(paths, names, *, ignore_mesh_names=False, others=()) -> list:
    """``(path, points)`` of every file of ``paths``, its points in mesh coordinates; each file
    must be named after one of ``names`` (the object's and its mesh's) unless
    ``ignore_mesh_names``, and not after one of ``others`` (the file's other objects) that fits
    it better: ``bone_12_picked_points.pp`` is ``bone_12``'s, not ``bone``'s, as in the batch.

    Raises
    ------
    GoniometerError
        Listing every file that cannot be read or names another mesh.
    """
    found, failures = [], []
    for path in paths:
        try:
            picked = picked_points.read_picked_points(path)
            owner = picked_points.mesh_for_file(path, [*names, *others])
            if not ignore_mesh_names and owner not in names:
                whose = f", but after the object '{owner}'" if owner is not None else ""
                raise GoniometerError(
                    f"'{Path(path).name}' is not named after '{names[0]}'{whose} (NAME.pp or "
                    "NAME_*.pp; tick Ignore Names to measure it here)"
                )
            found.append((path, picked_points.edge_points(picked)))
        except GoniometerError as error:
            failures.append(str(error))
    refuse_listed(failures, len(paths), "cannot be used; nothing was imported.")
    return found


def check_files_near(surface, found, radius) -> None:
    """Refuse the files of ``found`` (``(path, points)``) with points far from ``surface``
    (picked on another copy of the mesh, or in other units), every such file named at once."""
    failures = []
    for path, points in found:
        try:
            check_given_points(surface, points, radius, f"'{Path(path).name}'")
        except GoniometerError as error:
            failures.append(str(error))
    refuse_listed(failures, len(found), "lie off the mesh; nothing was recorded.")


def refuse_listed(failures, total, what) -> None:
    """Raise one GoniometerError listing ``failures`` (of ``total`` files), if any."""
    if failures:
        raise GoniometerError(
            f"{len(failures)} of {total} picked-points files {what}\n"
            + bounded_list(failures, lines=True)
        )


class VG_OT_import_picked_points(bpy.types.Operator, ImportHelper):
    """Make an Edge Profile from each MeshLab picked-points file (.pp): its points, in order,
    are the edge's start, via points and end, measured every Spacing with the panel's
    settings"""

    bl_idname = "vg.import_picked_points"
    bl_label = "Import Picked Points (.pp)"
    bl_options = {"REGISTER", "UNDO"}  # noqa: RUF012 (Blender wants a set)

    filename_ext = picked_points.SUFFIX
    filter_glob: StringProperty(default="*.pp", options={"HIDDEN"})
    files: CollectionProperty(type=bpy.types.OperatorFileListElement, options={"HIDDEN"})
    directory: StringProperty(subtype="DIR_PATH", options={"HIDDEN"})
    ignore_mesh_names: BoolProperty(
        name="Ignore Names",
        description="Measure files named after another mesh on this object too",
        default=False,
    )

    @classmethod
    def poll(cls, context):
        return poll_measurable(cls, context)

    def paths(self) -> list[str]:
        """The chosen files: every selected one in the browser, else ``filepath``."""
        names = [f.name for f in self.files if f.name]
        if names and self.directory:
            return [str(Path(bpy.path.abspath(self.directory)) / name) for name in names]
        path = absolute_path(self.filepath)
        if not path:
            raise GoniometerError("No file name given: choose the .pp file(s) to import.")
        return [path]

    def execute(self, context):
        obj = context.active_object
        settings = context.scene.vg_settings
        spacing, radius = typed_value(settings.edge_spacing), typed_value(settings.radius)
        lam, patch = typed_value(settings.seg_param), settings.patch
        try:
            check_measurable(obj)
            found = picked_edges(
                self.paths(),
                names_of(obj),
                ignore_mesh_names=self.ignore_mesh_names,
                others=other_names(obj),
            )
            geometry = evaluated_geometry(obj, context.evaluated_depsgraph_get())
            surface = surface_for(obj, geometry)
            check_files_near(surface, found, radius)
            measured = measure_all(
                surface,
                [points for _, points in found],
                (spacing, radius, lam, patch, settings.rule, settings.stability),
                [f"'{Path(path).name}'" for path, _ in found],
            )
            made = edges.record_profiles(
                obj, measured, geometry, [Path(path).name for path, _ in found]
            )
        except GoniometerError as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        self.report(
            {"INFO"},
            f"Made {len(made)} edge profile(s) on '{obj.name}' from picked points: "
            + ", ".join(f"{e.number} ({e.n_stations} stations, mean {e.mean:.1f}°)" for e in made),
        )
        return {"FINISHED"}


classes = (VG_OT_import_picked_points,)
