"""The run's stop (Ctrl-C, SIGTERM): asked for by the signal, acted on where the run can act.

The signal handler (:func:`on_stop_signal`) raises KeyboardInterrupt where Python happens to be,
except inside a handler Blender calls (a mesh import runs Blender's own ``version_update``
handlers; the extension's geometry watcher runs on depsgraph updates): there bpy would catch it,
print it as an error and carry on, so the run would end as if never stopped. The handler
therefore records the stop here, and the run calls :func:`check` between steps (each mesh, each
block of points) and :func:`requested` before each point.

Where an interrupt raised at an arbitrary line would lose work already done (points measured but
not yet recorded, rows half handed over), the run works :func:`deferred`: the handler only
records the stop, and the run acts on it at its next :func:`check`.
"""

from __future__ import annotations

import contextlib
import os
import signal

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


def handle_stop_signals() -> None:
    """Stop the run on SIGINT (Ctrl-C) and SIGTERM (``kill PID``, a job scheduler's stop, or the
    parent of a ``--jobs`` worker stopping it) with :func:`on_stop_signal`."""
    signal.signal(signal.SIGINT, on_stop_signal)
    signal.signal(signal.SIGTERM, on_stop_signal)


def on_stop_signal(signum, frame) -> None:
    """The stop signals' handler: record the stop and raise KeyboardInterrupt, unless the run
    works :func:`deferred` or the signal came inside a handler Blender calls (where bpy would
    print the interrupt as an error and carry on): the run then acts on it at its next
    :func:`check`.

    The run ends at once: a map being rendered is killed with its child process, the workers
    are stopped, the CSV is written with what was measured, the temporary folders are removed,
    exit status 130 (a worker hands over the rows it measured first). A second signal must not
    cut that short, so it is ignored from now on.
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    request()
    if deferring():
        return
    if not _in_a_blender_handler(frame):
        raise KeyboardInterrupt


def _in_a_blender_handler(frame) -> bool:
    """Whether ``frame`` runs inside a handler Blender calls (``bpy.app.handlers``: its own, in
    its add-ons and startup scripts, or the extension's), where an exception raised is printed
    as an error and swallowed; ``bpy.ops`` wrappers, which raise to their caller, are not."""
    import bpy

    scripts = bpy.utils.system_resource("SCRIPTS")
    if scripts:
        path = frame.f_code.co_filename if frame is not None else ""
        modules = os.path.join(scripts, "modules") + os.sep
        if path.startswith(scripts) and not path.startswith(modules):
            return True
    handlers = bpy.app.handlers
    codes = {
        getattr(function, "__code__", None)
        for name in dir(handlers)
        if isinstance(getattr(handlers, name), list)
        for function in getattr(handlers, name)
    }
    while frame is not None:
        if frame.f_code in codes:
            return True
        frame = frame.f_back
    return False
