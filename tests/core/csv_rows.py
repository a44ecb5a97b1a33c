"""What the CSV tests share: an export's columns as the MeshLab plugin and this extension name
them (written out here, not taken from the code under test), a complete row, and readers."""

import csv
import io
import struct

import pytest

from vg_addon import GoniometerError
from vg_addon.formats import csvio
from vg_addon.formats.csvio import MeasurementRow

MESHLAB_HEADER = (
    "Mesh Name,Date,Measurement #,Break #,Colors,User Data,Angle,Number of Vertices,Radius,"
    "x,y,z,fit,SegParam"
)
OUR_EXTRA_COLUMNS = [
    "Patch Mode",
    "Vertices +",
    "Vertices -",
    "Fit +",
    "Fit -",
    "Normal + x",
    "Normal + y",
    "Normal + z",
    "Normal - x",
    "Normal - y",
    "Normal - z",
    "Requested x",
    "Requested y",
    "Requested z",
    "Snap Distance",
    "Edge #",
    "Arc Length",
    "Spacing",
    "Edge Closed",
    "Units",
    "Coordinates",
    "Precision",
    "Stale",
    "Extension Version",
    "Blender Version",
    "Rule",
    "Convexity",
    "Convexity Correlation",
    "Stability",
    "Stability Centre",
    "Stability Radius",
    "Stability SegParam",
    "Stability Bootstrap",
    "Stability Orientation",
    "Stability Runs",
    "Stability Refused",
    "Stability Crease",
    "Stability Crease Refused",
    "Stability Noise Hides Crease",
    "Stability Flag",
    "error",
]


def bits(value: float) -> bytes:
    return struct.pack("<d", value)


def good_row(**changes) -> MeasurementRow:
    values = dict(
        mesh_name="bone_12",
        date="2024-05-01T14:03:11+02:00",
        number=1,
        break_number=1,
        colors="#E69F00/#0072B2",
        user_data="ridge, proximal end",
        angle=97.12345678901234,
        n_vertices=812,
        radius=3.0,
        x=1.25,
        y=-2.5,
        z=0.1,
        fit=0.0123,
        lam=2.0,
        patch="euclidean",
        n_plus=400,
        n_minus=412,
        fit_plus=0.01,
        fit_minus=0.02,
        normal_plus=(0.0, 0.0, 1.0),
        normal_minus=(0.6, 0.0, -0.8),
        requested=(1.2, -2.5, 0.11),
        snap_distance=0.0509,
        units="BU (1 BU = 0.001 m, shown in millimeters)",
        stale=False,
        extension_version="0.1.0",
        blender_version="5.0.1",
        rule="oriented",
        convexity="concave",
        correlation=-0.8660254037844386,
        stability=0.4123,
        stability_center=0.4123,
        stability_radius=0.1,
        stability_lam=0.05,
        stability_bootstrap=0.2,
        stability_orientation=0.0,
        stability_runs=21,
        stability_refused=1,
        stability_crease=0.1,
        stability_crease_refused=0,
        stability_noise_hides_crease=0,
        error="",
    )
    values.update(changes)
    return MeasurementRow(**values)


def cells(text: str) -> list[list[str]]:
    return list(csv.reader(io.StringIO(text, newline="")))


def raises_with(text, *fragments):
    """Read ``text`` for replication, expect a GoniometerError containing every fragment."""
    with pytest.raises(GoniometerError) as info:
        csvio.read_replication_csv(text)
    message = str(info.value)
    for fragment in fragments:
        assert fragment in message, f"{fragment!r} not in:\n{message}"
    return message
