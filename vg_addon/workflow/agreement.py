"""How the angles of a re-measured CSV agree with the angles the file holds: the words an import
adds to its report, so that a replication that did not come back exactly never passes unnoticed.

A re-measurement with the same coordinates, settings and NumPy gives the same bits. Where it
does not, the usual reason is one the file states: a batch run measured a mesh file at its
float64 precision (``Precision`` ``float64``), and Blender holds the vertices as float32; or the
row was ``Stale`` (recorded before the mesh was edited), so today's mesh is another surface.
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
    float64 : int
        Differing rows that the file says were measured at float64 precision.
    stale : int
        Rows not compared: the file marks them Stale.
    """

    compared: int
    differing: int
    largest: float
    float64: int
    stale: int

    @property
    def text(self) -> str:
        """What an import's report adds ("" with nothing compared or passed over), starting
        with "; "."""
        parts = []
        if self.compared and not self.differing:
            parts.append(f"all {self.compared} angles equal the file's exactly")
        elif self.differing:
            why = []
            if self.float64:
                why.append(
                    f"{self.float64} measured by a batch run at the mesh file's float64 "
                    "precision, which Blender's float32 vertices round: re-measure those with "
                    "the batch to replicate them exactly"
                )
            if self.differing > self.float64:
                why.append(
                    f"{self.differing - self.float64} on a mesh or with a version other than "
                    "the file's"
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
    remeasured: Sequence[float],
    precisions: Sequence[str],
    stale: Sequence[bool],
) -> Agreement:
    """Compare a file's angles with the same rows re-measured.

    Parameters
    ----------
    recorded : sequence of float or None
        Each row's angle as the file holds it (None: the file gives none; not compared).
    remeasured : sequence of float
        The angle measured again for each row.
    precisions : sequence of str
        Each row's ``Precision`` cell (``"float32"``, ``"float64"`` or empty).
    stale : sequence of bool
        Each row's ``Stale`` cell.

    Returns
    -------
    Agreement
    """
    compared = differing = in_float64 = passed_over = 0
    largest = 0.0
    for old, new, precision, was_stale in zip(recorded, remeasured, precisions, stale, strict=True):
        if old is None or not math.isfinite(old):
            continue
        if was_stale:
            passed_over += 1
            continue
        compared += 1
        if old != new:
            differing += 1
            in_float64 += precision == "float64"
            largest = max(largest, abs(new - old))
    return Agreement(compared, differing, largest, in_float64, passed_over)
