"""Synthetic shapes with known angles, for tests and demonstrations.

* :func:`wedge`: two planar faces meeting at a straight crease of a given interior angle.
* :func:`varying_wedge`: a crease whose interior angle changes linearly along it.
* :func:`lens`: two intersecting spheres, whose circular rim has one exact angle all round.
* :func:`bone_fragment`: a watertight long-bone shaft fragment (hollow tube) with a transverse
  and an oblique fracture face, and :class:`BreakSite` points on its rims whose true angles
  follow exactly from the geometry.

Everything is deterministic: random choices come from ``numpy.random.default_rng(seed)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .errors import GoniometerError
from .method.fixed_order import dot3, norm3, row_dot

__all__ = [
    "REGION_INNER",
    "REGION_OBLIQUE",
    "REGION_OUTER",
    "REGION_RIM",
    "REGION_TRANSVERSE",
    "BoneFragment",
    "BreakSite",
    "SynthMesh",
    "bevelled_wedge",
    "bone_fragment",
    "lens",
    "varying_wedge",
    "wedge",
]

# Per-vertex regions of a bone fragment.
REGION_RIM = -1  # on an edge where a fracture face meets the outer or inner surface
REGION_OUTER = 0  # periosteal (outer) cylinder
REGION_INNER = 1  # medullary (inner) cylinder
REGION_TRANSVERSE = 2  # fracture face perpendicular to the axis (z = 0)
REGION_OBLIQUE = 3  # tilted fracture face at the far end

_JITTER = 0.2  # irregular wedges: fraction of the grid spacing; < 1/4 keeps every triangle upright


@dataclass(frozen=True, eq=False)
class SynthMesh:
    """A synthetic wedge.

    Attributes
    ----------
    points : numpy.ndarray
        ``(n, 3)`` float64 vertex coordinates.
    triangles : numpy.ndarray
        ``(m, 3)`` int64 vertex indices, wound so that face normals point out of the solid.
    angle : float
        The true interior angle in degrees.
    side : numpy.ndarray
        int8 per vertex: +1 on the face at ``y > 0``, -1 on the face at ``y < 0``, 0 on the
        crease (shared by both faces).
    normal_plus, normal_minus : numpy.ndarray
        The exact outward unit normals of the +1 and -1 faces.
    """

    points: np.ndarray
    triangles: np.ndarray
    angle: float
    side: np.ndarray
    normal_plus: np.ndarray
    normal_minus: np.ndarray


def _positive(name: str, value) -> float:
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise GoniometerError(f"{name} must be a number, got {value!r}.") from None
    if not (math.isfinite(value) and value > 0):
        raise GoniometerError(f"{name} must be a positive finite number, got {value}.")
    return value


def _count(name: str, value, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < minimum:
        raise GoniometerError(f"{name} must be an integer ≥ {minimum}, got {value!r}.")
    return int(value)


def wedge(
    angle_deg: float,
    *,
    half_width: float = 1.0,
    depth: float = 1.0,
    n: int = 60,
    irregular: bool = False,
    seed: int = 0,
    imbalance: float = 1.0,
    concave: bool = False,
) -> SynthMesh:
    """Two planar faces meeting at a straight crease with interior angle ``angle_deg``.

    The crease runs along the x axis from ``-half_width`` to ``half_width`` through the origin;
    the solid lies below the faces with its bisector along -z, so the outward normals point up
    (positive z). Face +1 holds the points ``(x, t sin(a/2), -t cos(a/2))`` and face -1 the points
    ``(x, -t sin(a/2), -t cos(a/2))`` for ``0 <= t <= depth`` (``depth * imbalance`` on face -1).

    Parameters
    ----------
    angle_deg : float
        Interior (dihedral) angle inside the solid, in degrees, ``0 < angle_deg < 180``
        (5..175 is the range the tests use).
    half_width : float
        Half the crease length.
    depth : float
        Extent of face +1 away from the crease, measured in its plane.
    n : int
        Resolution: each face of a balanced wedge has about ``n * n`` vertices (a near-square
        grid of spacing ``sqrt(2 * half_width * depth) / n``).
    irregular : bool
        If true, vertices are jittered within their plane (crease vertices along the crease,
        boundary vertices along the boundary) and each grid cell's diagonal is chosen at random,
        so the mesh looks remeshed. Faces stay exactly planar and the crease vertices are shared.
    seed : int
        Seed of the random choices of an irregular wedge.
    imbalance : float
        Extent of face -1 relative to face +1 (same grid spacing), so a ball centred on the
        crease can hold unequal vertex counts per side.
    concave : bool
        Mirror the wedge in the plane ``z = 0``: the faces rise from the crease (a valley) and the
        solid lies below them, so the edge is concave and ``angle_deg`` is the angle of the open
        wedge above it (the solid's interior angle is ``360 - angle_deg``). Normals stay outward
        (upward).

    Returns
    -------
    SynthMesh

    Raises
    ------
    GoniometerError
        For an angle outside (0, 180) or a non-positive size or resolution.
    """
    try:
        angle = float(angle_deg)
    except (TypeError, ValueError):
        raise GoniometerError(f"The wedge angle must be a number, got {angle_deg!r}.") from None
    if not (0.0 < angle < 180.0):
        raise GoniometerError(f"The wedge angle must be between 0 and 180 degrees, got {angle}.")
    half_width = _positive("half_width", half_width)
    depth = _positive("depth", depth)
    imbalance = _positive("imbalance", imbalance)
    n = _count("n", n, 2)

    spacing = math.sqrt(2.0 * half_width * depth) / n
    columns = max(2, round(2.0 * half_width / spacing))
    rows = (max(1, round(depth / spacing)), max(1, round(depth * imbalance / spacing)))
    extents = (depth, depth * imbalance)
    x = np.linspace(-half_width, half_width, columns + 1)
    nx = x.size
    rng = np.random.default_rng(seed)

    # In-plane coordinates (x, t) of the crease row and of each face's rows.
    crease_x = x.copy()
    if irregular:
        crease_x[1:-1] += rng.uniform(-_JITTER, _JITTER, nx - 2) * (x[1] - x[0])
    faces = []
    for rows_, extent in zip(rows, extents, strict=True):
        t = np.linspace(0.0, extent, rows_ + 1)[1:]
        grid_x = np.broadcast_to(x, (rows_, nx)).copy()
        grid_t = np.broadcast_to(t[:, None], (rows_, nx)).copy()
        if irregular:
            hx, ht = x[1] - x[0], extent / rows_
            grid_x[:, 1:-1] += rng.uniform(-_JITTER, _JITTER, (rows_, nx - 2)) * hx
            grid_t[:-1, :] += rng.uniform(-_JITTER, _JITTER, (rows_ - 1, nx)) * ht
        faces.append((grid_x.ravel(), grid_t.ravel()))

    half = math.radians(angle) / 2.0
    s, c = math.sin(half), math.cos(half)
    (xa, ta), (xb, tb) = faces
    points = np.zeros((nx + xa.size + xb.size, 3))
    points[:nx, 0] = crease_x  # y = z = 0 exactly on the crease
    points[nx : nx + xa.size] = np.column_stack([xa, ta * s, -ta * c])
    points[nx + xa.size :] = np.column_stack([xb, -tb * s, -tb * c])
    side = np.zeros(points.shape[0], dtype=np.int8)
    side[nx : nx + xa.size] = 1
    side[nx + xa.size :] = -1

    triangles = []
    offset = nx
    for face_sign, rows_ in zip((1, -1), rows, strict=True):
        # Vertex ids of this face's (rows_ + 1) x nx grid, row 0 being the shared crease.
        ids = np.vstack([np.arange(nx), offset + np.arange(rows_ * nx).reshape(rows_, nx)])
        offset += rows_ * nx
        a, b = ids[:-1, :-1].ravel(), ids[:-1, 1:].ravel()
        cc, d = ids[1:, 1:].ravel(), ids[1:, :-1].ravel()
        # Quad a-b-c-d runs counter-clockwise in (x, t); its two triangles by either diagonal.
        diagonal_ac = rng.random(a.size) < 0.5 if irregular else np.ones(a.size, dtype=bool)
        first = np.where(
            diagonal_ac[:, None], np.column_stack([a, b, cc]), np.column_stack([a, b, d])
        )
        second = np.where(
            diagonal_ac[:, None], np.column_stack([a, cc, d]), np.column_stack([b, cc, d])
        )
        tris = np.stack([first, second], axis=1).reshape(-1, 3)
        if face_sign < 0:
            tris = tris[:, [0, 2, 1]]  # e_x x u points into the solid on face -1
        triangles.append(tris)

    normal_plus, normal_minus = np.array([0.0, c, s]), np.array([0.0, -c, s])
    if concave:  # a reflection also turns the winding, so the same triangles stay outward
        points[:, 2] = -points[:, 2]
        normal_plus, normal_minus = normal_minus, normal_plus
    return SynthMesh(
        points=points,
        triangles=np.vstack(triangles).astype(np.int64),
        angle=angle,
        side=side,
        normal_plus=normal_plus,
        normal_minus=normal_minus,
    )


def bevelled_wedge(
    angle_deg: float,
    fillet: float,
    *,
    half_width: float = 1.0,
    depth: float = 1.0,
    spacing: float = 0.02,
    concave: bool = False,
) -> SynthMesh:
    """A wedge whose crease is rounded by a circular fillet (a worn or bevelled edge).

    The two planar faces are those of :func:`wedge` (same angle, orientation and normals); near
    the crease they are joined by a circular arc of radius ``fillet``, tangent to both, so the
    angle between the faces is still exactly ``angle_deg``. The mesh is a regular grid: rows
    ``spacing`` apart along the profile (the arc gets at least two segments), columns ``spacing``
    apart along the crease (the x axis).

    Parameters
    ----------
    angle_deg : float
        Angle between the faces, ``0 < angle_deg < 180``.
    fillet : float
        Radius of the rounding (0: a sharp crease).
    half_width, depth : float
        Half the crease length; extent of each face beyond the fillet's tangent line.
    spacing : float
        Grid spacing.
    concave : bool
        Mirror in ``z = 0`` as :func:`wedge` does: a rounded valley, normals still outward.

    Returns
    -------
    SynthMesh
        ``side`` is +1/-1 on the planar parts, 0 on the fillet.
    """
    angle = float(angle_deg)
    if not 0.0 < angle < 180.0:
        raise GoniometerError(f"The wedge angle must be between 0 and 180 degrees, got {angle}.")
    fillet = float(fillet)
    if not (math.isfinite(fillet) and fillet >= 0):
        raise GoniometerError(f"The fillet radius must be 0 or more, got {fillet}.")
    half_width, depth = _positive("half_width", half_width), _positive("depth", depth)
    spacing = _positive("spacing", spacing)
    half = math.radians(angle) / 2.0
    s, c = math.sin(half), math.cos(half)
    tangent_length = fillet / math.tan(half)  # crease to the fillet's tangent points
    centre = np.array([0.0, -fillet / s])  # (y, z) of the fillet's centre, on the bisector
    # The tangent points sit at centre + fillet * (outward normal of their face): at the angles
    # pi - half (face -1) and half (face +1); the arc runs over the top between them.
    start, stop = math.pi - half, half
    n_arc = max(2, math.ceil(fillet * abs(stop - start) / spacing)) if fillet > 0 else 0
    arc_angles = np.linspace(start, stop, n_arc + 1) if fillet > 0 else np.zeros(1)
    arc = centre + fillet * np.column_stack([np.cos(arc_angles), np.sin(arc_angles)])
    if fillet == 0:
        arc = np.zeros((1, 2))
    steps = np.arange(1, math.floor(depth / spacing) + 1) * spacing
    plus = (tangent_length + steps)[:, None] * np.array([s, -c])
    minus = (tangent_length + steps[::-1])[:, None] * np.array([-s, -c])
    profile = np.vstack([minus, arc, plus])
    x = np.linspace(-half_width, half_width, max(2, round(2 * half_width / spacing)) + 1)
    points = np.column_stack(
        [np.repeat(x, len(profile)), np.tile(profile[:, 0], x.size), np.tile(profile[:, 1], x.size)]
    )
    side = np.tile(
        np.concatenate([-np.ones(len(minus)), np.zeros(len(arc)), np.ones(len(plus))]), x.size
    ).astype(np.int8)
    ids = np.arange(points.shape[0]).reshape(x.size, len(profile))
    a, b = ids[:-1, :-1].ravel(), ids[1:, :-1].ravel()
    cc, d = ids[1:, 1:].ravel(), ids[:-1, 1:].ravel()
    # Along the profile the points run from face -1 to face +1, i.e. towards +y; (e_x, +y)
    # counter-clockwise has its normal up (outward).
    triangles = np.vstack([np.column_stack([a, b, cc]), np.column_stack([a, cc, d])])
    normal_plus, normal_minus = np.array([0.0, c, s]), np.array([0.0, -c, s])
    if concave:
        points[:, 2] = -points[:, 2]
        normal_plus, normal_minus = normal_minus, normal_plus
    return SynthMesh(
        points=points,
        triangles=triangles.astype(np.int64),
        angle=angle,
        side=side,
        normal_plus=normal_plus,
        normal_minus=normal_minus,
    )


@dataclass(frozen=True, eq=False)
class EdgeShape:
    """A synthetic mesh with one break edge whose exact angle is known everywhere along it.

    Attributes
    ----------
    points, triangles : numpy.ndarray
        Vertices (float64) and outward-wound triangles (int64).
    edge : numpy.ndarray
        Indices of the vertices on the break edge, in order along it.
    angle_at : callable
        ``angle_at(xyz)`` gives the exact interior angle (degrees) at points of the edge,
        ``(k, 3) -> (k,)``.
    """

    points: np.ndarray
    triangles: np.ndarray
    edge: np.ndarray
    angle_at: object


def _grid_triangles(ids: np.ndarray, flip: bool) -> np.ndarray:
    """Two triangles per cell of a grid of vertex ids, counter-clockwise unless ``flip``."""
    a, b = ids[:-1, :-1].ravel(), ids[:-1, 1:].ravel()
    c, d = ids[1:, 1:].ravel(), ids[1:, :-1].ravel()
    tris = np.stack([np.column_stack([a, b, c]), np.column_stack([a, c, d])], axis=1).reshape(-1, 3)
    return tris[:, [0, 2, 1]] if flip else tris


def varying_wedge(
    angle_start: float,
    angle_end: float,
    *,
    half_width: float = 4.0,
    depth: float = 1.0,
    n: int = 30,
) -> EdgeShape:
    """A wedge whose interior angle changes linearly from ``angle_start`` at ``x = -half_width``
    to ``angle_end`` at ``x = half_width``.

    The crease is the x axis; the cross-section at ``x`` is an exact wedge of angle ``a(x)``:
    its faces are the ruled surfaces ``(x, ±t sin(a(x)/2), -t cos(a(x)/2))``, ``0 <= t <= depth``,
    so the local angle at crease point ``x`` is exactly ``a(x)``. ``n`` vertices per unit length.
    """
    for value in (angle_start, angle_end):
        if not 0.0 < float(value) < 180.0:
            raise GoniometerError(
                f"The wedge angles must be between 0 and 180 degrees, got {value}."
            )
    half_width, depth = _positive("half_width", half_width), _positive("depth", depth)
    n = _count("n", n, 2)
    x = np.linspace(-half_width, half_width, round(2 * half_width * n) + 1)
    t = np.linspace(0.0, depth, round(depth * n) + 1)[1:]
    half = (
        np.radians(angle_start + (angle_end - angle_start) * (x + half_width) / (2 * half_width))
        / 2
    )
    nx, nt = x.size, t.size
    points = [np.column_stack([x, np.zeros(nx), np.zeros(nx)])]
    for sign in (1.0, -1.0):
        grid_x = np.broadcast_to(x, (nt, nx))
        grid_y = sign * t[:, None] * np.sin(half)[None, :]
        grid_z = -t[:, None] * np.cos(half)[None, :]
        points.append(np.column_stack([grid_x.ravel(), grid_y.ravel(), grid_z.ravel()]))
    crease = np.arange(nx)
    plus = np.vstack([crease, nx + np.arange(nt * nx).reshape(nt, nx)])
    minus = np.vstack([crease, nx + nt * nx + np.arange(nt * nx).reshape(nt, nx)])
    triangles = np.vstack([_grid_triangles(plus, False), _grid_triangles(minus, True)])

    def angle_at(xyz):
        xs = np.asarray(xyz, dtype=np.float64).reshape(-1, 3)[:, 0]
        return angle_start + (angle_end - angle_start) * (xs + half_width) / (2 * half_width)

    return EdgeShape(np.vstack(points), triangles.astype(np.int64), crease, angle_at)


def lens(angle_deg: float = 70.53, *, radius: float = 1.0, n_around: int = 240) -> EdgeShape:
    """The lens where two spheres of equal ``radius`` overlap; its rim has interior angle
    ``angle_deg`` all round.

    The spheres' centres are ``(0, 0, ±d)``; the rim is the circle ``z = 0`` of radius
    ``rho = sqrt(radius^2 - d^2)``. At the rim the outward normals are ``(rho, 0, ±d) / radius``,
    so the interior angle is ``180° - arccos((rho^2 - d^2) / radius^2)``: ``d`` is chosen from it.
    The caps are polar grids of ``n_around`` vertices per ring, the rim ring shared by both.
    """
    angle = float(angle_deg)
    if not 0.0 < angle < 180.0:
        raise GoniometerError(f"The lens angle must be between 0 and 180 degrees, got {angle}.")
    radius = _positive("radius", radius)
    n_around = _count("n_around", n_around, 8)
    # (rho^2 - d^2) / R^2 = cos(180° - angle) and rho^2 + d^2 = R^2.
    cosine = math.cos(math.radians(180.0 - angle))
    d = radius * math.sqrt((1.0 - cosine) / 2.0)
    rho = math.sqrt(radius**2 - d**2)
    polar = math.acos(d / radius)  # the cap's half-angle seen from its sphere's centre
    rings = max(2, round(polar * radius / (2 * math.pi * rho / n_around)))
    phi = 2 * math.pi * np.arange(n_around) / n_around
    theta = polar * np.arange(1, rings + 1) / rings  # ring 'rings' is the rim
    sin_t, cos_t = np.sin(theta)[:, None], np.cos(theta)[:, None]
    rim = np.column_stack([rho * np.cos(phi), rho * np.sin(phi), np.zeros(n_around)])
    points, triangles = [rim], []
    offset = n_around
    for sign in (1.0, -1.0):  # the cap above z = 0 belongs to the sphere centred below
        ring_xyz = np.stack(
            [
                radius * sin_t * np.cos(phi),
                radius * sin_t * np.sin(phi),
                sign * (radius * cos_t - d) + 0 * phi,
            ],
            axis=-1,
        )[:-1]  # the last ring is the rim
        pole = offset
        points.append(np.array([[0.0, 0.0, sign * (radius - d)]]))
        ids = np.vstack(
            [
                offset + 1 + np.arange((rings - 1) * n_around).reshape(rings - 1, n_around),
                np.arange(n_around),
            ]
        )
        points.append(ring_xyz.reshape(-1, 3))
        offset += 1 + (rings - 1) * n_around
        wrap = np.hstack([ids, ids[:, :1]])
        cap = _grid_triangles(wrap, sign > 0)
        fan = np.column_stack([np.full(n_around, pole), wrap[0, :-1], wrap[0, 1:]])
        triangles += [cap, fan if sign > 0 else fan[:, [0, 2, 1]]]

    def angle_at(xyz):
        return np.full(np.asarray(xyz).reshape(-1, 3).shape[0], angle)

    return EdgeShape(
        np.vstack(points), np.vstack(triangles).astype(np.int64), np.arange(n_around), angle_at
    )


@dataclass(frozen=True)
class BreakSite:
    """A point on a rim of a synthetic fragment with its exactly known interior angle.

    Attributes
    ----------
    label : str
        Which rim and where, e.g. ``"oblique/outer acute"``.
    point : tuple of float
        xyz of the rim point; it is a vertex of the mesh (index ``vertex``).
    angle : float
        True interior angle in degrees: 180 minus the angle between the outward normals of the
        two surfaces meeting at the point.
    vertex : int
        Index of the point in the fragment's ``points``.
    """

    label: str
    point: tuple[float, float, float]
    angle: float
    vertex: int


@dataclass(frozen=True, eq=False)
class BoneFragment:
    """A synthetic long-bone shaft fragment.

    Attributes
    ----------
    points : numpy.ndarray
        ``(n, 3)`` float64 vertex coordinates in millimetres; the shaft axis is z.
    triangles : numpy.ndarray
        ``(m, 3)`` int64 vertex indices of a closed, watertight, outward-wound surface.
    sites : list of BreakSite
        Rim points with their true angles.
    region : numpy.ndarray
        int8 per vertex: ``REGION_OUTER``, ``REGION_INNER``, ``REGION_TRANSVERSE``,
        ``REGION_OBLIQUE``, or ``REGION_RIM`` on the four rims.
    """

    points: np.ndarray
    triangles: np.ndarray
    sites: list[BreakSite]
    region: np.ndarray


def _interior_angle(normal_a: np.ndarray, normal_b: np.ndarray) -> float:
    """180 degrees minus the angle between two outward normals."""
    between = math.atan2(norm3(np.cross(normal_a, normal_b)), dot3(normal_a, normal_b))
    return 180.0 - math.degrees(between)


def bone_fragment(
    *,
    outer_radius: float = 12.0,
    inner_radius: float = 7.0,
    length: float = 60.0,
    oblique_deg: float = 35.0,
    spacing: float = 0.2,
    roughness: float = 0.0,
    seed: int = 0,
) -> BoneFragment:
    """A hollow tube cut by a transverse and an oblique fracture plane, in millimetres.

    The shaft axis is z. The transverse fracture face is the plane ``z = 0``; the oblique one is
    the plane ``z = length + tan(oblique) * x``, tilted by ``oblique_deg`` about the y axis, so
    the fragment's mean length is ``length`` and its volume ``pi (R^2 - r^2) length``. The
    surface is one closed, watertight triangle mesh wound with outward normals (the inner
    cylinder's normals point towards the axis).

    Parameters
    ----------
    outer_radius, inner_radius : float
        Radii of the periosteal and medullary surfaces, ``0 < inner_radius < outer_radius``.
    length : float
        Length along the axis at the centre of the oblique face; must exceed
        ``outer_radius * tan(oblique_deg)`` so the two fracture faces do not meet.
    oblique_deg : float
        Tilt of the oblique fracture plane from transverse, ``0 <= oblique_deg < 90``.
    spacing : float
        Target edge length in mm. The default 0.2 gives about 250,000 vertices; tests use 1-2.
        The number of vertices around the shaft is a multiple of 8, so the break sites at
        0, 45, 90 and 180 degrees around the axis are vertices.
    roughness : float
        RMS amplitude in mm of a smooth deterministic bumpiness added to every surface along its
        normal (rim vertices stay put). Keep it below ``spacing`` to avoid folded triangles.
    seed : int
        Seed of the roughness pattern.

    Returns
    -------
    BoneFragment
        The mesh, eight :class:`BreakSite` and a per-vertex region label. Site angles are those of
        the ideal (smooth) geometry.

    Raises
    ------
    GoniometerError
        For inconsistent dimensions or a resolution beyond 50 million vertices.
    """
    big_r = _positive("outer_radius", outer_radius)
    small_r = _positive("inner_radius", inner_radius)
    length = _positive("length", length)
    spacing = _positive("spacing", spacing)
    if small_r >= big_r:
        raise GoniometerError(
            f"inner_radius ({small_r}) must be smaller than outer_radius ({big_r})."
        )
    oblique = float(oblique_deg)
    if not (0.0 <= oblique < 90.0):
        raise GoniometerError(f"oblique_deg must be in [0, 90), got {oblique}.")
    slope = math.tan(math.radians(oblique))
    if length <= big_r * slope:
        raise GoniometerError(
            f"The oblique cut reaches the transverse end: length ({length}) must exceed "
            f"outer_radius * tan(oblique_deg) = {big_r * slope:.3f}."
        )
    roughness = float(roughness)
    if not (math.isfinite(roughness) and roughness >= 0):
        raise GoniometerError(f"roughness must be ≥ 0, got {roughness}.")

    around = 8 * max(2, math.ceil(2 * math.pi * big_r / spacing / 8))
    along = max(2, round(length / spacing))
    across = max(1, round((big_r - small_r) / spacing))
    profile_size = 2 * across + 2 * along
    if around * profile_size > 50_000_000:
        raise GoniometerError(
            f"spacing {spacing} mm would make {around * profile_size:,} vertices; use a larger "
            "spacing (at most 50 million vertices)."
        )

    # The closed cross-section profile (radius, height fraction) walked once around:
    # transverse face outwards, outer cylinder up, oblique face inwards, inner cylinder down.
    # A vertex's height is fraction * (length + slope * x), which is 0 on the transverse face,
    # the oblique plane's height on the oblique face, and in between on the cylinders.
    steps_across = np.arange(across) / across
    steps_along = np.arange(along) / along
    radius = np.concatenate(
        [
            small_r + (big_r - small_r) * steps_across,
            np.full(along, big_r),
            big_r - (big_r - small_r) * steps_across,
            np.full(along, small_r),
        ]
    )
    fraction = np.concatenate([np.zeros(across), steps_along, np.ones(across), 1.0 - steps_along])
    region_profile = np.concatenate(
        [
            np.full(across, REGION_TRANSVERSE),
            np.full(along, REGION_OUTER),
            np.full(across, REGION_OBLIQUE),
            np.full(along, REGION_INNER),
        ]
    ).astype(np.int8)
    corners = [0, across, across + along, 2 * across + along]
    region_profile[corners] = REGION_RIM

    theta = 2.0 * math.pi * np.arange(around) / around
    cos_t, sin_t = np.cos(theta), np.sin(theta)
    x = cos_t[:, None] * radius[None, :]
    y = sin_t[:, None] * radius[None, :]
    z = fraction[None, :] * (length + slope * x)
    points = np.stack([x, y, z], axis=-1).reshape(-1, 3)
    region = np.broadcast_to(region_profile, (around, profile_size)).reshape(-1).copy()

    # Quads between neighbouring profile points and angles, both wrapping around (a torus grid).
    j = np.arange(around)[:, None]
    p = np.arange(profile_size)[None, :]
    a = (j * profile_size + p).ravel()
    b = (((j + 1) % around) * profile_size + p).ravel()
    c = (((j + 1) % around) * profile_size + (p + 1) % profile_size).ravel()
    d = (j * profile_size + (p + 1) % profile_size).ravel()
    triangles = np.stack([np.column_stack([a, b, c]), np.column_stack([a, c, d])], axis=1)
    triangles = triangles.reshape(-1, 3).astype(np.int64)

    tilt = math.radians(oblique)
    normal_oblique = np.array([-math.sin(tilt), 0.0, math.cos(tilt)])
    normal_transverse = np.array([0.0, 0.0, -1.0])

    if roughness > 0:
        normals = np.zeros_like(points)
        radial = np.stack(
            [
                np.broadcast_to(cos_t[:, None], x.shape),
                np.broadcast_to(sin_t[:, None], x.shape),
                np.zeros(x.shape),
            ],
            axis=-1,
        ).reshape(-1, 3)
        normals[region == REGION_OUTER] = radial[region == REGION_OUTER]
        normals[region == REGION_INNER] = -radial[region == REGION_INNER]
        normals[region == REGION_TRANSVERSE] = normal_transverse
        normals[region == REGION_OBLIQUE] = normal_oblique
        points += roughness * _bumps(points, seed)[:, None] * normals

    sites = []
    specs = [  # (label, angle around the axis in eighths of a turn, profile corner, normals)
        ("transverse/outer", 2, corners[1], "outer", "transverse"),
        ("transverse/inner", 6, corners[0], "inner", "transverse"),
        ("oblique/outer acute", 0, corners[2], "outer", "oblique"),
        ("oblique/outer 45°", 1, corners[2], "outer", "oblique"),
        ("oblique/outer side", 2, corners[2], "outer", "oblique"),
        ("oblique/outer obtuse", 4, corners[2], "outer", "oblique"),
        ("oblique/inner obtuse", 0, corners[3], "inner", "oblique"),
        ("oblique/inner acute", 4, corners[3], "inner", "oblique"),
    ]
    for label, eighth, corner, cylinder, face in specs:
        column = eighth * around // 8
        vertex = column * profile_size + corner
        outward = np.array([cos_t[column], sin_t[column], 0.0])
        normal_cylinder = outward if cylinder == "outer" else -outward
        normal_face = normal_oblique if face == "oblique" else normal_transverse
        sites.append(
            BreakSite(
                label=label,
                point=tuple(float(v) for v in points[vertex]),
                angle=_interior_angle(normal_cylinder, normal_face),
                vertex=int(vertex),
            )
        )
    return BoneFragment(points=points, triangles=triangles, sites=sites, region=region)


def _bumps(points: np.ndarray, seed: int, waves: int = 16) -> np.ndarray:
    """A smooth pseudo-random field of unit RMS: a sum of plane waves of 1.5-6 mm wavelength."""
    rng = np.random.default_rng(seed)
    directions = rng.normal(size=(waves, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    wavenumbers = 2.0 * math.pi / rng.uniform(1.5, 6.0, waves)
    phases = rng.uniform(0.0, 2.0 * math.pi, waves)
    waves_at = np.stack([row_dot(points, d) for d in directions * wavenumbers[:, None]], axis=1)
    field = np.sin(waves_at + phases).sum(axis=1)
    return field / math.sqrt(waves / 2.0)
