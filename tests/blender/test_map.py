"""The measurement map, rendered headless with Cycles: pictures per view, the contact sheet made
of exactly those pictures, labels where the centres are seen, nothing left behind."""

from pathlib import Path

import bpy
import numpy as np
import pytest
from bpy_extras.object_utils import world_to_camera_view
from bpy_helpers import exact, half_annulus_with_edge_vertices, mesh_object, wedge_object
from mathutils import Vector

SIZE = (200, 150)


def pixels_of(path: Path) -> np.ndarray:
    """RGBA of a PNG, rows from the top, as Blender reads it."""
    image = bpy.data.images.load(str(path), check_existing=False)
    try:
        width, height = image.size
        rgba = np.empty(width * height * 4, dtype=np.float32)
        image.pixels.foreach_get(rgba)
    finally:
        bpy.data.images.remove(image)
    return rgba.reshape(height, width, 4)[::-1]


def block_counts() -> dict:
    return {
        name: len(getattr(bpy.data, name))
        for name in ("objects", "meshes", "curves", "materials", "cameras", "lights", "scenes")
    }


def colourful(rgba: np.ndarray) -> int:
    """Pixels with clear colour (the painted sides; the grey mesh, the sky and the black and
    white labels have none)."""
    rgb = rgba[..., :3]
    return int(((rgb.max(axis=-1) - rgb.min(axis=-1)) > 0.25).sum())


def measured_annulus(vg):
    points, triangles, picks = half_annulus_with_edge_vertices()
    obj = mesh_object("HalfAnnulus", points, triangles, location=(1.0, 2.0, 3.0))
    for vertex in picks:
        vg.bridge.measuring.measure_on_object(obj, points[vertex], 0.3)
    return obj


def test_six_view_map_and_its_contact_sheet(vg, tmp_path):
    obj = measured_annulus(vg)
    before = block_counts()
    job = vg.bridge.measurement_map.MapJob(obj, tmp_path, size=SIZE, samples=1)
    try:
        seen = 0
        while not job.done:
            path = job.render_next()
            rgba = pixels_of(path)
            assert rgba.shape == (SIZE[1], SIZE[0], 4)
            # Every label drawn is a white dot on the picture where its centre projects.
            scene, camera = job._scene, job._camera
            for label in job.labels:
                if not job._visible(label, -np.array(camera.matrix_world.col[2][:3])):
                    continue
                seen += 1
                u, v, _ = world_to_camera_view(scene, camera, Vector(label.position))
                x, y = int(u * SIZE[0]), int((1.0 - v) * SIZE[1])
                assert (rgba[y, x, :3] > 0.9).all(), (path.name, label.text)
        assert seen >= 3  # every measurement is labelled in some view
        sheet = job.finish()
    finally:
        job.close()
    assert block_counts() == before  # the throwaway scene is gone
    names = sorted(p.name for p in tmp_path.iterdir())
    views = ("back", "bottom", "front", "left", "right", "top")
    assert names == ["HalfAnnulus_map.png", *(f"HalfAnnulus_map_{v}.png" for v in views)]
    # The sheet is the six pictures, row by row from the top left, and nothing else.
    tiles = pixels_of(sheet)
    assert tiles.shape == (2 * SIZE[1], 3 * SIZE[0], 4)
    for index, path in enumerate(job.written):
        row, column = divmod(index, 3)
        tile = tiles[row * SIZE[1] : (row + 1) * SIZE[1], column * SIZE[0] : (column + 1) * SIZE[0]]
        np.testing.assert_array_equal(tile[..., :3], pixels_of(path)[..., :3])
    assert colourful(tiles) > 200  # the sides are painted


@pytest.mark.parametrize("size", [(150, 300), (300, 150)], ids=["portrait", "landscape"])
def test_a_map_of_any_shape_frames_the_object_and_draws_each_label_inside(vg, tmp_path, size):
    """A picture taller than wide once cut the object off at both sides: Blender fitted the
    orthographic scale to the height, the map's framing to the width. A label the plan counted
    as drawn then fell outside the picture, so no close-up or "not shown" line made up for it.
    Oracle: Blender's own projection of the object's corners and of each label drawn."""
    width, height = size
    obj = measured_annulus(vg)
    corners = [obj.matrix_world @ Vector(c) for c in obj.bound_box]
    job = vg.bridge.measurement_map.MapJob(obj, tmp_path, size=size, samples=1)
    drawn = set()
    try:
        while not job.done:
            step = len(job.written)
            path = job.render_next()
            if step >= 6:
                continue  # close-ups frame a part of the object on purpose
            scene, camera = job._scene, job._camera
            uv = np.array([world_to_camera_view(scene, camera, c)[:2] for c in corners])
            assert uv.min() >= 0.0 and uv.max() <= 1.0, (path.name, uv.min(), uv.max())
            rgba = pixels_of(path)
            for index, _side in job.placements[step]:
                label = job.labels[index]
                u, v, _ = world_to_camera_view(scene, camera, Vector(label.position))
                assert 0.0 <= u < 1.0 and 0.0 <= v < 1.0, (path.name, label.text, u, v)
                x, y = int(u * width), int((1.0 - v) * height)
                assert (rgba[y, x, :3] > 0.9).all(), (path.name, label.text)
                drawn.add(label.number)
    finally:
        job.abort()
        job.close()
    assert drawn | {label.number for label in job.not_shown} == {
        item.number for item in obj.vg.measurements
    }


def test_an_unmeasured_side_shows_no_colour(vg, tmp_path):
    obj = wedge_object(90.0)
    bpy.ops.vg.measure_xyz(location=(0.0, 0.0, 0.0), radius=0.3)
    assert exact(obj.vg.measurements[0])["angle"] == pytest.approx(90.0, abs=1e-6)
    bpy.ops.vg.clear_measurements()
    assert not bpy.ops.vg.render_map.poll()  # nothing measured: greyed out
    with pytest.raises(vg.vg_addon.GoniometerError, match="Unknown map views 'SOME'"):
        vg.bridge.measurement_map.MapJob(obj, tmp_path, views="SOME", size=SIZE)
    views, sheet = vg.bridge.measurement_map.render_map(obj, tmp_path, size=SIZE, samples=1)
    assert len(views) == 6 and colourful(pixels_of(sheet)) == 0


def test_flake_map_has_two_faces(vg, tmp_path):
    rng = np.random.default_rng(2)
    grid = np.stack(np.meshgrid(np.linspace(-1, 1, 20), np.linspace(-0.6, 0.6, 12)), -1)
    top = np.column_stack([grid.reshape(-1, 2), 0.05 + 0.01 * rng.random(240)])
    points = np.vstack([top, top * [1, 1, -1]])
    cells = [(j * 20 + i, j * 20 + i + 1, (j + 1) * 20 + i) for j in range(11) for i in range(19)]
    quads = cells + [(b, c + 1, c) for a, b, c in cells]  # each cell's two triangles
    triangles = np.array(quads + [(a + 240, c + 240, b + 240) for a, b, c in quads])
    obj = mesh_object("Flake", points, triangles, rotation=(0.0, 0.5, 0.0))
    # Two near-parallel sheets hold no edge: the default rule refuses the patch (its planes meet
    # far outside it), and the map needs only a measurement, which the oriented rule gives in
    # the middle of a sheet (by the margin, where the two sheets' rims run side by side and are
    # not joined, the patch is refused: the margin's edge would be cut away).
    vg.bridge.measuring.measure_on_object(obj, points[130], 0.3, rule="oriented")
    views, sheet = vg.bridge.measurement_map.render_map(
        obj, tmp_path, views="FLAKE", size=SIZE, samples=1
    )
    assert [p.name for p in views] == ["Flake_map_face_A.png", "Flake_map_face_B.png"]
    assert pixels_of(sheet).shape == (SIZE[1], 2 * SIZE[0], 4)


def test_a_cancelled_map_keeps_no_picture(vg, tmp_path):
    obj = measured_annulus(vg)
    before = block_counts()
    calls = []

    def progress(done, total):
        calls.append((done, total))
        return done < 2  # stop before the third view

    with pytest.raises(vg.vg_addon.GoniometerError, match="cancelled: no picture was kept"):
        vg.bridge.measurement_map.render_map(obj, tmp_path, size=SIZE, samples=1, progress=progress)
    assert calls == [(0, 6), (1, 6), (2, 6)]
    assert list(tmp_path.iterdir()) == []
    assert block_counts() == before


def test_a_map_cancelled_or_failed_half_way_keeps_an_earlier_map_as_it_was(vg, tmp_path):
    """Rendering a map again into its folder: the earlier pictures are replaced only when the new
    map is complete, so a stop half-way loses nothing (the same files, untouched: same bytes and
    inodes); a completed map replaces every one of them (new inodes)."""
    obj = measured_annulus(vg)
    render_map = vg.bridge.measurement_map.render_map

    def files():
        return {p.name: (p.read_bytes(), p.stat().st_ino) for p in tmp_path.iterdir()}

    render_map(obj, tmp_path, size=SIZE, samples=1)
    earlier = files()
    assert len(earlier) == 7
    with pytest.raises(vg.vg_addon.GoniometerError, match="cancelled"):
        render_map(obj, tmp_path, size=SIZE, samples=1, progress=lambda done, total: done < 3)
    assert files() == earlier
    job = vg.bridge.measurement_map.MapJob(obj, tmp_path, size=SIZE, samples=1)
    try:
        job.render_next()
        job.render_next()
        job.abort()  # as the operator and the batch do when a view fails
    finally:
        job.close()
    assert files() == earlier
    render_map(obj, tmp_path, size=SIZE, samples=1)
    now = files()
    assert sorted(now) == sorted(earlier)  # the same names, no leftovers
    assert all(now[name][1] != earlier[name][1] for name in now)  # each file replaced


def test_the_operator_refuses_a_relative_folder_of_an_unsaved_file(vg):
    measured_annulus(vg)
    with pytest.raises(RuntimeError, match="has not been saved yet"):
        bpy.ops.vg.render_map(directory="//maps")


def test_the_operator_writes_the_map(vg, tmp_path):
    obj = measured_annulus(vg)
    folder = tmp_path / "maps"
    result = bpy.ops.vg.render_map(
        directory=str(folder), views="FLAKE", width=120, height=90, samples=1
    )
    assert result == {"FINISHED"}
    # The two faces have no room for measurement 1's label: it gets a close-up.
    assert sorted(p.name for p in folder.iterdir()) == [
        f"{obj.name}_map.png",
        f"{obj.name}_map_close-up_1.png",
        f"{obj.name}_map_face_A.png",
        f"{obj.name}_map_face_B.png",
    ]
    assert pixels_of(folder / f"{obj.name}_map.png").shape == (90, 360, 4)


def test_a_map_of_an_object_whose_colours_were_removed_is_refused_until_they_are_back(vg, tmp_path):
    """The map copies the mesh with its "VG Sides" colours. With the attribute removed (the
    Color Attributes list's minus button), it once rendered every view with no sides and
    reported success. Oracle: the pixels with clear colour in the written sheet."""
    obj = measured_annulus(vg)
    obj.data.color_attributes.remove(obj.data.color_attributes["VG Sides"])
    folder = tmp_path / "maps"
    with pytest.raises(RuntimeError, match="Update Colours"):
        bpy.ops.vg.render_map(directory=str(folder), width=120, height=90, samples=1)
    assert not folder.exists()  # nothing written, no folder left
    assert bpy.ops.vg.repaint() == {"FINISHED"}
    assert bpy.ops.vg.render_map(directory=str(folder), width=120, height=90, samples=1) == {
        "FINISHED"
    }
    assert colourful(pixels_of(folder / f"{obj.name}_map.png")) > 100


def _frame_to(direction):
    """A rotation taking +z to ``direction`` (columns: the new x, y, z)."""
    z = np.asarray(direction, dtype=np.float64) / np.linalg.norm(direction)
    x = np.cross([0.0, 0.0, 1.0], z) if abs(z[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def _quad(a, b, c, d, start):
    return [(start + a, start + b, start + c), (start + a, start + c, start + d)]


def hidden_measurements_mesh():
    """Three ridges (wedges whose outward normal is the local +z): one open to the sky at
    ``OPEN``; one at the bottom of a square tube along (1, 1, 1) over a floor plate at ``PIT``,
    which no axis-aligned view can see into; one shut in a closed box at ``SHUT``."""
    from vg_addon.synthetic_meshes import wedge

    points, triangles = [], []

    def add(vertices, faces):
        start = sum(len(p) for p in points)
        points.append(np.asarray(vertices, dtype=np.float64))
        triangles.extend((start + a, start + b, start + c) for a, b, c in faces)

    ridge = wedge(120.0, half_width=0.3, depth=0.3, n=12)
    for centre, rotation in ((OPEN, np.eye(3)), (PIT, _frame_to(DIAGONAL)), (SHUT, np.eye(3))):
        add(ridge.points @ rotation.T + centre, ridge.triangles)
    rotation = _frame_to(DIAGONAL)
    u, v, d = rotation.T
    plate = [
        PIT + d * -0.4 + 3.0 * (su * u + sv * v) for su, sv in ((-1, -1), (1, -1), (1, 1), (-1, 1))
    ]
    add(plate, _quad(0, 1, 2, 3, 0))
    w = 0.45
    for side, across in ((u, v), (-u, v), (v, u), (-v, u)):
        wall = [
            PIT + w * side + a * across * w + h * d
            for a, h in ((-1, -0.4), (1, -0.4), (1, 3.0), (-1, 3.0))
        ]
        add(wall, _quad(0, 1, 2, 3, 0))
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * 0.6
    box = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    add(corners + SHUT, [t for q in box for t in _quad(*q, 0)])
    return np.vstack(points), np.array(triangles)


OPEN, PIT, SHUT = np.array([4.0, 0.0, 0.0]), np.zeros(3), np.array([0.0, 0.0, -4.0])
DIAGONAL = np.array([1.0, 1.0, 1.0]) / np.sqrt(3.0)


def first_hit(points, triangles, origin, direction) -> float:
    """The distance along ``direction`` from ``origin`` to the first triangle it meets (inf if
    none): Moller-Trumbore over every triangle, in NumPy, not Blender's ray cast."""
    a, b, c = (points[triangles[:, k]] for k in range(3))
    e1, e2 = b - a, c - a
    p = np.cross(direction, e2)
    det = np.einsum("ij,ij->i", e1, p)
    ok = np.abs(det) > 1e-12
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    s = origin - a
    u = np.einsum("ij,ij->i", s, p) * inv
    q = np.cross(s, e1)
    v = (q @ direction) * inv
    t = np.einsum("ij,ij->i", e2, q) * inv
    hit = ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 0)
    return float(t[hit].min()) if hit.any() else float("inf")


def seen_along(points, triangles, centre, look) -> bool:
    """Whether a ray along ``look`` from far outside first meets the mesh at ``centre``."""
    far = 50.0
    return abs(first_hit(points, triangles, centre - far * look, look) - far) < 0.02


def rendered_labels(job, points, triangles, centres):
    """Render every view of ``job``; return the measurement numbers whose label a view drew
    while a NumPy ray along that camera's axis reaches their centre first, the text of the "not
    shown" picture, and the fonts the labels were set in."""
    appears, listed, fonts = set(), "", set()
    try:
        while not job.done:
            job.render_next()
            camera = job._camera.matrix_world
            look = -np.array(camera.col[2][:3])
            texts = [o.data for o in job._scene.objects if o.type == "FONT"]
            fonts.update(t.font.name for t in texts)
            bodies = {t.body for t in texts}
            if job.written[-1].name.endswith("_map_not_shown.png"):
                listed = " ".join(bodies)
            for number, centre in centres.items():
                label = any(b.startswith(f"{number}: ") for b in bodies)
                if label and seen_along(points, triangles, centre, look):
                    appears.add(number)
        job.finish()
    finally:
        job.close()
    return appears, listed, fonts


def test_every_measurement_appears_in_some_view_or_is_listed(vg, tmp_path):
    """Issue 20, item 5: a ridge at the bottom of a tube no axis-aligned view can see into gets a
    view of its own, and one shut in a closed box is listed on the contact sheet. The oracle is
    a NumPy ray cast from each rendered camera along its axis to each measured centre, and the
    label text objects in the scene that camera rendered."""
    points, triangles = hidden_measurements_mesh()
    obj = mesh_object("Hidden", points, triangles)
    for at in (OPEN, PIT, SHUT):
        vg.bridge.measuring.measure_on_object(obj, at, 0.2)
    centres = {item.number: np.asarray(exact(item)["center"]) for item in obj.vg.measurements}
    assert len(centres) == 3
    pit = next(n for n, c in centres.items() if np.linalg.norm(c - PIT) < 0.1)
    shut = next(n for n, c in centres.items() if np.linalg.norm(c - SHUT) < 0.1)
    axes = [np.array(look) for _name, look, _up in vg.vg_addon.workflow.labels.SIX_VIEWS]
    assert not any(seen_along(points, triangles, centres[pit], look) for look in axes)
    assert not any(
        seen_along(points, triangles, centres[shut], look)
        for look in vg.vg_addon.workflow.labels.looks_at(np.array([0.3, -0.2, 1.0]))
    )
    job = vg.bridge.measurement_map.MapJob(obj, tmp_path, size=(320, 240), samples=4)
    appears, listed, fonts = rendered_labels(job, points, triangles, centres)
    assert appears == set(centres) - {shut}
    assert f"#{shut}" in listed and f"#{pit}" not in listed
    assert [p.name for p in job.written][6:] == [
        f"Hidden_map_measurement_{pit}.png",
        "Hidden_map_not_shown.png",
    ]
    assert {f.rsplit(" ", 1)[0] for f in fonts} == {
        "DejaVu Sans Mono"
    }  # its "1" has a flag and a foot, unlike "I"
    sheet = pixels_of(job.sheet)
    assert sheet.shape == (3 * 240, 3 * 320, 4)  # eight pictures, three to a row


def test_labels_crowded_out_of_the_six_views_get_close_ups(vg, tmp_path):
    """Twelve readings 0.06 apart along one crease: the six views have room for a few labels;
    close-ups (the view that sees them, 4 or 12 times nearer) draw the others."""
    obj = wedge_object(100.0, "Crowded", n=40)
    for x in np.arange(-0.33, 0.34, 0.06):
        bpy.ops.vg.measure_xyz(location=(float(x), 0.0, 0.0), radius=0.2)
    points = np.array([v.co for v in obj.data.vertices], dtype=np.float64)
    triangles = np.array([p.vertices[:] for p in obj.data.polygons])
    centres = {item.number: np.asarray(exact(item)["center"]) for item in obj.vg.measurements}
    assert len(centres) == 12
    job = vg.bridge.measurement_map.MapJob(obj, tmp_path, size=(320, 240), samples=1)
    six = {i for placed in job.placements[:6] for i, _side in placed}
    assert len(six) < 12  # the test's point: the standard views leave some out
    appears, listed, _fonts = rendered_labels(job, points, triangles, centres)
    assert appears == set(centres) and listed == ""
    names = [p.name for p in job.written]
    # A close-up per label left out at most (labels go left or right of their centre, so a row
    # of centres 0.06 apart still fits about two to a picture: here 9 close-ups).
    assert all("close-up" in n for n in names[6:]) and 6 < len(names) <= 6 + 12 - len(six), names


def test_an_edges_inner_stations_get_no_close_ups(vg, tmp_path):
    """An edge profile's stations crowd along its line: the map makes extra views only for the
    first and last station of each edge (the others are labelled where the six views have room),
    while the same readings taken as single measurements each get one when crowded out. The
    oracle for the ends is the stations' stored arc lengths."""
    obj = wedge_object(100.0, "Edge", n=40)
    vg.bridge.edges.measure_edge_on_object(obj, [(-0.6, 0.0, 0.0), (0.6, 0.0, 0.0)], 0.06, 0.2)
    stations = sorted((exact(item)["arc_length"], item.number) for item in obj.vg.measurements)
    assert len(stations) >= 15
    ends = {stations[0][1], stations[-1][1]}
    job = vg.bridge.measurement_map.MapJob(obj, tmp_path, size=(320, 240), samples=1)
    try:
        extra = [name for name, _look, _up in job.views[6:]]
        drawn = {job.labels[i].number for placed in job.placements for i, _side in placed}
        crowded = len(stations) - len(
            {job.labels[i].number for placed in job.placements[:6] for i, _side in placed}
        )
    finally:
        job.close()
    assert crowded > 2  # the test's point: the six views leave more than the ends out
    assert all(int(name.rsplit(" ", 1)[1]) in ends for name in extra), extra
    assert ends <= drawn and not job.not_shown

    single = wedge_object(100.0, "Single", n=40)
    for _arc, number in stations:
        item = next(i for i in obj.vg.measurements if i.number == number)
        vg.bridge.measuring.measure_on_object(single, exact(item)["center"], 0.2)
    plain = vg.bridge.measurement_map.MapJob(single, tmp_path / "plain", size=(320, 240), samples=1)
    try:
        assert len(plain.views) > len(job.views)  # each crowded reading gets a close-up
    finally:
        plain.close()


def test_only_the_first_edges_ends_get_views_of_their_own(vg, tmp_path):
    """Issue 22, item 3: the close-ups for edges' ends are capped (``edge_ends``, the batch's
    ``--render-edge-ends``): three crowded edges along one crease, and only the ends of the first
    ``edge_ends`` edges by number get extra views; with 0 none does, and nothing is listed as not
    shown (the stations stay labelled where the six views have room). The oracle for the ends is
    each edge's stations' stored arc lengths."""
    obj = wedge_object(100.0, "Edges", n=40)
    for start, end in ((-0.7, -0.25), (-0.2, 0.25), (0.3, 0.75)):
        vg.bridge.edges.measure_edge_on_object(obj, [(start, 0.0, 0.0), (end, 0.0, 0.0)], 0.06, 0.2)
    by_edge: dict[int, list] = {}
    for item in obj.vg.measurements:
        by_edge.setdefault(item.edge_number, []).append((exact(item)["arc_length"], item.number))
    assert sorted(by_edge) == [1, 2, 3]
    ends = {edge: {min(s)[1], max(s)[1]} for edge, s in by_edge.items()}

    def extra_views(edge_ends):
        job = vg.bridge.measurement_map.MapJob(
            obj, tmp_path / str(edge_ends), size=(320, 240), samples=1, edge_ends=edge_ends
        )
        try:
            assert not job.not_shown
            return [int(name.rsplit(" ", 1)[1]) for name, _look, _up in job.views[6:]]
        finally:
            job.close()

    uncapped = extra_views(3)
    # The test's point: more than the first edge's ends are crowded out of the six views.
    assert set(uncapped) - ends[1], uncapped
    assert set(uncapped) <= ends[1] | ends[2] | ends[3]
    first = extra_views(1)
    assert first and set(first) <= ends[1], first
    assert extra_views(0) == []
    assert extra_views(vg.bridge.map_edges.EDGE_ENDS) == uncapped
    for bad in (-1, True, 2.0):
        with pytest.raises(vg.vg_addon.GoniometerError, match="0 or more"):
            vg.bridge.measurement_map.MapJob(obj, tmp_path / "bad", edge_ends=bad)


def test_an_edge_whose_stations_are_all_stale_draws_no_line(vg, tmp_path):
    """After the mesh is edited, the stations are stale and get no label; the edges' lines once
    stayed on the map where the edges used to be. Oracle: the curve objects in the map's scene,
    named by the edge numbers, before and after the edit."""
    obj = wedge_object(100.0, "Edge", n=40)
    first = vg.bridge.edges.measure_edge_on_object(
        obj, [(-0.6, 0.0, 0.0), (0.0, 0.0, 0.0)], 0.1, 0.2
    )
    second = vg.bridge.edges.measure_edge_on_object(
        obj, [(0.3, 0.0, 0.0), (0.8, 0.0, 0.0)], 0.1, 0.2
    )

    def lines():
        job = vg.bridge.measurement_map.MapJob(obj, tmp_path, size=(64, 48), samples=1)
        try:
            return sorted(o.name for o in job._scene.objects if o.type == "CURVE")
        finally:
            job.close()

    assert lines() == [f"VG Map edge {first.number}", f"VG Map edge {second.number}"]
    positions = np.empty(len(obj.data.vertices) * 3)
    obj.data.vertices.foreach_get("co", positions)
    positions = positions.reshape(-1, 3)
    positions[positions[:, 0] < -0.5, 2] += 0.5  # an edit: every record's geometry is gone
    obj.data.vertices.foreach_set("co", positions.ravel())
    obj.data.update()
    vg.bridge.measuring.repaint(obj)
    assert all(item.stale for item in obj.vg.measurements)
    assert lines() == []


def test_the_maps_of_two_objects_whose_names_make_one_file_name_keep_apart(vg, tmp_path):
    """ "A 1" and "A_1" both made the file name "A_1", so one object's map replaced the
    other's pictures in a shared folder. The object whose name is already a file name keeps
    it; the other takes "A_1-2". Oracle: the files written and their pixels."""
    bpy.ops.wm.read_homefile(use_empty=True)
    maps = {}
    for name in ("A 1", "A_1"):
        obj = wedge_object(90.0, name, n=20)
        vg.bridge.measuring.measure_on_object(obj, (0.0, 0.0, 0.0), 0.3)
    for name in ("A_1", "A 1"):
        _, sheet = vg.bridge.measurement_map.render_map(
            bpy.data.objects[name], tmp_path, size=SIZE, samples=1
        )
        maps[name] = (sheet.name, sheet.read_bytes())
    assert maps["A_1"][0] == "A_1_map.png" and maps["A 1"][0] == "A_1-2_map.png"
    for name, (file_name, data) in maps.items():
        assert (tmp_path / file_name).read_bytes() == data, name  # neither replaced
    assert len(list(tmp_path.glob("A_1_map_*.png"))) == len(list(tmp_path.glob("A_1-2_map_*.png")))


def test_an_object_named_later_like_a_mapped_one_never_writes_over_its_map(vg, tmp_path):
    """ "A 1" made its map as "A_1"; an object "A_1" made later (after a save and reload)
    took the same file name and wrote over "A 1"'s pictures. The stem a map was written under
    is kept in the .blend and stays its object's. Oracle: the files and their bytes."""
    bpy.ops.wm.read_homefile(use_empty=True)
    first = wedge_object(90.0, "A 1", n=20)
    vg.bridge.measuring.measure_on_object(first, (0.0, 0.0, 0.0), 0.3)
    views, sheet = vg.bridge.measurement_map.render_map(first, tmp_path, size=SIZE, samples=1)
    assert sheet.name == "A_1_map.png"
    pictures = {path: path.read_bytes() for path in [*views, sheet]}
    blend = tmp_path / "study.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(blend))
    bpy.ops.wm.open_mainfile(filepath=str(blend))
    later = wedge_object(60.0, "A_1", n=20)
    vg.bridge.measuring.measure_on_object(later, (0.0, 0.0, 0.0), 0.3)
    _, sheet = vg.bridge.measurement_map.render_map(later, tmp_path, size=SIZE, samples=1)
    assert sheet.name == "A_1-2_map.png"
    assert {path: path.read_bytes() for path in pictures} == pictures
    _, sheet = vg.bridge.measurement_map.render_map(
        bpy.data.objects["A 1"], tmp_path, size=SIZE, samples=1
    )
    assert sheet.name == "A_1_map.png"


@pytest.mark.parametrize("how", ["renamed", "copied"])
def test_a_renamed_or_copied_objects_map_leaves_the_others_pictures(vg, tmp_path, how):
    """ "A" mapped, then renamed "B" and a new "A" made; or "A" mapped and copied (the copy
    carries its record). The new "A" wrote over the pictures "B" made as "A", and "B"'s next
    map deleted the new "A"'s; a copy's map deleted its original's. Oracle: the bytes of the
    pictures each map wrote, read again after the other object's map."""
    bpy.ops.wm.read_homefile(use_empty=True)
    first = wedge_object(90.0, "A", n=20)
    vg.bridge.measuring.measure_on_object(first, (0.0, 0.0, 0.0), 0.3)
    views, sheet = vg.bridge.measurement_map.render_map(first, tmp_path, size=SIZE, samples=1)
    kept = {path: path.read_bytes() for path in [*views, sheet]}
    if how == "renamed":
        first.name = "B"
        other = wedge_object(60.0, "A", n=20)
        vg.bridge.measuring.measure_on_object(other, (0.0, 0.0, 0.0), 0.3)
    else:
        other = first.copy()
        other.data = first.data.copy()
        bpy.context.scene.collection.objects.link(other)
    views, sheet = vg.bridge.measurement_map.render_map(other, tmp_path, size=SIZE, samples=1)
    assert sheet.name == ("A-2_map.png" if how == "renamed" else "A.001_map.png")
    assert {path: path.read_bytes() for path in kept} == kept  # the first's, as they were
    if how == "copied":
        kept = {}  # the original's own map, made again next, may rewrite them
    kept.update({path: path.read_bytes() for path in [*views, sheet]})
    vg.bridge.measurement_map.render_map(first, tmp_path, size=SIZE, samples=1)
    assert {path: path.read_bytes() if path.exists() else None for path in kept} == kept


def test_a_map_made_again_leaves_no_close_up_of_the_map_before(vg, tmp_path):
    """A close-up (and the "not shown" list) of an earlier map stayed in the folder beside a
    new map that no longer had them, reading as part of it. Oracle: the files of each map."""
    points, triangles = hidden_measurements_mesh()
    obj = mesh_object("Hidden", points, triangles)
    for at in (OPEN, PIT, SHUT):
        vg.bridge.measuring.measure_on_object(obj, at, 0.2)
    other = tmp_path / "Hidden_map_measurement_2.png.keep"  # not a picture of this map
    other.write_bytes(b"mine")
    # Named like a close-up of this object, but not written by its map (another object's of the
    # same file name, made before a rename): kept.
    alike = tmp_path / "Hidden_map_measurement_99.png"
    alike.write_bytes(b"another object's")
    first, _ = vg.bridge.measurement_map.render_map(obj, tmp_path, size=SIZE, samples=1)
    assert len(first) == 8
    obj.vg.active_index = len(obj.vg.measurements) - 1
    while len(obj.vg.measurements) > 1:  # keep the one the six views see
        bpy.ops.vg.delete_measurement()
    again, sheet = vg.bridge.measurement_map.render_map(obj, tmp_path, size=SIZE, samples=1)
    assert len(again) == 6
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        [sheet.name, other.name, alike.name, *(p.name for p in again)]
    )


@pytest.mark.parametrize("how", ["object", "collection"])
def test_a_map_of_an_object_disabled_in_the_viewports_says_so(vg, tmp_path, how):
    """An object disabled in the viewports (its own monitor icon, or its collection's) has no
    evaluated mesh: the map failed with Blender's "has no evaluated mesh data". Oracle: the
    object's Outliner state and the folder left empty."""
    bpy.ops.wm.read_homefile(use_empty=True)
    obj = wedge_object(90.0, "Hidden", n=20)
    vg.bridge.measuring.measure_on_object(obj, (0.0, 0.0, 0.0), 0.3)
    if how == "object":
        obj.hide_viewport = True
    else:
        shelf = bpy.data.collections.new("Shelf")
        bpy.context.scene.collection.children.link(shelf)
        shelf.objects.link(obj)
        bpy.context.scene.collection.objects.unlink(obj)
        bpy.context.view_layer.layer_collection.children["Shelf"].exclude = True
    with pytest.raises(vg.vg_addon.GoniometerError, match="disabled in the viewports"):
        vg.bridge.measurement_map.render_map(obj, tmp_path / "map", size=SIZE, samples=1)
    assert not (tmp_path / "map").exists()
    obj.hide_viewport = False
    if how == "collection":
        bpy.context.view_layer.layer_collection.children["Shelf"].exclude = False
    views, _ = vg.bridge.measurement_map.render_map(obj, tmp_path / "map", size=SIZE, samples=1)
    assert len(views) == 6
