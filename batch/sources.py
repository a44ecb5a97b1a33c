"""What a batch run measures: mesh files imported as Blender objects, or objects of a .blend."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import bpy
import numpy as np

from ..bridge import mesh_data
from ..vg_addon import GoniometerError
from ..vg_addon.formats import meshio
from ..vg_addon.workflow import batchplan
from .cli import UsageError
from .stdio import quiet_stdout


@dataclasses.dataclass
class MeshSource:
    """A mesh to measure: a file to import, or an object of the open .blend."""

    name: str
    path: str = ""  # the mesh file; "" for a .blend object
    aliases: tuple[str, ...] = ()

    @property
    def names(self) -> tuple[str, ...]:
        return (self.name, *self.aliases)


def start_file(inputs: list[str]) -> tuple[list[str], str]:
    """Open the .blend among ``inputs`` (or keep the one Blender opened), else start empty.

    Returns the other inputs and the .blend path ("" if none).
    """
    blends = [p for p in inputs if p.lower().endswith(".blend")]
    others = [p for p in inputs if not p.lower().endswith(".blend")]
    if len(blends) > 1:
        raise UsageError(f"give at most one .blend file (got {', '.join(blends)}).")
    if blends:
        path = Path(blends[0])
        if not path.is_file():
            raise UsageError(f"{blends[0]}: no such .blend file.")
        try:
            with quiet_stdout():
                bpy.ops.wm.open_mainfile(filepath=str(path.resolve()), load_ui=False)
        except RuntimeError as error:
            raise UsageError(
                f"{blends[0]}: cannot open it as a .blend file ({str(error).strip()})."
            ) from None
        return others, str(path)
    if bpy.app.binary_path and bpy.data.filepath:  # `blender -b file.blend --python ...`
        return others, bpy.data.filepath
    bpy.ops.wm.read_homefile(use_empty=True)
    return others, ""


def blend_objects(names: list[str], blend: str) -> list[MeshSource]:
    if not blend:
        if names:
            raise UsageError("--object names an object of a .blend file: give the .blend too.")
        return []
    if not names:
        meshes = [o for o in bpy.context.scene.objects if o.type == "MESH"]
        if len(meshes) != 1:
            listed = ", ".join(o.name for o in meshes[:10]) or "none"
            raise UsageError(
                f"{blend} has {len(meshes)} mesh objects ({listed}): name the ones to measure "
                "with --object NAME."
            )
        names = [meshes[0].name]
    sources, problems = [], []
    graph = bpy.context.evaluated_depsgraph_get()
    for name in names:
        obj = bpy.data.objects.get(name)
        if obj is None:
            problems.append(f"{blend} has no object named {name!r}")
            continue
        try:
            mesh_data.check_measurable(obj)
            mesh_data.check_evaluated(obj, graph, "to measure")
        except GoniometerError as error:
            problems.append(str(error))
            continue
        # its mesh's name too, unless another object carries it (as Blender's imports read)
        sources.append(MeshSource(obj.name, "", mesh_data.names_of(obj)[1:]))
    if problems:
        raise UsageError("\n  ".join(["cannot measure these objects:", *problems]))
    return sources


def readable_name(name: str) -> str:
    """A mesh name as text every output can hold: bytes of a file name that are not UTF-8
    (Python keeps them as surrogate escapes) shown as ``\\xe9``. The same file always gets the
    same name, so a CSV written with it finds its mesh again, and two files differing only in
    such bytes keep different names (U+FFFD for every bad byte would merge "caf\\xe9" and
    "caf\\xe8")."""
    try:
        return name.encode("utf-8", "surrogateescape").decode("utf-8", "backslashreplace")
    except UnicodeEncodeError:
        return name.encode("utf-8", "backslashreplace").decode("utf-8")


def file_sources(inputs: list[str]) -> list[MeshSource]:
    """The mesh files among ``inputs`` (and in given folders), named by their stems."""
    if not inputs:
        return []
    try:
        files = batchplan.find_mesh_files(inputs)
        names = batchplan.mesh_names(files)
    except GoniometerError as error:
        raise UsageError(str(error)) from None
    return [
        MeshSource(readable_name(name), str(path)) for name, path in zip(names, files, strict=True)
    ]


def import_mesh(source: MeshSource):
    """A new mesh object made from ``source``'s file (float32 coordinates, as Blender stores
    them), linked to the scene at the world origin.

    Returns
    -------
    obj : bpy.types.Object
    exact_points : ndarray of float64, shape (n, 3), or None
        The file's own coordinates when they are float64 values that float32 rounds (e.g. a
        scan far from the origin), to be measured at the file's precision; ``None`` when
        Blender's float32 mesh holds them exactly.
    """
    data = meshio.read_mesh(source.path)
    points = np.ascontiguousarray(data.points, dtype=np.float32)
    rounded = not np.array_equal(points.astype(np.float64), data.points)
    exact_points = data.points if rounded else None
    polygons = data.polygons
    flaws = (False, False) if polygons is None else face_flaws(*polygons)
    if flaws[0]:
        polygons = None  # a face repeats a corner: Blender's importers each repair it their way
    if polygons is None and data.triangles is not None:
        flaws = face_flaws(data.triangles.reshape(-1), np.full(data.triangles.shape[0], 3))
    mesh = mesh_data.new_mesh(source.name, points, data.triangles, polygons)
    if any(flaws):
        # Drop degenerate and duplicate faces as Blender's own importers do, so the object is
        # the one File > Import would make from the same file. (Indices are in range: the
        # reader checked them; so a list with neither has nothing for validate() to change.)
        mesh.validate(verbose=False)
    obj = bpy.data.objects.new(source.name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj, exact_points


def face_flaws(corners: np.ndarray, sizes: np.ndarray) -> tuple[bool, bool]:
    """Whether a face repeats a corner, and whether two faces have the same vertices (in any
    order, from any corner): the faces Blender's importers repair.

    Parameters
    ----------
    corners : ndarray of int, shape (sum(sizes),)
        Each face's vertex indices, one face after the other.
    sizes : ndarray of int, shape (f,)
        Each face's number of corners.
    """
    if sizes.size == 0:
        return False, False
    if (sizes == sizes[0]).all():  # one size (all triangles, say): no gathering needed
        groups = [corners.reshape(-1, int(sizes[0]))]
    else:
        starts = np.cumsum(sizes) - sizes
        groups = [corners[starts[sizes == k][:, None] + np.arange(k)] for k in np.unique(sizes)]
    repeated = duplicated = False
    for rows in groups:
        flaws = _triangle_flaws(rows) if rows.shape[1] == 3 else _polygon_flaws(rows)
        repeated, duplicated = repeated or flaws[0], duplicated or flaws[1]
    return repeated, duplicated


def _polygon_flaws(rows: np.ndarray) -> tuple[bool, bool]:
    rows = np.sort(rows, axis=1)
    repeated = bool((rows[:, 1:] == rows[:, :-1]).any())
    return repeated, bool(np.unique(rows, axis=0).shape[0] < rows.shape[0])


def _triangle_flaws(triangles: np.ndarray) -> tuple[bool, bool]:
    """:func:`_polygon_flaws` of triangles, on one int64 key each where their indices fit."""
    a, b, c = (np.ascontiguousarray(triangles[:, k], dtype=np.int64) for k in range(3))
    repeated = bool(((a == b) | (b == c) | (a == c)).any())
    low = np.minimum(np.minimum(a, b), c)
    high = np.maximum(np.maximum(a, b), c)
    middle = a + b + c - low - high
    n = int(high.max()) + 1
    if n < 1 << 21:  # the three indices packed into one int64 key
        keys = np.sort((low << 42) | (middle << 21) | high)
        return repeated, bool((keys[1:] == keys[:-1]).any())
    order = np.lexsort((high, low * n + middle))
    first, second = (low * n + middle)[order], high[order]
    return repeated, bool(((first[1:] == first[:-1]) & (second[1:] == second[:-1])).any())
