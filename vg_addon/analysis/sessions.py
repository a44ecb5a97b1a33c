"""Measurement CSVs read as sessions: one observer, one method, one repetition each.

A session is any CSV with a mesh, a break number and an angle per row: this extension's export,
a batch run's ``--out``, the MeshLab plugin's file, or a plain table of manual goniometer readings
(``Mesh, Break #, Angle``). The centre, radius and vertex count are used where the file has
them; centres and radii in Blender's world space (``Coordinates``, docs/CSV.md) are never compared
with ones in mesh coordinates. Every row that is left out, and every file, is named with the
reason; nothing is dropped without a line saying so.
"""

from __future__ import annotations

import math
import os
import re
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import GoniometerError, bounded_list
from ..formats import csvio
from ..formats.csvio.replication import default_coordinates

#: Column names the analysis reads (matched ignoring case, spaces and ``_``).
COLUMNS = {
    "mesh": ("Mesh Name", "Mesh", "Object", "Object Name", "MeshName", "Mesh File", "Specimen"),
    "break": ("Break #", "Break Number", "Break"),
    "angle": ("Angle", "Fracture Angle", "Angle (deg)"),
    "x": ("x", "Center x", "Centre x"),
    "y": ("y", "Center y", "Centre y"),
    "z": ("z", "Center z", "Centre z"),
    "radius": ("Radius", "Patch Radius"),
    "vertices": ("Number of Vertices", "Vertices", "N Vertices"),
    "method": ("Method",),
    "observer": ("Observer", "Analyst", "Rater"),
    "repetition": ("Repetition", "Rep"),
    "edge": ("Edge #", "Edge Number"),
    "error": ("error",),
    "date": ("Date",),
    "kind": ("Break Type", "Fracture Type", "Type"),
    "coordinates": ("Coordinates", "Coordinate Space"),
}
REQUIRED = ("mesh", "break", "angle")

#: Coordinates beyond this are no scan's (and two such centres' distance could overflow).
MAX_COORDINATE = 1e300

#: The largest vertex count a patch can have: Blender and MeshLab count vertices in 32-bit ints.
MAX_VERTICES = 2**31 - 1

#: Words of a file name that name a method, and the method they mean.
METHOD_WORDS = {
    "man": "manual",
    "manual": "manual",
    "contact": "manual",
    "goniometer": "manual",
    "drag": "drag",
    "click": "drag",
    "xyz": "xyz",
}
_OBSERVER_WORD = re.compile(
    r"(?<![0-9a-z])(?:observer|obs|rater|analyst)[- ]?[0-9a-z]+", re.IGNORECASE
)


@dataclass(frozen=True)
class Reading:
    """One row of a session.

    Attributes
    ----------
    mesh : str
        The mesh as rows of different sessions are matched: its name without a folder or mesh
        file extension (``bone_12.ply`` and ``bone_12`` are one mesh).
    break_number : int
        ``Break #``.
    angle : float
        Degrees.
    centre : tuple of 3 float, or None
        ``x, y, z`` where the file has them.
    radius, vertices : float or None
        ``Radius`` and ``Number of Vertices`` where the file has them.
    row : int
        The row number as a spreadsheet shows it (the header is row 1).
    date : str
        When it was measured, where the file says (tells two identical re-measurements apart
        from one file given twice).
    kind : str
        The break's type (``Break Type`` column, e.g. transverse, oblique, spiral), or empty.
    coordinates : str
        The space of ``centre`` and ``radius``: ``"mesh"`` (the mesh's own coordinates) or
        ``"world"`` (Blender world space), from the ``Coordinates`` cell; blank or absent,
        ``"mesh"`` (see ``space_assumed``).
    space_assumed : bool
        The cell is blank or absent in an export of this extension written before the column,
        whose coordinates are world space (the importer converts them with the object's
        transform). The report has no transform: it takes them as mesh coordinates, which they
        are for every batch run (its object is never transformed) and for an object never
        moved, rotated or scaled, and says so (:func:`assumed_spaces`).
    """

    mesh: str
    break_number: int
    angle: float
    centre: tuple[float, float, float] | None = None
    radius: float | None = None
    vertices: float | None = None
    row: int = 0
    date: str = ""
    kind: str = ""
    coordinates: str = csvio.MESH_COORDINATES
    space_assumed: bool = False


@dataclass
class Session:
    """One observer's repetition with one method.

    Attributes
    ----------
    name : str
        The file's name (with ``[method/observer/repetition]`` when one file held several).
    source : str
        The file's path.
    method, observer : str
    readings : list of Reading
    left_out : list of str
        One line per row not used, with its reason.
    rows : int
        Data rows in the file for this session (used and left out).
    """

    name: str
    source: str
    method: str
    observer: str
    readings: list[Reading] = field(default_factory=list)
    left_out: list[str] = field(default_factory=list)
    rows: int = 0


@dataclass
class Loaded:
    """What :func:`load_sessions` read: the sessions used, one line per file left out, and one
    per session kept that may be a copy of another."""

    sessions: list[Session] = field(default_factory=list)
    refused: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)  # sessions kept that a reader should check


def method_word(text: str) -> str | None:
    """The method a name or cell names (``"obs2_drag_3"`` -> ``"drag"``), or ``None``."""
    for word in re.split(r"[^0-9a-zA-Z]+", text.casefold()):
        if word in METHOD_WORDS:
            return METHOD_WORDS[word]
    return None


def observer_word(text: str) -> str | None:
    """The observer a file name names (``"obs2_drag_3"`` -> ``"obs2"``), or ``None``."""
    found = _OBSERVER_WORD.search(Path(text).stem)
    return found.group(0) if found else None


def _method_of(cell: str) -> str:
    text = cell.strip()
    return method_word(text) or text


def _number(cells, columns, key, row, problems, whole=False):
    """The cell's finite number, ``None`` when blank or absent; a bad cell is a problem."""
    index = columns.get(key)
    if index is None or index >= len(cells) or not cells[index].strip():
        return None
    value, why = csvio.number_cell(cells[index])
    if why:
        problems.append(f"{COLUMNS[key][0]} {why}")
        return None
    if whole and value != int(value):
        problems.append(f"{COLUMNS[key][0]} is not a whole number ({cells[index].strip()!r})")
    return value


def _cell(cells, columns, key) -> str:
    index = columns.get(key)
    return cells[index] if index is not None and index < len(cells) else ""


def _reading(number: int, cells, columns, blank_space: str) -> tuple[Reading | None, str]:
    """A row as a reading, or ``None`` and why it is left out; ``blank_space`` is the
    coordinate space of a blank or absent ``Coordinates`` cell."""
    error = _cell(cells, columns, "error").strip()
    if error:
        return None, f"row {number}: not measured in its run ({error})"
    mesh = csvio.mesh_stem(csvio.text_cell(_cell(cells, columns, "mesh")))
    if not mesh:
        return None, f"row {number}: no mesh name"
    break_number = csvio.break_number_cell(_cell(cells, columns, "break"))
    if break_number is None:
        return None, f"row {number}: no Break #"
    if isinstance(break_number, str):
        return None, f"row {number}: Break # {break_number}"
    problems: list[str] = []
    angle = _number(cells, columns, "angle", number, problems)
    if angle is None and not problems:
        problems.append("no Angle")
    elif angle is not None and not 0.0 <= angle <= 180.0:
        problems.append(f"Angle {angle:g} is not an angle between two faces (0° to 180°)")
    parts = [_number(cells, columns, axis, number, problems) for axis in "xyz"]
    if any(p is not None and abs(p) > MAX_COORDINATE for p in parts):
        problems.append(f"x, y, z beyond {MAX_COORDINATE:g} are not a scan's coordinates")
    if any(p is not None for p in parts) and any(p is None for p in parts):
        problems.append("x, y, z must be all filled or all empty")
    radius = _number(cells, columns, "radius", number, problems)
    if radius is not None and radius <= 0:
        problems.append(f"Radius must be more than 0 (got {radius:g})")
    vertices = _number(cells, columns, "vertices", number, problems, whole=True)
    if vertices is not None and not 0 <= vertices <= MAX_VERTICES:
        problems.append(f"Number of Vertices {vertices:g} is not a count of a patch's vertices")
    space = _cell(cells, columns, "coordinates").strip()
    if space and space.casefold() not in csvio.COORDINATE_SPACES:
        problems.append(
            f"Coordinates {space!r} is not {' or '.join(csvio.COORDINATE_SPACES)}, so its centre "
            "and radius cannot be compared"
        )
    if problems:
        return None, f"row {number}: " + "; ".join(problems)
    centre = None if None in parts else tuple(parts)
    date = _cell(cells, columns, "date").strip()
    kind = csvio.text_cell(_cell(cells, columns, "kind").strip())
    assumed = not space and blank_space == csvio.WORLD_COORDINATES
    space = space.casefold() or csvio.MESH_COORDINATES
    return (
        Reading(
            mesh, break_number, angle, centre, radius, vertices, number, date, kind, space, assumed
        ),
        "",
    )


def _read_file(path, method, observer) -> tuple[list[Session], str]:
    """The sessions of one file, or none and why it is left out."""
    name = Path(os.fspath(path)).name
    try:
        source, header, records = csvio.read_table(path)
    except (GoniometerError, OSError, ValueError) as error:
        return [], f"'{name}': left out, it cannot be read: {error}"
    columns, problems = csvio.header_columns(header, COLUMNS)
    missing = [COLUMNS[key][0] for key in REQUIRED if key not in columns]
    if missing:
        found = ", ".join(h.strip() for h in header if h.strip()) or "none"
        return [], (
            f"{source}: left out, it has no {' or '.join(missing)} column (its columns: {found}); "
            "a session needs a mesh name, a Break # and an Angle per row"
        )
    if problems:
        return [], f"{source}: left out: {'; '.join(problems)}"
    if not records:
        return [], f"{source}: left out, it has a header but no rows"
    blank_space = default_coordinates(header)
    by_key: dict[tuple[str, str, str], Session] = {}
    for number, cells in records:
        row_method = method or _method_of(_cell(cells, columns, "method")) or method_word(name)
        row_observer = (
            observer
            or _cell(cells, columns, "observer").strip()
            or observer_word(name)
            or "observer 1"
        )
        repetition = _cell(cells, columns, "repetition").strip()
        key = (row_method or "", row_observer, repetition)
        session = by_key.get(key)
        if session is None:
            session = by_key[key] = Session(name, os.fspath(path), row_method or "", row_observer)
        session.rows += 1
        reading, why = _reading(number, cells, columns, blank_space)
        if reading is None:
            session.left_out.append(why)
        else:
            session.readings.append(reading)
    sessions = list(by_key.values())
    if len(sessions) > 1:
        for (m, o, r), session in by_key.items():
            session.name = f"{name} [{'/'.join(part for part in (m, o, r) if part)}]"
    kept = []
    refused = []
    for session in sessions:
        if not session.method:
            refused.append(
                f"{session.name}: left out, its method is unknown ({session.rows} rows): add a "
                "Method column, put manual, drag or xyz in the file name, or give --method"
            )
        else:
            kept.append(session)
    return kept, "\n".join(refused)


def _fingerprint(session: Session) -> tuple:
    readings = tuple(
        (r.mesh, r.break_number, r.angle, r.centre, r.radius, r.vertices, r.date)
        for r in session.readings
    )
    # Not the observer: a copy of a file under another observer's name is still one session.
    return (session.method, readings)


def _identifies(session: Session) -> bool:
    """Whether equal readings make two sessions one given twice: only with a date or a centre.
    A manual table's same angles twice can be chance (whole-degree readings of a few breaks)."""
    return any(r.date or r.centre is not None for r in session.readings)


def spaces_apart(sessions: list[Session]) -> list[str]:
    """One line per mesh whose sessions hold centres or radii in more than one coordinate
    space, naming each session and its rows in each space; empty when there is none."""
    by_mesh: dict[str, dict[str, Counter]] = {}
    for session in sessions:
        for r in session.readings:
            if r.centre is not None or r.radius is not None:
                named = by_mesh.setdefault(r.mesh, {})
                named.setdefault(session.name, Counter())[r.coordinates] += 1
    lines = []
    for mesh, named in by_mesh.items():
        if len({space for counts in named.values() for space in counts}) > 1:
            parts = [
                f"{name} has "
                + " and ".join(
                    f"{n} row{'s' if n > 1 else ''} in {space}"
                    for space, n in sorted(counts.items())
                )
                + " coordinates"
                for name, counts in named.items()
            ]
            lines.append(f"{mesh}: " + "; ".join(parts))
    return lines


def assumed_spaces(sessions: list[Session]) -> list[str]:
    """One note per session whose centres or radii are taken as mesh coordinates though its
    file does not say so (:attr:`Reading.space_assumed`)."""
    notes = []
    for session in sessions:
        count = sum(
            r.space_assumed and (r.centre is not None or r.radius is not None)
            for r in session.readings
        )
        if count:
            notes.append(
                f"{session.name}: written before the Coordinates column, so its {count} centre(s) "
                "and radii are in Blender's world space; they are compared as mesh coordinates, "
                "which they are for a batch run and for an object never moved, rotated or scaled. "
                "If the object was, its centre and radius IOVs and the stations matched by centre "
                "are wrong here: export it again with the current version (opening its .blend "
                "converts the measurements)"
            )
    return notes


def load_sessions(paths, methods=None, observers=None) -> Loaded:
    """Read each CSV as one session (or several, where its Method, Observer or Repetition
    columns hold several values).

    Parameters
    ----------
    paths : sequence of path-like
    methods, observers : sequence of str, optional
        One for every file, or one for all of them; over the file's own columns and name.

    Returns
    -------
    Loaded
        The sessions, and one line per file or session left out: unreadable, without the
        needed columns, of unknown method, or the same session as an earlier file.

    Raises
    ------
    GoniometerError
        ``--method`` or ``--observer`` given neither once nor once per file; or sessions whose
        centres or radii on one mesh are in different coordinate spaces (world and mesh, see
        :attr:`Reading.coordinates`): without the object's transform neither can be converted,
        and comparing them would give wrong centre and radius IOVs and match stations, and so
        angles, wrongly (:func:`spaces_apart` names them).
    """
    paths = list(paths)
    per_file = []
    for label, given in (("--method", methods), ("--observer", observers)):
        given = list(given or [])
        if len(given) not in (0, 1, len(paths)):
            raise GoniometerError(
                f"give {label} once for all files or once per file ({len(paths)}), not "
                f"{len(given)} times"
            )
        per_file.append(given * len(paths) if len(given) == 1 else given or [None] * len(paths))
    loaded = Loaded()
    seen_paths: dict[tuple, str] = {}
    seen: dict[tuple, str] = {}
    for path, method, observer in zip(paths, *per_file, strict=True):
        # The same file may be given again as another method (the paper's xyz series starts
        # with the first drag reading); as the same method it is the same session twice.
        resolved = (os.path.realpath(os.fspath(path)), method, observer)
        if resolved in seen_paths:
            loaded.refused.append(f"'{Path(path).name}': left out, it was given twice")
            continue
        seen_paths[resolved] = os.fspath(path)
        sessions, refused = _read_file(path, method and _method_of(method), observer)
        if refused:
            loaded.refused.append(refused)
        for session in sessions:
            fingerprint = _fingerprint(session)
            if session.readings and fingerprint in seen and not _identifies(session):
                loaded.notes.append(
                    f"{session.name}: kept, though its readings are those of "
                    f"{seen[fingerprint]}: without dates or centres a repetition that read the "
                    "same cannot be told from a copy; leave the file out if it is one"
                )
            elif session.readings and fingerprint in seen:
                loaded.refused.append(
                    f"{session.name}: left out, its rows (numbers and dates) are those of "
                    f"{seen[fingerprint]}: the same session given twice"
                )
                continue
            seen.setdefault(fingerprint, session.name)
            loaded.sessions.append(session)
    loaded.notes.extend(assumed_spaces(loaded.sessions))
    apart = spaces_apart(loaded.sessions)
    if apart:
        raise GoniometerError(
            "these sessions hold centres and radii in different coordinate spaces (Blender's "
            "world space and the mesh's own), which cannot be compared: their centre and radius "
            "IOVs would mix the two, and stations matched by centre would pair the wrong angles; "
            "no report is made:\n"
            + bounded_list(apart, lines=True)
            + "\nWorld rows come from exports of versions before the Coordinates column (or say "
            "world in it), and converting them needs the object's transform, which a CSV does "
            "not hold. Export those measurements again with the current version (opening their "
            ".blend in it converts them to mesh coordinates) or measure again; or, if the object "
            "had no location, rotation or scale when they were measured (world coordinates are "
            "then mesh coordinates), set their Coordinates cells to mesh."
        )
    return loaded


def distance(a, b) -> float:
    """Euclidean distance between two centres, summed in a fixed order."""
    differences = [p - q for p, q in zip(a, b, strict=True)]
    try:
        total = math.fsum(d * d for d in differences)
    except OverflowError:  # finite squares whose sum is not
        total = math.inf
    if math.isinf(total):  # centres beyond 1e154 apart: their squares overflow, not the distance
        return math.hypot(*differences)
    return math.sqrt(total)
