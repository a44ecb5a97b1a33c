"""The stability figure's crease part: a reading off by the strip of vertices that cuts the corner
gets a figure at least as large as its error, or is undetermined with the reason. Oracle: the
exact angle each wedge was built with."""

import math

import numpy as np
import pytest

from vg_addon import GoniometerError, Surface
from vg_addon.method.crease_band import crease_change
from vg_addon.method.result import stored_stability_text, stored_stability_warning
from vg_addon.reference_shapes import stretched_wedge
from vg_addon.synthetic_meshes import wedge


def nearest_the_crease(points):
    return points[np.argmin(np.linalg.norm(points, axis=1))]


def covered(surface, center, exact, rule="refined"):
    """The reading, its figure, and whether the figure covers its error (or is undetermined);
    None where the measurement is refused."""
    try:
        m = surface.measure(center, 0.2, rule=rule, stability=True)
    except GoniometerError:
        return None
    figure = m.stability
    undetermined = figure.text() == "± ?"
    return m, undetermined or abs(m.angle - exact) <= figure.spread


@pytest.mark.parametrize("angle", [30, 90, 150])
def test_nothing_moves_on_a_crease_through_a_row_of_vertices(angle):
    """Every vertex on its face: leaving any out moves nothing, and the figure is as before."""
    mesh = wedge(angle, n=50, irregular=True, seed=angle)
    surface = Surface(mesh.points, mesh.triangles)
    m = surface.measure([0.02, 0.01, 0.0], 0.5, stability=True)
    s = m.stability
    assert s.crease < 1e-9 and s.crease_refused == 0
    assert s.spread == pytest.approx(max(s.center, s.radius, s.lam, s.bootstrap, s.orientation))
    assert abs(m.angle - angle) < 1e-6


@pytest.mark.parametrize("spacing", [0.009, 0.013])
@pytest.mark.parametrize("angle", [60, 120, 150, 165])
def test_algorithm_1_readings_off_by_the_strip_are_covered(angle, spacing):
    """The oriented rule keeps the strip that cuts the corner (0.1° to 2° off on these grids,
    which the figure was not tuned on); its perturbed runs all share that tilt, the crease part
    does not."""
    points, triangles = stretched_wedge(angle, spacing)
    surface = Surface(points, triangles)
    m, ok = covered(surface, nearest_the_crease(points), angle, rule="oriented")
    assert ok, (m.angle - angle, m.stability)
    assert m.stability.crease > 0.5 * abs(m.angle - angle)  # the part that covers it


# The readings issue 19 named (METHOD.md "What it does not fix"), and the same wedges with other
# seeds: each is right, refused, or shows a figure at least as large as its error.
NAMED = [(172, 0.0106, 0.0), (170, 0.0106, 0.01), (175, 0.0106, 0.01), (165, 0.02, 0.01)]


@pytest.mark.parametrize(("angle", "spacing", "jitter"), NAMED)
@pytest.mark.parametrize("seed", [7, 8])
def test_near_flat_creases_on_coarse_grids_are_covered_or_undetermined(
    angle, spacing, jitter, seed
):
    points, triangles = stretched_wedge(angle, spacing)
    rng = np.random.default_rng(seed)
    noisy = points + rng.normal(scale=jitter * spacing, size=points.shape)
    result = covered(Surface(noisy, triangles), nearest_the_crease(points), angle)
    if result is not None:
        m, ok = result
        assert ok, (m.angle - angle, m.stability)


def test_a_face_left_without_vertices_beyond_the_band_makes_the_figure_undetermined():
    """A near-flat valley on a coarse grid: each side is two rows, which always fit a plane
    exactly, so the figure's other parts are 0; without the row beside the crease a side is one
    row, and the figure says it cannot tell."""
    angle = 174.0
    flat, triangles = stretched_wedge(90.0, 0.0125)
    points = flat.copy()
    points[:, 1] *= math.tan(math.radians(angle) / 2.0)
    surface = Surface(points, triangles[:, ::-1])
    m = surface.measure(nearest_the_crease(points), 0.2, stability=True)
    s = m.stability
    assert s.crease_refused > 0 and s.text() == "± ?"
    assert "without the vertices next to the crease a face keeps too few" in s.warning
    assert not s.noise_hides_crease and "noise" not in s.warning  # the one reason that holds
    # The stored record (the list, the panel, the CSV) says the same.
    stored = {"spread": s.spread, "runs": s.n_runs, "refused": s.n_failed}
    assert stored_stability_text(stored) != "± ?"  # a record made before the crease part
    stored["crease_refused"] = s.crease_refused
    assert stored_stability_text(stored) == "± ?"
    # A record made before the noise was kept apart: its count may hold either reason.
    assert "or the vertex normals' noise is larger" in stored_stability_warning(stored)
    stored["noise_hides_crease"] = s.noise_hides_crease
    assert stored_stability_warning(stored) == s.warning


def test_the_crease_part_is_reproducible_and_added_to_the_spread():
    points, triangles = stretched_wedge(150.0, 0.011)
    rng = np.random.default_rng(3)
    surface = Surface(points + rng.normal(scale=1e-4, size=points.shape), triangles)
    m = surface.measure(nearest_the_crease(points), 0.2, rule="oriented", stability=True)
    s = m.stability
    others = max(s.center, s.radius, s.lam, s.bootstrap, s.orientation)
    assert s.spread == others + s.crease and s.crease > 0
    assert crease_change(surface, m) == (s.crease, s.crease_refused, s.noise_hides_crease)
    again = surface.measure(nearest_the_crease(points), 0.2, rule="oriented", stability=True)
    assert again.stability == s


def test_the_crease_columns_round_trip_and_older_exports_still_read():
    from csv_rows import cells, good_row

    from vg_addon.formats import csvio
    from vg_addon.method.result import stability_text

    row = good_row(stability=2.5, stability_crease=1.25, stability_crease_refused=2)
    (back,) = csvio.read_measurements_csv(csvio.format_measurements_csv([row]))
    assert (back.stability_crease, back.stability_crease_refused) == (1.25, 2)
    counts = (back.stability_runs, back.stability_refused, back.stability_crease_refused)
    assert stability_text(back.stability, *counts) == "± ?"
    # An export written before the crease part: its figure reads as it was written.
    written = cells(csvio.format_measurements_csv([good_row()]))
    keep = [i for i, c in enumerate(written[0]) if c not in csvio.CREASE_COLUMNS]
    text = "\n".join(",".join(f'"{line[i]}"' for i in keep) for line in written) + "\n"
    (old,) = csvio.read_measurements_csv(text)
    assert old.stability_crease is None and old.stability_crease_refused is None
    assert old.stability == good_row().stability


def test_the_noise_column_round_trips_and_older_exports_keep_both_reasons():
    """The noise reason has a column of its own; an export written before it counted the noise
    in ``Stability Crease Refused``, so its undetermined figures name both reasons."""
    from csv_rows import cells, good_row

    from vg_addon.formats import csvio
    from vg_addon.method.result import stability_warning

    def warning(row):
        noise = row.stability_noise_hides_crease
        counts = (row.stability_runs, row.stability_refused, row.stability_crease_refused)
        return stability_warning(row.stability, *counts, None if noise is None else bool(noise))

    noisy = good_row(stability_crease_refused=0, stability_noise_hides_crease=1)
    (back,) = csvio.read_measurements_csv(csvio.format_measurements_csv([noisy]))
    assert back.stability_noise_hides_crease == 1
    assert "noise is larger than the turn" in warning(back)
    assert "a face keeps too few" not in warning(back)
    banded = good_row(stability_crease_refused=1, stability_noise_hides_crease=0)
    (back,) = csvio.read_measurements_csv(csvio.format_measurements_csv([banded]))
    assert "a face keeps too few" in warning(back) and "noise" not in warning(back)
    written = cells(csvio.format_measurements_csv([banded]))
    keep = [i for i, c in enumerate(written[0]) if c not in csvio.NOISE_COLUMNS]
    assert len(keep) == len(written[0]) - 1
    text = "\n".join(",".join(f'"{line[i]}"' for i in keep) for line in written) + "\n"
    (old,) = csvio.read_measurements_csv(text)
    assert old.stability_noise_hides_crease is None
    assert "a face keeps too few" in warning(old) and "or the vertex normals' noise" in warning(old)


@pytest.mark.parametrize(("angle", "spacing"), [(5, 0.03), (10, 0.04)])
def test_a_wedge_thinner_than_the_mesh_cells_is_undetermined(angle, spacing):
    """Marched on a grid whose cells hold both faces across the whole patch, the vertices lie on
    planes that fit exactly but are not the faces: every band refits the same planes, so a figure
    of leaving bands out would read "± 0.00°" beside a reading degrees off."""
    from vg_addon.reference_shapes import marched_wedge

    points, triangles, _, _ = marched_wedge(angle, spacing)
    center = points[np.argmin(np.linalg.norm(points[:, :2], axis=1) + np.abs(points[:, 2]))]
    m = Surface(points, triangles).measure(center, 0.2, stability=True)
    assert abs(m.angle - angle) > 1.0  # the oracle: the mesh does not resolve this wedge
    assert m.stability.text() == "± ?" and m.stability.crease_refused > 0
    assert "without the vertices next to the crease a face keeps too few" in m.stability.warning


# Near-flat creases jittered by 3-5% of the grid: the vertex normals' noise across the tangent is
# larger than each face's turn, Algorithm 1's sides are mixed across the patch, and every run and
# band shares that (+3.5° to +11° off with figures of 0.9° to 5.2° before).
NOISY = [
    (172, 0.0067, 0.05, 1787),
    (175, 0.0106, 0.05, 1856),
    (171, 0.0125, 0.05, 505),
    (174, 0.0085, 0.03, 7),
    (168, 0.017, 0.05, 9),
]


@pytest.mark.parametrize(("angle", "spacing", "jitter", "seed"), NOISY)
def test_near_flat_creases_whose_normals_hide_the_crease_are_undetermined(
    angle, spacing, jitter, seed
):
    flat, triangles = stretched_wedge(90.0, spacing)
    points = flat.copy()
    points[:, 1] *= math.tan(math.radians(angle) / 2.0)
    noisy = points + np.random.default_rng(seed).normal(scale=jitter * spacing, size=points.shape)
    result = covered(Surface(noisy, triangles), nearest_the_crease(points), angle)
    assert result is not None
    m, ok = result
    assert ok, (m.angle - angle, m.stability)
    # The reason given is the noise, not a band left without a plane (none was).
    s = m.stability
    assert s.noise_hides_crease and s.crease_refused == 0 and s.text() == "± ?"
    assert "the vertex normals' noise is larger than the turn" in s.warning
    assert "a face keeps too few" not in s.warning


BANDS = "without the vertices next to the crease a face keeps too few"
NOISE = "the vertex normals' noise is larger than the turn"
EITHER = "or the vertex normals' noise is larger"


def test_each_reason_that_holds_is_given_and_the_record_keeps_them_apart():
    """A 168° crease on a grid of 0.017 reads 7.5° flat with every vertex on its face: each side
    is a few rows, and a band leaves one too few to fit its plane. Its vertex normals have no
    component along the crease (the z axis), so they cannot hide it: the band is the one reason.
    Jittered by 5% of the grid, the normals' component along the crease (measured against the
    true axis, not the reading's tangent) exceeds the turn between the faces the reading shows,
    and the band still fails: both reasons hold, each with its own sentence."""
    from vg_addon.formats import record_codec

    angle, spacing = 168.0, 0.017
    flat, triangles = stretched_wedge(90.0, spacing)
    points = flat.copy()
    points[:, 1] *= math.tan(math.radians(angle) / 2.0)
    center = nearest_the_crease(points)
    jitter = np.random.default_rng(0).normal(scale=0.05 * spacing, size=points.shape)
    clean, noisy = Surface(points, triangles), Surface(points + jitter, triangles)
    mc = clean.measure(center, 0.2, stability=True)
    mn = noisy.measure(center, 0.2, stability=True)

    def along_crease(surface, m):
        return float(np.sqrt(np.mean(surface.normals[m.indices][:, 2] ** 2)))

    assert abs(mc.angle - angle) > 5.0 and abs(mn.angle - angle) > 5.0  # a "± ?" is owed
    assert along_crease(clean, mc) < 1e-12
    assert along_crease(noisy, mn) > 2.0 * math.sin(math.radians(180.0 - mn.angle) / 2.0)

    s = mc.stability
    assert s.text() == "± ?" and s.crease_refused > 0 and not s.noise_hides_crease
    assert BANDS in s.warning and "noise" not in s.warning
    s = mn.stability
    assert s.text() == "± ?" and s.crease_refused > 0 and s.noise_hides_crease
    assert BANDS in s.warning and NOISE in s.warning and EITHER not in s.warning
    assert s.warning.count("Undetermined:") == 2

    # The record (the list, the panel, the label) keeps the two apart and reads back the same.
    stored = record_codec.decode(record_codec.encode(record_codec.measurement_numbers(mn)))
    parts = stored["stability"]
    assert parts["noise_hides_crease"] is True and parts["crease_refused"] == s.crease_refused
    assert stored_stability_warning(parts) == s.warning
    assert stored_stability_text(parts) == "± ?"
    # A record made before them counted the noise as one more band and has no key of its own:
    # it reads as then, undetermined, with the sentence naming both.
    del parts["noise_hides_crease"]
    parts["crease_refused"] += 1
    older = stored_stability_warning(parts)
    assert stored_stability_text(parts) == "± ?" and EITHER in older
    assert older.count("Undetermined:") == 1


def test_a_small_patch_counts_each_band_once():
    """Where a mesh spacing is more than half the radius both spacing bands clamp to half the
    radius: with the quarter radius band that is two distinct bands, each counted once."""
    from vg_addon.method.refinement import mean_edge_length

    mesh = wedge(120, n=6, irregular=True, seed=1)
    surface = Surface(mesh.points, mesh.triangles)
    m = surface.measure([0.0, 0.0, 0.0], 0.45, stability=True)
    assert mean_edge_length(m.radius, m.n_vertices) > 0.5 * m.radius
    assert abs(m.angle - 120.0) < 1e-9
    assert crease_change(surface, m) == (pytest.approx(0.0, abs=1e-9), 2, False)
    assert m.stability.crease_refused == 2


def test_a_side_that_borrows_the_edge_row_is_always_undetermined():
    """A side that is one row of vertices off the edge has a plane only with the edge's row,
    which the other side fits too: nothing in the patch tests that the row lies on both faces, so
    however exact the reading (it is here, on planar faces) the figure does not vouch for it."""
    from test_oriented_rule import rows_wedge

    surface = Surface(*rows_wedge(170, 0.2))
    m = surface.measure([0.0, 0.0, 0.0], 0.35, stability=True)
    assert m.n_shared > 0 and abs(m.angle - 170.0) < 0.01
    s = m.stability
    assert s.text() == "± ?" and s.crease_refused > 0 and s.n_failed == s.n_runs


@pytest.mark.parametrize("jitter", [0.01, 0.02])
@pytest.mark.parametrize("angle", [120, 135, 150, 165])
def test_normals_that_tell_the_faces_apart_do_not_make_the_figure_undetermined(angle, jitter):
    """A guard against refusing right readings: on obtuse creases jittered by 1-2% of the grid
    the vertex normals' noise along the tangent is far below each face's turn, the reading lies
    within its figure (oracle: the angle the wedge was built with), and the figure is a number."""
    from vg_addon.method.crease_band import _normals_hide_the_crease

    spacing = 0.0106
    points, triangles = stretched_wedge(angle, spacing)
    rng = np.random.default_rng(1)
    surface = Surface(points + rng.normal(scale=jitter * spacing, size=points.shape), triangles)
    m = surface.measure(nearest_the_crease(points), 0.2, stability=True)
    assert abs(m.angle - angle) <= m.stability.spread, (m.angle - angle, m.stability)
    assert not _normals_hide_the_crease(surface.normals[m.indices], m.tangent, m.angle)
    assert m.stability.text() != "± ?"


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_a_non_finite_distance_to_the_crease_line_measures_no_strip(bad):
    """The strip's bands are binned by distance to the line; a non-finite one cast to an integer
    is a negative bin, which ``np.bincount`` refuses with a traceback. No strip is measured."""
    from vg_addon.method.planes import side_plane
    from vg_addon.method.refinement import _strip_width

    mesh = wedge(120, n=30, irregular=True, seed=2)
    points = mesh.points - mesh.points.mean(axis=0)
    side = np.ones(points.shape[0], dtype=bool)
    plane = side_plane(points, np.tile([0.0, 0.0, 1.0], (points.shape[0], 1)), side)
    to_line = np.linalg.norm(points[:, :2], axis=1)
    assert _strip_width(points, side, side, plane, plane[0], to_line, 0.05) >= 0.0
    to_line[3] = bad
    assert _strip_width(points, side, side, plane, plane[0], to_line, 0.05) == 0.0
