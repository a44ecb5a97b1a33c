"""Algorithm 1 of the Virtual Goniometer paper on a patch of vertices and normals."""

from __future__ import annotations

import math

import numpy as np

from ..errors import GoniometerError
from .fixed_order import (
    acos_degrees,
    column_moments,
    dot3,
    eigh3,
    eigh3_batched,
    eigh3_entries,
    moments,
    norm3,
    row_dot,
    total,
)
from .inputs import (
    MAX_MAGNITUDE,
    as_center,
    as_lambda,
    as_normals,
    as_points,
    as_radius,
    check_magnitude,
)
from .planes import (
    RANK_TOLERANCE,
    contradicting_normals_message,
    crease_line,
    sides_contradict_normals,
)
from .refinement import NOISE_FLOOR, mean_edge_length, refine_sides
from .result import Measurement
from .withinss import withinss_split

MIN_SIDE_VERTICES = 5
"""A plane needs three vertices, but three or four always fit one (almost) exactly and would
report a precise-looking nonsense; five is the fewest whose fit error means something."""

FLAT_TOLERANCE_DEG = 0.5
"""Angles closer than this to 180° mean the patch holds no break edge."""

PLANES_MEET_WITHIN = 1.0
"""Under the refined rule, the line where the two fitted planes meet must pass within this many
radii of the centre: farther, the edge they measure is not in the patch (the patch reaches past
the two faces at the edge and fitted others, the centre is off the edge, or a near-flat split
missed it). The 1,607 right readings of ``scripts/compare_core_bits.py``'s cases lie within 0.40
radii, the validation cases within 0.76 (docs/METHOD.md)."""

CROSSED_NOISE = 2.5
CROSSED_SHARE = 0.12
CROSSED_MOVE_DEG = 2.0
CROSSED_OFF_EDGE = 0.5
"""Under the refined rule a reading is refused where more than ``CROSSED_SHARE`` of a side's
vertices have normals past the other side by ``CROSSED_NOISE`` times the normals' noise, giving
them to it moves the angle by more than ``CROSSED_MOVE_DEG``, and the planes so fitted meet more
than ``CROSSED_OFF_EDGE`` radii from the centre. On the 27 readings of wedges clicked off the
edge that were 3° to 87° off, the share is 0.14 to 0.91 and giving the vertices over reads the
true angle; on 700 right readings (wedges exact, noisy and jittered, the reference meshes, the
synthetic bone) it is at most 0.09 (docs/METHOD.md)."""

SPLIT_MISSED_FIT = 0.25
"""Under the refined rule, where the faces the normals tell meet at the centre at another angle
than the reading's, and their planes fit with less than this share of the reading's fit error,
the split missed the faces: refused (a mesh much finer on one face than on the other, whose
split halves the fine face)."""

COS_CROSSED_MOVE = 0.9993908270190958
"""cos(:data:`CROSSED_MOVE_DEG`), written out so that the comparison has the same bits anywhere."""


NEAR_FLAT_DEG = 170.0
"""A refused reading above this many degrees is said to be near flat: there the planes' meeting
line is poorly placed, and a larger radius, not a smaller one, is the advice."""

RULES = ("refined", "oriented", "paper")
"""How a measurement is taken. ``"oriented"`` multiplies the position term of the projection by
the sign of the covariance between ``Nᵀb`` and ``(X − x̄)ᵀb``, which makes concave edges and
inward-wound meshes read right. ``"refined"`` (the default) is the oriented rule followed by
:func:`~vg_addon.method.refinement.refine_sides`: each side's plane from the vertices that lie on
it, exact where the crease runs between rows of vertices. ``"paper"`` is Algorithm 1 as printed,
``p = bᵀ[N + (λ/r)(X − x̄)]``, kept to replicate measurements taken with the MeshLab plugin and the
earlier add-on; ``"oriented"`` replicates this extension's measurements taken before the refined rule."""

DEFAULT_RULE = "refined"

CONVEXITIES = ("convex", "concave", "unclear")
"""The edge labels of a measurement, relative to the given (outward) normals."""

WEAK_CORRELATION = 0.2
"""Below this absolute correlation between ``Nᵀb`` and ``(X − x̄)ᵀb`` the sign of the position term
is weakly determined: the patch holds no clear convex or concave edge, so the oriented rule
measures both signs and keeps the better plane fit, and the edge is labelled ``"unclear"``."""

SHARED_ROW_FACTOR = 1.5
"""A side whose vertices lie on one line borrows the other side's vertices within this factor of
the nearest one's distance to that line: the row of vertices on the edge, which belongs to both
faces."""

FAR_RADII = 1e6
"""A patch whose centre lies more than this many radii from the origin (in any coordinate) is
measured relative to its centre. Its sums of coordinates would otherwise round by up to the
vertex count times float64's step there (a 90° wedge 2e12 units out, about 8,800 patch
vertices, read 94.56°); nearer, where that rounding is some 1e-10 radii at most, the coordinates
are used as given, so readings keep their bits (docs/METHOD.md, "float64 far out")."""

MIN_RADIUS = 1e-152
"""Smallest radius to measure with: squared distances below about 1e-154 lose precision
(subnormal). Finding a patch works with any positive radius."""


def canonical_order(points: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """Order that sorts a patch by coordinates (then normals), independent of vertex numbering.

    Every sum in the algorithm runs in this order, so the result is bit-identical whatever order
    the vertices of the mesh come in.
    """
    keys = (normals[:, 2], normals[:, 1], normals[:, 0], points[:, 2], points[:, 1], points[:, 0])
    return np.lexsort(keys)


def _smallest_eigenvector(matrix) -> tuple[float, np.ndarray, np.ndarray]:
    """Smallest eigenvalue, its unit eigenvector (sign fixed) and all eigenvalues of a 3x3 SPD
    matrix, given as an array or as its six entries ``xx, xy, xz, yy, yz, zz``."""
    if isinstance(matrix, list):
        values, vectors = eigh3_entries(*matrix)
    else:
        values, vectors = eigh3(matrix)
    vector = vectors[:, 0]
    if vector[np.argmax(np.abs(vector))] < 0:  # a sign that does not depend on the solver
        vector = -vector
    return float(values[0]), vector, values


def _column_means(array: np.ndarray) -> np.ndarray:
    """``array.mean(axis=0)``, without its wrapper's overhead: the same sums (row after row, per
    column), divided by the same count."""
    return np.add.reduce(array, axis=0) / array.shape[0]


def _plane(points: np.ndarray, mean: np.ndarray | None = None) -> tuple[np.ndarray, float, bool]:
    """PCA plane fit: unit normal, mean squared distance to the plane, and whether the points
    span a plane at all (``False``: they lie on a line). ``mean``: the points' mean, if known."""
    count = points.shape[0]
    mean = _column_means(points) if mean is None else mean
    # The centred coordinates column by column (the same differences, contiguous for products).
    centred = np.empty((3, count))
    np.subtract(points.T, mean[:, None], out=centred)
    error, normal, values = _smallest_eigenvector(
        [value / count for value in column_moments(centred)]
    )
    spans = bool(values[1] > RANK_TOLERANCE * max(values[2], np.finfo(float).tiny))
    return normal, max(error, 0.0), spans


def _row_beside(line_points: np.ndarray, others: np.ndarray) -> np.ndarray:
    """Mask of ``others`` on the row nearest to and parallel with the line through
    ``line_points``; all False when the nearest vertices do not form such a row."""
    centred = line_points - line_points.mean(axis=0)
    direction = eigh3(moments(centred))[1][:, 2]
    offsets = others - line_points.mean(axis=0)
    across = offsets - np.outer(row_dot(offsets, direction), direction)
    distance = np.sqrt(np.einsum("ij,ij->i", across, across))
    beside = distance <= SHARED_ROW_FACTOR * distance.min()
    # A row parallel to the line sits at one offset across it; scattered neighbours do not.
    scatter = np.linalg.norm(across[beside] - across[beside].mean(axis=0), axis=1).max()
    if beside.sum() < 3 or scatter > 0.25 * distance.min():
        beside[:] = False
    return beside


def _fit_side(points, joined, mask, side: str) -> tuple[np.ndarray, float, int, np.ndarray]:
    """The plane of one side, its fit error, how many vertices it borrowed from the other, and
    the mean of its own vertices.

    ``joined`` is the points and normals side by side, shape (k, 6): one gather and one sum give
    a side's vertices and the means of its points and normals. A side that is a single row of
    vertices (a coarse mesh across a near-flat edge) has no plane of its own; the row of the
    other side nearest it (the vertices on the edge, which lie on both faces) completes it.
    """
    rows = np.compress(mask, joined, axis=0)  # joined[mask], without fancy indexing's overhead
    normal, error, spans, centroid, mean_normal = _side_plane(rows)
    borrowed = 0
    if not spans:
        own = rows[:, :3]
        beside = _row_beside(own, points[~mask])
        borrowed = int(beside.sum())
        if borrowed:
            normal, error, spans = _plane(np.vstack([own, points[~mask][beside]]))
            normal = -normal if dot3(normal, mean_normal) < 0 else normal
        if not spans:
            raise GoniometerError(
                f"The vertices on the {side} side lie on a line, even with the row of vertices "
                "beside it, so no plane can be fitted: use a larger radius (each side needs at "
                "least two rows of vertices off the edge) or move the centre onto the break edge."
            )
    return normal, error, borrowed, centroid


def _side_plane(rows: np.ndarray) -> tuple[np.ndarray, float, bool, np.ndarray, np.ndarray]:
    """The plane of a side's own vertices: its normal turned towards their mean normal, its fit
    error, whether they span a plane, and the means of their points and normals. ``rows``: the
    side's points and normals side by side, shape (k, 6)."""
    means = _column_means(rows)
    centroid, mean_normal = means[:3], means[3:]
    normal, error, spans = _plane(rows[:, :3], centroid)
    normal = -normal if dot3(normal, mean_normal) < 0 else normal
    return normal, error, spans, centroid, mean_normal


def check_rule(rule) -> str:
    """Return the rule in lower case, or raise if it is not one of :data:`RULES`."""
    name = str(rule).lower()
    if name not in RULES:
        raise GoniometerError(
            f"Unknown rule {rule!r}: use 'refined' (the default), 'oriented' (the default before "
            "'refined') or 'paper' (Algorithm 1 as printed, to replicate old measurements)."
        )
    return name


def _correlation(a: np.ndarray, b: np.ndarray) -> float:
    """Pearson correlation of two vectors; 0 when either is constant."""
    a = a - np.add.reduce(a) / a.size  # a.mean(): the same sum and division, without its wrapper
    b = b - np.add.reduce(b) / b.size
    scale = math.sqrt(total(a * a) * total(b * b))
    return total(a * b) / scale if scale > 0 else 0.0


def _checked_angle(normal_plus, normal_minus) -> float:
    """``180 − arccos(v₊·v₋)``, refused where the planes fold onto each other or are flat."""
    angle = 180.0 - acos_degrees(dot3(normal_plus, normal_minus))
    if angle < FLAT_TOLERANCE_DEG:
        raise GoniometerError(
            f"The two sides fit planes folded onto each other ({angle:.2f}°): the patch "
            "straddles a thin sliver, or reaches opposite faces of the fragment. Use a radius "
            "that covers just the two faces at the edge, or move the centre."
        )
    if angle > 180.0 - FLAT_TOLERANCE_DEG:
        raise GoniometerError(
            f"No break edge found: the two sides fit planes within {180.0 - angle:.2f}° of each other, "
            "so the patch is flat. Move the centre onto the break edge, or use a larger radius."
        )
    return angle


def _split_and_fit(points, joined, projection) -> tuple[dict, tuple, list]:
    """Steps 9-13 of Algorithm 1: the WithinSS split of ``projection`` and a plane per side.

    Returns the measured fields, the centroids of the "+" and "−" sides' own vertices, and each
    side's plane as (normal, centroid, fit error), ``None`` for a side that borrowed a row (the
    refinement's first round starts from these).
    """
    threshold, _ = withinss_split(projection, min_size=MIN_SIDE_VERTICES)
    labels = projection >= threshold
    n_plus = int(np.count_nonzero(labels))
    normal_plus, error_plus, shared_plus, mean_plus = _fit_side(points, joined, labels, "+")
    normal_minus, error_minus, shared_minus, mean_minus = _fit_side(points, joined, ~labels, "-")
    angle = _checked_angle(normal_plus, normal_minus)
    fields = {
        "angle": angle,
        "fit_error": error_plus + error_minus,
        "fit_error_plus": error_plus,
        "fit_error_minus": error_minus,
        "normal_plus": normal_plus,
        "normal_minus": normal_minus,
        "threshold": threshold,
        "labels": labels,
        "n_plus": n_plus,
        "n_minus": labels.size - n_plus,
        "n_shared": shared_plus + shared_minus,
    }
    planes = [
        None if shared_plus else (normal_plus, mean_plus, error_plus),
        None if shared_minus else (normal_minus, mean_minus, error_minus),
    ]
    return fields, (mean_plus, mean_minus), planes


def _planes_form_ridge(fields, centroids) -> bool:
    """Whether the fitted planes meet in a ridge (convex) rather than a valley, relative to their
    normals: moving from the "−" side's centroid to the "+" side's, the normal turns the same
    way."""
    return dot3(centroids[0] - centroids[1], fields["normal_plus"] - fields["normal_minus"]) > 0


def _check_crease_in_patch(fields, centroids, center, radius) -> None:
    """Refuse where the line the two fitted planes meet in passes farther than
    :data:`PLANES_MEET_WITHIN` radii from ``center`` (each plane taken through its side's
    centroid in ``centroids``: that of the vertices it was fitted to, or, for a side that
    borrowed a row, of its own vertices, which lie on that plane to within its fit)."""
    (p0, p1, p2), (m0, m1, m2) = fields["normal_plus"].tolist(), fields["normal_minus"].tolist()
    (c0, c1, c2), (a0, a1, a2), (b0, b1, b2) = (v.tolist() for v in (center, *centroids))
    off_plus = (a0 - c0) * p0 + (a1 - c1) * p1 + (a2 - c2) * p2
    off_minus = (b0 - c0) * m0 + (b1 - c1) * m1 + (b2 - c2) * m2
    cosine = p0 * m0 + p1 * m1 + p2 * m2
    # The squared distance to the line, (e₊² + e₋² − 2 c e₊ e₋) / (1 − c²), compared without
    # dividing: 1 − c² is at least sin²(0.5°) once the flat and folded refusals have passed.
    reach = PLANES_MEET_WITHIN * radius
    spread = off_plus * off_plus + off_minus * off_minus - 2.0 * cosine * off_plus * off_minus
    if spread <= reach * reach * (1.0 - cosine * cosine):
        return
    distance = math.sqrt(spread / (1.0 - cosine * cosine))
    where = (
        f"meet {distance:.3g} from the centre, {distance / radius:.2f} times the radius "
        f"({radius:.3g}): outside the patch"
    )
    angle = fields["angle"]
    if angle > NEAR_FLAT_DEG:
        raise GoniometerError(
            f"The two fitted planes are nearly parallel (they would read {angle:.2f}°) and {where}, "
            "so they do not measure an edge at the centre: the split likely missed it (between "
            "near-flat faces their meeting line is poorly placed), or there is none. Try a "
            "larger radius, or move the centre onto the break edge."
        )
    raise GoniometerError(
        f"The two fitted planes (they would read {angle:.2f}°) {where}, so the edge they "
        "measure is not the one at the centre: the patch reaches past the two faces at the edge "
        "and fitted other faces, or the centre is not on a break edge. Use a radius that covers "
        "just the two faces at the edge (look at the coloured sides), or move the centre onto "
        "the edge."
    )


def _plane_rests_on_one_vertex(joined: np.ndarray, side: np.ndarray, normal) -> bool:
    """Whether leaving out one of the ``side``'s vertices turns its plane (unit ``normal``) by
    more than :data:`CROSSED_MOVE_DEG`: a few vertices of the other face with one past the
    crease, which tilts their plane, or a few noisy ones, whose plane no one of them may set.

    Each vertex left out in turn, at once: the scatter matrix less that vertex's share
    (``C − k/(k−1) d dᵀ``, ``d`` its offset from the mean). A vertex without which the rest
    lie on a line is passed over: the plane through a row and one vertex is what it is."""
    points = np.compress(side, joined[:, :3], axis=0)
    count = points.shape[0]
    if count < 3:
        return False  # no plane to turn (the split and the refinement keep 5 a side)
    offsets = points - _column_means(points)
    scatter = moments(offsets)
    without = scatter[None] - (count / (count - 1)) * (offsets[:, :, None] * offsets[:, None, :])
    values, vectors = eigh3_batched(without)
    # Where the rest lie on a line (a row on the crease), that vertex is what makes the plane,
    # as for a side that borrowed a row: not a turn.
    spans = values[:, 1] > RANK_TOLERANCE * np.maximum(values[:, 2], np.finfo(float).tiny)
    planes = vectors[spans, :, 0]
    # A cosine, not an angle: C's acos may round differently from one machine to the next.
    return bool((np.abs(row_dot(planes, normal)) < COS_CROSSED_MOVE).any())


def _sides_by_normals(joined, binormal, used) -> tuple[np.ndarray, np.ndarray] | None:
    """The patch's used vertices split by their normals alone (Algorithm 1's split at λ = 0):
    the two faces the normals tell, or ``None`` where no split keeps enough on each side."""
    along = row_dot(joined[:, 3:], binormal)
    try:
        threshold, _ = withinss_split(along[used], min_size=MIN_SIDE_VERTICES)
    except GoniometerError:
        return None
    upper = used & (along >= threshold)
    return upper, used & ~upper


def _split_missed_message(fields, share, moved_angle, moved_error) -> str:
    return (
        f"The split does not follow the faces: {share:.1%} of the vertices of one side face the "
        f"other side's plane; given to it, the two faces the normals tell read {moved_angle:.2f}° "
        f"with fit error {moved_error:.2g}, where the split reads {fields['angle']:.2f}° with "
        f"fit error {fields['fit_error']:.2g}. The split counts vertices, so a face meshed much "
        "more finely than the other outweighs it, or the patch holds more than two faces (a "
        "corner): move the centre onto the edge away from corners, use a smaller radius, or "
        "remesh the scan to an even density. Or one face's normals point the other way (its "
        "triangles wound against the rest): make them consistent (Blender: Mesh > Normals > "
        "Recalculate Outside)."
    )


def _check_sides_follow_normals(joined, fields, center, radius, noise) -> None:
    """Refuse where many vertices of a side face the other side's plane, and giving them to it
    moves the angle: the split did not follow the faces. A centre off the edge (a patch mostly
    on one face) is split inside that face; its planes still meet near the centre.

    A vertex faces the other plane when its normal, along the direction from the "−" plane's
    normal to the "+" one's, lies past the other side by more than :data:`CROSSED_NOISE` times
    the normals' ``noise`` (their RMS along the crease, which a crease does not bend).
    ``joined``: the points and normals side by side, shape (k, 6).
    """
    normals = joined[:, 3:]
    plus, minus = fields["normal_plus"], fields["normal_minus"]
    towards_plus = (plus - minus) / norm3(plus - minus)
    facing = row_dot(normals, towards_plus)
    noise = CROSSED_NOISE * noise
    labels = fields["labels"]
    used = ~fields["left_out"] if fields.get("left_out") is not None else np.ones_like(labels)
    plus_side, minus_side = labels & used, ~labels & used
    crossed_plus, crossed_minus = plus_side & (facing < -noise), minus_side & (facing > noise)
    shares = [
        np.count_nonzero(crossed) / max(np.count_nonzero(side), 1)
        for crossed, side in ((crossed_plus, plus_side), (crossed_minus, minus_side))
    ]
    if max(shares) <= CROSSED_SHARE:
        return
    moved = ((labels & ~crossed_plus) | crossed_minus) & used
    sides = (moved, used & ~moved)
    facing_one_face = min(np.count_nonzero(side) for side in sides)
    if facing_one_face < MIN_SIDE_VERTICES:
        # Too few left to fit the faces the normals tell. The vertices on the crease lie on
        # both faces and their normals lean either way, so that alone says nothing; a side
        # whose plane turns when one vertex is left out is a few vertices of the other face
        # with one past the crease, and reads what that vertex makes of it.
        crossed_sides = [
            (side, normal)
            for side, normal, share in (
                (plus_side, plus, shares[0]),
                (minus_side, minus, shares[1]),
            )
            if share > CROSSED_SHARE
        ]
        if not any(_plane_rests_on_one_vertex(joined, *crossed) for crossed in crossed_sides):
            sides = _sides_by_normals(joined, fields["binormal"], used)
            if sides is None:
                return
        else:
            raise GoniometerError(
                f"The patch lies almost entirely on one face: {max(shares):.1%} of the vertices of "
                f"one side face the other side's plane, and without them that side keeps "
                f"{facing_one_face} (at least {MIN_SIDE_VERTICES} are needed to fit a plane to "
                "a face). The centre is off the "
                "break edge or the radius is too small for the mesh: move the centre onto the edge, "
                "or use a larger radius. Or one face's normals point the other way (its triangles "
                "wound against the rest): make them consistent, e.g. in Blender's Edit Mode with "
                "Mesh > Normals > Recalculate Outside."
            )
    planes, moved_error = [], 0.0
    for side in sides:
        normal, error, spans, centroid, _ = _side_plane(np.compress(side, joined, axis=0))
        if not spans:
            return
        planes.append((normal, centroid))
        moved_error += error
    moved_angle = 180.0 - acos_degrees(dot3(planes[0][0], planes[1][0]))
    if abs(moved_angle - fields["angle"]) <= CROSSED_MOVE_DEG:
        return
    line = crease_line(planes, center)
    if line is None:
        return  # parallel: no edge to say the centre is off
    off = norm3(line[0] - center)
    if off <= CROSSED_OFF_EDGE * radius:
        if moved_error < SPLIT_MISSED_FIT * fields["fit_error"]:
            raise GoniometerError(
                _split_missed_message(fields, max(shares), moved_angle, moved_error)
            )
        return  # the faces the normals tell meet at the centre too: not a centre off its edge
    raise GoniometerError(
        f"The split does not follow the faces: {max(shares):.1%} of the vertices of one side "
        f"face the other side's plane, and given to it they read {moved_angle:.2f}° instead of "
        f"{fields['angle']:.2f}°, with the edge {off / radius:.2f} times the radius from the "
        "centre: the centre is off the break edge (the patch lies mostly on one face), or the "
        "patch reaches another edge. Move the centre onto the edge, or use a smaller radius."
    )


def measure_patch(
    points: np.ndarray,
    normals: np.ndarray,
    center: np.ndarray,
    radius: float,
    lam: float,
    rule: str = DEFAULT_RULE,
    estimated_normals: bool = False,
) -> dict:
    """Run Algorithm 1 on a validated, canonically ordered float64 patch.

    Returns a dict of the measured fields of :class:`~vg_addon.result.Measurement`; ``labels`` follow
    the order of ``points``. Callers normally use :func:`goniometer` or ``Surface.measure``.
    ``estimated_normals``: the normals are a point cloud's estimate, whose orientation can fail
    on one face; sides whose normals face opposite ways are then refused under every rule.
    """
    if not MIN_RADIUS <= radius <= MAX_MAGNITUDE:
        raise GoniometerError(
            f"The radius must be from {MIN_RADIUS:g} to {MAX_MAGNITUDE:g} to measure, where "
            f"squared distances stay representable; got {radius!r}. Scale the mesh to a real unit."
        )
    n_points = points.shape[0]
    if n_points < 2 * MIN_SIDE_VERTICES:
        raise GoniometerError(
            f"The patch holds {n_points} vertices; at least {2 * MIN_SIDE_VERTICES} are needed "
            f"({MIN_SIDE_VERTICES} per side): use a larger radius."
        )
    if float(np.abs(center).max()) > FAR_RADII * radius:
        points, center = points - center, np.zeros(3)
    along_tangent, tangent, normal_eigenvalues = _smallest_eigenvector(moments(normals))
    mean_normal = _column_means(normals)
    # np.cross's arithmetic on Python floats (the same IEEE operations, without its overhead).
    (t0, t1, t2), (m0, m1, m2) = tangent.tolist(), mean_normal.tolist()
    cross = np.array([t1 * m2 - t2 * m1, t2 * m0 - t0 * m2, t0 * m1 - t1 * m0])
    cross_norm = norm3(cross)
    if normal_eigenvalues[1] <= 1e-12 * normal_eigenvalues[2] or cross_norm <= 1e-12:
        raise GoniometerError(
            "The normals in the patch do not define a break edge (they are all parallel, or they "
            "cancel out): move the centre onto a break edge or use a larger radius."
        )
    binormal = cross / cross_norm
    along_normal = row_dot(normals, binormal)  # bᵀN
    across = row_dot(points - center, binormal)  # bᵀ(X − x̄)
    correlation = _correlation(along_normal, across)
    oriented = rule != "paper"
    orientation = -1 if oriented and correlation < 0 else 1

    def projection(sign: int) -> np.ndarray:
        """p = bᵀN + sign (λ/r) bᵀ(X − x̄); sign +1 is the paper's projection."""
        return along_normal + (sign * lam / radius) * across

    joined = np.concatenate((points, normals), axis=1)
    weak = abs(correlation) < WEAK_CORRELATION
    if not (oriented and weak and lam > 0):
        fields, centroids, planes = _split_and_fit(points, joined, projection(orientation))
        other_angle = None
    else:
        # The sign is weakly determined: measure with both and keep the better plane fit.
        readings = []
        for sign in (orientation, -orientation):
            try:
                readings.append((sign, *_split_and_fit(points, joined, projection(sign))))
            except GoniometerError as error:
                refusal = error
        if not readings:
            raise refusal
        orientation, fields, centroids, planes = min(readings, key=lambda r: r[1]["fit_error"])
        other_angle = next(
            (r["angle"] for sign, r, *_ in readings if sign != orientation), fields["angle"]
        )
    if weak or _planes_form_ridge(fields, centroids) != (correlation >= 0):
        convexity = "unclear"
    else:
        convexity = "convex" if correlation >= 0 else "concave"
    fields.update(
        tangent=tangent,
        mean_normal=mean_normal / norm3(mean_normal),
        binormal=binormal,
        n_vertices=n_points,
        rule=rule,
        orientation=orientation,
        correlation=correlation,
        convexity=convexity,
        orientation_difference=0.0 if other_angle is None else abs(other_angle - fields["angle"]),
    )
    if rule == "refined":
        centroids = _refine(points, normals, center, radius, fields, planes) or centroids
        _check_crease_in_patch(fields, centroids, center, radius)
    # A face whose normals point the other way reads as the supplement: a point cloud's
    # estimated normals under every rule; a mesh's mixed winding, or given normals pointing in,
    # under the refined one (the replication rules keep their readings, as the earlier
    # implementations gave them).
    if (estimated_normals or rule == "refined") and sides_contradict_normals(
        points, fields["labels"], fields["normal_plus"], fields["normal_minus"], center, radius
    ):
        raise GoniometerError(
            contradicting_normals_message(fields["angle"], cloud=estimated_normals)
        )
    if rule == "refined":
        noise = math.sqrt(max(along_tangent, 0.0) / n_points)  # the normals' RMS along t
        _check_sides_follow_normals(joined, fields, center, radius, noise)
    return fields


def _check_shared_row(points, labels, spacing) -> None:
    """Under the refined rule, refuse a side that is one row of vertices unless the row it
    borrowed lies on the other side's face: on a crease through a row of vertices that row is on
    both faces, and the borrowed plane is exact; where the crease runs between rows, the row
    beside it lies on neither face (the triangles cut the corner), and a plane through it and the
    one row would be a guess."""
    for side in (labels, ~labels):
        if _plane(points[side])[2]:
            continue
        lender = points[~side]
        beside = _row_beside(points[side], lender)
        rest = lender[~beside]
        if rest.shape[0] < MIN_SIDE_VERTICES or not _plane(rest)[2]:
            continue  # the other face is one row too: nothing tells the edge's row off it
        normal = _plane(rest)[0]
        off = np.abs(row_dot(lender[beside] - _column_means(rest), normal)).max()
        if off <= NOISE_FLOOR * spacing:
            continue
        raise GoniometerError(
            "One side of the patch holds a single row of vertices, and the row beside it across "
            "the edge lies on neither face, so that side's plane is not determined: use a larger "
            "radius (each side needs two rows of vertices on its face), or the 'oriented' rule to "
            "replicate a reading taken with it."
        )


def _refine(points, normals, center, radius, fields, planes) -> tuple | None:
    """Replace Algorithm 1's planes by :func:`refine_sides`' where it applies (in place) and
    return a point on each of them, or ``None`` where Algorithm 1's are kept; ``planes``:
    Algorithm 1's, as :func:`_split_and_fit` returns them."""
    if fields["n_shared"]:
        _check_shared_row(points, fields["labels"], mean_edge_length(radius, points.shape[0]))
    refined = refine_sides(
        points,
        normals,
        fields["labels"],
        center,
        radius,
        mean_edge_length(radius, points.shape[0]),
        fields["fit_error"],
        planes,
    )
    if refined is None:
        return None
    try:
        angle = _checked_angle(refined["normal_plus"], refined["normal_minus"])
    except GoniometerError:
        return None  # the refined planes would be refused: keep Algorithm 1's reading
    labels, used = refined.pop("labels"), refined.pop("used")
    centroids = refined.pop("centroids")
    fields.update(
        refined,
        split_angle=fields["angle"],
        angle=angle,
        labels=labels,
        n_plus=int(labels.sum()),
        n_minus=int((~labels).sum()),
        n_left_out=int((~used).sum()),
        left_out=~used,
    )
    return centroids


def goniometer(
    points, normals, lam: float = 2.0, center=None, radius=None, rule: str = DEFAULT_RULE
) -> Measurement:
    """Measure the break angle of a patch you already have (Algorithm 1 of the paper).

    Parameters
    ----------
    points : array_like, shape (n, 3)
        The patch vertices ``X``.
    normals : array_like, shape (n, 3)
        Their outward normals ``N`` (normalised here).
    lam : float, optional
        The segmentation parameter λ ≥ 0 (default 2).
    center : array_like, shape (3,), optional
        The centre ``x̄`` of the projection; default the mean of ``points``.
    radius : float, optional
        The ``r`` of the projection; default the largest distance from ``center`` to a point.
    rule : {"refined", "oriented", "paper"}, optional
        How the measurement is taken (see :data:`RULES`); default ``"refined"``.

    Returns
    -------
    Measurement
        ``labels`` follow the order of ``points``; ``indices`` is ``None``; ``patch`` is ``"given"``.

    Raises
    ------
    GoniometerError
        On non-finite or mis-shaped input, too few vertices (in the patch or on a side), a flat patch
        or a side whose vertices are collinear; under the refined rule, two fitted planes that meet
        farther than the radius from the centre, or sides whose normals face opposite ways for
        where they lie (one face's normals pointing the other way: the supplement would be read).
    """
    points = as_points("points", points)
    normals = as_normals(normals, points.shape[0])
    lam = as_lambda(lam)
    rule = check_rule(rule)
    order = canonical_order(points, normals)
    ordered_points, ordered_normals = points[order], normals[order]
    center = ordered_points.mean(axis=0) if center is None else as_center(center)
    # Surface.measure snaps to a vertex; a given centre is used as is.
    check_magnitude("The centre reaches", center, "give a centre among the points, in their units")
    if radius is None:
        radius = float(np.sqrt(((ordered_points - center) ** 2).sum(axis=1).max()))
        if radius <= 0:
            raise GoniometerError("All points coincide, so the patch has no extent to measure.")
    radius = as_radius(radius)
    fields = measure_patch(ordered_points, ordered_normals, center, radius, lam, rule)
    labels = np.empty_like(fields["labels"])
    labels[order] = fields["labels"]
    fields["labels"] = labels
    if fields.get("left_out") is not None:
        left_out = np.empty_like(fields["left_out"])
        left_out[order] = fields["left_out"]
        fields["left_out"] = left_out
    return Measurement(
        **fields,
        indices=None,
        center=center,
        requested_center=None,
        snap_distance=0.0,
        center_index=-1,
        radius=radius,
        lam=lam,
        patch="given",
    )
