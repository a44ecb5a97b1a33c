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
