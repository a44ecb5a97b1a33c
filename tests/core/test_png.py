"""The PNG writer streamed a block of rows at a time, read back by Pillow (an independent
decoder)."""

import io

import numpy as np
import pytest

from vg_addon.formats.png import encode_png, write_png

Image = pytest.importorskip("PIL.Image", reason="Pillow (matplotlib's dependency) reads the PNGs")


@pytest.mark.parametrize("channels", [3, 4])
def test_a_picture_written_in_blocks_reads_back_whole(tmp_path, channels):
    image = np.random.default_rng(7).integers(0, 256, (700, 93, channels), dtype=np.uint8)
    image[300:420] = 255  # a run that compresses, between blocks
    path = tmp_path / "sheet.png"
    write_png(path, image, block_rows=256)
    data = path.read_bytes()
    assert data.count(b"IDAT") > 1  # written in pieces, not held whole
    with Image.open(path) as read:
        assert read.mode == ("RGB" if channels == 3 else "RGBA")
        assert np.array_equal(np.asarray(read), image)
    with Image.open(io.BytesIO(encode_png(image))) as read:
        assert np.array_equal(np.asarray(read), image)
