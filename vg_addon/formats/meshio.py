"""Mesh file readers (PLY, OBJ, STL) and a PLY writer, vectorised with NumPy: the registry
(:data:`READERS`) and :func:`read_mesh`; each format is a module of its own (``mesh_ply``,
``mesh_obj``, ``mesh_stl``), their shared parts in ``mesh_common``.

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

from ..errors import GoniometerError
from .mesh_common import MeshData, _as_path
from .mesh_obj import read_obj
from .mesh_ply import read_ply
from .mesh_ply_write import write_ply
from .mesh_stl import read_stl

__all__ = [
    "MESH_EXTENSIONS",
    "READERS",
    "MeshData",
    "read_mesh",
    "read_obj",
    "read_ply",
    "read_stl",
    "write_ply",
]

# The one registry of mesh file types: extension (any case) -> reader. The batch plan, the CLI
# and :func:`read_mesh` all go by it.
READERS = {".ply": read_ply, ".obj": read_obj, ".stl": read_stl}
MESH_EXTENSIONS = tuple(READERS)


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
    reader = READERS.get(path.suffix.lower())
    if reader is None:
        kind = f"'{path.suffix}'" if path.suffix else "no extension"
        raise GoniometerError(
            f"Cannot read '{path}': unknown mesh format ({kind}). "
            "The Virtual Goniometer reads .ply, .obj and .stl files; export the mesh as one of them."
        )
    return reader(path)
