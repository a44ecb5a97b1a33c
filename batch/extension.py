"""The extension a batch run measures with: this package's saved data, registered once for the
process.

``vg_batch.py`` imports the package (or finds the copy Blender already runs). A batch run needs
only what holds and keeps measurements: the PropertyGroups saved in the .blend (``Object.vg``,
``Scene.vg_settings``) and the watcher that keeps a measured mesh's geometry between rows. No
operator, panel, tool or draw handler is registered: the batch reaches the bridge directly, as
the operators do.
"""

from __future__ import annotations

import sys
import traceback
from pathlib import Path

import addon_utils
import bpy

from .. import properties
from ..bridge import measuring, mesh_data, watch

PACKAGE_NAME = __name__.rpartition(".")[0].rpartition(".")[0]
EXTENSION_ID = "virtual_goniometer"

# Whether this process registered the data (unregistered before it ends: the bpy 4.2 module
# crashes at exit while Python classes are still registered).
_active = False


def package_folder() -> Path:
    """The folder of this extension package (the repository root, or the installed copy)."""
    return Path(sys.modules[PACKAGE_NAME].__file__).resolve().parent


def activate() -> None:
    """Register this package's data unless Blender already runs the extension; switch off any
    other copy.

    Another copy (e.g. an installed older version) would own the ``vg.*`` names: it is disabled
    for this session only (``default_set=False`` leaves the user's preferences as they are).
    """
    global _active
    if PACKAGE_NAME in bpy.context.preferences.addons or _active:
        return
    for name in list(bpy.context.preferences.addons.keys()):
        if name.rpartition(".")[2] == EXTENSION_ID and name != PACKAGE_NAME:
            addon_utils.disable(name, default_set=False)
    properties.register()
    watch.register()
    _active = True


def deactivate() -> None:
    """Unregister what :func:`activate` registered (at the end of the process)."""
    global _active
    if not _active:
        return
    _active = False
    try:
        watch.unregister()
        properties.unregister()
    except Exception:
        traceback.print_exc()
    mesh_data.clear_cache()
    measuring.clear_cache()
