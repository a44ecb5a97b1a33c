"""A batch run's pictures of a measured mesh: the extension's measurement map (Cycles on the
CPU, the sides in their colours, numbered labels), and the material the saved .blend shows the
sides with."""

from __future__ import annotations

from pathlib import Path

import bpy

from ..bridge import colors, measurement_map
from ..bridge.map_edges import EDGE_ENDS
from ..vg_addon.formats import files
from .outputs import refuse_input
from .stdio import quiet_stdout


def add_sides_material(obj):
    """Give a mesh without materials one that shows the side colours ("VG Sides", shared by
    the run's meshes and saved with the .blend)."""
    material = bpy.data.materials.get("VG Sides") or colors.new_sides_material(
        "VG Sides", roughness=0.6
    )
    if not obj.data.materials:
        obj.data.materials.append(material)
    return material


class NamedMap(measurement_map.MapJob):
    """The extension's measurement map with the batch's file names: ``stem`` unique within the
    run (see ``files.picture_names``) and never an input's path."""

    def __init__(self, obj, directory, *, stem: str, inputs, **settings):
        self.stem, self.inputs = stem, inputs
        super().__init__(obj, directory, **settings)

    def picture_path(self, view_name: str) -> Path:
        view = files.safe_file_name(view_name)
        path = self.directory / f"{self.stem}_map_{view}.png"
        refuse_input(path, self.inputs)
        return path

    def sheet_path(self) -> Path:
        sheet = self.directory / f"{self.stem}_map.png"
        refuse_input(sheet, self.inputs)
        return sheet


def render_map(obj, directory: Path, options: dict, stem: str, progress=None) -> Path:
    """Render the measurement map of ``obj`` into ``directory`` (the extension's own,
    ``bridge.measurement_map``: the views' PNGs and a contact sheet named after ``stem``) in
    this process; returns the sheet. A map that fails leaves none of its pictures.

    ``options["staging"]``: the hidden folder to render into (default: one made in
    ``directory``); ``progress(done, total, view)`` is called before each view.
    """
    with quiet_stdout():
        job = NamedMap(
            obj,
            directory,
            stem=stem,
            inputs=options.get("inputs", ()),
            views=options.get("render_views", "SIX"),
            size=tuple(options.get("render_size", (640, 480))),
            samples=options.get("render_samples", 16),
            staging=options.get("staging"),
            edge_ends=options.get("render_edge_ends", EDGE_ENDS),
        )
        try:
            while not job.done:
                if progress is not None:
                    progress(len(job.written), len(job.views), job.views[len(job.written)][0])
                job.render_next()
            return job.finish()
        except BaseException:
            job.abort()
            raise
        finally:
            job.close()
