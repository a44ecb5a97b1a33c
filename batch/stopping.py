"""The run's stop (Ctrl-C, SIGTERM): asked for by the signal, acted on where the run can act.

The signal handler raises KeyboardInterrupt where Python happens to be. Inside a Blender handler
(a mesh import runs Blender's own ``version_update`` handlers) bpy catches it, prints it as an
error and carries on, so the run would end as if never stopped. The handler therefore also
records the stop here, and the run calls :func:`check` between steps (each mesh, each block of
points) and :func:`requested` before each point.

Where an interrupt raised at an arbitrary line would lose work already done (points measured but
not yet recorded, rows half handed over), the run works :func:`deferred`: the handler only
records the stop, and the run acts on it at its next :func:`check`.
"""

from __future__ import annotations

import contextlib

_requested = False
_deferring = 0


def request() -> None:
    """Record that the run was asked to stop (from the signal handler)."""
    global _requested
    _requested = True


def requested() -> bool:
    """Whether the run was asked to stop."""
    return _requested


def check() -> None:
    """Raise KeyboardInterrupt if a stop was asked for (again, where bpy swallowed the first)."""
    if _requested:
        raise KeyboardInterrupt


@contextlib.contextmanager
def deferred():
    """Within this block a stop signal raises nothing; the block acts on it at :func:`check`."""
    global _deferring
    _deferring += 1
    try:
        yield
    finally:
        _deferring -= 1


def deferring() -> bool:
    """Whether a stop signal should only be recorded (see :func:`deferred`)."""
    return _deferring > 0
