"""Which way a mesh's faces are wound: outward or inward for a closed surface, by its signed volume.

The oriented rule reads the same angle whichever way the whole mesh is wound, but the
convex/concave label is relative to the normals: on an inward-wound mesh a convex edge reads
"concave". A closed surface says which way is out (its signed volume is positive when the faces
are wound outward); an open scan does not, so there the label is relative to the normals as given.
Where only some faces are flipped (mixed winding), an edge between a flipped face and another
reads as the supplement of its angle: the refined rule refuses it where the sides show it
(``planes.sides_contradict_normals``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import fins

WINDINGS = ("outward", "inward", "mixed", "open")
"""``"outward"``/``"inward"``: closed and consistently wound, with positive/negative volume.
``"mixed"``: closed, but neighbouring faces are wound against each other (some faces flipped).
``"open"``: the surface has a boundary (or edges shared by more than two faces, or no volume), so
which side is outside cannot be decided."""


_CHUNK = 1 << 18  # triangles per block: the temporaries stay small


def mesh_winding(
    points: np.ndarray,
    triangles: np.ndarray | None,
    corner_edges: np.ndarray | None = None,
    census: EdgeCensus | None = None,
) -> str:
    """Classify the winding of a triangle mesh (see :data:`WINDINGS`).

    Parameters
    ----------
    points : ndarray, shape (n, 3)
    triangles : ndarray of int, shape (m, 3), or None
        ``None`` (a point cloud) is ``"open"``. Fewer than 2**31 vertices.
    corner_edges : ndarray of int, shape (m, 3) or (3 m,), optional
        For each corner, the id of the undirected edge from it to the next corner of its
        triangle, aligned with ``triangles.ravel()`` (Blender's ``.corner_edge`` of an
        all-triangle mesh), one id per pair of vertices. Spares sorting the edges.
    census : EdgeCensus, optional
        :func:`edge_census` of the same triangles, if already taken.

    Returns
    -------
    str
        One of :data:`WINDINGS`.
    """
    if triangles is None or len(triangles) == 0:
        return "open"
    if census is None:
        census = edge_census(points, triangles, corner_edges)
    if not census.closed:
        return "open"  # a boundary, or an edge of more than two faces
    if not census.consistent:
        return "mixed"  # each edge is used twice, but twice in the same direction somewhere
    volume = _signed_volume(points, triangles)
    if volume == 0.0:
        return "open"
    return "outward" if volume > 0 else "inward"


@dataclass(frozen=True)
class EdgeCensus:
    """How a triangle mesh's edges are used, from one pass over its corners.

    Attributes
    ----------
    closed : bool
        Every edge is used by exactly two faces.
    consistent : bool
        Closed, and each edge is used once each way.
    fin_vertices : ndarray of int64
        The vertices of edges used by three or more faces with area (see :mod:`.fins`).
    """

    closed: bool
    consistent: bool
    fin_vertices: np.ndarray


def edge_census(points: np.ndarray, triangles: np.ndarray, corner_edges=None) -> EdgeCensus:
    """Take the :class:`EdgeCensus` of a triangle mesh, from a sort of the corners' edges or,
    given each corner's edge id (see :func:`mesh_winding`), from counts."""
    if corner_edges is not None:
        return _census_by_id(points, triangles, corner_edges)
    keys = _sorted_corner_keys(triangles, points.shape[0])
    closed, consistent = _pairs(keys)
    if closed:
        return EdgeCensus(True, consistent, np.empty(0, dtype=np.int64))
    keys >>= 1  # the undirected edges, still sorted
    return EdgeCensus(False, False, fins.from_sorted_edges(keys, points, triangles))


def _sorted_corner_keys(triangles: np.ndarray, n: int) -> np.ndarray:
    """A key per corner, sorted: the undirected edge (low, high) times two, plus one when the
    corner runs from high to low. Collapsed corners (both ends one vertex) add no key."""
    m = triangles.shape[0]
    keys = np.empty(3 * m, dtype=np.int64)
    for first in range(0, m, _CHUNK):
        start, end = fins.corner_ends(triangles[first : first + _CHUNK])
        low = np.minimum(start, end)
        key = low * np.int64(n)
        key += np.maximum(start, end)
        key *= 2
        key += start > end
        key[start == end] = -1
        keys[3 * first : 3 * first + key.size] = key
    keys.sort()
    return keys[np.searchsorted(keys, 0) :]


def _pairs(keys: np.ndarray) -> tuple[bool, bool]:
    """Whether every edge of the sorted corner ``keys`` is used by exactly two faces (closed),
    and once each way (consistent)."""
    if keys.size % 2:
        return False, False
    # Closed: sorted, the keys come in pairs of one edge, each edge in one pair only.
    consistent = True
    for first in range(0, keys.size, 2 * _CHUNK):
        block = keys[first : first + 2 * _CHUNK + 1]  # and the next pair's first key
        one, other = block[0:-1:2], block[1::2]
        edge = one >> 1
        if (edge != other >> 1).any() or (edge[1:] == other[:-1] >> 1).any():
            return False, False
        if block.size % 2 and block[-1] >> 1 == other[-1] >> 1:
            return False, False
        consistent = consistent and bool((other - one == 1).all())
    return True, consistent


def _census_by_id(points, triangles: np.ndarray, corner_edges: np.ndarray) -> EdgeCensus:
    """:func:`edge_census` from each corner's edge id: counts instead of a sort."""
    ids = np.asarray(corner_edges).ravel()
    m = triangles.shape[0]
    if ids.size != 3 * m:
        raise ValueError(f"{ids.size} corner edges for {m} triangles: expected {3 * m}.")
    size = int(ids.max()) + 1
    uses = np.zeros(size, dtype=np.int64)
    forward = np.zeros(size, dtype=np.int64)
    step = 8 * _CHUNK  # large blocks: each bincount walks all the edge counts
    for first in range(0, m, step):
        start, end = fins.corner_ends(triangles[first : first + step])
        block = ids[3 * first : 3 * first + start.size]
        uses += np.bincount(block[start != end], minlength=size)
        forward += np.bincount(block[start < end], minlength=size)
    if ((uses == 0) | (uses == 2)).all():
        return EdgeCensus(True, bool((2 * forward == uses).all()), np.empty(0, dtype=np.int64))
    return EdgeCensus(False, False, fins.from_edge_uses(uses, ids, points, triangles))


def _signed_volume(points: np.ndarray, triangles: np.ndarray) -> float:
    """Six times the signed volume, in units of the used vertices' extent around their mean."""
    used = np.zeros(points.shape[0], dtype=bool)
    used[triangles.ravel()] = True
    # All used: the same rows, in the same (C) layout, so the same sums, without a copy.
    corners = points if used.all() and points.flags.c_contiguous else points[used]
    origin = corners.mean(axis=0)
    scale = max(float(np.abs(corners[:, k] - origin[k]).max()) for k in range(3)) or 1.0
    del corners
    # Per face, then one sum over all faces (its rounding depends on the whole array). The cross
    # product written out is np.cross's arithmetic, element for element, without its overhead.
    m = triangles.shape[0]
    volumes = np.empty(m, dtype=np.float64)
    for first in range(0, m, _CHUNK):
        block = triangles[first : first + _CHUNK]
        a, b, c = (np.take(points, block[:, k], axis=0) for k in range(3))
        for corner in (a, b, c):
            corner -= origin
            corner /= scale
        cross = np.empty_like(a)
        np.subtract(b[:, 1] * c[:, 2], b[:, 2] * c[:, 1], out=cross[:, 0])
        np.subtract(b[:, 2] * c[:, 0], b[:, 0] * c[:, 2], out=cross[:, 1])
        np.subtract(b[:, 0] * c[:, 1], b[:, 1] * c[:, 0], out=cross[:, 2])
        volumes[first : first + block.shape[0]] = np.einsum("ij,ij->i", a, cross)
    return float(volumes.sum())


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
            f"Some faces of '{name}' are wound against their neighbours: an edge between a "
            "flipped face and another reads as the supplement of its angle (the refined rule "
            "refuses it where it can tell), and labels near them may be wrong. Recalculate its "
            "normals (outside) to fix them."
        )
    return ""
