"""Optimal split of one-dimensional data into two clusters (the paper's ``WithinSS``)."""

from __future__ import annotations

import numpy as np

from ..errors import GoniometerError


def withinss_split(values, min_size: int = 1) -> tuple[float, float]:
    """Split 1D data into ``{p < s}`` and ``{p >= s}`` minimising the within-cluster sum of squares.

    Runs in O(n log n): one sort and prefix sums, instead of the O(n^2) loop of the earlier
    implementations. Minimising the within-cluster sum of squares is the same as maximising the
    between-cluster term ``k (n - k) / n * (mean_left - mean_right)^2``; that form is evaluated on
    mean-centred data, which keeps it free of the cancellation a raw sum-of-squares formula suffers.

    Parameters
    ----------
    values : array_like, shape (n,)
        The projected values ``p``.
    min_size : int, optional
        Smallest number of values allowed on either side (default 1). Only thresholds that can be
        realised by ``p < s`` are considered, so tied values are never split apart.

    Returns
    -------
    threshold : float
        The value ``s``: the smallest value of the upper cluster.
    within_ss : float
        The within-cluster sum of squares at that split.

    Raises
    ------
    GoniometerError
        If no split leaves ``min_size`` values on each side.
    """
    p = np.sort(np.asarray(values, dtype=np.float64).ravel())
    n = p.size
    if n < 2 * max(min_size, 1):
        raise GoniometerError(
            f"Cannot split {n} values into two groups of at least {max(min_size, 1)}: "
            "use a larger patch radius so the patch holds more vertices."
        )
    centred = p - np.add.reduce(p) / n  # p.mean(): the same sum and division, without its wrapper
    prefix = np.cumsum(centred)
    k = np.arange(1, n, dtype=np.float64)  # size of the lower cluster for split after index k-1
    lower_sum = prefix[:-1]
    # With centred data the upper sum is -lower_sum, so mean_left - mean_right = lower_sum * n / (k (n-k)).
    between = lower_sum * lower_sum * n / (k * (n - k))
    valid = p[1:] > p[:-1]
    valid[: max(min_size, 1) - 1] = False
    if min_size > 1:
        valid[n - min_size :] = False
    if not valid.any():
        raise GoniometerError(
            f"The {n} projected values cannot be split with at least {max(min_size, 1)} on each side "
            "(too many identical values): use a larger patch radius or check the mesh for duplicates."
        )
    between = np.where(valid, between, -np.inf)
    best = int(np.argmax(between))
    total_ss = float(np.add.reduce(centred * centred))  # pairwise: not BLAS's machine-chosen order
    return float(p[best + 1]), max(total_ss - float(between[best]), 0.0)
