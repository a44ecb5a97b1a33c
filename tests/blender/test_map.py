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
    quads = [(j * 20 + i, j * 20 + i + 1, (j + 1) * 20 + i) for j in range(11) for i in range(19)]
    triangles = np.array(quads + [(a + 240, c + 240, b + 240) for a, b, c in quads])
    obj = mesh_object("Flake", points, triangles, rotation=(0.0, 0.5, 0.0))
    vg.bridge.measuring.measure_on_object(obj, points[30], 0.3)
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
    with pytest.raises(RuntimeError, match="not saved yet"):
        bpy.ops.vg.render_map(directory="//maps")


def test_the_operator_writes_the_map(vg, tmp_path):
    obj = measured_annulus(vg)
    folder = tmp_path / "maps"
    result = bpy.ops.vg.render_map(
        directory=str(folder), views="FLAKE", width=120, height=90, samples=1
    )
    assert result == {"FINISHED"}
    assert sorted(p.name for p in folder.iterdir()) == [
        f"{obj.name}_map.png",
        f"{obj.name}_map_face_A.png",
        f"{obj.name}_map_face_B.png",
    ]
    assert pixels_of(folder / f"{obj.name}_map.png").shape == (90, 240, 4)
