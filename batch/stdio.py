"""The batch run's terminal: progress lines on stderr, and Blender's C-level chatter silenced."""

from __future__ import annotations

import contextlib
import os
import sys


def say(text: str) -> None:
    """Print a progress or summary line for the user (stderr, so stdout stays clean)."""
    print(f"vg_batch: {text}", file=sys.stderr, flush=True)


@contextlib.contextmanager
def quiet_stdout():
    """Silence what Blender prints on the C level (render and save chatter) for a while."""
    sys.stdout.flush()
    try:
        saved = os.dup(1)
    except OSError:
        yield
        return
    try:
        with open(os.devnull, "wb") as null:
            os.dup2(null.fileno(), 1)
            yield
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(saved)
