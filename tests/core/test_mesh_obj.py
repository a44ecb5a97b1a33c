"""OBJ files: face forms, relative indices, normals, point clouds, and malformed lines named."""

import numpy as np
import pytest
from mesh_files import expect_error, fan, grid_polygons, write_text

from vg_addon.formats.meshio import read_mesh


def test_obj_face_forms_relative_indices_and_ignored_statements(tmp_path):
    text = """# a comment
mtllib thing.mtl
o thing
v 0 0 0
v 1 0 0 0.5 0.25 0.125
v 1 1 0
v 0 1 0
vt 0 0
vt 1 0
vn 0 0 1
g group one
usemtl stone
s off
f 1 2 3
f 1/1 3/2 4/1
f 1//1 2//1 3//1
f 1/1/1 2/2/1 3/1/1 4/2/1
f -4 -3 -1
v 0.5 0.5 2e-1
f -5/1/1 -4/2/1 -1/1/1
l 1 2
p 3
"""
    mesh = read_mesh(write_text(tmp_path / "forms.obj", text))
    assert np.array_equal(
        mesh.points, [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 0.5, 0.2]]
    )
    expected = [[0, 1, 2], [0, 2, 3], [0, 1, 2], [0, 1, 2], [0, 2, 3], [0, 1, 3], [0, 1, 4]]
    assert mesh.triangles.tolist() == expected
    assert mesh.normals is None  # one vn for five vertices
    assert mesh.source_dtype == "float64" and mesh.name == "forms"


def test_obj_polygons_crlf_tabs_and_leading_blanks(tmp_path):
    text = "v 0 0 0\r\n  v\t1 0 0\r\nv 2 1 0\r\n\tv 1 2 0\r\nv 0 1 0\r\n\r\n  f 1 2 3 4 5\r\n"
    mesh = read_mesh(write_text(tmp_path / "crlf.OBJ", text))
    assert mesh.n_vertices == 5
    assert mesh.triangles.tolist() == [[0, 1, 2], [0, 2, 3], [0, 3, 4]]


def test_obj_one_to_one_normals_are_kept(tmp_path):
    text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 0.6 0.8\nvn 1 0 0\nf 1//1 2//2 3//3\n"
    mesh = read_mesh(write_text(tmp_path / "n.obj", text))
    assert np.array_equal(mesh.normals, [[0, 0, 1], [0, 0.6, 0.8], [1, 0, 0]])
    for faces in ("f 1//2 2//1 3//3\n", "f 1 2 3\n", "f 1/1 2/2 3/3\n", "f 1//1 2 3//3\n"):
        mixed = text.rsplit("f", 1)[0] + faces
        assert read_mesh(write_text(tmp_path / "m.obj", mixed)).normals is None, faces
    cloud = "v 0 0 0\nvn 1 0 0\nv 1 0 0\nvn 0 1 0\n"
    assert np.array_equal(
        read_mesh(write_text(tmp_path / "c.obj", cloud)).normals, [[1, 0, 0], [0, 1, 0]]
    )


def test_obj_point_cloud(tmp_path):
    mesh = read_mesh(write_text(tmp_path / "cloud.obj", "v 1 2 3\nv 4 5 6\n"))
    assert mesh.triangles is None and mesh.points.tolist() == [[1, 2, 3], [4, 5, 6]]


def test_obj_matches_ply_of_the_same_mesh(tmp_path):
    points, faces = grid_polygons("mixed")
    lines = [f"v {x!r} {y!r} {z!r}" for x, y, z in points]
    lines += ["f " + " ".join(f"{i + 1}/{i + 1}" for i in f) for f in faces]
    mesh = read_mesh(write_text(tmp_path / "grid.obj", "\n".join(lines)))  # no final newline
    assert np.array_equal(mesh.points, points)
    assert mesh.triangles.tolist() == [list(t) for t in fan(faces)]


# ------------------------------------------------------------------------------------ malformed


@pytest.mark.parametrize(
    ("text", "fragments"),
    [
        ("v 0 0 0\nv 1 0\n", ("line 2", "three coordinates")),
        ("v 0 0 0\nv 1 O 0\nv 0 1 0\n", ("line 2", "cannot read")),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 x\n", ("line 5", "cannot read")),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2.5 3\nf 1 2 3\n", ("line 5", "indices")),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 /2 3\n", ("line 4", "no vertex index")),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", ("line 4", "index 0")),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", ("out of range",)),
        ("v 0 0 0\nv 1 0 0\nf -1 -2 -3\nv 0 1 0\n", ("out of range",)),
        ("v 0 0 0\nv inf 0 0\nv 0 1 0\nf 1 2 3\n", ("not finite", "vertex 1")),
        ("# nothing here\nvt 0 0\n", ("no vertices",)),
    ],
)
def test_malformed_obj(tmp_path, text, fragments):
    expect_error(write_text(tmp_path / "bad.obj", text), *fragments)


@pytest.mark.parametrize("columns", ["1 2 3", "1 2 3 1", "1 2 3 0.5 0.25 1"])
def test_obj_vertex_lines_with_w_or_colours_are_read(tmp_path, columns):
    """x y z, x y z w (the OBJ format) and x y z r g b (the colour extension MeshLab and
    Blender write)."""
    text = f"v 0 0 0\nv {columns}\nv 0 1 0\nf 1 2 3\n"
    mesh = read_mesh(write_text(tmp_path / "columns.obj", text))
    assert mesh.points.tolist() == [[0, 0, 0], [1, 2, 3], [0, 1, 0]]


@pytest.mark.parametrize(
    ("text", "fragments"),
    [
        ("v 0 0 0\nv 1 0 0 0.25 0.5\nv 0 1 0\nf 1 2 3\n", ("line 2", "5 numbers")),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0 1 1 1 1\nf 1 2 3\n", ("line 3", "7 numbers")),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\n# x\nf 1 2 4\n", ("line 5", "vertex 4", "3 vertices")),
        ("v 0 0 0\nf -1 -2 -3\nv 1 0 0\nv 0 1 0\n", ("line 2", "out of range")),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2/1/1/1 3\n", ("line 5", "'2/1/1/1'")),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/ 2 3\n", ("line 4", "'1/'")),
    ],
)
def test_obj_wrong_counts_and_indices_name_the_line(tmp_path, text, fragments):
    expect_error(write_text(tmp_path / "bad.obj", text), *fragments)


@pytest.mark.parametrize("faces", ["", "f 1 2 3\nf 1 3 4\n"], ids=["cloud", "last vertex unused"])
def test_an_obj_with_a_byte_order_mark_keeps_its_first_vertex(tmp_path, faces):
    """A UTF-8 byte-order mark (as Windows editors write) hid the first 'v' keyword: the first
    vertex was dropped and every face index shifted onto the next vertex, with no error."""
    points = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 0.5, 1.25]]
    text = "".join(f"v {x} {y} {z}\n" for x, y, z in points) + faces
    path = tmp_path / "bom.obj"
    path.write_bytes(b"\xef\xbb\xbf" + text.encode())
    mesh = read_mesh(path)
    assert mesh.points.tolist() == points
    if faces:
        assert mesh.triangles.tolist() == [[0, 1, 2], [0, 2, 3]]
    else:
        assert mesh.triangles is None
