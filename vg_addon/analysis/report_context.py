"""What the replication report's sections share: the page being written, the numbers they read,
the summary table every section adds to (``summary.csv``), and what the report returns."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from .html_page import Page
from .iov import BreakStats
from .sessions import Session

DEG = "°"
FIGURES = "figures"


@dataclass
class Outcome:
    """What a report used, what it left out and where it went.

    Attributes
    ----------
    folder : pathlib.Path
    sessions : int
        Sessions used.
    readings, rows : int
        Readings used in the analysis, and data rows read in all files.
    left_out : list of str
        One line per file, session, row or break left out, with its reason.
    not_computed : list of str
        One line per table or figure that could not be computed, with its reason.
    to_check : list of str
        One line per session used that the reader should check (one that may be a copy).
    figures : list of str
        The figures' names (each written as ``figures/NAME.png`` and ``.svg``).
    """

    folder: Path
    sessions: int = 0
    readings: int = 0
    rows: int = 0
    left_out: list[str] = field(default_factory=list)
    not_computed: list[str] = field(default_factory=list)
    to_check: list[str] = field(default_factory=list)
    figures: list[str] = field(default_factory=list)

    @property
    def code(self) -> int:
        """0: everything read was used; 1: the report was written, something was left out."""
        return 1 if self.left_out else 0


@dataclass
class Context:
    """One report being written: its inputs, the page, the outcome, and the summary rows."""

    paths: list
    folder: Path
    sessions: list[Session]
    stats: list[BreakStats]
    methods: list[str]
    outcome: Outcome
    page: Page
    summary_rows: list = field(default_factory=list)

    @property
    def figures(self) -> Path:
        return self.folder / FIGURES

    def figure(self, figure, name: str, caption: str) -> None:
        from .figures import save

        self.page.figure(save(figure, self.figures, name), caption)
        self.outcome.figures.append(name)

    def skip(self, what: str, why: str) -> None:
        line = f"{what}: not computed, {why}"
        self.outcome.not_computed.append(line)
        self.page.paragraph(line, note=True)


def iov_values(stats: list[BreakStats], method: str, quantity: str, units=None) -> list[float]:
    """The IOVs of ``quantity`` by ``method`` over the breaks (those in ``units`` only, by id)."""
    out = []
    for b in stats:
        if units is not None and id(b) not in units:
            continue
        m = b.methods.get(method)
        if m is not None and m.iov[quantity] is not None:
            out.append(m.iov[quantity])
    return out


def summary_table(summaries: dict[str, object]) -> list[list]:
    """The rows of a summary-statistics table: one per statistic, one column per summary."""
    rows = []
    for label, attribute in (
        ("N", "n"),
        ("min", "min"),
        ("Q1", "q1"),
        ("mean", "mean"),
        ("median", "median"),
        ("Q3", "q3"),
        ("max", "max"),
        ("SD", "sd"),
    ):
        rows.append([label, *(getattr(s, attribute) for s in summaries.values())])
    return rows


def record_summary(c: Context, table: str, method: str, quantity: str, s) -> None:
    """Add a summary ``s`` (``stats.summarise``) to the rows of ``summary.csv``."""
    ci95 = s.ci95 or (None, None)
    ci99 = s.ci99 or (None, None)
    c.summary_rows.append(
        [
            table,
            method,
            quantity,
            s.n,
            s.mean,
            s.sd,
            s.min,
            s.q1,
            s.median,
            s.q3,
            s.max,
            *ci95,
            *ci99,
        ]
    )
