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
    rows = np.zeros((height, 1 + channels * width), dtype=np.uint8)  # filter byte 0: no filter
    rows[:, 1:] = image.reshape(height, channels * width)
    colour_type = 2 if channels == 3 else 6
    header = struct.pack(">IIBBBBB", width, height, 8, colour_type, 0, 0, 0)
    return (
        _SIGNATURE
        + _chunk(b"IHDR", header)
        + _chunk(b"IDAT", zlib.compress(rows.tobytes(), level))
        + _chunk(b"IEND", b"")
    )
