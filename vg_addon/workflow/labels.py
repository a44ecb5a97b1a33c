"""Where measurement labels go, without Blender: which labels to show so that they do not pile
up, and the views a measurement map is drawn from.

Used by the viewport labels (``ui.labels``) and the measurement map (``bridge.measurement_map``),
which both have many measurements to label on a small picture.
"""

from __future__ import annotations

import numpy as np

from ..errors import GoniometerError


def declutter(positions, priority, min_distance: float) -> np.ndarray:
    """Indices of the labels to show: greedily, by priority, each at least ``min_distance``
    from every label kept before it.

    Parameters
    ----------
    positions : array_like, shape (n, 2)
        Label anchors on the picture (pixels).
    priority : array_like, shape (n,)
        Higher first (e.g. the active measurement, then the newest); ties keep input order.
    min_distance : float
        Pixels between any two kept anchors.

    Returns
    -------
    ndarray of int
        Kept indices, in priority order. The first label is always kept.
    """
    positions = np.asarray(positions, dtype=np.float64).reshape(-1, 2)
    priority = np.asarray(priority, dtype=np.float64).reshape(-1)
    if positions.shape[0] != priority.shape[0]:
        raise GoniometerError(
            f"declutter: {positions.shape[0]} positions but {priority.shape[0]} priorities."
        )
    order = np.argsort(-priority, kind="stable")
    kept: list[int] = []
    limit = float(min_distance) ** 2
    for index in order:  # labels shown at once: tens to a few hundred
        if kept:
            offsets = positions[kept] - positions[index]
            if np.einsum("ij,ij->i", offsets, offsets).min() < limit:
                continue
        kept.append(int(index))
    return np.array(kept, dtype=np.int64)


#: The six orthographic views of a map: name, the direction the camera looks along, and the
#: direction that is up in the picture (world axes, Z up, as Blender's front view looks along +Y).
SIX_VIEWS = (
    ("front", (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)),
    ("back", (0.0, -1.0, 0.0), (0.0, 0.0, 1.0)),
    ("right", (-1.0, 0.0, 0.0), (0.0, 0.0, 1.0)),
    ("left", (1.0, 0.0, 0.0), (0.0, 0.0, 1.0)),
    ("top", (0.0, 0.0, -1.0), (0.0, 1.0, 0.0)),
    ("bottom", (0.0, 0.0, 1.0), (0.0, -1.0, 0.0)),
)


def flake_views(points) -> tuple:
    """The two faces of a flat piece (a flake): looking along its thinnest direction, from
    both sides, with its longest direction up.

    Parameters
    ----------
    points : array_like, shape (n, 3)
        The vertices, in the space the views are wanted in (world space for a render).

    Returns
    -------
    tuple of (name, look direction, up direction)
        ``("face A", d, up)`` and ``("face B", -d, up)``; ``d`` is the principal axis of least
        spread, signed so that it has a non-negative largest component (deterministic).
    """
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if points.shape[0] < 3:
        raise GoniometerError("A flake map needs a mesh with at least 3 vertices.")
    centred = points - points.mean(axis=0)
    _, spread, axes = np.linalg.svd(centred, full_matrices=False)
    if spread[1] <= 0.0:
        raise GoniometerError("The mesh is a line, not a flake: choose the six views instead.")
    thin, long = axes[2], axes[0]
    for axis in (thin, long):
        if axis[np.argmax(np.abs(axis))] < 0:
            axis *= -1.0
    return (
        ("face A", tuple(thin), tuple(long)),
        ("face B", tuple(-thin), tuple(long)),
    )


def label_text(number: int, angle: float) -> str:
    """A label: the measurement number and its angle to the 0.01° it is reported to."""
    return f"{number}: {angle:.2f}°"
