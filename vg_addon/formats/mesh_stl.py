"""STL files (binary and ASCII): the reader, with the corners merged into shared vertices."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..errors import GoniometerError
from .mesh_common import (
    MeshData,
    _as_path,
    _finish,
    _read_bytes,
    _Text,
)

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
    facet_lines = text.keyword(b"facet", ignore_case=True)
    vertex_lines = text.keyword(b"vertex", ignore_case=True)
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
    closing = text.keyword(b"endfacet", ignore_case=True)
    closed = np.zeros(facet_lines.size, dtype=bool)  # each facet's own endfacet, after its vertices
    if closing.size:
        owner = np.searchsorted(facet_lines, closing) - 1
        last_vertex = np.full(facet_lines.size, -1)
        if vertex_lines.size:
            last_vertex[facet - 1] = vertex_lines  # in order: the last one written stays
        ok = owner >= 0
        closed[owner[ok][closing[ok] > last_vertex[owner[ok]]]] = True
    ends = text.keyword(b"endsolid", ignore_case=True)
    if not closed.all() or not ends.size or (facet_lines.size and ends[-1] < facet_lines[-1]):
        k = int(np.argmin(closed)) if not closed.all() else facet_lines.size - 1
        where = (
            f"the facet at line {facet_lines[k] + 1} has no 'endfacet'"
            if not closed.all()
            else "no 'endsolid' line ends it"
        )
        raise GoniometerError(
            f"'{path}' is a truncated ASCII STL: {where}. The file was not written completely; "
            "re-export or copy it again."
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
