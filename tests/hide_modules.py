"""Run Python (or the bpy module) as where some packages are not installed: a ``sitecustomize``
on the subprocess's path makes every import of them fail as it fails there. The harness hides
them; the shipped code has no switch for it."""

from __future__ import annotations

import os
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
