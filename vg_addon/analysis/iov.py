"""The paper's intra-observer variability (IOV) and the per-break statistics built on it.

The IOV of a break (Section 4, equation 4.1) is the mean absolute difference over all pairs of
one observer's repeated readings: for three, ``(|a-b| + |a-c| + |b-c|) / 3``. It is used here for
the angle, the centre (the distance between centres), the radius and the vertex count. With
several observers, a break's IOV is the mean of their IOVs, and the inter-observer IOV the mean
absolute difference over all pairs of readings by *different* observers.

Sums run in a fixed order with exact rounding (``math.fsum``), so the same CSVs give the same
numbers on every machine.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field

from .matching import Unit
from .sessions import Session, distance

#: Methods in the paper's order; others follow in the order first met.
METHOD_ORDER = ("manual", "drag", "xyz")

#: The quantities whose IOV is computed, with the reading's attribute and unit.
QUANTITIES = {
    "angle": ("angle", "°"),
    "centre": ("centre", "mesh units"),
    "radius": ("radius", "mesh units"),
    "vertices": ("vertices", "vertices"),
}


def mean_abs_difference(values) -> float | None:
    """Mean of ``|a - b|`` over all pairs; ``None`` for fewer than two values."""
    values = list(values)
    pairs = [abs(a - b) for a, b in itertools.combinations(values, 2)]
    return math.fsum(pairs) / len(pairs) if pairs else None


def mean_distance(centres) -> float | None:
    """Mean distance over all pairs of centres; ``None`` for fewer than two."""
    pairs = [distance(a, b) for a, b in itertools.combinations(list(centres), 2)]
    return math.fsum(pairs) / len(pairs) if pairs else None


def cross_difference(groups) -> float | None:
    """Mean ``|a - b|`` over pairs of values from different groups; ``None`` without any."""
    groups = [list(g) for g in groups]
    pairs = [
        abs(a - b) for g, h in itertools.combinations(groups, 2) for a, b in itertools.product(g, h)
    ]
    return math.fsum(pairs) / len(pairs) if pairs else None


@dataclass
class Describe:
    """Count, mean, sample SD (``None`` below two values), min and max."""

    n: int
    mean: float | None
    sd: float | None
    min: float | None
    max: float | None

    @classmethod
    def of(cls, values) -> Describe:
        values = list(values)
        if not values:
            return cls(0, None, None, None, None)
        n, low, high = len(values), min(values), max(values)
        if low == high:  # exactly: a rounded mean would leave an SD of 1e-16
            return cls(n, low, 0.0 if n > 1 else None, low, high)
        try:
            mean = math.fsum(values) / n
            sd = math.sqrt(math.fsum((v - mean) ** 2 for v in values) / (n - 1)) if n > 1 else None
        except OverflowError:  # values near the float limit: the same sums, scaled down
            scale = max(abs(low), abs(high))
            mean = math.fsum(v / scale for v in values) / n * scale
            spread = [(v / scale - mean / scale) ** 2 for v in values]
            sd = scale * math.sqrt(math.fsum(spread) / (n - 1)) if n > 1 else None
        return cls(n, mean, sd, low, high)


def _iov(readings, quantity: str) -> float | None:
    attribute = QUANTITIES[quantity][0]
    values = [getattr(r, attribute) for r in readings]
    if len(values) < 2 or any(v is None for v in values):
        return None
    return mean_distance(values) if quantity == "centre" else mean_abs_difference(values)


@dataclass
class MethodAtBreak:
    """One method's readings of one unit.

    Attributes
    ----------
    angle : Describe
        Of all the method's angles there (every observer and repetition).
    iov : dict of str to float or None
        The IOV of each quantity (``angle``, ``centre``, ``radius``, ``vertices``): one
        observer's, or the mean over observers with two or more readings; ``None`` where no
        observer has two readings with that quantity.
    inter_iov : float or None
        Mean absolute angle difference between readings of different observers.
    observer_means : dict of str to float
        Each observer's mean angle there (the ICC's rating).
    """

    angle: Describe
    iov: dict[str, float | None]
    inter_iov: float | None
    observer_means: dict[str, float] = field(default_factory=dict)
    repetitions: int = 0


@dataclass
class BreakStats:
    """One unit and its statistics per method."""

    unit: Unit
    methods: dict[str, MethodAtBreak]


def methods_of(sessions: list[Session]) -> list[str]:
    """The sessions' methods, the paper's three first."""
    found = list(dict.fromkeys(s.method for s in sessions))
    return [m for m in METHOD_ORDER if m in found] + [m for m in found if m not in METHOD_ORDER]


def method_at_break(readings_by_observer: dict[str, list]) -> MethodAtBreak:
    """The statistics of one method on one unit from each observer's readings."""
    every = [r for rs in readings_by_observer.values() for r in rs]
    iov: dict[str, float | None] = {}
    for quantity in QUANTITIES:
        each = [_iov(rs, quantity) for rs in readings_by_observer.values()]
        each = [v for v in each if v is not None]
        iov[quantity] = math.fsum(each) / len(each) if each else None
    inter = cross_difference([r.angle for r in rs] for rs in readings_by_observer.values())
    means = {o: math.fsum(r.angle for r in rs) / len(rs) for o, rs in readings_by_observer.items()}
    repetitions = max(len(rs) for rs in readings_by_observer.values())
    return MethodAtBreak(Describe.of(r.angle for r in every), iov, inter, means, repetitions)


def break_stats(units: list[Unit], sessions: list[Session]) -> list[BreakStats]:
    """Every unit's statistics per method (methods without a reading there are absent)."""
    stats = []
    for unit in units:
        grouped: dict[str, dict[str, list]] = {}
        for s, reading in unit.readings.items():
            session = sessions[s]
            grouped.setdefault(session.method, {}).setdefault(session.observer, []).append(reading)
        methods = {m: method_at_break(grouped[m]) for m in methods_of(sessions) if m in grouped}
        stats.append(BreakStats(unit, methods))
    return stats
