"""Which way a mesh's faces are wound: outward or inward for a closed surface, by its signed volume.

The oriented rule reads the same angle whichever way the faces are wound, but the convex/concave
label is relative to the normals: on an inward-wound mesh a convex edge reads "concave". A closed
surface says which way is out (its signed volume is positive when the faces are wound outward);
an open scan does not, so there the label is relative to the normals as given.
"""

from __future__ import annotations

import numpy as np

WINDINGS = ("outward", "inward", "mixed", "open")
"""``"outward"``/``"inward"``: closed and consistently wound, with positive/negative volume.
``"mixed"``: closed, but neighbouring faces are wound against each other (some faces flipped).
``"open"``: the surface has a boundary (or edges shared by more than two faces, or no volume), so
which side is outside cannot be decided."""


def mesh_winding(points: np.ndarray, triangles: np.ndarray | None) -> str:
    """Classify the winding of a triangle mesh (see :data:`WINDINGS`).

    Parameters
    ----------
    points : ndarray, shape (n, 3)
    triangles : ndarray of int64, shape (m, 3), or None
        ``None`` (a point cloud) is ``"open"``.

    Returns
    -------
    str
        One of :data:`WINDINGS`.
    """
    if triangles is None or len(triangles) == 0:
        return "open"
    n = np.int64(points.shape[0])
    start = triangles.ravel()
    end = triangles[:, [1, 2, 0]].ravel()
    keep = start != end  # a collapsed corner adds no edge
    start, end = start[keep], end[keep]
    low, high = np.minimum(start, end), np.maximum(start, end)
    _, uses = np.unique(low * n + high, return_counts=True)
    if not (uses == 2).all():
        return "open"
    directed = np.sort(start * n + end)
    if (np.diff(directed) == 0).any() or not np.array_equal(directed, np.sort(end * n + start)):
        return "mixed"  # each edge is used twice, but twice in the same direction somewhere
    used = np.unique(triangles)
    origin = points[used].mean(axis=0)
    scale = float(np.abs(points[used] - origin).max()) or 1.0
    a, b, c = ((points[triangles[:, k]] - origin) / scale for k in range(3))
    volume = float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum())
    if volume == 0.0:
        return "open"
    return "outward" if volume > 0 else "inward"


def winding_message(name: str, winding: str) -> str:
    """What to tell the user about a mesh's winding, or ``""`` when there is nothing to say.

    Parameters
    ----------
    name : str
        The mesh's name, as the user knows it.
    winding : str
        One of :data:`WINDINGS`.
    """
    if winding == "inward":
        return (
            f"'{name}' is wound inward (its normals point into the solid): the angles are right, "
            "but every convex edge is labelled concave and every concave edge convex. Flip its "
            "normals to fix the labels."
        )
    if winding == "mixed":
        return (
            f"Some faces of '{name}' are wound against their neighbours: convex/concave labels "
            "near them may be wrong. Recalculate its normals (outside) to fix them."
        )
    return ""
