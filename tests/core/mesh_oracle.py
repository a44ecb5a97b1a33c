"""The mesh readers' oracle: an independent plain-Python reader of PLY, OBJ and STL that takes
text formats one line at a time and binary ones one record at a time with ``struct``, so a value
too many can no longer shift the numbers that follow it unnoticed. test_reader_fuzz.py holds
every accepted mutated file to exactly its numbers."""

from __future__ import annotations

import math
import re
import struct

import numpy as np
import pytest
from mesh_files import STRUCT_CODES

from vg_addon.formats import meshio


class RefusedError(Exception):
    """The oracle finds the file malformed."""


INTEGER = re.compile(rb"-?[0-9]{1,18}")
PLY_FORMATS = (b"ascii", b"binary_little_endian", b"binary_big_endian")


def oracle(name: str, data: bytes):
    """``(points, triangles, normals, source_dtype)`` of a mesh file as lists (``None`` for no
    triangles or normals), read with plain Python; raises RefusedError for a malformed file."""
    suffix = name.rsplit(".", 1)[-1]
    read = {"ply": oracle_ply, "obj": oracle_obj, "stl": oracle_stl}[suffix]
    points, faces, normals, source_dtype = read(data)
    if not points:
        raise RefusedError("no vertices")
    if not all(math.isfinite(v) for point in points for v in point):
        raise RefusedError("a coordinate is not finite")
    if any(not 0 <= i < len(points) for face in faces for i in face):
        raise RefusedError("a face index out of range")
    triangles = [(f[0], f[k], f[k + 1]) for f in faces for k in range(1, len(f) - 1)]
    if normals is not None and (
        len(normals) != len(points) or not all(math.isfinite(v) for n in normals for v in n)
    ):
        normals = None
    return points, triangles or None, normals, source_dtype


def number(word: bytes) -> float:
    try:
        return float(word)
    except ValueError:
        raise RefusedError(f"{word!r} is not a number") from None


def typed(value: float, code: str):
    """An ASCII PLY value as its declared type (a struct code) stores it."""
    if code == "f":
        return float(np.float32(value))
    if code == "d":
        return value
    bits = 8 * struct.calcsize(code)
    low, high = (
        (-(1 << (bits - 1)), (1 << (bits - 1)) - 1) if code.islower() else (0, (1 << bits) - 1)
    )
    if not (value.is_integer() and low <= value <= high):
        raise RefusedError(f"{value} is not a valid {code} integer")
    return int(value)


def oracle_ply(data: bytes):
    if not data.startswith((b"ply\n", b"ply\r")):
        raise RefusedError("not a PLY file")
    fmt, elements, pos = None, [], 0
    while True:  # the header, one line at a time
        end = data.find(b"\n", pos)
        if end < 0:
            raise RefusedError("no end_header")
        words, pos = data[pos:end].split(), end + 1
        if not words or words[0] in (b"ply", b"comment", b"obj_info"):
            continue
        if words[0] == b"end_header":
            break
        if words[0] == b"format":
            if len(words) < 2 or words[1] not in PLY_FORMATS:
                raise RefusedError("unknown format")
            fmt = words[1]
        elif words[0] == b"element":
            if len(words) != 3 or not re.fullmatch(rb"[0-9]+", words[2]):
                raise RefusedError("bad element line")
            elements.append((words[1].decode("latin-1"), int(words[2]), []))
        elif words[0] == b"property":
            if not elements:
                raise RefusedError("a property before any element")
            types = [w.decode("latin-1") for w in words[1:]]
            if len(words) >= 2 and words[1] == b"list":
                if len(words) != 5 or not {types[1], types[2]} <= STRUCT_CODES.keys():
                    raise RefusedError("bad list property")
                if STRUCT_CODES[types[1]] in "fd":
                    raise RefusedError("a floating-point list count")
                prop = (types[3], STRUCT_CODES[types[2]], STRUCT_CODES[types[1]])
            elif len(words) != 3 or types[0] not in STRUCT_CODES:
                raise RefusedError("bad property")
            else:
                prop = (types[1], STRUCT_CODES[types[0]], None)
            elements[-1][2].append(prop)
    if fmt is None:
        raise RefusedError("no format")

    vertex = next((e for e in elements if e[0] == "vertex"), None)
    if vertex is None:
        raise RefusedError("no vertex element")
    scalars = {p[0]: p for p in reversed(vertex[2]) if p[2] is None}  # the first of each name
    if not {"x", "y", "z"} <= scalars.keys():
        raise RefusedError("no x, y, z coordinates (or one is a list)")
    wanted = {"vertex": ["x", "y", "z"]}
    if {"nx", "ny", "nz"} <= scalars.keys():
        wanted["vertex"] += ["nx", "ny", "nz"]
    face = next((e for e in elements if e[0] == "face"), None)
    if face is not None:
        lists = [p for p in face[2] if p[2] is not None]
        chosen = [p for p in lists if p[0] in ("vertex_indices", "vertex_index")][:1]
        chosen = chosen or (lists if len(lists) == 1 else [])
        if not chosen or chosen[0][1] in "fd":
            raise RefusedError("no integer vertex_indices list")
        wanted["face"] = [chosen[0][0]]
    for element in (vertex, face or ("face", 0, [])):
        for name in wanted.get(element[0], []):
            if [p[0] for p in element[2]].count(name) > 1:
                raise RefusedError(f"two {name!r} properties")

    read = oracle_ply_ascii if fmt == b"ascii" else oracle_ply_binary
    order = "<" if fmt == b"binary_little_endian" else ">"
    found = read(data, pos, elements, wanted, order)
    rows = found["vertex"]
    points = [[row["x"], row["y"], row["z"]] for row in rows]
    normals = (
        [[row["nx"], row["ny"], row["nz"]] for row in rows] if "nx" in wanted["vertex"] else None
    )
    faces = [row[wanted["face"][0]] for row in found.get("face", [])]
    name_of = {"f": "float32", "d": "float64", "b": "int8", "B": "uint8", "h": "int16",
               "H": "uint16", "i": "int32", "I": "uint32"}  # fmt: skip
    return points, faces, normals, name_of[scalars["x"][1]]


def oracle_ply_ascii(data, pos, elements, wanted, order):
    """One record per non-blank line; each line holds exactly its properties' values."""
    records = iter([line.split() for line in data[pos:].split(b"\n") if line.split()])
    found = {}
    for name, count, props in elements:
        need = wanted.get(name, []) if name not in found else []
        rows = []
        for _ in range(count):
            words = next(records, None)
            if words is None:
                raise RefusedError(f"fewer {name} lines than declared")
            values = [number(w) for w in words]
            row, at = {}, 0
            for prop, code, count_code in props:
                if count_code is None:
                    if at >= len(values):
                        raise RefusedError("a value too few")
                    value, at = values[at], at + 1
                    if prop in need:
                        row.setdefault(prop, typed(value, code))
                    continue
                if at >= len(values) or not values[at].is_integer() or values[at] < 0:
                    raise RefusedError("a bad list count")
                k = int(values[at])
                items, at = values[at + 1 : at + 1 + k], at + 1 + k
                if len(items) != k:
                    raise RefusedError("a list too short")
                if prop in need:
                    row.setdefault(prop, [typed(v, code) for v in items])
            if at != len(values):
                raise RefusedError("a value too many")
            rows.append(row)
        if need:
            found[name] = rows
    if next(records, None) is not None:
        raise RefusedError("lines after the last element")
    return found


def oracle_ply_binary(data, pos, elements, wanted, order):
    """One record at a time with struct; stops once the wanted elements are read."""
    found = {}
    for name, count, props in elements:
        if all(n in found for n in wanted):
            break
        need = wanted.get(name, []) if name not in found else []
        if not props:
            continue  # records of no bytes
        rows = []
        for _ in range(count):
            row = {}
            for prop, code, count_code in props:
                try:
                    if count_code is None:
                        value = struct.unpack_from(order + code, data, pos)[0]
                        pos += struct.calcsize(code)
                    else:
                        k = struct.unpack_from(order + count_code, data, pos)[0]
                        if k < 0:
                            raise RefusedError("a negative list count")
                        pos += struct.calcsize(count_code)
                        value = list(struct.unpack_from(f"{order}{k}{code}", data, pos))
                        pos += k * struct.calcsize(code)
                except struct.error:
                    raise RefusedError(f"truncated in {name}") from None
                if prop in need:
                    row.setdefault(prop, value)
            rows.append(row)
        if need:
            found[name] = rows
    return found


def oracle_obj(data: bytes):
    data = data.removeprefix(b"\xef\xbb\xbf")  # a UTF-8 byte-order mark is not a word
    points, faces, vn_lines = [], [], []
    vertex_refs, normal_refs, n_f_lines, vn_before = [], [], 0, []
    for line in data.split(b"\n"):
        words = line.split()
        if not words:
            continue
        if words[0] == b"v":
            values = [number(w) for w in words[1:]]
            if len(values) not in (3, 4, 6):
                raise RefusedError("a 'v' line without 3, 4 or 6 numbers")
            points.append(values[:3])
        elif words[0] == b"vn":
            vn_lines.append(words[1:])
        elif words[0] == b"f":
            n_f_lines += 1
            face = []
            for corner in words[1:]:
                parts = corner.split(b"/")
                if len(parts) > 3 or not all(INTEGER.fullmatch(p) for p in parts if p):
                    raise RefusedError(f"bad corner {corner!r}")
                if not parts[0] or not parts[-1] or (len(parts) == 2 and not parts[1]):
                    raise RefusedError(f"bad corner {corner!r}")
                i = int(parts[0])
                if i == 0:
                    raise RefusedError("face index 0")
                face.append(i - 1 if i > 0 else i + len(points))
                normal = int(parts[2]) if len(parts) == 3 else None
                vertex_refs.append(face[-1])
                normal_refs.append(normal)
                vn_before.append(len(vn_lines))
            faces.append(face)
    normals = None
    if vn_lines and len(vn_lines) == len(points):
        normals = [[number(w) for w in words] for words in vn_lines]
        if any(len(n) != 3 for n in normals):
            raise RefusedError("a 'vn' line without 3 numbers")
        if n_f_lines:
            resolved = [
                None if n in (None, 0) else n - 1 if n > 0 else n + before
                for n, before in zip(normal_refs, vn_before, strict=True)
            ]
            if not vertex_refs or resolved != vertex_refs:
                normals = None
    return points, faces, normals, "float64"


def oracle_stl(data: bytes):
    declared = int.from_bytes(data[80:84], "little") if len(data) >= 84 else -1
    looks_ascii = data[:1024].lstrip()[:5].lower() == b"solid" and b"\0" not in data[:4096]
    if declared >= 0 and (
        len(data) == 84 + 50 * declared or ((len(data) - 84) // 50 == declared and not looks_ascii)
    ):
        corners = []
        for k in range(declared):
            values = struct.unpack_from("<12fH", data, 84 + 50 * k)
            corners += [list(values[3 * c : 3 * c + 3]) for c in (1, 2, 3)]
        source_dtype = "float32"
    elif looks_ascii:
        facets = []
        for line in data.split(b"\n"):
            words = line.split()
            if words[:1] == [b"facet"]:
                if len(words) != 5:
                    raise RefusedError("a 'facet' line without 3 numbers")
                facets.append([])
            elif words[:1] == [b"vertex"]:
                values = [number(w) for w in words[1:]]
                if len(values) != 3 or not facets:
                    raise RefusedError("a bad 'vertex' line")
                facets[-1].append(values)
        if any(len(f) != 3 for f in facets) or (not facets and declared >= 0):
            raise RefusedError("a facet without 3 vertices, or no facet")
        corners = [c for f in facets for c in f]
        source_dtype = "float64"
    else:
        raise RefusedError("the size does not match the count")
    if not all(math.isfinite(v) for c in corners for v in c):
        raise RefusedError("a coordinate is not finite")
    index = {}  # -0.0 == 0.0 and they hash alike: merged, the first one seen kept
    for corner in corners:
        index.setdefault(tuple(corner), len(index))
    faces = [[index[tuple(c)] for c in corners[k : k + 3]] for k in range(0, len(corners), 3)]
    return [list(p) for p in index], faces, None, source_dtype


def assert_reads_like_the_oracle(name: str, data: bytes, mesh: meshio.MeshData):
    """The reader's numbers are exactly the oracle's (bit for bit, signed zeros included)."""
    try:
        points, triangles, normals, source_dtype = oracle(name, data)
    except RefusedError as why:
        pytest.fail(f"read_mesh accepted {name}, which the oracle refuses: {why}\n{data!r}")

    def same(got, expected):
        expected = np.array(expected, dtype=np.float64).reshape(-1, 3)
        return got.shape == expected.shape and np.array_equal(
            got.view(np.int64), expected.view(np.int64)
        )

    assert same(mesh.points, points), (mesh.points, points, data)
    if triangles is None:
        assert mesh.triangles is None, data
    else:
        assert mesh.triangles is not None and mesh.triangles.tolist() == [
            list(t) for t in triangles
        ], (mesh.triangles, triangles, data)
    assert (mesh.normals is None) == (normals is None), data
    assert normals is None or same(mesh.normals, normals), data
    assert mesh.source_dtype == source_dtype, data
