"""The bpy module where matplotlib, SciPy and statsmodels are not installed (Blender's own Python,
a distribution's Blender): the edge plot and the radius sweep are drawn by the extension's NumPy
drawing, the Report operator and ``vg_batch.py --report`` say what is missing and how to get it
and write nothing, and measuring goes on as before.

The harness hides the packages (``tests/hide_modules.py``); the shipped code has no switch."""

import struct
import textwrap

from bpy_helpers import batch
from conftest import MODULE, REPO, ROOT
from hide_modules import environment, run_reporting

from vg_addon.formats import meshio
from vg_addon.synthetic_meshes import wedge

HIDDEN = ("matplotlib", "scipy", "statsmodels")

SCENE = textwrap.dedent(
    """
    import json, os, sys
    import bpy

    bpy.ops.extensions.package_install_files(
        filepath=sys.argv[1], repo=sys.argv[2], enable_on_install=True
    )
    ops = bpy.ops.vg
    from vg_addon.synthetic_meshes import varying_wedge
    shape = varying_wedge(80.0, 120.0, half_width=2.0, depth=1.0, n=20)
    mesh = bpy.data.meshes.new("Ramp")
    mesh.from_pydata(shape.points.tolist(), [], shape.triangles.tolist())
    obj = bpy.data.objects.new("Ramp", mesh)
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    out = sys.argv[3]
    report = {"measured": sorted(ops.measure_xyz(location=(0.0, 0.0, 0.0), radius=0.3))}
    report["edge"] = sorted(ops.measure_edge(
        points=json.dumps([[-1.5, 0.01, 0.0], [0.0, -0.01, 0.0], [1.5, 0.0, 0.0]]),
        spacing=0.5,
        radius=0.3,
    ))
    edge = obj.vg.edges[0]
    report["edge_plot"] = list(bpy.data.images[edge.plot].size)
    bpy.context.scene.cursor.location = (0.0, 0.0, 0.0)
    report["sweep"] = sorted(ops.radius_sweep(
        filepath=os.path.join(out, "sweep.csv"), start=0.1, stop=0.5, count=5
    ))
    settings = bpy.context.scene.vg_settings
    settings.report_folder = os.path.join(out, "report")
    try:
        ops.report(directory=out, files=[])
        report["report"] = "ran"
    except RuntimeError as error:
        report["report"] = str(error)
    report["imported"] = sorted(
        name for name in sys.modules if name.split(".")[0] in {"matplotlib", "scipy", "statsmodels"}
    )
    print("REPORT " + json.dumps(report), flush=True)
    sys.stderr.flush()
    os._exit(0)  # Blender 4.2's bpy module can crash at interpreter exit
    """
)


def png_size(path) -> tuple[int, int]:
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", data[16:24])


def test_in_blender_the_plots_fall_back_and_the_report_says_what_to_install(
    extension_zip, tmp_path
):
    out = tmp_path / "out"
    out.mkdir()
    env = environment(tmp_path / "hide", HIDDEN)
    env["PYTHONPATH"] += f":{ROOT}"  # vg_addon for the test's wedge
    env["BLENDER_USER_RESOURCES"] = str(tmp_path / "user")
    result, report = run_reporting(SCENE, extension_zip, REPO, out, env=env)
    output = result.stdout + result.stderr
    assert report["measured"] == report["edge"] == report["sweep"] == ["FINISHED"], report
    assert report["edge_plot"] == [480, 240]
    assert png_size(out / "sweep.png") == (640, 430)  # the NumPy drawing's size
    assert "this Python has no matplotlib" in output  # the sweep's INFO line says so, and how
    assert "python3-matplotlib" in output
    assert "The report needs scipy, statsmodels, matplotlib" in report["report"], report
    assert "pip install scipy statsmodels matplotlib" in report["report"]
    assert "vg_batch.py --report" in report["report"]
    assert not (out / "report").exists()
    assert report["imported"] == []
    frames = [line for line in result.stderr.splitlines() if line.strip().startswith('File "')]
    assert not [f for f in frames if MODULE in f or "bl_ext" in f], output


def test_the_batch_draws_its_plots_and_refuses_the_report_clearly(tmp_path):
    shape = wedge(110, n=40, irregular=True, seed=3, concave=True)
    path = tmp_path / "valley.ply"
    meshio.write_ply(path, shape.points, shape.triangles)
    env = environment(tmp_path / "hide", HIDDEN)
    run = batch(path, "--at", "0.01", "0", "0", "--radius", "0.5", "--sweep", "0.1", "0.6", "6",
                "--out", tmp_path / "angles.csv", env={"PYTHONPATH": env["PYTHONPATH"]})  # fmt: skip
    assert run.returncode == 0, run.stdout + run.stderr
    assert png_size(tmp_path / "angles_sweep" / "valley_1.png") == (640, 430)
    report = batch("--report", tmp_path / "report", tmp_path / "angles.csv",
                   env={"PYTHONPATH": env["PYTHONPATH"]})  # fmt: skip
    assert report.returncode == 2, report.stdout + report.stderr
    assert "The report needs scipy, statsmodels, matplotlib" in report.stderr
    assert "pip install scipy statsmodels matplotlib" in report.stderr
    assert "Traceback" not in report.stderr
    assert not (tmp_path / "report").exists()
