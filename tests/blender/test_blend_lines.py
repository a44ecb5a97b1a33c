"""Which Blender lines open a .blend written by this one (the claim in docs/BATCH.md and the
manifest's comment): 4.x lines write the classic format every claimed line reads; 5.x lines write
the new format that only 4.5 LTS and newer read. Checked with every other line's bpy module that
scripts/setup.sh made (.venv, .venv-bpy42, .venv-bpy45, .venv-bpy53), each opening the file in a
subprocess and reading the measurements back without the extension (as stored ID properties)."""

import json
import re
import subprocess
import textwrap

import bpy
import pytest
from bpy_helpers import exact, wedge_object
from conftest import ROOT

ENVIRONMENTS = (".venv", ".venv-bpy42", ".venv-bpy45", ".venv-bpy53")

READ = textwrap.dedent(
    """
    import json, os, sys
    import bpy

    report = {"version": list(bpy.app.version)}
    try:
        bpy.ops.wm.open_mainfile(filepath=sys.argv[1])
    except RuntimeError as error:
        report["error"] = str(error)
    else:
        obj = bpy.data.objects["Wedge"]
        # 5.x keeps registered properties apart from the user's custom properties.
        system = getattr(obj, "bl_system_properties_get", None)
        props = system() if system is not None else obj
        stored = props.get("vg", {}).get("measurements", []) if props is not None else []
        report["exact"] = [item["exact"] for item in stored]
    print("REPORT " + json.dumps(report), flush=True)
    os._exit(0)  # the 4.x bpy modules can crash or hang at interpreter exit
    """
)


def opens(writer: tuple, reader: tuple) -> bool:
    """The documented rule: a 5.x file needs 4.5 or newer; a 4.x file opens in every line."""
    return writer < (5, 0, 0) or reader >= (4, 5, 0)


def other_lines():
    found = []
    for name in ENVIRONMENTS:
        python = ROOT / name / "bin" / "python"
        if python.exists():
            found.append(python)
    return found


def test_a_saved_blend_opens_in_the_lines_the_docs_say(vg, tmp_path):
    readers = other_lines()
    if len(readers) < 2:
        pytest.skip("needs the other Blender lines' environments: bash scripts/setup.sh all")
    obj = wedge_object(100.0)
    bpy.ops.vg.measure_xyz(location=(0, 0, 0), radius=0.5)
    recorded = [obj.vg.measurements[0].exact]
    assert exact(obj.vg.measurements[0])["radius"] == 0.5
    path = tmp_path / "written.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    writer = tuple(bpy.app.version)
    header = path.read_bytes()[:17]
    seen = {}
    for python in readers:
        result = subprocess.run(
            [str(python), "-c", READ, str(path)],
            capture_output=True,
            text=True,
            timeout=300,
            check=False,
        )
        line = next((x for x in result.stdout.splitlines() if x.startswith("REPORT ")), None)
        assert line is not None, result.stdout + result.stderr
        report = json.loads(line[7:])
        reader = tuple(report["version"])
        seen[reader] = "error" not in report
        if opens(writer, reader):
            assert report.get("exact") == recorded, (writer, reader, report)
        else:
            assert "error" in report, (writer, reader, report)
    # The format change is the header: "BLENDER-v4xx" before 5.0, "BLENDER17-01v05xx" after.
    if writer < (5, 0, 0):
        assert re.match(rb"BLENDER[-_][vV]\d{3}", header), header
    assert len(seen) >= 2, seen
