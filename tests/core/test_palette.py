"""The side colours: the first break's pair stays apart from Blender's selection outline."""

import numpy as np

from vg_addon import palette

# Blender's default theme (3D Viewport): the outline of the active and of a selected object.
OUTLINES = {"active": (255, 160, 40), "selected": (237, 87, 0)}


def lab(rgb8) -> np.ndarray:
    """CIE L*a*b* (D65) of an 8-bit sRGB colour, from the published formulas."""
    c = np.asarray(rgb8, dtype=np.float64) / 255.0
    linear = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    xyz = (
        np.array([[0.4124, 0.3576, 0.1805], [0.2126, 0.7152, 0.0722], [0.0193, 0.1192, 0.9505]])
        @ linear
        / np.array([0.95047, 1.0, 1.08883])
    )
    f = np.where(xyz > (6 / 29) ** 3, np.cbrt(xyz), xyz / (3 * (6 / 29) ** 2) + 4 / 29)
    return np.array([116 * f[1] - 16, 500 * (f[0] - f[1]), 200 * (f[1] - f[2])])


def test_break_one_does_not_merge_with_the_orange_selection_outline():
    """Issue 20, item 10: each side of break 1 is at least 40 CIE76 units from both outline
    colours (the former orange was 12 from the active outline), and its two sides differ in
    lightness by more than 30 L*."""
    plus, minus = palette.pair_srgb8(1)
    for side in (plus, minus):
        for outline in OUTLINES.values():
            assert np.linalg.norm(lab(side) - lab(outline)) > 40, (side, outline)
    assert abs(lab(plus)[0] - lab(minus)[0]) > 30
    assert np.linalg.norm(lab((255, 255, 255)) - [100, 0, 0]) < 0.05
