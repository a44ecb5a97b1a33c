"""The click-and-drag measuring interaction as a pure state machine (no Blender, no screen).

Press on the surface, drag out the radius while a preview shows the patch, release to measure.
Typed digits set the radius exactly, λ can be changed mid-drag (the current patch is re-measured),
and a cancel leaves nothing behind. The Blender operator only translates events and draws; every
decision lives here, so the tests drive it with synthetic events and a real :class:`Surface`.

>>> machine = DragMachine(**surface_callbacks(surface))      # doctest: +SKIP
>>> machine.press(hit_point); machine.move(0.4)              # doctest: +SKIP
>>> record = machine.release()   # a DragRecord, or None     # doctest: +SKIP
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from enum import StrEnum

import numpy as np

from ..errors import GoniometerError
from ..method.algorithm import DEFAULT_RULE, MIN_RADIUS, MIN_SIDE_VERTICES

MIN_PATCH_VERTICES = 2 * MIN_SIDE_VERTICES
"""The fewest patch vertices that can be measured (three per side)."""

LAM_STEP = 0.25
"""How much one key press or wheel step changes λ (a binary fraction: steps never drift)."""

MISSED = "Missed the mesh: press on the surface of the active mesh object."
TYPED_CHARACTERS = frozenset("0123456789.")


class Phase(StrEnum):
    """Where the interaction is. ``MEASURED`` and ``CANCELLED`` are final."""

    IDLE = "idle"
    DRAGGING = "dragging"
    MEASURED = "measured"
    CANCELLED = "cancelled"


@dataclass(frozen=True, eq=False)
class DragRecord:
    """What a successful release produced: everything ``vg.measure_xyz`` needs to redo it.

    Attributes
    ----------
    center : ndarray, shape (3,)
        The position of the vertex the press snapped to (float64).
    radius : float
        The patch radius, as the machine used it (already passed through ``quantize``).
    lam : float
        The segmentation parameter λ.
    measurement : object
        What ``measure(center, radius, lam)`` returned at release.
    """

    center: np.ndarray
    radius: float
    lam: float
    measurement: object


def too_few_message(count: int) -> str:
    """The hint shown while the preview patch is too small to measure."""
    return (
        f"Too few vertices: the patch holds {count}, at least {MIN_PATCH_VERTICES} are needed; "
        "drag further out or type a larger radius."
    )


def _identity(value: float) -> float:
    return float(value)


def _parse_number(text: str) -> float:
    return float(text) if text.strip(".") else 0.0


class DragMachine:
    """The drag interaction: events in, preview and at most one record out.

    Parameters
    ----------
    query : callable ``(center, radius) -> indices``
        The preview patch: indices of the vertices that a measurement at ``center`` with
        ``radius`` would use. Called on every radius change.
    measure : callable ``(center, radius, lam) -> measurement``
        Measures the patch (on release, and on a λ change mid-drag). May raise
        :class:`GoniometerError`; the machine turns that into its ``message``.
    snap : callable ``(point) -> center``, optional
        Moves the pressed point onto a vertex (default: keep the point). May raise
        :class:`GoniometerError`.
    lam : float, optional
        The starting λ (default 2).
    quantize : callable ``(value) -> value``, optional
        Applied to every radius and λ before it is used, e.g. rounding to the float32 that a
        Blender property stores, so the preview shows exactly what a replay will measure.
    parse : callable ``(text) -> radius``, optional
        Turns typed digits into a radius (default ``float``; Blender passes a unit-aware parser).
    min_vertices : int, optional
        The fewest patch vertices a release records (default :data:`MIN_PATCH_VERTICES`).
    measure_release : callable ``(center, radius, lam) -> Measurement``, optional
        What the release measures with, when it takes more than the previews (e.g. the
        stability figure); default ``measure``. Its result is the one recorded.

    Notes
    -----
    Events in a final phase (``MEASURED``, ``CANCELLED``) change nothing, so a release records at
    most once, and a cancel before it means nothing is ever recorded. A release (or Enter) with a
    patch too small to measure, or one the measurement rejects, records nothing and returns to
    ``IDLE`` with a message saying why; a press that misses (``None``) stays in ``IDLE``.
    """

    def __init__(
        self,
        query: Callable,
        measure: Callable,
        *,
        snap: Callable | None = None,
        lam: float = 2.0,
        quantize: Callable[[float], float] = _identity,
        parse: Callable[[str], float] = _parse_number,
        min_vertices: int = MIN_PATCH_VERTICES,
        measure_release: Callable | None = None,
    ):
        self._query = query
        self._measure = measure
        self._measure_release = measure_release or measure
        self._snap = snap
        self._quantize = quantize
        self._parse = parse
        self.min_vertices = int(min_vertices)
        self.phase = Phase.IDLE
        self.lam = float(lam)
        self.center: np.ndarray | None = None
        self.radius = 0.0
        self.mouse_radius = 0.0
        self.typed = ""
        self.indices = np.empty(0, dtype=np.int64)
        self.measurement = None
        self.record: DragRecord | None = None
        self.message = ""

    # -- what the operator shows ------------------------------------------------------------

    @property
    def n_vertices(self) -> int:
        """Number of vertices in the preview patch."""
        return int(self.indices.size)

    @property
    def can_record(self) -> bool:
        """Whether a release now would try to measure (the preview patch is big enough)."""
        return self.phase is Phase.DRAGGING and self.n_vertices >= self.min_vertices

    @property
    def finished(self) -> bool:
        """True once the interaction is over (measured or cancelled)."""
        return self.phase in (Phase.MEASURED, Phase.CANCELLED)

    # -- events -----------------------------------------------------------------------------

    def press(self, hit) -> bool:
        """Start a drag at ``hit`` (a point on the surface), or note a miss when it is ``None``.

        Returns True when a drag started.
        """
        if self.phase is not Phase.IDLE:
            return False
        if hit is None:
            self.message = MISSED
            return False
        try:
            center = self._snap(hit) if self._snap is not None else hit
            center = np.array(center, dtype=np.float64).reshape(3)
        except GoniometerError as error:
            self.message = str(error)
            return False
        self.center = center
        self.phase = Phase.DRAGGING
        self.typed = ""
        self.mouse_radius = 0.0
        self.measurement = None
        self._set_radius(0.0)
        return True

    def move(self, radius: float) -> None:
        """The mouse moved: ``radius`` is its distance from the centre. Ignored while typing."""
        if self.phase is not Phase.DRAGGING:
            return
        self.mouse_radius = self._quantize(radius)
        if not self.typed:
            self._set_radius(self.mouse_radius)

    def type_character(self, character: str) -> bool:
        """Typed input for an exact radius: a digit or the decimal point. Returns True if taken."""
        if self.phase is not Phase.DRAGGING or character not in TYPED_CHARACTERS:
            return False
        if character == "." and "." in self.typed:
            return False
        self.typed += character
        self._apply_typed()
        return True

    def backspace(self) -> None:
        """Remove the last typed character; with none left the mouse sets the radius again."""
        if self.phase is not Phase.DRAGGING or not self.typed:
            return
        self.typed = self.typed[:-1]
        if self.typed:
            self._apply_typed()
        else:
            self._set_radius(self.mouse_radius)

    def enter(self) -> DragRecord | None:
        """Confirm (Enter key): the same as releasing the mouse button."""
        return self.release()

    def change_lam(self, steps: float) -> None:
        """Change λ by ``steps`` × :data:`LAM_STEP` (never below 0) and re-measure the patch."""
        self.set_lam(self.lam + steps * LAM_STEP)

    def set_lam(self, lam: float) -> None:
        """Set λ (clamped at 0) and re-measure the current patch when it is big enough."""
        if self.phase is not Phase.DRAGGING:
            return
        self.lam = self._quantize(max(0.0, float(lam)))
        self.measurement = None
        if self.n_vertices >= self.min_vertices:
            try:
                self.measurement = self._measure(self.center, self.radius, self.lam)
            except GoniometerError as error:
                self.message = str(error)
            else:
                self.message = ""

    def release(self) -> DragRecord | None:
        """The mouse button went up: measure and return the record, or None (and say why)."""
        if self.phase is not Phase.DRAGGING:
            return None
        if self.n_vertices < self.min_vertices:
            self.message = too_few_message(self.n_vertices) + " Nothing was recorded."
            self._back_to_idle()
            return None
        try:
            measurement = self._measure_release(self.center, self.radius, self.lam)
        except GoniometerError as error:
            self.message = f"{error} Nothing was recorded."
            self._back_to_idle()
            return None
        self.measurement = measurement
        self.record = DragRecord(self.center.copy(), self.radius, self.lam, measurement)
        self.phase = Phase.MEASURED
        self.message = ""
        return self.record

    def cancel(self, reason: str = "Cancelled: nothing was recorded.") -> None:
        """Esc, right-click, leaving the view, or the object going away: end without a record."""
        if self.finished:
            return
        self.phase = Phase.CANCELLED
        self.indices = np.empty(0, dtype=np.int64)
        self.measurement = None
        self.message = reason

    # -- internals --------------------------------------------------------------------------

    def _apply_typed(self) -> None:
        try:
            value = self._parse(self.typed)
        except (ValueError, GoniometerError):
            value = 0.0
        self._set_radius(self._quantize(value))

    def _set_radius(self, radius: float) -> None:
        self.radius = float(radius)
        self.measurement = None
        # Below the smallest radius the core accepts a patch holds at most its centre vertex.
        if not np.isfinite(self.radius) or self.radius < MIN_RADIUS:
            self.indices = np.empty(0, dtype=np.int64)
        else:
            try:
                self.indices = np.asarray(self._query(self.center, self.radius), dtype=np.int64)
            except GoniometerError as error:
                self.indices = np.empty(0, dtype=np.int64)
                self.message = str(error)
                return
        self.message = (
            "" if self.n_vertices >= self.min_vertices else too_few_message(self.n_vertices)
        )

    def _back_to_idle(self) -> None:
        self.phase = Phase.IDLE
        self.center = None
        self.radius = self.mouse_radius = 0.0
        self.typed = ""
        self.indices = np.empty(0, dtype=np.int64)
        self.measurement = None


def surface_callbacks(
    surface, patch: str = "euclidean", rule: str = DEFAULT_RULE, stability: bool = False
) -> dict:
    """The ``snap``, ``query``, ``measure`` and ``measure_release`` callables of a
    :class:`DragMachine` on a Surface.

    ``snap`` moves a point to its nearest measurable vertex (however far), ``query`` returns the
    patch ``surface.measure`` would use, and ``measure`` is ``surface.measure`` itself; so is
    ``measure_release``, with the stability figure when ``stability`` is asked for (the
    previews go without it: it costs about ten measurements).

    Parameters
    ----------
    surface : Surface
    patch : {"euclidean", "geodesic"}, optional
    rule : {"refined", "oriented", "paper"}, optional
        The rule the measurement (and so the preview) uses.
    stability : bool, optional
        Whether the release's measurement (the one recorded) has the stability figure.
    """

    def snap(point):
        vertex, _ = surface.index.nearest(np.asarray(point, dtype=np.float64), np.inf)
        if vertex < 0:
            raise GoniometerError("The surface has no vertex to measure at.")
        return surface.points[vertex]

    def query(center, radius):
        vertex, _ = surface.snap(center, radius)
        return surface.patch(vertex, radius, patch)

    def measure(center, radius, lam):
        return surface.measure(center, radius, lam, patch, rule=rule)

    def measure_release(center, radius, lam):
        return surface.measure(center, radius, lam, patch, rule=rule, stability=stability)

    return {"snap": snap, "query": query, "measure": measure, "measure_release": measure_release}
