"""From a Blender mesh object to NumPy: world-space float64 vertices, triangles, a fingerprint,
and a cache of prepared :class:`~vg_addon.Surface` objects."""

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
        Triangulated faces, wound so that normals point outward in world space.
    matrix : ndarray of float64, shape (4, 4)
        The evaluated object's ``matrix_world``.
    points : ndarray of float64, shape (n, 3)
        World-space vertex coordinates (see :func:`world_points`).
    fingerprint : str
        Hash of ``local``, the face topology and ``matrix``: equal fingerprints mean equal
        measurements.
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


def fingerprint(local: np.ndarray, triangles: np.ndarray, matrix: np.ndarray) -> str:
    """A short hex digest of the geometry a measurement depends on."""
    digest = hashlib.blake2b(digest_size=16)
    for array in (local, triangles, matrix):
        array = np.ascontiguousarray(array)
        digest.update(f"{array.dtype.str}{array.shape}".encode())
        # Flat, because a memoryview with a zero in its shape (no faces) cannot be cast; the
        # bytes, and so the digests of recorded measurements, are the same.
        digest.update(memoryview(array.reshape(-1)).cast("B"))
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
    """The evaluated mesh of ``obj`` (modifiers applied) in world space.

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
    key = fingerprint(local, triangles, matrix)
    triangles = triangles.astype(np.int64)
    if np.linalg.det(matrix[:3, :3]) < 0.0:
        # A mirroring transform turns the faces inside out in world space: flip the winding so
        # the normals the core derives from it still point outward.
        triangles = triangles[:, ::-1].copy()
    points = world_points(local, matrix)
    if not np.isfinite(points).all():
        raise GoniometerError(
            f"'{obj.name}' has vertices with infinite or NaN coordinates (check its transform "
            "and modifiers)."
        )
    return Geometry(local, triangles, matrix, points, key)


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
