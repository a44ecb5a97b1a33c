"""The default rule's refinement (vg_addon.method.refinement): exact where the crease falls between
rows of vertices, unchanged where it does not apply. Oracles: the wedges' exact angles, the
oriented rule's own readings (the refinement must never read farther from the truth than them
on curved or rough walls), and bit-for-bit equality where nothing should move."""

from __future__ import annotations

import numpy as np
import pytest

from vg_addon import Surface
from vg_addon.method.algorithm import DEFAULT_RULE, RULES
from vg_addon.reference_shapes import marched_wedge
from vg_addon.synthetic_meshes import bevelled_wedge, bone_fragment, wedge


def _on_crease(points, direction):
    """The vertex nearest the crease among those near its middle (the patch stays off the ends)."""
    along = np.abs(points @ direction)
    off = np.linalg.norm(points - np.outer(points @ direction, direction), axis=1)
    return points[np.argmin(np.where(along < 0.05, off, np.inf))]


def test_refined_is_the_default():
    assert DEFAULT_RULE == "refined" and set(RULES) == {"refined", "oriented", "paper"}


@pytest.mark.parametrize(
    ("angle", "seed", "spacing"),
    [(a, s, 0.02) for a in (30, 45, 60, 75, 90, 105, 120, 135, 150, 165, 170, 175) for s in (3, 4)]
    + [(a, None, 0.013) for a in (40, 100, 160)],
)
def test_creases_between_vertex_rows_read_within_a_tenth(angle, seed, spacing):
    """Marched wedges: the crease between rows, the corner cut by the triangles across it; as a
    ridge and as a valley (the same triangles reversed), turned at random."""
    points, triangles, _, direction = marched_wedge(angle, spacing, turn_seed=seed)
    center = _on_crease(points, direction)
    for faces, convexity in ((triangles, "convex"), (triangles[:, ::-1], "concave")):
        surface = Surface(points, faces)
        m = surface.measure(center, 0.2)
        assert abs(m.angle - angle) < 0.1, (convexity, m.angle, m.split_angle)
        assert m.convexity == convexity and m.rule == "refined"


def test_the_refinement_is_what_makes_marched_creases_exact():
    """Without it (the oriented rule) the same creases read tenths of a degree to degrees off."""
    errors = []
    for angle in (30, 60, 90, 120):
        points, triangles, _, direction = marched_wedge(angle, 0.02, turn_seed=4)
        surface = Surface(points, triangles)
        center = _on_crease(points, direction)
        oriented = surface.measure(center, 0.2, rule="oriented")
        refined = surface.measure(center, 0.2)
        assert refined.split_angle == oriented.angle and refined.n_left_out > 0
        errors.append((abs(oriented.angle - angle), abs(refined.angle - angle)))
    assert all(before > 0.2 and after < 0.1 for before, after in errors), errors


@pytest.mark.parametrize("irregular", [False, True])
@pytest.mark.parametrize("concave", [False, True])
@pytest.mark.parametrize("angle", [5, 20, 60, 90, 135, 170, 175])
def test_creases_on_a_vertex_row_keep_their_bits(angle, concave, irregular):
    """Where Algorithm 1 is already exact nothing moves: the refined reading is the oriented
    reading, bit for bit."""
    mesh = wedge(angle, n=40, irregular=irregular, seed=angle, concave=concave)
    surface = Surface(mesh.points, mesh.triangles)
    refined = surface.measure([0.013, 0.0, 0.0], 0.5)
    oriented = surface.measure([0.013, 0.0, 0.0], 0.5, rule="oriented")
    assert refined.split_angle is None and refined.n_left_out == 0
    assert refined.angle == oriented.angle
    assert np.array_equal(refined.labels, oriented.labels)


def test_curved_walls_keep_the_oriented_reading_or_come_nearer():
    """The synthetic bone shaft: curved, rough walls with known angles. No reading gets worse."""
    bone = bone_fragment(spacing=0.6, roughness=0.05, seed=1)
    surface = Surface(bone.points, bone.triangles)
    for site in bone.sites:
        refined = surface.measure(site.point, 3.0)
        oriented = surface.measure(site.point, 3.0, rule="oriented")
        assert abs(refined.angle - site.angle) <= abs(oriented.angle - site.angle) + 1e-9


@pytest.mark.parametrize("angle", [20, 60, 90, 135])
def test_a_rounded_crease_reads_its_faces(angle):
    """A fillet of 1% of the radius: its vertices lie on neither face and are left out."""
    mesh = bevelled_wedge(angle, 0.01)
    top = mesh.points[np.argmin(np.abs(mesh.points[:, 0]) + np.abs(mesh.points[:, 1]))]
    surface = Surface(mesh.points, mesh.triangles)
    refined, oriented = surface.measure(top, 0.5), surface.measure(top, 0.5, rule="oriented")
    assert abs(refined.angle - angle) < 0.05 <= abs(oriented.angle - angle) or angle >= 135
    assert abs(refined.angle - angle) <= abs(oriented.angle - angle) + 1e-9


def test_the_paper_rule_is_unchanged_by_the_refinement():
    points, triangles, _, direction = marched_wedge(90, 0.02, turn_seed=3)
    surface = Surface(points, triangles)
    m = surface.measure(_on_crease(points, direction), 0.2, rule="paper")
    assert m.rule == "paper" and m.split_angle is None and m.n_left_out == 0
