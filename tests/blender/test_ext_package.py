"""The extension package: the zip Blender's tool builds, installing it, register/unregister."""

import tomllib
import zipfile

import addon_utils
import bpy
import pytest
from bpy_helpers import wedge_object
from conftest import MODULE, ROOT, enable_extension


def test_zip_holds_the_extension_and_nothing_else(extension_zip):
    names = set(zipfile.ZipFile(extension_zip).namelist())
    left_out = {"tests", "docs", "scripts", "dist", "build", "requirements", "vg_demo_output"}
    sources = {
        path.relative_to(ROOT).as_posix()
        for path in ROOT.rglob("*.py")
        if not path.relative_to(ROOT).parts[0].startswith(".")
        and path.relative_to(ROOT).parts[0] not in left_out
        and "__pycache__" not in path.parts
    }
    assert {"__init__.py", "properties.py", "vg_addon/method/surface.py"} <= sources
    assert sources - names == set(), "source files missing from the zip"
    for needed in ("blender_manifest.toml", "LICENSE"):
        assert needed in names, needed
    for name in names:
        top = name.split("/")[0]
        assert top not in {"tests", "docs", "scripts", "dist", "requirements", ".ci", ".git"}, name
        assert "__pycache__" not in name and not name.endswith(".pyc"), name
        assert top not in {"pyproject.toml", "README.md"}, name


def test_manifest_declares_what_the_issue_asks():
    with open(ROOT / "blender_manifest.toml", "rb") as handle:
        manifest = tomllib.load(handle)
    assert manifest["id"] == "virtual_goniometer"
    assert manifest["type"] == "add-on"
    assert manifest["blender_version_min"] == "4.2.0"
    assert manifest["license"] == ["SPDX:GPL-3.0-or-later"]
    assert "CSV" in manifest["permissions"]["files"]


def _registered() -> dict:
    return {
        "operator": hasattr(bpy.types, "VG_OT_measure_xyz"),
        "panel": hasattr(bpy.types, "VIEW3D_PT_vg_measure"),
        "list": hasattr(bpy.types, "VG_UL_measurements"),
        "object_property": hasattr(bpy.types.Object, "vg"),
        "scene_property": hasattr(bpy.types.Scene, "vg_settings"),
    }


def test_installed_from_the_zip_and_enabled(installed_extension):
    enable_extension()
    assert MODULE in bpy.context.preferences.addons
    assert installed_extension.__name__ == MODULE
    assert all(_registered().values()), _registered()


@pytest.mark.parametrize("how", ["preferences", "module"])
def test_register_unregister_is_clean_and_repeatable(vg, how):
    for _ in range(3):
        if how == "preferences":
            addon_utils.disable(MODULE, default_set=True)
        else:
            vg.unregister()
        assert not any(_registered().values()), _registered()
        if how == "preferences":
            enable_extension()
        else:
            vg.register()
        assert all(_registered().values()), _registered()
    # Still usable after all that.
    obj = wedge_object(90.0)
    bpy.ops.vg.measure_xyz(location=(0, 0, 0), radius=0.5)
    assert len(obj.vg.measurements) == 1


def test_scene_settings_defaults(vg):
    settings = bpy.context.scene.vg_settings
    assert settings.seg_param == 2.0
    assert settings.patch == "euclidean"
    assert settings.radius > 0
    # In the mesh's own units, labelled with the object's Scan Units: never converted by the
    # scene's unit system (a millimetre scan in a metre scene would read 1000 times off).
    assert settings.bl_rna.properties["radius"].unit == "NONE"


def test_panels_live_in_the_goniometer_tab(vg):
    for name in (
        "VIEW3D_PT_vg_measure",
        "VIEW3D_PT_vg_selected",
        "VIEW3D_PT_vg_edges",
        "VIEW3D_PT_vg_csv",
    ):
        panel = getattr(bpy.types, name)
        assert (panel.bl_space_type, panel.bl_region_type) == ("VIEW_3D", "UI")
        assert panel.bl_category == "Goniometer"
    selected = bpy.types.VIEW3D_PT_vg_selected
    obj = wedge_object(90.0)
    assert not selected.poll(bpy.context)  # nothing measured yet
    bpy.ops.vg.measure_xyz(location=(0, 0, 0), radius=0.5)
    assert selected.poll(bpy.context)
    assert obj.vg.active_index == 0
