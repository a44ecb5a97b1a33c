"""From a Blender mesh object to NumPy: float64 vertices in the mesh's own coordinates,
triangles, a fingerprint, and a cache of prepared :class:`~vg_addon.Surface` objects.

Measurements are taken in mesh coordinates (object space: the coordinates of the file the scan
came from), so moving, rotating or scaling the object changes none of them; the object's
``matrix_world`` only converts a world-space point (the 3D cursor, a click) into them and back.
"""

from __future__ import annotations

import hashlib
from collections import OrderedDict
from dataclasses import dataclass

import bpy
import numpy as np

from ..vg_addon import GoniometerError, Surface

# A Surface of a million-vertex scan takes a few hundred MB; keep only the latest few.
_CACHE_SIZE = 3
_surfaces: OrderedDict[tuple[str, str], Surface] = OrderedDict()


@dataclass(frozen=True)
class Geometry:
    """The evaluated mesh of an object, as measured.

    Attributes
    ----------
    local : ndarray of float32, shape (n, 3)
        Vertex coordinates in object space, as Blender stores them.
    triangles : ndarray of int64, shape (m, 3)
        Triangulated faces, as the mesh winds them.
    matrix : ndarray of float64, shape (4, 4)
        The evaluated object's ``matrix_world`` (not part of the measurement).
    points : ndarray of float64, shape (n, 3)
        ``local`` as float64: the coordinates every measurement is taken in.
    fingerprint : str
        Hash of ``local`` and the face topology: equal fingerprints mean equal measurements.
        The object's transform is not part of it.
    """

    local: np.ndarray
    triangles: np.ndarray
    matrix: np.ndarray
    points: np.ndarray
    fingerprint: str


def world_points(local: np.ndarray, matrix: np.ndarray) -> np.ndarray:
    """World-space float64 coordinates ``M[:3, :3] @ p + M[:3, 3]`` of object-space points.

    Any affine ``matrix_world`` is honoured, non-uniform scale and shear included.
    """
    local = np.asarray(local, dtype=np.float64)
    matrix = np.asarray(matrix, dtype=np.float64)
    return local @ matrix[:3, :3].T + matrix[:3, 3]


def mesh_points(world: np.ndarray, matrix: np.ndarray) -> np.ndarray:
    """Mesh (object-space) float64 coordinates of world-space points: the inverse of
    :func:`world_points`.

    Raises
    ------
    GoniometerError
        The transform cannot be inverted (a scale of 0 on some axis).
    """
    matrix = np.asarray(matrix, dtype=np.float64)
    linear = matrix[:3, :3]
    if not np.isfinite(matrix).all() or abs(np.linalg.det(linear)) <= 1e-300:
        raise GoniometerError(
            "The object's transform flattens it (a scale of 0 on some axis): a point in world "
            "space has no place on its mesh. Give it a non-zero scale."
        )
    world = np.asarray(world, dtype=np.float64)
    return np.linalg.solve(linear, (world - matrix[:3, 3]).T).T


def uniform_scale(matrix: np.ndarray, rtol: float = 1e-6) -> float | None:
    """The scale factor of ``matrix`` if it scales every direction alike (a rotation, a
    mirror, a uniform scale and a move), else None (a non-uniform scale or a shear).

    A non-uniform object scale changes angles in world space; measurements are taken in mesh
    coordinates and do not see it. The factor is rounded to float32, the precision Blender keeps
    transforms in (so a scale of 3 under a rotation is 3, not 2.99999996).
    """
    linear = np.asarray(matrix, dtype=np.float64)[:3, :3]
    gram = linear.T @ linear
    scale2 = float(np.trace(gram)) / 3.0
    if not np.isfinite(scale2) or scale2 <= 0.0:
        return None
    if np.abs(gram - scale2 * np.eye(3)).max() > rtol * scale2:
        return None
    return float(np.float32(np.sqrt(scale2)))


def fingerprint(*arrays: np.ndarray) -> str:
    """A short hex digest of the geometry a measurement depends on (the vertex coordinates and
    the triangles)."""
    digest = hashlib.blake2b(digest_size=16)
    for array in arrays:
        array = np.ascontiguousarray(array)
        digest.update(f"{array.dtype.str}{array.shape}".encode())
        digest.update(memoryview(array).cast("B"))
    return digest.hexdigest()


def read_positions(mesh) -> np.ndarray:
    """Vertex coordinates of a bpy mesh, float32 ``(n, 3)``, as stored."""
    co = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
    position = mesh.attributes.get("position")
    if position is not None and position.data_type == "FLOAT_VECTOR":
        position.data.foreach_get("vector", co)  # the fast path: a plain array copy
    else:
        mesh.vertices.foreach_get("co", co)
    return co.reshape(-1, 3)


def read_triangles(mesh) -> np.ndarray:
    """Triangles of a bpy mesh, int32 ``(m, 3)``: its own triangles, or Blender's
    triangulation of its quads and n-gons (``loop_triangles``)."""
    n_faces, n_corners = len(mesh.polygons), len(mesh.loops)
    corner_vert = mesh.attributes.get(".corner_vert")
    if n_corners == 3 * n_faces and corner_vert is not None and corner_vert.data_type == "INT":
        # Every face is a triangle (each has at least 3 corners), and faces own consecutive
        # corners in order: the corner-vertex array is the triangle list. Reading it is ~100x
        # faster than reading loop_triangles, and gives the same triangles.
        corners = np.empty(n_corners, dtype=np.int32)
        corner_vert.data.foreach_get("value", corners)
        return corners.reshape(-1, 3)
    mesh.calc_loop_triangles()
    triangles = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", triangles)
    return triangles.reshape(-1, 3)


def check_measurable(obj) -> None:
    """Raise a :class:`GoniometerError` saying why ``obj`` cannot be measured, if it cannot."""
    if obj is None:
        raise GoniometerError(
            "No active object: click the mesh to measure so that it is the active object."
        )
    if obj.type != "MESH":
        raise GoniometerError(
            f"'{obj.name}' is not a mesh but an object of type {obj.type}: select a mesh object."
        )
    for block in (obj, obj.data):
        if block.library is not None or block.override_library is not None or not block.is_editable:
            source = block.library.filepath if block.library is not None else "a library override"
            raise GoniometerError(
                f"'{block.name}' is linked from {source} and cannot be changed here: make it "
                "local first (Object > Relations > Make Local)."
            )
    if obj.mode == "EDIT":
        raise GoniometerError(
            f"'{obj.name}' is in Edit Mode: switch to Object Mode (Tab) before measuring, so the "
            "measurement and its colours see the edited mesh."
        )


def evaluated_geometry(obj, depsgraph=None) -> Geometry:
    """The evaluated mesh of ``obj`` (modifiers applied) in its own coordinates.

    Parameters
    ----------
    obj : bpy.types.Object
        A mesh object (the original, not the evaluated copy).
    depsgraph : bpy.types.Depsgraph, optional
        Default: the context's evaluated depsgraph.
    """
    if depsgraph is None:
        depsgraph = bpy.context.evaluated_depsgraph_get()
    obj_eval = obj.evaluated_get(depsgraph)
    mesh = obj_eval.to_mesh()
    try:
        local = read_positions(mesh)
        triangles = read_triangles(mesh)
    finally:
        obj_eval.to_mesh_clear()
    if local.shape[0] == 0:
        raise GoniometerError(f"'{obj.name}' has no vertices: there is nothing to measure.")
    matrix = np.array(obj_eval.matrix_world, dtype=np.float64)
    key = fingerprint(local, triangles)
    points = local.astype(np.float64)
    if not np.isfinite(points).all():
        raise GoniometerError(
            f"'{obj.name}' has vertices with infinite or NaN coordinates (check its modifiers)."
        )
    return Geometry(local, triangles.astype(np.int64), matrix, points, key)


def surface_for(obj, geometry: Geometry) -> Surface:
    """The prepared :class:`Surface` of ``geometry``, built once per object and fingerprint."""
    key = (obj.name, geometry.fingerprint)
    surface = _surfaces.get(key)
    if surface is None:
        triangles = geometry.triangles if geometry.triangles.size else None
        surface = Surface(geometry.points, triangles)
        _surfaces[key] = surface
        while len(_surfaces) > _CACHE_SIZE:
            _surfaces.popitem(last=False)
    else:
        _surfaces.move_to_end(key)
    return surface


def clear_cache() -> None:
    """Forget every cached Surface (frees memory; called on unregister and file load)."""
    _surfaces.clear()
