"""The default rule's step after Algorithm 1: each side's plane from the vertices that lie on it.

Algorithm 1 splits the patch by one number per vertex and fits a plane to each side. Where the
crease runs between rows of vertices, the triangles across it cut the corner: the vertices next
to the crease are handed to the wrong side, or lie on neither face (a marching-cubes or
marching-tetrahedra mesh places them inside the corner). Each such vertex tilts a fitted plane,
and the reading drifts by tenths of a degree to degrees, growing towards flat edges.

The refinement takes Algorithm 1's planes as a start and repeats, until nothing changes:

1. the line where the two planes meet, and each side as the half-plane from it;
2. every vertex near the other side's half-plane goes to the half-plane it is nearer to;
3. each side's plane is fitted robustly (least trimmed squares) to its vertices away from the
   other face, and the side's vertices that lie off it by more than :data:`OUTLIER_SPREADS`
   robust standard deviations are left out of the plane fits;
4. the two planes are fitted again to the vertices kept on each side.

The result replaces Algorithm 1's only where it explains the patch much better and is the edge
the user measured: the summed plane-fit error falls by :data:`MIN_IMPROVEMENT` or more, both
faces are shown to be planes (:data:`CURVED_GAIN`), the crease passes near the centre
(:data:`CREASE_REACH`), and what is left out is a strip along the crease, not a face
(:data:`MAX_LEFT_OUT`, :data:`MAX_LEFT_OUT_OF_PATCH`; beyond them only where all of it lies
nearer the crease than what is kept and the kept band shows no bend, :data:`STRICT_GAIN`). A
curved or rough wall keeps Algorithm 1's planes bit for bit; so do creases on a row of vertices,
where nothing moves. Where the strip is shown, the planes without it fit the patch
:data:`DECISIVE_IMPROVEMENT` times better, but what is left of a face is too few rows of
vertices to carry its plane, Algorithm 1's reading is known to be off and the measurement is
refused (:class:`~vg_addon.errors.GoniometerError`, saying why).

Where a scan's noise hides the strip's single vertices, so that these steps keep Algorithm 1's
planes or end in planes that do not fit 1000-fold better (:data:`DECISIVE_IMPROVEMENT`), a second
stage finds the strip by where its vertices lie on average, band by band outwards from the crease
(:data:`STRIP_SPREADS`), leaves it out whole and fits the planes again; its planes are used where
both faces are then shown to be planes and meet near the centre. Everything runs
in a fixed order (:mod:`.fixed_order`), so the same inputs give the same bits on every machine.
The reasons and the measurements are in docs/METHOD.md.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import GoniometerError
from .fixed_order import (
    columns_dot,
    columns_dots,
    cross3,
    dot3,
    gram,
    offset_columns,
    solve,
    total,
)
from .planes import crease_line, distance_to_line, side_plane

NEAR_SPACINGS = 3.0
"""How close to the other side's half-plane, in mesh spacings, a vertex may be handed over or
left out. Triangles can cut the corner only where both faces are within a cell or two; on an
acute crease that band reaches farther from the crease line itself, which this measure follows."""

OUTLIER_SPREADS = 3.0
"""A vertex is left out when it lies off its face's robust plane by more than this many robust
standard deviations (1.4826 × the median absolute residual)."""

NOISE_FLOOR = 1e-4
"""The smallest residual spread, in mesh spacings: on an exact plane the spread is rounding
error (or a float32 file's 1e-7), and no vertex should count as off the face for that. Where
Algorithm 1's planes already fit this well, there is nothing to refine."""

MIN_IMPROVEMENT = 4.0
"""The refined planes are used only if they divide the summed plane-fit error by at least this.
Vertices that sit off both faces near the crease inflate the error many times over (a hundred
to a billion on marching-cubes wedges); a wall whose misfit is its own curvature or roughness
improves by less than 2 when its vertices next to the crease are left out."""

MIN_CURVATURE_SPREAD = 4.0
"""A face is shown to be a plane only where its kept vertices reach this many mesh spacings
across the crease: over two or three rows a curved wall and a plane look alike."""

DECISIVE_IMPROVEMENT = 1000.0
"""Where a face left beside the strip is too narrow to show it is a plane, the measurement is
refused only if the refined planes divide the fit error by at least this: then the strip is
what spoiled Algorithm 1's planes (on exact faces the error falls 10⁸ to 10¹⁴-fold). A curved
wall's misfit is its curvature, which leaving a strip out cannot remove (15-fold at a rim of the
demo's bone shaft, 1 mm patch): there nothing shows Algorithm 1's reading is off, and it stays."""

CURVED_GAIN = 2.0
"""A side whose kept vertices a quadratic surface fits with less than half the mean squared
residual of its plane is curved. There the plane is a secant, the vertices next to the crease
pull it towards the tangent at the crease, and leaving any out would move the reading for a
reason that is not the mesh's: the refinement is for faces that are planes."""

STRICT_GAIN = 1.1
"""The quadratic's largest gain where more than the shares above is left out
(:data:`MAX_LEFT_OUT`, :data:`MAX_LEFT_OUT_OF_PATCH`): a plane with noise gains ``n / (n - 6)``
from the quadratic's six terms; the far band of the half annulus's curved wall gains 1.3."""

CREASE_REACH = 0.5
"""The refined planes must meet within this fraction of the radius of the centre. On a scan a
patch can hold three faces; leaving one out may leave two others that fit planes well but meet
away from where the user measured (a thin wall's two sides), and that is not the edge asked for."""

EARLY_IMPROVEMENT = 2.0
"""After its first round the refinement stops unless the fit error has already halved. Where a
strip cuts the corner, the first round removes most of it (the error falls 10 to 10¹³-fold on
marched wedges); on a noisy scan it falls a few percent, and more rounds only trim noise."""

MAX_ROUNDS = 20
"""Rounds of re-assignment; the sides settle within 2 to 4."""

MAX_LEFT_OUT = 0.5
"""The most of a side that may be left out, unless what is left out lies nearer the crease than
everything kept (:func:`_beside_the_crease`): the robust plane rests on the half of the side
nearest it, so beyond half what is left out could be the face and what is kept a chance band
(a plane cuts a curved wall in two strips)."""

MAX_LEFT_OUT_OF_PATCH = 0.2
"""The most of the whole patch that may be left out at a right or obtuse crease (at an acute
one, ``1 / sin(angle)`` times this, at most :data:`MAX_LEFT_OUT`: the strip that cuts the corner
reaches that much farther into each face), unless what is left out lies nearer the crease than
everything kept. A strip a few spacings wide along the crease is a small part of a patch; on a
scan, more left out is another face in the patch, not a strip. A mesh stretched across the
crease holds few rows per face, and its strip is a large share of them."""

MAX_STRAY = 0.02
"""The share of a side that a scan's noise may put beyond the outlier limit (a few in a thousand
beyond :data:`OUTLIER_SPREADS` for Gaussian noise, more on rougher scans): a side that left out no
more than this is not asked where they lie, and a strip beside the crease may have this many
beyond it. A face of its own, or the far strip of a curved wall that a plane cuts in two, is
more."""

LTS_STEPS = 2
"""Refits of a face's plane to the half of its vertices nearest the previous fit."""

MIN_FAR_VERTICES = 12
"""A side needs this many vertices away from the other face for its robust plane; with fewer,
none of its vertices is left out."""

STRIP_SPREADS = 3.0
"""A band of vertices at one distance from the crease (one mesh spacing wide) belongs to the strip
that cuts the corner where its mean height over the face, towards the other face, exceeds this
many standard errors of a mean of its size (the robust spread of the face's outer half over the
square root of its count). A scan's noise averages out over a band; the strip's vertices all lie
on the same side of both faces, so they stand out however noisy the scan."""

MIN_BAND_VERTICES = 3
"""Bands holding fewer vertices than this are passed over when the strip is measured."""

FIRST_BAND = 2.0
"""Before the strip is measured, the vertices within this many mesh spacings of Algorithm 1's
crease line are left out once and the planes fitted again: Algorithm 1's planes are tilted by the
strip, and so is their line, beside which the strip's bands would be measured."""


def mean_edge_length(radius: float, n_vertices: int) -> float:
    """Mean edge length of a triangulated disk of ``radius`` holding ``n_vertices`` vertices.

    An equilateral triangulation with edge ``h`` has one vertex per ``(√3 / 2) h²`` of area, so
    ``h = r √(2π / (√3 n))``: an estimate from the patch itself, valid for meshes and point clouds.
    """
    return radius * math.sqrt(2.0 * math.pi / (math.sqrt(3.0) * n_vertices))


def _half_plane_distances(points, center, planes):
    """Each vertex's distance to the two half-planes that meet at the planes' line; ``None``
    when the planes are parallel. Also returns the line's frame for the smooth-surface fits."""
    (normal_plus, centroid_plus, _), (normal_minus, centroid_minus, _) = planes
    line = crease_line(planes, center)
    if line is None:
        return None
    on_line, direction = line
    relative = offset_columns(points, on_line)
    along = columns_dot(relative, direction)
    across = relative - direction[:, None] * along
    squares = across * across
    distance_to_line = np.sqrt(squares[0] + squares[1] + squares[2])
    outward = []
    for normal, centroid in ((normal_plus, centroid_plus), (normal_minus, centroid_minus)):
        into_face = cross3(direction, normal)
        if dot3(into_face, centroid - on_line) < 0:
            into_face = -into_face
        outward.append(into_face)
    # Per face: how far into it (its side of the crease line) and the height over its plane.
    into_plus, height_plus, into_minus, height_minus = columns_dots(
        across, [outward[0], normal_plus, outward[1], normal_minus]
    )
    distances = [
        np.where(into_plus >= 0, np.abs(height_plus), distance_to_line),
        np.where(into_minus >= 0, np.abs(height_minus), distance_to_line),
    ]
    return distances, (on_line, direction, outward)


def _face_coordinates(points, plane, frame, radius):
    """Each point's coordinates over a face: across the crease into the face and along it (both
    in radii, from the crease line), and its height over the face's plane."""
    normal, centroid, _ = plane
    on_line, direction, into_face = frame
    u, w = columns_dots(offset_columns(points, on_line), [into_face, direction]) / radius
    return u, w, columns_dot(offset_columns(points, centroid), normal)


def _residuals(basis, height, fitted_on):
    """``|height − fit|`` for the least-squares fit of ``height`` by the rows of ``basis`` over the
    points ``fitted_on``; ``None`` when the fit is singular."""
    matrix, rhs = gram(np.compress(fitted_on, basis, axis=1), np.compress(fitted_on, height))
    coefficients = solve(matrix, rhs)
    if coefficients is None:
        return None
    fitted = basis[0] * coefficients[0]
    for k in range(1, basis.shape[0]):
        fitted += basis[k] * coefficients[k]
    return np.abs(height - fitted, out=fitted)


def _median(values) -> float:
    """``np.median`` of a 1-D array without NaNs, bit for bit, without its wrapper's overhead:
    the middle value, or the mean of the two middle values (their sum halved)."""
    half = values.size // 2
    if values.size % 2:
        return float(np.partition(values, half)[half])
    middle = np.partition(values, (half - 1, half))
    return (float(middle[half - 1]) + float(middle[half])) / 2  # the same IEEE sum and halving


def _robust_spread(median_deviation, spacing) -> float:
    """The robust standard deviation of values whose median absolute deviation is
    ``median_deviation`` (1.4826 times it, as for a normal distribution), at least
    :data:`NOISE_FLOOR` mesh spacings."""
    return max(1.4826 * median_deviation, NOISE_FLOOR * spacing)


def _off_surface(points, side, fitted_on, plane, frame, spacing, radius):
    """Vertices of ``side`` that lie off the face's plane, fitted robustly to ``fitted_on``.

    Least trimmed squares: the plane is fitted to the half of the vertices farthest from the
    crease, then refitted to the half nearest it, a few times, so a strip of vertices that cuts
    the corner (up to half the side) cannot tilt it; the residuals' spread is then that of the
    vertices on the face.
    """
    off = np.zeros(points.shape[0], dtype=bool)
    if np.count_nonzero(fitted_on) < MIN_FAR_VERTICES:
        return off
    members = np.flatnonzero(side)
    fit_here = fitted_on[members]
    u, w, height = _face_coordinates(np.take(points, members, axis=0), plane, frame, radius)
    basis = np.stack([np.ones_like(u), u, w])
    # Start from the half farthest from the crease, where the face is least likely disturbed.
    subset = fit_here & (u >= _median(np.compress(fit_here, u)))
    for _ in range(LTS_STEPS):
        residual = _residuals(basis, height, subset)
        if residual is None:
            return off
        middle = _median(np.compress(fit_here, residual))
        subset = fit_here & (residual <= middle)
        if np.count_nonzero(subset) < MIN_FAR_VERTICES:
            break
    off[members] = residual > OUTLIER_SPREADS * _robust_spread(middle, spacing)
    return off


def _planar(points, side, plane, frame, spacing, radius, gain=None) -> bool | None:
    """Whether a side's kept vertices are shown to lie on its plane: ``True`` where they reach far
    enough across the crease (:data:`MIN_CURVATURE_SPREAD`) for a bend to show and a quadratic
    surface fits them no markedly better than the plane (:data:`CURVED_GAIN`); ``False`` where the
    quadratic fits markedly better (a curved face); ``None`` where they are too few rows, or too
    narrow a band, to tell. ``gain``: the quadratic's largest allowed gain, if not
    :data:`CURVED_GAIN`."""
    u, w, height = _face_coordinates(np.compress(side, points, axis=0), plane, frame, radius)
    if float(u.max() - u.min()) * radius < MIN_CURVATURE_SPREAD * spacing:
        return None
    basis = np.stack([np.ones_like(u), u, w, u * w, w * w, u * u])
    residual = _residuals(basis, height, np.ones(u.size, dtype=bool))
    if residual is None:
        return None  # two rows of vertices, or fewer: every smooth surface through them fits
    floor = (NOISE_FLOOR * spacing) ** 2
    return (
        total(height * height) / height.size
        <= (gain or CURVED_GAIN) * (total(residual * residual) / height.size) + floor
    )


def _beside_the_crease(to_line, side, used) -> bool:
    """Whether what a side left out lies nearer the crease than what it kept: at most
    :data:`MAX_STRAY` of the side is left out beyond the kept vertex that many from the nearest
    (a scan's noise outliers); a strip that cuts the corner lies there whole, a face of its own
    or the far strip of a curved wall does not."""
    kept = to_line[side & used]
    if kept.size == 0:
        return False
    allowed = int(MAX_STRAY * int(side.sum()))
    nearest = float(np.partition(kept, min(allowed, kept.size - 1))[min(allowed, kept.size - 1)])
    return int((side & ~used & (to_line > nearest)).sum()) <= allowed


def _refuse_a_lost_face(points, plus, used, planes, frame, split_error) -> None:
    """Refuse where handing over and leaving out the vertices off a face left it one row of
    vertices, if what it left out is a strip along the crease and the other face's plane explains
    its side :data:`MIN_IMPROVEMENT` times better than Algorithm 1's planes did (else, return:
    the refinement does not apply)."""
    whole = [plane for plane in planes if plane is not None]
    if len(whole) != 1 or split_error < MIN_IMPROVEMENT * whole[0][2]:
        return
    to_line = distance_to_line(points, frame[0], frame[1])
    lost = plus if planes[0] is None else ~plus
    if not (lost & ~used).any() or _beside_the_crease(to_line, lost, used):
        raise GoniometerError(
            "The vertices next to the crease lie on neither face (the mesh's triangles cut the "
            "corner), and without them one face keeps a single row of vertices in the patch, so "
            "its plane is not determined: use a larger radius (or the 'oriented' rule to "
            "replicate a reading taken with it)."
        )


def _fields(plus, used, planes) -> dict:
    """The refined fields :func:`refine_sides` returns, from the sides and their two planes."""
    return {
        "labels": plus,
        "used": used,
        "normal_plus": planes[0][0],
        "normal_minus": planes[1][0],
        "fit_error_plus": planes[0][2],
        "fit_error_minus": planes[1][2],
        "fit_error": planes[0][2] + planes[1][2],
        "centroids": (planes[0][1], planes[1][1]),
    }


def _refine_by_outliers(points, normals, labels, center, radius, spacing, split_error, planes):
    """The first stage of :func:`refine_sides`: the vertices off each face's robust plane are
    left out, with the gates of the module's description. Same parameters and results.
    """
    plus = labels
    used = np.ones(points.shape[0], dtype=bool)
    given, frame = planes or [None, None], None
    for round_number in range(MAX_ROUNDS):
        planes = [
            side_plane(points, normals, side) if round_number or plane is None else plane
            for side, plane in zip((plus & used, ~plus & used), given, strict=True)
        ]
        if planes[0] is None or planes[1] is None:
            if frame is not None:
                _refuse_a_lost_face(points, plus, used, planes, frame, split_error)
            return None
        if round_number == 1 and split_error < EARLY_IMPROVEMENT * (planes[0][2] + planes[1][2]):
            return None  # the first round found no corner-cutting strip: a scan's noise
        found = _half_plane_distances(points, center, planes)
        if found is None:
            return None
        (to_plus, to_minus), frame = found
        limit = NEAR_SPACINGS * spacing
        near_other = np.where(plus, to_minus, to_plus) < limit
        new_plus = np.where(near_other, to_plus < to_minus, plus)
        near = np.where(new_plus, to_minus, to_plus) < limit
        plus_frame = (frame[0], frame[1], frame[2][0])
        minus_frame = (frame[0], frame[1], frame[2][1])
        # Each side's smooth surface is fitted away from the other face and from the vertices
        # already left out; then any of its vertices may be found off it (the strip that cuts
        # the corner can reach past the band on a mesh stretched across the crease).
        away = used & ~near
        off = _off_surface(
            points, new_plus, new_plus & away, planes[0], plus_frame, spacing, radius
        )
        off |= _off_surface(
            points, ~new_plus, ~new_plus & away, planes[1], minus_frame, spacing, radius
        )
        new_used = ~off
        if np.array_equal(new_plus, plus) and np.array_equal(new_used, used):
            break
        plus, used = new_plus, new_used
        if min(int((plus & used).sum()), int((~plus & used).sum())) < 5:
            return None
    else:
        planes = [side_plane(points, normals, side) for side in (plus & used, ~plus & used)]
        if planes[0] is None or planes[1] is None:
            _refuse_a_lost_face(points, plus, used, planes, frame, split_error)
            return None
        found = _half_plane_distances(points, center, planes)
        if found is None:
            return None
        frame = found[1]
    if np.array_equal(plus, labels) and used.all():
        return None
    refined_error = planes[0][2] + planes[1][2]
    if split_error < MIN_IMPROVEMENT * refined_error:
        return None
    on_line, direction, into_faces = frame
    if distance_to_line(center[None, :], on_line, direction)[0] > CREASE_REACH * radius:
        return None  # the planes of two other faces: the crease is not where the user measured
    to_line = distance_to_line(points, on_line, direction)
    # An acute corner's strip reaches 1 / sin(angle) times as far into each face.
    opening = math.sqrt(max(0.0, 1.0 - dot3(planes[0][0], planes[1][0]) ** 2))
    share = MAX_LEFT_OUT_OF_PATCH / max(opening, MAX_LEFT_OUT_OF_PATCH / MAX_LEFT_OUT)
    small = (~used).sum() <= share * used.size
    planar, sides = [], []
    for side, plane, into_face in zip((plus, ~plus), planes, into_faces, strict=True):
        left_out, kept = side & ~used, side & used
        beside = _beside_the_crease(to_line, side, used)
        stray = left_out.sum() > MAX_STRAY * side.sum() and not beside
        if stray and _median(to_line[left_out]) > _median(to_line[kept]):
            return None  # what was left out is no strip along the crease (a face of its own)
        small = small and left_out.sum() <= MAX_LEFT_OUT * side.sum()
        if not (small or beside):
            return None
        sides.append((kept, plane, (on_line, direction, into_face)))
    # Beyond the shares, the kept band must show no bend at all: a curved wall's far band, which
    # a plane fits but for its curvature, gains from a quadratic what a plane with noise cannot.
    gain = None if small else STRICT_GAIN
    for kept, plane, frame in sides:
        planar.append(_planar(points, kept, plane, frame, spacing, radius, gain))
    if False in planar:
        return None  # a curved face: its plane is a secant, and stays Algorithm 1's
    if None in planar:
        if not small:
            return None  # a wide strip and a face too narrow to show it is a plane: a curved wall
        if split_error < DECISIVE_IMPROVEMENT * refined_error:
            return None  # no proof that the strip is what spoiled Algorithm 1's planes
        raise GoniometerError(
            "The vertices next to the crease lie on neither face (the mesh's triangles cut the "
            "corner), and without them a face keeps too few rows of vertices in the patch to show "
            "it is a plane, so the angle is not determined: use a larger radius (or the "
            "'oriented' rule to replicate a reading taken with it)."
        )
    return _fields(plus, used, planes)


def _strip_width(points, side, kept, plane, toward_other, to_line, spacing) -> float:
    """How far from the crease the strip that cuts the corner reaches on one side: the outer edge
    of the last of the bands (one spacing wide, from the crease outwards) whose vertices lie, on
    average, significantly towards the other face (:data:`STRIP_SPREADS`); 0 where none does."""
    normal, centroid, _ = plane
    if dot3(normal, toward_other) < 0:
        normal = -normal
    kept_here = np.compress(side, kept)
    if not kept_here.any():
        return 0.0
    height = columns_dot(offset_columns(np.compress(side, points, axis=0), centroid), normal)
    distance = np.compress(side, to_line)
    if not np.isfinite(distance).all():
        return 0.0  # no line to bin from (a cast NaN would be a negative bin): no strip measured
    outer = kept_here & (distance >= _median(np.compress(kept_here, distance)))
    if not outer.any():
        return 0.0
    outer_height = np.compress(outer, height)
    spread = _robust_spread(_median(np.abs(outer_height - _median(outer_height))), spacing)
    # A bin per spacing where the line runs through the patch; only the bands that hold vertices
    # where it lies far from it (planes near parallel). The sums run in the same order.
    index_of = (distance / spacing).astype(np.int64)
    if int(index_of.max()) <= 4 * index_of.size:
        counts = np.bincount(index_of)
        bands, sums = None, np.bincount(index_of, weights=height)
    else:
        bands, slot, counts = np.unique(index_of, return_inverse=True, return_counts=True)
        sums = np.bincount(slot.ravel(), weights=height)
    width = 0.0
    for index in np.flatnonzero(counts >= MIN_BAND_VERTICES).tolist():
        band, count = index if bands is None else int(bands[index]), int(counts[index])
        if float(sums[index]) / count <= STRIP_SPREADS * spread / math.sqrt(count):
            break
        width = (band + 1) * spacing
    return width


def _refine_by_strip(points, normals, labels, center, radius, spacing, planes):
    """The second stage of :func:`refine_sides`, where the first leaves Algorithm 1's planes: the
    strip that cuts the corner is measured by where the vertices lie on average, band by band
    outwards from the crease (:func:`_strip_width`), not by which single vertices stand out from
    a scan's noise; it is left out whole, the vertices beyond it go to the face they are nearer,
    and the planes are fitted again, until nothing changes. Used only where both faces are then
    shown to be planes (:func:`_planar`) and meet near the centre; ``None`` otherwise."""
    plus = labels
    planes = [
        plane if plane is not None else side_plane(points, normals, side)
        for plane, side in zip(planes or [None, None], (plus, ~plus), strict=True)
    ]
    kept = np.ones(points.shape[0], dtype=bool)
    widths = [0.0, 0.0]
    if planes[0] is not None and planes[1] is not None and FIRST_BAND > 0:
        found = _half_plane_distances(points, center, planes)
        if found is None:
            return None
        (to_plus, to_minus), frame = found
        plus = to_plus < to_minus
        kept = distance_to_line(points, frame[0], frame[1]) >= FIRST_BAND * spacing
        if min(int((plus & kept).sum()), int((~plus & kept).sum())) < MIN_FAR_VERTICES:
            return None
        planes = [side_plane(points, normals, side) for side in (plus & kept, ~plus & kept)]
    for round_number in range(MAX_ROUNDS):
        if planes[0] is None or planes[1] is None:
            return None
        found = _half_plane_distances(points, center, planes)
        if found is None:
            return None
        (to_plus, to_minus), frame = found
        on_line, direction, into_faces = frame
        to_line = distance_to_line(points, on_line, direction)
        new_plus = to_plus < to_minus
        new_kept = np.ones(points.shape[0], dtype=bool)
        sides = (new_plus, ~new_plus)
        for k, side in enumerate(sides):
            widths[k] = _strip_width(
                points, side, kept, planes[k], into_faces[1 - k], to_line, spacing
            )
            new_kept[side] = to_line[side] >= widths[k]
        if round_number == 0 and max(widths) == 0.0:
            return None  # no strip beside the planes fitted without the first band
        if np.array_equal(new_plus, plus) and np.array_equal(new_kept, kept):
            break
        plus, kept = new_plus, new_kept
        if min(int((plus & kept).sum()), int((~plus & kept).sum())) < MIN_FAR_VERTICES:
            return None
        planes = [side_plane(points, normals, side) for side in (plus & kept, ~plus & kept)]
    else:
        return None
    if max(widths) == 0.0:
        return None  # no strip: Algorithm 1's planes stand
    if distance_to_line(center[None, :], on_line, direction)[0] > CREASE_REACH * radius:
        return None
    for k, side in enumerate((plus, ~plus)):
        face_frame = (on_line, direction, into_faces[k])
        if (
            _planar(points, side & kept, planes[k], face_frame, spacing, radius, STRICT_GAIN)
            is not True
        ):
            return None  # a curved face, or one too narrow to show it is a plane
    return _fields(plus, kept, planes)


def refine_sides(points, normals, labels, center, radius, spacing, split_error, planes=None):
    """Refine Algorithm 1's split (see the module's description).

    Parameters
    ----------
    points, normals : ndarray, shape (k, 3)
        The patch, in canonical order.
    labels : ndarray of bool, shape (k,)
        Algorithm 1's sides (``True``: "+").
    center : ndarray, shape (3,)
        The centre of the patch.
    radius, spacing : float
        The patch radius and its mean edge length.
    split_error : float
        Algorithm 1's summed plane-fit error.
    planes : list, optional
        Algorithm 1's two planes as (unit normal oriented by the side's mean normal, centroid,
        fit error), or ``None`` for a side whose plane is not its own vertices' (a borrowed row):
        the first round starts from them instead of fitting them again.

    Returns
    -------
    dict or None
        The refined fields (``labels``, ``used``, the two planes' normals, fit errors and
        ``centroids``, a point on each), or
        ``None`` where the refinement does not apply: nothing moved, a side ran out of vertices or
        no longer spans a plane, or one of the conditions in the module's description fails.

    Raises
    ------
    GoniometerError
        Where a strip that cuts the corner is found but a face keeps too few rows of vertices
        without it to carry its plane (Algorithm 1's reading would be off, by an unknown amount).
    """
    if split_error <= (NOISE_FLOOR * spacing) ** 2:
        return None  # Algorithm 1's planes already fit to rounding error
    # A refusal of the first stage stands: it showed a strip that leaves a face too little to
    # carry its plane, and a narrower band found by the second would read that face's plane off.
    refined = _refine_by_outliers(
        points, normals, labels, center, radius, spacing, split_error, planes
    )
    if refined is not None and split_error >= DECISIVE_IMPROVEMENT * refined["fit_error"]:
        return refined  # exact faces without the vertices off them: nothing is left to find
    by_strip = _refine_by_strip(points, normals, labels, center, radius, spacing, planes)
    if by_strip is not None and (
        refined is None or by_strip["used"].sum() <= refined["used"].sum()
    ):
        return by_strip  # a band at least as large as the vertices the first stage found off
    return refined


__all__ = ["MIN_IMPROVEMENT", "NEAR_SPACINGS", "mean_edge_length", "refine_sides"]
