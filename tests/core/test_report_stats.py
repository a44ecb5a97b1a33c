"""The report's statistics against values published or computed elsewhere, typed in with their
source: the ICC against Shrout & Fleiss (1979), Tukey's HSD against R, the regression against
NIST's certified Longley results, Bland-Altman and the CIs against arithmetic done here."""

from __future__ import annotations

import itertools
import math
import statistics
import subprocess
import sys
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("scipy", reason="the report's statistics need SciPy (requirements/report.txt)")
pytest.importorskip("statsmodels", reason="the report's regression needs statsmodels")

from vg_addon.analysis import icc, stats

# Shrout & Fleiss (1979), Psychological Bulletin 86(2), Table 2: 6 targets rated by 4 judges.
SHROUT_FLEISS = [
    [9, 2, 5, 8],
    [6, 1, 3, 2],
    [8, 4, 6, 8],
    [7, 1, 2, 6],
    [10, 5, 6, 9],
    [6, 2, 4, 7],
]


def test_two_way_mean_squares_are_shrout_and_fleiss_table_2():
    # Their Table 2: BMS 11.24, WMS 6.26, JMS 32.49, EMS 1.02.
    a = icc.two_way(SHROUT_FLEISS)
    assert (a.n, a.k) == (6, 4)
    assert a.ms_rows == pytest.approx(11.24, abs=0.005)
    assert a.ms_within == pytest.approx(6.26, abs=0.005)
    assert a.ms_columns == pytest.approx(32.49, abs=0.005)
    assert a.ms_error == pytest.approx(1.02, abs=0.005)


def test_icc_absolute_agreement_is_shrout_and_fleiss_icc_2():
    # Shrout & Fleiss (1979) Table 4: ICC(2,1) = .29, ICC(2,4) = .62. Confidence limits and the
    # F test as R's psych::ICC prints them for the same table (its example data `sf`):
    # ICC2 0.29 [0.019, 0.76], ICC2k 0.62 [0.071, 0.93], F = 11 on 5 and 15 df, p = 0.00013.
    single, mean = icc.icc_absolute(SHROUT_FLEISS)
    assert single.value == pytest.approx(0.29, abs=0.005)
    assert mean.value == pytest.approx(0.62, abs=0.005)
    assert (single.lower, single.upper) == pytest.approx((0.019, 0.76), abs=0.0051)
    assert (mean.lower, mean.upper) == pytest.approx((0.071, 0.93), abs=0.0051)
    assert single.f == pytest.approx(11.0, abs=0.05)
    assert (single.df1, single.df2) == (5, 15)
    assert single.p == pytest.approx(0.00013, abs=0.000005)
    assert mean.kind == "ICC(A,4)"


def test_icc_of_raters_who_agree_exactly_is_one_and_undefined_without_variation():
    agreeing = [[1, 1], [5, 5], [9, 9]]
    single, mean = icc.icc_absolute(agreeing)
    assert single.value == 1.0 and mean.value == 1.0
    with pytest.raises(ValueError, match="every rating is the same"):
        icc.icc_absolute([[3, 3], [3, 3], [3, 3]])
    with pytest.raises(ValueError, match="at least 2"):
        icc.icc_absolute([[1, 2, 3]])


def test_the_icc_of_every_small_table_is_a_number_or_a_reason():
    """Every 2x2, 3x2 and 2x3 table of whole degrees 40 to 42 (1,539 tables, as small pilot
    data are): ICC(A,1) either refused with a reason or given; each figure a finite number or
    None with a note saying why; each interval in order and at most 1. Before: 0/0 and x/0 raised
    ZeroDivisionError (the report crashed), NaN limits, ICC(A,k) lower limits above 1."""
    count = 0
    for n, k in ((2, 2), (3, 2), (2, 3)):
        for cells in itertools.product((40, 41, 42), repeat=n * k):
            table = [list(cells[r * k : (r + 1) * k]) for r in range(n)]
            try:
                results = icc.icc_absolute(table)
            except ValueError as error:
                assert "undefined" in str(error), table
                continue
            count += 1
            for result in results:
                figures = [result.value, result.lower, result.upper]
                assert all(v is None or math.isfinite(v) for v in figures), (table, result)
                assert (None in figures) == bool(result.note), (table, result)
                if result.lower is not None and result.upper is not None:
                    assert result.lower <= result.upper + 1e-12 <= 1.0 + 1e-12, (table, result)
                assert result.value is None or result.value <= 1.0
    assert count > 1000


def test_an_icc_a_k_limit_past_the_spearman_brown_pole_is_unbounded_not_a_number():
    """Five breaks, two observers: ICC(A,1)'s lower limit is below -1/(k-1) = -1, where the
    Spearman-Brown step k r / (1 + (k-1) r) jumps past its pole; the mean's lower limit is then
    unbounded below (before: 18.5, above its upper limit 0.92)."""
    single, mean = icc.icc_absolute([[89, 92], [91, 90], [90, 88], [92, 92], [89, 91]])
    assert single.lower < -1.0 < single.upper
    assert mean.lower is None and "unbounded below" in mean.note
    assert mean.upper == pytest.approx(2 * single.upper / (1 + single.upper), rel=1e-12)


def test_observers_a_constant_apart_have_an_icc_of_zero_and_no_f():
    """Each break read 5 by one observer and 7 by the other: MSR = MSE = 0, MSC = 6, so McGraw &
    Wong's ICC(A,1) = (0 - 0) / (0 + 0 + 2 * 6 / 3) = 0 (before: refused as "the ratings do
    not vary", which they do). F = MSR / MSE is 0/0: no F, no p."""
    single, _ = icc.icc_absolute([[5, 7], [5, 7], [5, 7]])
    assert single.value == 0.0 and single.f is None and single.p is None
    with pytest.raises(ValueError, match="not positive"):
        icc.icc_absolute([[40, 50], [50, 40]])  # the two observers swapped: no estimate


def exact_error_mean_square(table) -> Fraction:
    """MSE of the two-way table in exact rational arithmetic on the floats as given."""
    x = [[Fraction(v) for v in row] for row in table]
    n, k = len(x), len(x[0])
    grand = sum(map(sum, x)) / (n * k)
    rows = [sum(row) / k for row in x]
    cols = [sum(x[i][j] for i in range(n)) / n for j in range(k)]
    residuals = (x[i][j] - rows[i] - cols[j] + grand for i in range(n) for j in range(k))
    return sum(r * r for r in residuals) / ((n - 1) * (k - 1))


def test_observers_a_rounded_constant_apart_have_no_f_and_no_p():
    """Observer means of three readings (150, 150, 150 and 154, 154, 155): every break the
    same 150 and 463/3 rounded, so MSR = MSE = 0 exactly. Before: MSR 1.9e-27 and MSE
    -1.4e-15 from subtracting sums, so F = inf and p = 0 in agreement.csv."""
    table = [[150.0, math.fsum([154.0, 154.0, 155.0]) / 3]] * 6
    assert exact_error_mean_square(table) == 0
    single, mean = icc.icc_absolute(table)
    assert single.value == 0.0 and single.f is None and single.p is None
    assert mean.value == 0.0


def test_the_error_mean_square_is_zero_exactly_where_it_is_and_never_negative():
    """Additive tables (a break's value plus an observer's offset, both rounded to 0.001) whose
    exact MSE is 0 get 0; the others agree with the exact value (oracle: Fractions)."""
    rng = np.random.default_rng(5)
    zeros = 0
    for _ in range(400):
        n, k = int(rng.integers(2, 7)), int(rng.integers(2, 4))
        table = np.round(
            np.round(rng.uniform(0, 180, (n, 1)), 3) + np.round(rng.uniform(-1, 1, (1, k)), 3), 6
        )
        if rng.random() < 0.3:  # and some with error variance
            table = table + np.round(rng.normal(0, 0.5, (n, k)), 3)
        exact = exact_error_mean_square(table.tolist())
        ms_error = icc.two_way(table).ms_error
        assert ms_error >= 0
        if exact == 0:
            zeros += 1
            assert ms_error == 0, table.tolist()
        else:
            assert ms_error == pytest.approx(float(exact), rel=1e-9, abs=1e-20)
    assert zeros > 20  # the case is exercised


def test_the_icc_agrees_with_exact_arithmetic_on_a_table_with_error():
    """A table with real error variance keeps its figures: the Shrout & Fleiss table's MSE
    summed from residuals is the exact one."""
    assert icc.two_way(SHROUT_FLEISS).ms_error == pytest.approx(
        float(exact_error_mean_square(SHROUT_FLEISS)), rel=1e-15
    )


# R's PlantGrowth data set (Dobson 1983), 10 plants per group.
PLANT_GROWTH = {
    "ctrl": [4.17, 5.58, 5.18, 6.11, 4.50, 4.61, 5.17, 4.53, 5.33, 5.14],
    "trt1": [4.81, 4.17, 4.41, 3.59, 5.87, 3.83, 6.03, 4.89, 4.32, 4.69],
    "trt2": [6.31, 5.12, 5.54, 5.50, 5.37, 5.29, 4.92, 6.15, 5.80, 5.26],
}


def test_tukey_hsd_is_r_tukeyhsd_on_plant_growth():
    # R: TukeyHSD(aov(weight ~ group, data = PlantGrowth))
    #             diff        lwr       upr     p adj
    # trt1-ctrl -0.371 -1.0622161 0.3202161 0.3908711
    # trt2-ctrl  0.494 -0.1972161 1.1852161 0.1979960
    # trt2-trt1  0.865  0.1737839 1.5562161 0.0120064
    r = {
        ("ctrl", "trt1"): (-0.371, -1.0622161, 0.3202161, 0.3908711),
        ("ctrl", "trt2"): (0.494, -0.1972161, 1.1852161, 0.1979960),
        ("trt1", "trt2"): (0.865, 0.1737839, 1.5562161, 0.0120064),
    }
    pairs = stats.tukey_hsd(PLANT_GROWTH)
    assert {(p.first, p.second) for p in pairs} == set(r)
    for p in pairs:
        diff, lower, upper, padj = r[(p.first, p.second)]
        assert p.difference == pytest.approx(diff, abs=5e-7)
        assert (p.lower, p.upper) == pytest.approx((lower, upper), abs=5e-7)
        assert p.p == pytest.approx(padj, abs=5e-7)
    assert [p.reject for p in pairs] == [False, False, True]


def test_tukey_refuses_a_group_of_one_and_groups_without_variance():
    with pytest.raises(ValueError, match="two or more values"):
        stats.tukey_hsd({"a": [1.0, 2.0], "b": [3.0]})
    with pytest.raises(ValueError, match="no variance"):
        stats.tukey_hsd({"a": [0.0, 0.0], "b": [3.0, 3.0]})
    # Values whose mean rounds off them (fsum of 25 times 4/3, over 25, is not 4/3): still
    # no variance (before: an SD of 2.3e-16, and p = 4.4e-16 from SciPy).
    for a, b in (([4 / 3] * 25, [2 / 3] * 25), ([0.1] * 3, [0.2] * 3)):
        assert math.fsum(a) / len(a) != a[0] or math.fsum(b) / len(b) != b[0]
        with pytest.raises(ValueError, match="no variance"):
            stats.tukey_hsd({"manual": a, "drag": b})


# NIST StRD, Longley (1967): the certified values of the linear regression of employment on six
# economic series (https://www.itl.nist.gov/div898/strd/lls/data/Longley.shtml).
LONGLEY_CERTIFIED = [
    (-3482258.63459582, 890420.383607373),
    (15.0618722713733, 84.9149257747669),
    (-0.358191792925910e-01, 0.334910077722432e-01),
    (-2.02022980381683, 0.488399681651699),
    (-1.03322686717359, 0.214274163161675),
    (-0.511041056535807e-01, 0.226073200069370),
    (1829.15146461355, 455.478499142212),
]


def test_regression_is_nist_longley_certified():
    from statsmodels.datasets import longley

    data = longley.load_pandas()
    predictors = {name: list(data.exog[name]) for name in data.exog.columns}
    fit = stats.ols(list(data.endog), predictors, response="TOTEMP")
    assert fit.n == 16
    for coefficient, (estimate, se) in zip(fit.coefficients, LONGLEY_CERTIFIED, strict=True):
        assert coefficient.estimate == pytest.approx(estimate, rel=1e-7)
        assert coefficient.se == pytest.approx(se, rel=1e-7)
        assert coefficient.t == pytest.approx(estimate / se, rel=1e-7)
    assert fit.r2 == pytest.approx(0.995479004577296, rel=1e-9)
    assert fit.residual_se == pytest.approx(304.854073561965, rel=1e-9)


def test_regression_refuses_too_few_rows_and_collinear_predictors():
    with pytest.raises(ValueError, match="more breaks"):
        stats.ols([1.0, 2.0, 3.0], {"a": [1.0, 2.0, 3.0], "b": [0.0, 1.0, 0.0]})
    with pytest.raises(ValueError, match="exact"):
        stats.ols([1.0, 3.0, 5.0, 7.0, 9.0], {"a": [0.0, 1.0, 2.0, 3.0, 4.0], "b": [1, 0, 1, 0, 0]})
    with pytest.raises(ValueError, match="collinear"):
        stats.ols([1.0, 2.0, 3.0, 5.0, 4.0], {"a": [0.0] * 5, "b": [1.0, 2.0, 3.0, 4.0, 5.0]})
    # A response that never varies (before: R² = -inf, a negative F, t of 1e15).
    rng = np.random.default_rng(2)
    predictors = {name: list(rng.normal(size=8)) for name in "abc"}
    with pytest.raises(ValueError, match="nothing to explain"):
        stats.ols([math.log(2 / 3)] * 8, predictors, response="angle IOV")


def test_bland_altman_by_hand():
    first = [10.0, 12.0, 11.0, 15.0, 9.0]
    second = [11.0, 12.5, 10.0, 16.0, 10.5]
    d = [b - a for a, b in zip(first, second, strict=True)]  # 1, 0.5, -1, 1, 1.5
    bias, sd = statistics.fmean(d), statistics.stdev(d)
    ba = stats.bland_altman(first, second, names=("A", "B"))
    assert ba.bias == pytest.approx(0.6) and bias == pytest.approx(0.6)
    assert ba.sd == pytest.approx(sd)
    assert (ba.lower, ba.upper) == pytest.approx((bias - 1.959964 * sd, bias + 1.959964 * sd))
    t4 = 2.776445  # Student's t, 4 df, 97.5% (tables)
    assert ba.bias_ci == pytest.approx(
        (bias - t4 * sd / math.sqrt(5), bias + t4 * sd / math.sqrt(5))
    )
    half = t4 * math.sqrt(3 * sd**2 / 5)
    assert ba.upper_ci == pytest.approx((ba.upper - half, ba.upper + half))
    assert list(ba.means) == [10.5, 12.25, 10.5, 15.5, 9.75]
    with pytest.raises(ValueError, match="at least 3"):
        stats.bland_altman([1.0, 2.0], [1.0, 2.0])


def test_summary_quartiles_and_intervals():
    s = stats.summarise([1, 2, 3, 4, 10])
    assert (s.n, s.mean, s.median, s.q1, s.q3, s.min, s.max) == (5, 4.0, 3.0, 2.0, 4.0, 1.0, 10.0)
    assert s.sd == pytest.approx(statistics.stdev([1, 2, 3, 4, 10]))
    t95, t99 = 2.776445, 4.604095  # Student's t, 4 df (tables)
    half = s.sd / math.sqrt(5)
    assert s.ci95 == pytest.approx((4 - t95 * half, 4 + t95 * half), rel=1e-6)
    assert s.ci99 == pytest.approx((4 - t99 * half, 4 + t99 * half), rel=1e-6)
    one = stats.summarise([7.0])
    assert (one.n, one.mean, one.sd, one.ci95) == (1, 7.0, None, None)


def test_the_statistics_run_without_a_deprecation_warning():
    # statsmodels 0.14 with pandas 3 printed about 130 deprecation warnings on import; a fresh
    # interpreter that turns every warning into an error runs the regression, Tukey and the ICC.
    code = (
        "from vg_addon.analysis import icc, stats\n"
        "stats.ols([1.0, 2.1, 2.9, 4.2, 5.1], {'x': [1.0, 2.0, 3.0, 4.0, 5.5]})\n"
        "stats.tukey_hsd({'a': [1.0, 2.0, 3.0], 'b': [2.0, 3.5, 4.0]})\n"
        f"icc.icc_absolute({SHROUT_FLEISS!r})\n"
    )
    run = subprocess.run(
        [sys.executable, "-W", "error", "-c", code],
        cwd=Path(__file__).resolve().parents[2],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 0, run.stderr[-2000:]
    assert run.stderr == ""
