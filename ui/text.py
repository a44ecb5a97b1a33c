"""Text that fits the sidebar: labels wrapped to the region's width by Blender's own font
metrics (a label that is too long is cut with "…", which hid the end of hints and help)."""

from __future__ import annotations

import blf

# Room a label loses to the sidebar's tabs, the panel's margins and its icon, in pixels at UI
# scale 1: in Blender 4.3's window the sidebar is 291 pixels wide and a label's text spans at
# most 234 of them.
MARGIN = 58.0
SIDEBAR = 291.0  # the sidebar's width as Blender opens it, at UI scale 1
ICON = 20.0
# Blender draws the UI font a little wider than blf measures it at the widget's size (in the
# 4.3 window, 209 drawn pixels for 190 measured): widths are taken this much larger.
DRAWN = 1.12


def ui_scale(context) -> float:
    """The UI scale (1 where Blender has no window: headless)."""
    return context.preferences.system.ui_scale or 1.0


def text_width(context, text: str) -> float:
    """The width of ``text`` in pixels as the sidebar draws a label (Blender's UI font at the
    widget size, times the UI scale, with :data:`DRAWN`'s allowance)."""
    blf.size(0, context.preferences.ui_styles[0].widget.points * ui_scale(context))
    return DRAWN * blf.dimensions(0, text)[0]


def wrap(text: str, room: float, measure) -> list[str]:
    """``text`` split at spaces into lines each ``measure``-d no wider than ``room`` (a word
    wider than that gets a line of its own)."""
    lines: list[str] = []
    for paragraph in text.splitlines() or [""]:
        line = ""
        for word in paragraph.split():
            candidate = f"{line} {word}" if line else word
            if line and measure(candidate) > room:
                lines.append(line)
                line = word
            else:
                line = candidate
        lines.append(line)
    return lines


def wrapped_label(layout, context, text: str, icon: str = "NONE") -> None:
    """``text`` as labels, one per line, wrapped to the width of ``context.region``; the icon on
    the first line, the others indented to match."""
    scale = ui_scale(context)
    width = region_width(context)
    room = max(width - (MARGIN + (ICON if icon != "NONE" else 0.0)) * scale, 40.0 * scale)
    column = layout.column(align=True)
    for number, line in enumerate(wrap(text, room, lambda t: text_width(context, t))):
        first = number == 0
        column.label(text=line, icon=icon if first or icon == "NONE" else "BLANK1")


def region_width(context) -> float:
    """The width of the region being drawn (pixels), or the default sidebar's."""
    region = getattr(context, "region", None)
    return region.width if region is not None else SIDEBAR * ui_scale(context)


def fits_beside(label: str, value: str, width: float, share: float, measure, scale=1.0) -> bool:
    """Whether ``label`` and ``value`` both fit a row ``width`` pixels wide split at ``share``
    (the label's part), each with a label's padding."""
    room = width - MARGIN * scale
    padding = 8.0 * scale
    return (
        measure(label) <= share * room - padding and measure(value) <= (1 - share) * room - padding
    )
