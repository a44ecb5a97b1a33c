"""PLY files (ASCII and binary, either byte order): the reader; the writer is in mesh_ply_write."""

from __future__ import annotations

import os
import struct
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import GoniometerError
from .mesh_common import (
    MeshData,
    _as_path,
    _blank,
    _check_face_indices,
    _fan,
    _finish,
    _gather,
    _parse_numbers,
    _polygons,
    _read_bytes,
    _where_not_a_number,
)

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
    triangles = polygons = None
    if face is not None and face.count > 0:
        flat, counts = found["face"][face_list]
        flat = flat.astype(np.int64)
        _check_face_indices(flat, counts, len(points), path, lines.get("face"))
        triangles = _fan(flat, counts)
        polygons = _polygons(flat, counts)
    source_dtype = vertex.properties[names.index("x")].dtype.name
    return _finish(path, points, triangles, normals, source_dtype, polygons)


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
        start = pos
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
    else:  # every element read: bytes for another record mean the header's count is short
        last = elements[-1] if elements else None
        if last is not None and last.count and len(data) - pos >= _record_floor(last, pos - start):
            raise GoniometerError(
                f"'{path}': {len(data) - pos} bytes follow the last element the header declares "
                f"({last.count} '{last.name}'), at least as much as another record. The header's "
                "counts are wrong or the file has data too many; re-export it."
            )
    return found


def _record_floor(element: _PlyElement, size: int) -> float:
    """Fewer bytes than this after an ``element`` whose ``count`` records took ``size`` bytes
    cannot hold another record: the smaller of their mean size and the size of one with each
    list three long (a polygon's least)."""
    least = sum(
        p.dtype.itemsize if p.count_dtype is None else p.count_dtype.itemsize + 3 * p.dtype.itemsize
        for p in element.properties
    )
    return min(size / element.count, least)


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
