"""Coordinates stored as float32 (as Blender keeps a mesh), or as float64 trillions of units from
the origin: where their rounding is too coarse for a patch, a measurement is refused rather than
read off the rounding."""

from __future__ import annotations

import numpy as np

from ..errors import GoniometerError

PRECISIONS = ("float32", "float64")
MAX_ROUNDING = 0.1
"""Largest float32 rounding step of a patch's coordinates, as a share of the spacing of its
vertices, that is measured at any vertex count (see docs/METHOD.md, "Coordinates far from the
origin")."""
MAX_MOVE = 0.05
"""Largest move of a reading, in degrees, that the rounding is let make."""
ROUNDING_SENSITIVITY = 1000.0
"""The largest move of a reading, in degrees, times the patch's vertex count, per unit of the
rounding step's share of the vertex spacing: 130 to 400 in the table of
``scripts/float32_rounding_table.py`` (wedges of 22 to 2,015 patch vertices, eight moves a cell),
up to about 880 over 300 moves of one patch, so a patch of ``n`` vertices moves by up to about
``ROUNDING_SENSITIVITY * share / n`` degrees."""


def rounding_limit(n_vertices: int) -> float:
    """The largest rounding step, as a share of the vertex spacing, that a patch of
    ``n_vertices`` is measured at: the share at which the rounding can move the reading by
    :data:`MAX_MOVE`, and never more than :data:`MAX_ROUNDING`."""
    return min(MAX_ROUNDING, MAX_MOVE * n_vertices / ROUNDING_SENSITIVITY)


def precision_of(points, precision=None) -> str:
    """The precision the coordinates ``points`` were stored at: ``precision`` if given (one of
    :data:`PRECISIONS`), else ``"float32"`` for a float32 NumPy array and ``"float64"`` for
    anything else. Narrower floats (float16) are refused: their rounding is not float32's, and
    with three significant digits they cannot hold a scan."""
    if precision is not None:
        if precision not in PRECISIONS:
            raise GoniometerError(
                f"Unknown precision {precision!r}: use one of {', '.join(PRECISIONS)}."
            )
        return precision
    dtype = getattr(points, "dtype", None)
    if dtype is not None and dtype.kind == "f" and dtype.itemsize < 4:
        raise GoniometerError(
            f"The coordinates are stored as {dtype.name}, which keeps about three significant "
            "digits: too coarse to measure on. Give them as float32 or float64 (convert them "
            "where they were made, not here: the rounding has already happened)."
        )
    if dtype is not None and dtype.kind == "f" and dtype.itemsize == 4:
        return "float32"
    return "float64"


def check_rounding(patch_points: np.ndarray, radius: float, precision: str) -> None:
    """Refuse a patch whose coordinates are rounded by more than :func:`rounding_limit` of the
    spacing of its vertices.

    Far from the mesh's origin, float32 keeps coordinates only to a coarse step (0.25 units at
    4 million units, 6e-5 at a thousand): each vertex is moved by up to half a step, which tilts
    the normals the sides are split by and the planes fitted to them. The angle moves by about
    the step's share of the spacing over the vertex count (times up to about 900 degrees, measured;
    by degrees once the step nears the spacing), so a small patch takes a finer step than a
    large one (see docs/METHOD.md). float64 rounds the same way some 5e8 times finer: its step
    reaches a scan's vertex spacing only trillions of units out (0.002 at 1e13).

    Parameters
    ----------
    patch_points : ndarray, shape (n, 3)
        The patch's vertices, in the coordinates they are stored in.
    radius : float
        The patch radius; with ``n`` it gives the spacing, ``radius * sqrt(pi / n)``.
    precision : {"float32", "float64"}
        How the coordinates were stored: the step is that type's.

    Raises
    ------
    GoniometerError
        The rounding step is too coarse, with the numbers and what to do.
    """
    largest = float(np.abs(patch_points).max())
    step = float(np.spacing(np.dtype(precision).type(largest)))
    n_vertices = patch_points.shape[0]
    spacing = radius * float(np.sqrt(np.pi / n_vertices))
    limit = rounding_limit(n_vertices)
    if step <= limit * spacing:
        return
    larger = ""
    if limit < MAX_ROUNDING:
        larger = ", or use a larger radius (a patch of more vertices takes a coarser step)"
    distance = f"{largest:,.0f}" if largest >= 10.0 else f"{largest:.3g}"
    rounding = (
        f"rounds them to steps of {step:.2g}: {step / spacing:.2g} of the spacing of the "
        f"vertices here ({spacing:.2g}), more than the {limit:.2g} at which it can move the "
        f"angle of a patch of {n_vertices} vertices by {MAX_MOVE:g}°."
    )
    if precision == "float64":
        raise GoniometerError(
            f"This mesh's coordinates reach {distance} units from its origin, where even float64 "
            f"{rounding} Subtract an offset from the coordinates (move the scan near the origin) "
            f"and measure again{larger}."
        )
    raise GoniometerError(
        f"This mesh's coordinates are stored as float32 (as Blender keeps every mesh), which at "
        f"coordinates up to {distance} units {rounding} The rounding happened when the mesh was "
        "stored: move the scan near the origin before it is imported (subtract an offset from "
        "its coordinates), or keep its coordinates as float64 (vg_batch measures a float64 mesh "
        f"file at the file's own coordinates){larger}."
    )
