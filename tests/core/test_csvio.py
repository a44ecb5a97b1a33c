"""The measurement CSV: export schema, atomic writer, formula guard and replication reader."""

import csv
import io
import math
import os
import re
import struct
from datetime import datetime

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vg_addon import GoniometerError
from vg_addon.formats import csvio
from vg_addon.formats.csvio import MeasurementRow, ReplicationRow

MESHLAB_HEADER = (
    "Mesh Name,Date,Measurement #,Break #,Colors,User Data,Angle,Number of Vertices,Radius,"
    "x,y,z,fit,SegParam"
)
OUR_EXTRA_COLUMNS = [
    "Patch Mode",
    "Vertices +",
    "Vertices -",
    "Fit +",
    "Fit -",
    "Normal + x",
    "Normal + y",
    "Normal + z",
    "Normal - x",
    "Normal - y",
    "Normal - z",
    "Requested x",
    "Requested y",
    "Requested z",
    "Snap Distance",
    "Edge #",
    "Arc Length",
    "Spacing",
    "Units",
    "Coordinates",
    "Precision",
    "Stale",
    "Extension Version",
    "Blender Version",
    "Rule",
    "Convexity",
    "Convexity Correlation",
    "Stability",
    "Stability Centre",
    "Stability Radius",
    "Stability SegParam",
    "Stability Bootstrap",
    "Stability Orientation",
    "Stability Runs",
    "Stability Refused",
    "error",
]


def bits(value: float) -> bytes:
    return struct.pack("<d", value)


def good_row(**changes) -> MeasurementRow:
    values = dict(
        mesh_name="bone_12",
        date="2024-05-01T14:03:11+02:00",
        number=1,
        break_number=1,
        colors="#E69F00/#0072B2",
        user_data="ridge, proximal end",
        angle=97.12345678901234,
        n_vertices=812,
        radius=3.0,
        x=1.25,
        y=-2.5,
        z=0.1,
        fit=0.0123,
        lam=2.0,
        patch="euclidean",
        n_plus=400,
        n_minus=412,
        fit_plus=0.01,
        fit_minus=0.02,
        normal_plus=(0.0, 0.0, 1.0),
        normal_minus=(0.6, 0.0, -0.8),
        requested=(1.2, -2.5, 0.11),
        snap_distance=0.0509,
        units="BU (1 BU = 0.001 m, shown in millimeters)",
        stale=False,
        extension_version="0.1.0",
        blender_version="5.0.1",
        rule="oriented",
        convexity="concave",
        correlation=-0.8660254037844386,
        stability=0.4123,
        stability_center=0.4123,
        stability_radius=0.1,
        stability_lam=0.05,
        stability_bootstrap=0.2,
        stability_orientation=0.0,
        stability_runs=21,
        stability_refused=1,
        error="",
    )
    values.update(changes)
    return MeasurementRow(**values)


def cells(text: str) -> list[list[str]]:
    return list(csv.reader(io.StringIO(text, newline="")))


def raises_with(text, *fragments):
    """Read ``text`` for replication, expect a GoniometerError containing every fragment."""
    with pytest.raises(GoniometerError) as info:
        csvio.read_replication_csv(text)
    message = str(info.value)
    for fragment in fragments:
        assert fragment in message, f"{fragment!r} not in:\n{message}"
    return message


# --------------------------------------------------------------------------- schema


def test_header_starts_with_the_exact_meshlab_columns():
    text = csvio.format_measurements_csv([])
    first_line = text.split("\n")[0]
    assert first_line.startswith(MESHLAB_HEADER + ",")
    assert tuple(MESHLAB_HEADER.split(",")) == csvio.MESHLAB_COLUMNS
    assert list(csvio.EXPORT_COLUMNS) == MESHLAB_HEADER.split(",") + OUR_EXTRA_COLUMNS
    assert first_line == ",".join(csvio.EXPORT_COLUMNS)


def test_every_column_has_a_field_and_every_field_a_column():
    row = good_row()
    written = cells(csvio.format_measurements_csv([row]))
    assert len(written) == 2
    assert len(written[1]) == len(csvio.EXPORT_COLUMNS)
    by_column = dict(zip(csvio.EXPORT_COLUMNS, written[1], strict=True))
    assert by_column["Mesh Name"] == "bone_12"
    assert by_column["Measurement #"] == "1"
    assert by_column["Number of Vertices"] == "812"
    assert by_column["SegParam"] == "2.0"
    assert by_column["Normal - x"] == "0.6"
    assert by_column["Requested z"] == "0.11"
    assert by_column["Stale"] == "FALSE"
    assert by_column["error"] == ""


def test_text_is_utf8_with_newline_line_ends(tmp_path):
    path = tmp_path / "m.csv"
    csvio.write_measurements_csv(path, [good_row(user_data="λ = 2, «ok»"), good_row(number=2)])
    data = path.read_bytes()
    assert b"\r" not in data
    assert data.count(b"\n") == 3
    assert not data.startswith(b"\xef\xbb\xbf")
    assert "λ = 2, «ok»" in data.decode("utf-8")


def test_failed_row_leaves_numeric_cells_empty():
    failed = MeasurementRow(mesh_name="bone_12", x=1.0, y=2.0, z=3.0, error="too few vertices")
    written = dict(
        zip(csvio.EXPORT_COLUMNS, cells(csvio.format_measurements_csv([failed]))[1], strict=True)
    )
    for column in ("Angle", "Number of Vertices", "Radius", "fit", "Normal + x", "Snap Distance"):
        assert written[column] == ""
    assert written["error"] == "too few vertices"
    assert [written[c] for c in "xyz"] == ["1.0", "2.0", "3.0"]


# --------------------------------------------------------------------------- round trips

finite = st.floats(allow_nan=False, allow_infinity=False)
special = st.sampled_from(
    [0.0, -0.0, 5e-324, -5e-324, 2.2250738585072014e-308, 1.7976931348623157e308, 0.1, 1 / 3]
)
any_float = finite | special


@settings(max_examples=150, deadline=None)
@given(values=st.lists(any_float, min_size=19, max_size=19), blank=st.booleans())
def test_every_float_round_trips_bit_identical(values, blank):
    floats = iter(values)
    row = good_row(
        angle=next(floats),
        radius=next(floats),
        x=next(floats),
        y=next(floats),
        z=next(floats),
        fit=next(floats),
        lam=next(floats),
        fit_plus=next(floats),
        fit_minus=next(floats),
        normal_plus=(next(floats), next(floats), next(floats)),
        normal_minus=(next(floats), next(floats), next(floats)),
        requested=(next(floats), next(floats), next(floats)),
        snap_distance=None if blank else next(floats),
    )
    (back,) = csvio.read_measurements_csv(csvio.format_measurements_csv([row]))
    assert back == row
    for name in ("angle", "radius", "x", "y", "z", "fit", "lam", "fit_plus", "fit_minus"):
        assert bits(getattr(back, name)) == bits(getattr(row, name)), name
    for name in ("normal_plus", "normal_minus", "requested"):
        assert [bits(v) for v in getattr(back, name)] == [bits(v) for v in getattr(row, name)]


@settings(max_examples=100, deadline=None)
@given(
    xyz=st.tuples(any_float, any_float, any_float),
    radius=st.floats(min_value=5e-324, allow_infinity=False),
    lam=st.floats(min_value=0.0, allow_infinity=False),
)
def test_replication_reads_back_the_written_floats_exactly(xyz, radius, lam):
    x, y, z = xyz
    text = csvio.format_measurements_csv([good_row(x=x, y=y, z=z, radius=radius, lam=lam)])
    (row,) = csvio.read_replication_csv(text)
    assert [bits(v) for v in (row.x, row.y, row.z)] == [bits(v) for v in xyz]
    assert bits(row.radius) == bits(radius)
    assert bits(row.lam) == bits(lam)


def test_file_round_trip_of_every_field(tmp_path):
    rows = [
        good_row(),
        good_row(number=2, break_number=2, stale=True, patch="geodesic", user_data=""),
        MeasurementRow(mesh_name="bone_12", date="d", error="centre too far from the surface"),
    ]
    path = tmp_path / "out.csv"
    csvio.write_measurements_csv(path, rows)
    assert csvio.read_measurements_csv(path) == rows
    assert csvio.read_measurements_csv(str(path)) == rows


def test_numpy_floats_are_written_as_plain_numbers():
    np = pytest.importorskip("numpy")
    value = np.float64(0.1) + np.float64(0.2)
    row = good_row(angle=value, normal_plus=np.array([0.0, 0.6, -0.8]), n_vertices=np.int64(9))
    written = dict(
        zip(csvio.EXPORT_COLUMNS, cells(csvio.format_measurements_csv([row]))[1], strict=True)
    )
    assert written["Angle"] == "0.30000000000000004"
    assert written["Normal + z"] == "-0.8"
    assert written["Number of Vertices"] == "9"


# --------------------------------------------------------------------------- formula injection

INJECTIONS = ["=SUM(A1)", "+1", "-x", "@x", "\tx", "\rx", "'=x", "'plain"]


@pytest.mark.parametrize("text", INJECTIONS)
def test_formula_like_text_is_neutralised_and_read_back(text):
    row = good_row(mesh_name="bone " + text if text == "'plain" else text, user_data=text)
    written = cells(csvio.format_measurements_csv([row]))[1]
    by_column = dict(zip(csvio.EXPORT_COLUMNS, written, strict=True))
    assert by_column["User Data"] == "'" + text
    assert by_column["User Data"][0] == "'"
    if text != "'plain":
        assert by_column["Mesh Name"] == "'" + text
    # the full reader restores the text exactly
    (back,) = csvio.read_measurements_csv(csvio.format_measurements_csv([row]))
    assert back.mesh_name == row.mesh_name
    assert back.user_data == text
    # the replication reader too (its cells are read without surrounding whitespace)
    (rep,) = csvio.read_replication_csv(csvio.format_measurements_csv([row]))
    assert rep.label == text
    assert rep.mesh_name == row.mesh_name


def test_numbers_are_never_prefixed():
    row = good_row(x=-1.5, y=-0.0, z=-1e-300, angle=-0.0, normal_minus=(-1.0, -0.0, -0.0))
    written = dict(
        zip(csvio.EXPORT_COLUMNS, cells(csvio.format_measurements_csv([row]))[1], strict=True)
    )
    assert written["x"] == "-1.5"
    assert written["y"] == "-0.0"
    assert written["z"] == "-1e-300"
    assert written["Normal - x"] == "-1.0"


def test_a_foreign_leading_apostrophe_is_kept():
    text = "x,y,z,label\n1,2,3,'quoted'\n"
    (row,) = csvio.read_replication_csv(text)
    assert row.label == "'quoted'"


# --------------------------------------------------------------------------- atomic writing


def test_a_row_that_cannot_be_formatted_leaves_the_old_file_intact(tmp_path):
    path = tmp_path / "m.csv"
    csvio.write_measurements_csv(path, [good_row()])
    before = path.read_bytes()
    for bad in (
        good_row(angle=math.nan),
        good_row(x=math.inf),
        good_row(n_vertices=2.5),
        good_row(normal_plus=(1.0, 0.0)),
        good_row(radius="three"),
    ):
        with pytest.raises(GoniometerError, match="Nothing was written"):
            csvio.write_measurements_csv(path, [good_row(number=5), bad])
        assert path.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.csv"]


def test_failed_replace_keeps_the_old_file_and_removes_the_temp(tmp_path, monkeypatch):
    path = tmp_path / "m.csv"
    csvio.write_measurements_csv(path, [good_row()])
    before = path.read_bytes()

    def refuse(source, target):
        assert os.path.dirname(source) == os.path.dirname(os.path.abspath(target))
        assert os.path.exists(source)
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(os, "replace", refuse)
    with pytest.raises(GoniometerError) as info:
        csvio.write_measurements_csv(path, [good_row(number=2), good_row(number=3)])
    assert "old file is unchanged" in str(info.value)
    assert path.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.csv"]


def test_failed_write_removes_the_temp(tmp_path, monkeypatch):
    path = tmp_path / "m.csv"
    csvio.write_measurements_csv(path, [good_row()])
    before = path.read_bytes()

    def disk_full(fd):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "fsync", disk_full)
    with pytest.raises(OSError, match="No space left"):
        csvio.write_measurements_csv(path, [good_row(number=2)])
    assert path.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.csv"]


def test_writing_into_a_missing_folder_says_so(tmp_path):
    with pytest.raises(GoniometerError, match="does not exist"):
        csvio.write_measurements_csv(tmp_path / "nowhere" / "m.csv", [good_row()])


@pytest.mark.skipif(os.name != "posix", reason="POSIX permission bits")
def test_overwriting_keeps_the_file_permissions(tmp_path):
    path = tmp_path / "m.csv"
    path.write_text("old\n")
    path.chmod(0o640)
    csvio.write_measurements_csv(path, [good_row()])
    assert path.stat().st_mode & 0o777 == 0o640
    assert path.read_text().startswith(MESHLAB_HEADER)


# --------------------------------------------------------------------------- other formats

MESHLAB_FILE = (
    MESHLAB_HEADER + "\n"
    "sample_mesh.ply,Tue Mar  2 14:03:11 2021,1,1,Red/Blue, ,97.123456,1234,3.000000,"
    "1.234567,-2.345678,0.123456,0.012345,2.000000\n"
    "sample_mesh.ply,Tue Mar  2 14:05:40 2021,2.05,2,Red/Green, ,121.500000,98,0.812000,"
    "10.000000,20.000000,30.000000,0.100000,1.500000\n"
)

# The earlier AMAAZE Blender add-on: the same 14 columns, '%c' dates, colour names, the text
# "fill" in fit and a constant 2 in SegParam.
OLD_ADDON_FILE = (
    MESHLAB_HEADER + "\r\n"
    "Fragment_07,Wed Jun 16 10:22:31 2021,1,1,Orange/Sky Blue,,83.91,523,2.5,"
    "0.5,1.5,-3.25,fill,2\r\n"
    "Fragment_07,Wed Jun 16 10:23:02 2021,2,1,Orange/Sky Blue,cortical,88.2,610,2.5,"
    "0.75,1.25,-3.0,fill,2\r\n"
)


def test_meshlab_file_parses():
    rows = csvio.read_replication_csv(MESHLAB_FILE)
    assert rows == [
        ReplicationRow(
            row_number=2,
            mesh_name="sample_mesh.ply",
            x=1.234567,
            y=-2.345678,
            z=0.123456,
            radius=3.0,
            lam=2.0,
            patch=None,
            label=None,
            number=1,
            break_number=1,
            source_format="meshlab",
            rule="paper",
        ),
        ReplicationRow(
            row_number=3,
            mesh_name="sample_mesh.ply",
            x=10.0,
            y=20.0,
            z=30.0,
            radius=0.812,
            lam=1.5,
            patch=None,
            label=None,
            number=2.05,
            break_number=2,
            source_format="meshlab",
            rule="paper",
        ),
    ]


def test_old_blender_addon_file_parses():
    rows = csvio.read_replication_csv(OLD_ADDON_FILE)
    assert [(r.row_number, r.mesh_name, r.x, r.y, r.z) for r in rows] == [
        (2, "Fragment_07", 0.5, 1.5, -3.25),
        (3, "Fragment_07", 0.75, 1.25, -3.0),
    ]
    assert [r.radius for r in rows] == [2.5, 2.5]
    assert [r.lam for r in rows] == [2.0, 2.0]
    assert [r.label for r in rows] == [None, "cortical"]
    assert {r.source_format for r in rows} == {"meshlab"}


def test_our_export_is_recognised():
    rows = csvio.read_replication_csv(
        csvio.format_measurements_csv([good_row(patch="geodesic", user_data="note")])
    )
    assert rows[0].source_format == "extension"
    assert rows[0].patch == "geodesic"
    assert rows[0].label == "note"
    assert rows[0].number == 1
    assert rows[0].coordinates == "mesh"


def legacy_export(rows) -> str:
    """An export as versions before the Coordinates column wrote it (world coordinates)."""
    records = list(csv.reader(io.StringIO(csvio.format_measurements_csv(rows))))
    drop = records[0].index("Coordinates")
    out = io.StringIO()
    csv.writer(out, lineterminator="\n").writerows(
        [cell for i, cell in enumerate(record) if i != drop] for record in records
    )
    return out.getvalue()


def test_an_export_without_the_coordinates_column_is_read_as_world_space():
    old = legacy_export([good_row()])
    assert "Coordinates" not in old.split("\n")[0]
    replicated = csvio.read_replication_csv(old)
    assert replicated[0].source_format == "extension"
    assert replicated[0].coordinates == "world"
    full = csvio.read_measurements_csv(old)
    assert full[0].coordinates == "world"
    assert full[0].x == good_row().x


def test_meshlab_and_points_files_are_mesh_coordinates():
    assert {r.coordinates for r in csvio.read_replication_csv(MESHLAB_FILE)} == {"mesh"}
    assert csvio.read_replication_csv("x,y,z\n1,2,3\n")[0].coordinates == "mesh"
    assert csvio.read_replication_csv("x,y,z,coordinates\n1,2,3,World\n")[0].coordinates == (
        "world"
    )


def test_unknown_coordinates_are_a_problem_with_their_row():
    with pytest.raises(GoniometerError, match=r"row 3: unknown coordinates 'local'"):
        csvio.read_replication_csv("x,y,z,Coordinates\n1,2,3,mesh\n1,2,3,local\n")


def test_plain_points_file_with_aliases_bom_and_odd_case(tmp_path):
    path = tmp_path / "points.csv"
    path.write_bytes(
        "\ufeff X , y,Z ,Radius, λ ,Patch_Mode,Label,mesh\n"
        "1,2,3,0.5,1,Geodesic,first,bone_12\n"
        "\n"
        " 4 , 5 , 6 ,,,,,\n".encode()
    )
    rows = csvio.read_replication_csv(path)
    assert rows == [
        ReplicationRow(2, "bone_12", 1.0, 2.0, 3.0, 0.5, 1.0, "geodesic", "first"),
        ReplicationRow(4, None, 4.0, 5.0, 6.0),
    ]
    assert rows[0].source_format == "points"


@pytest.mark.parametrize(
    "header",
    ["x,y,z,SegParam", "x,y,z,Seg Param", "x,y,z,lambda", "x,y,z,Segmentation Parameter"],
)
def test_lambda_aliases(header):
    (row,) = csvio.read_replication_csv(header + "\n1,2,3,0.75\n")
    assert row.lam == 0.75


@pytest.mark.parametrize("header", ["Mesh Name", "mesh", "Object", "MESH_NAME"])
def test_mesh_name_aliases(header):
    (row,) = csvio.read_replication_csv(f"{header},x,y,z\nbone,1,2,3\n")
    assert row.mesh_name == "bone"


def test_label_wins_over_user_data():
    (row,) = csvio.read_replication_csv("x,y,z,User Data,label\n1,2,3,from user data,from label\n")
    assert row.label == "from label"


def test_failed_rows_without_coordinates_are_skipped():
    text = csvio.format_measurements_csv(
        [
            good_row(),
            MeasurementRow(mesh_name="bone_12", error="could not read the mesh"),
            MeasurementRow(mesh_name="bone_12", x=1.0, y=2.0, z=3.0, error="too few vertices"),
        ]
    )
    rows = csvio.read_replication_csv(text)
    assert [r.row_number for r in rows] == [2, 4]


def test_only_failed_rows_is_an_error():
    text = csvio.format_measurements_csv([MeasurementRow(mesh_name="b", error="failed")])
    raises_with(text, "no rows to replicate", "failed")


def test_row_numbers_count_blank_lines_and_multiline_cells():
    text = 'x,y,z,label\n\n1,2,3,"two\nlines"\n4,5,6,\n'
    rows = csvio.read_replication_csv(text)
    assert [r.row_number for r in rows] == [3, 4]
    assert rows[0].label == "two\nlines"


# --------------------------------------------------------------------------- bad input


def test_missing_columns_are_named_with_those_found():
    message = raises_with("x,radius,foo\n1,2,3\n", "y, z", "'x'", "'radius'", "'foo'")
    assert "row" not in message.split("found")[0].split("header")[0]


def test_semicolon_delimiter_is_named():
    raises_with("x;y;z\n1;2;3\n", "semicolon", "comma")


def test_tab_delimiter_is_named():
    raises_with("x\ty\tz\n1\t2\t3\n", "tab", "comma")


def test_semicolon_file_with_decimal_commas_is_named():
    raises_with("Mesh Name;x;y;z;Radius\nbone;1,5;2,5;3,5;0,8\n", "semicolon")


@pytest.mark.parametrize("data", [b"", b"\xef\xbb\xbf", b"\n\n  \n", b"\xef\xbb\xbf\r\n"])
def test_empty_file(tmp_path, data):
    path = tmp_path / "empty.csv"
    path.write_bytes(data)
    raises_with(path, "'empty.csv'", "is empty")
    raises_with(data, "is empty")
    with pytest.raises(GoniometerError, match="is empty"):
        csvio.parse_replication_csv(data.decode("utf-8"))


def test_header_only_file():
    raises_with("x,y,z,radius\n", "header but no data rows")
    raises_with(MESHLAB_HEADER + "\n\n", "header but no data rows")


def test_every_bad_cell_is_listed_with_its_row_and_column():
    text = (
        "x,y,z,Radius,lambda,patch mode\n"
        "1,2,3,0.5,2,euclidean\n"  # row 2 good
        "abc,2,3,0.5,2,\n"  # row 3
        "1,,3,0.5,2,\n"  # row 4
        "1,2,inf,0.5,2,\n"  # row 5
        "1,2,3,0,2,\n"  # row 6
        "1,2,3,-1,2,\n"  # row 7
        "1,2,3,0.5,-0.1,\n"  # row 8
        "1,2,3,0.5,nan,\n"  # row 9
        "1,2,3,0.5,2,spherical\n"  # row 10
        "1,2,3,1e999,2,\n"  # row 11
    )
    message = raises_with(
        text,
        "row 3: x is not a number ('abc')",
        "row 4: y is empty",
        "row 5: z is not a finite number ('inf')",
        "row 6: Radius must be greater than 0",
        "row 7: Radius must be greater than 0",
        "row 8: lambda (λ) must be 0 or more",
        "row 9: lambda is not a finite number",
        "row 10: unknown patch mode 'spherical'",
        "row 11: Radius is not a finite number",
        "9 problem(s)",
    )
    assert "row 2" not in message


def test_problem_list_is_capped():
    text = "x,y,z\n" + "".join(f"{i},oops,3\n" for i in range(30))
    message = raises_with(text, "30 problem(s)", "row 2:", "row 21:", "and 10 more")
    assert "row 22:" not in message
    assert len(message.splitlines()) <= 23


def test_decimal_comma_gets_a_hint():
    raises_with('x,y,z\n"1,5",2,3\n', "row 2: x is not a number ('1,5'", "decimal separator")


def test_unquoted_comma_makes_a_row_too_long():
    raises_with("Mesh Name,x,y,z\nbone, left,1,2,3\n", "row 2: 5 cells", "4 columns")


def test_duplicate_columns_are_a_problem():
    raises_with("x,y,z,X\n1,2,3,4\n", "columns 1 and 4", "'x'")


def test_not_utf8_is_explained(tmp_path):
    path = tmp_path / "latin.csv"
    path.write_bytes("Mesh Name,x,y,z\nos_fémur,1,2,3\n".encode("cp1252"))
    raises_with(path, "not UTF-8", "CSV UTF-8")


def test_unreadable_path_is_an_os_error(tmp_path):
    with pytest.raises(OSError):
        csvio.read_replication_csv(tmp_path / "missing.csv")


def test_nothing_is_returned_half_way():
    good = "".join(f"{i},{i},{i}\n" for i in range(50))
    with pytest.raises(GoniometerError, match="row 52"):
        csvio.read_replication_csv("x,y,z\n" + good + "1,2,x\n")


def test_full_reader_lists_missing_columns_and_bad_cells():
    with pytest.raises(GoniometerError, match="Patch Mode"):
        csvio.read_measurements_csv(MESHLAB_FILE)
    text = csvio.format_measurements_csv([good_row()])
    bad = text.replace(",812,", ",many,", 1)
    with pytest.raises(GoniometerError, match=r"row 2: Number of Vertices is not a whole number"):
        csvio.read_measurements_csv(bad)


# --------------------------------------------------------------------------- mesh names


def test_rows_for_mesh_and_other_meshes():
    text = "Mesh Name,x,y,z\nbone_12,1,2,3\nbone_12.ply,1,2,3\nbone_13,1,2,3\n,1,2,3\nbone_12.001,1,2,3\n"
    rows = csvio.read_replication_csv(text)
    assert [r.row_number for r in csvio.rows_for_mesh(rows, "bone_12")] == [2, 3, 5]
    others = csvio.rows_for_other_meshes(rows, ("bone_12", "bone_12_mesh"))
    assert [r.row_number for r in others] == [4, 6]
    assert csvio.mesh_name_matches("C:\\scans\\bone_13.PLY", ["bone_13"])
    assert csvio.mesh_name_matches(None, "anything")
    with pytest.raises(GoniometerError) as info:
        csvio.check_mesh_names(rows, "bone_12", source="'m.csv'")
    message = str(info.value)
    assert "rows 4 ('bone_13'), 6 ('bone_12.001')" in message
    assert "'m.csv'" in message
    csvio.check_mesh_names(csvio.rows_for_mesh(rows, "bone_12"), "bone_12")


# --------------------------------------------------------------------------- helpers


def test_now_iso_is_local_time_with_offset_to_the_second():
    stamp = csvio.now_iso()
    assert re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d[+-]\d\d:\d\d", stamp)
    parsed = datetime.fromisoformat(stamp)
    assert parsed.utcoffset() is not None
    assert abs((datetime.now().astimezone() - parsed).total_seconds()) < 5


def test_format_colors():
    assert csvio.format_colors(((230, 159, 0), (86, 180, 233))) == "#E69F00/#56B4E9"
    assert csvio.format_colors(("orange", "Sky Blue")) == "#E69F00/#56B4E9"
    assert csvio.format_colors("orange/blue") == "#E69F00/#0072B2"
    assert csvio.format_colors(["#e69f00", "#0072b2"]) == "#E69F00/#0072B2"
    for bad in [("orange",), ("orange", "mauve"), ((256, 0, 0), (0, 0, 0)), ((1, 2), "blue")]:
        with pytest.raises(GoniometerError):
            csvio.format_colors(bad)


# --------------------------------------------------------------------------- the rule column


def test_rule_and_stability_columns_round_trip():
    text = csvio.format_measurements_csv([good_row(), good_row(rule="paper", stability=None)])
    back = csvio.parse_measurements_csv(text)
    assert back[0] == good_row()
    assert back[1].rule == "paper" and back[1].stability is None
    by_column = dict(zip(csvio.EXPORT_COLUMNS, cells(text)[1], strict=True))
    assert by_column["Rule"] == "oriented"
    assert by_column["Convexity"] == "concave"
    assert by_column["Stability"] == "0.4123"


def test_replication_keeps_the_rule_each_row_was_taken_with():
    text = csvio.format_measurements_csv([good_row(rule="paper"), good_row(rule="oriented")])
    assert [row.rule for row in csvio.read_replication_csv(text)] == ["paper", "oriented"]


def test_files_from_before_the_rule_replicate_with_the_papers_rule():
    assert {r.rule for r in csvio.read_replication_csv(MESHLAB_FILE)} == {"paper"}
    assert {r.rule for r in csvio.read_replication_csv(OLD_ADDON_FILE)} == {"paper"}
    old_columns = [c for c in csvio.EXPORT_COLUMNS if c not in csvio.RULE_COLUMNS]
    full = cells(csvio.format_measurements_csv([good_row()]))
    keep = [csvio.EXPORT_COLUMNS.index(c) for c in old_columns]
    old_export = "\n".join(",".join(f'"{row[i]}"' for i in keep) for row in full) + "\n"
    rows = csvio.read_replication_csv(old_export)
    assert rows[0].source_format == "extension" and rows[0].rule == "paper"
    assert csvio.parse_measurements_csv(old_export)[0].rule == ""


def test_points_files_take_the_default_rule_or_their_own():
    assert csvio.read_replication_csv("x,y,z\n1,2,3\n")[0].rule is None
    rows = csvio.read_replication_csv("x,y,z,rule\n1,2,3,Paper\n1,2,3,\n")
    assert [r.rule for r in rows] == ["paper", None]
    raises_with("x,y,z,rule\n1,2,3,literal\n", "row 2", "unknown rule 'literal'")


# --------------------------------------------------------------------------- break numbers


@pytest.mark.parametrize("cell", ["2147483648", "99999999999999999999", "abc", "1.5", "0", "-1"])
def test_a_break_number_that_blender_cannot_store_is_refused(cell):
    text = f"x,y,z,Break #\n1,2,3,2\n4,5,6,{cell}\n"
    with pytest.raises(GoniometerError) as info:
        csvio.read_replication_csv(text)
    message = str(info.value)
    assert "nothing was read" in message
    assert f"row 3: Break # must be a whole number from 1 to 2147483647 (got '{cell}')" in message
    assert "row 2" not in message


def test_break_numbers_at_the_limits_and_blank():
    text = "x,y,z,Break #\n1,2,3,1\n4,5,6,2147483647\n7,8,9,\n"
    rows = csvio.read_replication_csv(text)
    assert [row.break_number for row in rows] == [1, 2**31 - 1, None]


def test_an_integer_too_long_for_python_is_a_clear_problem():
    digits = "9" * 5000  # int() refuses text this long
    rows = csvio.read_replication_csv(f"x,y,z,Measurement #\n1,2,3,{digits}\n")
    assert rows[0].number is None  # Measurement # is informative only: not a number then
    with pytest.raises(GoniometerError, match="row 2: Break # must be a whole number"):
        csvio.read_replication_csv(f"x,y,z,Break #\n1,2,3,{digits}\n")


def test_an_export_written_before_the_precision_column_still_reads_back():
    text = csvio.format_measurements_csv([good_row(precision="float64")])
    header, row = csv.reader(io.StringIO(text))
    at = header.index("Precision")
    assert row[at] == "float64"
    stream = io.StringIO()
    csv.writer(stream, lineterminator="\n").writerows(
        cells[:at] + cells[at + 1 :] for cells in (header, row)
    )
    (read,) = csvio.read_measurements_csv(stream.getvalue())
    assert read.precision == "" and read.angle == good_row().angle


# --------------------------------------------------------------------------- edge profiles


def test_station_rows_carry_their_edge_and_replicate_with_it(tmp_path):
    station = good_row(edge_number=3, arc_length=1.2345678901234567, spacing=0.5)
    single = good_row(number=2)
    path = tmp_path / "m.csv"
    csvio.write_measurements_csv(path, [station, single])
    back = csvio.read_measurements_csv(path)
    assert (back[0].edge_number, back[0].arc_length, back[0].spacing) == (
        3,
        station.arc_length,
        0.5,
    )
    assert (back[1].edge_number, back[1].arc_length, back[1].spacing) == (None, None, None)
    rows = csvio.read_replication_csv(path)
    assert (rows[0].edge_number, rows[0].arc_length, rows[0].spacing) == (
        3,
        station.arc_length,
        0.5,
    )
    assert rows[1].edge_number is None


def test_an_export_from_before_the_edge_columns_still_reads():
    old_columns = [c for c in csvio.EXPORT_COLUMNS if c not in csvio.LATER_COLUMNS]
    written = cells(csvio.format_measurements_csv([good_row()]))
    keep = [i for i, c in enumerate(written[0]) if c in old_columns]
    text = "\n".join(",".join(f'"{line[i]}"' for i in keep) for line in written) + "\n"
    (row,) = csvio.read_measurements_csv(text)
    assert row.angle == good_row().angle and row.edge_number is None


def test_edge_summary_file_round_trips_beside_the_export(tmp_path):
    points = [(0.1, -2.0, 1e-17), (3.0, 4.0, 5.123456789012345)]
    edge = csvio.EdgeRow(
        mesh_name="bone_12",
        date="2024-05-01T14:03:11+02:00",
        edge_number=1,
        break_number=4,
        colors="#E69F00/#0072B2",
        n_stations=12,
        spacing=0.5,
        radius=3.0,
        lam=2.0,
        patch="euclidean",
        length=5.75,
        mean=101.25,
        std=0.3,
        min=100.5,
        max=102.0,
        pooled_angle=101.2,
        pooled_fit=0.004,
        points=csvio.format_points(points),
        units="BU",
    )
    path = csvio.edges_path_for(tmp_path / "m.csv")
    assert path.name == "m_edges.csv"
    csvio.write_edges_csv(path, [edge])
    (back,) = csvio.read_edges_csv(path)
    assert back == edge
    assert csvio.parse_points(back.points) == points
    assert path.read_text().split("\n")[0] == ",".join(csvio.EDGE_COLUMNS)
    assert csvio.is_edges_csv(path)
    assert not csvio.is_edges_csv(csvio.format_measurements_csv([good_row()]))
    with pytest.raises(GoniometerError, match="three numbers"):
        csvio.parse_points("1 2")
