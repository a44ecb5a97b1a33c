"""The replication report's agreement sections: inter-observer IOV and the ICC, and Bland–Altman
between methods, observers and the sessions named to compare."""

from __future__ import annotations

import itertools
import math

from ..formats import csvio
from .report_context import DEG, Context, record_summary


def agreement_section(c: Context) -> None:
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
        record_summary(c, "inter-observer IOV", m, "angle", s)
        try:
            single, mean = icc.icc_absolute(complete)
        except ValueError as error:
            c.skip(f"the ICC of {m}", str(error))
            single = mean = None
        row = [m, len(observers), s.n, s.mean, s.median, s.sd, len(complete)]
        for value in (single, mean):
            row += [None] * 3 if value is None else [value.value, value.lower, value.upper]
            if value is not None and value.note:
                c.skip(f"the {value.kind} of {m}, in part", value.note)
        # F is infinite where the observers agree exactly (no error variance): no number.
        finite = single is not None and single.f is not None and math.isfinite(single.f)
        f = single.f if finite else None
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


def _pairs_to_compare(c: Context, compare) -> list[tuple[str, str, dict, dict]]:
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
    for a, b in compare:
        values = []
        for name in (a, b):
            sharing = [s for s in c.sessions if s.name == name]
            if name in c.methods and sharing:
                values = None
                c.skip(
                    f"Bland–Altman {a} against {b}",
                    f"{name!r} names both a method and a session file: rename the file, or "
                    "give the method another name (--method)",
                )
                break
            if name in c.methods:
                values.append(method_means(name))
            elif len(sharing) > 1:
                values = None
                c.skip(
                    f"Bland–Altman {a} against {b}",
                    f"{name!r} names {len(sharing)} sessions (of observers "
                    f"{', '.join(sorted({s.observer or '?' for s in sharing}))}): give the "
                    "files names of their own",
                )
                break
            elif sharing:
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


def bland_altman_section(c: Context, compare) -> None:
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
