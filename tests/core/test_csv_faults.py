"""CSV faults from the second fault hunt (issues 24 and 25): a bad row never costs a good row,
a quote left open never swallows the rows after it silently, a path is never read as CSV text,
and every CSV the product writes reads back to the same rows."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from vg_addon import GoniometerError
from vg_addon.formats import csvio
from vg_addon.formats.csvio import MeasurementRow


def edge_row(**given) -> csvio.EdgeRow:
    values = {
        "mesh_name": "bone",
        "edge_number": 1,
        "n_stations": 3,
        "spacing": 0.5,
        "radius": 0.3,
        "lam": 2.0,
        "patch": "euclidean",
        "points": "0.0 0.0 0.0; 1.0 0.0 0.0",
    }
    return csvio.EdgeRow(**(values | given))


@pytest.mark.parametrize("bad", ["nan", "inf", "-inf", "NaN"])
def test_a_non_finite_point_in_an_edges_csv_is_refused_with_its_row(bad):
    text = csvio.format_edges_csv([edge_row(), edge_row(points=f"0 0 0; {bad} 0 0", edge_number=2)])
    with pytest.raises(GoniometerError, match=r"row 3: Points") as caught:
        csvio.read_edges_csv(text)
    assert "finite" in str(caught.value)
    with pytest.raises(GoniometerError, match="finite"):
        csvio.parse_points(f"0 0 0; {bad} 0 0")


@pytest.mark.parametrize("kind", ["edges", "measurements"])
def test_a_coordinates_cell_is_mesh_or_world_in_any_case_and_nothing_else(kind):
    """Before, an edges CSV's "World" or "foo" was read as it stood, and the import took any
    cell but "world" for mesh coordinates: a world-space edge would be traced at the wrong
    place. Now the case is folded, an empty cell means world (as a file without the column),
    and any other word is refused with its row."""
    if kind == "edges":
        fmt, read = csvio.format_edges_csv, csvio.read_edges_csv
        row = edge_row()
    else:
        fmt, read = csvio.format_measurements_csv, csvio.read_measurements_csv
        row = MeasurementRow(mesh_name="a", angle=90.0, radius=0.3, x=0.0, y=0.0, z=0.0)
    text = fmt([row, dataclasses.replace(row, coordinates="world")])
    assert [r.coordinates for r in read(text)] == ["mesh", "world"]
    for cell, read_as in (("World", "world"), ("MESH", "mesh"), ("", "world")):
        edited = text.replace(",world,", f",{cell},", 1)
        assert [r.coordinates for r in read(edited)] == ["mesh", read_as]
    with pytest.raises(GoniometerError, match=r"row 3: Coordinates is 'foo', not mesh or world"):
        read(text.replace(",world,", ",foo,", 1))


def test_a_row_that_cannot_be_written_costs_only_itself():
    good = MeasurementRow(mesh_name="a", angle=90.0, radius=0.3, x=0.0, y=0.0, z=0.0)
    bad = MeasurementRow(mesh_name="b", requested=(math.nan, 0.0, 0.0), radius=0.3, error="x")
    odd = MeasurementRow(mesh_name="caf\udce9", angle=80.0, radius=0.3)  # a surrogate: not UTF-8
    kept = [csvio.writable_row(row) for row in (good, bad, odd)]
    assert kept[0] == good
    assert kept[1].requested is None and kept[1].radius == 0.3
    assert kept[1].error.startswith("x; ") and "Requested" in kept[1].error
    assert kept[2].mesh_name == "caf\ufffd" and kept[2].angle == 80.0 and kept[2].error
    text = csvio.format_measurements_csv(kept)
    assert [row.mesh_name for row in csvio.read_measurements_csv(text)] == ["a", "b", "caf\ufffd"]
    edge = csvio.writable_row(edge_row(mean=math.inf))
    assert edge.mean is None and "Mean Angle" in edge.error


@pytest.mark.parametrize(
    "text, line",
    [
        ('x,y,z,label\n0,0,0,"note\n1,0,0,b\n2,0,0,c\n3,0,0,d\n', 2),
        ('x,y,z,label\n0,0,0,a\n\n1,0,0,"note\n2,0,0,b\n3,0,0,"c"\n', 4),
    ],
    ids=["to the end", "closed by a later quote"],
)
def test_an_unclosed_quote_is_refused_with_the_line_where_it_opens(text, line):
    with pytest.raises(GoniometerError, match=rf"line {line}\b.*quote") as caught:
        csvio.read_replication_csv(text)
    assert "nothing was read" in str(caught.value).lower()
    export = csvio.format_measurements_csv([MeasurementRow(mesh_name="a", x=0.0, y=0.0, z=0.0)])
    broken = export.replace("\na,", '\n"a,', 1) + export.split("\n", 1)[1]
    with pytest.raises(GoniometerError, match="quote"):
        csvio.read_measurements_csv(broken)


def test_an_unclosed_quote_before_rows_with_columns_left_out_is_refused():
    """Rows that leave optional columns out have fewer cells than the header: a quote left open
    before them must still not swallow them (the file ends inside the quote)."""
    text = 'x,y,z,radius,label\n0,0,0,1,"open\n1,0,0\n2,0,0\n'
    with pytest.raises(GoniometerError, match="quote"):
        csvio.read_replication_csv(text)


def test_notes_with_many_commas_over_several_lines_still_read():
    """What the product writes, and what a hand-written file with a well-closed note holds, reads
    back, however many commas a note's lines hold."""
    note = "first line\n" + ", ".join(f"point {k}" for k in range(60))
    rows = [MeasurementRow(mesh_name="a", user_data=note, x=0.0, y=0.0, z=0.0)]
    text = csvio.format_measurements_csv(rows * 2)
    assert [row.user_data for row in csvio.read_measurements_csv(text)] == [note, note]
    assert [row.label for row in csvio.read_replication_csv(text)] == [note, note]
    hand = 'x,y,z,label\n0,0,0,"two lines\nsee: a, b, c, d"\n1,0,0,plain\n'
    assert [row.label for row in csvio.read_replication_csv(hand)] == [
        "two lines\nsee: a, b, c, d",
        "plain",
    ]


def test_a_note_written_over_several_lines_still_reads():
    rows = [MeasurementRow(mesh_name="a", user_data="two\nlines, one comma", x=0.0, y=0.0, z=0.0)]
    (back,) = csvio.read_replication_csv(csvio.format_measurements_csv(rows))
    assert back.label == "two\nlines, one comma"


def test_a_path_with_a_line_break_is_read_as_a_path(tmp_path):
    folder = tmp_path / "two\nlines"
    folder.mkdir()
    points = folder / "points.csv"
    points.write_text("x,y,z\n1,2,3\n", encoding="utf-8")
    (row,) = csvio.read_replication_csv(str(points))
    assert (row.x, row.y, row.z) == (1.0, 2.0, 3.0)
    edges = folder / "e_edges.csv"
    csvio.write_edges_csv(edges, [edge_row()])
    assert csvio.read_edges_csv(str(edges))[0].points == edge_row().points
    assert csvio.is_edges_csv(str(edges))
    export = folder / "m.csv"
    csvio.write_measurements_csv(export, [MeasurementRow(mesh_name="a", x=0.0, y=0.0, z=0.0)])
    assert csvio.read_measurements_csv(str(export))[0].mesh_name == "a"
    with pytest.raises(FileNotFoundError):
        csvio.read_replication_csv(str(folder / "missing\n.csv"))


@pytest.mark.parametrize("name", [" lead", "trail ", " both  "])
def test_mesh_names_with_surrounding_spaces_read_back_as_written(name):
    row = MeasurementRow(mesh_name=name, x=0.5, y=0.0, z=0.0, radius=0.3)
    (back,) = csvio.read_replication_csv(csvio.format_measurements_csv([row]))
    assert back.mesh_name == name
    assert csvio.mesh_name_matches(back.mesh_name, (name,))
    assert csvio.mesh_name_matches(f"{name}.ply", (name,))
    # A hand-typed name with stray spaces still finds its mesh.
    assert csvio.mesh_name_matches(f" {name.strip()} ", (name.strip(),))
    edges = csvio.format_edges_csv([edge_row(mesh_name=name)])
    assert csvio.read_edges_csv(edges)[0].mesh_name == name


def test_a_mesh_name_written_in_another_unicode_normalisation_finds_its_mesh():
    """macOS keeps file names decomposed (``e`` and a combining accent); a CSV typed elsewhere
    holds the composed ``é``. The two look alike, and the batch refused the row, naming the
    mesh 'café' as not among ('café'). Now it finds the mesh, after an exact name."""
    from vg_addon.workflow.batchplan import closest_mesh

    composed, decomposed = "caf\u00e9", "cafe\u0301"
    assert csvio.mesh_name_matches(composed, (decomposed,))
    assert csvio.mesh_name_matches(f"scans/{decomposed}.ply", (composed,))
    assert not csvio.mesh_name_matches("cafe", (composed,))
    assert closest_mesh(composed, [(decomposed,), ("other",)], "row 2") == (0, "")
    assert closest_mesh(composed, [(decomposed,), (composed,)], "row 2") == (1, "")


def test_the_rows_of_a_written_csv_read_back_to_the_same_rows():
    rows = [
        MeasurementRow(mesh_name=name, user_data=note, x=0.5, y=0.0, z=0.0, radius=0.3)
        for name, note in [(" a", "=1+1"), ("b ", " spaced "), ("c\td", "x\ny")]
    ]
    back = csvio.read_measurements_csv(csvio.format_measurements_csv(rows))
    assert [dataclasses.replace(r, date="") for r in back] == rows


def test_an_edge_of_many_points_reads_back_and_leaves_the_csv_modules_cap_alone():
    """An edge from a picked-points file of 20,000 points: its Points cell (about 1.2 million
    characters) is far over the csv module's default cap of 131,072 per cell, which refused
    the file the batch had just written. Read back exactly; the process-wide cap is restored."""
    import csv

    rng = np.random.default_rng(7)
    points = rng.normal(size=(20_000, 3)) * 1e3
    cell = csvio.format_points(points)
    assert len(cell) > 8 * 131_072
    cap = csv.field_size_limit()
    text = csvio.format_edges_csv([edge_row(points=cell), edge_row(edge_number=2)])
    rows = csvio.read_edges_csv(text)
    assert [row.edge_number for row in rows] == [1, 2]
    assert np.array_equal(np.array(csvio.parse_points(rows[0].points)), points)
    assert csv.field_size_limit() == cap
