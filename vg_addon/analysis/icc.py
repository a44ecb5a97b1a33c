"""Intraclass correlation: two-way model, absolute agreement (McGraw & Wong 1996, case 2A;
Shrout & Fleiss 1979, ICC(2,1) and ICC(2,k)).

The mean squares come from the two-way ANOVA without replication (targets x raters); the
confidence limits are McGraw & Wong's (their Table 7), with Satterthwaite's degrees of freedom,
from SciPy's F distribution. SciPy is imported when :func:`icc_absolute` runs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass
class TwoWay:
    """The two-way ANOVA of an ``n x k`` table: targets (rows) by raters (columns)."""

    n: int
    k: int
    ms_rows: float
    ms_columns: float
    ms_error: float
    ms_within: float


@dataclass
class ICC:
    """One ICC with its 95% confidence interval and F test.

    ``value``, ``lower``, ``upper``, ``f`` and ``p`` are None where the table leaves them
    undefined (a zero denominator, a limit beyond the Spearman-Brown step's pole); ``note``
    then says why, for the report.
    """

    kind: str
    value: float | None
    lower: float | None
    upper: float | None
    f: float | None
    df1: int
    df2: int
    p: float | None
    note: str = ""


def _fsum(values) -> float:
    return math.fsum(float(v) for v in np.ravel(values))


def two_way(table) -> TwoWay:
    """The mean squares of a complete ``n x k`` table (no missing cells), summed exactly.

    Each sum of squares is summed from its own deviations (never one sum less others, which
    leaves rounding residue of either sign), and a sum within rounding of zero is zero: a table
    whose observers are a constant apart has no error variance, not 1e-15 of it.
    """
    x = np.asarray(table, dtype=np.float64)
    n, k = x.shape
    grand = _fsum(x) / (n * k)
    row_means = np.array([_fsum(row) / k for row in x])
    col_means = np.array([_fsum(col) / n for col in x.T])
    # Each deviation carries a few units in the last place of the table's largest value.
    floor = n * k * (8.0 * np.finfo(np.float64).eps * float(np.max(np.abs(x)))) ** 2

    def summed(deviations) -> float:
        total = _fsum(np.square(deviations))
        return total if total > floor else 0.0

    ss_rows = k * summed(row_means - grand)
    ss_cols = n * summed(col_means - grand)
    ss_error = summed(x - row_means[:, None] - col_means[None, :] + grand)
    ss_within = summed(x - row_means[:, None])
    return TwoWay(
        n,
        k,
        ss_rows / (n - 1),
        ss_cols / (k - 1),
        ss_error / ((n - 1) * (k - 1)),
        ss_within / (n * (k - 1)),
    )


def icc_absolute(table, confidence: float = 0.95) -> tuple[ICC, ICC]:
    """ICC(A,1) and ICC(A,k): absolute agreement of single raters and of the mean of ``k``.

    Parameters
    ----------
    table : array_like, shape (n, k)
        One row per target (break), one column per rater (observer); complete.
    confidence : float
        Of the interval.

    Returns
    -------
    single, mean : ICC

    Raises
    ------
    ValueError
        Fewer than 2 targets or raters, a cell that is not finite, every rating the same, or a
        table whose variance estimate is not positive: ICC(A,1) is undefined. Figures the table
        leaves undefined beyond that are None, with the reason in :attr:`ICC.note`.
    """
    from scipy import stats

    x = np.asarray(table, dtype=np.float64)
    if x.ndim != 2 or x.shape[0] < 2 or x.shape[1] < 2:
        raise ValueError("the ICC needs at least 2 breaks rated by at least 2 observers")
    if not np.all(np.isfinite(x)):
        raise ValueError("the ICC needs a finite rating in every cell")
    a = two_way(x)
    n, k = a.n, a.k
    msr, msc, mse = a.ms_rows, a.ms_columns, a.ms_error
    if msr == 0 and msc == 0 and mse == 0:
        raise ValueError("every rating is the same, so the ICC is undefined")
    denominator = msr + (k - 1) * mse + k * (msc - mse) / n
    if not denominator > 0:
        raise ValueError(
            "the ICC is undefined for this table: its variance estimate "
            "MSR + (k-1) MSE + k (MSC - MSE) / n is not positive (too few breaks for the ANOVA "
            "to tell breaks, observers and error apart)"
        )
    single = (msr - mse) / denominator
    df1, df2 = n - 1, (n - 1) * (k - 1)
    if mse > 0:
        f = msr / mse
        p = float(stats.f.sf(f, df1, df2))
    else:  # no error variance: F is infinite where the breaks differ, undefined where not
        f = math.inf if msr > 0 else None
        p = 0.0 if msr > 0 else None
    lower, upper, why = _single_limits(a, single, 1 - confidence, stats)
    single_icc = ICC("ICC(A,1)", single, lower, upper, f, df1, df2, p, why)
    mean_denominator = msr + (msc - mse) / n
    if not mean_denominator > 0:
        note = f"ICC(A,{k}) is undefined for this table: MSR + (MSC - MSE) / n is not positive"
        return single_icc, ICC(f"ICC(A,{k})", None, None, None, f, df1, df2, p, note)
    mean = (msr - mse) / mean_denominator
    lower_k, upper_k, why_k = _spearman_brown(lower, upper, k, why)
    return single_icc, ICC(f"ICC(A,{k})", mean, lower_k, upper_k, f, df1, df2, p, why_k)


def _single_limits(a: TwoWay, single: float, alpha: float, stats) -> tuple:
    """ICC(A,1)'s confidence limits (McGraw & Wong 1996, Table 7, case 2A: Satterthwaite's
    degrees of freedom for the denominator's mix of the rater and error mean squares), as
    ``(lower, upper, "")``, or ``(None, None, why)`` where the table leaves them undefined."""
    n, k = a.n, a.k
    msr, msc, mse = a.ms_rows, a.ms_columns, a.ms_error
    if single >= 1:
        return 1.0, 1.0, ""
    ca = k * single / (n * (1 - single))
    cb = 1 + k * single * (n - 1) / (n * (1 - single))
    spread_of_mix = (ca * msc) ** 2 / (k - 1) + (cb * mse) ** 2 / ((n - 1) * (k - 1))
    undefined = (
        None,
        None,
        "the ICC's confidence interval is undefined for this table: Satterthwaite's degrees of "
        "freedom for it are 0 or cannot be formed (too few breaks, or no error variance)",
    )
    if not spread_of_mix > 0:
        return undefined
    v = (ca * msc + cb * mse) ** 2 / spread_of_mix
    f_upper = float(stats.f.ppf(1 - alpha / 2, n - 1, v))
    f_lower = float(stats.f.ppf(1 - alpha / 2, v, n - 1))
    spread = k * msc + (k * n - k - n) * mse
    lower_denominator = f_upper * spread + n * msr
    upper_denominator = spread + n * f_lower * msr
    if not (
        v > 0 and math.isfinite(v) and math.isfinite(f_upper) and math.isfinite(f_lower)
    ) or not (lower_denominator != 0 and upper_denominator != 0):
        return undefined
    lower = n * (msr - f_upper * mse) / lower_denominator
    upper = n * (f_lower * msr - mse) / upper_denominator
    return lower, upper, ""


def _spearman_brown(lower, upper, k: int, why: str) -> tuple:
    """The mean of ``k`` raters' limits from a single rater's, by the Spearman-Brown step
    ``k r / (1 + (k-1) r)``. The step has a pole at ``r = -1/(k-1)``: a single-rater limit at or
    below it leaves the mean's limit unbounded below (not the number past the pole)."""
    if lower is None:
        return None, None, why
    pole = -1.0 / (k - 1)
    if upper <= pole:
        return (
            None,
            None,
            (
                f"ICC(A,{k})'s confidence interval is undefined: the single-rater interval "
                f"[{lower:.3g}, {upper:.3g}] lies below -1/(k-1) = {pole:.3g}"
            ),
        )
    upper_k = k * upper / (1 + (k - 1) * upper)
    if lower <= pole:
        return (
            None,
            upper_k,
            (
                f"ICC(A,{k})'s lower limit is unbounded below: the single-rater lower limit "
                f"{lower:.3g} is at or below -1/(k-1) = {pole:.3g}"
            ),
        )
    return k * lower / (1 + (k - 1) * lower), upper_k, ""
