"""The replication report's IOV sections: the angle IOV by method (the paper's Tables 4 to 6,
Tukey's HSD), the IOV of vertices, radius and centre, and the regression of its Table 7."""

from __future__ import annotations

import math

from ..formats import csvio
from .iov import QUANTITIES
from .report_context import DEG, Context, iov_values, record_summary, summary_table


def angle_iov_section(c: Context) -> None:
    from . import figures, stats

    page = c.page
    page.heading("Angle IOV by method")
    with_iov = [m for m in c.methods if iov_values(c.stats, m, "angle")]
    for m in c.methods:
        if m not in with_iov:
            c.skip(f"angle IOV of {m}", "no break was measured twice or more with it")
    if not with_iov:
        return
    common = {
        id(b)
        for b in c.stats
        if all(b.methods.get(m) and b.methods[m].iov["angle"] is not None for m in with_iov)
    }
    groups = {m: iov_values(c.stats, m, "angle", common) for m in with_iov}
    n = len(common)
    page.paragraph(
        "The IOV of a break is the mean absolute difference over all pairs of one observer's "
        "readings (the paper's equation 4.1); with several observers, the mean of their IOVs. "
        f"This section uses the {n} breaks measured at least twice by every method "
        f"({', '.join(with_iov)}), as the paper's Table 4 does."
    )
    if n == 0:
        c.skip("the comparison of methods", "no break was measured twice by every method")
        return
    summaries = {m: stats.summarise(groups[m]) for m in with_iov}
    for m, s in summaries.items():
        record_summary(c, "angle IOV, breaks of every method", m, "angle", s)
    page.table(
        f"Summary statistics for angle IOV ({DEG}), n = {n}",
        ["statistic", *with_iov],
        summary_table(summaries),
    )
    c.figure(
        figures.iov_histograms(groups, "angle", DEG),
        "iov_histograms",
        f"Histograms of angle IOV per method (n={n}); each on its own scale.",
    )
    rows = []
    for m, s in summaries.items():
        row = [m, s.mean]
        for ci in (s.ci95, s.ci99):
            row += [None] * 4 if ci is None else [ci[0], ci[1], ci[1] - ci[0], (ci[1] - ci[0]) / 2]
        rows.append(row)
    page.table(
        "Confidence intervals of the mean angle IOV (Student's t, n − 1 degrees of freedom)",
        [
            "method",
            "mean",
            "95% lower",
            "95% upper",
            "range",
            "±",
            "99% lower",
            "99% upper",
            "range",
            "±",
        ],
        rows,
    )
    if any(s.ci95 for s in summaries.values()):
        c.figure(
            figures.ci_plot({m: s for m, s in summaries.items() if s.ci95}, DEG),
            "ci_plot",
            "Mean angle IOV with its 95% (thick) and 99% (thin) confidence intervals.",
        )
    _tukey(c, groups)


def _tukey(c: Context, groups) -> None:
    from . import stats

    if len(groups) < 2:
        c.skip("Tukey's HSD", "it needs two or more methods")
        return
    try:
        pairs = stats.tukey_hsd(groups)
    except ValueError as error:
        c.skip("Tukey's HSD", str(error))
        return
    rows = [[p.first, p.second, p.difference, p.p, p.lower, p.upper, p.reject] for p in pairs]
    c.page.table(
        "Tukey's HSD between methods (angle IOV; difference = group 2 − group 1; 95% family "
        "confidence)",
        ["group 1", "group 2", "difference", "p adjusted", "lower", "upper", "reject"],
        rows,
        text_columns=2,
    )
    csvio.write_table(
        c.folder / "tukey.csv",
        ["Group 1", "Group 2", "Difference", "P Adjusted", "Lower", "Upper", "Reject"],
        rows,
    )


def virtual_section(c: Context) -> None:
    from . import stats

    page = c.page
    located = [m for m in c.methods if iov_values(c.stats, m, "centre")]
    page.heading("IOV of angle, vertices, radius and centre (methods with centres)")
    if not located:
        c.skip("the IOV of vertices, radius and centre", "no method's sessions have centres")
        return
    header = ["statistic"]
    columns = []
    for m in located:
        for q in ("angle", "vertices", "radius", "centre"):
            header.append(f"{m} {q}")
            s = stats.summarise(iov_values(c.stats, m, q))
            columns.append(s)
            record_summary(c, "IOV, every break of the method", m, q, s)
    page.table(
        f"Summary statistics for IOV (angle {DEG}; vertices; radius and centre in mesh units), "
        "every break the method measured twice or more",
        header,
        summary_table(dict(enumerate(columns))),
    )
    _regressions(c, located)


def _regressions(c: Context, located: list[str]) -> None:
    from . import figures, stats

    page = c.page
    page.heading("Multiple regression of log angle IOV on vertices, radius and location IOV")
    page.paragraph(
        "ln(angle IOV) = b0 + b1·vertices IOV + b2·radius IOV + b3·location IOV, least squares "
        "(the paper's Table 7). Breaks whose angle IOV is 0 have no logarithm and are left out of "
        "the fit, counted below."
    )
    rows_csv = []
    for m in located:
        rows = [
            b.methods[m].iov
            for b in c.stats
            if m in b.methods and all(b.methods[m].iov[q] is not None for q in QUANTITIES)
        ]
        zero = [r for r in rows if r["angle"] <= 0]
        rows = [r for r in rows if r["angle"] > 0]
        if zero and not rows:
            c.skip(
                f"the regression for {m}",
                f"the angle IOV of every break ({len(zero)}) is 0: no logarithm, nothing varies",
            )
            continue
        if zero:
            line = f"regression of {m}: {len(zero)} breaks with angle IOV 0 (no logarithm)"
            c.outcome.not_computed.append(line)
            page.paragraph(line, note=True)
        try:
            reg = stats.ols(
                [math.log(r["angle"]) for r in rows],
                {f"{q} IOV": [r[q] for r in rows] for q in ("vertices", "radius", "centre")},
                response="ln(angle IOV)",
            )
        except ValueError as error:
            c.skip(f"the regression for {m}", str(error))
            continue
        table = [[k.name, k.estimate, k.se, k.t, k.p] for k in reg.coefficients]
        page.table(
            f"{m}: multiple regression results (n={reg.n}); R² {reg.r2:.4g}, adjusted R² "
            f"{reg.adjusted_r2:.4g}, F {reg.f:.4g}, p {reg.f_p:.4g}",
            ["", "estimate", "std. error", "t", "p"],
            table,
        )
        rows_csv += [[m, *row, reg.n, reg.r2, reg.adjusted_r2, reg.f, reg.f_p] for row in table]
        c.figure(
            figures.regression_plots(reg, f"{m}: ln(angle IOV) regression residuals"),
            f"regression_{m}",
            f"{m}: Q-Q plot of the regression's residuals and Cook's distances.",
        )
    csvio.write_table(
        c.folder / "regression.csv",
        ["Method", "Term", "Estimate", "Std Error", "t", "p", "n", "R2", "Adjusted R2", "F", "F p"],
        rows_csv,
    )
