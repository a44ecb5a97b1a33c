"""The README's Python API example runs as written."""

import re
from pathlib import Path

README = Path(__file__).resolve().parents[2] / "README.md"


def test_python_api_example_runs(capsys):
    text = README.read_text(encoding="utf-8")
    section = text[text.index("## Python API") :]
    example = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    exec(compile(example, "README.md (Python API)", "exec"), {})
    printed = capsys.readouterr().out
    assert "60.00°" in printed
    assert "farther than the radius" in printed
