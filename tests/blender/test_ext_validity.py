"""Issue 8 in the extension: the rule, the convex/concave label, the stability figure, the winding
notice and the radius sweep, each against the core measuring the same world-space mesh."""

import csv
import json
import zlib

import bpy
import numpy as np
import pytest
from bpy_helpers import exact, local_points, mesh_object, wedge_object, world

from vg_addon import Surface
from vg_addon.formats import csvio, mpl_plots
from vg_addon.synthetic_meshes import bone_fragment, wedge


def concave_wedge_object(angle, name="Valley"):
    """The object, and the core's Surface of the float32 coordinates Blender stores for it."""
    shape = wedge(angle, n=40, irregular=True, seed=2, concave=True)
    obj = mesh_object(name, shape.points, shape.triangles)
    return obj, Surface(world(local_points(obj), obj), shape.triangles)


def test_concave_edge_is_measured_labelled_and_given_a_stability_figure(vg):
    obj, surface = concave_wedge_object(120.0)
    assert bpy.ops.vg.measure_xyz(location=(0.01, 0, 0), radius=0.5) == {"FINISHED"}
    item = obj.vg.measurements[0]
    m = surface.measure([0.01, 0, 0], 0.5, stability=True)
    numbers = exact(item)
    assert numbers["angle"] == m.angle and abs(m.angle - 120.0) < 0.1
    assert (item.convexity, item.rule, numbers["rule"]) == ("concave", "refined", "refined")
    assert numbers["stability"]["spread"] == m.stability.spread
    assert numbers["stability"]["bootstrap"] == m.stability.bootstrap
    assert item.stability_text == m.stability.text()


def test_paper_rule_and_no_stability_from_the_panel(vg):
    obj, surface = concave_wedge_object(90.0)
    settings = bpy.context.scene.vg_settings
    settings.rule, settings.stability = "paper", False
    bpy.ops.vg.measure_xyz(location=(0.01, 0, 0), radius=0.5)
    item = obj.vg.measurements[0]
    assert exact(item)["angle"] == surface.measure([0.01, 0, 0], 0.5, rule="paper").angle
    assert exact(item)["stability"] is None and item.stability_text == "not computed"
    assert item.rule == "paper"


def test_records_from_before_the_rule_replay_with_the_papers_rule(vg, tmp_path):
    obj, _ = concave_wedge_object(90.0)
    bpy.context.scene.vg_settings.rule = "paper"
    bpy.ops.vg.measure_xyz(location=(0.01, 0, 0), radius=0.5)
    item = obj.vg.measurements[0]
    numbers = exact(item)
    for key in ("rule", "convexity", "correlation", "stability"):  # as an older version wrote
        del numbers[key]
    item.exact = json.dumps(numbers)
    assert bpy.ops.vg.repaint() == {"FINISHED"}
    assert not item.stale  # the paper's rule reproduces its patch and sides
    assert item.rule == "paper"
    path = tmp_path / "old.csv"
    bpy.ops.vg.export_csv(filepath=str(path))
    row = csvio.read_measurements_csv(path)[0]
    assert row.rule == "paper" and row.stability is None


def test_meshlab_rows_replicate_with_the_papers_rule(vg, tmp_path):
    obj, surface = concave_wedge_object(90.0)
    path = tmp_path / "meshlab.csv"
    path.write_text(
        ",".join(csvio.MESHLAB_COLUMNS) + "\nValley.ply,Tue Mar  2 14:03:11 2021,1,1,Red/Blue,,"
        "103.95,350,0.5,0.01,0,0,0.006,2\n",
        encoding="utf-8",
    )
    assert bpy.ops.vg.import_csv(filepath=str(path)) == {"FINISHED"}
    item = obj.vg.measurements[0]
    assert item.rule == "paper"
    assert exact(item)["angle"] == surface.measure([0.01, 0, 0], 0.5, rule="paper").angle


def test_inward_wound_closed_mesh_is_noticed(vg):
    bone = bone_fragment(spacing=1.5)
    obj = mesh_object("Bone", bone.points, bone.triangles[:, ::-1])
    site = bone.sites[0]
    bpy.ops.vg.measure_xyz(location=site.point, radius=4.0)
    assert obj.vg.winding == "inward"
    outward = Surface(world(local_points(obj), obj), bone.triangles).measure(site.point, 4.0)
    item = obj.vg.measurements[0]
    assert exact(item)["angle"] == pytest.approx(outward.angle, abs=1e-6)
    assert item.convexity == "concave" and outward.convexity == "convex"


def test_radius_sweep_writes_its_csv_and_png(vg, tmp_path):
    obj = wedge_object(70.0)
    bpy.context.scene.cursor.location = (0.01, 0.0, 0.0)
    path = tmp_path / "sweep.csv"
    result = bpy.ops.vg.radius_sweep(filepath=str(path), start=0.05, stop=0.6, count=6)
    assert result == {"FINISHED"}
    assert len(obj.vg.measurements) == 0  # a sweep records nothing
    with open(path, newline="", encoding="utf-8") as handle:
        rows = list(csv.DictReader(handle))
    assert [float(r["Radius"]) for r in rows] == list(np.linspace(0.05, 0.6, 6))
    assert all(abs(float(r["Angle"]) - 70.0) < 0.1 for r in rows if r["Angle"])
    obj.vg.unit = "MM"  # the unit the measurement CSV would name, on every row
    assert bpy.ops.vg.radius_sweep(filepath=str(path), start=0.05, stop=0.6, count=6) == {
        "FINISHED"
    }
    with open(path, newline="", encoding="utf-8") as handle:
        assert {r["Units"] for r in csv.DictReader(handle)} == {"mm"}
    png = path.with_suffix(".png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and zlib.crc32(png[12:29]) == int.from_bytes(
        png[29:33], "big"
    )
    image = bpy.data.images.load(str(path.with_suffix(".png")))
    # Blender itself reads the plot: matplotlib's where it runs (requirements/report.txt), else
    # the NumPy drawing (test_ext_no_matplotlib.py runs the bpy module without matplotlib).
    assert tuple(image.size) == ((800, 560) if mpl_plots.available() else (640, 430))


def test_radius_sweep_takes_unset_radii_from_the_panel(vg, tmp_path):
    wedge_object(70.0)
    bpy.context.scene.cursor.location = (0.01, 0.0, 0.0)
    settings = bpy.context.scene.vg_settings
    settings.sweep_start, settings.sweep_stop, settings.sweep_count = 0.1, 0.5, 5
    path = tmp_path / "sweep.csv"
    assert bpy.ops.vg.radius_sweep(filepath=str(path)) == {"FINISHED"}
    with open(path, newline="", encoding="utf-8") as handle:
        rows = list(csv.DictReader(handle))
    radii = np.linspace(np.float32(0.1), np.float32(0.5), 5)  # the panel keeps 32-bit floats
    np.testing.assert_allclose([float(r["Radius"]) for r in rows], radii, rtol=1e-6)
    assert all(abs(float(r["Angle"]) - 70.0) < 0.1 for r in rows if r["Angle"])
