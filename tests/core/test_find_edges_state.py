"""The Find Break Edges review (``vg_addon.workflow.find_edges_state``) without Blender: the
finder stepped to its result, clicks on projected candidates, decisions, trims, and the
accepted candidates measured all or nothing.

The oracles are not the machine: the one-shot ``find_break_edges`` for the candidates, a
projection written out by hand, each station measured on its own with ``Surface.measure``, and
the original path's own vertices and arc lengths for a trim."""

from __future__ import annotations

import collections

import numpy as np
import pytest
from edge_truth import mean_edge_length

from vg_addon.fragments import bone_shaft, with_noise
from vg_addon.method.break_edges import BreakEdgeFinder, find_break_edges
from vg_addon.method.surface import Surface
from vg_addon.synthetic_meshes import bone_fragment
from vg_addon.workflow.find_edges_state import (
    Decision,
    FindEdgesMachine,
    FindPhase,
    edge_points,
    nearest_on_path,
    nearest_on_screen,
    project,
)

SPACING, RADIUS = 4.0, 1.5
WIDTH, HEIGHT = 800.0, 600.0


@pytest.fixture(scope="module")
def surface():
    fragment = bone_fragment(spacing=0.4)
    return Surface(fragment.points, fragment.triangles)


def side_view(surface) -> np.ndarray:
    """An orthographic view along y, oblique from above (the fragment's shaft is along z): its
    x and z + 0.3 y fill the region; each candidate shows apart from the others."""
    low, high = surface.points.min(axis=0), surface.points.max(axis=0)
    centre, half = (low + high) / 2.0, (high - low).max() / 2.0 * 1.2
    matrix = np.zeros((4, 4))
    matrix[0, :3] = [1.0 / half, 0.0, 0.0]
    matrix[1, :3] = [0.0, 0.3 / half, 1.0 / half]
    matrix[2, :3] = [0.0, 0.01 / half, 0.0]
    matrix[:2, 3] = -matrix[:2, :3] @ centre
    matrix[3, 3] = 1.0
    return matrix


def found(surface) -> FindEdgesMachine:
    machine = FindEdgesMachine(surface, BreakEdgeFinder(surface))
    while machine.step():
        pass
    return machine


def pixels(machine, matrix) -> list[np.ndarray]:
    return [project(c.path.points, matrix, WIDTH, HEIGHT) for c in machine.candidates]


def test_finding_steps_to_the_one_shot_result(surface):
    machine = FindEdgesMachine(surface, BreakEdgeFinder(surface))
    progress = []
    while machine.step():
        assert machine.phase is FindPhase.FINDING
        progress.append(machine.progress)
    assert progress == sorted(progress) and progress[0] >= 0.0 and progress[-1] <= 1.0
    assert machine.phase is FindPhase.REVIEW and machine.progress == 1.0
    expected = find_break_edges(surface).candidates
    assert len(machine.candidates) == len(expected) >= 2
    for got, want in zip(machine.candidates, expected, strict=True):
        assert got.number == want.number
        assert np.array_equal(got.path.vertices, want.path.vertices)
    assert machine.decisions == [Decision.PENDING] * len(expected)
    assert machine.selected == 0  # the most confident, ready for A or X


def test_project_is_the_hand_written_projection():
    matrix = np.diag([0.5, 0.25, 1.0, 1.0])
    matrix[3] = [0.0, 0.0, -1.0, 0.0]  # a perspective: w = -z
    points = np.array([[2.0, 4.0, -2.0], [0.0, 0.0, -1.0], [1.0, 1.0, 3.0]])
    got = project(points, matrix, WIDTH, HEIGHT)
    # x_ndc = 0.5 x / -z, y_ndc = 0.25 y / -z; pixels = (ndc + 1) / 2 * size
    assert got[0].tolist() == [(0.5 + 1) / 2 * WIDTH, (0.5 + 1) / 2 * HEIGHT]
    assert got[1].tolist() == [WIDTH / 2, HEIGHT / 2]
    assert np.isnan(got[2]).all()  # behind the viewer
    assert nearest_on_screen(got, (WIDTH / 2 + 3, HEIGHT / 2 + 4)) == (1, 5.0)
    assert nearest_on_screen(got[2:], (0, 0)) == (-1, float("inf"))


def test_a_click_selects_the_candidate_under_it_and_a_miss_changes_nothing(surface):
    machine = found(surface)
    matrix = side_view(surface)
    drawn = pixels(machine, matrix)
    tried = 0
    for index in reversed(range(len(drawn))):
        # A vertex of this candidate that no other candidate is drawn near (two may be drawn
        # on top of each other in this view: those are not tried).
        others = np.vstack([p for i, p in enumerate(drawn) if i != index])
        gaps = np.array([nearest_on_screen(others, xy)[1] for xy in drawn[index]])
        if gaps.max() < 10.0:
            continue
        xy = drawn[index][int(np.argmax(gaps))]
        assert machine.pick(drawn, (xy[0] + 2.0, xy[1] - 2.0))
        assert machine.selected == index
        tried += 1
    assert tried >= 2
    assert not machine.pick(drawn, (-500.0, -500.0))
    assert machine.selected == 0 and "No candidate there" in machine.message


def test_only_accepted_candidates_are_measured_each_station_as_alone(surface):
    machine = found(surface)
    assert machine.accept()  # candidate 1; the next undecided is selected
    assert machine.selected == 1
    assert machine.reject()
    assert machine.decisions[:2] == [Decision.ACCEPTED, Decision.REJECTED]
    assert machine.finish(SPACING, RADIUS)
    assert machine.phase is FindPhase.MEASURING
    while machine.step():
        pass
    assert machine.phase is FindPhase.DONE
    ((points, profile),) = machine.profiles
    candidate = machine.candidates[0]
    assert np.array_equal(points, candidate.path.points[candidate.path.waypoints])
    assert np.array_equal(profile.path.vertices, candidate.path.vertices)  # retraced exactly
    assert profile.n_stations >= candidate.length // SPACING
    for station in profile.stations:
        alone = surface.measure(station.center, RADIUS)
        assert (alone.angle, alone.fit_error) == (station.angle, station.fit_error)


def test_enter_with_nothing_accepted_keeps_the_review_and_its_decisions(surface):
    """Enter pressed before any candidate was accepted once ended the review, losing every
    decision and trim made so far."""
    machine = found(surface)
    machine.reject()
    assert not machine.finish(SPACING, RADIUS)
    assert machine.phase is FindPhase.REVIEW and machine.profiles == []
    assert "No candidate is accepted yet" in machine.message
    assert machine.decisions[0] is Decision.REJECTED
    assert machine.accept()  # the review goes on: candidate 2
    assert machine.finish(SPACING, RADIUS) and machine.phase is FindPhase.MEASURING


@pytest.mark.parametrize("steps", [0, 1, None])
def test_cancel_while_finding_or_reviewing_leaves_nothing(surface, steps):
    machine = FindEdgesMachine(surface, BreakEdgeFinder(surface))
    if steps is None:
        while machine.step():
            pass
        machine.accept_pending()
    else:
        for _ in range(steps):
            machine.step()
    machine.cancel()
    assert machine.phase is FindPhase.CANCELLED and machine.profiles == []
    assert not machine.step() and not machine.accept() and not machine.finish(SPACING, RADIUS)


def test_two_clicks_trim_the_selected_candidate_to_the_part_between(surface):
    machine = found(surface)
    matrix = side_view(surface)
    if machine.candidates[0].closed:  # an open candidate: most of the loop
        assert machine.trim_to(0.0, 0.9 * machine.candidates[0].length)
        assert not machine.candidates[0].closed
    original = machine.candidates[0].path
    n = original.vertices.size
    a, b = n // 4, (3 * n) // 5
    assert machine.start_trim() and machine.phase is FindPhase.TRIMMING
    drawn = pixels(machine, matrix)
    assert machine.pick(drawn, drawn[0][b]) and machine.trim_arcs == [original.arc_lengths[b]]
    assert machine.pick(drawn, drawn[0][a])  # either order
    assert machine.phase is FindPhase.REVIEW
    part = machine.candidates[0].path
    assert np.array_equal(part.vertices, original.vertices[a : b + 1])
    assert part.length == pytest.approx(original.arc_lengths[b] - original.arc_lengths[a])
    assert machine.candidates[0].number == 1
    # What is recorded of it retraces the part, not the whole candidate.
    machine.accept()
    machine.finish(SPACING, RADIUS)
    while machine.step():
        pass
    assert np.array_equal(machine.profiles[0][1].path.vertices, part.vertices)


@pytest.mark.parametrize("inside", [True, False], ids=["between", "through_the_start"])
def test_on_a_loop_a_third_click_picks_the_part_kept(surface, inside):
    machine = found(surface)
    index = next(k for k, c in enumerate(machine.candidates) if c.closed)
    machine.select(index)
    loop = machine.candidates[index].path
    n = loop.vertices.size
    a, b = n // 4, (3 * n) // 5
    machine.start_trim()
    drawn = pixels(machine, side_view(surface))
    assert machine.pick(drawn, drawn[index][a]) and machine.pick(drawn, drawn[index][b])
    assert machine.phase is FindPhase.TRIMMING and machine.message.startswith("Click the part")
    assert machine.pick(drawn, drawn[index][(a + b) // 2 if inside else n // 10])
    assert machine.phase is FindPhase.REVIEW and machine.message == ""
    part = machine.candidates[index].path
    if inside:
        expected = loop.vertices[a : b + 1]
    else:
        expected = np.concatenate([loop.vertices[b:], loop.vertices[1 : a + 1]])
    assert np.array_equal(part.vertices, expected)


def test_a_click_off_the_trimmed_candidate_and_esc_leave_it_whole(surface):
    machine = found(surface)
    drawn = pixels(machine, side_view(surface))
    whole = machine.candidates[0]
    machine.start_trim()
    assert not machine.pick(drawn, (-500.0, -500.0))
    assert machine.phase is FindPhase.TRIMMING and machine.trim_arcs == []
    assert machine.pick(drawn, drawn[0][3])
    assert machine.back() and machine.phase is FindPhase.REVIEW
    assert machine.candidates[0] is whole


def test_keys_that_decide_during_a_trim_say_to_finish_it_first(surface):
    # Before, Enter, A, X and Shift+A during a trim did nothing and said nothing.
    machine = found(surface)
    machine.start_trim()
    for press in (machine.accept, machine.reject, machine.accept_pending):
        machine.message = ""
        assert not press() and "trim" in machine.message
    machine.message = ""
    assert not machine.finish(SPACING, 1.0) and "trim" in machine.message
    assert machine.phase is FindPhase.TRIMMING and machine.count(Decision.PENDING) == len(
        machine.candidates
    )


def test_a_candidate_that_cannot_be_measured_sends_the_review_back_naming_it(surface):
    machine = found(surface)
    machine.accept()
    machine.accept()
    tiny = 1e-6  # smaller than any mesh edge: no patch has enough points
    machine.finish(SPACING, tiny)
    while machine.step():
        pass
    assert machine.phase is FindPhase.REVIEW and machine.profiles == []
    assert machine.message.startswith("Candidate 1 cannot be measured")
    # The header shows the message's first line: it says why, not only that it failed.
    assert "radius" in machine.message.splitlines()[0]
    assert machine.selected == 0
    assert machine.accepted == [0, 1]  # the decisions are kept


def test_esc_while_measuring_returns_to_the_review_with_nothing_kept(surface):
    machine = found(surface)
    machine.accept_pending()
    machine.finish(SPACING, RADIUS)
    machine.step()
    assert machine.back()
    assert machine.phase is FindPhase.REVIEW and machine.profiles == []
    assert machine.count(Decision.ACCEPTED) == len(machine.candidates)


def test_next_prefers_undecided_candidates(surface):
    machine = found(surface)
    assert len(machine.candidates) >= 3
    machine.select(1)
    machine.reject()
    machine.select(0)
    assert machine.select_next() and machine.selected == 2  # 1 is decided
    assert machine.select_next(-1) and machine.selected == 0
    assert edge_points(machine.candidates[0]).dtype == np.float64


def test_accepted_candidates_are_measured_with_the_rule_and_stability_given(surface):
    machine = found(surface)
    assert machine.accept()  # candidate 1 alone
    assert machine.finish(SPACING, RADIUS, rule="paper", stability=True)
    while machine.step():
        pass
    ((_, profile),) = machine.profiles
    for station in profile.stations:
        alone = surface.measure(station.center, RADIUS, rule="paper", stability=True)
        assert station.rule == "paper"
        assert (station.angle, station.stability) == (alone.angle, alone.stability)


def test_selecting_a_candidate_that_passes_a_place_twice_says_so():
    # On the shaft with noise of 0.3 mean edge lengths, candidate 4's path goes out to one vertex
    # and back (a spur the finder could not untie without a shortcut off the crest). Its
    # stations there would be refused; the review says so when it is selected, and says nothing
    # for the others. Oracle: the path's repeated vertex indices, counted in plain Python.
    shaft = bone_shaft(0.3)
    noisy = with_noise(shaft, 0.3 * mean_edge_length(shaft.points, shaft.triangles), seed=1)
    machine = found(Surface(noisy.points, noisy.triangles))
    for index, candidate in enumerate(machine.candidates):
        vertices = candidate.path.vertices.tolist()[:-1]  # every candidate here is a loop
        counts = collections.Counter(vertices)
        twice = [k for k, v in enumerate(vertices) if counts[v] > 1]
        machine.select(index)
        if not twice:
            assert machine.message == ""
            continue
        arcs = candidate.path.arc_lengths
        assert machine.message.startswith(f"Candidate {candidate.number} passes the same vertices")
        assert f"{arcs[twice[0]]:.4g} to" in machine.message and "trim" in machine.message
        assert f"{arcs[twice[-1]]:.4g})" in machine.message
    assert any(machine.candidates[i].path.revisited_spans for i in range(4))


def test_a_click_on_the_drawn_line_between_far_vertices_picks_it(surface):
    """Zoomed in, a candidate's vertices lie far apart on screen: a click on its line, 100 px
    from either vertex, said "No candidate there". Oracle: the line's pixels by hand."""
    assert nearest_on_path([[100.0, 100.0], [300.0, 100.0]], (180.0, 103.0)) == (0, 3.0)
    assert nearest_on_path([[100.0, 100.0], [300.0, 100.0]], (240.0, 96.0)) == (1, 4.0)
    assert nearest_on_path([[np.nan, np.nan], [300.0, 100.0]], (240.0, 100.0)) == (1, 60.0)
    machine = found(surface)
    far = [np.array([[5000.0 + i, 5000.0]]) for i in range(len(machine.candidates))]
    target = len(machine.candidates) - 1
    far[target] = np.array([[100.0, 100.0], [300.0, 100.0]])
    assert machine.pick(far, (200.0, 105.0)) and machine.selected == target
    assert not machine.pick(far, (200.0, 150.0))  # 50 px off the line: no candidate
