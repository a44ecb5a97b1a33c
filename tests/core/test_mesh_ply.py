"""PLY files: the reference meshes, every flavour (ASCII, binary either endian, any types), write_ply,
and malformed files refused with the line or the value that is wrong."""

import struct

import numpy as np
import pytest
from mesh_files import (
    FORMATS,
    NUMPY_TYPES,
    STRUCT_CODES,
    expect_error,
    fan,
    grid_polygons,
    ply_bytes,
    write_text,
)

from vg_addon import GoniometerError
from vg_addon.formats.meshio import MeshData, read_mesh, write_ply
from vg_addon.synthetic_meshes import wedge

# --------------------------------------------------------------------------- reference meshes


def ply_header_counts(path):
    """Element counts, property types and header size, parsed independently."""
    with open(path, "rb") as file:
        data = file.read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    counts, types = {}, {}
    for line in data[:end].decode("ascii").splitlines():
        words = line.split()
        if words and words[0] == "element":
            counts[words[1]] = int(words[2])
            current = words[1]
            types[current] = []
        elif words and words[0] == "property":
            types[current].append(words[1:])
    return data, end, counts, types


REFERENCE = ["HalfAnnulus.ply", "IntersectingSpheres.ply", "sample_mesh.ply"]


@pytest.mark.parametrize("name", REFERENCE)
def test_reference_meshes_load_with_the_header_counts(shared_data, name):
    path = shared_data / name
    data, body, counts, types = ply_header_counts(path)
    mesh = read_mesh(path)
    assert isinstance(mesh, MeshData)
    assert mesh.name == path.stem
    assert mesh.points.shape == (counts["vertex"], 3)
    assert mesh.triangles.shape == (counts["face"], 3)
    assert mesh.points.dtype == np.float64 and mesh.triangles.dtype == np.int64
    assert mesh.normals is None

    # First and last vertex and face, unpacked with struct at offsets computed from the header.
    coord = STRUCT_CODES[types["vertex"][0][0]]
    assert mesh.source_dtype == NUMPY_TYPES[types["vertex"][0][0]].name
    vertex_size = 3 * struct.calcsize(coord)
    count_code, index_code = (STRUCT_CODES[t] for t in types["face"][0][1:3])
    face_size = struct.calcsize(count_code) + 3 * struct.calcsize(index_code)
    faces_at = body + counts["vertex"] * vertex_size
    assert len(data) == faces_at + counts["face"] * face_size  # all faces are triangles
    for k in (0, counts["vertex"] - 1):
        expected = struct.unpack_from("<3" + coord, data, body + k * vertex_size)
        assert tuple(mesh.points[k]) == expected
    for k in (0, counts["face"] - 1):
        n, *corners = struct.unpack_from(
            f"<{count_code}3{index_code}", data, faces_at + k * face_size
        )
        assert n == 3 and tuple(mesh.triangles[k]) == tuple(corners)
    assert mesh.triangles.max() < counts["vertex"]


# ------------------------------------------------------------------------------- PLY flavours


@pytest.mark.parametrize("fmt", FORMATS)
@pytest.mark.parametrize("coord", ["float", "double", "float32", "float64"])
@pytest.mark.parametrize(
    ("count_type", "index_type"),
    [("uchar", "int"), ("int", "int"), ("uint8", "uint"), ("ushort", "int32")],
)
@pytest.mark.parametrize("kind", ["triangles", "quads", "mixed"])
def test_ply_flavours(tmp_path, fmt, coord, count_type, index_type, kind):
    points, faces = grid_polygons(kind)
    elements = [
        ("vertex", [(c, coord) for c in "xyz"], points),
        ("face", [("vertex_indices", "list", count_type, index_type)], [(f,) for f in faces]),
    ]
    path = tmp_path / "mesh.ply"
    path.write_bytes(ply_bytes(fmt, elements))
    mesh = read_mesh(path)
    stored = np.array(points, dtype=NUMPY_TYPES[coord]).astype(np.float64)
    assert np.array_equal(mesh.points, stored)
    assert mesh.triangles.tolist() == [list(t) for t in fan(faces)]
    assert mesh.source_dtype == NUMPY_TYPES[coord].name
    assert mesh.normals is None


@pytest.mark.parametrize("fmt", FORMATS)
@pytest.mark.parametrize("kind", ["triangles", "quads", "mixed"])
def test_ply_extra_properties_elements_and_comments(tmp_path, fmt, kind):
    """Colours, quality and normals in odd places, extra face properties and lists, other
    elements before and after, comments and obj_info: only x y z, normals and faces count."""
    points, faces = grid_polygons(kind)
    rng = np.random.default_rng(1)
    normals = rng.normal(size=(len(points), 3)).astype(np.float32)
    vertex_props = [
        ("red", "uchar"),
        ("x", "double"),
        ("quality", "float"),
        ("y", "double"),
        ("tags", "list", "uchar", "short"),
        ("z", "double"),
        ("nx", "float"),
        ("ny", "float"),
        ("nz", "float"),
        ("alpha", "uchar"),
    ]
    vertex_rows = [
        (i % 256, p[0], 0.5 * i, p[1], list(range(i % 3)), p[2], *normals[i], 255)
        for i, p in enumerate(points)
    ]
    face_props = [
        ("flags", "uchar"),
        ("vertex_indices", "list", "uchar", "int"),
        ("texcoord", "list", "uchar", "float"),
        ("tag", "int"),
    ]
    face_rows = [(7, f, [0.25] * (2 * len(f)), -k) for k, f in enumerate(faces)]
    elements = [
        ("material", [("ambient", "float"), ("power", "uchar")], [(0.5, 2), (0.25, 3)]),
        ("range", [("values", "list", "int", "double")], [([1.0, 2.0],), ([],), ([3.0],)]),
        ("vertex", vertex_props, vertex_rows),
        ("face", face_props, face_rows),
        ("edge", [("vertex1", "int"), ("vertex2", "int")], [(0, 1), (1, 2)]),
    ]
    comments = ("comment first", "obj_info scanned by a test", "comment   end_header is a word")
    path = tmp_path / "extras.ply"
    path.write_bytes(ply_bytes(fmt, elements, comments))
    mesh = read_mesh(path)
    assert np.array_equal(mesh.points, np.array(points))
    assert mesh.triangles.tolist() == [list(t) for t in fan(faces)]
    assert np.array_equal(mesh.normals, normals.astype(np.float64))
    assert mesh.source_dtype == "float64"


@pytest.mark.parametrize("fmt", FORMATS)
def test_ply_point_cloud_and_empty_face_element(tmp_path, fmt):
    points, _ = grid_polygons("triangles")
    path = tmp_path / "cloud.ply"
    path.write_bytes(ply_bytes(fmt, [("vertex", [(c, "float") for c in "xyz"], points)]))
    assert read_mesh(path).triangles is None
    path.write_bytes(
        ply_bytes(
            fmt,
            [
                ("vertex", [(c, "float") for c in "xyz"], points),
                ("face", [("vertex_indices", "list", "uchar", "int")], []),
            ],
        )
    )
    mesh = read_mesh(path)
    assert mesh.triangles is None and mesh.n_triangles == 0 and mesh.n_vertices == len(points)


def test_ascii_ply_values_take_their_declared_type(tmp_path):
    """ASCII "0.1" declared float reads as float32(0.1), like the binary twin of the file."""
    text = (
        "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty double y\n"
        "property float z\nend_header\n0.1 0.1 -0.0\n1e-3 2.5 3\n"
    )
    mesh = read_mesh(write_text(tmp_path / "declared.ply", text))
    assert mesh.points[0, 0] == float(np.float32(0.1)) != 0.1
    assert mesh.points[0, 1] == 0.1 and mesh.points[1, 0] == np.float32(1e-3)
    assert mesh.source_dtype == "float32"


def test_ply_crlf_header_and_case_insensitive_extension(tmp_path):
    points, faces = grid_polygons("quads")
    data = ply_bytes(
        "binary_little_endian",
        [
            ("vertex", [(c, "float") for c in "xyz"], points),
            ("face", [("vertex_indices", "list", "uchar", "int")], [(f,) for f in faces]),
        ],
    )
    end = data.index(b"end_header\n") + len(b"end_header\n")
    path = tmp_path / "Windows.PLY"
    path.write_bytes(data[:end].replace(b"\n", b"\r\n") + data[end:])
    mesh = read_mesh(str(path))
    assert mesh.name == "Windows"
    assert mesh.triangles.tolist() == [list(t) for t in fan(faces)]


def test_ply_non_finite_normals_are_dropped(tmp_path):
    points, _ = grid_polygons("triangles")
    rows = [(*p, 0.0, 0.0, 1.0 if i else float("nan")) for i, p in enumerate(points)]
    props = [(c, "float") for c in ("x", "y", "z", "nx", "ny", "nz")]
    path = tmp_path / "n.ply"
    path.write_bytes(ply_bytes("binary_little_endian", [("vertex", props, rows)]))
    assert read_mesh(path).normals is None


def test_ply_many_mixed_polygons(tmp_path):
    """The general (mixed polygon size) path on a few thousand random polygons."""
    rng = np.random.default_rng(5)
    n = 500
    points = rng.normal(size=(n, 3))
    faces = [tuple(rng.choice(n, size=k, replace=False)) for k in rng.integers(3, 9, 3000)]
    for fmt in FORMATS:
        for count_type in ("uchar", "int"):
            path = tmp_path / f"{fmt}_{count_type}.ply"
            path.write_bytes(
                ply_bytes(
                    fmt,
                    [
                        ("vertex", [(c, "double") for c in "xyz"], points.tolist()),
                        (
                            "face",
                            [("flags", "short"), ("vertex_indices", "list", count_type, "uint")],
                            [(1, f) for f in faces],
                        ),
                    ],
                )
            )
            mesh = read_mesh(path)
            assert np.array_equal(mesh.points, points)
            assert mesh.triangles.tolist() == [list(t) for t in fan(faces)]


# ---------------------------------------------------------------------------------- write_ply


@pytest.mark.parametrize("binary", [True, False])
def test_write_ply_round_trips_exactly(tmp_path, binary):
    rng = np.random.default_rng(3)
    points = rng.normal(size=(300, 3)) * 10.0 ** rng.integers(-8, 8, size=(300, 1))
    points[0] = [-0.0, 1e-300, 1.0 / 3.0]
    triangles = rng.integers(0, 300, size=(500, 3))
    normals = rng.normal(size=(300, 3))
    path = write_ply(tmp_path / "out.ply", points, triangles, normals, binary=binary)
    mesh = read_mesh(path)
    assert np.array_equal(mesh.points, points)
    assert np.array_equal(mesh.triangles, triangles)
    assert np.array_equal(mesh.normals, normals)
    assert mesh.source_dtype == "float64"
    assert path.read_bytes().startswith(b"ply\nformat " + (b"binary" if binary else b"ascii"))


@pytest.mark.parametrize("binary", [True, False])
def test_write_ply_point_cloud(tmp_path, binary):
    points = np.arange(30, dtype=float).reshape(10, 3) / 7
    mesh = read_mesh(write_ply(tmp_path / "cloud.ply", points, binary=binary))
    assert np.array_equal(mesh.points, points) and mesh.triangles is None and mesh.normals is None


@pytest.mark.parametrize(
    ("points", "triangles", "normals", "message"),
    [
        (np.zeros((0, 3)), None, None, "points"),
        (np.zeros((4, 2)), None, None, "points"),
        ([[0, 0, np.nan]], None, None, "not finite"),
        (np.zeros((3, 3)), [[0, 1, 3]], None, "outside"),
        (np.zeros((3, 3)), [[0.0, 1.0, 2.0]], None, "integer"),
        (np.zeros((3, 3)), None, np.zeros((2, 3)), "normals"),
    ],
)
def test_write_ply_rejects_bad_input(tmp_path, points, triangles, normals, message):
    with pytest.raises(GoniometerError, match=message):
        write_ply(tmp_path / "bad.ply", points, triangles, normals)


# ------------------------------------------------------------------------------------ malformed


@pytest.mark.parametrize(
    ("text", "fragments"),
    [
        ("solid nothing\n", ("not a PLY file",)),
        ("ply\nformat ascii 1.0\nelement vertex 1\n", ("end_header",)),
        ("ply\nformat text 1.0\nend_header\n", ("unknown PLY format",)),
        ("ply\nelement vertex 0\nend_header\n", ("no 'format'",)),
        ("ply\nformat ascii 1.0\nproperty float x\nend_header\n", ("before any element",)),
        ("ply\nformat ascii 1.0\nelement vertex 1\nproperty half x\nend_header\n", ("half",)),
        (
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n1\n",
            ("no y, z coordinate",),
        ),
        ("ply\nformat ascii 1.0\nelement face 0\nend_header\n", ("no 'vertex' element",)),
        (
            "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\n"
            "property float z\nend_header\n",
            ("no vertices",),
        ),
        (
            "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
            "property float z\nend_header\n0 0 0\n1 nan 0\n",
            ("not finite", "vertex 1"),
        ),
        (
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
            "property float z\nend_header\n0 zero 0\n",
            ("not a number",),
        ),
        (
            "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
            "property float z\nend_header\n0 0 0\n",
            ("truncated", "vertex"),
        ),
        (
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
            "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
            "0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n",
            ("out of range", "vertex 3", "3 vertices"),
        ),
        (
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
            "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
            "0 0 0\n1 0 0\n0 1 0\n3 0 1.5 2\n",
            ("not a valid int32",),
        ),
        (
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
            "property float z\nelement face 1\nproperty list uchar float vertex_indices\n"
            "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
            ("must be integers",),
        ),
    ],
)
def test_malformed_ply(tmp_path, text, fragments):
    expect_error(write_text(tmp_path / "bad.ply", text), *fragments)


@pytest.mark.parametrize("kind", ["triangles", "mixed"])
@pytest.mark.parametrize("cut", ["vertices", "faces"])
def test_truncated_binary_ply(tmp_path, kind, cut):
    points, faces = grid_polygons(kind)
    data = ply_bytes(
        "binary_little_endian",
        [
            ("vertex", [(c, "float") for c in "xyz"], points),
            ("face", [("vertex_indices", "list", "uchar", "int")], [(f,) for f in faces]),
        ],
    )
    body = data.index(b"end_header\n") + len(b"end_header\n")
    keep = body + 12 * len(points) - 5 if cut == "vertices" else len(data) - 3
    element = "vertex" if cut == "vertices" else "face"
    (tmp_path / "short.ply").write_bytes(data[:keep])
    expect_error(tmp_path / "short.ply", "truncated", f"'{element}' element")


def test_binary_ply_face_index_out_of_range(tmp_path):
    points, faces = grid_polygons("quads")
    faces[-1] = (0, 1, 2, 99)
    path = tmp_path / "range.ply"
    path.write_bytes(
        ply_bytes(
            "binary_big_endian",
            [
                ("vertex", [(c, "double") for c in "xyz"], points),
                ("face", [("vertex_indices", "list", "uchar", "int")], [(f,) for f in faces]),
            ],
        )
    )
    expect_error(path, "out of range", "vertex 99", "12 vertices")


# ------------------------------------- a value too many or too few: each line read by its header


def wedge_ply_ascii(tmp_path, name="wedge.ply"):
    """An exact 60° wedge written as ASCII PLY: its path, its lines, the header's line count,
    and the vertex and face counts."""
    mesh = wedge(60.0, n=20)
    # A vertex of the crease (z = 0) last, as in the file: a value too many then makes
    # the first face count 0, and the flat reading went on without an error.
    last = int(np.flatnonzero(mesh.points[:, 2] == 0)[-1])
    order = np.r_[np.delete(np.arange(len(mesh.points)), last), last]
    points = mesh.points[order]
    triangles = np.argsort(order)[mesh.triangles]
    path = write_ply(tmp_path / name, points, triangles, binary=False)
    lines = path.read_bytes().split(b"\n")
    header = lines.index(b"end_header") + 1
    return path, lines, header, len(points), len(triangles)


def test_a_stray_value_on_an_ascii_ply_vertex_line_is_refused_with_its_line(tmp_path):
    """Issue 25: " 0.25" appended to one vertex line, 200 lines before the end of the vertex
    block, shifted every later vertex and dropped the last face (42.64° on a 60° wedge)."""
    path, lines, header, n_vertices, _ = wedge_ply_ascii(tmp_path)
    assert read_mesh(path).n_vertices == n_vertices
    stray = header + n_vertices - 200  # 0-based index of the line in the file
    lines[stray] += b" 0.25"
    path.write_bytes(b"\n".join(lines))
    expect_error(path, f"line {stray + 1}:", "4 values", "3")


@pytest.mark.parametrize("where", ["first", "middle", "last"])
def test_an_ascii_ply_face_line_with_an_extra_index_is_refused_with_its_line(tmp_path, where):
    path, lines, header, n_vertices, n_faces = wedge_ply_ascii(tmp_path)
    first_face = header + n_vertices
    at = {"first": first_face, "middle": first_face + n_faces // 2}.get(
        where, first_face + n_faces - 1
    )
    lines[at] += b" 5"
    path.write_bytes(b"\n".join(lines))
    expect_error(path, f"line {at + 1}:", "5 values", "'face'")


@pytest.mark.parametrize("fault", ["a face line missing", "a face line too many"])
def test_an_ascii_ply_with_a_line_missing_or_too_many_is_refused(tmp_path, fault):
    path, lines, header, n_vertices, n_faces = wedge_ply_ascii(tmp_path)
    end = header + n_vertices + n_faces  # index of the line after the last face (blank)
    assert lines[end:] == [b""]
    if fault == "a face line missing":
        del lines[end - 1]
        fragments = (f"line {end}:", f"{n_faces - 1} of the {n_faces}", "'face'")
    else:
        lines.insert(end, b"3 0 1 2")
        fragments = (f"line {end + 1}:", "after the last element")
    path.write_bytes(b"\n".join(lines))
    expect_error(path, *fragments)


def test_an_ascii_ply_vertex_line_missing_is_refused_where_the_faces_begin(tmp_path):
    """A vertex line too few makes the first face line the last vertex: refused there."""
    path, lines, header, n_vertices, _ = wedge_ply_ascii(tmp_path)
    del lines[header + 10]
    path.write_bytes(b"\n".join(lines))
    expect_error(path, f"line {header + n_vertices}:", "4 values", "'vertex'")


def test_an_ascii_ply_face_index_out_of_range_names_its_line(tmp_path):
    path, lines, header, n_vertices, _ = wedge_ply_ascii(tmp_path)
    at = header + n_vertices + 7
    lines[at] = f"3 0 1 {n_vertices}".encode()
    path.write_bytes(b"\n".join(lines))
    expect_error(path, f"line {at + 1}:", f"vertex {n_vertices}", f"{n_vertices} vertices")
    lines[at] = b"3 0 -1 2"
    path.write_bytes(b"\n".join(lines))
    expect_error(path, f"line {at + 1}:", "vertex -1")


def test_ascii_ply_blank_lines_crlf_and_comments_are_read(tmp_path):
    points, faces = grid_polygons("mixed")
    data = ply_bytes(
        "ascii",
        [
            ("vertex", [(c, "double") for c in "xyz"], points),
            ("face", [("vertex_indices", "list", "uchar", "int")], [(f,) for f in faces]),
        ],
        comments=("comment one", "comment 3 0 1 2", "obj_info two"),
    )
    head, body = data.split(b"end_header\n")
    lines = body.split(b"\n")
    lines.insert(5, b"   ")  # a blank line among the vertices
    body = b"\r\n".join(b"\t" + line + b"  " for line in lines) + b"\n\n \r\n"
    path = tmp_path / "blank.ply"
    path.write_bytes(head + b"end_header\n" + body)
    mesh = read_mesh(path)
    assert np.array_equal(mesh.points, np.array(points))
    assert mesh.triangles.tolist() == [list(t) for t in fan(faces)]


def test_ascii_ply_lists_in_other_elements_are_checked_line_by_line(tmp_path):
    """A vertex list property and an extra face list: each line's length follows its counts."""
    points, faces = grid_polygons("quads")
    elements = [
        ("vertex", [("x", "float"), ("tags", "list", "uchar", "int"), ("y", "float"),
                    ("z", "float")], [(p[0], [1] * (i % 3), p[1], p[2]) for i, p in
                                      enumerate(points)]),
        ("face", [("vertex_indices", "list", "uchar", "int"), ("uv", "list", "int", "float")],
         [(f, [0.5] * k) for k, f in enumerate(faces)]),
    ]  # fmt: skip
    path = tmp_path / "lists.ply"
    data = ply_bytes("ascii", elements)
    path.write_bytes(data)
    mesh = read_mesh(path)
    assert np.array_equal(mesh.points, np.array(points, np.float32))
    lines = data.split(b"\n")
    header = lines.index(b"end_header") + 1
    for at, change, fragment in [
        (header + 2, b" 7", "'vertex'"),  # one tag too many
        (header + len(points) + 3, b" 0.5", "'face'"),  # one uv too many
    ]:
        changed = [*lines[:at], lines[at] + change, *lines[at + 1 :]]
        path.write_bytes(b"\n".join(changed))
        expect_error(path, f"line {at + 1}:", fragment)
    changed = list(lines)
    changed[header + len(points)] = b"9 0 1 5 4"  # a count larger than the line holds
    path.write_bytes(b"\n".join(changed))
    expect_error(path, f"line {header + len(points) + 1}:", "'face'")


PLY_XYZ_HEAD = b"ply\nformat ascii 1.0\nelement vertex 3\n" + b"".join(
    b"property float %s\n" % c for c in (b"x", b"y", b"z")
)


def test_a_ply_header_count_in_non_ascii_digits_is_refused_cleanly(tmp_path):
    """Latin-1 "²" is a digit to str.isdigit(), not to int(): it raised a bare ValueError."""
    path = tmp_path / "digit.ply"
    path.write_bytes(PLY_XYZ_HEAD.replace(b"vertex 3", b"vertex \xb2") + b"end_header\n")
    expect_error(path, "header line 3", "element <name> <count>")


@pytest.mark.parametrize("fmt", FORMATS)
def test_a_ply_vertex_with_two_x_properties_is_refused(tmp_path, fmt):
    """Two 'x' properties: the first one's type was reported, the last one's values read."""
    props = [("x", "float"), ("y", "float"), ("z", "float"), ("x", "double")]
    rows = [(0.0, 0.0, 0.0, 9.0), (1.0, 0.0, 0.0, 9.0), (0.0, 1.0, 0.0, 9.0)]
    path = tmp_path / "two_x.ply"
    path.write_bytes(ply_bytes(fmt, [("vertex", props, rows)]))
    expect_error(path, "more than one 'x'")


@pytest.mark.parametrize("fmt", FORMATS)
def test_ply_normals_that_are_lists_are_ignored(tmp_path, fmt):
    """An 'nx' list is no normal: the points are read, the normals left out (it raised)."""
    props = [("x", "float"), ("y", "float"), ("z", "float"), ("nx", "list", "uchar", "float"),
             ("ny", "float"), ("nz", "float")]  # fmt: skip
    rows = [(*p, [5.0], 0.0, 1.0) for p in ((0, 0, 0), (1, 0, 0), (0, 1, 0))]
    path = tmp_path / "list_nx.ply"
    path.write_bytes(ply_bytes(fmt, [("vertex", props, rows)]))
    mesh = read_mesh(path)
    assert mesh.points.tolist() == [[0, 0, 0], [1, 0, 0], [0, 1, 0]] and mesh.normals is None


@pytest.mark.parametrize("sign", [b"-", b"+"])
@pytest.mark.parametrize("where", ["last value", "inside"])
def test_a_lone_sign_in_ascii_ply_faces_is_not_a_number(tmp_path, sign, where):
    """NumPy's integer text parser reads a lone sign as 0 (or joins it to the next number):
    whole-number face lists are parsed as integers for speed, so this must still be refused."""
    points, faces = grid_polygons("triangles")
    data = ply_bytes(
        "ascii",
        [
            ("vertex", [(c, "float") for c in "xyz"], points),
            ("face", [("vertex_indices", "list", "uchar", "int")], [(f,) for f in faces]),
        ],
    )
    lines = data.rstrip(b"\n").split(b"\n")
    at = len(lines) - 1 if where == "last value" else len(lines) - 3
    lines[at] = lines[at].rsplit(b" ", 1)[0] + b" " + sign
    if where == "inside":
        lines[at] += b" 1"
    path = tmp_path / "sign.ply"
    path.write_bytes(b"\n".join(lines))
    expect_error(path, f"line {at + 1}", repr(sign.decode()), "not a number")


@pytest.mark.parametrize("short", ["vertex", "face"])
def test_a_binary_ply_with_a_record_more_than_its_header_declares_is_refused(tmp_path, short):
    """The header's count one short of the data: the last point or face was dropped with no
    error (an ASCII PLY with the same fault was refused). A byte or two of padding is not a
    record, and is still read."""
    points = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 0.5, 1.25]]
    faces = [[0, 1, 2, 3], [0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]]
    vertex_header = "element vertex {}\nproperty float x\nproperty float y\nproperty float z\n"
    face_header = "element face {}\nproperty list uchar int vertex_indices\n"
    body = b"".join(struct.pack("<3f", *p) for p in points)
    if short == "vertex":
        header = vertex_header.format(4)
    else:
        header = vertex_header.format(5) + face_header.format(4)
        body += b"".join(struct.pack(f"<B{len(f)}i", len(f), *f) for f in faces)
    start = f"ply\nformat binary_little_endian 1.0\n{header}end_header\n".encode()
    (tmp_path / "short.ply").write_bytes(start + body)
    expect_error(tmp_path / "short.ply", "follow the last element", f"4 '{short}'")
    if short == "face":
        whole = start.replace(b"face 4", b"face 5")
        (tmp_path / "padded.ply").write_bytes(whole + body + b"\n")
        assert read_mesh(tmp_path / "padded.ply").triangles.shape == (6, 3)
