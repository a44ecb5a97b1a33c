"""What the extension registers when Blender's Python cannot import NumPy: an explanation with
the fix, in the sidebar tab and in the extension's preferences, instead of a bare import error.

A Blender from blender.org bundles NumPy; a Linux distribution's Blender runs on the system
Python and leaves NumPy to the distribution's package. This module imports nothing but bpy.
"""

from __future__ import annotations

import sys

import bpy

_state = {"error": ""}


def message_lines(error: str) -> list[str]:
    """The explanation, one short line each (the sidebar is narrow)."""
    version = ".".join(str(part) for part in sys.version_info[:3])
    return [
        "Virtual Goniometer needs NumPy, which this Blender's",
        f"Python {version} cannot import ({error}).",
        "Blender from blender.org includes NumPy. A Linux",
        "distribution's Blender uses the system Python:",
        "install its NumPy package, then restart Blender:",
        "  Debian, Ubuntu: sudo apt install python3-numpy",
        "  Fedora: sudo dnf install python3-numpy",
        "  Arch: sudo pacman -S python-numpy",
        f"Python in use: {sys.executable}",
    ]


def message(error: str) -> str:
    """The explanation as one text (for the console and reports)."""
    return "\n".join(message_lines(error))


def _draw(layout, error: str) -> None:
    column = layout.column(align=True)
    column.label(text="NumPy is missing", icon="ERROR")
    for line in message_lines(error):
        column.label(text=line)


class VIEW3D_PT_vg_numpy_missing(bpy.types.Panel):
    """Why the Goniometer tab is empty, and the fix."""

    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Goniometer"
    bl_label = "Virtual Goniometer"

    def draw(self, context):
        _draw(self.layout, _state["error"])


class VG_numpy_missing_preferences(bpy.types.AddonPreferences):
    """Shown under the extension in Preferences, where it was just enabled."""

    bl_idname = __package__

    def draw(self, context):
        _draw(self.layout, _state["error"])


classes = (VIEW3D_PT_vg_numpy_missing, VG_numpy_missing_preferences)


def _popup() -> None:
    """Say it once, where the user is looking (a window exists only outside background mode)."""

    def draw(menu, context):
        for line in message_lines(_state["error"]):
            menu.layout.label(text=line)

    window_manager = bpy.context.window_manager
    if window_manager is None or not len(window_manager.windows):
        return
    # A timer runs without a window in its context: give it the first one.
    with bpy.context.temp_override(window=window_manager.windows[0]):
        window_manager.popup_menu(draw, title="Virtual Goniometer: NumPy is missing", icon="ERROR")


def register(error: BaseException) -> None:
    """Register the explanation for ``error`` (the failed NumPy import) and print it."""
    _state["error"] = str(error)
    for cls in classes:
        bpy.utils.register_class(cls)
    print(message(_state["error"]), file=sys.stderr)
    if not bpy.app.background:
        bpy.app.timers.register(_popup, first_interval=0.5)


def unregister() -> None:
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
