"""Which way round to paint a measurement's two sides, so that one face of a break keeps one colour.

A measurement's "+" side is where Algorithm 1's projection ``p = bᵀN + (λ/r) bᵀ(X − x̄)`` is
large, and the binormal ``b = t × n`` takes its sign from the tangent ``t``, an eigenvector whose
sign is only a convention. Two measurements of one break can therefore call the same fracture
face "+" at one centre and "−" at the next; painting each "+" side in the break's first colour
then makes a patchwork. The measured numbers stay as they are: only the colours are swapped, for
a measurement whose "+" plane normal agrees better with the colour the break's earlier
measurements gave the other face.
"""

from __future__ import annotations

import math
from collections.abc import Iterable


def _dot(a, b) -> float:
    return float(a[0]) * float(b[0]) + float(a[1]) * float(b[1]) + float(a[2]) * float(b[2])


def paint_swapped(normal_plus, normal_minus, center, radius: float, earlier: Iterable) -> bool:
    """Whether to paint a new measurement's "+" side in its break's second colour.

    Parameters
    ----------
    normal_plus, normal_minus : array_like, shape (3,)
        The new measurement's plane normals, in the same coordinates as ``earlier``'s (a record's
        mesh coordinates).
    center : array_like, shape (3,)
        Its centre.
    radius : float
        Its radius: the length over which earlier measurements count fully (see Notes).
    earlier : iterable of (first, second, center)
        For each earlier measurement of the same break: the plane normal of its side painted in
        the pair's first colour, that of its side in the second colour, and its centre.

    Returns
    -------
    bool
        True when the sides agree better the other way round: the "+" plane normal with the
        earlier second-colour normals and the "−" with the first-colour ones. False with no
        earlier measurement, or a tie.

    Notes
    -----
    The score is ``Σ w (n₊ − n₋)·(f − s)`` over the earlier measurements, ``f`` and ``s`` their
    first- and second-colour normals, weighted by ``w = 1 / (1 + (d / r)²)`` for a centre ``d``
    away: the faces of a curved break turn along it, so the measurements beside the new one say
    more than those at the far end. The difference ``n₊ − n₋`` points across the edge, from the
    "−" face's normal to the "+" face's, and takes both faces into account.
    """
    across = [float(p) - float(m) for p, m in zip(normal_plus, normal_minus, strict=True)]
    scale = float(radius) if radius and math.isfinite(radius) and radius > 0 else 1.0
    score = 0.0
    for first, second, other_center in earlier:
        offset = [float(a) - float(b) for a, b in zip(other_center, center, strict=True)]
        weight = 1.0 / (1.0 + _dot(offset, offset) / (scale * scale))
        difference = [float(f) - float(s) for f, s in zip(first, second, strict=True)]
        score += weight * _dot(across, difference)
    return score < 0.0
