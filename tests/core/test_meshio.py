"""The mesh reader registry: a file found by its extension, missing files, empty files and
unknown formats refused with the name."""

from mesh_files import expect_error, write_text


def test_missing_file_and_folder(tmp_path):
    expect_error(tmp_path / "nowhere.ply", "not found")
    folder = tmp_path / "folder.ply"
    folder.mkdir()
    expect_error(folder, "folder")


def test_empty_file_and_unknown_format(tmp_path):
    for name in ("empty.ply", "empty.obj", "empty.stl"):
        expect_error(write_text(tmp_path / name, ""), "empty")
    expect_error(write_text(tmp_path / "mesh.xyz", "1 2 3\n"), "unknown mesh format", ".ply")
    expect_error(write_text(tmp_path / "noextension", "ply\n"), "unknown mesh format")


def test_polygons_are_kept_as_the_file_gives_them_beside_their_fans(tmp_path):
    """A pentagon and a triangle: ``triangles`` holds the pentagon's fan from its first corner
    (the core's surface), ``polygons`` the faces as written, so that a Blender mesh made from the
    file fills the pentagon as Blender's importer does. A face of two corners is no face. An
    all-triangle file has no ``polygons``."""
    import numpy as np

    from vg_addon.formats import meshio

    vertices = "v 0 0 0\nv 1 0 0\nv 1.5 1 0\nv 0.5 1.5 0\nv -0.5 1 0\nv 0 -1 0\n"
    mesh = meshio.read_mesh(
        write_text(tmp_path / "pentagon.obj", vertices + "f 1 2 3 4 5\nf 1 6\nf 1 6 2\n")
    )
    np.testing.assert_array_equal(mesh.triangles, [[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 5, 1]])
    corners, sizes = mesh.polygons
    np.testing.assert_array_equal(corners, [0, 1, 2, 3, 4, 0, 5, 1])
    np.testing.assert_array_equal(sizes, [5, 3])
    assert (
        meshio.read_mesh(write_text(tmp_path / "triangle.obj", vertices + "f 1 6 2\n")).polygons
        is None
    )
