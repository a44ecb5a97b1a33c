"""The radius sweep (the MeshLab plugin's "burst"): one site measured over a range of radii."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import GoniometerError
from .algorithm import DEFAULT_RULE
from .inputs import as_radius
from .result import Measurement

MAX_SWEEP_RADII = 1000
"""More radii than this would only take long; the plot cannot show them apart anyway."""


@dataclass(frozen=True, eq=False)
class SweepPoint:
    """One radius of a sweep: its measurement, or why it was refused.

    Attributes
    ----------
    radius : float
    measurement : Measurement or None
        ``None`` when the radius was refused.
    error : str
        Empty when measured; the refusal's message otherwise.
    """

    radius: float
    measurement: Measurement | None
    error: str


def sweep_radii(start, stop, count) -> np.ndarray:
    """``count`` radii evenly spaced from ``start`` to ``stop`` (both included), validated."""
    start, stop = as_radius(start), as_radius(stop)
    if isinstance(count, bool) or not isinstance(count, (int, np.integer)):
        raise GoniometerError(f"The number of radii must be a whole number; got {count!r}.")
    if not 2 <= count <= MAX_SWEEP_RADII:
        raise GoniometerError(
            f"A sweep needs 2 to {MAX_SWEEP_RADII} radii; got {count}: change the count."
        )
    if not start < stop:
        raise GoniometerError(
            f"The sweep's first radius ({start:g}) must be smaller than its last ({stop:g})."
        )
    return np.linspace(start, stop, int(count))


def radius_sweep(
    surface,
    center,
    start: float,
    stop: float,
    count: int,
    lam: float = 2.0,
    patch: str = "euclidean",
    rule: str = DEFAULT_RULE,
) -> list[SweepPoint]:
    """Measure at ``center`` with ``count`` radii from ``start`` to ``stop``.

    Parameters
    ----------
    surface : Surface
    center : array_like, shape (3,)
        Snapped to the nearest vertex for each radius, as ``Surface.measure`` does.
    start, stop : float
        First and last radius, ``0 < start < stop``.
    count : int
        Number of radii, 2 to :data:`MAX_SWEEP_RADII`.
    lam, patch, rule
        As for ``Surface.measure``.

    Returns
    -------
    list of SweepPoint
        One per radius, in increasing order; refused radii carry their message.

    Raises
    ------
    GoniometerError
        Bad radii or count, or no radius could be measured (the message gives the first and
        last refusal, so the user sees what to change).
    """
    points = []
    for radius in sweep_radii(start, stop, count):
        try:
            m = surface.measure(center, float(radius), lam, patch, rule=rule)
            points.append(SweepPoint(float(radius), m, ""))
        except GoniometerError as error:
            points.append(SweepPoint(float(radius), None, str(error)))
    if all(point.measurement is None for point in points):
        raise GoniometerError(
            f"No radius from {start:g} to {stop:g} could be measured here. At {start:g}: "
            f"{points[0].error} At {stop:g}: {points[-1].error}"
        )
    return points
