"""The exact numbers of a stored measurement or edge profile, written and read in one place.

Blender's FloatProperty holds a 32-bit float, too coarse to replay a measurement, so a record
keeps every number as float64 in one JSON text (``VG_Measurement.exact``, ``VG_Edge.exact``):
Python's ``json`` writes floats with ``repr``, which reads back exactly. This module turns a
:class:`~vg_addon.method.result.Measurement` into those numbers (:func:`measurement_numbers`),
numbers into the text (:func:`encode`) and the text back (:func:`decode`, :func:`exact_numbers`).
Pure Python and NumPy: no Blender.

Keys of a measurement: ``angle``, ``fit``, ``fit_plus``, ``fit_minus``, ``radius``, ``lam``,
``snap_distance`` (floats); ``center``, ``requested``, ``normal_plus``, ``normal_minus`` (lists
of 3 floats); ``rule``, ``convexity``, ``correlation`` and ``stability`` (a dict of its parts, or
None), absent from records of versions before the oriented rule (measured with the paper's
rule); ``space`` (:data:`MESH`, ``"mesh"``; absent from world-space records of earlier versions). A station
of an edge profile adds ``arc_length``, ``spacing`` and ``plus_left``; a measurement whose sides
are painted the other way round ``painted_swapped`` (:data:`SWAPPED`). Keys of an edge profile:
see :func:`edge_numbers`.
"""

from __future__ import annotations

import json

import numpy as np

from .csvio import MESH_COORDINATES as MESH  # a record's coordinates: the mesh's own

# Present (True) when a record's sides are painted the other way round: its "+" side agreed
# better with the side its break's earlier measurements painted in the second colour (see
# ``vg_addon.method.break_sides``); its numbers are as measured.
SWAPPED = "painted_swapped"


def _floats(vector) -> list[float]:
    return [float(v) for v in np.asarray(vector, dtype=np.float64)]


def _stability(stability) -> dict:
    return {
        "spread": float(stability.spread),
        "center": float(stability.center),
        "radius": float(stability.radius),
        "lam": float(stability.lam),
        "bootstrap": float(stability.bootstrap),
        "orientation": float(stability.orientation),
        "runs": int(stability.n_runs),
        "refused": int(stability.n_failed),
        "crease": float(stability.crease),
        "crease_refused": int(stability.crease_refused),
        "noise_hides_crease": bool(stability.noise_hides_crease),
    }


def measurement_numbers(m, station=None) -> dict:
    """The exact numbers stored for measurement ``m`` (taken in mesh coordinates).

    ``station``: ``(edge_number, arc_length, spacing, plus_left)`` for a station of an edge
    profile, else None.
    """
    numbers = {}
    if station is not None:
        _, arc_length, spacing, plus_left = station
        numbers = {
            "arc_length": float(arc_length),
            "spacing": float(spacing),
            "plus_left": bool(plus_left),
        }
    return {
        **numbers,
        "angle": float(m.angle),
        "fit": float(m.fit_error),
        "fit_plus": float(m.fit_error_plus),
        "fit_minus": float(m.fit_error_minus),
        "radius": float(m.radius),
        "lam": float(m.lam),
        "snap_distance": float(m.snap_distance),
        "center": _floats(m.center),
        "requested": _floats(m.requested_center),
        "normal_plus": _floats(m.normal_plus),
        "normal_minus": _floats(m.normal_minus),
        "rule": m.rule,
        "convexity": m.convexity,
        "correlation": float(m.correlation),
        "stability": None if m.stability is None else _stability(m.stability),
        "space": MESH,
    }


def _optional(value) -> float | None:
    return None if value is None else float(value)


#: The break-agent study's figures an edge record keeps (see ``vg_addon.method.break_figures``);
#: records of earlier versions lack them (their CSV cells stay blank).
STUDY_FIGURES = ("median", "range", "arc_length", "chord_length", "arc_angle")


def study_texts(numbers: dict, unit: str) -> list[tuple[str, str]]:
    """The break-agent study's per-break figures of an edge record's ``numbers`` as
    ``(label, text)`` rows for display, lengths followed by ``unit`` (``"mm"``); one row saying
    they are not recorded for a record of a version before them."""
    if any(name not in numbers for name in STUDY_FIGURES):
        return [("Study figures", "not recorded (an older version): measure again")]
    arc_angle = numbers["arc_angle"]
    return [
        ("Median, range", f"{numbers['median']:.2f}°, {numbers['range']:.2f}°"),
        ("Arc, chord", f"{numbers['arc_length']:.4g}, {numbers['chord_length']:.4g} {unit}"),
        (
            "Arc angle",
            # Short enough for the sidebar: the cases (one station, a ring, a fragment as wide
            # as long) are in docs/EDGE_PROFILES.md.
            "undefined (no single direction)" if arc_angle is None else f"{arc_angle:.2f}°",
        ),
    ]


def figure_numbers(figures) -> dict:
    """The summary numbers an edge record stores for ``figures`` (an ``EdgeSummary``):
    ``mean``, ``std``, ``min``, ``max``, ``pooled_angle``, ``pooled_fit`` and the
    :data:`STUDY_FIGURES` (``std`` and ``arc_angle`` may be None: undefined)."""
    return {
        "mean": float(figures.mean),
        "std": _optional(figures.std),
        "min": float(figures.min),
        "max": float(figures.max),
        "pooled_angle": float(figures.pooled_angle),
        "pooled_fit": float(figures.pooled_fit_error),
        **{name: _optional(getattr(figures, name)) for name in STUDY_FIGURES},
    }


def edge_numbers(profile, clicks) -> dict:
    """The exact numbers an edge record stores for ``profile`` (an ``EdgeProfile``) and its
    ``clicks`` (the points that define its path)."""
    spans = profile.path.flat_spans
    return {
        "points": [_floats(p) for p in clicks],
        "path": [_floats(p) for p in profile.path.points],
        "spacing": float(profile.spacing),
        "radius": float(profile.radius),
        "lam": float(profile.lam),
        "length": float(profile.path.length),
        "arc_lengths": [float(a) for a in profile.arc_lengths],
        "angles": [float(a) for a in profile.angles],
        **figure_numbers(profile.figures),
        "flat_spans": [[float(a), float(b)] for a, b in spans],
        "space": MESH,
        "rule": profile.stations[0].rule,  # every station's
    }


def encode(numbers: dict) -> str:
    """The text a record stores for ``numbers`` (every float exactly)."""
    return json.dumps(numbers)


def decode(text: str) -> dict:
    """The numbers of a record's text; ``{}`` for an empty or unreadable text (a record
    damaged outside the extension shows no numbers rather than failing)."""
    try:
        numbers = json.loads(text) if text else {}
    except ValueError:
        return {}
    return numbers if isinstance(numbers, dict) else {}


def exact_numbers(record) -> dict:
    """The numbers of a stored measurement or edge profile (anything with an ``exact`` text)."""
    return decode(record.exact)
