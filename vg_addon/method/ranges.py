"""Expanding many index ranges at once, the building block of every vectorised neighbour walk."""

from __future__ import annotations

import numpy as np


def expand_ranges(starts: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    """Concatenate ``arange(s, s + n)`` for every pair ``(s, n)``, without a Python loop.

    Parameters
    ----------
    starts, lengths : ndarray of int, shape (k,)
        Range starts and lengths (a length may be 0).

    Returns
    -------
    ndarray of int64, shape (lengths.sum(),)

    Examples
    --------
    >>> expand_ranges(np.array([10, 3]), np.array([2, 3]))
    array([10, 11,  3,  4,  5])
    """
    starts = np.asarray(starts, dtype=np.int64)
    lengths = np.asarray(lengths, dtype=np.int64)
    total = int(lengths.sum())
    firsts = np.cumsum(lengths) - lengths
    return np.repeat(starts - firsts, lengths) + np.arange(total, dtype=np.int64)
