"""The report as one HTML file that opens offline: styles inline, figures embedded as base64
PNG, no script and no reference to anything outside the file."""

from __future__ import annotations

import base64
import html
import math
from dataclasses import dataclass, field

STYLE = """
body { font-family: sans-serif; max-width: 1100px; margin: 2em auto; color: #222; }
h1 { font-size: 1.5em; } h2 { font-size: 1.2em; border-bottom: 1px solid #ccc; }
table { border-collapse: collapse; margin: 0.6em 0 1.2em; font-size: 0.9em; }
th, td { border: 1px solid #bbb; padding: 2px 8px; text-align: right; }
th { background: #eee; } td.text, th.text { text-align: left; }
caption { text-align: left; font-weight: bold; padding-bottom: 4px; }
figure { margin: 1em 0; } img { max-width: 100%; border: 1px solid #ddd; }
p.note { color: #555; font-size: 0.9em; } ul.left-out { font-size: 0.9em; color: #8a2d00; }
"""


def number(value, digits: int = 4) -> str:
    """A table cell: ``None`` as an em dash, integers as they are, floats to ``digits``
    significant digits (small values in scientific notation)."""
    if value is None:
        return "—"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if not math.isfinite(value):
            return "—"
        if value == 0:
            return "0"
        return f"{value:.{digits}g}"
    return str(value)


@dataclass
class Page:
    """An HTML page built section by section."""

    title: str
    parts: list[str] = field(default_factory=list)
    figures: int = 0

    def heading(self, text: str) -> None:
        self.parts.append(f"<h2>{html.escape(text)}</h2>")

    def paragraph(self, text: str, note: bool = False) -> None:
        cls = ' class="note"' if note else ""
        self.parts.append(f"<p{cls}>{html.escape(text)}</p>")

    def lines(self, items: list[str]) -> None:
        if items:
            body = "".join(f"<li>{html.escape(item)}</li>" for item in items)
            self.parts.append(f'<ul class="left-out">{body}</ul>')

    def table(self, caption: str, header: list[str], rows: list[list], text_columns=1) -> None:
        def cell(tag: str, index: int, value) -> str:
            cls = ' class="text"' if index < text_columns else ""
            return f"<{tag}{cls}>{html.escape(number(value))}</{tag}>"

        head = "".join(cell("th", i, h) for i, h in enumerate(header))
        body = "".join(
            "<tr>" + "".join(cell("td", i, v) for i, v in enumerate(row)) + "</tr>" for row in rows
        )
        self.parts.append(
            f"<table><caption>{html.escape(caption)}</caption><thead><tr>{head}</tr></thead>"
            f"<tbody>{body}</tbody></table>"
        )

    def figure(self, png: bytes, caption: str) -> None:
        data = base64.b64encode(png).decode("ascii")
        self.figures += 1
        self.parts.append(
            f'<figure><img alt="{html.escape(caption)}" src="data:image/png;base64,{data}">'
            f"<figcaption>Figure {self.figures}. {html.escape(caption)}</figcaption></figure>"
        )

    def text(self) -> str:
        return (
            '<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
            f"<title>{html.escape(self.title)}</title><style>{STYLE}</style></head><body>"
            f"<h1>{html.escape(self.title)}</h1>" + "\n".join(self.parts) + "</body></html>\n"
        )
