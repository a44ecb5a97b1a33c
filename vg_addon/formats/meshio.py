"""Mesh file readers (PLY, OBJ, STL) and a PLY writer, vectorised with NumPy.

``read_mesh(path)`` picks the reader from the file extension and returns a :class:`MeshData`:
float64 points, int64 triangles (polygons are fan-triangulated) or ``None`` for a point cloud,
and per-vertex normals when the file carries them. Every problem with a file is reported as a
:class:`~vg_addon.errors.GoniometerError` whose message names the file and what is wrong.

Parsing never loops in Python over vertices. The one exception is a binary PLY whose faces have
*different* vertex counts: there the start of each face record depends on the count of the
previous one, so the record starts are found with one light Python step per face; all values are
then gathered with NumPy. Text is read line by line, but with NumPy: the values of every line are
counted at once and checked against what the line must hold, so a value too many or too few is
refused with its line number instead of shifting every number after it.
"""

from __future__ import annotations

import os
import re
import struct
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import GoniometerError

__all__ = [
    "MESH_EXTENSIONS",
    "MeshData",
    "read_mesh",
    "read_obj",
    "read_ply",
    "read_stl",
    "write_ply",
]

MESH_EXTENSIONS = (".ply", ".obj", ".stl")  # the file types read (by extension, any case)


@dataclass(frozen=True, eq=False)
class MeshData:
    """A mesh or point cloud read from a file.

    Attributes
    ----------
    points : numpy.ndarray
        ``(n, 3)`` float64 vertex coordinates, in file order.
    triangles : numpy.ndarray or None
        ``(m, 3)`` int64 vertex indices (polygons fan-triangulated, file order kept), or ``None``
        when the file holds no faces (a point cloud).
    normals : numpy.ndarray or None
        ``(n, 3)`` float64 per-vertex normals as stored in the file (not normalised), or ``None``
        when the file has none, they do not map one-to-one to the vertices, or any is not finite.
    name : str
        The file name without its extension.
    source_dtype : str
        Precision of the coordinates in the file: the declared PLY type of ``x`` (``"float32"``,
        ``"float64"``, ...), ``"float32"`` for binary STL, ``"float64"`` for text formats
        without a declared type (OBJ, ASCII STL).
    """

    points: np.ndarray
    triangles: np.ndarray | None
    normals: np.ndarray | None
    name: str
    source_dtype: str

    @property
    def n_vertices(self) -> int:
        """Number of vertices."""
        return int(self.points.shape[0])

    @property
    def n_triangles(self) -> int:
        """Number of triangles (0 for a point cloud)."""
        return 0 if self.triangles is None else int(self.triangles.shape[0])


def read_mesh(path: str | os.PathLike) -> MeshData:
    """Read a ``.ply``, ``.obj`` or ``.stl`` file (extension case-insensitive).

    Parameters
    ----------
    path : str or path-like
        The mesh file.

    Returns
    -------
    MeshData

    Raises
    ------
    GoniometerError
        If the file is missing, unreadable, of an unknown format, truncated or malformed, has no
        vertices, has non-finite coordinates or a face index out of range. Text files are read
        line by line and a bad line is named with its number.
    """
    path = _as_path(path)
    readers = {".ply": read_ply, ".obj": read_obj, ".stl": read_stl}
    reader = readers.get(path.suffix.lower())
    if reader is None:
        kind = f"'{path.suffix}'" if path.suffix else "no extension"
        raise GoniometerError(
            f"Cannot read '{path}': unknown mesh format ({kind}). "
            "The Virtual Goniometer reads .ply, .obj and .stl files; export the mesh as one of them."
        )
    return reader(path)


# ----------------------------------------------------------------------------------------- common


def _as_path(path) -> Path:
    try:
        return Path(os.fspath(path))
    except TypeError:
        raise GoniometerError(
            f"Expected a file path for the mesh, got {type(path).__name__}."
        ) from None


def _read_bytes(path: Path) -> bytes:
    if not path.exists():
        raise GoniometerError(
            f"Mesh file not found: '{path}'. Check the path and that the file was not moved."
        )
    if path.is_dir():
        raise GoniometerError(f"'{path}' is a folder, not a mesh file; choose the file inside it.")
    try:
        data = path.read_bytes()
    except OSError as error:
        raise GoniometerError(
            f"Could not read '{path}': {error.strerror or error}. Check the file's permissions."
        ) from None
    if not data:
        raise GoniometerError(f"'{path}' is empty (0 bytes); re-export the mesh.")
    return data


def _finish(path: Path, points, triangles, normals, source_dtype: str) -> MeshData:
    """Validate what a reader found and pack it into fresh, writable, contiguous arrays."""
    points = np.array(points, dtype=np.float64, order="C").reshape(-1, 3)
    n = points.shape[0]
    if n == 0:
        raise GoniometerError(f"'{path}' has no vertices; the file holds nothing to measure.")
    finite = np.isfinite(points).all(axis=1)
    if not finite.all():
        bad = np.flatnonzero(~finite)
        raise GoniometerError(
            f"'{path}': {bad.size} vertices have coordinates that are not finite (NaN or "
            f"infinity), the first is vertex {bad[0]}. Repair or re-export the mesh."
        )
    if triangles is not None:
        triangles = np.array(triangles, dtype=np.int64, order="C").reshape(-1, 3)
        if triangles.size:
            low, high = int(triangles.min()), int(triangles.max())
            if low < 0 or high >= n:
                bad_value = low if low < 0 else high
                first = int(np.flatnonzero(((triangles < 0) | (triangles >= n)).any(axis=1))[0])
                raise GoniometerError(
                    f"'{path}': face index out of range: a face refers to vertex {bad_value} "
                    f"(counting from 0; the first bad one is in triangle {first}, polygons "
                    f"split into triangles), but the file has {n} vertices (valid 0..{n - 1}). "
                    "The file is corrupt or was written incorrectly; re-export it."
                )
        else:
            triangles = None
    if normals is not None:
        normals = np.array(normals, dtype=np.float64, order="C").reshape(-1, 3)
        if normals.shape[0] != n or not np.isfinite(normals).all():
            normals = None
    return MeshData(points, triangles, normals, path.stem, source_dtype)


def _fan(flat: np.ndarray, counts: np.ndarray) -> np.ndarray:
    """Fan-triangulate polygons given as a flat index array and per-polygon counts.

    Polygon ``(v0, v1, ..., vk-1)`` becomes ``(v0, v1, v2), (v0, v2, v3), ...``; polygons with
    fewer than three vertices give no triangle. Triangles keep the polygons' order.
    """
    counts = np.asarray(counts, dtype=np.int64)
    if counts.size == 0:
        return np.empty((0, 3), np.int64)
    k = int(counts[0])
    if (counts == k).all():
        if k < 3:
            return np.empty((0, 3), np.int64)
        polygons = flat.reshape(-1, k)
        if k == 3:
            return polygons
        fans = [polygons[:, [0, j, j + 1]] for j in range(1, k - 1)]
        return np.stack(fans, axis=1).reshape(-1, 3)
    starts = np.cumsum(counts) - counts
    n_tri = np.maximum(counts - 2, 0)
    owner = np.repeat(np.arange(counts.size), n_tri)
    first = np.cumsum(n_tri) - n_tri
    j = np.arange(owner.size) - np.repeat(first, n_tri) + 1
    base = starts[owner]
    return np.stack([flat[base], flat[base + j], flat[base + j + 1]], axis=1)


_NOT_BLANK = re.compile(rb"\S")


def _parse_numbers(text: bytes, dtype=np.float64) -> np.ndarray | None:
    """All whitespace-separated numbers in ``text`` (as ``dtype``), or None if a token is not
    one."""
    if _NOT_BLANK.search(text) is None:
        return np.empty(0, dtype)  # np.fromstring returns [-1.0] for blank text
    with warnings.catch_warnings():
        warnings.simplefilter("error", DeprecationWarning)
        try:
            return np.fromstring(text, dtype=dtype, sep=" ")
        except (ValueError, DeprecationWarning):
            return None


_NOT_A_NUMBER = re.compile(
    rb"(?<!\S)(?![+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?(?!\S)|[+-]?(?i:nan|inf(?:inity)?)(?!\S))\S+"
)


def _where_not_a_number(data: bytes, pos: int) -> str:
    """``", line N ('token')"`` for the first word from ``pos`` on that is not a number (only
    for error messages), or ``""`` if none is found."""
    found = _NOT_A_NUMBER.search(data, pos)
    if found is None:
        return ""
    line = data.count(b"\n", 0, found.start()) + 1
    word = found.group().decode("utf-8", "replace")[:40]
    return f", line {line} ({word!r})"


# -------------------------------------------------------------------------------------------- PLY

_PLY_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1",
    "short": "i2", "int16": "i2", "ushort": "u2", "uint16": "u2",
    "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
    "float": "f4", "float32": "f4", "double": "f8", "float64": "f8",
}  # fmt: skip
_PLY_FORMATS = {"ascii": None, "binary_little_endian": "<", "binary_big_endian": ">"}


@dataclass
class _PlyProperty:
    name: str
    dtype: np.dtype  # value type (list items for a list)
    count_dtype: np.dtype | None = None  # None for a scalar property


@dataclass
class _PlyElement:
    name: str
    count: int
    properties: list[_PlyProperty]

    @property
    def has_lists(self) -> bool:
        return any(p.count_dtype is not None for p in self.properties)


def _ply_header(data: bytes, path: Path) -> tuple[str, list[_PlyElement], int]:
    """Parse the header; return the format, the elements and the offset of the body."""
    if not data.startswith(b"ply") or data[3:4] not in (b"\n", b"\r"):
        raise GoniometerError(
            f"'{path}' is not a PLY file (it does not start with the line 'ply'). "
            "Check that the file is a mesh and re-export it as PLY."
        )
    fmt = None
    elements: list[_PlyElement] = []
    pos = 0
    number = 0
    while True:
        end = data.find(b"\n", pos)
        if end < 0:
            raise GoniometerError(
                f"'{path}': the PLY header has no 'end_header' line; the file is truncated or "
                "not a PLY file."
            )
        # Words are split at ASCII whitespace only, like the body's values.
        line = data[pos:end].strip().decode("latin-1")
        words = [word.decode("latin-1") for word in data[pos:end].split()]
        pos = end + 1
        number += 1
        if not words or words[0] in ("ply", "comment", "obj_info"):
            continue
        keyword = words[0]
        where = f"'{path}', header line {number} ('{line}')"
        if keyword == "end_header":
            break
        if keyword == "format":
            if len(words) < 2 or words[1] not in _PLY_FORMATS:
                raise GoniometerError(
                    f"{where}: unknown PLY format; expected ascii, binary_little_endian or "
                    "binary_big_endian."
                )
            fmt = words[1]
        elif keyword == "element":
            if len(words) != 3 or not (words[2].isascii() and words[2].isdigit()):
                raise GoniometerError(f"{where}: expected 'element <name> <count>'.")
            elements.append(_PlyElement(words[1], int(words[2]), []))
        elif keyword == "property":
            if not elements:
                raise GoniometerError(f"{where}: a property comes before any element.")
            elements[-1].properties.append(_ply_property(words, where))
        # Other keywords do not change the data layout and are ignored.
    if fmt is None:
        raise GoniometerError(
            f"'{path}': the PLY header has no 'format' line; the file is corrupt."
        )
    return fmt, elements, pos


def _ply_property(words: list[str], where: str) -> _PlyProperty:
    def dtype(name: str) -> np.dtype:
        if name not in _PLY_TYPES:
            raise GoniometerError(
                f"{where}: unknown property type '{name}'; PLY types are "
                "char, uchar, short, ushort, int, uint, float and double."
            )
        return np.dtype(_PLY_TYPES[name])

    if len(words) >= 2 and words[1] == "list":
        if len(words) != 5:
            raise GoniometerError(f"{where}: expected 'property list <count type> <type> <name>'.")
        count_dtype = dtype(words[2])
        if count_dtype.kind == "f":
            raise GoniometerError(f"{where}: a list count must have an integer type.")
        return _PlyProperty(words[4], dtype(words[3]), count_dtype)
    if len(words) != 3:
        raise GoniometerError(f"{where}: expected 'property <type> <name>'.")
    return _PlyProperty(words[2], dtype(words[1]))


def read_ply(path: str | os.PathLike) -> MeshData:
    """Read a PLY file: ascii, binary little- or big-endian, any scalar property types.

    The ``vertex`` element must have ``x``, ``y``, ``z``; ``nx``, ``ny``, ``nz`` become the
    normals; other vertex properties (colours, quality, ...) are ignored in any order. The
    ``face`` element's ``vertex_indices`` (or ``vertex_index``) list is fan-triangulated; other
    face properties and other elements are skipped. An ASCII body is read line by line: each
    element takes the next ``count`` non-blank lines, and each line must hold exactly the values
    of its element's properties (one per scalar, a count and that many items per list).

    Parameters
    ----------
    path : str or path-like
        The ``.ply`` file.

    Returns
    -------
    MeshData

    Raises
    ------
    GoniometerError
        For a missing, unreadable, truncated or malformed file (see :func:`read_mesh`); in an
        ASCII file, a line with the wrong count of values, a face index out of range, or element
        counts that do not match the lines are named with the line number.
    """
    path = _as_path(path)
    data = _read_bytes(path)
    fmt, elements, body = _ply_header(data, path)
    vertex = next((e for e in elements if e.name == "vertex"), None)
    if vertex is None:
        raise GoniometerError(f"'{path}': the PLY file has no 'vertex' element, so no points.")
    names = [p.name for p in vertex.properties]
    missing = [c for c in "xyz" if c not in names]
    if missing:
        raise GoniometerError(
            f"'{path}': the PLY vertex element has no {', '.join(missing)} coordinate "
            f"(its properties are: {', '.join(names) or 'none'})."
        )
    for c in "xyz":
        if vertex.properties[names.index(c)].count_dtype is not None:
            raise GoniometerError(f"'{path}': the vertex coordinate '{c}' is a list, not a number.")
    scalars = {p.name for p in vertex.properties if p.count_dtype is None}
    wanted = {"vertex": {"x", "y", "z"}}
    if {"nx", "ny", "nz"} <= scalars:
        wanted["vertex"] |= {"nx", "ny", "nz"}
    face = next((e for e in elements if e.name == "face"), None)
    if face is not None:
        face_list = _face_list_name(face, path)
        wanted["face"] = {face_list}
    for element in (e for e in (vertex, face) if e is not None):
        for name in wanted[element.name]:
            if sum(p.name == name for p in element.properties) > 1:
                raise GoniometerError(
                    f"'{path}': the PLY '{element.name}' element has more than one '{name}' "
                    "property, so which one to read is ambiguous; re-export the mesh."
                )
    lines = {}
    if fmt == "ascii":
        found, lines = _ply_ascii_body(data, body, elements, wanted, path)
    else:
        found = _ply_binary_body(data, body, elements, wanted, _PLY_FORMATS[fmt], path)

    values = found["vertex"]
    points = np.column_stack([values["x"], values["y"], values["z"]])
    normals = None
    if all(c in values for c in ("nx", "ny", "nz")):
        normals = np.column_stack([values["nx"], values["ny"], values["nz"]])
    triangles = None
    if face is not None and face.count > 0:
        flat, counts = found["face"][face_list]
        flat = flat.astype(np.int64)
        _check_face_indices(flat, counts, len(points), path, lines.get("face"))
        triangles = _fan(flat, counts)
    source_dtype = vertex.properties[names.index("x")].dtype.name
    return _finish(path, points, triangles, normals, source_dtype)


def _check_face_indices(flat, counts, n, path, lines=None) -> None:
    """Refuse a face index outside ``0..n-1`` (also in faces of fewer than three vertices,
    which give no triangle), naming the face's line (``lines``, ASCII) or its number."""
    bad = (flat < 0) | (flat >= n)
    if bad.any():
        k = int(np.argmax(bad))
        face = int(np.searchsorted(np.cumsum(counts), k, side="right"))
        where = (
            f"'{path}', line {lines[face]}"
            if lines is not None
            else f"'{path}', face {face} (from 0)"
        )
        raise GoniometerError(
            f"{where}: face index out of range: the face refers to vertex {flat[k]} (counting "
            f"from 0), but the file has {n} vertices (valid 0..{n - 1}). The file is corrupt or "
            "was written incorrectly; re-export it."
        )


def _face_list_name(face: _PlyElement, path: Path) -> str:
    lists = [p for p in face.properties if p.count_dtype is not None]
    chosen = next((p for p in lists if p.name in ("vertex_indices", "vertex_index")), None)
    if chosen is None and len(lists) == 1:
        chosen = lists[0]
    if chosen is None:
        raise GoniometerError(
            f"'{path}': the PLY face element has no 'vertex_indices' list; cannot read the faces."
        )
    if chosen.dtype.kind == "f":
        raise GoniometerError(
            f"'{path}': the PLY face list '{chosen.name}' has a floating-point type; "
            "vertex indices must be integers."
        )
    return chosen.name


def _truncated(path: Path, element: _PlyElement) -> GoniometerError:
    return GoniometerError(
        f"'{path}' is truncated: the data ends inside the '{element.name}' element "
        f"({element.count} declared in the header). The file was not written completely; "
        "re-export or copy it again."
    )


def _ply_binary_body(data, pos, elements, wanted, order, path) -> dict:
    """Read the needed properties of each element from binary data starting at ``pos``."""
    found: dict[str, dict] = {}
    buffer = np.frombuffer(data, np.uint8)
    for element in elements:
        if all(name in found for name in wanted):
            break  # later elements are not needed, so they need not even be complete
        need = wanted.get(element.name, set()) if element.name not in found else set()
        if not element.has_lists:
            dtype = np.dtype(
                [(f"p{i}", p.dtype.newbyteorder(order)) for i, p in enumerate(element.properties)]
            )
            size = dtype.itemsize * element.count
            if pos + size > len(data):
                raise _truncated(path, element)
            if need:
                rows = np.frombuffer(data, dtype, element.count, pos)
                found[element.name] = {
                    p.name: rows[f"p{i}"]
                    for i, p in enumerate(element.properties)
                    if p.name in need
                }
            pos += size
            continue
        values, pos = _binary_uniform_lists(data, pos, element, order, need)
        if values is None:
            values, pos = _binary_mixed_lists(data, buffer, pos, element, order, need, path)
        if need:
            found[element.name] = values
    return found


def _binary_uniform_lists(data, pos, element, order, need):
    """Fast path: every record has the list counts of the first one, so one structured dtype
    reads the whole element. Returns ``(None, pos)`` when that assumption does not hold."""
    fields = []
    offset = pos
    counts = {}
    for i, p in enumerate(element.properties):
        if p.count_dtype is None:
            fields.append((f"p{i}", p.dtype.newbyteorder(order)))
            offset += p.dtype.itemsize
            continue
        count_dtype = p.count_dtype.newbyteorder(order)
        if offset + count_dtype.itemsize > len(data):
            return None, pos
        count = int(np.frombuffer(data, count_dtype, 1, offset)[0])
        if count < 0 or offset + count * p.dtype.itemsize > len(data):
            return None, pos
        counts[i] = count
        fields.append((f"c{i}", count_dtype))
        fields.append((f"p{i}", p.dtype.newbyteorder(order), (count,)))
        offset += count_dtype.itemsize + count * p.dtype.itemsize
    dtype = np.dtype(fields)
    size = dtype.itemsize * element.count
    if element.count == 0:
        return _empty_values(element, need), pos
    if pos + size > len(data):
        return None, pos
    rows = np.frombuffer(data, dtype, element.count, pos)
    if any((rows[f"c{i}"] != c).any() for i, c in counts.items()):
        return None, pos
    values = {}
    for i, p in enumerate(element.properties):
        if p.name not in need:
            continue
        if p.count_dtype is None:
            values[p.name] = rows[f"p{i}"]
        else:
            values[p.name] = (
                rows[f"p{i}"].reshape(-1),
                np.full(element.count, counts[i], np.int64),
            )
    return values, pos + size


def _empty_values(element, need):
    values = {}
    for p in element.properties:
        if p.name in need:
            empty = np.empty(0, p.dtype)
            values[p.name] = empty if p.count_dtype is None else (empty, np.empty(0, np.int64))
    return values


def _binary_mixed_lists(data, buffer, pos, element, order, need, path):
    """General path: find each record's start (one Python step per record, since a record's
    length depends on its counts), then gather every value with NumPy."""
    # The record layout as runs of fixed bytes separated by list counts.
    runs: list[tuple[int, str, int, int]] = []  # (fixed bytes before, count format, size, item)
    fixed = 0
    for p in element.properties:
        if p.count_dtype is None:
            fixed += p.dtype.itemsize
        else:
            code = order + p.count_dtype.char
            runs.append((fixed, code, p.count_dtype.itemsize, p.dtype.itemsize))
            fixed = 0
    tail = fixed
    starts = []
    append = starts.append
    try:
        if len(runs) == 1 and runs[0][1][1] == "B":  # the common face layout: uchar count
            before, _, _, item = runs[0]
            for _ in range(element.count):
                append(pos)
                pos += before + 1 + data[pos + before] * item + tail
        else:
            unpack = [
                (before, struct.Struct(code).unpack_from, size, item)
                for before, code, size, item in runs
            ]
            for _ in range(element.count):
                append(pos)
                for before, read, size, item in unpack:
                    pos += before
                    count = read(data, pos)[0]
                    if count < 0:
                        raise GoniometerError(
                            f"'{path}': a negative list count ({count}) in the "
                            f"'{element.name}' element; the file is corrupt."
                        )
                    pos += size + count * item
                pos += tail
    except (IndexError, struct.error):
        raise _truncated(path, element) from None
    if pos > len(data):
        raise _truncated(path, element)

    cursor = np.array(starts, dtype=np.int64)
    values = {}
    for p in element.properties:
        if p.count_dtype is None:
            if p.name in need:
                values[p.name] = _gather(buffer, cursor, p.dtype.newbyteorder(order))
            cursor = cursor + p.dtype.itemsize
            continue
        counts = _gather(buffer, cursor, p.count_dtype.newbyteorder(order)).astype(np.int64)
        first = cursor + p.count_dtype.itemsize
        if p.name in need:
            rank = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
            at = np.repeat(first, counts) + rank * p.dtype.itemsize
            values[p.name] = (_gather(buffer, at, p.dtype.newbyteorder(order)), counts)
        cursor = first + counts * p.dtype.itemsize
    return values, pos


def _gather(buffer: np.ndarray, offsets: np.ndarray, dtype: np.dtype) -> np.ndarray:
    """The values of type ``dtype`` stored at byte ``offsets`` of ``buffer``."""
    at = offsets[:, None] + np.arange(dtype.itemsize)
    return np.ascontiguousarray(buffer[at]).view(dtype).reshape(-1)


_SPACE = np.uint8(32)
_SLASH = np.uint8(ord("/"))
_MINUS = np.uint8(ord("-"))


def _blank(buffer: np.ndarray) -> np.ndarray:
    """Mask of the ASCII whitespace bytes (tab, newline, vertical tab, form feed, carriage
    return, space): the separators ``np.fromstring`` and ``bytes.split`` use."""
    return ((buffer - np.uint8(9)) < 5) | (buffer == _SPACE)


def _ply_ascii_body(data, pos, elements, wanted, path) -> tuple[dict, dict]:
    """Read an ASCII body line by line against the header.

    Each element takes the next ``count`` non-blank lines, one record per line, and each line
    must hold exactly the values its properties call for (one per scalar, a count and that
    many items per list). Blank lines anywhere are skipped. Returns the needed values and, per
    needed element, the 1-based line number of each record (for later messages).
    """
    buffer = np.frombuffer(data, np.uint8, offset=pos)
    blank = _blank(buffer)
    # A value starts at a non-blank byte after a blank one; the header's last newline
    # precedes the body, so its first byte starts a value unless it is blank.
    starts = np.empty(buffer.size, bool)
    if buffer.size:
        starts[0] = not blank[0]
        np.less(blank[1:], blank[:-1], out=starts[1:])
    value_at = np.flatnonzero(starts)
    del starts, blank
    line_starts = pos + np.concatenate([[0], np.flatnonzero(buffer == 10) + 1, [buffer.size]])
    per_line = np.diff(np.searchsorted(value_at + pos, line_starts[:-1]), append=value_at.size)
    del value_at
    first_line = data.count(b"\n", 0, pos) + 1  # the body's first line, counted from 1
    records = np.flatnonzero(per_line)  # body lines that hold values, one record each
    widths = per_line[records]
    del per_line

    found: dict[str, dict] = {}
    lines: dict[str, np.ndarray] = {}
    at = 0
    for element in elements:
        if element.count > records.size - at:
            last = int(records[-1]) + first_line if records.size else first_line - 1
            raise GoniometerError(
                f"'{path}', line {last + 1}: the file ends after {records.size - at} of the "
                f"{element.count} '{element.name}' lines the header declares: lines are "
                "missing, the file is truncated or its header is wrong. Re-export it."
            )
        take = slice(at, at + element.count)
        need = wanted.get(element.name, set()) if element.name not in found else set()
        record_lines = records[take] + first_line
        numbers = np.empty(0)
        if element.count:
            begin, end = line_starts[records[at]], line_starts[records[take][-1] + 1]
            numbers = _ascii_numbers(data, begin, end, element, widths[take].sum(), path)
        values = _ascii_records(numbers, widths[take], record_lines, element, need, path)
        if need:
            found[element.name] = values
            lines[element.name] = record_lines
        at += element.count
    if at < records.size:
        declared = ", ".join(f"{e.count} '{e.name}'" for e in elements) or "no elements"
        raise GoniometerError(
            f"'{path}', line {int(records[at]) + first_line}: a line after the last element "
            f"the header declares ({declared} lines). The header's counts are wrong or the "
            "file has lines too many; re-export it."
        )
    return found, lines


def _ascii_numbers(data, begin, end, element, expected, path) -> np.ndarray:
    """The ``expected`` numbers of ``data[begin:end]`` (an element's lines) as float64."""
    text = data[begin:end]
    numbers = None
    if (
        all(
            p.dtype.kind in "iu" and (p.count_dtype is None or p.count_dtype.kind in "iu")
            for p in element.properties
        )
        and b"-" not in text
        and b"+" not in text
    ):
        # Unsigned whole numbers (face lists) parse three times faster as integers. Signs take
        # the float path: the integer parser reads a lone '-' as 0 or joins it to the next
        # number. Values beyond int64 saturate, which every PLY integer type refuses anyway;
        # anything else (3.0, 1e2) fails here and takes the float path too, where the declared
        # type is checked.
        numbers = _parse_numbers(text, np.int64)
    numbers = _parse_numbers(text) if numbers is None else numbers.astype(np.float64)
    if numbers is None or numbers.size != expected:
        raise GoniometerError(
            f"'{path}'{_where_not_a_number(data, begin)}: the '{element.name}' data of this "
            "ASCII PLY contains something that is not a number; the file is corrupt."
        )
    return numbers


def _ascii_records(numbers, widths, lines, element, need, path) -> dict:
    """Check each record's value count against the element's properties and return the needed
    values. ``numbers``: the element's values, record after record; ``widths``: how many each
    record has; ``lines``: their line numbers."""
    props = element.properties
    n = widths.size
    if n == 0:
        return _empty_values(element, need)
    if (widths == widths[0]).all():
        # The common case, every record alike (e.g. all triangles): one table, read by column.
        table = numbers.reshape(n, int(widths[0]))
        layout = _ascii_table_layout(table, props)
        if layout is not None:
            values = {}
            for p, (column, count) in zip(props, layout, strict=True):
                if p.name not in need:
                    continue
                if count is None:
                    values[p.name] = _ascii_cast(
                        table[:, column], p.dtype, element, lines.__getitem__, path
                    )
                    continue
                flat = table[:, column + 1 : column + 1 + count].reshape(-1)
                values[p.name] = (
                    _ascii_cast(flat, p.dtype, element, lambda k, c=count: lines[k // c], path),
                    np.full(n, count, np.int64),
                )
            return values

    # Walk the properties, all records at once: a list's count says where the next one starts.
    firsts = np.cumsum(widths) - widths  # each record's first value
    offset = np.zeros(n, np.int64)
    bad = np.zeros(n, bool)
    layout = []  # per property: the offset of its value (or of its list's count), and the count
    for p in props:
        if p.count_dtype is None:
            layout.append((offset, None))
            offset = offset + 1
            continue
        inside = offset < widths
        count = numbers[firsts + np.minimum(offset, widths - 1)]
        ok = inside & (count >= 0) & (count == np.floor(count)) & (count < widths - offset)
        bad |= ~ok
        count = np.where(ok, count, 0).astype(np.int64)
        layout.append((offset, count))
        offset = offset + 1 + count
    bad |= offset != widths
    if bad.any():
        raise _ascii_record_error(numbers, firsts, widths, lines, element, bad, path)
    values = {}
    for p, (offset, count) in zip(props, layout, strict=True):
        if p.name not in need:
            continue
        if count is None:
            values[p.name] = _ascii_cast(
                numbers[firsts + offset], p.dtype, element, lines.__getitem__, path
            )
            continue
        rank = np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
        flat = numbers[np.repeat(firsts + offset + 1, count) + rank]
        ends = np.cumsum(count)

        def line_of(k, ends=ends):
            return lines[np.searchsorted(ends, k, side="right")]

        values[p.name] = (_ascii_cast(flat, p.dtype, element, line_of, path), count)
    return values


def _ascii_table_layout(table, props) -> list | None:
    """Column of each property in a table of equally long records (with its list's length,
    or None for a scalar), or None if the records' list counts do not all make that length."""
    column = 0
    layout = []
    for p in props:
        if p.count_dtype is None:
            layout.append((column, None))
            column += 1
            continue
        if column >= table.shape[1]:
            return None
        count = table[0, column]
        if not (0 <= count < table.shape[1] - column and count == np.floor(count)):
            return None
        if (table[:, column] != count).any():
            return None
        layout.append((column, int(count)))
        column += 1 + int(count)
    return layout if column == table.shape[1] else None


def _ascii_record_error(numbers, firsts, widths, lines, element, bad, path) -> GoniometerError:
    """The message for the first record in ``bad``, worked out again for that one line."""
    r = int(np.argmax(bad))
    values = numbers[firsts[r] : firsts[r] + widths[r]]
    where = f"'{path}', line {lines[r]}"
    expected = 0
    parts = []
    for p in element.properties:
        if p.count_dtype is None:
            expected += 1
            parts.append(p.name)
            continue
        if expected >= values.size:
            return GoniometerError(
                f"{where}: the line ends before the count of the '{p.name}' list of the "
                f"'{element.name}' element; a value is missing, the file is corrupt."
            )
        count = values[expected]
        left = values.size - expected - 1
        if not (0 <= count <= left and count == np.floor(count)):
            return GoniometerError(
                f"{where}: the count {count:g} of the '{p.name}' list in this "
                f"'{element.name}' line is not a whole number from 0 to the {left} values "
                "after it on the line; the file is corrupt."
            )
        expected += 1 + int(count)
        parts.append(f"{p.name}: 1 + {int(count)}")
    return GoniometerError(
        f"{where}: this '{element.name}' line has {values.size} values, but the header's "
        f"properties make it {expected} ({', '.join(parts)}). The line has a value too many "
        "or too few, so the file is corrupt; re-export it."
    )


def _ascii_cast(values, dtype, element, line_of, path) -> np.ndarray:
    """ASCII numbers stored as the declared type (so an ASCII file reads like its binary twin);
    ``line_of(k)`` is the line number of value ``k``, for the message."""
    if dtype.kind in "iu" and values.size:
        info = np.iinfo(dtype)
        bad = (values != np.floor(values)) | (values < info.min) | (values > info.max)
        if bad.any():
            k = int(np.argmax(bad))
            raise GoniometerError(
                f"'{path}', line {line_of(k)}: the value {values[k]:g} in the "
                f"'{element.name}' element is not a valid {dtype.name} integer; the file is "
                "corrupt."
            )
    return values.astype(dtype)


# -------------------------------------------------------------------------------------------- OBJ


class _Text:
    """Line and word structure of a text file, found with NumPy over its bytes."""

    def __init__(self, data: bytes, path: Path):
        self.path = path
        self.buffer = np.frombuffer(data + b"\n", np.uint8)
        self.blank = _blank(self.buffer)
        self.ends = np.flatnonzero(self.buffer == 10)  # each line's newline
        starts = np.concatenate([[0], self.ends[:-1] + 1])
        first = starts.copy()
        todo = np.flatnonzero(self.blank[first] & (first < self.ends))
        while todo.size:  # step over leading blanks: one pass per blank column, not per line
            first[todo] += 1
            todo = todo[self.blank[first[todo]] & (first[todo] < self.ends[todo])]
        self.first = first  # first non-blank byte of each line (its newline if the line is blank)

    def keyword(self, word: bytes) -> np.ndarray:
        """Indices of the lines whose first word is ``word``."""
        after = self.first + len(word)
        match = after <= self.ends
        for k, byte in enumerate(word):
            match &= self.buffer[np.minimum(self.first + k, self.ends)] == byte
        return np.flatnonzero(match & self.blank[np.minimum(after, self.ends)])

    def body(self, lines: np.ndarray, skip: int) -> tuple[np.ndarray, np.ndarray]:
        """Mask of the bytes after the first ``skip`` bytes of each line in ``lines``, and the
        position where each of those parts begins."""
        begin = self.first[lines] + skip
        end = self.ends[lines]
        keep = begin < end
        inside = np.zeros(self.buffer.size + 1, np.int8)
        inside[begin[keep]] = 1
        inside[end[keep]] = -1
        return np.cumsum(inside, dtype=np.int8)[:-1].view(bool), begin

    @staticmethod
    def word_starts(mask: np.ndarray, separator: np.ndarray) -> np.ndarray:
        """Mask of the first byte of each run of non-separator bytes inside ``mask``."""
        inside = mask & ~separator
        starts = inside.copy()
        starts[1:] &= ~inside[:-1]
        return starts

    @staticmethod
    def per_segment(positions: np.ndarray, begin: np.ndarray) -> np.ndarray:
        """How many of the sorted ``positions`` lie between consecutive ``begin`` positions
        (the last segment runs to the end)."""
        at = np.searchsorted(positions, begin)
        return np.diff(at, append=positions.size).astype(np.int64)

    def word_counts(self, lines: np.ndarray) -> np.ndarray:
        """How many words each of the given lines holds."""
        mask, begin = self.body(lines, 0)
        return self.per_segment(np.flatnonzero(self.word_starts(mask, self.blank)), begin)

    def floats(self, lines: np.ndarray, skip: int, what: str) -> tuple[np.ndarray, np.ndarray]:
        """All numbers after the first ``skip`` bytes of the given lines, as float64, and how
        many each line holds."""
        mask, begin = self.body(lines, skip)
        counts = self.per_segment(np.flatnonzero(self.word_starts(mask, self.blank)), begin)
        values = _parse_numbers(np.where(mask, self.buffer, _SPACE).tobytes())
        if values is None or values.size != counts.sum():
            raise GoniometerError(
                f"'{self.path}', line {self._bad_line(lines, begin)}: cannot read the numbers "
                f"of this {what} line; the file is corrupt."
            )
        return values, counts

    def _bad_line(self, lines: np.ndarray, begin: np.ndarray, convert=float) -> int:
        """Line number (1-based) of the first line holding a word that ``convert`` rejects;
        only called to word an error message."""
        for line, at in zip(lines, begin, strict=True):
            text = self.buffer[at : self.ends[line]].tobytes().replace(b"/", b" ")
            try:
                [convert(word) for word in text.split()]
            except ValueError:
                return int(line) + 1
        return int(lines[-1]) + 1 if lines.size else 1

    def faces(self, lines: np.ndarray):
        """Face corners of ``f`` lines, each ``i``, ``i/t``, ``i//n`` or ``i/t/n``.

        Returns ``(vertex, normal, counts)``: the raw (1-based or negative) vertex reference of
        each corner, its normal reference (None unless every corner has one) and the number of
        corners per line.
        """
        mask, begin = self.body(lines, 1)
        slash = mask & (self.buffer == _SLASH)
        corners = np.flatnonzero(self.word_starts(mask, self.blank))
        counts = self.per_segment(corners, begin)
        part_inside = mask & ~self.blank & ~slash
        edges = np.diff(part_inside.view(np.int8), prepend=np.int8(0))
        part_starts = np.flatnonzero(edges == 1)
        part_stops = np.flatnonzero(edges == -1)  # the byte after each part
        parts = _parse_integers(self.buffer, part_starts, part_stops)
        if parts is None:
            raise GoniometerError(
                f"'{self.path}', line {self._bad_line(lines, begin, int)}: cannot read the indices "
                "of this 'f' line; the file is corrupt."
            )
        if corners.size and (self.buffer[corners] == _SLASH).any():
            bad = corners[self.buffer[corners] == _SLASH][0]
            line = int(lines[np.searchsorted(begin, bad, side="right") - 1]) + 1
            raise GoniometerError(f"'{self.path}', line {line}: a face corner has no vertex index.")
        n_parts = self.per_segment(part_starts, corners)
        n_slashes = self.per_segment(np.flatnonzero(slash), corners)
        first_part = np.cumsum(n_parts) - n_parts
        # A corner ends in a slash when the byte after its last part is one (1/, 1//, 1/2/).
        bad = n_slashes > 2
        if corners.size:
            bad |= self.buffer[part_stops[first_part + n_parts - 1]] == _SLASH
        if bad.any():
            k = int(np.argmax(bad))
            line = int(lines[np.searchsorted(begin, corners[k], side="right") - 1]) + 1
            corner = self.buffer[corners[k] : self.ends[line - 1]].tobytes().split()[0]
            raise GoniometerError(
                f"'{self.path}', line {line}: the face corner "
                f"{corner[:40].decode('utf-8', 'replace')!r} is not one of i, i/t, i//n or "
                "i/t/n; the file is corrupt."
            )
        vertex = parts[first_part]
        normal = None
        if corners.size and (n_slashes == 2).all() and (n_parts >= 2).all():
            normal = parts[first_part + n_parts - 1]  # i//n and i/t/n: the last part
        return vertex, normal, counts


def _parse_integers(buffer: np.ndarray, starts: np.ndarray, stops: np.ndarray):
    """Decimal integers (optional leading '-') at ``buffer[starts[k]:stops[k]]``, or None if
    any is not one. Vectorised digit by digit: much faster than text-to-float parsing."""
    if starts.size == 0:
        return np.zeros(0, np.int64)
    negative = buffer[starts] == _MINUS
    first = starts + negative
    length = stops - first
    if length.min() < 1 or length.max() > 18:
        return None
    value = np.zeros(starts.size, np.int64)
    for k in range(int(length.max())):
        if k < length.min():
            digit = buffer[first + k] - np.uint8(48)  # non-digits wrap around to > 9
            if (digit > 9).any():
                return None
            value = value * 10 + digit
        else:
            active = np.flatnonzero(length > k)
            digit = buffer[first[active] + k] - np.uint8(48)
            if (digit > 9).any():
                return None
            value[active] = value[active] * 10 + digit
    return np.where(negative, -value, value)


def read_obj(path: str | os.PathLike) -> MeshData:
    """Read a Wavefront OBJ file.

    ``v`` lines give the points: ``x y z``, optionally followed by ``w`` or by colours ``r g b``
    (both ignored). ``f`` lines give the faces with corners in any of the forms ``i``, ``i/t``,
    ``i//n``, ``i/t/n``, negative (relative) indices allowed; polygons are fan-triangulated.
    ``vn`` normals are returned only if they map one-to-one to the vertices (as many as
    vertices, and every face corner's normal index equals its vertex index). Comments and all
    other statements are ignored.

    Parameters
    ----------
    path : str or path-like
        The ``.obj`` file.

    Returns
    -------
    MeshData

    Raises
    ------
    GoniometerError
        For a missing, unreadable or malformed file (see :func:`read_mesh`); a line with the
        wrong count of numbers, a malformed corner or a face index 0 or out of range is named
        with its line number.
    """
    path = _as_path(path)
    text = _Text(_read_bytes(path), path)
    v_lines = text.keyword(b"v")
    values, counts = text.floats(v_lines, 1, "'v'")
    # x y z, then w (the official format) or r g b (the colour extension that MeshLab, Blender
    # and others write and read); any other count is a value too many or too few.
    bad = (counts != 3) & (counts != 4) & (counts != 6)
    if bad.any():
        k = int(np.argmax(bad))
        raise GoniometerError(
            f"'{path}', line {v_lines[k] + 1}: a 'v' line needs three coordinates x y z, "
            f"optionally followed by w or by r g b (3, 4 or 6 numbers); this one has "
            f"{counts[k]} numbers. The file is corrupt; re-export it."
        )
    points = values[(np.cumsum(counts) - counts)[:, None] + np.arange(3)]

    f_lines = text.keyword(b"f")
    triangles = corners = normal_refs = None
    if f_lines.size:
        vertex_refs, normal_refs, counts = text.faces(f_lines)
        corners = _obj_indices(
            vertex_refs, counts, np.searchsorted(v_lines, f_lines), f_lines, path, "vertex"
        )
        bad = (corners < 0) | (corners >= v_lines.size)
        if bad.any():
            k = int(np.argmax(bad))
            line = f_lines[np.searchsorted(np.cumsum(counts), k, side="right")] + 1
            raise GoniometerError(
                f"'{path}', line {line}: face index out of range: the face refers to vertex "
                f"{vertex_refs[k]} (as written; OBJ counts from 1, or back from -1 for the last "
                f"vertex defined so far), but the file has {v_lines.size} vertices. The file is "
                "corrupt or was written incorrectly; re-export it."
            )
        triangles = _fan(corners, counts)

    normals = None
    vn_lines = text.keyword(b"vn")
    if vn_lines.size and vn_lines.size == v_lines.size:
        values, ncounts = text.floats(vn_lines, 2, "'vn'")
        if (ncounts != 3).any():
            k = int(np.argmax(ncounts != 3))
            raise GoniometerError(
                f"'{path}', line {vn_lines[k] + 1}: a 'vn' line needs three numbers "
                f"x y z; this one has {ncounts[k]}. The file is corrupt; re-export it."
            )
        normals = values.reshape(-1, 3)
        if corners is not None:
            if normal_refs is None or (normal_refs == 0).any():
                normals = None
            else:
                defined = np.repeat(np.searchsorted(vn_lines, f_lines), counts)
                refs = np.where(normal_refs < 0, normal_refs + defined, normal_refs - 1)
                if not np.array_equal(refs, corners):
                    normals = None
    return _finish(path, points, triangles, normals, "float64")


def _obj_indices(refs, counts, before, lines, path, what) -> np.ndarray:
    """OBJ references (1-based, or negative = relative to the ones defined so far) to 0-based."""
    if (refs == 0).any():
        bad = lines[np.repeat(np.arange(counts.size), counts)[refs == 0][0]]
        raise GoniometerError(
            f"'{path}', line {bad + 1}: face {what} index 0 is invalid (OBJ indices start at 1)."
        )
    defined = np.repeat(before, counts)
    return np.where(refs < 0, refs + defined, refs - 1)


# -------------------------------------------------------------------------------------------- STL

_STL_RECORD = np.dtype([("normal", "<f4", (3,)), ("corners", "<f4", (3, 3)), ("attribute", "<u2")])


def read_stl(path: str | os.PathLike) -> MeshData:
    """Read a binary or ASCII STL file and merge identical vertices into an indexed mesh.

    Binary and ASCII are told apart by the binary size rule (84 + 50 bytes per triangle), so a
    binary file whose header starts with ``solid`` is still read as binary. A binary file must
    hold exactly the triangles its header declares; up to 49 bytes after the last one (less than
    a triangle, which some writers add) are ignored. An ASCII file is read line by line: each
    ``facet normal`` line has three numbers and is followed by exactly three ``vertex`` lines of
    three numbers each. Corners with exactly identical coordinates become one vertex, numbered in
    order of first appearance.

    Parameters
    ----------
    path : str or path-like
        The ``.stl`` file.

    Returns
    -------
    MeshData
        With ``normals=None`` (STL stores facet normals only).

    Raises
    ------
    GoniometerError
        For a missing, unreadable, truncated or malformed file (see :func:`read_mesh`): a binary
        file whose size does not match its header's triangle count (both counts are named), an
        ASCII line with the wrong count of numbers or a facet without exactly three vertices
        (named with its line number).
    """
    path = _as_path(path)
    data = _read_bytes(path)
    declared = int.from_bytes(data[80:84], "little") if len(data) >= 84 else -1
    expected = 84 + _STL_RECORD.itemsize * declared
    implied, extra = divmod(len(data) - 84, _STL_RECORD.itemsize)
    looks_ascii = data[:1024].lstrip()[:5].lower() == b"solid" and b"\0" not in data[:4096]
    if declared >= 0 and (len(data) == expected or (implied == declared and not looks_ascii)):
        records = np.frombuffer(data, _STL_RECORD, declared, 84)
        corners = records["corners"].reshape(-1, 3)
        source_dtype = "float32"
    elif looks_ascii:
        corners = _stl_ascii_corners(data, path)
        if corners.size == 0 and declared >= 0:
            raise GoniometerError(
                f"'{path}' is neither a complete binary STL (its header declares {declared} "
                f"triangles, its size of {len(data)} bytes implies {implied}) nor an ASCII STL "
                "with 'vertex' lines. The file is truncated or corrupt; re-export it."
            )
        source_dtype = "float64"
    elif declared >= 0:
        size = f"{len(data)} bytes: 84 for the header and the count, then 50 per triangle"
        size += f", and {extra} bytes more" if extra else ""
        if len(data) < expected:
            raise GoniometerError(
                f"'{path}' is a truncated binary STL: its header declares {declared} triangles "
                f"({expected} bytes), but the file's size implies {implied} ({size}). "
                "Re-export or copy it again."
            )
        raise GoniometerError(
            f"'{path}': the binary STL header declares {declared} triangles, but the file's "
            f"size implies {implied} ({size}). The header's count is wrong or the file was "
            "damaged; re-export it."
        )
    else:
        raise GoniometerError(
            f"'{path}' is not an STL file: too short for a binary STL and not ASCII "
            "('solid ...'). Re-export the mesh."
        )
    if not np.isfinite(corners).all():
        # Report before merging, so the message counts corners as the file stores them.
        return _finish(path, corners, None, None, source_dtype)
    points, triangles = _merge_exact(corners)
    return _finish(path, points, triangles, None, source_dtype)


def _stl_ascii_corners(data: bytes, path: Path) -> np.ndarray:
    """The ``(3 m, 3)`` corners of an ASCII STL, each facet line checked with its vertices."""
    text = _Text(data, path)
    facet_lines = text.keyword(b"facet")
    vertex_lines = text.keyword(b"vertex")
    # Facet normals are not used, so only their count is checked ("facet normal nx ny nz").
    numbers = text.word_counts(facet_lines) - 2
    if (numbers != 3).any():
        k = int(np.argmax(numbers != 3))
        raise GoniometerError(
            f"'{path}', line {facet_lines[k] + 1}: a 'facet' line is 'facet normal nx ny nz'; "
            f"this one has {max(numbers[k], 0)} numbers after 'facet normal'. The file is "
            "corrupt; re-export it."
        )
    values, counts = text.floats(vertex_lines, 6, "'vertex'")
    if (counts != 3).any():
        k = int(np.argmax(counts != 3))
        raise GoniometerError(
            f"'{path}', line {vertex_lines[k] + 1}: a 'vertex' line needs exactly three "
            f"coordinates; this one has {counts[k]} numbers. The file is corrupt; re-export it."
        )
    facet = np.searchsorted(facet_lines, vertex_lines)  # 1 + the facet each vertex line is in
    if vertex_lines.size and facet[0] == 0:
        raise GoniometerError(
            f"'{path}', line {vertex_lines[0] + 1}: a 'vertex' line before any 'facet' line; "
            "the file is corrupt."
        )
    per_facet = np.bincount(facet, minlength=facet_lines.size + 1)[1:]
    if (per_facet != 3).any():
        k = int(np.argmax(per_facet != 3))
        raise GoniometerError(
            f"'{path}', line {facet_lines[k] + 1}: this facet has {per_facet[k]} vertex lines, "
            "not 3 (an STL facet is one triangle). The file is corrupt; re-export it."
        )
    return values.reshape(-1, 3)


def _merge_exact(corners: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Merge corners with identical coordinates; vertices numbered by first appearance."""
    n = corners.shape[0]
    if n == 0:
        return np.empty((0, 3)), np.empty((0, 3), np.int64)
    # Comparisons treat -0.0 and 0.0 as equal, so they merge (the first one seen is kept).
    order = np.lexsort((corners[:, 2], corners[:, 1], corners[:, 0]))  # stable
    ranked = corners[order]
    new = np.ones(n, dtype=bool)
    new[1:] = (ranked[1:] != ranked[:-1]).any(axis=1)
    group = np.cumsum(new) - 1  # group id per sorted corner
    first = order[new]  # the first appearance of each group (lexsort is stable)
    renumber = np.empty(first.size, np.int64)
    renumber[np.argsort(first, kind="stable")] = np.arange(first.size)
    index = np.empty(n, np.int64)
    index[order] = renumber[group]
    points = np.empty((first.size, 3), dtype=np.float64)
    points[renumber] = corners[first]
    return points, index.reshape(-1, 3)


# ------------------------------------------------------------------------------------------ write


def write_ply(
    path: str | os.PathLike,
    points,
    triangles=None,
    normals=None,
    binary: bool = True,
) -> Path:
    """Write a PLY file with float64 ("double") coordinates, exactly readable by :func:`read_ply`.

    Parameters
    ----------
    path : str or path-like
        The file to write (overwritten).
    points : array_like
        ``(n, 3)`` finite coordinates.
    triangles : array_like, optional
        ``(m, 3)`` vertex indices; omitted for a point cloud.
    normals : array_like, optional
        ``(n, 3)`` per-vertex normals, written as ``nx ny nz``.
    binary : bool
        ``True`` for binary little-endian, ``False`` for ASCII (17 significant digits, so the
        values round-trip exactly).

    Returns
    -------
    pathlib.Path
        The written path.

    Raises
    ------
    GoniometerError
        If the arrays have the wrong shape, are not finite, indices are out of range, or the
        file cannot be written.
    """
    path = _as_path(path)
    points = np.asarray(points, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] != 3 or points.shape[0] == 0:
        raise GoniometerError(f"write_ply needs (n, 3) points with n > 0, got {points.shape}.")
    if not np.isfinite(points).all():
        raise GoniometerError("write_ply: some point coordinates are not finite.")
    n = points.shape[0]
    columns = [points]
    names = ["x", "y", "z"]
    if normals is not None:
        normals = np.asarray(normals, dtype=np.float64)
        if normals.shape != points.shape:
            raise GoniometerError(
                f"write_ply: normals must have the points' shape {points.shape}, "
                f"got {normals.shape}."
            )
        columns.append(normals)
        names += ["nx", "ny", "nz"]
    if triangles is not None:
        triangles = np.asarray(triangles)
        if triangles.ndim != 2 or triangles.shape[1] != 3 or triangles.dtype.kind not in "iu":
            raise GoniometerError(
                f"write_ply needs (m, 3) integer triangles, got {triangles.shape} "
                f"{triangles.dtype}."
            )
        if triangles.size and (triangles.min() < 0 or triangles.max() >= n):
            raise GoniometerError(
                f"write_ply: a triangle index is outside 0..{n - 1} (the points' range)."
            )
    header = [
        "ply",
        f"format {'binary_little_endian' if binary else 'ascii'} 1.0",
        "comment written by the Virtual Goniometer",
        f"element vertex {n}",
    ]
    header += [f"property double {name}" for name in names]
    if triangles is not None:
        header += [f"element face {len(triangles)}", "property list uchar int vertex_indices"]
    header.append("end_header")
    vertices = np.hstack(columns)
    try:
        with open(path, "wb") as file:
            file.write(("\n".join(header) + "\n").encode("ascii"))
            if binary:
                file.write(vertices.astype("<f8").tobytes())
                if triangles is not None:
                    faces = np.empty(len(triangles), [("n", "u1"), ("v", "<i4", (3,))])
                    faces["n"] = 3
                    faces["v"] = triangles
                    file.write(faces.tobytes())
            else:
                np.savetxt(file, vertices, fmt="%.17g")
                if triangles is not None:
                    np.savetxt(
                        file, np.column_stack([np.full(len(triangles), 3), triangles]), fmt="%d"
                    )
    except OSError as error:
        raise GoniometerError(f"Could not write '{path}': {error.strerror or error}.") from None
    return path
