"""The measurement list (a UIList: it only draws)."""

import bpy

# Shares of a row at the default sidebar width (about 170 pixels for the list at UI scale 1): the
# angle first and widest (room for a warning icon, "179.99°" and a word such as "concave"), then
# the number, then the two side colours (which also tell the break). Labels in a plain row share
# the width equally, which cut every angle to "6…"; a split gives each its own share.
ANGLE_SHARE = 0.6
NUMBER_SHARE = 0.6  # of what the angle leaves


def row_texts(item) -> tuple[str, str]:
    """The two texts of a list row: the angle (2 decimals) and ``"#number"``.

    A stale measurement keeps both (the angle gets a warning icon); the break is told by the
    row's colour pair, and every number is in the Selected Measurement panel.
    """
    # A concave or unclear edge is named: its angle is not the solid's interior angle.
    kind = "" if item.convexity in ("convex", "not recorded") else f" {item.convexity}"
    return f"{item.angle:.2f}°{kind}", f"#{item.number}"


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
