"""Planning a batch run: which point is measured on which mesh, in what order, by which shard.

Pure Python (no NumPy, no Blender): ``vg_batch.py`` turns its command line into a list of
:class:`Task` objects here, then measures them in Blender. The plan fixes everything a task's
output row depends on apart from the measurement itself (its position in the output, its
``Measurement #`` and ``Break #``), so that sharded and parallel runs produce the same rows as a
single run.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

from ..errors import GoniometerError, bounded_list
from ..formats.csvio import ReplicationRow, mesh_name_match
from ..formats.meshio import MESH_EXTENSIONS
from ..method.algorithm import DEFAULT_RULE
from ..method.inputs import as_center, as_lambda, as_radius
from ..method.surface import check_patch_mode

STOPPED_EDGE = "the run was stopped before this edge"
"""Why an edge a run had not measured when it was stopped has no figures (its row's error)."""


@dataclass(frozen=True)
class Task:
    """One point to measure on one mesh: one row of the output CSV.

    Attributes
    ----------
    index : int
        Position in the whole run's output (0-based), before any sharding.
    mesh : int
        Index of the mesh in the run's mesh list, or -1 when the row matches no mesh (then
        ``error`` says why).
    center : tuple of 3 float
        Requested centre, in the mesh's units.
    radius : float or None
        Patch radius (None only for a task with an ``error``).
    lam : float
        λ, the segmentation parameter.
    patch : str
        ``"euclidean"`` or ``"geodesic"``.
    label : str
        Free text recorded with the measurement (the CSV's ``User Data``).
    number : int
        ``Measurement #`` on its mesh: the task's 1-based position among that mesh's tasks
        (a failed row keeps its number, leaving a gap).
    break_number : int or None
        ``Break #`` from the points CSV; None: the object's current break.
    source_row : int or None
        The spreadsheet row of the points CSV it came from (None for ``--at`` points).
    mesh_name : str
        The mesh name as the input gave it (for rows that match no mesh).
    error : str
        Why this task cannot be measured at all; empty for a task to measure.
    coordinates : str
        ``"mesh"``: ``center`` and ``radius`` are in the mesh's own coordinates (every input
        but a world-space row, see :attr:`ReplicationRow.coordinates`); ``"world"``: in Blender
        world space, to be converted by the object's transform.
    default_radius : bool
        ``radius`` is the run's default (``--radius``), in mesh units whatever ``coordinates``
        says: a world-space row without its own radius keeps it as it is.
    rule : str
        ``"refined"``, ``"oriented"`` or ``"paper"``: a CSV row's own rule (MeshLab and earlier add-on rows
        carry the paper's), else the run's.
    units : str
        A CSV row's ``Units`` cell ("" where it has none): a run without ``--units`` takes the
        unit its rows name as the mesh's.
    requested : tuple of 3 float, or None
        Where an exported row's measurement was asked for (its ``Requested x/y/z``, in
        ``coordinates``): the row is measured at ``center`` and records this as its requested
        centre. None: ``center`` is what was asked for.
    """

    index: int
    mesh: int
    center: tuple[float, float, float]
    radius: float | None
    lam: float
    patch: str
    label: str = ""
    number: int = 0
    break_number: int | None = None
    source_row: int | None = None
    mesh_name: str = ""
    error: str = ""
    coordinates: str = "mesh"
    rule: str = DEFAULT_RULE
    units: str = ""
    default_radius: bool = False
    requested: tuple[float, float, float] | None = None


# --------------------------------------------------------------------------- command line values


def parse_shard(text: str) -> tuple[int, int]:
    """``"K/N"`` → ``(K, N)`` with ``1 <= K <= N``.

    Raises
    ------
    GoniometerError
        Anything else, with an example of the right form.
    """
    match = re.fullmatch(r"\s*(\d+)\s*/\s*(\d+)\s*", str(text))
    if match is None:
        raise GoniometerError(
            f"--shard {text!r} is not of the form K/N (e.g. --shard 3/10: the 3rd of 10 shares)."
        )
    k, n = int(match.group(1)), int(match.group(2))
    if n < 1 or not 1 <= k <= n:
        raise GoniometerError(
            f"--shard {text!r}: K must be from 1 to N and N at least 1 (e.g. --shard 1/{max(n, 2)})."
        )
    return k, n


def find_mesh_files(paths: Iterable[str | os.PathLike]) -> list[Path]:
    """The mesh files named by ``paths``: files as given, folders expanded to the PLY, OBJ and
    STL files directly inside them (sorted by name; subfolders are not searched).

    Raises
    ------
    GoniometerError
        Listing every path that does not exist, cannot be read, is not a PLY/OBJ/STL file, or is
        a folder without mesh files.
    """
    files, problems = [], []
    for given in paths:
        path = Path(given)
        if path.is_dir():
            try:
                found = sorted(
                    (
                        p
                        for p in path.iterdir()
                        if p.suffix.lower() in MESH_EXTENSIONS and p.is_file()
                    ),
                    key=lambda p: p.name,
                )
            except OSError as error:
                problems.append(f"{given}: cannot list the folder ({error.strerror or error})")
                continue
            if not found:
                problems.append(
                    f"{given}: a folder with no {', '.join(MESH_EXTENSIONS)} files directly in it"
                )
            files.extend(found)
        elif not path.exists():
            problems.append(f"{given}: no such file or folder")
        elif path.suffix.lower() not in MESH_EXTENSIONS:
            problems.append(
                f"{given}: not a mesh file this script reads (use {', '.join(MESH_EXTENSIONS)}, "
                "or a .blend with --object)"
            )
        elif not os.access(path, os.R_OK):
            problems.append(f"{given}: not readable (check its permissions)")
        else:
            files.append(path)
    if problems:
        raise GoniometerError(_listing("mesh input(s) cannot be used", problems))
    return files


def mesh_names(files: Sequence[str | os.PathLike]) -> list[str]:
    """The name each mesh file is known by: its file name without the extension.

    Raises
    ------
    GoniometerError
        Two files with the same name (e.g. ``a/bone.ply`` and ``b/bone.ply``): rows could not
        tell them apart.
    """
    names = [Path(f).stem for f in files]
    seen: dict[str, str] = {}
    clashes, repeats = [], []
    for name, path in zip(names, files, strict=True):
        if name not in seen:
            seen[name] = str(path)
        elif os.path.realpath(seen[name]) == os.path.realpath(path):
            repeats.append(
                f"{path}" + (f" (also as {seen[name]})" if seen[name] != str(path) else "")
            )
        else:
            clashes.append(f"{seen[name]} and {path} are both named {name!r}")
    if repeats:
        raise GoniometerError(
            _listing(
                "mesh file(s) given twice, as a file or in a folder given; give each once",
                repeats,
            )
        )
    if clashes:
        raise GoniometerError(
            _listing(
                "pair(s) of meshes share a name; rename one of each pair (a mesh is known by its "
                "file name without the extension)",
                clashes,
            )
        )
    return names


# --------------------------------------------------------------------------- planning


def plan_points(
    n_meshes: int,
    points: Sequence[Sequence[float]],
    *,
    radius,
    lam: float,
    patch: str,
    rule: str = DEFAULT_RULE,
) -> list[Task]:
    """Tasks for ``--at`` points: every point on every mesh (mesh by mesh, points in order).

    Raises
    ------
    GoniometerError
        No radius, or a bad radius, λ or patch mode.
    """
    if radius is None:
        raise GoniometerError("--at needs --radius R (the patch radius, in the mesh's units).")
    radius, lam, patch = _check_defaults(radius, lam, patch)
    tasks = []
    for mesh in range(n_meshes):
        for number, point in enumerate(points, start=1):
            tasks.append(
                Task(
                    index=len(tasks),
                    mesh=mesh,
                    center=_xyz(point),
                    radius=radius,
                    lam=lam,
                    patch=patch,
                    number=number,
                    rule=rule,
                )
            )
    return tasks


def plan_rows(
    meshes: Sequence[Sequence[str]],
    rows: Sequence[ReplicationRow],
    *,
    radius=None,
    lam: float = 2.0,
    patch: str = "euclidean",
    ignore_mesh_names: bool = False,
    source: str = "the points CSV",
    rule: str = DEFAULT_RULE,
) -> list[Task]:
    """Tasks for the rows of a points or measurements CSV, in file order.

    Parameters
    ----------
    meshes : sequence of sequences of str
        Per mesh, the names it is known by (its primary name first, e.g. the file name without
        extension; for a Blender object also its mesh data name).
    rows : sequence of csvio.ReplicationRow
    radius, lam, patch, rule
        Defaults for rows that carry none (``radius=None``: every row must carry one); rows
        from MeshLab and earlier add-on files carry the paper's rule.
    ignore_mesh_names : bool
        With a single mesh, measure every row on it whatever mesh the row names.
    source : str
        How messages name the CSV.

    Returns
    -------
    list of Task
        One per row. A row that names a mesh not given, or names none while several are given,
        becomes a task with mesh -1 and an ``error``.

    Raises
    ------
    GoniometerError
        Rows without a radius and no default radius; ``ignore_mesh_names`` with several meshes;
        several meshes and no row naming any (the CSV has no mesh column).
    """
    if not meshes:
        raise GoniometerError("No mesh to measure on: give at least one mesh file or object.")
    radius, lam, patch = _check_defaults(radius, lam, patch)
    missing = [row.row_number for row in rows if row.radius is None]
    if missing and radius is None:
        raise GoniometerError(
            f"{len(missing)} row(s) of {source} have no radius (rows {_numbers(missing)}): add a "
            "radius column or give --radius R as the default."
        )
    several = len(meshes) > 1
    if several and ignore_mesh_names:
        raise GoniometerError(
            "--ignore-mesh-names needs a single mesh: with several, each row's mesh name says "
            "which one to measure it on."
        )
    if several and rows and all(not (row.mesh_name or "").strip() for row in rows):
        primary = ", ".join(repr(names[0]) for names in meshes[:5])
        raise GoniometerError(
            f"{source} names no mesh, and {len(meshes)} meshes are given ({primary}"
            f"{', ...' if len(meshes) > 5 else ''}): add a 'mesh' column with each row's mesh "
            "(the file name without extension), or run one mesh at a time."
        )
    counters = [0] * len(meshes)
    tasks = []
    for row in rows:
        mesh, error = (0, "") if ignore_mesh_names else _match(row, meshes)
        number = 0
        if mesh >= 0:
            counters[mesh] += 1
            number = counters[mesh]
        tasks.append(
            Task(
                index=len(tasks),
                mesh=mesh,
                center=(row.x, row.y, row.z),
                radius=row.radius if row.radius is not None else radius,
                default_radius=row.radius is None,
                lam=row.lam if row.lam is not None else lam,
                patch=row.patch or patch,
                label=row.label or "",
                number=number,
                break_number=row.break_number,
                source_row=row.row_number,
                mesh_name=row.mesh_name or "",
                error=error,
                coordinates=row.coordinates,
                rule=row.rule or rule,
                units=row.units or "",
                requested=row.requested,
            )
        )
    return tasks


def _match(row: ReplicationRow, meshes: Sequence[Sequence[str]]) -> tuple[int, str]:
    """``(mesh index, "")`` for the mesh ``row`` names, or ``(-1, why not)``."""
    return closest_mesh(row.mesh_name, meshes, f"row {row.row_number}")


def closest_mesh(
    mesh_name: str | None, meshes: Sequence[Sequence[str]], where: str
) -> tuple[int, str]:
    """The one mesh ``mesh_name`` names, as ``(index in meshes, "")``, or ``(-1, why not)``
    (``where`` names the row or file in the reason).

    ``meshes`` holds each mesh's names, its primary name (its object's) first. The closest match
    wins: an exact name before one without surrounding spaces before a file stem, and a primary
    name before a mesh's other names (mesh data); a tie between meshes is no match.
    """
    closeness = {}
    for i, names in enumerate(meshes):
        primary, any_name = (mesh_name_match(mesh_name, n) for n in (names[:1], names))
        if any_name is not None:
            closeness[i] = (any_name, 0 if primary == any_name else 1)
    best = min(closeness.values(), default=None)
    found = [i for i, key in closeness.items() if key == best]
    if len(found) == 1:
        return found[0], ""
    if not found:
        known = ", ".join(repr(names[0]) for names in meshes[:10])
        more = ", ..." if len(meshes) > 10 else ""
        return -1, (
            f"{where} names mesh {mesh_name!r}, which is not among the meshes given "
            f"({known}{more}): give that mesh's file, or fix the name"
            + (" (or use --ignore-mesh-names)" if len(meshes) == 1 else "")
            + "."
        )
    if not (mesh_name or "").strip():
        return -1, f"{where} names no mesh, and several are given: fill in its mesh column."
    listed = ", ".join(repr(meshes[i][0]) for i in found)
    return -1, f"{where}: mesh name {mesh_name!r} fits several meshes ({listed}): rename one."


def _check_defaults(radius, lam, patch) -> tuple[float | None, float, str]:
    """The defaults validated by the core's own rules; ``radius`` may be None (no default).

    Every problem is reported at once, in the core's words.
    """
    checks = (
        ("radius", as_radius if radius is not None else (lambda value: None), radius),
        ("lam", as_lambda, lam),
        ("patch", check_patch_mode, patch),
    )
    values, problems = {}, []
    for name, check, value in checks:
        try:
            values[name] = check(value)
        except GoniometerError as error:
            problems.append(str(error))
    if problems:
        raise GoniometerError(" ".join(problems))
    return values["radius"], values["lam"], values["patch"]


def _xyz(point) -> tuple[float, float, float]:
    x, y, z = (float(v) for v in as_center(point))
    return x, y, z


# --------------------------------------------------------------------------- dividing the work


def shard(tasks: Sequence[Task], k: int, n: int) -> list[Task]:
    """The ``k``-th (1-based) of ``n`` contiguous, equal (±1 task) shares of ``tasks``.

    The shares, taken for ``k = 1 .. n`` and concatenated, are ``tasks`` again in order; a mesh
    is only loaded by the shards that hold some of its tasks.
    """
    if not 1 <= k <= n:
        raise GoniometerError(f"Shard {k}/{n}: K must be from 1 to N.")
    total = len(tasks)
    return list(tasks[total * (k - 1) // n : total * k // n])


def by_mesh(tasks: Iterable[Task]) -> dict[int, list[Task]]:
    """Tasks grouped by mesh index (tasks with mesh -1 under -1), meshes in order of their
    first task, tasks in order within each."""
    groups: dict[int, list[Task]] = {}
    for task in tasks:
        groups.setdefault(task.mesh, []).append(task)
    return groups


def exit_code(failed_rows: int, bad_files: int) -> int:
    """The batch script's exit status: 2 if a file could not be read, else 1 if any row failed,
    else 0."""
    if bad_files:
        return 2
    return 1 if failed_rows else 0


# --------------------------------------------------------------------------- messages


def _numbers(numbers: Sequence[int]) -> str:
    return bounded_list(numbers)


def _listing(what: str, problems: Sequence[str]) -> str:
    return f"{len(problems)} {what}:\n" + bounded_list(problems, lines=True)
