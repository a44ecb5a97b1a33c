"""The measurement list (a UIList: it only draws)."""

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
    return f"{item.angle:.2f}°{kind}", f"#{item.number} B{item.break_number}"


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


classes = (VG_UL_measurements,)
