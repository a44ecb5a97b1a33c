"""Synthetic fragments whose break edges are known exactly, to measure an edge finder against.

Each :class:`Fragment` carries its mesh, its true break edges as dense polylines, the true face
of every vertex and which faces are fracture surfaces:

* :func:`bone_shaft`: the demo's long-bone shaft (:func:`~vg_addon.synthetic_meshes.bone_fragment`),
  a hollow tube with a transverse and an oblique fracture face: four rims, all closed loops.
* :func:`bevelled_cube`: a cube, two of its top edges rounded by a fillet (a worn or bevelled
  edge, whose true edge is the fillet's middle line), the other ten sharp.
* :func:`flake`: a flake-like solid: a convex dorsal cap on a flat ventral (fracture) face with a
  knife edge of 45° all round, and a striking platform cut across one end; meshed with its
  vertices on the edges.

:func:`with_noise` adds scanner-like noise to any of them; :func:`marched_bevelled_cube` and
:func:`marched_flake` mesh the cube and the flake afresh by marching tetrahedra, so that no vertex
lies on an edge. Lengths are millimetres.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from .marching_tetrahedra import march
from .method.normals import vertex_normals
from .synthetic_meshes import REGION_OBLIQUE, REGION_TRANSVERSE
from .synthetic_meshes import bone_fragment as _bone_fragment

__all__ = [
    "Fragment",
    "bevelled_cube",
    "bone_shaft",
    "flake",
    "marched_bevelled_cube",
    "marched_flake",
    "with_noise",
]

_SAMPLES_PER_MM = 20  # true edges are sampled this densely (every 0.05 mm)


@dataclass(frozen=True, eq=False)
class Fragment:
    """A synthetic fragment with known break edges.

    Attributes
    ----------
    name : str
    points : ndarray, shape (n, 3)
        Vertex coordinates in mm.
    triangles : ndarray of int64, shape (m, 3)
        Closed, outward-wound faces.
    edges : tuple of ndarray, shape (k, 3)
        The true break edges, each a polyline sampled every 0.05 mm (a loop repeats its first
        point at the end).
    faces : ndarray of int64, shape (n,)
        The true face each vertex lies on (the nearest one for a vertex on an edge).
    fracture : frozenset of int
        The faces that are fracture surfaces (the rest are original surface).
    """

    name: str
    points: np.ndarray
    triangles: np.ndarray
    edges: tuple
    faces: np.ndarray
    fracture: frozenset


def _polyline(function, low: float, high: float, length: float) -> np.ndarray:
    """``function(t)`` for ``t`` from ``low`` to ``high``, sampled every 0.05 mm of ``length``."""
    count = max(2, math.ceil(length * _SAMPLES_PER_MM) + 1)
    return function(np.linspace(low, high, count))


def _circle(centre, radius: float, height_of=None, turns=(0.0, 2.0 * math.pi)) -> np.ndarray:
    """A circle (arc) about the z axis through ``centre``; z from ``height_of(x)`` if given."""
    cx, cy, cz = centre

    def at(theta):
        x = cx + radius * np.cos(theta)
        z = height_of(x) if height_of is not None else np.full(theta.size, cz)
        return np.column_stack([x, cy + radius * np.sin(theta), z])

    samples = _polyline(at, turns[0], turns[1], 2.5 * radius * abs(turns[1] - turns[0]))
    return samples


def bone_shaft(spacing: float = 1.0, **options) -> Fragment:
    """The demo's bone shaft fragment (outer radius 12, inner 7, length 60, oblique cut 35°).

    Parameters
    ----------
    spacing : float
        Mesh edge length in mm.
    **options
        Passed to :func:`~vg_addon.synthetic_meshes.bone_fragment` (``roughness``, ``seed``,
        ``outer_radius``, ...).
    """
    options.setdefault("outer_radius", 12.0)
    options.setdefault("inner_radius", 7.0)
    options.setdefault("length", 60.0)
    options.setdefault("oblique_deg", 35.0)
    bone = _bone_fragment(spacing=spacing, **options)
    slope = math.tan(math.radians(options["oblique_deg"]))
    length = options["length"]
    edges = []
    for radius in (options["outer_radius"], options["inner_radius"]):
        edges.append(_circle((0.0, 0.0, 0.0), radius))
        edges.append(_circle((0.0, 0.0, 0.0), radius, lambda x: length + slope * x))
    faces = bone.region.astype(np.int64)
    rim = faces < 0  # a rim vertex is counted on the fracture face it bounds
    z, oblique_z = bone.points[:, 2], length + slope * bone.points[:, 0]
    end = np.where(np.abs(z) < np.abs(z - oblique_z), REGION_TRANSVERSE, REGION_OBLIQUE)
    faces[rim] = end[rim]
    return Fragment(
        name="bone shaft",
        points=bone.points,
        triangles=bone.triangles,
        edges=tuple(edges),
        faces=faces,
        fracture=frozenset({REGION_TRANSVERSE, REGION_OBLIQUE}),
    )


def _cube_profile(a: float, r: float, spacing: float):
    """The cube's cross-section in the (x, z) plane, walked once round (not closed), with
    each point's face (+x 0, -x 1, +z 4, -z 5, fillets 6 and 7) and corners on the points."""

    def line(p, q, face):
        count = max(1, math.ceil(math.dist(p, q) / spacing))
        t = np.arange(count)[:, None] / count
        return np.asarray(p) + t * (np.asarray(q) - np.asarray(p)), np.full(count, face)

    def arc(centre, start, face):
        count = max(2, math.ceil(r * math.pi / 2 / spacing))
        theta = start + np.arange(count) / count * math.pi / 2
        return np.column_stack(
            [centre[0] + r * np.cos(theta), centre[1] + r * np.sin(theta)]
        ), np.full(count, face)

    pieces = [
        line((-a, -a), (a, -a), 5), line((a, -a), (a, a - r), 0), arc((a - r, a - r), 0.0, 6),
        line((a - r, a), (-(a - r), a), 4), arc((-(a - r), a - r), math.pi / 2, 7),
        line((-a, a - r), (-a, -a), 1),
    ]  # fmt: skip
    return np.vstack([p for p, _ in pieces]), np.concatenate([f for _, f in pieces])


def bevelled_cube(size: float = 20.0, fillet: float = 1.5, spacing: float = 0.4) -> Fragment:
    """A cube of side ``size`` whose two top edges along y are rounded by a fillet of radius
    ``fillet``: a prism of its cross-section, vertices about ``spacing`` apart, on the edges.

    The true edge of a rounded edge is the fillet's middle line; where the rounded edges meet
    the side faces ±y, those faces' edges follow the fillet's arc. Faces: 0..5 the planes +x,
    -x, +y, -y, +z, -z; 6 and 7 the fillets. All are counted as original surface (a cube has no
    fracture face); the fragment tests edges, not the kinds of regions.
    """
    a, r = size / 2.0, fillet
    profile, labels = _cube_profile(a, r, spacing)
    closed = np.vstack([profile, profile[:1]])  # rows repeat their first point (welded)
    ys = np.linspace(-a, a, max(2, math.ceil(size / spacing)) + 1)
    sides = [np.column_stack([closed[:, 0], np.full(len(closed), y), closed[:, 1]]) for y in ys]
    parts = [(*_strips(sides, lambda c: c * [1.0, 0.0, 1.0]), 4)]
    scales = np.linspace(0.0, 1.0, max(2, math.ceil(a / spacing)) + 1)
    for y, face in ((a, 2), (-a, 3)):
        rows = [np.array([[0.0, y, 0.0]])]
        rows += [np.column_stack([f * closed[:, 0], np.full(len(closed), y), f * closed[:, 1]])
                 for f in scales[1:]]  # fmt: skip
        outward = np.array([0.0, 1.0 if y > 0 else -1.0, 0.0])
        parts.append((*_strips(rows, lambda c, o=outward: np.broadcast_to(o, c.shape)), face))
    points, triangles, faces = _weld(parts)
    # The side vertices take their face from the profile (the caps' own rows came later).
    on_side = np.abs(np.abs(points[:, 1]) - a) > 1e-9
    offsets = points[:, None, [0, 2]] - profile[None, :, :]
    nearest = np.argmin(np.einsum("ijk,ijk->ij", offsets, offsets), axis=1)
    faces = np.where(on_side, labels[nearest], faces)
    mid = a - r + r / math.sqrt(2.0)
    inner = a - r  # where the flat top ends and each fillet begins
    edges = [
        _polyline(lambda t, s=s: np.column_stack([np.full(t.size, s * mid), t, np.full(t.size, mid)]), -a, a, size)
        for s in (1.0, -1.0)
    ]  # fmt: skip
    for y in (a, -a):

        def side(t, y=y):  # t runs over the top's outline in the plane y: arc, line, arc
            theta = np.clip(t, 0.0, math.pi / 2)
            arc_one = np.column_stack([inner + r * np.cos(theta), inner + r * np.sin(theta)])
            line = np.column_stack([inner - (t - math.pi / 2), np.full(t.size, a)])
            rest = np.clip(t - math.pi / 2 - 2 * inner, 0.0, math.pi / 2)
            arc_two = np.column_stack(
                [-inner - r * np.sin(rest), inner + r * np.cos(rest)]
            )  # fmt: skip
            xz = np.where((t < math.pi / 2)[:, None], arc_one, line)
            xz = np.where((t > math.pi / 2 + 2 * inner)[:, None], arc_two, xz)
            return np.column_stack([xz[:, 0], np.full(t.size, y), xz[:, 1]])

        total = math.pi + 2 * inner
        edges.append(_polyline(side, 0.0, total, math.pi * r + 2 * inner))
        for x in (a, -a):
            edges.append(
                _polyline(lambda t, x=x, y=y: np.column_stack([np.full(t.size, x), np.full(t.size, y), t]), -a, inner, a + inner)
            )  # fmt: skip
        edges.append(
            _polyline(lambda t, y=y: np.column_stack([t, np.full(t.size, y), np.full(t.size, -a)]), -a, a, size)
        )  # fmt: skip
    for x in (a, -a):
        edges.append(
            _polyline(lambda t, x=x: np.column_stack([np.full(t.size, x), t, np.full(t.size, -a)]), -a, a, size)
        )  # fmt: skip
    return Fragment(
        name="bevelled cube",
        points=points,
        triangles=triangles,
        edges=tuple(edges),
        faces=faces,
        fracture=frozenset(),
    )


FLAKE_EDGE_DEG = 45.0
"""The interior angle of the flake's margin, where its dorsal cap meets the ventral face."""


def _weld(parts):
    """One mesh from ``(points, triangles, face)`` parts: coincident vertices merged, triangles
    that collapse (two corners on one vertex) dropped."""
    points = np.vstack([p for p, _, _ in parts])
    offsets = np.cumsum([0] + [len(p) for p, _, _ in parts])
    triangles = np.vstack([t + o for (_, t, _), o in zip(parts, offsets, strict=False)])
    faces = np.concatenate([np.full(len(p), f) for p, _, f in parts])
    keys = np.round(points / 1e-9).astype(np.int64)
    _, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    order = np.argsort(first)  # keep the vertices in the order they were made
    rank = np.empty_like(order)
    rank[order] = np.arange(order.size)
    triangles = rank[inverse.ravel()][triangles]
    keep = (
        (triangles[:, 0] != triangles[:, 1])
        & (triangles[:, 1] != triangles[:, 2])
        & (triangles[:, 0] != triangles[:, 2])
    )
    return points[first[order]], triangles[keep].astype(np.int64), faces[first[order]]


def _strips(rows: list, outward) -> tuple[np.ndarray, np.ndarray]:
    """Points and triangles joining consecutive rows of points (``(k_i, 3)`` each, any
    lengths), each triangle wound so that its normal agrees with ``outward(centroid)``."""
    offsets = np.cumsum([0] + [len(r) for r in rows])
    triangles = []
    for k in range(len(rows) - 1):
        a, b = len(rows[k]), len(rows[k + 1])
        ta = np.linspace(0.0, 1.0, a)[1:] if a > 1 else np.zeros(0)
        tb = np.linspace(0.0, 1.0, b)[1:] if b > 1 else np.zeros(0)
        # Walk both rows at once: each step advances along one of them, making a triangle.
        steps = np.concatenate([np.zeros(ta.size, bool), np.ones(tb.size, bool)])
        steps = steps[np.argsort(np.concatenate([ta, tb]), kind="stable")]
        i = np.concatenate([[0], np.cumsum(~steps)])[:-1]
        j = np.concatenate([[0], np.cumsum(steps)])[:-1]
        top, bottom = offsets[k] + i, offsets[k + 1] + j
        third = np.where(steps, bottom + 1, top + 1)
        triangles.append(np.column_stack([top, bottom, third]))
    points = np.vstack(rows)
    triangles = np.vstack(triangles)
    corner = points[triangles]
    normal = np.cross(corner[:, 1] - corner[:, 0], corner[:, 2] - corner[:, 0])
    wrong = np.einsum("ij,ij->i", normal, outward(corner.mean(axis=1))) < 0
    triangles[wrong] = triangles[wrong][:, [0, 2, 1]]
    return points, triangles


def flake(
    radius: float = 20.0, platform: float = 14.0, spacing: float = 0.4, edge_deg=FLAKE_EDGE_DEG
) -> Fragment:
    """A flake-like solid: a spherical dorsal cap over the flat ventral face ``z = 0``, whose
    rim (the margin, a circle of ``radius``) has the interior angle ``edge_deg`` all round, cut
    by a striking platform, the plane ``x = platform``.

    Meshed row by row across x, rows and the vertices in each about ``spacing`` apart, with
    its vertices on the true edges, as a scanner's mesh of a sharp margin has.

    Faces: 0 dorsal (original surface), 1 ventral and 2 platform (fracture surfaces). True edges:
    the margin (dorsal/ventral arc), the platform's edge on the ventral face (a line) and on the
    dorsal cap (an arc).
    """
    sphere = radius / math.sin(math.radians(edge_deg))  # the cap's sphere radius
    depth = math.sqrt(sphere**2 - radius**2)  # its centre lies this far below z = 0
    centre = np.array([0.0, 0.0, -depth])
    x = np.linspace(-radius, platform, max(2, round((radius + platform) / spacing)) + 1)
    half_width = np.sqrt(np.maximum(radius**2 - x**2, 0.0))
    # Each row across the flake holds vertices about ``spacing`` apart (one at the tip).
    rows = [np.linspace(-1.0, 1.0, max(1, round(2 * w / spacing)) + 1) if w > 0 else np.zeros(1)
            for w in half_width]  # fmt: skip
    ventral = [np.column_stack([np.full(t.size, xi), t * w, np.zeros(t.size)])
               for xi, w, t in zip(x, half_width, rows, strict=True)]  # fmt: skip
    dorsal = []
    for row in ventral:
        lift = -depth + np.sqrt(np.maximum(sphere**2 - row[:, 0] ** 2 - row[:, 1] ** 2, 0.0))
        dorsal.append(np.column_stack([row[:, :2], np.maximum(lift, 0.0)]))
    levels = max(1, math.ceil(dorsal[-1][:, 2].max() / spacing))
    fraction = np.linspace(0.0, 1.0, levels + 1)
    face = [np.column_stack([dorsal[-1][:, :2], f * dorsal[-1][:, 2]]) for f in fraction]
    parts = [
        (*_strips(dorsal, lambda c: c - centre), 0),
        (*_strips(ventral, lambda c: np.broadcast_to([0.0, 0.0, -1.0], c.shape)), 1),
        (*_strips(face, lambda c: np.broadcast_to([1.0, 0.0, 0.0], c.shape)), 2),
    ]
    points, triangles, faces = _weld(parts)
    stop = math.acos(platform / radius)
    margin = _circle((0.0, 0.0, 0.0), radius, turns=(stop, 2 * math.pi - stop))
    half = radius * math.sin(stop)
    line = _polyline(
        lambda t: np.column_stack([np.full(t.size, platform), t, np.zeros(t.size)]),
        -half,
        half,
        2 * half,
    )
    # The platform cuts the sphere in a circle of radius rho about (platform, 0, -depth).
    rho = math.sqrt(sphere**2 - platform**2)
    reach = math.asin(half / rho)
    arc = _polyline(
        lambda t: np.column_stack(
            [np.full(t.size, platform), rho * np.sin(t), -depth + rho * np.cos(t)]
        ),
        -reach,
        reach,
        2 * reach * rho,
    )
    return Fragment(
        name="flake",
        points=points,
        triangles=triangles,
        edges=(margin, line, arc),
        faces=faces.astype(np.int64),
        fracture=frozenset({1, 2}),
    )


def with_noise(fragment: Fragment, sigma: float, seed: int = 0) -> Fragment:
    """``fragment`` with every vertex moved along its normal by Gaussian noise of SD ``sigma``
    (mm), like a scanner's; the true edges stay where they were."""
    normals, _ = vertex_normals(fragment.points, fragment.triangles)
    rng = np.random.default_rng(seed)
    moved = fragment.points + sigma * rng.standard_normal(len(fragment.points))[:, None] * normals
    return replace(fragment, points=moved, name=f"{fragment.name}, noise {sigma:g} mm")


def _marched(truth: Fragment, function, face_of, spacing: float) -> Fragment:
    """``truth``'s solid (``function``: negative inside) meshed afresh by marching tetrahedra,
    as a scanner's reconstruction meshes it: its edges run between vertices and the triangles
    across them cut the corner. The true edges and fracture faces stay ``truth``'s."""
    low, high = truth.points.min(axis=0), truth.points.max(axis=0)
    shift = np.array([0.3183, 0.2719, 0.1414]) * spacing  # no grid point on a face or an edge
    points, triangles = march(function, low - 2 * spacing + shift, high + 2 * spacing, spacing)
    return Fragment(
        name=f"{truth.name}, marched",
        points=points,
        triangles=triangles,
        edges=truth.edges,
        faces=face_of(points),
        fracture=truth.fracture,
    )


def marched_bevelled_cube(
    size: float = 20.0, fillet: float = 1.5, spacing: float = 0.4
) -> Fragment:
    """:func:`bevelled_cube` meshed by marching tetrahedra of step ``spacing``: no vertex on
    its edges (see :func:`_marched`)."""
    a, r = size / 2.0, fillet
    inner = a - r

    def terms(p):
        """Signed distances to the faces 0..7 (the fillets' only over their quarter)."""
        x, y, z = p[:, 0], p[:, 1], p[:, 2]
        corner = (np.abs(x) > inner) & (z > inner)
        round_ = np.hypot(np.abs(x) - inner, z - inner) - r
        fillets = [np.where(corner & (s * x > 0), round_, np.inf) for s in (1.0, -1.0)]
        return np.stack([x - a, -x - a, y - a, -y - a, z - a, -z - a, *fillets], axis=1)

    def function(p):
        flat = terms(p)[:, :6].max(axis=1)
        corner = (np.abs(p[:, 0]) > inner) & (p[:, 2] > inner)
        round_ = np.hypot(np.abs(p[:, 0]) - inner, p[:, 2] - inner) - r
        return np.where(corner, np.maximum(round_, np.abs(p[:, 1]) - a), flat)

    def face_of(p):
        return np.argmin(np.abs(terms(p)), axis=1).astype(np.int64)

    return _marched(bevelled_cube(size, fillet, spacing), function, face_of, spacing)


def marched_flake(
    radius: float = 20.0, platform: float = 14.0, spacing: float = 0.4, edge_deg=FLAKE_EDGE_DEG
) -> Fragment:
    """:func:`flake` meshed by marching tetrahedra of step ``spacing``: no vertex on its edges
    (see :func:`_marched`)."""
    sphere = radius / math.sin(math.radians(edge_deg))
    centre = np.array([0.0, 0.0, -math.sqrt(sphere**2 - radius**2)])

    def terms(p):
        """Signed distances to the dorsal cap, the ventral face and the platform (faces 0..2)."""
        offset = p - centre
        cap = np.sqrt(np.sum(offset * offset, axis=1)) - sphere
        return np.stack([cap, -p[:, 2], p[:, 0] - platform], axis=1)

    def face_of(p):
        return np.argmin(np.abs(terms(p)), axis=1).astype(np.int64)

    truth = flake(radius, platform, spacing, edge_deg)
    return _marched(truth, lambda p: terms(p).max(axis=1), face_of, spacing)
