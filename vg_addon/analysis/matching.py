"""Rows of different sessions matched as measurements of the same place on a break.

Rows are matched by mesh and break number. Where a break holds one row in every session, that is
the match, as in the paper (every measurement of a break taken at its centre). Where some
session holds several rows (stations) on one break, each row is matched to a station of the
*anchor* session (the one with most rows on that break, the first given on a tie) by nearest
centre: the two must lie within the patch radius of each other, each must be the other's
nearest, and no other station may be as near. Anything else is reported as ambiguous and left
out, never guessed.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from .sessions import Reading, Session, distance


@dataclass
class Unit:
    """One place on a break, as measured by the sessions that matched there.

    Attributes
    ----------
    mesh : str
    break_number : int
    station : int
        1 where the break holds one place; else the anchor row's order on the break.
    readings : dict of int to Reading
        Session index (in the sessions given) -> its reading here.
    several : bool
        The break holds several stations.
    """

    mesh: str
    break_number: int
    station: int = 1
    readings: dict[int, Reading] = field(default_factory=dict)
    several: bool = False

    @property
    def label(self) -> str:
        """``"bone_12 break 3"``, with ``" station 2"`` where the break holds several."""
        text = f"{self.mesh} break {self.break_number}"
        return f"{text} station {self.station}" if self.several else text


@dataclass
class Matched:
    """The units, and one line per reading that could not be matched."""

    units: list[Unit] = field(default_factory=list)
    unmatched: list[str] = field(default_factory=list)


def _where(session: Session, reading: Reading) -> str:
    return f"{session.name} row {reading.row}"


def _reach(a: Reading, b: Reading) -> float | None:
    radii = [r for r in (a.radius, b.radius) if r is not None]
    return max(radii) if radii else None


def _match_stations(mesh, number, by_session, sessions, matched: Matched) -> None:
    """Several rows on one break: each matched to an anchor station by nearest centre."""
    anchor_index = max(by_session, key=lambda s: (len(by_session[s]), -s))
    anchors = by_session[anchor_index]
    anchor_session = sessions[anchor_index]
    place = f"{mesh} break {number}"
    if any(a.centre is None for a in anchors):
        for s, readings in by_session.items():
            for r in readings:
                matched.unmatched.append(
                    f"{_where(sessions[s], r)}: {place} holds {len(anchors)} rows in "
                    f"{anchor_session.name} without centres, so which of them this is cannot be "
                    "told; left out"
                )
        return
    units = [
        Unit(mesh, number, k, {anchor_index: a}, several=True) for k, a in enumerate(anchors, 1)
    ]
    for s, readings in by_session.items():
        if s == anchor_index:
            continue
        session = sessions[s]
        for r in readings:
            if r.centre is None:
                matched.unmatched.append(
                    f"{_where(session, r)}: {place} has {len(anchors)} stations in "
                    f"{anchor_session.name}; this row has no centre to tell which; left out"
                )
                continue
            near = sorted(
                (distance(r.centre, a.centre), k) for k, a in enumerate(anchors) if a.centre
            )
            d, k = near[0]
            reach = _reach(r, anchors[k])
            others = [
                distance(o.centre, anchors[k].centre) for o in readings if o is not r and o.centre
            ]
            if reach is None:
                why = "neither row has a radius to match stations within"
            elif d > reach:
                why = (
                    f"no station of {anchor_session.name} within its radius ({d:.4g} > {reach:.4g})"
                )
            elif len(near) > 1 and near[1][0] == d:
                why = (
                    f"as near to rows {anchors[k].row} and {anchors[near[1][1]].row} of "
                    f"{anchor_session.name} ({d:.4g})"
                )
            elif any(o <= d for o in others):
                why = (
                    f"another row of this session is as near to row {anchors[k].row} of "
                    f"{anchor_session.name}"
                )
            else:
                units[k].readings[s] = r
                continue
            matched.unmatched.append(f"{_where(session, r)}: {place}: ambiguous, {why}; left out")
    matched.units.extend(units)


def match_sessions(sessions: list[Session]) -> Matched:
    """Group the sessions' readings into units (one per place on a break).

    Parameters
    ----------
    sessions : list of Session

    Returns
    -------
    Matched
        Units in order of mesh, break and station; the readings that could not be matched,
        each with its session, row and reason.
    """
    groups: dict[tuple[str, int], dict[int, list[Reading]]] = {}
    for s, session in enumerate(sessions):
        for r in session.readings:
            groups.setdefault((r.mesh, r.break_number), {}).setdefault(s, []).append(r)
    matched = Matched()
    for (mesh, number), by_session in sorted(groups.items()):
        if all(len(readings) == 1 for readings in by_session.values()):
            matched.units.append(Unit(mesh, number, 1, {s: rs[0] for s, rs in by_session.items()}))
        else:
            _match_stations(mesh, number, by_session, sessions, matched)
    return matched
