"""A minimal PNG writer (8-bit RGB, no dependencies but zlib), for plots the user can open."""

from __future__ import annotations

import struct
import zlib

import numpy as np

from ..errors import GoniometerError

_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def _chunk(kind: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def encode_png(image: np.ndarray) -> bytes:
    """The bytes of a PNG file holding ``image``, an ``(height, width, 3)`` uint8 RGB array."""
    image = np.asarray(image)
    if image.ndim != 3 or image.shape[2] != 3 or image.dtype != np.uint8 or 0 in image.shape:
        raise GoniometerError(
            f"A PNG image must be a non-empty (height, width, 3) uint8 array; got {image.dtype} "
            f"{image.shape}."
        )
    height, width = image.shape[:2]
    rows = np.zeros((height, 1 + 3 * width), dtype=np.uint8)  # filter byte 0: no filter
    rows[:, 1:] = image.reshape(height, 3 * width)
    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return (
        _SIGNATURE
        + _chunk(b"IHDR", header)
        + _chunk(b"IDAT", zlib.compress(rows.tobytes(), 9))
        + _chunk(b"IEND", b"")
    )
