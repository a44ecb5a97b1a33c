"""What a label says and where it stands: each current measurement's number, angle and centre
in world space, read from the records (for the viewport labels and the measurement map)."""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..vg_addon.formats.record_codec import decode, exact_numbers
from ..vg_addon.method.result import stored_stability_undetermined
from ..vg_addon.workflow.labels import label_text
from . import records
from .mesh_data import world_points


@dataclass(frozen=True)
class Label:
    """One measurement's label.

    Attributes
    ----------
    number, break_number : int
    text : str
        E.g. ``"3: 91.25°"``.
    position : ndarray, shape (3,)
        The measured centre in world space, where the object is now.
    outward : ndarray, shape (3,)
        Unit direction away from the surface at the centre, world space (the mean of the two
        sides' normals), for placing the text off the surface.
    radius : float
        The patch radius in world units (mesh radius times the object's mean scale).
    active : bool
        The list's selected measurement.
    unstable : bool
        An unstable reading (flagged in the list): its text carries the stability figure.
    """

    number: int
    break_number: int
    text: str
    position: np.ndarray
    outward: np.ndarray
    radius: float
    active: bool
    unstable: bool = False


@lru_cache(maxsize=4096)
def _label_numbers(exact: str):
    """``(centre, normal sum, angle, radius, stability parts)`` of a record's exact numbers in
    mesh coordinates, or None (a world-space record of an earlier version, or no centre).

    Kept per exact text: the viewport labels are drawn on every redraw, and decoding every
    record each time cost 45 ms a redraw at 600 measurements."""
    numbers = decode(exact)
    if numbers.get("space") != records.MESH or "center" not in numbers:
        return None
    centre = np.asarray(numbers["center"], dtype=np.float64)
    normals = np.asarray(numbers["normal_plus"]) + np.asarray(numbers["normal_minus"])
    centre.flags.writeable = normals.flags.writeable = False  # shared by every caller
    parts = numbers.get("stability") or {}
    return centre, normals, numbers["angle"], float(numbers["radius"]), parts


def stability_flag(item, parts: dict | None = None) -> str:
    """The stability figure an unstable reading is flagged with (``"±78°"``; ``"±?"`` where the
    figure is undetermined), or ``""`` for a reading that is not flagged (see
    ``vg_addon.method.result.stability_warning``). ``parts``: the record's stability numbers,
    where the caller has them."""
    if not item.stability_warning:
        return ""
    if parts is None:
        parts = exact_numbers(item).get("stability") or {}
    if stored_stability_undetermined(parts):
        return "±?"  # the figure itself may be far too small: no number that looks steady
    return f"±{float(parts.get('spread', 0.0)):.0f}°"


def labels_of(obj, *, active_break_only: bool = False) -> list[Label]:
    """Labels of ``obj``'s measurements that are current (stale ones get none), in list order.

    ``active_break_only`` keeps those of the break the next measurement goes to.
    """
    data = getattr(obj, "vg", None)
    if data is None or not len(data.measurements):
        return []
    matrix = np.array(obj.matrix_world, dtype=np.float64)
    linear = matrix[:3, :3]
    try:
        normal_matrix = np.linalg.inv(linear).T
    except np.linalg.LinAlgError:
        return []
    scale = float(np.cbrt(abs(np.linalg.det(linear))))
    kept = []
    for index, item in enumerate(data.measurements):
        if item.stale or (active_break_only and item.break_number != data.break_number):
            continue
        numbers = _label_numbers(item.exact)
        if numbers is not None:
            kept.append((index, item, numbers))
    if not kept:
        return []
    positions = world_points(np.array([numbers[0] for _, _, numbers in kept]), matrix)
    outwards = np.array([numbers[1] for _, _, numbers in kept]) @ normal_matrix.T
    lengths = np.linalg.norm(outwards, axis=1)
    outwards[lengths > 0] /= lengths[lengths > 0, None]
    labels = []
    for (index, item, numbers), position, outward in zip(kept, positions, outwards, strict=True):
        _, _, angle, radius, parts = numbers
        flag = stability_flag(item, parts)
        text = label_text(item.number, angle)
        labels.append(
            Label(
                number=item.number,
                break_number=item.break_number,
                text=f"{text} {flag}" if flag else text,
                position=position,
                outward=outward,
                radius=radius * scale,
                active=index == data.active_index,
                unstable=bool(flag),
            )
        )
    return labels
