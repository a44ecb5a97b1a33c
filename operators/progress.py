"""Progress of a long operation, in Blender's way: the window manager's progress cursor and a
status-bar message, both removed on every way out; and the timer steps of a modal operator."""

from __future__ import annotations

import contextlib
import time

# The status text is redrawn at most this often (a 5,000-row import steps 5,000 times).
_INTERVAL = 0.1


class Progress:
    """A context manager whose :meth:`step` reports ``done`` of ``total``.

    ``step`` returns True (go on), so it can be handed to loops that stop when a callback
    returns False. Without a window (background mode) it only counts.
    """

    def __init__(self, context, label: str):
        self.label = label
        self.window_manager = getattr(context, "window_manager", None)
        self.workspace = getattr(context, "workspace", None)
        self.total = 0
        self.done = 0
        self._begun = False
        self._shown = -_INTERVAL

    def __enter__(self) -> Progress:
        return self

    def step(self, done: int, total: int) -> bool:
        """Show that ``done`` of ``total`` items are done."""
        self.done, self.total = int(done), int(total)
        now = time.perf_counter()
        if now - self._shown < _INTERVAL and 0 < self.done < self.total - 1:
            return True
        self._shown = now
        if self.window_manager is not None and self.window_manager.windows:
            if not self._begun:
                self.window_manager.progress_begin(0, max(self.total, 1))
                self._begun = True
            self.window_manager.progress_update(self.done)
        if self.workspace is not None:
            with contextlib.suppress(AttributeError, ReferenceError, RuntimeError):
                self.workspace.status_text_set(f"{self.label}: {self.done} of {self.total}")
        return True

    def __exit__(self, *_exc) -> None:
        if self._begun:
            with contextlib.suppress(AttributeError, ReferenceError, RuntimeError):
                self.window_manager.progress_end()
        if self.workspace is not None:
            with contextlib.suppress(AttributeError, ReferenceError, RuntimeError):
                self.workspace.status_text_set(None)


def own_timer_tick(operator, event) -> bool:
    """Whether ``event`` is a tick of ``operator._timer`` not yet stepped on.

    Blender's Event does not say which timer sent a TIMER event, and every running timer's
    events reach a modal handler (another operator's, a second import's). A timer's
    ``time_duration`` grows each time it fires, so a TIMER event is this timer's tick when that
    has grown since the last step: one step per tick, whatever other timers run.
    """
    timer = getattr(operator, "_timer", None)
    if event.type != "TIMER" or timer is None:
        return False
    duration = timer.time_duration
    if duration == getattr(operator, "_stepped_at", None):
        return False
    operator._stepped_at = duration
    return True
