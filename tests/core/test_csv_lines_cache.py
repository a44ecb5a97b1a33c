"""Rewriting a growing export with remembered lines (the batch's CSV, rewritten as meshes
finish): each text equals the one formatted from scratch, a row replaced by another object
gets its own line, and each row is formatted once. Oracle: ``format_measurements_csv`` without
the remembered lines."""

from __future__ import annotations

import dataclasses

from csv_rows import good_row

from vg_addon.formats import csvio


def test_remembered_lines_give_the_text_formatted_from_scratch():
    rows = [good_row(number=n, angle=90.0 + n / 7) for n in range(1, 6)]
    lines: dict = {}
    assert csvio.format_measurements_csv(rows[:2], lines=lines) == csvio.format_measurements_csv(
        rows[:2]
    )
    assert len(lines) == 2
    rows.append(good_row(number=6, user_data='a, "quoted" note'))
    assert csvio.format_measurements_csv(rows, lines=lines) == csvio.format_measurements_csv(rows)
    assert len(lines) == 6
    # A row replaced by another (an error row written for a row that never came) is written as
    # the new row says, not as the line remembered for the old one.
    rows[1] = dataclasses.replace(rows[1], angle=None, error="not measured: stopped")
    text = csvio.format_measurements_csv(rows, lines=lines)
    assert text == csvio.format_measurements_csv(rows) and "not measured: stopped" in text


def test_each_row_is_formatted_once(monkeypatch):
    from vg_addon.formats.csvio import measurements

    calls = []
    real = measurements.row_cells
    monkeypatch.setattr(measurements, "row_cells", lambda *a: calls.append(a[1]) or real(*a))
    rows = [good_row(number=n) for n in range(1, 4)]
    lines: dict = {}
    for _ in range(3):
        csvio.format_measurements_csv(rows, lines=lines)
    assert len(calls) == 3
