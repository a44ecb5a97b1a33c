"""The pictures of a batch run (maps, profile and sweep plots): named so that no two meshes of
a run share a file, written only after the mesh's rows, and never at the cost of a row.

The rule, here and in ``run``: a bad row or a failed picture never costs a good row. A picture
that cannot be written (a folder in its place, a full disk, an input at its path) is one line
in the summary and exit status 2; the CSV is complete all the same.
"""

from __future__ import annotations

import os
from pathlib import Path

from ..vg_addon import GoniometerError
from ..vg_addon.formats import files
from .outputs import refuse_input

# Below this much free space a failed picture is reported as a full disk (Blender's own errors
# on a full disk name other symptoms, e.g. an empty pixel buffer).
NEARLY_FULL_BYTES = 1 << 20


def disk_full(folder) -> bool:
    """Whether the file system holding ``folder`` has (almost) no space left."""
    try:
        info = os.statvfs(folder)
    except (OSError, AttributeError):
        return False
    return info.f_bavail * info.f_frsize < NEARLY_FULL_BYTES


def reason(error: BaseException, folder=None) -> str:
    """What went wrong, in words: an OSError's own text, and a full disk named as such."""
    if isinstance(error, OSError) and error.strerror:
        text = error.strerror
    else:
        text = str(error).strip() or type(error).__name__
        if not isinstance(error, GoniometerError | OSError):
            text = f"{type(error).__name__}: {text}"
    if folder is not None and "No space left" not in text and disk_full(folder):
        text = f"No space left on device ({text})"
    return text


def write_picture(path, data, inputs) -> None:
    """Write picture bytes ``data()`` to ``path`` atomically, unless ``path`` is an input or a
    folder.

    Raises
    ------
    GoniometerError, OSError
        Why it was not written; an old file at ``path`` is then unchanged.
    """
    refuse_input(path, inputs)
    if Path(path).is_dir():
        raise GoniometerError("a folder is in its place; move it away")
    files.replace_atomically(os.fspath(path), data())


def try_picture(failures: list[str], what: str, path, data, inputs) -> bool:
    """:func:`write_picture`, a failure added to ``failures`` as one line; whether written."""
    try:
        write_picture(path, data, inputs)
    except (OSError, GoniometerError) as error:
        failures.append(f"{what} {path}: {reason(error, Path(path).parent)}")
        return False
    return True
