"""The "Goniometer" tab of the 3D viewport sidebar (panels only draw; operators do the work)."""

import bpy

from ..bridge.plots import plot_image
from ..bridge.records import is_shown_at_own_size, unit_symbol, units_label
from ..operators.measure import non_uniform_scale_note
from ..vg_addon.formats.record_codec import exact_numbers, study_texts
from ..vg_addon.method.edge_summary import sd_text
from ..vg_addon.method.winding import winding_message
from .text import fits_beside, region_width, text_width, ui_scale, wrapped_label

# What the angle of a measurement is, by its convexity label.
ANGLE_MEANING = {
    "convex": "Interior angle of the solid",
    "concave": "Open wedge: 360° minus the solid's angle",
    "unclear": "Convex or concave unclear here",
}

CATEGORY = "Goniometer"


def _active_mesh(context):
    obj = context.active_object
    return obj if obj is not None and obj.type == "MESH" else None


class _GoniometerPanel:
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = CATEGORY


class VIEW3D_PT_vg_measure(_GoniometerPanel, bpy.types.Panel):
    """Settings, the measure buttons and the list of measurements."""

    bl_label = "Virtual Goniometer"

    def draw(self, context):
        layout = self.layout
        settings = context.scene.vg_settings
        obj = _active_mesh(context)
        unit = unit_symbol(obj, context.scene)
        column = layout.column(align=True)
        column.use_property_split = True
        column.use_property_decorate = False
        if obj is not None:  # one row whatever it says: the buttons below never move
            guessed = obj.vg.unit_guessed
            column.prop(obj.vg, "unit", text="Units (guessed)" if guessed else "Scan Units")
        column.prop(settings, "radius", text=f"Radius ({unit})")
        column.prop(settings, "seg_param")
        column.prop(settings, "patch")
        column.prop(settings, "rule")
        column.prop(settings, "stability")

        if obj is None:
            layout.label(text="Select a mesh object to measure", icon="INFO")
            return
        if non_uniform_scale_note(obj):
            wrapped_label(
                layout.box(),
                context,
                "Non-uniform scale: not measured. Angles are those of the mesh as stored; apply "
                "the scale (Ctrl A) to change its shape",
                icon="INFO",
            )
        if message := winding_message(obj.name, obj.vg.winding):
            wrapped_label(layout.box(), context, message, icon="ERROR")
        layout.operator("vg.measure_xyz", text="Measure at 3D Cursor", icon="PIVOT_CURSOR")
        drag = layout.operator("wm.tool_set_by_id", text="Drag to Measure", icon="MOUSE_LMB_DRAG")
        drag.name = "vg.measure_drag_tool"
        wrapped_label(layout, context, "3D cursor on the edge: Shift + Right-click", "MOUSE_RMB")
        row = layout.row(align=True)
        row.label(text=f"Break {obj.vg.break_number}")
        row.operator("vg.next_break", text="Next Break", icon="ADD")

        row = layout.row()
        row.template_list(
            "VG_UL_measurements", "", obj.vg, "measurements", obj.vg, "active_index", rows=4
        )
        side = row.column(align=True)
        side.operator("vg.delete_measurement", text="", icon="REMOVE")
        side.operator("vg.clear_measurements", text="", icon="TRASH")
        side.separator()
        side.operator("vg.repaint", text="", icon="FILE_REFRESH")
        row = layout.row(align=True)
        row.prop(settings, "show_labels", icon="FONT_DATA")
        sub = row.row(align=True)
        sub.active = settings.show_labels
        sub.prop(settings, "labels_active_break", text="Current Break")


class VIEW3D_PT_vg_selected(_GoniometerPanel, bpy.types.Panel):
    """The selected measurement's full numbers."""

    bl_label = "Selected Measurement"
    bl_parent_id = "VIEW3D_PT_vg_measure"

    @classmethod
    def poll(cls, context):
        obj = _active_mesh(context)
        return obj is not None and 0 <= obj.vg.active_index < len(obj.vg.measurements)

    def draw(self, context):
        obj = _active_mesh(context)
        item = obj.vg.measurements[obj.vg.active_index]
        layout = self.layout
        if item.stale:
            wrapped_label(
                layout.box(),
                context,
                "Stale: the mesh changed since this measurement. Numbers kept as recorded; not "
                "painted",
                icon="ERROR",
            )
        if warning := item.stability_warning:  # the list's flag, with its reason in full
            box = layout.box()
            box.alert = True
            wrapped_label(box, context, warning, icon="ERROR")
        # Recorded values are shown as text, exactly as stored, not as (rounded, editable)
        # fields; only the note is the user's.
        column = layout.column(align=True)
        stacked = False  # a vector's Y and Z rows follow its X row
        for label, value in selected_rows(item, context.scene):
            if label or not value.startswith(("Y  ", "Z  ")):
                stacked = not _fits(context, label, value)
            _text(column, label, value, stacked=stacked)
        row = column.row(align=True)
        row.prop(item, "color_plus")
        row.prop(item, "color_minus", text="")
        layout.prop(item, "note")


def exact_text(value: float) -> str:
    """A float64 as the shortest text that reads back to exactly it (how the .blend stores it)."""
    return repr(float(value))


def selected_rows(item, scene) -> list[tuple[str, str]]:
    """The Selected Measurement panel's rows ``(label, text)``: every recorded number exactly.

    Angles in degrees; lengths and coordinates in Blender units (BU), as stored and exported;
    vectors one component a row.
    """
    numbers = exact_numbers(item)

    def number(key, suffix=""):
        return exact_text(numbers[key]) + suffix if key in numbers else "missing"

    rows = [
        ("Number", f"{item.number}, break {item.break_number}"),
    ]
    if item.edge_number:
        rows.append(
            ("Station of edge", f"{item.edge_number}, at arc length {number('arc_length')}")
        )
    rows += [
        ("Angle", number("angle", "°")),
        ("Edge", item.convexity),
        ("", ANGLE_MEANING.get(item.convexity, "")),
        ("Rule", item.rule),
        ("Stability", item.stability_text),
        ("Fit error", number("fit")),
        ("Fit error +", number("fit_plus")),
        ("Fit error −", number("fit_minus")),
        ("Radius", number("radius")),
        ("λ (SegParam)", number("lam")),
        ("Patch", item.patch.capitalize()),
        ("Vertices", f"{item.n_vertices} ({item.n_plus} +, {item.n_minus} −)"),
    ]
    for label, key in (
        ("Centre", "center"),
        ("Requested", "requested"),
        ("Normal +", "normal_plus"),
        ("Normal −", "normal_minus"),
    ):
        vector = numbers.get(key) or [None] * 3
        for axis, value in zip("XYZ", vector, strict=True):
            text = "missing" if value is None else exact_text(value)
            rows.append((label if axis == "X" else "", f"{axis}  {text}"))
    if numbers.get("space") == "mesh":
        # Where the measured vertex is now, the object's transform applied (float32, as shown).
        for axis, value in zip("XYZ", item.center_world, strict=True):
            rows.append(("World" if axis == "X" else "", f"{axis}  {value:.9g}"))
        rows.append(("Coordinates", "mesh (the object's own)"))
    else:
        rows.append(("Coordinates", "world (recorded by an older version)"))
    rows.append(("Snapped", number("snap_distance")))
    stability = numbers.get("stability") or {}
    for label, key in (
        ("± centre", "center"),
        ("± radius", "radius"),
        ("± λ", "lam"),
        ("± bootstrap", "bootstrap"),
        ("± orientation", "orientation"),
        ("± crease", "crease"),
    ):
        if key in stability:
            rows.append((label, exact_text(stability[key]) + "°"))
    obj = item.id_data
    if obj.vg.unit != "SCENE" or not is_shown_at_own_size(obj):
        # The scan's own unit, whatever the object's scale; or how a scaled object's relate.
        rows.append(("Lengths in", units_label(scene, obj)))
    else:
        units = scene.unit_settings
        scale = "" if units.system == "NONE" else f" (1 BU = {units.scale_length:g} m)"
        rows.append(("Lengths in", "BU" + scale))
    day, _, time = item.date.partition("T")  # the ISO date and time on a row each
    rows.append(("Date", day))
    if time:
        rows.append(("", time))
    return rows


LABEL_SHARE = 0.4  # of a row, for the label of a value ("λ (SegParam)" is 71 pixels)


def _fits(context, label, value) -> bool:
    """Whether ``label`` and ``value`` fit side by side in this sidebar."""
    return fits_beside(
        label,
        value,
        region_width(context),
        LABEL_SHARE,
        lambda t: text_width(context, t),
        ui_scale(context),
    )


def _text(layout, label, value, *, stacked=False):
    """A row: ``label`` right-aligned, then ``value``; ``stacked`` (a value too long to fit
    beside its label in this sidebar, such as an exact number with all its digits): the label,
    then the value on a row of its own, so nothing is cut."""
    if stacked:
        if label:
            layout.label(text=label)
        layout.label(text=value, icon="BLANK1")
        return
    split = layout.split(factor=LABEL_SHARE, align=True)
    left = split.row()
    left.alignment = "RIGHT"
    left.label(text=label)
    split.label(text=value)


def _text_fitted(layout, context, label, value) -> None:
    """:func:`_text`, stacked where the value does not fit beside its label."""
    _text(layout, label, value, stacked=not _fits(context, label, value))


class VIEW3D_PT_vg_edges(_GoniometerPanel, bpy.types.Panel):
    """Whole edges: spacing, Find Break Edges (with its settings, folded) and the .pp import, the
    Edge Profile button, the list, and the selected one's plot."""

    bl_label = "Edge Profiles"
    bl_parent_id = "VIEW3D_PT_vg_measure"

    @classmethod
    def poll(cls, context):
        return _active_mesh(context) is not None

    def draw(self, context):
        obj = _active_mesh(context)
        settings = context.scene.vg_settings
        layout = self.layout
        column = layout.column(align=True)
        column.use_property_split = True
        column.use_property_decorate = False
        unit = unit_symbol(obj, context.scene)
        column.prop(settings, "edge_spacing", text=f"Spacing ({unit})")
        column.prop(settings, "radius", text=f"Radius ({unit})")
        layout.operator("vg.measure_edge", text="Edge Profile", icon="CURVE_PATH")
        wrapped_label(layout, context, "Click start, via points, end; Enter measures", "INFO")
        row = layout.split(factor=0.7, align=True)
        row.operator("vg.find_break_edges", text="Find Break Edges", icon="VIEWZOOM")
        row.operator("vg.import_picked_points", text=".pp", icon="IMPORT")
        header, body = layout.panel("VG_find_edges_settings", default_closed=True)
        header.label(text="Finder Settings")
        if body is not None:
            column = body.column(align=True)
            column.use_property_split = True
            column.use_property_decorate = False
            column.prop(settings, "find_scale", text=f"Scale ({unit})")
            column.prop(settings, "find_min_length", text=f"Min Length ({unit})")
            column.prop(settings, "find_min_bend", text="Min Bend (°)")
            wrapped_label(body, context, "0: derived from the mesh", "INFO")
        if not len(obj.vg.edges):
            return
        row = layout.row()
        row.template_list("VG_UL_edges", "", obj.vg, "edges", obj.vg, "active_edge_index", rows=3)
        row.column(align=True).operator("vg.delete_edge", text="", icon="REMOVE")
        if not 0 <= obj.vg.active_edge_index < len(obj.vg.edges):
            return
        edge = obj.vg.edges[obj.vg.active_edge_index]
        if edge.stations_changed:
            wrapped_label(
                layout.box(),
                context,
                "Stations stale or deleted since measured: the summary is kept as it was recorded",
                icon="ERROR",
            )
        column = layout.column(align=True)
        _text_fitted(column, context, "Edge", f"{edge.number}, break {edge.break_number}")
        _text_fitted(
            column,
            context,
            "Stations",
            f"{edge.n_stations} every {edge.spacing:.4g} over {edge.length:.4g} {unit}",
        )
        # "SD", never "±": in this extension "±" is a reading's stability figure.
        sd = sd_text(exact_numbers(edge).get("std"))
        _text_fitted(column, context, "Mean, SD", f"{edge.mean:.2f}°, {sd}")
        _text_fitted(column, context, "Min, max", f"{edge.min:.2f}°, {edge.max:.2f}°")
        for label, text in study_texts(exact_numbers(edge), unit):
            _text_fitted(column, context, label, text)
        _text_fitted(column, context, "Pooled", f"{edge.pooled_angle:.2f}°")
        image = plot_image(edge)
        if image is not None:  # the image's preview icon, made on demand by layout.icon
            # As wide as the sidebar (scale counts 20-pixel icon units): a fixed 10 units left
            # the plot's numbers too small to read.
            scale = ui_scale(context)
            units = max(8.0, (region_width(context) - 60 * scale) / (20 * scale))
            layout.template_icon(icon_value=layout.icon(image), scale=units)
            layout.label(text=f"Angle (°) against arc length ({unit})")
        layout.prop(edge, "note")


class VIEW3D_PT_vg_csv(_GoniometerPanel, bpy.types.Panel):
    """Export the measurements, or replicate a CSV's measurements on this mesh."""

    bl_label = "CSV"
    bl_parent_id = "VIEW3D_PT_vg_measure"
    bl_options = {"DEFAULT_CLOSED"}  # noqa: RUF012 (Blender wants a set)

    def draw(self, context):
        settings = context.scene.vg_settings
        layout = self.layout
        row = layout.row(align=True)
        op = row.operator("vg.export_csv", text="Export", icon="EXPORT")
        op.all_objects = settings.export_all_objects
        row.prop(settings, "export_all_objects", text="All Objects")
        # The button on a row of its own: beside the toggle its words were cut.
        op = layout.operator("vg.import_csv", text="Import (Re-measure)", icon="IMPORT")
        op.ignore_mesh_names = settings.ignore_mesh_names
        layout.prop(settings, "ignore_mesh_names", text="Ignore Mesh Names")
        layout.operator("vg.report", text="Replication Report…", icon="GRAPH")


class VIEW3D_PT_vg_sweep(_GoniometerPanel, bpy.types.Panel):
    """Angle and fit error over a range of radii at the 3D cursor, written as a CSV and a plot."""

    bl_label = "Radius Sweep"
    bl_parent_id = "VIEW3D_PT_vg_measure"
    bl_options = {"DEFAULT_CLOSED"}  # noqa: RUF012 (Blender wants a set)

    def draw(self, context):
        settings = context.scene.vg_settings
        layout = self.layout
        column = layout.column(align=True)
        column.use_property_split = True
        column.use_property_decorate = False
        unit = unit_symbol(_active_mesh(context), context.scene)
        column.prop(settings, "sweep_start", text=f"From ({unit})")
        column.prop(settings, "sweep_stop", text=f"To ({unit})")
        column.prop(settings, "sweep_count")
        layout.operator("vg.radius_sweep", text="Sweep at 3D Cursor", icon="GRAPH")


class VIEW3D_PT_vg_map(_GoniometerPanel, bpy.types.Panel):
    """Render the measurement map: the coloured sides with numbered labels, from chosen views."""

    bl_label = "Measurement Map"
    bl_parent_id = "VIEW3D_PT_vg_measure"
    bl_options = {"DEFAULT_CLOSED"}  # noqa: RUF012 (Blender wants a set)

    def draw(self, context):
        settings = context.scene.vg_settings
        layout = self.layout
        layout.prop(settings, "map_views", expand=True)
        layout.prop(settings, "map_directory", text="")
        op = layout.operator("vg.render_map", text="Render Map", icon="RENDER_STILL")
        op.views = settings.map_views
        op.directory = settings.map_directory


classes = (
    VIEW3D_PT_vg_measure,
    VIEW3D_PT_vg_selected,
    VIEW3D_PT_vg_edges,
    VIEW3D_PT_vg_csv,
    VIEW3D_PT_vg_sweep,
    VIEW3D_PT_vg_map,
)
