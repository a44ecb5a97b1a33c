"""Parts of found break edges: a candidate's confidence, the part an analyst trims it to, and
the part that is its own where it meets a more confident one."""

from __future__ import annotations

import math
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from ..errors import GoniometerError
from .edge_pieces import retraced_legs
from .edge_profile import EdgePath, assemble_path, is_loop, trace_leg
from .ranges import expand_ranges
from .ridge_field import bend_of_anisotropy

if TYPE_CHECKING:
    from .break_edges import BreakEdgeCandidate


def confidence(ridge_fraction: float, mean_bend_deg: float, min_bend_deg: float) -> float:
    """How sure a candidate is: ``ridge_fraction * (1 - exp(-2 (mean - min) / min))``, 0 when
    the mean bend is below ``min_bend_deg``."""
    clear = max(0.0, mean_bend_deg - min_bend_deg) / min_bend_deg
    return float(ridge_fraction * (1.0 - math.exp(-2.0 * clear)))


def rated(candidate: BreakEdgeCandidate, path: EdgePath, bend_deg: np.ndarray, **changes):
    """``candidate`` with ``path`` and its bends, mean bend and confidence worked out anew."""
    mean_bend = float(bend_deg.mean())
    on_ridge = float(np.mean(bend_deg >= candidate.ridge_min_deg))
    return replace(
        candidate,
        path=path,
        bend_deg=bend_deg,
        mean_bend_deg=mean_bend,
        confidence=confidence(on_ridge, mean_bend, candidate.min_bend_deg),
        **changes,
    )


def trim(candidate: BreakEdgeCandidate, start_arc: float, end_arc: float) -> BreakEdgeCandidate:
    """The part of ``candidate`` between arc lengths ``start_arc`` and ``end_arc``.

    Each end snaps to the path vertex nearest its arc length. On a loop (``candidate.closed``) a
    ``start_arc`` beyond ``end_arc`` keeps the part that runs on from ``start_arc`` through the
    loop's start to ``end_arc``. The part keeps the candidate's waypoints that fall inside it,
    plus via points where the part would not otherwise retrace identically through
    ``trace_edge``; where the cheapest ridge path between the ends of one of its mesh edges goes
    round by a third vertex (no via point can hold that edge), the part goes that way too. Its
    bends (read from ``candidate.bend_field``), confidence and mean bend are the part's.

    Raises
    ------
    GoniometerError
        Arc lengths out of order on an open candidate or outside 0 to its length (not clamped:
        a part the caller did not ask for is never kept), or leaving less than one mesh edge.
    """
    if candidate.bend_field is None:
        raise GoniometerError(
            "Only a candidate the finder made can be trimmed: this one carries no bend field."
        )
    path = candidate.path
    arc = path.arc_lengths
    try:
        start_arc, end_arc = float(start_arc), float(end_arc)
    except (TypeError, ValueError):
        raise GoniometerError("The trim's arc lengths must be numbers.") from None
    wraps = candidate.closed and start_arc > end_arc
    slack = 1e-9 * path.length  # a click's arc length computed in another order of sums
    within = all(-slack <= value <= path.length + slack for value in (start_arc, end_arc))
    if not (within and (start_arc < end_arc or wraps)):  # also refuses NaN and infinities
        raise GoniometerError(
            f"Trim from arc length {start_arc:g} to {end_arc:g}: the start must come before the "
            f"end, both within 0 to {path.length:.6g}."
        )
    first = int(np.argmin(np.abs(arc - start_arc)))
    last = int(np.argmin(np.abs(arc - end_arc)))
    end = arc.size - 1
    if wraps:
        # The loop's start and end are one vertex: a part that reaches either does not wrap.
        if first == end:
            first, wraps = 0, False
        elif last == 0:
            last, wraps = end, False
    if wraps:
        vertices = np.concatenate([path.vertices[first:], path.vertices[1 : last + 1]])
        inside = [int(w) - first for w in path.waypoints if first < w < end]
        inside += [end - first] + [end - first + int(w) for w in path.waypoints if 0 < w < last]
    elif last <= first:
        raise GoniometerError(
            f"Trimming from {start_arc:g} to {end_arc:g} leaves less than one mesh edge of this "
            "candidate: keep a longer part."
        )
    else:
        vertices = path.vertices[first : last + 1]
        inside = [int(w) - first for w in path.waypoints if first < w < last]
    surface = candidate.surface
    stops = [0, *inside, vertices.size - 1]
    # A leg of one mesh edge has no vertex to hold it: where the cheapest ridge path between its
    # ends goes round by a third vertex, the part takes that way, so it retraces as it is.
    legs = [
        trace_leg(surface, leg[0], leg[-1]) if leg.size == 2 else leg
        for leg in retraced_legs(surface, vertices, stops)
    ]
    part = assemble_path(surface, legs)
    bend_deg = bend_of_anisotropy(candidate.bend_field[part.vertices])
    return rated(candidate, part, bend_deg, closed=is_loop(part))


def without_shared_ends(candidates, starts, target, min_length: float) -> list:
    """``candidates`` (most confident first) with every end that runs along a more confident
    candidate's path (on it or on the vertices beside it) cut back to where the two part.

    Where edges meet (a cube's corner, a platform edge joining a flake's margin) two candidates
    can both run round the same stretch of ridge; profiled, that stretch would be measured
    twice, once under each edge. Each candidate loses the runs of vertices at its ends that lie
    on or beside a more confident one's path, except the last, where they part. A candidate
    left shorter than ``min_length`` (or with nothing of its own) is dropped. A stretch shared in
    the middle of a path, and loops, are kept as they are.

    Parameters
    ----------
    candidates : sequence of BreakEdgeCandidate
        In order of confidence, highest first.
    starts, target : ndarray of int64
        The mesh's vertex neighbours (CSR, as :class:`~.edge_profile.RidgeGraph` holds them).
    min_length : float
        The shortest candidate kept.

    Returns
    -------
    list of BreakEdgeCandidate
        The candidates kept, in the order given; a cut one is :func:`trim`'s part, which
        retraces through its waypoints.
    """
    beside = np.zeros(starts.size - 1, dtype=bool)  # on or next to a kept candidate's path
    kept = []
    for candidate in candidates:
        part = _own_part(candidate, beside)
        if part is None or part.length < min_length:
            continue
        vertices = part.path.vertices
        beside[vertices] = True
        beside[target[expand_ranges(starts[vertices], starts[vertices + 1] - starts[vertices])]] = (
            True
        )
        kept.append(part)
    return kept


def _own_part(candidate: BreakEdgeCandidate, beside: np.ndarray):
    """The part of an open ``candidate`` past the runs of ``beside`` vertices at its ends (None
    when nothing is left)."""
    if candidate.closed:
        return candidate
    shared = beside[candidate.path.vertices]
    if shared.all():
        return None
    lead = int(np.argmin(shared))  # the first vertex not taken
    trail = int(np.argmin(shared[::-1]))
    first = max(lead - 1, 0)
    last = shared.size - 1 - max(trail - 1, 0)
    if first == 0 and last == shared.size - 1:
        return candidate
    if last <= first:
        return None
    arc = candidate.path.arc_lengths
    return trim(candidate, arc[first], arc[last])
