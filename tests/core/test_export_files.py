"""An export's measurement CSV and the edge summary beside it are written as one record: never a
summary listing edges the CSV no longer has, never a CSV replaced when its summary cannot be."""

from pathlib import Path

import pytest

from vg_addon import GoniometerError
from vg_addon.formats import csvio
from vg_addon.formats.csvio import EdgeRow, MeasurementRow

ROWS = [MeasurementRow(mesh_name="bone", number=1, break_number=1, angle=97.5, radius=2.0)]
STATION = MeasurementRow(mesh_name="bone", number=2, break_number=1, angle=96.0, edge_number=1)
EDGE = EdgeRow(mesh_name="bone", edge_number=1, break_number=1, n_stations=1, mean=96.0)


def test_an_export_with_edges_writes_both(tmp_path):
    out = tmp_path / "site.csv"
    summary = csvio.write_export(out, [*ROWS, STATION], [EDGE])
    assert summary == tmp_path / "site_edges.csv"
    assert [r.edge_number for r in csvio.read_edges_csv(summary)] == [1]
    assert len(csvio.read_measurements_csv(out)) == 2


def test_an_export_without_edges_empties_an_earlier_summary(tmp_path):
    # Before: the earlier summary stayed, listing edge 1, and importing it brought the edge back.
    out = tmp_path / "site.csv"
    csvio.write_export(out, [*ROWS, STATION], [EDGE])
    summary = csvio.write_export(out, ROWS, [])
    assert summary == tmp_path / "site_edges.csv"
    assert summary.read_text(encoding="utf-8") == csvio.format_edges_csv([])
    assert [r.edge_number for r in csvio.read_measurements_csv(out)] == [None]


def test_an_export_without_edges_makes_no_summary_unless_asked(tmp_path):
    out = tmp_path / "site.csv"
    assert csvio.write_export(out, ROWS, []) is None
    assert sorted(p.name for p in tmp_path.iterdir()) == ["site.csv"]
    assert csvio.write_export(out, ROWS, [], summary=True) == tmp_path / "site_edges.csv"
    assert csvio.read_edges_csv(tmp_path / "site_edges.csv") == []


def test_a_summary_that_cannot_be_written_leaves_the_csv_as_it_was(tmp_path):
    # Before: the CSV was replaced first, then the summary failed, and the message said the CSV
    # "was not written".
    out = tmp_path / "site.csv"
    out.write_text("the earlier export\n", encoding="utf-8")
    (tmp_path / "site_edges.csv").mkdir()
    with pytest.raises(GoniometerError, match="folder"):
        csvio.write_export(out, [*ROWS, STATION], [EDGE])
    assert out.read_text(encoding="utf-8") == "the earlier export\n"


def test_a_folder_named_like_a_summary_is_no_reason_to_refuse_an_export_without_edges(tmp_path):
    out = tmp_path / "site.csv"
    Path(tmp_path / "site_edges.csv").mkdir()
    assert csvio.write_export(out, ROWS, []) is None
    assert len(csvio.read_measurements_csv(out)) == 1


def test_edge_rows_read_back_carry_their_spreadsheet_rows_blank_lines_counted(tmp_path):
    # Import messages name these rows; before, they counted the rows read (blank lines left out),
    # so a fault on spreadsheet row 5 was reported on row 4.
    text = csvio.format_edges_csv([EDGE, EDGE])
    header, first, second = text.splitlines()
    path = tmp_path / "site_edges.csv"
    path.write_text(f"{header}\n{first}\n\n{second}\n", encoding="utf-8")
    assert [row.row_number for row in csvio.read_edges_csv(path)] == [2, 4]
    assert csvio.read_edges_csv(path) == [EDGE, EDGE]  # the number is not part of the row


def test_a_file_named_like_a_summary_that_is_not_one_is_left_alone(tmp_path):
    # A points list or the user's notes named site_edges.csv: not an earlier export's to empty
    # (a first version of write_export emptied any file of that name, a --points input too).
    out = tmp_path / "site.csv"
    points = tmp_path / "site_edges.csv"
    points.write_text("x,y,z,radius,label\n0,0,0,0.3,my point\n", encoding="utf-8")
    assert csvio.write_export(out, ROWS, []) is None
    assert points.read_text(encoding="utf-8") == "x,y,z,radius,label\n0,0,0,0.3,my point\n"
    assert not csvio.holds_edge_summary(points)


@pytest.mark.parametrize("summary", [True, False], ids=["a run with edges", "an export with edges"])
def test_an_export_with_edges_refuses_to_replace_a_file_that_is_not_a_summary(tmp_path, summary):
    """The user's notes named site_edges.csv: an export with edges replaced them (before). Now
    nothing is written, and the message names the file; an empty file is no one's notes."""
    out = tmp_path / "site.csv"
    notes = tmp_path / "site_edges.csv"
    notes.write_text("my notes, not a summary\n", encoding="utf-8")
    edges = [] if summary else [EDGE]
    with pytest.raises(GoniometerError, match="lacks Edge #, Points and Spacing"):
        csvio.write_export(out, [*ROWS, STATION], edges, summary=summary)
    assert notes.read_text(encoding="utf-8") == "my notes, not a summary\n"
    assert not out.exists()
    # A summary re-saved with semicolons is not read as one: refused, saying so.
    notes.write_text("Edge #;Points;Spacing\n1;0 0 0;1\n", encoding="utf-8")
    with pytest.raises(GoniometerError, match="semicolon"):
        csvio.write_export(out, [*ROWS, STATION], edges, summary=summary)
    for blank in (b"", b"\n", b"\r\n", b"\xef\xbb\xbf", b"\xef\xbb\xbf  \r\n"):  # no one's notes
        notes.write_bytes(blank)
        assert csvio.write_export(out, [*ROWS, STATION], edges, summary=summary) == notes
        assert csvio.is_edges_csv(notes)
