"""The edge profile plot: matplotlib's figure (its labels, units, title, legend and stations), its
NumPy drawing where matplotlib is missing (checked pixel by pixel and by decoding the PNG by
hand), and which of the two runs where."""

import struct
import subprocess
import sys
import zlib
from pathlib import Path

import numpy as np
import pytest

from vg_addon import GoniometerError
from vg_addon.formats import mpl_plots, profile_plot
from vg_addon.formats.png import encode_png

ROOT = Path(__file__).resolve().parents[2]


def decode_png(data: bytes) -> np.ndarray:
    """A textbook decoder for the 8-bit RGBA, filter-0, non-interlaced PNGs the writer makes."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    position, chunks = 8, {}
    while position < len(data):
        (length,) = struct.unpack(">I", data[position : position + 4])
        kind = data[position + 4 : position + 8]
        body = data[position + 8 : position + 8 + length]
        (crc,) = struct.unpack(">I", data[position + 8 + length : position + 12 + length])
        assert crc == zlib.crc32(kind + body)
        chunks.setdefault(kind, b"")
        chunks[kind] += body
        position += 12 + length
    width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", chunks[b"IHDR"])
    assert (depth, colour, interlace) == (8, 6, 0)
    raw = np.frombuffer(zlib.decompress(chunks[b"IDAT"]), dtype=np.uint8).reshape(height, -1)
    assert (raw[:, 0] == 0).all()
    return raw[:, 1:].reshape(height, width, 4)


def test_stations_are_drawn_where_the_axes_put_them():
    arc = np.array([0.0, 1.0, 2.0, 3.0, 4.0])
    angles = np.array([80.0, 90.0, 100.0, 95.0, 120.0])
    image = profile_plot.draw_profile(arc, angles, width=400, height=200)
    assert image.shape == (200, 400, 4) and image.dtype == np.uint8
    to_x, to_y, x_range, y_range = profile_plot.plot_frame(arc, angles, 400, 200)
    assert x_range == (0.0, 4.0) and y_range[0] < 80.0 and y_range[1] > 120.0
    for a, b in zip(arc, angles, strict=True):
        column, row = round(float(to_x(a))), round(float(to_y(b)))
        assert tuple(image[row, column]) == profile_plot.DOTS
    # Higher angles are higher up; the first station is at the left edge of the axes.
    assert to_y(120.0) < to_y(80.0) and round(float(to_x(0.0))) == 48


def test_a_constant_profile_is_a_flat_line_in_the_middle():
    image = profile_plot.draw_profile([0, 1, 2], [70.5, 70.5, 70.5], width=300, height=160)
    line_rows = np.flatnonzero((image[:, 100] == profile_plot.LINE).all(axis=1))
    assert line_rows.size and abs(line_rows.mean() - (10 + 136) / 2) <= 2


def test_the_numpy_drawing_round_trips_as_png():
    image = profile_plot.draw_profile([0, 2.5], [91.0, 93.5])
    assert np.array_equal(decode_png(encode_png(image)), image)


def test_nice_ticks_are_round_and_inside():
    ticks = profile_plot.nice_ticks(71.3, 118.2)
    assert ticks.tolist() == [80.0, 90.0, 100.0, 110.0]
    assert profile_plot.nice_ticks(0.0, 0.9).tolist() == pytest.approx([0.0, 0.2, 0.4, 0.6, 0.8])


def test_bad_input_is_refused():
    with pytest.raises(GoniometerError, match="one finite arc length"):
        profile_plot.render_profile([0, 1], [90.0])
    with pytest.raises(GoniometerError, match="one finite arc length"):
        profile_plot.profile_png([0, 1], [90.0, float("nan")])
    with pytest.raises(GoniometerError, match="at least 160"):
        profile_plot.render_profile([0], [90.0], width=50, height=50)
    with pytest.raises(GoniometerError, match="at least 160"):
        profile_plot.draw_profile([0], [90.0], width=50, height=50)


ARC = np.array([0.0, 0.5, 1.0, 1.5, 2.0, 2.5])
ANGLES = np.array([96.0, 97.5, 99.0, 98.0, 94.0, 91.5])


def test_matplotlib_draws_the_stations_with_labels_units_title_and_legend():
    pytest.importorskip("matplotlib", reason="requirements/report.txt")
    figure = mpl_plots.profile_figure(
        ARC, ANGLES, width=480, height=240, dpi=100, units="mm", title="Flake 3, edge 1", pooled=96
    )
    (ax,) = figure.axes
    assert ax.get_xlabel() == "arc length along the edge (mm)"
    assert ax.get_ylabel() == "angle (°)"
    assert figure.get_suptitle() == "Flake 3, edge 1"
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert legend == ["station angle (6 stations)", "whole edge 96.00°"]
    stations = ax.get_lines()[0]
    assert np.array_equal(stations.get_xdata(), ARC) and np.array_equal(
        stations.get_ydata(), ANGLES
    )
    low, high = ax.get_ylim()
    assert low < ANGLES.min() and high > ANGLES.max()
    # Each station's dot is where matplotlib's own data-to-pixel transform puts it.
    image = mpl_plots.rgba(figure)
    assert image.shape == (240, 480, 4)
    dot = np.array([int(mpl_plots.VERMILLION[i : i + 2], 16) for i in (1, 3, 5)])
    for x, y in ax.transData.transform(np.column_stack([ARC, ANGLES])):
        column, row = round(x), 240 - round(y)  # display y runs up from the bottom
        patch = image[row - 1 : row + 2, column - 1 : column + 2, :3].reshape(-1, 3).astype(int)
        assert (np.abs(patch - dot).sum(axis=1) < 30).any(), (x, y)


def test_units_label_falls_back_to_mesh_units():
    assert mpl_plots.unit_label("mm") == "mm"
    assert mpl_plots.unit_label("BU (1 BU = 1 m, shown in metres)") == "BU"
    assert mpl_plots.unit_label("") == "mesh units"


def test_the_batch_png_is_matplotlibs_where_it_runs():
    pytest.importorskip("matplotlib", reason="requirements/report.txt")
    data = profile_plot.profile_png(ARC, ANGLES, units="mm", title="t")
    width, height = struct.unpack(">II", data[16:24])
    assert (width, height) == (768, 408)  # the NumPy drawing is 480 x 240


FALLBACK = """
import json, sys
import numpy as np
from vg_addon.formats import mpl_plots, profile_plot, sweep_plot
from vg_addon.formats.png import encode_png
from vg_addon import Surface
from vg_addon.method.sweep import radius_sweep
from vg_addon.synthetic_meshes import wedge
arc, angles = [0.0, 0.5, 1.0], [91.0, 92.0, 90.5]
rgba = profile_plot.render_profile(arc, angles, units="mm", title="t")
mesh = wedge(75, n=40, irregular=True, seed=4, concave=True)
points = radius_sweep(Surface(mesh.points, mesh.triangles), [0.01, 0.0, 0.0], 0.02, 0.6, 5)
print(json.dumps({
    "available": mpl_plots.available(),
    "panel": bool(np.array_equal(rgba, profile_plot.draw_profile(arc, angles))),
    "png": profile_plot.profile_png(arc, angles) == encode_png(
        profile_plot.draw_profile(arc, angles), level=6
    ),
    "sweep": sweep_plot.sweep_png(points, units="mm", title="t") == encode_png(
        sweep_plot.draw_sweep(*sweep_plot.sweep_series(points))
    ),
    "refused": sum(p.measurement is None for p in points),
    "matplotlib_imported": "matplotlib" in sys.modules,
}))
"""


def test_without_matplotlib_the_numpy_drawings_are_used(tmp_path):
    import json

    from hide_modules import environment

    run = subprocess.run(
        [sys.executable, "-c", FALLBACK],
        cwd=ROOT,
        env=environment(tmp_path / "hide", ("matplotlib",)),
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert run.returncode == 0, run.stderr
    assert json.loads(run.stdout) == {
        "available": False,
        "panel": True,
        "png": True,
        "sweep": True,
        "refused": 1,  # the smallest radius: the NumPy drawing marks it too
        "matplotlib_imported": False,
    }


# Sizes where width / dpi × dpi falls just short of a whole pixel (251 / 100 × 100 = 250.99…)
# among others: the image Blender copies pixels into must have exactly the size asked for.
SIZES = [(480, 251), (160, 113), (167, 230), *((160 + 13 * k, 100 + 7 * k) for k in range(40))]


def test_matplotlib_images_are_exactly_the_size_asked_for():
    pytest.importorskip("matplotlib", reason="requirements/report.txt")
    for width, height in SIZES:
        image = profile_plot.render_profile(ARC, ANGLES, width=width, height=height)
        assert image.shape == (height, width, 4)
    for width, height in SIZES[::6]:
        for dpi in (100, 120, 72):
            figure = mpl_plots.profile_figure(ARC, ANGLES, width=width, height=height, dpi=dpi)
            data = mpl_plots.png(figure)
            assert struct.unpack(">II", data[16:24]) == (width, height), dpi


@pytest.mark.parametrize("size", [(480, 240), (256, 192)])
def test_the_widest_tick_label_is_drawn_whole(size):
    """An edge at 100° has the tick label "101.0°", wider than the first version's margin: its
    first digit ran off the picture's left side. Every label now starts inside, four pixels
    from the edge or more."""
    image = profile_plot.draw_profile([0.0], [100.0], width=size[0], height=size[1])
    ink = (image[..., :3] == profile_plot.AXES[:3]).all(axis=2)
    assert not ink[:, :4].any()
    assert ink[:, 4:12].any()  # the widest label's first digit, whole
