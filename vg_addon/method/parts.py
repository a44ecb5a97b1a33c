"""Separate parts of a mesh inside a Euclidean patch: another fragment, a sheet of scan debris.

The Euclidean ball takes every vertex within the radius, whether or not the mesh's faces join it
to the vertex measured. Where a mesh holds two refitted fragments, or a floating sheet of scan
debris, the ball can reach a part that is not the break's: a 120° edge with the sheet of a
fragment 0.005 from one face read 30.00° under the refined rule, a 90° edge under a sheet of
debris 66.56° under every rule, each with a small fit error and nothing else to show it. So the
Euclidean patch leaves out the vertices of such a part (:func:`measured_part`) where it is
large; a crumb, a speck of debris or a bead a thin edge broke into (marching-cubes wedges of 5°
and 20°, thinner than a voxel at the crease, break into beads along it), is kept as before.
Algorithm 1 as printed (the paper rule) takes the whole ball, and is refused where the two differ.

A part is what faces join, with the vertices at exactly the same coordinates taken as one
(:func:`mesh_parts`): a seam whose vertices were not merged (a mesh split in two, an STL's
loose triangles) is one surface.
"""

from __future__ import annotations

import numpy as np

from .mesh_regions import edge_components, jump_to_roots


def part_labels(n: int, triangles: np.ndarray) -> np.ndarray:
    """Label each vertex with its part: the smallest vertex index that faces join it to.

    Parameters
    ----------
    n : int
        Number of vertices.
    triangles : ndarray of int, shape (m, 3)

    Returns
    -------
    ndarray of int32 (int64 from 2**31 vertices), shape (n,)
        The label of each vertex (its own index where it is on no face). Whatever the order of
        the faces, the same labels.

    Notes
    -----
    Min-label propagation over the faces with pointer jumping: each round every face's corners
    hook their roots on the least of the three labels, then each label jumps to its root. Faces
    already settled (one label on all three corners) drop out once they are most of them.
    """
    kind = np.int32 if n < 2**31 else np.int64
    label = np.arange(n, dtype=kind)
    corners = [triangles[:, k].astype(kind) for k in range(3)]
    while True:
        ends = [label[corner] for corner in corners]
        least = np.minimum(np.minimum(ends[0], ends[1]), ends[2])
        unsettled = (ends[0] != least) | (ends[1] != least) | (ends[2] != least)
        count = np.count_nonzero(unsettled)
        if count == 0:
            return label
        if 4 * count < unsettled.size:  # compressing costs more than it saves on most faces
            keep = np.flatnonzero(unsettled)
            corners = [corner[keep] for corner in corners]
            ends = [end[keep] for end in ends]
            least = least[keep]
        for end in ends:  # ends are roots: hook each on the least label of a face it is on
            np.minimum.at(label, end, least)
        del ends, least, unsettled
        jump_to_roots(label, np.flatnonzero(label != np.arange(n, dtype=kind)))


def mesh_parts(points: np.ndarray, triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Label each vertex with its part, and count each part's vertices.

    Parameters
    ----------
    points : ndarray, shape (n, 3)
    triangles : ndarray of int, shape (m, 3)

    Returns
    -------
    labels : ndarray of int, shape (n,)
        The same number for the vertices of one part: what faces join, vertices at the same
        coordinates (-0.0 as 0.0) joined too where the faces make more than one part. A vertex
        on no face is a part of its own, or of the vertices at its coordinates.
    sizes : ndarray of int64
        ``sizes[label]``: how many vertices have that label.

    Notes
    -----
    The faces are labelled first (:func:`part_labels`); only where they make more than one part
    are the vertices sorted by their coordinates, and parts holding the same coordinates joined.
    """
    labels = part_labels(points.shape[0], triangles)
    if triangles.shape[0] and (labels[triangles[:, 0]] != labels[triangles[0, 0]]).any():
        first, second = _same_coordinates(points)
        apart = labels[first] != labels[second]
        if apart.any():
            joined = edge_components(points.shape[0], labels[first[apart]], labels[second[apart]])
            labels = joined[labels]
    return labels, np.bincount(labels, minlength=points.shape[0])


def _same_coordinates(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Pairs of vertices at exactly the same coordinates (-0.0 as 0.0), enough to join each
    set of them: each vertex with the next of its set in the order of a sort."""
    columns = [points[:, k] + 0.0 for k in range(3)]
    order = np.lexsort(columns[::-1])
    same = np.ones(order.size - 1, dtype=bool)
    for column in columns:
        ordered = column[order]
        same &= ordered[1:] == ordered[:-1]
    return order[:-1][same], order[1:][same]


def measured_part(
    labels: np.ndarray, sizes: np.ndarray, ball: np.ndarray, center: int
) -> np.ndarray | None:
    """The vertices of ``ball`` that a Euclidean patch measures.

    Parameters
    ----------
    labels, sizes : ndarray of int
        :func:`mesh_parts` of the mesh.
    ball : ndarray of int
        The vertices within the radius, in any order (kept in it).
    center : int
        The vertex measured, one of ``ball``.

    Returns
    -------
    ndarray of int or None
        ``ball`` without the vertices of the large parts other than the one measured. A part is
        large where it has at least as many vertices in the whole mesh as the rest of the ball
        (the ball's vertices not on it); a smaller one is a crumb (a speck of debris, or a bead
        a thin edge broke into, which can lie on the surface measured) and is kept. The part
        measured is the centre's; where the centre is on a crumb, the one large part in the
        ball, and ``None`` where there are several: which to measure cannot be told. ``ball``
        itself (one gather) where it lies on one part.
    """
    patch_labels = np.take(labels, ball)
    if (patch_labels == labels[center]).all():
        return ball
    parts, part = np.unique(patch_labels, return_inverse=True)
    part = part.reshape(-1)
    inside = np.bincount(part, minlength=parts.size)
    large = sizes[parts] + inside >= ball.size
    chosen = part[np.flatnonzero(ball == center)[0]]
    large, crumb = np.flatnonzero(large), not large[chosen]
    if crumb:  # the centre is on a crumb: the one large part, if one
        if large.size > 1:
            return None
        if large.size == 0:
            return ball
        chosen = large[0]
    dropped = large[large != chosen]
    if dropped.size == 0:
        return ball
    return ball[~np.isin(part, dropped)]
