"""An export's two files together: the measurement CSV and the edge summary beside it.

They are one record. The summary is written whenever there are edges, and also when there are
none but an earlier edge summary lies beside the CSV (it is emptied to its header: otherwise it
would list edges the new CSV no longer has, and importing it would bring them back). Both targets
are checked before either is written, so a summary that cannot be written leaves the CSV as it
was.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

from ...errors import GoniometerError
from ..files import output_target, replace_atomically
from .edges import EdgeRow, edges_path_for, format_edges_csv, is_edges_csv
from .measurements import MeasurementRow, format_measurements_csv

#: :func:`_summary_place`'s words for a place the export may write its summary into.
_EMPTY, _SUMMARY = "empty", "summary"


def _summary_place(path) -> str:
    """What the file at ``path`` is to an export: ``_EMPTY`` (none there, or nothing but blanks
    and a byte-order mark), ``_SUMMARY`` (an edge summary an earlier export wrote), or why it is
    not an edge summary the export may replace."""
    if not os.path.isfile(path):
        return _EMPTY
    try:
        with open(path, "rb") as handle:
            start = handle.read(4096)
    except OSError as error:
        return error.strerror or str(error)
    if not start.removeprefix(b"\xef\xbb\xbf").strip():
        return _EMPTY
    try:
        return _SUMMARY if is_edges_csv(path) else "its header lacks Edge #, Points and Spacing"
    except (OSError, GoniometerError) as error:
        return str(error).split("\n")[0].split(". ")[0]  # what it is, not the advice


def holds_edge_summary(path) -> bool:
    """Whether ``path`` holds an edge summary an earlier export wrote. Any other file of that
    name (a points list, the user's notes) is not this export's to empty."""
    return _summary_place(path) == _SUMMARY


class SummaryWriteError(GoniometerError):
    """The measurement CSV was written, its edge summary was not (the message names both).

    ``summary_path`` is where the summary belongs, ``summary_text`` what it should hold (so a
    caller can keep it elsewhere), ``cause`` why it could not be written.
    """

    def __init__(self, message, *, summary_path, summary_text, cause):
        super().__init__(message)
        self.summary_path = summary_path
        self.summary_text = summary_text
        self.cause = cause


def write_export(
    path,
    rows: Sequence[MeasurementRow],
    edge_rows: Sequence[EdgeRow],
    *,
    lines=None,
    summary: bool = False,
) -> Path | None:
    """Write the measurement CSV ``path`` and its edge summary (:func:`edges_path_for`).

    Parameters
    ----------
    path : str or PathLike
        The measurement CSV.
    rows, edge_rows
        The station and measurement rows, and one row per edge profile (may be empty).
    lines : dict, optional
        As for :func:`write_measurements_csv`.
    summary : bool
        Write the edge summary even with no edges and none there before (a run that looked for
        edges says so with an empty one).

    Returns
    -------
    Path or None
        The edge summary written: with ``edge_rows``, or emptied to its header where an earlier
        one was there; None when there was none to write.

    Raises
    ------
    SummaryWriteError
        The summary failed after the CSV was written (a :class:`GoniometerError`).
    GoniometerError
        Either target cannot be written, or the summary's place holds a file that is not an
        edge summary (checked before anything is written).
    OSError
        The CSV itself could not be written (nothing was).
    """
    edges_path = edges_path_for(path)
    csv_text = format_measurements_csv(rows, lines=lines).encode("utf-8")
    is_file = output_target(path) == "file"
    place = _summary_place(edges_path) if is_file else _EMPTY  # read once
    with_edges = bool(edge_rows) or summary or place == _SUMMARY
    edges_text = format_edges_csv(edge_rows).encode("utf-8") if with_edges else b""
    if with_edges:
        output_target(edges_path)
        if place not in (_EMPTY, _SUMMARY):
            raise GoniometerError(
                f"{edges_path}, where the edge summary goes, holds a file this extension does "
                f"not read as its edge summary ({place}): it is left alone, and nothing was "
                "written. Move it, or write the CSV under another name."
            )
    replace_atomically(path, csv_text)
    if not with_edges:
        return None
    try:
        replace_atomically(edges_path, edges_text)
    except (OSError, GoniometerError) as error:
        raise SummaryWriteError(
            f"{os.fspath(path)} was written, but its edge summary {edges_path} was not ({error}): "
            "the two no longer match; write the export again once that file can be replaced.",
            summary_path=edges_path,
            summary_text=edges_text,
            cause=error,
        ) from error
    return edges_path
