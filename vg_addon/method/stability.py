"""The stability figure: how much a measurement's angle moves under the changes of centre, radius
and λ that make two drag measurements of one edge differ, and under a bootstrap of its vertices,
plus how far it moves when the vertices next to the crease are left out (:mod:`.crease_band`).

All perturbed measurements run at once on one pool of vertices (the ball that holds every
perturbed patch; for the bootstrap, the patch itself): Algorithm 1 batched over the rows of a
``(runs, vertices)`` weight matrix (0/1 for a patch, counts for a resample), every sum an exact
matrix product and the WithinSS split a row-wise sort and prefix sums. No Python loop runs over
vertices.
"""

from __future__ import annotations

import numpy as np

from ..errors import GoniometerError
from .algorithm import FLAT_TOLERANCE_DEG, MIN_SIDE_VERTICES
from .crease_band import crease_change
from .fixed_order import (
    acos_degrees_array,
    combine,
    eigh3_batched,
    exact_integer_sums,
    rows_dot,
    split_exactly,
)
from .planes import RANK_TOLERANCE
from .refinement import mean_edge_length
from .result import Measurement, Stability

SMALL_PATCH_VERTICES = 100
"""A patch of fewer vertices always carries its stability figure, asked for or not. Its faces'
planes rest on a few rows of vertices, where a reading can be degrees off with nothing in the fit
error to show it (a 90° fold meshed by Qhull with 2% noise: up to 14° off at 10-18 vertices, 3.8°
at 26-34, 1.1° at 47-61; docs/METHOD.md), and the figure costs about 10 ms there."""

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

MAX_RUN_VERTICES = 4_000_000
"""The most perturbed runs times pool vertices the figure computes at once (its arrays hold a
few dozen bytes per run and vertex: about 250 MB at this limit). 95 runs over a patch of 30,000
vertices fit; a radius that takes in most of a large scan does not, and is refused before
anything is allocated."""


def _moved_centers(surface, m: Measurement) -> np.ndarray:
    """Vertices within two mean edge lengths of the centre (not the centre), nearest first."""
    reach = CENTER_EDGE_LENGTHS * mean_edge_length(m.radius, m.n_vertices)
    ids, distance = surface.index.ball(m.center, reach)
    keep = ids != m.center_index
    if (taken := surface.on_measured_parts(ids, m)) is not None:
        keep &= taken
    ids, distance = ids[keep], distance[keep]
    coords = surface.points[ids]
    order = np.lexsort((coords[:, 2], coords[:, 1], coords[:, 0], distance))
    return ids[order[:MAX_CENTERS]]


_PAIRS = ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))
"""The six distinct entries of a symmetric 3×3 matrix, row by row."""

# Columns of the per-vertex features whose weighted sums Algorithm 1 needs (see _features).
_NN, _N, _L, _NL, _LL = slice(0, 6), slice(6, 9), slice(9, 12), slice(12, 21), slice(21, 27)
_SIDE = np.r_[9:12, 21:27, 6:9]  # a side's plane: coordinates, their products, normals


def _features(local: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """Per vertex, ``(m, 27)``: the distinct products of the normal's components, the normal, the
    coordinates, the products of normal and coordinate components, and the distinct products of
    the coordinates' components. Weighted sums of these are every sum Algorithm 1 takes."""
    columns = [normals[:, i] * normals[:, j] for i, j in _PAIRS]
    columns += [normals[:, i] for i in range(3)] + [local[:, i] for i in range(3)]
    columns += [normals[:, i] * local[:, j] for i in range(3) for j in range(3)]
    columns += [local[:, i] * local[:, j] for i, j in _PAIRS]
    return np.stack(columns, axis=1)


def _symmetric(distinct: np.ndarray) -> np.ndarray:
    """``(k, 3, 3)`` symmetric matrices from their six distinct entries, ``(k, 6)``."""
    out = np.empty((distinct.shape[0], 3, 3))
    for column, (i, j) in enumerate(_PAIRS):
        out[:, i, j] = out[:, j, i] = distinct[:, column]
    return out


def _side_covariances(sums: np.ndarray, count: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Covariance matrices of weighted vertex sets, and their weighted mean normals.

    ``sums`` are the sets' weighted sums of the side features (coordinates, their six distinct
    products, normals), ``(k, 12)``; ``count`` their total weights."""
    scaled = sums / np.maximum(count, 1.0)[:, None]
    mean = scaled[:, :3]
    return _symmetric(scaled[:, 3:9]) - mean[:, :, None] * mean[:, None, :], scaled[:, 9:12]


def _side_normals(values, vectors, mean_normals, count) -> tuple[np.ndarray, np.ndarray]:
    """Plane normals (oriented by the side's mean normal) from the covariances' eigen-pairs, and
    whether each set spans a plane with at least the minimum number of vertices."""
    normal = vectors[:, :, 0]
    spans = values[:, 1] > RANK_TOLERANCE * np.maximum(values[:, 2], np.finfo(float).tiny)
    flip = rows_dot(normal, mean_normals) < 0
    normal[flip] = -normal[flip]
    return normal, spans & (count >= MIN_SIDE_VERTICES)


_PROJECTION_ROWS = 16
"""Rows of the projection computed together: a block stays in the CPU's cache between its terms."""


def _projection(binormal, scale, normals, local, offset) -> np.ndarray:
    """``p = bᵀ(N + s X) − offset`` for every row and pool vertex, ``(k, m)``, in a fixed order
    (a matrix product would leave the order to BLAS). Rows that share ``s`` (the same λ/r and
    sign) share ``N + s X``, so each row costs three products."""
    out = np.empty((binormal.shape[0], normals.shape[0]))
    term = np.empty((_PROJECTION_ROWS, normals.shape[0]))
    values, group = np.unique(scale, return_inverse=True)
    for g, value in enumerate(values):
        rows = np.flatnonzero(group == g)
        columns = (normals + value * local).T.copy()  # contiguous rows: N + s X, per axis
        for start in range(0, rows.size, _PROJECTION_ROWS):
            block_rows = rows[start : start + _PROJECTION_ROWS]
            factors, block_term = binormal[block_rows], term[: block_rows.size]
            block = np.multiply(factors[:, :1], columns[0])
            for i in (1, 2):
                np.multiply(factors[:, i : i + 1], columns[i], out=block_term)
                block += block_term
            block -= offset[block_rows, None]
            out[block_rows] = block
    return out


def _best_splits(
    projection, members, weights, count, row_mean, draws=None
) -> tuple[np.ndarray, np.ndarray]:
    """Each row's WithinSS split of its members' projections (weighted), as the smallest value of
    the upper side, and whether the row has a split leaving both sides enough vertices.

    Members come first in sorted order, non-members (+inf) after them; a split after position
    ``j`` maximises the between-sides sum of squares ``P_j² W / (L_j (W - L_j))``.
    ``draws``: for a bootstrap, the positions drawn in each row, ``(k, n)`` (their counts are
    ``weights``).
    """
    if draws is None:
        masked = np.where(members, projection, np.inf)
        n_members = members.sum(axis=1)
    else:
        # A vertex drawn c times is c equal values: the weighted split is the plain split of the
        # drawn values, which a sort of values alone orders the same on every CPU.
        masked = np.take_along_axis(projection, draws, axis=1)
        n_members = np.full(draws.shape[0], draws.shape[1])
    # Only the first (most members) columns can hold a split; the rest are +inf in every row.
    width = min(masked.shape[1], max(int(n_members.max(initial=0)), 2))
    # Members tied at a value add equal terms, so the sorted values alone give the same sums as
    # any order of them would, if every member's projection is finite.
    ordered = np.sort(masked, axis=1)[:, :width]
    last = ordered[np.arange(ordered.shape[0]), np.maximum(n_members, 1) - 1]
    if not ((np.isfinite(ordered[:, 0]) & np.isfinite(last)) | (n_members == 0)).all():
        return _weighted_splits(projection, members, weights, count, row_mean)
    position = np.arange(width - 1)
    lower = position + 1.0  # members below a split after position j
    total = count[:, None]
    with np.errstate(divide="ignore", invalid="ignore"):
        # Past the members the sums are +inf: those splits are never allowed.
        prefix = np.cumsum(ordered - row_mean, axis=1)[:, :-1]
        between = prefix * prefix * total / (lower * (total - lower))
    allowed = ordered[:, 1:] > ordered[:, :-1]
    allowed &= position >= MIN_SIDE_VERTICES - 1
    allowed &= position[None, :] < (n_members - MIN_SIDE_VERTICES)[:, None]
    best = np.argmax(np.where(allowed, between, -np.inf), axis=1)
    return ordered[np.arange(ordered.shape[0]), best + 1], allowed.any(axis=1)


def _weighted_splits(projection, members, weights, count, row_mean):
    """:func:`_best_splits` where some member's projection is not finite (never on finite
    coordinates; kept so that such a row is refused, not a crash): a weighted split of the
    finite values."""
    masked = np.where(members, projection, np.inf)
    n_members = members.sum(axis=1)
    width = min(masked.shape[1], max(int(n_members.max(initial=0)), 2))
    order = np.argsort(masked, axis=1)[:, :width]
    ordered = np.take_along_axis(masked, order, axis=1)
    ordered_weights = np.take_along_axis(weights, order, axis=1)
    total = count[:, None]
    inside = np.arange(width)[None, :] < n_members[:, None]
    centred = np.where(inside, ordered - row_mean, 0.0)
    # The sort leaves tied values in an order of its own (it differs between CPUs); their
    # weights are summed first, exactly, and enter once per distinct value, at its last place.
    running = np.cumsum(ordered_weights, axis=1, dtype=np.float64)
    run_end = np.ones(ordered.shape, dtype=bool)
    run_end[:, :-1] = ordered[:, 1:] != ordered[:, :-1]
    before = np.zeros_like(running)
    before[:, 1:] = np.maximum.accumulate(np.where(run_end, running, 0.0), axis=1)[:, :-1]
    centred *= np.where(run_end, running - before, 0.0)
    lower = running[:, :-1]
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
        bootstrap count for a resample); whole numbers.
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
    (result,) = _run_together(
        _algorithm_steps(local, normals, weights, centers, position_scale, rule)
    )
    return result


def _run_together(*batches) -> list:
    """Run :func:`_algorithm_steps` generators in step, each of their 3×3 eigen-problems solved
    in one call for all of them (the solver's cost is mostly per call, not per matrix)."""
    requests = [next(batch) for batch in batches]
    while True:
        ends = np.cumsum([len(request) for request in requests])[:-1]
        values, vectors = eigh3_batched(np.concatenate(requests))
        answers = zip(np.split(values, ends), np.split(vectors, ends), strict=True)
        requests, results = [], []
        for batch, answer in zip(batches, answers, strict=True):
            try:
                requests.append(batch.send(answer))
            except StopIteration as finished:
                results.append(finished.value)
        if results:
            return results


def _algorithm_steps(
    local, normals, weights, centers, position_scale, rule: str, split=None, draws=None
):
    """:func:`batched_angles` as a generator: it yields the 3×3 matrices whose eigen-pairs it
    needs and is sent them back (see :func:`_run_together`); it returns the angles and flags.
    ``split``: :func:`split_exactly` of the pool's features, if already made (for at least as
    many terms as a row of ``weights`` adds up to); ``draws``: see :func:`_best_splits`."""
    weights = np.asarray(weights)
    # Whole-number weights (0/1 or counts) are gathered and summed in their own narrow type: their
    # running sums are exact integers, the same in float64 whatever the order.
    whole = weights.dtype.kind in "biu"  # booleans and integers are whole numbers already
    raw = weights if whole else weights.astype(np.float64)
    weights = weights.astype(np.float64)
    if not whole and not np.array_equal(weights, np.round(weights)):
        raise ValueError("batched_angles needs whole-number weights (memberships or counts)")
    members = weights > 0
    count = weights.sum(axis=1)
    ok = count >= 2 * MIN_SIDE_VERTICES
    safe = np.maximum(count, 1.0)

    # Every sum over a patch is a product of the whole-number weights with the pool's features,
    # made exact (see fixed_order.exact_integer_sums): no order, kernel or thread changes it.
    if split is None:
        split = split_exactly(_features(local, normals), int(count.max(initial=1.0)))
    parts = exact_integer_sums(weights, split)
    sums = combine(parts, split)
    values, vectors = yield _symmetric(sums[:, _NN])
    tangent = vectors[:, :, 0]
    weighted_normal = sums[:, _N]
    mean_normal = weighted_normal / safe[:, None]
    cross = np.cross(tangent, mean_normal)
    cross_norm = np.sqrt(rows_dot(cross, cross))
    ok &= (values[:, 1] > 1e-12 * values[:, 2]) & (cross_norm > 1e-12)
    binormal = cross / np.maximum(cross_norm, 1e-300)[:, None]

    center_b = rows_dot(centers, binormal)
    sum_q = rows_dot(binormal, weighted_normal)
    sum_u = rows_dot(binormal, sums[:, _L]) - count * center_b
    if rule != "paper":
        cross_moments = sums[:, _NL].reshape(-1, 3, 3)
        terms = binormal[:, :, None] * cross_moments * binormal[:, None, :]
        sum_qu = np.add.reduce(terms.reshape(-1, 9), axis=1) - center_b * sum_q
        sign = np.where(sum_qu - sum_q * sum_u / safe < 0, -1.0, 1.0)
    else:
        sign = np.ones(weights.shape[0])
    scale = sign * position_scale
    projection = _projection(binormal, scale, normals, local, scale * center_b)
    row_mean = ((sum_q + scale * sum_u) / safe)[:, None]

    threshold, split_found = _best_splits(projection, members, raw, count, row_mean, draws)
    ok &= split_found
    plus = members & (projection >= threshold[:, None])

    # The "+" sides' sums by an exact product; the "−" sides' are the rest of the patch's, exactly.
    side_split = split.columns(_SIDE)
    plus_weights = np.where(plus, weights, 0.0)
    plus_parts = exact_integer_sums(plus_weights, side_split)
    side_parts = np.concatenate([plus_parts, parts[:, split.part_columns(_SIDE)] - plus_parts])
    plus_count = plus_weights.sum(axis=1)
    side_count = np.concatenate([plus_count, count - plus_count])
    covariances, side_mean_normals = _side_covariances(combine(side_parts, side_split), side_count)
    values, vectors = yield covariances
    normals_both, planes = _side_normals(values, vectors, side_mean_normals, side_count)
    k = weights.shape[0]
    normal_plus, normal_minus = normals_both[:k], normals_both[k:]
    ok &= planes[:k] & planes[k:]
    angle = 180.0 - acos_degrees_array(rows_dot(normal_plus, normal_minus))
    ok &= (angle >= FLAT_TOLERANCE_DEG) & (angle <= 180.0 - FLAT_TOLERANCE_DEG)
    return angle, ok


def bootstrap_angles(surface, m: Measurement, n_resamples: int = N_BOOTSTRAP):
    """Algorithm 1 on bootstrap resamples of the patch's vertices (drawn with replacement): the
    tangent, binormal, split and planes are all estimated again from each resample.

    Returns the angles and which resamples Algorithm 1 would measure (see
    :func:`batched_angles`).
    """
    (result,) = _run_together(_bootstrap_steps(surface, m, n_resamples))
    return result


def _bootstrap_steps(surface, m: Measurement, n_resamples: int, pool=None):
    """The bootstrap's batch; ``pool``: the perturbed runs' ``(ids, local, normals, split)``,
    which hold the patch, to share their features."""
    size = m.indices.size
    _check_size(n_resamples, size)
    rng = np.random.default_rng(BOOTSTRAP_SEED)
    draws = rng.integers(0, size, size=(n_resamples, size))
    flat = (draws + size * np.arange(n_resamples)[:, None]).ravel()
    counts = np.bincount(flat, minlength=n_resamples * size).reshape(n_resamples, size)
    if pool is None:
        local = (surface.points[m.indices] - m.center) / m.radius
        normals, split = surface.normals[m.indices], None
    else:
        ids, pool_local, pool_normals, pool_split = pool
        at = np.searchsorted(ids, m.indices)
        local, normals, split = pool_local[at], pool_normals[at], pool_split.rows(at)
    return _algorithm_steps(
        local,
        normals,
        counts,
        np.zeros((n_resamples, 3)),
        np.full(n_resamples, m.lam),
        m.rule,
        split,
        draws,
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
    (result,) = _run_together(_perturbed_steps(surface, m, center_ids, radii, lams))
    return result


def _perturbed_steps(surface, m: Measurement, center_ids, radii, lams, pool=None):
    """The perturbed runs' batch, on ``pool`` (see :func:`_pool`) if given."""
    ids, local, normals, split = _pool(surface, m, center_ids, radii) if pool is None else pool
    if m.patch == "geodesic":
        members = np.zeros((center_ids.size, ids.size), dtype=bool)
        for row, (center, radius) in enumerate(zip(center_ids, radii, strict=True)):
            members[row, np.searchsorted(ids, surface.patch(center, radius, "geodesic"))] = True
    else:
        offsets = surface.points[ids][None, :, :] - surface.points[center_ids][:, None, :]
        members = np.einsum("kmi,kmi->km", offsets, offsets) <= (radii * radii)[:, None]
    centers = (surface.points[center_ids] - m.center) / m.radius
    return _algorithm_steps(
        local, normals, members, centers, lams * m.radius / radii, m.rule, split
    )


def _check_size(runs: int, vertices: int) -> None:
    """Refuse a figure larger than :data:`MAX_RUN_VERTICES`, before allocating it."""
    if runs * vertices > MAX_RUN_VERTICES:
        raise GoniometerError(
            f"The stability figure would run {runs} perturbed measurements over {vertices:,} "
            f"vertices, more than the {MAX_RUN_VERTICES:,} run-vertices it is limited to (about "
            f"{MAX_RUN_VERTICES // runs:,} vertices around the centre): use a smaller radius, or "
            "measure without the figure."
        )


def _pool(surface, m: Measurement, center_ids, radii):
    """The vertices every perturbed patch (and the measurement's own) is drawn from: sorted
    ids, coordinates relative to the centre in units of the radius, normals, and the split of
    their features for exact sums of up to all of them."""
    reach = float(np.linalg.norm(surface.points[center_ids] - m.center, axis=1).max())
    ids, _ = surface.index.ball(m.center, float(radii.max()) + reach)
    if (taken := surface.on_measured_parts(ids, m)) is not None:
        ids = ids[taken]
    _check_size(center_ids.size + N_BOOTSTRAP, ids.size)
    ids = np.sort(ids)
    local = (surface.points[ids] - m.center) / m.radius
    normals = surface.normals[ids]
    return ids, local, normals, split_exactly(_features(local, normals), ids.size)


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
    pool = _pool(surface, m, center_ids, radii)
    (angles, measured), (resampled, kept) = _run_together(
        _perturbed_steps(surface, m, center_ids, radii, lams, pool),
        _bootstrap_steps(surface, m, N_BOOTSTRAP, pool),
    )
    # The runs are Algorithm 1's (the batched steps have no refinement): they are compared with
    # Algorithm 1's own reading, so the figure is how far the split moves, not the refinement's gain.
    reference = m.angle if m.split_angle is None else m.split_angle
    parts = {
        name: _largest_change(angles[rows], measured[rows], reference)
        for name, rows in families.items()
    }
    low, high = np.percentile(resampled[kept], [2.5, 97.5]) if kept.any() else (0.0, 0.0)
    parts["bootstrap"] = float(high - low) / 2.0
    parts["orientation"] = m.orientation_difference
    # The runs above all keep the vertices next to the crease, and so share the tilt they give
    # the planes: that bias is measured apart and added to the spread, not compared with it.
    crease, crease_refused, noise_hides_crease = crease_change(surface, m)
    return Stability(
        spread=max(parts.values()) + crease,
        **parts,
        n_runs=int(center_ids.size + kept.size),
        n_failed=int((~measured).sum() + (~kept).sum()),
        crease=crease,
        crease_refused=crease_refused,
        noise_hides_crease=noise_hides_crease,
    )


__all__ = [
    "batched_angles",
    "bootstrap_angles",
    "estimate_stability",
    "mean_edge_length",
    "perturbations",
    "perturbed_angles",
]
