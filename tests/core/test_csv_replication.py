"""The replication reader: MeshLab's, the earlier add-on's and points files, every bad input
refused with its row and column, mesh names, the rule and break numbers of each row."""

import csv
import io

import pytest
from csv_rows import MESHLAB_HEADER, cells, good_row, raises_with

from vg_addon import GoniometerError
from vg_addon.formats import csvio
from vg_addon.formats.csvio import MeasurementRow, ReplicationRow

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


@pytest.mark.parametrize("note", [" lead", "trail ", "two\nlines\n", "\x0bvt", "=1+1"])
def test_a_note_is_read_back_as_written_to_be_recorded_again(note):
    # Re-measuring records the note again; before, it lost its surrounding spaces and line ends.
    text = csvio.format_measurements_csv([good_row(user_data=note)])
    assert csvio.read_measurements_csv(text)[0].user_data == note  # the export reader's
    assert csvio.read_replication_csv(text)[0].label == note


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


def test_excels_separator_line_is_not_a_header(tmp_path):
    """Excel writes and hides a first line "sep=," (before: "missing x, y, z (found: 'sep=')").
    Rows are numbered as Excel shows them; a "sep=;" file is named as semicolon-separated."""
    path = tmp_path / "points.csv"
    path.write_bytes(b"\xef\xbb\xbfsep=,\r\nx,y,z,label\r\n1,2,3,first\r\n")
    assert csvio.read_replication_csv(path) == [
        ReplicationRow(2, None, 1.0, 2.0, 3.0, label="first")
    ]
    with pytest.raises(GoniometerError, match="semicolon"):
        csvio.read_replication_csv("sep=;\nx;y;z\n1;2;3\n")


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


@pytest.mark.parametrize("written, read", [("812.0", 812), ("812.00", 812), ("8.12e2", 812)])
def test_whole_numbers_resaved_as_floats_read_as_whole_numbers(written, read):
    """pandas and R write a column with blanks (Edge # of single measurements) as floats."""
    text = csvio.format_measurements_csv([good_row()]).replace(",812,", f",{written},", 1)
    assert csvio.read_measurements_csv(text)[0].n_vertices == read


@pytest.mark.parametrize(
    "written", ["812.5", "1e300", "811.99999999999999999", "812.0000000000000001"]
)
def test_a_fraction_or_a_huge_float_in_a_whole_number_column_is_refused(written):
    """Exactly whole, not whole once rounded to a float."""
    text = csvio.format_measurements_csv([good_row()]).replace(",812,", f",{written},", 1)
    with pytest.raises(GoniometerError, match=r"row 2: Number of Vertices is not a whole number"):
        csvio.read_measurements_csv(text)


@pytest.mark.parametrize(
    ("forms", "read"),
    [
        (("10000000000000000", "1e16", "1.0e16", "10000000000000000.0"), 10**16),
        (("999999999999999999", "999999999999999999.0"), 10**18 - 1),
        (("1000000000000000000", "1e18", "1.0e18"), None),
    ],
)
def test_a_whole_number_reads_alike_however_it_is_written(forms, read):
    """Up to 18 digits, a whole number is read whether written as digits or as a float (a table
    tool's re-save); beyond, it is refused in every form. Once ``1e16`` was refused while its
    digits were read."""
    from vg_addon.formats.csvio.text import whole_cell

    assert [whole_cell(form) for form in forms] == [read] * len(forms)


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


# --------------------------------------------------------------------------- the rule column


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


def test_a_row_never_measured_without_a_rule_takes_the_default_rule_not_the_papers():
    """A batch run's failed row was written with an empty Rule; the reader took that for an
    export of before the Rule column and retried the row with the paper's rule (a concave 100°
    edge read 125.98°). A measured row whose Rule was emptied (its Convexity filled) still
    takes the paper's, as the replay's report says."""
    never = good_row(rule="", convexity="", angle=None)
    emptied = good_row(rule="")
    rows = csvio.read_replication_csv(
        csvio.format_measurements_csv([never, emptied, good_row(rule="oriented")])
    )
    assert rows[0].source_format == "extension"
    assert [row.rule for row in rows] == [None, "paper", "oriented"]
    # A MeshLab file with a Rule column added (no Convexity: nothing says a row was not measured)
    meshlab = csvio.format_measurements_csv([good_row(user_data="note")]).splitlines()
    header, row = (line.split(",")[:14] for line in meshlab[:2])
    (added,) = csvio.read_replication_csv(",".join([*header, "Rule"]) + "\n" + ",".join([*row, ""]))
    assert added.rule == "paper"


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


@pytest.mark.parametrize(("written", "read"), [("2.0", 2), ("2", 2), ("", None)])
def test_a_break_number_resaved_as_a_float_is_that_break_when_re_measured(written, read):
    text = f"Mesh Name,x,y,z,Break #\nbone,1,2,3,{written}\n"
    assert csvio.read_replication_csv(text)[0].break_number == read


@pytest.mark.parametrize("written", ["2.5", "0.0", "1e12"])
def test_a_break_number_that_is_not_a_whole_number_from_1_is_refused(written):
    with pytest.raises(GoniometerError, match="Break # must be a whole number from 1"):
        csvio.read_replication_csv(f"Mesh Name,x,y,z,Break #\nbone,1,2,3,{written}\n")


def test_requested_centres_are_read_where_their_snap_distance_is_theirs():
    """An export's Requested x/y/z are where the user asked, kept where the row's Snap Distance
    is their distance from x, y, z; a row whose x, y, z were edited since asks for those."""
    header = "Mesh Name,x,y,z,Requested x,Requested y,Requested z,Snap Distance\n"
    rows = csvio.read_replication_csv(
        header
        + "b,1,2,3,1.1,2,3,0.1\n"  # as exported: 0.1 from x, y, z
        + "b,1,2,3,,,,\n"  # no requested centre
        + "b,1,2,3.5,1.1,2,3,0.1\n"  # x, y, z edited: the snap distance is no longer theirs
        + "b,1,2,3,1,2,3,0\n"  # asked for at the vertex itself
    )
    assert [r.requested for r in rows] == [(1.1, 2.0, 3.0), None, None, (1.0, 2.0, 3.0)]
    # Where it was asked for is not what is measured: incomplete, such a row asks for x, y, z.
    rows = csvio.read_replication_csv(header + "b,1,2,3,1.1,,3,0.1\nb,1,2,3,a,2,3,0.1\n")
    assert [(r.requested, r.x) for r in rows] == [(None, 1.0), (None, 1.0)]
