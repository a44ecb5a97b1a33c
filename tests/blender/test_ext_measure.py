"""bpy.ops.vg.measure_xyz against the core: the same inputs in mesh coordinates give
bit-identical numbers, wherever the object is placed."""

import math

import bpy
import numpy as np
import pytest
from bpy_helpers import (
    BREAK_PAIRS,
    COLOUR_ATTRIBUTE,
    OKABE_ITO_HEX,
    colours,
    evaluated_surface,
    exact,
    expected_colours,
    half_annulus_with_edge_vertices,
    linear_rgba,
    local_points,
    mesh_object,
    wedge_object,
    world,
)

from vg_addon import Surface
from vg_addon.formats import csvio


def triangles_of(obj) -> np.ndarray:
    mesh = obj.data
    mesh.calc_loop_triangles()
    tris = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", tris)
    return tris.reshape(-1, 3).astype(np.int64)


def core_surface(obj) -> Surface:
    """The core's Surface of the object's own mesh, in mesh coordinates, built here
    independently."""
    return Surface(local_points(obj).astype(np.float64), triangles_of(obj))


def assert_same(item, m, *, requested=True):
    """The recorded item holds exactly the core measurement ``m`` (but for the requested
    centre and the snap distance, when ``requested`` is False)."""
    numbers = exact(item)
    assert numbers["space"] == "mesh"
    assert numbers["angle"] == m.angle
    assert numbers["fit"] == m.fit_error
    assert numbers["fit_plus"] == m.fit_error_plus
    assert numbers["fit_minus"] == m.fit_error_minus
    assert numbers["radius"] == m.radius
    assert numbers["lam"] == m.lam
    assert numbers["center"] == m.center.tolist()
    if requested:
        assert numbers["requested"] == m.requested_center.tolist()
        assert numbers["snap_distance"] == m.snap_distance
    assert numbers["normal_plus"] == m.normal_plus.tolist()
    assert numbers["normal_minus"] == m.normal_minus.tolist()
    assert (item.n_vertices, item.n_plus, item.n_minus) == (m.n_vertices, m.n_plus, m.n_minus)
    assert item.patch == m.patch
    assert not item.stale


@pytest.mark.parametrize("angle", [30.0, 90.0, 121.5, 160.0])
def test_wedge_angle_matches_core_bit_for_bit(vg, angle):
    obj = wedge_object(angle)
    bpy.ops.vg.measure_xyz(location=(0.01, -0.02, 0.0), radius=0.5, seg_param=2.0)
    item = obj.vg.measurements[0]
    m = core_surface(obj).measure([0.01, -0.02, 0.0], 0.5, 2.0)
    assert_same(item, m)
    assert abs(item.angle - obj["true_angle"]) < 0.01
    assert (item.number, item.break_number) == (1, 1)
    assert item.date and item.colors == "yellow/blue"


def test_typed_values_are_kept_as_typed(vg):
    """Operator properties are float32; 0.3 must be measured and recorded as the float64 0.3."""
    obj = wedge_object(75.0)
    bpy.ops.vg.measure_xyz(location=(0.1, 0.2, 0.0), radius=0.3, seg_param=1.7)
    numbers = exact(obj.vg.measurements[0])
    assert numbers["radius"] == 0.3
    assert numbers["lam"] == 1.7
    assert numbers["requested"] == [0.1, 0.2, 0.0]


def test_defaults_come_from_the_cursor_and_the_panel(vg):
    obj = wedge_object(100.0)
    scene = bpy.context.scene
    scene.cursor.location = (0.05, 0.1, 0.0)
    scene.vg_settings.radius = 0.45
    scene.vg_settings.seg_param = 3.0
    scene.vg_settings.patch = "geodesic"
    bpy.ops.vg.measure_xyz()
    item = obj.vg.measurements[0]
    numbers = exact(item)
    assert numbers["requested"] == [0.05, 0.1, 0.0]
    assert (numbers["radius"], numbers["lam"], item.patch) == (0.45, 3.0, "geodesic")
    assert_same(item, core_surface(obj).measure([0.05, 0.1, 0.0], 0.45, 3.0, "geodesic"))


def test_reports_the_angle(vg, capfd):
    obj = wedge_object(60.0)
    bpy.ops.vg.measure_xyz(location=(0, 0, 0), radius=0.5)
    out = capfd.readouterr()
    angle = obj.vg.measurements[0].angle
    assert f"{angle:.2f}°" in out.out + out.err


def test_a_small_patch_reports_its_stability_figure_unasked(vg, capfd):
    """Fewer than 100 vertices: the figure is computed, recorded and reported though the
    Stability option is off; a larger patch records none."""
    obj = wedge_object(90.0, n=20)
    spacing = np.sqrt(2.0) / 20
    bpy.ops.vg.measure_xyz(location=(0, 0, 0), radius=2.5 * spacing, stability=False)
    small = obj.vg.measurements[-1]
    out = capfd.readouterr()
    assert small.n_vertices < 100
    assert small.stability_text.startswith("±")
    assert small.stability_text in out.out + out.err
    bpy.ops.vg.measure_xyz(location=(0, 0, 0), radius=0.5, stability=False)
    large = obj.vg.measurements[-1]
    assert large.n_vertices >= 100 and large.stability_text == "not computed"
    assert "not computed" not in capfd.readouterr().out


def test_colour_attribute_paints_the_sides_and_spares_the_users_colours(vg):
    obj = wedge_object(80.0)
    mine = obj.data.color_attributes.new("Scan colour", "BYTE_COLOR", "CORNER")
    rng = np.random.default_rng(1)
    before = rng.random(len(mine.data) * 4).astype(np.float32)
    mine.data.foreach_set("color", before)
    before = np.empty_like(before)
    obj.data.color_attributes["Scan colour"].data.foreach_get("color", before)

    bpy.ops.vg.measure_xyz(location=(0, 0, 0), radius=0.4)
    bpy.ops.vg.next_break()
    bpy.ops.vg.measure_xyz(location=(0.3, 0.0, 0.0), radius=0.3)
    surface = core_surface(obj)
    first = surface.measure([0, 0, 0], 0.4)
    second = surface.measure([0.3, 0, 0], 0.3)

    attribute = obj.data.color_attributes[COLOUR_ATTRIBUTE]
    assert (attribute.domain, attribute.data_type) == ("POINT", "FLOAT_COLOR")
    assert obj.data.color_attributes.active_color_name == COLOUR_ATTRIBUTE
    n = len(obj.data.vertices)
    expected = expected_colours(
        n, [(first.indices, first.labels, 1), (second.indices, second.labels, 2)]
    )
    np.testing.assert_array_equal(colours(obj), expected)
    assert obj.vg.measurements[1].colors == "vermillion/sky blue"

    after = np.empty_like(before)
    obj.data.color_attributes["Scan colour"].data.foreach_get("color", after)
    np.testing.assert_array_equal(after, before)


def test_the_users_active_colour_attribute_is_switched_only_once(vg):
    obj = wedge_object(80.0)
    obj.data.color_attributes.new("Scan colour", "BYTE_COLOR", "CORNER")
    obj.data.color_attributes.active_color = obj.data.color_attributes["Scan colour"]
    bpy.ops.vg.measure_xyz(location=(0, 0, 0), radius=0.4)  # the first: show the sides
    assert obj.data.color_attributes.active_color_name == COLOUR_ATTRIBUTE
    obj.data.color_attributes.active_color = obj.data.color_attributes["Scan colour"]
    bpy.ops.vg.measure_xyz(location=(0.3, 0.0, 0.0), radius=0.3)
    bpy.ops.vg.repaint()
    bpy.ops.vg.delete_measurement()
    assert obj.data.color_attributes.active_color_name == "Scan colour"
    assert colours(obj) is not None  # still painted, just not forced into view


def test_viewports_show_attribute_colours(vg):
    wedge_object(90.0)
    bpy.ops.vg.measure_xyz(location=(0, 0, 0), radius=0.5)
    spaces = [
        space
        for window in bpy.context.window_manager.windows
        for area in window.screen.areas
        if area.type == "VIEW_3D"
        for space in area.spaces
        if space.type == "VIEW_3D" and space.shading.type == "SOLID"
    ]
    if not spaces:
        pytest.skip("this bpy session has no solid-shaded 3D viewport")
    assert all(space.shading.color_type == "VERTEX" for space in spaces)


@pytest.mark.parametrize(
    "scale", [(1.0, 1.0, 1.0), (2.5, 2.5, 2.5), (2.0, 0.5, 1.3)], ids=["unit", "uniform", "skewed"]
)
def test_measured_in_mesh_coordinates_under_any_transform(vg, scale):
    obj = wedge_object(60.0, location=(3.0, -1.0, 2.0), rotation=(0.3, 0.2, 1.1), scale=scale)
    vertex = int(np.argmin(np.linalg.norm(local_points(obj), axis=1)))  # on the crease
    cursor = world(local_points(obj)[vertex : vertex + 1], obj)[0]
    bpy.ops.vg.measure_xyz(location=cursor.tolist(), radius=0.6)  # world space, the default
    item = obj.vg.measurements[0]
    m = core_surface(obj).measure(local_points(obj)[vertex].astype(np.float64), 0.6)
    assert_same(item, m, requested=False)
    assert abs(m.angle - 60.0) < 1e-4  # the wedge as built, whatever the object's scale
    assert exact(item)["center"] == local_points(obj)[vertex].astype(np.float64).tolist()
    np.testing.assert_allclose(item.center_world, cursor, atol=1e-5)


def test_location_in_mesh_coordinates_is_taken_as_given(vg):
    obj = wedge_object(75.0, location=(1.0, 2.0, 3.0), rotation=(0.0, 0.4, 0.0))
    location = (0.013, -0.021, 0.004)
    bpy.ops.vg.measure_xyz(location=location, space="MESH", radius=0.5)
    typed = [float(str(np.float32(v))) for v in location]
    assert_same(obj.vg.measurements[0], core_surface(obj).measure(typed, 0.5))


def test_moving_rotating_and_scaling_keep_measurements_current(vg):
    obj = wedge_object(100.0, location=(0.5, 0.0, 0.0))
    bpy.ops.vg.measure_xyz(location=(0.5, 0.0, 0.0), radius=0.5)
    before = (exact(obj.vg.measurements[0]), colours(obj).copy())
    obj.location = (4.0, -3.0, 1.0)
    obj.rotation_euler = (0.7, -0.2, 2.0)
    obj.scale = (0.001, 0.001, 0.001)  # e.g. a scan in mm shown in metres
    bpy.context.view_layer.update()
    bpy.ops.vg.repaint()
    item = obj.vg.measurements[0]
    assert not item.stale
    assert (exact(item), colours(obj).tolist()) == (before[0], before[1].tolist())
    # Measuring again at the same vertex, now far away in world space, gives the same numbers.
    centre_world = world(np.array([exact(item)["center"]]), obj)[0]
    bpy.ops.vg.measure_xyz(location=centre_world.tolist(), radius=0.5)
    again = obj.vg.measurements[1]
    assert exact(again)["angle"] == exact(item)["angle"]
    assert exact(again)["center"] == exact(item)["center"]


def test_mirrored_object_keeps_outward_normals(vg):
    plain = wedge_object(110.0, "Plain")
    bpy.ops.vg.measure_xyz(location=(0, 0, 0), radius=0.5)
    mirrored = wedge_object(110.0, "Mirrored", scale=(-1.0, 1.0, 1.0))
    bpy.ops.vg.measure_xyz(location=(0, 0, 0), radius=0.5)
    a, b = plain.vg.measurements[0], mirrored.vg.measurements[0]
    assert abs(a.angle - b.angle) < 1e-9
    assert_same(b, core_surface(mirrored).measure([0, 0, 0], 0.5))


def test_deforming_modifier_is_applied(vg):
    obj = wedge_object(95.0)
    modifier = obj.modifiers.new("Displace", "DISPLACE")
    modifier.strength = 0.05
    bpy.ops.vg.measure_xyz(location=(0, 0, 0), radius=0.5)
    item = obj.vg.measurements[0]
    surface = evaluated_surface(obj)
    assert not np.array_equal(surface.points, local_points(obj))
    m = surface.measure([0, 0, 0], 0.5)
    assert_same(item, m)
    np.testing.assert_array_equal(
        colours(obj), expected_colours(len(obj.data.vertices), [(m.indices, m.labels, 1)])
    )


def test_subdivision_modifier_is_applied(vg):
    obj = wedge_object(70.0, n=20)
    bpy.ops.vg.measure_xyz(location=(0, 0, 0), radius=0.5)
    modifier = obj.modifiers.new("Subdivision", "SUBSURF")
    modifier.subdivision_type = "SIMPLE"
    modifier.levels = 1
    bpy.ops.vg.measure_xyz(location=(0, 0, 0), radius=0.5)
    plain, subdivided = obj.vg.measurements
    m = evaluated_surface(obj).measure([0, 0, 0], 0.5)
    assert_same(subdivided, m)
    assert subdivided.n_vertices > plain.n_vertices
    assert plain.stale  # the evaluated mesh changed under it
    # Every original vertex inside the patch is painted with one of the pair's colours.
    rgba = colours(obj)
    offsets = local_points(obj) - m.center
    inside = np.einsum("ij,ij->i", offsets, offsets) <= 0.5 * 0.5
    grey = np.asarray(vg.vg_addon.palette.neutral_linear(), dtype=np.float32)
    assert not (rgba[inside] == grey).all(axis=1).any()
    assert (rgba[~inside] == grey).all()


def test_geodesic_patch(vg):
    obj = wedge_object(85.0)
    bpy.ops.vg.measure_xyz(location=(0, 0, 0), radius=0.5, patch="geodesic")
    assert_same(obj.vg.measurements[0], core_surface(obj).measure([0, 0, 0], 0.5, patch="geodesic"))


def test_measure_on_object_keeps_float64_inputs_exactly(vg):
    """The pipeline function other tools call takes float64 as it is."""
    from vg_addon.synthetic_meshes import wedge

    shape = wedge(88.0, n=30, irregular=True)
    obj = mesh_object("Exact", shape.points, shape.triangles, location=(0.1, 0.2, 0.3))
    location = np.zeros(3) + 1e-9  # on the edge, between vertices, in mesh coordinates
    item = vg.bridge.measuring.measure_on_object(obj, location, 0.123456789, 1.5, note="hi")
    m = core_surface(obj).measure(location, 0.123456789, 1.5)
    assert_same(item, m)
    assert item.note == "hi"
    # The same point in world space: a pure translation moves it back exactly.
    in_world = location + np.array([0.1, 0.2, 0.3], dtype=np.float32).astype(np.float64)
    item = vg.bridge.measuring.measure_on_object(obj, in_world, 0.123456789, 1.5, space="world")
    assert exact(item)["center"] == m.center.tolist()
    assert exact(item)["angle"] == m.angle


# Reference meshes ---------------------------------------------------------------------------

TOP, OUTER = 4, 2


def reference_object(path):
    from vg_addon.formats.meshio import read_mesh

    mesh = read_mesh(path)
    return mesh, mesh_object(path.stem, mesh.points, mesh.triangles)


def test_half_annulus_right_angle(vg, shared_data):
    mesh, obj = reference_object(shared_data / "HalfAnnulus.ply")
    labels = np.load(shared_data / "HalfAnnulus_Labels.npz")["labels"]
    corner = labels[mesh.triangles]
    straddling = (corner == TOP).any(axis=1) & (corner == OUTER).any(axis=1)
    vertices = np.unique(mesh.triangles[straddling])
    middle = np.median(mesh.points[vertices], axis=0)
    centre = mesh.points[
        vertices[np.argmin(np.linalg.norm(mesh.points[vertices] - middle, axis=1))]
    ]
    item = vg.bridge.measuring.measure_on_object(obj, centre, 0.4)
    assert_same(item, core_surface(obj).measure(centre, 0.4))
    # The core on the file's float64 coordinates measures 94.727° here (the bevelled crease,
    # see tests/core/test_reference_meshes.py); Blender's float32 copy stays within 0.05° of it.
    assert abs(exact(item)["angle"] - 94.727) < 0.05


def test_intersecting_spheres_rim(vg, shared_data):
    _, obj = reference_object(shared_data / "IntersectingSpheres.ply")
    points = world(local_points(obj), obj)
    centred = points - points.mean(axis=0)
    axis = np.linalg.svd(centred, full_matrices=False)[2][2]
    radial = np.linalg.norm(centred - np.outer(centred @ axis, axis), axis=1)
    centre = points[np.argmax(radial)]
    radius = 0.06 * float(np.ptp(points, axis=0).max())
    item = vg.bridge.measuring.measure_on_object(obj, centre, radius)
    assert_same(item, core_surface(obj).measure(centre, radius))
    # Measured 67.956° here, 2.57° under the exact 70.53° (the rim's bevel; the core on the
    # file's float64 coordinates reads 68.092°, its rim vertex and radius differ a little).
    assert abs(exact(item)["angle"] - 67.956) < 0.05


def test_the_projects_half_annulus_and_lens_measure_as_the_core_does(vg):
    """The reference shapes the project makes (in every clone): the extension records what the
    core measures on Blender's float32 copy, and the readings are the geometry's (a bevelled
    right angle; the lens rim near its exact 70.53°)."""
    from vg_addon.reference_shapes import LENS_RIM_ANGLE, intersecting_spheres

    points, triangles, picks = half_annulus_with_edge_vertices()
    obj = mesh_object("HalfAnnulus", points, triangles)
    centre = points[picks[0]]  # top meets outer wall at 90°
    item = vg.bridge.measuring.measure_on_object(obj, centre, 0.4)
    assert_same(item, core_surface(obj).measure(centre, 0.4))
    assert abs(exact(item)["angle"] - 90.0) < 2.5  # the core reads +1.6° on float64 (bevel)
    lens = intersecting_spheres()
    obj = mesh_object("Lens", lens.points, lens.triangles)
    local = local_points(obj).astype(np.float64)
    centre = local[np.argmax(np.hypot(local[:, 1] - 1.0, local[:, 2] - 1.0))]
    radius = 0.06 * float(np.ptp(local, axis=0).max())
    item = vg.bridge.measuring.measure_on_object(obj, centre, radius)
    assert_same(item, core_surface(obj).measure(centre, radius))
    assert abs(exact(item)["angle"] - LENS_RIM_ANGLE) < 2.0


def test_sample_bone_scan(vg, shared_data):
    _, obj = reference_object(shared_data / "sample_mesh.ply")
    points = world(local_points(obj), obj)
    # The vertex farthest along the scan's long axis is on its broken end.
    centred = points - points.mean(axis=0)
    axis = np.linalg.svd(centred, full_matrices=False)[2][0]
    centre = points[np.argmax(centred @ axis)]
    radius = 0.05 * float(np.ptp(points, axis=0).max())
    item = vg.bridge.measuring.measure_on_object(obj, centre, radius)
    assert_same(item, core_surface(obj).measure(centre, radius))
    # No true angle is known for a real scan; what is recorded must hang together: the angle is
    # the one between the recorded side normals, and the sides share out the patch.
    numbers = exact(item)
    cosine = np.dot(numbers["normal_plus"], numbers["normal_minus"])
    assert numbers["angle"] == pytest.approx(180.0 - np.degrees(np.arccos(cosine)), abs=1e-9)
    assert item.n_plus + item.n_minus == item.n_vertices and min(item.n_plus, item.n_minus) >= 5


def cloud_object(name, points, edges=()):
    """A mesh object with vertices (and optionally edges) but no faces: a point cloud."""
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(np.asarray(points, dtype=np.float64).tolist(), list(edges), [])
    mesh.update()
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    bpy.context.view_layer.update()
    return obj


@pytest.mark.parametrize("with_edges", [False, True], ids=["vertices only", "edges only"])
def test_a_mesh_without_faces_is_measured_as_a_point_cloud(vg, with_edges):
    from vg_addon.synthetic_meshes import wedge

    shape = wedge(100.0, n=40)
    edges = [(int(a), int(b)) for a, b, _ in shape.triangles[:50]] if with_edges else ()
    obj = cloud_object("Cloud", shape.points, edges)
    assert len(obj.data.polygons) == 0 and len(obj.data.edges) == len(edges)
    bpy.ops.vg.measure_xyz(location=(0.0, 0.0, 0.0), radius=0.5)
    (item,) = obj.vg.measurements
    # The core on the same world points, without triangles (PCA normals), is the oracle.
    m = Surface(world(local_points(obj), obj)).measure([0.0, 0.0, 0.0], 0.5)
    assert_same(item, m)
    assert abs(item.angle - 100.0) < 1.0
    painted = colours(obj)
    assert painted is not None and painted.shape == (len(shape.points), 4)


def test_one_face_of_a_break_keeps_one_colour_along_it(vg):
    """Seven measurements along one crease, where Algorithm 1's binormal (a sign convention)
    turns over between centres, so that one face is the "+" side at some and the "−" side at
    others: each face keeps one colour of the break's pair at every measurement, the list and
    the CSV's Colors say which colour each "+" side got, and the numbers stay as measured."""
    from vg_addon.synthetic_meshes import wedge

    shape = wedge(90.0, n=40, irregular=True)
    c = np.sqrt(0.5)
    # The crease along (1, -1, 0) in mesh coordinates: the tangent's sign convention (its largest
    # component positive) then picks x at some centres and y at others.
    rotation = np.array([[c, c, 0.0], [-c, c, 0.0], [0.0, 0.0, 1.0]])
    obj = mesh_object("Ridge", shape.points @ rotation.T, shape.triangles)
    along, across = rotation @ [1.0, 0.0, 0.0], rotation @ [0.0, 1.0, 0.0]
    face = np.sign(np.round(local_points(obj).astype(np.float64) @ across, 6))  # 0: the crease
    pair = BREAK_PAIRS[0]
    palette = {name: linear_rgba(OKABE_ITO_HEX[name]).astype(np.float32) for name in pair}

    def names(rgba):
        return {
            next((n for n, c in palette.items() if np.allclose(colour, c, atol=1e-6)), "other")
            for colour in rgba
        }

    surface = core_surface(obj)
    seen = {1.0: set(), -1.0: set()}
    for x in np.linspace(-0.45, 0.45, 7):
        centre = x * along
        bpy.ops.vg.measure_xyz(location=tuple(centre), space="MESH", radius=0.3)
        item = obj.vg.measurements[-1]
        m = surface.measure(centre, 0.3)
        assert_same(item, m, requested=False)  # the numbers, "+" and "−" included, as measured
        painted = colours(obj)[m.indices]  # this measurement's patch, painted last
        for sign in seen:
            seen[sign] |= names(painted[face[m.indices] == sign])
    plus_faces = [np.sign(np.dot(exact(i)["normal_plus"], across)) for i in obj.vg.measurements]
    assert set(plus_faces) == {1.0, -1.0}, "the binormal never turned over: the test shows nothing"
    assert len(seen[1.0]) == 1 and len(seen[-1.0]) == 1, seen
    assert seen[1.0] | seen[-1.0] == set(pair)
    for item, plus_face in zip(obj.vg.measurements, plus_faces, strict=True):
        assert item.colors == f"{min(seen[plus_face])}/{min(seen[-plus_face])}"


def test_an_object_left_out_of_the_depsgraph_is_refused_not_measured_without_its_modifiers(
    vg, tmp_path
):
    """An object with Disable in Viewports on (or in an excluded collection) is not evaluated:
    Blender hands back the original, and its mesh was measured without its modifiers (a 100°
    wedge stretched to 134.48° by a hook read 100°, recorded as current). Oracle: the stretch's
    angle, 2·atan(2·tan 50°)."""
    stretched = math.degrees(2.0 * math.atan(2.0 * math.tan(math.radians(50.0))))

    def hooked(name):
        obj = wedge_object(100.0, name, irregular=False)
        handle = bpy.data.objects.new(name + " hook", None)
        bpy.context.scene.collection.objects.link(handle)
        handle.scale = (1.0, 2.0, 1.0)
        hook = obj.modifiers.new("Hook", "HOOK")
        hook.object = handle
        hook.vertex_indices_set(list(range(len(obj.data.vertices))))
        bpy.context.view_layer.objects.active = obj
        return obj

    shown = hooked("Shown")
    bpy.ops.vg.measure_xyz(location=(0, 0, 0), radius=0.5)
    assert abs(shown.vg.measurements[0].angle - stretched) < 0.01
    disabled = hooked("Disabled")
    disabled.hide_viewport = True
    with pytest.raises(RuntimeError, match="disabled in the viewports"):
        bpy.ops.vg.measure_xyz(location=(0, 0, 0), radius=0.5)
    assert len(disabled.vg.measurements) == 0
    # Measured while shown, then disabled: measuring again is refused too, though its geometry
    # was read and kept while it was shown.
    shown.hide_viewport = True
    bpy.context.view_layer.objects.active = shown
    with pytest.raises(RuntimeError, match="disabled in the viewports"):
        bpy.ops.vg.measure_xyz(location=(0, 0, 0), radius=0.5)
    assert len(shown.vg.measurements) == 1
    # Its measurement is exported as current, not stale (its mesh cannot be read to say), and
    # deleting it is refused: its colours could not be taken off the mesh.
    path = tmp_path / "disabled.csv"
    bpy.ops.vg.export_csv(filepath=str(path))
    assert [row.stale for row in csvio.read_measurements_csv(path)] == [False]
    with pytest.raises(RuntimeError, match="disabled in the viewports"):
        bpy.ops.vg.delete_measurement()
    assert len(shown.vg.measurements) == 1
