"""WithinSS: the O(n log n) split must equal the brute-force optimum of the paper's f(s)."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vg_addon import GoniometerError, withinss_split
from vg_addon.method.algorithm import MIN_SIDE_VERTICES


def brute_force(values, min_size=1):
    """The paper's definition, evaluated at every candidate threshold (O(n^2))."""
    p = np.asarray(values, dtype=float)
    best = (np.inf, None)
    for s in np.unique(p):
        upper, lower = p[p >= s], p[p < s]
        if min(upper.size, lower.size) < min_size:
            continue
        cost = ((upper - upper.mean()) ** 2).sum() + ((lower - lower.mean()) ** 2).sum()
        if cost < best[0] - 1e-9 * max(1.0, abs(cost)):
            best = (cost, s)
    return best


@pytest.mark.parametrize("min_size", [1, MIN_SIDE_VERTICES])  # the default, and as measured
@settings(max_examples=300, deadline=None)
@given(
    st.lists(
        st.floats(-1e3, 1e3, allow_nan=False, allow_infinity=False), min_size=2, max_size=60
    ).filter(lambda v: len(set(v)) >= 2)
)
def test_split_matches_brute_force(min_size, values):
    expected_cost, expected_threshold = brute_force(values, min_size)
    if expected_threshold is None:  # no split leaves min_size values on both sides
        with pytest.raises(GoniometerError):
            withinss_split(values, min_size=min_size)
        return
    threshold, cost = withinss_split(values, min_size=min_size)
    p = np.asarray(values)
    upper, lower = p[p >= threshold], p[p < threshold]
    assert min(upper.size, lower.size) >= min_size
    achieved = ((upper - upper.mean()) ** 2).sum() + ((lower - lower.mean()) ** 2).sum()
    assert achieved == pytest.approx(expected_cost, rel=1e-9, abs=1e-9)
    assert cost == pytest.approx(achieved, rel=1e-7, abs=1e-7)


def test_two_clusters_are_found():
    rng = np.random.default_rng(1)
    values = np.concatenate([rng.normal(-5, 0.1, 500), rng.normal(3, 0.1, 200)])
    threshold, _ = withinss_split(rng.permutation(values))
    assert (values >= threshold).sum() == 200


def test_min_size_is_respected():
    values = [0.0, 0.0, 0.0, 0.0, 0.0, 10.0]
    with pytest.raises(GoniometerError, match="identical"):
        withinss_split(values, min_size=3)
    threshold, _ = withinss_split([0, 1, 2, 3, 4, 100], min_size=3)
    assert threshold == 3


def test_ties_are_never_split():
    values = [1.0, 2.0, 2.0, 2.0, 9.0]
    threshold, _ = withinss_split(values)
    assert threshold in values
    p = np.asarray(values)
    assert not ((p[p >= threshold] == 2.0).any() and (p[p < threshold] == 2.0).any())


def test_too_few_values_is_a_clear_error():
    with pytest.raises(GoniometerError, match="larger patch radius"):
        withinss_split([1.0])
