"""The machine-independent arithmetic of ``vg_addon/method/fixed_order.py`` against independent
oracles: exact rational arithmetic (``fractions``) and LAPACK's eigen-solver and linear solver."""

from fractions import Fraction

import numpy as np
import pytest

from vg_addon.method.fixed_order import (
    acos_degrees,
    acos_degrees_array,
    column_moments,
    columns_dot,
    eigh3,
    eigh3_batched,
    exact_weighted_sums,
    gram,
    moments,
    offset_columns,
    row_dot,
    solve,
    solve3,
    split_exactly,
)


def _symmetric_cases(rng):
    """Random, nearly degenerate, diagonal, zero, rank-one, tiny- and huge-scale matrices."""
    cases = []
    for _ in range(300):
        a = rng.normal(size=(3, 3))
        cases.append(a + a.T)
    for gap in (1e-3, 1e-8, 1e-12, 0.0):
        q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        cases.append(q @ np.diag([1.0, 1.0 + gap, 3.0]) @ q.T)
    x = rng.normal(size=(50, 3))
    cases += [x.T @ x, x.T @ x * 1e-140, x.T @ x * 1e140, np.outer(x[0], x[0])]
    cases += [np.diag([3.0, 1.0, 2.0]), np.zeros((3, 3)), np.eye(3)]
    cases += [np.array([[1.0, 1e-200, 0.0], [1e-200, 2.0, 0.0], [0.0, 0.0, 3.0]])]
    cases += [np.array([[1.0, 1.0, 0.0], [1.0, 1.0, 0.0], [0.0, 0.0, 3.0]])]
    return cases


def test_eigh3_agrees_with_lapack_and_is_an_eigen_decomposition():
    rng = np.random.default_rng(4)
    for matrix in _symmetric_cases(rng):
        values, vectors = eigh3(matrix)
        scale = max(float(np.abs(matrix).max()), 1e-300)
        expected = np.linalg.eigvalsh(matrix)
        assert np.all(np.diff(values) >= 0)
        assert np.abs(values - expected).max() <= 1e-14 * scale
        assert np.abs(matrix @ vectors - vectors * values).max() <= 1e-14 * scale
        assert np.abs(vectors.T @ vectors - np.eye(3)).max() <= 1e-14


def test_the_batched_solver_gives_the_scalar_solvers_bits():
    rng = np.random.default_rng(5)
    cases = np.array(_symmetric_cases(rng))
    values, vectors = eigh3_batched(cases)
    for k, matrix in enumerate(cases):
        one_values, one_vectors = eigh3(matrix)
        assert values[k].tobytes() == one_values.tobytes()
        assert vectors[k].tobytes() == one_vectors.tobytes()


def test_moments_are_the_exact_sums_rounded_or_within_pairwise_error():
    rng = np.random.default_rng(6)
    rows = rng.normal(size=(1000, 3)) * np.array([1.0, 1e-3, 1e3])
    got = moments(rows)
    exact = [
        [
            sum(Fraction(a) * Fraction(b) for a, b in zip(rows[:, i], rows[:, j], strict=True))
            for j in range(3)
        ]
        for i in range(3)
    ]
    bound = np.abs(rows).T @ np.abs(rows) * 1e-15  # pairwise summation of 1,000 terms
    assert np.all(np.abs(got - np.array(exact, dtype=float)) <= bound)
    assert np.array_equal(got, got.T)


def test_exact_weighted_sums_do_not_depend_on_the_order_of_the_vertices():
    rng = np.random.default_rng(7)
    features = rng.normal(size=(3000, 5)) * np.array([1.0, 1e-6, 1e6, 1e-300, 0.0])
    weights = rng.integers(0, 4, size=(40, 3000)).astype(np.float64)
    split = split_exactly(features, int(weights.sum(axis=1).max()))
    sums = exact_weighted_sums(weights, split)
    order = rng.permutation(3000)
    shuffled = split_exactly(features[order], int(weights.sum(axis=1).max()))
    assert sums.tobytes() == exact_weighted_sums(weights[:, order], shuffled).tobytes()
    # The same numbers as exact rational arithmetic, to the rounding of the final value and the
    # bits the split leaves out (below 2^-(2·bits) of each column's largest value).
    for row in (0, 17, 39):
        for column in range(5):
            exact = sum(
                Fraction(int(w)) * Fraction(f)
                for w, f in zip(weights[row], features[:, column], strict=True)
            )
            largest = float(np.abs(features[:, column]).max())
            tolerance = 2e-16 * abs(float(exact)) + 3000 * 4 * largest * 2.0 ** (-2 * split.bits)
            assert abs(sums[row, column] - float(exact)) <= tolerance


def test_solve3_agrees_with_lapack_and_refuses_singular_matrices():
    rng = np.random.default_rng(8)
    for _ in range(200):
        matrix = rng.normal(size=(3, 3))
        rhs = rng.normal(size=(7, 3))
        expected = np.linalg.solve(matrix, rhs.T).T
        assert np.allclose(solve3(matrix, rhs), expected, rtol=1e-9, atol=1e-9)
    assert solve3(np.diag([1.0, 0.0, 1.0]), rng.normal(size=(2, 3))) is None
    assert solve3(np.full((3, 3), np.nan), rng.normal(size=(2, 3))) is None


@pytest.mark.parametrize("cosine", [-1.5, -1.0, -0.5, 0.0, 1e-17, 0.5, 0.999999999, 1.0, 2.0])
def test_acos_degrees_clips_and_matches_the_scalar_and_array_forms(cosine):
    expected = float(np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0))))
    assert acos_degrees(cosine) == pytest.approx(expected, abs=1e-12)
    assert acos_degrees_array(np.array([cosine]))[0] == acos_degrees(cosine)


# Sizes around NumPy's pairwise-summation blocks (8 and 128 values) and its buffer (8,192).
SUM_SIZES = (1, 2, 7, 8, 9, 127, 128, 129, 1000, 2001, 8191, 8192, 8193, 70001)


@pytest.mark.parametrize("size", SUM_SIZES)
def test_batched_sums_are_each_row_summed_alone(size):
    """``gram`` and ``column_moments`` sum all their rows of products in one call; each entry must
    be the bits of that row's own one-dimensional sum (what they summed before, one call each), or
    every stored number built on them would move."""
    rng = np.random.default_rng(size)
    columns = rng.normal(size=(3, size)) * np.array([[1.0], [1e-4], [1e5]])
    values = rng.normal(size=size)
    matrix, rhs = gram(columns, values)
    for i in range(3):
        assert rhs[i] == np.add.reduce(columns[i] * values)
        for j in range(3):
            assert matrix[i, j] == np.add.reduce(columns[i] * columns[j])
    entries = column_moments(columns)
    pairs = ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))
    assert entries == [float(np.add.reduce(columns[i] * columns[j])) for i, j in pairs]
    assert np.array_equal(
        moments(np.ascontiguousarray(columns.T)).ravel()[[0, 1, 2, 4, 5, 8]], entries
    )


def test_columns_dot_gives_row_dots_bits():
    rng = np.random.default_rng(8)
    rows = rng.normal(size=(3001, 3)) * 1e3
    origin, vector = rng.normal(size=3), rng.normal(size=3)
    columns = offset_columns(rows, origin)
    for k in range(3):
        assert columns[k].tobytes() == (rows - origin)[:, k].tobytes()
    assert columns_dot(columns, vector).tobytes() == row_dot(rows - origin, vector).tobytes()


def test_solve_agrees_with_lapack_and_pivots():
    """Gaussian elimination with partial pivoting on Python floats agrees with LAPACK's solver;
    a singular matrix gives None; a system that needs a row swap is solved exactly."""
    rng = np.random.default_rng(9)
    for _ in range(200):
        matrix = rng.normal(size=(6, 6))
        rhs = rng.normal(size=6)
        got = solve(matrix, rhs)
        exact = np.linalg.solve(matrix, rhs)  # LAPACK, an independent solver
        assert np.allclose(got, exact, rtol=1e-9, atol=1e-12)
    assert solve(np.ones((3, 3)), np.ones(3)) is None
    assert solve([[0.0, 2.0], [1.0, 0.0]], [4.0, 3.0]) == [3.0, 2.0]  # a row swap, exact
