"""expand_ranges equals concatenating Python ranges."""

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from vg_addon.method.ranges import expand_ranges


@given(st.lists(st.tuples(st.integers(-50, 1000), st.integers(0, 20)), max_size=30))
def test_expand_ranges_matches_concatenated_ranges(pairs):
    starts = np.array([s for s, _ in pairs], dtype=np.int64)
    lengths = np.array([n for _, n in pairs], dtype=np.int64)
    expected = [i for s, n in pairs for i in range(s, s + n)]
    assert expand_ranges(starts, lengths).tolist() == expected
