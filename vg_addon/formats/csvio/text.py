"""The CSV text every file of this package is written in and read from: one dialect, one place.

Writing: UTF-8, comma-delimited, ``\\n`` line ends, cells quoted as RFC 4180 asks
(:func:`csv_line`), floats as ``repr`` (the shortest text that reads back to the same float64,
bit for bit), text cells protected against spreadsheet formula injection (:func:`escape_text`),
a row's cells from its schema (:func:`row_cells`). Reading: bytes or a path or the text itself
(:func:`load`), checked as a whole before any cell is judged (:func:`read_records`: UTF-8, a
comma delimiter, quotes closed where they should be), header names matched case-, space- and
``_``-insensitively (:func:`resolve_columns`), cells parsed with reasons for what is not a value
(:func:`number_cell`, :func:`text_cell`), a schema's rows read back (:func:`parse_table`), and
any other table (:func:`read_table`, :func:`format_table`).

A schema is a tuple of ``(row field, kind, CSV columns)`` in column order; kinds are ``text``,
``int``, ``float``, ``bool``, ``flag`` (a ``bool`` that may be left empty, for "not known")
and ``vec3`` (three float columns).

Row numbers in messages are the rows a spreadsheet shows for the file: the header is row 1, so
the first data row is row 2. Blank lines count as rows (a spreadsheet shows them as empty rows);
a quoted cell that spans lines stays one row.
"""

from __future__ import annotations

import contextlib
import csv
import dataclasses
import decimal
import io
import math
import operator
import os
import re
import threading
from collections.abc import Iterable, Sequence
from pathlib import Path

from ...errors import GoniometerError, bounded_list
from ..files import replace_atomically

#: The values of the ``Coordinates`` column: the mesh's own coordinates (object space, those of
#: the file the scan came from) and, in exports of versions before it existed, world space.
MESH_COORDINATES = "mesh"


WORLD_COORDINATES = "world"


COORDINATE_SPACES = (MESH_COORDINATES, WORLD_COORDINATES)


# What a missing column of the LATER_COLUMNS means (others: an empty cell).
_LEGACY_DEFAULTS = {"Coordinates": WORLD_COORDINATES}


_TRUE = "TRUE"


_FALSE = "FALSE"


# Leading characters that make a spreadsheet treat a cell as a formula (OWASP's list). The
# apostrophe is included so that escaping is reversible: a text that starts with one is
# escaped too, and the reader removes exactly one.
_FORMULA_START = ("=", "+", "-", "@", "\t", "\r", "'")


NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")


# At most 18 digits: every such integer fits 64 bits, and int() never meets Python's limit on
# the length of integer text.
INTEGER = re.compile(r"[+-]?\d{1,18}")


# Header aliases of the coordinate columns, normalised (case-folded, "_" as space, whitespace
# collapsed): what every reader takes as x, y and z.
XYZ_ALIASES = {
    "x": ("x", "center x", "centre x"),
    "y": ("y", "center y", "centre y"),
    "z": ("z", "center z", "centre z"),
}


# --------------------------------------------------------------------------- writing


def escape_text(text: str) -> str:
    """Prefix an apostrophe to text a spreadsheet would run as a formula."""
    return "'" + text if text.startswith(_FORMULA_START) else text


def text_cell(text: str) -> str:
    """A text cell read back: :func:`escape_text` undone (the spreadsheet apostrophe removed);
    other leading apostrophes (e.g. in foreign files) stay."""
    if len(text) > 1 and text[0] == "'" and text[1] in _FORMULA_START:
        return text[1:]
    return text


def _cell_error(index: int, row, column: str, value, need: str) -> GoniometerError:
    name = getattr(row, "mesh_name", "")
    return GoniometerError(
        f"Cannot write measurement {index + 1} (mesh {name!r}): {column} is {value!r}, "
        f"not {need}. Nothing was written."
    )


def float_cell(value, index, row, column) -> str:
    if value is None:
        return ""
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise _cell_error(index, row, column, value, "a number") from None
    if not math.isfinite(number):
        raise _cell_error(index, row, column, value, "a finite number")
    return repr(number)


def row_cells(index: int, row, schema) -> list[str]:
    """The cells of ``row`` by ``schema``; ``index`` (from 0) names the row in errors."""
    cells = []
    for field, kind, columns in schema:
        value = getattr(row, field)
        if kind in ("text", "space"):
            text = "" if value is None else str(value)
            if not is_utf8(text):
                raise _cell_error(index, row, columns[0], value, "text UTF-8 can hold")
            cells.append(escape_text(text))
        elif kind == "float":
            cells.append(float_cell(value, index, row, columns[0]))
        elif kind == "int":
            if value is None:
                cells.append("")
            else:
                try:
                    cells.append(str(operator.index(value)))
                except TypeError:
                    raise _cell_error(index, row, columns[0], value, "a whole number") from None
        elif kind in ("bool", "flag"):
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
                float_cell(part, index, row, column)
                for part, column in zip(parts, columns, strict=True)
            )
    return cells


def is_utf8(text: str) -> bool:
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:  # a lone surrogate, e.g. from a file name that is not UTF-8
        return False
    return True


def as_utf8(text: str) -> str:
    """``text`` with what UTF-8 cannot hold replaced: a file name's undecodable bytes (Python's
    surrogate escapes) by U+FFFD, as a file manager shows them."""
    try:
        return text.encode("utf-8", "surrogateescape").decode("utf-8", "replace")
    except UnicodeEncodeError:
        return text.encode("utf-8", "replace").decode("utf-8")


def csv_line(cells: Iterable[str]) -> str:
    # csv.writer on Python 3.11 leaves a lone "\r" unquoted when lines end in "\n", which
    # splits the row for every reader; quote by hand (RFC 4180).
    quoted = (
        '"' + cell.replace('"', '""') + '"' if any(c in cell for c in ',"\r\n') else cell
        for cell in cells
    )
    return ",".join(quoted) + "\n"


# --------------------------------------------------------------------------- reading


def load(path_or_text) -> tuple[str, str]:
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


# Excel's hint of the delimiter, a first line it writes and hides ("sep=,"): not a record.
_EXCEL_SEPARATOR = re.compile(r'"?sep=.?"?', re.IGNORECASE)


_CAP_LOCK = threading.Lock()


def read_records(text: str, source: str) -> list[tuple[int, list[str]]]:
    """Every record with its spreadsheet row number, after the BOM and delimiter checks (an
    Excel ``sep=`` first line is dropped, and not counted: Excel does not show it)."""
    if text.startswith("\ufeff"):
        text = text[1:]
    first, newline, rest = text.partition("\n")
    if newline and _EXCEL_SEPARATOR.fullmatch(first.rstrip("\r")):
        text = rest
    if not text.strip():
        raise GoniometerError(
            f"{source} is empty: it needs a header line (e.g. 'x,y,z,radius') and one row per "
            "measurement."
        )
    header_line = next(line for line in text.splitlines() if line.strip())
    _check_delimiter(header_line, source)
    # The csv module's default cap on a cell (131,072 characters) is below what an edge's Points
    # cell holds for a few thousand picked points; no cell is longer than the text. The cap is
    # the process's: one reader at a time lifts it and puts it back.
    with _CAP_LOCK:
        limit = csv.field_size_limit(max(csv.field_size_limit(), min(len(text) + 1, 2**31 - 1)))
        try:
            return _records(text, source)
        finally:
            csv.field_size_limit(limit)  # other code in Blender keeps its cap


def _records(text: str, source: str) -> list[tuple[int, list[str]]]:
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
            header = header or ([] if is_blank(cells) else cells)
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
    names = [normalise(cell) for cell in header]
    found = []
    for axis in ("x", "y", "z"):
        position = next((names.index(a) for a in XYZ_ALIASES[axis] if a in names), None)
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
    return len(cells) > max(columns) and all(number_cell(cells[k])[0] is not None for k in columns)


def is_blank(cells: Sequence[str]) -> bool:
    return all(not cell.strip() for cell in cells)


def normalise(header: str) -> str:
    return " ".join(header.replace("_", " ").casefold().split())


def problems_error(source: str, problems: list[str]) -> GoniometerError:
    return GoniometerError(
        f"{source} has {len(problems)} problem(s); nothing was read. Fix them and try again:\n"
        + bounded_list(problems, lines=True)
    )


def whole_cell(text: str) -> int | None:
    """A stripped cell as a whole number, ``None`` if it is not one. ``1.0`` is 1: a column with
    blanks that a table tool (pandas, R) re-saved holds its whole numbers as floats."""
    if INTEGER.fullmatch(text):
        return int(text)
    if NUMBER.fullmatch(text):
        value = float(text)
        if value.is_integer() and abs(value) <= 1e18:  # INTEGER's 18 digits, written any way
            # Exactly whole, not after rounding to a float ("0.99999999999999999" is not 1).
            with contextlib.suppress(decimal.InvalidOperation):  # exponents beyond its range
                exact = decimal.Decimal(text)
                if exact == exact.to_integral_value() and abs(exact) < 10**18:
                    return int(exact)
    return None


def number_cell(raw: str) -> tuple[float | None, str | None]:
    """A non-blank cell as a finite number: ``(value, None)``, or ``(None, why not)`` worded as
    this package's messages are (a decimal comma named as the cause)."""
    text = raw.strip()
    if NUMBER.fullmatch(text):
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
    if "," in text and NUMBER.fullmatch(text.replace(",", ".", 1)):
        hint = "; use a point as the decimal separator"
    return None, f"is not a number ({text!r}{hint})"


def optional_text(raw: str) -> str | None:
    text = raw.strip()
    return text_cell(text) if text else None


def bool_cell(raw: str) -> bool | None:
    text = raw.strip().casefold()
    if text in ("true", "yes", "1"):
        return True
    if text in ("false", "no", "0", ""):
        return False
    return None


def flag_cell(raw: str) -> tuple[bool | None, str]:
    """A cell that may be left empty: True, False or None (empty), and why it is none of
    them ("" when it is)."""
    if not raw.strip():
        return None, ""
    value = bool_cell(raw)
    return value, "" if value is not None else "is not TRUE or FALSE"


def space_cell(raw: str) -> tuple[str, str]:
    """A ``Coordinates`` cell: ``"mesh"`` or ``"world"`` in any case (empty: ``"world"``, as in
    files written before the column), and why it is neither ("" when it is one)."""
    value = raw.strip().casefold() or WORLD_COORDINATES
    if value in COORDINATE_SPACES:
        return value, ""
    return WORLD_COORDINATES, f"is {raw.strip()!r}, not {' or '.join(COORDINATE_SPACES)}"


def resolve_columns(header: list[str], aliases: dict, problems: list[str]) -> dict:
    """Field -> column index for the fields the header has; ambiguous names are problems."""
    positions: dict[str, list[int]] = {}
    for index, name in enumerate(header):
        positions.setdefault(normalise(name), []).append(index)
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


def header_of(records, source: str) -> tuple[int, list[str]]:
    for position, (_, cells) in enumerate(records):
        if not is_blank(cells):
            return position, cells
    raise GoniometerError(f"{source} is empty.")  # read_records already rejects blank text


def parse_table(text, source, schema, row_type, optional, what, check=None):
    """The rows of a table written by :func:`row_cells` with ``schema``, as ``row_type``.

    Every column of ``schema`` must be in the header (in any order; names matched as
    :func:`resolve_columns` does) except those in ``optional``, which files written before they
    existed lack; ``what`` names the file in that message. Text cells are kept as written (only
    the formula-guard apostrophe removed), numbers read back bit-identical, blank lines are
    skipped. ``check(values)``, if given, says what else is wrong with a row's values (or None).
    A ``row_type`` with a ``row_number`` field gets each row's spreadsheet row number there.

    Raises
    ------
    GoniometerError
        Listing every missing column and every cell that does not parse, with row numbers.
    """
    records = read_records(text, source)
    header_at, header = header_of(records, source)
    numbered = "row_number" in {f.name for f in dataclasses.fields(row_type)}
    problems: list[str] = []
    all_columns = [column for _, _, names in schema for column in names]
    aliases = {column: (normalise(column),) for column in all_columns}
    columns = resolve_columns(header, aliases, problems)
    missing = [c for c in all_columns if c not in columns and c not in optional]
    if missing:
        problems.insert(
            0,
            f"header: missing the column(s) {', '.join(missing)}; it is not {what} of this "
            "extension, or not a complete one",
        )
    if problems:
        raise problems_error(source, problems)

    rows = []
    for number, cells in records[header_at + 1 :]:
        if is_blank(cells):
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
            value, why = number_cell(raw)
            if why:
                problems.append(f"row {number}: {column} {why}")
            return value

        values = {}
        for field, kind, names in schema:
            if kind == "text":
                values[field] = text_cell(cell(names[0]))
            elif kind == "float":
                values[field] = number_of(names[0])
            elif kind == "int":
                raw = cell(names[0]).strip()
                values[field] = whole_cell(raw)
                if raw and values[field] is None:
                    problems.append(f"row {number}: {names[0]} is not a whole number ({raw!r})")
            elif kind == "bool":
                values[field] = bool_cell(cell(names[0]))
                if values[field] is None:
                    problems.append(f"row {number}: {names[0]} is not TRUE or FALSE")
            elif kind in ("flag", "space"):
                parse = flag_cell if kind == "flag" else space_cell
                values[field], why = parse(cell(names[0]))
                if why:
                    problems.append(f"row {number}: {names[0]} {why}")
            else:
                parts = [number_of(name) for name in names]
                blank = [not cell(name).strip() for name in names]
                values[field] = None if None in parts else tuple(parts)
                if any(blank) and not all(blank):
                    problems.append(
                        f"row {number}: {', '.join(names)} must be all filled or all empty"
                    )
        why = check(values) if check is not None else None
        if why:
            problems.append(f"row {number}: {why}")
        if numbered:
            values["row_number"] = number
        rows.append(row_type(**values))
    if problems:
        raise problems_error(source, problems)
    return rows


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
    text, source = load(path_or_text)
    records = read_records(text, source)
    header_at, header = header_of(records, source)
    return (
        source,
        header,
        [(n, cells) for n, cells in records[header_at + 1 :] if not is_blank(cells)],
    )


def header_columns(header: Sequence[str], aliases: dict) -> tuple[dict, list[str]]:
    """``(field -> column index, problems)`` for a header, its names matched as this module
    matches them (case, spaces and ``_`` ignored; the first alias found wins)."""
    problems: list[str] = []
    normalised = {field: tuple(normalise(a) for a in names) for field, names in aliases.items()}
    return resolve_columns(list(header), normalised, problems), problems


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
        return escape_text(str(value))

    lines = [csv_line(cell(h) for h in header)]
    lines += [csv_line(cell(value) for value in row) for row in rows]
    return "".join(lines)


def write_table(path, header: Sequence[str], rows: Iterable[Sequence]) -> None:
    """Write :func:`format_table`'s text to ``path`` atomically (the old file kept on failure)."""
    replace_atomically(path, format_table(header, rows).encode("utf-8"))
