"""The default rule's refinement (vg_addon.method.refinement): exact where the crease falls between
rows of vertices, unchanged where it does not apply. Oracles: the wedges' exact angles, the
oriented rule's own readings (the refinement must never read farther from the truth than them
on curved or rough walls), and bit-for-bit equality where nothing should move."""

from __future__ import annotations

import numpy as np
import pytest

from vg_addon import GoniometerError, Surface
from vg_addon.method.algorithm import DEFAULT_RULE, RULES
from vg_addon.method.refinement import _median
from vg_addon.reference_shapes import _turn, marched_wedge, stretched_wedge
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
    [(a, s, 0.02) for a in (20, 30, 45, 60, 90, 120, 135, 150, 165, 170, 175) for s in (3, 4)]
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


@pytest.mark.parametrize("spacing", [0.0106, 0.02])
@pytest.mark.parametrize("angle", [5, 20, 45, 90, 120, 150])
def test_wedges_made_as_the_authors_make_them_read_exact(angle, spacing):
    """A right-angled wedge marched, then stretched across the crease: the rows of vertices move
    apart and the row the triangles cut the corner through lies on neither face."""
    points, triangles = stretched_wedge(angle, spacing)
    center = points[np.argmin(np.linalg.norm(points, axis=1))]
    oriented = Surface(points, triangles).measure(center, 0.2, rule="oriented")
    for faces in (triangles, triangles[:, ::-1]):
        m = Surface(points, faces).measure(center, 0.2)
        assert abs(m.angle - angle) < 0.1, (m.angle, oriented.angle)
    assert abs(oriented.angle - angle) > 0.05  # the oracle case is not trivial for Algorithm 1


def test_a_side_of_one_row_beside_a_row_off_both_faces_is_refused():
    """A near-flat wedge so stretched that one face holds a single row in the patch, and the row
    beside it across the crease lies on neither face: no plane is determined for that side.
    Algorithm 1 borrows that row and reads degrees off; the refined rule says why it cannot."""
    points, triangles = stretched_wedge(172.0, 0.015)
    center = points[np.argmin(np.linalg.norm(points, axis=1))]
    surface = Surface(points, triangles)
    oriented = surface.measure(center, 0.25, rule="oriented")
    assert oriented.n_shared > 0 and abs(oriented.angle - 172.0) > 1.0
    with pytest.raises(GoniometerError, match="single row of vertices"):
        surface.measure(center, 0.25)


def test_an_undetermined_figure_shows_no_number():
    """Where nearly every perturbed run is refused, the figure of the few left would vouch for a
    reading degrees off: it shows "± ?" and says why."""
    points, triangles = stretched_wedge(172.0, 0.02)
    center = points[np.argmin(np.linalg.norm(points, axis=1))]
    m = Surface(points, triangles).measure(center, 0.2, stability=True)
    assert m.stability.n_failed > 0.5 * m.stability.n_runs
    assert m.stability.text() == "± ?" and "Undetermined" in m.stability.warning
    assert "± ?" in m.summary()


def _jittered(points, spacing, seed):
    """Every vertex moved off its face at random by 1% of the grid spacing, as a scanner's noise."""
    return points + np.random.default_rng(seed).normal(scale=0.01 * spacing, size=points.shape)


@pytest.mark.parametrize(
    ("angle", "spacing", "jitter"),
    [(170, 0.0106, False), (20, 0.0106, True), (120, 0.015, True), (165, 0.0106, True)],
)
def test_wide_strips_on_stretched_wedges_read_exact(angle, spacing, jitter):
    """Stretched across the crease, a near-flat wedge's rows lie far apart: the strip that cuts
    the corner is three of a face's seven rows, more than the shares a scan's strip takes, but all
    of it nearer the crease than what is kept. With 1% noise, a few vertices away from the crease
    lie beyond the outlier limit too; neither keeps Algorithm 1's drift."""
    points, triangles = stretched_wedge(angle, spacing)
    center = points[np.argmin(np.linalg.norm(points, axis=1))]
    if jitter:
        points = _jittered(points, spacing, angle)
    oriented = Surface(points, triangles).measure(center, 0.2, rule="oriented")
    assert abs(oriented.angle - angle) > 0.2
    for faces in (triangles, triangles[:, ::-1]):
        m = Surface(points, faces).measure(center, 0.2)
        assert abs(m.angle - angle) < 0.1 and m.split_angle is not None, (m.angle, oriented.angle)


@pytest.mark.parametrize(("angle", "spacing"), [(165, 0.015), (160, 0.02)])
def test_a_face_of_too_few_rows_beside_a_strip_is_refused(angle, spacing):
    """Without the strip that cuts the corner, a face keeps two rows of vertices in the patch:
    they fit a plane, but so do two rows of any curved wall, so the angle is not determined.
    Algorithm 1 read these 2.3° and 3.5° off; the refined rule says why it cannot read them."""
    points, triangles = stretched_wedge(angle, spacing)
    center = points[np.argmin(np.linalg.norm(points, axis=1))]
    surface = Surface(points, triangles)
    assert abs(surface.measure(center, 0.2, rule="oriented").angle - angle) > 1.0
    with pytest.raises(GoniometerError, match="too few rows of vertices"):
        surface.measure(center, 0.2)


def test_a_face_left_one_row_beside_a_strip_is_refused():
    """At 175° on grid 0.0106 one face holds three rows in the patch, two of them in the strip
    that cuts the corner: without them it is one row, and no plane. Algorithm 1 read +2.45° with a
    stability figure of ± 0.1°; the refined rule says why it cannot read it."""
    points, triangles = stretched_wedge(175.0, 0.0106)
    center = points[np.argmin(np.linalg.norm(points, axis=1))]
    surface = Surface(points, triangles)
    assert abs(surface.measure(center, 0.2, rule="oriented").angle - 175.0) > 2.0
    with pytest.raises(GoniometerError, match="single row of vertices in the patch"):
        surface.measure(center, 0.2)


@pytest.mark.parametrize("size", [1, 2, 3, 10, 11, 999, 1000])
def test_the_fast_median_is_numpys_bit_for_bit(size):
    """The refinement's median skips np.median's wrapper; oracle: np.median itself."""
    rng = np.random.default_rng(size)
    for scale in (1e-12, 1.0, 1e9):
        values = rng.normal(size=size) * scale
        assert _median(values) == float(np.median(values))


def test_a_curved_rim_traced_at_a_small_radius_is_read_not_refused():
    """Along the bone shaft's oblique rim (a plane meeting the curved outer wall) at a 1 mm patch,
    five mesh spacings: leaving a strip out helps the plane fit 15-fold there, but the wall's
    misfit is its curvature, and nothing shows Algorithm 1's reading is off. No station is
    refused; each reads within 1.5° of the exact rim angle (the curvature costs about 1° at 1 mm;
    oracle: the rim's geometry, 180° minus the angle between the cylinder's and the oblique
    plane's normals)."""
    fragment = bone_fragment()
    surface = Surface(fragment.points, fragment.triangles)
    sites = {site.label: site.point for site in fragment.sites}
    path = surface.trace_edge(
        sites["oblique/outer acute"],
        sites["oblique/outer obtuse"],
        via=[sites["oblique/outer side"]],
    )
    plane = np.array([-np.tan(np.radians(35.0)), 0.0, 1.0])
    plane /= np.linalg.norm(plane)
    for center in path.points[:: max(1, path.points.shape[0] // 40)]:
        radial = center[:2] / np.linalg.norm(center[:2])
        exact = 180.0 - np.degrees(np.arccos(radial @ plane[:2]))
        m = surface.measure(center, 1.0)
        assert abs(m.angle - exact) < 1.5, (center, m.angle, exact)


def _stretched_and_jittered(angle, spacing, jitter, seed, turn_seed):
    """A stretched wedge (the authors' construction) with every vertex moved at random by
    ``jitter`` grid spacings, turned at random; its crease passes through the turned origin."""
    points, triangles = stretched_wedge(angle, spacing)
    center = points[np.argmin(np.linalg.norm(points, axis=1))]
    points = points + np.random.default_rng(seed).normal(scale=jitter * spacing, size=points.shape)
    turn = _turn(turn_seed)
    return points @ turn.T, triangles, center @ turn.T


@pytest.mark.parametrize(
    ("angle", "spacing", "seed"),
    [(60, 0.009, 901), (100, 0.0125, 902), (150, 0.0125, 904), (120, 0.0106, 905)],
)
def test_a_strip_hidden_in_noise_is_found_by_where_its_vertices_lie_on_average(
    angle, spacing, seed
):
    """With noise of 5% of the grid spacing, single vertices of the strip that cuts the corner
    no longer stand out, and leaving out the outliers does not cut the fit error 4-fold; the
    strip's vertices still lie on average towards the other face, band by band along the crease.
    Oracle: the wedge's exact angle from its construction, on grids, seeds and turns the rule was
    not tuned on; as a ridge and as a valley."""
    points, triangles, center = _stretched_and_jittered(angle, spacing, 0.05, seed, seed)
    oriented = Surface(points, triangles).measure(center, 0.2, rule="oriented")
    assert abs(oriented.angle - angle) > 0.1  # Algorithm 1 is off here
    for faces in (triangles, triangles[:, ::-1]):
        m = Surface(points, faces).measure(center, 0.2)
        assert abs(m.angle - angle) < 0.1 and m.n_left_out > 0, (m.angle, oriented.angle)


def test_strip_bands_far_from_the_line_make_no_bin_per_spacing_up_to_it():
    # Near-parallel planes put their line far from the patch: the bands are binned by what they
    # hold, not by every spacing up to the line (a bincount that long would not fit in memory).
    from vg_addon.method.refinement import _strip_width

    rng = np.random.default_rng(5)
    count = 400
    points = np.column_stack(
        [rng.uniform(-1, 1, count), rng.uniform(-1, 1, count), np.zeros(count)]
    )
    side = np.ones(count, dtype=bool)
    plane = (np.array([0.0, 0.0, 1.0]), np.zeros(3), 0.0)
    to_line = 1e15 + np.abs(points[:, 0])  # spacings 0.1: 1e16 bins before
    width = _strip_width(points, side, side, plane, np.array([0.0, 0.0, 1.0]), to_line, 0.1)
    assert width == 0.0  # a flat side: no band lies towards the other face
    assert _strip_width(points, side, ~side, plane, plane[0], to_line, 0.1) == 0.0


def test_strip_width_is_the_raised_bands_whether_the_line_is_near_or_far():
    # A side whose vertices within three spacings of the line lie towards the other face: the
    # strip is those three bands, counted from the line, whether the bands are binned one per
    # spacing (line through the patch) or by what they hold (line far away). Binary fractions
    # keep every band number exact.
    from vg_addon.method.refinement import _strip_width

    rng = np.random.default_rng(11)
    count, spacing = 400, 0.125
    distance = rng.uniform(0.0, 2.0, count)
    height = np.where(distance < 3 * spacing, 0.5, rng.normal(scale=0.01, size=count))
    points = np.column_stack([distance, np.zeros(count), height])
    side = np.ones(count, dtype=bool)
    plane = (np.array([0.0, 0.0, 1.0]), np.zeros(3), 0.0)
    up = np.array([0.0, 0.0, 1.0])
    for offset in (0.0, 2.0**20 * spacing):
        width = _strip_width(points, side, side, plane, up, offset + distance, spacing)
        assert width == offset + 3 * spacing
    flat = points.copy()
    flat[:, 2] = rng.normal(scale=0.01, size=count)
    assert _strip_width(flat, side, side, plane, up, distance, spacing) == 0.0
