"""The drag interaction's state machine, driven by synthetic events on a real Surface."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vg_addon import GoniometerError, Surface
from vg_addon.method.algorithm import MIN_RADIUS
from vg_addon.workflow.drag_state import (
    LAM_STEP,
    MIN_PATCH_VERTICES,
    MISSED,
    DragMachine,
    Phase,
    surface_callbacks,
)


def folded_grid(n: int = 31, angle_deg: float = 90.0) -> Surface:
    """A square grid folded along the x axis: two flat faces meeting at ``angle_deg``."""
    s = np.linspace(-1.0, 1.0, n)
    x, t = np.meshgrid(s, s, indexing="ij")
    x, t = x.ravel(), t.ravel()
    half = np.radians(angle_deg) / 2.0
    # each face leaves the edge (t = 0) at half the interior angle below the horizontal
    y = np.abs(t) * np.sin(half) * np.sign(t)
    z = -np.abs(t) * np.cos(half)
    points = np.column_stack([x, y, z])
    grid = np.arange(n * n).reshape(n, n)
    a, b = grid[:-1, :-1].ravel(), grid[1:, :-1].ravel()
    c, d = grid[1:, 1:].ravel(), grid[:-1, 1:].ravel()
    triangles = np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    return Surface(points, triangles)


SURFACE = folded_grid()
EDGE_POINT = np.array([0.0, 0.0, 0.0])  # on the fold, a vertex of the grid
FLAT_POINT = np.array([0.0, 0.7 * np.sin(np.pi / 4), -0.7 * np.cos(np.pi / 4)])


def machine(patch: str = "euclidean", **options) -> DragMachine:
    return DragMachine(**surface_callbacks(SURFACE, patch), **options)


def brute_ball(center, radius) -> np.ndarray:
    offsets = SURFACE.points - center
    squared = np.einsum("ij,ij->i", offsets, offsets)  # the index's own boundary test
    return np.flatnonzero((squared <= radius * radius) & SURFACE.valid)


def test_press_drag_release_records_what_surface_measure_gives():
    m = machine()
    assert m.press(EDGE_POINT + np.array([0.01, 0.002, -0.001]))
    assert m.phase is Phase.DRAGGING
    assert np.array_equal(m.center, EDGE_POINT)  # snapped onto the vertex
    m.move(0.3)
    assert m.n_vertices == brute_ball(m.center, 0.3).size
    assert m.message == ""
    record = m.release()
    assert record is not None and m.phase is Phase.MEASURED
    expected = SURFACE.measure(record.center, record.radius, record.lam)
    assert record.measurement.angle == expected.angle
    assert abs(record.measurement.angle - 90.0) < 1e-6
    assert np.array_equal(np.sort(record.measurement.indices), np.sort(m.indices))


@pytest.mark.parametrize("patch", ["euclidean", "geodesic"])
def test_preview_patch_is_the_measured_patch(patch):
    m = machine(patch)
    m.press(EDGE_POINT)
    m.move(0.45)
    preview = np.sort(m.indices)
    record = m.release()
    assert np.array_equal(preview, np.sort(record.measurement.indices))
    assert record.measurement.patch == patch


def test_press_that_misses_does_nothing_and_says_why():
    m = machine()
    assert not m.press(None)
    assert m.phase is Phase.IDLE and m.message == MISSED
    m.move(0.5)
    assert m.release() is None and m.record is None and m.n_vertices == 0


def test_small_drag_previews_too_few_and_release_records_nothing():
    m = machine()
    m.press(EDGE_POINT)
    m.move(0.01)
    assert 0 < m.n_vertices < MIN_PATCH_VERTICES
    assert "Too few vertices" in m.message and not m.can_record
    assert m.release() is None
    assert m.phase is Phase.IDLE and m.record is None
    assert "Nothing was recorded" in m.message
    # a fresh press after the failed release works
    assert m.press(EDGE_POINT)
    m.move(0.3)
    assert m.release() is not None


def test_flat_patch_is_refused_on_release_with_the_core_message():
    m = machine()
    m.press(FLAT_POINT)
    m.move(0.2)
    assert m.can_record
    with pytest.raises(GoniometerError) as error:
        SURFACE.measure(m.center, m.radius, m.lam)
    assert m.release() is None
    assert str(error.value) in m.message and m.record is None


def test_cancel_mid_drag_clears_the_preview_and_ignores_later_events():
    m = machine()
    m.press(EDGE_POINT)
    m.move(0.3)
    m.cancel()
    assert m.phase is Phase.CANCELLED and m.n_vertices == 0
    m.move(0.5)
    assert m.release() is None and m.enter() is None and m.record is None
    assert not m.press(EDGE_POINT)


def test_typed_radius_overrides_the_mouse_until_erased():
    m = machine()
    m.press(EDGE_POINT)
    m.move(0.2)
    for character in "0.35":
        assert m.type_character(character)
    assert m.radius == 0.35
    m.move(0.9)  # the mouse no longer sets the radius
    assert m.radius == 0.35 and m.mouse_radius == 0.9
    assert not m.type_character(".")  # a second decimal point is refused
    assert not m.type_character("x")
    for _ in range(4):
        m.backspace()
    assert m.typed == "" and m.radius == 0.9
    assert m.n_vertices == brute_ball(m.center, 0.9).size


def test_enter_confirms_a_typed_radius():
    m = machine()
    m.press(EDGE_POINT)
    for character in "0.4":
        m.type_character(character)
    record = m.enter()
    assert record is not None and record.radius == 0.4


def test_lam_change_remeasures_the_current_patch():
    m = machine()
    m.press(EDGE_POINT)
    m.move(0.5)
    m.change_lam(+2)
    assert m.lam == 2.0 + 2 * LAM_STEP
    assert m.measurement is not None and m.measurement.lam == m.lam
    assert m.measurement.angle == SURFACE.measure(m.center, 0.5, m.lam).angle
    m.change_lam(-100)
    assert m.lam == 0.0
    m.move(0.45)  # a new patch: the old measurement no longer applies
    assert m.measurement is None
    record = m.release()
    assert record.lam == 0.0 and record.measurement.lam == 0.0


def test_quantize_applies_to_mouse_and_typed_radii():
    as_float32 = lambda r: float(np.float32(r))  # noqa: E731
    m = machine(quantize=as_float32)
    m.press(EDGE_POINT)
    m.move(0.3)
    assert m.radius == float(np.float32(0.3)) != 0.3
    for character in "0.41":
        m.type_character(character)
    assert m.radius == float(np.float32(0.41))
    assert m.release().radius == float(np.float32(0.41))


def test_snap_error_is_a_message_not_an_exception():
    def refuse(point):
        raise GoniometerError("too far from the surface")

    m = DragMachine(query=lambda c, r: [], measure=lambda c, r, lam: None, snap=refuse)
    assert not m.press([0.0, 0.0, 0.0])
    assert m.phase is Phase.IDLE and m.message == "too far from the surface"


# -- properties over random event sequences --------------------------------------------------

vertex_ids = st.integers(0, SURFACE.n_points - 1)
events = st.one_of(
    st.tuples(st.just("press"), st.one_of(st.none(), vertex_ids)),
    st.tuples(st.just("move"), st.floats(0.0, 1.5)),
    st.tuples(st.just("type"), st.sampled_from("0123456789.x")),
    st.tuples(st.just("backspace"), st.none()),
    st.tuples(st.just("enter"), st.none()),
    st.tuples(st.just("release"), st.none()),
    st.tuples(st.just("cancel"), st.none()),
    st.tuples(st.just("lam"), st.integers(-4, 4)),
)


def would_measure(m: DragMachine) -> bool:
    if m.phase is not Phase.DRAGGING or m.n_vertices < MIN_PATCH_VERTICES:
        return False
    try:
        SURFACE.measure(m.center, m.radius, m.lam)
    except GoniometerError:
        return False
    return True


@settings(max_examples=150, deadline=None)
@given(st.lists(events, max_size=25))
def test_event_sequences(sequence):
    m = machine()
    records = []
    cancelled_first = False
    for kind, value in sequence:
        if kind == "press":
            m.press(None if value is None else SURFACE.points[value] + 1e-4)
        elif kind == "move":
            m.move(value)
        elif kind == "type":
            m.type_character(value)
        elif kind == "backspace":
            m.backspace()
        elif kind == "lam":
            m.change_lam(value)
        elif kind == "cancel":
            cancelled_first = cancelled_first or not records
            m.cancel()
        else:
            expected = would_measure(m)
            record = m.release() if kind == "release" else m.enter()
            assert (record is not None) == expected
            if record is not None:
                records.append(record)
        if m.phase is Phase.DRAGGING:
            if m.radius >= MIN_RADIUS:  # smaller radii are refused: no patch
                assert m.n_vertices == brute_ball(m.center, m.radius).size
            if m.typed:  # a typed radius is exactly the number typed
                assert m.radius == (float(m.typed) if m.typed != "." else 0.0)
            assert (m.n_vertices < MIN_PATCH_VERTICES) == ("Too few" in m.message)
    assert len(records) <= 1  # release records at most once
    if cancelled_first:
        assert not records and m.record is None and m.phase is Phase.CANCELLED
    if records:
        record = records[0]
        assert m.phase is Phase.MEASURED and m.record is record
        replay = SURFACE.measure(record.center, record.radius, record.lam)
        assert replay.angle == record.measurement.angle  # replayable bit for bit
        assert replay.center_index == record.measurement.center_index


@settings(max_examples=80, deadline=None)
@given(
    whole=st.integers(0, 99),
    fraction=st.text(alphabet="0123456789", max_size=6),
    mouse=st.floats(0.0, 2.0),
)
def test_typed_radius_is_exact(whole, fraction, mouse):
    text = f"{whole}.{fraction}" if fraction else str(whole)
    m = machine()
    m.press(EDGE_POINT)
    m.move(mouse)
    for character in text:
        assert m.type_character(character)
    assert m.radius == float(text)
    m.move(mouse + 0.1)
    assert m.radius == float(text)
    record = m.release()
    if record is not None:
        assert record.radius == float(text)
