"""Measurement records: a core :class:`Measurement` into an ``Object.vg`` item, and an item into
a CSV row."""

from __future__ import annotations

import hashlib
import math
import tomllib
from functools import cache, lru_cache
from pathlib import Path

import bpy
import numpy as np

from ..properties import set_unit
from ..vg_addon import GoniometerError, palette, units
from ..vg_addon.formats import csvio, record_codec
from ..vg_addon.formats.record_codec import exact_numbers
from ..vg_addon.method.break_sides import paint_swapped
from ..vg_addon.method.result import stored_stability_warning
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


def add_measurement(
    obj, m, geometry_fingerprint: str, *, note: str = "", break_number=None, station=None
):
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
        1 to ``csvio.MAX_BREAK_NUMBER``. Default: the object's current break.
    station : tuple (edge_number, arc_length, spacing, plus_left), optional
        For a station of an edge profile: its edge, its arc length along the path, the edge's
        spacing, and whether its "+" side lies left of the path (if not, its colours are
        recorded the other way round, so that one side of the whole edge has one colour).

    Returns
    -------
    The new ``VG_Measurement`` item (valid until the collection changes again).

    Raises
    ------
    GoniometerError
        A break number out of range; nothing is added then.
    """
    data = obj.vg
    guess_unit(obj, bpy.context.scene)
    break_number = data.break_number if break_number is None else break_number
    if not (
        isinstance(break_number, int | np.integer) and 1 <= break_number <= csvio.MAX_BREAK_NUMBER
    ):
        raise GoniometerError(
            f"Break # must be a whole number from 1 to {csvio.MAX_BREAK_NUMBER}; got "
            f"{break_number!r}. Nothing was recorded."
        )
    numbers = record_codec.measurement_numbers(m, station)
    if station is None and _painted_swapped(data, m, break_number):
        numbers[SWAPPED] = True  # painted the other way round; the numbers are as measured
    exact = record_codec.encode(numbers)
    # Everything that can fail is done: from here on the item is written whole.
    item = data.measurements.add()
    item.number = data.next_number
    data.next_number += 1
    item.break_number = int(break_number)
    item.exact = exact
    if station is not None:
        item.edge_number = int(station[0])
    item.patch = m.patch
    item.n_vertices = int(m.n_vertices)
    item.n_plus = int(m.n_plus)
    item.n_minus = int(m.n_minus)
    item.date = csvio.now_iso()
    item.note = note
    item.colors = "/".join(station_colours(item.break_number, _plus_first(numbers)))
    item.fingerprint = geometry_fingerprint
    item.stale = False
    stamp(item)
    data.active_index = len(data.measurements) - 1
    return item


def position_after_removal(active: int, removed, remaining: int) -> int:
    """Where the selected list item stands once the items at positions ``removed`` are gone.

    The same item stays selected; where it was removed, the one now in its place (the new last
    one at the end of the list). ``remaining``: the list's length after the removal.
    """
    before = sum(1 for position in removed if position < active)
    return max(min(active - before, remaining - 1), 0)


def content_id(item) -> int:
    """A digest, from 1 to 2**31 - 1, of what painting ``item`` depends on besides its
    break: its exact numbers, patch mode and geometry fingerprint."""
    digest = hashlib.sha256(f"{item.fingerprint}\0{item.patch}\0{item.exact}".encode())
    return int.from_bytes(digest.digest()[:4], "little") % (2**31 - 1) + 1


def stamp(item) -> None:
    """Record ``item``'s :func:`content_id`; call after changing its exact numbers, patch mode
    or fingerprint."""
    item.content_id = content_id(item)


def next_free_break(obj) -> int:
    """The break after the current one: one past the highest the object uses or is on."""
    data = obj.vg
    highest = max([data.break_number, *(item.break_number for item in data.measurements)])
    return _break_after(highest)


def continue_after_recorded_breaks(obj) -> None:
    """After recording many measurements at once (a batch run, a CSV import): make the current
    break one past the highest in use, so the next click starts a break of its own instead of
    joining a recorded one (and its colours)."""
    data = obj.vg
    highest = max((item.break_number for item in data.measurements), default=0)
    data.break_number = max(data.break_number, _break_after(highest))


def _break_after(highest: int) -> int:
    """The break after ``highest``; at the largest a break can be (an imported ``Break #`` of
    2**31 - 1, the most Blender's integer holds), that one: none can follow it."""
    return min(highest + 1, csvio.MAX_BREAK_NUMBER)


def station_colours(break_number: int, plus_left: bool = True) -> tuple[str, str]:
    """The "+"/"-" colour names of a measurement: its break's pair, swapped when its "+" side is
    painted in the second colour (an edge station whose "+" side lies right of the path: the
    edge's left side always gets the first colour; a measurement painted swapped to agree with
    its break's earlier ones)."""
    names = tuple(palette.pair_names(break_number))
    return names if plus_left else names[::-1]


SWAPPED = record_codec.SWAPPED

# The earlier measurements of a break that orient a new one's colours: the latest this many
# (each oriented by its own predecessors), so a click reads a bounded number of records.
BREAK_NEIGHBOURS = 32


def _plus_first(numbers: dict) -> bool:
    """Whether the "+" side of a record with these exact numbers is painted in the first colour
    of its break's pair."""
    return bool(numbers.get("plus_left", True)) and not numbers.get(SWAPPED, False)


def honour_colours(item, cell: str) -> bool:
    """Paint ``item``'s sides the way round a CSV's ``Colors`` cell says (a re-imported row whose
    file gives its break's pair the other way round); returns whether that changed anything.

    Only the order of the item's own pair can follow the file: another pair, an unreadable cell
    or an edge station (whose order is its path's side) leaves it as it is. The measured numbers
    never change; only which side is painted in which colour.
    """
    if not cell or item.edge_number:
        return False
    try:
        wanted = csvio.format_colors(cell)
        mine = csvio.format_colors(tuple(item.colors.split("/")))
    except GoniometerError:
        return False
    if wanted == mine or wanted != "/".join(reversed(mine.split("/"))):
        return False
    numbers = record_codec.decode(item.exact)
    if numbers.pop(SWAPPED, False) is False:
        numbers[SWAPPED] = True
    item.exact = record_codec.encode(numbers)
    item.colors = "/".join(reversed(item.colors.split("/")))
    stamp(item)
    return True


def plus_on_pair_side(item) -> bool:
    """Whether ``item``'s "+" side is painted in the first colour of its break's pair."""
    return _plus_first(exact_numbers(item))


@lru_cache(maxsize=4096)
def _painted_normals(exact: str):
    """(first-colour normal, second-colour normal, centre) of a record's exact numbers in mesh
    coordinates, or None (a world-space record of an earlier version, or numbers missing)."""
    try:
        numbers = record_codec.decode(exact)
        plus, minus, center = numbers["normal_plus"], numbers["normal_minus"], numbers["center"]
    except (KeyError, TypeError):
        return None
    if numbers.get("space") != MESH:
        return None
    return (plus, minus, center) if _plus_first(numbers) else (minus, plus, center)


# How far back among an object's measurements a new one looks for its break's latest ones: a
# record reads a bounded number of records, however many the object holds (a batch or an import
# of many rows would otherwise cost time that grows with the square of their number).
BREAK_WINDOW = 1024


def _painted_swapped(data, m, break_number: int) -> bool:
    """Whether ``m``, recorded now in ``break_number``, gets its sides painted the other way
    round (to agree with its break's earlier measurements)."""
    return paint_swapped(
        m.normal_plus, m.normal_minus, m.center, m.radius, _break_sides(data, break_number)
    )


def colours_as_painted(obj, m) -> tuple[tuple, tuple]:
    """The 8-bit sRGB colours ``("+" side, "-" side)`` that recording measurement ``m`` on
    ``obj`` now (in its current break) would paint: what the drag previews before the release."""
    data = obj.vg
    plus, minus = palette.pair_srgb8(data.break_number)
    if _painted_swapped(data, m, data.break_number):
        return minus, plus
    return plus, minus


def _break_sides(data, break_number: int) -> list:
    """The painted normals and centres (see :func:`_painted_normals`) of the latest
    :data:`BREAK_NEIGHBOURS` measurements of ``break_number`` among the last
    :data:`BREAK_WINDOW` of ``data.measurements``."""
    items = data.measurements
    count = len(items)
    if count == 0:
        return []
    # One read of every break number: indexing a Blender collection walks it from the start,
    # so reading the window item by item cost time growing with the records held, per record.
    breaks = np.empty(count, dtype=np.int32)
    items.foreach_get("break_number", breaks)
    start = max(count - BREAK_WINDOW, 0)
    latest = np.flatnonzero(breaks[start:] == break_number)[-BREAK_NEIGHBOURS:] + start
    sides = (_painted_normals(items[int(index)].exact) for index in latest)
    return [entry for entry in sides if entry is not None]


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


def _as_flag(value) -> int | None:
    """A stored yes/no as a CSV's 1 or 0; ``None`` (not recorded) stays empty."""
    return None if value is None else int(bool(value))


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


MESH_UNITS = "mesh units"
"""The unit of a scaled object's coordinates where no Scan Units name it."""


def unit_symbol(obj, scene) -> str:
    """The symbol of ``obj``'s coordinate unit (``"mm"``): the one its Scan Units say, else what
    one Blender unit is in ``scene`` (``"BU"`` if no unit is exactly that) for an object shown at
    its own size; ``"mesh units"`` for a scaled one, whose coordinates the scene's unit does not
    measure (``units_label`` says how they relate)."""
    key = getattr(getattr(obj, "vg", None), "unit", units.SCENE)
    if key in units.SYMBOLS:
        return units.SYMBOLS[key]
    if obj is not None and not is_shown_at_own_size(obj):
        return MESH_UNITS
    settings = scene.unit_settings
    return units.scene_symbol(settings.system, settings.scale_length)


def is_shown_at_own_size(obj) -> bool:
    """Whether ``obj``'s transform keeps lengths (a uniform scale of 1): then one mesh unit is
    one Blender unit."""
    scale = uniform_scale(np.array(obj.matrix_world, dtype=np.float64))
    return scale is not None and math.isclose(scale, 1.0, rel_tol=1e-6)


def choose_unit(obj, key: str) -> bool:
    """Set ``obj``'s Scan Units to ``key`` (the batch's ``--units``, the unit of the scene's
    Blender units) where that is the unit of the mesh's own coordinates: an object shown at its
    own size, with no Scan Units chosen before. Returns whether they were set; else the label
    stays the scene's (``units_label``), which says how a scaled object's units relate."""
    if obj.vg.unit_chosen or obj.vg.unit != units.SCENE or not is_shown_at_own_size(obj):
        return False
    set_unit(obj.vg, key, guessed=False)
    return True


def adopt_file_units(obj, texts) -> str | None:
    """Take the unit that the Units cells ``texts`` of a file of this extension all name as
    ``obj``'s Scan Units, unless the user chose them; returns the key taken, or None where
    nothing changed (no cells, cells that disagree or name no unit, a unit already set)."""
    found = {units.unit_of_text(text) for text in texts}
    if len(found) != 1 or None in found or obj.vg.unit_chosen:
        return None
    (key,) = found
    if obj.vg.unit == key:
        return None
    set_unit(obj.vg, key, guessed=False)
    return key


def guess_unit(obj, scene) -> None:
    """Guess ``obj``'s Scan Units from its size, once, before its first measurement: only when
    nobody chose them and the scene's units are Blender's default (a scene set up with its own
    units says what a Blender unit is); see ``vg_addon.units.guess_unit``."""
    data = obj.vg
    settings = scene.unit_settings
    if (
        len(data.measurements)
        or data.unit_chosen
        or data.unit != units.SCENE
        or settings.system != "METRIC"
        or settings.scale_length != 1.0
    ):
        return
    corners = np.array([tuple(c) for c in obj.bound_box], dtype=np.float64)
    extent = float((corners.max(axis=0) - corners.min(axis=0)).max())
    set_unit(data, units.guess_unit(extent), guessed=True)


def units_label(scene, obj=None) -> str:
    """What one coordinate unit is: the object's Scan Units (``"mm"``) when it has them, else
    Blender units and their length in the scene's unit system, for a mesh shown at its own size;
    for an object scaled by ``s``, one mesh unit is ``s`` Blender units in the scene, and the
    label says so."""
    key = getattr(getattr(obj, "vg", None), "unit", units.SCENE)
    if key in units.SYMBOLS:
        return units.SYMBOLS[key]  # the mesh's own coordinates, whatever the object's scale
    units_ = scene.unit_settings
    scale = None
    if obj is not None:
        scale = uniform_scale(np.array(obj.matrix_world, dtype=np.float64))
        if scale is None:
            return "mesh units (the object's scale is not uniform)"
    if units_.system == "NONE":
        base = "BU"
        metres = None
    else:
        base = f"BU (1 BU = {units_.scale_length:g} m, shown in {units_.length_unit.lower()})"
        metres = units_.scale_length
    if scale is None or scale == 1.0:
        return base
    shown = f"{scale:g} BU" if metres is None else f"{scale * metres:g} m"
    return f"mesh units (1 unit = {shown} in the scene, object scale {scale:g})"


def to_row(
    obj, item, *, stale: bool, units: str, precision: str = "float32", edge_closed=None
) -> csvio.MeasurementRow:
    """The CSV row of a stored ``item``, measured on ``obj``, its numbers read from the item
    (see :func:`measurement_row`)."""
    return measurement_row(
        obj,
        item,
        numbers_of(item),
        stale=stale,
        units=units,
        precision=precision,
        edge_closed=edge_closed,
    )


def measurement_row(
    obj,
    item,
    numbers: dict,
    *,
    stale: bool,
    units: str,
    precision: str = "float32",
    edge_closed: bool | None = None,
) -> csvio.MeasurementRow:
    """The CSV row of ``item``, measured on ``obj``, with its exact ``numbers``
    (``record_codec.measurement_numbers``: those ``item.exact`` holds); ``precision``: the
    coordinates measured (``"float32"``, Blender's mesh, unless a batch run measured a file's
    float64 ones); ``edge_closed``: for a station, whether its edge is a loop
    (:func:`closed_edges`)."""
    x, y, z = numbers["center"]
    stability = numbers.get("stability") or {}
    station = item.edge_number > 0
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
        lam=numbers["lam"],
        patch=item.patch,
        n_plus=item.n_plus,
        n_minus=item.n_minus,
        fit_plus=numbers["fit_plus"],
        fit_minus=numbers["fit_minus"],
        normal_plus=tuple(numbers["normal_plus"]),
        normal_minus=tuple(numbers["normal_minus"]),
        requested=tuple(numbers["requested"]),
        snap_distance=numbers["snap_distance"],
        edge_number=item.edge_number if station else None,
        arc_length=numbers.get("arc_length") if station else None,
        spacing=numbers.get("spacing") if station else None,
        edge_closed=edge_closed if station else None,
        units=units,
        coordinates=numbers.get("space", WORLD),
        precision=precision,
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
        stability_crease=stability.get("crease"),
        stability_crease_refused=stability.get("crease_refused"),
        stability_noise_hides_crease=_as_flag(stability.get("noise_hides_crease")),
        stability_flag=stored_stability_warning(stability or None),
        error="",
    )


def add_edge(obj, profile, clicks, geometry_fingerprint: str, *, break_number: int, note: str = ""):
    """Append an edge profile record to ``obj.vg.edges`` and make it the active one.

    Parameters
    ----------
    profile : vg_addon.EdgeProfile
        The measured profile.
    clicks : sequence of array_like, shape (3,)
        The points that define the path (start, via points, end).
    break_number : int
        The break its stations were recorded in.

    Returns
    -------
    The new ``VG_EdgeProfile`` item; its ``number`` is the stations' ``edge_number``.
    """
    numbers = record_codec.edge_numbers(profile, clicks)
    return _add_edge(
        obj, numbers, profile.patch, geometry_fingerprint, break_number=break_number, note=note
    )


def _add_edge(obj, numbers: dict, patch: str, fingerprint: str, *, break_number: int, note=""):
    data = obj.vg
    edge = data.edges.add()
    edge.number = data.next_edge_number
    data.next_edge_number += 1
    edge.break_number = int(break_number)
    edge.exact = record_codec.encode(numbers)
    edge.patch = patch
    edge.n_stations = len(numbers["angles"])
    edge.date = csvio.now_iso()
    edge.note = note
    edge.colors = "/".join(palette.pair_names(edge.break_number))
    edge.fingerprint = fingerprint
    data.active_edge_index = len(data.edges) - 1
    return edge


def update_changed_edges(obj) -> None:
    """Set each edge profile's ``stations_changed`` of ``obj``: whether any of its stations is
    stale or was deleted since it was measured.

    The measurements' edge numbers and stale flags are read at once (``foreach_get``), so the
    panels draw the flag without walking the measurements; only changed flags are written.
    """
    data = obj.vg
    edges, items = data.edges, data.measurements
    if not len(edges):
        return
    owners = np.empty(len(items), dtype=np.int32)  # IntProperty's own type
    stale = np.empty(len(items), dtype=bool)
    items.foreach_get("edge_number", owners)
    items.foreach_get("stale", stale)
    numbers = np.empty(len(edges), dtype=np.int32)
    expected = np.empty(len(edges), dtype=np.int32)
    flags = np.empty(len(edges), dtype=bool)
    edges.foreach_get("number", numbers)
    edges.foreach_get("n_stations", expected)
    edges.foreach_get("stations_changed", flags)
    owners = np.maximum(owners, 0)  # 0: not a station (edge numbers start at 1)
    size = int(max(owners.max(initial=0), numbers.max(initial=0))) + 1
    counts = np.bincount(owners, minlength=size)
    stale_counts = np.bincount(owners[stale], minlength=size)
    where = np.maximum(numbers, 0)
    changed = (counts[where] != expected) | (stale_counts[where] > 0)
    if not np.array_equal(changed, flags):
        edges.foreach_set("stations_changed", changed)


def add_edge_from_numbers(
    obj, numbers: dict, patch: str, fingerprint: str, *, break_number, note=""
):
    """Append an edge record from ready numbers (see ``record_codec.edge_numbers``); used when an edge is
    rebuilt from re-measured stations."""
    return _add_edge(obj, numbers, patch, fingerprint, break_number=break_number, note=note)


def edge_is_closed(numbers: dict) -> bool:
    """Whether an edge record's ``numbers`` describe a loop: its traced path, or the points it
    was traced through, end where they start."""
    for key in ("path", "points"):
        line = numbers.get(key) or []
        if len(line) > 2 and line[0] == line[-1]:
            return True
    return False


def closed_edges(obj) -> dict[int, bool]:
    """``{edge number: whether it is a loop}`` for every edge profile of ``obj``."""
    return {edge.number: edge_is_closed(exact_numbers(edge)) for edge in obj.vg.edges}


def edge_row(obj, edge, *, units: str, stale: bool = False) -> csvio.EdgeRow:
    """The edge summary CSV row of ``edge``, measured on ``obj`` (``stale``: some of its
    stations were measured on other geometry than the mesh has now)."""
    numbers = exact_numbers(edge)
    spans = numbers.get("flat_spans", [])
    return csvio.EdgeRow(
        mesh_name=obj.name,
        date=edge.date,
        edge_number=edge.number,
        break_number=edge.break_number,
        colors=csvio.format_colors(tuple(edge.colors.split("/"))),
        user_data=edge.note,
        n_stations=edge.n_stations,
        spacing=numbers.get("spacing"),
        radius=numbers.get("radius"),
        lam=numbers.get("lam"),
        patch=edge.patch,
        rule=numbers.get("rule", ""),
        length=numbers.get("length"),
        mean=numbers.get("mean"),
        std=numbers.get("std"),
        min=numbers.get("min"),
        max=numbers.get("max"),
        pooled_angle=numbers.get("pooled_angle"),
        pooled_fit=numbers.get("pooled_fit"),
        **{name: numbers.get(name) for name in record_codec.STUDY_FIGURES},
        points=csvio.format_points(numbers.get("points", [])),
        flat_spans="; ".join(f"{a!r}-{b!r}" for a, b in spans),
        units=units,
        coordinates=numbers.get("space", WORLD),
        stale=stale,
        extension_version=extension_version(),
        blender_version=bpy.app.version_string,
    )
