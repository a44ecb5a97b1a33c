"""Synthetic shapes: wedges of known angle and the watertight bone fragment with break sites."""

import math

import numpy as np
import pytest

from vg_addon import GoniometerError
from vg_addon.synthetic_meshes import (
    REGION_INNER,
    REGION_OBLIQUE,
    REGION_OUTER,
    REGION_RIM,
    REGION_TRANSVERSE,
    bone_fragment,
    wedge,
)


def face_normals(points, triangles):
    """Unit normals by the right-hand rule, and the triangle areas."""
    a, b, c = (points[triangles[:, k]] for k in range(3))
    cross = np.cross(b - a, c - a)
    length = np.linalg.norm(cross, axis=1)
    return cross / length[:, None], length / 2


def directed_edges(triangles):
    return np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])


def angle_between(u, v):
    return math.degrees(math.atan2(np.linalg.norm(np.cross(u, v)), np.dot(u, v)))


# ------------------------------------------------------------------------------------------ wedge


@pytest.mark.parametrize("irregular", [False, True])
@pytest.mark.parametrize("angle", [5, 17.5, 60, 90, 135, 175])
def test_wedge_faces_meet_at_the_stated_angle(angle, irregular):
    mesh = wedge(angle, n=30, irregular=irregular, seed=int(angle))
    assert mesh.angle == angle
    points, triangles = mesh.points, mesh.triangles
    assert points.dtype == np.float64 and triangles.dtype == np.int64
    normals, areas = face_normals(points, triangles)
    assert areas.min() > 0

    # Each triangle lies on one side; its vertices are on that side or on the crease.
    sides = mesh.side[triangles]
    assert not ((sides == 1).any(axis=1) & (sides == -1).any(axis=1)).any()
    plus = (sides == 1).any(axis=1)
    assert plus.sum() > 0 and (~plus).sum() > 0

    # All normals of a side agree (planar, consistently wound) and point up, out of the solid.
    n_plus, n_minus = normals[plus].mean(axis=0), normals[~plus].mean(axis=0)
    assert np.abs(normals[plus] - n_plus).max() < 1e-9
    assert np.abs(normals[~plus] - n_minus).max() < 1e-9
    assert (normals[:, 2] > 0).all()
    # Interior angle = 180 - angle between outward normals.
    assert 180 - angle_between(n_plus, n_minus) == pytest.approx(angle, abs=1e-9)
    # The stored normals are those faces' normals; the solid's bisector is -z.
    assert np.allclose(mesh.normal_plus, n_plus, atol=1e-9)
    assert np.allclose(mesh.normal_minus, n_minus, atol=1e-9)
    assert np.allclose(n_plus + n_minus, [0, 0, 2 * math.sin(math.radians(angle) / 2)])


@pytest.mark.parametrize("irregular", [False, True])
def test_wedge_sides_and_crease(irregular):
    mesh = wedge(70, half_width=1.5, depth=0.8, n=25, irregular=irregular, seed=2)
    x, y, z = mesh.points.T
    on_crease = mesh.side == 0
    assert np.array_equal(on_crease, (y == 0) & (z == 0))
    assert (y[mesh.side == 1] > 0).all() and (y[mesh.side == -1] < 0).all()
    assert x.min() == -1.5 and x.max() == 1.5
    assert np.all(z <= 0)
    # Distance from the crease, measured in each plane, reaches the depth exactly.
    assert np.hypot(y, z)[mesh.side == 1].max() == pytest.approx(0.8, abs=1e-12)
    # The crease is a line of vertices shared by both sides: each crease segment has two
    # triangles, one per side.
    crease = np.flatnonzero(on_crease)
    assert crease.size >= 2 * 25 * 0.5
    edges = directed_edges(mesh.triangles)
    both_on_crease = on_crease[edges].all(axis=1)
    assert both_on_crease.sum() == 2 * (crease.size - 1)


@pytest.mark.parametrize("angle", [5, 45, 120, 175])
def test_irregular_wedges_are_exactly_planar_and_irregular(angle):
    regular = wedge(angle, n=20)
    mesh = wedge(angle, n=20, irregular=True, seed=9)
    assert mesh.points.shape == regular.points.shape
    half = math.radians(angle) / 2
    for sign in (1, -1):
        normal = np.array([0.0, sign * math.cos(half), math.sin(half)])
        on_side = mesh.points[mesh.side == sign]
        assert np.abs(on_side @ normal).max() < 1e-14  # planes through the crease
    moved = np.linalg.norm(mesh.points - regular.points, axis=1)
    assert (moved > 1e-6).mean() > 0.5  # most vertices are off the grid
    assert not np.array_equal(mesh.triangles, regular.triangles)  # diagonals differ
    # Orientation survives the jitter: no triangle flips.
    normals, _ = face_normals(mesh.points, mesh.triangles)
    assert (normals[:, 2] > 0).all()


def test_wedge_is_an_oriented_manifold_patch():
    mesh = wedge(80, n=15, irregular=True, seed=4)
    edges = directed_edges(mesh.triangles)
    assert np.unique(edges, axis=0).shape[0] == edges.shape[0]  # each directed edge once
    undirected, count = np.unique(np.sort(edges, axis=1), axis=0, return_counts=True)
    assert set(count.tolist()) == {1, 2}
    # Interior edges (count 2) are traversed both ways: consistent orientation.
    directed = {tuple(e) for e in edges.tolist()}
    for a, b in undirected[count == 2]:
        assert (a, b) in directed and (b, a) in directed
    assert np.unique(mesh.triangles).size == mesh.points.shape[0]  # no stray vertices


def test_wedge_resolution_and_determinism():
    mesh = wedge(90, n=40)
    assert 0.9 * 2 * 40**2 < mesh.points.shape[0] < 1.2 * 2 * 40**2
    a = wedge(90, n=30, irregular=True, seed=5)
    b = wedge(90, n=30, irregular=True, seed=5)
    c = wedge(90, n=30, irregular=True, seed=6)
    assert np.array_equal(a.points, b.points) and np.array_equal(a.triangles, b.triangles)
    assert not np.array_equal(a.points, c.points)


@pytest.mark.parametrize("imbalance", [0.3, 2.0])
def test_wedge_imbalance_shrinks_one_side_only(imbalance):
    mesh = wedge(40, n=40, imbalance=imbalance)
    depth = np.hypot(mesh.points[:, 1], mesh.points[:, 2])
    assert depth[mesh.side == 1].max() == pytest.approx(1.0)
    assert depth[mesh.side == -1].max() == pytest.approx(imbalance)
    ratio = (mesh.side == -1).sum() / (mesh.side == 1).sum()
    assert ratio == pytest.approx(imbalance, rel=0.1)
    ball = np.linalg.norm(mesh.points, axis=1) <= 0.6
    plus, minus = (ball & (mesh.side == 1)).sum(), (ball & (mesh.side == -1)).sum()
    assert (minus < plus) if imbalance < 1 else (minus == pytest.approx(plus, rel=0.05))


@pytest.mark.parametrize(
    ("args", "kwargs", "message"),
    [
        ((0,), {}, "between 0 and 180"),
        ((180,), {}, "between 0 and 180"),
        ((float("nan"),), {}, "between 0 and 180"),
        (("wide",), {}, "must be a number"),
        ((90,), {"n": 1}, "n must be an integer"),
        ((90,), {"n": 10.5}, "n must be an integer"),
        ((90,), {"depth": -1}, "depth"),
        ((90,), {"half_width": float("inf")}, "half_width"),
        ((90,), {"imbalance": 0}, "imbalance"),
    ],
)
def test_wedge_rejects_bad_arguments(args, kwargs, message):
    with pytest.raises(GoniometerError, match=message):
        wedge(*args, **kwargs)


# ---------------------------------------------------------------------------------- bone fragment

SMALL = {"spacing": 1.5}


@pytest.fixture(scope="module")
def fragment():
    return bone_fragment(**SMALL)


def check_watertight(points, triangles):
    edges = directed_edges(triangles)
    # Each directed edge exactly once: consistent orientation, no edge used twice the same way.
    assert np.unique(edges, axis=0).shape[0] == edges.shape[0]
    # Each undirected edge in exactly two triangles: closed, no boundary, no fins.
    _, count = np.unique(np.sort(edges, axis=1), axis=0, return_counts=True)
    assert (count == 2).all()
    # Every reversed directed edge exists too.
    forward = edges[:, 0] * points.shape[0] + edges[:, 1]
    backward = edges[:, 1] * points.shape[0] + edges[:, 0]
    assert np.array_equal(np.sort(forward), np.sort(backward))
    _, areas = face_normals(points, triangles)
    assert areas.min() > 0
    # A hollow tube is a torus: V - E + F = 0.
    assert points.shape[0] - count.size + triangles.shape[0] == 0


def signed_volume(points, triangles):
    a, b, c = (points[triangles[:, k]] for k in range(3))
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6)


def test_bone_fragment_is_watertight_and_outward(fragment):
    check_watertight(fragment.points, fragment.triangles)
    volume = signed_volume(fragment.points, fragment.triangles)
    assert volume > 0
    assert volume == pytest.approx(math.pi * (12**2 - 7**2) * 60, rel=0.01)
    # The mesh is a polygonal prism: exactly the inscribed polygonal annulus times the length.
    around = np.unique(np.round(np.arctan2(fragment.points[:, 1], fragment.points[:, 0]), 9)).size
    polygon = around / 2 * (12**2 - 7**2) * math.sin(2 * math.pi / around)
    assert volume == pytest.approx(polygon * 60, rel=1e-9)
    assert around % 8 == 0


def test_bone_fragment_regions_are_where_they_should_be(fragment):
    x, y, z = fragment.points.T
    rho = np.hypot(x, y)
    region = fragment.region
    tan = math.tan(math.radians(35))
    assert np.allclose(rho[region == REGION_OUTER], 12)
    assert np.allclose(rho[region == REGION_INNER], 7)
    assert np.allclose(z[region == REGION_TRANSVERSE], 0)
    assert np.allclose(z[region == REGION_OBLIQUE], 60 + tan * x[region == REGION_OBLIQUE])
    rim = region == REGION_RIM
    on_end = np.isclose(z, 0) | np.isclose(z, 60 + tan * x)
    on_cylinder = np.isclose(rho, 12) | np.isclose(rho, 7)
    assert np.array_equal(rim, on_end & on_cylinder)
    # Outward normals of each region's triangles point the way the geometry says.
    normals, _ = face_normals(fragment.points, fragment.triangles)
    tri_region = region[fragment.triangles].max(axis=1)  # RIM is -1, so a region wins
    radial = np.column_stack([x, y, np.zeros_like(x)])[fragment.triangles].mean(axis=1)
    outward = np.einsum("ij,ij->i", normals, radial)
    assert (outward[tri_region == REGION_OUTER] > 0).all()
    assert (outward[tri_region == REGION_INNER] < 0).all()
    assert (normals[tri_region == REGION_TRANSVERSE, 2] < -0.999).all()
    oblique = np.array([-math.sin(math.radians(35)), 0, math.cos(math.radians(35))])
    assert np.allclose(normals[tri_region == REGION_OBLIQUE], oblique)


def plane_normal(points):
    """Unit normal of the plane best fitting ``points`` (by SVD)."""
    centred = points - points.mean(axis=0)
    return np.linalg.svd(centred, full_matrices=False)[2][2]


def expected_site_angle(fragment, site, outer, inner):
    """The interior angle at a rim point, derived here from the mesh: which cylinder the point
    is on (its distance to the axis), the cylinder's outward normal (radial, reversed on the
    inner one), and the fracture plane's normal fitted to that face's vertices."""
    point = np.array(site.point)
    rho = math.hypot(point[0], point[1])
    radial = np.array([point[0] / rho, point[1] / rho, 0.0])
    if math.isclose(rho, outer):
        cylinder = radial
    else:
        assert math.isclose(rho, inner)
        cylinder = -radial
    transverse = fragment.points[fragment.region == REGION_TRANSVERSE]
    oblique = fragment.points[fragment.region == REGION_OBLIQUE]
    if abs(point[2]) < 1e-9:
        face = plane_normal(transverse)
        face *= -np.sign(face[2])  # the transverse end faces -z
    else:
        face = plane_normal(oblique)
        face *= np.sign(face[2])  # the oblique end faces +z
    return 180 - angle_between(cylinder, face)


@pytest.mark.parametrize(
    "params",
    [
        SMALL,
        {"spacing": 1.0, "outer_radius": 10, "inner_radius": 4, "oblique_deg": 20, "length": 30},
    ],
)
def test_break_sites_lie_on_rims_with_their_true_angles(params):
    fragment = bone_fragment(**params)
    outer = params.get("outer_radius", 12.0)
    inner = params.get("inner_radius", 7.0)
    tilt = params.get("oblique_deg", 35.0)
    assert 6 <= len(fragment.sites) <= 10
    assert len({s.label for s in fragment.sites}) == len(fragment.sites)
    for site in fragment.sites:
        point = np.array(site.point)
        distance = np.linalg.norm(fragment.points - point, axis=1)
        assert distance.min() < 1e-9
        assert distance[site.vertex] < 1e-9
        assert fragment.region[site.vertex] == REGION_RIM
        assert site.angle == pytest.approx(
            expected_site_angle(fragment, site, outer, inner), abs=1e-9
        )
    angles = sorted(s.angle for s in fragment.sites)
    assert angles[0] == pytest.approx(90 - tilt, abs=1e-9)
    assert angles[-1] == pytest.approx(90 + tilt, abs=1e-9)
    labels = " ".join(s.label for s in fragment.sites)
    for needed in ("transverse/outer", "transverse/inner", "oblique/outer", "oblique/inner"):
        assert needed in labels


def test_bone_fragment_default_size_and_determinism():
    big = bone_fragment()
    assert 100_000 < big.points.shape[0] < 1_000_000
    assert big.triangles.shape[0] == 2 * big.points.shape[0]
    again = bone_fragment()
    assert np.array_equal(big.points, again.points)
    assert [s.angle for s in big.sites] == [s.angle for s in again.sites]


def test_roughness_is_deterministic_small_and_keeps_the_mesh_closed(fragment):
    rough = bone_fragment(roughness=0.1, seed=3, **SMALL)
    assert np.array_equal(rough.points, bone_fragment(roughness=0.1, seed=3, **SMALL).points)
    assert not np.array_equal(rough.points, bone_fragment(roughness=0.1, seed=4, **SMALL).points)
    check_watertight(rough.points, rough.triangles)
    assert np.array_equal(rough.triangles, fragment.triangles)
    rim = fragment.region == REGION_RIM
    assert np.array_equal(rough.points[rim], fragment.points[rim])
    shift = np.linalg.norm(rough.points - fragment.points, axis=1)[~rim]
    assert 0.03 < np.sqrt(np.mean(shift**2)) < 0.3
    assert [s.angle for s in rough.sites] == [s.angle for s in fragment.sites]
    assert signed_volume(rough.points, rough.triangles) > 0


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"inner_radius": 12}, "smaller than outer_radius"),
        ({"outer_radius": -1}, "outer_radius"),
        ({"length": 5}, "oblique cut reaches"),
        ({"oblique_deg": 90}, r"\[0, 90\)"),
        ({"spacing": 0.001}, "larger spacing"),
        ({"roughness": -0.1}, "roughness"),
    ],
)
def test_bone_fragment_rejects_bad_arguments(kwargs, message):
    with pytest.raises(GoniometerError, match=message):
        bone_fragment(**kwargs)


@pytest.mark.parametrize("concave", [False, True])
@pytest.mark.parametrize(("angle", "fillet"), [(30, 0.05), (90, 0.02), (150, 0.1), (60, 0.0)])
def test_bevelled_wedge_geometry(angle, fillet, concave):
    """Planar parts on the exact planes with the exact outward normals; the fillet an arc of the
    given radius, tangent to both faces."""
    from vg_addon import Surface
    from vg_addon.synthetic_meshes import bevelled_wedge

    mesh = bevelled_wedge(angle, fillet, concave=concave)
    surface = Surface(mesh.points, mesh.triangles)
    for side, normal in ((1, mesh.normal_plus), (-1, mesh.normal_minus)):
        on_face = mesh.side == side
        offset = mesh.points[on_face] @ normal
        assert np.ptp(offset) < 1e-12  # one plane
        interior = on_face & (np.abs(mesh.points[:, 0]) < 0.9)
        assert (surface.normals[interior] @ normal).min() > 1 - 1e-9
    half = np.radians(angle) / 2
    # The faces' planes pass through the sharp crease (the x axis) when extended.
    assert np.abs(mesh.points[mesh.side == 1] @ mesh.normal_plus).max() < 1e-12
    if fillet:
        arc = mesh.points[mesh.side == 0]
        centre_z = (1 if concave else -1) * fillet / np.sin(half)
        radius = np.hypot(arc[:, 1], arc[:, 2] - centre_z)
        assert np.abs(radius - fillet).max() < 1e-12
    else:
        assert np.abs(mesh.points[mesh.side == 0][:, 1:]).max() == 0
