"""The edge-profile and radius-sweep plots drawn with matplotlib, where it is installed.

matplotlib is imported only when a plot is drawn, and drawn through its object API on the Agg
canvas: no window, no display, and no change to the backend or settings of other code running
in the same Python (Blender's, another add-on's). Where it cannot be imported (a Blender whose
Python has NumPy only, docs/REPORT.md "Where it runs"), :mod:`profile_plot` and
:mod:`sweep_plot` draw their NumPy pictures instead.
"""

from __future__ import annotations

import io

import numpy as np

BLUE = "#0072B2"  # Okabe-Ito: the angles
VERMILLION = "#D55E00"  # the fit errors and station dots
PURPLE = "#CC79A7"  # refused radii
#: Text size (points) and what the saved files leave out (no dates or versions: the same data
#: give the same file).
STYLE = {"font.size": 8, "svg.hashsalt": "vg-plot", "axes.titlesize": 9}
PNG_METADATA = {"Software": None}
#: What a plot drawn without matplotlib says, with how to get it.
MISSING = (
    "plot drawn plainly: this Python has no matplotlib; install it into Blender's Python "
    "(python -m pip install matplotlib) or, in a Linux distribution's Blender, its "
    "python3-matplotlib package"
)


def available() -> bool:
    """Whether matplotlib can be imported here (a broken install counts as missing)."""
    try:
        import matplotlib  # noqa: F401
        from matplotlib.backends import backend_agg  # noqa: F401
    except Exception:
        return False
    return True


def unit_label(units: str) -> str:
    """The short form of a units label for an axis: ``"mm"`` of ``"mm"``, ``"BU"`` of
    ``"BU (1 BU = 1 m, ...)"``, ``"mesh units"`` when none is known."""
    return (units or "").split(" (")[0].strip() or "mesh units"


def _figure(width: int, height: int, dpi: float):
    import matplotlib
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    # Agg truncates figsize × dpi to whole pixels, and width / dpi × dpi can fall just short
    # (251 / 100 × 100 = 250.99…): half a pixel more makes the truncation land on the size asked.
    size = ((width + 0.5) / dpi, (height + 0.5) / dpi)
    with matplotlib.rc_context(STYLE):
        figure = Figure(figsize=size, dpi=dpi, layout="constrained")
        FigureCanvasAgg(figure)
    return figure


def rgba(figure) -> np.ndarray:
    """The figure drawn as an ``(height, width, 4)`` uint8 array, row 0 at the top."""
    import matplotlib

    with matplotlib.rc_context(STYLE):
        figure.canvas.draw()
        return np.array(figure.canvas.buffer_rgba(), dtype=np.uint8)


def png(figure) -> bytes:
    """The figure as the bytes of a PNG file."""
    import matplotlib

    buffer = io.BytesIO()
    with matplotlib.rc_context(STYLE):
        figure.savefig(buffer, format="png", metadata=PNG_METADATA)
    return buffer.getvalue()


def _legend_above(ax) -> None:
    """The axes' legend in a row above them, where it hides no data."""
    ax.legend(loc="lower left", bbox_to_anchor=(0.0, 1.0), ncol=3, frameon=False, fontsize="small")


def _foot_marks(ax, xs, marker: str, colour: str, label: str) -> None:
    """Marks at the foot of ``ax`` at the x values ``xs`` (radii without a point to draw)."""
    if len(xs):
        ax.plot(
            xs,
            np.full(len(xs), 0.04),
            marker,
            linestyle="none",
            color=colour,
            markersize=6,
            markeredgewidth=1.5,
            transform=ax.get_xaxis_transform(),  # x in data, y in fractions of the axes
            label=f"{label} ({len(xs)})",
        )


def profile_figure(arc_lengths, angles, *, width, height, dpi, units="", title="", pooled=None):
    """An edge profile: the angle at each station against its arc length along the edge, and
    the whole-edge (pooled) angle as a dashed line when given.

    Parameters
    ----------
    arc_lengths, angles : ndarray, shape (s,)
        The stations (finite, checked by the caller).
    width, height, dpi : int, int, float
        The picture's size in pixels and its resolution.
    units : str
        The mesh's length unit (``"mm"``); empty: "mesh units".
    title : str
        Above the plot; empty: "Edge profile".
    pooled : float, optional
        The whole-edge angle (degrees).
    """
    import matplotlib

    arc = np.asarray(arc_lengths, dtype=np.float64)
    angle = np.asarray(angles, dtype=np.float64)
    figure = _figure(width, height, dpi)
    with matplotlib.rc_context(STYLE):
        ax = figure.add_subplot()
        ax.plot(
            arc,
            angle,
            "-o",
            color=BLUE,
            markerfacecolor=VERMILLION,
            markeredgecolor=VERMILLION,
            markersize=3.5,
            linewidth=1.4,
            label=f"station angle ({arc.size} station{'s' * (arc.size != 1)})",
        )
        if pooled is not None and np.isfinite(pooled):
            ax.axhline(
                pooled, color="0.35", linestyle="--", linewidth=1, label=f"whole edge {pooled:.2f}°"
            )
        low, high = float(angle.min()), float(angle.max())
        pad = max((high - low) * 0.12, 1.0)  # a constant profile is a flat line in the middle
        ax.set_ylim(low - pad, high + pad)
        if arc.max() <= arc.min():
            ax.set_xlim(arc.min() - 0.5, arc.max() + 0.5)
        ax.grid(True, color="0.9", linewidth=0.6)
        ax.set_xlabel(f"arc length along the edge ({unit_label(units)})")
        ax.set_ylabel("angle (°)")
        figure.suptitle(title or "Edge profile")
        _legend_above(ax)
    return figure


def sweep_figure(radii, angles, fit_errors, *, width, height, dpi, units="", title=""):
    """A radius sweep: the angle (top) and the fit error on a log scale (bottom) against the
    radius; a refused radius is a cross at the foot of the angle panel, and the line breaks
    there.

    Parameters
    ----------
    radii : ndarray, shape (k,)
        Increasing radii.
    angles, fit_errors : ndarray, shape (k,)
        NaN where the radius was refused.
    units : str
        The mesh's length unit; the fit error (mean squared distance of each side to its plane,
        summed) is in its square.
    """
    import matplotlib

    radii = np.asarray(radii, dtype=np.float64)
    angles = np.asarray(angles, dtype=np.float64)
    fits = np.asarray(fit_errors, dtype=np.float64)
    unit = unit_label(units)
    measured = np.isfinite(angles)
    figure = _figure(width, height, dpi)
    with matplotlib.rc_context(STYLE):
        top, bottom = figure.subplots(2, 1, sharex=True)
        top.plot(radii, angles, "-o", color=BLUE, markersize=3.5, linewidth=1.4, label="angle")
        _foot_marks(top, radii[~measured], "x", PURPLE, "refused")
        if measured.any():
            low, high = float(angles[measured].min()), float(angles[measured].max())
            pad = max((high - low) * 0.15, 0.5)
            top.set_ylim(low - pad, high + pad)
        top.set_ylabel("angle (°)")
        positive = measured & (fits > 0)
        if positive.any():  # 0 has no place on a log axis: an exact fit is a mark at its foot
            bottom.set_yscale("log")
        shown = np.where(positive, fits, np.nan) if positive.any() else fits
        bottom.plot(
            radii, shown, "-o", color=VERMILLION, markersize=3.5, linewidth=1.4, label="fit error"
        )
        if positive.any():
            _foot_marks(bottom, radii[measured & ~positive], "v", VERMILLION, "exact fit, 0")
        bottom.margins(y=0.15)  # the lowest point stands clear of the marks at the foot
        bottom.set_ylabel(f"fit error ({unit}²)")
        bottom.set_xlabel(f"radius ({unit})")
        for ax in (top, bottom):
            ax.grid(True, color="0.9", linewidth=0.6)
            _legend_above(ax)
        figure.suptitle(title or "Radius sweep")
    return figure
