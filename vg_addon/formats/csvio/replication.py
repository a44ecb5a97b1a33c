"""The rows to re-measure (the paper's "xyz method"), read from any CSV that has x, y and z.

:func:`read_replication_csv` accepts this extension's exports, the MeshLab plugin's file, the
earlier Blender add-on's file and a plain points CSV (``x,y,z`` with optional radius, lambda,
patch mode, label and mesh columns). It checks every row first and raises one
:class:`GoniometerError` listing every problem, or returns every row: never part of a file.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from ...errors import GoniometerError
from ...method.algorithm import RULES
from ...method.surface import PATCH_MODES
from .measurements import EXPORT_COLUMNS, MESHLAB_COLUMNS
from .text import (
    COORDINATE_SPACES,
    INTEGER,
    MESH_COORDINATES,
    NUMBER,
    WORLD_COORDINATES,
    XYZ_ALIASES,
    flag_cell,
    header_of,
    is_blank,
    load,
    normalise,
    number_cell,
    optional_text,
    problems_error,
    read_records,
    resolve_columns,
    text_cell,
    whole_cell,
)

#: How :attr:`ReplicationRow.source_format` names the kinds of file the reader accepts.
SOURCE_FORMATS = ("extension", "meshlab", "points")


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
        Patch radius (> 0); ``None`` when the file has no radius column (an ``r`` column beside
        ``g`` and ``b`` is a colour's red, not a radius) or the cell is blank.
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
    edge_closed : bool or None
        Whether the station's edge is a loop (``Edge Closed``); ``None`` when the file does not
        say.
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
        were all measured with the paper's rule), and for a measured row (its ``Convexity``
        filled) whose ``Rule`` was emptied; a points file's ``rule`` column, else ``None`` (the
        current default), as for a row never measured (a batch run's failed row).
    units : str or None
        The ``Units`` cell of an export (what one coordinate unit is, e.g. ``"mm"``); ``None``
        when absent or blank.
    requested : tuple of 3 float, or None
        Where the original measurement was asked for (``Requested x/y/z`` of an export, in
        ``coordinates``), kept where the row's ``Snap Distance`` is its distance from x, y, z
        (a row whose x, y, z were edited asks for x, y, z); ``None`` when absent or blank. The
        row is measured at x, y, z and keeps this as its requested centre.
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
    edge_closed: bool | None = None
    source_format: str = "points"
    coordinates: str = MESH_COORDINATES
    rule: str | None = None
    units: str | None = None
    requested: tuple[float, float, float] | None = None


# Header aliases of the replication reader, normalised (case-folded, "_" as space, whitespace
# collapsed). The first alias found in a header wins.
_REPLICATION_ALIASES = {
    "mesh_name": ("mesh name", "mesh", "object", "object name", "meshname", "mesh file"),
    **XYZ_ALIASES,
    "radius": ("radius", "patch radius", "r"),
    "lam": ("segparam", "seg param", "lambda", "λ", "lam", "segmentation parameter"),
    "patch": ("patch mode", "patch", "patchmode"),
    "label": ("label", "user data", "note", "notes"),
    "number": ("measurement #", "measurement number", "measurement", "number"),
    "break_number": ("break #", "break number", "break"),
    "coordinates": ("coordinates", "coordinate space"),
    "rule": ("rule",),
    "convexity": ("convexity",),  # filled where the row was measured
    "edge_number": ("edge #", "edge number", "edge"),
    "arc_length": ("arc length", "arc"),
    "spacing": ("spacing",),
    "edge_closed": ("edge closed",),
    "error": ("error",),
    "units": ("units",),
    "requested_x": ("requested x",),
    "requested_y": ("requested y",),
    "requested_z": ("requested z",),
    "snap_distance": ("snap distance",),
}


_REQUIRED = ("x", "y", "z")

#: Columns that, all three in one header, are a colour: its ``r`` is red (0 to 255 in a
#: coloured point list, as CloudCompare and MeshLab write ``X,Y,Z,R,G,B``), not a radius.
_COLOUR = ("r", "g", "b")


#: The largest ``Break #`` (Blender stores it as a 32-bit signed integer).
MAX_BREAK_NUMBER = 2**31 - 1


def break_number_cell(raw: str) -> int | str | None:
    """The break number of a cell, ``None`` when blank, or why it is not one (a str)."""
    text = raw.strip()
    if not text:
        return None
    number = whole_cell(text)  # "2.0" too, as a table tool re-saves a column with blanks
    if number is not None and 1 <= number <= MAX_BREAK_NUMBER:
        return number
    return f"must be a whole number from 1 to {MAX_BREAK_NUMBER} (got {text!r})"


def _lenient_number(raw: str) -> int | float | None:
    text = raw.strip()
    if INTEGER.fullmatch(text):
        return int(text)
    if NUMBER.fullmatch(text):
        value = float(text)
        return value if math.isfinite(value) else None
    return None


def _parse_name(raw: str) -> str | None:
    """A mesh name or a note as written, surrounding spaces kept (a file " lead.ply" is the
    mesh " lead"; a note is re-recorded as it was); ``None`` when blank."""
    return text_cell(raw) if raw.strip() else None


def _aliases(header: list[str]) -> dict:
    """The reader's aliases for this header: without ``r`` for the radius where the header
    also has ``g`` and ``b`` (a colour's red, which taken as the radius would measure every row
    with a patch as wide as its red value)."""
    names = {normalise(name) for name in header}
    if not set(_COLOUR) <= names:
        return _REPLICATION_ALIASES
    radius = tuple(a for a in _REPLICATION_ALIASES["radius"] if a not in _COLOUR)
    return {**_REPLICATION_ALIASES, "radius": radius}


#: Fields that decide what is measured and where. A header that names one of them twice, by two
#: of its aliases (``lambda`` and ``SegParam``), is refused: the first alias would be measured
#: and the other column ignored without a word.
_SETTINGS = {
    "mesh_name": "mesh name",  # the mesh a row is measured on
    "edge_number": "edge number",  # a station of an edge, or a measurement of its own
    "x": "x",
    "y": "y",
    "z": "z",
    "radius": "radius",
    "lam": "λ (SegParam)",
    "patch": "patch mode",
    "rule": "rule",
    "coordinates": "coordinate space",
    "units": "units",
    "spacing": "spacing",
}


def _settings_named_twice(header: list[str], aliases: dict) -> list[str]:
    """A problem for each setting the header gives in two differently named columns."""
    names = [normalise(name) for name in header]
    problems = []
    for field, words in _SETTINGS.items():
        found = [i for i, name in enumerate(names) if name in aliases[field]]
        if len({names[i] for i in found}) > 1:
            listed = " and ".join(f"{i + 1} ({header[i].strip()!r})" for i in found)
            problems.append(
                f"header: columns {listed} both give the {words} of each row, and only one "
                "would be used; keep one of them"
            )
    return problems


#: What may follow a setting's name in a column that holds that setting: a unit, a symbol or
#: an annotation in brackets ("Radius (mm)", "Lambda λ", "radius_mm"), or only punctuation.
_ANNOTATION = re.compile(r"[(\[{<].*|mm|cm|m|µm|μm|um|nm|in|inch|inches|ft|deg|degrees|°|λ|units?|")


def _settings_not_read(header: list[str], columns: dict, aliases: dict) -> list[str]:
    """A problem for each column the reader does not take whose name is a setting's name with
    a unit or an annotation ("Radius (mm)", "Lambda λ"): its values would be passed over
    without a word, and every row measured with the default instead. Other names that merely
    start like a setting's ("Break Type", "Radius 2") are passed over, as any column is."""
    taken = set(columns.values()) | {
        index  # a second name of a setting: _settings_named_twice says so
        for index, name in enumerate(header)
        if any(normalise(name) in names for names in aliases.values())
    }
    fields = (*_SETTINGS, "break_number")
    starts = sorted(
        ((alias, field) for field in fields for alias in aliases[field] if len(alias) >= 3),
        key=lambda pair: -len(pair[0]),
    )
    problems = []
    for index, raw in enumerate(header):
        name = normalise(raw)
        if index in taken:
            continue
        for alias, field in starts:
            rest = name[len(alias) :].strip(" -:.,;=*")
            if (
                name.startswith(alias)
                and not name[len(alias)].isalnum()
                and _ANNOTATION.fullmatch(rest)
            ):
                words = _SETTINGS.get(field, "break number")
                problems.append(
                    f"header: column {index + 1} ({raw.strip()!r}) would not be read: names are "
                    f"matched whole, so its values are not taken as the {words} of each row "
                    f"(rename it {aliases[field][0]!r}, as in the CSV docs, or remove it)"
                )
                break
    return problems


def default_coordinates(header: list[str]) -> str:
    """The coordinate space of a row whose ``Coordinates`` cell is blank or absent, in a file
    with this header: ``"world"`` in this extension's exports (it wrote world coordinates until
    it wrote the column), ``"mesh"`` in every other file."""
    return WORLD_COORDINATES if _source_format(header) == "extension" else MESH_COORDINATES


def _source_format(header: list[str]) -> str:
    names = [normalise(name) for name in header]
    if names[: len(MESHLAB_COLUMNS)] == [normalise(c) for c in MESHLAB_COLUMNS]:
        ours = {normalise(c) for c in EXPORT_COLUMNS[len(MESHLAB_COLUMNS) :]}
        return "extension" if ours & set(names) else "meshlab"
    return "points"


def parse_replication_csv(
    text: str, source: str = "The CSV text", passed_over: list | None = None
) -> list[ReplicationRow]:
    """Parse CSV text into replication rows; see :func:`read_replication_csv`.

    ``source`` names the text in error messages (e.g. ``"'points.csv'"``).
    """
    records = read_records(text, source)
    header_at, header = header_of(records, source)
    problems: list[str] = []
    aliases = _aliases(header)
    columns = resolve_columns(header, aliases, problems)
    problems += _settings_named_twice(header, aliases)
    problems += _settings_not_read(header, columns, aliases)
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
        raise problems_error(source, problems)

    fmt = _source_format(header)
    blank_space = default_coordinates(header)
    width = len(header)
    data = [(number, cells) for number, cells in records[header_at + 1 :] if not is_blank(cells)]
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
        if not is_blank(extra):
            problems.append(
                f"row {number}: {len(cells)} cells but the header has {width} columns (a comma "
                "inside an unquoted name or note, or a decimal comma?)"
            )
            continue
        if cell("error").strip() and all(not cell(f).strip() for f in _REQUIRED):
            skipped += 1
            if passed_over is not None:
                passed_over.append(number)
            continue
        values: dict[str, float | None] = {}
        for field in ("x", "y", "z", "radius", "lam", "arc_length", "spacing"):
            raw = cell(field)
            if not raw.strip():
                values[field] = None
                if field in _REQUIRED:
                    problems.append(f"row {number}: {name_of(field)} is empty")
                continue
            value, why = number_cell(raw)
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
        requested = _requested_cells([cell(f"requested_{axis}") for axis in "xyz"])
        if requested is not None and not _snaps_to(requested, values, cell("snap_distance")):
            requested = None
        edge_closed, why = flag_cell(cell("edge_closed"))
        if why:
            problems.append(f"row {number}: {name_of('edge_closed')} {why}")
        break_number = break_number_cell(cell("break_number"))
        if isinstance(break_number, str):
            problems.append(f"row {number}: {name_of('break_number')} {break_number}")
        patch = optional_text(cell("patch"))
        if patch is not None:
            patch = patch.casefold()
            if patch not in PATCH_MODES:
                problems.append(
                    f"row {number}: unknown patch mode {cell('patch').strip()!r} "
                    f"(use {' or '.join(PATCH_MODES)})"
                )
        coordinates = optional_text(cell("coordinates"))
        if coordinates is None:
            coordinates = blank_space
        coordinates = coordinates.casefold()
        if coordinates not in COORDINATE_SPACES:
            problems.append(
                f"row {number}: unknown coordinates {cell('coordinates').strip()!r} "
                f"(use {' or '.join(COORDINATE_SPACES)})"
            )
        rule = optional_text(cell("rule"))
        if rule is not None:
            rule = rule.casefold()
            if rule not in RULES:
                problems.append(
                    f"row {number}: unknown rule {cell('rule').strip()!r} (use {' or '.join(RULES)})"
                )
        elif fmt != "points" and not (
            "rule" in columns and "convexity" in columns and not cell("convexity").strip()
        ):
            # MeshLab, the earlier add-on, exports from before the Rule column, and a measured
            # row whose Rule was emptied; a row never measured (a batch run's failed row, from
            # before it kept its Rule) takes the default, as the run that wrote it did.
            rule = "paper"
        if problems:
            continue  # nothing is returned anyway; keep collecting
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
                label=_parse_name(cell("label")),
                number=_lenient_number(cell("number")),
                break_number=break_number,
                edge_number=whole_cell(cell("edge_number").strip()),
                arc_length=values["arc_length"],
                spacing=values["spacing"],
                edge_closed=edge_closed,
                source_format=fmt,
                coordinates=coordinates,
                rule=rule,
                units=optional_text(cell("units")),
                requested=requested,
            )
        )
    if problems:
        raise problems_error(source, problems)
    if not rows:
        raise GoniometerError(
            f"{source} has no rows to replicate: all {skipped} data row(s) are failed rows "
            "(their error column is filled and they have no coordinates)."
        )
    return rows


def read_from_export(rows: list[ReplicationRow]) -> bool:
    """Whether ``rows`` (as :func:`read_replication_csv` returns them) come from a file whose
    header is this extension's export, so that its angles can be compared with the new ones."""
    return bool(rows) and rows[0].source_format == "extension"


def read_replication_csv(path_or_text, passed_over: list | None = None) -> list[ReplicationRow]:
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
    aliases: ``Mesh Name``/``Mesh``/``Object``; ``x``/``Center x``; ``Radius``/``r`` (not ``r``
    in a header that also has ``g`` and ``b``: that is a colour's red, and the rows then have no
    radius, as in a file without the column);
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
    are all blank (a batch run's failed rows; their row numbers are appended to
    ``passed_over``, if given, so the caller can say so). A failed row that has coordinates is
    kept.

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
    text, source = load(path_or_text)
    return parse_replication_csv(text, source, passed_over)


def _requested_cells(cells: list[str]) -> tuple[float, float, float] | None:
    """The ``Requested x/y/z`` cells as a point; ``None`` unless all three are finite numbers
    (they are where the original was asked for, not what is measured: a row without them asks
    for its x, y, z)."""
    values = [number_cell(raw) if raw.strip() else (None, "blank") for raw in cells]
    if any(why for _, why in values):
        return None
    return (values[0][0], values[1][0], values[2][0])


def _snaps_to(requested, values: dict, snap_cell: str) -> bool:
    """Whether the row's ``Snap Distance`` is the distance from ``requested`` to its x, y, z, as
    the export wrote them (to a part in a million)."""
    snap, why = number_cell(snap_cell) if snap_cell.strip() else (None, "blank")
    if why or None in (values["x"], values["y"], values["z"]):
        return False
    distance = math.dist(requested, (values["x"], values["y"], values["z"]))
    return math.isfinite(distance) and abs(distance - snap) <= 1e-6 * max(distance, snap, 1e-300)
