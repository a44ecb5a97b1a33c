"""The edge summary CSV: one row per measured edge profile, written beside an export.

Its stations are rows of the measurement CSV (``measurements``) with the same ``Edge #``; this
file holds what they say together (:class:`EdgeRow`), in the package's dialect (``text``).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path

from ...errors import GoniometerError
from ...method.algorithm import RULES
from ..files import replace_atomically
from .text import (
    MESH_COORDINATES,
    csv_line,
    header_of,
    load,
    normalise,
    parse_table,
    read_records,
    row_cells,
)

# The edge summary file: one row per measured edge profile (see EdgeRow); (field, kind, columns)
# as in text.row_cells.
EDGE_SCHEMA = (
    ("mesh_name", "text", ("Mesh Name",)),
    ("date", "text", ("Date",)),
    ("edge_number", "int", ("Edge #",)),
    ("break_number", "int", ("Break #",)),
    ("colors", "text", ("Colors",)),
    ("user_data", "text", ("User Data",)),
    ("n_stations", "int", ("Stations",)),
    ("spacing", "float", ("Spacing",)),
    ("radius", "float", ("Radius",)),
    ("lam", "float", ("SegParam",)),
    ("patch", "text", ("Patch Mode",)),
    ("rule", "text", ("Rule",)),
    ("length", "float", ("Length",)),
    ("mean", "float", ("Mean Angle",)),
    ("std", "float", ("SD Angle",)),
    ("min", "float", ("Min Angle",)),
    ("max", "float", ("Max Angle",)),
    ("pooled_angle", "float", ("Pooled Angle",)),
    ("pooled_fit", "float", ("Pooled Fit",)),
    ("median", "float", ("Median Angle",)),
    ("range", "float", ("Angle Range",)),
    ("arc_length", "float", ("Arc Length",)),
    ("chord_length", "float", ("Chord Length",)),
    ("arc_angle", "float", ("Arc Angle",)),
    ("points", "text", ("Points",)),
    ("flat_spans", "text", ("Flat Spans",)),
    ("units", "text", ("Units",)),
    ("coordinates", "space", ("Coordinates",)),
    ("stale", "flag", ("Stale",)),
    ("extension_version", "text", ("Extension Version",)),
    ("blender_version", "text", ("Blender Version",)),
    ("error", "text", ("error",)),
)


#: Every column of an edge summary file.
EDGE_COLUMNS = tuple(column for _, _, columns in EDGE_SCHEMA for column in columns)


#: The break-agent study's per-break figures (``vg_addon.method.break_figures``).
STUDY_COLUMNS = ("Median Angle", "Angle Range", "Arc Length", "Chord Length", "Arc Angle")

#: Columns added to the edge summary file after its first version: files without them read,
#: their cells blank.
LATER_EDGE_COLUMNS = ("Coordinates", "Rule", "Stale", *STUDY_COLUMNS)


@dataclass
class EdgeRow:
    """One row of an edge summary file: what the stations of one edge profile say together.

    Attributes
    ----------
    mesh_name, date, colors, user_data, units, extension_version, blender_version, error : str
        As in :class:`MeasurementRow`.
    edge_number, break_number : int or None
        The edge (its stations carry the same ``Edge #``) and its break.
    n_stations : int or None
    spacing, radius, lam : float or None
        The settings every station was measured with; ``patch`` the patch mode.
    rule : str
        The rule every station was measured with (``vg_addon.method.algorithm.RULES``); a
        replay measures with it. Empty in files of earlier versions (a replay then uses the
        run's ``--rule`` or the panel's Rule).
    length : float or None
        Arc length of the traced path.
    mean, std, min, max : float or None
        Of the stations' angles (degrees); ``std`` is the sample standard deviation.
    pooled_angle, pooled_fit : float or None
        One plane pair fitted to all stations' sides (the whole-edge angle), and its fit error.
    median, range : float or None
        The stations' median angle and range (max − min), degrees.
    arc_length, chord_length : float or None
        Length of the polyline through the station centres, and from the first to the last.
    arc_angle : float or None
        Angle (degrees, 0 to 90) between the edge's principal axis and the fragment's; blank
        where undefined (fewer than two stations, a ring). None for all five in files and
        records of earlier versions.
    points : str
        The clicked points that define the path, ``"x y z; x y z; ..."`` (start, via, end).
    coordinates : str
        ``"mesh"``: the points, lengths and radius are in the mesh's own coordinates;
        ``"world"``: in Blender world space (files written before this column existed).
    flat_spans : str
        Arc-length intervals where the path crossed no ridge, ``"a-b; ..."``; empty if none.
    stale : bool or None
        Some of the edge's stations were measured on other geometry than the mesh has now (the
        mesh changed since); None (not known) in files written before the column.
    row_number : int or None
        The spreadsheet row it was read from (the header is row 1, blank lines count), for
        messages; None for a row not read from a file. Not written, not compared.
    """

    mesh_name: str = ""
    date: str = ""
    edge_number: int | None = None
    break_number: int | None = None
    colors: str = ""
    user_data: str = ""
    n_stations: int | None = None
    spacing: float | None = None
    radius: float | None = None
    lam: float | None = None
    patch: str = ""
    rule: str = ""
    length: float | None = None
    mean: float | None = None
    std: float | None = None
    min: float | None = None
    max: float | None = None
    pooled_angle: float | None = None
    pooled_fit: float | None = None
    median: float | None = None
    range: float | None = None
    arc_length: float | None = None
    chord_length: float | None = None
    arc_angle: float | None = None
    points: str = ""
    flat_spans: str = ""
    units: str = ""
    coordinates: str = MESH_COORDINATES
    stale: bool | None = False
    extension_version: str = ""
    blender_version: str = ""
    error: str = ""
    row_number: int | None = field(default=None, compare=False)


def format_points(points) -> str:
    """The ``Points`` cell of an edge row: ``"x y z; x y z"`` with every float in full."""
    return "; ".join(" ".join(repr(float(v)) for v in point) for point in points)


def parse_points(text: str) -> list[tuple[float, float, float]]:
    """The points of a ``Points`` cell (see :func:`format_points`)."""
    points = []
    for part in text.split(";"):
        values = part.split()
        if len(values) != 3:
            raise GoniometerError(f"A point of the edge must be three numbers x y z; got {part!r}.")
        try:
            point = tuple(float(v) for v in values)
        except ValueError:
            raise GoniometerError(f"A point of the edge is not three numbers: {part!r}.") from None
        if not all(math.isfinite(v) for v in point):
            raise GoniometerError(
                f"A point of the edge must be three finite numbers; got {part.strip()!r}."
            )
        points.append(point)
    return points


def format_edges_csv(rows: Iterable[EdgeRow]) -> str:
    """The text of an edge summary file: the :data:`EDGE_COLUMNS` header and one line per edge,
    written like :func:`format_measurements_csv`."""
    lines = [csv_line(EDGE_COLUMNS)]
    lines.extend(csv_line(row_cells(index, row, EDGE_SCHEMA)) for index, row in enumerate(rows))
    return "".join(lines)


def edges_path_for(path) -> Path:
    """Where the edge summary of the export ``path`` goes: ``name_edges.csv`` beside it."""
    path = Path(path)
    return path.with_name(f"{path.stem}_edges{path.suffix or '.csv'}")


def write_edges_csv(path, rows: Iterable[EdgeRow]) -> None:
    """Write an edge summary file to ``path``, atomically, like :func:`write_measurements_csv`."""
    replace_atomically(path, format_edges_csv(rows).encode("utf-8"))


def parse_edges_csv(text: str, source: str = "The CSV text") -> list[EdgeRow]:
    """Parse an edge summary file written by :func:`format_edges_csv` back into rows."""
    return parse_table(
        text,
        source,
        EDGE_SCHEMA,
        EdgeRow,
        LATER_EDGE_COLUMNS,
        "an edge summary file",
        check=_points_problem,
    )


def _points_problem(values) -> str | None:
    rule = values["rule"].strip().lower()
    if rule and rule not in RULES:
        return f"Rule: unknown rule {values['rule'].strip()!r} (use {' or '.join(RULES)})"
    if values["points"].strip():
        try:
            parse_points(values["points"])
        except GoniometerError as error:
            return f"Points: {error}"
    return None


def is_edges_csv(path_or_text) -> bool:
    """Whether a CSV file (or text) is an edge summary file: its header has ``Edge #``,
    ``Points`` and ``Spacing``."""
    text, source = load(path_or_text)
    _, header = header_of(read_records(text, source), source)
    names = {normalise(name) for name in header}
    return {"edge #", "points", "spacing"} <= names


def read_edges_csv(path_or_text) -> list[EdgeRow]:
    """Read an edge summary file (see :func:`parse_edges_csv`); arguments as for
    :func:`read_replication_csv`."""
    text, source = load(path_or_text)
    return parse_edges_csv(text, source)
