"""Measurement records: a core :class:`Measurement` into an ``Object.vg`` item, and an item into
a CSV row."""

from __future__ import annotations

import json
import tomllib
from functools import cache
from pathlib import Path

import bpy
import numpy as np

from ..properties import exact_numbers
from ..vg_addon import GoniometerError, palette
from ..vg_addon.formats import csvio
from .mesh_data import uniform_scale

_MANIFEST = Path(__file__).resolve().parents[1] / "blender_manifest.toml"

# The coordinates a record's centre, radius and normals are in (its "space"): the mesh's own
# since this extension measures in them; records made before that have no "space" and are in
# world space (see ``legacy``).
MESH = csvio.MESH_COORDINATES
WORLD = csvio.WORLD_COORDINATES


@cache
def extension_version() -> str:
    """The extension's version, from its ``blender_manifest.toml``."""
    try:
        with open(_MANIFEST, "rb") as handle:
            return str(tomllib.load(handle)["version"])
    except (OSError, KeyError, tomllib.TOMLDecodeError):
        return "unknown"


def _floats(vector) -> list[float]:
    return [float(v) for v in np.asarray(vector, dtype=np.float64)]


def _stability(stability) -> dict:
    return {
        "spread": float(stability.spread),
        "center": float(stability.center),
        "radius": float(stability.radius),
        "lam": float(stability.lam),
        "bootstrap": float(stability.bootstrap),
        "orientation": float(stability.orientation),
        "runs": int(stability.n_runs),
        "refused": int(stability.n_failed),
    }


def exact_record(m) -> dict:
    """The exact numbers stored for measurement ``m`` (taken in mesh coordinates)."""
    return {
        "angle": float(m.angle),
        "fit": float(m.fit_error),
        "fit_plus": float(m.fit_error_plus),
        "fit_minus": float(m.fit_error_minus),
        "radius": float(m.radius),
        "lam": float(m.lam),
        "snap_distance": float(m.snap_distance),
        "center": _floats(m.center),
        "requested": _floats(m.requested_center),
        "normal_plus": _floats(m.normal_plus),
        "normal_minus": _floats(m.normal_minus),
        "rule": m.rule,
        "convexity": m.convexity,
        "correlation": float(m.correlation),
        "stability": None if m.stability is None else _stability(m.stability),
        "space": MESH,
    }


def add_measurement(obj, m, geometry_fingerprint: str, *, note: str = "", break_number=None):
    """Append measurement ``m`` to ``obj.vg.measurements`` and make it the active one.

    Parameters
    ----------
    obj : bpy.types.Object
    m : vg_addon.Measurement
        A surface measurement, in the mesh's own coordinates.
    geometry_fingerprint : str
        Fingerprint of the geometry it was taken on (see ``mesh_data.fingerprint``).
    note : str
        Free text (the CSV's User Data).
    break_number : int, optional
        Default: the object's current break.

    Returns
    -------
    The new ``VG_Measurement`` item (valid until the collection changes again).
    """
    data = obj.vg
    item = data.measurements.add()
    item.number = data.next_number
    data.next_number += 1
    item.break_number = data.break_number if break_number is None else int(break_number)
    item.exact = json.dumps(exact_record(m))
    item.patch = m.patch
    item.n_vertices = int(m.n_vertices)
    item.n_plus = int(m.n_plus)
    item.n_minus = int(m.n_minus)
    item.date = csvio.now_iso()
    item.note = note
    item.colors = "/".join(palette.pair_names(item.break_number))
    item.fingerprint = geometry_fingerprint
    item.stale = False
    data.active_index = len(data.measurements) - 1
    return item


_KEYS = (
    "angle",
    "fit",
    "fit_plus",
    "fit_minus",
    "radius",
    "lam",
    "snap_distance",
    "center",
    "requested",
    "normal_plus",
    "normal_minus",
)


def numbers_of(item) -> dict:
    """The exact numbers of ``item`` (see ``properties.exact_numbers``), all of them or an error."""
    numbers = exact_numbers(item)
    missing = [key for key in _KEYS if key not in numbers]
    if missing:
        raise GoniometerError(
            f"Measurement {item.number} has lost its stored numbers ({', '.join(missing)}); "
            "delete it and measure again."
        )
    return numbers


def space_of(item) -> str:
    """The coordinates ``item`` was recorded in: ``"mesh"``, or ``"world"`` for a record made
    before measurements were taken in mesh coordinates."""
    return exact_numbers(item).get("space", WORLD)


def replay_args(item) -> dict:
    """The exact inputs that reproduce ``item``: ``center``, ``radius``, ``lam``, ``patch``,
    ``rule`` (``"paper"`` for records from before the rule existed: that is what they used)."""
    numbers = numbers_of(item)
    return {
        "center": np.array(numbers["center"], dtype=np.float64),
        "radius": float(numbers["radius"]),
        "lam": float(numbers["lam"]),
        "patch": item.patch,
        "rule": numbers.get("rule", "paper"),
    }


def units_label(scene, obj=None) -> str:
    """What one coordinate unit is: Blender units and their length in the scene's unit system,
    for a mesh shown at its own size; for an object scaled by ``s``, one mesh unit is ``s``
    Blender units in the scene, and the label says so."""
    units = scene.unit_settings
    scale = None
    if obj is not None:
        scale = uniform_scale(np.array(obj.matrix_world, dtype=np.float64))
        if scale is None:
            return "mesh units (the object's scale is not uniform)"
    if units.system == "NONE":
        base = "BU"
        metres = None
    else:
        base = f"BU (1 BU = {units.scale_length:g} m, shown in {units.length_unit.lower()})"
        metres = units.scale_length
    if scale is None or scale == 1.0:
        return base
    shown = f"{scale:g} BU" if metres is None else f"{scale * metres:g} m"
    return f"mesh units (1 unit = {shown} in the scene, object scale {scale:g})"


def to_row(obj, item, *, stale: bool, units: str) -> csvio.MeasurementRow:
    """The CSV row of ``item``, measured on ``obj``."""
    numbers = numbers_of(item)
    x, y, z = numbers["center"]
    stability = numbers.get("stability") or {}
    return csvio.MeasurementRow(
        mesh_name=obj.name,
        date=item.date,
        number=item.number,
        break_number=item.break_number,
        colors=csvio.format_colors(tuple(item.colors.split("/"))),
        user_data=item.note,
        angle=numbers["angle"],
        n_vertices=item.n_vertices,
        radius=numbers["radius"],
        x=x,
        y=y,
        z=z,
        fit=numbers["fit"],
        seg_param=numbers["lam"],
        patch=item.patch,
        n_plus=item.n_plus,
        n_minus=item.n_minus,
        fit_plus=numbers["fit_plus"],
        fit_minus=numbers["fit_minus"],
        normal_plus=tuple(numbers["normal_plus"]),
        normal_minus=tuple(numbers["normal_minus"]),
        requested=tuple(numbers["requested"]),
        snap_distance=numbers["snap_distance"],
        units=units,
        coordinates=numbers.get("space", WORLD),
        stale=stale,
        extension_version=extension_version(),
        blender_version=bpy.app.version_string,
        rule=numbers.get("rule", "paper"),
        convexity=numbers.get("convexity", ""),
        correlation=numbers.get("correlation"),
        stability=stability.get("spread"),
        stability_center=stability.get("center"),
        stability_radius=stability.get("radius"),
        stability_lam=stability.get("lam"),
        stability_bootstrap=stability.get("bootstrap"),
        stability_orientation=stability.get("orientation"),
        stability_runs=stability.get("runs"),
        stability_refused=stability.get("refused"),
        error="",
    )
