"""The measurement map: the object rendered from chosen views with its coloured sides and a
numbered label beside each current measurement, one PNG per view and one contact sheet.

It is what a user prints and keeps beside the CSV (the paper's analysts made one from
screenshots). The operator ``vg.render_map`` and the batch's ``--render`` both make it here.

Rendering is Cycles on the CPU: the headless ``bpy`` module has no GPU context, and Workbench
and EEVEE need one (Workbench there renders garbage on a machine without a GPU). The scene is a
throwaway one: a copy of the evaluated mesh (so the user's materials are never touched) with a
material showing the "VG Sides" colours, orthographic cameras, a sun and a grey sky, and the
labels as text objects with their own flat materials, on a plane in front of the mesh so the
mesh never hides them. A label is only drawn in a view that sees its centre (a ray from the
camera reaches it), and labels too close to a more important one on the picture are left out.

Every measurement appears in at least one view: the views are planned before anything is
rendered, and a measurement that none of the chosen views shows gets a view of its own, looking
onto its surface along its mean normal (or tilted from it, or from the other side, until a ray
reaches its centre). One that no direction sees (inside a closed cavity) is listed on a last
picture, "not shown", which the contact sheet includes. The stations of an edge profile between
its first and last are the exception: they are labelled where a view has room, and get no view
of their own (their numbers run in order along the edge's line); so are all the stations of the
edges after the first ``edge_ends`` (``map_edges.stations_without_views``, ``EDGE_ENDS``).
The labels are set in DejaVu Sans Mono, which Blender ships: its "1" has a flag and a foot, so
"11" never reads "II".
Each edge profile's traced path is drawn as a thin magenta line (``map_edges``). Everything made
for the render is removed afterwards, whatever happens.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import tempfile
from pathlib import Path

import bpy
import numpy as np
from mathutils import Matrix, Vector

from ..vg_addon import GoniometerError
from ..vg_addon.formats.files import kept_picture_name, safe_file_name
from ..vg_addon.formats.png import write_png
from ..vg_addon.workflow.labels import SIX_VIEWS, flake_views, looks_at, place_labels, view_up
from .colors import ATTRIBUTE_NAME, has_attribute, new_sides_material
from .label_data import labels_of
from .map_edges import EDGE_ENDS, LINE_COLOUR, add_edge_lines, stations_without_views
from .mesh_data import check_evaluated, read_positions, world_points

MAP_VIEWS = ("SIX", "FLAKE")
TEXT_FRACTION = 0.035  # label height, as a fraction of the picture's width
GLYPH_EM = 0.6  # the width of a label's character (at most, about), in label heights
OUTLINE = 0.07  # the black ring around label text, in label heights
MARGIN = 1.25  # the frame around the object, room for labels at its edges
FONT_FILE = "DejaVuSansMono.woff2"  # in Blender's datafiles/fonts: a "1" unlike "I"
NOT_SHOWN = "not shown"
CLOSE_UPS = (
    4.0,
    12.0,
)  # how much nearer a close-up looks, for labels crowded out of a view  # the name of the picture listing measurements no view can show


def map_stem(obj) -> str:
    """The file-name stem of ``obj``'s map, unique among the file's objects: see
    :func:`~vg_addon.formats.files.kept_picture_name`. Recorded at the map's end
    (``obj.vg.map_stem``, saved in the .blend)."""
    records = {
        other.name: getattr(getattr(other, "vg", None), "map_stem", "")
        for other in bpy.data.objects
    }
    return kept_picture_name(obj.name, records)


def view_list(obj, views: str, depsgraph) -> tuple:
    """The ``(name, look, up)`` views of a map of ``obj``: ``"SIX"`` or ``"FLAKE"``."""
    if views == "SIX":
        return SIX_VIEWS
    if views == "FLAKE":
        mesh = obj.evaluated_get(depsgraph).to_mesh()
        try:
            local = read_positions(mesh)
        finally:
            obj.evaluated_get(depsgraph).to_mesh_clear()
        return flake_views(world_points(local, np.array(obj.matrix_world, dtype=np.float64)))
    raise GoniometerError(f"Unknown map views {views!r}: use one of {', '.join(MAP_VIEWS)}.")


class MapJob:
    """One measurement map being made, a view at a time (so an operator can show progress and
    stop between views).

    Use :meth:`render_next` until :attr:`done`, then :meth:`finish`; call :meth:`close` on
    every way out (it removes the throwaway scene), and :meth:`abort` to remove the pictures
    written so far when the map is not completed.

    The views are rendered into a hidden folder inside ``directory`` and moved into place, each
    replacing its file atomically, only when :meth:`finish` has made the contact sheet: a map
    cancelled or failed half-way leaves an earlier map in the same folder as it was.
    ``staging``: that hidden folder, made by the caller (it must be inside ``directory``, on the
    same file system); by default one is made.
    """

    def __init__(
        self,
        obj,
        directory,
        *,
        views="SIX",
        size=(800, 600),
        samples=16,
        staging=None,
        edge_ends=EDGE_ENDS,
    ):
        if obj is None or obj.type != "MESH":
            raise GoniometerError("Select the measured mesh object to make its map.")
        if len(obj.vg.measurements) and not has_attribute(obj.data):
            # The map copies the mesh with its colours: without them its sides would be blank.
            raise GoniometerError(
                f"'{obj.name}' has lost its '{ATTRIBUTE_NAME}' colour attribute, so the "
                "map would show no sides: press Update Colours, then make the map."
            )
        if isinstance(edge_ends, bool) or not isinstance(edge_ends, int) or edge_ends < 0:
            raise GoniometerError(
                f"The edges whose ends get views of their own must be a whole number, 0 or more "
                f"(got {edge_ends!r})."
            )
        width, height = (int(v) for v in size)
        if width < 16 or height < 16 or samples < 1:
            raise GoniometerError(
                f"A map needs pictures of at least 16 x 16 pixels and 1 sample (got "
                f"{width} x {height}, {samples})."
            )
        self.obj = obj
        self._stem = map_stem(obj)  # fixed for the job: a rename meanwhile splits no map
        self.directory = Path(directory)
        self.size = (width, height)
        self.samples = int(samples)
        self.depsgraph = bpy.context.evaluated_depsgraph_get()
        check_evaluated(obj, self.depsgraph, "to render")
        self.views = list(view_list(obj, views, self.depsgraph))
        self.labels = labels_of(obj)
        unviewed = stations_without_views(obj, edge_ends)
        # Labels that get no view of their own when no chosen view draws them (see map_edges).
        self._unviewed = {i for i, label in enumerate(self.labels) if label.number in unviewed}
        self.placements: list[list] = []  # per view: (label index, side) of each label drawn
        self.not_shown: list = []  # labels no view can show (listed on the last picture)
        self.written: list[Path] = []
        self.sheet: Path | None = None
        self._made: list = []
        self._scene = None
        self._label_objects: list = []
        self.directory.mkdir(parents=True, exist_ok=True)
        self._staging: Path | None = Path(
            staging or tempfile.mkdtemp(prefix=".vg-map-", dir=self.directory)
        )
        try:
            self._build_scene()
            self._plan()
        except BaseException:
            self.close()
            raise

    @property
    def done(self) -> bool:
        """Whether every view has been rendered."""
        return len(self.written) == len(self.views)

    def picture_path(self, view_name: str) -> Path:
        """Where the picture of a view ends up."""
        return self.directory / f"{self._stem}_map_{safe_file_name(view_name)}.png"

    def sheet_path(self) -> Path:
        """Where the contact sheet ends up."""
        return self.directory / f"{self._stem}_map.png"

    def _staged(self, path: Path) -> Path:
        return self._staging / path.name

    # -- the throwaway scene ------------------------------------------------------------------

    def _keep(self, block):
        self._made.append(block)
        return block

    def _build_scene(self) -> None:
        scene = self._scene = self._keep(bpy.data.scenes.new("VG Map"))
        mesh = self._keep(
            bpy.data.meshes.new_from_object(
                self.obj.evaluated_get(self.depsgraph),
                preserve_all_data_layers=True,
                depsgraph=self.depsgraph,
            )
        )
        mesh.materials.clear()
        mesh.materials.append(self._sides_material())
        copy = self._keep(bpy.data.objects.new("VG Map mesh", mesh))
        copy.matrix_world = self.obj.matrix_world
        scene.collection.objects.link(copy)
        corners = np.array([list(self.obj.matrix_world @ Vector(c)) for c in self.obj.bound_box])
        self._corners = corners
        self._size = float(np.linalg.norm(corners.max(axis=0) - corners.min(axis=0))) or 1.0

        camera_data = self._keep(bpy.data.cameras.new("VG Map camera"))
        camera_data.type = "ORTHO"
        camera_data.sensor_fit = "HORIZONTAL"  # the scale spans the width, as _frame assumes
        self._camera = self._keep(bpy.data.objects.new("VG Map camera", camera_data))
        scene.collection.objects.link(self._camera)
        scene.camera = self._camera

        sun_data = self._keep(bpy.data.lights.new("VG Map sun", "SUN"))
        sun_data.energy = 2.5
        sun_data.angle = 0.3
        self._sun = self._keep(bpy.data.objects.new("VG Map sun", sun_data))
        scene.collection.objects.link(self._sun)

        world = self._keep(bpy.data.worlds.new("VG Map sky"))
        if world.node_tree is None:
            world.use_nodes = True
        background = world.node_tree.nodes.get("Background")
        if background is not None:
            background.inputs["Color"].default_value = (0.9, 0.9, 0.9, 1.0)
            background.inputs["Strength"].default_value = 0.9
        scene.world = world

        scene.render.engine = "CYCLES"
        scene.cycles.device = "CPU"
        scene.cycles.samples = self.samples
        scene.cycles.use_denoising = False
        scene.cycles.use_adaptive_sampling = False
        scene.render.resolution_x, scene.render.resolution_y = self.size
        scene.render.resolution_percentage = 100
        scene.render.image_settings.file_format = "PNG"
        scene.render.film_transparent = False
        scene.view_settings.view_transform = "Standard"
        self._white = self._flat_material("VG Map label", (1.0, 1.0, 1.0, 1.0))
        self._black = self._flat_material("VG Map outline", (0.0, 0.0, 0.0, 1.0))
        line = self._flat_material("VG Map edge", LINE_COLOUR)
        add_edge_lines(scene, self.obj, line, self._size, self._keep)
        self._copy = copy
        self._font = self._label_font()

    def _label_font(self):
        """Blender's DejaVu Sans Mono, or None (Blender's built-in font) if it is not there."""
        folder = bpy.utils.system_resource("DATAFILES", path="fonts")
        path = os.path.join(folder, FONT_FILE) if folder else ""
        if not os.path.isfile(path):
            return None
        try:
            return self._keep(bpy.data.fonts.load(path, check_existing=False))
        except (RuntimeError, OSError):
            return None

    def _sides_material(self):
        return self._keep(new_sides_material("VG Map sides", roughness=0.7))

    def _flat_material(self, name, rgba):
        """A material that shows ``rgba`` whatever the light (an emission)."""
        material = self._keep(bpy.data.materials.new(name))
        if material.node_tree is None:
            material.use_nodes = True
        nodes = material.node_tree.nodes
        nodes.clear()
        emission = nodes.new("ShaderNodeEmission")
        emission.inputs["Color"].default_value = rgba
        emission.inputs["Strength"].default_value = 1.0
        output = nodes.new("ShaderNodeOutputMaterial")
        material.node_tree.links.new(emission.outputs["Emission"], output.inputs["Surface"])
        return material

    # -- one view -------------------------------------------------------------------------------

    def _frame(self, look, up, zoom=None):
        """Camera axes, placement and ortho scale that frame the object seen along ``look``;
        ``zoom`` ``(point, factor)``: a close-up, centred on ``point``, ``factor`` times
        nearer."""
        back = -np.asarray(look, dtype=np.float64)
        up = np.asarray(up, dtype=np.float64)
        right = np.cross(up, back)
        along = [self._corners @ axis for axis in (right, up, back)]
        extent = [float(a.max() - a.min()) for a in along]
        width, height = self.size
        aspect = width / height
        scale = MARGIN * max(extent[0], extent[1] * aspect, self._size * 1e-3)
        centre = (
            right * (along[0].max() + along[0].min()) / 2
            + up * (along[1].max() + along[1].min()) / 2
        )
        front = float(along[2].max())
        if zoom is not None:
            point, factor = zoom
            centre = right * (point @ right) + up * (point @ up)
            scale /= factor
        return right, up, back, centre, front, scale

    # -- which views show which labels ------------------------------------------------------

    def _layout(self, look, up, focus=None, zoom=None) -> list:
        """The labels a view looking along ``look`` draws: ``(label index, side)`` of each one
        whose centre it sees, on the picture, and that has room there; ``focus`` (a label
        index) first, then the selected measurement, then all but the edge stations that get
        no view of their own, then the newest."""
        right, up, back, centre, _front, scale = self._frame(look, up, zoom)
        width, height = self.size
        pixel = scale / width
        text_px = TEXT_FRACTION * width
        anchors, shown = [], []
        for i, label in enumerate(self.labels):
            x = ((label.position - centre) @ right) / pixel
            y = ((label.position - centre) @ up) / pixel
            inside = abs(x) < width / 2 - text_px and abs(y) < height / 2 - text_px
            if inside and self._visible(label, -back):
                anchors.append([x, y])
                shown.append(i)
        if not shown:
            return []
        total = len(shown)
        # Focus, then the selected measurement, then any but the edge stations that get no
        # view of their own, then the newest.
        priority = [
            4 * total * (i == focus)
            + 2 * total * self.labels[i].active
            + total * (i not in self._unviewed)
            + rank
            for rank, i in enumerate(shown)
        ]
        widths = [GLYPH_EM * len(self.labels[i].text) * text_px for i in shown]
        # Never cut by the picture's edge: a text that would cross it goes on the other side.
        edge = width / 2 - 0.3 * text_px
        placed = place_labels(
            anchors, widths, text_px, priority, gap=0.45 * text_px, bounds=(-edge, edge)
        )
        return [(shown[index], side) for index, side in placed]

    def _plan(self) -> None:
        """Lay out the chosen views and add views until every measurement is drawn in one: a
        close-up where a view sees it but its label had no room (neighbours crowd it), else a
        view looking onto its surface (see ``looks_at``); a last picture lists those that no
        direction shows."""
        self.placements = [self._layout(look, up) for _name, look, up in self.views]
        self._zooms: dict[int, tuple] = {}
        drawn = {index for placed in self.placements for index, _side in placed}
        for index, label in enumerate(self.labels):
            if index in drawn or index in self._unviewed:
                continue  # an edge station that gets no view of its own (map_edges)
            if not self._add_view_for(index, label, drawn):
                self.not_shown.append(label)
        if self.not_shown:
            self.views.append((NOT_SHOWN, None, None))
            self.placements.append([])

    def _add_view_for(self, index, label, drawn) -> bool:
        """Add a view that draws ``label``; whether one was found. ``drawn`` grows by every
        label the new view draws."""
        # The chosen view that looks most squarely onto its surface, for a close-up.
        seen_in = sorted(
            (
                (look, up)
                for _n, look, up in self.views[:6]
                if look is not None and self._visible(label, look)
            ),
            key=lambda view: float(np.asarray(view[0]) @ label.outward),
        )
        candidates = [
            (f"close-up {label.number}", look, up, (label.position, factor))
            for look, up in seen_in[:1]
            for factor in CLOSE_UPS
        ]
        candidates += [
            (f"measurement {label.number}", tuple(look), view_up(look), None)
            for look in looks_at(label.outward)
        ]
        for name, look, up, zoom in candidates:
            if zoom is None and not self._visible(label, look):
                continue
            placed = self._layout(look, up, focus=index, zoom=zoom)
            if any(i == index for i, _side in placed):
                if zoom is not None:
                    self._zooms[len(self.views)] = zoom
                self.views.append((name, tuple(look), up))
                self.placements.append(placed)
                drawn.update(i for i, _side in placed)
                return True
        return False

    # -- rendering ------------------------------------------------------------------------------

    def render_next(self) -> Path:
        """Render the next view into its PNG; returns where the picture is now (the job's hidden
        folder, until :meth:`finish` moves it to :meth:`picture_path`)."""
        if self.done:
            raise GoniometerError("Every view of this map is rendered already.")
        step = len(self.written)
        name, look, up = self.views[step]
        self._copy.hide_render = look is None
        if look is None:
            look, up = SIX_VIEWS[0][1:]
        right, up, back, centre, front, scale = self._frame(look, up, self._zooms.get(step))
        rotation = Matrix(np.column_stack([right, up, back]).tolist()).to_4x4()
        camera = self._camera
        camera.matrix_world = Matrix.Translation(Vector(centre + back * (front + self._size))) @ (
            rotation
        )
        camera.data.ortho_scale = scale
        camera.data.clip_start = self._size * 1e-3
        camera.data.clip_end = 3.0 * self._size
        key = -np.asarray(look) + 0.5 * right + 0.6 * up
        self._sun.rotation_euler = Vector(-key).to_track_quat("-Z", "Y").to_euler()
        if name == NOT_SHOWN and self.views[step][1] is None:
            self._list_not_shown(right, up, back, centre, front, scale, rotation)
        else:
            self._place_labels(
                name, self.placements[step], right, up, back, centre, front, scale, rotation
            )
        path = self.picture_path(name)
        staged = self._staged(path)
        scene = self._scene
        scene.render.filepath = str(staged.resolve())
        bpy.ops.render.render(write_still=True, scene=scene.name)
        if not staged.is_file():
            raise GoniometerError(f"Cycles wrote no picture to {staged}.")
        self.written.append(path)
        return staged

    def _visible(self, label, look) -> bool:
        """Whether the camera looking along ``look`` sees ``label``'s centre: a ray along
        ``look`` through the centre, or through one of four points a quarter radius around it
        (a centre on a break edge is often right on the outline), first meets the object
        within half a radius of the centre."""
        obj_eval = self.obj.evaluated_get(self.depsgraph)
        to_local = np.linalg.inv(np.array(self.obj.matrix_world, dtype=np.float64))
        look = np.asarray(look, dtype=np.float64)
        side = np.cross(look, [0.0, 0.0, 1.0] if abs(look[2]) < 0.9 else [1.0, 0.0, 0.0])
        side /= np.linalg.norm(side)
        other = np.cross(look, side)
        step = 0.25 * label.radius
        local_direction = Vector(to_local[:3, :3] @ look)
        reach = max(0.5 * label.radius, self._size * 1e-3)
        for offset in (0.0 * side, step * side, -step * side, step * other, -step * other):
            origin = label.position + offset - look * 2.0 * self._size
            local_origin = Vector(to_local[:3, :3] @ origin + to_local[:3, 3])
            hit, location, _normal, _face = obj_eval.ray_cast(local_origin, local_direction)
            if not hit:
                continue
            world_hit = np.array(self.obj.matrix_world @ location, dtype=np.float64)
            if float(np.linalg.norm(world_hit - label.position)) <= reach:
                return True
        return False

    def _clear_labels(self) -> None:
        for block in self._label_objects:
            self._remove(block)
        self._label_objects = []

    def _place_labels(
        self, view_name, placed, right, up, back, centre, front, scale, rotation
    ) -> None:
        self._clear_labels()
        width = self.size[0]
        pixel = scale / width  # world size of one pixel
        text_height = TEXT_FRACTION * width * pixel
        plane = front + 0.05 * self._size  # in front of the mesh, behind the camera
        gap = 0.45 * TEXT_FRACTION * width
        for index, side in placed:
            label = self.labels[index]
            on_plane = label.position + back * (plane - label.position @ back)
            self._marker(on_plane, rotation, 0.22 * text_height)
            at = on_plane + side * right * gap * pixel
            self._text(label.text, at, rotation, text_height, "LEFT" if side > 0 else "RIGHT")
        self._caption(f"{self.obj.name} · {view_name}", centre, back * plane, scale, rotation)

    def _caption(self, text, centre, plane, scale, rotation, line=0) -> None:
        """A line of text in the top-left corner of the picture (``line`` 0 the top one)."""
        right, up = np.array(rotation.col[0][:3]), np.array(rotation.col[1][:3])
        width, height = self.size
        text_height = TEXT_FRACTION * scale
        corner = (
            centre
            + plane
            - right * (scale / 2 - text_height)
            + up * (scale * height / width / 2 - (1.2 + 1.5 * line) * text_height)
        )
        self._text(text, corner, rotation, text_height)

    def _list_not_shown(self, right, up, back, centre, front, scale, rotation) -> None:
        """The picture of the measurements no view shows: their numbers, a line each few."""
        self._clear_labels()
        plane = back * (front + 0.05 * self._size)
        room = max(8, int(self.size[0] / (GLYPH_EM * TEXT_FRACTION * self.size[0])) - 3)
        lines = [f"{self.obj.name}: not shown in any view", "(no line of sight to the centre):"]
        line = ""
        for label in self.not_shown:
            word = f"#{label.number}"
            if line and len(line) + 2 + len(word) > room:
                lines.append(line + ",")
                line = ""
            line = f"{line}, {word}" if line else word
        lines.append(line)
        for number, text in enumerate(lines):
            self._caption(text, centre, plane, scale, rotation, line=number)

    def _text(self, text, at, rotation, height, align="LEFT") -> None:
        """White text ringed in black, its left (or right) middle at ``at``, facing the camera:
        eight black copies shifted around a white one, so it reads on light and dark alike."""
        right, up, back = (np.array(rotation.col[i][:3]) for i in range(3))
        shift = OUTLINE * height
        copies = [
            (self._black, right * dx * shift + up * dy * shift - back * 0.02 * height)
            for dx, dy in ((-1, -1), (-1, 0), (-1, 1), (0, -1), (0, 1), (1, -1), (1, 0), (1, 1))
        ]
        curve = self._keep(bpy.data.curves.new("VG Map label", "FONT"))
        curve.body = text
        curve.size = height
        curve.align_x = align
        curve.align_y = "CENTER"
        if self._font is not None:
            curve.font = self._font
        curve.materials.append(self._black)
        white = self._keep(curve.copy())
        white.materials[0] = self._white
        for data, offset in [*((curve, o) for _, o in copies), (white, np.zeros(3))]:
            label = self._keep(bpy.data.objects.new("VG Map label", data))
            label.matrix_world = Matrix.Translation(Vector(np.asarray(at) + offset)) @ rotation
            self._scene.collection.objects.link(label)
            self._label_objects.append(label)
        self._label_objects.extend([curve, white])

    def _marker(self, at, rotation, radius) -> None:
        """A white dot ringed in black at a measurement's centre."""
        angles = np.linspace(0.0, 2.0 * np.pi, 25)[:-1]
        for material, scale, depth in ((self._black, 1.6, -0.002), (self._white, 1.0, 0.0)):
            ring = np.column_stack([np.cos(angles), np.sin(angles), np.zeros_like(angles)])
            verts = [(0.0, 0.0, 0.0), *(radius * scale * ring).tolist()]
            faces = [(0, 1 + i, 1 + (i + 1) % len(angles)) for i in range(len(angles))]
            mesh = self._keep(bpy.data.meshes.new("VG Map marker"))
            mesh.from_pydata(verts, [], faces)
            mesh.materials.append(material)
            dot = self._keep(bpy.data.objects.new("VG Map marker", mesh))
            back = np.array(rotation.col[2][:3])
            dot.matrix_world = (
                Matrix.Translation(Vector(np.asarray(at) + back * depth * radius * 10)) @ rotation
            )
            self._scene.collection.objects.link(dot)
            self._label_objects.extend([dot, mesh])

    # -- the end ----------------------------------------------------------------------------------

    def finish(self) -> Path:
        """Write the contact sheet of every view and move the pictures into place; returns the
        sheet's path."""
        if not self.done:
            raise GoniometerError("The map is not complete: render every view first.")
        sheet = self.sheet_path()
        columns = 3 if len(self.written) > 2 else 2
        write_contact_sheet(
            [self._staged(p) for p in self.written], self._staged(sheet), columns=columns
        )
        for path in [*self.written, sheet]:
            os.replace(self._staged(path), path)
        self.sheet = sheet
        self._remove_staging()
        for path in self._outdated_pictures():
            with contextlib.suppress(OSError):
                path.unlink()
        with contextlib.suppress(AttributeError, TypeError, RuntimeError):  # linked: none kept
            self.obj.vg.map_pictures = json.dumps(
                [str(path.resolve()) for path in [*self.written, sheet]]
            )
            self.obj.vg.map_stem = self._stem
        return sheet

    def _outdated_pictures(self) -> list:
        """Pictures this object's earlier map wrote into this folder (its record,
        ``obj.vg.map_pictures``) under this map's file name that this map does not make again:
        a close-up of a measurement since deleted or now seen in a view, or the "not shown"
        list. Left there, they would read as part of this map. Nothing else is touched: not
        files the record does not name, nor those of a record made under another file name (a
        copy of an object carries its original's record; a renamed object's earlier map)."""
        if self.obj.vg.map_stem != self._stem:
            return []
        try:
            earlier = [Path(p) for p in json.loads(self.obj.vg.map_pictures or "[]")]
        except (ValueError, TypeError):
            earlier = []
        written = {path.resolve() for path in [*self.written, self.sheet]}
        folder = self.directory.resolve()
        return [
            path
            for path in earlier
            if path.parent == folder
            and path.name.startswith(f"{self._stem}_map")
            and path not in written
            and path.is_file()
        ]

    def abort(self) -> None:
        """Remove the pictures of a map not finished (a cancelled map leaves nothing half-done,
        and an earlier map in the folder as it was); a finished map stays."""
        self._remove_staging()
        if self.sheet is None:
            self.written = []

    def _remove_staging(self) -> None:
        staging, self._staging = self._staging, None
        if staging is not None:
            shutil.rmtree(staging, ignore_errors=True)

    def _remove(self, block) -> None:
        with contextlib.suppress(ReferenceError, RuntimeError):
            collection = {
                bpy.types.Object: bpy.data.objects,
                bpy.types.Mesh: bpy.data.meshes,
                bpy.types.TextCurve: bpy.data.curves,
                bpy.types.Curve: bpy.data.curves,
                bpy.types.Camera: bpy.data.cameras,
                bpy.types.SunLight: bpy.data.lights,
                bpy.types.World: bpy.data.worlds,
                bpy.types.Material: bpy.data.materials,
                bpy.types.Scene: bpy.data.scenes,
                bpy.types.VectorFont: bpy.data.fonts,
            }.get(type(block))
            if collection is not None:
                collection.remove(block)

    def close(self) -> None:
        """Remove everything made for the render (safe to call more than once)."""
        if self.sheet is None:
            self._remove_staging()
        made, self._made, self._label_objects = self._made, [], []
        # Objects first, then their data, the scene last but one: each removal is allowed.
        order = sorted(
            made,
            key=lambda b: (
                0 if isinstance(b, bpy.types.Object) else 2 if isinstance(b, bpy.types.Scene) else 1
            ),
        )
        for block in order:
            self._remove(block)


def write_contact_sheet(paths, out: Path, *, columns: int = 3) -> Path:
    """Tile the PNGs ``paths`` (all the same size) into one PNG, ``columns`` wide, row by row
    from the top left."""
    if not paths:
        raise GoniometerError("The map has no pictures to tile.")
    # Eight bits a channel, as the views are, and one view loaded at a time: the memory is the
    # sheet's bytes and one view's, where Blender's float pixels took 17 MB a view.
    sheet = None
    for index, path in enumerate(paths):
        image = bpy.data.images.load(str(path), check_existing=False)
        try:
            width, height = image.size
            pixels = np.empty(width * height * 4, dtype=np.float32)
            image.pixels.foreach_get(pixels)
        finally:
            bpy.data.images.remove(image)
        if sheet is None:
            tile = (height, width)
            rows = -(-len(paths) // columns)
            sheet = np.full((rows * height, columns * width, 3), 255, dtype=np.uint8)
        if (height, width) != tile:
            raise GoniometerError("The map's pictures differ in size: cannot tile them.")
        row, column = divmod(index, columns)
        view = pixels.reshape(height, width, 4)[::-1, :, :3]  # Blender's rows start at the bottom
        sheet[row * height : (row + 1) * height, column * width : (column + 1) * width] = np.rint(
            np.clip(view, 0.0, 1.0) * 255.0
        )
    write_png(out, sheet)
    return out


def render_map(obj, directory, *, views="SIX", size=(800, 600), samples=16, progress=None):
    """Render the measurement map of ``obj`` into ``directory``: one PNG per view and a contact
    sheet. Returns ``(view paths, sheet path)``.

    ``progress(done, total)`` is called before each view; returning False cancels: the
    pictures written so far are removed and a GoniometerError says so.
    """
    job = MapJob(obj, directory, views=views, size=size, samples=samples)
    try:
        while not job.done:
            if progress is not None and progress(len(job.written), len(job.views)) is False:
                job.abort()
                raise GoniometerError("The map was cancelled: no picture was kept.")
            job.render_next()
        job.finish()
    except BaseException:
        job.abort()
        raise
    finally:
        job.close()
    return job.written, job.sheet
