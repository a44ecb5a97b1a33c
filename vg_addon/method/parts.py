"""Separate parts of a mesh inside a Euclidean patch: another fragment, a sheet of scan debris.

The Euclidean ball takes every vertex within the radius, whether or not the mesh's faces join it
to the vertex measured. Where a mesh holds two refitted fragments, or a floating sheet of scan
debris, the ball can reach a part that is not the break's: a 120° edge with the sheet of a
fragment 0.005 from one face read 30.00° under the refined rule, a 90° edge under a sheet of
debris 66.56° under every rule, each with a small fit error and nothing else to show it. So the
Euclidean patch leaves out the vertices of such a part (:func:`measured_part`) where it is
large. A smaller part, a crumb (a speck of debris, or a bead a thin edge broke into:
marching-cubes wedges of 5° and 20°, thinner than a voxel at the crease, break into beads along
it), stays, and ``Surface.measure`` refuses a reading that its crumbs move
(:func:`crumb_vertices`). Algorithm 1 as printed (the paper rule) takes the whole ball, and is
refused where the ball reaches a large part left out.

A part is what faces join, with the vertices at the same coordinates taken as one
(:func:`mesh_parts`): a seam whose vertices were not merged (a mesh split in two, an STL's
loose triangles) is one surface. Copies a little apart are not joined: a large part whose rim
runs along the measured part's refuses the patch instead (:func:`touching`).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .fins import corner_ends
from .mesh_regions import edge_components, jump_to_roots
from .spatial import GridIndex, neighbour_pairs


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


class MeshParts(NamedTuple):
    """A mesh's parts (:func:`mesh_parts`).

    Attributes
    ----------
    labels : ndarray of int, shape (n,)
        The same number for the vertices of one part: what faces join, vertices at the same
        coordinates (-0.0 as 0.0) joined too where the faces make more than one part. A vertex
        on no face is a part of its own, or of the vertices at its coordinates.
    sizes : ndarray of int64
        ``sizes[label]``: how many vertices have that label.
    """

    labels: np.ndarray
    sizes: np.ndarray


def mesh_parts(points: np.ndarray, triangles: np.ndarray) -> MeshParts:
    """Label each vertex with its part, and count each part's vertices.

    Parameters
    ----------
    points : ndarray, shape (n, 3)
    triangles : ndarray of int, shape (m, 3)

    Returns
    -------
    MeshParts

    Notes
    -----
    The faces are labelled first (:func:`part_labels`); only where they make more than one part
    are the vertices sorted by their coordinates, and parts holding the same coordinates joined.
    """
    n = points.shape[0]
    labels = part_labels(n, triangles)
    if triangles.shape[0] and (labels[triangles[:, 0]] != labels[triangles[0, 0]]).any():
        first, second = _same_coordinates(points)
        apart = labels[first] != labels[second]
        if apart.any():
            labels = edge_components(n, labels[first[apart]], labels[second[apart]])[labels]
    return MeshParts(labels, np.bincount(labels, minlength=n))


def mesh_rims(points: np.ndarray, triangles: np.ndarray) -> tuple[np.ndarray, float]:
    """The vertices on the mesh's rims, and the median length of the rims' edges.

    A rim edge is used by one face alone, copies at the same coordinates taken as one vertex
    (so an STL's soup has the rims of the merged mesh). Returns a mask of shape (n,) and the
    median (0 where there is no rim); for :func:`touching`.
    """
    n = points.shape[0]
    welded = edge_components(n, *_same_coordinates(points))  # each vertex as its first copy
    low, high = _boundary_edges(welded[triangles], n)
    edge = float(np.median(np.linalg.norm(points[low] - points[high], axis=1))) if low.size else 0.0
    rim = np.zeros(n, dtype=bool)
    rim[low], rim[high] = True, True
    return rim[welded], edge


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


def _boundary_edges(welded: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """The ends of the edges that one of the ``welded`` faces alone uses."""
    start, end = corner_ends(welded)
    keys = np.minimum(start, end) * np.int64(n) + np.maximum(start, end)
    keys = keys[start != end]
    keys.sort()
    once = np.ones(keys.size, dtype=bool)
    same = keys[1:] == keys[:-1]
    once[1:] &= ~same
    once[:-1] &= ~same
    return keys[once] // n, keys[once] % n


def _pairs_within(points: np.ndarray, ids: np.ndarray, gap: float):
    """Pairs of ``ids`` (two different ones) whose points lie at most ``gap`` apart."""
    index = GridIndex(points[ids], cell_size=gap, ids=ids)
    found = list(neighbour_pairs(index, gap))
    first = np.concatenate([pair[0] for pair in found])
    second = np.concatenate([pair[1] for pair in found])
    keep = first != second
    return first[keep], second[keep]


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


def touching(
    points: np.ndarray, boundary: np.ndarray, patch: np.ndarray, left_out: np.ndarray, gap: float
) -> int:
    """How many of the boundary vertices ``left_out`` lie within ``gap`` of a boundary vertex of
    ``patch``: a large part left out whose rim runs along the measured part's (a seam whose
    copies were not merged, or a crack), where leaving it out cuts a face of the edge away. A
    fragment or a sheet of debris lying over a face has its rim elsewhere."""
    patch, left_out = patch[boundary[patch]], left_out[boundary[left_out]]
    if not left_out.size or not patch.size or not gap > 0:
        return 0
    first, second = _pairs_within(points, np.concatenate([patch, left_out]), gap)
    side = np.zeros(points.shape[0], dtype=np.int8)
    side[patch], side[left_out] = 1, 2
    cross = side[first] != side[second]
    return int(np.unique(np.where(side[first[cross]] == 2, first[cross], second[cross])).size)


def crumb_vertices(
    labels: np.ndarray, sizes: np.ndarray, ball_size: int, patch: np.ndarray
) -> np.ndarray | None:
    """Which vertices of a Euclidean ``patch`` (from :func:`measured_part`) lie on crumbs.

    Parameters
    ----------
    labels, sizes : ndarray of int
        :func:`mesh_parts` of the mesh.
    ball_size : int
        How many vertices the ball held, before large parts were left out.
    patch : ndarray of int
        The patch's vertices.

    Returns
    -------
    ndarray of bool or None
        ``True`` for the vertices of parts smaller than the rest of the ball (see
        :func:`measured_part`), in the order of ``patch``; ``None`` where the patch lies on one
        part (one gather), or where every part in it is a crumb (there is no surface to measure
        without them).
    """
    patch_labels = np.take(labels, patch)
    if (patch_labels == patch_labels[0]).all():
        return None
    parts, part = np.unique(patch_labels, return_inverse=True)
    part = part.reshape(-1)
    inside = np.bincount(part, minlength=parts.size)
    crumb = sizes[parts] + inside < ball_size
    return crumb[part] if crumb.any() and not crumb.all() else None
