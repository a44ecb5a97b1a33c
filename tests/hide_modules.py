"""Run Python (or the bpy module) as where some packages are not installed: a ``sitecustomize``
on the subprocess's path makes every import of them fail as it fails there. The harness hides
them; the shipped code has no switch for it."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

SITECUSTOMIZE = '''
import sys

class HideModules:
    """Imports of {names} fail as where they are not installed."""

    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in {names!r}:
            raise ModuleNotFoundError(f"No module named {{name!r}}", name=name)
        return None

sys.meta_path.insert(0, HideModules())
'''


def environment(folder: Path, names: tuple[str, ...]) -> dict:
    """The environment of a subprocess in which ``names`` cannot be imported (``folder``: where
    the ``sitecustomize.py`` goes, made if missing)."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "sitecustomize.py").write_text(
        SITECUSTOMIZE.format(names=tuple(names)), encoding="utf-8"
    )
    path = os.pathsep.join(p for p in (str(folder), os.environ.get("PYTHONPATH", "")) if p)
    return {**os.environ, "PYTHONPATH": path}


def run_reporting(code: str, *args, env: dict) -> tuple[subprocess.CompletedProcess, dict]:
    """Run ``code`` with this Python (``-c``, then ``args``) in ``env``; it must exit 0 and print
    one line ``REPORT <json>``. Returns the run and that JSON."""
    result = subprocess.run(
        [sys.executable, "-c", code, *map(str, args)],
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
        check=False,
    )
    assert result.returncode == 0, result.stdout + result.stderr
    line = next(line for line in result.stdout.splitlines() if line.startswith("REPORT "))
    return result, json.loads(line[len("REPORT ") :])
