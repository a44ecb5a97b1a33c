"""vg.find_break_edges and vg.import_picked_points in Blender (the bpy module), against the core.

The modal review is its state machine (tests/core/test_find_edges_state.py) plus what it ends
in: the accepted edges' points in ``edges``, recorded by the operator's exec path in one undo
step; the real window's clicks and keys are tests/gui/test_gui_find_edges.py. Oracles: the core's
``find_break_edges`` and ``Surface.measure_along`` on the object's own mesh, built here.
"""

import importlib
import json

import bpy
import numpy as np
import pytest
from bpy_helpers import exact, mesh_object, wedge_object
from conftest import MODULE
from test_ext_measure import core_surface

from vg_addon import GoniometerError
from vg_addon.method.break_edges import BreakEdgeFinder, find_break_edges
from vg_addon.synthetic_meshes import bone_fragment
from vg_addon.workflow.find_edges_state import FindEdgesMachine, FindPhase

SPACING, RADIUS = 4.0, 1.5


def fragment_object(name="Fragment"):
    fragment = bone_fragment(spacing=0.4)
    obj = mesh_object(name, fragment.points, fragment.triangles, location=(3.0, -2.0, 1.0))
    bpy.context.scene.vg_settings.edge_spacing = SPACING
    bpy.context.scene.vg_settings.radius = RADIUS
    return obj


def stations(obj, edge_number) -> list[dict]:
    return [exact(m) for m in obj.vg.measurements if m.edge_number == edge_number]


def assert_profile_recorded(obj, edge, profile, points):
    """The edge and its stations hold the core's profile bit for bit; its Points are
    ``points``."""
    got = stations(obj, edge.number)
    assert len(got) == profile.n_stations == edge.n_stations
    for numbers, m, arc in zip(got, profile.stations, profile.arc_lengths, strict=True):
        assert (numbers["angle"], numbers["fit"]) == (m.angle, m.fit_error)
        assert numbers["center"] == m.center.tolist() and numbers["arc_length"] == arc
    assert exact(edge)["points"] == np.asarray(points).tolist()
    assert exact(edge)["mean"] == profile.mean
    assert {m.break_number for m in obj.vg.measurements if m.edge_number == edge.number} == {
        edge.break_number
    }


def test_poll_says_why_it_cannot_run(vg):
    bpy.context.view_layer.objects.active = None
    assert not bpy.ops.vg.find_break_edges.poll()
    assert not bpy.ops.vg.import_picked_points.poll()
    with pytest.raises(RuntimeError, match="No active object: click the mesh"):
        bpy.ops.vg.find_break_edges(accept="ALL")


def core_profiles(surface, candidates) -> dict:
    """``{number: (points, profile)}`` of the candidates the core measures along (a candidate
    with a station the core refuses is refused by the operator too: test_edges_are_all_or_nothing)."""
    measured = {}
    for candidate in candidates:
        points = candidate.path.points[candidate.path.waypoints]
        try:
            measured[candidate.number] = (points, surface.measure_along(points, SPACING, RADIUS))
        except GoniometerError:
            continue
    return measured


def test_accepted_candidates_are_recorded_as_the_cores_profiles(vg):
    obj = fragment_object()
    surface = core_surface(obj)
    candidates = find_break_edges(surface).candidates
    measured = core_profiles(surface, candidates)
    assert len(measured) >= 2
    accept = "ALL" if len(measured) == len(candidates) else " ".join(map(str, measured))
    assert bpy.ops.vg.find_break_edges(accept=accept) == {"FINISHED"}
    assert len(obj.vg.edges) == len(measured)
    for edge, number in zip(obj.vg.edges, measured, strict=True):
        points, profile = measured[number]
        assert np.array_equal(profile.path.vertices, candidates[number - 1].path.vertices)
        assert_profile_recorded(obj, edge, profile, points)
    # Each edge its own break; a measurement after them starts a new one.
    breaks = [edge.break_number for edge in obj.vg.edges]
    assert len(set(breaks)) == len(breaks) and obj.vg.break_number == max(breaks) + 1


def test_named_candidates_only_and_unknown_numbers_refused_with_nothing_recorded(vg):
    obj = fragment_object()
    n = len(find_break_edges(core_surface(obj)).candidates)
    with pytest.raises(RuntimeError, match=f"No candidate numbered {n + 1}"):
        bpy.ops.vg.find_break_edges(accept=f"1 {n + 1}")
    with pytest.raises(RuntimeError, match="accept must be ALL or candidate numbers"):
        bpy.ops.vg.find_break_edges(accept="first")
    with pytest.raises(RuntimeError, match="Name the candidates to record"):
        bpy.ops.vg.find_break_edges()
    for name in ("scale", "min_length"):  # refused as given, never replaced by the default
        with pytest.raises(RuntimeError, match=f"parameter {name} must be a positive number"):
            bpy.ops.vg.find_break_edges(accept="ALL", **{name: -1.0})
    assert len(obj.vg.edges) == len(obj.vg.measurements) == 0
    assert bpy.ops.vg.find_break_edges(accept="2") == {"FINISHED"}
    assert len(obj.vg.edges) == 1


def test_the_panels_finder_settings_drive_it_and_are_saved_in_the_blend(vg, tmp_path):
    obj = fragment_object()
    surface = core_surface(obj)
    lengths = sorted(c.length for c in find_break_edges(surface).candidates)
    assert len(lengths) >= 2
    # Between the two shortest: the core, given it, drops the shortest candidate.
    min_length = (lengths[0] + lengths[1]) / 2
    kept = find_break_edges(surface, min_length=min_length).candidates
    assert 1 <= len(kept) < len(lengths)
    settings = bpy.context.scene.vg_settings
    settings.find_min_length, settings.find_min_bend = min_length, 35.0
    path, name = tmp_path / "settings.blend", obj.name
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.read_homefile(use_empty=True)
    bpy.ops.wm.open_mainfile(filepath=str(path))
    settings = bpy.context.scene.vg_settings
    assert (settings.find_scale, settings.find_min_bend) == (0.0, 35.0)
    assert settings.find_min_length == pytest.approx(min_length, rel=1e-6)  # a float32 property
    obj = bpy.data.objects[name]
    bpy.context.view_layer.objects.active = obj
    expected = find_break_edges(
        core_surface(obj), min_length=settings.find_min_length, min_bend_deg=35.0
    ).candidates
    assert bpy.ops.vg.find_break_edges(accept="ALL") == {"FINISHED"}
    assert len(obj.vg.edges) == len(expected) < len(lengths)
    # What the caller gives wins over the panel.
    with pytest.raises(RuntimeError, match="parameter min_length must be a positive number"):
        bpy.ops.vg.find_break_edges(accept="ALL", min_length=-1.0)


def test_a_review_records_its_accepted_and_trimmed_edges_in_one_undo_step(vg):
    """The review on the bridge's own surface: accept candidate 1, reject 2, trim and accept 3;
    what it stores in ``edges`` records exactly the machine's profiles, and one undo removes
    all of it."""
    obj = fragment_object()
    bridge = importlib.import_module(f"{MODULE}.bridge.mesh_data")
    find_edges = importlib.import_module(f"{MODULE}.operators.find_edges")
    surface = bridge.surface_for(obj, bridge.evaluated_geometry(obj))
    machine = FindEdgesMachine(surface, BreakEdgeFinder(surface))
    while machine.step():
        pass
    machine.accept()
    machine.reject()
    whole = machine.candidates[2].length
    machine.trim_to(0.25 * whole, 0.75 * whole)
    machine.accept()
    machine.finish(SPACING, RADIUS)
    while machine.step():
        pass
    assert machine.phase is FindPhase.DONE and len(machine.profiles) == 2
    assert machine.profiles[1][1].path.length == pytest.approx(0.5 * whole, rel=0.1)

    bpy.ops.ed.undo_push(message="before")
    edges_json = find_edges.format_edges_json([points for points, _ in machine.profiles])
    assert bpy.ops.vg.find_break_edges("EXEC_DEFAULT", True, edges=edges_json) == {"FINISHED"}
    obj = bpy.data.objects["Fragment"]
    assert len(obj.vg.edges) == 2
    for edge, (points, profile) in zip(obj.vg.edges, machine.profiles, strict=True):
        assert_profile_recorded(obj, edge, profile, points)
    bpy.ops.ed.undo()
    obj = bpy.data.objects["Fragment"]  # undo reloads the data
    assert len(obj.vg.edges) == len(obj.vg.measurements) == 0


def test_edges_are_all_or_nothing(vg):
    obj = fragment_object()
    candidate = find_break_edges(core_surface(obj)).candidates[0]
    good = candidate.path.points[candidate.path.waypoints].tolist()
    far = [[500.0, 500.0, 500.0], [600.0, 500.0, 500.0]]  # off the mesh
    with pytest.raises(RuntimeError, match="1 of 2 edges cannot be measured; nothing"):
        bpy.ops.vg.find_break_edges(edges=json.dumps([good, far]))
    with pytest.raises(RuntimeError, match="Edge 1 needs two or more"):
        bpy.ops.vg.find_break_edges(edges=json.dumps([[[0, 0, 0]]]))
    assert len(obj.vg.edges) == len(obj.vg.measurements) == 0


# -- MeshLab picked points ----------------------------------------------------------------------
def write_pp(path, points, active=None):
    active = [1] * len(points) if active is None else active
    rows = "\n".join(
        f' <point x="{x!r}" y="{y!r}" z="{z!r}" name="{k}" active="{a}"/>'
        for k, ((x, y, z), a) in enumerate(zip(np.asarray(points).tolist(), active, strict=True))
    )
    path.write_text(
        "<!DOCTYPE PickedPoints>\n<PickedPoints>\n <DocumentData>\n"
        '  <DataFileName name="Fragment.ply"/>\n </DocumentData>\n'
        f"{rows}\n</PickedPoints>\n"
    )
    return path


def test_picked_points_make_edges_named_files_only_all_or_nothing(vg, tmp_path):
    obj = fragment_object()
    surface = core_surface(obj)
    candidates = find_break_edges(surface).candidates
    # Two breaks' endpoints as an analyst picked them in MeshLab: a start, a via point and an
    # end on each rim (a few path vertices in from the candidate's own ends).
    picks = []
    for candidate in candidates[:2]:
        path = candidate.path
        k = path.vertices.size
        picks.append(path.points[[3, k // 3, k // 2]].astype(np.float64))
    first = write_pp(tmp_path / "Fragment_break1.pp", picks[0])
    second = write_pp(tmp_path / "Fragment_break2.pp", picks[1], active=[1, 0, 1])
    other = write_pp(tmp_path / "Other_break1.pp", picks[0])

    with pytest.raises(RuntimeError, match="is not named after 'Fragment'"):
        bpy.ops.vg.import_picked_points(
            directory=str(tmp_path), files=[{"name": first.name}, {"name": other.name}]
        )
    assert len(obj.vg.edges) == 0
    result = bpy.ops.vg.import_picked_points(
        directory=str(tmp_path), files=[{"name": first.name}, {"name": second.name}]
    )
    assert result == {"FINISHED"} and len(obj.vg.edges) == 2
    expected = (picks[0], picks[1][[0, 2]])  # the inactive via point is not the edge's
    for edge, points, name in zip(obj.vg.edges, expected, (first, second), strict=True):
        profile = surface.measure_along(points, SPACING, RADIUS)
        assert_profile_recorded(obj, edge, profile, points)
        assert edge.note == name.name
    assert bpy.ops.vg.import_picked_points(filepath=str(other), ignore_mesh_names=True) == {
        "FINISHED"
    }
    assert len(obj.vg.edges) == 3


def test_picked_points_off_the_mesh_are_refused_naming_the_file(vg, tmp_path):
    obj = fragment_object()
    surface = core_surface(obj)
    path = find_break_edges(surface).candidates[0].path
    k = path.vertices.size
    # Picked on a copy of the mesh moved 30 along x, beside this one (it spans x from
    # -12 to 12); the oracle distance is the brute-force nearest vertex's.
    shifted = path.points[[3, k // 2]] + np.array([30.0, 0.0, 0.0])
    nearest = np.linalg.norm(surface.points[None] - shifted[:, None], axis=2).min(axis=1)
    good = write_pp(tmp_path / "Fragment_good.pp", path.points[[3, k // 2]])
    off = write_pp(tmp_path / "Fragment_shifted.pp", shifted)
    with pytest.raises(RuntimeError, match="1 of 2 picked-points files lie off the mesh") as error:
        bpy.ops.vg.import_picked_points(
            directory=str(tmp_path), files=[{"name": good.name}, {"name": off.name}]
        )
    assert "'Fragment_shifted.pp': point 1 (" in str(error.value)
    assert f"is {nearest[0]:.6g} from the mesh" in str(error.value)
    assert f"is {nearest[1]:.6g} from the mesh" in str(error.value)
    assert len(obj.vg.edges) == len(obj.vg.measurements) == 0


def test_stations_take_the_panels_rule_and_stability(vg):
    obj = fragment_object()
    settings = bpy.context.scene.vg_settings
    settings.rule, settings.stability = "paper", True
    surface = core_surface(obj)
    number = next(iter(core_profiles(surface, find_break_edges(surface).candidates)))
    assert bpy.ops.vg.find_break_edges(accept=str(number)) == {"FINISHED"}
    got = stations(obj, obj.vg.edges[0].number)
    assert got
    for numbers in got:
        # Oracle: a single measurement at the station's centre with the panel's settings.
        alone = surface.measure(numbers["center"], RADIUS, rule="paper", stability=True)
        assert numbers["rule"] == "paper" and numbers["angle"] == alone.angle
        assert numbers["stability"]["spread"] == alone.stability.spread


def test_a_picked_points_file_named_after_another_object_is_not_measured_on_the_active_one(
    vg, tmp_path
):
    """MeshLab names a file NAME_picked_points.pp. ``bone_12_picked_points.pp`` once fitted the
    active object ``bone`` ("bone" + "_...") and was measured there, though the file belongs to
    ``bone_12`` (the batch, choosing among both, sends it there). Oracle: the edges recorded on
    each object, and the angle of the one made on the right object."""
    bone_12 = wedge_object(60.0, "bone_12", n=40)
    bone = wedge_object(100.0, "bone", n=40)
    bpy.context.view_layer.objects.active = bone
    path = write_pp(tmp_path / "bone_12_picked_points.pp", [[-0.3, 0.0, 0.0], [0.3, 0.0, 0.0]])
    settings = bpy.context.scene.vg_settings
    settings.edge_spacing, settings.radius = 0.1, 0.15
    with pytest.raises(RuntimeError, match="but after the object 'bone_12'"):
        bpy.ops.vg.import_picked_points(filepath=str(path))
    assert len(bone.vg.edges) == 0
    bpy.context.view_layer.objects.active = bone_12
    assert bpy.ops.vg.import_picked_points(filepath=str(path)) == {"FINISHED"}
    (edge,) = bone_12.vg.edges
    assert edge.mean == pytest.approx(60.0, abs=0.01)
