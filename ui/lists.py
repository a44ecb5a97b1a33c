"""The measurement and edge-profile lists (UILists: they only draw)."""

import bpy

# Shares of a row at the default sidebar width: the angle first and widest, then the number and
# break, then the two side colours. Labels in a plain row share the width equally, which cut
# every angle to "6…"; a split gives each its own share.
ANGLE_SHARE = 0.46
NUMBER_SHARE = 0.62  # of what the angle leaves


def row_texts(item) -> tuple[str, str]:
    """The two texts of a list row: the angle (2 decimals) and ``"#number B break"``.

    A stale measurement keeps both (the angle gets a warning icon); every other number is in the
    Selected Measurement panel.
    """
    # A concave or unclear edge is named: its angle is not the solid's interior angle.
    kind = "" if item.convexity in ("convex", "not recorded") else f" {item.convexity}"
    edge = f" E{item.edge_number}" if item.edge_number else ""
    return f"{item.angle:.2f}°{kind}", f"#{item.number} B{item.break_number}{edge}"


class VG_UL_measurements(bpy.types.UIList):
    """One row per measurement: angle (with "concave" or "unclear" where the edge is), number
    and break, the colours of its two sides."""

    def draw_item(self, context, layout, data, item, icon, active_data, active_property, index):
        angle, number = row_texts(item)
        if self.layout_type == "GRID":
            layout.alignment = "CENTER"
            layout.label(text=angle)
            return
        split = layout.split(factor=ANGLE_SHARE, align=True)
        split.label(text=angle, icon="ERROR" if item.stale else "NONE")
        rest = split.split(factor=NUMBER_SHARE, align=True)
        rest.label(text=number)
        swatches = rest.row(align=True)
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
