"""A coloured point list (``X,Y,Z,R,G,B``, as CloudCompare and MeshLab write one): its ``R`` is
red, not the patch radius, so its rows have no radius of their own and take the run's."""

import pytest

from vg_addon import GoniometerError
from vg_addon.formats import csvio
from vg_addon.workflow import batchplan


@pytest.mark.parametrize(
    "header", ["X,Y,Z,R,G,B", "x,y,z,r,g,b", "x, y, z, R , G , B ", "r,g,b,x,y,z", "X,Y,Z,B,G,R"]
)
def test_red_beside_green_and_blue_is_a_colour_not_a_radius(header):
    values = {"x": "1.5", "y": "2.5", "z": "3.5", "r": "200", "g": "10", "b": "10"}
    row = ",".join(values[name.strip().lower()] for name in header.split(","))
    rows = csvio.read_replication_csv(f"{header}\n{row}\n")
    # Before: a radius of 200, measured with no word said.
    assert [(r.x, r.y, r.z, r.radius) for r in rows] == [(1.5, 2.5, 3.5, None)]


def test_r_alone_or_beside_one_colour_is_still_the_radius():
    assert csvio.read_replication_csv("x,y,z,r\n1,2,3,0.5\n")[0].radius == 0.5
    assert csvio.read_replication_csv("x,y,z,r,g\n1,2,3,0.5,9\n")[0].radius == 0.5


def test_a_radius_column_beside_a_colour_is_read():
    rows = csvio.read_replication_csv("x,y,z,Radius,R,G,B\n1,2,3,0.5,200,10,10\n")
    assert rows[0].radius == 0.5


def test_a_colour_red_cell_is_never_checked_as_a_radius():
    # Red 0 is a colour; as a radius it was refused ("must be greater than 0").
    assert csvio.read_replication_csv("X,Y,Z,R,G,B\n1,2,3,0,0,0\n")[0].radius is None


def test_a_batch_run_takes_its_own_radius_or_says_the_rows_have_none():
    rows = csvio.read_replication_csv("X,Y,Z,R,G,B\n1,2,3,200,10,10\n")
    with pytest.raises(GoniometerError, match=r"1 row\(s\) of 'points.csv' have no radius"):
        batchplan.plan_rows([["bone"]], rows, source="'points.csv'")
    tasks = batchplan.plan_rows([["bone"]], rows, radius=0.5, source="'points.csv'")
    assert [(t.radius, t.default_radius) for t in tasks] == [(0.5, True)]
