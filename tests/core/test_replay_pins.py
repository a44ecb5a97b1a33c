"""Recorded measurements replay bit for bit: outputs pinned from the code before the hot-path
changes (see ``replay_cases.py`` for how and at which commit the pins were made)."""

import json

import numpy as np
import pytest
from replay_cases import PINS, SHARED_DATA, cases, record, surfaces

PINNED = json.loads(PINS.read_text())
PINNED_NUMPY = PINNED.pop("numpy")
SURFACES = surfaces()


@pytest.mark.parametrize("name", sorted(PINNED))
def test_replays_match_pins(name):
    if name not in SURFACES:
        pytest.skip(f"reference mesh {name} not found in {SHARED_DATA}")
    surface = SURFACES[name]
    got = [record(surface, *case) for case in cases(surface, name)]
    expected = PINNED[name]
    assert len(got) == len(expected)
    same_numpy = np.__version__ == PINNED_NUMPY
    for k, (new, old) in enumerate(zip(got, expected, strict=True)):
        assert new.get("patch_part") == old.get("patch_part"), f"{name} case {k}: the patch"
        assert ("error" in new) == ("error" in old), f"{name} case {k}: the refusal"
        if same_numpy:
            assert new.get("numbers") == old.get("numbers"), f"{name} case {k}: the numbers"
            assert new == old
