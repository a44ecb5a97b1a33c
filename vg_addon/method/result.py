"""The result of one Virtual Goniometer measurement."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, eq=False)
class Measurement:
    """Everything one measurement produced, and everything needed to redo it.

    Attributes
    ----------
    angle : float
        Interior angle of the break edge in degrees, ``180 - arccos(v+ . v-)``.
    fit_error : float
        ``fit_error_plus + fit_error_minus``: the summed mean squared distances of each side's
        vertices to its fitted plane (squared length units).
    fit_error_plus, fit_error_minus : float
        The per-side mean squared plane-fit distances.
    normal_plus, normal_minus : ndarray, shape (3,)
        Unit normals of the two fitted planes, each oriented to agree with the mean vertex normal of
        its own side.
    tangent, mean_normal, binormal : ndarray, shape (3,)
        The break tangent ``t``, the mean normal ``n`` and the binormal ``b = t x n / |t x n|``.
    threshold : float
        The WithinSS split value ``s`` of the projection ``p``.
    labels : ndarray of bool, shape (k,)
        ``True`` for a vertex on the "+" side (``p >= s``), aligned with ``indices``.
    indices : ndarray of int64, shape (k,) or None
        Indices of the patch vertices into the surface's points (``None`` when the patch was given
        directly to :func:`goniometer`; then ``labels`` follows the order of the given points).
    n_vertices, n_plus, n_minus : int
        Vertex counts: the whole patch and each side.
    center : ndarray, shape (3,)
        The centre ``x̄`` used in the projection (the snapped vertex for surface measurements).
    requested_center : ndarray, shape (3,) or None
        The centre that was asked for, before snapping.
    snap_distance : float
        Distance from the requested centre to ``center``.
    center_index : int
        Index of the snapped vertex in the surface's points, or -1.
    radius : float
        The patch radius ``r`` (also the ``r`` of the projection).
    lam : float
        The segmentation parameter λ (the MeshLab plugin's ``SegParam``).
    patch : str
        How the patch was chosen: ``"euclidean"``, ``"geodesic"`` or ``"given"``.
    """

    angle: float
    fit_error: float
    fit_error_plus: float
    fit_error_minus: float
    normal_plus: np.ndarray
    normal_minus: np.ndarray
    tangent: np.ndarray
    mean_normal: np.ndarray
    binormal: np.ndarray
    threshold: float
    labels: np.ndarray
    indices: np.ndarray | None
    n_vertices: int
    n_plus: int
    n_minus: int
    center: np.ndarray
    requested_center: np.ndarray | None
    snap_distance: float
    center_index: int
    radius: float
    lam: float
    patch: str

    def summary(self) -> str:
        """One line for reports: angle, fit error, radius, λ and vertex counts."""
        return (
            f"{self.angle:.2f}° (fit {self.fit_error:.3g}, r={self.radius:g}, λ={self.lam:g}, "
            f"{self.n_vertices} vertices: {self.n_plus}+/{self.n_minus}-)"
        )
