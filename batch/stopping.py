"""The run's stop (Ctrl-C, SIGTERM): asked for by the signal, acted on where the run can act.

The signal handler raises KeyboardInterrupt where Python happens to be. Inside a Blender handler
(a mesh import runs Blender's own ``version_update`` handlers) bpy catches it, prints it as an
error and carries on, so the run would end as if never stopped. The handler therefore also
records the stop here, and the run calls :func:`check` between steps (each mesh, each point).
"""

from __future__ import annotations

_requested = False


def request() -> None:
    """Record that the run was asked to stop (from the signal handler)."""
    global _requested
    _requested = True


def check() -> None:
    """Raise KeyboardInterrupt if a stop was asked for (again, where bpy swallowed the first)."""
    if _requested:
        raise KeyboardInterrupt
