"""The result of one Virtual Goniometer measurement."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

ROUNDING_FIT = 1e-12
"""A fit error below this many times the squared radius is rounding, not a measured distance:
the plane fits' eigenvalues are exact to about 1e-16 r², and sums of a few thousand terms lose a
few more bits."""


def fit_text(fit_error: float, radius: float) -> str:
    """The fit error for people: its value to three digits, or ``< bound`` at rounding level.

    The digits of a rounding-level fit error depend on the order of operations, so printing them
    would say nothing and differ between builds; the bound is ``ROUNDING_FIT · r²`` rounded up to
    one digit.
    """
    bound = ROUNDING_FIT * radius * radius
    if fit_error >= bound:
        return f"{fit_error:.3g}"
    exponent = math.floor(math.log10(bound))
    return f"< {math.ceil(bound / 10.0**exponent - 1e-9):d}e{exponent:+03d}"


UNSTABLE_DEGREES = 5.0
"""A stability figure above this many degrees flags the reading as unstable: the angle depends on
where the measurement was taken more than the differences a user looks for between edges."""

UNDETERMINED_REFUSED = 0.1
"""More than this share of the stability figure's perturbed runs refused flags the figure as
undetermined: the refused runs add nothing to it, so it may be far too small."""


def stability_text(
    spread: float,
    runs: int = 0,
    refused: int = 0,
    crease_refused: int = 0,
    noise_hides_crease: bool | None = False,
) -> str:
    """The stability figure as shown: ``"± 0.4°"`` (two decimals below 0.1°), or ``"± ?"`` when
    it is undetermined (see :func:`stability_undetermined`): a spread of the few runs that were
    not refused says nothing, and printed as a number it would vouch for the reading."""
    if stability_undetermined(runs, refused, crease_refused, noise_hides_crease):
        return "± ?"
    return f"± {spread:.2f}°" if spread < 0.1 else f"± {spread:.1f}°"


def stability_undetermined(
    runs: int, refused: int, crease_refused: int = 0, noise_hides_crease: bool | None = False
) -> bool:
    """Whether more than :data:`UNDETERMINED_REFUSED` of a figure's ``runs`` were ``refused``, a
    band left out along the crease left a face without a plane (``crease_refused`` > 0), or the
    vertex normals' noise is larger than the turn between the faces (``noise_hides_crease``):
    the figure is then undetermined (it may be far too small)."""
    return (
        (runs > 0 and refused > UNDETERMINED_REFUSED * runs)
        or crease_refused > 0
        or bool(noise_hides_crease)
    )


_UNKNOWN_OFF = "how far the reading is off is not known and the ± figure may be far too small."

_REASONS = {
    "bands": (
        "Undetermined: without the vertices next to the crease a face keeps too few vertices "
        "off it to fit its plane (on a thin wedge the mesh's cells hold both faces across the "
        f"patch), so {_UNKNOWN_OFF}"
    ),
    "noise": (
        "Undetermined: the vertex normals' noise is larger than the turn between the faces, so "
        f"the two sides can be mixed across the patch: {_UNKNOWN_OFF}"
    ),
    # A record made before the two were kept apart counted both in ``crease_refused``.
    "either": (
        "Undetermined: without the vertices next to the crease a face keeps too few vertices "
        "off it to fit its plane (on a thin wedge the mesh's cells hold both faces across the "
        "patch), or the vertex normals' noise is larger than the turn between the faces (the "
        f"sides can be mixed), so {_UNKNOWN_OFF}"
    ),
}


def stability_warning(
    spread: float,
    runs: int = 0,
    refused: int = 0,
    crease_refused: int = 0,
    noise_hides_crease: bool | None = False,
) -> str:
    """Why a reading with this stability figure should not be trusted as it stands, or ``""``.

    The one rule every place that shows a reading uses (the list, the Selected Measurement
    panel, the operator's report, the batch's summary): unstable when the figure (``spread``,
    degrees) is more than :data:`UNSTABLE_DEGREES`; undetermined when more than
    :data:`UNDETERMINED_REFUSED` of its ``runs`` perturbed measurements were ``refused``, when
    leaving out the vertices next to the crease left a face too few vertices to fit its plane
    (``crease_refused`` bands), or when the vertex normals' noise is larger than the turn
    between the faces (``noise_hides_crease``). Each reason that holds is given; ``None`` for
    ``noise_hides_crease`` is a record made before the last two were kept apart (its
    ``crease_refused`` may count either), whose reason names both.
    """
    reasons = []
    if spread > UNSTABLE_DEGREES:
        reasons.append(
            f"Unstable: the angle moves by up to {spread:.1f}° when the centre, radius or λ "
            "change slightly, the vertices are resampled or those next to the crease are left "
            f"out (more than {UNSTABLE_DEGREES:g}°)."
        )
    if runs > 0 and refused > UNDETERMINED_REFUSED * runs:
        reasons.append(
            f"Undetermined: {refused} of {runs} perturbed measurements were refused (more than "
            f"{UNDETERMINED_REFUSED:.0%}), so the ± figure may be far too small."
        )
    if noise_hides_crease is None:
        if crease_refused > 0:
            reasons.append(_REASONS["either"])
    else:
        if crease_refused > 0:
            reasons.append(_REASONS["bands"])
        if noise_hides_crease:
            reasons.append(_REASONS["noise"])
    if not reasons:
        return ""
    return " ".join(reasons) + " Measure again on the edge, or with a larger radius."


def _stored_counts(parts: dict) -> tuple:
    """``runs``, ``refused``, ``crease_refused`` (0 where absent: records made before the crease
    part) and ``noise_hides_crease`` (``None`` where absent: records made before it was kept
    apart from ``crease_refused``) of a stored stability record."""
    counts = tuple(int(parts.get(key) or 0) for key in ("runs", "refused", "crease_refused"))
    noise = parts.get("noise_hides_crease")
    return (*counts, None if noise is None else bool(noise))


def stored_stability_text(parts: dict | None) -> str:
    """:func:`stability_text` of a stored stability record (the JSON dict with ``spread``,
    ``runs``, ``refused``, ``crease_refused`` and ``noise_hides_crease``); ``"not computed"``
    for none."""
    if not parts:
        return "not computed"
    return stability_text(float(parts["spread"]), *_stored_counts(parts))


def stored_stability_warning(parts: dict | None) -> str:
    """:func:`stability_warning` of a stored stability record (the JSON dict with ``spread``,
    ``runs``, ``refused``, ``crease_refused`` and ``noise_hides_crease``, as a measurement
    record and the CSV keep it); ``""`` for none."""
    if not parts:
        return ""
    return stability_warning(float(parts.get("spread", 0.0)), *_stored_counts(parts))


def stored_stability_undetermined(parts: dict | None) -> bool:
    """:func:`stability_undetermined` of a stored stability record; ``False`` for none."""
    if not parts:
        return False
    return stability_undetermined(*_stored_counts(parts))


@dataclass(frozen=True)
class Stability:
    """How much a measurement's angle depends on where and how it was taken.

    Each part is the largest change of the angle, in degrees, under one kind of perturbation of
    the measurement (the changes that make two drag measurements of one edge differ, and the
    vertices next to the crease left out); ``spread``, the figure shown as "± 0.4°", is the
    largest of the first five parts plus :attr:`crease`.

    Attributes
    ----------
    spread : float
        The largest of the parts below but :attr:`crease`, plus :attr:`crease`.
    center : float
        The centre moved to each vertex within two mean edge lengths of it.
    radius : float
        The radius 10% smaller and 10% larger.
    lam : float
        λ at 1, 1.5, 2, 2.5 and 3.
    bootstrap : float
        Half the width of the central 95% interval of the angle over bootstrap resamples of the
        patch's vertices (Algorithm 1 redone on each: tangent, split and planes).
    orientation : float
        :attr:`Measurement.orientation_difference`: where convex or concave is unclear, how far
        the reading with the other sign of the position term was.
    n_runs : int
        Perturbed measurements tried: centre, radius, λ and the bootstrap resamples.
    n_failed : int
        Of those, how many were refused (too few vertices, no edge, ...); they add nothing to
        the parts, so a large count means the figure is optimistic.
    crease : float
        The largest change of the angle when the vertices within one or two mesh spacings, or a
        quarter or half of the radius, of the line where the planes meet are left out and the
        planes fitted again (:mod:`~vg_addon.method.crease_band`): the tilt the vertices next to
        the crease give both planes, which every perturbed run above shares. Added to the
        largest of the other parts, not compared with them: it is a bias, they are spreads.
    crease_refused : int
        Checks of the crease that could not be made: bands whose refit was refused (a side
        kept too few vertices, or a line). The figure is then undetermined.
    noise_hides_crease : bool
        The vertex normals' noise is larger than the turn between the faces, so a vertex's
        normal does not say which face it is on and the sides can be mixed across the patch.
        The figure is then undetermined.
    """

    spread: float
    center: float
    radius: float
    lam: float
    bootstrap: float
    orientation: float
    n_runs: int
    n_failed: int
    crease: float = 0.0
    crease_refused: int = 0
    noise_hides_crease: bool = False

    def _counts(self) -> tuple:
        return (self.n_runs, self.n_failed, self.crease_refused, self.noise_hides_crease)

    def text(self) -> str:
        """The figure as shown: ``"± 0.4°"`` (two decimals below 0.1°), ``"± ?"`` when undetermined."""
        return stability_text(self.spread, *self._counts())

    @property
    def warning(self) -> str:
        """Why the reading is flagged (unstable, or the figure undetermined), or ``""``: see
        :func:`stability_warning`."""
        return stability_warning(self.spread, *self._counts())


@dataclass(frozen=True, eq=False)
class Measurement:
    """Everything one measurement produced, and everything needed to redo it.

    Attributes
    ----------
    angle : float
        ``180 - arccos(v+ . v-)`` in degrees: the solid's interior angle on a convex edge; on a
        concave edge the angle of the open wedge (360° minus the solid's interior angle).
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
    rule : str
        ``"refined"`` (the default), ``"oriented"`` or ``"paper"``: how the measurement was taken
        (see ``vg_addon.method.algorithm.RULES``).
    orientation : int
        The sign ``s`` (+1 or -1) the position term was given; always +1 under the paper's rule.
    correlation : float
        The correlation between ``Nᵀb`` and ``(X - x̄)ᵀb`` over the patch, from -1 to 1: its
        sign is the edge's convexity, its size how clearly the patch shows it.
    convexity : str
        ``"convex"``, ``"concave"`` or ``"unclear"`` (``|correlation| < 0.2``, or the fitted planes
        disagree with its sign), relative to the normals as given: on an inward-wound mesh a
        convex edge reads ``"concave"``.
    orientation_difference : float
        Where the convexity is unclear, the oriented rule measures with both signs and keeps the
        better plane fit: how far the other reading was, in degrees (0 otherwise).
    n_shared : int
        Vertices used by both planes: a side that is one row of vertices (a coarse mesh across a
        near-flat edge) borrows the row beside it on the edge. Usually 0.
    stability : Stability or None
        How much the angle moves under small changes of centre, radius and λ, and under a
        bootstrap of the vertices (``None`` unless asked for).
    split_angle : float or None
        Under the refined rule, where the refinement applied: the angle of Algorithm 1's split
        before it (``None`` where Algorithm 1's planes were kept).
    n_left_out : int
        Under the refined rule: vertices next to the crease that lie on neither face and were
        left out of the plane fits (they keep their side in ``labels``). Usually 0.
    left_out : ndarray of bool, shape (k,) or None
        Which of them, aligned with ``labels`` (``None`` where none was left out).
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
    rule: str
    orientation: int
    correlation: float
    convexity: str
    orientation_difference: float
    n_shared: int
    stability: Stability | None = None
    split_angle: float | None = None
    n_left_out: int = 0
    left_out: np.ndarray | None = None

    def with_requested(self, requested) -> Measurement:
        """This measurement as asked for at ``requested`` (mesh coordinates): a replication
        measures at the stored centre and keeps where the original was asked for, its snap
        distance from that centre."""
        point = np.array(requested, dtype=np.float64)
        offset = (self.center - point)[None]  # as the snap measures it (spatial.GridIndex)
        return dataclasses.replace(
            self,
            requested_center=point,
            snap_distance=math.sqrt(float(np.einsum("ij,ij->i", offset, offset)[0])),
        )

    @property
    def angle_meaning(self) -> str:
        """What the angle is, for the place it is shown: interior, open wedge, or either."""
        if self.convexity == "convex":
            return "interior angle of the solid"
        if self.convexity == "concave":
            return "open wedge angle (360° minus the solid's interior angle)"
        return "angle between the fitted planes (convex or concave unclear)"

    def summary(self) -> str:
        """One line for reports: angle, fit error, radius, λ and vertex counts."""
        spread = "" if self.stability is None else f" {self.stability.text()}"
        return (
            f"{self.angle:.2f}°{spread} {self.convexity} (fit {fit_text(self.fit_error, self.radius)}, "
            f"r={self.radius:g}, λ={self.lam:g}, {self.n_vertices} vertices: "
            f"{self.n_plus}+/{self.n_minus}-)"
        )
