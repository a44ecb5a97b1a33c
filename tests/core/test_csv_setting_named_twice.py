"""A points header that names one setting twice, by two of its names (``lambda`` and
``SegParam``): refused, as a column named twice alike is. Before, the first name the reader
knows was measured and the other column ignored without a word. So is a column named like a
setting that the reader would not take (``Radius (mm)``)."""

import pytest

from vg_addon import GoniometerError
from vg_addon.formats import csvio


@pytest.mark.parametrize(
    ("header", "row", "columns"),
    [
        ("x,y,z,lambda,SegParam", "0,0,0,3,2", "4 ('lambda') and 5 ('SegParam')"),
        ("x,y,z,patch radius,radius", "0,0,0,0.3,0.5", "4 ('patch radius') and 5 ('radius')"),
        ("x,y,z,Center X", "0,0,0,5", "1 ('x') and 4 ('Center X')"),
        ("x,y,z,Patch,Patch Mode", "0,0,0,euclidean,geodesic", "4 ('Patch') and 5"),
    ],
)
def test_a_setting_given_by_two_of_its_names_is_refused(header, row, columns):
    with pytest.raises(GoniometerError, match="nothing was read") as refusal:
        csvio.read_replication_csv(f"{header}\n{row}\n")
    assert f"columns {columns}" in str(refusal.value)
    assert "keep one of them" in str(refusal.value)


def test_other_columns_given_twice_are_read_as_before():
    """A label beside a note, or two break numbers, decide nothing measured: the first name the
    reader knows is read, as before."""
    rows = csvio.read_replication_csv("x,y,z,Label,Note,Break #,break\n1,2,3,a,b,4,5\n")
    assert (rows[0].label, rows[0].break_number) == ("a", 4)


@pytest.mark.parametrize(
    ("header", "row", "columns"),
    [
        ("x,y,z,Mesh Name,Object", "1,2,3,m,o", "4 ('Mesh Name') and 5 ('Object')"),
        ("Object,Mesh Name,x,y,z", "o,m,1,2,3", "1 ('Object') and 2 ('Mesh Name')"),
        ("x,y,z,Edge #,edge,Arc Length", "1,2,3,1,2,0.5", "4 ('Edge #') and 5 ('edge')"),
    ],
)
def test_a_mesh_name_or_edge_number_given_twice_is_refused(header, row, columns):
    """The mesh name picks the mesh a row is measured on, and the edge number whether it is a
    station: an object beside a mesh name was read as the mesh name alone, without a word."""
    with pytest.raises(GoniometerError, match="nothing was read") as refusal:
        csvio.read_replication_csv(f"{header}\n{row}\n")
    assert f"columns {columns}" in str(refusal.value)


def test_an_edge_number_a_spreadsheet_wrote_as_a_decimal_is_the_edge():
    text = "x,y,z,Edge #,Arc Length,Spacing\n1,2,3,1.0,0.5,0.25\n1,2,4,2,0.75,0.25\n"
    assert [row.edge_number for row in csvio.read_replication_csv(text)] == [1, 2]


def test_one_name_per_setting_reads_as_before():
    rows = csvio.read_replication_csv("x,y,z,SegParam,Radius,Patch Mode\n1,2,3,2,0.4,geodesic\n")
    assert (rows[0].lam, rows[0].radius, rows[0].patch) == (2.0, 0.4, "geodesic")


@pytest.mark.parametrize(
    ("header", "column", "words"),
    [
        ("x,y,z,Radius (mm)", "4 ('Radius (mm)')", "the radius of each row"),
        ("x,y,z,radius,Lambda λ", "5 ('Lambda λ')", "the λ (SegParam) of each row"),
        ("x,y,z,Patch Mode [euclidean/geodesic]", "4 ", "the patch mode of each row"),
        ("Mesh File:,x,y,z", "1 ('Mesh File:')", "the mesh name of each row"),
        ("x,y,z,radius_mm", "4 ('radius_mm')", "the radius of each row"),
        ("x,y,z,Break # [1-9]", "4 ('Break # [1-9]')", "the break number of each row"),
    ],
)
def test_a_column_named_like_a_setting_but_not_read_is_refused(header, column, words):
    """A header's names are matched whole: ``Radius (mm)`` was passed over without a word, and
    with a default radius set every row was measured with it instead of its own (0.25 for
    0.15 and 0.4, exit 0). Refused, naming the column and what to call it."""
    with pytest.raises(GoniometerError, match="nothing was read") as refusal:
        csvio.read_replication_csv(f"{header}\n{','.join(['0'] * (header.count(',') + 1))}\n")
    assert f"column {column}" in str(refusal.value)
    assert words in str(refusal.value) and "would not be read" in str(refusal.value)


def test_columns_not_named_like_a_setting_are_still_passed_over():
    """Names that only start like a setting's hold something else: the report's own ``Break
    Type``, a second radius, a note (a review found them refused by a first version)."""
    header = "x,y,z,Angle (deg),notes on break,Break Type,Radius 2,Patch Size,Edge Length,Radius"
    rows = csvio.read_replication_csv(f"{header}\n1,2,3,90,a,spiral,9,4,3,0.5\n")
    assert rows[0].radius == 0.5 and rows[0].label is None and rows[0].break_number is None
