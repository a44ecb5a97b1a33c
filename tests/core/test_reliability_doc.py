"""docs/RELIABILITY.md stays true: every test it names exists, in the file it names."""

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_every_test_named_in_the_fault_matrix_exists():
    text = (ROOT / "docs" / "RELIABILITY.md").read_text(encoding="utf-8")
    named = 0
    for cell in re.findall(r"^\|.*\|(.*)\|\s*$", text, re.M):
        current = None
        for reference in re.findall(r"`([^`]*::[^`]*)`", cell):
            file, _, name = reference.partition("::")
            current = file or current
            assert current, f"{reference}: no test file named before it"
            (path,) = ROOT.glob(f"tests/*/{current}")
            assert re.search(rf"^\s*def {re.escape(name)}\(", path.read_text(), re.M), reference
            named += 1
    assert named >= 40
