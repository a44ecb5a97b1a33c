"""Incremental painting of the "VG Sides" attribute.

Per object, the colours last written and, per vertex, which painted measurement owns it (the
latest one covering it). A new measurement paints its own patch only; a deleted one repaints
only the vertices it owned, from the earlier measurements that overlap it; anything else (a
stale change, another geometry, a file just loaded) repaints everything from the records. The
sides of each measurement are kept, keyed by the geometry and the measurement's exact numbers,
so a full repaint measures only what it has never seen (once per file load).
"""

from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass, field

import numpy as np

from ..vg_addon import palette

# Patch vertices whose sides are kept, in all (5 bytes each): bounds the memory, not the count.
_KEPT_VERTICES = 20_000_000
# Beyond this many removed or inserted measurements, painting everything again is cheaper.
_MAX_CHANGES = 8


@dataclass(frozen=True)
class Sides:
    """One measurement's sides on the vertices of the object's own mesh.

    Attributes
    ----------
    vertices : ndarray of int32
        The mesh vertices it paints.
    plus : ndarray of bool
        ``True`` where the vertex is on the "+" side.
    break_number : int
        Picks the colour pair.
    center : ndarray of float64, shape (3,)
    reach : float
        Every painted vertex lies within ``reach`` of ``center`` (world space).
    """

    vertices: np.ndarray
    plus: np.ndarray
    break_number: int
    center: np.ndarray
    reach: float


_kept: OrderedDict[tuple, Sides] = OrderedDict()
_kept_vertices = 0


def kept_sides(key: tuple) -> Sides | None:
    """The sides kept under ``key`` (see :func:`keep`), or None."""
    sides = _kept.get(key)
    if sides is not None:
        _kept.move_to_end(key)
    return sides


def keep(key: tuple, sides: Sides) -> None:
    """Keep ``sides`` under ``key``; the least recently used go beyond the memory bound."""
    global _kept_vertices
    if key in _kept:
        return
    _kept[key] = sides
    _kept_vertices += sides.vertices.size
    while len(_kept) > 1 and _kept_vertices > _KEPT_VERTICES:
        _kept_vertices -= _kept.popitem(last=False)[1].vertices.size


@dataclass
class PaintState:
    """What was last painted on one object's mesh."""

    fingerprint: str
    colours: np.ndarray  # float32 (n, 4)
    owner: np.ndarray  # int32 (n,): 1 + position in ``painted`` of the owning entry, 0 for none
    painted: list = field(default_factory=list)  # keys, in painting order
    sides: list = field(default_factory=list)  # their Sides, aligned with ``painted``
    # The records as last painted: signature -> (key, Sides), or (None, None) for a stale one;
    # trusted in the generation it was made in (see ``generation``), and in later ones for
    # records with a content id.
    known: dict = field(default_factory=dict)
    generation: int = -1
    # The records' signatures as last painted (one row each) and the stale numbers.
    rows: np.ndarray = field(default_factory=lambda: np.zeros((0, 7), dtype=np.int32))
    stale: list = field(default_factory=list)

    @classmethod
    def blank(cls, fingerprint: str, n: int) -> PaintState:
        colours = np.empty((n, 4), dtype=np.float32)
        colours[:] = palette.neutral_linear()
        return cls(fingerprint, colours, np.zeros(n, dtype=np.int32))

    def add(self, key: tuple, sides: Sides) -> None:
        """Paint ``sides`` over everything painted so far."""
        self.painted.append(key)
        self.sides.append(sides)
        self._paint(sides, sides.vertices, sides.plus, len(self.painted))

    def _paint(self, sides: Sides, vertices, plus, owner: int) -> None:
        colour_plus, colour_minus = palette.pair_linear(sides.break_number)
        self.colours[vertices[plus]] = colour_plus
        self.colours[vertices[~plus]] = colour_minus
        self.owner[vertices] = owner

    def remove(self, position: int) -> None:
        """Unpaint the entry at ``position``: its vertices take the colour of the latest earlier
        entry covering them, or grey."""
        gone = self.sides[position]
        owned = gone.vertices[self.owner[gone.vertices] == position + 1]
        self.owner[owned] = -1  # to be resolved
        if owned.size and position:
            earlier_sides = self.sides[:position]
            centers = np.array([sides.center for sides in earlier_sides])
            reaches = np.array([sides.reach for sides in earlier_sides])
            # Only measurements close enough to share a vertex with the removed one.
            near = np.linalg.norm(centers - gone.center, axis=1) <= reaches + gone.reach
            candidates = np.flatnonzero(near)[::-1]
        else:
            candidates = ()
        for earlier in candidates:
            if not owned.size:
                break
            sides = self.sides[earlier]
            take = self.owner[sides.vertices] == -1
            if take.any():
                self._paint(sides, sides.vertices[take], sides.plus[take], earlier + 1)
                owned = owned[self.owner[owned] == -1]
        if owned.size:
            self.colours[owned] = palette.neutral_linear()
            self.owner[owned] = 0
        del self.painted[position]
        del self.sides[position]
        later = self.owner > position + 1
        self.owner[later] -= 1

    def insert(self, position: int, key: tuple, sides: Sides) -> None:
        """Paint ``sides`` as the entry at ``position``: over the entries before it, under the
        ones after it (e.g. a deleted measurement brought back by undo)."""
        self.owner[self.owner > position] += 1  # the later entries move up one place
        self.painted.insert(position, key)
        self.sides.insert(position, sides)
        free = self.owner[sides.vertices] <= position  # earlier entries' or nobody's
        self._paint(sides, sides.vertices[free], sides.plus[free], position + 1)

    def update_to(self, keys: list, sides_of) -> bool:
        """Bring the painting to ``keys`` (in painting order) by removing, inserting and adding
        entries; False (nothing changed) if only a full repaint can, i.e. an entry kept would
        have to move, or there are many to remove or insert. ``sides_of(key)`` gives the Sides
        of a key to add."""
        if keys[: len(self.painted)] == self.painted:  # only additions (the usual click)
            for key in keys[len(self.painted) :]:
                self.add(key, sides_of(key))
            return True
        wanted = set(keys)
        kept = [key for key in self.painted if key in wanted]
        present = set(kept)
        missing = [position for position, key in enumerate(keys) if key not in present]
        last_kept = max((p for p, key in enumerate(keys) if key in present), default=-1)
        inserts = sum(position < last_kept for position in missing)  # the others are added
        changes = len(self.painted) - len(kept) + inserts
        if [key for key in keys if key in present] != kept or changes > _MAX_CHANGES:
            return False
        for position in range(len(self.painted) - 1, -1, -1):
            if self.painted[position] not in wanted:
                self.remove(position)
        for position in missing:  # in increasing order: each lands at its place in ``keys``
            if position == len(self.painted):
                self.add(keys[position], sides_of(keys[position]))
            else:
                self.insert(position, keys[position], sides_of(keys[position]))
        return True


_states: dict[int, PaintState] = {}
_generation = 0


def generation() -> int:
    """Changes whenever records may have changed behind this module's back (undo, redo)."""
    return _generation


def new_generation() -> None:
    global _generation
    _generation += 1


def state_for(obj) -> PaintState | None:
    return _states.get(obj.session_uid)


def set_state(obj, state: PaintState) -> None:
    _states[obj.session_uid] = state


def forget() -> None:
    """Forget every paint state and kept sides (file load, unregister)."""
    global _kept_vertices
    _states.clear()
    _kept.clear()
    _kept_vertices = 0
