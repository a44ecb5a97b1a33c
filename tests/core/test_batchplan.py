"""Planning batch runs: mesh inputs, points to tasks, mesh-name matching, sharding."""

import pytest
from hypothesis import given
from hypothesis import strategies as st

from vg_addon import GoniometerError
from vg_addon.formats.csvio import ReplicationRow
from vg_addon.workflow.batchplan import (
    Task,
    by_mesh,
    exit_code,
    find_mesh_files,
    mesh_names,
    parse_shard,
    plan_points,
    plan_rows,
    shard,
)


def row(
    n, mesh=None, radius=None, lam=None, patch=None, label=None, break_number=None,
    coordinates="mesh",
):  # fmt: skip
    return ReplicationRow(
        row_number=n, mesh_name=mesh, x=float(n), y=0.0, z=0.0, radius=radius, lam=lam,
        patch=patch, label=label, break_number=break_number, coordinates=coordinates,
    )  # fmt: skip


# --------------------------------------------------------------------------- command line values


@pytest.mark.parametrize(
    ("text", "expected"), [("1/1", (1, 1)), ("3/10", (3, 10)), (" 2 / 4 ", (2, 4))]
)
def test_parse_shard(text, expected):
    assert parse_shard(text) == expected


@pytest.mark.parametrize("text", ["0/4", "5/4", "1/0", "2", "a/b", "1/2/3", "-1/2", ""])
def test_parse_shard_rejects_with_an_example(text):
    with pytest.raises(GoniometerError, match=r"K/N|K must be"):
        parse_shard(text)


def test_find_mesh_files_expands_folders_sorted_and_keeps_files(tmp_path):
    folder = tmp_path / "scans"
    folder.mkdir()
    for name in ("b.PLY", "a.obj", "c.stl", "notes.txt"):
        (folder / name).write_text("x")
    (folder / "sub").mkdir()
    (folder / "sub" / "deep.ply").write_text("x")
    single = tmp_path / "z.ply"
    single.write_text("x")
    files = find_mesh_files([single, folder])
    assert [f.name for f in files] == ["z.ply", "a.obj", "b.PLY", "c.stl"]


def test_find_mesh_files_lists_every_problem(tmp_path):
    empty = tmp_path / "empty"
    empty.mkdir()
    text = tmp_path / "notes.txt"
    text.write_text("x")
    with pytest.raises(GoniometerError) as caught:
        find_mesh_files([tmp_path / "missing.ply", empty, text])
    message = str(caught.value)
    assert message.startswith("3 mesh input(s) cannot be used")
    assert "missing.ply: no such file or folder" in message
    assert "a folder with no .ply, .obj, .stl files" in message
    assert "notes.txt: not a mesh file" in message


def test_mesh_names_are_file_stems_and_must_be_unique(tmp_path):
    assert mesh_names(["a/bone_1.ply", "b/bone_2.stl"]) == ["bone_1", "bone_2"]
    with pytest.raises(GoniometerError, match="both named 'bone'"):
        mesh_names(["a/bone.ply", "b/bone.obj"])


def test_a_mesh_file_given_twice_is_named_so_not_as_a_name_clash(tmp_path):
    (tmp_path / "bone.ply").touch()
    (tmp_path / "sub").mkdir()
    twice = [tmp_path / "bone.ply", tmp_path / "sub" / ".." / "bone.ply"]
    with pytest.raises(GoniometerError) as raised:
        mesh_names(twice)
    message = str(raised.value)
    assert message.startswith("1 mesh file(s) given twice") and "share a name" not in message
    assert f"(also as {twice[0]})" in message


# --------------------------------------------------------------------------- planning


def test_plan_points_measures_every_point_on_every_mesh():
    tasks = plan_points(2, [(0, 0, 0), (1, 2, 3)], radius=0.5, lam=1.5, patch="Geodesic")
    assert [(t.index, t.mesh, t.number, t.center) for t in tasks] == [
        (0, 0, 1, (0.0, 0.0, 0.0)),
        (1, 0, 2, (1.0, 2.0, 3.0)),
        (2, 1, 1, (0.0, 0.0, 0.0)),
        (3, 1, 2, (1.0, 2.0, 3.0)),
    ]
    assert {(t.radius, t.lam, t.patch) for t in tasks} == {(0.5, 1.5, "geodesic")}


@pytest.mark.parametrize(
    ("radius", "lam", "patch", "match"),
    [
        (None, 2, "euclidean", "(?i)--at needs --radius"),
        (0, 2, "euclidean", "(?i)radius must be a finite number greater than 0"),
        (1, -1, "euclidean", "(?i)λ \\(SegParam\\) must be a number from 0"),
        (1, 2, "ball", "(?i)unknown patch mode 'ball'"),
    ],
)
def test_plan_points_rejects_bad_defaults(radius, lam, patch, match):
    with pytest.raises(GoniometerError, match=match):
        plan_points(1, [(0, 0, 0)], radius=radius, lam=lam, patch=patch)


def test_plan_rows_uses_each_rows_values_and_the_defaults_for_the_rest():
    rows = [row(2, radius=0.3, lam=1.0, patch="geodesic", label="a", break_number=4), row(3)]
    first, second = plan_rows([("bone",)], rows, radius=0.7, lam=2.5, patch="euclidean")
    assert (first.radius, first.lam, first.patch, first.label, first.break_number) == (
        0.3, 1.0, "geodesic", "a", 4,
    )  # fmt: skip
    assert (second.radius, second.lam, second.patch, second.label, second.break_number) == (
        0.7, 2.5, "euclidean", "", None,
    )  # fmt: skip
    assert [(t.index, t.number, t.source_row) for t in (first, second)] == [(0, 1, 2), (1, 2, 3)]


def test_plan_rows_keep_each_rows_coordinate_space():
    rows = [row(2, radius=0.3, coordinates="world"), row(3, radius=0.3)]
    world, mesh = plan_rows([("bone",)], rows)
    assert (world.coordinates, mesh.coordinates) == ("world", "mesh")
    assert plan_points(1, [(0.0, 0.0, 0.0)], radius=1.0, lam=2.0, patch="euclidean")[
        0
    ].coordinates == ("mesh")


def test_plan_rows_needs_a_radius_for_every_row():
    with pytest.raises(
        GoniometerError, match=r"2 row\(s\) of 'p.csv' have no radius \(rows 3, 5\)"
    ):
        plan_rows([("m",)], [row(2, radius=1.0), row(3), row(5)], source="'p.csv'")


def test_plan_rows_matches_mesh_names_like_the_extension():
    meshes = [("bone_1",), ("bone_2", "Bone2Mesh")]
    rows = [
        row(2, "bone_2"),
        row(3, "scans/bone_1.ply"),  # MeshLab writes the file name
        row(4, "Bone2Mesh"),  # a Blender object's mesh data name
        row(5, "bone_1"),
        row(6, "bone_3"),
    ]
    tasks = plan_rows(meshes, rows, radius=1.0)
    assert [t.mesh for t in tasks] == [1, 0, 1, 0, -1]
    assert [t.number for t in tasks] == [1, 1, 2, 2, 0]  # per mesh, in file order
    assert "row 6 names mesh 'bone_3', which is not among the meshes given" in tasks[4].error
    assert all(not t.error for t in tasks[:4])


def test_plan_rows_prefers_an_objects_own_name_over_another_objects_mesh_name():
    meshes = [("Cube", "Mesh"), ("Mesh", "Cube.001")]
    assert [t.mesh for t in plan_rows(meshes, [row(2, "Mesh"), row(3, "Cube")], radius=1)] == [1, 0]


def test_plan_rows_single_mesh_takes_unnamed_rows_and_can_ignore_names():
    tasks = plan_rows([("a",)], [row(2), row(3, "other")], radius=1)
    assert [t.mesh for t in tasks] == [0, -1]
    assert "--ignore-mesh-names" in tasks[1].error
    tasks = plan_rows([("a",)], [row(2), row(3, "other")], radius=1, ignore_mesh_names=True)
    assert [(t.mesh, t.number) for t in tasks] == [(0, 1), (0, 2)]


def test_plan_rows_with_several_meshes_needs_mesh_names():
    with pytest.raises(GoniometerError, match="names no mesh, and 2 meshes are given"):
        plan_rows([("a",), ("b",)], [row(2), row(3)], radius=1)
    tasks = plan_rows([("a",), ("b",)], [row(2, "a"), row(3)], radius=1)
    assert tasks[1].mesh == -1 and "names no mesh, and several are given" in tasks[1].error
    with pytest.raises(GoniometerError, match="--ignore-mesh-names needs a single mesh"):
        plan_rows([("a",), ("b",)], [row(2, "a")], radius=1, ignore_mesh_names=True)


# --------------------------------------------------------------------------- dividing the work


def _tasks(n):
    return [Task(index=i, mesh=i % 3, center=(0.0, 0.0, 0.0), radius=1.0, lam=2.0,
                 patch="euclidean") for i in range(n)]  # fmt: skip


@given(st.integers(0, 200), st.integers(1, 12))
def test_shards_concatenate_to_the_whole_in_equal_shares(total, n):
    tasks = _tasks(total)
    shares = [shard(tasks, k, n) for k in range(1, n + 1)]
    assert [t for share in shares for t in share] == tasks
    sizes = [len(share) for share in shares]
    assert max(sizes) - min(sizes) <= 1


def test_shard_rejects_k_out_of_range():
    with pytest.raises(GoniometerError):
        shard(_tasks(4), 3, 2)


def test_by_mesh_groups_in_order_of_first_appearance():
    tasks = [
        Task(index=i, mesh=m, center=(0.0, 0.0, 0.0), radius=1.0, lam=2.0, patch="euclidean")
        for i, m in enumerate([2, 0, 2, -1, 0])
    ]
    groups = by_mesh(tasks)
    assert list(groups) == [2, 0, -1]
    assert [t.index for t in groups[2]] == [0, 2]
    assert [t.index for t in groups[0]] == [1, 4]


@pytest.mark.parametrize(("failed", "bad", "code"), [(0, 0, 0), (3, 0, 1), (0, 1, 2), (5, 2, 2)])
def test_exit_code(failed, bad, code):
    assert exit_code(failed, bad) == code
