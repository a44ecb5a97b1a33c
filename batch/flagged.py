"""The batch summary's lines for flagged readings: unstable, or the ± figure undetermined."""

from __future__ import annotations

from ..vg_addon.method.result import stability_text, stability_warning


def _counts(row) -> tuple:
    """A row's stability runs, refused runs and refused crease bands (0 where empty), and
    whether the normals' noise hides the crease (``None`` where empty)."""
    noise = row.stability_noise_hides_crease
    return (
        row.stability_runs or 0,
        row.stability_refused or 0,
        row.stability_crease_refused or 0,
        None if noise is None else bool(noise),
    )


def flagged_rows(rows: dict) -> list:
    """``(index, row, warning)`` of the measured rows whose stability figure flags them (see
    ``vg_addon.method.result.stability_warning``), in row order."""
    flagged = []
    for index, row in sorted(rows.items()):
        if row.error or row.stability is None:
            continue
        warning = stability_warning(row.stability, *_counts(row))
        if warning:
            flagged.append((index, row, warning))
    return flagged


def flagged_lines(rows: dict, station_rows: list, by_index: dict) -> list[str]:
    """How many readings are flagged (points, then edge stations), and the first ten with why;
    nothing where none is. ``by_index``: each point row's task, which names its row or point."""
    flagged = []
    for index, row, warning in flagged_rows(rows):
        task = by_index[index]
        where = f"row {task.source_row}" if task.source_row else f"point {task.number}"
        flagged.append((where, row, warning))
    for _, row, warning in flagged_rows(dict(enumerate(station_rows))):
        where = f"edge {row.edge_number} station at arc length {row.arc_length:.4g}"
        flagged.append((where, row, warning))
    if not flagged:
        return []
    lines = [f"{len(flagged):,} flagged reading(s): unstable, or the ± figure undetermined"]
    for where, row, warning in flagged[:10]:
        lines.append(
            f"  flagged: {where} on {row.mesh_name!r}: {row.angle:.2f}° "
            f"{stability_text(row.stability, *_counts(row))}: {warning}"
        )
    if len(flagged) > 10:
        lines.append(f"  ... and {len(flagged) - 10} more flagged rows (see the Stability columns)")
    return lines
