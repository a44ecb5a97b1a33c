"""The replication report: sessions in, ``report.html``, CSV tables and figures out.

:func:`write_report` is what ``vg_batch.py --report DIR CSV...`` and the Report operator call.
It needs SciPy, statsmodels and matplotlib (see :func:`vg_addon.analysis.missing_message`); it
refuses with that message where they are absent, before reading or writing anything.
"""

from __future__ import annotations

import itertools
import math
import os
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import GoniometerError, bounded_list
from ..formats import csvio, files
from . import missing_message
from .html_page import Page
from .iov import QUANTITIES, BreakStats, break_stats, methods_of
from .matching import match_sessions
from .sessions import Session, load_sessions

DEG = "°"
OUTPUT_FILES = (
    "report.html",
    "breaks.csv",
    "summary.csv",
    "tukey.csv",
    "regression.csv",
    "agreement.csv",
    "bland_altman.csv",
    "sessions.csv",
    "left_out.csv",
)
FIGURES = "figures"


@dataclass
class Outcome:
    """What a report used, what it left out and where it went.

    Attributes
    ----------
    folder : pathlib.Path
    sessions : int
        Sessions used.
    readings, rows : int
        Readings used in the analysis, and data rows read in all files.
    left_out : list of str
        One line per file, session, row or break left out, with its reason.
    not_computed : list of str
        One line per table or figure that could not be computed, with its reason.
    figures : list of str
        The figures' names (each written as ``figures/NAME.png`` and ``.svg``).
    """

    folder: Path
    sessions: int = 0
    readings: int = 0
    rows: int = 0
    left_out: list[str] = field(default_factory=list)
    not_computed: list[str] = field(default_factory=list)
    figures: list[str] = field(default_factory=list)

    @property
    def code(self) -> int:
        """0: everything read was used; 1: the report was written, something was left out."""
        return 1 if self.left_out else 0


def _check_outputs(paths, folder: Path) -> None:
    inputs = {os.path.realpath(os.fspath(p)) for p in paths}
    for name in OUTPUT_FILES:
        if os.path.realpath(folder / name) in inputs:
            raise GoniometerError(
                f"{folder / name} is one of the sessions given; the report would overwrite it. "
                "Choose another report folder."
            )
    if folder.exists() and not folder.is_dir():
        raise GoniometerError(f"{folder} exists and is not a folder.")


def _values(stats: list[BreakStats], method: str, quantity: str, units=None) -> list[float]:
    out = []
    for b in stats:
        if units is not None and id(b) not in units:
            continue
        m = b.methods.get(method)
        if m is not None and m.iov[quantity] is not None:
            out.append(m.iov[quantity])
    return out


def _summary_rows(summaries: dict[str, object]) -> list[list]:
    rows = []
    for label, attribute in (
        ("N", "n"),
        ("min", "min"),
        ("Q1", "q1"),
        ("mean", "mean"),
        ("median", "median"),
        ("Q3", "q3"),
        ("max", "max"),
        ("SD", "sd"),
    ):
        rows.append([label, *(getattr(s, attribute) for s in summaries.values())])
    return rows


@dataclass
class _Context:
    paths: list
    folder: Path
    sessions: list[Session]
    stats: list[BreakStats]
    methods: list[str]
    outcome: Outcome
    page: Page
    summary_rows: list = field(default_factory=list)

    @property
    def figures(self) -> Path:
        return self.folder / FIGURES

    def figure(self, figure, name: str, caption: str) -> None:
        from .figures import save

        self.page.figure(save(figure, self.figures, name), caption)
        self.outcome.figures.append(name)

    def skip(self, what: str, why: str) -> None:
        line = f"{what}: not computed, {why}"
        self.outcome.not_computed.append(line)
        self.page.paragraph(line, note=True)


def _sessions_section(c: _Context, refused: list[str], unmatched: list[str]) -> None:
    page = c.page
    page.heading("Sessions")
    rows = [
        [s.name, s.method, s.observer, s.rows, len(s.readings), len(s.left_out)] for s in c.sessions
    ]
    page.table(
        "One session per CSV: one observer, one method, one repetition",
        ["session", "method", "observer", "rows", "used", "left out"],
        rows,
        text_columns=3,
    )
    csvio.write_table(
        c.folder / "sessions.csv",
        ["Session", "Method", "Observer", "Rows", "Used", "Left Out", "File"],
        [[*row, s.source] for row, s in zip(rows, c.sessions, strict=True)],
    )
    left = list(refused)
    for s in c.sessions:
        left += [f"{s.name}: {line}" for line in s.left_out]
    left += unmatched
    alone = [
        b.unit.label + f": only in {c.sessions[next(iter(b.unit.readings))].name}"
        for b in c.stats
        if len(b.unit.readings) == 1
    ]
    left += [f"{line}; no IOV" for line in alone]
    c.outcome.left_out.extend(left)
    used = sum(len(b.unit.readings) for b in c.stats if len(b.unit.readings) > 1)
    c.outcome.readings = used
    page.paragraph(
        f"{len(c.sessions)} sessions, {c.outcome.rows} rows read, {used} readings used in "
        f"{sum(len(b.unit.readings) > 1 for b in c.stats)} breaks measured in two or more "
        f"sessions; {len(left)} lines left out:"
    )
    page.lines(left)
    csvio.write_table(
        c.folder / "left_out.csv", ["What", "Reason"], [line.split(": ", 1) for line in left]
    )


def _breaks_csv(c: _Context) -> None:
    header = ["Mesh", "Break #", "Station", "Sessions"]
    per_method = [
        "n",
        "observers",
        "repetitions",
        "mean angle",
        "SD angle",
        "min angle",
        "max angle",
        "angle IOV",
        "centre IOV",
        "radius IOV",
        "vertices IOV",
        "inter-observer IOV",
    ]
    header += [f"{m} {column}" for m in c.methods for column in per_method]
    rows = []
    for b in c.stats:
        row = [b.unit.mesh, b.unit.break_number, b.unit.station, len(b.unit.readings)]
        for m in c.methods:
            s = b.methods.get(m)
            if s is None:
                row += [None] * len(per_method)
                continue
            row += [
                s.angle.n,
                len(s.observer_means),
                s.repetitions,
                s.angle.mean,
                s.angle.sd,
                s.angle.min,
                s.angle.max,
                *(s.iov[q] for q in QUANTITIES),
                s.inter_iov,
            ]
        rows.append(row)
    csvio.write_table(c.folder / "breaks.csv", header, rows)


def _summary_record(c: _Context, table: str, method: str, quantity: str, s) -> None:
    ci95 = s.ci95 or (None, None)
    ci99 = s.ci99 or (None, None)
    c.summary_rows.append(
        [
            table,
            method,
            quantity,
            s.n,
            s.mean,
            s.sd,
            s.min,
            s.q1,
            s.median,
            s.q3,
            s.max,
            *ci95,
            *ci99,
        ]
    )


def _angle_iov_section(c: _Context) -> None:
    from . import figures, stats

    page = c.page
    page.heading("Angle IOV by method")
    with_iov = [m for m in c.methods if _values(c.stats, m, "angle")]
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
    groups = {m: _values(c.stats, m, "angle", common) for m in with_iov}
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
        _summary_record(c, "angle IOV, breaks of every method", m, "angle", s)
    page.table(
        f"Summary statistics for angle IOV ({DEG}), n = {n}",
        ["statistic", *with_iov],
        _summary_rows(summaries),
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


def _tukey(c: _Context, groups) -> None:
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


def _virtual_section(c: _Context) -> None:
    from . import stats

    page = c.page
    located = [m for m in c.methods if _values(c.stats, m, "centre")]
    page.heading("IOV of angle, vertices, radius and centre (methods with centres)")
    if not located:
        c.skip("the IOV of vertices, radius and centre", "no method's sessions have centres")
        return
    header = ["statistic"]
    columns = []
    for m in located:
        for q in ("angle", "vertices", "radius", "centre"):
            header.append(f"{m} {q}")
            s = stats.summarise(_values(c.stats, m, q))
            columns.append(s)
            _summary_record(c, "IOV, every break of the method", m, q, s)
    page.table(
        f"Summary statistics for IOV (angle {DEG}; vertices; radius and centre in mesh units), "
        "every break the method measured twice or more",
        header,
        _summary_rows(dict(enumerate(columns))),
    )
    _regressions(c, located)


def _regressions(c: _Context, located: list[str]) -> None:
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


def _agreement_section(c: _Context) -> None:
    from . import icc, stats

    page = c.page
    page.heading("Inter-observer agreement")
    rows = []
    for m in c.methods:
        observers = sorted({s.observer for s in c.sessions if s.method == m})
        if len(observers) < 2:
            c.skip(f"inter-observer agreement of {m}", "it needs two or more observers")
            continue
        inter = [b.methods[m].inter_iov for b in c.stats if m in b.methods]
        inter = [v for v in inter if v is not None]
        complete = [
            [b.methods[m].observer_means[o] for o in observers]
            for b in c.stats
            if m in b.methods and all(o in b.methods[m].observer_means for o in observers)
        ]
        s = stats.summarise(inter)
        _summary_record(c, "inter-observer IOV", m, "angle", s)
        try:
            single, mean = icc.icc_absolute(complete)
        except ValueError as error:
            c.skip(f"the ICC of {m}", str(error))
            single = mean = None
        row = [m, len(observers), s.n, s.mean, s.median, s.sd, len(complete)]
        for value in (single, mean):
            row += [None] * 3 if value is None else [value.value, value.lower, value.upper]
        # F is infinite where the observers agree exactly (no error variance): no number.
        f = single.f if single is not None and math.isfinite(single.f) else None
        row += [None] * 4 if single is None else [f, single.df1, single.df2, single.p]
        rows.append(row)
    if not rows:
        return
    page.paragraph(
        "Inter-observer IOV: the mean absolute angle difference over pairs of readings by "
        "different observers. ICC: two-way random model, absolute agreement, of each observer's "
        "mean angle per break (McGraw & Wong 1996 ICC(A,1) and ICC(A,k), Shrout & Fleiss 1979 "
        "ICC(2,1) and ICC(2,k)), over the breaks every observer measured; 95% CIs."
    )
    header = ["method", "observers", "breaks", "mean inter IOV", "median", "SD", "ICC breaks"]
    header += ["ICC(A,1)", "lower", "upper", "ICC(A,k)", "lower", "upper", "F", "df1", "df2", "p"]
    page.table(f"Inter-observer agreement (angle, {DEG})", header, rows)
    csvio.write_table(c.folder / "agreement.csv", header, rows)


def _pairs_to_compare(c: _Context, compare) -> list[tuple[str, str, dict, dict]]:
    """``(name a, name b, unit -> value a, unit -> value b)`` for each pair of methods, each pair
    of observers within a method, and each pair named with ``compare`` (methods or sessions)."""

    def method_means(m):
        return {
            id(b): b.methods[m].angle.mean
            for b in c.stats
            if m in b.methods and b.methods[m].angle.mean is not None
        }

    def observer_means(m, o):
        return {
            id(b): b.methods[m].observer_means[o]
            for b in c.stats
            if m in b.methods and o in b.methods[m].observer_means
        }

    def session_values(name):
        index = [i for i, s in enumerate(c.sessions) if s.name == name]
        return {
            id(b): b.unit.readings[index[0]].angle for b in c.stats if index[0] in b.unit.readings
        }

    pairs = [
        (a, b, method_means(a), method_means(b)) for a, b in itertools.combinations(c.methods, 2)
    ]
    for m in c.methods:
        observers = sorted({s.observer for s in c.sessions if s.method == m})
        for a, b in itertools.combinations(observers, 2):
            pairs.append((f"{m} {a}", f"{m} {b}", observer_means(m, a), observer_means(m, b)))
    names = {s.name for s in c.sessions}
    for a, b in compare:
        values = []
        for name in (a, b):
            if name in c.methods:
                values.append(method_means(name))
            elif name in names:
                values.append(session_values(name))
            else:
                values = None
                c.skip(
                    f"Bland–Altman {a} against {b}",
                    f"{name!r} is neither a method ({', '.join(c.methods)}) nor a session",
                )
                break
        if values:
            pairs.append((a, b, *values))
    return pairs


def _bland_altman_section(c: _Context, compare) -> None:
    from . import figures, stats

    c.page.heading("Bland–Altman agreement")
    rows = []
    plots = []
    for index, (a, b, first, second) in enumerate(_pairs_to_compare(c, compare), start=1):
        shared = [u for u in first if u in second]
        try:
            ba = stats.bland_altman(
                [first[u] for u in shared], [second[u] for u in shared], names=(a, b)
            )
        except ValueError as error:
            c.skip(f"Bland–Altman {b} against {a}", str(error))
            continue
        rows.append(
            [
                a,
                b,
                ba.n,
                ba.bias,
                ba.sd,
                ba.lower,
                ba.upper,
                *ba.bias_ci,
                *ba.lower_ci,
                *ba.upper_ci,
            ]
        )
        plots.append((index, a, b, ba))
    header = ["first", "second", "n", "bias", "SD", "lower limit", "upper limit", "bias CI low"]
    header += ["bias CI high", "lower limit CI low", "lower limit CI high", "upper limit CI low"]
    header += ["upper limit CI high"]
    if rows:
        c.page.table(
            f"Bland–Altman: bias (second − first) and 95% limits of agreement ({DEG})",
            header,
            rows,
            text_columns=2,
        )
    for index, a, b, ba in plots:
        c.figure(
            figures.bland_altman_plot(ba, DEG),
            f"bland_altman_{index}",
            f"Bland–Altman plot of {b} against {a} (mean angle per break); shaded: 95% CIs.",
        )
    csvio.write_table(c.folder / "bland_altman.csv", header, rows)


def _distribution_section(c: _Context) -> None:
    from . import figures

    c.page.heading("Angle distributions")
    by_method: dict[str, list[float]] = {}
    by_mesh: dict[str, list[float]] = {}
    for b in c.stats:
        for s, r in b.unit.readings.items():
            by_method.setdefault(c.sessions[s].method, []).append(r.angle)
            by_mesh.setdefault(b.unit.mesh, []).append(r.angle)
    by_method = {m: by_method[m] for m in c.methods if m in by_method}
    by_kind: dict[str, list[float]] = {}
    for b in c.stats:
        kinds = [r.kind for r in b.unit.readings.values() if r.kind]
        if kinds:
            by_kind.setdefault(kinds[0], []).extend(r.angle for r in b.unit.readings.values())
    c.figure(
        figures.distributions(by_method, "Angles by method (every reading)", "method", DEG),
        "angles_by_method",
        "Angles by method: box plots (quartiles, whiskers to 1.5 IQR) with every reading.",
    )
    c.figure(
        figures.distributions(dict(sorted(by_mesh.items())), "Angles by mesh", "mesh", DEG),
        "angles_by_mesh",
        "Angles by mesh, every reading of every method.",
    )
    if by_kind:
        c.figure(
            figures.distributions(
                dict(sorted(by_kind.items())), "Angles by break type", "type", DEG
            ),
            "angles_by_type",
            "Angles by break type (the Break Type column), every reading of every method.",
        )
    profiles: dict[tuple[str, int], dict[str, tuple[list[int], list[float]]]] = {}
    for b in c.stats:
        if not b.unit.several:
            continue
        series = profiles.setdefault((b.unit.mesh, b.unit.break_number), {})
        for s, r in b.unit.readings.items():
            stations, angles = series.setdefault(c.sessions[s].name, ([], []))
            stations.append(b.unit.station)
            angles.append(r.angle)
    for index, ((mesh, number), series) in enumerate(sorted(profiles.items()), start=1):
        c.figure(
            figures.profile_plot(f"{mesh} break {number}", series, DEG),
            f"profile_{index}",
            f"Edge profile of {mesh} break {number}: the angle at each matched station.",
        )


def write_report(
    paths,
    folder,
    *,
    methods=None,
    observers=None,
    compare=(),
    title: str = "Virtual Goniometer replication report",
) -> Outcome:
    """Read the sessions, compute the paper's Section 4 analysis and write the report.

    Parameters
    ----------
    paths : sequence of path-like
        The session CSVs.
    folder : path-like
        Where ``report.html``, the CSV tables and ``figures/`` go (made if missing).
    methods, observers : sequence of str, optional
        One per file, or one for all; over the files' own columns and names.
    compare : sequence of (str, str)
        Extra Bland–Altman pairs, each a method or a session name.

    Returns
    -------
    Outcome

    Raises
    ------
    GoniometerError
        The libraries are missing, no session could be used, or an output would overwrite an
        input; nothing is written then.
    """
    missing = missing_message()
    if missing:
        raise GoniometerError(missing)
    paths = list(paths)
    if not paths:
        raise GoniometerError("give the session CSVs to report on (one per session)")
    folder = Path(folder)
    _check_outputs(paths, folder)
    loaded = load_sessions(paths, methods, observers)
    if not loaded.sessions:
        raise GoniometerError(
            "no session could be used; nothing was written:\n"
            + bounded_list(loaded.refused, lines=True)
        )
    folder.mkdir(parents=True, exist_ok=True)
    matched = match_sessions(loaded.sessions)
    outcome = Outcome(folder, len(loaded.sessions), rows=sum(s.rows for s in loaded.sessions))
    stats = break_stats(matched.units, loaded.sessions)
    c = _Context(
        paths, folder, loaded.sessions, stats, methods_of(loaded.sessions), outcome, Page(title)
    )
    _sessions_section(c, loaded.refused, matched.unmatched)
    _breaks_csv(c)
    _angle_iov_section(c)
    _virtual_section(c)
    _agreement_section(c)
    _bland_altman_section(c, compare)
    _distribution_section(c)
    csvio.write_table(
        folder / "summary.csv",
        [
            "Table",
            "Method",
            "Quantity",
            "N",
            "Mean",
            "SD",
            "Min",
            "Q1",
            "Median",
            "Q3",
            "Max",
            "CI95 Low",
            "CI95 High",
            "CI99 Low",
            "CI99 High",
        ],
        c.summary_rows,
    )
    c.page.paragraph(
        "Statistics: SciPy (t and F distributions, Tukey's HSD), statsmodels (least squares); "
        "IOV, means and SDs summed exactly in a fixed order. Figures: matplotlib. Tables as "
        "CSV and figures as PNG and SVG beside this file.",
        note=True,
    )
    files.replace_atomically(folder / "report.html", c.page.text().encode("utf-8"))
    return outcome
