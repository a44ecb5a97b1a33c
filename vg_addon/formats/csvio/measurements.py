"""The measurement CSV: the export's schema, its rows, and its writer and reader.

Every export starts with the 14 columns of the MeshLab Virtual Goniometer plugin, in its order
(:data:`MESHLAB_COLUMNS`), so analysis scripts written for MeshLab files keep working; this
extension's own columns follow (:data:`EXPORT_COLUMNS`). The earlier AMAAZE Blender add-on wrote
the same 14 columns.

Writing (:func:`write_measurements_csv`) is the package's dialect (``text``) and atomic: the old
file stays intact if anything fails. Reading an export back whole is
:func:`read_measurements_csv`; re-measuring the rows of any such file is ``replication``'s.
"""

from __future__ import annotations

import dataclasses
import operator
import re
from collections.abc import Iterable
from dataclasses import dataclass
from datetime import datetime

from ...errors import GoniometerError
from ...palette import OKABE_ITO
from ..files import replace_atomically
from .edges import EDGE_SCHEMA, EdgeRow
from .text import (
    MESH_COORDINATES,
    as_utf8,
    csv_line,
    load,
    parse_table,
    row_cells,
)

#: The MeshLab Virtual Goniometer plugin's header, exactly (``SegParam`` is λ).
MESHLAB_COLUMNS = (
    "Mesh Name",
    "Date",
    "Measurement #",
    "Break #",
    "Colors",
    "User Data",
    "Angle",
    "Number of Vertices",
    "Radius",
    "x",
    "y",
    "z",
    "fit",
    "SegParam",
)


# (MeasurementRow field, kind, CSV columns), in column order. Kinds: text, int, float, bool,
# flag (a bool that may be empty), space (mesh or world, see text.space_cell) and vec3 (three
# float columns).
SCHEMA = (
    ("mesh_name", "text", ("Mesh Name",)),
    ("date", "text", ("Date",)),
    ("number", "int", ("Measurement #",)),
    ("break_number", "int", ("Break #",)),
    ("colors", "text", ("Colors",)),
    ("user_data", "text", ("User Data",)),
    ("angle", "float", ("Angle",)),
    ("n_vertices", "int", ("Number of Vertices",)),
    ("radius", "float", ("Radius",)),
    ("x", "float", ("x",)),
    ("y", "float", ("y",)),
    ("z", "float", ("z",)),
    ("fit", "float", ("fit",)),
    ("lam", "float", ("SegParam",)),
    ("patch", "text", ("Patch Mode",)),
    ("n_plus", "int", ("Vertices +",)),
    ("n_minus", "int", ("Vertices -",)),
    ("fit_plus", "float", ("Fit +",)),
    ("fit_minus", "float", ("Fit -",)),
    ("normal_plus", "vec3", ("Normal + x", "Normal + y", "Normal + z")),
    ("normal_minus", "vec3", ("Normal - x", "Normal - y", "Normal - z")),
    ("requested", "vec3", ("Requested x", "Requested y", "Requested z")),
    ("snap_distance", "float", ("Snap Distance",)),
    ("edge_number", "int", ("Edge #",)),
    ("arc_length", "float", ("Arc Length",)),
    ("spacing", "float", ("Spacing",)),
    ("edge_closed", "flag", ("Edge Closed",)),
    ("units", "text", ("Units",)),
    ("coordinates", "space", ("Coordinates",)),
    ("precision", "text", ("Precision",)),
    ("stale", "bool", ("Stale",)),
    ("extension_version", "text", ("Extension Version",)),
    ("blender_version", "text", ("Blender Version",)),
    ("rule", "text", ("Rule",)),
    ("convexity", "text", ("Convexity",)),
    ("correlation", "float", ("Convexity Correlation",)),
    ("stability", "float", ("Stability",)),
    ("stability_center", "float", ("Stability Centre",)),
    ("stability_radius", "float", ("Stability Radius",)),
    ("stability_lam", "float", ("Stability SegParam",)),
    ("stability_bootstrap", "float", ("Stability Bootstrap",)),
    ("stability_orientation", "float", ("Stability Orientation",)),
    ("stability_runs", "int", ("Stability Runs",)),
    ("stability_refused", "int", ("Stability Refused",)),
    ("stability_crease", "float", ("Stability Crease",)),
    ("stability_crease_refused", "int", ("Stability Crease Refused",)),
    ("stability_noise_hides_crease", "int", ("Stability Noise Hides Crease",)),
    ("stability_flag", "text", ("Stability Flag",)),
    ("error", "text", ("error",)),
)


#: Columns added with the oriented rule (issue 8). Exports written before lack them; such a file
#: still reads, and its rows replicate with the paper's rule, the only one there was then.
RULE_COLUMNS = (
    "Rule",
    "Convexity",
    "Convexity Correlation",
    "Stability",
    "Stability Centre",
    "Stability Radius",
    "Stability SegParam",
    "Stability Bootstrap",
    "Stability Orientation",
    "Stability Runs",
    "Stability Refused",
)


#: Columns added with the stability figure's crease part (issue 19). Exports written before lack
#: them; their figures read as they were (no crease part, none refused).
CREASE_COLUMNS = ("Stability Crease", "Stability Crease Refused")


#: Column added when the normals' noise was kept apart from the refused crease bands (issue 19).
#: Exports written before lack it; their ``Stability Crease Refused`` may count either reason,
#: and an undetermined figure of theirs gives both.
NOISE_COLUMNS = ("Stability Noise Hides Crease",)


#: Column added so that a spreadsheet shows an undetermined or unstable figure beside its number
#: (the ``Stability`` cell is the spread of the runs that ran, a number even when too many were
#: refused). Derived from the other Stability columns; exports written before lack it.
FLAG_COLUMNS = ("Stability Flag",)


#: Column added so that an import rebuilds a station's edge as the loop or the open path it was
#: (before it, the import judged a loop by how near the last station is to the first). Exports
#: written before lack it.
CLOSED_COLUMNS = ("Edge Closed",)


#: Every column of an export: :data:`MESHLAB_COLUMNS`, then this extension's own.
EXPORT_COLUMNS = tuple(column for _, _, columns in SCHEMA for column in columns)


#: Columns added after the first exports: a file without them still reads (their cells empty).
LATER_COLUMNS = (
    "Precision",
    *RULE_COLUMNS,
    "Edge #",
    "Arc Length",
    "Spacing",
    "Coordinates",
    *CREASE_COLUMNS,
    *CLOSED_COLUMNS,
    *NOISE_COLUMNS,
    *FLAG_COLUMNS,
)


@dataclass
class MeasurementRow:
    """One row of an export; one field per column (vectors take three columns).

    A failed row (the batch script's) has ``error`` set and ``None`` in the numbers it could not
    compute; those cells are written empty.

    Attributes
    ----------
    mesh_name : str
        Object name (``Mesh Name``).
    date : str
        When it was measured, ISO 8601 with UTC offset (see :func:`now_iso`).
    number, break_number : int or None
        ``Measurement #`` and ``Break #``.
    colors : str
        ``"+ colour/- colour"`` as hex sRGB, e.g. ``"#E69F00/#0072B2"`` (see :func:`format_colors`).
    user_data : str
        Free-text note.
    angle : float or None
        Degrees.
    n_vertices, n_plus, n_minus : int or None
        Vertices in the patch and on its two sides.
    radius : float or None
        Patch radius, scene units.
    x, y, z : float or None
        The centre the measurement snapped to (a mesh vertex).
    fit, fit_plus, fit_minus : float or None
        Fit errors of both planes, and of each.
    lam : float or None
        λ, the segmentation parameter.
    patch : str
        ``"euclidean"`` or ``"geodesic"``.
    normal_plus, normal_minus : tuple of 3 float, or None
        Unit normals of the two sides.
    requested : tuple of 3 float, or None
        The centre that was asked for, before snapping.
    snap_distance : float or None
        Distance from ``requested`` to ``(x, y, z)``.
    edge_number : int or None
        The edge profile the row is a station of (``None`` for a single measurement).
    arc_length : float or None
        The station's arc length along its edge's traced path.
    spacing : float or None
        The edge's station spacing.
    edge_closed : bool or None
        Whether a station's edge is a loop (its path ends where it starts); ``None`` for a single
        measurement, and in files written before the column.
    units : str
        What one coordinate unit is.
    coordinates : str
        ``"mesh"``: x, y, z, the requested centre, the radius and the normals are in the mesh's
        own coordinates (those of its file); ``"world"``: in Blender world space (exports of
        versions before this column existed).
    precision : str
        The coordinates measured: ``"float32"`` (a Blender mesh, as Blender stores it) or
        ``"float64"`` (a mesh file's double-precision coordinates, measured as the file holds
        them); empty for a failed row.
    stale : bool
        The mesh changed since the measurement was taken.
    extension_version, blender_version : str
    rule : str
        ``"refined"``, ``"oriented"`` or ``"paper"``: how the measurement was taken (see
        ``vg_addon.method.algorithm.RULES``).
    convexity : str
        ``"convex"``, ``"concave"`` (the angle is then the open wedge's) or ``"unclear"``.
    correlation : float or None
        The correlation whose sign gives the convexity (its size: how clearly).
    stability : float or None
        The stability figure, degrees (the "±"); empty when it was not computed.
    stability_center, stability_radius, stability_lam, stability_bootstrap, stability_orientation : float or None
        Its parts: the largest change of the angle with the centre moved, the radius ±10%, λ from
        1 to 3, the bootstrap's 95% half-width, and the other sign's reading where unclear.
    stability_runs, stability_refused : int or None
        Perturbed measurements tried, and how many of them were refused.
    stability_crease : float or None
        The crease part: the largest change of the angle with the vertices next to the crease
        left out (included in ``stability``, added to the largest of the other parts).
    stability_crease_refused : int or None
        Bands along the crease whose refit was refused; more than 0 makes the figure undetermined.
        In exports without ``stability_noise_hides_crease`` it may also count that reason (one).
    stability_noise_hides_crease : int or None
        1 where the vertex normals' noise is larger than the turn between the faces (the figure
        is then undetermined), 0 where not; empty when the figure was not computed or the
        export predates the column.
    stability_flag : str
        Why the figure flags the reading, in the panel's words (``"Undetermined: ..."``,
        ``"Unstable: ..."``); empty for a stable reading, a figure not computed, or an export
        that predates the column. Derived from the columns above: a reader need not trust it.
    error : str
        Empty for a good row; why it failed otherwise.
    """

    mesh_name: str = ""
    date: str = ""
    number: int | None = None
    break_number: int | None = None
    colors: str = ""
    user_data: str = ""
    angle: float | None = None
    n_vertices: int | None = None
    radius: float | None = None
    x: float | None = None
    y: float | None = None
    z: float | None = None
    fit: float | None = None
    lam: float | None = None
    patch: str = ""
    n_plus: int | None = None
    n_minus: int | None = None
    fit_plus: float | None = None
    fit_minus: float | None = None
    normal_plus: tuple[float, float, float] | None = None
    normal_minus: tuple[float, float, float] | None = None
    requested: tuple[float, float, float] | None = None
    snap_distance: float | None = None
    edge_number: int | None = None
    arc_length: float | None = None
    spacing: float | None = None
    edge_closed: bool | None = None
    units: str = ""
    coordinates: str = MESH_COORDINATES
    precision: str = ""
    stale: bool = False
    extension_version: str = ""
    blender_version: str = ""
    rule: str = ""
    convexity: str = ""
    correlation: float | None = None
    stability: float | None = None
    stability_center: float | None = None
    stability_radius: float | None = None
    stability_lam: float | None = None
    stability_bootstrap: float | None = None
    stability_orientation: float | None = None
    stability_runs: int | None = None
    stability_refused: int | None = None
    stability_crease: float | None = None
    stability_crease_refused: int | None = None
    stability_noise_hides_crease: int | None = None
    stability_flag: str = ""
    error: str = ""


def now_iso() -> str:
    """The local time with its UTC offset, to the second: ``"2024-05-01T14:03:11+02:00"``."""
    return datetime.now().astimezone().isoformat(timespec="seconds")


def _hex_colour(colour) -> str:
    if isinstance(colour, str):
        text = colour.strip()
        if re.fullmatch(r"#[0-9A-Fa-f]{6}", text):
            return text.upper()
        rgb = OKABE_ITO.get(" ".join(text.casefold().split()))
        if rgb is None:
            raise GoniometerError(
                f"Unknown colour {colour!r}: use a palette name ({', '.join(OKABE_ITO)}), "
                "'#RRGGBB', or three 0-255 values."
            )
    else:
        rgb = colour
    try:
        values = [operator.index(c) for c in rgb]
    except TypeError:
        values = []
    if len(values) != 3 or not all(0 <= c <= 255 for c in values):
        raise GoniometerError(
            f"Colour {colour!r} is not three whole numbers from 0 to 255 (8-bit sRGB)."
        )
    return "#{:02X}{:02X}{:02X}".format(*values)


def format_colors(pair_rgb) -> str:
    """The ``Colors`` cell for a ("+" side, "-" side) colour pair: ``"#E69F00/#56B4E9"``.

    Parameters
    ----------
    pair_rgb : sequence of two colours, or str
        Each colour is three 8-bit sRGB integers (0-255), a ``"#RRGGBB"`` string, or a name of
        :data:`vg_addon.palette.OKABE_ITO` (case-insensitive). A string ``"orange/blue"`` is
        split at the ``/``.

    Raises
    ------
    GoniometerError
        Not exactly two colours, or a colour that is none of the above.
    """
    pair = pair_rgb.split("/") if isinstance(pair_rgb, str) else list(pair_rgb)
    if len(pair) != 2:
        raise GoniometerError(
            f"A colour pair needs exactly two colours ('+' side, '-' side), got {pair_rgb!r}."
        )
    return "/".join(_hex_colour(colour) for colour in pair)


def _schema_of(row):
    return EDGE_SCHEMA if isinstance(row, EdgeRow) else SCHEMA


def writable_row(row):
    """``row`` (a :class:`MeasurementRow` or :class:`EdgeRow`) if every cell can be written,
    else a copy that can: a number that is not finite (or not a number) left empty, text that
    UTF-8 cannot hold with those characters replaced, and each change said in ``error``.

    So one bad value costs its own cell, never the other rows of a file: writers that must
    keep every good row (the batch) pass their rows through this first.
    """
    try:
        row_cells(0, row, _schema_of(row))
        return row  # the usual case: the whole row at once
    except Exception:  # any cell that cannot be written costs only itself, below
        pass
    changes, problems = {}, []
    for entry in _schema_of(row):
        field, kind, columns = entry
        try:
            row_cells(0, row, (entry,))
        except Exception:
            value = getattr(row, field)
            if kind in ("text", "space"):
                changes[field] = as_utf8(str(value))
                problems.append(f"{columns[0]} {changes[field]!r} had characters UTF-8 cannot hold")
            else:
                changes[field] = None
                problems.append(f"{columns[0]} could not be written ({value!r}): left empty")
    if not changes:
        return row
    error = changes.get("error", row.error)
    changes["error"] = "; ".join(part for part in (error, *problems) if part)
    return dataclasses.replace(row, **changes)


def format_measurements_csv(rows: Iterable[MeasurementRow], *, lines: dict | None = None) -> str:
    """The text of an export: the :data:`EXPORT_COLUMNS` header and one line per row.

    Floats are written with ``repr`` (so they read back bit-identical), integers as integers,
    ``None`` as an empty cell, ``stale`` as ``TRUE``/``FALSE``. A text cell that starts with
    ``= + - @``, a tab, a carriage return or an apostrophe gets a leading apostrophe, so no
    spreadsheet runs it as a formula (the readers remove it again).

    ``lines``: a dict kept between calls by a writer that rewrites a growing file (the batch):
    it remembers each row's line (rows are matched by identity, and kept in it; a row is not
    changed once written), so each call formats only the rows it has not seen.

    Raises
    ------
    GoniometerError
        A value that cannot be written: a non-finite or non-numeric float, a fractional count,
        a vector without three numbers.
    """
    text = [csv_line(EXPORT_COLUMNS)]
    for index, row in enumerate(rows):
        known = None if lines is None else lines.get(id(row))
        if known is not None and known[0] is row:
            text.append(known[1])
            continue
        line = csv_line(row_cells(index, row, SCHEMA))
        if lines is not None:
            lines[id(row)] = (row, line)  # the row kept: its id is not reused while here
        text.append(line)
    return "".join(text)


def write_measurements_csv(
    path, rows: Iterable[MeasurementRow], *, lines: dict | None = None
) -> None:
    """Write an export to ``path`` (UTF-8, comma-delimited, ``\\n`` line ends).

    The whole text is formatted first (see :func:`format_measurements_csv`). A regular file is
    written atomically: to a temporary file in the same folder, then moved over ``path`` in one
    step, so ``path`` holds either its old content or the complete new one; on any failure the
    temporary file is removed. An existing file's permissions are kept; through a symbolic link,
    the link's target is replaced and the link stays. ``"-"``, a pipe, a terminal, a character
    device (``/dev/null``) or a name of an open descriptor (``/dev/stdout``) is written into,
    never replaced (see ``files.output_target``).

    Raises
    ------
    GoniometerError
        A row that cannot be written, a missing folder, a folder or other target that is not a
        file, a target that cannot be replaced, or a stream that refuses the data (e.g.
        ``/dev/full``).
    OSError
        Other file-system errors (disk full, no permission to create the file, ...).
    """
    data = format_measurements_csv(rows, lines=lines).encode("utf-8")
    replace_atomically(path, data)


def parse_measurements_csv(text: str, source: str = "The CSV text") -> list[MeasurementRow]:
    """Parse an export written by :func:`format_measurements_csv` back into rows.

    Every column of :data:`EXPORT_COLUMNS` must be present (in any order; names are matched
    case-insensitively), except the :data:`LATER_COLUMNS`, which older exports lack; text cells
    are kept as written (only the formula-guard apostrophe is removed), numbers read back
    bit-identical. Blank lines are skipped.

    Raises
    ------
    GoniometerError
        Listing every missing column and every cell that does not parse, with row numbers.
    """
    return parse_table(text, source, SCHEMA, MeasurementRow, LATER_COLUMNS, "an export")


def replayed_rows(rows: Iterable[MeasurementRow]) -> list[MeasurementRow]:
    """The rows of an export that a replication re-measures, in order: all but a batch run's
    failed rows (an ``error`` and no coordinates), which the replication reader passes over."""
    return [row for row in rows if not (row.error and (row.x, row.y, row.z) == (None,) * 3)]


def read_measurements_csv(path_or_text) -> list[MeasurementRow]:
    """Read a complete export of this extension back into :class:`MeasurementRow` objects.

    ``path_or_text`` is taken as in :func:`read_replication_csv`. See
    :func:`parse_measurements_csv`.
    """
    text, source = load(path_or_text)
    return parse_measurements_csv(text, source)
