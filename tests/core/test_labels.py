"""Label layout: decluttering against brute force, the views of a map against exact shapes."""

import itertools

import numpy as np
import pytest

from vg_addon import GoniometerError
from vg_addon.workflow.labels import SIX_VIEWS, declutter, flake_views, label_text


def test_declutter_keeps_labels_apart_and_prefers_priority():
    rng = np.random.default_rng(4)
    positions = rng.uniform(0, 400, size=(300, 2))
    priority = rng.permutation(300)
    kept = declutter(positions, priority, 30.0)
    # No two kept labels are closer than the distance ...
    for a, b in itertools.combinations(kept, 2):
        assert np.linalg.norm(positions[a] - positions[b]) >= 30.0
    # ... every dropped one is near a kept label of higher priority (why it was dropped) ...
    for index in set(range(300)) - set(kept.tolist()):
        near = [k for k in kept if np.linalg.norm(positions[k] - positions[index]) < 30.0]
        assert near and max(priority[near]) > priority[index]
    # ... and the highest priority is always shown first.
    assert kept[0] == int(np.argmax(priority))


def test_declutter_edge_cases():
    assert declutter(np.zeros((0, 2)), [], 10).tolist() == []
    assert declutter([[0, 0], [0, 0]], [1, 1], 10).tolist() == [0]  # ties: input order
    assert declutter([[0, 0], [5, 0]], [1, 2], 0).tolist() == [1, 0]
    with pytest.raises(GoniometerError, match="2 positions but 1 priorities"):
        declutter([[0, 0], [1, 1]], [1], 5)


def test_six_views_are_the_axis_directions_with_perpendicular_ups():
    looks = sorted(tuple(look) for _, look, _ in SIX_VIEWS)
    assert looks == sorted(tuple(s * e) for e in np.eye(3) for s in (1.0, -1.0))
    for _, look, up in SIX_VIEWS:
        assert np.dot(look, up) == 0.0 and np.linalg.norm(up) == 1.0


def test_flake_views_look_along_the_thin_direction():
    rng = np.random.default_rng(0)
    # A flat slab 10 x 4 x 0.3, turned by a known rotation: the thin axis is R @ z.
    slab = rng.uniform(-1, 1, size=(2000, 3)) * [5.0, 2.0, 0.15]
    angle = 0.7
    rotation = np.array(
        [[np.cos(angle), 0, np.sin(angle)], [0, 1, 0], [-np.sin(angle), 0, np.cos(angle)]]
    )
    (name_a, look_a, up_a), (name_b, look_b, up_b) = flake_views(slab @ rotation.T + 3.0)
    assert (name_a, name_b) == ("face A", "face B")
    assert abs(abs(np.dot(look_a, rotation @ [0, 0, 1])) - 1.0) < 1e-3
    assert abs(abs(np.dot(up_a, rotation @ [1, 0, 0])) - 1.0) < 1e-3
    assert np.allclose(look_b, -np.array(look_a)) and np.allclose(up_a, up_b)


def test_flake_views_refuse_degenerate_meshes():
    with pytest.raises(GoniometerError, match="at least 3 vertices"):
        flake_views([[0, 0, 0], [1, 0, 0]])
    with pytest.raises(GoniometerError, match="a line"):
        flake_views([[0, 0, 0], [1, 0, 0], [2, 0, 0]])


def test_label_text():
    assert label_text(3, 91.2549) == "3: 91.25°"
