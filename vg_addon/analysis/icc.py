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
    """One ICC with its 95% confidence interval and F test (``value > 0``)."""

    kind: str
    value: float
    lower: float
    upper: float
    f: float
    df1: int
    df2: int
    p: float


def _fsum(values) -> float:
    return math.fsum(float(v) for v in np.ravel(values))


def two_way(table) -> TwoWay:
    """The mean squares of a complete ``n x k`` table (no missing cells), summed exactly."""
    x = np.asarray(table, dtype=np.float64)
    n, k = x.shape
    grand = _fsum(x) / (n * k)
    row_means = np.array([_fsum(row) / k for row in x])
    col_means = np.array([_fsum(col) / n for col in x.T])
    ss_rows = k * _fsum((row_means - grand) ** 2)
    ss_cols = n * _fsum((col_means - grand) ** 2)
    ss_total = _fsum((x - grand) ** 2)
    ss_error = ss_total - ss_rows - ss_cols
    ss_within = ss_total - ss_rows
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
        Fewer than 2 targets or raters, or no variation at all (the ICC is undefined).
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
    denominator = msr + (k - 1) * mse + k * (msc - mse) / n
    if not denominator > 0 or (mse == 0 and msr == 0):
        raise ValueError("the ratings do not vary, so the ICC is undefined")
    single = (msr - mse) / denominator
    mean = (msr - mse) / (msr + (msc - mse) / n)
    f = msr / mse if mse > 0 else math.inf
    df1, df2 = n - 1, (n - 1) * (k - 1)
    p = float(stats.f.sf(f, df1, df2)) if math.isfinite(f) else 0.0
    alpha = 1 - confidence
    # McGraw & Wong (1996), Table 7, case 2A: Satterthwaite's degrees of freedom for the
    # denominator's mix of the rater and error mean squares.
    ca = k * single / (n * (1 - single)) if single < 1 else math.inf
    cb = 1 + k * single * (n - 1) / (n * (1 - single)) if single < 1 else math.inf
    if math.isfinite(ca):
        v = (ca * msc + cb * mse) ** 2 / (
            (ca * msc) ** 2 / (k - 1) + (cb * mse) ** 2 / ((n - 1) * (k - 1))
        )
        f_upper = float(stats.f.ppf(1 - alpha / 2, n - 1, v))
        f_lower = float(stats.f.ppf(1 - alpha / 2, v, n - 1))
        spread = k * msc + (k * n - k - n) * mse
        lower = n * (msr - f_upper * mse) / (f_upper * spread + n * msr)
        upper = n * (f_lower * msr - mse) / (spread + n * f_lower * msr)
    else:
        lower = upper = 1.0
    # The mean of k raters: the Spearman-Brown step of each limit.
    lower_k = k * lower / (1 + (k - 1) * lower)
    upper_k = k * upper / (1 + (k - 1) * upper)
    return (
        ICC("ICC(A,1)", single, lower, upper, f, df1, df2, p),
        ICC(f"ICC(A,{k})", mean, lower_k, upper_k, f, df1, df2, p),
    )
