"""The radius sweep's plot: angle (top) and fit error (bottom, log scale) against the radius.

Drawn with matplotlib where it is installed (:mod:`.mpl_plots`: axis labels with units, a title,
a legend); where it is not (a Blender whose Python has NumPy only), by :func:`draw_sweep` here,
with tick labels in a built-in 3x5 pixel font, so the Sweep operator and the batch always write
a picture.
"""

from __future__ import annotations

import math
import os

import numpy as np

from . import mpl_plots
from .files import replace_atomically
from .png import encode_png

WIDTH, HEIGHT = 640, 430
_LEFT, _RIGHT = 78, 20
_ANGLE_PANEL = (40, 215)  # top and bottom pixel rows
_FIT_PANEL = (250, 385)
_SCALE = 2  # font pixels per glyph pixel

_WHITE = (255, 255, 255)
_BLACK = (0, 0, 0)
_GRID = (225, 225, 225)
_ANGLE_COLOUR = (0, 114, 178)  # Okabe-Ito blue
_FIT_COLOUR = (213, 94, 0)  # Okabe-Ito vermillion
_REFUSED_COLOUR = (204, 121, 167)  # Okabe-Ito reddish purple

_GLYPHS = {
    "0": "111101101101111",
    "1": "010110010010111",
    "2": "111001111100111",
    "3": "111001111001111",
    "4": "101101111001001",
    "5": "111100111001111",
    "6": "111100111101111",
    "7": "111001001001001",
    "8": "111101111101111",
    "9": "111101111001111",
    ".": "000000000000010",
    "-": "000000111000000",
    "+": "000010111010000",
    "(": "010100100100010",
    ")": "010001001001010",
    "/": "001001010100100",
    ":": "000010000010000",
    "°": "111101111000000",  # a ring at the top: the old diamond read as "*"
    " ": "000000000000000",
    "A": "010101111101101",
    "C": "111100100100111",
    "D": "110101101101110",
    "E": "111100111100111",
    "F": "111100111100100",
    "G": "111100101101111",
    "I": "111010010010111",
    "L": "100100100100111",
    "N": "110101101101101",  # an "n": in three columns the usual N reads as M
    "O": "111101101101111",
    "R": "110101110101101",
    "S": "111100111001111",
    "T": "111010010010010",
    "U": "101101101101111",
    "V": "101101101101010",
    "X": "101101010101101",
}


def _text(image, x: int, y: int, text: str, colour=_BLACK, align: str = "left") -> None:
    """Draw ``text`` (upper case, digits, a few signs) with its top-left (or right end) at x, y."""
    advance = 4 * _SCALE
    if align == "right":
        x -= advance * len(text)
    elif align == "centre":
        x -= advance * len(text) // 2
    for position, char in enumerate(text.upper()):
        bits = np.array([c == "1" for c in _GLYPHS.get(char, _GLYPHS[" "])]).reshape(5, 3)
        block = np.kron(bits, np.ones((_SCALE, _SCALE), dtype=bool))
        left = x + position * advance
        region = image[y : y + block.shape[0], left : left + block.shape[1]]
        region[block[: region.shape[0], : region.shape[1]]] = colour


def _nice_ticks(low: float, high: float, count: int = 5) -> np.ndarray:
    """About ``count`` round tick values (steps of 1, 2 or 5 times a power of ten) in [low, high]."""
    raw = (high - low) / max(count - 1, 1)
    power = 10.0 ** math.floor(math.log10(raw))
    step = next(m * power for m in (1, 2, 5, 10) if m * power >= raw)
    first = math.ceil(low / step - 1e-9) * step
    return np.arange(first, high + step * 1e-9, step)


def _pixel(value: float) -> int:
    return int(np.rint(value))


def _label(value: float) -> str:
    text = f"{value:.6g}"
    return "0" if text in ("-0", "0") else text.upper()


def _segment(image, x0, y0, x1, y1, colour, width: int = 2) -> None:
    steps = int(max(abs(x1 - x0), abs(y1 - y0))) + 1
    xs = np.round(np.linspace(x0, x1, steps)).astype(int)
    ys = np.round(np.linspace(y0, y1, steps)).astype(int)
    for dx in range(width):
        for dy in range(width):
            image[np.clip(ys + dy, 0, HEIGHT - 1), np.clip(xs + dx, 0, WIDTH - 1)] = colour


def _panel(image, top, bottom, radii, values, x_of, low, high, colour, title, ticks, labels):
    def y_of(value):
        return bottom - (value - low) / (high - low) * (bottom - top)

    for tick, text in zip(ticks, labels, strict=True):
        y = _pixel(y_of(tick))
        image[y, _LEFT : WIDTH - _RIGHT] = _GRID
        _text(image, _LEFT - 6, y - 5, text, align="right")
    image[top:bottom, _LEFT] = _BLACK
    image[bottom, _LEFT : WIDTH - _RIGHT] = _BLACK
    _text(image, _LEFT + 6, top - 14, title, colour)
    measured = np.isfinite(values)
    for i in range(len(radii) - 1):  # a line between neighbouring measured radii only
        if measured[i] and measured[i + 1]:
            _segment(
                image,
                x_of(radii[i]),
                y_of(values[i]),
                x_of(radii[i + 1]),
                y_of(values[i + 1]),
                colour,
            )
    for r, v in zip(radii[measured], values[measured], strict=True):
        x, y = _pixel(x_of(r)), _pixel(y_of(v))
        image[max(y - 3, 0) : y + 4, max(x - 3, 0) : x + 4] = colour


def draw_sweep(radii, angles, fit_errors) -> np.ndarray:
    """The NumPy drawing of a radius sweep (no plotting library): an ``(HEIGHT, WIDTH, 3)``
    uint8 image.

    Parameters
    ----------
    radii : array_like, shape (k,)
        Increasing radii.
    angles, fit_errors : array_like, shape (k,)
        The measured values; NaN for a refused radius (drawn as a mark on the axis, no point).
    """
    radii = np.asarray(radii, dtype=np.float64)
    angles = np.asarray(angles, dtype=np.float64)
    fits = np.asarray(fit_errors, dtype=np.float64)
    image = np.full((HEIGHT, WIDTH, 3), _WHITE, dtype=np.uint8)
    x_low, x_high = float(radii[0]), float(radii[-1])

    def x_of(r):
        return _LEFT + (r - x_low) / (x_high - x_low) * (WIDTH - _RIGHT - _LEFT)

    measured = np.isfinite(angles)
    low, high = float(angles[measured].min()), float(angles[measured].max())
    middle, half = (low + high) / 2, max((high - low) / 2 * 1.15, 0.5)
    ticks = _nice_ticks(middle - half, middle + half)
    low, high = min(ticks[0], middle - half), max(ticks[-1], middle + half)
    _panel(
        image,
        *_ANGLE_PANEL,
        radii,
        angles,
        x_of,
        low,
        high,
        _ANGLE_COLOUR,
        "ANGLE (°)",
        ticks,
        [_label(t) for t in ticks],
    )

    # 0 has no place on a log axis: an exact fit is a mark at the panel's foot, as matplotlib's
    # drawing has it (before, it was drawn as the smallest positive fit).
    positive = measured & (fits > 0)
    logs = np.where(positive, np.log10(np.where(positive, fits, 1.0)), np.nan)
    low, high = (
        (math.floor(np.nanmin(logs)), math.ceil(np.nanmax(logs))) if positive.any() else (0, 1)
    )
    high = max(high, low + 1)
    step = max(1, math.ceil((high - low) / 4))
    ticks = np.arange(low, high + 1, step, dtype=np.float64)
    _panel(
        image,
        *_FIT_PANEL,
        radii,
        logs,
        x_of,
        float(ticks[0]),
        float(max(ticks[-1], high)),
        _FIT_COLOUR,
        "FIT ERROR (LOG)",
        ticks,
        [f"1E{int(t)}" for t in ticks],
    )

    for tick in _nice_ticks(x_low, x_high, 6):
        x = _pixel(x_of(tick))
        image[_FIT_PANEL[1] : _FIT_PANEL[1] + 5, x] = _BLACK
        _text(image, x, _FIT_PANEL[1] + 9, _label(tick), align="centre")
    _text(image, WIDTH // 2, HEIGHT - 16, "RADIUS", align="centre")
    for r in radii[~measured]:  # refused radii: a mark under the angle panel
        x = _pixel(x_of(r))
        _text(image, x, _ANGLE_PANEL[1] + 4, "X", _REFUSED_COLOUR, align="centre")
    for r in radii[measured & ~positive]:  # exact fits: a mark at the fit panel's foot
        x = _pixel(x_of(r))
        _text(image, x, _FIT_PANEL[1] - 16, "0", _FIT_COLOUR, align="centre")
    return image


def sweep_series(points) -> tuple[list, list, list]:
    """The radii, angles and fit errors of ``vg_addon.method.sweep`` points (NaN: refused)."""
    measured = [point.measurement for point in points]
    return (
        [point.radius for point in points],
        [np.nan if m is None else m.angle for m in measured],
        [np.nan if m is None else m.fit_error for m in measured],
    )


def sweep_png(points, *, units: str = "", title: str = "") -> bytes:
    """The plot of ``vg_addon.method.sweep`` points as the bytes of a PNG file: 800 x 560 pixels
    by matplotlib where it is installed, else :func:`draw_sweep`'s picture.

    Parameters
    ----------
    units : str
        The mesh's length unit (``"mm"``); empty: "mesh units".
    title : str
        The plot's title (matplotlib only), e.g. "Fragment 3, site 2".
    """
    radii, angles, fits = sweep_series(points)
    if not mpl_plots.available():
        return encode_png(draw_sweep(radii, angles, fits))
    figure = mpl_plots.sweep_figure(
        radii, angles, fits, width=800, height=560, dpi=120, units=units, title=title
    )
    return mpl_plots.png(figure)


def write_sweep_png(path, points, *, units: str = "", title: str = "") -> None:
    """Draw a sweep (:func:`sweep_png`) and write it to ``path``, atomically."""
    replace_atomically(os.fspath(path), sweep_png(points, units=units, title=title))
