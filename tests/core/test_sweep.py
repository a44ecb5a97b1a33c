"""The radius sweep: measurements per radius, its CSV, and its plot as a PNG read back by hand."""

import csv
import io
import struct
import zlib

import numpy as np
import pytest

from vg_addon import GoniometerError, Surface
from vg_addon.formats import csvio, sweep_plot
from vg_addon.formats.png import encode_png
from vg_addon.method.sweep import radius_sweep, sweep_radii
from vg_addon.synthetic_meshes import wedge


@pytest.fixture(scope="module")
def surface():
    mesh = wedge(75, n=40, irregular=True, seed=4, concave=True)
    return Surface(mesh.points, mesh.triangles)


def test_each_radius_is_the_measurement_at_that_radius(surface):
    points = radius_sweep(surface, [0.01, 0.0, 0.0], 0.02, 0.6, 12, lam=1.5)
    assert [p.radius for p in points] == list(np.linspace(0.02, 0.6, 12))
    for point in points:
        try:
            single = surface.measure([0.01, 0.0, 0.0], point.radius, 1.5)
        except GoniometerError as error:
            assert point.measurement is None and point.error == str(error)
            continue
        assert point.error == ""
        assert point.measurement.angle == single.angle
        assert point.measurement.fit_error == single.fit_error
    assert points[0].measurement is None  # 0.02 holds too few vertices
    assert abs(points[-1].measurement.angle - 75) < 0.1
    assert points[-1].measurement.convexity == "concave"


def test_nothing_measurable_says_what_happened_at_both_ends(surface):
    with pytest.raises(
        GoniometerError, match=r"No radius from 0.001 to 0.002.*At 0.001: .* At 0.002: "
    ):
        radius_sweep(surface, [0, 0, 0], 0.001, 0.002, 3)


@pytest.mark.parametrize(
    ("start", "stop", "count", "match"),
    [
        (0.5, 0.1, 5, "smaller than its last"),
        (0, 1, 5, "radius"),
        (0.1, 1, 1, "2 to 1000"),
        (0.1, 1, 2.5, "whole number"),
        (0.1, 1, True, "whole number"),
    ],
)
def test_bad_sweeps_are_refused(start, stop, count, match):
    with pytest.raises(GoniometerError, match=match):
        sweep_radii(start, stop, count)


def test_sweep_csv_reads_back_exactly(surface):
    points = radius_sweep(surface, [0.01, 0.0, 0.0], 0.02, 0.5, 5)
    text = csvio.format_sweep_rows(csvio.sweep_cells("=wedge", 3, p, "mm") for p in points)
    rows = list(csv.DictReader(io.StringIO(text)))
    assert list(rows[0]) == list(csvio.SWEEP_COLUMNS)
    assert {row["Units"] for row in rows} == {"mm"}  # also on the refused radius's row
    assert rows[0]["Mesh Name"] == "'=wedge" and rows[0]["Measurement #"] == "3"
    assert rows[0]["Angle"] == "" and "larger radius" in rows[0]["error"]
    for row, point in zip(rows[1:], points[1:], strict=True):
        m = point.measurement
        assert float(row["Radius"]) == point.radius
        assert float(row["Angle"]) == m.angle and float(row["fit"]) == m.fit_error
        assert int(row["Vertices +"]) + int(row["Vertices -"]) == int(row["Number of Vertices"])
        assert (row["Convexity"], row["Rule"], row["error"]) == ("concave", "refined", "")


def read_png(data: bytes) -> np.ndarray:
    """A PNG decoder for what the writer may produce (8-bit RGB, filter 0), checking every CRC."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    position, chunks = 8, {}
    while position < len(data):
        (length,) = struct.unpack(">I", data[position : position + 4])
        kind = data[position + 4 : position + 8]
        body = data[position + 8 : position + 8 + length]
        (crc,) = struct.unpack(">I", data[position + 8 + length : position + 12 + length])
        assert crc == zlib.crc32(kind + body)
        chunks[kind] = chunks.get(kind, b"") + body
        position += 12 + length
    width, height, depth, colour, _, _, _ = struct.unpack(">IIBBBBB", chunks[b"IHDR"])
    assert (depth, colour) == (8, 2) and b"IEND" in chunks
    rows = np.frombuffer(zlib.decompress(chunks[b"IDAT"]), dtype=np.uint8).reshape(height, -1)
    assert (rows[:, 0] == 0).all()
    return rows[:, 1:].reshape(height, width, 3)


def test_png_round_trip():
    image = np.random.default_rng(0).integers(0, 256, size=(7, 11, 3), dtype=np.uint8)
    assert np.array_equal(read_png(encode_png(image)), image)
    with pytest.raises(GoniometerError, match="uint8"):
        encode_png(image.astype(np.float32))


def test_the_numpy_drawing_marks_every_measured_radius_in_both_panels(surface):
    points = radius_sweep(surface, [0.01, 0.0, 0.0], 0.02, 0.6, 9)
    image = read_png(encode_png(sweep_plot.draw_sweep(*sweep_plot.sweep_series(points))))
    assert image.shape == (sweep_plot.HEIGHT, sweep_plot.WIDTH, 3)
    span = sweep_plot.WIDTH - sweep_plot._RIGHT - sweep_plot._LEFT
    for point in points:
        x = int(np.rint(sweep_plot._LEFT + (point.radius - 0.02) / 0.58 * span))
        angle_panel = image[slice(*sweep_plot._ANGLE_PANEL), x]
        fit_panel = image[slice(*sweep_plot._FIT_PANEL), x]
        has_angle = (angle_panel == sweep_plot._ANGLE_COLOUR).all(axis=1).any()
        has_fit = (fit_panel == sweep_plot._FIT_COLOUR).all(axis=1).any()
        assert has_angle == has_fit == (point.measurement is not None)


def test_matplotlib_plot_has_both_panels_labels_and_the_refused_radii(surface, tmp_path):
    pytest.importorskip("matplotlib", reason="requirements/report.txt")
    from vg_addon.formats import mpl_plots

    points = radius_sweep(surface, [0.01, 0.0, 0.0], 0.02, 0.6, 9)
    radii, angles, fits = (np.array(v) for v in sweep_plot.sweep_series(points))
    refused = np.isnan(angles)
    assert 0 < refused.sum() < len(points)
    figure = mpl_plots.sweep_figure(
        radii, angles, fits, width=800, height=560, dpi=120, units="mm", title="Wedge, site 1"
    )
    top, bottom = figure.axes
    assert figure.get_suptitle() == "Wedge, site 1"
    assert (top.get_ylabel(), bottom.get_ylabel()) == ("angle (°)", "fit error (mm²)")
    assert bottom.get_xlabel() == "radius (mm)" and bottom.get_yscale() == "log"
    angle_line, crosses = top.get_lines()
    assert np.array_equal(angle_line.get_xdata(), radii)
    assert np.array_equal(angle_line.get_ydata(), angles, equal_nan=True)  # a gap where refused
    assert np.array_equal(crosses.get_xdata(), radii[refused])
    legend = [t.get_text() for t in top.get_legend().get_texts()]
    assert legend == ["angle", f"refused ({refused.sum()})"]
    # Fits of 0 (rounding-exact on this wedge) have no place on the log axis: marks at its foot.
    exact = ~refused & (fits == 0)
    fit_line, exact_marks = bottom.get_lines()
    assert exact.any()
    assert np.array_equal(fit_line.get_ydata(), np.where(exact, np.nan, fits), equal_nan=True)
    assert np.array_equal(exact_marks.get_xdata(), radii[exact])
    path = tmp_path / "sweep.png"
    sweep_plot.write_sweep_png(path, points, units="mm", title="Wedge, site 1")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_matplotlib_sweep_images_are_exactly_the_size_asked_for(surface):
    pytest.importorskip("matplotlib", reason="requirements/report.txt")
    from vg_addon.formats import mpl_plots

    series = sweep_plot.sweep_series(radius_sweep(surface, [0.01, 0.0, 0.0], 0.02, 0.6, 5))
    # 251 / 100 × 100 falls just short of a whole pixel.
    for width, height in ((480, 251), (640, 413), (801, 559), (800, 560), (517, 339)):
        for dpi in (100, 120):
            figure = mpl_plots.sweep_figure(*series, width=width, height=height, dpi=dpi)
            assert mpl_plots.rgba(figure).shape == (height, width, 4)
            data = mpl_plots.png(figure)
            assert struct.unpack(">II", data[16:24]) == (width, height)


@pytest.mark.parametrize("fits", [[0.0, 1e-6, 1e-4], [0.0, 0.0, 0.0]], ids=["one", "all"])
def test_the_numpy_drawing_marks_an_exact_fit_at_the_foot_not_as_the_smallest(fits):
    # Before, a fit of exactly 0 was drawn as a point where the smallest positive fit is, on
    # the panel's floor (with all fits 0, on an axis of 1E-300 to 1E-299); matplotlib's drawing
    # marks it at the panel's foot, with no point.
    radii = [0.1, 0.2, 0.3]
    image = sweep_plot.draw_sweep(radii, [90.0, 91.0, 92.0], fits)
    span = sweep_plot.WIDTH - sweep_plot._RIGHT - sweep_plot._LEFT
    top, bottom = sweep_plot._FIT_PANEL
    fit_coloured = (image == sweep_plot._FIT_COLOUR).all(axis=2)
    for radius, fit in zip(radii, fits, strict=True):
        x = int(np.rint(sweep_plot._LEFT + (radius - 0.1) / 0.2 * span))
        if fit > 0:
            assert fit_coloured[top : bottom + 4, x - 3 : x + 4].sum() >= 20  # its point
        else:
            assert not fit_coloured[bottom - 2 : bottom + 4, x - 3 : x + 4].any()  # no point
            assert fit_coloured[bottom - 20 : bottom - 2, x - 6 : x + 7].any()  # its mark
