"""Bad input: a clear message (the operator's error report), never a traceback, and nothing changed."""

import bpy
import numpy as np
import pytest
from bpy_helpers import (
    colours,
    exact,
    expected_colours,
    linked_object,
    local_points,
    mesh_object,
    snapshot,
    wedge_object,
    world,
)

from vg_addon import Surface
from vg_addon.synthetic_meshes import wedge


def measured_wedge():
    """A wedge with one measurement already, so that 'nothing changed' has something to keep."""
    obj = wedge_object(100.0)
    bpy.ops.vg.measure_xyz(location=(0, 0, 0), radius=0.5)
    return obj


def assert_refused(match, **kwargs):
    with pytest.raises(RuntimeError, match=match) as error:
        bpy.ops.vg.measure_xyz(**kwargs)
    assert "Traceback" not in str(error.value)


def test_no_active_object(vg):
    obj = measured_wedge()
    before = snapshot(obj)
    bpy.context.view_layer.objects.active = None
    assert_refused("No active object", location=(0, 0, 0), radius=0.5)
    assert snapshot(obj) == before


def test_not_a_mesh(vg):
    obj = measured_wedge()
    before = snapshot(obj)
    empty = bpy.data.objects.new("Empty", None)
    bpy.context.scene.collection.objects.link(empty)
    bpy.context.view_layer.objects.active = empty
    assert_refused(
        "'Empty' is not a mesh but an object of type EMPTY", location=(0, 0, 0), radius=0.5
    )
    curve = bpy.data.objects.new("Curve", bpy.data.curves.new("Curve", "CURVE"))
    bpy.context.scene.collection.objects.link(curve)
    bpy.context.view_layer.objects.active = curve
    assert_refused("not a mesh", location=(0, 0, 0), radius=0.5)
    assert snapshot(obj) == before


def test_empty_mesh(vg):
    obj = bpy.data.objects.new("Nothing", bpy.data.meshes.new("Nothing"))
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    before = snapshot(obj)
    assert_refused("'Nothing' has no vertices", location=(0, 0, 0), radius=0.5)
    assert snapshot(obj) == before


def test_location_farther_than_the_radius(vg):
    obj = measured_wedge()
    before = snapshot(obj)
    assert_refused("farther than the radius", location=(0, 0, 5.0), radius=0.5)
    assert snapshot(obj) == before


def test_radius_too_small(vg):
    obj = measured_wedge()
    before = snapshot(obj)
    on_a_vertex = exact(obj.vg.measurements[0])["center"]
    assert_refused("use a larger radius", location=on_a_vertex, radius=0.01)
    assert snapshot(obj) == before


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"radius": 0.0}, "adius"),
        ({"radius": float("nan")}, "adius"),
        ({"lam": -1.0}, "λ|lam|SegParam"),
        ({"patch": "spherical"}, "Unknown patch mode"),
        ({"location": (np.inf, 0, 0)}, "entre|finite"),
    ],
)
def test_bad_numbers_through_the_pipeline_function(vg, kwargs, match):
    obj = measured_wedge()
    before = snapshot(obj)
    args = {"location": (0, 0, 0), "radius": 0.5, "lam": 2.0, "patch": "euclidean"} | kwargs
    with pytest.raises(vg.vg_addon.GoniometerError, match=match):
        vg.bridge.measuring.measure_on_object(obj, **args)
    assert snapshot(obj) == before


def test_edit_mode(vg):
    obj = measured_wedge()
    before = snapshot(obj)
    bpy.ops.object.mode_set(mode="EDIT")
    try:
        assert_refused("Edit Mode", location=(0, 0, 0), radius=0.5)
    finally:
        bpy.ops.object.mode_set(mode="OBJECT")
    assert snapshot(obj) == before


def test_linked_data_is_read_only(vg, tmp_path):
    wedge_object(100.0, "Linked wedge")
    library = tmp_path / "library.blend"
    bpy.data.libraries.write(str(library), {bpy.data.objects["Linked wedge"]})
    obj = linked_object(library, "Linked wedge")
    assert obj.library is not None
    assert_refused("is linked from .*library.blend.*Make Local", location=(0, 0, 0), radius=0.5)
    assert len(obj.vg.measurements) == 0
    assert colours(obj) is None


def edit_a_vertex(obj):
    co = local_points(obj).copy()
    co[0] += 0.01
    obj.data.vertices.foreach_set("co", co.ravel())
    obj.data.update()
    bpy.context.view_layer.update()


def test_stale_measurement_is_kept_but_not_painted(vg, capfd):
    obj = measured_wedge()
    first = exact(obj.vg.measurements[0])
    edit_a_vertex(obj)
    bpy.ops.vg.repaint()
    assert "Measurement(s) 1 of 'Wedge' are stale" in capfd.readouterr().out
    item = obj.vg.measurements[0]
    assert item.stale and exact(item) == first  # numbers kept as recorded
    grey = np.asarray(vg.vg_addon.palette.neutral_linear(), dtype=np.float32)
    assert (colours(obj) == grey).all()  # not mis-coloured on the changed mesh

    # A new measurement on the edited mesh is painted; the stale one still is not.
    bpy.ops.vg.measure_xyz(location=(0.2, 0, 0), radius=0.4)
    assert "are stale" in capfd.readouterr().out
    surface = Surface(world(local_points(obj), obj), _triangles(obj))
    m = surface.measure([0.2, 0, 0], 0.4)
    np.testing.assert_array_equal(
        colours(obj), expected_colours(len(obj.data.vertices), [(m.indices, m.labels, 1)])
    )
    assert [i.stale for i in obj.vg.measurements] == [True, False]

    # Putting the vertex back makes the first measurement valid again, and the second stale.
    co = local_points(obj).copy()
    co[0] -= 0.01
    obj.data.vertices.foreach_set("co", co.ravel())
    obj.data.update()
    bpy.ops.vg.repaint()
    assert [i.stale for i in obj.vg.measurements] == [False, True]


def test_edits_are_noticed_without_running_an_operator(vg):
    """A handler notes edited objects; a timer (which needs Blender's event loop, so it is
    called by hand here) then flags their stale measurements and repaints."""
    watch = vg.bridge.watch
    obj = measured_wedge()
    assert not watch.refresh(obj)  # nothing to do yet
    edit_a_vertex(obj)
    assert "Wedge" in watch._pending
    watch._check_pending()
    assert obj.vg.measurements[0].stale
    grey = np.asarray(vg.vg_addon.palette.neutral_linear(), dtype=np.float32)
    assert (colours(obj) == grey).all()
    assert not watch.refresh(obj)


def test_moving_the_object_keeps_measurements_current(vg):
    obj = measured_wedge()
    vg.bridge.watch._check_pending()  # the measurement's own colour write
    before = snapshot(obj)
    obj.location.x += 1.0
    obj.rotation_euler.z += 0.5
    bpy.context.view_layer.update()
    assert "Wedge" not in vg.bridge.watch._pending  # a move is not an edit of the mesh
    bpy.ops.vg.repaint()
    assert snapshot(obj) == before


def _triangles(obj):
    mesh = obj.data
    mesh.calc_loop_triangles()
    tris = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", tris)
    return tris.reshape(-1, 3)


def test_delete_with_nothing_selected(vg):
    obj = measured_wedge()
    before = snapshot(obj)
    with pytest.raises(RuntimeError, match="no measurement at list position 5"):
        bpy.ops.vg.delete_measurement(index=5)
    assert snapshot(obj) == before


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"seg_param": -1.0}, r"λ \(SegParam\) must be a number from 0 .*got -1\.0"),
        ({"radius": -1.0}, r"radius must be a finite number greater than 0; got -1\.0"),
    ],
)
def test_negative_operator_values_are_refused_as_given(vg, kwargs, match):
    obj = measured_wedge()
    before = snapshot(obj)
    assert_refused(match, location=(0, 0, 0), **({"radius": 0.5} | kwargs))
    assert snapshot(obj) == before


EDGE = {"points": "[[-0.4, 0, 0], [0.4, 0, 0]]", "space": "MESH", "radius": 0.3, "spacing": 0.2}


@pytest.mark.parametrize(
    ("operator", "kwargs", "match"),
    [
        ("measure_edge", EDGE | {"radius": -1.0}, r"radius .*got -1\.0"),
        ("measure_edge", EDGE | {"seg_param": -1.0}, r"λ \(SegParam\) must be a number .*got -1"),
        ("measure_edge", EDGE | {"spacing": -1.0}, r"spacing .*-1"),
        ("radius_sweep", {"start": -1.0, "stop": 0.5, "count": 3}, r"-1"),
        ("radius_sweep", {"start": 0.1, "stop": -1.0, "count": 3}, r"-1"),
    ],
    ids=["edge radius", "edge λ", "edge spacing", "sweep from", "sweep to"],
)
def test_every_operator_refuses_negative_values_as_given(vg, tmp_path, operator, kwargs, match):
    """The measuring operators share one property set (operators/common.py): a negative length
    or λ reaches the measuring code and is refused naming it, never clamped to 0."""
    obj = measured_wedge()
    before = snapshot(obj)
    if operator == "radius_sweep":
        kwargs = kwargs | {"filepath": str(tmp_path / "sweep.csv"), "location": (0, 0, 0)}
    with pytest.raises(RuntimeError, match=match) as error:
        getattr(bpy.ops.vg, operator)(**kwargs)
    assert "Traceback" not in str(error.value)
    assert snapshot(obj) == before
    assert not list(tmp_path.iterdir())


def test_a_mesh_shared_by_two_objects_is_refused_until_each_has_its_own(vg):
    """A linked duplicate (Alt+D) shares its mesh, and the sides' colours live on the mesh: a
    measurement on either object would paint over the other's colours (before: accepted, and
    the other object showed this one's sides). Refused, naming the other object, with nothing
    changed; once the copy has its own mesh, measuring one leaves the other's colours alone."""
    obj = measured_wedge()
    copy = bpy.data.objects.new("Copy", obj.data)
    bpy.context.scene.collection.objects.link(copy)
    before = snapshot(obj)
    for target, other in ((obj, "Copy"), (copy, obj.name)):
        bpy.context.view_layer.objects.active = target
        assert_refused(
            f"shares its mesh '{obj.data.name}' with '{other}'", location=(0, 0, 0), radius=0.5
        )
        assert not bpy.ops.vg.delete_measurement.poll()
    assert snapshot(obj) == before and not len(copy.vg.measurements)

    copy.data = obj.data.copy()  # Make Single User > Object & Data
    copy_colours = colours(copy).copy()
    bpy.context.view_layer.objects.active = obj
    bpy.ops.vg.measure_xyz(location=(0.1, 0, 0), radius=0.4)
    assert len(obj.vg.measurements) == 2
    assert np.array_equal(colours(copy), copy_colours)
    assert not np.array_equal(colours(obj), copy_colours)


def test_a_mesh_stored_far_from_its_origin_is_refused_with_the_reason(vg):
    """A scan imported in site coordinates, its coordinates up to 1.13 million: Blender holds
    its vertices as float32, rounded to 0.125, more than the spacing of its vertices, and the
    90° wedge read degrees off (Unstable, with no reason given). Now refused, naming float32
    and the step. The same wedge kept near its mesh origin and placed that far away by the
    object's location is measured: the oracle is the wedge's true angle."""
    shape = wedge(90.0, n=40, irregular=True, seed=1)
    centre = np.array([1.13, -0.71, 0.37]) * 1e6
    far = mesh_object("Far", np.asarray(shape.points) + centre, shape.triangles)
    before = snapshot(far)
    assert_refused(r"stored as float32.*steps of 0\.12", location=centre, radius=0.5, space="MESH")
    assert snapshot(far) == before
    placed = mesh_object("Placed", shape.points, shape.triangles, location=centre)
    bpy.ops.vg.measure_xyz(location=(0.0, 0.0, 0.0), radius=0.5, space="MESH")
    assert placed.vg.measurements[-1].angle == pytest.approx(90.0, abs=0.01)


def test_a_patch_on_a_fin_is_refused_and_the_edge_beyond_it_is_measured(vg):
    """A third face standing on the break edge (a fin ten vertex spacings high, each crease
    edge under it bordering three faces, as Blender keeps it): the click on it is refused with
    how to select such edges, nothing changed (before: 69.65° recorded for a 90° edge); the
    same edge beyond the fin reads its angle, the oracle."""
    from defect_meshes import wedge_with_fin

    points, triangles = wedge_with_fin(90.0, rows=10)
    obj = mesh_object("Fin", points, triangles)
    multi_face = [len(edge_faces) for edge_faces in _faces_of_edges(obj).values()]
    assert max(multi_face) == 3  # Blender kept the fin on the crease
    bpy.ops.vg.measure_xyz(location=(0.5, 0.0, 0.0), radius=0.3)
    before = snapshot(obj)
    assert_refused(
        r"shared by three or more faces.*Non Manifold", location=(-0.6, 0, 0), radius=0.3
    )
    assert snapshot(obj) == before
    assert obj.vg.measurements[-1].angle == pytest.approx(90.0, abs=1e-4)


def test_a_separate_part_in_the_ball_is_left_out_and_the_paper_rule_refused(vg):
    """Another fragment kept in the same mesh, its sheet 0.005 from the +1 face of a 120° edge
    and joined to it by no face: the click there measures the wedge's part alone (before: 30.00°
    recorded), as the geodesic patch does; the paper rule, which takes the whole ball, is
    refused with how to separate the parts, nothing changed. Oracle: the edge's angle."""
    from defect_meshes import wedge_with_fragment

    points, triangles = wedge_with_fragment(120.0, 0.005)
    obj = mesh_object("Refitted", points, triangles)
    bpy.ops.vg.measure_xyz(location=(-0.3, 0.0, 0.0), radius=0.3)
    bpy.ops.vg.measure_xyz(location=(-0.3, 0.0, 0.0), radius=0.3, patch="geodesic")
    before = snapshot(obj)
    assert_refused(
        r"separate part of the mesh.*paper rule.*By Loose Parts",
        location=(-0.3, 0, 0),
        radius=0.3,
        rule="paper",
    )
    assert snapshot(obj) == before
    assert [item.angle for item in obj.vg.measurements] == pytest.approx([120.0, 120.0], abs=1e-4)


def _faces_of_edges(obj) -> dict:
    faces = {}
    for polygon in obj.data.polygons:
        for key in polygon.edge_keys:
            faces.setdefault(key, []).append(polygon.index)
    return faces
