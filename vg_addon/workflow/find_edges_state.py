"""The Find Break Edges review as a pure state machine (no Blender, no screen).

The detector (``method.break_edges.BreakEdgeFinder``) is stepped until it has its candidates
(each step a chunk of work, so a modal operator can show progress and stop at once); then the
analyst reviews them: select one (a click near it, or the next in turn), accept it, reject it,
or trim it to the part between two clicks on it (on a loop, a third click picks the part).
Finishing measures every accepted candidate
with the Edge Profile settings, one per step, all or nothing: a candidate whose stations
cannot be measured sends the review back with a message naming it. Cancelling at any point
leaves nothing. The Blender operator only projects, translates events, draws and records the
finished profiles in one undo step.

>>> machine = FindEdgesMachine(surface, BreakEdgeFinder(surface))   # doctest: +SKIP
>>> while machine.step(): pass                                      # doctest: +SKIP
>>> machine.select(0); machine.accept()                             # doctest: +SKIP
>>> machine.finish(spacing=2.0, radius=1.5)                         # doctest: +SKIP
>>> while machine.step(): pass                                      # doctest: +SKIP
>>> machine.profiles                                                # doctest: +SKIP
"""

from __future__ import annotations

from enum import StrEnum

import numpy as np

from ..errors import GoniometerError, bounded_list
from ..method.break_edges import BreakEdgeCandidate
from ..method.candidate_parts import trim
from ..method.edge_profile import measure_along

#: A click selects the candidate drawn nearest to it within this many pixels.
PICK_PIXELS = 12.0


class FindPhase(StrEnum):
    """Where the tool is. ``DONE`` and ``CANCELLED`` are final."""

    FINDING = "finding"
    REVIEW = "review"
    TRIMMING = "trimming"
    MEASURING = "measuring"
    DONE = "done"
    CANCELLED = "cancelled"


class Decision(StrEnum):
    """The analyst's verdict on one candidate."""

    PENDING = "pending"
    ACCEPTED = "accepted"
    REJECTED = "rejected"


def project(points, to_clip, width: float, height: float) -> np.ndarray:
    """Pixel coordinates in a view region of ``points`` (``(k, 3)``).

    ``to_clip`` is the 4×4 matrix from the points' coordinates to clip space (the region's
    perspective matrix times the object's world matrix). Points behind the viewer come out
    NaN, so they are never nearest to anything.
    """
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    matrix = np.asarray(to_clip, dtype=np.float64)
    homogeneous = np.hstack([points, np.ones((points.shape[0], 1))]) @ matrix.T
    w = homogeneous[:, 3]
    out = np.full((points.shape[0], 2), np.nan)
    ahead = w > 0.0
    ndc = homogeneous[ahead, :2] / w[ahead, None]
    out[ahead] = (ndc + 1.0) * 0.5 * np.array([width, height], dtype=np.float64)
    return out


def nearest_on_screen(pixels: np.ndarray, mouse) -> tuple[int, float]:
    """``(index, distance)`` of the point of ``pixels`` (``(k, 2)``, NaN: not on screen)
    nearest ``mouse``, or ``(-1, inf)`` when none is on screen."""
    pixels = np.asarray(pixels, dtype=np.float64).reshape(-1, 2)
    distance = np.hypot(pixels[:, 0] - mouse[0], pixels[:, 1] - mouse[1])
    distance = np.where(np.isnan(distance), np.inf, distance)
    if not distance.size or not np.isfinite(distance).any():
        return -1, float("inf")
    index = int(np.argmin(distance))
    return index, float(distance[index])


def nearest_on_path(pixels: np.ndarray, mouse) -> tuple[int, float]:
    """``(index, distance)`` for a path drawn through ``pixels`` (``(k, 2)``, NaN: not on
    screen): the distance from ``mouse`` to the drawn line (its segments, and any point on
    screen alone), and the vertex nearest the spot on it; ``(-1, inf)`` when none is on
    screen. Zoomed in, a click on the line can be far from every vertex of it."""
    pixels = np.asarray(pixels, dtype=np.float64).reshape(-1, 2)
    index, distance = nearest_on_screen(pixels, mouse)
    if len(pixels) < 2:
        return index, distance
    start, step = pixels[:-1], np.diff(pixels, axis=0)
    length2 = np.einsum("ij,ij->i", step, step)
    offset = np.asarray(mouse, dtype=np.float64) - start
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.clip(np.einsum("ij,ij->i", offset, step) / length2, 0.0, 1.0)
    t = np.where(length2 > 0.0, t, 0.0)
    gaps = np.hypot(*(offset - t[:, None] * step).T)
    gaps = np.where(np.isnan(gaps), np.inf, gaps)
    segment = int(np.argmin(gaps))
    if gaps[segment] < distance:
        return segment + int(t[segment] > 0.5), float(gaps[segment])
    return index, distance


def edge_points(candidate: BreakEdgeCandidate) -> np.ndarray:
    """The points an accepted candidate is recorded with: its path's waypoints (start, via
    points, end), which ``trace_edge`` follows back to its path; float64 mesh coordinates."""
    return np.array(candidate.waypoint_points, dtype=np.float64)


class FindEdgesMachine:
    """The finder's progress, the candidates, the analyst's decisions and the measured edges.

    Parameters
    ----------
    surface : Surface
        The mesh the finder works on (the accepted edges are measured on it).
    finder : BreakEdgeFinder
        Not yet stepped; :meth:`step` iterates its ``steps()``.

    Attributes
    ----------
    phase : FindPhase
    progress : float
        Fraction of the current work done, in [0, 1] (finding, then measuring).
    candidates : list of BreakEdgeCandidate
        The candidates, best first; a trimmed one replaces the original in its place.
    decisions : list of Decision
        One per candidate.
    selected : int or None
        Index into :attr:`candidates` of the selected one.
    trim_arcs : list of float
        The arc lengths clicked so far while trimming: the two ends of the part kept, then, on a
        loop, a point on the part kept.
    profiles : list of (ndarray, EdgeProfile)
        Set when :attr:`phase` is ``DONE``: each accepted candidate's points (as
        :func:`edge_points`) and its measured profile, in candidate order.
    message : str
        The last hint or refusal, for the header; ``""`` when there is none.
    """

    def __init__(self, surface, finder):
        self.surface = surface
        self.finder = finder
        self.phase = FindPhase.FINDING
        self.progress = 0.0
        self.candidates: list[BreakEdgeCandidate] = []
        self.decisions: list[Decision] = []
        self.selected: int | None = None
        self.trim_arcs: list[float] = []
        self.profiles: list = []
        self.message = ""
        self._work = iter(finder.steps())
        self._settings: tuple | None = None
        self._queue: list[int] = []

    # -- finding and measuring --------------------------------------------------------------
    @property
    def working(self) -> bool:
        """Whether :meth:`step` has work to do (finding or measuring)."""
        return self.phase in (FindPhase.FINDING, FindPhase.MEASURING)

    def step(self) -> bool:
        """Do one chunk of the current work; returns whether more is left."""
        if self.phase is FindPhase.FINDING:
            return self._find_step()
        if self.phase is FindPhase.MEASURING:
            return self._measure_step()
        return False

    def _find_step(self) -> bool:
        try:
            self.progress = float(next(self._work))
            return True
        except StopIteration:
            pass
        except GoniometerError as error:
            self.cancel(f"No break edges were found: {error}")
            return False
        self.candidates = list(self.finder.result.candidates)
        self.decisions = [Decision.PENDING] * len(self.candidates)
        self.progress = 1.0
        self.phase = FindPhase.REVIEW
        if self.candidates:
            self.selected = 0
            self.message = ""
        else:
            self.message = "No break edges were found: nothing to review."
        return False

    def _measure_step(self) -> bool:
        index = self._queue[len(self.profiles)]
        points = edge_points(self.candidates[index])
        try:
            settings, options = self._settings
            profile = measure_along(self.surface, points, *settings, **options)
        except GoniometerError as error:
            self.phase = FindPhase.REVIEW
            self.selected = index
            self.profiles = []
            first = str(error).splitlines()[0]
            self.message = (
                f"Candidate {self.candidates[index].number} cannot be measured: {first} "
                "Trim or reject it, or change the settings."
            )
            return False
        self.profiles.append((points, profile))
        self.progress = len(self.profiles) / len(self._queue)
        if len(self.profiles) == len(self._queue):
            self.phase = FindPhase.DONE
            self.message = ""
            return False
        return True

    # -- review -----------------------------------------------------------------------------
    @property
    def reviewing(self) -> bool:
        """Whether decisions can be made now."""
        return self.phase is FindPhase.REVIEW

    @property
    def accepted(self) -> list[int]:
        """Indices of the accepted candidates, in order."""
        return [i for i, d in enumerate(self.decisions) if d is Decision.ACCEPTED]

    def count(self, decision: Decision) -> int:
        """How many candidates have ``decision``."""
        return sum(d is decision for d in self.decisions)

    def select(self, index: int | None) -> bool:
        """Select candidate ``index`` (``None``: none); returns whether it was taken."""
        if not self.reviewing:
            return False
        if index is not None and not 0 <= index < len(self.candidates):
            return False
        self.selected = index
        self.message = "" if index is None else _revisit_hint(self.candidates[index])
        return True

    def select_next(self, step: int = 1) -> bool:
        """Select the next (``step=-1``: previous) candidate, preferring undecided ones."""
        if not self.reviewing or not self.candidates:
            return False
        n = len(self.candidates)
        start = -1 if self.selected is None and step > 0 else (self.selected or 0)
        order = [(start + step * k) % n for k in range(1, n + 1)]
        pending = [i for i in order if self.decisions[i] is Decision.PENDING]
        return self.select((pending or order)[0])

    def pick(self, pixels_per_candidate, mouse, tolerance: float = PICK_PIXELS) -> bool:
        """Select the candidate drawn nearest ``mouse`` (region pixels) if within
        ``tolerance``; ``pixels_per_candidate``: each candidate's path projected (:func:`project`).
        During a trim, a click on the candidate being trimmed marks one end instead."""
        if self.phase is FindPhase.TRIMMING:
            return self._trim_click(pixels_per_candidate[self.selected], mouse, tolerance)
        if not self.reviewing:
            return False
        best, best_distance = None, tolerance
        for index, pixels in enumerate(pixels_per_candidate):
            _, distance = nearest_on_path(pixels, mouse)
            if distance <= best_distance:
                best, best_distance = index, distance
        if best is None:
            self.message = "No candidate there: click on one of the numbered lines."
            return False
        return self.select(best)

    def _deciding(self) -> bool:
        """Whether decisions can be made now; during a trim the message says to end it first
        (a key that did nothing and said nothing looked like a lost decision)."""
        if self.phase is FindPhase.TRIMMING:
            self.message = "Finish the trim first: click on the candidate."
        return self.reviewing

    def _decide(self, decision: Decision) -> bool:
        if not self._deciding():
            return False
        if self.selected is None:
            self.message = "Select a candidate first: click on it."
            return False
        self.decisions[self.selected] = decision
        self.message = ""
        self.select_next()
        return True

    def accept(self) -> bool:
        """Accept the selected candidate, then select the next undecided one."""
        return self._decide(Decision.ACCEPTED)

    def reject(self) -> bool:
        """Reject the selected candidate, then select the next undecided one."""
        return self._decide(Decision.REJECTED)

    def accept_pending(self) -> int:
        """Accept every undecided candidate; returns how many."""
        if not self._deciding():
            return 0
        pending = [i for i, d in enumerate(self.decisions) if d is Decision.PENDING]
        for index in pending:
            self.decisions[index] = Decision.ACCEPTED
        self.message = ""
        return len(pending)

    # -- trimming ---------------------------------------------------------------------------
    def start_trim(self) -> bool:
        """Start trimming the selected candidate: the next two clicks on it mark the ends of the
        part kept (on a loop, a third click on the part to keep says which of the two it is)."""
        if not self.reviewing:
            return False
        if self.selected is None:
            self.message = "Select a candidate to trim first: click on it."
            return False
        self.phase = FindPhase.TRIMMING
        self.trim_arcs = []
        self.message = ""
        return True

    def _trim_click(self, pixels, mouse, tolerance: float) -> bool:
        index, distance = nearest_on_path(pixels, mouse)
        if distance > tolerance:
            self.message = "Click on the candidate being trimmed, where the kept part ends."
            return False
        candidate = self.candidates[self.selected]
        self.trim_arcs.append(float(candidate.path.arc_lengths[index]))
        ends = 3 if candidate.closed else 2
        if len(self.trim_arcs) < ends:
            self.message = "Click the part of the loop to keep." if len(self.trim_arcs) == 2 else ""
            return True
        low, high = sorted(self.trim_arcs[:2])
        chosen = self.trim_arcs[2] if candidate.closed else low
        self.trim_arcs = []
        self.phase = FindPhase.REVIEW
        # Two clicks cut a loop in two: the third says which part is kept (it may run on through
        # the loop's start).
        if low <= chosen <= high:
            return self.trim_to(low, high)
        return self.trim_to(high, low)

    def trim_to(self, start_arc: float, end_arc: float) -> bool:
        """Trim the selected candidate to the arc lengths ``start_arc`` to ``end_arc`` along
        it (what two clicks on it do)."""
        if not self.reviewing or self.selected is None:
            return False
        try:
            trimmed = trim(self.candidates[self.selected], start_arc, end_arc)
        except GoniometerError as error:
            self.message = f"Not trimmed: {error}"
            return False
        self.candidates[self.selected] = trimmed
        self.message = ""
        return True

    def back(self) -> bool:
        """Back to the review: a trim left unfinished (the candidate stays as it was), or the
        measuring stopped (nothing measured is kept); returns whether there was one."""
        if self.phase is FindPhase.TRIMMING:
            self.message = "Trim abandoned: the candidate is as it was."
        elif self.phase is FindPhase.MEASURING:
            self.profiles = []
            self.message = "Measuring stopped: nothing was recorded; Enter measures again."
        else:
            return False
        self.phase = FindPhase.REVIEW
        self.trim_arcs = []
        return True

    # -- the end ----------------------------------------------------------------------------
    def finish(self, spacing: float, radius: float, *settings, **options) -> bool:
        """Start measuring the accepted candidates (one per :meth:`step`). With none accepted
        the review goes on, saying so (Enter pressed early must not lose the decisions made);
        Esc leaves it with nothing recorded.

        ``spacing``, ``radius`` and the further ``settings`` (``lam``, ``patch``, ``rule``,
        ``stability``, by position or name) are those of :func:`~.edge_profile.measure_along`.
        """
        if not self._deciding():
            return False
        if not self.accepted:
            self.message = "No candidate is accepted yet: accept one (A) to record it, or Esc."
            return False
        self._settings = ((spacing, radius, *settings), options)
        self._queue = self.accepted
        self.profiles = []
        self.phase = FindPhase.MEASURING
        self.progress = 0.0
        self.message = ""
        return True

    def cancel(self, message: str = "Cancelled: nothing was recorded.") -> None:
        """End without recording anything (the finder is dropped)."""
        if self.phase not in (FindPhase.DONE, FindPhase.CANCELLED):
            self.phase = FindPhase.CANCELLED
            self.profiles = []
            self.message = message
            self._work = iter(())


def _revisit_hint(candidate) -> str:
    """What to do with a candidate whose path passes the same vertices twice (the finder could
    not untie it), or ``""``: a station there would measure one place twice, or be refused."""
    spans = candidate.path.revisited_spans
    if not spans:
        return ""
    where = bounded_list(f"{a:.4g} to {b:.4g}" for a, b in spans)
    return (
        f"Candidate {candidate.number} passes the same vertices twice (arc lengths {where}): "
        "trim that stretch off, or reject it."
    )
