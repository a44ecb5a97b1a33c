"""An edge profile's plot: the angle at each station against its arc length along the edge.

Drawn with matplotlib where it is installed (:mod:`.mpl_plots`: axis labels with units, a title,
a legend and the whole-edge angle); where it is not (a Blender whose Python has NumPy only), by
:func:`draw_profile` here, in pure NumPy, so the Blender panel and the headless batch always get
a picture: axes with labelled ticks, a line through the stations and a dot at each, the y range
padded so a constant profile is a flat line in the middle.
"""

from __future__ import annotations

import numpy as np

from ..errors import GoniometerError
from . import mpl_plots
from .png import encode_png

BACKGROUND = (255, 255, 255, 255)
AXES = (60, 60, 60, 255)
GRID = (225, 225, 225, 255)
LINE = (0, 114, 178, 255)  # Okabe-Ito blue
DOTS = (213, 94, 0, 255)  # Okabe-Ito vermillion

# A 3x5 pixel font for tick labels: each glyph is five rows of three bits.
_GLYPHS = {
    "0": (7, 5, 5, 5, 7),
    "1": (2, 6, 2, 2, 7),
    "2": (7, 1, 7, 4, 7),
    "3": (7, 1, 7, 1, 7),
    "4": (5, 5, 7, 1, 1),
    "5": (7, 4, 7, 1, 7),
    "6": (7, 4, 7, 5, 7),
    "7": (7, 1, 1, 1, 1),
    "8": (7, 5, 7, 5, 7),
    "9": (7, 5, 7, 1, 7),
    ".": (0, 0, 0, 0, 2),
    "-": (0, 0, 7, 0, 0),
    "°": (7, 5, 7, 0, 0),
    "e": (0, 7, 7, 4, 7),
    "+": (0, 2, 7, 2, 0),
    " ": (0, 0, 0, 0, 0),
}
_SCALE = 2  # font pixels per glyph bit
_MARGIN_LEFT, _MARGIN_BOTTOM, _MARGIN_TOP, _MARGIN_RIGHT = 48, 24, 10, 12


def nice_ticks(low: float, high: float, count: int = 5) -> np.ndarray:
    """About ``count`` round tick values (steps of 1, 2 or 5 times a power of ten) in ``[low, high]``."""
    span = max(high - low, 1e-12)
    raw = span / max(count, 1)
    power = 10.0 ** np.floor(np.log10(raw))
    step = power * min((1, 2, 5, 10), key=lambda m: abs(m * power - raw))
    first = np.ceil(low / step - 1e-9) * step
    return np.arange(first, high + step * 1e-9, step)


def _text_width(text: str) -> int:
    """Width of ``text`` in pixels, as :func:`_text` draws it."""
    return len(text) * 4 * _SCALE - _SCALE


def _y_labels(y_range) -> tuple[np.ndarray, list[str]]:
    """The angle axis's ticks and their labels."""
    ticks = nice_ticks(*y_range)
    step = float(ticks[1] - ticks[0]) if ticks.size > 1 else 1.0
    return ticks, [_label(tick, step) + "°" for tick in ticks]


def _text(image, x: int, y: int, text: str, color, anchor: str = "left") -> None:
    """Draw ``text`` with its top at row ``y``; ``anchor`` left/right/centre at column ``x``."""
    width = _text_width(text)
    x0 = {"left": x, "right": x - width, "centre": x - width // 2}[anchor]
    for k, char in enumerate(text):
        rows = _GLYPHS.get(char, _GLYPHS[" "])
        for r, bits in enumerate(rows):
            for c in range(3):
                if bits >> (2 - c) & 1:
                    top, left = y + r * _SCALE, x0 + (k * 4 + c) * _SCALE
                    if top >= 0 and top + _SCALE <= image.shape[0] and left >= 0:
                        image[top : top + _SCALE, left : left + _SCALE] = color


def _label(value: float, step: float) -> str:
    decimals = max(0, int(-np.floor(np.log10(step) + 1e-9))) if step < 1 else 0
    if abs(value) < step * 1e-6:
        value = 0.0  # no "-0"
    return f"{value:.{decimals}f}"


def _segments(image, xs: np.ndarray, ys: np.ndarray, color, thickness: int = 2) -> None:
    """Draw the polyline through pixel positions ``xs, ys`` (float), one sample per pixel."""
    if xs.size == 1:
        samples_x, samples_y = xs, ys
    else:
        lengths = np.maximum(np.ceil(np.hypot(np.diff(xs), np.diff(ys))).astype(int), 1)
        t = np.concatenate([np.arange(n) / n for n in lengths] + [np.array([1.0])])
        start = np.concatenate([np.repeat(np.arange(xs.size - 1), lengths), [xs.size - 2]])
        samples_x = xs[start] + t * (xs[start + 1] - xs[start])
        samples_y = ys[start] + t * (ys[start + 1] - ys[start])
    height, width = image.shape[:2]
    for dx in range(thickness):
        for dy in range(thickness):
            col = np.clip(np.round(samples_x).astype(int) + dx - thickness // 2, 0, width - 1)
            row = np.clip(np.round(samples_y).astype(int) + dy - thickness // 2, 0, height - 1)
            image[row, col] = color


def plot_frame(arc_lengths, angles, width: int, height: int):
    """The pixel mapping of :func:`draw_profile`: ``(to_x, to_y, x_range, y_range)``.

    ``to_x(arc)`` and ``to_y(angle)`` give (float) pixel columns and rows, row 0 at the top.
    """
    arc = np.asarray(arc_lengths, dtype=np.float64)
    angle = np.asarray(angles, dtype=np.float64)
    x_low, x_high = float(arc.min()), float(arc.max())
    if x_high - x_low <= 0:
        x_low, x_high = x_low - 0.5, x_high + 0.5
    y_low, y_high = float(angle.min()), float(angle.max())
    pad = max((y_high - y_low) * 0.1, 1.0)
    y_low, y_high = y_low - pad, y_high + pad
    # Wide enough for the widest tick label ("101.0°" did not fit: its first digit was cut).
    widest = max(_text_width(label) for label in _y_labels((y_low, y_high))[1])
    left, right = max(_MARGIN_LEFT, widest + 8), width - _MARGIN_RIGHT
    top, bottom = _MARGIN_TOP, height - _MARGIN_BOTTOM

    def to_x(value):
        return left + (np.asarray(value) - x_low) / (x_high - x_low) * (right - left)

    def to_y(value):
        return bottom - (np.asarray(value) - y_low) / (y_high - y_low) * (bottom - top)

    return to_x, to_y, (x_low, x_high), (y_low, y_high)


def _checked(arc_lengths, angles, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    arc = np.asarray(arc_lengths, dtype=np.float64).ravel()
    angle = np.asarray(angles, dtype=np.float64).ravel()
    if arc.size == 0 or arc.size != angle.size or not np.isfinite(np.r_[arc, angle]).all():
        raise GoniometerError(
            "A profile plot needs one finite arc length per finite angle, at least one station."
        )
    if width < 160 or height < 100:
        raise GoniometerError(
            f"A profile plot needs at least 160 x 100 pixels; got {width} x {height}."
        )
    return arc, angle


def render_profile(
    arc_lengths, angles, *, width: int = 480, height: int = 240, units="", title="", pooled=None
) -> np.ndarray:
    """The profile plot as an ``(height, width, 4)`` uint8 RGBA image, row 0 at the top: drawn
    by matplotlib where it is installed, else by :func:`draw_profile`.

    Parameters
    ----------
    arc_lengths, angles : array_like, shape (s,)
        The stations: arc length along the edge and angle (degrees).
    width, height : int
        Image size in pixels (at least 160 x 100).
    units : str
        The mesh's length unit for the arc-length axis (``"mm"``); empty: "mesh units".
    title : str
        The plot's title (matplotlib only), e.g. "Fragment 3, edge 1".
    pooled : float, optional
        The whole-edge angle, drawn as a dashed line (matplotlib only).
    """
    arc, angle = _checked(arc_lengths, angles, width, height)
    if not mpl_plots.available():
        return draw_profile(arc, angle, width=width, height=height)
    figure = mpl_plots.profile_figure(
        arc, angle, width=width, height=height, dpi=100, units=units, title=title, pooled=pooled
    )
    return mpl_plots.rgba(figure)


def profile_png(arc_lengths, angles, *, units="", title="", pooled=None) -> bytes:
    """The profile plot as the bytes of a PNG file, for the batch: 768 x 408 pixels by
    matplotlib where it is installed, else :func:`draw_profile`'s 480 x 240."""
    arc, angle = _checked(arc_lengths, angles, 480, 240)
    if not mpl_plots.available():
        return encode_png(draw_profile(arc, angle), level=6)
    figure = mpl_plots.profile_figure(
        arc, angle, width=768, height=408, dpi=120, units=units, title=title, pooled=pooled
    )
    return mpl_plots.png(figure)


def draw_profile(arc_lengths, angles, *, width: int = 480, height: int = 240) -> np.ndarray:
    """The NumPy drawing of the profile plot (no plotting library): an ``(height, width, 4)``
    uint8 RGBA image with tick labels in a 3x5 pixel font (arguments as :func:`render_profile`)."""
    arc, angle = _checked(arc_lengths, angles, width, height)
    image = np.empty((height, width, 4), dtype=np.uint8)
    image[:] = BACKGROUND
    to_x, to_y, x_range, y_range = plot_frame(arc, angle, width, height)
    left, right = round(float(to_x(x_range[0]))), width - _MARGIN_RIGHT
    top, bottom = _MARGIN_TOP, height - _MARGIN_BOTTOM
    y_ticks, y_labels = _y_labels(y_range)
    x_ticks = nice_ticks(*x_range)
    x_step = float(x_ticks[1] - x_ticks[0]) if x_ticks.size > 1 else 1.0
    for tick, label in zip(y_ticks, y_labels, strict=True):
        row = round(float(to_y(tick)))
        image[row, left:right] = GRID
        _text(image, left - 4, row - 5, label, AXES, anchor="right")
    for tick in x_ticks:
        column = round(float(to_x(tick)))
        image[top:bottom, column] = GRID
        _text(image, column, bottom + 6, _label(tick, x_step), AXES, anchor="centre")
    image[top : bottom + 1, left] = AXES
    image[bottom, left : right + 1] = AXES
    xs, ys = to_x(arc), to_y(angle)
    _segments(image, xs, ys, LINE)
    for x, y in zip(np.round(xs).astype(int), np.round(ys).astype(int), strict=True):
        image[max(y - 2, 0) : y + 3, max(x - 2, 0) : x + 3] = DOTS
    return image
