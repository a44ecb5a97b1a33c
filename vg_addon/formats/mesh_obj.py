"""Wavefront OBJ files: the reader (vertices, faces, polygons fan-triangulated)."""

from __future__ import annotations

import os

import numpy as np

from ..errors import GoniometerError
from .mesh_common import (
    MeshData,
    _as_path,
    _fan,
    _finish,
    _polygons,
    _read_bytes,
    _Text,
)


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
    data = _read_bytes(path)
    # A byte-order mark (as Windows editors write) would hide the first line's keyword.
    text = _Text(data[3:] if data.startswith(b"\xef\xbb\xbf") else data, path)
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
    triangles = corners = normal_refs = polygons = None
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
        polygons = _polygons(corners, counts)

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
    return _finish(path, points, triangles, normals, "float64", polygons)


def _obj_indices(refs, counts, before, lines, path, what) -> np.ndarray:
    """OBJ references (1-based, or negative = relative to the ones defined so far) to 0-based."""
    if (refs == 0).any():
        bad = lines[np.repeat(np.arange(counts.size), counts)[refs == 0][0]]
        raise GoniometerError(
            f"'{path}', line {bad + 1}: face {what} index 0 is invalid (OBJ indices start at 1)."
        )
    defined = np.repeat(before, counts)
    return np.where(refs < 0, refs + defined, refs - 1)
