"""The edge-profile interaction's state machine, driven by clicks on a real Surface."""

import numpy as np

from vg_addon import Surface
from vg_addon.synthetic_meshes import varying_wedge
from vg_addon.workflow.edge_state import MISSED, EdgeMachine, EdgePhase

SHAPE = varying_wedge(80.0, 120.0, half_width=2.0, depth=1.0, n=20)
SURFACE = Surface(SHAPE.points, SHAPE.triangles)


def test_clicks_trace_the_path_as_they_come_and_confirm_measures_it():
    machine = EdgeMachine(SURFACE)
    assert machine.click([-1.5, 0.01, 0.0]) and machine.path is None  # one click: no path yet
    assert machine.click([0.0, -0.01, 0.0])
    first_leg = machine.path
    assert first_leg.points[-1][0] == 0.0 and np.abs(first_leg.points[:, 1:]).max() == 0.0
    assert machine.click([1.5, 0.0, 0.0])
    assert machine.path.length > first_leg.length
    assert machine.path.waypoints.tolist() == [0, 30, 60]  # 20 vertices per unit on the crease
    profile = machine.confirm(spacing=0.5, radius=0.3)
    assert machine.phase is EdgePhase.CONFIRMED and profile is machine.profile
    # The same clicks through the core's one-call API give the same stations, bit for bit.
    again = SURFACE.measure_along(machine.clicks, 0.5, 0.3)
    assert again.angles.tolist() == profile.angles.tolist()
    assert np.array_equal(again.path.vertices, profile.path.vertices)


def test_undo_drops_the_last_click_and_its_leg():
    machine = EdgeMachine(SURFACE)
    for x in (-1.5, 0.0, 1.5):
        machine.click([x, 0.0, 0.0])
    machine.undo()
    assert len(machine.clicks) == 2 and machine.path.points[-1][0] == 0.0
    machine.undo()
    assert machine.path is None and len(machine.clicks) == 1
    machine.undo()
    assert not machine.undo() and machine.clicks == []


def test_refusals_leave_the_machine_as_it_was():
    machine = EdgeMachine(SURFACE)
    assert not machine.click(None) and machine.message == MISSED
    machine.click([-1.0, 0.0, 0.0])
    assert not machine.click([-1.0, 0.001, 0.0])
    assert "same vertex" in machine.message and len(machine.clicks) == 1
    assert machine.confirm(0.5, 0.3) is None and "start and the end" in machine.message
    machine.click([1.0, 0.0, 0.0])
    assert machine.confirm(0.5, 0.001) is None  # too small a radius: refused, still picking
    assert machine.phase is EdgePhase.PICKING and "could not be measured" in machine.message
    assert "radius" in machine.message.splitlines()[0]  # why, on the line the header shows
    assert machine.confirm(0.5, 0.3) is not None


def test_cancel_is_final():
    machine = EdgeMachine(SURFACE)
    machine.click([-1.0, 0.0, 0.0])
    machine.cancel()
    assert machine.phase is EdgePhase.CANCELLED and "nothing was recorded" in machine.message
    assert not machine.click([1.0, 0.0, 0.0]) and machine.confirm(0.5, 0.3) is None


def test_a_click_off_the_ridge_shows_the_flat_warning_while_picking():
    machine = EdgeMachine(SURFACE)
    machine.click([-1.5, 0.0, 0.0])
    half = np.radians(80.0) / 2
    machine.click([-1.5, 0.8 * np.sin(half), -0.8 * np.cos(half)])  # straight down face +
    assert machine.path.flat_spans and "no ridge" in machine.message


def test_a_click_that_turns_back_along_the_edge_is_flagged_while_picking():
    # Before, nothing said so until Enter refused the path (or, where no two stations met on a
    # vertex, measured the stretch twice). Oracle: the crease is the x axis with 20 vertices per
    # unit; out from -1.5 to 1.5 and back to -0.5, the path passes x from -0.5 to 1.45 twice:
    # arc lengths 1 to 2.95 going out and 3.05 to 5 coming back.
    machine = EdgeMachine(SURFACE)
    for x in (-1.5, 1.5):
        machine.click([x, 0.0, 0.0])
    assert machine.message == ""
    assert machine.click([-0.5, 0.0, 0.0])  # a warning, not a refusal: the user may mean it
    spans = np.array(machine.path.revisited_spans)
    assert np.allclose(spans, [[1.0, 2.95], [3.05, 5.0]], atol=1e-9), spans
    assert machine.message.startswith("The traced path passes the same vertices twice")
    assert "1 to 2.95" in machine.message and "3.05 to 5 of 5" in machine.message
    machine.undo()
    assert machine.message == "" and machine.path.revisited_spans == ()


def test_confirm_measures_every_station_with_the_rule_given():
    machine = EdgeMachine(SURFACE)
    for x in (-1.5, 1.5):
        machine.click([x, 0.0, 0.0])
    profile = machine.confirm(0.5, 0.3, rule="paper", stability=True)
    for station in profile.stations:
        alone = SURFACE.measure(station.center, 0.3, rule="paper", stability=True)
        assert station.rule == "paper"
        assert (station.angle, station.stability) == (alone.angle, alone.stability)
