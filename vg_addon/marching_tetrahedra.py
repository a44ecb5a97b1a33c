"""A closed triangle mesh of the zero level set of a function sampled on a grid.

Marching tetrahedra: each grid cube is split into six tetrahedra around its main diagonal (the
same split in every cube, so neighbouring cubes share their face diagonals and the surface is
watertight), and each tetrahedron whose corners change sign holds one triangle or two. Like
marching cubes, the surface runs through the cells, so creases come out bevelled and flat faces
slightly rippled: the kind of mesh the reference meshes of the project are. Vectorised: no
Python loop over cells or vertices.
"""

from __future__ import annotations

import numpy as np

from .errors import GoniometerError

# Corner k of a cube sits at offset (k & 1, (k >> 1) & 1, (k >> 2) & 1); six tetrahedra share
# the diagonal from corner 0 to corner 7.
_CORNERS = np.array([(k & 1, (k >> 1) & 1, (k >> 2) & 1) for k in range(8)])
_TETRAHEDRA = np.array(
    [(0, 1, 3, 7), (0, 3, 2, 7), (0, 2, 6, 7), (0, 6, 4, 7), (0, 4, 5, 7), (0, 5, 1, 7)]
)

MAX_GRID_POINTS = 50_000_000
"""The largest grid sampled (400 MB of float64 values): a finer spacing is refused."""


def march(function, lower, upper, spacing: float) -> tuple[np.ndarray, np.ndarray]:
    """Triangulate ``{p : function(p) = 0}`` inside a box, wound with normals towards
    ``function > 0`` (outward, for a function negative inside the solid).

    Parameters
    ----------
    function : callable
        ``(n, 3) float64 -> (n,)``: negative inside the solid, positive outside. It should be
        nowhere exactly 0 on the grid (shift ``lower`` by a fraction of ``spacing`` if it is).
    lower, upper : array_like, shape (3,)
        Opposite corners of the box sampled; the solid must lie strictly inside it.
    spacing : float
        The grid step.

    Returns
    -------
    points : ndarray, shape (n, 3), float64
    triangles : ndarray, shape (m, 3), int64
    """
    lower = np.asarray(lower, dtype=np.float64)
    upper = np.asarray(upper, dtype=np.float64)
    shape = np.floor((upper - lower) / spacing).astype(np.int64) + 1
    if np.prod(shape, dtype=np.float64) > MAX_GRID_POINTS:
        raise GoniometerError(
            f"A spacing of {spacing:g} samples {int(np.prod(shape, dtype=np.float64)):,} grid "
            f"points, more than {MAX_GRID_POINTS:,}: use a coarser spacing."
        )
    axes = [lower[k] + spacing * np.arange(shape[k]) for k in range(3)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    values = np.asarray(function(grid), dtype=np.float64)
    if (values == 0.0).any():
        raise GoniometerError(
            "The function is exactly 0 at a grid point: shift the box by a fraction of the spacing."
        )
    inside = values < 0.0
    strides = np.array([shape[1] * shape[2], shape[2], 1])
    # Cubes with corners on both sides (the only ones that hold surface).
    cube_ids = np.stack(
        np.meshgrid(*[np.arange(n - 1) for n in shape], indexing="ij"), axis=-1
    ).reshape(-1, 3)
    corner_offsets = _CORNERS @ strides
    base = cube_ids @ strides
    corners = base[:, None] + corner_offsets[None, :]
    corner_inside = inside[corners]
    mixed = corner_inside.any(axis=1) & ~corner_inside.all(axis=1)
    tets = corners[mixed][:, _TETRAHEDRA].reshape(-1, 4)
    tet_inside = inside[tets]
    n_inside = tet_inside.sum(axis=1)

    triangles = []  # as pairs of grid vertices (the edges the triangle's corners lie on)
    facing = []  # a direction from inside to outside for each triangle
    order = np.argsort(~tet_inside, axis=1, kind="stable")  # inside corners first
    ranked = np.take_along_axis(tets, order, axis=1)
    for count in (1, 2, 3):
        group = ranked[n_inside == count]
        if not group.size:
            continue
        ins, outs = group[:, :count], group[:, count:]
        direction = grid[outs].mean(axis=1) - grid[ins].mean(axis=1)
        if count == 1:
            edges = [(ins[:, 0], outs[:, k]) for k in range(3)]
            triangles.append(np.stack([np.stack(e, axis=1) for e in edges], axis=1))
            facing.append(direction)
        elif count == 3:
            edges = [(ins[:, k], outs[:, 0]) for k in range(3)]
            triangles.append(np.stack([np.stack(e, axis=1) for e in edges], axis=1))
            facing.append(direction)
        else:  # a quad on edges i0o0, i0o1, i1o1, i1o0, in order round it
            quad = [(ins[:, 0], outs[:, 0]), (ins[:, 0], outs[:, 1])]
            quad += [(ins[:, 1], outs[:, 1]), (ins[:, 1], outs[:, 0])]
            corners4 = np.stack([np.stack(e, axis=1) for e in quad], axis=1)
            triangles.append(corners4[:, [0, 1, 2]])
            triangles.append(corners4[:, [0, 2, 3]])
            facing += [direction, direction]
    pairs = np.concatenate(triangles)  # (m, 3, 2) grid vertex ids: inside end, outside end
    facing = np.concatenate(facing)

    # One surface vertex per grid edge crossed, shared by every triangle that uses it.
    keys = pairs[..., 0] * grid.shape[0] + pairs[..., 1]
    unique, corner_vertex = np.unique(keys.ravel(), return_inverse=True)
    ends = np.stack([unique // grid.shape[0], unique % grid.shape[0]], axis=1)
    a, b = values[ends[:, 0]], values[ends[:, 1]]
    t = a / (a - b)
    points = grid[ends[:, 0]] + t[:, None] * (grid[ends[:, 1]] - grid[ends[:, 0]])
    tris = corner_vertex.reshape(-1, 3).astype(np.int64)
    normal = np.cross(
        points[tris[:, 1]] - points[tris[:, 0]], points[tris[:, 2]] - points[tris[:, 0]]
    )
    flip = np.einsum("ij,ij->i", normal, facing) < 0
    tris[flip] = tris[flip][:, [0, 2, 1]]
    return points, tris
