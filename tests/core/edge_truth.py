"""Scoring found break edges against a synthetic fragment's true ones (the issue's metric).

A true edge counts as found where a found path passes within ``tolerance`` (one mean edge
length of the mesh); found length is false where no true edge lies within ``tolerance``. Both
are measured on polylines resampled every 0.05 mm, so the fractions are fractions of length.
"""

from __future__ import annotations

import itertools

import numpy as np

STEP = 0.05  # mm between samples


def resample(polyline: np.ndarray, step: float = STEP) -> np.ndarray:
    """Points along ``polyline`` at most ``step`` apart (its vertices included)."""
    polyline = np.asarray(polyline, dtype=np.float64)
    pieces = [polyline[:1]]
    for a, b in itertools.pairwise(polyline):
        count = max(1, int(np.ceil(np.linalg.norm(b - a) / step)))
        t = np.arange(1, count + 1)[:, None] / count
        pieces.append(a + t * (b - a))
    return np.vstack(pieces)


def nearest_distances(queries: np.ndarray, targets: np.ndarray, chunk: int = 2048) -> np.ndarray:
    """Distance from each query point to the nearest target point (brute force, in chunks)."""
    out = np.empty(len(queries))
    if len(targets) == 0:
        out.fill(np.inf)
        return out
    squared = np.einsum("ij,ij->i", targets, targets)
    for first in range(0, len(queries), chunk):
        q = queries[first : first + chunk]
        d2 = np.einsum("ij,ij->i", q, q)[:, None] - 2 * (q @ targets.T) + squared[None, :]
        out[first : first + chunk] = np.sqrt(np.maximum(d2.min(axis=1), 0.0))
    return out


def mean_edge_length(points: np.ndarray, triangles: np.ndarray) -> float:
    """Mean length of the mesh's (undirected) edges."""
    edges = np.vstack([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    edges = np.unique(np.sort(edges, axis=1), axis=0)
    return float(np.linalg.norm(points[edges[:, 0]] - points[edges[:, 1]], axis=1).mean())


def score(fragment, paths, tolerance: float | None = None) -> dict:
    """Recall (share of true edge length found) and false share (of the found length).

    Parameters
    ----------
    fragment : vg_addon.fragments.Fragment
    paths : sequence of ndarray, shape (k, 3)
        The found edges as polylines.
    tolerance : float, optional
        Default: the mesh's mean edge length.
    """
    if tolerance is None:
        tolerance = mean_edge_length(fragment.points, fragment.triangles)
    truth = np.vstack([resample(edge) for edge in fragment.edges])
    found = np.vstack([resample(p) for p in paths]) if len(paths) else np.zeros((0, 3))
    found_near = nearest_distances(truth, found) <= tolerance
    false = nearest_distances(found, truth) > tolerance if len(found) else np.zeros(0, bool)
    return {
        "recall": float(found_near.mean()),
        "false": float(false.mean()) if false.size else 0.0,
        "tolerance": tolerance,
        "found_length": float(sum(np.linalg.norm(np.diff(p, axis=0), axis=1).sum() for p in paths)),
        "true_length": float(
            sum(np.linalg.norm(np.diff(e, axis=0), axis=1).sum() for e in fragment.edges)
        ),
    }


def found_on(make, noise: float = 0.0, tolerance: float | None = None, seed: int = 1, **parameters):
    """Run the finder on the fragment ``make()`` makes, with noise of ``noise`` mean edge
    lengths (noise seed ``seed``) if any, and score it. ``parameters``: break-edge parameters to
    change from the defaults (e.g. ``scale=2.0``).

    Returns ``(fragment, surface, result, figures)``; ``figures`` as :func:`score` gives them.
    """
    from vg_addon import Surface
    from vg_addon.fragments import with_noise

    fragment = make()
    if noise:
        h = mean_edge_length(fragment.points, fragment.triangles)
        fragment = with_noise(fragment, noise * h, seed=seed)
    surface = Surface(fragment.points, fragment.triangles)
    result = surface.find_break_edges(**parameters)
    figures = score(fragment, [c.path.points for c in result.candidates], tolerance)
    return fragment, surface, result, figures
