"""The stability figure: its batched runs against single measurements, and its growth with noise."""

import numpy as np
import pytest

from vg_addon import GoniometerError, Surface
from vg_addon.formats.meshio import read_mesh
from vg_addon.method.stability import (
    bootstrap_angles,
    mean_edge_length,
    perturbations,
    perturbed_angles,
)
from vg_addon.reference_shapes import half_annulus
from vg_addon.synthetic_meshes import wedge


def noisy_wedge(angle, noise, seed=0, concave=False):
    mesh = wedge(angle, n=50, irregular=True, seed=seed, concave=concave)
    rng = np.random.default_rng(seed)
    return Surface(mesh.points + rng.normal(scale=noise, size=mesh.points.shape), mesh.triangles)


def check_runs_against_single_measurements(surface, m):
    """Every batched run equals Surface.measure at that centre, radius and λ (or both refuse)."""
    center_ids, radii, lams, _ = perturbations(surface, m)
    angles, measured = perturbed_angles(surface, m, center_ids, radii, lams)
    compared = 0
    for center, radius, lam, angle, ok in zip(
        center_ids, radii, lams, angles, measured, strict=True
    ):
        try:
            single = surface.measure(surface.points[center], radius, lam, m.patch, rule=m.rule)
        except GoniometerError:
            assert not ok
            continue
        if single.n_shared or single.orientation_difference:
            continue  # the batched runs skip the shared edge row and the two-sign fallback
        assert ok
        assert angle == pytest.approx(single.angle, abs=1e-6)
        compared += 1
    return compared


@pytest.mark.parametrize("patch", ["euclidean", "geodesic"])
@pytest.mark.parametrize(("angle", "concave"), [(40, False), (90, True), (150, False)])
def test_batched_runs_equal_single_measurements_on_wedges(angle, concave, patch):
    surface = noisy_wedge(angle, 0.003, seed=angle, concave=concave)
    m = surface.measure([0.01, 0.0, 0.0], 0.4, patch=patch)
    assert check_runs_against_single_measurements(surface, m) >= 10


@pytest.mark.parametrize("source", ["bone scan", "project half annulus"])
def test_batched_runs_equal_single_measurements_on_the_bone_scan(source, request):
    if source == "bone scan":
        mesh = read_mesh(request.getfixturevalue("shared_data") / "sample_mesh.ply")
    else:  # bevelled creases and curved faces, in every clone
        mesh = half_annulus()
    surface = Surface(mesh.points, mesh.triangles)
    radius = 0.04 * float(np.ptp(mesh.points, axis=0).max())
    rng = np.random.default_rng(5)
    compared = 0
    for vertex in rng.choice(surface.valid_ids, 12, replace=False):
        for rule in ("paper", "oriented"):
            try:
                m = surface.measure(surface.points[vertex], radius, rule=rule)
            except GoniometerError:
                continue
            compared += check_runs_against_single_measurements(surface, m)
    assert compared > 100


def test_the_figure_grows_with_noise():
    """Gaussian noise of 0, 0.1% and 1% of the radius on a 90° wedge."""
    radius = 0.5
    figures = []
    for noise in (0.0, 0.001 * radius, 0.01 * radius):
        surface = noisy_wedge(90, noise, seed=3)
        m = surface.measure([0.0, 0.0, 0.0], radius, stability=True)
        figures.append(m.stability)
    assert figures[0].spread < 1e-9
    assert figures[0].spread < figures[1].spread < figures[2].spread
    assert figures[1].bootstrap < figures[2].bootstrap
    assert figures[2].spread < 2.0  # 1% noise moves a 90° wedge by tenths of a degree


def test_parts_and_figure():
    surface = noisy_wedge(70, 0.004, seed=9)
    s = surface.measure([0.0, 0.0, 0.0], 0.45, stability=True).stability
    parts = (s.center, s.radius, s.lam, s.bootstrap, s.orientation)
    assert s.spread == max(parts) + s.crease  # the crease part is a bias, added to the spread
    assert all(part >= 0 for part in (*parts, s.crease)) and s.crease_refused == 0
    assert s.n_runs >= 2 + 5 + 3 and 0 <= s.n_failed <= s.n_runs
    assert s.text().startswith("± ") and s.text().endswith("°")


def test_moved_centres_are_the_vertices_within_two_mean_edge_lengths():
    surface = noisy_wedge(90, 0.0, seed=1)
    m = surface.measure([0.0, 0.0, 0.0], 0.4)
    center_ids, _, _, families = perturbations(surface, m)
    moved = center_ids[families["center"]]
    reach = 2.0 * mean_edge_length(m.radius, m.n_vertices)
    distance = np.linalg.norm(surface.points - m.center, axis=1)
    brute = np.flatnonzero((distance <= reach) & surface.valid)
    brute = brute[brute != m.center_index]
    assert set(moved) == set(brute[np.argsort(distance[brute], kind="stable")][: moved.size])
    assert 4 <= moved.size <= 24


def test_mean_edge_length_of_a_regular_wedge():
    mesh = wedge(90, n=60)
    surface = Surface(mesh.points, mesh.triangles)
    m = surface.measure([0.0, 0.0, 0.0], 0.4)
    edges = np.vstack(
        [mesh.triangles[:, [0, 1]], mesh.triangles[:, [1, 2]], mesh.triangles[:, [2, 0]]]
    )
    true_mean = np.linalg.norm(np.diff(mesh.points[edges], axis=1), axis=2).mean()
    assert mean_edge_length(m.radius, m.n_vertices) == pytest.approx(true_mean, rel=0.25)


def test_bootstrap_of_exact_planes_is_exact_and_reproducible():
    surface = noisy_wedge(60, 0.0)
    m = surface.measure([0.0, 0.0, 0.0], 0.4)
    angles, measured = bootstrap_angles(surface, m)
    assert measured.all() and np.abs(angles - 60.0).max() < 1e-9
    noisy = noisy_wedge(60, 0.003)
    m = noisy.measure([0.0, 0.0, 0.0], 0.4, stability=True)
    again = noisy.measure([0.0, 0.0, 0.0], 0.4, stability=True)
    assert m.stability == again.stability
    assert np.array_equal(bootstrap_angles(noisy, m)[0], bootstrap_angles(noisy, again)[0])


def test_plain_measurements_carry_no_figure():
    surface = noisy_wedge(60, 0.0)
    assert surface.measure([0.0, 0.0, 0.0], 0.4).stability is None


def test_bootstrap_redoes_the_whole_method_on_each_resample():
    """Oracle: a resample given to the core's own ``goniometer`` as a patch (duplicates kept)."""
    from vg_addon import goniometer
    from vg_addon.method import stability

    surface = noisy_wedge(120, 0.004, seed=6, concave=True)
    m = surface.measure([0.0, 0.0, 0.0], 0.4)
    angles, measured = bootstrap_angles(surface, m, n_resamples=6)
    rng = np.random.default_rng(stability.BOOTSTRAP_SEED)
    size = m.indices.size
    draws = rng.integers(0, size, size=(6, size))
    for row, (angle, ok) in enumerate(zip(angles, measured, strict=True)):
        chosen = m.indices[draws[row]]
        single = goniometer(
            surface.points[chosen], surface.normals[chosen], m.lam, m.center, m.radius
        )
        assert ok and angle == pytest.approx(single.angle, abs=1e-6)


def test_a_figure_too_large_to_compute_is_refused_before_allocating_it():
    """A radius that takes in a whole large mesh: the measurement is made, the figure refused
    with the limit named, before its arrays (runs × vertices) are allocated."""
    import tracemalloc

    from vg_addon.method.stability import MAX_RUN_VERTICES

    shape = wedge(90.0, n=220)  # 96,800 vertices
    surface = Surface(shape.points, shape.triangles)
    m = surface.measure([0.0, 0.0, 0.0], 5.0)
    assert m.n_vertices == surface.n_points
    tracemalloc.start()
    try:
        with pytest.raises(GoniometerError, match=f"{MAX_RUN_VERTICES:,} run-vertices"):
            surface.measure([0.0, 0.0, 0.0], 5.0, stability=True)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    # The measurement itself holds a few arrays of the patch; the figure would need 100 times it.
    assert peak < 40 * m.n_vertices * 8, peak


def test_the_flag_rule_unstable_above_5_degrees_undetermined_above_10_percent_refused():
    from vg_addon.method.result import (
        Stability,
        stability_text,
        stability_warning,
        stored_stability_warning,
    )

    assert stability_warning(5.0, 80, 8) == ""  # at the thresholds: not flagged
    assert stability_warning(0.0, 0, 0) == ""
    unstable = stability_warning(78.4, 80, 1)
    assert unstable.startswith("Unstable: the angle moves by up to 78.4°")
    assert "more than 5°" in unstable and "Undetermined" not in unstable
    undetermined = stability_warning(0.2, 80, 9)
    assert undetermined.startswith("Undetermined: 9 of 80 perturbed measurements were refused")
    assert "more than 10%" in undetermined and "Unstable" not in undetermined
    both = stability_warning(6.0, 10, 2)
    assert both.startswith("Unstable") and "Undetermined: 2 of 10" in both
    # From the stored numbers (a record's stability dict, the CSV's columns) the same words.
    stored = {"spread": 78.4, "runs": 80, "refused": 1, "center": 78.4}
    assert stored_stability_warning(stored) == unstable
    assert stored_stability_warning(None) == "" and stored_stability_warning({}) == ""
    figure = Stability(78.4, 78.4, 1.0, 1.0, 1.0, 0.0, 80, 1)
    assert figure.warning == unstable and figure.text() == stability_text(78.4) == "± 78.4°"
    assert stability_text(0.04) == "± 0.04°"


def test_a_reading_off_the_crease_with_a_small_radius_is_flagged_unstable():
    mesh = wedge(90.0, n=40, irregular=True)
    surface = Surface(mesh.points.astype(np.float32).astype(np.float64), mesh.triangles)
    flagged = surface.measure([0.0, 0.1, -0.02], 0.12, stability=True)
    assert flagged.stability.spread > 5.0 and flagged.stability.warning.startswith("Unstable")
    steady = surface.measure([0.0, 0.0, 0.0], 0.3, stability=True)
    assert steady.stability.warning == ""
