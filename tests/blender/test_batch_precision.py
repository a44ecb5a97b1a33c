"""Float64 mesh files in batch runs: measured at the file's own coordinates (Blender's float32
mesh would round them), and the CSV's Precision column says which coordinates were measured."""

from __future__ import annotations

import bpy
import numpy as np
import pytest
from bpy_helpers import batch, exact, mesh_object

from vg_addon import Surface
from vg_addon.formats import csvio, meshio
from vg_addon.synthetic_meshes import wedge


@pytest.mark.parametrize(
    "offset",
    [(1000.0, 2000.0, 50.0), (500_000.0, 4_000_000.0, 100.0)],
    ids=["kilometre", "UTM-like"],
)
def test_a_float64_file_far_from_the_origin_is_measured_at_its_precision(tmp_path, offset):
    shape = wedge(90.0, n=24, irregular=True, seed=3)
    points = shape.points + np.array(offset)
    assert not np.array_equal(points.astype(np.float32).astype(np.float64), points)
    path = meshio.write_ply(tmp_path / "far.ply", points, shape.triangles)
    at = [repr(float(v)) for v in np.add(offset, (0.05, 0.0, 0.0))]
    out = tmp_path / "out.csv"
    result = batch(path, "--at", *at, "--radius", "0.3", "--out", out)
    assert result.returncode == 0, result.stderr
    (row,) = csvio.read_measurements_csv(out)
    # The oracle: the core on the file's own float64 coordinates and triangles.
    m = Surface(points, shape.triangles).measure([float(v) for v in at], 0.3)
    assert abs(row.angle - 90.0) < 1e-6
    assert row.angle == m.angle and (row.x, row.y, row.z) == tuple(m.center)
    assert row.precision == "float64"


def test_a_file_that_float32_holds_exactly_is_measured_as_blender_stores_it(tmp_path):
    shape = wedge(90.0, n=24, irregular=True, seed=3)
    points = shape.points.astype(np.float32).astype(np.float64)
    path = meshio.write_ply(tmp_path / "near.ply", points, shape.triangles)
    out = tmp_path / "out.csv"
    result = batch(path, "--at", "0.05", "0", "0", "--radius", "0.3", "--out", out)
    assert result.returncode == 0, result.stderr
    (row,) = csvio.read_measurements_csv(out)
    assert row.precision == "float32"
    assert row.angle == Surface(points, shape.triangles).measure([0.05, 0, 0], 0.3).angle


@pytest.mark.parametrize(
    "offset",
    [(1000.0, 2000.0, 50.0), (500_000.0, 5_000_000.0, 100.0)],
    ids=["kilometre", "UTM-like"],
)
def test_edge_stations_of_a_float64_file_are_measured_at_its_precision(tmp_path, offset):
    shape = wedge(60.0, n=40)
    points = shape.points + np.array(offset)
    path = meshio.write_ply(tmp_path / "far.ply", points, shape.triangles)
    ends = [repr(float(v)) for end in ((-0.4, 0, 0), (0.4, 0, 0)) for v in np.add(offset, end)]
    out = tmp_path / "out.csv"
    result = batch(path, "--at", *ends[:3], "--edge", *ends, "--spacing", "0.2", "--radius",
                   "0.3", "--out", out)  # fmt: skip
    assert result.returncode == 0, result.stderr
    rows = csvio.read_measurements_csv(out)
    stations = [row for row in rows if row.edge_number]
    assert len(stations) >= 4 and {row.precision for row in rows} == {"float64"}
    # The oracle: the core's profile on the file's own float64 coordinates, bit for bit.
    profile = Surface(points, shape.triangles).measure_along(
        [[float(v) for v in ends[:3]], [float(v) for v in ends[3:]]], 0.2, 0.3
    )
    assert [row.angle for row in stations] == profile.angles.tolist()
    assert max(abs(row.angle - 60.0) for row in stations) < 1e-6


def test_a_replication_at_another_precision_says_its_angles_differ_and_why(vg, tmp_path, capfd):
    """Blender holds vertices as float32, so a batch row measured at a file's float64 precision
    comes back a little different when the CSV is imported there. It once did so in silence.
    Oracle: the core on the float32-rounded coordinates, and the file's own angle."""
    shape = wedge(90.0, n=24, irregular=True, seed=3)
    points = shape.points + np.array([1000.0, 2000.0, 50.0])
    path = meshio.write_ply(tmp_path / "far.ply", points, shape.triangles)
    at = [repr(float(v)) for v in np.add((1000.0, 2000.0, 50.0), (0.05, 0.0, 0.0))]
    out = tmp_path / "out.csv"
    assert batch(path, "--at", *at, "--radius", "0.3", "--out", out).returncode == 0
    (row,) = csvio.read_measurements_csv(out)
    rounded = points.astype(np.float32).astype(np.float64)
    in_float32 = Surface(rounded, shape.triangles).measure([row.x, row.y, row.z], 0.3).angle
    assert row.precision == "float64" and in_float32 != row.angle
    bpy.ops.wm.read_homefile(use_empty=True)
    obj = mesh_object("far", points, shape.triangles)
    capfd.readouterr()
    bpy.ops.vg.import_csv(filepath=str(out))
    assert exact(obj.vg.measurements[0])["angle"] == in_float32
    said = capfd.readouterr()
    assert (
        f"1 of 1 angles differ from the file's, by up to {abs(in_float32 - row.angle):.2g}° "
        "(1 measured at another precision than the file's"
    ) in said.out + said.err
    again = tmp_path / "again.csv"
    bpy.ops.vg.export_csv(filepath=str(again))
    bpy.ops.vg.import_csv(filepath=str(again))
    said = capfd.readouterr()
    assert "all 1 angles equal the file's exactly" in said.out + said.err
    # The batch says the same of its own CSV, and of Blender's float32 rows on the float64 file.
    replay = tmp_path / "replay.csv"
    result = batch(path, "--points", out, "--out", replay)
    assert "re-measured out.csv: all 1 angles equal the file's exactly" in result.stderr
    result = batch(path, "--points", again, "--out", replay)
    assert result.returncode == 0, result.stderr
    assert (
        f"re-measured again.csv: 1 of 1 angles differ from the file's, by up to "
        f"{abs(in_float32 - row.angle):.2g}° (1 measured at another precision"
    ) in result.stderr
