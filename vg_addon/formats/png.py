"""The one PNG writer (8-bit RGB or RGBA, no dependencies but zlib), for plots the user can open."""

from __future__ import annotations

import struct
import zlib

import numpy as np

from ..errors import GoniometerError

_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def _chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def encode_png(image: np.ndarray, *, level: int = 9) -> bytes:
    """The bytes of a PNG file holding ``image``, an ``(height, width, 3)`` (RGB) or
    ``(height, width, 4)`` (RGBA) uint8 array, row 0 at the top; ``level``: zlib's compression
    level."""
    header, height, rows = _scanlines(image)
    return (
        _SIGNATURE
        + header
        + _chunk(b"IDAT", zlib.compress(rows(0, height), level))
        + _chunk(b"IEND", b"")
    )


def write_png(path, image: np.ndarray, *, level: int = 6, block_rows: int = 256) -> None:
    """Write ``image`` (as for :func:`encode_png`) to the file ``path``, compressed
    ``block_rows`` rows at a time: a picture too large to copy whole in memory (a contact sheet
    of many views) costs only its own array and one block more."""
    header, height, rows = _scanlines(image)
    compressor = zlib.compressobj(level)
    with open(path, "wb") as file:
        file.write(_SIGNATURE + header)
        for top in range(0, height, block_rows):
            data = compressor.compress(rows(top, min(top + block_rows, height)))
            if data:
                file.write(_chunk(b"IDAT", data))
        file.write(_chunk(b"IDAT", compressor.flush()) + _chunk(b"IEND", b""))


def _scanlines(image):
    """The IHDR chunk of ``image``, its height, and a function giving its rows
    ``[top, bottom)`` as PNG scanlines (filter byte 0: no filter)."""
    image = np.asarray(image)
    if (
        image.ndim != 3
        or image.shape[2] not in (3, 4)
        or image.dtype != np.uint8
        or 0 in image.shape
    ):
        raise GoniometerError(
            f"A PNG image must be a non-empty (height, width, 3 or 4) uint8 array; got "
            f"{image.dtype} {image.shape}."
        )
    height, width, channels = image.shape
    flat = image.reshape(height, channels * width)

    def rows(top: int, bottom: int) -> bytes:
        lines = np.zeros((bottom - top, 1 + channels * width), dtype=np.uint8)
        lines[:, 1:] = flat[top:bottom]
        return lines.tobytes()

    colour_type = 2 if channels == 3 else 6
    header = struct.pack(">IIBBBBB", width, height, 8, colour_type, 0, 0, 0)
    return _chunk(b"IHDR", header), height, rows
