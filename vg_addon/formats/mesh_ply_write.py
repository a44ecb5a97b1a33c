"""Writing PLY files that :func:`vg_addon.formats.mesh_ply.read_ply` reads back exactly."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..errors import GoniometerError
from .mesh_common import _as_path


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
