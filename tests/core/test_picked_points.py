"""MeshLab picked-points (.pp) files: the reader, its refusals, and matching a file to its mesh.

The files are written here as text in the layouts MeshLab and other tools write (attribute
orders, spaces around ``=``, no DocumentData, CRLF), not by the code under test.
"""

import numpy as np
import pytest

from vg_addon import GoniometerError
from vg_addon.formats import picked_points as pp

MESHLAB = """<!DOCTYPE PickedPoints>
<PickedPoints>
 <DocumentData>
  <DateTime time="16:21:09" date="2021-03-04"/>
  <User name="analyst"/>
  <DataFileName name="bone_12.ply"/>
  <templateName name=""/>
 </DocumentData>
 <point x="12.125" y="3.5" z="-7.875" name="0" active="1"/>
 <point x="20" y="-1e-3" z="4.25E2" name="1" active="0"/>
 <point x="30.5" y="2.25" z="-9" name="2" active="1"/>
 <point x=".5" y="+2." z="-0.0" name="end" active="1"/>
</PickedPoints>
"""


def test_a_meshlab_file_reads_every_point_with_its_name_and_state():
    picked = pp.parse_picked_points(MESHLAB)
    assert picked.data_file == "bone_12.ply"
    assert [p.name for p in picked.points] == ["0", "1", "2", "end"]
    assert [p.active for p in picked.points] == [True, False, True, True]
    assert picked.points[1].xyz == (20.0, -0.001, 425.0)
    assert [p.line for p in picked.points] == [9, 10, 11, 12]


def test_an_edge_is_the_active_points_in_file_order():
    points = pp.edge_points(pp.parse_picked_points(MESHLAB))
    expected = np.array([[12.125, 3.5, -7.875], [30.5, 2.25, -9.0], [0.5, 2.0, -0.0]])
    assert points.dtype == np.float64
    np.testing.assert_array_equal(points, expected)


def test_other_writers_layouts_read_the_same_numbers():
    # Attribute order shuffled, spaces around '=', no DocumentData, no active (= picked),
    # Windows line ends, an XML declaration, 17-digit numbers kept exactly.
    text = (
        '<?xml version="1.0" encoding="UTF-8"?>\r\n<!DOCTYPE PickedPoints>\r\n<PickedPoints>\r\n'
        ' <point y = "0.1" name = "a" z = "0.30000000000000004" x = "-1.2345678901234567"/>\r\n'
        "\t<point z='1' x='2' y='3' active='1'/>\r\n</PickedPoints>\r\n"
    )
    picked = pp.parse_picked_points(text.encode("utf-8"))
    assert picked.data_file == ""
    assert picked.points[0].xyz == (-1.2345678901234567, 0.1, 0.30000000000000004)
    assert picked.points[1].xyz == (2.0, 3.0, 1.0)
    assert all(p.active for p in picked.points)


@pytest.mark.parametrize(
    ("point", "words"),
    [
        ('<point x="1" y="2" name="a"/>', "no z"),
        ('<point x="1" y="two" z="3"/>', "y='two' is not a number"),
        ('<point x="nan" y="2" z="3"/>', "x='nan' is not a number"),
        ('<point x="1" y="inf" z="3"/>', "y='inf' is not a number"),
        ('<point x="1e999" y="2" z="3"/>', "x='1e999' is not a finite number"),
        ('<point x="1_000" y="2" z="3"/>', "x='1_000' is not a number"),
        ('<point x="" y="2" z="3"/>', "x='' is not a number"),
        ('<point x="1" y="2" z="3" active="yes"/>', "active='yes' is not 1 or 0"),
    ],
)
def test_a_bad_point_is_refused_naming_its_line_and_what_is_wrong(point, words):
    text = f'<PickedPoints>\n <point x="0" y="0" z="0"/>\n {point}\n</PickedPoints>\n'
    with pytest.raises(GoniometerError, match="nothing was read") as caught:
        pp.parse_picked_points(text, "'b.pp'")
    message = str(caught.value)
    assert "'b.pp'" in message and "line 3" in message and words in message
    assert "line 2" not in message


def test_every_bad_point_is_listed_at_once():
    rows = "\n".join(f' <point x="{i}" y="?" z="0"/>' for i in range(3))
    with pytest.raises(GoniometerError) as caught:
        pp.parse_picked_points(f"<PickedPoints>\n{rows}\n</PickedPoints>")
    assert "3 problem(s)" in str(caught.value)
    assert all(f"line {n}" in str(caught.value) for n in (2, 3, 4))


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("", "malformed at line 1"),
        ("x,y,z\n1,2,3\n", "malformed at line 1"),
        ('<PickedPoints>\n <point x="1" y="2" z="3">\n</PickedPoints>', "malformed at line 3"),
        ('<Points><point x="1" y="2" z="3"/></Points>', "root element is <Points>"),
        ('<PickedPoints><point x="1" y="2" z="3"/></PickedPoints><x/>', "malformed"),
        ("<PickedPoints><Marker/></PickedPoints>", "<Marker> (only"),
        ('<PickedPoints><DocumentData><point x="1" y="2" z="3"/></DocumentData></PickedPoints>',
         "a <point> inside <DocumentData>"),
        ("<PickedPoints><DocumentData/><DocumentData/></PickedPoints>", "a second"),
        ('<!DOCTYPE PickedPoints [<!ENTITY a "aaaa">]><PickedPoints/>', "its own document type"),
        ("<PickedPoints>&lol;</PickedPoints>", "malformed"),
    ],
)  # fmt: skip
def test_files_that_are_not_picked_points_are_refused(text, words):
    with pytest.raises(GoniometerError, match="picked-points") as caught:
        pp.parse_picked_points(text)
    assert words in str(caught.value)


def test_an_edge_needs_two_active_points():
    text = (
        '<PickedPoints><point x="1" y="2" z="3"/>'
        '<point x="4" y="5" z="6" active="0"/></PickedPoints>'
    )
    picked = pp.parse_picked_points(text, "'one.pp'")
    with pytest.raises(GoniometerError, match=r"'one.pp' has 1 picked point\(s\) \(1 more are"):
        pp.edge_points(picked)
    with pytest.raises(GoniometerError, match="has 0 picked point"):
        pp.edge_points(pp.parse_picked_points("<PickedPoints/>"))


def test_reading_a_file_refuses_missing_and_oversized_files(tmp_path):
    path = tmp_path / "bone_12.pp"
    path.write_text(MESHLAB, encoding="utf-8")
    assert len(pp.read_picked_points(path).points) == 4
    with pytest.raises(GoniometerError, match="cannot be read"):
        pp.read_picked_points(tmp_path / "gone.pp")
    with pytest.raises(GoniometerError, match="cannot be read"):
        pp.read_picked_points(tmp_path)  # a folder
    huge = tmp_path / "huge.pp"
    with open(huge, "wb") as handle:
        handle.truncate(pp.MAX_BYTES + 1)  # sparse: nothing is written
    with pytest.raises(GoniometerError, match="far more than a list"):
        pp.read_picked_points(huge)


def test_a_file_belongs_to_the_mesh_its_name_starts_with():
    names = ["bone", "bone_12", "flake", "flake2"]
    assert pp.mesh_for_file("scans/bone_12.pp", names) == "bone_12"
    assert pp.mesh_for_file("bone_12_break3.pp", names) == "bone_12"
    assert pp.mesh_for_file("bone_1.pp", names) == "bone"
    assert pp.mesh_for_file("bone.PP", names) == "bone"
    assert pp.mesh_for_file("flake2.pp", names) == "flake2"
    assert pp.mesh_for_file("flake_a.pp", names) == "flake"
    assert pp.mesh_for_file("flakes.pp", names) is None
    assert pp.mesh_for_file("other.pp", names) is None


def test_a_file_name_matches_its_mesh_whatever_the_case_unless_that_is_ambiguous():
    names = ["Bone", "bone_12", "FLAKE"]
    assert pp.mesh_for_file("bone.pp", names) == "Bone"
    assert pp.mesh_for_file("BONE_12_Break3.PP", names) == "bone_12"
    assert pp.mesh_for_file("Bone_1.pp", names) == "Bone"
    assert pp.mesh_for_file("flake_a.pp", names) == "FLAKE"
    assert pp.mesh_for_file("flakes.pp", names) is None
    # Two meshes differing only in case: the one spelt like the file, else neither.
    twins = ["Scan", "scan"]
    assert pp.mesh_for_file("scan_a.pp", twins) == "scan"
    assert pp.mesh_for_file("Scan.pp", twins) == "Scan"
    assert pp.mesh_for_file("SCAN.pp", twins) is None


def test_a_folder_lists_its_pp_files_by_name(tmp_path):
    for name in ("b.pp", "a.PP", "c.txt"):
        (tmp_path / name).write_text("<PickedPoints/>", encoding="utf-8")
    (tmp_path / "sub.pp").mkdir()
    assert [p.name for p in pp.files_in(tmp_path)] == ["a.PP", "b.pp"]
    with pytest.raises(GoniometerError, match="cannot list"):
        pp.files_in(tmp_path / "none")
