"""The stability figure: how much a measurement's angle moves under the changes of centre, radius
and λ that make two drag measurements of one edge differ, and under a bootstrap of its vertices.

All perturbed measurements run at once on one pool of vertices (the ball that holds every
perturbed patch; for the bootstrap, the patch itself): Algorithm 1 batched over the rows of a
``(runs, vertices)`` weight matrix (0/1 for a patch, counts for a resample), every sum a matrix
product and the WithinSS split a row-wise sort and prefix sums. No Python loop runs over vertices.
"""

from __future__ import annotations

import math

import numpy as np

from .algorithm import FLAT_TOLERANCE_DEG, MIN_SIDE_VERTICES
from .result import Measurement, Stability

CENTER_EDGE_LENGTHS = 2.0
"""The centre moves to every vertex within this many mean edge lengths of it."""

MAX_CENTERS = 24
"""At most this many moved centres (the nearest ones), so a dense patch stays cheap."""

RADIUS_FACTORS = (0.9, 1.1)
"""The radius 10% smaller and 10% larger."""

LAMBDAS = (1.0, 1.5, 2.0, 2.5, 3.0)
"""λ across the range users set it to."""

N_BOOTSTRAP = 64
"""Bootstrap resamples of the patch's vertices (enough for a 95% interval to a few tenths of its
width; each costs about a tenth of a measurement, batched)."""

BOOTSTRAP_SEED = 0
"""A fixed seed: the same measurement always gets the same figure."""

_RANK_TOLERANCE = 1e-10  # as Algorithm 1's test for a side on a line


def mean_edge_length(radius: float, n_vertices: int) -> float:
    """Mean edge length of a triangulated disk of ``radius`` holding ``n_vertices`` vertices.

    An equilateral triangulation with edge ``h`` has one vertex per ``(√3 / 2) h²`` of area, so
    ``h = r √(2π / (√3 n))``: an estimate from the patch itself, valid for meshes and point clouds.
    """
    return radius * math.sqrt(2.0 * math.pi / (math.sqrt(3.0) * n_vertices))


def _moved_centers(surface, m: Measurement) -> np.ndarray:
    """Vertices within two mean edge lengths of the centre (not the centre), nearest first."""
    reach = CENTER_EDGE_LENGTHS * mean_edge_length(m.radius, m.n_vertices)
    ids, distance = surface.index.ball(m.center, reach)
    keep = ids != m.center_index
    ids, distance = ids[keep], distance[keep]
    coords = surface.points[ids]
    order = np.lexsort((coords[:, 2], coords[:, 1], coords[:, 0], distance))
    return ids[order[:MAX_CENTERS]]


def _features(local: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """Per vertex: coordinates, their outer product (flattened) and the normal, ``(n, 15)``.

    One matrix product of a weight matrix with these gives every sum a plane fit needs.
    """
    return np.hstack([local, _outer_pairs(local, local), normals])


def _outer_pairs(first: np.ndarray, second: np.ndarray) -> np.ndarray:
    """Row-wise outer products ``first_i second_iᵀ``, flattened: ``(n, 9)``."""
    return (first[:, :, None] * second[:, None, :]).reshape(-1, 9)


def _side_normals(weights: np.ndarray, features: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Plane normals (oriented by the side's mean normal) of weighted vertex sets, and whether
    each set spans a plane with at least the minimum number of vertices."""
    count = weights.sum(axis=1)
    sums = weights @ features / np.maximum(count, 1.0)[:, None]
    mean = sums[:, :3]
    covariance = sums[:, 3:12].reshape(-1, 3, 3) - mean[:, :, None] * mean[:, None, :]
    values, vectors = np.linalg.eigh(covariance)
    normal = vectors[:, :, 0]
    spans = values[:, 1] > _RANK_TOLERANCE * np.maximum(values[:, 2], np.finfo(float).tiny)
    flip = np.einsum("ki,ki->k", normal, sums[:, 12:]) < 0
    normal[flip] = -normal[flip]
    return normal, spans & (count >= MIN_SIDE_VERTICES)


def _best_splits(projection, members, weights, count, row_mean) -> tuple[np.ndarray, np.ndarray]:
    """Each row's WithinSS split of its members' projections (weighted), as the smallest value of
    the upper side, and whether the row has a split leaving both sides enough vertices.

    Members come first in sorted order, non-members (+inf) after them; a split after position
    ``j`` maximises the weighted between-sides sum of squares ``P_j² W / (L_j (W - L_j))``.
    """
    masked = np.where(members, projection, np.inf)
    n_members = members.sum(axis=1)
    # Only the first (most members) columns can hold a split; the rest are +inf in every row.
    width = min(masked.shape[1], max(int(n_members.max(initial=0)), 2))
    ordered_weights = None
    if weights.dtype == bool:
        # With 0/1 weights the members tied at a value add equal terms, so the sorted values alone
        # give the same sums as a permutation would, if every member's projection is finite.
        ordered = np.sort(masked, axis=1)[:, :width]
        last = ordered[np.arange(ordered.shape[0]), np.maximum(n_members, 1) - 1]
        finite = (np.isfinite(ordered[:, 0]) & np.isfinite(last)) | (n_members == 0)
    if weights.dtype != bool or not finite.all():
        order = np.argsort(masked, axis=1)[:, :width]
        ordered = np.take_along_axis(masked, order, axis=1)
        ordered_weights = np.take_along_axis(weights, order, axis=1)
    total = count[:, None]
    inside = np.arange(width)[None, :] < n_members[:, None]
    centred = np.where(inside, ordered - row_mean, 0.0)
    if ordered_weights is None:
        lower = np.minimum(np.arange(1.0, width), total)  # weight below a split after position j
    else:
        centred *= ordered_weights
        lower = np.cumsum(ordered_weights, axis=1, dtype=np.float64)[:, :-1]
    prefix = np.cumsum(centred, axis=1)[:, :-1]
    with np.errstate(divide="ignore", invalid="ignore"):
        between = prefix * prefix * total / (lower * (total - lower))
    allowed = (ordered[:, 1:] > ordered[:, :-1]) & np.isfinite(ordered[:, 1:])
    allowed &= (lower >= MIN_SIDE_VERTICES) & (total - lower >= MIN_SIDE_VERTICES)
    best = np.argmax(np.where(allowed, between, -np.inf), axis=1)
    return ordered[np.arange(ordered.shape[0]), best + 1], allowed.any(axis=1)


def batched_angles(
    local, normals, weights, centers, position_scale, rule: str
) -> tuple[np.ndarray, np.ndarray]:
    """Algorithm 1 on many weighted patches of one pool of vertices at once.

    Parameters
    ----------
    local : ndarray, shape (m, 3)
        Pool coordinates relative to the measurement's centre, divided by its radius.
    normals : ndarray, shape (m, 3)
        Unit normals of the pool.
    weights : ndarray, shape (k, m)
        Row ``j`` is patch ``j``: how many times each vertex is in it (0 or 1 for a patch, a
        bootstrap count for a resample).
    centers : ndarray, shape (k, 3)
        Each patch's centre ``x̄`` in the same local coordinates.
    position_scale : ndarray, shape (k,)
        Each patch's ``λ / r`` in local units.
    rule : {"oriented", "paper"}

    Returns
    -------
    angles : ndarray, shape (k,)
    measured : ndarray of bool, shape (k,)
        False where Algorithm 1 would refuse the patch (too few vertices, no edge, a side on a
        line, flat or folded planes); those angles mean nothing.
    """
    weights = np.asarray(weights)
    # Whole-number weights (0/1 or counts) are gathered and summed in their own narrow type: their
    # running sums are exact integers, the same in float64 whatever the order.
    raw = weights if weights.dtype.kind in "biu" else weights.astype(np.float64)
    weights = weights.astype(np.float64)
    members = weights > 0
    count = weights.sum(axis=1)
    ok = count >= 2 * MIN_SIDE_VERTICES
    safe = np.maximum(count, 1.0)

    values, vectors = np.linalg.eigh((weights @ _outer_pairs(normals, normals)).reshape(-1, 3, 3))
    tangent = vectors[:, :, 0]
    weighted_normal = weights @ normals
    mean_normal = weighted_normal / safe[:, None]
    cross = np.cross(tangent, mean_normal)
    cross_norm = np.linalg.norm(cross, axis=1)
    ok &= (values[:, 1] > 1e-12 * values[:, 2]) & (cross_norm > 1e-12)
    binormal = cross / np.maximum(cross_norm, 1e-300)[:, None]

    # Sums over each patch, as matrix products with the pool: no (k, m) temporaries.
    weighted_local = weights @ local
    center_b = np.einsum("ki,ki->k", centers, binormal)
    sum_q = np.einsum("ki,ki->k", binormal, weighted_normal)
    sum_u = np.einsum("ki,ki->k", binormal, weighted_local) - count * center_b
    if rule == "oriented":
        cross_moments = (weights @ _outer_pairs(normals, local)).reshape(-1, 3, 3)
        sum_qu = np.einsum("ki,kij,kj->k", binormal, cross_moments, binormal) - center_b * sum_q
        sign = np.where(sum_qu - sum_q * sum_u / safe < 0, -1.0, 1.0)
    else:
        sign = np.ones(weights.shape[0])
    scale = sign * position_scale
    # p = bᵀN + s (λ/r) bᵀ(X - x̄), for every row at once.
    projection = np.hstack([binormal, scale[:, None] * binormal]) @ np.hstack([normals, local]).T
    projection -= (scale * center_b)[:, None]
    row_mean = ((sum_q + scale * sum_u) / safe)[:, None]

    threshold, split = _best_splits(projection, members, raw, count, row_mean)
    ok &= split
    plus = members & (projection >= threshold[:, None])

    features = _features(local, normals)
    normal_plus, plane_plus = _side_normals(np.where(plus, weights, 0.0), features)
    normal_minus, plane_minus = _side_normals(np.where(plus, 0.0, weights), features)
    ok &= plane_plus & plane_minus
    cosine = np.clip(np.einsum("ki,ki->k", normal_plus, normal_minus), -1.0, 1.0)
    angle = 180.0 - np.degrees(np.arccos(cosine))
    ok &= (angle >= FLAT_TOLERANCE_DEG) & (angle <= 180.0 - FLAT_TOLERANCE_DEG)
    return angle, ok


def bootstrap_angles(surface, m: Measurement, n_resamples: int = N_BOOTSTRAP):
    """Algorithm 1 on bootstrap resamples of the patch's vertices (drawn with replacement): the
    tangent, binormal, split and planes are all estimated again from each resample.

    Returns the angles and which resamples Algorithm 1 would measure (see
    :func:`batched_angles`).
    """
    size = m.indices.size
    rng = np.random.default_rng(BOOTSTRAP_SEED)
    draws = rng.integers(0, size, size=(n_resamples, size)) + size * np.arange(n_resamples)[:, None]
    counts = np.bincount(draws.ravel(), minlength=n_resamples * size).reshape(n_resamples, size)
    local = (surface.points[m.indices] - m.center) / m.radius
    return batched_angles(
        local,
        surface.normals[m.indices],
        counts,
        np.zeros((n_resamples, 3)),
        np.full(n_resamples, m.lam),
        m.rule,
    )


def _largest_change(angles: np.ndarray, measured: np.ndarray, reference: float) -> float:
    angles = angles[measured]
    return float(np.abs(angles - reference).max()) if angles.size else 0.0


def perturbations(surface, m: Measurement) -> tuple[np.ndarray, np.ndarray, np.ndarray, dict]:
    """The perturbed measurements of the figure: centre vertex, radius and λ of each run.

    Returns
    -------
    center_ids : ndarray of int64, radii : ndarray, lams : ndarray
        One entry per run.
    families : dict of str to slice
        Which runs move the centre (``"center"``), the radius and λ.
    """
    moved = _moved_centers(surface, m)
    center_ids = np.concatenate(
        [moved, np.full(len(RADIUS_FACTORS) + len(LAMBDAS), m.center_index)]
    ).astype(np.int64)
    radii = np.concatenate(
        [
            np.full(moved.size, m.radius),
            m.radius * np.array(RADIUS_FACTORS),
            np.full(len(LAMBDAS), m.radius),
        ]
    )
    lams = np.concatenate([np.full(moved.size + len(RADIUS_FACTORS), m.lam), LAMBDAS])
    families = {
        "center": slice(0, moved.size),
        "radius": slice(moved.size, moved.size + len(RADIUS_FACTORS)),
        "lam": slice(moved.size + len(RADIUS_FACTORS), center_ids.size),
    }
    return center_ids, radii, lams, families


def perturbed_angles(surface, m: Measurement, center_ids, radii, lams):
    """The angles of the perturbed runs, batched, and which of them Algorithm 1 would measure."""
    reach = float(np.linalg.norm(surface.points[center_ids] - m.center, axis=1).max())
    pool, _ = surface.index.ball(m.center, float(radii.max()) + reach)
    pool = np.sort(pool)
    points = surface.points[pool]
    if m.patch == "geodesic":
        members = np.zeros((center_ids.size, pool.size), dtype=bool)
        for row, (center, radius) in enumerate(zip(center_ids, radii, strict=True)):
            members[row, np.searchsorted(pool, surface.patch(center, radius, "geodesic"))] = True
    else:
        offsets = points[None, :, :] - surface.points[center_ids][:, None, :]
        members = np.einsum("kmi,kmi->km", offsets, offsets) <= (radii * radii)[:, None]
    local = (points - m.center) / m.radius
    centers = (surface.points[center_ids] - m.center) / m.radius
    return batched_angles(
        local, surface.normals[pool], members, centers, lams * m.radius / radii, m.rule
    )


def estimate_stability(surface, m: Measurement) -> Stability:
    """The stability figure of a measurement taken on ``surface`` (see :class:`Stability`).

    Parameters
    ----------
    surface : Surface
        The surface ``m`` was measured on.
    m : Measurement
        A measurement from ``surface.measure`` (with ``indices``).

    Returns
    -------
    Stability
    """
    center_ids, radii, lams, families = perturbations(surface, m)
    angles, measured = perturbed_angles(surface, m, center_ids, radii, lams)
    parts = {
        name: _largest_change(angles[rows], measured[rows], m.angle)
        for name, rows in families.items()
    }
    resampled, kept = bootstrap_angles(surface, m)
    low, high = np.percentile(resampled[kept], [2.5, 97.5]) if kept.any() else (0.0, 0.0)
    parts["bootstrap"] = float(high - low) / 2.0
    parts["orientation"] = m.orientation_difference
    return Stability(
        spread=max(parts.values()),
        **parts,
        n_runs=int(center_ids.size + kept.size),
        n_failed=int((~measured).sum() + (~kept).sum()),
    )


__all__ = [
    "batched_angles",
    "bootstrap_angles",
    "estimate_stability",
    "mean_edge_length",
    "perturbations",
    "perturbed_angles",
]
