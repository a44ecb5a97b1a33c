"""The "Goniometer" tab of the 3D viewport sidebar (panels only draw; operators do the work)."""

import textwrap

import bpy

from ..operators.measure import non_uniform_scale_note
from ..vg_addon.method.winding import winding_message

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
        column = layout.column(align=True)
        column.use_property_split = True
        column.use_property_decorate = False
        column.prop(settings, "radius")
        column.prop(settings, "seg_param")
        column.prop(settings, "patch")
        column.prop(settings, "rule")
        column.prop(settings, "stability")

        obj = _active_mesh(context)
        if obj is None:
            layout.label(text="Select a mesh object to measure", icon="INFO")
            return
        if non_uniform_scale_note(obj):
            box = layout.box()
            box.label(text="Non-uniform scale: not measured", icon="INFO")
            box.label(text="Angles are those of the mesh as stored;")
            box.label(text="apply the scale (Ctrl A) to change its shape")
        if message := winding_message(obj.name, obj.vg.winding):
            box = layout.box()
            for number, line in enumerate(textwrap.wrap(message, 42)):
                box.label(text=line, icon="ERROR" if number == 0 else "BLANK1")
        layout.operator("vg.measure_xyz", text="Measure at 3D Cursor", icon="PIVOT_CURSOR")
        drag = layout.operator("wm.tool_set_by_id", text="Drag to Measure", icon="MOUSE_LMB_DRAG")
        drag.name = "vg.measure_drag_tool"
        layout.label(text="Place the cursor on the edge: Shift + Right-click")
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
            box = layout.box()
            box.label(text="Stale: the mesh changed since this measurement", icon="ERROR")
            box.label(text="Numbers kept as recorded; not painted")
        # Recorded values are shown, not edited (only the note is the user's): the computed
        # views are read-only properties, the stored ones are drawn as text.
        column = layout.column(align=True)
        column.use_property_split = True
        column.use_property_decorate = False
        _text(column, "Measurement", f"{item.number}, break {item.break_number}")
        column.prop(item, "angle")
        _text(column, "Edge", f"{item.convexity}: {ANGLE_MEANING.get(item.convexity, '')}")
        _text(column, "Stability", item.stability_text)
        if item.stability_text != "not computed":
            for name in (
                "stability_center",
                "stability_radius",
                "stability_lam",
                "stability_bootstrap",
                "stability_orientation",
            ):
                column.prop(item, name)
        _text(column, "Rule", item.rule)
        for name in ("fit_error", "fit_error_plus", "fit_error_minus"):
            column.prop(item, name)
        column.prop(item, "radius")
        column.prop(item, "seg_param")
        _text(column, "Patch", item.patch.capitalize())
        _text(column, "Vertices", f"{item.n_vertices} ({item.n_plus} +, {item.n_minus} −)")
        for name in (
            "center",
            "center_world",
            "requested_center",
            "snap_distance",
            "normal_plus",
            "normal_minus",
        ):
            column.prop(item, name)
        row = column.row(align=True)
        row.prop(item, "color_plus")
        row.prop(item, "color_minus", text="")
        _text(column, "Date", item.date)
        layout.prop(item, "note")


def _text(layout, label, value):
    split = layout.split(factor=0.4, align=True)
    left = split.row()
    left.alignment = "RIGHT"
    left.label(text=label)
    split.label(text=value)


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
        row = layout.row(align=True)
        op = row.operator("vg.import_csv", text="Import (Re-measure)", icon="IMPORT")
        op.ignore_mesh_names = settings.ignore_mesh_names
        row.prop(settings, "ignore_mesh_names", text="Ignore Names")


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
        column.prop(settings, "sweep_start")
        column.prop(settings, "sweep_stop")
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
    VIEW3D_PT_vg_csv,
    VIEW3D_PT_vg_sweep,
    VIEW3D_PT_vg_map,
)
