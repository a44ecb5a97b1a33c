"""Validation of what the method is given: points, normals, a centre, a radius and λ, each
refused with a reason (a :class:`~vg_addon.errors.GoniometerError`) rather than measured wrong."""

from __future__ import annotations

import math

import numpy as np

from ..errors import GoniometerError

MAX_LAMBDA = 1e6
"""Beyond this, λ only scales positions past floating-point range; the split no longer changes."""

MAX_MAGNITUDE = 1e150
"""Largest coordinate and radius, in any unit: squares of larger values, and sums of them over
many points, overflow float64 (from about 1e154). A scan in any real unit is far below this."""


def _check_finite(name: str, array: np.ndarray) -> None:
    bad = ~np.isfinite(array).all(axis=1)
    if bad.any():
        first = int(np.flatnonzero(bad)[0])
        raise GoniometerError(
            f"{int(bad.sum())} {name} are not finite (NaN or infinite), the first at row {first}: "
            f"repair or remove them before measuring."
        )


def as_points(name: str, values, *, allow_empty: bool = False) -> np.ndarray:
    """Validate an (n, 3) array of finite numbers and return it as C-contiguous float64."""
    try:
        array = _real_float64(values)
    except (TypeError, ValueError) as error:
        raise GoniometerError(f"The {name} must be numbers in an (n, 3) array: {error}") from None
    if array is None:
        raise GoniometerError(f"The {name} must be real numbers; got complex ones.")
    if array.ndim != 2 or array.shape[1] != 3:
        raise GoniometerError(
            f"The {name} must be an (n, 3) array of x, y, z values; got shape {array.shape}."
        )
    if not allow_empty and array.shape[0] == 0:
        raise GoniometerError(f"There are no {name}: the mesh or patch is empty.")
    _check_finite(name, array)
    check_magnitude(
        f"The {name} reach",
        array,
        "scale the mesh to a real unit (e.g. millimetres) before measuring",
    )
    return array


def _real_float64(values) -> np.ndarray | None:
    """``values`` as a C-contiguous float64 array; ``None`` for complex numbers, whose imaginary
    parts the conversion would drop with only a warning. Raises NumPy's ``TypeError`` or
    ``ValueError`` for what is not numbers (ragged lists, strings)."""
    given = np.asarray(values)
    if given.dtype.kind == "c":
        return None
    if given.dtype.kind in "bUS":  # NumPy would read True as 1 and "0.3" as 0.3 without a word
        raise TypeError(f"got {given.dtype.name} values, not numbers")
    try:
        return np.ascontiguousarray(given, dtype=np.float64)
    except OverflowError as error:  # a Python int past float64's range
        raise ValueError(str(error)) from None


def _real_number(value) -> float:
    """``value`` as a float; ``TypeError`` for a bool or text, which ``float`` would take. A
    Python int past float64's range is infinite, as a float that large would be."""
    if isinstance(value, (bool, str, bytes)) or np.asarray(value).dtype.kind in "bUS":
        raise TypeError("not a number")
    try:
        return float(value)
    except OverflowError:
        return math.inf if value > 0 else -math.inf


def check_magnitude(what: str, array: np.ndarray, advice: str) -> None:
    """Refuse values beyond ±:data:`MAX_MAGNITUDE` ("``what`` 1e+200, beyond ...: ``advice``.")."""
    largest = float(np.abs(array).max()) if array.size else 0.0
    if largest > MAX_MAGNITUDE:
        raise GoniometerError(
            f"{what} {largest:.3g}, beyond ±{MAX_MAGNITUDE:g}, where squared distances "
            f"overflow: {advice}."
        )


def as_radius(radius) -> float:
    """Validate a patch radius: a finite number greater than zero."""
    try:
        value = _real_number(radius)
    except (TypeError, ValueError):
        raise GoniometerError(f"The radius must be a number; got {radius!r}.") from None
    if not np.isfinite(value) or value <= 0:
        raise GoniometerError(f"The radius must be a finite number greater than 0; got {value!r}.")
    return value


def as_lambda(lam) -> float:
    """Validate the segmentation parameter λ: a number from 0 to :data:`MAX_LAMBDA`."""
    try:
        value = _real_number(lam)
    except (TypeError, ValueError):
        raise GoniometerError(f"λ (SegParam) must be a number; got {lam!r}.") from None
    if not np.isfinite(value) or not 0 <= value <= MAX_LAMBDA:
        raise GoniometerError(
            f"λ (SegParam) must be a number from 0 to {MAX_LAMBDA:g} (2 is the usual); got {value!r}."
        )
    return value


def as_center(center) -> np.ndarray:
    """Validate a centre: three finite numbers."""
    try:
        value = _real_float64(center)
    except (TypeError, ValueError):
        raise GoniometerError(
            f"The centre must be three numbers x, y, z; got {center!r}."
        ) from None
    if value is None:
        raise GoniometerError(f"The centre must be three real numbers x, y, z; got {center!r}.")
    value = value.reshape(-1)
    if value.shape != (3,) or not np.isfinite(value).all():
        raise GoniometerError(f"The centre must be three finite numbers x, y, z; got {center!r}.")
    return value


TINY_LENGTH = 1e-150
"""Below this length a normal's squared components can underflow; it is rescaled first."""


def unit_normals(name: str, normals: np.ndarray) -> np.ndarray:
    """Normalise given normals; zero-length ones are an error (they carry no direction)."""
    lengths = np.linalg.norm(normals, axis=1)
    short = np.flatnonzero(lengths < TINY_LENGTH)
    if short.size:
        # Their squares underflow (a length of 1e-170 came out as 0): scaled by their largest
        # component first, they keep their direction. Other rows keep their bits.
        normals = normals.copy()
        largest = np.abs(normals[short]).max(axis=1)
        nonzero = largest > 0
        normals[short[nonzero]] /= largest[nonzero, None]
        lengths[short] = np.linalg.norm(normals[short], axis=1)
    zero = lengths == 0
    if zero.any():
        raise GoniometerError(
            f"{int(zero.sum())} {name} have zero length (the first at row "
            f"{int(np.flatnonzero(zero)[0])}): recompute the normals or drop those vertices."
        )
    return normals / lengths[:, None]


def as_normals(normals, n_points: int) -> np.ndarray:
    """Validate given normals: one finite, non-zero 3-vector per point; returned normalised."""
    normals = as_points("normals", normals)
    if normals.shape[0] != n_points:
        raise GoniometerError(
            f"There must be one normal per point: {n_points} points, {normals.shape[0]} normals."
        )
    return unit_normals("normals", normals)


def as_flag(name: str, value) -> bool:
    """Validate a yes/no setting: ``True`` or ``False`` (NumPy's too), or 1 or 0. A string such
    as ``"False"`` is refused: Python would take it as true."""
    if isinstance(value, (bool, np.bool_)) or (
        isinstance(value, (int, np.integer)) and value in (0, 1)
    ):
        return bool(value)
    raise GoniometerError(f"{name} must be True or False; got {value!r}.")
