"""The measurement export: schema, bit-exact round trips, formula guard, atomic writer, and
the edge summary file written beside it."""

import csv
import io
import math
import os
import re
from datetime import datetime

import pytest
from csv_rows import MESHLAB_HEADER, OUR_EXTRA_COLUMNS, bits, cells, good_row
from hypothesis import given, settings
from hypothesis import strategies as st

from vg_addon import GoniometerError
from vg_addon.formats import csvio
from vg_addon.formats.csvio import MeasurementRow

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


@pytest.mark.parametrize("stem", ["m" * 251, "é" * 125 + "m"])
def test_a_name_as_long_as_the_disk_takes_is_written_and_rewritten(tmp_path, stem):
    """A 255-byte name (the limit of most disks): its hidden temporary name was longer, and
    the write failed with "File name too long"."""
    path = tmp_path / f"{stem}.csv"
    assert len(path.name.encode()) == 255
    for number in (1, 2):
        csvio.write_measurements_csv(path, [good_row(number=number)])
        assert csvio.read_measurements_csv(path)[0].number == number
    assert [p.name for p in tmp_path.iterdir()] == [path.name]


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


@pytest.mark.parametrize("closed", [True, False])
def test_a_station_says_whether_its_edge_is_a_loop_and_an_empty_cell_says_nothing(tmp_path, closed):
    station = good_row(edge_number=3, arc_length=0.25, spacing=0.5, edge_closed=closed)
    path = tmp_path / "m.csv"
    csvio.write_measurements_csv(path, [station, good_row(number=2)])
    header, first, second = cells(path.read_text(encoding="utf-8"))
    at = header.index("Edge Closed")
    assert (first[at], second[at]) == ("TRUE" if closed else "FALSE", "")
    back = csvio.read_measurements_csv(path)
    assert (back[0].edge_closed, back[1].edge_closed) == (closed, None)
    rows = csvio.read_replication_csv(path)
    assert (rows[0].edge_closed, rows[1].edge_closed) == (closed, None)
    first[at] = "perhaps"
    stream = io.StringIO()
    csv.writer(stream, lineterminator="\n").writerows([header, first])
    for read in (csvio.read_measurements_csv, csvio.read_replication_csv):
        with pytest.raises(GoniometerError, match="row 2: Edge Closed is not TRUE or FALSE"):
            read(stream.getvalue())


def test_an_export_from_before_the_edge_columns_still_reads():
    old_columns = [c for c in csvio.EXPORT_COLUMNS if c not in csvio.LATER_COLUMNS]
    written = cells(csvio.format_measurements_csv([good_row()]))
    keep = [i for i, c in enumerate(written[0]) if c in old_columns]
    text = "\n".join(",".join(f'"{line[i]}"' for i in keep) for line in written) + "\n"
    (row,) = csvio.read_measurements_csv(text)
    assert row.angle == good_row().angle and row.edge_number is None
    assert row.edge_closed is None


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
        rule="oriented",
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
    # A rule no version wrote is refused, naming its row; a file without the column reads.
    text = path.read_text()
    with pytest.raises(GoniometerError, match="row 2: Rule: unknown rule 'steep'"):
        csvio.parse_edges_csv(text.replace(",oriented,", ",steep,"))
    header, line = text.splitlines()
    at = header.split(",").index("Rule")
    older = "\n".join(
        ",".join(c for i, c in enumerate(r.split(",")) if i != at) for r in (header, line)
    )
    (old,) = csvio.parse_edges_csv(older)
    assert old.rule == "" and old.points == edge.points
