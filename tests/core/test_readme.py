"""The Python API examples of the README and of docs/API.md run as written and print what they
say they print."""

import re
from pathlib import Path

README = Path(__file__).resolve().parents[2] / "README.md"
API = Path(__file__).resolve().parents[2] / "docs" / "API.md"


def test_python_api_example_prints_what_the_readme_shows(capsys):
    text = README.read_text(encoding="utf-8")
    section = text[text.index("## Python API") :]
    example = re.search(r"```python\n(.*?)```", section, re.S)
    shown = re.search(r"prints\s*\n\s*```text\n(.*?)```", section[example.end() :], re.S)
    assert shown, "the README's Python API example should show its output after 'prints'"
    exec(compile(example.group(1), "README.md (Python API)", "exec"), {})
    assert capsys.readouterr().out == shown.group(1)


def test_api_md_example_prints_what_its_comments_say(capsys):
    """docs/API.md shows output as a comment after a print: ``print(x)  # what it prints``."""
    text = API.read_text(encoding="utf-8")
    example = re.search(r"```python\n(.*?)```", text, re.S).group(1)
    promised = re.findall(r"^print\(.*\)\s+#\s*(.+)$", example, re.M)
    assert promised, "docs/API.md's example should say what its prints print"
    exec(compile(example, "docs/API.md (Python API)", "exec"), {})
    printed = capsys.readouterr().out.splitlines()
    assert all(line in printed for line in promised), (promised, printed)
