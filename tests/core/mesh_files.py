"""What the mesh reader tests share: a small independent PLY writer (struct / text, not
``write_ply``, so the reader is checked against the format and not against itself), polygon
grids, and the check that a file is refused with its name and the reason."""

import struct

import numpy as np
import pytest

from vg_addon import GoniometerError
from vg_addon.formats.meshio import read_mesh

STRUCT_CODES = {
    "char": "b", "int8": "b", "uchar": "B", "uint8": "B", "short": "h", "int16": "h",
    "ushort": "H", "uint16": "H", "int": "i", "int32": "i", "uint": "I", "uint32": "I",
    "float": "f", "float32": "f", "double": "d", "float64": "d",
}  # fmt: skip
NUMPY_TYPES = {name: np.dtype(code) for name, code in STRUCT_CODES.items()}
FORMATS = ["ascii", "binary_little_endian", "binary_big_endian"]


# ------------------------------------------------------------------------------ a tiny PLY writer


def ply_bytes(fmt, elements, comments=("comment made by the test",)):
    """A PLY file. ``elements``: list of (name, properties, rows); a property is
    ``(name, type)`` or ``(name, "list", count_type, item_type)``; a row is a tuple with a
    sequence in place of each list."""
    header = ["ply", f"format {fmt} 1.0", *comments]
    for name, props, rows in elements:
        header.append(f"element {name} {len(rows)}")
        for prop in props:
            if prop[1] == "list":
                header.append(f"property list {prop[2]} {prop[3]} {prop[0]}")
            else:
                header.append(f"property {prop[1]} {prop[0]}")
    header.append("end_header")
    out = bytearray(("\n".join(header) + "\n").encode())
    order = {"binary_little_endian": "<", "binary_big_endian": ">"}.get(fmt)
    for _, props, rows in elements:
        for row in rows:
            if order is None:
                words = []
                for prop, value in zip(props, row, strict=True):
                    if prop[1] == "list":
                        words.append(str(len(value)))
                        words += [as_text(v, prop[3]) for v in value]
                    else:
                        words.append(as_text(value, prop[1]))
                out += (" ".join(words) + "\n").encode()
            else:
                for prop, value in zip(props, row, strict=True):
                    if prop[1] == "list":
                        out += struct.pack(order + STRUCT_CODES[prop[2]], len(value))
                        out += struct.pack(f"{order}{len(value)}{STRUCT_CODES[prop[3]]}", *value)
                    else:
                        out += struct.pack(order + STRUCT_CODES[prop[1]], value)
    return bytes(out)


def as_text(value, type_name):
    if NUMPY_TYPES[type_name].kind == "f":
        return repr(float(NUMPY_TYPES[type_name].type(value)))
    return str(int(value))


def fan(polygons):
    return [(p[0], p[i], p[i + 1]) for p in polygons for i in range(1, len(p) - 1)]


def grid_polygons(kind):
    """Vertices of a 4 x 3 grid and its faces: triangles, quads or mixed polygons."""
    points = [(0.1 * i - 0.05, 0.3 * j + 1 / 3, 0.01 * i * j) for j in range(3) for i in range(4)]
    quads = [
        (j * 4 + i, j * 4 + i + 1, j * 4 + i + 5, j * 4 + i + 4) for j in range(2) for i in range(3)
    ]
    if kind == "triangles":
        faces = fan(quads)
    elif kind == "quads":
        faces = quads
    else:  # a pentagon (two quads merged), quads and triangles
        faces = [(0, 1, 2, 6, 5), *quads[2:4], *fan(quads[4:])]
    return points, faces


def write_text(path, text):
    path.write_bytes(text.encode())
    return path


def expect_error(path, *fragments):
    with pytest.raises(GoniometerError) as caught:
        read_mesh(path)
    message = str(caught.value)
    assert path.name in message, message
    for fragment in fragments:
        assert fragment.lower() in message.lower(), message
    return message
