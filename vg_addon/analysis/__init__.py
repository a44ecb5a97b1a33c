"""From measurement CSVs to the paper's replication analysis (its Section 4).

The parts here need NumPy and the standard library only, like the rest of ``vg_addon``:
``sessions`` reads each CSV as one session (an observer's repetition with one method), ``matching``
pairs the rows of different sessions by mesh, break and, where a break holds several stations,
nearest centre, and ``iov`` computes the intra- and inter-observer variability per break.

The statistics (``stats``, ``icc``), the figures (``figures``) and the report (``report``) import
SciPy, statsmodels and matplotlib inside their functions, so importing this package never needs
them; :func:`missing_libraries` says which are absent (Blender's own Python has none of them).
"""

from __future__ import annotations

import importlib.util

#: What the statistics and figures need beyond NumPy: import name -> pip name.
REPORT_LIBRARIES = {"scipy": "scipy", "statsmodels": "statsmodels", "matplotlib": "matplotlib"}


def missing_libraries() -> list[str]:
    """The pip names of the report's libraries this Python cannot import (empty: all there)."""
    return [pip for name, pip in REPORT_LIBRARIES.items() if not _found(name)]


def _found(name: str) -> bool:
    try:
        return importlib.util.find_spec(name) is not None
    except (ImportError, ValueError):  # a finder that refuses it, a broken entry in sys.modules
        return False


def missing_message(command: str = "python vg_batch.py --report DIR SESSION.csv ...") -> str:
    """Why the report cannot run here and what does the same elsewhere, in short lines (a
    Blender popup does not wrap); empty when it can run."""
    missing = missing_libraries()
    if not missing:
        return ""
    return (
        f"The report needs {', '.join(missing)}, which this Python does not have\n"
        "(Blender's own Python has NumPy only). Install them into it:\n"
        f"  python -m pip install {' '.join(missing)}\n"
        "(a Linux distribution's Blender: its packages, e.g.\n"
        f"  sudo apt install {' '.join('python3-' + m for m in missing)})\n"
        "or run the same report from the repository's environment:\n"
        f"  {command}"
    )
