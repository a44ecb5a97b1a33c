"""Measurement CSV files: the export schema, its writer, and the readers used to replicate.

Every export starts with the 14 columns of the MeshLab Virtual Goniometer plugin, in its order
(:data:`MESHLAB_COLUMNS`), so analysis scripts written for MeshLab files keep working; this
extension's own columns follow (:data:`EXPORT_COLUMNS`). The earlier AMAAZE Blender add-on wrote
the same 14 columns.

Writing (:func:`write_measurements_csv`) is UTF-8, comma-delimited, ``\\n`` line ends, floats
as ``repr`` (the shortest text that reads back to the same float64, bit for bit), text cells
protected against spreadsheet formula injection, and atomic: the old file stays intact if
anything fails.

Reading for replication (:func:`read_replication_csv`, the paper's "xyz method") accepts this
extension's exports, the MeshLab plugin's file, the earlier Blender add-on's file and a plain
points CSV (``x,y,z`` with optional radius, lambda, patch mode, label and mesh columns). It
checks every row first and raises one :class:`GoniometerError` listing every problem, or
returns every row: never part of a file.

Row numbers in messages and in :attr:`ReplicationRow.row_number` are the rows a spreadsheet
shows for the file: the header is row 1, so the first data row is row 2. Blank lines count as
rows (a spreadsheet shows them as empty rows); a quoted cell that spans lines stays one row.
"""

from __future__ import annotations

import csv
import dataclasses
import io
import math
import operator
import os
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path

from ..errors import GoniometerError, bounded_list
from ..method.algorithm import RULES
from ..method.surface import PATCH_MODES
from ..palette import OKABE_ITO
from .files import replace_atomically

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

# (MeasurementRow field, kind, CSV columns), in column order. Kinds: text, int, float, bool and
# vec3 (three float columns).
_SCHEMA = (
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
    ("units", "text", ("Units",)),
    ("coordinates", "text", ("Coordinates",)),
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

#: Every column of an export: :data:`MESHLAB_COLUMNS`, then this extension's own.
EXPORT_COLUMNS = tuple(column for _, _, columns in _SCHEMA for column in columns)

#: The values of the ``Coordinates`` column: the mesh's own coordinates (object space, those of
#: the file the scan came from) and, in exports of versions before it existed, world space.
MESH_COORDINATES = "mesh"
WORLD_COORDINATES = "world"
COORDINATE_SPACES = (MESH_COORDINATES, WORLD_COORDINATES)

# What a missing column of the LATER_COLUMNS means (others: an empty cell).
_LEGACY_DEFAULTS = {"Coordinates": WORLD_COORDINATES}

#: Columns added after the first exports: a file without them still reads (their cells empty).
LATER_COLUMNS = ("Precision", *RULE_COLUMNS, "Edge #", "Arc Length", "Spacing", "Coordinates")

# The edge summary file: one row per measured edge profile (see EdgeRow).
_EDGE_SCHEMA = (
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
    ("length", "float", ("Length",)),
    ("mean", "float", ("Mean Angle",)),
    ("std", "float", ("SD Angle",)),
    ("min", "float", ("Min Angle",)),
    ("max", "float", ("Max Angle",)),
    ("pooled_angle", "float", ("Pooled Angle",)),
    ("pooled_fit", "float", ("Pooled Fit",)),
    ("points", "text", ("Points",)),
    ("flat_spans", "text", ("Flat Spans",)),
    ("units", "text", ("Units",)),
    ("coordinates", "text", ("Coordinates",)),
    ("extension_version", "text", ("Extension Version",)),
    ("blender_version", "text", ("Blender Version",)),
    ("error", "text", ("error",)),
)

#: Every column of an edge summary file.
EDGE_COLUMNS = tuple(column for _, _, columns in _EDGE_SCHEMA for column in columns)

#: Columns added to the edge summary file after its first version.
LATER_EDGE_COLUMNS = ("Coordinates",)

#: How :attr:`ReplicationRow.source_format` names the kinds of file the reader accepts.
SOURCE_FORMATS = ("extension", "meshlab", "points")

_TRUE = "TRUE"
_FALSE = "FALSE"

# Leading characters that make a spreadsheet treat a cell as a formula (OWASP's list). The
# apostrophe is included so that escaping is reversible: a text that starts with one is
# escaped too, and the reader removes exactly one.
_FORMULA_START = ("=", "+", "-", "@", "\t", "\r", "'")

_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")
# At most 18 digits: every such integer fits 64 bits, and int() never meets Python's limit on
# the length of integer text.
_INTEGER = re.compile(r"[+-]?\d{1,18}")

# File extensions a CSV's mesh name may carry (MeshLab writes the scan's file name).
_MESH_FILE_SUFFIXES = frozenset(
    [
        ".ply",
        ".obj",
        ".stl",
        ".off",
        ".glb",
        ".gltf",
        ".fbx",
        ".dae",
        ".x3d",
        ".wrl",
        ".3ds",
        ".abc",
        ".usd",
        ".usda",
        ".usdc",
        ".usdz",
        ".vtk",
    ]
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
    error: str = ""


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
    length : float or None
        Arc length of the traced path.
    mean, std, min, max : float or None
        Of the stations' angles (degrees); ``std`` is the sample standard deviation.
    pooled_angle, pooled_fit : float or None
        One plane pair fitted to all stations' sides (the whole-edge angle), and its fit error.
    points : str
        The clicked points that define the path, ``"x y z; x y z; ..."`` (start, via, end).
    coordinates : str
        ``"mesh"``: the points, lengths and radius are in the mesh's own coordinates;
        ``"world"``: in Blender world space (files written before this column existed).
    flat_spans : str
        Arc-length intervals where the path crossed no ridge, ``"a-b; ..."``; empty if none.
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
    length: float | None = None
    mean: float | None = None
    std: float | None = None
    min: float | None = None
    max: float | None = None
    pooled_angle: float | None = None
    pooled_fit: float | None = None
    points: str = ""
    flat_spans: str = ""
    units: str = ""
    coordinates: str = MESH_COORDINATES
    extension_version: str = ""
    blender_version: str = ""
    error: str = ""


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


@dataclass(frozen=True)
class ReplicationRow:
    """One row to re-measure, as read by :func:`read_replication_csv`.

    Attributes
    ----------
    row_number : int
        The row a spreadsheet shows for it (the header is row 1, the first data row 2).
    mesh_name : str or None
        The mesh the row was measured on; ``None`` when the file has no mesh column or the cell
        is blank.
    x, y, z : float
        The centre to measure at.
    radius : float or None
        Patch radius (> 0); ``None`` when the file has no radius column or the cell is blank.
    lam : float or None
        λ (≥ 0), from ``SegParam`` / ``lambda`` / ...; ``None`` when absent or blank.
    patch : str or None
        ``"euclidean"`` or ``"geodesic"``; ``None`` when absent or blank.
    label : str or None
        From ``label`` (preferred) or ``User Data``; ``None`` when absent or blank.
    number : int or float or None
        The original ``Measurement #`` (MeshLab's burst measurements are fractional, e.g. 3.05);
        ``None`` when absent, blank or not a number.
    break_number : int or None
        The original ``Break #`` (1 to :data:`MAX_BREAK_NUMBER`); ``None`` when absent or blank.
    edge_number : int or None
        The ``Edge #`` of an edge profile's station; ``None`` for a single measurement.
    arc_length, spacing : float or None
        A station's ``Arc Length`` and its edge's ``Spacing`` (kept with the re-measured station).
    source_format : str
        ``"extension"`` (this extension's export), ``"meshlab"`` (the MeshLab plugin's 14
        columns, also written by the earlier AMAAZE Blender add-on) or ``"points"`` (anything
        else with x, y, z columns).
    coordinates : str
        ``"mesh"`` (the mesh's own coordinates: MeshLab's files, points files, exports with
        ``Coordinates`` = mesh) or ``"world"`` (Blender world space: exports of this extension
        written before the ``Coordinates`` column existed, or with ``Coordinates`` = world).
    rule : str or None
        The rule to replicate with: the ``Rule`` cell of an export; ``"paper"`` for MeshLab and
        earlier add-on files and for exports written before the ``Rule`` column existed (they
        were all measured with the paper's rule); a points file's ``rule`` column, else ``None``
        (the current default).
    """

    row_number: int
    mesh_name: str | None
    x: float
    y: float
    z: float
    radius: float | None = None
    lam: float | None = None
    patch: str | None = None
    label: str | None = None
    number: int | float | None = None
    break_number: int | None = None
    edge_number: int | None = None
    arc_length: float | None = None
    spacing: float | None = None
    source_format: str = "points"
    coordinates: str = MESH_COORDINATES
    rule: str | None = None


# --------------------------------------------------------------------------- small helpers


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


def _escape_text(text: str) -> str:
    """Prefix an apostrophe to text a spreadsheet would run as a formula."""
    return "'" + text if text.startswith(_FORMULA_START) else text


def _unescape_text(text: str) -> str:
    """Undo :func:`_escape_text`; other leading apostrophes (e.g. in foreign files) stay."""
    if len(text) > 1 and text[0] == "'" and text[1] in _FORMULA_START:
        return text[1:]
    return text


def _split_names(names) -> tuple[str, ...]:
    if isinstance(names, str):
        return (names,)
    return tuple(str(name) for name in names)


def _mesh_stem(name: str) -> str:
    # MeshLab writes the scan's file name (maybe with a folder); strip the folder and a mesh
    # file extension only, so Blender's "bone.001" stays distinct from "bone".
    base = re.split(r"[\\/]", name)[-1]
    stem, dot, suffix = base.rpartition(".")
    if dot and stem and "." + suffix.casefold() in _MESH_FILE_SUFFIXES:
        return stem
    return base


def mesh_name_match(csv_name: str | None, names) -> int | None:
    """How closely a CSV's mesh name refers to a mesh known by ``names``: 0 exactly (surrounding
    spaces included: a mesh file " lead.ply" is the mesh " lead"), 1 without its surrounding
    spaces (a hand-typed cell), 2 after dropping a folder and a mesh file extension
    (``"scans/bone_12.ply"`` matches ``"bone_12"``); None when it does not. A blank name is 2
    for any mesh."""
    given = csv_name or ""
    if not given.strip():
        return 2
    candidates = set(_split_names(names))
    if given in candidates:
        return 0
    if given.strip() in candidates:
        return 1
    if any(_mesh_stem(name) in candidates for name in (given, given.strip())):
        return 2
    return None


def mesh_name_matches(csv_name: str | None, names) -> bool:
    """Whether a CSV's mesh name refers to a mesh known by ``names`` (see
    :func:`mesh_name_match`).

    Parameters
    ----------
    csv_name : str or None
        The row's mesh name. Blank or ``None`` matches any mesh.
    names : str or iterable of str
        The mesh's names, e.g. its object name and its mesh data name.
    """
    return mesh_name_match(csv_name, names) is not None


def rows_for_mesh(rows: Iterable[ReplicationRow], mesh_name) -> list[ReplicationRow]:
    """The rows that refer to ``mesh_name`` (str or several names), or name no mesh at all."""
    return [row for row in rows if mesh_name_matches(row.mesh_name, mesh_name)]


def rows_for_other_meshes(rows: Iterable[ReplicationRow], mesh_name) -> list[ReplicationRow]:
    """The rows that name another mesh than ``mesh_name`` (str or several names)."""
    return [row for row in rows if not mesh_name_matches(row.mesh_name, mesh_name)]


def check_mesh_names(rows: Sequence[ReplicationRow], mesh_name, *, source="the CSV") -> None:
    """Raise if any row names another mesh than ``mesh_name`` (str or several names).

    Raises
    ------
    GoniometerError
        Listing those rows' numbers and names (the first 20) and what to do.
    """
    others = rows_for_other_meshes(rows, mesh_name)
    if not others:
        return
    shown = next(iter(_split_names(mesh_name)), "")
    listed = bounded_list(f"{row.row_number} ({row.mesh_name!r})" for row in others)
    raise GoniometerError(
        f"{len(others)} row(s) of {source} name another mesh than '{shown}': rows {listed}. "
        "Nothing was imported. Select the mesh they were measured on, or ignore the mesh names "
        "to measure them on this one."
    )


# --------------------------------------------------------------------------- writing


def _cell_error(index: int, row, column: str, value, need: str) -> GoniometerError:
    name = getattr(row, "mesh_name", "")
    return GoniometerError(
        f"Cannot write measurement {index + 1} (mesh {name!r}): {column} is {value!r}, "
        f"not {need}. Nothing was written."
    )


def _float_cell(value, index, row, column) -> str:
    if value is None:
        return ""
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise _cell_error(index, row, column, value, "a number") from None
    if not math.isfinite(number):
        raise _cell_error(index, row, column, value, "a finite number")
    return repr(number)


def _row_cells(index: int, row, schema=_SCHEMA) -> list[str]:
    cells = []
    for field, kind, columns in schema:
        value = getattr(row, field)
        if kind == "text":
            text = "" if value is None else str(value)
            if not _is_utf8(text):
                raise _cell_error(index, row, columns[0], value, "text UTF-8 can hold")
            cells.append(_escape_text(text))
        elif kind == "float":
            cells.append(_float_cell(value, index, row, columns[0]))
        elif kind == "int":
            if value is None:
                cells.append("")
            else:
                try:
                    cells.append(str(operator.index(value)))
                except TypeError:
                    raise _cell_error(index, row, columns[0], value, "a whole number") from None
        elif kind == "bool":
            cells.append("" if value is None else (_TRUE if value else _FALSE))
        else:  # vec3
            if value is None:
                cells.extend(("", "", ""))
                continue
            try:
                parts = list(value)
            except TypeError:
                parts = []
            if len(parts) != 3:
                raise _cell_error(index, row, field, value, "three numbers")
            cells.extend(
                _float_cell(part, index, row, column)
                for part, column in zip(parts, columns, strict=True)
            )
    return cells


def _is_utf8(text: str) -> bool:
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:  # a lone surrogate, e.g. from a file name that is not UTF-8
        return False
    return True


def _as_utf8(text: str) -> str:
    """``text`` with what UTF-8 cannot hold replaced: a file name's undecodable bytes (Python's
    surrogate escapes) by U+FFFD, as a file manager shows them."""
    try:
        return text.encode("utf-8", "surrogateescape").decode("utf-8", "replace")
    except UnicodeEncodeError:
        return text.encode("utf-8", "replace").decode("utf-8")


def _schema_of(row):
    return _EDGE_SCHEMA if isinstance(row, EdgeRow) else _SCHEMA


def writable_row(row):
    """``row`` (a :class:`MeasurementRow` or :class:`EdgeRow`) if every cell can be written,
    else a copy that can: a number that is not finite (or not a number) left empty, text that
    UTF-8 cannot hold with those characters replaced, and each change said in ``error``.

    So one bad value costs its own cell, never the other rows of a file: writers that must
    keep every good row (the batch) pass their rows through this first.
    """
    try:
        _row_cells(0, row, _schema_of(row))
        return row  # the usual case: the whole row at once
    except Exception:  # any cell that cannot be written costs only itself, below
        pass
    changes, problems = {}, []
    for entry in _schema_of(row):
        field, kind, columns = entry
        try:
            _row_cells(0, row, (entry,))
        except Exception:
            value = getattr(row, field)
            if kind == "text":
                changes[field] = _as_utf8(str(value))
                problems.append(f"{columns[0]} {changes[field]!r} had characters UTF-8 cannot hold")
            else:
                changes[field] = None
                problems.append(f"{columns[0]} could not be written ({value!r}): left empty")
    if not changes:
        return row
    error = changes.get("error", row.error)
    changes["error"] = "; ".join(part for part in (error, *problems) if part)
    return dataclasses.replace(row, **changes)


def _csv_line(cells: Iterable[str]) -> str:
    # csv.writer on Python 3.11 leaves a lone "\r" unquoted when lines end in "\n", which
    # splits the row for every reader; quote by hand (RFC 4180).
    quoted = (
        '"' + cell.replace('"', '""') + '"' if any(c in cell for c in ',"\r\n') else cell
        for cell in cells
    )
    return ",".join(quoted) + "\n"


def format_measurements_csv(rows: Iterable[MeasurementRow]) -> str:
    """The text of an export: the :data:`EXPORT_COLUMNS` header and one line per row.

    Floats are written with ``repr`` (so they read back bit-identical), integers as integers,
    ``None`` as an empty cell, ``stale`` as ``TRUE``/``FALSE``. A text cell that starts with
    ``= + - @``, a tab, a carriage return or an apostrophe gets a leading apostrophe, so no
    spreadsheet runs it as a formula (the readers remove it again).

    Raises
    ------
    GoniometerError
        A value that cannot be written: a non-finite or non-numeric float, a fractional count,
        a vector without three numbers.
    """
    lines = [_csv_line(EXPORT_COLUMNS)]
    lines.extend(_csv_line(_row_cells(index, row)) for index, row in enumerate(rows))
    return "".join(lines)


#: The path that means standard output.
def format_edges_csv(rows: Iterable[EdgeRow]) -> str:
    """The text of an edge summary file: the :data:`EDGE_COLUMNS` header and one line per edge,
    written like :func:`format_measurements_csv`."""
    lines = [_csv_line(EDGE_COLUMNS)]
    lines.extend(_csv_line(_row_cells(index, row, _EDGE_SCHEMA)) for index, row in enumerate(rows))
    return "".join(lines)


def write_measurements_csv(path, rows: Iterable[MeasurementRow]) -> None:
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
    data = format_measurements_csv(rows).encode("utf-8")
    replace_atomically(path, data)


def edges_path_for(path) -> Path:
    """Where the edge summary of the export ``path`` goes: ``name_edges.csv`` beside it."""
    path = Path(path)
    return path.with_name(f"{path.stem}_edges{path.suffix or '.csv'}")


def write_edges_csv(path, rows: Iterable[EdgeRow]) -> None:
    """Write an edge summary file to ``path``, atomically, like :func:`write_measurements_csv`."""
    replace_atomically(path, format_edges_csv(rows).encode("utf-8"))


# --------------------------------------------------------------------------- reading


def _load(path_or_text) -> tuple[str, str]:
    """``(text, name for messages)``; a str with a line break is content, other str a path."""
    if isinstance(path_or_text, bytes):
        return _decode(path_or_text, "The CSV data"), "The CSV data"
    if isinstance(path_or_text, str) and _is_csv_text(path_or_text):
        return path_or_text, "The CSV text"
    path = Path(os.fspath(path_or_text))
    source = f"'{path.name}'"
    return _decode(path.read_bytes(), source), source


def _is_csv_text(text: str) -> bool:
    """Whether a str is CSV content rather than a path: it has a line break, is not the name of
    an existing file (a path may hold a line break) and its first line has a delimiter."""
    if "\n" not in text and "\r" not in text:
        return False
    if os.path.lexists(text):
        return False
    first = next((line for line in text.splitlines() if line.strip()), "")
    return not first or any(delimiter in first for delimiter in _DELIMITER_NAMES)


def _decode(data: bytes, source: str) -> str:
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as error:
        raise GoniometerError(
            f"{source} is not UTF-8 text (byte {error.start + 1} is 0x{data[error.start]:02X}). "
            "Save it as 'CSV UTF-8 (comma delimited)' and import again."
        ) from None


_DELIMITER_NAMES = {",": "a comma", ";": "a semicolon (;)", "\t": "a tab"}


def _check_delimiter(header_line: str, source: str) -> None:
    unquoted = re.sub(r'"[^"]*"', "", header_line)
    counts = {d: unquoted.count(d) for d in _DELIMITER_NAMES}
    delimiter = max(counts, key=lambda d: (counts[d], d == ","))
    if delimiter != "," and counts[delimiter] > counts[","]:
        raise GoniometerError(
            f"{source} uses {_DELIMITER_NAMES[delimiter]} as its delimiter, not a comma. "
            "Save it comma-separated (in a spreadsheet: 'CSV UTF-8 (comma delimited)') and "
            "import again."
        )


def _records(text: str, source: str) -> list[tuple[int, list[str]]]:
    """Every record with its spreadsheet row number, after the BOM and delimiter checks."""
    if text.startswith("\ufeff"):
        text = text[1:]
    if not text.strip():
        raise GoniometerError(
            f"{source} is empty: it needs a header line (e.g. 'x,y,z,radius') and one row per "
            "measurement."
        )
    header_line = next(line for line in text.splitlines() if line.strip())
    _check_delimiter(header_line, source)
    # strict: a quote still open at the end of the file, or text after a closing quote, is an
    # error, not a cell that swallows the rest of the file.
    reader = csv.reader(io.StringIO(text, newline=""), strict=True)
    records = []
    header: list[str] = []
    line = 1
    try:
        while True:
            line = reader.line_num + 1  # the physical line the record starts on
            cells = next(reader, None)
            if cells is None:
                break
            records.append((len(records) + 1, cells))
            header = header or ([] if _blank(cells) else cells)
            if reader.line_num > line:
                _check_open_quote(cells, line, header, source)
    except csv.Error as error:
        if "end of data" in str(error) or reader.line_num > line:  # a quote that never closes
            raise GoniometerError(
                f"{source}: line {line} opens a quote that is not closed where its cell ends "
                f"({error}), so the lines after it would be read as part of one cell; nothing "
                f"was read. Close the quote on line {line} (a quote inside a cell is written as "
                'two quotes "") and try again.'
            ) from None
        raise GoniometerError(
            f"{source} is not a readable CSV near line {reader.line_num}: {error}. "
            "Check the quotes on that line."
        ) from None
    return records


def _check_open_quote(cells: Sequence[str], line: int, header: Sequence[str], source: str) -> None:
    """Refuse a record whose quoted cell runs over lines that look like rows of their own: a
    quote left open swallows later rows into one cell until another quote closes it, which would
    otherwise read as one row with a long note. A line looks like a row when it has numbers in
    the header's x, y and z columns (or, without them, as many cells as a header of six or more
    columns). A note written over several lines, commas and all, does not."""
    for column, cell in enumerate(cells, start=1):
        swallowed = [part for part in cell.splitlines()[1:] if _looks_like_a_row(part, header)]
        if swallowed:
            raise GoniometerError(
                f"{source}: line {line} opens a quote (in cell {column}) that is not closed on "
                f"that line, so the {len(swallowed)} line(s) after it that look like rows would "
                "be read as part of that one cell; nothing was read. Close the quote on line "
                f'{line} (a quote inside a cell is written as two quotes "") and try again.'
            )


def _coordinate_columns(header: Sequence[str]) -> list[int] | None:
    names = [_normalise(cell) for cell in header]
    found = []
    for axis in ("x", "y", "z"):
        position = next((names.index(a) for a in _REPLICATION_ALIASES[axis] if a in names), None)
        if position is None:
            return None
        found.append(position)
    return found


def _looks_like_a_row(line: str, header: Sequence[str]) -> bool:
    try:
        cells = next(csv.reader([line]), [])
    except csv.Error:
        return False
    columns = _coordinate_columns(header)
    if columns is None:
        return len(header) >= 6 and len(cells) == len(header)
    return len(cells) > max(columns) and all(_parse_float(cells[k])[0] is not None for k in columns)


def _blank(cells: Sequence[str]) -> bool:
    return all(not cell.strip() for cell in cells)


def _normalise(header: str) -> str:
    return " ".join(header.replace("_", " ").casefold().split())


def _problems_error(source: str, problems: list[str]) -> GoniometerError:
    return GoniometerError(
        f"{source} has {len(problems)} problem(s); nothing was read. Fix them and try again:\n"
        + bounded_list(problems, lines=True)
    )


def _parse_float(raw: str) -> tuple[float | None, str | None]:
    """``(value, None)`` or ``(None, why not)`` for a non-blank cell."""
    text = raw.strip()
    if _NUMBER.fullmatch(text):
        value = float(text)
        if math.isfinite(value):
            return value, None
        return None, f"is not a finite number ({text!r})"
    try:
        value = float(text)
    except ValueError:
        value = None
    if value is not None and not math.isfinite(value):
        return None, f"is not a finite number ({text!r})"
    hint = ""
    if "," in text and _NUMBER.fullmatch(text.replace(",", ".", 1)):
        hint = "; use a point as the decimal separator"
    return None, f"is not a number ({text!r}{hint})"


def _parse_optional_text(raw: str) -> str | None:
    text = raw.strip()
    return _unescape_text(text) if text else None


def _parse_name(raw: str) -> str | None:
    """A mesh name as written, surrounding spaces kept (a file " lead.ply" is the mesh
    " lead"); ``None`` when blank."""
    return _unescape_text(raw) if raw.strip() else None


# Header aliases of the replication reader, normalised (case-folded, "_" as space, whitespace
# collapsed). The first alias found in a header wins.
_REPLICATION_ALIASES = {
    "mesh_name": ("mesh name", "mesh", "object", "object name", "meshname", "mesh file"),
    "x": ("x", "center x", "centre x"),
    "y": ("y", "center y", "centre y"),
    "z": ("z", "center z", "centre z"),
    "radius": ("radius", "patch radius", "r"),
    "lam": ("segparam", "seg param", "lambda", "λ", "lam", "segmentation parameter"),
    "patch": ("patch mode", "patch", "patchmode"),
    "label": ("label", "user data", "note", "notes"),
    "number": ("measurement #", "measurement number", "measurement", "number"),
    "break_number": ("break #", "break number", "break"),
    "coordinates": ("coordinates", "coordinate space"),
    "rule": ("rule",),
    "edge_number": ("edge #", "edge number", "edge"),
    "arc_length": ("arc length", "arc"),
    "spacing": ("spacing",),
    "error": ("error",),
}
_REQUIRED = ("x", "y", "z")


def _resolve_columns(header: list[str], aliases: dict, problems: list[str]) -> dict:
    """Field -> column index for the fields the header has; ambiguous names are problems."""
    positions: dict[str, list[int]] = {}
    for index, name in enumerate(header):
        positions.setdefault(_normalise(name), []).append(index)
    columns = {}
    for field, names in aliases.items():
        for alias in names:
            found = positions.get(alias)
            if not found:
                continue
            if len(found) > 1:
                listed = " and ".join(str(i + 1) for i in found)
                problems.append(
                    f"header: columns {listed} are all named {header[found[0]].strip()!r}; "
                    "keep one of them"
                )
            columns[field] = found[0]
            break
    return columns


def _source_format(header: list[str]) -> str:
    names = [_normalise(name) for name in header]
    if names[: len(MESHLAB_COLUMNS)] == [_normalise(c) for c in MESHLAB_COLUMNS]:
        ours = {_normalise(c) for c in EXPORT_COLUMNS[len(MESHLAB_COLUMNS) :]}
        return "extension" if ours & set(names) else "meshlab"
    return "points"


def _header(records, source: str) -> tuple[int, list[str]]:
    for position, (_, cells) in enumerate(records):
        if not _blank(cells):
            return position, cells
    raise GoniometerError(f"{source} is empty.")  # _records already rejects blank text


def _lenient_number(raw: str) -> int | float | None:
    text = raw.strip()
    if _INTEGER.fullmatch(text):
        return int(text)
    if _NUMBER.fullmatch(text):
        value = float(text)
        return value if math.isfinite(value) else None
    return None


#: The largest ``Break #`` (Blender stores it as a 32-bit signed integer).
MAX_BREAK_NUMBER = 2**31 - 1


def _parse_break_number(raw: str) -> int | str | None:
    """The break number of a cell, ``None`` when blank, or why it is not one (a str)."""
    text = raw.strip()
    if not text:
        return None
    if _INTEGER.fullmatch(text) and 1 <= int(text) <= MAX_BREAK_NUMBER:
        return int(text)
    return f"must be a whole number from 1 to {MAX_BREAK_NUMBER} (got {text!r})"


def parse_replication_csv(text: str, source: str = "The CSV text") -> list[ReplicationRow]:
    """Parse CSV text into replication rows; see :func:`read_replication_csv`.

    ``source`` names the text in error messages (e.g. ``"'points.csv'"``).
    """
    records = _records(text, source)
    header_at, header = _header(records, source)
    problems: list[str] = []
    columns = _resolve_columns(header, _REPLICATION_ALIASES, problems)
    missing = [field for field in _REQUIRED if field not in columns]
    if missing:
        found = ", ".join(repr(name.strip()) for name in header if name.strip()) or "none"
        problems.insert(
            0,
            f"header: missing the required column(s) {', '.join(missing)} (found: {found}). "
            "A replication CSV needs x, y and z columns (names are case-insensitive; radius, "
            "lambda/SegParam, patch mode, label/User Data and mesh name are optional)",
        )
    if problems:
        raise _problems_error(source, problems)

    fmt = _source_format(header)
    width = len(header)
    data = [(number, cells) for number, cells in records[header_at + 1 :] if not _blank(cells)]
    if not data:
        raise GoniometerError(
            f"{source} has a header but no data rows: add one row per measurement "
            "(x, y, z and optionally radius, lambda, ...) below the header."
        )

    def name_of(field: str) -> str:
        return header[columns[field]].strip()

    rows, skipped = [], 0
    for number, cells in data:

        def cell(field: str, cells=cells) -> str:
            index = columns.get(field)
            return cells[index] if index is not None and index < len(cells) else ""

        extra = cells[width:]
        if not _blank(extra):
            problems.append(
                f"row {number}: {len(cells)} cells but the header has {width} columns (a comma "
                "inside an unquoted name or note, or a decimal comma?)"
            )
            continue
        if cell("error").strip() and all(not cell(f).strip() for f in _REQUIRED):
            skipped += 1
            continue
        values: dict[str, float | None] = {}
        for field in ("x", "y", "z", "radius", "lam", "arc_length", "spacing"):
            raw = cell(field)
            if not raw.strip():
                values[field] = None
                if field in _REQUIRED:
                    problems.append(f"row {number}: {name_of(field)} is empty")
                continue
            value, why = _parse_float(raw)
            values[field] = value
            if why:
                problems.append(f"row {number}: {name_of(field)} {why}")
        if values["radius"] is not None and values["radius"] <= 0:
            problems.append(
                f"row {number}: {name_of('radius')} must be greater than 0 "
                f"(got {cell('radius').strip()})"
            )
        if values["lam"] is not None and values["lam"] < 0:
            problems.append(
                f"row {number}: {name_of('lam')} (λ) must be 0 or more (got {cell('lam').strip()})"
            )
        break_number = _parse_break_number(cell("break_number"))
        if isinstance(break_number, str):
            problems.append(f"row {number}: {name_of('break_number')} {break_number}")
        patch = _parse_optional_text(cell("patch"))
        if patch is not None:
            patch = patch.casefold()
            if patch not in PATCH_MODES:
                problems.append(
                    f"row {number}: unknown patch mode {cell('patch').strip()!r} "
                    f"(use {' or '.join(PATCH_MODES)})"
                )
        coordinates = _parse_optional_text(cell("coordinates"))
        if coordinates is None:
            # This extension wrote world coordinates until it wrote the column; every other
            # tool writes the mesh's own.
            coordinates = WORLD_COORDINATES if fmt == "extension" else MESH_COORDINATES
        coordinates = coordinates.casefold()
        if coordinates not in COORDINATE_SPACES:
            problems.append(
                f"row {number}: unknown coordinates {cell('coordinates').strip()!r} "
                f"(use {' or '.join(COORDINATE_SPACES)})"
            )
        rule = _parse_optional_text(cell("rule"))
        if rule is not None:
            rule = rule.casefold()
            if rule not in RULES:
                problems.append(
                    f"row {number}: unknown rule {cell('rule').strip()!r} (use {' or '.join(RULES)})"
                )
        elif fmt != "points":
            rule = "paper"  # MeshLab, the earlier add-on, exports from before the Rule column
        if problems:
            continue  # nothing is returned anyway; keep collecting
        edge_number = _lenient_number(cell("edge_number"))
        rows.append(
            ReplicationRow(
                row_number=number,
                mesh_name=_parse_name(cell("mesh_name")),
                x=values["x"],
                y=values["y"],
                z=values["z"],
                radius=values["radius"],
                lam=values["lam"],
                patch=patch,
                label=_parse_optional_text(cell("label")),
                number=_lenient_number(cell("number")),
                break_number=break_number,
                edge_number=edge_number if isinstance(edge_number, int) else None,
                arc_length=values["arc_length"],
                spacing=values["spacing"],
                source_format=fmt,
                coordinates=coordinates,
                rule=rule,
            )
        )
    if problems:
        raise _problems_error(source, problems)
    if not rows:
        raise GoniometerError(
            f"{source} has no rows to replicate: all {skipped} data row(s) are failed rows "
            "(their error column is filled and they have no coordinates)."
        )
    return rows


def read_replication_csv(path_or_text) -> list[ReplicationRow]:
    """Read the rows to re-measure (the paper's xyz method) from a CSV file or text.

    Parameters
    ----------
    path_or_text : str, os.PathLike or bytes
        A path, or the CSV content itself: a ``str`` containing a line break, or ``bytes``
        (UTF-8). A ``str`` without a line break is taken as a path.

    Returns
    -------
    list of ReplicationRow
        In file order. ``row_number`` is the spreadsheet row: the header is row 1 (or later, if
        blank lines come first), so the first data row is normally 2.

    Accepted files: this extension's export; the MeshLab plugin's CSV and the earlier AMAAZE
    Blender add-on's (both have the 14 MeshLab columns; the add-on writes the text ``fill`` in
    ``fit``, which is not read); and a plain points CSV. Header names are matched
    case-insensitively, ignoring surrounding whitespace and with ``_`` read as a space, with
    aliases: ``Mesh Name``/``Mesh``/``Object``; ``x``/``Center x``; ``Radius``/``r``;
    ``SegParam``/``Seg Param``/``lambda``/``λ``/``Segmentation Parameter``;
    ``Patch Mode``/``patch``; ``label``/``User Data``/``note`` (``label`` wins over
    ``User Data``); ``Measurement #``; ``Break #``; ``Rule`` (``oriented`` or ``paper``);
    ``Coordinates`` (``mesh`` or ``world``; absent or blank: ``world`` in an export of this
    extension, which wrote world coordinates before it had the column, ``mesh`` in every other
    file); ``error``. Only x, y and z are required. Rows of MeshLab and earlier add-on files, and
    of exports without a ``Rule`` column, replicate with the paper's rule (see
    :attr:`ReplicationRow.rule`).
    A UTF-8 byte-order mark is ignored; cells are read without surrounding whitespace, and the
    apostrophe the writer puts before formula-like text is removed.

    Skipped: fully blank lines, and rows whose ``error`` cell is filled *and* whose x, y and z
    are all blank (a batch run's failed rows). A failed row that has coordinates is kept.

    Raises
    ------
    GoniometerError
        One error listing every problem (the first 20, then "and N more") with its row number
        and column name: missing x/y/z columns (naming those found), duplicate columns, a blank,
        non-numeric or non-finite x/y/z/radius/lambda, radius ≤ 0, λ < 0, an unknown patch
        mode, a ``Break #`` that is not a whole number from 1 to :data:`MAX_BREAK_NUMBER`, a row
        with more cells than the header; or: an empty file, a header without data
        rows, only failed rows, a ``;`` or tab delimiter, text that is not UTF-8. Nothing is
        returned then.
    OSError
        The file cannot be read.
    """
    text, source = _load(path_or_text)
    return parse_replication_csv(text, source)


def _parse_bool(raw: str) -> bool | None:
    text = raw.strip().casefold()
    if text in ("true", "yes", "1"):
        return True
    if text in ("false", "no", "0", ""):
        return False
    return None


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
    return _parse_table(text, source, _SCHEMA, MeasurementRow, LATER_COLUMNS, "an export")


def parse_edges_csv(text: str, source: str = "The CSV text") -> list[EdgeRow]:
    """Parse an edge summary file written by :func:`format_edges_csv` back into rows."""
    return _parse_table(
        text, source, _EDGE_SCHEMA, EdgeRow, LATER_EDGE_COLUMNS, "an edge summary file"
    )


def is_edges_csv(path_or_text) -> bool:
    """Whether a CSV file (or text) is an edge summary file: its header has ``Edge #``,
    ``Points`` and ``Spacing``."""
    text, source = _load(path_or_text)
    _, header = _header(_records(text, source), source)
    names = {_normalise(name) for name in header}
    return {"edge #", "points", "spacing"} <= names


def read_edges_csv(path_or_text) -> list[EdgeRow]:
    """Read an edge summary file (see :func:`parse_edges_csv`); arguments as for
    :func:`read_replication_csv`."""
    text, source = _load(path_or_text)
    return parse_edges_csv(text, source)


def _parse_table(text, source, schema, row_type, optional, what):
    records = _records(text, source)
    header_at, header = _header(records, source)
    problems: list[str] = []
    all_columns = [column for _, _, names in schema for column in names]
    aliases = {column: (_normalise(column),) for column in all_columns}
    columns = _resolve_columns(header, aliases, problems)
    missing = [c for c in all_columns if c not in columns and c not in optional]
    if missing:
        problems.insert(
            0,
            f"header: missing the column(s) {', '.join(missing)}; this reader needs a complete "
            f"{what} of this extension (use read_replication_csv for other files)",
        )
    if problems:
        raise _problems_error(source, problems)

    rows = []
    for number, cells in records[header_at + 1 :]:
        if _blank(cells):
            continue

        def cell(column: str, cells=cells) -> str:
            index = columns.get(column)
            if index is None:
                return _LEGACY_DEFAULTS.get(column, "")
            return cells[index] if index < len(cells) else ""

        def number_of(column: str, number=number) -> float | None:
            raw = cell(column)
            if not raw.strip():
                return None
            value, why = _parse_float(raw)
            if why:
                problems.append(f"row {number}: {column} {why}")
            return value

        values = {}
        for field, kind, names in schema:
            if kind == "text":
                values[field] = _unescape_text(cell(names[0]))
            elif kind == "float":
                values[field] = number_of(names[0])
            elif kind == "int":
                raw = cell(names[0]).strip()
                values[field] = int(raw) if _INTEGER.fullmatch(raw) else None
                if raw and values[field] is None:
                    problems.append(f"row {number}: {names[0]} is not a whole number ({raw!r})")
            elif kind == "bool":
                values[field] = _parse_bool(cell(names[0]))
                if values[field] is None:
                    problems.append(f"row {number}: {names[0]} is not TRUE or FALSE")
            else:
                parts = [number_of(name) for name in names]
                blank = [not cell(name).strip() for name in names]
                values[field] = None if None in parts else tuple(parts)
                if any(blank) and not all(blank):
                    problems.append(
                        f"row {number}: {', '.join(names)} must be all filled or all empty"
                    )
        if values.get("points", "").strip() and row_type is EdgeRow:
            try:
                parse_points(values["points"])
            except GoniometerError as error:
                problems.append(f"row {number}: Points: {error}")
        rows.append(row_type(**values))
    if problems:
        raise _problems_error(source, problems)
    return rows


def read_measurements_csv(path_or_text) -> list[MeasurementRow]:
    """Read a complete export of this extension back into :class:`MeasurementRow` objects.

    ``path_or_text`` is taken as in :func:`read_replication_csv`. See
    :func:`parse_measurements_csv`.
    """
    text, source = _load(path_or_text)
    return parse_measurements_csv(text, source)


# --------------------------------------------------------------------------- radius sweeps

#: The columns of a radius-sweep CSV: one row per radius, refused radii with their message.
SWEEP_COLUMNS = (
    "Mesh Name",
    "Measurement #",
    "Radius",
    "Angle",
    "fit",
    "Number of Vertices",
    "Vertices +",
    "Vertices -",
    "Convexity",
    "x",
    "y",
    "z",
    "Requested x",
    "Requested y",
    "Requested z",
    "SegParam",
    "Patch Mode",
    "Rule",
    "error",
)


def sweep_cells(mesh_name: str, number: int | None, point) -> list[str]:
    """The cells of one :data:`SWEEP_COLUMNS` row for a ``vg_addon.method.sweep.SweepPoint``.

    A refused radius keeps its radius and message; its measured cells are empty.
    """
    m = point.measurement

    def cell(value, column):
        return _float_cell(value, 0, point, column)

    cells = [_escape_text(str(mesh_name)), "" if number is None else str(int(number))]
    cells.append(cell(point.radius, "Radius"))
    if m is None:
        cells += [""] * (len(SWEEP_COLUMNS) - 4)
    else:
        cells += [
            cell(m.angle, "Angle"),
            cell(m.fit_error, "fit"),
            str(int(m.n_vertices)),
            str(int(m.n_plus)),
            str(int(m.n_minus)),
            m.convexity,
            *(cell(v, "x") for v in m.center),
            *(cell(v, "Requested x") for v in m.requested_center),
            cell(m.lam, "SegParam"),
            m.patch,
            m.rule,
        ]
    cells.append(_escape_text(point.error))
    return cells


def format_sweep_rows(rows: Iterable[Sequence[str]]) -> str:
    """A sweep CSV's text: the :data:`SWEEP_COLUMNS` header, then rows from :func:`sweep_cells`."""
    return _csv_line(SWEEP_COLUMNS) + "".join(_csv_line(cells) for cells in rows)


def write_sweep_csv(path, mesh_name: str, points, number: int | None = None) -> None:
    """Write one site's sweep to ``path`` atomically (as :func:`write_measurements_csv`)."""
    text = format_sweep_rows(sweep_cells(mesh_name, number, point) for point in points)
    replace_atomically(os.fspath(path), text.encode("utf-8"))


# --------------------------------------------------------------------------- any table


def read_table(path_or_text) -> tuple[str, list[str], list[tuple[int, list[str]]]]:
    """Any comma-separated table, cell by cell, with this module's checks (UTF-8, the
    delimiter, quotes left open), for readers that judge each cell themselves.

    ``path_or_text`` is taken as in :func:`read_replication_csv`.

    Returns
    -------
    source : str
        The file's name for messages (``"'session.csv'"``).
    header : list of str
        The first non-blank record.
    rows : list of (int, list of str)
        The non-blank records after it, each with its row number as a spreadsheet shows it.
    """
    text, source = _load(path_or_text)
    records = _records(text, source)
    header_at, header = _header(records, source)
    return (
        source,
        header,
        [(n, cells) for n, cells in records[header_at + 1 :] if not _blank(cells)],
    )


def header_columns(header: Sequence[str], aliases: dict) -> tuple[dict, list[str]]:
    """``(field -> column index, problems)`` for a header, its names matched as this module
    matches them (case, spaces and ``_`` ignored; the first alias found wins)."""
    problems: list[str] = []
    normalised = {field: tuple(_normalise(a) for a in names) for field, names in aliases.items()}
    return _resolve_columns(list(header), normalised, problems), problems


def number_cell(raw: str) -> tuple[float | None, str | None]:
    """A non-blank cell as a finite number: ``(value, None)``, or ``(None, why not)`` worded as
    this module's messages are (a decimal comma named as the cause)."""
    return _parse_float(raw)


def break_number_cell(raw: str) -> int | str | None:
    """A ``Break #`` cell: the number, ``None`` when blank, or why it is not one (a str)."""
    return _parse_break_number(raw)


def text_cell(raw: str) -> str:
    """A text cell as written by :func:`writable_row` read back (the spreadsheet apostrophe
    removed)."""
    return _unescape_text(raw)


def mesh_stem(name: str) -> str:
    """A mesh name without a folder and a mesh file extension (``scans/bone.ply`` -> ``bone``;
    Blender's ``bone.001`` stays as it is)."""
    return _mesh_stem(name.strip())


def format_table(header: Sequence[str], rows: Iterable[Sequence]) -> str:
    """A table's CSV text in this module's form: floats as ``repr`` (they read back exactly),
    ``None`` empty, text guarded against spreadsheet formulas."""

    def cell(value) -> str:
        if value is None:
            return ""
        if isinstance(value, bool):
            return "TRUE" if value else "FALSE"
        if isinstance(value, (int, float)):
            return repr(value) if isinstance(value, float) else str(value)
        return _escape_text(str(value))

    lines = [_csv_line(cell(h) for h in header)]
    lines += [_csv_line(cell(value) for value in row) for row in rows]
    return "".join(lines)


def write_table(path, header: Sequence[str], rows: Iterable[Sequence]) -> None:
    """Write :func:`format_table`'s text to ``path`` atomically (the old file kept on failure)."""
    replace_atomically(path, format_table(header, rows).encode("utf-8"))
