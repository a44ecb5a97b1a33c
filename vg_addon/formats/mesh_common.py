"""What the mesh file readers share: :class:`MeshData`, reading a file's bytes, checking and
finishing what a reader parsed, and the vectorised text scanning of ASCII formats."""

from __future__ import annotations

import os
import re
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import GoniometerError


@dataclass(frozen=True, eq=False)
class MeshData:
    """A mesh or point cloud read from a file.

    Attributes
    ----------
    points : numpy.ndarray
        ``(n, 3)`` float64 vertex coordinates, in file order.
    triangles : numpy.ndarray or None
        ``(m, 3)`` int64 vertex indices (polygons fan-triangulated, file order kept), or ``None``
        when the file holds no faces (a point cloud).
    normals : numpy.ndarray or None
        ``(n, 3)`` float64 per-vertex normals as stored in the file (not normalised), or ``None``
        when the file has none, they do not map one-to-one to the vertices, or any is not finite.
    name : str
        The file name without its extension.
    source_dtype : str
        Precision of the coordinates in the file: the declared PLY type of ``x`` (``"float32"``,
        ``"float64"``, ...), ``"float32"`` for binary STL, ``"float64"`` for text formats
        without a declared type (OBJ, ASCII STL).
    polygons : tuple of numpy.ndarray or None
        ``(corners, sizes)``: the faces as the file gives them, each face's vertex indices in
        turn (int64) and each face's corner count (int64, faces of three corners or more), where
        a face is not a triangle; ``None`` where every face is one. Blender fills a polygon
        with other triangles than ``triangles``' fans: a Blender mesh made from a file is made
        from these (see ``batch.sources``).
    """

    points: np.ndarray
    triangles: np.ndarray | None
    normals: np.ndarray | None
    name: str
    source_dtype: str
    polygons: tuple[np.ndarray, np.ndarray] | None = None

    @property
    def n_vertices(self) -> int:
        """Number of vertices."""
        return int(self.points.shape[0])

    @property
    def n_triangles(self) -> int:
        """Number of triangles (0 for a point cloud)."""
        return 0 if self.triangles is None else int(self.triangles.shape[0])


# ----------------------------------------------------------------------------------------- common


def _as_path(path) -> Path:
    try:
        return Path(os.fspath(path))
    except TypeError:
        raise GoniometerError(
            f"Expected a file path for the mesh, got {type(path).__name__}."
        ) from None


def _read_bytes(path: Path) -> bytes:
    if not path.exists():
        raise GoniometerError(
            f"Mesh file not found: '{path}'. Check the path and that the file was not moved."
        )
    if path.is_dir():
        raise GoniometerError(f"'{path}' is a folder, not a mesh file; choose the file inside it.")
    try:
        data = path.read_bytes()
    except OSError as error:
        raise GoniometerError(
            f"Could not read '{path}': {error.strerror or error}. Check the file's permissions."
        ) from None
    if not data:
        raise GoniometerError(f"'{path}' is empty (0 bytes); re-export the mesh.")
    return data


def _finish(path: Path, points, triangles, normals, source_dtype: str, polygons=None) -> MeshData:
    """Validate what a reader found and pack it into fresh, writable, contiguous arrays.
    ``polygons``: the faces as :func:`_polygons` keeps them."""
    points = np.array(points, dtype=np.float64, order="C").reshape(-1, 3)
    n = points.shape[0]
    if n == 0:
        raise GoniometerError(f"'{path}' has no vertices; the file holds nothing to measure.")
    finite = np.isfinite(points).all(axis=1)
    if not finite.all():
        bad = np.flatnonzero(~finite)
        raise GoniometerError(
            f"'{path}': {bad.size} vertices have coordinates that are not finite (NaN or "
            f"infinity), the first is vertex {bad[0]}. Repair or re-export the mesh."
        )
    if triangles is not None:
        triangles = np.array(triangles, dtype=np.int64, order="C").reshape(-1, 3)
        if triangles.size:
            low, high = int(triangles.min()), int(triangles.max())
            if low < 0 or high >= n:
                bad_value = low if low < 0 else high
                first = int(np.flatnonzero(((triangles < 0) | (triangles >= n)).any(axis=1))[0])
                raise GoniometerError(
                    f"'{path}': face index out of range: a face refers to vertex {bad_value} "
                    f"(counting from 0; the first bad one is in triangle {first}, polygons "
                    f"split into triangles), but the file has {n} vertices (valid 0..{n - 1}). "
                    "The file is corrupt or was written incorrectly; re-export it."
                )
        else:
            triangles = None
    if normals is not None:
        normals = np.array(normals, dtype=np.float64, order="C").reshape(-1, 3)
        if normals.shape[0] != n or not np.isfinite(normals).all():
            normals = None
    if triangles is None:
        polygons = None
    return MeshData(points, triangles, normals, path.stem, source_dtype, polygons)


def _polygons(flat: np.ndarray, counts: np.ndarray):
    """The faces of three corners or more as ``(corners, sizes)`` (int64), where one is not a
    triangle; ``None`` where every face is one (or none is a face)."""
    counts = np.asarray(counts, dtype=np.int64)
    if counts.size == 0 or (counts == 3).all():
        return None
    kept = counts >= 3
    owner = np.repeat(kept, counts)
    polygons = (np.ascontiguousarray(flat[owner], dtype=np.int64), counts[kept].copy())
    return None if (polygons[1] == 3).all() else polygons


def _fan(flat: np.ndarray, counts: np.ndarray) -> np.ndarray:
    """Fan-triangulate polygons given as a flat index array and per-polygon counts.

    Polygon ``(v0, v1, ..., vk-1)`` becomes ``(v0, v1, v2), (v0, v2, v3), ...``; polygons with
    fewer than three vertices give no triangle. Triangles keep the polygons' order.
    """
    counts = np.asarray(counts, dtype=np.int64)
    if counts.size == 0:
        return np.empty((0, 3), np.int64)
    k = int(counts[0])
    if (counts == k).all():
        if k < 3:
            return np.empty((0, 3), np.int64)
        polygons = flat.reshape(-1, k)
        if k == 3:
            return polygons
        fans = [polygons[:, [0, j, j + 1]] for j in range(1, k - 1)]
        return np.stack(fans, axis=1).reshape(-1, 3)
    starts = np.cumsum(counts) - counts
    n_tri = np.maximum(counts - 2, 0)
    owner = np.repeat(np.arange(counts.size), n_tri)
    first = np.cumsum(n_tri) - n_tri
    j = np.arange(owner.size) - np.repeat(first, n_tri) + 1
    base = starts[owner]
    return np.stack([flat[base], flat[base + j], flat[base + j + 1]], axis=1)


_NOT_BLANK = re.compile(rb"\S")


def _parse_numbers(text: bytes, dtype=np.float64) -> np.ndarray | None:
    """All whitespace-separated numbers in ``text`` (as ``dtype``), or None if a token is not
    one."""
    if _NOT_BLANK.search(text) is None:
        return np.empty(0, dtype)  # np.fromstring returns [-1.0] for blank text
    with warnings.catch_warnings():
        warnings.simplefilter("error", DeprecationWarning)
        try:
            return np.fromstring(text, dtype=dtype, sep=" ")
        except (ValueError, DeprecationWarning):
            return None


_NOT_A_NUMBER = re.compile(
    rb"(?<!\S)(?![+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?(?!\S)|[+-]?(?i:nan|inf(?:inity)?)(?!\S))\S+"
)


def _where_not_a_number(data: bytes, pos: int) -> str:
    """``", line N ('token')"`` for the first word from ``pos`` on that is not a number (only
    for error messages), or ``""`` if none is found."""
    found = _NOT_A_NUMBER.search(data, pos)
    if found is None:
        return ""
    line = data.count(b"\n", 0, found.start()) + 1
    word = found.group().decode("utf-8", "replace")[:40]
    return f", line {line} ({word!r})"


# -------------------------------------------------------------------------------------------- OBJ


_SPACE = np.uint8(32)
_SLASH = np.uint8(ord("/"))
_MINUS = np.uint8(ord("-"))


def _blank(buffer: np.ndarray) -> np.ndarray:
    """Mask of the ASCII whitespace bytes (tab, newline, vertical tab, form feed, carriage
    return, space): the separators ``np.fromstring`` and ``bytes.split`` use."""
    return ((buffer - np.uint8(9)) < 5) | (buffer == _SPACE)


class _Text:
    """Line and word structure of a text file, found with NumPy over its bytes."""

    def __init__(self, data: bytes, path: Path):
        self.path = path
        self.buffer = np.frombuffer(data + b"\n", np.uint8)
        self.blank = _blank(self.buffer)
        self.ends = np.flatnonzero(self.buffer == 10)  # each line's newline
        starts = np.concatenate([[0], self.ends[:-1] + 1])
        first = starts.copy()
        todo = np.flatnonzero(self.blank[first] & (first < self.ends))
        while todo.size:  # step over leading blanks: one pass per blank column, not per line
            first[todo] += 1
            todo = todo[self.blank[first[todo]] & (first[todo] < self.ends[todo])]
        self.first = first  # first non-blank byte of each line (its newline if the line is blank)

    def keyword(self, word: bytes, ignore_case: bool = False) -> np.ndarray:
        """Indices of the lines whose first word is ``word`` (a lower-case word; with
        ``ignore_case``, in capitals too)."""
        after = self.first + len(word)
        match = after <= self.ends
        for k, byte in enumerate(word):
            found = self.buffer[np.minimum(self.first + k, self.ends)]
            if ignore_case and chr(byte).isalpha():
                found = found | 0x20  # ASCII capitals to lower case
            match &= found == byte
        return np.flatnonzero(match & self.blank[np.minimum(after, self.ends)])

    def body(self, lines: np.ndarray, skip: int) -> tuple[np.ndarray, np.ndarray]:
        """Mask of the bytes after the first ``skip`` bytes of each line in ``lines``, and the
        position where each of those parts begins."""
        begin = self.first[lines] + skip
        end = self.ends[lines]
        keep = begin < end
        inside = np.zeros(self.buffer.size + 1, np.int8)
        inside[begin[keep]] = 1
        inside[end[keep]] = -1
        return np.cumsum(inside, dtype=np.int8)[:-1].view(bool), begin

    @staticmethod
    def word_starts(mask: np.ndarray, separator: np.ndarray) -> np.ndarray:
        """Mask of the first byte of each run of non-separator bytes inside ``mask``."""
        inside = mask & ~separator
        starts = inside.copy()
        starts[1:] &= ~inside[:-1]
        return starts

    @staticmethod
    def per_segment(positions: np.ndarray, begin: np.ndarray) -> np.ndarray:
        """How many of the sorted ``positions`` lie between consecutive ``begin`` positions
        (the last segment runs to the end)."""
        at = np.searchsorted(positions, begin)
        return np.diff(at, append=positions.size).astype(np.int64)

    def word_counts(self, lines: np.ndarray) -> np.ndarray:
        """How many words each of the given lines holds."""
        mask, begin = self.body(lines, 0)
        return self.per_segment(np.flatnonzero(self.word_starts(mask, self.blank)), begin)

    def floats(self, lines: np.ndarray, skip: int, what: str) -> tuple[np.ndarray, np.ndarray]:
        """All numbers after the first ``skip`` bytes of the given lines, as float64, and how
        many each line holds."""
        mask, begin = self.body(lines, skip)
        counts = self.per_segment(np.flatnonzero(self.word_starts(mask, self.blank)), begin)
        values = _parse_numbers(np.where(mask, self.buffer, _SPACE).tobytes())
        if values is None or values.size != counts.sum():
            raise GoniometerError(
                f"'{self.path}', line {self._bad_line(lines, begin)}: cannot read the numbers "
                f"of this {what} line; the file is corrupt."
            )
        return values, counts

    def _bad_line(self, lines: np.ndarray, begin: np.ndarray, convert=float) -> int:
        """Line number (1-based) of the first line holding a word that ``convert`` rejects;
        only called to word an error message."""
        for line, at in zip(lines, begin, strict=True):
            text = self.buffer[at : self.ends[line]].tobytes().replace(b"/", b" ")
            try:
                [convert(word) for word in text.split()]
            except ValueError:
                return int(line) + 1
        return int(lines[-1]) + 1 if lines.size else 1

    def faces(self, lines: np.ndarray):
        """Face corners of ``f`` lines, each ``i``, ``i/t``, ``i//n`` or ``i/t/n``.

        Returns ``(vertex, normal, counts)``: the raw (1-based or negative) vertex reference of
        each corner, its normal reference (None unless every corner has one) and the number of
        corners per line.
        """
        mask, begin = self.body(lines, 1)
        slash = mask & (self.buffer == _SLASH)
        corners = np.flatnonzero(self.word_starts(mask, self.blank))
        counts = self.per_segment(corners, begin)
        part_inside = mask & ~self.blank & ~slash
        edges = np.diff(part_inside.view(np.int8), prepend=np.int8(0))
        part_starts = np.flatnonzero(edges == 1)
        part_stops = np.flatnonzero(edges == -1)  # the byte after each part
        parts = _parse_integers(self.buffer, part_starts, part_stops)
        if parts is None:
            raise GoniometerError(
                f"'{self.path}', line {self._bad_line(lines, begin, int)}: cannot read the indices "
                "of this 'f' line; the file is corrupt."
            )
        if corners.size and (self.buffer[corners] == _SLASH).any():
            bad = corners[self.buffer[corners] == _SLASH][0]
            line = int(lines[np.searchsorted(begin, bad, side="right") - 1]) + 1
            raise GoniometerError(f"'{self.path}', line {line}: a face corner has no vertex index.")
        n_parts = self.per_segment(part_starts, corners)
        n_slashes = self.per_segment(np.flatnonzero(slash), corners)
        first_part = np.cumsum(n_parts) - n_parts
        # A corner ends in a slash when the byte after its last part is one (1/, 1//, 1/2/).
        bad = n_slashes > 2
        if corners.size:
            bad |= self.buffer[part_stops[first_part + n_parts - 1]] == _SLASH
        if bad.any():
            k = int(np.argmax(bad))
            line = int(lines[np.searchsorted(begin, corners[k], side="right") - 1]) + 1
            corner = self.buffer[corners[k] : self.ends[line - 1]].tobytes().split()[0]
            raise GoniometerError(
                f"'{self.path}', line {line}: the face corner "
                f"{corner[:40].decode('utf-8', 'replace')!r} is not one of i, i/t, i//n or "
                "i/t/n; the file is corrupt."
            )
        vertex = parts[first_part]
        normal = None
        if corners.size and (n_slashes == 2).all() and (n_parts >= 2).all():
            normal = parts[first_part + n_parts - 1]  # i//n and i/t/n: the last part
        return vertex, normal, counts


def _parse_integers(buffer: np.ndarray, starts: np.ndarray, stops: np.ndarray):
    """Decimal integers (optional leading '-') at ``buffer[starts[k]:stops[k]]``, or None if
    any is not one. Vectorised digit by digit: much faster than text-to-float parsing."""
    if starts.size == 0:
        return np.zeros(0, np.int64)
    negative = buffer[starts] == _MINUS
    first = starts + negative
    length = stops - first
    if length.min() < 1 or length.max() > 18:
        return None
    value = np.zeros(starts.size, np.int64)
    for k in range(int(length.max())):
        if k < length.min():
            digit = buffer[first + k] - np.uint8(48)  # non-digits wrap around to > 9
            if (digit > 9).any():
                return None
            value = value * 10 + digit
        else:
            active = np.flatnonzero(length > k)
            digit = buffer[first[active] + k] - np.uint8(48)
            if (digit > 9).any():
                return None
            value[active] = value[active] * 10 + digit
    return np.where(negative, -value, value)


def _check_face_indices(flat, counts, n, path, lines=None) -> None:
    """Refuse a face index outside ``0..n-1`` (also in faces of fewer than three vertices,
    which give no triangle), naming the face's line (``lines``, ASCII) or its number."""
    bad = (flat < 0) | (flat >= n)
    if bad.any():
        k = int(np.argmax(bad))
        face = int(np.searchsorted(np.cumsum(counts), k, side="right"))
        where = (
            f"'{path}', line {lines[face]}"
            if lines is not None
            else f"'{path}', face {face} (from 0)"
        )
        raise GoniometerError(
            f"{where}: face index out of range: the face refers to vertex {flat[k]} (counting "
            f"from 0), but the file has {n} vertices (valid 0..{n - 1}). The file is corrupt or "
            "was written incorrectly; re-export it."
        )


def _gather(buffer: np.ndarray, offsets: np.ndarray, dtype: np.dtype) -> np.ndarray:
    """The values of type ``dtype`` stored at byte ``offsets`` of ``buffer``."""
    at = offsets[:, None] + np.arange(dtype.itemsize)
    return np.ascontiguousarray(buffer[at]).view(dtype).reshape(-1)
