"""MeshLab picked-points files (``.pp``): points picked on a mesh, read as an edge's endpoints.

MeshLab's PickPoints editor saves the points it picked as a small XML file::

    <!DOCTYPE PickedPoints>
    <PickedPoints>
     <DocumentData>
      <DateTime time="16:00:00" date="2021-03-04"/>
      <DataFileName name="bone_12.ply"/>
     </DocumentData>
     <point x="12.1" y="3.4" z="-7.9" name="0" active="1"/>
     <point x="30.5" y="2.2" z="-9.0" name="1" active="1"/>
    </PickedPoints>

The break-agent study kept each break's endpoints this way. Read as an edge, a file's active
points in file order are its start, via points and end (:func:`edge_points`). A file is matched
to the mesh it was picked on by its file name (:func:`mesh_for_file`): ``NAME.pp`` or
``NAME_anything.pp`` belongs to the mesh ``NAME`` (``bone_12.ply``, ``bone_12_break3.pp``).

The reader is strict: a file that is not this XML, a ``point`` without three finite numbers, an
``active`` that is not 0 or 1, or a document that declares entities is refused with one
:class:`GoniometerError` naming the file and the line of every problem; never part of a file.
Points with ``active="0"`` (a template's points not picked yet) are kept in the result but are
not an edge's points.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path
from xml.parsers import expat

import numpy as np

from ..errors import GoniometerError, bounded_list

SUFFIX = ".pp"
"""The file extension MeshLab gives picked-points files."""

MAX_BYTES = 64 * 1024 * 1024
"""The largest file read: a million points fit; a larger file is not a list of picked points."""

ROOT = "PickedPoints"
DOCUMENT = "DocumentData"
POINT = "point"

_NUMBER = re.compile(r"\s*[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?\s*")
_ACTIVE = {"1": True, "0": False, "true": True, "false": False}


@dataclass(frozen=True)
class PickedPoint:
    """One ``<point>`` of a picked-points file.

    Attributes
    ----------
    name : str
        Its ``name`` attribute ("" when it has none).
    xyz : tuple of float
        Its coordinates, in the mesh's units and frame.
    active : bool
        False for ``active="0"``: a point MeshLab lists but that was not picked.
    line : int
        The line of the file it is on (for messages).
    """

    name: str
    xyz: tuple[float, float, float]
    active: bool
    line: int


@dataclass(frozen=True)
class PickedPoints:
    """The contents of one picked-points file.

    Attributes
    ----------
    source : str
        How messages name the file (its path, quoted).
    points : tuple of PickedPoint
        Every ``<point>``, in file order.
    data_file : str
        The ``DataFileName`` the file names ("" when it has none): the mesh MeshLab had open.
    """

    source: str
    points: tuple[PickedPoint, ...]
    data_file: str = ""

    @property
    def active(self) -> tuple[PickedPoint, ...]:
        """The points that were picked (``active`` not 0), in file order."""
        return tuple(point for point in self.points if point.active)


class _Collector:
    """Expat handlers that collect the elements of a picked-points file with their lines."""

    def __init__(self, parser, source: str):
        self.parser = parser
        self.source = source
        self.stack: list[str] = []
        self.problems: list[str] = []
        self.points: list[PickedPoint] = []
        self.data_file = ""
        self.documents = 0
        self.root_seen = False

    def doctype(self, name, system_id, public_id, has_internal_subset):
        if has_internal_subset:
            raise GoniometerError(
                f"{self.source} declares its own document type (entities, attributes): a MeshLab "
                "picked-points file has only <!DOCTYPE PickedPoints>, so it is not read."
            )

    def entity(self, *args):
        raise GoniometerError(
            f"{self.source} declares an XML entity: a MeshLab picked-points file has none, so it "
            "is not read."
        )

    def start(self, tag: str, attributes: dict) -> None:
        line = self.parser.CurrentLineNumber
        depth = len(self.stack)
        self.stack.append(tag)
        if depth == 0:
            self.root_seen = True
            if tag != ROOT:
                raise GoniometerError(
                    f"{self.source} is not a MeshLab picked-points file: its root element is "
                    f"<{tag}>, not <{ROOT}>."
                )
            return
        if depth == 1:
            if tag == POINT:
                self._point(attributes, line)
            elif tag == DOCUMENT:
                self.documents += 1
                if self.documents > 1:
                    self.problems.append(f"line {line}: a second <{DOCUMENT}>")
            else:
                self.problems.append(
                    f"line {line}: <{tag}> (only <{DOCUMENT}> and <{POINT}> belong in <{ROOT}>)"
                )
            return
        if tag == POINT:
            self.problems.append(f"line {line}: a <{POINT}> inside <{self.stack[-2]}>")
        elif self.stack[1] == DOCUMENT and depth == 2 and tag == "DataFileName":
            self.data_file = attributes.get("name", "")

    def end(self, tag: str) -> None:
        self.stack.pop()

    def _point(self, attributes: dict, line: int) -> None:
        values, bad = [], []
        for axis in ("x", "y", "z"):
            raw = attributes.get(axis)
            if raw is None:
                bad.append(f"no {axis}")
            elif not _NUMBER.fullmatch(raw):
                bad.append(f"{axis}={raw!r} is not a number")
            else:
                value = float(raw)
                if not np.isfinite(value):
                    bad.append(f"{axis}={raw!r} is not a finite number")
                values.append(value)
        raw_active = attributes.get("active", "1")
        active = _ACTIVE.get(raw_active.strip().lower())
        if active is None:
            bad.append(f"active={raw_active!r} is not 1 or 0")
        if bad:
            self.problems.append(f"line {line}: <{POINT}> " + ", ".join(bad))
            return
        self.points.append(PickedPoint(attributes.get("name", ""), tuple(values), active, line))


def parse_picked_points(data: bytes | str, source: str = "The picked-points text") -> PickedPoints:
    """Parse the contents of a MeshLab picked-points file.

    Parameters
    ----------
    data : bytes or str
        The file's contents (bytes are decoded as the XML declaration says, UTF-8 by default).
    source : str, optional
        How messages name the file.

    Returns
    -------
    PickedPoints

    Raises
    ------
    GoniometerError
        Not well-formed XML (with the line and column expat names), a root other than
        ``<PickedPoints>``, an entity or internal DTD, or any ``<point>`` without three finite
        numbers or with an ``active`` other than 0 or 1: every problem is listed with its line.
    """
    parser = expat.ParserCreate()
    collector = _Collector(parser, source)
    parser.StartDoctypeDeclHandler = collector.doctype
    parser.EntityDeclHandler = collector.entity
    parser.StartElementHandler = collector.start
    parser.EndElementHandler = collector.end
    try:
        parser.Parse(data, True)
    except expat.ExpatError as error:
        raise GoniometerError(
            f"{source} is not a readable picked-points file: its XML is malformed at line "
            f"{error.lineno}, column {error.offset + 1} ({expat.ErrorString(error.code)}). "
            "Save it again from MeshLab's PickPoints tool."
        ) from None
    if collector.problems:
        raise GoniometerError(
            f"{source} has {len(collector.problems)} problem(s); nothing was read:\n"
            + bounded_list(collector.problems, lines=True)
        )
    return PickedPoints(source, tuple(collector.points), collector.data_file)


def read_picked_points(path: str | os.PathLike) -> PickedPoints:
    """Read a MeshLab picked-points file (see :func:`parse_picked_points`).

    Raises
    ------
    GoniometerError
        A missing, unreadable or too large file (over :data:`MAX_BYTES`), or one the parser
        refuses.
    """
    path = Path(path)
    source = f"'{path}'"
    try:
        size = path.stat().st_size
        if size > MAX_BYTES:
            raise GoniometerError(
                f"{source} is {size:,} bytes: far more than a list of picked points (at most "
                f"{MAX_BYTES:,} are read). Is it the right file?"
            )
        data = path.read_bytes()
    except OSError as error:
        raise GoniometerError(f"{source} cannot be read: {error.strerror or error}.") from None
    return parse_picked_points(data, source)


def edge_points(picked: PickedPoints) -> np.ndarray:
    """The points of the edge a picked-points file defines: its active points in file order
    (start, via points, end), as float64.

    Raises
    ------
    GoniometerError
        Fewer than two active points (an edge needs a start and an end).
    """
    active = picked.active
    if len(active) < 2:
        inactive = len(picked.points) - len(active)
        note = f" ({inactive} more are not active)" if inactive else ""
        raise GoniometerError(
            f"{picked.source} has {len(active)} picked point(s){note}: an edge needs two or "
            "more, its start, any via points and its end, in order."
        )
    return np.array([point.xyz for point in active], dtype=np.float64)


def mesh_for_file(path: str | os.PathLike, mesh_names) -> str | None:
    """The mesh a picked-points file belongs to, by its file name: ``NAME.pp`` or
    ``NAME_anything.pp`` belongs to the mesh ``NAME``; where several names fit (meshes ``bone``
    and ``bone_12`` for ``bone_12_a.pp``) the longest wins. Case does not matter (``Bone_12.PP``
    belongs to ``bone_12``) unless two names of that length differ only in case: then the one
    spelt like the file wins, and if neither is, the file names no mesh (None, as when no name
    fits).

    Parameters
    ----------
    path : str or path-like
        The ``.pp`` file.
    mesh_names : iterable of str
        The names of the meshes to choose from (mesh files' stems).
    """
    stem = Path(path).name
    if stem.lower().endswith(SUFFIX):
        stem = stem[: -len(SUFFIX)]
    folded = stem.casefold()
    fits = {
        name
        for name in mesh_names
        if name and (folded == name.casefold() or folded.startswith(name.casefold() + "_"))
    }
    if not fits:
        return None
    longest = max(map(len, fits))
    best = [name for name in fits if len(name) == longest]
    if len(best) == 1:
        return best[0]
    exact = [name for name in best if stem == name or stem.startswith(name + "_")]
    return exact[0] if len(exact) == 1 else None


def files_in(folder: str | os.PathLike) -> list[Path]:
    """The picked-points files directly in ``folder``, sorted by name (subfolders are not
    searched).

    Raises
    ------
    GoniometerError
        A folder that cannot be listed.
    """
    folder = Path(folder)
    try:
        return sorted(
            (p for p in folder.iterdir() if p.suffix.lower() == SUFFIX and p.is_file()),
            key=lambda p: p.name,
        )
    except OSError as error:
        raise GoniometerError(
            f"'{folder}': cannot list the folder ({error.strerror or error})."
        ) from None
