"""``--report DIR CSV [CSV ...]``: the replication report over session CSVs.

The analysis is ``vg_addon.analysis``; this module checks the arguments, runs it and says in a
few lines what was written, used and left out.
"""

from __future__ import annotations

import sys

from ..vg_addon.analysis.report import write_report
from ..vg_addon.errors import bounded_list
from .cli import FINDER_SETTINGS, UsageError

#: Options of a measuring run that mean nothing to a report.
MEASURING_OPTIONS = (
    ("--at", "at"),
    ("--points", "points"),
    ("--edge", "edge"),
    ("--edges", "edges_csv"),
    ("--find-edges", "find_edges"),
    *((flag, name) for flag, _, name in FINDER_SETTINGS),
    ("--out", "out"),
    ("--save-blend", "save_blend"),
    ("--render", "render"),
    ("--sweep", "sweep"),
    ("--object", "object"),
    ("--shard", "shard"),
    ("--demo", "demo"),
)


def check_report_args(args) -> None:
    """Refuse a report without sessions, or with a measuring run's options."""
    given = [option for option, name in MEASURING_OPTIONS if getattr(args, name, None)]
    if given:
        raise UsageError(
            f"--report takes session CSVs only, not {', '.join(given)}: measure first, then "
            "report on the CSVs."
        )
    if not args.inputs:
        raise UsageError(
            "--report DIR needs the session CSVs after it: one CSV per session (one observer, "
            "one method, one repetition)."
        )
    for label, given in (("--method", args.method), ("--observer", args.observer)):
        if len(given) not in (0, 1, len(args.inputs)):
            raise UsageError(
                f"give {label} once for all {len(args.inputs)} CSVs or once per CSV, in their "
                f"order (got {len(given)})."
            )


def run_report(args) -> int:
    """Write the report; 0 when every row read was used, 1 when some were left out (each named
    in the report and here)."""
    outcome = write_report(
        args.inputs,
        args.report,
        methods=args.method,
        observers=args.observer,
        compare=[tuple(pair) for pair in args.compare],
    )
    print(
        f"vg_batch: report: {outcome.folder / 'report.html'} ({outcome.sessions} sessions, "
        f"{outcome.readings} of {outcome.rows} rows used, {len(outcome.figures)} figures)",
        flush=True,
    )
    for what, lines in (
        ("left out", outcome.left_out),
        ("not computed", outcome.not_computed),
        ("to check", outcome.to_check),
    ):
        if lines:
            print(
                f"vg_batch: {what} ({len(lines)}):\n{bounded_list(lines, lines=True)}",
                file=sys.stderr,
                flush=True,
            )
    return outcome.code
