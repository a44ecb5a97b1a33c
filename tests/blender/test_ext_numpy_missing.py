"""A Blender whose Python has no NumPy (a Linux distribution's Blender without python3-numpy):
enabling the extension registers an explanation with the fix instead of failing on the import.

The harness, not the extension, hides NumPy: a ``sitecustomize`` on the subprocess's path makes
every ``import numpy`` fail as it fails where NumPy is not installed.
"""

import os
import textwrap

from bpy_helpers import batch
from conftest import MODULE, REPO, ROOT
from hide_modules import run_reporting

HIDE_NUMPY = textwrap.dedent(
    """
    import sys

    class HideNumpy:
        def find_spec(self, name, path=None, target=None):
            if name == "numpy" or name.startswith("numpy."):
                raise ModuleNotFoundError(f"No module named {name!r}", name=name)
            return None

    sys.meta_path.insert(0, HideNumpy())
    """
)

ENABLE = textwrap.dedent(
    """
    import json, os, sys
    import bpy
    import addon_utils

    bpy.ops.extensions.package_install_files(
        filepath=sys.argv[1], repo=sys.argv[2], enable_on_install=True
    )
    module = sys.modules.get(sys.argv[3])
    report = {
        "enabled": sys.argv[3] in bpy.context.preferences.addons,
        "numpy_imported": "numpy" in sys.modules,
        "explanation_panel": hasattr(bpy.types, "VIEW3D_PT_vg_numpy_missing"),
        "measure_operator": hasattr(bpy.types, "VG_OT_measure_xyz"),
        "preferences": getattr(
            bpy.context.preferences.addons.get(sys.argv[3]), "preferences", None
        ) is not None,
        "lines": module.numpy_missing.message_lines("No module named 'numpy'") if module else [],
    }
    addon_utils.disable(sys.argv[3], default_set=True)
    report["unregistered"] = not hasattr(bpy.types, "VIEW3D_PT_vg_numpy_missing")
    print("REPORT " + json.dumps(report), flush=True)
    sys.stderr.flush()
    os._exit(0)  # Blender 4.2's bpy module can crash at interpreter exit
    """
)


def test_enabling_without_numpy_explains_the_fix(extension_zip, tmp_path):
    harness = tmp_path / "harness"
    harness.mkdir()
    (harness / "sitecustomize.py").write_text(HIDE_NUMPY, encoding="utf-8")
    user = tmp_path / "user"
    user.mkdir()
    env = {
        **os.environ,
        "PYTHONPATH": str(harness),
        "BLENDER_USER_RESOURCES": str(user),
    }
    result, report = run_reporting(ENABLE, extension_zip, REPO, MODULE, env=env)
    output = result.stdout + result.stderr
    assert report["enabled"] and not report["numpy_imported"], report
    assert report["explanation_panel"] and report["preferences"], report
    assert not report["measure_operator"], report
    assert report["unregistered"], report
    # Printed when it was enabled, and what the panel and preferences show: the cause and the fix.
    assert "Virtual Goniometer needs NumPy" in result.stderr, output
    assert "No module named 'numpy'" in result.stderr, output
    assert "sudo apt install python3-numpy" in result.stderr, output
    # No traceback runs through the extension (bpy 5.x itself prints one for its own optional
    # NumPy import at start-up, before any extension is loaded).
    frames = [line for line in result.stderr.splitlines() if line.strip().startswith('File "')]
    assert not [f for f in frames if "virtual_goniometer" in f or "bl_ext" in f], output
    assert any("sudo apt install python3-numpy" in line for line in report["lines"])


def test_batch_without_numpy_says_why_and_exits_2(tmp_path):
    harness = tmp_path / "harness"
    harness.mkdir()
    (harness / "sitecustomize.py").write_text(HIDE_NUMPY, encoding="utf-8")
    mesh = tmp_path / "tri.obj"
    mesh.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", encoding="ascii")
    out = tmp_path / "out.csv"
    result = batch(
        mesh, "--at", "0", "0", "0", "--radius", "1", "--out", out,
        env={"PYTHONPATH": str(harness)}, timeout=300,
    )  # fmt: skip
    assert result.returncode == 2, result.stdout + result.stderr
    assert "vg_batch: error: Virtual Goniometer needs NumPy" in result.stderr
    assert "sudo apt install python3-numpy" in result.stderr
    frames = [line for line in result.stderr.splitlines() if line.strip().startswith('File "')]
    assert not [f for f in frames if str(ROOT) in f], result.stderr
    assert not out.exists()
