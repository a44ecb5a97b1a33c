"""Where measurement labels go, without Blender: which labels to show so that they do not pile
up, and the views a measurement map is drawn from.

Used by the viewport labels (``ui.labels``) and the measurement map (``bridge.measurement_map``),
which both have many measurements to label on a small picture.
"""

from __future__ import annotations

import numpy as np

from ..errors import GoniometerError


def label_box(anchor, width: float, height: float, side: int, gap: float) -> np.ndarray:
    """``[left, bottom, right, top]`` of a label's text: to the right of its anchor
    (``side=1``) or to the left (``side=-1``), ``gap`` away, vertically centred on it."""
    x, y = float(anchor[0]), float(anchor[1])
    near, far = x + side * gap, x + side * (gap + width)
    return np.array([min(near, far), y - height / 2, max(near, far), y + height / 2])


def _overlaps(boxes: np.ndarray, box: np.ndarray) -> bool:
    return bool(
        (
            (boxes[:, 0] < box[2])
            & (box[0] < boxes[:, 2])
            & (boxes[:, 1] < box[3])
            & (box[1] < boxes[:, 3])
        ).any()
    )


def place_labels(
    anchors,
    widths,
    height: float,
    priority,
    *,
    gap: float | None = None,
    right_edge=None,
    bounds=None,
) -> list:
    """Which labels to show and on which side of their anchor, so that no two overlap.

    Greedily, by priority: a label goes to the right of its anchor if its text box is clear of
    every text and anchor kept before it, else to the left, else it is left out.

    Parameters
    ----------
    anchors : array_like, shape (n, 2)
        Where each label points (pixels): the measurement's centre on the picture.
    widths : array_like, shape (n,)
        Each label's text width (pixels).
    height : float
        The text height (pixels); labels keep a quarter of it apart.
    priority : array_like, shape (n,)
        Higher first (e.g. the selected measurement, then the newest); ties keep input order.
    gap : float, optional
        Between anchor and text; default half the height.
    right_edge : float, optional
        Where the visible picture ends on the right (pixels): a label whose text would cross it
        tries the left side first.
    bounds : (float, float), optional
        Where the picture ends on the left and on the right (pixels): a text that would cross
        either is not put on that side (a map's picture cuts what crosses its edges).

    Returns
    -------
    list of (int, int)
        ``(index, side)`` of each label shown, in priority order; side 1 is right, -1 left.
        The first label is always shown.
    """
    anchors = np.asarray(anchors, dtype=np.float64).reshape(-1, 2)
    widths = np.asarray(widths, dtype=np.float64).reshape(-1)
    priority = np.asarray(priority, dtype=np.float64).reshape(-1)
    if not anchors.shape[0] == widths.shape[0] == priority.shape[0]:
        raise GoniometerError(
            f"place_labels: {anchors.shape[0]} anchors, {widths.shape[0]} widths and "
            f"{priority.shape[0]} priorities; give one of each per label."
        )
    gap = 0.5 * height if gap is None else float(gap)
    pad = 0.125 * height
    dot = 0.25 * height
    taken = np.empty((0, 4))
    shown = []
    for index in np.argsort(-priority, kind="stable"):
        anchor = anchors[index]
        mark = np.array([anchor[0] - dot, anchor[1] - dot, anchor[0] + dot, anchor[1] + dot])
        sides = (1, -1)
        if (
            right_edge is not None
            and label_box(anchor, widths[index], height, 1, gap)[2] > right_edge
        ):
            sides = (-1, 1)
        for side in sides:
            box = label_box(anchor, widths[index], height, side, gap)
            if bounds is not None and (box[0] < bounds[0] or box[2] > bounds[1]):
                continue
            padded = box + np.array([-pad, -pad, pad, pad])
            if not taken.size or not (_overlaps(taken, padded) or _overlaps(taken, mark)):
                shown.append((int(index), side))
                taken = np.vstack([taken, box, mark])
                break
    return shown


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


def view_up(look) -> tuple:
    """The up direction of a picture looking along ``look``: world Z made square to it, or world
    Y when ``look`` is nearly vertical."""
    look = np.asarray(look, dtype=np.float64)
    look = look / np.linalg.norm(look)
    up = np.array([0.0, 0.0, 1.0]) if abs(look[2]) < 0.9 else np.array([0.0, 1.0, 0.0])
    up = up - (up @ look) * look
    return tuple(up / np.linalg.norm(up))


def looks_at(outward, tilts=(20.0, 40.0, 60.0), turns: int = 8) -> list:
    """Directions to look at a measurement from, best first: straight onto its surface (along
    minus its mean normal ``outward``), then tilted ``tilts`` degrees from it at ``turns``
    evenly spaced turns, then the same from the other side (a normal can point inwards).

    Parameters
    ----------
    outward : array_like, shape (3,)
        The mean of the measurement's two side normals; a zero vector gives no direction.

    Returns
    -------
    list of ndarray
        Unit look directions (the way the camera points).
    """
    outward = np.asarray(outward, dtype=np.float64)
    length = float(np.linalg.norm(outward))
    if not np.isfinite(length) or length == 0.0:
        return []
    axis = -outward / length
    side = np.array(view_up(axis))
    other = np.cross(axis, side)
    looks = []
    for sign in (1.0, -1.0):
        looks.append(sign * axis)
        for tilt in np.radians(tilts):
            for turn in np.arange(turns) * (2.0 * np.pi / turns):
                bend = np.cos(turn) * side + np.sin(turn) * other
                looks.append(sign * (np.cos(tilt) * axis + np.sin(tilt) * bend))
    return looks
