"""What the stations of one edge profile say together: their angles' summary, the whole-edge
mean angle and the break-agent study's figures (:func:`summarize`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import GoniometerError
from .break_figures import break_figures, fragment_axis
from .fixed_order import acos_degrees, cross3, dot3, in_frame, norm3
from .result import Measurement


@dataclass(frozen=True)
class EdgeSummary:
    """What the stations of one edge say together (see :func:`summarize`).

    Attributes
    ----------
    n_stations : int
    mean, min, max : float
        Of the stations' angles (degrees).
    std : float or None
        The sample standard deviation of the stations' angles (degrees); None (undefined) for
        one station, whose spread is unknown, not 0 (see :func:`sd_text`).
    pooled_angle, pooled_fit_error : float
        The whole-edge mean angle: the angle between the mean plane normals of the edge's left
        and right sides, each station's two fitted normals expressed in its own frame (along the
        edge, across it, and the bisector of the two normals, so that a curved edge pools like a
        straight one) and weighted by the vertices of its side; it lies within the stations'
        range. The fit error is the two sides' mean squared plane-fit distances, each the
        vertex-weighted mean of the stations'.
    plus_left : tuple of bool
        Per station, whether its "+" side lies to the left of the path's direction (seen from
        outside, along the mean normal). A station's "+" side follows its own binormal, which can
        turn over along a curved edge; painting the left side in one colour keeps the sides of
        the whole edge consistent.
    median, range, arc_length, chord_length, arc_angle : float or None
        The break-agent study's figures (see :mod:`.break_figures`): the stations' median angle
        and range (degrees), the length of the polyline through their centres and from the
        first to the last, and the angle between the edge's and the fragment's principal axes
        (degrees; None where undefined).
    """

    n_stations: int
    mean: float
    std: float | None
    min: float
    max: float
    pooled_angle: float
    pooled_fit_error: float
    plus_left: tuple = ()
    median: float | None = None
    range: float | None = None
    arc_length: float | None = None
    chord_length: float | None = None
    arc_angle: float | None = None


def _frame(m: Measurement, direction: np.ndarray) -> np.ndarray:
    """Rows: along the edge (oriented like ``direction``), across it, and the mean normal."""
    tangent = m.tangent if dot3(m.tangent, direction) >= 0 else -m.tangent
    normal = m.mean_normal - dot3(m.mean_normal, tangent) * tangent
    normal /= norm3(normal)
    return np.array([tangent, np.cross(normal, tangent), normal])


def _bisector_frame(m: Measurement, direction: np.ndarray) -> np.ndarray:
    """Rows: along the edge (oriented like ``direction``), across it, and the bisector of the
    station's two plane normals (its mean normal where they are opposite)."""
    tangent = m.tangent if dot3(m.tangent, direction) >= 0 else -m.tangent
    middle = m.normal_plus + m.normal_minus
    middle = middle - dot3(middle, tangent) * tangent
    if norm3(middle) <= 1e-12:
        return _frame(m, direction)
    middle /= norm3(middle)
    return np.array([tangent, cross3(middle, tangent), middle])


def _in_rows(frame: np.ndarray, vector) -> list[float]:
    return [dot3(row, vector) for row in frame]


def summarize(surface, stations) -> EdgeSummary:
    """Summary figures of an edge's station measurements, in order along the edge.

    The direction along the edge at each station comes from its neighbours' centres; it only
    orients each station's frame, so that every station's left side pools with the others' left.
    """
    if not stations:
        raise GoniometerError("An edge profile needs at least one station.")
    angles = np.array([m.angle for m in stations])
    centers = np.array([m.center for m in stations])
    # Per side (left, right): the vertex-weighted sums of the fitted normals, each in its
    # station's bisector frame, of the vertex counts and of the counts times the fit errors.
    normal_sums = {True: [0.0, 0.0, 0.0], False: [0.0, 0.0, 0.0]}
    counts = {True: 0, False: 0}
    error_sums = {True: 0.0, False: 0.0}
    plus_left = []
    for k, m in enumerate(stations):
        ahead, behind = centers[min(k + 1, len(stations) - 1)], centers[max(k - 1, 0)]
        direction = ahead - behind if len(stations) > 1 else m.tangent
        local = in_frame(surface.points[m.indices] - m.center, _frame(m, direction))
        plus_is_left = bool(local[m.labels, 1].mean() >= local[~m.labels, 1].mean())
        plus_left.append(plus_is_left)
        frame = _bisector_frame(m, direction)
        for normal, count, error, is_plus in (
            (m.normal_plus, m.n_plus, m.fit_error_plus, True),
            (m.normal_minus, m.n_minus, m.fit_error_minus, False),
        ):
            key = is_plus == plus_is_left
            for axis, value in enumerate(_in_rows(frame, normal)):
                normal_sums[key][axis] += count * value
            counts[key] += count
            error_sums[key] += count * error
    left, right = (np.array(normal_sums[key]) / norm3(normal_sums[key]) for key in (True, False))
    pooled = 180.0 - acos_degrees(dot3(left, right))
    left_error, right_error = (error_sums[key] / counts[key] for key in (True, False))
    study = break_figures(angles, centers, fragment_axis(surface))
    return EdgeSummary(
        n_stations=len(stations),
        mean=float(angles.mean()),
        std=float(angles.std(ddof=1)) if angles.size > 1 else None,
        min=float(angles.min()),
        max=float(angles.max()),
        pooled_angle=pooled,
        pooled_fit_error=left_error + right_error,
        plus_left=tuple(plus_left),
        median=study.median,
        range=study.range,
        arc_length=study.arc_length,
        chord_length=study.chord_length,
        arc_angle=study.arc_angle,
    )


__all__ = ["EdgeSummary", "summarize"]


def sd_text(std) -> str:
    """An edge's SD for a report or panel: ``"0.42°"``, or ``"undefined (one station)"`` where
    ``std`` is None (the CSV leaves the cell blank)."""
    return "undefined (one station)" if std is None else f"{std:.2f}°"
