"""Where a break edge's crest is placed before tracing: the middle of a rounded edge, not where
two floods happen to meet, and via points that never lie behind the leg they split.

Oracles: a filleted prism built here, whose fillet's middle line is known from its geometry,
and points on a line, whose order is known.
"""

import math

import numpy as np

from vg_addon import Surface
from vg_addon.method.edge_pieces import Piece, _via, balanced_crest
from vg_addon.method.edge_profile import ridge_graph
from vg_addon.method.normals import vertex_normals

H = 0.25
"""Spacing of the prism's vertices (mm)."""

RADIUS = 1.5
ARC_STEPS = 8
"""The fillet's quarter circle in this many steps: an even number, so its middle is a vertex."""


def filleted_prism():
    """A flat top (normal +z) rounded by a quarter-circle fillet into a vertical side (normal
    +x), extruded along y; the profile's points and which of them is the fillet's middle."""
    top = np.column_stack([np.arange(-24, 0) * H, np.zeros(24)])
    phi = np.linspace(0.0, math.pi / 2, ARC_STEPS + 1)
    arc = np.column_stack([RADIUS * np.sin(phi), RADIUS * np.cos(phi) - RADIUS])
    side = np.column_stack([np.full(24, RADIUS), -RADIUS - np.arange(1, 25) * H])
    profile = np.vstack([top, arc, side])
    middle = top.shape[0] + ARC_STEPS // 2
    ys = np.arange(41) * H
    n_profile, n_y = profile.shape[0], ys.size
    points = np.column_stack(
        [np.tile(profile[:, 0], n_y), np.repeat(ys, n_profile), np.tile(profile[:, 1], n_y)]
    )
    i, j = np.meshgrid(np.arange(n_profile - 1), np.arange(n_y - 1), indexing="ij")
    a = (j * n_profile + i).ravel()
    b, c, d = a + 1, a + n_profile, a + n_profile + 1
    triangles = np.vstack([np.column_stack([a, c, b]), np.column_stack([b, c, d])])
    return points, triangles, n_profile, n_y, middle


def test_the_crest_of_a_fillet_moves_to_its_middle_from_a_meeting_line_beside_it():
    points, triangles, n_profile, n_y, middle = filleted_prism()
    surface = Surface(points, triangles)
    graph = ridge_graph(surface)
    column = np.tile(np.arange(n_profile), n_y)
    # The floods met two vertices off the middle, towards the side; the fillet is band.
    meet = middle + 2
    flooded = np.where(column <= meet, 0, 1)
    band = (column >= middle - ARC_STEPS // 2) & (column <= middle + ARC_STEPS // 2)
    crest = np.flatnonzero((column == meet) | (column == meet + 1))
    ends = crest[(points[crest, 1] == 0) | (points[crest, 1] == points[:, 1].max())]
    normals, _ = vertex_normals(points, triangles)
    moved = balanced_crest(graph, Piece(crest, (0, 1), ends), flooded, band, normals, rings=12)
    # The fillet's middle line: x = z + R = R sin 45°, every y.
    on_middle = np.abs(points[moved.vertices, 0] - RADIUS * math.sin(math.pi / 4)) < 1e-9
    assert on_middle.all(), points[moved.vertices[~on_middle]]
    assert moved.vertices.size == n_y  # the whole line, one vertex wide
    assert moved.regions == (0, 1) and np.array_equal(moved.ends, ends)


def test_a_ridge_inside_one_region_or_beside_a_curved_side_keeps_its_crest():
    points, triangles, n_profile, n_y, middle = filleted_prism()
    surface = Surface(points, triangles)
    graph = ridge_graph(surface)
    column = np.tile(np.arange(n_profile), n_y)
    crest = np.flatnonzero(column == middle)
    normals, _ = vertex_normals(points, triangles)
    flooded = np.where(column <= middle, 0, 1)
    band = np.zeros(column.size, dtype=bool)
    inside = Piece(crest, (-1, -1), crest[:0])
    assert balanced_crest(graph, inside, flooded, band, normals, rings=6) is inside
    # Side 1 taken as the whole fillet and the side: their normals turn through 90° and
    # average to a vector about 0.91 long, no mean stands for them.
    flooded = np.where(column < middle - ARC_STEPS // 2, 0, 1)
    curved = Piece(crest, (0, 1), crest[:0])
    assert balanced_crest(graph, curved, flooded, band, normals, rings=30) is curved


def test_a_via_point_lies_between_the_ends_of_the_leg_it_splits():
    points = np.column_stack([np.arange(10.0), np.zeros(10), np.zeros(10)])
    crest_ids = np.array([0, 2, 5, 9])
    # Nearest the middle of the stray run is vertex 9, beyond the leg's end 6: not taken.
    assert _via(points, 1, 6, points[8], points[crest_ids], crest_ids) == 5
    # Nothing on the crest between 4 and 5: the leg's start comes back (no split).
    assert _via(points, 4, 5, points[4], points[crest_ids], crest_ids) == 4
