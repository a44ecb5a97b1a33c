"""How the angles of a re-measured CSV agree with the angles the file holds: the words an import
(Blender's) or a batch run adds to its report, so that a replication that did not come back
exactly never passes unnoticed.

A re-measurement with the same coordinates, settings and NumPy gives the same bits. Where it
does not, the usual reason is one the file states: the row was measured at another precision
(``Precision``: a batch run measures a mesh file at its float64 coordinates where float32 would
round them, and Blender holds every mesh as float32), or the row was ``Stale`` (recorded
before the mesh was edited), so today's mesh is another surface.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

from .batchplan import STOPPED_EDGE


@dataclasses.dataclass(frozen=True)
class Agreement:
    """How re-measured angles agree with a file's.

    Attributes
    ----------
    compared : int
        Rows whose file angle was compared with the re-measured one.
    differing : int
        Of those, rows whose angles are not the same float64.
    largest : float
        The largest absolute difference in degrees (0.0 when none differ).
    other_precision : int
        Differing rows re-measured at another precision than the file says they were.
    stale : int
        Rows not compared: the file marks them Stale.
    no_rule : int
        Differing rows (at the file's precision) with no Rule though their file is of a version
        that records it (their Convexity is filled: the Rule column was deleted or emptied):
        they were measured with the paper's rule, as rows without a rule are.
    """

    compared: int
    differing: int
    largest: float
    other_precision: int
    stale: int
    no_rule: int = 0

    @property
    def text(self) -> str:
        """What a report adds ("" with nothing compared or passed over), each part starting
        with "; "."""
        parts = []
        if self.compared and not self.differing:
            parts.append(f"all {self.compared} angles equal the file's exactly")
        elif self.differing:
            why = []
            if self.other_precision:
                why.append(
                    f"{self.other_precision} measured at another precision than the file's "
                    "(a batch run measures a mesh file's float64 coordinates, Blender its "
                    "float32 vertices): only the same precision replicates them exactly"
                )
            if self.no_rule:
                why.append(
                    f"{self.no_rule} without a Rule in a file of a version that records it, so "
                    "measured with the paper's rule, as rows without one are (a Rule column "
                    "names another)"
                )
            if self.differing > self.other_precision + self.no_rule:
                why.append(
                    f"{self.differing - self.other_precision - self.no_rule} on a mesh or with a "
                    "version other than the file's"
                )
            parts.append(
                f"{self.differing} of {self.compared} angles differ from the file's, by up to "
                f"{self.largest:.2g}° ({'; '.join(why)})"
            )
        if self.stale:
            parts.append(
                f"{self.stale} row(s) marked Stale (measured before the mesh was edited) not "
                "compared"
            )
        return "".join(f"; {part}" for part in parts)


def not_compared(error: Exception) -> str:
    """What a report adds ("; ...") where a file whose header has columns of this extension's
    export could not be read back as one (``error``, from ``csvio.read_measurements_csv``: a cell a
    spreadsheet re-saved, ``FALSCH`` for ``FALSE``, or a column deleted), so its angles were
    not compared: said, with the first problem, instead of passed over."""
    lines = [line.strip() for line in str(error).splitlines() if line.strip()]
    problem = lines[1] if len(lines) > 1 else (lines[0] if lines else type(error).__name__)
    return (
        "; its angles were not compared with the file's: its header has columns of this "
        f"extension's export, but the file does not read back as one ({problem})"
    )


def agreement(
    recorded: Sequence[float | None],
    remeasured: Sequence[float | None],
    file_precisions: Sequence[str],
    precisions: Sequence[str],
    stale: Sequence[bool],
    rule_missing: Sequence[bool] | None = None,
) -> Agreement:
    """Compare a file's angles with the same rows re-measured.

    Parameters
    ----------
    recorded : sequence of float or None
        Each row's angle as the file holds it (None: the file gives none; not compared).
    remeasured : sequence of float or None
        The angle measured again for each row (None: it could not be; not compared).
    file_precisions, precisions : sequence of str
        Each row's ``Precision`` in the file and in the re-measurement (``"float32"``,
        ``"float64"``, or empty where not known).
    stale : sequence of bool
        Each row's ``Stale`` cell in the file.
    rule_missing : sequence of bool, optional
        Each row: its file is of a version that records the rule, but its ``Rule`` is empty.

    Returns
    -------
    Agreement
    """
    compared = differing = other_precision = passed_over = no_rule = 0
    largest = 0.0
    missing = [False] * len(recorded) if rule_missing is None else rule_missing
    rows = zip(recorded, remeasured, file_precisions, precisions, stale, missing, strict=True)
    for old, new, old_precision, new_precision, was_stale, no_rule_here in rows:
        if was_stale:
            passed_over += 1
            continue
        if old is None or new is None or not (math.isfinite(old) and math.isfinite(new)):
            continue
        compared += 1
        if old != new:
            differing += 1
            precision_differs = (
                bool(old_precision and new_precision) and new_precision != old_precision
            )
            other_precision += precision_differs
            no_rule += bool(no_rule_here) and not precision_differs
            largest = max(largest, abs(new - old))
    return Agreement(compared, differing, largest, other_precision, passed_over, no_rule)


def agreement_of_rows(file_rows: Sequence, remeasured: Sequence, precisions: Sequence[str]):
    """:func:`agreement` of a file's rows (``csvio.MeasurementRow``: their angles, precisions
    and Stale cells) with the angles and precisions of the same rows re-measured."""
    return agreement(
        [row.angle for row in file_rows],
        remeasured,
        [row.precision for row in file_rows],
        precisions,
        [row.stale for row in file_rows],
        [not row.rule.strip() and bool(row.convexity.strip()) for row in file_rows],
    )


EDGE_FIGURES = (
    ("n_stations", "stations"),
    ("mean", "mean"),
    ("min", "min"),
    ("max", "max"),
    ("pooled_angle", "pooled angle"),
)
"""The figures of an edge summary row compared after a replay (field, as said), in order."""

LISTED_EDGES = 5
"""How many differing edges a report names; the rest are counted."""


def _figure_texts(field: str, old, new) -> tuple[str, str]:
    """The two values as said: four decimals, or every digit where four would read the same."""
    if new is None:
        return _figure_texts(field, old, old)[0], "none"
    if field == "n_stations":
        return f"{old:d}", f"{new:d}"
    texts = f"{old:.4f}°", f"{new:.4f}°"
    return texts if texts[0] != texts[1] else (f"{old!r}°", f"{new!r}°")


@dataclasses.dataclass(frozen=True)
class EdgeAgreement:
    """How re-measured edges agree with an edge summary file's rows.

    Attributes
    ----------
    compared : int
        Rows whose edge was measured again and whose figures were compared.
    differing : list of str
        For each compared row whose figures (:data:`EDGE_FIGURES`) are not the same numbers,
        the row and what changed, e.g. ``"row 3: mean 95.3100° → 95.4200°"``.
    stale : int
        Rows the file marks Stale (measured before the mesh was edited): not compared.
    blank : int
        Rows without figures in the file (an edge the run that wrote it could not measure,
        its error cleared to try again): measured, not compared.
    failed : int
        Rows whose edge could not be measured again (the replay's error says why).
    stopped : int
        Rows whose edge the replay was stopped before (not measured again, not failed).
    """

    compared: int
    differing: list
    stale: int = 0
    blank: int = 0
    failed: int = 0
    stopped: int = 0

    @property
    def text(self) -> str:
        """What a report adds ("" with nothing compared or passed over), each part starting
        with "; "."""
        parts = []
        if self.compared == 1 and not self.differing:
            parts.append(
                "its edge's stations, mean, min, max and pooled angle equal the file's exactly"
            )
        elif self.compared and not self.differing:
            parts.append(
                f"all {self.compared} edges' stations, mean, min, max and pooled angle equal "
                "the file's exactly"
            )
        elif self.differing:
            listed = "; ".join(self.differing[:LISTED_EDGES])
            more = len(self.differing) - LISTED_EDGES
            listed += f"; and {more} more" if more > 0 else ""
            parts.append(
                f"{len(self.differing)} of {self.compared} edges differ from the file's figures "
                f"({listed}): measured at another precision (Blender holds float32 vertices, a "
                "batch run reads a mesh file's float64 coordinates), on an edited mesh, or with "
                "another version or rule"
            )
        if self.failed:
            parts.append(f"{self.failed} edge(s) could not be measured again (see their error)")
        if self.stopped:
            parts.append(f"{self.stopped} edge(s) not measured again: the run was stopped first")
        if self.blank:
            parts.append(
                f"{self.blank} row(s) without figures in the file (not measured when it was "
                "written) not compared"
            )
        if self.stale:
            parts.append(
                f"{self.stale} edge(s) marked Stale (measured before the mesh was edited) not "
                "compared"
            )
        return "".join(f"; {part}" for part in parts)


def edge_agreement(file_rows: Sequence, remeasured: Sequence) -> EdgeAgreement:
    """Compare an edge summary file's rows (``csvio.EdgeRow``) with the summary rows of the
    edges measured again from them.

    Each re-measured row carries the ``row_number`` of the file row it was measured from (a
    replay numbers its edges afresh, and may have moved its points into the mesh's
    coordinates); re-measured rows without one (edges given otherwise) are left out, as are
    file rows with an ``error`` (never measured, not measured again).
    """
    replayed = {row.row_number: row for row in remeasured if row.row_number is not None}
    compared, differing, stale, blank, failed, stopped = 0, [], 0, 0, 0, 0
    for old in file_rows:
        new = replayed.get(old.row_number)
        if old.error or new is None:
            continue
        if new.error:
            if STOPPED_EDGE in new.error:
                stopped += 1
            else:
                failed += 1
            continue
        if old.stale:
            stale += 1
            continue
        if all(getattr(old, field) is None for field, _ in EDGE_FIGURES):
            blank += 1
            continue
        compared += 1
        changes = []
        for field, said in EDGE_FIGURES:
            before, after = getattr(old, field), getattr(new, field)
            if before is not None and before != after:
                was, now = _figure_texts(field, before, after)
                changes.append(f"{said} {was} → {now}")
        if changes:
            differing.append(f"row {old.row_number}: {', '.join(changes)}")
    return EdgeAgreement(compared, differing, stale, blank, failed, stopped)
