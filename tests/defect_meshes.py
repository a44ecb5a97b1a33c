"""Meshes with defects a scan can have, made for the tests of both lanes."""

import itertools

import numpy as np

from vg_addon.synthetic_meshes import wedge


def wedge_with_fin(angle, rows, *, below=-0.2):
    """A wedge (crease on the x axis) with a fin ``rows`` vertex spacings high standing straight
    up on the crease where x < ``below``: each crease edge there borders three triangles."""
    mesh = wedge(angle, n=60)
    points, triangles = np.asarray(mesh.points), np.asarray(mesh.triangles)
    crease = np.flatnonzero((points[:, 1] == 0) & (points[:, 2] == 0))
    crease = crease[np.argsort(points[crease, 0])]
    crease = crease[points[crease, 0] < below]
    xs = points[crease, 0]
    spacing = float(np.median(np.diff(xs)))
    rows_of = [crease]
    all_points, all_triangles = [points], [triangles]
    for k in range(1, rows + 1):
        first = sum(len(p) for p in all_points)
        all_points.append(np.column_stack([xs, np.zeros_like(xs), np.full_like(xs, k * spacing)]))
        rows_of.append(np.arange(first, first + len(xs)))
    for a, b in itertools.pairwise(rows_of):
        all_triangles.append(np.column_stack([a[:-1], a[1:], b[1:]]))
        all_triangles.append(np.column_stack([a[:-1], b[1:], b[:-1]]))
    return np.vstack(all_points), np.vstack(all_triangles)


def wedge_with_fragment(angle, gap, *, below=0.0):
    """A wedge (crease on the x axis) and, as a separate part no face joins to it, a sheet of
    its +1 face's triangles where x < ``below``, moved ``gap`` out along that face's normal and
    turned to face it: a second fragment refitted against the first, kept in one mesh."""
    mesh = wedge(angle, n=60)
    points, triangles = np.asarray(mesh.points), np.asarray(mesh.triangles)
    on_face = (mesh.side >= 0) & (points[:, 0] < below)
    faces = triangles[on_face[triangles].all(axis=1)]
    used = np.unique(faces)
    renumber = np.full(len(points), -1)
    renumber[used] = np.arange(used.size) + len(points)
    sheet = points[used] + gap * np.asarray(mesh.normal_plus)
    return np.vstack([points, sheet]), np.vstack([triangles, renumber[faces][:, ::-1]])


def wedge_with_debris(angle, count, *, seed=0, extent=0.1):
    """A wedge (crease on the x axis) and a loose sheet of scan debris: about ``count`` vertices
    in a crumpled grid of their own faces, ``extent`` either way of x = 0 and y = 0, floating
    0.05 above the crease."""
    mesh = wedge(angle, n=60)
    points, triangles = np.asarray(mesh.points), np.asarray(mesh.triangles)
    side = max(2, round(count**0.5))
    grid = np.linspace(-extent, extent, side)
    u, v = np.meshgrid(grid, grid, indexing="ij")
    rng = np.random.default_rng(seed)
    sheet = np.column_stack([u.ravel(), v.ravel(), 0.05 + 0.02 * rng.standard_normal(u.size)])
    ids = np.arange(side * side).reshape(side, side) + len(points)
    a, b, c, d = (
        ids[:-1, :-1].ravel(),
        ids[1:, :-1].ravel(),
        ids[1:, 1:].ravel(),
        ids[:-1, 1:].ravel(),
    )
    sheet_triangles = np.vstack([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    return np.vstack([points, sheet]), np.vstack([triangles, sheet_triangles])
