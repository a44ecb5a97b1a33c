"""The replication report: sessions in, ``report.html``, CSV tables and figures out.

:func:`write_report` is what ``vg_batch.py --report DIR CSV...`` and the Report operator call.
It needs SciPy, statsmodels and matplotlib (see :func:`vg_addon.analysis.missing_message`); it
refuses with that message where they are absent, before reading or writing anything.
"""

from __future__ import annotations

import os
from pathlib import Path

from ..errors import GoniometerError, bounded_list
from ..formats import csvio, files
from . import missing_message
from .html_page import Page
from .iov import QUANTITIES, break_stats, methods_of
from .matching import match_sessions
from .report_agreement import agreement_section, bland_altman_section
from .report_context import DEG, Context, Outcome
from .report_iov import angle_iov_section, virtual_section
from .sessions import load_sessions

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


def _sessions_section(c: Context, refused: list[str], unmatched: list[str]) -> None:
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


def _breaks_csv(c: Context) -> None:
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


def _distribution_section(c: Context) -> None:
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
        The libraries are missing, no session could be used, sessions hold centres and radii
        of one mesh in different coordinate spaces (``sessions.load_sessions``), or an output
        would overwrite an input; nothing is written then.
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
    c = Context(
        paths, folder, loaded.sessions, stats, methods_of(loaded.sessions), outcome, Page(title)
    )
    _sessions_section(c, loaded.refused, matched.unmatched)
    for line in loaded.notes:
        c.page.paragraph(line, note=True)
    outcome.to_check.extend(loaded.notes)
    _breaks_csv(c)
    angle_iov_section(c)
    virtual_section(c)
    agreement_section(c)
    bland_altman_section(c, compare)
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
