"""STL files, binary and ASCII: vertices merged into an indexed mesh, malformed files refused."""

import struct

import numpy as np
import pytest
from mesh_files import (
    expect_error,
)

from vg_addon.formats.meshio import read_mesh

# -------------------------------------------------------------------------------------------- STL

CUBE_CORNERS = np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)], float)
CUBE_TRIANGLES = [
    [0, 1, 3],
    [0, 3, 2],
    [4, 6, 7],
    [4, 7, 5],
    [0, 4, 5],
    [0, 5, 1],
    [2, 3, 7],
    [2, 7, 6],
    [0, 2, 6],
    [0, 6, 4],
    [1, 5, 7],
    [1, 7, 3],
]


def stl_binary(corners, header=b"binary stl from a test"):
    data = bytearray(header.ljust(80, b"\0"))
    data += struct.pack("<I", len(corners))
    for triangle in corners:
        data += struct.pack("<3f", 0, 0, 0) + struct.pack("<9f", *np.ravel(triangle)) + b"\0\0"
    return bytes(data)


def stl_ascii(corners):
    lines = ["solid cube"]
    for triangle in corners:
        lines += ["  facet normal 0 0 0", "    outer loop"]
        lines += [f"      vertex {float(x)!r} {float(y)!r} {float(z)!r}" for x, y, z in triangle]
        lines += ["    endloop", "  endfacet"]
    return ("\n".join([*lines, "endsolid cube"]) + "\n").encode()


@pytest.mark.parametrize("flavour", ["binary", "binary solid header", "ascii"])
def test_stl_vertices_are_merged_into_an_indexed_mesh(tmp_path, flavour):
    corners = CUBE_CORNERS[CUBE_TRIANGLES] * 0.1  # 0.1 is not exact in float32
    if flavour == "ascii":
        data = stl_ascii(corners.astype(np.float32).astype(float))
    else:
        data = stl_binary(corners, b"solid cube" if "solid" in flavour else b"cube")
    path = tmp_path / "cube.stl"
    path.write_bytes(data)
    mesh = read_mesh(path)
    assert mesh.n_vertices == 8 and mesh.n_triangles == 12
    assert np.array_equal(mesh.points[mesh.triangles], corners.astype(np.float32).astype(float))
    first_seen = list(dict.fromkeys(np.ravel(CUBE_TRIANGLES)))
    assert np.array_equal(mesh.points, (CUBE_CORNERS[first_seen] * 0.1).astype(np.float32))
    assert mesh.normals is None
    assert mesh.source_dtype == ("float64" if flavour == "ascii" else "float32")


def test_stl_signed_zeros_are_one_vertex(tmp_path):
    corners = np.array(
        [[[-0.0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0.0, -0.0, 0], [0, 1, 0], [1, 0, 0]]]
    )
    path = tmp_path / "zeros.stl"
    path.write_bytes(stl_binary(corners))
    mesh = read_mesh(path)
    assert mesh.n_vertices == 3 and mesh.triangles.tolist() == [[0, 1, 2], [0, 2, 1]]


def test_stl_trailing_bytes_after_binary_data_are_ignored(tmp_path):
    path = tmp_path / "padded.stl"
    path.write_bytes(stl_binary(CUBE_CORNERS[CUBE_TRIANGLES]) + b"\0" * 7)
    assert read_mesh(path).n_triangles == 12


# ------------------------------------------------------------------------------------ malformed


def test_malformed_stl(tmp_path):
    whole = stl_binary(CUBE_CORNERS[CUBE_TRIANGLES])
    path = tmp_path / "bad.stl"
    path.write_bytes(whole[:-20])
    expect_error(path, "truncated", "12 triangles")
    path.write_bytes(stl_binary(CUBE_CORNERS[CUBE_TRIANGLES], b"solid looks like text")[:-20])
    expect_error(path, "truncated")
    path.write_bytes(b"not an stl")
    expect_error(path, "not an STL")
    path.write_bytes(b"solid x\nfacet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n")
    expect_error(path, "line 2:", "2 vertex lines, not 3")
    path.write_bytes(b"solid x\nfacet normal 0 0 0\nouter loop\nvertex 0 0 0 0\n")
    expect_error(path, "line 4", "exactly three", "4 numbers")
    path.write_bytes(stl_binary([[[0, 0, 0], [1, np.nan, 0], [0, 1, 0]]]))
    expect_error(path, "not finite")
    path.write_bytes(stl_binary([]))
    expect_error(path, "no vertices")


def test_ascii_stl_facets_are_read_line_by_line(tmp_path):
    data = stl_ascii(CUBE_CORNERS[CUBE_TRIANGLES])
    lines = data.split(b"\n")
    path = tmp_path / "cube.stl"
    facet = lines.index(b"  facet normal 0 0 0", 10)  # the third facet's line
    for change, fragments in [
        ({facet: b"  facet normal 0 0 0 1"}, (f"line {facet + 1}:", "4 numbers")),
        ({facet: b"  facet normal 0 0"}, (f"line {facet + 1}:", "2 numbers")),
        ({facet + 2: lines[facet + 2] + b" 0.25"}, (f"line {facet + 3}:", "4 numbers")),
    ]:
        changed = [change.get(k, line) for k, line in enumerate(lines)]
        path.write_bytes(b"\n".join(changed))
        expect_error(path, *fragments)
    # A vertex line moved from one facet to the next: still a multiple of three vertex lines.
    moved = [
        *lines[: facet + 2],
        *lines[facet + 3 : facet + 8],
        lines[facet + 2],
        *lines[facet + 8 :],
    ]
    path.write_bytes(b"\n".join(moved))
    expect_error(path, f"line {facet + 1}:", "2 vertex lines")


@pytest.mark.parametrize("count", [0, 6, 11, 13, 24])
def test_binary_stl_whose_header_count_disagrees_with_its_size_is_refused(tmp_path, count):
    """Issue 25: a count of 0 read as "no vertices", half the count read half the triangles."""
    data = bytearray(stl_binary(CUBE_CORNERS[CUBE_TRIANGLES]))
    data[80:84] = struct.pack("<I", count)
    path = tmp_path / "count.stl"
    path.write_bytes(bytes(data))
    expect_error(path, f"declares {count} triangles", "implies 12")


def test_binary_stl_trailing_bytes_are_ignored_only_short_of_a_record(tmp_path):
    whole = stl_binary(CUBE_CORNERS[CUBE_TRIANGLES])
    path = tmp_path / "padded.stl"
    for extra in (1, 49):
        path.write_bytes(whole + b"\0" * extra)
        assert read_mesh(path).n_triangles == 12
    for extra in (50, 51, 120):
        path.write_bytes(whole + b"\0" * extra)
        expect_error(path, "declares 12 triangles", f"implies {12 + extra // 50}")


@pytest.mark.parametrize("cut", ["inside the last number", "after an endfacet"])
def test_a_truncated_ascii_stl_is_refused(tmp_path, cut):
    """An ASCII STL cut short was read as a smaller or different mesh: cut inside the last
    vertex's z (1.25 → 1.2) it gave a wrong corner; cut after an 'endfacet', fewer facets."""
    corners = CUBE_CORNERS[np.array(CUBE_TRIANGLES)].copy()
    corners[-1, -1, 2] = 1.25
    data = stl_ascii(corners)
    if cut == "inside the last number":
        keep = data.rindex(b"1.25") + 3
        expected = "has no 'endfacet'"
    else:
        keep = data.index(b"endfacet", data.index(b"endfacet") + 1) + len(b"endfacet\n")
        expected = "no 'endsolid'"
    (tmp_path / "cut.stl").write_bytes(data[:keep])
    expect_error(tmp_path / "cut.stl", "truncated ASCII STL", expected)
    (tmp_path / "whole.stl").write_bytes(data)
    assert read_mesh(tmp_path / "whole.stl").triangles.shape == (12, 3)


def test_an_ascii_stl_in_capitals_reads_as_in_lower_case(tmp_path):
    """Some writers put the keywords in capitals (SOLID, FACET NORMAL, VERTEX, ENDSOLID): such a
    file was called "truncated ASCII STL: no 'endsolid' line" (found by a review)."""
    lower = stl_ascii(CUBE_CORNERS[CUBE_TRIANGLES])
    (tmp_path / "lower.stl").write_bytes(lower)
    (tmp_path / "upper.stl").write_bytes(lower.upper())
    expected, mesh = read_mesh(tmp_path / "lower.stl"), read_mesh(tmp_path / "upper.stl")
    assert np.array_equal(mesh.points, expected.points) and mesh.n_triangles == 12
    assert np.array_equal(mesh.triangles, expected.triangles)
