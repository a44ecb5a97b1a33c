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
            precision_differs = bool(old_precision and new_precision != old_precision)
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


def _figure_text(field: str, value) -> str:
    if value is None:
        return "none"
    return f"{value:d}" if field == "n_stations" else f"{value:.4f}°"


@dataclasses.dataclass(frozen=True)
class EdgeAgreement:
    """How re-measured edges agree with an edge summary file's rows.

    Attributes
    ----------
    compared : int
        Edges of the file that were measured again (matched by their ``Points``).
    differing : list of str
        For each compared edge whose figures (:data:`EDGE_FIGURES`) are not the same numbers,
        its row and what changed, e.g. ``"row 3: mean 95.3100° → 95.4200°"``.
    stale : int
        Edges the file marks Stale (measured before the mesh was edited): not compared.
    """

    compared: int
    differing: list
    stale: int

    @property
    def text(self) -> str:
        """What a report adds ("" with nothing compared or passed over), each part starting
        with "; "."""
        parts = []
        if self.compared and not self.differing:
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
                f"({listed}): a batch run measures a mesh file's float64 coordinates where "
                "Blender measured its float32 vertices, and another mesh, version or rule reads "
                "other stations"
            )
        if self.stale:
            parts.append(
                f"{self.stale} edge(s) marked Stale (measured before the mesh was edited) not "
                "compared"
            )
        return "".join(f"; {part}" for part in parts)


def edge_agreement(file_rows: Sequence, remeasured: Sequence) -> EdgeAgreement:
    """Compare an edge summary file's rows (``csvio.EdgeRow``) with the summary rows of the
    edges measured again from it.

    A replay numbers its edges afresh, so each row is matched by its ``Points``: to the
    re-measured edges through the same points on a mesh of the row's ``Mesh Name``, or, where
    none has that name (a mesh matched by a close name, or ``--ignore-mesh-names``), to every
    re-measured edge through them. File rows with an ``error`` (never measured) and re-measured
    edges that match no row are left out.
    """
    replayed = {}
    for row in remeasured:
        replayed.setdefault(row.points.strip(), []).append(row)
    compared, stale, differing = 0, 0, []
    for old in file_rows:
        candidates = replayed.get(old.points.strip(), [])
        if old.error or not candidates:
            continue
        if old.stale:
            stale += 1
            continue
        named = [row for row in candidates if row.mesh_name == old.mesh_name]
        for new in named or candidates:
            compared += 1
            changes = [
                f"{said} {_figure_text(field, getattr(old, field))} → "
                f"{_figure_text(field, getattr(new, field))}"
                for field, said in EDGE_FIGURES
                if getattr(old, field) != getattr(new, field)
            ]
            if changes:
                where = f"row {old.row_number}" if old.row_number else f"edge {old.edge_number}"
                on = "" if new.mesh_name == old.mesh_name else f" on {new.mesh_name!r}"
                differing.append(f"{where}{on}: {', '.join(changes)}")
    return EdgeAgreement(compared, differing, stale)
