"""From a Blender mesh object to NumPy: float64 vertices in the mesh's own coordinates,
triangles, a fingerprint, and caches of each object's evaluated geometry and prepared
:class:`~vg_addon.Surface`.

Measurements are taken in mesh coordinates (object space: the coordinates of the file the scan
came from), so moving, rotating or scaling the object changes none of them; the object's
``matrix_world`` only converts a world-space point (the 3D cursor, a click) into them and back.

The geometry of an object is read once and kept until a depsgraph update says its geometry
changed (``watch`` calls :func:`invalidate`; a transform alone does not), so a click reads
nothing it already has. After an invalidation the mesh is read again; if its fingerprint is
unchanged (e.g. an undo step that only restored colours) the kept geometry and Surface are
reused.
"""

from __future__ import annotations

import dataclasses
import hashlib
from collections import OrderedDict
from dataclasses import dataclass
from functools import cached_property

import bpy
import numpy as np
from mathutils.bvhtree import BVHTree

from ..vg_addon import GoniometerError, Surface
from ..vg_addon.method.fixed_order import in_frame, moments, solve3

# A Surface of a million-vertex scan takes a few hundred MB; keep only the latest few.
_CACHE_SIZE = 3
_surfaces: OrderedDict[str, Surface] = OrderedDict()
# Per fingerprint, a ray-cast tree of the evaluated mesh (see ``ray_tree_for``).
_ray_trees: OrderedDict[str, BVHTree] = OrderedDict()

FINGERPRINT_PREFIX = "2-"
"""Fingerprints written since issue 10 (SHA-256 of positions, face corners and face offsets;
since issue 12 without the transform). Older files hold 32-hex-digit BLAKE2b fingerprints of
positions and loop triangles (and the transform, for world-space records)."""

# Per object (its session_uid): the geometry last read, and whether it is still current, i.e. no
# depsgraph update has touched the object's geometry since. Only trusted while the
# watcher's depsgraph handler is registered (``watching``).
_geometries: OrderedDict[int, Geometry] = OrderedDict()
_current: set[int] = set()
_watching = False
# Meshes whose colours we are writing: the depsgraph update that follows is ours, not an edit.
_own_writes: set[int] = set()


@dataclass(frozen=True)
class Geometry:
    """The evaluated mesh of an object, as measured.

    Attributes
    ----------
    local : ndarray of float32, shape (n, 3)
        Vertex coordinates in object space, as Blender stores them.
    triangles : ndarray of int32, shape (m, 3)
        Triangulated faces, as the mesh winds them (for a mesh of triangles, a view of
        ``corners``: no copy).
    matrix : ndarray of float64, shape (4, 4)
        The evaluated object's ``matrix_world`` (not part of the measurement).
    points : ndarray of float64, shape (n, 3)
        ``local`` as float64: the coordinates every measurement is taken in.
    fingerprint : str
        Hash of ``local`` and the face topology: equal fingerprints mean equal measurements.
        The object's transform is not part of it.
    corners, faces : ndarray of int32
        What :func:`read_corners` gave (``faces`` None when every face is a triangle); kept to
        recognise the world-space fingerprints of older files.
    """

    local: np.ndarray
    triangles: np.ndarray
    matrix: np.ndarray
    points: np.ndarray
    fingerprint: str
    corners: np.ndarray | None = None
    faces: np.ndarray | None = None

    @cached_property
    def legacy_fingerprint(self) -> str:
        """The mesh-space fingerprint of this geometry in the format before issue 10 (BLAKE2b
        of the positions and the loop triangles as Blender gives them)."""
        return legacy_fingerprint(self.local, self.triangles)

    @cached_property
    def world_fingerprints(self) -> frozenset[str]:
        """The fingerprints world-space records (files written before issue 12) hold for this
        geometry at its current transform: BLAKE2b of positions, loop triangles and the matrix
        (before issue 10), and SHA-256 of positions, face corners and the matrix (issue 10)."""
        old = legacy_fingerprint(self.local, self.triangles, self.matrix)
        if self.corners is None:
            return frozenset((old,))
        return frozenset((old, fingerprint(self.local, self.corners, self.faces, self.matrix)))

    def matches(self, stored: str) -> bool:
        """Whether a mesh-space measurement recorded with fingerprint ``stored`` was taken on
        this geometry (a fingerprint of either format). World-space records are matched by
        ``bridge.legacy`` against :attr:`world_fingerprints`."""
        if stored == self.fingerprint:
            return True
        return is_legacy(stored) and stored == self.legacy_fingerprint


def world_points(local: np.ndarray, matrix: np.ndarray) -> np.ndarray:
    """World-space float64 coordinates ``M[:3, :3] @ p + M[:3, 3]`` of object-space points.

    Any affine ``matrix_world`` is honoured, non-uniform scale and shear included.
    """
    local = np.asarray(local, dtype=np.float64)
    matrix = np.asarray(matrix, dtype=np.float64)
    rows = in_frame(local.reshape(-1, 3), matrix[:3, :3]) + matrix[:3, 3]
    return rows.reshape(local.shape)


def mesh_points(world: np.ndarray, matrix: np.ndarray) -> np.ndarray:
    """Mesh (object-space) float64 coordinates of world-space points: the inverse of
    :func:`world_points`.

    Raises
    ------
    GoniometerError
        The transform cannot be inverted (a scale of 0 on some axis).
    """
    matrix = np.asarray(matrix, dtype=np.float64)
    world = np.asarray(world, dtype=np.float64)
    rows = (world - matrix[:3, 3]).reshape(-1, 3)
    local = solve3(matrix[:3, :3], rows) if np.isfinite(matrix).all() else None
    if local is None:
        raise GoniometerError(
            "The object's transform flattens it (a scale of 0 on some axis): a point in world "
            "space has no place on its mesh. Give it a non-zero scale."
        )
    return local.reshape(world.shape)


def uniform_scale(matrix: np.ndarray, rtol: float = 1e-6) -> float | None:
    """The scale factor of ``matrix`` if it scales every direction alike (a rotation, a
    mirror, a uniform scale and a move), else None (a non-uniform scale or a shear).

    A non-uniform object scale changes angles in world space; measurements are taken in mesh
    coordinates and do not see it. The factor is rounded to float32, the precision Blender keeps
    transforms in (so a scale of 3 under a rotation is 3, not 2.99999996).
    """
    linear = np.asarray(matrix, dtype=np.float64)[:3, :3]
    gram = moments(linear)  # linearᵀ linear
    scale2 = float(np.trace(gram)) / 3.0
    if not np.isfinite(scale2) or scale2 <= 0.0:
        return None
    if np.abs(gram - scale2 * np.eye(3)).max() > rtol * scale2:
        return None
    return float(np.float32(np.sqrt(scale2)))


def _digest(digest, arrays) -> None:
    for array in arrays:
        array = np.ascontiguousarray(array)
        digest.update(f"{array.dtype.str}{array.shape}".encode())
        # Flat, because a memoryview with a zero in its shape (no faces) cannot be cast; the
        # bytes, and so the digests of recorded measurements, are the same.
        digest.update(memoryview(array.reshape(-1)).cast("B"))


def fingerprint(local: np.ndarray, corners: np.ndarray, faces, matrix=None) -> str:
    """A short digest of the geometry a measurement depends on (not the transform).

    Parameters
    ----------
    local : ndarray of float32, shape (n, 3)
        Vertex positions, object space.
    corners : ndarray of int32
        The vertex of each face corner, face after face.
    faces : ndarray of int32 or None
        Each face's first corner; None when every face is a triangle (implied by ``corners``).
    matrix : ndarray of float64, shape (4, 4), optional
        Only to recognise world-space records written before issue 12, whose fingerprint
        included the object's transform.

    Notes
    -----
    Blender's triangulation of quads and n-gons follows from these, so they fix the triangles
    without reading them. SHA-256: the fastest hashlib digest on CPUs with SHA instructions
    (about 2.5x BLAKE2b here), and collisions are out of reach.
    """
    digest = hashlib.sha256()
    arrays = (local, corners, np.zeros(0, np.int32) if faces is None else faces)
    _digest(digest, arrays if matrix is None else (*arrays, matrix))
    return FINGERPRINT_PREFIX + digest.hexdigest()[:32]


def legacy_fingerprint(local: np.ndarray, triangles: np.ndarray, matrix=None) -> str:
    """The fingerprint of files written before issue 10 (kept to migrate them): with
    ``matrix`` that of world-space records, without it that of mesh-space ones."""
    digest = hashlib.blake2b(digest_size=16)
    _digest(digest, (local, triangles) if matrix is None else (local, triangles, matrix))
    return digest.hexdigest()


def is_legacy(stored: str) -> bool:
    """Whether ``stored`` is a fingerprint of the format before issue 10."""
    return len(stored) == 32 and not stored.startswith(FINGERPRINT_PREFIX)


def new_mesh(name: str, points, triangles=None, polygons=None):
    """A new Blender mesh of ``points`` (stored as float32, as Blender keeps positions) and
    ``triangles`` (vertex indices; None for a point cloud), or ``polygons`` where given
    (``(corners, sizes)``, as ``MeshData.polygons``: faces of any size, which Blender fills with
    its own triangles, as its importers' meshes), its edges computed: the one way this
    extension builds a mesh from arrays. The attribute arrays take plain copies, much faster
    than the per-vertex properties."""
    points = np.ascontiguousarray(points, dtype=np.float32)
    mesh = bpy.data.meshes.new(name)
    mesh.vertices.add(points.shape[0])
    mesh.attributes["position"].data.foreach_set("vector", points.ravel())
    if polygons is not None:
        corners, sizes = (np.ascontiguousarray(a, dtype=np.int32) for a in polygons)
    elif triangles is not None:
        corners = np.ascontiguousarray(triangles, dtype=np.int32).ravel()
        sizes = np.full(corners.size // 3, 3, dtype=np.int32)
    if polygons is not None or triangles is not None:
        mesh.loops.add(corners.size)
        mesh.attributes[".corner_vert"].data.foreach_set("value", corners)
        mesh.polygons.add(sizes.size)
        mesh.polygons.foreach_set("loop_start", (np.cumsum(sizes) - sizes).astype(np.int32))
    mesh.update(calc_edges=True)
    return mesh


def new_mesh_object(name: str, points, triangles=None):
    """A new object of :func:`new_mesh`, linked to the scene's collection, made active and
    selected."""
    obj = bpy.data.objects.new(name, new_mesh(name, points, triangles))
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    return obj


def read_positions(mesh) -> np.ndarray:
    """Vertex coordinates of a bpy mesh, float32 ``(n, 3)``, as stored."""
    co = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
    position = mesh.attributes.get("position")
    if position is not None and position.data_type == "FLOAT_VECTOR":
        position.data.foreach_get("vector", co)  # the fast path: a plain array copy
    else:
        mesh.vertices.foreach_get("co", co)
    return co.reshape(-1, 3)


def read_corners(mesh) -> tuple[np.ndarray, np.ndarray | None]:
    """The vertex of every face corner (int32), and each face's first corner (int32), or None
    when every face is a triangle."""
    n_faces, n_corners = len(mesh.polygons), len(mesh.loops)
    corners = np.empty(n_corners, dtype=np.int32)
    corner_vert = mesh.attributes.get(".corner_vert")
    if corner_vert is not None and corner_vert.data_type == "INT":
        corner_vert.data.foreach_get("value", corners)
    else:
        mesh.loops.foreach_get("vertex_index", corners)
    if n_corners == 3 * n_faces:
        return corners, None  # every face has at least 3 corners, so exactly 3
    faces = np.empty(n_faces, dtype=np.int32)
    mesh.polygons.foreach_get("loop_start", faces)
    return corners, faces


def read_triangles(mesh, corners: np.ndarray | None = None, faces=0) -> np.ndarray:
    """Triangles of a bpy mesh, int32 ``(m, 3)``: its own triangles, or Blender's
    triangulation of its quads and n-gons (``loop_triangles``).

    ``corners`` and ``faces``: what :func:`read_corners` gave, if already read.
    """
    if corners is None:
        corners, faces = read_corners(mesh)
    if faces is None:
        # Every face is a triangle, and faces own consecutive corners in order: the corner
        # array is the triangle list. ~100x faster than reading loop_triangles, same triangles.
        return corners.reshape(-1, 3)
    mesh.calc_loop_triangles()
    triangles = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", triangles)
    return triangles.reshape(-1, 3)


def names_of(obj) -> tuple[str, ...]:
    """The names a CSV row or picked-points file may call ``obj`` by: its own and its mesh's,
    unless another object is named like its mesh (an object renamed after import keeps its
    mesh's old name, which may be another object's): a row naming that is the other object's."""
    other = bpy.data.objects.get(obj.data.name)
    if other is not None and other != obj:
        return (obj.name,)
    return (obj.name, obj.data.name)


def other_names(obj) -> tuple[str, ...]:
    """The names of every other mesh object of the file and of their meshes, less ``obj``'s own
    (:func:`names_of`): a file named after one of them belongs to it, not to ``obj``."""
    own = set(names_of(obj))
    names = {
        name
        for other in bpy.data.objects
        if other.type == "MESH" and other != obj
        for name in (other.name, other.data.name)
    }
    return tuple(sorted(names - own))


def is_changeable(block) -> bool:
    """Whether ``block`` (an object, a mesh) may be changed in this file: neither linked from a
    library nor a library override, and editable."""
    return block.library is None and block.override_library is None and block.is_editable


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
        if not is_changeable(block):
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
    others = _sharing_objects(obj)
    if others:
        names = ", ".join(f"'{name}'" for name in others[:3]) + (", ..." if len(others) > 3 else "")
        raise GoniometerError(
            f"'{obj.name}' shares its mesh '{obj.data.name}' with {names} (a linked duplicate, "
            "Alt+D): the sides' colours are kept on the mesh, so one object's would paint over "
            "the other's. Give it a mesh of its own first (Object > Relations > Make Single User "
            "> Object & Data); its measurements are kept."
        )


def _sharing_objects(obj) -> list[str]:
    """The names of the other objects whose data is ``obj``'s mesh (sorted)."""
    mesh = obj.data
    if mesh.users - int(mesh.use_fake_user) <= 1:  # the usual case, without a look at every object
        return []
    return sorted(other.name for other in bpy.data.objects if other.data == mesh and other != obj)


_TO_MEASURE = "to measure (its modifiers and shape keys are not applied)"


class NotEvaluatedError(GoniometerError):
    """The object has no evaluated mesh: it is disabled in the viewports or left out of the view
    layer. Its records stand, but nothing can be measured, painted or rendered on it."""


def is_evaluated(obj, depsgraph) -> bool:
    """Whether ``depsgraph`` holds ``obj`` evaluated (its modifiers and shape keys applied).
    Where it does not, Blender hands back the original, whose mesh lacks the modifiers and shape
    keys the user sees, and whose matrix_world is not kept up to date."""
    return obj.evaluated_get(depsgraph).is_evaluated


def check_evaluated(obj, depsgraph, purpose: str) -> None:
    """Raise :class:`NotEvaluatedError` where ``depsgraph`` does not hold ``obj`` evaluated,
    saying it has no evaluated mesh for ``purpose`` ("to render")."""
    if not is_evaluated(obj, depsgraph):
        raise NotEvaluatedError(
            f"'{obj.name}' is disabled in the viewports or left out of this view layer (the "
            "monitor icon or the checkbox in the Outliner, its own or its collection's), so "
            f"Blender has no evaluated mesh {purpose}: enable it first (hiding it with H is "
            "fine)."
        )


def evaluated_geometry(obj, depsgraph=None, *, purpose: str = _TO_MEASURE) -> Geometry:
    """The evaluated mesh of ``obj`` (modifiers applied) in its own coordinates.

    Read once and kept until a depsgraph update touches the object's geometry
    (see the module notes); the kept geometry is returned without reading the mesh.

    Parameters
    ----------
    obj : bpy.types.Object
        A mesh object (the original, not the evaluated copy).
    depsgraph : bpy.types.Depsgraph, optional
        Default: the context's evaluated depsgraph.
    purpose : str, optional
        What the mesh is read for, in the :class:`NotEvaluatedError` message ("to repaint").

    Raises
    ------
    NotEvaluatedError
        The object is disabled in the viewports or left out of the view layer.
    GoniometerError
        The mesh cannot be measured (no vertices, say).
    """
    if depsgraph is None:
        depsgraph = bpy.context.evaluated_depsgraph_get()
    check_evaluated(obj, depsgraph, purpose)
    obj_eval = obj.evaluated_get(depsgraph)
    key = obj.session_uid
    kept = _geometries.get(key)
    if _watching and kept is not None and key in _current:
        _geometries.move_to_end(key)
        matrix = np.array(obj_eval.matrix_world, dtype=np.float64)
        if not np.array_equal(matrix, kept.matrix):
            # Moved, rotated or scaled: the same measurements, only world positions differ.
            kept = dataclasses.replace(kept, matrix=matrix)
            _geometries[key] = kept
        return kept
    geometry = _read_geometry(obj, obj_eval, kept)
    _geometries[key] = geometry
    _geometries.move_to_end(key)
    _current.add(key)
    while len(_geometries) > _CACHE_SIZE:
        _current.discard(_geometries.popitem(last=False)[0])
    return geometry


def _read_geometry(obj, obj_eval, kept: Geometry | None) -> Geometry:
    mesh = obj_eval.to_mesh()
    try:
        local = read_positions(mesh)
        if local.shape[0] == 0:
            raise GoniometerError(f"'{obj.name}' has no vertices: there is nothing to measure.")
        corners, faces = read_corners(mesh)
        matrix = np.array(obj_eval.matrix_world, dtype=np.float64)
        if kept is not None and _same_bits(kept, local, corners, faces):
            # What the fingerprint hashes is unchanged, bit for bit (e.g. an undo that only
            # restored colours): comparing costs a fraction of hashing.
            if np.array_equal(matrix, kept.matrix):
                return kept
            return dataclasses.replace(kept, matrix=matrix)
        key = fingerprint(local, corners, faces)
        triangles = read_triangles(mesh, corners, faces)
    finally:
        obj_eval.to_mesh_clear()
    points = local.astype(np.float64)
    if not np.isfinite(points).all():
        raise GoniometerError(
            f"'{obj.name}' has vertices with infinite or NaN coordinates (check its modifiers)."
        )
    return Geometry(local, triangles, matrix, points, key, corners, faces)


def _same_bits(kept: Geometry, local: np.ndarray, corners: np.ndarray, faces) -> bool:
    """Whether ``local``, ``corners`` and ``faces`` are bit for bit those ``kept`` was read
    from (so its fingerprint is theirs; -0.0 and 0.0 differ, as in the hash)."""
    if kept.corners is None or (faces is None) != (kept.faces is None):
        return False
    pairs = [(local.view(np.uint32), kept.local.view(np.uint32)), (corners, kept.corners)]
    if faces is not None:
        pairs.append((faces, kept.faces))
    return all(a.shape == b.shape and np.array_equal(a, b) for a, b in pairs)


def invalidate(obj) -> None:
    """Note that ``obj``'s geometry may have changed: the next
    :func:`evaluated_geometry` reads it again."""
    _current.discard(obj.session_uid)


def invalidate_all() -> None:
    """Note that any object may have changed (file load, undo)."""
    _current.clear()


def is_own_write(obj) -> bool:
    """Whether a depsgraph update of ``obj`` comes from our own colour write (see
    :func:`own_write`), not from a change of its geometry."""
    data = obj.data
    return data is not None and data.session_uid in _own_writes


class own_write:
    """Write into ``mesh``'s attributes with ``with own_write(mesh): ...``.

    Pending depsgraph updates are evaluated first (they are the user's and invalidate as they
    should); then, after the body, the depsgraph is evaluated again while the updates of
    ``mesh`` are marked as ours, so writing colours neither drops the kept geometry nor wakes
    the staleness watcher.
    """

    def __init__(self, mesh, depsgraph=None):
        self.mesh = mesh
        self.depsgraph = depsgraph

    def _evaluate(self) -> None:
        if self.depsgraph is not None:
            self.depsgraph.update()
        else:
            bpy.context.evaluated_depsgraph_get()

    def __enter__(self):
        self._evaluate()
        return self.mesh

    def __exit__(self, *exc) -> None:
        key = self.mesh.session_uid
        _own_writes.add(key)
        try:
            self._evaluate()
        finally:
            _own_writes.discard(key)


def set_watching(watching: bool) -> None:
    """Whether depsgraph updates reach :func:`invalidate` (the watcher is registered); kept
    geometry is only trusted while they do."""
    global _watching
    _watching = watching
    _current.clear()


def _kept(cache: OrderedDict, key: str, build):
    """``cache[key]``, built by ``build()`` if absent; the latest :data:`_CACHE_SIZE` kept."""
    value = cache.get(key)
    if value is None:
        value = cache[key] = build()
        while len(cache) > _CACHE_SIZE:
            cache.popitem(last=False)
    else:
        cache.move_to_end(key)
    return value


def surface_for(obj, geometry: Geometry) -> Surface:
    """The prepared :class:`Surface` of ``geometry``, built once per fingerprint (objects with
    equal meshes share it, wherever they are placed)."""
    triangles = geometry.triangles if geometry.triangles.size else None
    return _kept(
        _surfaces,
        geometry.fingerprint,
        lambda: Surface(geometry.points, triangles, precision="float32"),
    )


def ray_tree_for(obj, geometry: Geometry, depsgraph=None) -> BVHTree:
    """A ray-cast tree of ``obj``'s evaluated mesh, in mesh coordinates, built once per
    fingerprint.

    Rays cast on it hit the triangles ``obj.evaluated_get(depsgraph).ray_cast`` hits (to
    float32 precision), but it survives our colour writes: Blender rebuilds the evaluated
    mesh's own tree after every change of the mesh, colours included (0.7 s at 1M vertices, on
    the press after each measurement).

    Parameters
    ----------
    geometry : Geometry
        ``evaluated_geometry(obj, depsgraph)``, just read: the tree is built from the same
        evaluated mesh.
    """

    def build() -> BVHTree:
        graph = bpy.context.evaluated_depsgraph_get() if depsgraph is None else depsgraph
        return BVHTree.FromObject(obj.evaluated_get(graph), graph)

    return _kept(_ray_trees, geometry.fingerprint, build)


def clear_cache() -> None:
    """Forget every cached Surface, ray-cast tree and geometry (frees memory; called on
    unregister and file load)."""
    _surfaces.clear()
    _ray_trees.clear()
    _geometries.clear()
    _current.clear()
