"""The measurement list and the edge-profile list (UILists: they only draw)."""

import bpy

from ..bridge.label_data import stability_flag

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


def row_flag(item) -> str:
    """The stability figure a flagged row shows beside its angle (``"±78°"``, highlighted, with
    a warning icon; the reason is the tooltip), or ``""`` for a row that is not flagged; the
    viewport labels and the map show the same (``bridge.label_data.stability_flag``)."""
    return stability_flag(item)


def flagged_text(item) -> str:
    """A flagged row's first text: the angle and the figure, ``"71.0° ±78°"`` (the edge word
    makes way for the figure, and a second decimal, which such a reading does not have; the
    Selected Measurement panel still names the edge and gives both)."""
    return f"{item.angle:.1f}° {row_flag(item)}"


class VG_UL_measurements(bpy.types.UIList):
    """One row per measurement: angle (with "concave" or "unclear" where the edge is, and the
    stability figure highlighted where the reading is unstable), number and break, the colours
    of its two sides."""

    def draw_item(self, context, layout, data, item, icon, active_data, active_property, index):
        angle, number = row_texts(item)
        flag = row_flag(item)
        if self.layout_type == "GRID":
            layout.alignment = "CENTER"
            layout.label(text=angle, icon="ERROR" if flag else "NONE")
            return
        split = layout.split(factor=ANGLE_SHARE, align=True)
        if flag:  # a button that looks like the label, for its tooltip: the reason
            cell = split.row(align=True)
            cell.alert = True
            button = cell.operator(
                "vg.stability_warning", text=flagged_text(item), icon="ERROR", emboss=False
            )
            button.index = index
        else:
            split.label(text=angle, icon="ERROR" if item.stale else "NONE")
        rest = split.split(factor=NUMBER_SHARE, align=True)
        rest.label(text=number)
        swatches = rest.row(align=True)
        swatches.prop(item, "color_plus", text="")
        swatches.prop(item, "color_minus", text="")


# Shares of an edge row: its number, then the mean angle, then the station count.
EDGE_NUMBER_SHARE = 0.25
EDGE_MEAN_SHARE = 0.5  # of what the number leaves


def edge_row_texts(edge) -> tuple[str, str, str]:
    """The three texts of an edge-profile row: ``"#number"``, the mean station angle (2
    decimals) and the number of stations."""
    stations = "station" if edge.n_stations == 1 else "stations"
    return f"#{edge.number}", f"{edge.mean:.2f}°", f"{edge.n_stations} {stations}"


class VG_UL_edges(bpy.types.UIList):
    """One row per edge profile: its number, the mean angle of its stations (with a warning
    icon when a station is stale or deleted) and how many stations it has."""

    def draw_item(self, context, layout, data, item, icon, active_data, active_property, index):
        number, mean, stations = edge_row_texts(item)
        if self.layout_type == "GRID":
            layout.alignment = "CENTER"
            layout.label(text=number)
            return
        split = layout.split(factor=EDGE_NUMBER_SHARE, align=True)
        split.label(text=number)
        rest = split.split(factor=EDGE_MEAN_SHARE, align=True)
        rest.label(text=mean, icon="ERROR" if item.stations_changed else "NONE")
        rest.label(text=stations)


classes = (VG_UL_measurements, VG_UL_edges)
