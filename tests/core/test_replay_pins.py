"""Recorded measurements replay bit for bit, on every NumPy and machine (see ``replay_cases.py``
for how the pins were made), and within 1e-9° of what commit 5ffee72 gave."""

import json

import pytest
from replay_cases import PINS, PINS_5FFEE72, SHARED_DATA, cases, record, surfaces

PINNED = json.loads(PINS.read_text())
PINNED.pop("numpy")
BEFORE = json.loads(PINS_5FFEE72.read_text())
BEFORE.pop("numpy")
SURFACES = surfaces()


def _numbers(entry) -> dict:
    return {
        key: [float.fromhex(value) for value in (values if isinstance(values, list) else [values])]
        for key, values in entry["numbers"].items()
    }


@pytest.mark.parametrize("name", sorted(PINNED))
def test_replays_match_pins(name):
    if name not in SURFACES:
        pytest.skip(f"reference mesh {name} not found in {SHARED_DATA}")
    surface = SURFACES[name]
    got = [record(surface, *case) for case in cases(surface, name)]
    expected = PINNED[name]
    assert len(got) == len(expected)
    for k, (new, old) in enumerate(zip(got, expected, strict=True)):
        assert new.get("patch_part") == old.get("patch_part"), f"{name} case {k}: the patch"
        assert ("error" in new) == ("error" in old), f"{name} case {k}: the refusal"
        assert new.get("numbers") == old.get("numbers"), f"{name} case {k}: the numbers"
        assert new == old


@pytest.mark.parametrize("name", sorted(BEFORE))
def test_pins_are_within_a_billionth_of_a_degree_of_commit_5ffee72(name):
    """Issue 18 changed the arithmetic, not the measurements: the same patches and splits, the
    numbers moved in their last bits only."""
    for k, (now, before) in enumerate(zip(PINNED[name], BEFORE[name], strict=True)):
        assert now.get("patch_part") == before.get("patch_part"), f"{name} case {k}"
        assert now.get("error") == before.get("error"), f"{name} case {k}"
        if "numbers" not in now:
            continue
        new, old = _numbers(now), _numbers(before)
        radius = float.fromhex(now["radius"])
        assert abs(new["angle"][0] - old["angle"][0]) <= 1e-9, f"{name} case {k}"
        assert (
            max(abs(a - b) for a, b in zip(new["fit"], old["fit"], strict=True))
            <= 1e-14 * radius**2
        )
        assert max(abs(a - b) for a, b in zip(new["normals"], old["normals"], strict=True)) <= 1e-12
