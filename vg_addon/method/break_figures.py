"""The per-break figures of the break-agent study, from an edge's stations.

The study behind the authors' package (breaks picked in MeshLab, measured with the Virtual
Goniometer along each break) described every break by its readings' count, mean, median,
standard deviation, minimum, maximum and range, and by the shape of the line of readings: its
arc length (the polyline through the readings in order), its chord ("Euclidean") length (first
reading to last) and its arc angle (the angle between the break's main direction and the
fragment's long axis). :func:`break_figures` computes them from an edge profile's stations.

Arc angle, precisely: the break's direction is the first principal axis (largest spread) of its
station centres; the fragment's axis the first principal axis of the mesh's vertices; the arc
angle is the angle between the two lines, ``acos |d · a|`` in degrees, 0° for a break along the
fragment's long axis, 90° for one across it. It is undefined (None) for fewer than two stations
and where either direction is not determined by the data: its two largest spreads within
:data:`AXIS_TOLERANCE` of each other (a break that closes on itself as a ring, a fragment as
wide as it is long).

Every number is computed in a fixed order (:mod:`.fixed_order`): the same bits on any machine.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass

import numpy as np

from .fixed_order import acos_degrees, dot3, eigh3, moments, total

AXIS_TOLERANCE = 0.01
"""A principal axis counts as determined when its spread (eigenvalue) exceeds the next one by
more than this fraction; otherwise the direction is an accident of sampling."""

_axes: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


@dataclass(frozen=True)
class BreakFigures:
    """The study's per-break figures (angles in degrees, lengths in the mesh's units).

    Attributes
    ----------
    count : int
        Number of stations.
    median, range : float
        Median and range (max − min) of the station angles.
    arc_length : float
        Length of the polyline through the station centres in order.
    chord_length : float
        Distance from the first station's centre to the last's.
    arc_angle : float or None
        Angle between the break's and the fragment's principal axes, in [0°, 90°]; None where
        undefined (see the module's description).
    """

    count: int
    median: float
    range: float
    arc_length: float
    chord_length: float
    arc_angle: float | None


def principal_axis(points: np.ndarray) -> np.ndarray | None:
    """The unit direction of largest spread of ``points`` (shape ``(n, 3)``), or None when it
    is not determined (fewer than two distinct points, or its spread within
    :data:`AXIS_TOLERANCE` of the next)."""
    points = np.asarray(points, dtype=np.float64)
    if points.shape[0] < 2:
        return None
    centre = np.array([total(points[:, k]) / points.shape[0] for k in range(3)])
    values, vectors = eigh3(moments(points - centre))
    if not values[2] > 0.0 or values[2] <= values[1] * (1.0 + AXIS_TOLERANCE):
        return None
    return vectors[:, 2]


def fragment_axis(surface) -> np.ndarray | None:
    """The first principal axis of the surface's vertices (see :func:`principal_axis`), kept
    with the surface once computed."""
    if surface not in _axes:
        _axes[surface] = principal_axis(surface.points[surface.valid])
    return _axes[surface]


def break_figures(angles, centers, axis: np.ndarray | None) -> BreakFigures:
    """The study's figures of one break from its stations, in order along it.

    Parameters
    ----------
    angles : array_like, shape (s,)
        The stations' angles (degrees).
    centers : array_like, shape (s, 3)
        Their centres.
    axis : ndarray or None
        The fragment's principal axis (:func:`fragment_axis`); None makes the arc angle None.

    Returns
    -------
    BreakFigures
    """
    angles = np.asarray(angles, dtype=np.float64)
    centers = np.asarray(centers, dtype=np.float64)
    steps = np.diff(centers, axis=0)
    lengths = np.sqrt(steps[:, 0] * steps[:, 0] + steps[:, 1] * steps[:, 1] + steps[:, 2] ** 2)
    chord = centers[-1] - centers[0]
    direction = principal_axis(centers)
    arc_angle = None
    if direction is not None and axis is not None:
        arc_angle = acos_degrees(abs(dot3(direction, axis)))
    return BreakFigures(
        count=int(angles.size),
        median=float(np.median(angles)),
        range=float(angles.max() - angles.min()),
        arc_length=total(lengths) if lengths.size else 0.0,
        chord_length=math.sqrt(dot3(chord, chord)),
        arc_angle=arc_angle,
    )
