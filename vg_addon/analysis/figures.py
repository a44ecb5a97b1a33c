"""The report's figures, drawn with matplotlib (imported when a figure is drawn, on its Agg
backend: no window, no display needed).

Each function returns a matplotlib Figure; :func:`save` writes it as PNG and SVG without dates
or version stamps, so the same data give the same files, and returns the PNG's bytes for the
HTML page.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

#: One colour per method (Okabe-Ito, readable with colour-blindness), the paper's three first.
METHOD_COLOURS = ("#E69F00", "#0072B2", "#009E73", "#CC79A7", "#D55E00", "#56B4E9", "#F0E442")


def _pyplot():
    import matplotlib

    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    plt.rcParams.update({"svg.hashsalt": "vg-report", "figure.dpi": 100, "font.size": 9})
    return plt


def colour(index: int) -> str:
    return METHOD_COLOURS[index % len(METHOD_COLOURS)]


def save(figure, folder: Path, name: str) -> bytes:
    """Write ``folder/name.png`` and ``.svg`` and close the figure; returns the PNG bytes."""
    plt = _pyplot()
    folder.mkdir(parents=True, exist_ok=True)
    png = folder / f"{name}.png"
    figure.savefig(png, format="png", dpi=110, metadata={"Software": None})
    figure.savefig(folder / f"{name}.svg", format="svg", metadata={"Date": None, "Creator": None})
    plt.close(figure)
    return png.read_bytes()


def iov_histograms(values: dict[str, list[float]], quantity: str, unit: str):
    """One histogram of IOV per method, each on its own scale (as the paper's Figure 4)."""
    plt = _pyplot()
    names = list(values)
    figure, axes = plt.subplots(1, len(names), figsize=(3.6 * len(names), 3.2), squeeze=False)
    for i, (ax, name) in enumerate(zip(axes[0], names, strict=True)):
        data = np.asarray(values[name], dtype=np.float64)
        same = bool(len(data)) and np.ptp(data) == 0
        # All equal (the xyz method's 0): one narrow bar on the value, not a bin of width 1
        # reaching below 0, where an IOV cannot be.
        width = max(abs(float(data[0])) * 0.05, 0.05) if same else 0.0
        ax.hist(
            data,
            bins=[data[0], data[0] + width] if same else "auto",
            color=colour(i),
            edgecolor="black",
        )
        if same:
            ax.set_xlim(max(0.0, data[0] - 10 * width), data[0] + 10 * width)
        ax.set_title(f"{name} (n={len(data)}" + (f", all {data[0]:g})" if same else ")"))
        ax.set_xlabel(f"{quantity} IOV ({unit})")
        ax.set_ylabel("breaks")
    figure.suptitle(f"Histograms of {quantity} IOV per method")
    figure.tight_layout()
    return figure


def ci_plot(summaries: dict[str, object], unit: str):
    """The mean IOV of each method with its 95% and 99% confidence intervals, one panel per
    method so a tiny interval is not lost beside a wide one (the paper's Figure 5)."""
    plt = _pyplot()
    names = list(summaries)
    figure, axes = plt.subplots(1, len(names), figsize=(2.6 * len(names), 3.2), squeeze=False)
    for i, (ax, name) in enumerate(zip(axes[0], names, strict=True)):
        s = summaries[name]
        for ci, width, label in ((s.ci99, 1.0, "99% CI"), (s.ci95, 3.0, "95% CI")):
            if ci is not None:
                ax.plot([0, 0], ci, color=colour(i), linewidth=width, label=label)
        ax.plot([0], [s.mean], "o", color="black", label="mean", clip_on=False)
        ax.set_xticks([0], [name])
        ax.set_xlim(-1, 1)
        if s.ci99 is None or s.ci99[0] == s.ci99[1]:  # no spread (xyz: all 0): no axis below 0
            ax.set_ylim(max(0.0, s.mean - 1.0), s.mean + 1.0)
        ax.set_ylabel(f"mean angle IOV ({unit})")
        ax.ticklabel_format(axis="y", style="sci", scilimits=(-3, 4), useOffset=False)
        ax.set_title(name)
        if i == 0:
            ax.legend(loc="best", fontsize=7)
    figure.suptitle("Confidence intervals of the mean angle IOV")
    figure.tight_layout()
    return figure


def bland_altman_plot(ba, unit: str):
    """Differences against means with the bias and 95% limits of agreement (and their CIs)."""
    plt = _pyplot()
    figure, ax = plt.subplots(figsize=(5.2, 3.8))
    ax.scatter(ba.means, ba.differences, s=14, color=colour(1), edgecolor="black", linewidth=0.3)
    span = [float(np.min(ba.means)), float(np.max(ba.means))]
    for value, ci, label, style in (
        (ba.bias, ba.bias_ci, f"bias {ba.bias:.3g}", "-"),
        (ba.upper, ba.upper_ci, f"upper limit {ba.upper:.3g}", "--"),
        (ba.lower, ba.lower_ci, f"lower limit {ba.lower:.3g}", "--"),
    ):
        ax.axhline(value, color="black", linestyle=style, linewidth=1, label=label)
        shade = "95% CIs" if label.startswith("bias") else None
        ax.axhspan(ci[0], ci[1], color="grey", alpha=0.15, label=shade)
    pad = (span[1] - span[0]) * 0.04 if span[0] < span[1] else 1.0  # no point cut at the edge
    ax.set_xlim(span[0] - pad, span[1] + pad)
    ax.set_xlabel(f"mean of {ba.first} and {ba.second} ({unit})")
    ax.set_ylabel(f"{ba.second} − {ba.first} ({unit})")
    ax.set_title(f"Bland–Altman: {ba.second} against {ba.first} (n={ba.n})")
    ax.legend(loc="best", fontsize=7)
    figure.tight_layout()
    return figure


def distributions(groups: dict[str, list[float]], title: str, xlabel: str, unit: str):
    """Box plots of angles per group with every reading drawn over them."""
    plt = _pyplot()
    names = list(groups)
    figure, ax = plt.subplots(figsize=(max(4.0, 0.9 * len(names) + 2), 3.8))
    data = [np.asarray(groups[n], dtype=np.float64) for n in names]
    ax.boxplot(data, showfliers=False, widths=0.6)
    ax.set_xticks(range(1, len(names) + 1), names, rotation=30 if len(names) > 4 else 0)
    spread = np.random.default_rng(0)  # a fixed jitter: the same picture every run
    for i, values in enumerate(data, start=1):
        x = i + spread.uniform(-0.15, 0.15, size=len(values))
        ax.scatter(x, values, s=10, color=colour(i - 1), edgecolor="black", linewidth=0.3)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(f"angle ({unit})")
    ax.set_title(title)
    figure.tight_layout()
    return figure


def profile_plot(label: str, series: dict[str, tuple[list[int], list[float]]], unit: str):
    """The angle at each station of one break, one line per session."""
    plt = _pyplot()
    figure, ax = plt.subplots(figsize=(5.2, 3.4))
    for i, (name, (stations, angles)) in enumerate(series.items()):
        ax.plot(stations, angles, "o-", color=colour(i), label=name, markersize=3, linewidth=1)
    ax.set_xlabel("station (the anchor session's order along the break)")
    ax.set_ylabel(f"angle ({unit})")
    ax.set_title(f"Edge profile: {label}")
    ax.legend(loc="best", fontsize=6)
    figure.tight_layout()
    return figure


def regression_plots(reg, title: str):
    """Q-Q plot of the residuals and Cook's distances (the paper's Figures 7 and 8)."""
    plt = _pyplot()
    from scipy import stats

    figure, (qq, cook) = plt.subplots(1, 2, figsize=(8.0, 3.4))
    (osm, osr), (slope, intercept, _) = stats.probplot(reg.residuals, dist="norm")
    qq.scatter(osm, osr, s=10, color=colour(1))
    qq.plot(osm, slope * np.asarray(osm) + intercept, color="black", linewidth=1)
    qq.set_xlabel("theoretical quantiles (normal)")
    qq.set_ylabel("residual quantiles")
    qq.set_title("Q-Q plot of the residuals")
    cook.stem(np.arange(1, len(reg.cooks) + 1), reg.cooks, basefmt=" ")
    cook.axhline(4 / max(reg.n, 1), color="grey", linestyle="--", linewidth=1, label="4/n")
    cook.xaxis.get_major_locator().set_params(integer=True)
    cook.set_xlabel("break (row of the fit)")
    cook.set_ylabel("Cook's distance")
    cook.set_title("Cook's distances")
    cook.legend(loc="best", fontsize=7)
    figure.suptitle(title)
    figure.tight_layout()
    return figure
