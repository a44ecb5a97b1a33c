"""The break-agent study's per-break figures of an edge profile (count, median, range, arc and
chord length, arc angle), against an oracle written here from the stations with the standard
library and NumPy's SVD; the summary's record and CSV round trip; old edge files still read."""

from __future__ import annotations

import itertools
import math
import statistics

import numpy as np
import pytest

from vg_addon import Surface
from vg_addon.formats import csvio, record_codec
from vg_addon.method.break_figures import break_figures, principal_axis
from vg_addon.synthetic_meshes import varying_wedge, wedge


def first_axis(points) -> np.ndarray:
    """The direction of largest spread by NumPy's SVD (not the code under test's Jacobi)."""
    points = np.asarray(points, dtype=np.float64)
    return np.linalg.svd(points - points.mean(axis=0), full_matrices=False)[2][0]


def oracle(profile, surface) -> dict:
    """The study's figures of ``profile`` computed from its stations as the study defines them."""
    angles = [m.angle for m in profile.stations]
    centers = [tuple(float(v) for v in m.center) for m in profile.stations]
    cosine = abs(float(np.dot(first_axis(centers), first_axis(surface.points))))
    return {
        "count": len(angles),
        "mean": statistics.fmean(angles),
        "std": statistics.stdev(angles),
        "median": statistics.median(angles),
        "range": max(angles) - min(angles),
        "arc_length": sum(math.dist(a, b) for a, b in itertools.pairwise(centers)),
        "chord_length": math.dist(centers[0], centers[-1]),
        "arc_angle": math.degrees(math.acos(min(cosine, 1.0))),
    }


@pytest.mark.parametrize(
    ("shape", "points", "spacing", "arc_angle"),
    [
        # A crease along the fragment's long axis: arc angle 0 (the angle rising along the
        # crease tilts the axis of this fragment, wider at one end, by about 2°).
        (varying_wedge(80.0, 120.0, half_width=2.0, depth=1.0, n=20),
         [[-1.5, 0.0, 0.0], [1.5, 0.0, 0.0]], 0.4, 2.0),
        (wedge(100.0, half_width=2.0, depth=1.0, n=20), [[-1.5, 0.0, 0.0], [1.5, 0.0, 0.0]],
         0.4, 0.0),
        # A short crease across a fragment that is long across it: 90°.
        (wedge(90.0, half_width=0.6, depth=3.0, n=30), [[-0.5, 0.0, 0.0], [0.5, 0.0, 0.0]],
         0.15, 90.0),
    ],
)  # fmt: skip
def test_the_study_figures_match_the_oracle(shape, points, spacing, arc_angle):
    surface = Surface(shape.points, shape.triangles)
    profile = surface.measure_along(points, spacing, 0.3)
    figures, want = profile.figures, oracle(profile, surface)
    assert figures.n_stations == want["count"] >= 6
    for name in ("mean", "std", "median", "range", "arc_length", "chord_length"):
        assert getattr(figures, name) == pytest.approx(want[name], rel=1e-12, abs=1e-12), name
    assert figures.arc_angle == pytest.approx(want["arc_angle"], abs=1e-6)
    assert figures.arc_angle == pytest.approx(arc_angle, abs=1.0)
    # A straight edge: the chord is the arc; an angle varying along it has a range.
    assert figures.chord_length == pytest.approx(figures.arc_length, rel=1e-9)


def test_a_curved_break_has_an_arc_longer_than_its_chord_and_an_oblique_axis():
    # Stations on a quarter circle in the xy plane, the fragment long along x.
    t = np.radians(np.linspace(0.0, 90.0, 10))
    centers = np.column_stack([np.cos(t), np.sin(t), np.zeros_like(t)])
    angles = [100.0, 101.0, 99.0, 104.0, 120.0, 98.0, 97.5, 102.0, 103.0, 100.5]
    figures = break_figures(angles, centers, np.array([1.0, 0.0, 0.0]))
    assert figures.count == 10
    assert figures.median == statistics.median(angles) == 100.75
    assert figures.range == 22.5
    exact_arc = sum(math.dist(a, b) for a, b in itertools.pairwise(centers.tolist()))
    assert figures.arc_length == pytest.approx(exact_arc, rel=1e-14)
    assert figures.chord_length == pytest.approx(math.sqrt(2.0), rel=1e-14)
    # By symmetry the quarter circle's long axis is its chord, at 45° to x.
    assert figures.arc_angle == pytest.approx(45.0, abs=1e-9)


def test_the_arc_angle_is_undefined_where_no_direction_is():
    ring = np.radians(np.arange(0.0, 360.0, 10.0))
    circle = np.column_stack([np.cos(ring), np.sin(ring), np.zeros_like(ring)])
    assert principal_axis(circle) is None  # a ring has no main direction
    assert principal_axis(circle[:1]) is None
    assert principal_axis(np.zeros((5, 3))) is None
    one = break_figures([90.0], [[0.0, 0.0, 0.0]], np.array([1.0, 0.0, 0.0]))
    assert (one.count, one.median, one.range, one.arc_length, one.chord_length) == (
        1, 90.0, 0.0, 0.0, 0.0
    )  # fmt: skip
    assert one.arc_angle is None
    line = np.column_stack([np.linspace(0, 1, 5), np.zeros(5), np.zeros(5)])
    assert break_figures([1, 2, 3, 4, 5], line, None).arc_angle is None


def test_the_figures_travel_through_the_record_and_the_edges_csv_exactly():
    shape = varying_wedge(80.0, 120.0, half_width=2.0, depth=1.0, n=20)
    surface = Surface(shape.points, shape.triangles)
    clicks = [[-1.5, 0.0, 0.0], [1.5, 0.0, 0.0]]
    profile = surface.measure_along(clicks, 0.4, 0.3)
    numbers = record_codec.decode(record_codec.encode(record_codec.edge_numbers(profile, clicks)))
    names = ("median", "range", "arc_length", "chord_length", "arc_angle")
    for name in names:
        assert numbers[name] == getattr(profile.figures, name), name
    row = csvio.EdgeRow(mesh_name="ramp", edge_number=1, points=csvio.format_points(clicks),
                        **{name: numbers[name] for name in names})  # fmt: skip
    (back,) = csvio.read_edges_csv(csvio.format_edges_csv([row]))
    assert [getattr(back, n) for n in names] == [getattr(profile.figures, n) for n in names]
    blank = csvio.read_edges_csv(csvio.format_edges_csv([csvio.EdgeRow(points="0 0 0; 1 0 0")]))
    assert blank[0].arc_angle is None  # an undefined arc angle is a blank cell


def test_an_edge_file_of_an_earlier_version_still_reads():
    old_columns = [c for c in csvio.EDGE_COLUMNS if c not in csvio.LATER_EDGE_COLUMNS]
    values = {"Mesh Name": "bone", "Edge #": "3", "Mean Angle": "101.5", "Points": "0 0 0; 1 0 0",
              "Spacing": "0.5", "Radius": "1.0"}  # fmt: skip
    text = ",".join(old_columns) + "\n" + ",".join(values.get(c, "") for c in old_columns) + "\n"
    (row,) = csvio.read_edges_csv(text)
    assert (row.mesh_name, row.edge_number, row.mean) == ("bone", 3, 101.5)
    assert (row.median, row.range, row.arc_length, row.chord_length, row.arc_angle) == (None,) * 5
    assert "Median Angle" not in old_columns and "Arc Angle" in csvio.EDGE_COLUMNS
