"""The radius-sweep CSV: one row per radius of a sweep, refused radii with their message."""

from __future__ import annotations

import os
from collections.abc import Iterable, Sequence

from ...errors import GoniometerError
from ..files import replace_atomically
from .text import csv_line, escape_text, float_cell, header_of, load, normalise, read_records

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
    "Units",
)


def sweep_cells(mesh_name: str, number: int | None, point, units: str = "") -> list[str]:
    """The cells of one :data:`SWEEP_COLUMNS` row for a ``vg_addon.method.sweep.SweepPoint``.

    A refused radius keeps its radius and message; its measured cells are empty. ``units``
    says what one coordinate unit is (the Units cell of the measurement CSV: the radius and
    x, y, z are in the mesh's coordinates).
    """
    m = point.measurement

    def cell(value, column):
        return float_cell(value, 0, point, column)

    cells = [escape_text(str(mesh_name)), "" if number is None else str(int(number))]
    cells.append(cell(point.radius, "Radius"))
    if m is None:
        cells += [""] * (len(SWEEP_COLUMNS) - 5)
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
    cells.append(escape_text(point.error))
    cells.append(escape_text(units))
    return cells


def format_sweep_rows(rows: Iterable[Sequence[str]]) -> str:
    """A sweep CSV's text: the :data:`SWEEP_COLUMNS` header, then rows from :func:`sweep_cells`."""
    return csv_line(SWEEP_COLUMNS) + "".join(csv_line(cells) for cells in rows)


def write_sweep_csv(
    path, mesh_name: str, points, number: int | None = None, units: str = ""
) -> None:
    """Write one site's sweep to ``path`` atomically (as :func:`write_measurements_csv`)."""
    text = format_sweep_rows(sweep_cells(mesh_name, number, point, units) for point in points)
    replace_atomically(os.fspath(path), text.encode("utf-8"))


def holds_sweep(path) -> bool:
    """Whether the file ``path`` is a radius-sweep CSV (its header begins with
    :data:`SWEEP_COLUMNS`; files written before the ``Units`` column count too). Any other file
    of that name is not a sweep's to empty."""
    if not os.path.isfile(path):
        return False
    try:
        text, source = load(path)
        _, header = header_of(read_records(text, source), source)
    except (OSError, GoniometerError):
        return False
    names = [normalise(name) for name in header]
    earliest = [normalise(column) for column in SWEEP_COLUMNS[:-1]]
    return names[: len(earliest)] == earliest
