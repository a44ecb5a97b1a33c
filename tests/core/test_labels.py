"""Label layout: placement against brute force, the views of a map against exact shapes."""

import itertools

import numpy as np
import pytest

from vg_addon import GoniometerError
from vg_addon.workflow.labels import (
    SIX_VIEWS,
    flake_views,
    label_box,
    label_text,
    place_labels,
)

PAD = np.array([-1.75, -1.75, 1.75, 1.75])  # a quarter of the 14 px height, around a box


def boxes_of(anchors, widths, height, shown):
    boxes = [label_box(anchors[i], widths[i], height, side, 0.5 * height) for i, side in shown]
    dots = [[x - height / 4, y - height / 4, x + height / 4, y + height / 4] for x, y in anchors]
    return boxes, dots


def overlap(a, b) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def test_shown_labels_never_overlap_each_other_or_the_anchors():
    rng = np.random.default_rng(4)
    anchors = rng.uniform(0, 600, size=(200, 2))
    widths = rng.uniform(40, 90, size=200)
    priority = rng.permutation(200)
    shown = place_labels(anchors, widths, 14.0, priority)
    boxes, dots = boxes_of(anchors, widths, 14.0, shown)
    kept = [i for i, _ in shown]
    for (a, box_a), (b, box_b) in itertools.combinations(zip(kept, boxes, strict=True), 2):
        assert not overlap(box_a, box_b)
        assert not overlap(box_a, dots[b]) and not overlap(box_b, dots[a])
    # A label left out has both its sides (with the quarter-height spacing) blocked by a
    # label of higher priority ...
    for index in set(range(200)) - set(kept):
        for side in (1, -1):
            box = label_box(anchors[index], widths[index], 14.0, side, 7.0) + PAD
            assert any(
                overlap(box, kept_box) or overlap(dots[index], kept_box)
                for k, kept_box in zip(kept, boxes, strict=True)
                if priority[k] > priority[index]
            ) or any(
                overlap(box, dots[k]) or overlap(dots[index], dots[k])
                for k in kept
                if priority[k] > priority[index]
            )
    # ... and the first is always shown, to the right.
    assert shown[0] == (int(np.argmax(priority)), 1)


def test_a_crowded_label_moves_to_the_left():
    # Two anchors on a line 60 px apart with 80 px labels: the lower priority goes left.
    shown = place_labels([[100, 0], [160, 0]], [80, 80], 10.0, [1, 2])
    assert shown == [(1, 1), (0, -1)]
    # A third between them fits nowhere; one a line lower fits to the right.
    shown = place_labels([[100, 0], [160, 0], [130, 0]], [80, 80, 80], 10.0, [1, 2, 0])
    assert [i for i, _ in shown] == [1, 0]
    assert place_labels([[100, 0], [100, 13]], [80, 80], 10.0, [2, 1]) == [(0, 1), (1, 1)]


def test_place_labels_edge_cases():
    assert place_labels(np.zeros((0, 2)), [], 10.0, []) == []
    with pytest.raises(GoniometerError, match="2 anchors, 1 widths and 2 priorities"):
        place_labels([[0, 0], [1, 1]], [5], 10.0, [1, 2])


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


def test_a_label_that_would_cross_the_right_edge_goes_left():
    anchors = [[95.0, 50.0], [10.0, 10.0]]
    widths = [40.0, 40.0]
    free = place_labels(anchors, widths, 12.0, [1, 0])
    assert dict(free) == {0: 1, 1: 1}  # without an edge, both to the right
    bounded = dict(place_labels(anchors, widths, 12.0, [1, 0], right_edge=100.0))
    assert bounded == {0: -1, 1: 1}  # the one near the edge flips; the other stays
    # Every shown box lies inside the edge when it can.
    for index, side in bounded.items():
        box = label_box(np.array(anchors[index]), widths[index], 12.0, side, 6.0)
        assert box[2] <= 100.0


def test_looks_at_a_measurement_start_straight_onto_its_surface():
    from vg_addon.workflow.labels import looks_at, view_up

    outward = np.array([0.0, 3.0, 4.0])
    looks = looks_at(outward)
    assert len(looks) == 2 * (1 + 3 * 8)
    np.testing.assert_allclose(looks[0], [0.0, -0.6, -0.8])
    np.testing.assert_allclose(looks[25], [0.0, 0.6, 0.8])  # then from the other side
    np.testing.assert_allclose(np.linalg.norm(looks, axis=1), 1.0)
    angles = np.degrees(np.arccos(np.clip(np.asarray(looks[1:25]) @ looks[0], -1, 1)))
    np.testing.assert_allclose(sorted(angles), np.repeat([20.0, 40.0, 60.0], 8), atol=1e-9)
    assert looks_at(np.zeros(3)) == [] and looks_at(np.array([np.nan, 0, 1])) == []
    for look in looks:
        up = np.array(view_up(look))
        assert abs(up @ look) < 1e-12 and abs(np.linalg.norm(up) - 1.0) < 1e-12
