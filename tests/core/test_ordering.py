"""canonical_ranks: sorting a patch by its ranks is the six-key lexsort of the patch."""

import numpy as np
import pytest

from vg_addon import Surface
from vg_addon.method.ordering import canonical_ranks
from vg_addon.synthetic_meshes import wedge


@pytest.mark.parametrize("seed", range(20))
def test_ranks_order_subsets_like_lexsort(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 500))
    # Few distinct values, so runs of equal x, equal points and exact duplicates all occur.
    points = rng.integers(0, 4, size=(n, 3)).astype(float)
    normals = rng.integers(0, 3, size=(n, 3)).astype(float)
    if seed % 2:
        points[:, 1:] = rng.normal(size=(n, 2))
    ranks = canonical_ranks(points, normals)
    assert np.array_equal(np.sort(ranks), np.arange(n))
    # Subsets listed in vertex order (as the grid lists equal points): exact ties by index.
    subset = np.sort(rng.choice(n, size=int(rng.integers(1, n + 1)), replace=False))
    p, q = points[subset], normals[subset]
    expected = np.lexsort((q[:, 2], q[:, 1], q[:, 0], p[:, 2], p[:, 1], p[:, 0]))
    assert np.array_equal(subset[np.argsort(ranks[subset], kind="stable")], subset[expected])


def test_surface_patch_is_in_lexicographic_order():
    mesh = wedge(60.0, n=40, irregular=True, seed=2)
    surface = Surface(mesh.points, mesh.triangles)
    m = surface.measure([0.1, 0.0, 0.0], 0.3)
    p, q = surface.points[m.indices], surface.normals[m.indices]
    assert np.array_equal(
        np.lexsort((q[:, 2], q[:, 1], q[:, 0], p[:, 2], p[:, 1], p[:, 0])), np.arange(m.n_vertices)
    )


def test_ranks_break_exact_ties_by_index_on_large_inputs():
    """Large enough for the unstable (SIMD) sort by x to shuffle equal x: the ranks do not
    depend on it."""
    rng = np.random.default_rng(7)
    points = rng.integers(0, 3, size=(20_000, 3)).astype(float)
    normals = rng.integers(0, 2, size=(20_000, 3)).astype(float)
    ranks = canonical_ranks(points, normals)
    expected = np.lexsort(
        (np.arange(20_000), *normals[:, ::-1].T, points[:, 2], points[:, 1], points[:, 0])
    )
    assert np.array_equal(np.argsort(ranks), expected)
