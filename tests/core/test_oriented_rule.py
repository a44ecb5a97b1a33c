"""The oriented rule (the default): concave and convex edges, inward winding, near-flat edges and
the convex/concave label, against exact wedges and against the paper's rule on negated normals."""

import numpy as np
import pytest

from vg_addon import GoniometerError, Surface, goniometer
from vg_addon.formats.meshio import read_mesh
from vg_addon.method.algorithm import WEAK_CORRELATION
from vg_addon.synthetic_meshes import wedge

CREASES = list(range(10, 171, 10))


def rotation(seed):
    q, r = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def folded_grid(angle, concave, n=161):
    """The issue's folded grid: z = ∓|x| tan((180 - θ)/2) on [-1, 1]², crease at x = 0."""
    g = np.linspace(-1.0, 1.0, n)
    x, y = np.meshgrid(g, g, indexing="ij")
    z = (1.0 if concave else -1.0) * np.abs(x) * np.tan(np.radians((180.0 - angle) / 2.0))
    ids = np.arange(n * n).reshape(n, n)
    a, b, c, d = ids[:-1, :-1].ravel(), ids[1:, :-1].ravel(), ids[1:, 1:].ravel(), ids[:-1, 1:]
    triangles = np.vstack([np.column_stack([a, b, c]), np.column_stack([a, c, d.ravel()])])
    return np.column_stack([x.ravel(), y.ravel(), z.ravel()]), triangles


@pytest.mark.parametrize("irregular", [False, True])
@pytest.mark.parametrize("concave", [False, True])
@pytest.mark.parametrize("angle", CREASES)
def test_creases_read_their_angle_and_convexity(angle, concave, irregular):
    mesh = wedge(angle, n=50, irregular=irregular, seed=angle, concave=concave)
    turn, shift = rotation(angle), np.array([3.0, -1.0, 2.0])
    surface = Surface(mesh.points @ turn.T + shift, mesh.triangles)
    m = surface.measure(turn @ [0.02, 0.01, 0.0] + shift, 0.5)
    assert abs(m.angle - angle) < 0.1
    assert m.convexity == ("concave" if concave else "convex")
    assert m.orientation == (-1 if concave else 1)
    assert m.rule == "refined"  # the default: the oriented rule, then the refinement
    assert m.split_angle is None  # a crease on a vertex row: nothing to refine, the same bits


@pytest.mark.parametrize("concave", [False, True])
@pytest.mark.parametrize("angle", [20, 60, 90, 135, 165])
def test_inward_winding_keeps_the_angle_and_swaps_the_label(angle, concave):
    mesh = wedge(angle, n=50, irregular=True, seed=angle + 1, concave=concave)
    outward = Surface(mesh.points, mesh.triangles).measure([0.03, 0.0, 0.0], 0.45)
    inward = Surface(mesh.points, mesh.triangles[:, ::-1]).measure([0.03, 0.0, 0.0], 0.45)
    assert abs(inward.angle - angle) < 0.1
    assert abs(inward.angle - outward.angle) < 1e-9
    assert {outward.convexity, inward.convexity} == {"convex", "concave"}


@pytest.mark.parametrize("angle", [30, 60, 90, 120, 150, 165])
def test_the_issues_folded_grid_valleys_are_exact(angle):
    """The table of issue 8: λ = 2, radius 0.1, centre on the crease (a coarser grid)."""
    valley = Surface(*folded_grid(angle, concave=True)).measure([0, 0, 0], 0.1)
    ridge = Surface(*folded_grid(angle, concave=False)).measure([0, 0, 0], 0.1)
    assert abs(valley.angle - angle) < 0.01
    assert abs(ridge.angle - angle) < 0.01
    assert (valley.convexity, ridge.convexity) == ("concave", "convex")


def test_the_paper_rule_still_misreads_a_valley():
    """What the oriented rule fixes: the paper's rule drags crease vertices to the wrong side."""
    surface = Surface(*folded_grid(120, concave=True))
    paper = surface.measure([0, 0, 0], 0.1, rule="paper")
    assert paper.angle > 130
    assert paper.orientation == 1
    assert paper.convexity == "concave"  # the label does not depend on the rule


def rows_wedge(angle, row_spacing, rows=4, spacing=0.02):
    """A wedge meshed in rows parallel to the crease, far apart across it: a coarse scan."""
    x = np.arange(-1.0, 1.0 + 1e-9, spacing)
    t = np.arange(-rows, rows + 1) * row_spacing
    xx, tt = np.meshgrid(x, t, indexing="ij")
    z = -np.abs(tt) * np.tan(np.radians((180.0 - angle) / 2.0))
    ids = np.arange(x.size * t.size).reshape(x.size, t.size)
    a, b, c, d = ids[:-1, :-1].ravel(), ids[1:, :-1].ravel(), ids[1:, 1:].ravel(), ids[:-1, 1:]
    triangles = np.vstack([np.column_stack([a, b, c]), np.column_stack([a, c, d.ravel()])])
    return np.column_stack([xx.ravel(), tt.ravel(), z.ravel()]), triangles


@pytest.mark.parametrize("angle", [160, 170, 175])
@pytest.mark.parametrize(("row_spacing", "radius"), [(0.2, 0.25), (0.2, 0.35), (0.3, 0.45)])
def test_near_flat_edge_with_one_row_per_side_shares_the_edge_row(angle, row_spacing, radius):
    surface = Surface(*rows_wedge(angle, row_spacing))
    m = surface.measure([0.0, 0.0, 0.0], radius)
    assert abs(m.angle - angle) < 0.01
    assert m.n_shared > 0  # the crease row completes the side that is a single row


def test_a_side_that_stays_a_line_is_refused_with_what_to_change():
    surface = Surface(*rows_wedge(175, 0.3))
    with pytest.raises(GoniometerError, match="larger radius"):
        surface.measure([0.0, 0.0, 0.0], 0.25)


def test_unknown_rule_is_refused():
    mesh = wedge(90, n=20)
    with pytest.raises(GoniometerError, match="'oriented'"):
        Surface(mesh.points, mesh.triangles).measure([0, 0, 0], 0.5, rule="literal")
    with pytest.raises(GoniometerError, match="'paper'"):
        goniometer(mesh.points, np.tile([0, 0, 1.0], (len(mesh.points), 1)), rule=3)


def test_angle_meaning_names_what_the_number_is():
    ridge = Surface(*folded_grid(100, concave=False)).measure([0, 0, 0], 0.1)
    valley = Surface(*folded_grid(100, concave=True)).measure([0, 0, 0], 0.1)
    assert "interior" in ridge.angle_meaning
    assert "open wedge" in valley.angle_meaning and "360°" in valley.angle_meaning


def test_real_scan_matches_the_paper_rule_on_oriented_normals(shared_data):
    """Oracle: the rule with sign -1 is the paper's rule on negated normals (b and n flip too).

    On the bone scan the oriented rule must read the paper's angle where the correlation is
    positive, the negated normals' angle where it is negative, and where the sign is weak the one
    of the two with the smaller fit error, labelled "unclear".
    """
    mesh = read_mesh(shared_data / "sample_mesh.ply")
    forward = Surface(mesh.points, mesh.triangles)
    backward = Surface(mesh.points, mesh.triangles, normals=-forward.normals)
    backward.valid = forward.valid
    radius = 0.04 * float(np.ptp(mesh.points, axis=0).max())
    rng = np.random.default_rng(2)
    seen = {"convex": 0, "concave": 0, "unclear": 0}

    def paper(surface, center):
        try:
            return surface.measure(center, radius, rule="paper")
        except GoniometerError:
            return None

    for vertex in rng.choice(forward.valid_ids, 120, replace=False):
        center = forward.points[vertex]
        plus, minus = paper(forward, center), paper(backward, center)
        try:
            m = forward.measure(center, radius, rule="oriented")
        except GoniometerError:
            assert plus is None or minus is None
            continue
        seen[m.convexity] += 1
        if abs(m.correlation) >= WEAK_CORRELATION:
            expected = plus if m.correlation >= 0 else minus
            assert m.angle == pytest.approx(expected.angle, abs=1e-9)
        else:
            assert m.convexity == "unclear"
            readings = [r for r in (plus, minus) if r is not None]
            best = min(readings, key=lambda r: r.fit_error)
            assert m.fit_error == pytest.approx(best.fit_error, rel=1e-9, abs=1e-300)
            assert m.angle == pytest.approx(best.angle, abs=1e-9)
            if len(readings) == 2:
                difference = abs(plus.angle - minus.angle)
                assert m.orientation_difference == pytest.approx(difference, abs=1e-9)
    assert all(count > 0 for count in seen.values()), seen


@pytest.mark.parametrize("angle", [20, 45, 90, 135, 160])
def test_a_bevelled_valley_reads_what_the_bevelled_ridge_reads(angle):
    """The rounded valley is the rounded ridge's complement (mirrored, normals outward): the same
    two planes, so the oriented rule must read the same angle; the paper's rule does not."""
    from vg_addon.synthetic_meshes import bevelled_wedge

    readings = []
    for concave in (False, True):
        mesh = bevelled_wedge(angle, 0.02, concave=concave)
        top = mesh.points[np.argmin(np.abs(mesh.points[:, 0]) + np.abs(mesh.points[:, 1]))]
        readings.append(Surface(mesh.points, mesh.triangles).measure(top, 0.5))
    ridge, valley = readings
    assert valley.angle == pytest.approx(ridge.angle, abs=1e-9)
    assert (ridge.convexity, valley.convexity) == ("convex", "concave")
    assert abs(ridge.angle - angle) < 1.0


def test_bevel_error_shrinks_with_the_fillet_and_vanishes_without_it():
    from vg_addon.synthetic_meshes import bevelled_wedge

    errors = []
    for fillet in (0.0, 0.01, 0.03, 0.06):
        mesh = bevelled_wedge(60, fillet, concave=True)
        top = mesh.points[np.argmin(np.abs(mesh.points[:, 0]) + np.abs(mesh.points[:, 1]))]
        surface = Surface(mesh.points, mesh.triangles)
        errors.append(abs(surface.measure(top, 0.5, rule="oriented").angle - 60))
        # The refinement leaves the rounding's vertices out where the faces are planes.
        assert abs(surface.measure(top, 0.5).angle - 60) <= errors[-1] + 1e-9
    assert errors[0] < 1e-9
    assert errors[0] < errors[1] < errors[2] < errors[3]
