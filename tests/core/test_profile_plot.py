"""The profile plot image and the PNG writer, checked by decoding the file by hand."""

import struct
import zlib

import numpy as np
import pytest

from vg_addon import GoniometerError
from vg_addon.formats import profile_plot


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
    image = profile_plot.render_profile(arc, angles, width=400, height=200)
    assert image.shape == (200, 400, 4) and image.dtype == np.uint8
    to_x, to_y, x_range, y_range = profile_plot.plot_frame(arc, angles, 400, 200)
    assert x_range == (0.0, 4.0) and y_range[0] < 80.0 and y_range[1] > 120.0
    for a, b in zip(arc, angles, strict=True):
        column, row = round(float(to_x(a))), round(float(to_y(b)))
        assert tuple(image[row, column]) == profile_plot.DOTS
    # Higher angles are higher up; the first station is at the left edge of the axes.
    assert to_y(120.0) < to_y(80.0) and round(float(to_x(0.0))) == 48


def test_a_constant_profile_is_a_flat_line_in_the_middle():
    image = profile_plot.render_profile([0, 1, 2], [70.5, 70.5, 70.5], width=300, height=160)
    line_rows = np.flatnonzero((image[:, 100] == profile_plot.LINE).all(axis=1))
    assert line_rows.size and abs(line_rows.mean() - (10 + 136) / 2) <= 2


def test_png_round_trips_and_never_overwrites(tmp_path):
    image = profile_plot.render_profile([0, 2.5], [91.0, 93.5])
    path = tmp_path / "edge.png"
    profile_plot.write_png(path, image)
    assert np.array_equal(decode_png(path.read_bytes()), image)
    with pytest.raises(GoniometerError, match="already exists"):
        profile_plot.write_png(path, image)


def test_nice_ticks_are_round_and_inside():
    ticks = profile_plot.nice_ticks(71.3, 118.2)
    assert ticks.tolist() == [80.0, 90.0, 100.0, 110.0]
    assert profile_plot.nice_ticks(0.0, 0.9).tolist() == pytest.approx([0.0, 0.2, 0.4, 0.6, 0.8])


def test_bad_input_is_refused():
    with pytest.raises(GoniometerError, match="one finite arc length"):
        profile_plot.render_profile([0, 1], [90.0])
    with pytest.raises(GoniometerError, match="at least 160"):
        profile_plot.render_profile([0], [90.0], width=50, height=50)
