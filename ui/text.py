"""Text that fits the sidebar: labels wrapped to the region's width by Blender's own font
metrics (a label that is too long is cut with "…", which hid the end of hints and help)."""

from __future__ import annotations

import blf

# Room a label loses to the panel's margins and its icon, in pixels at UI scale 1.
MARGIN = 34.0
ICON = 20.0


def text_width(context, text: str) -> float:
    """The width of ``text`` in pixels as the sidebar draws a label (Blender's UI font at the
    widget size, times the UI scale)."""
    scale = context.preferences.system.ui_scale
    blf.size(0, context.preferences.ui_styles[0].widget.points * scale)
    return blf.dimensions(0, text)[0]


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
    scale = context.preferences.system.ui_scale
    width = region_width(context)
    room = max(width - (MARGIN + (ICON if icon != "NONE" else 0.0)) * scale, 40.0 * scale)
    column = layout.column(align=True)
    for number, line in enumerate(wrap(text, room, lambda t: text_width(context, t))):
        first = number == 0
        column.label(text=line, icon=icon if first or icon == "NONE" else "BLANK1")


def region_width(context) -> float:
    """The width of the region being drawn (pixels), or the default sidebar's."""
    region = getattr(context, "region", None)
    return region.width if region is not None else 240 * context.preferences.system.ui_scale


def fits_beside(label: str, value: str, width: float, share: float, measure, scale=1.0) -> bool:
    """Whether ``label`` and ``value`` both fit a row ``width`` pixels wide split at ``share``
    (the label's part), each with a label's padding."""
    room = width - MARGIN * scale
    padding = 8.0 * scale
    return (
        measure(label) <= share * room - padding and measure(value) <= (1 - share) * room - padding
    )
