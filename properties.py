"""Data saved in the .blend: the panel settings (``Scene.vg_settings``) and each object's
measurements (``Object.vg``).

Blender's FloatProperty holds a 32-bit float, too coarse to replay a measurement exactly, so every
recorded number lives, exactly as float64, in the JSON text of ``VG_Measurement.exact``
(``json`` writes floats with ``repr``, which round-trips). The float properties of a measurement
(angle, radius, centre, ...) are read-only views of that text for the panel; they are computed,
not stored. Code reads and writes that text with ``vg_addon.formats.record_codec``.
"""

from __future__ import annotations

import bpy
from bpy.props import (
    BoolProperty,
    CollectionProperty,
    EnumProperty,
    FloatProperty,
    FloatVectorProperty,
    IntProperty,
    PointerProperty,
    StringProperty,
)
from bpy.types import PropertyGroup
from mathutils import Vector

from .vg_addon import palette, units
from .vg_addon.formats.record_codec import exact_numbers
from .vg_addon.method.break_edges import BreakEdgeParameters
from .vg_addon.method.result import (
    UNDETERMINED_REFUSED,
    UNSTABLE_DEGREES,
    stored_stability_text,
    stored_stability_warning,
)

# Paths may start with // (the .blend's folder); Blender 4.5 and later want that declared.
BLEND_RELATIVE = {"PATH_SUPPORTS_BLEND_RELATIVE"} if bpy.app.version >= (4, 5, 0) else set()
RULE_ITEMS = (
    (
        "refined",
        "Refined",
        "The oriented rule, then each side's plane from the vertices that lie on it: exact where "
        "the crease runs between rows of vertices (the default)",
    ),
    (
        "oriented",
        "Oriented",
        "Sign the position term by the edge's convexity: right on concave edges and on meshes "
        "wound inward (the default before the refined rule)",
    ),
    (
        "paper",
        "Paper",
        "Algorithm 1 as printed (MeshLab plugin, earlier add-on): misreads concave edges; for "
        "replicating old measurements",
    ),
)

PATCH_ITEMS = (
    ("euclidean", "Euclidean", "All vertices within the radius (a ball around the centre)"),
    ("geodesic", "Geodesic", "Vertices reachable along mesh edges within the radius"),
)


def _number(key):
    def get(self):
        value = exact_numbers(self).get(key)
        return 0.0 if value is None else float(value)  # shown undefined by the panels

    return get


def _vector(key):
    def get(self):
        value = exact_numbers(self).get(key)
        return tuple(value) if value else (0.0, 0.0, 0.0)

    return get


def _world_centre(self):
    numbers = exact_numbers(self)
    centre = numbers.get("center")
    if not centre:
        return (0.0, 0.0, 0.0)
    if numbers.get("space", "world") == "world":
        return tuple(centre)
    matrix = getattr(self.id_data, "matrix_world", None)
    if matrix is None:
        return tuple(centre)
    return tuple(matrix @ Vector(centre))


def _text_value(key, default=""):
    def get(self):
        return str(exact_numbers(self).get(key, default))

    return get


def _stability_text(self):
    return stored_stability_text(exact_numbers(self).get("stability"))


def _stability_warning(self):
    return stored_stability_warning(exact_numbers(self).get("stability"))


def _stability_part(key):
    def get(self):
        return float((exact_numbers(self).get("stability") or {}).get(key, 0.0))

    return get


def _side_colour(side):
    def get(self):
        names = self.colors.split("/")
        rgb = palette.OKABE_ITO.get(names[side].strip()) if len(names) == 2 else None
        return tuple(c / 255.0 for c in (rgb or palette.NEUTRAL_GREY))

    return get


class VG_Measurement(PropertyGroup):
    """One measurement on an object, with everything needed to redo it."""

    number: IntProperty(name="Measurement #", description="Measurement number on this object")
    break_number: IntProperty(name="Break #", description="Break this measurement belongs to")
    exact: StringProperty(
        name="Exact numbers",
        description="The measurement's float64 numbers (JSON); the source of every number shown",
        options={"HIDDEN"},
    )
    patch: EnumProperty(name="Patch", items=PATCH_ITEMS, description="How the patch was chosen")
    n_vertices: IntProperty(name="Vertices", description="Vertices in the patch")
    n_plus: IntProperty(name="Vertices +", description="Vertices on the + side")
    n_minus: IntProperty(name="Vertices −", description="Vertices on the − side")
    date: StringProperty(name="Date", description="When the measurement was taken (ISO 8601)")
    note: StringProperty(name="Note", description="Free text, exported as the CSV's User Data")
    colors: StringProperty(
        name="Colours", description="Palette colours of the + and − sides, '+ colour/− colour'"
    )
    fingerprint: StringProperty(
        name="Geometry fingerprint",
        description="Hash of the evaluated mesh the measurement was taken on",
        options={"HIDDEN"},
    )
    stale: BoolProperty(
        name="Stale",
        description="The mesh or its modifiers changed since this measurement was taken: its "
        "numbers are kept as recorded, but it is no longer painted",
    )
    edge_number: IntProperty(
        name="Edge #", description="The edge profile this measurement is a station of (0: none)"
    )
    content_id: IntProperty(
        name="Content id",
        description="A digest of the exact numbers, patch mode and fingerprint (0: not yet "
        "stamped): recognises a record restored by undo without reading it",
        options={"HIDDEN"},
    )

    # Read-only views of the exact numbers, for drawing.
    arc_length: FloatProperty(
        name="Arc length",
        description="Where this station lies along its edge's traced path",
        subtype="DISTANCE",
        unit="LENGTH",
        get=_number("arc_length"),
    )
    angle: FloatProperty(name="Angle (°)", get=_number("angle"), precision=2)
    fit_error: FloatProperty(name="Fit error", get=_number("fit"), precision=6)
    fit_error_plus: FloatProperty(name="Fit error +", get=_number("fit_plus"), precision=6)
    fit_error_minus: FloatProperty(name="Fit error −", get=_number("fit_minus"), precision=6)
    radius: FloatProperty(name="Radius", subtype="DISTANCE", unit="LENGTH", get=_number("radius"))
    seg_param: FloatProperty(name="λ (SegParam)", get=_number("lam"))
    snap_distance: FloatProperty(
        name="Snap distance", subtype="DISTANCE", unit="LENGTH", get=_number("snap_distance")
    )
    center: FloatVectorProperty(
        name="Centre (mesh)",
        description="The vertex measured at, in the mesh's own coordinates (the CSV's x, y, z)",
        size=3,
        subtype="XYZ",
        unit="LENGTH",
        get=_vector("center"),
    )
    center_world: FloatVectorProperty(
        name="Centre (world)",
        description="The vertex measured at, in world space where the object is now",
        size=3,
        subtype="XYZ",
        unit="LENGTH",
        get=_world_centre,
    )
    requested_center: FloatVectorProperty(
        name="Requested centre",
        description="The point asked for before snapping, in mesh coordinates",
        size=3,
        subtype="XYZ",
        unit="LENGTH",
        get=_vector("requested"),
    )
    normal_plus: FloatVectorProperty(
        name="Plane normal +", size=3, subtype="DIRECTION", get=_vector("normal_plus")
    )
    normal_minus: FloatVectorProperty(
        name="Plane normal −", size=3, subtype="DIRECTION", get=_vector("normal_minus")
    )
    rule: StringProperty(
        name="Rule",
        description="How the projection was signed: oriented, or paper (Algorithm 1 as printed); "
        "measurements recorded before the rule existed used the paper's",
        get=_text_value("rule", "paper"),
    )
    convexity: StringProperty(
        name="Edge",
        description="Convex, concave (the angle is then the open wedge's, 360° minus the solid's "
        "interior angle) or unclear, relative to the mesh's normals",
        get=_text_value("convexity", "not recorded"),
    )
    stability_text: StringProperty(
        name="Stability",
        description="The largest change of the angle with the centre moved two edge lengths, "
        "the radius ±10%, λ from 1 to 3, and the vertices resampled, plus how far it moves "
        "with the vertices next to the crease left out",
        get=_stability_text,
    )
    stability_warning: StringProperty(
        name="Stability warning",
        description=f"Why the reading is flagged: its stability figure is more than "
        f"{UNSTABLE_DEGREES:g}° (unstable), or more than {UNDETERMINED_REFUSED:.0%} of its "
        "perturbed runs were refused or a face kept too few vertices away from the crease "
        "(undetermined); empty for a reading that is not flagged",
        get=_stability_warning,
    )
    stability_center: FloatProperty(name="Centre moved (°)", get=_stability_part("center"))
    stability_radius: FloatProperty(name="Radius ±10% (°)", get=_stability_part("radius"))
    stability_lam: FloatProperty(name="λ 1 to 3 (°)", get=_stability_part("lam"))
    stability_bootstrap: FloatProperty(name="Bootstrap 95% (°)", get=_stability_part("bootstrap"))
    stability_orientation: FloatProperty(name="Other sign (°)", get=_stability_part("orientation"))
    stability_crease: FloatProperty(name="Crease left out (°)", get=_stability_part("crease"))
    color_plus: FloatVectorProperty(
        name="Colour +", size=3, subtype="COLOR_GAMMA", get=_side_colour(0)
    )
    color_minus: FloatVectorProperty(
        name="Colour −", size=3, subtype="COLOR_GAMMA", get=_side_colour(1)
    )


class VG_EdgeProfile(PropertyGroup):
    """One whole break edge measured at stations: its clicks, path and summary.

    The stations are the object's measurements with this ``number`` as their ``edge_number``.
    """

    number: IntProperty(name="Edge #", description="Edge profile number on this object")
    break_number: IntProperty(name="Break #", description="Break the stations belong to")
    exact: StringProperty(
        name="Exact numbers",
        description="The profile's float64 numbers (JSON): clicks, path, settings and summary",
        options={"HIDDEN"},
    )
    patch: EnumProperty(name="Patch", items=PATCH_ITEMS, description="How the patches were chosen")
    n_stations: IntProperty(name="Stations", description="Number of stations measured")
    stations_changed: BoolProperty(
        name="Stations changed",
        description="A station is stale or was deleted since the edge was measured: its summary "
        "is kept as recorded",
    )
    date: StringProperty(name="Date", description="When the edge was measured (ISO 8601)")
    note: StringProperty(name="Note", description="Free text, exported with the edge")
    colors: StringProperty(name="Colours", description="Palette colours of the + and − sides")
    fingerprint: StringProperty(
        name="Geometry fingerprint",
        description="Hash of the evaluated mesh and transform the edge was measured on",
        options={"HIDDEN"},
    )
    plot: StringProperty(
        name="Plot image", description="Name of the image holding the profile's plot"
    )

    # Read-only views of the exact numbers, for drawing.
    mean: FloatProperty(name="Mean (°)", get=_number("mean"), precision=2)
    std: FloatProperty(name="SD (°)", get=_number("std"), precision=2)
    min: FloatProperty(name="Min (°)", get=_number("min"), precision=2)
    max: FloatProperty(name="Max (°)", get=_number("max"), precision=2)
    pooled_angle: FloatProperty(name="Pooled (°)", get=_number("pooled_angle"), precision=2)
    length: FloatProperty(name="Length", subtype="DISTANCE", unit="LENGTH", get=_number("length"))
    spacing: FloatProperty(
        name="Spacing", subtype="DISTANCE", unit="LENGTH", get=_number("spacing")
    )
    radius: FloatProperty(name="Radius", subtype="DISTANCE", unit="LENGTH", get=_number("radius"))


UNIT_ITEMS = (
    (units.SCENE, "Scene Units", "Blender units, as the scene's unit system says (Scene > Units)"),
    *(
        (key, symbol, f"The scan's coordinates are in {name.lower()}")
        for key, name, symbol, _m in units.UNITS
    ),
)


unit_chosen_handlers: list = []
"""Called with the object after the user chose its Scan Units. The extension's registration adds
the redrawing of the object's edge plots (their axis names the unit); the batch, which sets units
from code, adds nothing."""


def _unit_chosen(data, _context) -> None:
    """The user chose the unit: it is no longer a guess, and no later guess replaces it."""
    data.unit_chosen = True
    data.unit_guessed = False
    for handler in unit_chosen_handlers:
        handler(data.id_data)


def set_unit(data, key: str, *, guessed: bool) -> None:
    """Set an object's Scan Units from code (a guess, a CSV's Units) without tagging the object
    for a depsgraph update (only labels change: nothing to re-evaluate or re-check)."""
    data["unit"] = next(i for i, item in enumerate(UNIT_ITEMS) if item[0] == key)
    data["unit_guessed"] = guessed
    data["unit_chosen"] = not guessed


class VG_ObjectData(PropertyGroup):
    """An object's measurements (``Object.vg``)."""

    unit: EnumProperty(
        name="Scan Units",
        items=UNIT_ITEMS,
        default=units.SCENE,
        description="The unit of the scan's coordinates, used to show lengths and in the CSV's "
        "Units column; no stored number changes. Guessed on the first measurement from the "
        "mesh's size (2 units across or more: mm, else m) when the scene's units are "
        "Blender's default",
        update=_unit_chosen,
    )
    unit_guessed: BoolProperty(
        name="Unit guessed",
        description="The scan's unit was guessed from its size, not chosen",
        default=False,
        options={"HIDDEN"},
    )
    unit_chosen: BoolProperty(
        name="Unit chosen",
        description="The user chose the scan's unit (no guess replaces it)",
        default=False,
        options={"HIDDEN"},
    )

    measurements: CollectionProperty(type=VG_Measurement)
    active_index: IntProperty(name="Active measurement", default=0, min=0)
    edges: CollectionProperty(type=VG_EdgeProfile)
    active_edge_index: IntProperty(name="Active edge", default=0, min=0)
    next_edge_number: IntProperty(
        name="Next edge #", description="Number the next edge profile gets", default=1, min=1
    )
    break_number: IntProperty(
        name="Break #", description="Break the next measurement belongs to", default=1, min=1
    )
    next_number: IntProperty(
        name="Next measurement #", description="Number the next measurement gets", default=1, min=1
    )
    map_pictures: StringProperty(
        name="Map pictures",
        description="The pictures this object's last measurement map wrote (JSON paths): a map "
        "made again removes those it does not make again, and no other file",
        default="[]",
        options={"HIDDEN"},
    )
    map_stem: StringProperty(
        name="Map file name",
        description="The file-name stem this object's measurement maps are written under: kept "
        "while it comes from the object's name, so another object never takes it",
        default="",
        options={"HIDDEN"},
    )
    sides_shown: BoolProperty(
        name="Sides shown",
        description="The viewports were switched to show the sides, on the first measurement",
        default=False,
        options={"HIDDEN"},
    )
    winding: StringProperty(
        name="Winding",
        description="Which way the measured mesh's faces are wound: outward, inward, mixed, or "
        "open (cannot be decided); set when it is measured",
    )


class VG_SceneSettings(PropertyGroup):
    """The panel's measuring settings (``Scene.vg_settings``)."""

    radius: FloatProperty(
        name="Radius",
        description="Patch radius around the centre, in the mesh's own units (its coordinates, "
        "whatever the object's scale: the Scan Units the panel shows)",
        default=1.0,
        min=0.0,
        soft_min=1e-4,
        precision=4,
    )
    seg_param: FloatProperty(
        name="λ (SegParam)",
        description="Segmentation parameter λ of the Virtual Goniometer (MeshLab's SegParam); "
        "larger values favour splitting along the break",
        default=2.0,
        min=0.0,
        soft_max=10.0,
        precision=3,
    )
    patch: EnumProperty(
        name="Patch", items=PATCH_ITEMS, default="euclidean", description="How the patch is chosen"
    )
    rule: EnumProperty(
        name="Rule",
        items=RULE_ITEMS,
        default="refined",
        description="How the measurement is taken",
    )
    stability: BoolProperty(
        name="Stability",
        description="Also compute the stability figure (± degrees) of each measurement",
        default=True,
    )
    sweep_start: FloatProperty(
        name="From",
        description="First radius of a radius sweep, in the mesh's own units",
        default=0.5,
        min=0.0,
        precision=4,
    )
    edge_spacing: FloatProperty(
        name="Spacing",
        description="Arc length between the stations of an edge profile, in the mesh's own units",
        default=1.0,
        min=0.0,
        soft_min=1e-4,
        precision=4,
    )
    find_scale: FloatProperty(
        name="Scale",
        description="Find Break Edges: the neighbourhood a bend is judged at, in the mesh's own "
        "units; 0: derived from the mesh",
        default=0.0,
        min=0.0,
        precision=4,
    )
    find_min_length: FloatProperty(
        name="Min Length",
        description="Find Break Edges: shorter candidates are dropped, in the mesh's own units; "
        "0: derived from the mesh",
        default=0.0,
        min=0.0,
        precision=4,
    )
    find_min_bend: FloatProperty(
        name="Min Bend",
        description="Find Break Edges: a ridge bends at least this much (180° minus its angle), "
        "in degrees",
        default=BreakEdgeParameters().min_bend_deg,
        min=0.1,  # above 0 and below 180, as the finder needs
        max=179.9,
        soft_max=90.0,
    )
    sweep_stop: FloatProperty(
        name="To",
        description="Last radius of a radius sweep, in the mesh's own units",
        default=2.0,
        min=0.0,
        precision=4,
    )
    sweep_count: IntProperty(
        name="Radii", description="Number of radii in a sweep", default=16, min=2, max=1000
    )
    export_all_objects: BoolProperty(
        name="All objects",
        description="Export the measurements of every object in the scene, not only the active one",
        default=False,
    )
    show_labels: BoolProperty(
        name="Labels",
        description="Draw each current measurement's number and angle beside it in the viewport "
        "(stale ones are not labelled; labels too close to a more important one are left out)",
        default=True,
    )
    labels_active_break: BoolProperty(
        name="Active Break Only",
        description="Label only the measurements of the current break",
        default=False,
    )
    map_views: EnumProperty(
        name="Views",
        items=(
            ("SIX", "Six Views", "Front, back, right, left, top and bottom, orthographic"),
            ("FLAKE", "Two Faces", "The two faces of a flat piece, seen along its thinnest axis"),
        ),
        default="SIX",
        description="What the measurement map shows",
    )
    map_directory: StringProperty(
        name="Map Folder",
        description="Folder the map's pictures are written to (// is the .blend's folder)",
        default="//vg_map",
        subtype="DIR_PATH",
        options=BLEND_RELATIVE,
    )
    ignore_mesh_names: BoolProperty(
        name="Ignore mesh names",
        description="Import rows whose Mesh Name is not this object's (e.g. a renamed scan)",
        default=False,
    )
    # The Replication Report's choices (its file browser shows them), kept with the scene.
    report_include_scene: BoolProperty(
        name="This scene's measurements",
        description="Add the measurements of every mesh in this scene as one more session",
        default=True,
    )
    report_scene_method: EnumProperty(
        name="Their method",
        description="The method of this scene's measurements as a session",
        items=(
            ("drag", "Drag", "Centres placed and radii dragged by hand"),
            ("xyz", "xyz", "Re-measured at given centres (CSV import)"),
        ),
        default="drag",
    )
    report_folder: StringProperty(
        name="Report folder",
        description="Where report.html, the CSV tables and figures/ go (default: a folder "
        "'vg_report' beside the first CSV, or beside the .blend file)",
        subtype="DIR_PATH",
        default="",
    )


classes = (VG_Measurement, VG_EdgeProfile, VG_ObjectData, VG_SceneSettings)


def register() -> None:
    """Register the groups and attach them to Scene and Object: all the extension and the batch
    need to read and write measurements."""
    for cls in classes:
        bpy.utils.register_class(cls)
    bpy.types.Scene.vg_settings = PointerProperty(type=VG_SceneSettings)
    bpy.types.Object.vg = PointerProperty(type=VG_ObjectData)


def unregister() -> None:
    """Undo :func:`register` (the data stays in the .blend)."""
    for owner, name in ((bpy.types.Object, "vg"), (bpy.types.Scene, "vg_settings")):
        if hasattr(owner, name):
            delattr(owner, name)
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
