"""The README's Python API example runs as written and prints what the README says it prints."""

import re
from pathlib import Path

README = Path(__file__).resolve().parents[2] / "README.md"


def test_python_api_example_prints_what_the_readme_shows(capsys):
    text = README.read_text(encoding="utf-8")
    section = text[text.index("## Python API") :]
    example = re.search(r"```python\n(.*?)```", section, re.S)
    shown = re.search(r"prints\s*\n\s*```text\n(.*?)```", section[example.end() :], re.S)
    assert shown, "the README's Python API example should show its output after 'prints'"
    exec(compile(example.group(1), "README.md (Python API)", "exec"), {})
    assert capsys.readouterr().out == shown.group(1)
