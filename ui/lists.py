"""The measurement and edge-profile lists (UILists: they only draw)."""

import bpy


class VG_UL_measurements(bpy.types.UIList):
    """One row per measurement: number, break, angle, fit error, radius, vertices, colours."""

    def draw_item(self, context, layout, data, item, icon, active_data, active_property, index):
        if self.layout_type == "GRID":
            layout.alignment = "CENTER"
            layout.label(text=str(item.number))
            return
        row = layout.row(align=True)
        row.label(text=f"#{item.number}", icon="ERROR" if item.stale else "NONE")
        row.label(
            text=f"B{item.break_number}" + (f" E{item.edge_number}" if item.edge_number else "")
        )
        row.label(text=f"{item.angle:.2f}°")
        row.label(text=f"fit {item.fit_error:.2g}")
        row.label(text=f"r {item.radius:.3g}")
        row.label(text=f"{item.n_vertices} v")
        swatches = row.row(align=True)
        swatches.scale_x = 0.35
        swatches.prop(item, "color_plus", text="")
        swatches.prop(item, "color_minus", text="")


class VG_UL_edges(bpy.types.UIList):
    """One row per edge profile: number, break, stations, mean ± SD, pooled angle, colours."""

    def draw_item(self, context, layout, data, item, icon, active_data, active_property, index):
        if self.layout_type == "GRID":
            layout.alignment = "CENTER"
            layout.label(text=str(item.number))
            return
        row = layout.row(align=True)
        row.label(text=f"E{item.number}")
        row.label(text=f"B{item.break_number}")
        row.label(text=f"{item.n_stations} st")
        row.label(text=f"{item.mean:.1f}±{item.std:.1f}°")
        row.label(text=f"pooled {item.pooled_angle:.1f}°")


classes = (VG_UL_measurements, VG_UL_edges)
