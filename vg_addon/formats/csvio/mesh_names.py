"""Which mesh a CSV row names: a name as written, as typed, or as MeshLab writes a file name."""

from __future__ import annotations

import re
import unicodedata
from collections.abc import Iterable, Sequence

from ...errors import GoniometerError, bounded_list
from ..meshio import MESH_EXTENSIONS
from .replication import ReplicationRow

# File extensions a CSV's mesh name may carry (MeshLab writes the scan's file name): those this
# package reads (meshio's registry) and the other mesh formats MeshLab and Blender open.
_MESH_FILE_SUFFIXES = frozenset(MESH_EXTENSIONS) | {
    ".off",
    ".glb",
    ".gltf",
    ".fbx",
    ".dae",
    ".x3d",
    ".wrl",
    ".3ds",
    ".abc",
    ".usd",
    ".usda",
    ".usdc",
    ".usdz",
    ".vtk",
}


def _split_names(names) -> tuple[str, ...]:
    if isinstance(names, str):
        return (names,)
    return tuple(str(name) for name in names)


def _mesh_stem(name: str) -> str:
    # MeshLab writes the scan's file name (maybe with a folder); strip the folder and a mesh
    # file extension only, so Blender's "bone.001" stays distinct from "bone".
    base = re.split(r"[\\/]", name)[-1]
    stem, dot, suffix = base.rpartition(".")
    if dot and stem and "." + suffix.casefold() in _MESH_FILE_SUFFIXES:
        return stem
    return base


def mesh_stem(name: str) -> str:
    """A mesh name without a folder and a mesh file extension (``scans/bone.ply`` -> ``bone``;
    Blender's ``bone.001`` stays as it is)."""
    return _mesh_stem(name.strip())


def mesh_name_match(csv_name: str | None, names) -> int | None:
    """How closely a CSV's mesh name refers to a mesh known by ``names``: 0 exactly (surrounding
    spaces included: a mesh file " lead.ply" is the mesh " lead"), 1 without its surrounding
    spaces (a hand-typed cell), 2 after dropping a folder and a mesh file extension
    (``"scans/bone_12.ply"`` matches ``"bone_12"``), 3 where only the Unicode normalisation
    differs (``café`` typed as one character or as ``e`` and a combining accent, as macOS keeps
    file names: the two look alike); None when it does not. A blank name is 2 for any mesh."""
    given = csv_name or ""
    if not given.strip():
        return 2
    candidates = set(_split_names(names))
    if given in candidates:
        return 0
    if given.strip() in candidates:
        return 1
    if any(_mesh_stem(name) in candidates for name in (given, given.strip())):
        return 2
    composed = {unicodedata.normalize("NFC", name) for name in candidates}
    if any(
        unicodedata.normalize("NFC", name) in composed
        for name in (given, given.strip(), _mesh_stem(given), _mesh_stem(given.strip()))
    ):
        return 3
    return None


def mesh_name_matches(csv_name: str | None, names) -> bool:
    """Whether a CSV's mesh name refers to a mesh known by ``names`` (see
    :func:`mesh_name_match`).

    Parameters
    ----------
    csv_name : str or None
        The row's mesh name. Blank or ``None`` matches any mesh.
    names : str or iterable of str
        The mesh's names, e.g. its object name and its mesh data name.
    """
    return mesh_name_match(csv_name, names) is not None


def rows_for_mesh(rows: Iterable[ReplicationRow], mesh_name) -> list[ReplicationRow]:
    """The rows that refer to ``mesh_name`` (str or several names), or name no mesh at all."""
    return [row for row in rows if mesh_name_matches(row.mesh_name, mesh_name)]


def rows_for_other_meshes(rows: Iterable[ReplicationRow], mesh_name) -> list[ReplicationRow]:
    """The rows that name another mesh than ``mesh_name`` (str or several names)."""
    return [row for row in rows if not mesh_name_matches(row.mesh_name, mesh_name)]


def check_mesh_names(rows: Sequence[ReplicationRow], mesh_name, *, source="the CSV") -> None:
    """Raise if any row names another mesh than ``mesh_name`` (str or several names).

    Raises
    ------
    GoniometerError
        Listing those rows' numbers and names (the first 20) and what to do.
    """
    others = rows_for_other_meshes(rows, mesh_name)
    if not others:
        return
    shown = next(iter(_split_names(mesh_name)), "")
    listed = bounded_list(f"{row.row_number} ({row.mesh_name!r})" for row in others)
    raise GoniometerError(
        f"{len(others)} row(s) of {source} name another mesh than '{shown}': rows {listed}. "
        "Nothing was imported. Select the mesh they were measured on, or ignore the mesh names "
        "to measure them on this one."
    )
