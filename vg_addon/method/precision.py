"""Coordinates stored as float32 (as Blender keeps a mesh): where their rounding is too coarse
for a patch, a measurement is refused rather than read off the rounding."""

from __future__ import annotations

import numpy as np

from ..errors import GoniometerError

PRECISIONS = ("float32", "float64")
MAX_ROUNDING = 0.1
"""Largest float32 rounding step of a patch's coordinates, as a share of the spacing of its
vertices, that is measured (see docs/METHOD.md, "Coordinates far from the origin")."""


def precision_of(points, precision=None) -> str:
    """The precision the coordinates ``points`` were stored at: ``precision`` if given (one of
    :data:`PRECISIONS`), else ``"float32"`` for a float32 (or narrower) NumPy array and
    ``"float64"`` for anything else."""
    if precision is not None:
        if precision not in PRECISIONS:
            raise GoniometerError(
                f"Unknown precision {precision!r}: use one of {', '.join(PRECISIONS)}."
            )
        return precision
    dtype = getattr(points, "dtype", None)
    if dtype is not None and dtype.kind == "f" and dtype.itemsize <= 4:
        return "float32"
    return "float64"


def check_rounding(patch_points: np.ndarray, radius: float, precision: str) -> None:
    """Refuse a patch whose float32 coordinates are rounded to more than :data:`MAX_ROUNDING`
    of the spacing of its vertices.

    Far from the mesh's origin, float32 keeps coordinates only to a coarse step (0.25 units at
    4 million units, 6e-5 at a thousand): each vertex is moved by up to half a step, which tilts
    the normals the sides are split by and the planes fitted to them. Measured on wedges of
    about 600 patch vertices, the angle moves by up to 0.08° at a step of a tenth of the
    spacing, and by degrees past it; a patch of about 100 vertices moves by up to 0.4° below
    the limit (see docs/METHOD.md).

    Parameters
    ----------
    patch_points : ndarray, shape (n, 3)
        The patch's vertices, in the coordinates they are stored in.
    radius : float
        The patch radius; with ``n`` it gives the spacing, ``radius * sqrt(pi / n)``.
    precision : {"float32", "float64"}
        How the coordinates were stored; float64 coordinates are never refused here.

    Raises
    ------
    GoniometerError
        The rounding step is too coarse, with the numbers and what to do.
    """
    if precision != "float32":
        return
    largest = float(np.abs(patch_points).max())
    step = float(np.spacing(np.float32(largest)))
    spacing = radius * float(np.sqrt(np.pi / patch_points.shape[0]))
    if step <= MAX_ROUNDING * spacing:
        return
    distance = f"{largest:,.0f}" if largest >= 10.0 else f"{largest:.3g}"
    raise GoniometerError(
        f"This mesh's coordinates are stored as float32 (as Blender keeps every mesh), which at "
        f"coordinates up to {distance} units rounds them to steps of {step:.2g}: "
        f"{step / spacing:.2g} of the spacing of the vertices here ({spacing:.2g}), more than "
        f"the {MAX_ROUNDING:g} at which the angle can move by several hundredths of a degree. "
        "The rounding happened when the mesh was stored: move the scan near the origin before "
        "it is imported (subtract an offset from its coordinates), or measure a float64 scan "
        "file with vg_batch, which measures at the file's own coordinates."
    )
