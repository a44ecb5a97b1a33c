"""Creases meshed by an independent mesher, as a scan's reconstruction meshes them.

A folded plane is sampled at jittered grid points turned by a random angle and shifted off the
crease, and triangulated by SciPy's Delaunay (Qhull) in its unfolded plane: the crease falls
between vertices anywhere, and the triangles across it cut its corner. None of the project's
mesh makers is used, and no table these tests check was tuned on such meshes. The oracle is the
fold's exact angle. Issue 19's goal: within 0.1° (175°: 0.5°) at the paper's radius and λ, and a
stability figure that never vouches for a reading it does not cover.
"""

import numpy as np
import pytest

from vg_addon import GoniometerError, Surface

Delaunay = pytest.importorskip("scipy.spatial").Delaunay

ANGLES = [5, 20, 45, 90, 120, 150, 165, 170, 175]
GRIDS = [0.0067, 0.011, 0.02]  # 30, 18 and 10 spacings per radius
RADIUS = 0.2


def tolerance(angle: float) -> float:
    return 0.5 if angle >= 175 else 0.1


def rotation(seed: int) -> np.ndarray:
    q, r = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def folded(angle: float, spacing: float, seed: int, half: float = 0.45):
    """A fold of interior ``angle`` along the y axis through the origin, convex seen from +z.

    Returns points and outward-wound triangles (normals towards +z)."""
    rng = np.random.default_rng(seed)
    count = int(2 * half / spacing) + 6
    ticks = (np.arange(count) - count / 2) * spacing
    u, v = np.meshgrid(ticks, ticks)
    flat = np.column_stack([u.ravel(), v.ravel()])
    flat += rng.uniform(-0.3, 0.3, flat.shape) * spacing
    turn = rng.uniform(0.0, np.pi)
    flat = flat @ np.array([[np.cos(turn), np.sin(turn)], [-np.sin(turn), np.cos(turn)]])
    flat += rng.uniform(-spacing, spacing, 2)
    flat = flat[(np.abs(flat) <= half).all(axis=1)]
    triangles = Delaunay(flat).simplices.astype(np.int64)
    slope = np.radians(90.0 - angle / 2.0)
    across, along = flat[:, 0], flat[:, 1]
    points = np.column_stack([across * np.cos(slope), along, -np.abs(across) * np.sin(slope)])
    first = points[triangles[:, 1]] - points[triangles[:, 0]]
    second = points[triangles[:, 2]] - points[triangles[:, 0]]
    down = np.cross(first, second)[:, 2] < 0
    triangles[down] = triangles[down][:, ::-1]
    return points, triangles


def measured(angle, spacing, seed, concave=False, noise=0.0):
    """The default rule's reading at the vertex nearest the fold's middle, turned and moved in
    space (``concave``: wound inward, so the same surface bounds the solid on its other side);
    ``noise``: vertices moved along their normal, SD in spacings."""
    points, triangles = folded(angle, spacing, seed)
    if concave:
        triangles = triangles[:, ::-1].copy()
    if noise:
        normals = Surface(points, triangles).normals
        offsets = np.random.default_rng(seed + 1).normal(0.0, noise * spacing, len(points))
        points = points + normals * offsets[:, None]
    turn, shift = rotation(seed), np.array([2.0, -3.0, 1.0])
    surface = Surface(points @ turn.T + shift, triangles)
    middle = points[np.argmin(np.einsum("ij,ij->i", points, points))]
    return surface.measure(turn @ middle + shift, RADIUS, stability=True)


@pytest.mark.parametrize("concave", [False, True], ids=["ridge", "valley"])
@pytest.mark.parametrize("spacing", GRIDS)
@pytest.mark.parametrize("angle", ANGLES)
def test_a_crease_between_vertices_reads_its_angle(angle, spacing, concave):
    m = measured(angle, spacing, seed=int(angle * 10 + spacing * 1e4), concave=concave)
    assert abs(m.angle - angle) <= tolerance(angle), (m.angle, m.stability.text())
    assert m.convexity == ("concave" if concave else "convex")


@pytest.mark.parametrize("spacing", GRIDS)
@pytest.mark.parametrize("angle", ANGLES)
def test_a_crease_with_slight_noise_reads_its_angle(angle, spacing):
    """Vertices moved off their faces by 1% of the spacing (a good scanner's noise)."""
    m = measured(angle, spacing, seed=int(angle * 7 + spacing * 1e4), noise=0.01)
    assert abs(m.angle - angle) <= tolerance(angle), (m.angle, m.stability.text())


@pytest.mark.parametrize("spacing", GRIDS)
@pytest.mark.parametrize("angle", ANGLES)
def test_the_stability_figure_covers_what_noise_costs(angle, spacing):
    """At 5% noise a reading may miss the goal (the faces' own fit is that uncertain on a
    coarse grid), but then the figure shown beside it covers the error or flags the reading."""
    try:
        m = measured(angle, spacing, seed=int(angle * 3 + spacing * 1e4), noise=0.05)
    except GoniometerError:
        return  # a refusal says why: not a wrong number
    error = abs(m.angle - angle)
    covered = error <= max(tolerance(angle), m.stability.spread)
    assert covered or m.stability.warning, (m.angle, m.stability.text())
    assert not (m.stability.text() == "± 0.00°" and error > 0.1)


def noisy_fold(angle, spacing, seed, noise):
    points, triangles = folded(angle, spacing, seed)
    normals = Surface(points, triangles).normals
    offsets = np.random.default_rng(seed + 1).normal(0.0, noise * spacing, len(points))
    return Surface(points + normals * offsets[:, None], triangles)


@pytest.mark.parametrize("spacings", [2.0, 2.5, 3.0, 4.0])
@pytest.mark.parametrize("angle", [30, 90, 135, 165])
def test_a_small_patch_carries_its_stability_figure_unasked(angle, spacings):
    """A patch of a few rows of vertices can read degrees off with no sign in its fit error; it
    gets its stability figure without being asked, and the figure covers the error or flags it."""
    spacing, missed = 0.02, []
    surface = noisy_fold(angle, spacing, seed=angle + int(spacings * 10), noise=0.02)
    for along in np.linspace(-0.2, 0.2, 5):
        try:
            m = surface.measure([0.0, along, 0.0], spacings * spacing)
        except GoniometerError:
            continue
        assert m.indices.size < 100 and m.stability is not None
        error = abs(m.angle - angle)
        if not (error <= max(tolerance(angle), m.stability.spread) or m.stability.warning):
            missed.append((along, m.angle, m.stability.text()))
    assert not missed


def test_a_large_patch_gets_its_figure_only_when_asked():
    surface = noisy_fold(90, 0.02, seed=7, noise=0.02)
    m = surface.measure([0.0, 0.0, 0.0], RADIUS)
    assert m.indices.size >= 100 and m.stability is None
    assert surface.measure([0.0, 0.0, 0.0], RADIUS, stability=True).stability is not None
