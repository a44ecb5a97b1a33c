"""Measurements recorded in world space, by versions before measurements were taken in mesh
coordinates, brought into the mesh's own coordinates.

Such a record has no ``"space"`` in its exact numbers, and its fingerprint hashed the object's
transform with the mesh. When that fingerprint still matches the object (the mesh and the
transform are as they were when it was measured) and the transform is a similarity (a move, a
rotation, a mirror and a uniform scale, which keep angles), the record is re-measured at the same
vertex, with the radius divided by the scale, the same λ, patch mode and rule (the paper's for
records from before the rule existed), and its numbers are
replaced by the new measurement's: the one it replays to from then on. The world-space numbers
are kept in the record (``"world_record"``) so the change stays traceable. The angle is the same
up to the rounding the world-space coordinates carried (a similarity changes no angle; a few
1e-6° in the test suite, far below the 0.01° angles are reported to).

A record that cannot be brought over (the mesh or the transform changed since, or a non-uniform
scale that the world-space angle depended on) keeps its numbers in world space and stays stale;
its CSV row says ``world`` in the Coordinates column.
"""

from __future__ import annotations

import numpy as np

from ..vg_addon import GoniometerError
from ..vg_addon.formats import record_codec
from ..vg_addon.formats.record_codec import exact_numbers
from . import records
from .mesh_data import Geometry, mesh_points, uniform_scale


def has_world_records(obj, signatures=None, known=()) -> bool:
    """Whether any measurement of ``obj`` is still recorded in world space.

    ``signatures`` (one row per record) and ``known`` (signatures of records already read, as
    ``measuring.repaint`` keeps them) skip the records already read, which it has judged.
    """
    items = obj.vg.measurements
    positions = range(len(items))
    if signatures is not None:
        positions = [i for i, row in enumerate(signatures.tolist()) if tuple(row) not in known]
    for position in positions:
        numbers = exact_numbers(items[position])
        if numbers and "space" not in numbers:
            return True
    return False


def migrate(obj, geometry: Geometry, surface) -> list[int]:
    """Bring ``obj``'s world-space records that still match it into mesh coordinates.

    Parameters
    ----------
    obj : bpy.types.Object
    geometry : mesh_data.Geometry
        Its current evaluated geometry.
    surface : vg_addon.Surface
        The prepared surface of ``geometry``.

    Returns
    -------
    list of int
        Numbers of the records migrated (the others are left exactly as they were).
    """
    scale = uniform_scale(geometry.matrix)
    migrated = []
    for item in obj.vg.measurements:
        numbers = exact_numbers(item)
        if not numbers or "space" in numbers:
            continue
        if item.fingerprint not in geometry.world_fingerprints or scale is None:
            continue
        try:
            m = _remeasure(geometry, surface, numbers, item.patch, scale)
        except (GoniometerError, KeyError, ValueError, TypeError):
            continue
        station = None
        if "arc_length" in numbers:  # an edge station: its lengths in mesh units too
            station = (
                0,
                float(numbers["arc_length"]) / scale,
                float(numbers["spacing"]) / scale,
                bool(numbers.get("plus_left", True)),
            )
        new = record_codec.measurement_numbers(m, station)
        new["world_record"] = numbers
        item.exact = record_codec.encode(new)
        item.n_vertices, item.n_plus, item.n_minus = (
            int(m.n_vertices),
            int(m.n_plus),
            int(m.n_minus),
        )
        item.fingerprint = geometry.fingerprint
        item.stale = False
        records.stamp(item)
        migrated.append(item.number)
    return migrated


def _remeasure(geometry: Geometry, surface, numbers: dict, patch: str, scale: float):
    """The measurement a world-space record makes in mesh coordinates, at the same vertex."""
    world_centre = np.array(numbers["center"], dtype=np.float64)
    # The recorded centre was a vertex's world position, computed exactly this way (a matrix
    # product, as world-space records were made; world_points now sums in a fixed order).
    matrix = np.asarray(geometry.matrix, dtype=np.float64)
    recorded_way = geometry.local @ matrix[:3, :3].T + matrix[:3, 3]
    hits = np.flatnonzero((recorded_way == world_centre).all(axis=1))
    if not hits.size:
        raise GoniometerError("the recorded centre is no vertex of the mesh")
    vertex = int(hits[0])
    radius = float(numbers["radius"]) / scale
    requested = mesh_points(np.array(numbers["requested"], dtype=np.float64), geometry.matrix)
    options = {
        "rule": numbers.get("rule", "paper"),  # records from before the rule used the paper's
        "stability": bool(numbers.get("stability")),
    }
    m = surface.measure(requested, radius, float(numbers["lam"]), patch, **options)
    if not np.array_equal(m.center, geometry.points[vertex]):
        # Rounding moved the snap to an equally near vertex: measure at the recorded one.
        m = surface.measure(
            geometry.points[vertex], radius, float(numbers["lam"]), patch, **options
        )
    return m
