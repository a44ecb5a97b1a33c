"""The extension a batch run measures with: this package, registered once for the process.

``vg_batch.py`` imports the package (or finds the copy Blender already runs); registering it
here gives the batch the same operators, properties and pipeline a user's Blender has.
"""

from __future__ import annotations

import sys
import traceback
from pathlib import Path

import addon_utils
import bpy

PACKAGE_NAME = __name__.rpartition(".")[0].rpartition(".")[0]
EXTENSION_ID = "virtual_goniometer"

# Packages registered by this process, unregistered before it ends: the bpy 4.2 module crashes
# at exit while Python classes are still registered.
_registered: list = []


def package_folder() -> Path:
    """The folder of this extension package (the repository root, or the installed copy)."""
    return Path(sys.modules[PACKAGE_NAME].__file__).resolve().parent


def activate() -> None:
    """Register this package unless Blender already runs it; switch off any other copy.

    Another copy (e.g. an installed older version) would own the ``vg.*`` names: it is disabled
    for this session only (``default_set=False`` leaves the user's preferences as they are).
    """
    if PACKAGE_NAME in bpy.context.preferences.addons or _registered:
        return
    for name in list(bpy.context.preferences.addons.keys()):
        if name.rpartition(".")[2] == EXTENSION_ID and name != PACKAGE_NAME:
            addon_utils.disable(name, default_set=False)
    package = sys.modules[PACKAGE_NAME]
    package.register()
    _registered.append(package)


def deactivate() -> None:
    """Unregister what :func:`activate` registered (at the end of the process)."""
    while _registered:
        try:
            _registered.pop().unregister()
        except Exception:
            traceback.print_exc()
