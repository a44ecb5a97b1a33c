"""The edge-profile interaction as a pure state machine (no Blender, no screen).

Click the start of a break edge, any via points, and the end on the surface; each click traces
the leg from the previous one along the ridge, so the path can be drawn as it is found. Undo
drops the last click, cancel leaves nothing behind, confirm measures the stations. The Blender
operator only ray-casts, translates events and draws; it records through the same code path as
a scripted ``vg.measure_edge`` with the machine's clicks, so the two give bit-identical stations.

>>> machine = EdgeMachine(surface)                          # doctest: +SKIP
>>> machine.click(start); machine.click(end)                # doctest: +SKIP
>>> profile = machine.confirm(spacing=0.5, radius=0.3)      # doctest: +SKIP
"""

from __future__ import annotations

from enum import StrEnum

import numpy as np

from ..errors import GoniometerError
from ..method.edge_profile import (
    EdgePath,
    EdgeProfile,
    assemble_path,
    measure_along,
    snap_click,
    trace_leg,
)

MISSED = "Missed the mesh: click on the surface of the active mesh object."


class EdgePhase(StrEnum):
    """Where the interaction is. ``CONFIRMED`` and ``CANCELLED`` are final."""

    PICKING = "picking"
    CONFIRMED = "confirmed"
    CANCELLED = "cancelled"


class EdgeMachine:
    """Clicks along a break edge, the path traced through them, and the confirmed profile.

    Parameters
    ----------
    surface : Surface
        The triangle mesh the clicks are on.

    Attributes
    ----------
    phase : EdgePhase
    clicks : list of ndarray
        The clicked points (float64), start first.
    path : EdgePath or None
        The path through every click (``None`` before the second click).
    profile : EdgeProfile or None
        Set by a successful :meth:`confirm`.
    message : str
        The last hint or refusal, for the header; ``""`` when there is none.
    """

    def __init__(self, surface):
        self.surface = surface
        self.phase = EdgePhase.PICKING
        self.clicks: list[np.ndarray] = []
        self._vertices: list[int] = []
        self._legs: list[np.ndarray] = []
        self.path: EdgePath | None = None
        self.profile: EdgeProfile | None = None
        self.message = ""

    @property
    def picking(self) -> bool:
        """Whether the machine still takes clicks."""
        return self.phase is EdgePhase.PICKING

    def click(self, point) -> bool:
        """Add a click (``None``: the ray missed the mesh) and trace the leg to it.

        Returns whether the click was taken; if not, :attr:`message` says why and nothing
        changed.
        """
        if not self.picking:
            return False
        if point is None:
            self.message = MISSED
            return False
        point = np.array(point, dtype=np.float64)
        try:
            vertex = snap_click(self.surface, point, len(self.clicks) + 1)
            if self._vertices and vertex == self._vertices[-1]:
                raise GoniometerError(
                    "This click snaps to the same vertex as the previous one: click farther "
                    "along the edge."
                )
            leg = trace_leg(self.surface, self._vertices[-1], vertex) if self._vertices else None
        except GoniometerError as error:
            self.message = str(error)
            return False
        self.clicks.append(point)
        self._vertices.append(vertex)
        if leg is not None:
            self._legs.append(leg)
        self._update_path()
        return True

    def undo(self) -> bool:
        """Drop the last click and its leg; returns whether there was one."""
        if not self.picking or not self.clicks:
            return False
        self.clicks.pop()
        self._vertices.pop()
        if self._legs:
            self._legs.pop()
        self._update_path()
        return True

    def _update_path(self) -> None:
        self.path = assemble_path(self.surface, self._legs) if self._legs else None
        self.message = self.path.warning if self.path is not None else ""

    def confirm(self, spacing: float, radius: float, *settings, **options):
        """Measure the stations along the path: the :class:`EdgeProfile`, or ``None`` with
        :attr:`message` saying why (the machine then stays in picking, so the user can fix the
        settings or the clicks).

        ``spacing``, ``radius`` and the further ``settings`` (``lam``, ``patch``, ``rule``,
        ``stability``, by position or name) are those of :func:`~.edge_profile.measure_along`.
        """
        if not self.picking:
            return None
        if self.path is None:
            self.message = "Click at least the start and the end of the edge before confirming."
            return None
        try:
            self.profile = measure_along(
                self.surface, self.path, spacing, radius, *settings, **options
            )
        except GoniometerError as error:
            self.message = str(error)
            return None
        self.phase = EdgePhase.CONFIRMED
        self.message = ""
        return self.profile

    def cancel(self, message: str = "Cancelled: nothing was recorded.") -> None:
        """End the interaction without recording anything."""
        if self.picking:
            self.phase = EdgePhase.CANCELLED
            self.message = message
