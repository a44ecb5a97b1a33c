"""Arithmetic whose rounding does not depend on the machine: no BLAS, no LAPACK, no SIMD dispatch.

NumPy hands matrix products (``@``, ``np.dot``) to BLAS and ``np.linalg.eigh`` to LAPACK, whose
kernels are picked at run time for the CPU (``OPENBLAS_CORETYPE``) and split work over threads:
each choice sums in another order, with or without fused multiply-adds, so the last bits of a
measurement depended on the machine. NumPy's transcendental ufuncs (``np.arccos``) also have
CPU-specific SIMD versions. Everything here is made of operations whose result IEEE 754 fixes:
element-wise ``+ − × ÷`` and ``sqrt``, NumPy's pairwise sums of contiguous data (plain C, the same
on every CPU), the C library's ``acos`` through :mod:`math`, and matrix products whose every
partial sum is an exact integer (:func:`exact_weighted_sums`), so their order cannot matter.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

_MAX_SWEEPS = 32
"""Cyclic Jacobi on a 3×3 matrix converges quadratically: 4 to 6 sweeps in practice."""


def row_dot(rows: np.ndarray, vector) -> np.ndarray:
    """``rows @ vector`` for an ``(n, 3)`` array, as ``x·v0 + y·v1 + z·v2`` in that order."""
    v0, v1, v2 = (float(value) for value in vector)
    return rows[:, 0] * v0 + rows[:, 1] * v1 + rows[:, 2] * v2


def rows_dot(first: np.ndarray, second: np.ndarray) -> np.ndarray:
    """Row-wise dot products of two ``(k, 3)`` arrays, summed in a fixed order."""
    return first[:, 0] * second[:, 0] + first[:, 1] * second[:, 1] + first[:, 2] * second[:, 2]


def offset_columns(rows: np.ndarray, origin) -> np.ndarray:
    """``(rows - origin).T`` for an ``(n, 3)`` array, as a contiguous ``(3, n)`` array: the same
    differences, laid out for :func:`columns_dot`'s and :func:`columns_dots`' contiguous
    products."""
    columns = np.empty((3, rows.shape[0]))
    np.subtract(rows.T, np.asarray(origin, dtype=np.float64)[:, None], out=columns)
    return columns


def columns_dot(columns, vector) -> np.ndarray:
    """:func:`row_dot` of the rows whose three columns are ``columns``: ``x·v0 + y·v1 + z·v2``
    in that order, so the same bits."""
    v0, v1, v2 = (float(value) for value in vector)
    x, y, z = columns
    return x * v0 + y * v1 + z * v2


def columns_dots(columns: np.ndarray, vectors) -> np.ndarray:
    """:func:`columns_dot` with each of ``m`` vectors at once, shape ``(m, n)``: every product in
    one call and the same sums, ``x·v0 + y·v1 + z·v2`` in that order, so the same bits."""
    products = np.asarray(vectors, dtype=np.float64)[:, :, None] * columns[None]
    dots = np.add(products[:, 0], products[:, 1])
    dots += products[:, 2]
    return dots


def in_frame(rows: np.ndarray, frame: np.ndarray) -> np.ndarray:
    """``rows @ frame.T``: each ``(n, 3)`` row's coordinates along the three rows of ``frame``."""
    return np.stack([row_dot(rows, axis) for axis in frame], axis=1)


def dot3(a, b) -> float:
    """The dot product of two 3-vectors, in a fixed order, as a Python float."""
    (a0, a1, a2), (b0, b1, b2) = (float(x) for x in a), (float(x) for x in b)
    return a0 * b0 + a1 * b1 + a2 * b2


def cross3(a, b) -> np.ndarray:
    """The cross product of two 3-vectors, on Python floats."""
    (a0, a1, a2), (b0, b1, b2) = (float(x) for x in a), (float(x) for x in b)
    return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


def norm3(a) -> float:
    """The length of a 3-vector."""
    return math.sqrt(dot3(a, a))


def total(values: np.ndarray) -> float:
    """Sum of a 1-D array by NumPy's pairwise summation (fixed order for a given length)."""
    return float(np.add.reduce(np.ascontiguousarray(values, dtype=np.float64)))


def moments(rows: np.ndarray) -> np.ndarray:
    """``rows.T @ rows`` for an ``(n, 3)`` array: the symmetric 3×3 matrix ``Σ r_i r_iᵀ``.

    Each of the six distinct entries is NumPy's pairwise sum of a contiguous row of products.
    """
    return _symmetric(column_moments(rows.T.copy()))


def column_moments(columns: np.ndarray) -> list[float]:
    """The six distinct entries of :func:`moments` (``xx, xy, xz, yy, yz, zz``) of the points
    whose coordinates are the three contiguous rows of ``columns``, shape ``(3, n)``: the same
    sums, for callers that hold their points column by column."""
    x, y, z = columns
    products = np.empty((6, columns.shape[1]))
    np.multiply(x, x, out=products[0])
    np.multiply(x, y, out=products[1])
    np.multiply(x, z, out=products[2])
    np.multiply(y, y, out=products[3])
    np.multiply(y, z, out=products[4])
    np.multiply(z, z, out=products[5])
    return np.add.reduce(products, axis=1).tolist()


def _symmetric(entries) -> np.ndarray:
    xx, xy, xz, yy, yz, zz = entries
    return np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])


_UPPER = ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))


def gram(columns: np.ndarray, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The normal equations of a least-squares fit, ``(A.T @ A, A.T @ values)``.

    ``columns`` has shape ``(m, k)``: ``m`` basis functions at ``k`` points, so ``A`` is its
    transpose. Every entry is NumPy's pairwise sum of one contiguous row of products (all rows
    summed by one call, which sums each row as it would alone).
    """
    m = columns.shape[0]
    pairs = [(i, j) for i in range(m) for j in range(i, m)]
    products = np.empty((len(pairs) + m, columns.shape[1]))
    for k, (i, j) in enumerate(pairs):
        np.multiply(columns[i], columns[j], out=products[k])
    for i in range(m):
        np.multiply(columns[i], values, out=products[len(pairs) + i])
    sums = np.add.reduce(products, axis=1).tolist()
    matrix = [[0.0] * m for _ in range(m)]
    for k, (i, j) in enumerate(pairs):
        matrix[i][j] = matrix[j][i] = sums[k]
    return np.array(matrix), np.array(sums[len(pairs) :])


def solve(matrix, rhs) -> list[float] | None:
    """Solve the small linear system ``matrix @ x = rhs`` by Gaussian elimination with partial
    pivoting on Python floats; None when singular (a pivot below 1e-13 of the largest entry)."""
    a = np.asarray(matrix, dtype=np.float64).tolist()
    b = [float(value) for value in rhs]
    n = len(b)
    largest = max(max(map(abs, row)) for row in a)
    if not math.isfinite(largest) or largest == 0.0:
        return None
    for column in range(n):
        pivot, size = column, abs(a[column][column])
        for row in range(column + 1, n):  # the first of the largest, as max() picks
            if abs(a[row][column]) > size:
                pivot, size = row, abs(a[row][column])
        if size <= 1e-13 * largest:
            return None
        a[column], a[pivot] = a[pivot], a[column]
        b[column], b[pivot] = b[pivot], b[column]
        top, head = a[column], a[column][column]
        for row in range(column + 1, n):
            current = a[row]
            factor = current[column] / head
            for k in range(column, n):
                current[k] -= factor * top[k]
            b[row] -= factor * b[column]
    x = [0.0] * n
    for row in range(n - 1, -1, -1):
        value = b[row]
        current = a[row]
        for k in range(row + 1, n):
            value -= current[k] * x[k]
        x[row] = value / current[row]
    return x


def solve3(matrix, rhs: np.ndarray) -> np.ndarray | None:
    """Solve ``matrix @ x_i = rhs_i`` for every row ``rhs_i`` of an ``(n, 3)`` array.

    Gaussian elimination with partial pivoting on Python floats (LAPACK's ``dgesv`` picks its
    kernel by CPU), applied to all right-hand sides in a fixed order. Returns None when the
    matrix is singular or not finite (a pivot of 0, or below 1e-300 of the largest entry).
    """
    a = [list(row) for row in np.asarray(matrix, dtype=np.float64).tolist()]
    largest = max(abs(value) for row in a for value in row)
    if not math.isfinite(largest) or largest == 0.0:
        return None
    b = [np.asarray(rhs, dtype=np.float64)[:, k].copy() for k in range(3)]
    for column in range(3):
        pivot = max(range(column, 3), key=lambda row: abs(a[row][column]))
        if abs(a[pivot][column]) <= 1e-300 * largest:
            return None
        a[column], a[pivot] = a[pivot], a[column]
        b[column], b[pivot] = b[pivot], b[column]
        for row in range(column + 1, 3):
            factor = a[row][column] / a[column][column]
            for k in range(column, 3):
                a[row][k] -= factor * a[column][k]
            b[row] = b[row] - factor * b[column]
    x = [None, None, None]
    for row in (2, 1, 0):
        value = b[row]
        for k in range(row + 1, 3):
            value = value - a[row][k] * x[k]
        x[row] = value / a[row][row]
    return np.stack(x, axis=1)


def acos_degrees(cosine: float) -> float:
    """``degrees(arccos(cosine))`` by the C library's ``acos``, the argument clipped to [−1, 1]."""
    return math.degrees(math.acos(min(1.0, max(-1.0, cosine))))


def acos_degrees_array(cosines: np.ndarray) -> np.ndarray:
    """:func:`acos_degrees` of each value (NumPy's ``arccos`` has CPU-specific SIMD versions)."""
    clipped = np.clip(cosines, -1.0, 1.0).tolist()
    return np.degrees(np.array([math.acos(c) for c in clipped], dtype=np.float64))


def eigh3(matrix) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues (ascending) and unit eigenvectors (columns) of a symmetric 3×3 matrix.

    Cyclic Jacobi rotations on Python floats: every operation is IEEE ``+ − × ÷`` or a correctly
    rounded ``sqrt``, so the result is the same on every machine. Jacobi's eigenvalues and vectors
    are as accurate as LAPACK's (to a few units in the last place of the matrix's norm).

    Parameters
    ----------
    matrix : array_like, shape (3, 3)
        Symmetric; only its upper triangle is read.

    Returns
    -------
    values : ndarray, shape (3,)
    vectors : ndarray, shape (3, 3)
        ``vectors[:, k]`` belongs to ``values[k]``.
    """
    (a0, a01, a02), (_, a1, a12), (_, _, a2) = np.asarray(matrix, dtype=np.float64).tolist()
    return eigh3_entries(a0, a01, a02, a1, a12, a2)


def eigh3_entries(a0, a01, a02, a1, a12, a2) -> tuple[np.ndarray, np.ndarray]:
    """:func:`eigh3` of the symmetric matrix with diagonal ``a0, a1, a2`` and off-diagonal
    entries ``a01, a02, a12`` (Python floats).

    Each rotation, written out in place (the same operations in the same order as a call per
    step, without the calls): ``theta = (a_qq − a_pp) / 2 a_pq``,
    ``t = sign(theta) / (|theta| + √(theta² + 1))``, ``c = 1 / √(t² + 1)``, ``s = t c`` (Numerical
    Recipes' form; where ``theta²`` overflows, ``t`` is 0: ``a_pq`` is then below 1e-150 of
    ``a_qq − a_pp`` and is dropped). After the first sweep an ``a_pq`` below the last bit of both
    diagonal entries is zeroed, not rotated.
    """
    copysign, sqrt = math.copysign, math.sqrt
    # Columns of the eigenvector matrix, rotated along with the matrix.
    x0, y0, z0, x1, y1, z1, x2, y2, z2 = 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0
    for sweep in range(_MAX_SWEEPS):
        if a01 == 0.0 and a02 == 0.0 and a12 == 0.0:
            break
        first = sweep == 0
        if a01 != 0.0:  # p, q, r = 0, 1, 2
            g = 100.0 * abs(a01)
            if not first and abs(a0) + g == abs(a0) and abs(a1) + g == abs(a1):
                a01 = 0.0
            else:
                theta = (a1 - a0) / (a01 + a01)
                t = copysign(1.0 / (abs(theta) + sqrt(theta * theta + 1.0)), theta)
                c = 1.0 / sqrt(t * t + 1.0)
                s = t * c
                shift = t * a01
                a0, a1, a01 = a0 - shift, a1 + shift, 0.0
                a02, a12 = c * a02 - s * a12, s * a02 + c * a12
                x0, y0, z0, x1, y1, z1 = (
                    c * x0 - s * x1, c * y0 - s * y1, c * z0 - s * z1,
                    s * x0 + c * x1, s * y0 + c * y1, s * z0 + c * z1,
                )  # fmt: skip
        if a02 != 0.0:  # p, q, r = 0, 2, 1
            g = 100.0 * abs(a02)
            if not first and abs(a0) + g == abs(a0) and abs(a2) + g == abs(a2):
                a02 = 0.0
            else:
                theta = (a2 - a0) / (a02 + a02)
                t = copysign(1.0 / (abs(theta) + sqrt(theta * theta + 1.0)), theta)
                c = 1.0 / sqrt(t * t + 1.0)
                s = t * c
                shift = t * a02
                a0, a2, a02 = a0 - shift, a2 + shift, 0.0
                a01, a12 = c * a01 - s * a12, s * a01 + c * a12
                x0, y0, z0, x2, y2, z2 = (
                    c * x0 - s * x2, c * y0 - s * y2, c * z0 - s * z2,
                    s * x0 + c * x2, s * y0 + c * y2, s * z0 + c * z2,
                )  # fmt: skip
        if a12 != 0.0:  # p, q, r = 1, 2, 0
            g = 100.0 * abs(a12)
            if not first and abs(a1) + g == abs(a1) and abs(a2) + g == abs(a2):
                a12 = 0.0
            else:
                theta = (a2 - a1) / (a12 + a12)
                t = copysign(1.0 / (abs(theta) + sqrt(theta * theta + 1.0)), theta)
                c = 1.0 / sqrt(t * t + 1.0)
                s = t * c
                shift = t * a12
                a1, a2, a12 = a1 - shift, a2 + shift, 0.0
                a01, a02 = c * a01 - s * a02, s * a01 + c * a02
                x1, y1, z1, x2, y2, z2 = (
                    c * x1 - s * x2, c * y1 - s * y2, c * z1 - s * z2,
                    s * x1 + c * x2, s * y1 + c * y2, s * z1 + c * z2,
                )  # fmt: skip
    diagonal = (a0, a1, a2)
    columns = ((x0, y0, z0), (x1, y1, z1), (x2, y2, z2))
    order = sorted(range(3), key=diagonal.__getitem__)
    values = np.array([diagonal[k] for k in order])
    vectors = np.array([columns[k] for k in order]).T
    return values, vectors


def eigh3_batched(matrices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`eigh3` of each of ``k`` symmetric 3×3 matrices, vectorised over ``k``.

    Parameters
    ----------
    matrices : ndarray, shape (k, 3, 3)

    Returns
    -------
    values : ndarray, shape (k, 3)
        Ascending.
    vectors : ndarray, shape (k, 3, 3)
        ``vectors[j, :, i]`` belongs to ``values[j, i]``.
    """
    m = np.asarray(matrices, dtype=np.float64)
    k = m.shape[0]
    a = [m[:, 0, 0].copy(), m[:, 1, 1].copy(), m[:, 2, 2].copy()]
    off = {(0, 1): m[:, 0, 1].copy(), (0, 2): m[:, 0, 2].copy(), (1, 2): m[:, 1, 2].copy()}
    v = np.zeros((k, 3, 3))  # v[:, p] is column p of the eigenvector matrix, for speed
    v[:, 0, 0] = v[:, 1, 1] = v[:, 2, 2] = 1.0
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        for sweep in range(_MAX_SWEEPS):
            if not (off[0, 1].any() or off[0, 2].any() or off[1, 2].any()):
                break
            for p, q, r in ((0, 1, 2), (0, 2, 1), (1, 2, 0)):
                apq = off[p, q]
                off[p, q] = np.zeros(k)
                if sweep:  # below the last bit of both diagonal entries: zeroed, not rotated
                    g = 100.0 * np.abs(apq)
                    abs_p, abs_q = np.abs(a[p]), np.abs(a[q])
                    apq = np.where((abs_p + g == abs_p) & (abs_q + g == abs_q), 0.0, apq)
                active = apq != 0.0
                if not active.any():
                    continue
                theta = (a[q] - a[p]) / (apq + apq)
                t = np.copysign(1.0 / (np.abs(theta) + np.sqrt(theta * theta + 1.0)), theta)
                t = np.where(active, t, 0.0)
                c = 1.0 / np.sqrt(t * t + 1.0)
                s = t * c
                shift = t * apq
                a[p] = a[p] - shift
                a[q] = a[q] + shift
                rp, rq = (min(r, p), max(r, p)), (min(r, q), max(r, q))
                arp, arq = off[rp], off[rq]
                off[rp] = c * arp - s * arq
                off[rq] = s * arp + c * arq
                vp, vq = v[:, p], v[:, q]
                c2, s2 = c[:, None], s[:, None]
                v[:, p], v[:, q] = c2 * vp - s2 * vq, s2 * vp + c2 * vq
    values = np.stack(a, axis=1)
    order = np.argsort(values, axis=1, kind="stable")
    rows = np.arange(k)[:, None]
    return values[rows, order], v[rows, order].transpose(0, 2, 1)


@dataclass(frozen=True)
class ExactSplit:
    """Features split for exact weighted sums (see :func:`split_exactly`).

    Attributes
    ----------
    parts : ndarray, shape (n, 2 f)
        Per vertex, the ``high`` whole numbers of the ``f`` features, then the ``low`` ones.
    scale : ndarray, shape (f,)
        ``2^-shift`` of each feature: ``feature ≈ (high + low · 2^-bits) · scale``.
    bits : int
    """

    parts: np.ndarray
    scale: np.ndarray
    bits: int

    def rows(self, index) -> ExactSplit:
        """The split of some vertices (the same scales, so still exact for as many terms)."""
        return ExactSplit(self.parts[index], self.scale, self.bits)

    def columns(self, index) -> ExactSplit:
        """The split of some features."""
        index = np.arange(self.scale.size)[index]
        return ExactSplit(
            self.parts[:, np.concatenate([index, index + self.scale.size])],
            self.scale[index],
            self.bits,
        )

    def part_columns(self, index) -> np.ndarray:
        """Where the high and low parts of some features are in :attr:`parts` (and in the
        sums of :func:`exact_integer_sums`)."""
        index = np.arange(self.scale.size)[index]
        return np.concatenate([index, index + self.scale.size])


def split_exactly(features: np.ndarray, max_terms: int) -> ExactSplit:
    """Split each column of ``features`` into two whole-number parts for exact weighted sums.

    ``features[:, c] ≈ (high[:, c] + low[:, c] · 2^-bits) · 2^-shift[c]``, where ``high`` and
    ``low`` hold whole numbers small enough that any sum of at most ``max_terms`` of them, each
    times a whole number, is exact in float64 (below 2^53). What is left out is below
    ``2^-(2·bits)`` of the column's largest value (``bits`` is 52 minus the bits of
    ``max_terms``: 32 for a million terms): far below anything a measurement can resolve. Every
    scaling is by a power of two, so exact.
    """
    bits = 52 - max(int(max_terms), 1).bit_length()
    largest = np.max(np.abs(features), axis=0, initial=0.0)
    _, exponent = np.frexp(largest)  # largest < 2^exponent
    shift = bits - exponent
    if shift.max(initial=0) < 1000:  # a product by 2^shift is exact and faster than ldexp
        scaled = features * np.ldexp(1.0, shift)
    else:  # columns of values near 1e-300, whose 2^shift is beyond float64
        scaled = np.ldexp(features, shift)
    f = features.shape[1]
    parts = np.empty((features.shape[0], 2 * f))
    high, low = parts[:, :f], parts[:, f:]
    np.rint(scaled, out=high)
    np.subtract(scaled, high, out=low)
    low *= 2.0**bits
    np.rint(low, out=low)
    return ExactSplit(parts, np.ldexp(1.0, -shift), bits)


def exact_integer_sums(weights: np.ndarray, split: ExactSplit) -> np.ndarray:
    """The whole-number parts of ``weights @ features``: exact, so bit-identical everywhere.

    Parameters
    ----------
    weights : ndarray, shape (k, n)
        Whole numbers (0/1 memberships or bootstrap counts) as float64; the sum of each row must be
        at most the ``max_terms`` the split was made for.
    split : ExactSplit
        :func:`split_exactly` of the ``(n, f)`` features.

    Returns
    -------
    ndarray, shape (k, 2 f)
        The sums of the high parts, then of the low parts. Every partial sum of this matrix
        product is a whole number below 2^53, so BLAS's order, blocking, fused multiply-adds and
        threads cannot change it. Being exact, sums can also be subtracted exactly (the sums over
        a set's complement). :func:`combine` turns them into the feature sums.
    """
    return weights @ split.parts


def combine(sums: np.ndarray, split: ExactSplit) -> np.ndarray:
    """The weighted sums of the features from their exact parts, rounded once."""
    f = split.scale.size
    return (sums[:, :f] + sums[:, f:] * 2.0**-split.bits) * split.scale


def exact_weighted_sums(weights: np.ndarray, split: ExactSplit) -> np.ndarray:
    """``weights @ features`` for whole-number weights, bit-identical on every machine (see
    :func:`exact_integer_sums`)."""
    return combine(exact_integer_sums(weights, split), split)
