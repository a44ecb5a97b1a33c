"""The report's statistics: summaries with confidence intervals, Tukey's HSD, the multiple
regression and Bland-Altman agreement.

SciPy and statsmodels are imported inside each function, so this module imports without them
(Blender's own Python has NumPy only; see :func:`vg_addon.analysis.missing_message`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .iov import Describe


@dataclass
class Summary:
    """The paper's Table 4 and 5 for one set of values: its summary and mean's CIs.

    ``ci95`` and ``ci99`` are ``(lower, upper)`` of the mean from Student's t with ``n - 1``
    degrees of freedom; ``None`` below two values.
    """

    n: int
    mean: float | None
    sd: float | None
    min: float | None
    q1: float | None
    median: float | None
    q3: float | None
    max: float | None
    ci95: tuple[float, float] | None
    ci99: tuple[float, float] | None


def mean_interval(mean: float, sd: float, n: int, confidence: float) -> tuple[float, float]:
    """Student's t interval of a mean."""
    from scipy import stats

    half = float(stats.t.ppf(0.5 + confidence / 2, n - 1)) * sd / math.sqrt(n)
    return mean - half, mean + half


def summarise(values) -> Summary:
    """Count, mean, SD, quartiles (linear interpolation, R's default type 7), min, max and the
    mean's 95% and 99% confidence intervals."""
    values = [float(v) for v in values]
    d = Describe.of(values)
    if not values:
        return Summary(0, None, None, None, None, None, None, None, None, None)
    q1, median, q3 = (float(q) for q in np.quantile(np.array(values), [0.25, 0.5, 0.75]))
    ci95 = ci99 = None
    if d.n > 1:
        ci95 = mean_interval(d.mean, d.sd, d.n, 0.95)
        ci99 = mean_interval(d.mean, d.sd, d.n, 0.99)
    return Summary(d.n, d.mean, d.sd, d.min, q1, median, q3, d.max, ci95, ci99)


@dataclass
class Comparison:
    """One pair of Tukey's HSD: ``mean(second) - mean(first)`` with its adjusted p and CI."""

    first: str
    second: str
    difference: float
    p: float
    lower: float
    upper: float

    @property
    def reject(self) -> bool:
        return self.p < 0.05


def tukey_hsd(groups: dict[str, list[float]], confidence: float = 0.95) -> list[Comparison]:
    """Tukey's honestly significant difference between every pair of groups (Tukey-Kramer for
    unequal sizes), from :func:`scipy.stats.tukey_hsd`.

    Raises
    ------
    ValueError
        Fewer than two groups, a group with fewer than two values, or no variance at all.
    """
    from scipy import stats

    names = list(groups)
    if len(names) < 2 or any(len(groups[g]) < 2 for g in names):
        raise ValueError("Tukey's HSD needs at least two methods with two or more values each")
    if all(Describe.of(groups[g]).sd == 0 for g in names):
        raise ValueError(
            "every method's values are all the same, so there is no variance to test against"
        )
    result = stats.tukey_hsd(*(np.asarray(groups[g], dtype=np.float64) for g in names))
    interval = result.confidence_interval(confidence_level=confidence)
    out = []
    for i in range(len(names)):
        for j in range(i + 1, len(names)):
            # SciPy's statistic[i, j] is mean(i) - mean(j); report mean(j) - mean(i) as R's
            # TukeyHSD and the paper's table do (second minus first).
            out.append(
                Comparison(
                    names[i],
                    names[j],
                    -float(result.statistic[i, j]),
                    float(result.pvalue[i, j]),
                    -float(interval.high[i, j]),
                    -float(interval.low[i, j]),
                )
            )
    return out


@dataclass
class Coefficient:
    name: str
    estimate: float
    se: float
    t: float
    p: float


@dataclass
class Regression:
    """An ordinary least-squares fit: its coefficients and the model's fit."""

    response: str
    n: int
    coefficients: list[Coefficient]
    r2: float
    adjusted_r2: float
    f: float
    f_p: float
    residual_se: float
    residuals: np.ndarray
    fitted: np.ndarray
    cooks: np.ndarray


def ols(y, predictors: dict[str, list[float]], response: str = "y") -> Regression:
    """Least squares of ``y`` on the predictors with an intercept (statsmodels' OLS).

    Raises
    ------
    ValueError
        Fewer rows than coefficients plus one, a response that never varies, predictors that
        are collinear, or an exact fit.
    """
    from statsmodels.regression.linear_model import OLS
    from statsmodels.tools.tools import add_constant

    y = np.asarray(y, dtype=np.float64)
    names = list(predictors)
    if len(y) <= len(names) + 1:
        raise ValueError(
            f"the regression needs more breaks ({len(y)}) than coefficients ({len(names) + 1})"
        )
    x = np.column_stack([np.asarray(predictors[n], dtype=np.float64) for n in names])
    x = add_constant(x, has_constant="add")
    if np.linalg.matrix_rank(x) < x.shape[1]:
        raise ValueError(
            "the predictors are collinear (one is constant or a combination of others)"
        )
    if not np.ptp(y) > 0:
        raise ValueError(f"every break has the same {response}, so there is nothing to explain")
    fit = OLS(y, x).fit()
    # Rounding leaves a residual of about 1e-30 where the fit is exact: none to speak of.
    if not fit.ssr > 1e-20 * float(np.sum((y - y.mean()) ** 2)):
        raise ValueError("the fit is exact (no residual), so it has no standard errors")
    coefficients = [
        Coefficient(name, float(b), float(se), float(t), float(p))
        for name, b, se, t, p in zip(
            ["(Intercept)", *names], fit.params, fit.bse, fit.tvalues, fit.pvalues, strict=True
        )
    ]
    return Regression(
        response,
        len(y),
        coefficients,
        float(fit.rsquared),
        float(fit.rsquared_adj),
        float(fit.fvalue),
        float(fit.f_pvalue),
        float(math.sqrt(fit.scale)),
        np.asarray(fit.resid),
        np.asarray(fit.fittedvalues),
        np.asarray(fit.get_influence().cooks_distance[0]),
    )


@dataclass
class BlandAltman:
    """Agreement of two sets of paired readings (Bland & Altman 1986): the bias (mean of
    ``second - first``), the SD of the differences, the 95% limits of agreement and the 95%
    CIs of the bias and of each limit (their standard error ``sqrt(3 s^2 / n)``)."""

    first: str
    second: str
    n: int
    bias: float
    sd: float
    lower: float
    upper: float
    bias_ci: tuple[float, float]
    lower_ci: tuple[float, float]
    upper_ci: tuple[float, float]
    means: np.ndarray
    differences: np.ndarray


def bland_altman(first, second, names=("first", "second")) -> BlandAltman:
    """Bland-Altman agreement of paired readings.

    Raises
    ------
    ValueError
        Fewer than three pairs, or sets of different sizes.
    """
    from scipy import stats

    a = np.asarray(first, dtype=np.float64)
    b = np.asarray(second, dtype=np.float64)
    if a.shape != b.shape or a.ndim != 1:
        raise ValueError("Bland-Altman needs two sets of paired readings of the same size")
    n = len(a)
    if n < 3:
        raise ValueError(f"Bland-Altman needs at least 3 paired readings (got {n})")
    d = Describe.of(float(v) for v in b - a)
    z = float(stats.norm.ppf(0.975))
    t = float(stats.t.ppf(0.975, n - 1))
    lower, upper = d.mean - z * d.sd, d.mean + z * d.sd
    se_bias = d.sd / math.sqrt(n)
    se_limit = math.sqrt(3 * d.sd**2 / n)
    return BlandAltman(
        names[0],
        names[1],
        n,
        d.mean,
        d.sd,
        lower,
        upper,
        (d.mean - t * se_bias, d.mean + t * se_bias),
        (lower - t * se_limit, lower + t * se_limit),
        (upper - t * se_limit, upper + t * se_limit),
        (a + b) / 2,
        b - a,
    )
