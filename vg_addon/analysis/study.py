"""A study shaped like the paper's (Section 3), planned on synthetic fragments.

Each observer measures every break site three times by "drag" (the centre placed by eye and the
radius dragged by hand: both jittered here) and reads it three times with a contact goniometer
("manual": the true angle with a reading error, rounded to whole degrees as a goniometer is
read); the "xyz" sessions re-measure the observer's first drag session at its own centres and
radii. The plans are point lists for ``vg_batch.py --points``; the batch does the measuring.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..synthetic_meshes import BoneFragment, bone_fragment

#: Hand jitter of a drag measurement: centre SD (mm, each axis) and radius SD (log scale).
CENTRE_SD = 0.4
RADIUS_LOG_SD = 0.15
#: The contact goniometer's reading SD in degrees (the paper's manual IOV median is 4.67°).
MANUAL_SD = 4.0


@dataclass(frozen=True)
class Plan:
    """One session's plan: its file stem and rows (mesh, break, label, x, y, z, radius), or
    for a manual session rows (mesh, break, angle, break type)."""

    name: str
    method: str
    observer: str
    header: tuple[str, ...]
    rows: tuple[tuple, ...]


def fragments(count: int, seed: int = 0, spacing: float = 0.3) -> dict[str, BoneFragment]:
    """``count`` fragments of different shape (oblique cut and roughness), named
    ``fragment_1`` ... in millimetres, vertices ``spacing`` apart."""
    out = {}
    for i in range(count):
        out[f"fragment_{i + 1}"] = bone_fragment(
            oblique_deg=30.0 + 7.5 * i, roughness=0.05 * (i % 3), seed=seed + i, spacing=spacing
        )
    return out


def plan_study(
    meshes: dict[str, BoneFragment],
    *,
    observers: int = 1,
    drag_repetitions: int = 3,
    manual_repetitions: int = 3,
    radius: float = 3.0,
    seed: int = 0,
) -> list[Plan]:
    """The drag and manual sessions of every observer (xyz sessions follow from the first drag
    session's output, see the module's description)."""
    rng = np.random.default_rng(seed)
    plans = []
    header = ("mesh", "break", "label", "x", "y", "z", "radius")
    for o in range(1, observers + 1):
        observer = f"obs{o}"
        for rep in range(1, drag_repetitions + 1):
            rows = []
            for name, fragment in meshes.items():
                for number, site in enumerate(fragment.sites, start=1):
                    centre = np.asarray(site.point) + rng.normal(0.0, CENTRE_SD, 3)
                    r = radius * float(np.exp(rng.normal(0.0, RADIUS_LOG_SD)))
                    rows.append((name, number, site.label, *map(float, centre), r))
            plans.append(Plan(f"{observer}_drag_{rep}", "drag", observer, header, tuple(rows)))
        for rep in range(1, manual_repetitions + 1):
            rows = []
            for name, fragment in meshes.items():
                for number, site in enumerate(fragment.sites, start=1):
                    reading = float(np.round(site.angle + rng.normal(0.0, MANUAL_SD)))
                    rows.append((name, number, reading, site.label.split("/")[0]))
            plans.append(
                Plan(
                    f"{observer}_manual_{rep}",
                    "manual",
                    observer,
                    ("Mesh", "Break #", "Angle", "Break Type"),
                    tuple(rows),
                )
            )
    return plans
