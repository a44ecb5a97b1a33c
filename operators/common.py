"""What every measuring operator shares, defined once: the property sets (mixins) and their
refusals, the panel defaults, ``poll()`` and typed values.

A negative radius, λ or spacing is refused by the measuring code with the value as given
("radius must be a finite number greater than 0; got -1.0"), never clamped to 0 by the property:
so every such property has a ``soft_min`` (the slider's floor), never a ``min``.
"""

from __future__ import annotations

import contextlib

import bpy
import numpy as np
from bpy.props import BoolProperty, EnumProperty, FloatProperty, FloatVectorProperty

from ..bridge.mesh_data import check_measurable
from ..properties import PATCH_ITEMS, RULE_ITEMS
from ..vg_addon import GoniometerError

SPACE_ITEMS = (
    ("WORLD", "World", "World space, where the object is now (the 3D cursor's coordinates)"),
    ("MESH", "Mesh", "The mesh's own coordinates (object space: those of its file and the CSV)"),
)


def absolute_path(path: str) -> str:
    """A file or folder path an operator was given, made absolute; ``""`` when none was given.

    Raises
    ------
    GoniometerError
        A path relative to the .blend file (``//``) while the file has never been saved: it
        would silently mean the process's working folder.
    """
    if path.startswith("//") and not bpy.data.filepath:
        raise GoniometerError(
            f"{path!r} is relative to the .blend file ('//'), but this file has not been saved "
            "yet: save the .blend file first, or choose a full path."
        )
    return bpy.path.abspath(path) if path else ""


def length_property(name: str, description: str):
    """A length in the mesh's units whose negative values are refused as given, not clamped.

    A plain number, as the panel's fields are: with Blender's length unit the Adjust Last
    Operation panel showed a radius of 5 (mm, the panel's) as "5 m", and "5 mm" typed there was
    stored as 0.005.
    """
    return FloatProperty(name=name, description=description, soft_min=0.0, precision=4)


class LocationProperties:
    """Where to measure: a point and the coordinates it is given in (default: the 3D cursor)."""

    location: FloatVectorProperty(
        name="Location",
        description="Centre to measure at (snaps to the nearest vertex), in the coordinates "
        "chosen by Space; default: the 3D cursor",
        size=3,
        subtype="TRANSLATION",
        unit="LENGTH",
    )
    space: EnumProperty(
        name="Space",
        items=SPACE_ITEMS,
        default="WORLD",
        description="The coordinates Location is given in",
    )


class PatchProperties:
    """How each patch is measured: radius, λ and patch mode (defaults: the panel's)."""

    radius: length_property(
        "Radius", "Patch radius, in the mesh's own units; default: the panel's radius"
    )
    seg_param: FloatProperty(
        name="λ (SegParam)",
        description="Segmentation parameter; default: the panel's",
        soft_min=0.0,
    )
    patch: EnumProperty(name="Patch", items=PATCH_ITEMS, description="Default: the panel's")


class RuleProperties:
    """How each measurement is taken: its rule and whether its stability figure is computed
    (defaults: the panel's)."""

    rule: EnumProperty(name="Rule", items=RULE_ITEMS, description="Default: the panel's")
    stability: BoolProperty(
        name="Stability", description="Compute the stability figure; default: the panel's"
    )


def typed_value(value: float) -> float:
    """The float64 of the shortest decimal that a 32-bit operator property rounds to ``value``.

    Operator properties are 32-bit, so a typed 0.1 arrives as 0.10000000149...; measuring with
    0.1 instead keeps the recorded radius (and CSV) equal to what the user typed.
    """
    return float(str(np.float32(value)))


def defaults_from_panel(operator, context, settings_of: dict) -> None:
    """Give each operator property the caller did not set (a key of ``settings_of``) the value
    of its panel setting (the value); an unset ``location`` is the 3D cursor, in world space."""
    given = operator.properties.is_property_set
    settings = context.scene.vg_settings
    for name, setting in settings_of.items():
        if not given(name):
            setattr(operator, name, getattr(settings, setting))
    if "location" in operator.properties.bl_rna.properties and not given("location"):
        operator.location = context.scene.cursor.location
        operator.space = "WORLD"


#: The panel settings an edge-measuring operator takes by default: ``defaults_from_panel``'s
#: ``settings_of`` for ``spacing``, the patch properties and the rule properties.
EDGE_SETTINGS = {
    "spacing": "edge_spacing",
    "radius": "radius",
    "seg_param": "seg_param",
    "patch": "patch",
    "rule": "rule",
    "stability": "stability",
}


#: The panel settings Find Break Edges takes by default for its detector's parameters.
FIND_SETTINGS = {
    "scale": "find_scale",
    "min_length": "find_min_length",
    "min_bend": "find_min_bend",
}


def clear_texts(area, workspace) -> None:
    """Remove a modal session's header text (``area``) and status-bar hints (``workspace``);
    either may be None or already gone."""
    for clear in (
        lambda: area.header_text_set(None),
        lambda: area.tag_redraw(),
        lambda: workspace.status_text_set(None),
    ):
        with contextlib.suppress(AttributeError, ReferenceError):  # None, or already gone
            clear()


def poll_measurable(cls, context) -> bool:
    """``poll()`` of operators that need a measurable active mesh; the reason it is not goes
    to the button's tooltip."""
    try:
        check_measurable(context.active_object)
    except GoniometerError as error:
        cls.poll_message_set(str(error))
        return False
    return True


def poll_measured(cls, context) -> bool:
    """``poll()`` of operators that need a measurable active mesh with measurements."""
    if not poll_measurable(cls, context):
        return False
    if not len(context.active_object.vg.measurements):
        cls.poll_message_set(f"'{context.active_object.name}' has no measurements yet.")
        return False
    return True


def status_hints(hints):
    """A status-bar draw function (for ``WorkSpace.status_text_set``) showing ``hints``, pairs
    of (icons, text) such as ``(("MOUSE_LMB",), "Measure")``, as Blender's own modal tools do."""

    def draw(header, context):
        row = header.layout.row(align=True)
        for icons, text in hints:
            for icon in icons:
                row.label(text="", icon=icon)
            row.label(text=text)
            row.separator(factor=2.0)

    return draw
