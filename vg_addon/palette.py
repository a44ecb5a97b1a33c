"""Colours for painting the two sides of each measurement, safe for colour-blind viewers.

The colours are from the Okabe-Ito palette (Okabe & Ito 2008, "Color Universal Design"), which
stays distinguishable under the common forms of colour blindness. Each break gets a pair of
contrasting colours, the "+" side first; the pairs rotate with the break number so neighbouring
breaks look different. Everything that is not part of a measurement is painted neutral grey.
"""

from __future__ import annotations

import numpy as np

#: Okabe-Ito colours as 8-bit sRGB.
OKABE_ITO = {
    "orange": (230, 159, 0),
    "sky blue": (86, 180, 233),
    "bluish green": (0, 158, 115),
    "yellow": (240, 228, 66),
    "blue": (0, 114, 178),
    "vermillion": (213, 94, 0),
    "reddish purple": (204, 121, 167),
}

#: ("+" side, "-" side) colour names per break, in rotation order. Each pair joins a warm and a
#: cool colour that differ in lightness as well as hue, so the two sides stay apart for viewers
#: with deuteranopia, protanopia or tritanopia.
#:
#: Break 1 is yellow and blue because the measured object is selected while one works on it, and
#: Blender draws a selected object's silhouette in orange (theme: active object #FFA028,
#: selected #ED5700): an orange side at the silhouette merged with that outline (CIE76 distance
#: 12 to the active outline; vermillion is 13 from the selected one). Yellow is 43 and 76 from
#: them, blue over 119, and of all the pairs yellow and blue differ most in lightness (L* 89
#: and 46), so the two sides stay apart for every colour vision. Orange and vermillion come in
#: later breaks, each beside a blue.
BREAK_PAIRS = (
    ("yellow", "blue"),
    ("vermillion", "sky blue"),
    ("reddish purple", "bluish green"),
    ("orange", "blue"),
)

#: The colour of everything outside a measurement (8-bit sRGB): a mid grey that none of the
#: pair colours is confused with.
NEUTRAL_GREY = (128, 128, 128)


def pair_names(break_number: int) -> tuple[str, str]:
    """Colour names ``("+" side, "-" side)`` for a break (numbered from 1; the pairs rotate)."""
    return BREAK_PAIRS[(int(break_number) - 1) % len(BREAK_PAIRS)]


def pair_srgb8(break_number: int) -> tuple[tuple[int, int, int], tuple[int, int, int]]:
    """8-bit sRGB colours ``("+" side, "-" side)`` for a break."""
    plus, minus = pair_names(break_number)
    return OKABE_ITO[plus], OKABE_ITO[minus]


def srgb_to_linear(rgb8) -> np.ndarray:
    """Convert 8-bit sRGB colours (shape (..., 3)) to scene-linear RGBA floats (alpha 1).

    Blender's float colour attributes hold scene-linear values; this is the standard sRGB
    transfer function (IEC 61966-2-1).
    """
    c = np.asarray(rgb8, dtype=np.float64) / 255.0
    linear = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    alpha = np.ones((*linear.shape[:-1], 1))
    return np.concatenate([linear, alpha], axis=-1)


def pair_linear(break_number: int) -> tuple[np.ndarray, np.ndarray]:
    """Scene-linear RGBA colours ``("+" side, "-" side)`` for a break."""
    plus, minus = pair_srgb8(break_number)
    return srgb_to_linear(plus), srgb_to_linear(minus)


def neutral_linear() -> np.ndarray:
    """Scene-linear RGBA of the neutral grey."""
    return srgb_to_linear(NEUTRAL_GREY)
