"""The summary's line on a replayed file: how its re-measured angles (``--points``) or edge
figures (``--edges``) agree with the figures the file holds (``workflow.agreement``)."""

from __future__ import annotations

from pathlib import Path

from ..vg_addon import GoniometerError
from ..vg_addon.formats import csvio
from ..vg_addon.workflow import agreement


def points_line(path: Path, replayed: int, export: bool, rows: dict) -> str:
    """The line for a ``--points`` file of ``replayed`` rows, re-measured as ``rows`` (task
    index -> output row); ``export``: its header is this extension's export. ``""`` where there
    is nothing to say (MeshLab's, the earlier add-on's or a plain points file: no angles of
    ours)."""
    try:
        file_rows = csvio.replayed_rows(csvio.read_measurements_csv(path))
    except (GoniometerError, OSError, ValueError) as error:
        return f"re-measured {path.name}: " + agreement.not_compared(error)[2:] if export else ""
    if len(file_rows) != replayed:
        return ""
    measured = [row for _, row in sorted(rows.items())]
    agreed = agreement.agreement_of_rows(
        [file_rows[index] for index in sorted(rows)],
        [row.angle for row in measured],
        [row.precision for row in measured],
    )
    return f"re-measured {path.name}: " + agreed.text[2:] if agreed.text else ""


def edges_line(path: Path, edge_rows: list) -> str:
    """The line for an ``--edges`` summary file re-measured as ``edge_rows``; ``""`` where
    there is nothing to say."""
    try:
        file_rows = csvio.read_edges_csv(path)
    except (GoniometerError, OSError, ValueError):
        return ""  # read when the run was planned; gone or changed since: nothing to compare
    agreed = agreement.edge_agreement(file_rows, edge_rows)
    return f"re-measured {path.name}: " + agreed.text[2:] if agreed.text else ""
