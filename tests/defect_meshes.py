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
