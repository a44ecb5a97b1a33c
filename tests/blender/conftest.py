"""Blender-side test setup: a throwaway Blender user directory, the extension built and installed
into it as a user would (Install from Disk), and a fresh empty file for every test.

``BLENDER_USER_RESOURCES`` is read once, when ``bpy`` is imported, so it is set here, before any
test module of this folder imports bpy. The whole folder skips where bpy is not installed.
"""

import atexit
import importlib
import os
import shutil
import sys
import tempfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

if "bpy" in sys.modules:
    _USER_DIR = None  # imported earlier by someone else: too late to redirect it
else:
    _USER_DIR = tempfile.mkdtemp(prefix="vg-blender-user-")
    os.environ["BLENDER_USER_RESOURCES"] = _USER_DIR
    atexit.register(shutil.rmtree, _USER_DIR, ignore_errors=True)

bpy = pytest.importorskip("bpy", reason="the bpy module (Blender as a Python module) is needed")

# The processes the tests start (batch runs, workers, map children) make their temporary files,
# Blender's session folder among them, here: a test that kills one with SIGKILL on purpose would
# otherwise leave its folder in the machine's temporary folder. This process's own are made
# where they were (tempfile has already chosen its folder, bpy has made its session folder).
_CHILDREN_TEMP = tempfile.mkdtemp(prefix="vg-blender-tests-")
for _name in ("TMPDIR", "TEMP", "TMP"):
    os.environ[_name] = _CHILDREN_TEMP
atexit.register(shutil.rmtree, _CHILDREN_TEMP, ignore_errors=True)

import addon_utils  # noqa: E402  (Blender's, importable once bpy is)

REPO = "user_default"
MODULE = f"bl_ext.{REPO}.virtual_goniometer"


@pytest.fixture(scope="session")
def installed_extension(extension_zip):
    """The extension installed from its zip into the throwaway user directory and enabled."""
    extensions = Path(bpy.utils.user_resource("EXTENSIONS"))
    if _USER_DIR is None or not extensions.is_relative_to(_USER_DIR):
        pytest.skip(
            "bpy was imported before tests/blender/conftest.py could point "
            "BLENDER_USER_RESOURCES at a throwaway directory; refusing to install into "
            f"{extensions}"
        )
    bpy.ops.extensions.package_install_files(
        filepath=str(extension_zip), repo=REPO, enable_on_install=True
    )
    assert (extensions / REPO / "virtual_goniometer" / "blender_manifest.toml").is_file()
    yield importlib.import_module(MODULE)
    # Blender 4.2's bpy module crashes at interpreter exit while add-on classes are still
    # registered; a user's Blender unregisters on quit, so do the same.
    if MODULE in bpy.context.preferences.addons:
        addon_utils.disable(MODULE, default_set=True, handle_error=_raise)


def enable_extension() -> None:
    """Enable the installed extension if a test left it disabled."""
    if MODULE not in bpy.context.preferences.addons:
        addon_utils.enable(MODULE, default_set=True, handle_error=_raise)


def _raise(error):
    raise error


@pytest.fixture
def vg(installed_extension):
    """The enabled extension's root module, in a fresh empty Blender file.

    After the test, every record left in the file is checked to carry the content id of what
    it holds (0 only for records from older versions' files): painting after an undo
    recognises records by it, so a write that changes a record without stamping it would
    paint the old content."""
    enable_extension()
    bpy.ops.wm.read_homefile(use_empty=True)
    yield installed_extension
    enable_extension()
    records = importlib.import_module(f"{MODULE}.bridge.records")
    for obj in bpy.data.objects:
        for item in getattr(getattr(obj, "vg", None), "measurements", ()):
            assert item.content_id in (0, records.content_id(item)), (obj.name, item.number)


_exit_status = {"code": 0}


def pytest_sessionfinish(session, exitstatus):
    _exit_status["code"] = int(exitstatus)


def pytest_unconfigure(config):
    """The 4.x bpy modules can fail while the interpreter shuts down, after every test has run
    and pytest has printed its summary: 4.2 crashes (SIGSEGV), 4.5 hangs for ever (a static
    destructor waits on the thread that closes files read in the background, once a .blend has
    been read). End the process with pytest's own status instead; the 5.x lines exit cleanly and
    are left alone. Blender's session folder is removed first, as Blender's own exit would."""
    if bpy.app.version < (5, 0, 0):
        session = Path(bpy.app.tempdir or ".").resolve()
        if session.name.startswith("blender_"):
            shutil.rmtree(session, ignore_errors=True)
        for folder in (_CHILDREN_TEMP, _USER_DIR):  # os._exit runs no atexit handler
            if folder:
                shutil.rmtree(folder, ignore_errors=True)
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(_exit_status["code"])
