"""Break edges found against the truth: synthetic fragments whose edges are known exactly.

The issue's bar, on the bone shaft, the bevelled cube and the flake of ``vg_addon.fragments``
and on noisy copies of each: at least 95% of the true edge length found within one mean edge
length, at most 5% of the found length false (``edge_truth.score``: both measured on the
polylines resampled every 0.05 mm). Also: every candidate retraces from its waypoints, and
stations placed along a candidate read what a hand-placed measurement reads there.
"""

import functools

import numpy as np
import pytest
from edge_truth import found_on, mean_edge_length, score

from vg_addon import Surface, fragments
from vg_addon.fragments import bevelled_cube, bone_shaft, flake, with_noise
from vg_addon.synthetic_meshes import bone_fragment

NOISE = 0.1
"""Noise of the noisy copies: SD of the normal displacement, in mean edge lengths."""

MAKERS = {"bone shaft": lambda: bone_shaft(0.3), "bevelled cube": bevelled_cube, "flake": flake}


@functools.cache
def finding(name: str, noisy: bool):
    """The fragment, its surface and what the finder found on it (each made once)."""
    fragment = MAKERS[name]()
    if noisy:
        h = mean_edge_length(fragment.points, fragment.triangles)
        fragment = with_noise(fragment, NOISE * h, seed=1)
    surface = Surface(fragment.points, fragment.triangles)
    return fragment, surface, surface.find_break_edges()


CASES = [(name, noisy) for name in MAKERS for noisy in (False, True)]


def case_id(case) -> str:
    return case[0] + (" noisy" if case[1] else "")


@pytest.fixture(scope="module", params=CASES, ids=case_id)
def found(request):
    return finding(*request.param)


def test_true_edges_are_found_and_little_else(found):
    fragment, _, result = found
    figures = score(fragment, [c.path.points for c in result.candidates])
    assert figures["recall"] >= 0.95, figures
    assert figures["false"] <= 0.05, figures


def assert_retraces(surface, candidate) -> None:
    """The candidate's path is what the tracer makes of its start, via and end points."""
    points = candidate.waypoint_points
    again = surface.trace_edge(points[0], points[-1], via=points[1:-1])
    assert np.array_equal(again.vertices, candidate.path.vertices), candidate.number


def test_every_candidate_retraces_from_its_waypoints(found):
    _, surface, result = found
    for candidate in result.candidates:
        assert_retraces(surface, candidate)


MARCH_STEP = 0.4
"""The marched fragments' grid step (their default ``spacing``): marching cuts a corner by up to
about this much, so the mesh's own crease lies that far from the true edge."""

HARDER = {
    "bone shaft, noise 0.3": (lambda: bone_shaft(0.3), 0.3, None),
    "flake, noise 0.3": (flake, 0.3, None),
    "bevelled cube, noise 0.3": (bevelled_cube, 0.3, None),
    "bevelled cube, marched": (fragments.marched_bevelled_cube, 0.0, MARCH_STEP),
    "bevelled cube, marched, noise 0.1": (fragments.marched_bevelled_cube, 0.1, MARCH_STEP),
    "bevelled cube, marched, noise 0.1, one edge": (fragments.marched_bevelled_cube, 0.1, None),
    "flake, marched": (fragments.marched_flake, 0.0, MARCH_STEP),
    "flake, marched, within one mean edge": (fragments.marched_flake, 0.0, None),
    "flake, marched, noise 0.1": (fragments.marched_flake, 0.1, MARCH_STEP),
    "flake, marched, noise 0.1, one edge": (fragments.marched_flake, 0.1, None),
}


@pytest.mark.parametrize("name", sorted(HARDER))
def test_the_harder_cases_that_docs_claim_pass_do(name):
    """The rows of EDGE_DETECTION.md's limits table marked pass: noise of 0.3 mean edge
    lengths on the shaft, the flake and the bevelled cube, and fragments meshed by marching
    tetrahedra (no vertex on an edge) scored within the marching step, the noisy marched cube
    and the flake also within one mean edge length (the flake's path keeps to the sharper of the
    two rows of bent edges a cut corner leaves)."""
    _, surface, result, figures = found_on(*HARDER[name])
    assert figures["recall"] >= 0.95, figures
    assert figures["false"] <= 0.05, figures
    for candidate in result.candidates:
        assert_retraces(surface, candidate)


@pytest.mark.parametrize("seed", [2, 3])
def test_the_noisy_marched_cube_finds_its_fillets_at_their_scale(seed):
    """With these noise seeds the default scale (1.17 mm) reads one 1.5 mm fillet below the bend
    bar and misses most of it (recall 93.6% and 94.7%); a scale of the fillets' size, the
    setting docs/EDGE_DETECTION.md and docs/BATCH.md give for rounded edges, finds all 12 edges
    within one mean edge length."""
    fragment, surface, result, figures = found_on(
        fragments.marched_bevelled_cube, 0.1, None, seed, scale=2.0
    )
    assert len(result.candidates) == len(fragment.edges), figures
    assert figures["recall"] >= 0.95, figures
    assert figures["false"] <= 0.05, figures
    for candidate in result.candidates:
        assert_retraces(surface, candidate)


def test_no_candidate_passes_a_place_twice():
    """A via point a little off the crest sent the marched flake's candidate 3 out to it and
    back over the same 4 vertices (arc lengths 31.6 to 33.5): stations there measured one place
    twice, or were refused. Oracle: the path's vertex indices, a loop's closing one left out, are
    all different; and the candidate still retraces from its waypoints."""
    for make in (fragments.marched_flake, fragments.marched_bevelled_cube, flake, bevelled_cube):
        fragment = make()
        surface = Surface(fragment.points, fragment.triangles)
        for candidate in surface.find_break_edges().candidates:
            vertices = candidate.path.vertices.tolist()
            once = vertices[:-1] if candidate.closed else vertices
            assert len(set(once)) == len(once), (make.__name__, candidate.number)
            assert candidate.path.revisited_spans == ()
            assert_retraces(surface, candidate)


@pytest.mark.parametrize(
    "make, noise",
    [(bevelled_cube, 0.0), (bevelled_cube, 0.1), (bevelled_cube, 0.3),
     (fragments.marched_bevelled_cube, 0.0), (fragments.marched_flake, 0.0),
     (fragments.marched_flake, 0.1)],
)  # fmt: skip
def test_no_stretch_of_ridge_is_in_two_candidates(make, noise):
    """Where two edges meet (a rounded cube corner, the flake's platform edge joining its
    margin) both candidates ran round the same stretch: on the clean cube candidates 3 and 11
    shared 9 vertices (3.8 mm), so a batch profiling every edge measured it twice. Oracle: the
    vertex indices of any two candidates' paths have at most one in common (where they meet),
    and the bar still holds."""
    fragment, _, result, figures = found_on(make, noise)
    paths = [set(c.path.vertices.tolist()) for c in result.candidates]
    for i, first in enumerate(paths):
        for j in range(i + 1, len(paths)):
            assert len(first & paths[j]) <= 1, (fragment.name, i + 1, j + 1)
    if make is bevelled_cube:
        assert figures["recall"] >= 0.95 and figures["false"] <= 0.05, figures


@pytest.mark.parametrize("seed", [2, 3])
def test_the_bevelled_cube_at_noise_0_3_passes_with_other_noise_seeds(seed):
    """The seeds on which its fillets' paths wandered most and noise ridges inside its faces
    were candidates (a fifth of the found length false, before the balanced crest and the
    local noise bar). No open path passes a vertex twice (it went out to a via point and back
    over the same vertices before)."""
    fragment = bevelled_cube()
    h = mean_edge_length(fragment.points, fragment.triangles)
    fragment = with_noise(fragment, 0.3 * h, seed=seed)
    surface = Surface(fragment.points, fragment.triangles)
    result = surface.find_break_edges()
    figures = score(fragment, [c.path.points for c in result.candidates])
    assert figures["recall"] >= 0.95, figures
    assert figures["false"] <= 0.05, figures
    for candidate in result.candidates:
        vertices = candidate.path.vertices
        assert candidate.closed or np.unique(vertices).size == vertices.size, candidate.number
        assert_retraces(surface, candidate)


@pytest.mark.parametrize("seed", [3, 6, 11])
def test_the_noisy_flake_passes_with_other_noise_seeds(seed):
    """Noise of 0.3 mean edges with seeds that failed before: with seed 3 the platform edge
    stands out from the noise round it by only about 30 times, and the local noise bar must keep
    it (a bar of 30 dropped it, recall 88.9%); with seeds 6 and 11 the dorsal/platform crest ran
    on the platform's row and the margin's path partly off the edge (5.1% and 9.0% false)
    before the outer crest."""
    fragment = flake()
    h = mean_edge_length(fragment.points, fragment.triangles)
    fragment = with_noise(fragment, 0.3 * h, seed=seed)
    result = Surface(fragment.points, fragment.triangles).find_break_edges()
    figures = score(fragment, [c.path.points for c in result.candidates])
    assert len(result.candidates) == len(fragment.edges), figures
    assert figures["recall"] >= 0.95, figures
    assert figures["false"] <= 0.05, figures


@pytest.mark.parametrize("case", [c for c in CASES if c[0] != "bevelled cube"], ids=case_id)
def test_fracture_faces_are_told_from_the_original_surface(case):
    """On the shaft and the flake (the cube has no fracture face): the region covering most of
    each face that is a region has the face's kind."""
    fragment, _, result = finding(*case)
    told = 0
    for face in np.unique(fragment.faces):
        regions = result.region[(fragment.faces == face) & (result.region >= 0)]
        if regions.size == 0:
            continue  # a face narrower than the scale (the flake's platform) is all band
        kind = result.region_kind[np.bincount(regions).argmax()]
        assert kind == (2 if face in fragment.fracture else 1), (face, kind)
        told += 1
    assert told >= 2


@pytest.fixture(scope="module")
def shaft():
    bone = bone_fragment(spacing=0.3)
    surface = Surface(bone.points, bone.triangles)
    return bone, surface, surface.find_break_edges()


@pytest.mark.parametrize("label", ["transverse/outer", "transverse/inner",
                                   "oblique/outer acute", "oblique/outer obtuse",
                                   "oblique/inner obtuse", "oblique/inner acute"])  # fmt: skip
def test_stations_read_what_a_hand_placed_measurement_reads(shaft, label):
    """At the break sites where the angle is level along the rim (so a station a fraction of a
    millimetre away reads the same angle), the profile's station nearest the site reads within
    0.5° of a measurement placed by hand on the site."""
    bone, surface, result = shaft
    site = next(s for s in bone.sites if s.label == label)
    candidate = min(
        result.candidates, key=lambda c: np.linalg.norm(c.path.points - site.point, axis=1).min()
    )
    profile = surface.measure_along(candidate.path, spacing=0.6, radius=2.0)
    centres = np.array([m.center for m in profile.stations])
    nearest = int(np.argmin(np.linalg.norm(centres - site.point, axis=1)))
    assert np.linalg.norm(centres[nearest] - site.point) <= 0.6
    by_hand = surface.measure(site.point, 2.0)
    assert abs(profile.stations[nearest].angle - by_hand.angle) <= 0.5


@pytest.mark.parametrize(
    ("spacing", "roughness"),
    [(0.5, 0.0), (0.6, 0.0), (0.6, 0.05), (0.7, 0.0), (0.7, 0.05), (0.8, 0.0)],
)
def test_the_demo_bone_at_coarse_spacings_has_all_four_rims(spacing, roughness):
    """The README demo's shaft at 0.5 to 0.8 mm: its transverse face is 5 mm wide, narrower than
    the band the default scale (five edges, up to 4 mm) leaves round its two rims; the fine field
    recovers it as a region, so all four rims are found (the fragment's exact rims the oracle)."""
    fragment = bone_shaft(spacing, roughness=roughness, seed=1)
    surface = Surface(fragment.points, fragment.triangles)
    result = surface.find_break_edges()
    figures = score(fragment, [c.path.points for c in result.candidates])
    assert figures["recall"] >= 0.95, figures
    assert figures["false"] <= 0.05, figures
    assert len(result.candidates) == 4 and all(c.closed for c in result.candidates)
