"""Every file reader against mutated valid files (hypothesis): the numbers the file holds or a
GoniometerError that names the file, never another exception, never a hang, never a runaway
allocation.

Each seed is a small valid file of one format; hypothesis applies a few mutations (byte flips,
insertions of troublesome tokens, deletions, truncations, duplicated spans, replaced words, a
value appended to a line, a line dropped or repeated) and the reader must either return sound
data or refuse with a message naming the file. Sound means exactly what an independent oracle
in this file reads: a plain-Python parser that takes text formats one line at a time and binary
ones one record at a time with ``struct`` (so a value too many can no longer shift the numbers
that follow it unnoticed). Every call runs under an alarm (a hang fails the test), its peak
allocation is traced (more than 64 MiB for a few-kB file fails it) and the process's address
space is capped (so a forged size fails before it can exhaust the machine).
"""

from __future__ import annotations

import contextlib
import math
import os
import re
import resource
import signal
import struct
import tempfile
import tracemalloc
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from vg_addon import GoniometerError
from vg_addon.formats import csvio, meshio

pytestmark = pytest.mark.skipif(
    not hasattr(signal, "SIGALRM") or not hasattr(resource, "RLIMIT_AS"),
    reason="needs POSIX alarms and address-space limits",
)

SECONDS_PER_CALL = 5  # a reader takes milliseconds on these few-kB files
PEAK_BYTES = 64 << 20  # memory a call may allocate at its peak (the inputs are a few kB)
# Address space a call may add: a safety net that stops a forged size before it reaches the
# machine's memory (an allocator that reuses address space it already holds can slip under
# it, so the peak above, traced by tracemalloc, is the bound the test checks).
EXTRA_ADDRESS_SPACE = 1 << 30

# A small mesh: a quad-topped tetrahedron-like solid with a quad face, so readers see both
# triangles and polygons.
POINTS = np.array(
    [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 0.5, 1.25], [0.5, -0.75, 0.5]],
    dtype=np.float64,
)
TRIANGLES = [[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4], [0, 5, 1]]
QUAD = [0, 3, 2, 1]


def ply_ascii() -> bytes:
    head = [
        "ply",
        "format ascii 1.0",
        "comment fuzz seed",
        f"element vertex {len(POINTS)}",
        "property float x",
        "property float y",
        "property float z",
        "property float nx",
        "property float ny",
        "property float nz",
        f"element face {len(TRIANGLES) + 1}",
        "property list uchar int vertex_indices",
        "end_header",
    ]
    body = [" ".join(f"{v:g}" for v in (*p, 0.0, 0.0, 1.0)) for p in POINTS]
    body += [" ".join(map(str, [len(f), *f])) for f in [*TRIANGLES, QUAD]]
    return ("\n".join(head + body) + "\n").encode()


def ply_binary(order: str, coord: str) -> bytes:
    endian = "<" if order == "little" else ">"
    fmt = {"float": "f", "double": "d"}[coord]
    head = (
        f"ply\nformat binary_{order}_endian 1.0\nelement vertex {len(POINTS)}\n"
        f"property {coord} x\nproperty {coord} y\nproperty {coord} z\n"
        f"element face {len(TRIANGLES) + 1}\nproperty list uchar uint vertex_indices\n"
        "element extra 1\nproperty short flag\nend_header\n"
    ).encode()
    body = b"".join(struct.pack(endian + fmt * 3, *p) for p in POINTS)
    for face in [*TRIANGLES, QUAD]:
        body += struct.pack(endian + "B" + "I" * len(face), len(face), *face)
    return head + body + struct.pack(endian + "h", 7)


def obj_text() -> bytes:
    lines = ["# fuzz seed", "o solid"]
    lines += [f"v {x:g} {y:g} {z:g}" for x, y, z in POINTS]
    lines += ["vn 0 0 1", "vt 0.5 0.5"]
    lines += [f"f {a + 1}//1 {b + 1}/1/1 {c + 1}" for a, b, c in TRIANGLES[:-1]]
    lines += ["f -6 -1 -5", "f " + " ".join(str(i + 1) for i in QUAD)]
    return ("\n".join(lines) + "\n").encode()


def stl_ascii() -> bytes:
    lines = ["solid fuzz"]
    for face in TRIANGLES:
        lines += ["  facet normal 0 0 1", "    outer loop"]
        lines += [f"      vertex {x:g} {y:g} {z:g}" for x, y, z in POINTS[face]]
        lines += ["    endloop", "  endfacet"]
    lines.append("endsolid fuzz")
    return ("\n".join(lines) + "\n").encode()


def stl_binary() -> bytes:
    data = b"fuzz seed".ljust(80, b" ") + struct.pack("<I", len(TRIANGLES))
    for face in TRIANGLES:
        data += struct.pack("<3f", 0, 0, 1)
        data += b"".join(struct.pack("<3f", *POINTS[i]) for i in face)
        data += b"\0\0"
    return data


def export_csv() -> bytes:
    row = csvio.MeasurementRow(
        mesh_name="bone_12",
        date="2024-05-01T14:03:11+02:00",
        number=1,
        break_number=2,
        colors="#E69F00/#0072B2",
        user_data="=ridge, proximal",
        angle=97.5,
        n_vertices=812,
        radius=3.0,
        x=1.25,
        y=-2.5,
        z=0.1,
        fit=0.0123,
        lam=2.0,
        patch="euclidean",
        n_plus=400,
        n_minus=412,
        fit_plus=0.01,
        fit_minus=0.0023,
        normal_plus=(0.0, 0.0, 1.0),
        normal_minus=(1.0, 0.0, 0.0),
        requested=(1.2, -2.5, 0.1),
        snap_distance=0.05,
        units="mm",
    )
    return csvio.format_measurements_csv([row, row]).encode()


MESHLAB_CSV = (
    b"Mesh Name,Date,Measurement #,Break #,Colors,User Data,Angle,Number of Vertices,Radius,"
    b"x,y,z,fit,SegParam\n"
    b"bone.ply,Tue Mar  2 14:03:11 2021,1,1,Red/Blue, ,97.12,1234,3.0,1.2,-2.3,0.1,0.01,2.0\n"
    b'bone.ply,Tue Mar  2 14:05:40 2021,2.05,2,Red/Green,"a, b",121.5,98,0.8,10,20,30,fill,1.5\n'
)
POINTS_CSV = b"x,y,z,radius,lambda,patch,label\n0,0,0,0.5,2,geodesic,a\n1,2,3,,,,\n"

MESH_SEEDS = {
    "ascii.ply": ply_ascii(),
    "little.ply": ply_binary("little", "double"),
    "big.ply": ply_binary("big", "float"),
    "mesh.obj": obj_text(),
    "ascii.stl": stl_ascii(),
    "binary.stl": stl_binary(),
}
CSV_SEEDS = {
    "export.csv": export_csv(),
    "meshlab.csv": MESHLAB_CSV,
    "points.csv": POINTS_CSV,
}

# Text that readers meet in damaged or hostile files.
TOKENS = [
    b" ",
    b"\n",
    b"\r\n",
    b"\t",
    b",",
    b'"',
    b";",
    b"#",
    b"/",
    b"//",
    b"-",
    b"+",
    b".",
    b"e",
    b"0",
    b"-1",
    b"1.5",
    b"nan",
    b"inf",
    b"-inf",
    b"1e999",
    b"1e-999",
    b"255",
    b"256",
    b"65536",
    b"2147483648",
    b"4294967295",
    b"-2147483649",
    b"18446744073709551616",
    b"9" * 30,
    b"\x00",
    b"\xff\xfe",
    b"\xef\xbb\xbf",
    b"\xc3\x28",
    b"ply",
    b"end_header",
    b"element vertex 4000000000\n",
    b"element face 99999999999\n",
    b"property double x\n",
    b"property list uchar int vertex_indices\n",
    b"property list int int vertex_indices\n",
    b"format binary_big_endian 1.0\n",
    b"format ascii 1.0\n",
    b"v 1 2 3\n",
    b"f 1 2 3 4 5\n",
    b"f 0 0 0\n",
    b"facet normal",
    b"vertex 1 2 3",
    b"solid",
    b"endsolid",
    b"x,y,z\n",
    b"Break #",
    b"SegParam",
    b"0.25",
    b"3 0 1 2",
]

_fraction = st.floats(min_value=0.0, max_value=1.0)
MUTATION = st.one_of(
    st.tuples(st.just("flip"), _fraction, st.integers(0, 255)),
    st.tuples(st.just("insert"), _fraction, st.sampled_from(TOKENS)),
    st.tuples(st.just("delete"), _fraction, st.integers(1, 64)),
    st.tuples(st.just("truncate"), _fraction),
    st.tuples(st.just("duplicate"), _fraction, st.integers(1, 256)),
    st.tuples(st.just("word"), _fraction, st.sampled_from(TOKENS)),
)
# Mesh files also lose a line, repeat one or get a value appended to one: a count that no longer
# matches the lines must be refused, never read shifted. (A CSV that loses its rows to these is
# a valid empty CSV, hence mesh files only.)
MESH_MUTATION = st.one_of(
    MUTATION,
    st.tuples(st.just("append"), _fraction, st.sampled_from(TOKENS)),
    st.tuples(st.just("line"), _fraction, st.sampled_from(["drop", "repeat"])),
)


def mutate(data: bytes, mutations) -> bytes:
    buffer = bytearray(data)
    for mutation in mutations:
        at = int(mutation[1] * len(buffer))
        if mutation[0] == "flip" and buffer:
            buffer[min(at, len(buffer) - 1)] = mutation[2]
        elif mutation[0] == "insert":
            buffer[at:at] = mutation[2]
        elif mutation[0] == "delete":
            del buffer[at : at + mutation[2]]
        elif mutation[0] == "truncate":
            del buffer[at:]
        elif mutation[0] == "duplicate":
            buffer[at:at] = buffer[at : at + mutation[2]]
        elif mutation[0] == "word":
            words = bytes(buffer).split(b" ")
            words[min(int(mutation[1] * len(words)), len(words) - 1)] = mutation[2]
            buffer = bytearray(b" ".join(words))
        elif mutation[0] in ("append", "line"):
            lines = bytes(buffer).split(b"\n")
            k = min(int(mutation[1] * len(lines)), len(lines) - 1)
            if mutation[0] == "append":
                lines[k] += b" " + mutation[2]
            elif mutation[2] == "drop":
                del lines[k]
            else:
                lines.insert(k, lines[k])
            buffer = bytearray(b"\n".join(lines))
    return bytes(buffer)


class _TimeoutError(Exception):
    pass


def _alarm(signum, frame):
    raise _TimeoutError


def _address_space() -> int:
    with open("/proc/self/statm") as handle:
        return int(handle.read().split()[0]) * resource.getpagesize()


@contextlib.contextmanager
def bounded(seconds: int, extra: int):
    """Fail a call that runs longer than ``seconds`` or maps more than ``extra`` new bytes."""
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    cap = _address_space() + extra
    if hard != resource.RLIM_INFINITY:
        cap = min(cap, hard)
    previous = signal.signal(signal.SIGALRM, _alarm)
    resource.setrlimit(resource.RLIMIT_AS, (cap, hard))
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        resource.setrlimit(resource.RLIMIT_AS, (soft, hard))
        signal.signal(signal.SIGALRM, previous)


def check_call(read, path: Path, peak_bytes: int = PEAK_BYTES):
    """Run ``read(path)`` bounded; return its result or the GoniometerError it raised."""
    too_much = f"{read.__name__} tried to allocate more than {peak_bytes >> 20} MiB"
    started = not tracemalloc.is_tracing()
    if started:
        tracemalloc.start()
    tracemalloc.reset_peak()
    try:
        with bounded(SECONDS_PER_CALL, EXTRA_ADDRESS_SPACE):
            result = read(path)
    except GoniometerError as error:
        message = str(error)
        assert path.name in message, f"the message does not name the file: {message}"
        assert "Traceback" not in message and len(message) < 5000
        result = error
    except _TimeoutError:
        pytest.fail(f"{read.__name__} did not finish within {SECONDS_PER_CALL} s")
    except MemoryError:
        pytest.fail(too_much)
    finally:
        peak = tracemalloc.get_traced_memory()[1]
        if started:
            tracemalloc.stop()
    if peak > peak_bytes:
        pytest.fail(too_much)
    return result


def assert_sound_mesh(mesh: meshio.MeshData):
    assert mesh.points.ndim == 2 and mesh.points.shape[1] == 3 and mesh.n_vertices > 0
    assert np.isfinite(mesh.points).all()
    if mesh.triangles is not None:
        assert mesh.triangles.ndim == 2 and mesh.triangles.shape[1] == 3
        assert mesh.triangles.min() >= 0 and mesh.triangles.max() < mesh.n_vertices
    if mesh.normals is not None:
        assert mesh.normals.shape == mesh.points.shape and np.isfinite(mesh.normals).all()


def assert_sound_rows(rows, data: bytes):
    # No rows only from a file of a header alone (an export of no measurements reads back so).
    assert rows or not [line for line in data.split(b"\n")[1:] if line.strip(b' \t\r,"')]
    for row in rows:
        values = [row.x, row.y, row.z] if hasattr(row, "row_number") else []
        assert all(math.isfinite(v) for v in values)
        if hasattr(row, "row_number"):
            assert row.radius is None or row.radius > 0
            assert row.lam is None or row.lam >= 0
            assert row.break_number is None or 1 <= row.break_number <= csvio.MAX_BREAK_NUMBER


# ------------------------------------------------------ the oracle: an independent, plain reader


class RefusedError(Exception):
    """The oracle finds the file malformed."""


STRUCT_CODES = {
    "char": "b", "int8": "b", "uchar": "B", "uint8": "B", "short": "h", "int16": "h",
    "ushort": "H", "uint16": "H", "int": "i", "int32": "i", "uint": "I", "uint32": "I",
    "float": "f", "float32": "f", "double": "d", "float64": "d",
}  # fmt: skip
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


FUZZ = settings(
    max_examples=60,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)


@pytest.mark.parametrize("seed", MESH_SEEDS)
def test_the_mesh_seeds_are_valid(seed):
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / seed
        path.write_bytes(MESH_SEEDS[seed])
        mesh = meshio.read_mesh(path)
    assert mesh.n_vertices == len(POINTS) and mesh.n_triangles in (5, 7)
    assert_reads_like_the_oracle(seed, MESH_SEEDS[seed], mesh)
    # STL merges corners into vertices in order of first use: compare the sets of points
    np.testing.assert_allclose(np.unique(mesh.points, axis=0), np.unique(POINTS, axis=0), atol=1e-6)


@pytest.mark.parametrize("seed", MESH_SEEDS)
@FUZZ
@given(mutations=st.lists(MESH_MUTATION, min_size=1, max_size=4))
def test_mesh_readers_on_mutated_files(seed, mutations):
    data = mutate(MESH_SEEDS[seed], mutations)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / seed
        path.write_bytes(data)
        result = check_call(meshio.read_mesh, path)
    if isinstance(result, meshio.MeshData):
        assert_sound_mesh(result)
        assert_reads_like_the_oracle(seed, data, result)


@pytest.mark.parametrize("seed", CSV_SEEDS)
@FUZZ
@given(mutations=st.lists(MUTATION, min_size=1, max_size=4))
def test_csv_readers_on_mutated_files(seed, mutations):
    data = mutate(CSV_SEEDS[seed], mutations)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / seed
        path.write_bytes(data)
        for read in (csvio.read_replication_csv, csvio.read_measurements_csv):
            result = check_call(read, path)
            if isinstance(result, list):
                assert_sound_rows(result, data)


def test_the_csv_seeds_are_valid():
    with tempfile.TemporaryDirectory() as folder:
        for name, data in CSV_SEEDS.items():
            path = Path(folder) / name
            path.write_bytes(data)
            assert len(csvio.read_replication_csv(path)) == 2
        assert len(csvio.read_measurements_csv(Path(folder) / "export.csv")) == 2


def test_a_forged_vertex_count_is_refused_without_allocating_it(tmp_path):
    path = tmp_path / "forged.ply"
    path.write_bytes(
        MESH_SEEDS["little.ply"].replace(b"element vertex 6", b"element vertex 4000000000")
    )
    result = check_call(meshio.read_mesh, path)
    assert isinstance(result, GoniometerError)


def test_the_bounds_catch_a_hang_and_a_runaway_allocation(tmp_path):
    path = tmp_path / "x.ply"
    path.write_bytes(b"ply\n")

    def hang(_path):
        while True:
            pass

    def hog(_path):
        # Far past the cap: freed memory a long test session keeps mapped cannot absorb it
        # (np.empty: were the cap ever missing, nothing would be touched).
        return np.empty(PEAK_BYTES // 8 + (1 << 31))

    for function, why in ((hang, "did not finish"), (hog, "tried to allocate")):
        with pytest.raises(pytest.fail.Exception, match=why):
            check_call(function, path)
    assert os.path.exists(path)


def test_a_word_in_ascii_ply_data_is_named_with_its_line(tmp_path):
    path = tmp_path / "word.ply"
    path.write_bytes(MESH_SEEDS["ascii.ply"].replace(b"\n1 0 0 ", b"\n1 0 zero "))
    with pytest.raises(GoniometerError, match=r"'.*word\.ply', line 15 \('zero'\): .*not a number"):
        meshio.read_mesh(path)


def test_an_index_out_of_range_names_its_line(tmp_path):
    path = tmp_path / "index.ply"
    path.write_bytes(MESH_SEEDS["ascii.ply"].replace(b"\n3 2 3 4\n", b"\n3 2 3 40\n"))
    with pytest.raises(GoniometerError, match=r"'.*index\.ply', line 22: .*vertex 40 "):
        meshio.read_mesh(path)
