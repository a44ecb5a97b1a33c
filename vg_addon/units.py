"""The unit of a scan's coordinates: what the numbers of a mesh (and so of every length measured
on it) mean, said once per object, for display and for the CSV's Units column.

The numbers themselves never change: a radius of 0.3 on a millimetre scan is stored as 0.3 and
shown as "0.3 mm". Blender's scene units describe Blender units (BU) in general; a scan has its
own, usually millimetres, whatever the scene says.
"""

from __future__ import annotations

import math
import re

#: The units one can choose: key, name, symbol and metres per unit.
UNITS = (
    ("UM", "Micrometres", "µm", 1e-6),
    ("MM", "Millimetres", "mm", 1e-3),
    ("CM", "Centimetres", "cm", 1e-2),
    ("M", "Metres", "m", 1.0),
    ("IN", "Inches", "in", 0.0254),
    ("FT", "Feet", "ft", 0.3048),
)
SCENE = "SCENE"  # no unit said: Blender units, as the scene's unit system describes them
SYMBOLS = {key: symbol for key, _name, symbol, _metres in UNITS}
METRES = {key: metres for key, _name, _symbol, metres in UNITS}

#: A mesh whose bounding box is this large or larger (in its own coordinates) is taken to be in
#: millimetres, a smaller one in metres. Scanners write millimetres, and a fragment is rarely
#: under 2 mm or over 2 m: a 30 mm flake is 30 units across in millimetres and 0.03 in metres.
MILLIMETRE_EXTENT = 2.0


def guess_unit(extent: float) -> str:
    """The unit a mesh ``extent`` units across (its bounding box's largest side) is most likely
    in: ``"MM"`` from :data:`MILLIMETRE_EXTENT` up, ``"M"`` below (see there why)."""
    return "MM" if math.isfinite(extent) and extent >= MILLIMETRE_EXTENT else "M"


def scene_symbol(system: str, scale_length: float) -> str:
    """What one Blender unit is in a scene's unit system: the symbol of the unit that is exactly
    ``scale_length`` metres (``"m"`` for Blender's default scene), else ``"BU"``."""
    if system == "NONE":
        return "BU"
    for key, metres in METRES.items():
        if math.isclose(scale_length, metres, rel_tol=1e-6):
            return SYMBOLS[key]
    return "BU"


_SCENE_LENGTH = re.compile(r"^BU \(1 BU = ([0-9.eE+-]+) m\b")


def unit_of_text(text: str) -> str | None:
    """The unit a CSV's Units cell names: a symbol (``"mm"``, ``"mm (the scan's coordinates)"``),
    or a scene description whose unit is exactly one of :data:`UNITS` (``"BU (1 BU = 0.001 m,
    shown in millimeters)"``, what a batch run with ``--units mm`` writes); None otherwise
    (``"BU"`` alone, a length no unit has, 1 BU = 1 m: Blender's default scene, which says
    nothing about the scan, or "mesh units (...)" of a scaled object)."""
    word = text.strip().split(" ", 1)[0] if text else ""
    word = {"um": "µm", "μm": "µm"}.get(word, word)  # the Greek mu for the micro sign
    key = next((key for key, symbol in SYMBOLS.items() if symbol == word), None)
    if key is not None or not text:
        return key
    found = _SCENE_LENGTH.search(text)
    if found is None:
        return None
    try:
        metres = float(found.group(1))
    except ValueError:
        return None
    if metres == 1.0:
        return None
    # Written with %g (6 significant digits): 0.0254 and 0.3048 survive it exactly.
    return next((k for k, m in METRES.items() if math.isclose(metres, m, rel_tol=1e-9)), None)


def length_text(value: float, symbol: str) -> str:
    """A length for display: 5 significant digits and the unit, ``"0.3 mm"``."""
    return f"{value:.5g} {symbol}"
