"""The project's mesh readers read what Blender's own importers read from the same file.

Files in each format and flavour the readers accept (ASCII and binary PLY of both byte orders,
float and double, extra properties, comments, CRLF line ends; OBJ with w and vertex colours,
polygons and relative indices; ASCII and binary STL) are imported by Blender (``wm.ply_import``,
``wm.obj_import``, ``wm.stl_import``) and read by ``vg_addon.formats.meshio``: the vertices, as
float32 (Blender's precision), and the triangles' corner coordinates must be the same multisets
(Blender may reorder or merge vertices, so order is not compared). Blank lines between PLY
records, which the project's reader accepts, are left out: Blender's importer refuses them."""

from __future__ import annotations

import struct

import bpy
import numpy as np
import pytest

from vg_addon.formats import meshio
from vg_addon.synthetic_meshes import wedge


def _blender_import(path) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (float32, object space) and triangle corner coordinates of what Blender's
    importer makes of ``path``."""
    before = set(bpy.data.objects)
    importer = {".ply": bpy.ops.wm.ply_import, ".obj": bpy.ops.wm.obj_import}.get(
        path.suffix, bpy.ops.wm.stl_import
    )
    importer(filepath=str(path), forward_axis="Y", up_axis="Z")  # the file's own axes
    (obj,) = set(bpy.data.objects) - before
    mesh = obj.data
    co = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", co)
    co = co.reshape(-1, 3)
    mesh.calc_loop_triangles()
    tris = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", tris)
    return co, co[tris.reshape(-1, 3)]


def _multiset(rows: np.ndarray) -> np.ndarray:
    rows = np.ascontiguousarray(rows, dtype=np.float32).reshape(len(rows), -1)
    return rows[np.lexsort(rows.T[::-1])]


def _triangle_multiset(corners: np.ndarray) -> np.ndarray:
    """Triangles as sets of corner coordinates, each rotated to start at its smallest corner
    (importers keep a triangle's winding but may start it anywhere)."""
    corners = np.asarray(corners, dtype=np.float32)
    keys = np.lexsort(corners.transpose(2, 0, 1)[::-1].reshape(3, -1)).reshape(-1)
    order = np.empty(corners.shape[0] * 3, dtype=np.int64)
    order[keys] = np.arange(keys.size)
    first = np.argmin(order.reshape(-1, 3), axis=1)
    rolled = np.stack([np.roll(c, -f, axis=0) for c, f in zip(corners, first, strict=True)])
    return _multiset(rolled)


def _wedge():
    mesh = wedge(70.0, n=12, irregular=True, seed=2)
    return mesh.points + np.array([1.25, -2.5, 0.75]), mesh.triangles


def _ply_ascii(path, points, triangles, *, crlf=False, extra=False):
    newline = "\r\n" if crlf else "\n"
    header = [
        "ply",
        "format ascii 1.0",
        "comment made by the test",
        f"element vertex {len(points)}",
    ]
    header += ["property double x", "property double y", "property double z"]
    if extra:
        header += ["property uchar red", "property float quality"]
    header += [f"element face {len(triangles)}", "property list uchar int vertex_indices"]
    header += ["end_header"]
    lines = list(header)
    for p in points:
        lines.append(" ".join(repr(float(v)) for v in p) + (" 200 0.5" if extra else ""))
    lines += ["3 " + " ".join(str(int(i)) for i in t) for t in triangles]
    path.write_bytes((newline.join(lines) + newline).encode())


def _ply_binary(path, points, triangles, *, order="<", dtype="f"):
    name = {"<": "binary_little_endian", ">": "binary_big_endian"}[order]
    kind = {"f": "float", "d": "double"}[dtype]
    header = (
        f"ply\nformat {name} 1.0\nelement vertex {len(points)}\n"
        f"property {kind} x\nproperty {kind} y\nproperty {kind} z\n"
        f"element face {len(triangles)}\nproperty list uchar int vertex_indices\nend_header\n"
    )
    body = b"".join(struct.pack(f"{order}3{dtype}", *p) for p in points)
    body += b"".join(struct.pack(f"{order}B3i", 3, *map(int, t)) for t in triangles)
    path.write_bytes(header.encode() + body)


def _obj(path, points, triangles):
    lines = ["# made by the test", "o wedge"]
    for k, p in enumerate(points):
        extra = " 1.0" if k % 3 == 1 else (" 0.5 0.25 1.0" if k % 3 == 2 else "")
        lines.append("v " + " ".join(repr(float(v)) for v in p) + extra)
    quads = len(triangles) // 2
    for k, t in enumerate(triangles):
        if k < quads and k % 2 == 0:
            lines.append("f " + " ".join(f"{int(i) - len(points)}" for i in t))  # relative
        else:
            lines.append("f " + " ".join(f"{int(i) + 1}" for i in t))
    path.write_text("\n".join(lines) + "\n")


def _stl(path, points, triangles, *, binary):
    corners = points[triangles]
    if binary:
        body = b"".join(struct.pack("<12fH", 0, 0, 0, *c.ravel(), 0) for c in corners)
        path.write_bytes(b"\0" * 80 + struct.pack("<I", len(corners)) + body)
        return
    lines = ["solid wedge"]
    for c in corners:
        lines += ["facet normal 0 0 0", "outer loop"]
        lines += ["vertex " + " ".join(repr(float(v)) for v in p) for p in c]
        lines += ["endloop", "endfacet"]
    path.write_text("\n".join([*lines, "endsolid wedge"]) + "\n")


CASES = {
    "ascii.ply": lambda path, p, t: _ply_ascii(path, p, t),
    "ascii-crlf-extra.ply": lambda path, p, t: _ply_ascii(path, p, t, crlf=True, extra=True),
    "binary-le-float.ply": lambda path, p, t: _ply_binary(path, p, t),
    "binary-be-double.ply": lambda path, p, t: _ply_binary(path, p, t, order=">", dtype="d"),
    "wedge.obj": _obj,
    "ascii.stl": lambda path, p, t: _stl(path, p, t, binary=False),
    "binary.stl": lambda path, p, t: _stl(path, p, t, binary=True),
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_the_reader_reads_what_blenders_importer_reads(name, tmp_path):
    points, triangles = _wedge()
    path = tmp_path / name
    CASES[name](path, points, triangles)
    ours = meshio.read_mesh(path)
    theirs, their_corners = _blender_import(path)
    our_points = ours.points.astype(np.float32)
    if path.suffix == ".stl":  # STL has no shared vertices: compare the distinct ones
        our_points, theirs = np.unique(our_points, axis=0), np.unique(theirs, axis=0)
    assert np.array_equal(_multiset(our_points), _multiset(theirs))
    our_corners = ours.points[ours.triangles].astype(np.float32)
    assert np.array_equal(_triangle_multiset(our_corners), _triangle_multiset(their_corners))


def _hexagon_wedge():
    """A 100° wedge tiled by hexagons (each a grid cell with a vertex in the middle of either
    side across the crease, so its fan from the first corner differs from Blender's fill), the
    crease between vertex rows; coordinates float32 holds exactly."""
    n, rows, step, half = 21, 10, 0.1, np.radians(50.0)
    xs = np.linspace(-1.0, 1.0, n)
    ys = (np.arange(-rows, rows) + 0.5) * step
    mids = (ys[:-1] + ys[1:]) / 2
    grid = np.stack(np.meshgrid(xs, ys, indexing="ij"), axis=-1).reshape(-1, 2)
    middle = np.stack(np.meshgrid(xs, mids, indexing="ij"), axis=-1).reshape(-1, 2)
    flat = np.vstack([grid, middle])
    points = np.column_stack([flat, -np.abs(flat[:, 1]) / np.tan(half)])
    points = points.astype(np.float32).astype(np.float64)
    on_grid = np.arange(grid.shape[0]).reshape(n, ys.size)
    in_middle = grid.shape[0] + np.arange(middle.shape[0]).reshape(n, mids.size)
    i, j = np.meshgrid(np.arange(n - 1), np.arange(mids.size), indexing="ij")
    faces = np.stack(
        [
            on_grid[i, j],
            on_grid[i + 1, j],
            in_middle[i + 1, j],
            on_grid[i + 1, j + 1],
            on_grid[i, j + 1],
            in_middle[i, j],
        ],
        axis=-1,
    ).reshape(-1, 6)
    return points, faces


def _polygon_files(folder):
    points, faces = _hexagon_wedge()
    ply = folder / "hexagons.ply"
    header = [
        "ply",
        "format ascii 1.0",
        f"element vertex {len(points)}",
        *(f"property double {axis}" for axis in "xyz"),
        f"element face {len(faces)}",
        "property list uchar int vertex_indices",
        "end_header",
    ]
    vertices = [" ".join(repr(float(v)) for v in p) for p in points]
    ply.write_text("\n".join([*header, *vertices, *("6 " + " ".join(map(str, f)) for f in faces)]))
    obj = folder / "hexagons.obj"
    lines = ["v " + line for line in vertices] + [
        "f " + " ".join(str(i + 1) for i in f) for f in faces
    ]
    obj.write_text("\n".join(lines) + "\n")
    return ply, obj


def _loop_triangle_corners(obj) -> np.ndarray:
    mesh = obj.data
    mesh.calc_loop_triangles()
    tris = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", tris)
    co = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", co)
    return co.reshape(-1, 3)[tris.reshape(-1, 3)]


@pytest.mark.parametrize("suffix", [".ply", ".obj"])
def test_the_batchs_mesh_of_polygons_is_blenders_own_import(vg, tmp_path, suffix):
    """A file of hexagons: the batch fan-triangulated each from its first corner, where
    Blender's importer keeps the hexagon and fills it its own way; all 1,520 triangles
    differed, and the batch's readings with them (off the crease, a stability of ±21.2° where
    Blender's mesh gives ±0.00°). Now the batch's object keeps the polygons: the same
    triangles as File > Import's, and the same bits when measured. The reader's own triangles
    stay the fans (the core's users get those)."""
    import importlib

    sources = importlib.import_module(f"{vg.__name__}.batch.sources")
    path = dict(zip((".ply", ".obj"), _polygon_files(tmp_path), strict=True))[suffix]
    ours, _ = sources.import_mesh(sources.MeshSource("ours", str(path)))
    assert all(len(face.vertices) == 6 for face in ours.data.polygons)
    _, their_corners = _blender_import(path)
    our_corners = _loop_triangle_corners(ours)
    assert np.array_equal(_triangle_multiset(our_corners), _triangle_multiset(their_corners))
    fans = meshio.read_mesh(path)
    fan_corners = fans.points[fans.triangles].astype(np.float32)
    assert not np.array_equal(_triangle_multiset(fan_corners), _triangle_multiset(our_corners))
    from vg_addon import Surface

    def surface(corners):  # corners welded back into vertices
        points, corner_vertices = np.unique(corners.reshape(-1, 3), axis=0, return_inverse=True)
        return Surface(points.astype(np.float64), corner_vertices.reshape(-1, 3))

    centre = [0.1, 0.05, -0.042]
    ours_measured, theirs_measured = (
        surface(corners).measure(centre, 0.3, stability=True)
        for corners in (our_corners, their_corners)
    )
    assert (
        Surface(fans.points, fans.triangles).measure(centre, 0.3, stability=True).stability.spread
        > 10
    )
    assert ours_measured.angle == theirs_measured.angle
    assert ours_measured.stability.spread == theirs_measured.stability.spread


QUADS = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\n"


@pytest.mark.parametrize(
    ("name", "text"),
    [
        ("twice.obj", QUADS + "f 1 2 3 4\nf 2 3 4 1\nf 2 5 6 3\n"),
        (
            "twice.ply",
            "ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\nproperty float y\n"
            "property float z\nelement face 3\nproperty list uchar int vertex_indices\n"
            "end_header\n" + QUADS.replace("v ", "") + "4 0 1 2 3\n4 1 2 3 0\n4 1 4 5 2\n",
        ),
    ],
)
def test_a_polygon_written_twice_is_kept_once_as_blender_keeps_it(vg, tmp_path, name, text):
    """A quad written twice from another corner (no two of its fans alike): Blender's importers
    keep one, the batch kept both (found by a review of the change that keeps polygons)."""
    import importlib

    sources = importlib.import_module(f"{vg.__name__}.batch.sources")
    path = tmp_path / name
    path.write_text(text)
    ours, _ = sources.import_mesh(sources.MeshSource("ours", str(path)))
    _, their_corners = _blender_import(path)
    our_corners = _loop_triangle_corners(ours)
    assert np.array_equal(_triangle_multiset(our_corners), _triangle_multiset(their_corners))
