"""The measurement list (a UIList: it only draws)."""

import bpy


class VG_UL_measurements(bpy.types.UIList):
    """One row per measurement: number, break, angle (and concave/unclear), fit error, radius,
    vertices, colours."""

    def draw_item(self, context, layout, data, item, icon, active_data, active_property, index):
        if self.layout_type == "GRID":
            layout.alignment = "CENTER"
            layout.label(text=str(item.number))
            return
        row = layout.row(align=True)
        row.label(text=f"#{item.number}", icon="ERROR" if item.stale else "NONE")
        row.label(text=f"B{item.break_number}")
        # A concave or unclear edge is named: its angle is not the solid's interior angle.
        kind = "" if item.convexity in ("convex", "not recorded") else f" {item.convexity}"
        row.label(text=f"{item.angle:.2f}°{kind}")
        row.label(text=f"fit {item.fit_error:.2g}")
        row.label(text=f"r {item.radius:.3g}")
        row.label(text=f"{item.n_vertices} v")
        swatches = row.row(align=True)
        swatches.scale_x = 0.35
        swatches.prop(item, "color_plus", text="")
        swatches.prop(item, "color_minus", text="")


classes = (VG_UL_measurements,)
