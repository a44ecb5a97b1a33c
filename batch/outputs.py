"""Where a batch run writes, checked before anything is read or written: no output may be an
input (or another output), and every output must be a place the run can write to."""

from __future__ import annotations

import contextlib
import os
import stat
from pathlib import Path

import bpy

from ..vg_addon import GoniometerError
from ..vg_addon.formats import csvio, files, picked_points
from ..vg_addon.workflow import batchplan
from .cli import UsageError


def _same_file(a: str, b: str) -> bool:
    try:
        return os.path.samefile(a, b)  # also a hard link or a symbolic link to the same file
    except OSError:  # one of them does not exist (yet): compare where they lead
        return os.path.normcase(os.path.realpath(a)) == os.path.normcase(os.path.realpath(b))


def input_files(args) -> list[tuple[str, str]]:
    """``(what, path)`` of every file the run reads: mesh files (also those in given folders),
    the .blend, the points CSV and the edges CSV."""
    found = []
    meshes = [p for p in args.inputs if not p.lower().endswith(".blend")]
    blends = [p for p in args.inputs if p.lower().endswith(".blend")]
    try:
        files = batchplan.find_mesh_files(meshes)
    except GoniometerError:
        files = [Path(p) for p in meshes]  # reported as missing later; still compared here
    found += [("mesh file", str(path)) for path in files]
    found += [("input .blend", path) for path in blends]
    if bpy.app.binary_path and bpy.data.filepath and not blends:  # blender -b file.blend
        found.append(("input .blend", bpy.data.filepath))
    if args.points:
        found.append(("points CSV", args.points))
    edges = getattr(args, "edges_csv", None)
    if edges and Path(edges).is_dir():  # a folder of MeshLab picked-points files
        # A folder that cannot be listed is refused when the edges are read.
        with contextlib.suppress(GoniometerError):
            found += [("picked-points file", str(path)) for path in picked_points.files_in(edges)]
    elif edges:
        what = (
            "picked-points file"
            if Path(edges).suffix.lower() == picked_points.SUFFIX
            else "edges CSV"
        )
        found.append((what, edges))
    return found


def input_of(path, inputs) -> str:
    """The input ``path`` would overwrite (``"what path"``), or "" when it is none of
    ``inputs`` (``(what, path)`` pairs, see :func:`input_files`)."""
    for what, source in inputs:
        if _same_file(os.fspath(path), source):
            return f"the {what} {source}"
    return ""


def refuse_input(path, inputs) -> None:
    """Raise :class:`GoniometerError` when writing ``path`` would overwrite an input: checked for
    every picture just before it is written (their names depend on the meshes)."""
    if victim := input_of(path, inputs):
        raise GoniometerError(f"{path} is {victim}: it is not overwritten.")


def _writable_folder(folder: Path, option: str, given: str) -> None:
    """Raise unless ``folder`` exists and is writable, or can be created."""
    existing = folder
    while not existing.exists():
        if existing.parent == existing:
            break
        existing = existing.parent
    if not existing.is_dir():
        raise UsageError(f"{option} {given}: {existing} is a file, not a folder.")
    if not os.access(existing, os.W_OK | os.X_OK):
        what = "write into" if existing == folder else f"create {folder} in"
        raise UsageError(
            f"{option} {given}: no permission to {what} {existing}; choose another place."
        )


def _kind(out: str) -> str:
    """How ``--out`` is written (see ``files.output_target``); a place that cannot be written
    (a folder, a read-only file, ...) is refused naming the option."""
    try:
        return files.output_target(out)
    except GoniometerError as error:
        raise UsageError(f"--out {out}: {error}") from None


def is_stream(out) -> bool:
    """Whether ``--out`` is standard output or a stream (a pipe, a terminal, a device), which
    nothing is written beside and which gets the CSV once, at the end. The one verdict for both
    the output check and the run."""
    return out == files.STDOUT or (os.path.exists(out) and _kind(out) == "stream")


def _stdout_input(inputs) -> str:
    """The input standard output is (``"what path"``; e.g. ``>> mesh.ply``), or "". Descriptor
    1, which the CSV is written to (``files``), whatever ``sys.stdout`` has been replaced by."""
    try:
        out = os.fstat(1)
    except OSError:  # closed
        return ""
    if not stat.S_ISREG(out.st_mode):
        return ""
    for what, source in inputs:
        with contextlib.suppress(OSError):
            if os.path.samestat(out, os.stat(source)):
                return f"the {what} {source}"
    return ""


def sweep_paths(out) -> tuple[Path, Path]:
    """Where ``--sweep`` writes: ``<out>_sweep.csv`` and the plot folder ``<out>_sweep/``,
    beside ``out`` as given (a link's target's folder would part them from the CSV)."""
    out = Path(out).absolute()
    return out.with_name(out.stem + "_sweep.csv"), out.with_name(out.stem + "_sweep")


def keeps_earlier(out) -> bool:
    """Whether ``--out`` is a regular file already, which the run keeps whole until it
    completes (:func:`partial_paths`); a stream or a new file is written as the run goes."""
    return bool(out) and not is_stream(out) and os.path.isfile(out)


def partial_paths(out) -> tuple[Path, Path, Path]:
    """Where a run to an earlier ``--out`` writes its CSV until it completes: the side file
    ``<stem>.partial<suffix>``, its edge summary ``<stem>.partial_edges<suffix>`` and its sweep
    ``<stem>.partial_sweep.csv``, beside ``out`` as given (as :func:`sweep_paths`)."""
    out = Path(out)
    partial = out.with_name(f"{out.stem}.partial{out.suffix or '.csv'}")
    return partial, csvio.edges_path_for(partial), sweep_paths(partial)[0]


def holds_export(path) -> bool:
    """Whether ``path`` is a measurement CSV (its header begins with MeshLab's columns), as a
    run's side file is; any other file of that name is not the run's to remove."""
    if not os.path.isfile(path):
        return False
    try:
        _, header, _ = csvio.read_table(Path(path))
    except (OSError, GoniometerError):
        return False
    return tuple(header[: len(csvio.MESHLAB_COLUMNS)]) == csvio.MESHLAB_COLUMNS


def partial_outputs(args, edges: bool) -> list[tuple[str, str]]:
    """``(what, path)`` of the side files this run writes (its ``--out`` is an earlier file):
    outputs like any other. (Where one is there already, the run is refused: it holds a stopped
    run's results, see :func:`check_outputs`.)"""
    if not args.out or is_stream(args.out) or not keeps_earlier(args.out):
        return []
    partial, partial_edges, partial_sweep = partial_paths(args.out)
    found = [("--out's partial results", str(partial))]
    if edges:
        found.append(("--out's partial edge summary", str(partial_edges)))
    if args.sweep:
        found.append(("--out's partial sweep CSV", str(partial_sweep)))
    return found


def remove_partial(out) -> list[str]:
    """Remove the side files of :func:`partial_paths` that a run wrote (once the run to ``out``
    has completed, they are stale); returns why any could not be removed."""
    partial, partial_edges, partial_sweep = partial_paths(out)
    problems = []
    for path, ours in (
        (partial, holds_export),
        (partial_edges, csvio.holds_edge_summary),
        (partial_sweep, csvio.holds_sweep),
    ):
        if ours(path):
            try:
                path.unlink()
            except OSError as error:
                problems.append(f"{path}: {error.strerror or error}")
    return problems


def _holds_something(path: Path) -> bool:
    """Whether ``path`` is a file with more than blanks and a byte-order mark in it (or one that
    cannot be read, which is not ours to replace either)."""
    if not path.is_file():
        return False
    try:
        with open(path, "rb") as handle:
            return bool(handle.read(4096).removeprefix(b"\xef\xbb\xbf").strip())
    except OSError:
        return True


def check_outputs(args) -> None:
    """Refuse outputs that are inputs or each other, and outputs that cannot be written.

    Raises
    ------
    UsageError
        Naming the option, the path and what to do; nothing has been read or written then.
    """
    outputs = [("--out", args.out), ("--save-blend", args.save_blend)]
    outputs = [(option, path) for option, path in outputs if path and path != files.STDOUT]
    edge_options = (("--edge", "edge"), ("--edges", "edges_csv"), ("--find-edges", "find_edges"))
    edges = [option for option, name in edge_options if getattr(args, name, None)]
    if args.out and edges and is_stream(args.out):
        raise UsageError(
            f"{edges[0]} writes the edge summary <out>_edges.csv and a plot per edge beside "
            f"--out, so --out {args.out} must be a file name, not standard output or a stream."
        )
    summary = csvio.edges_path_for(args.out) if args.out and not is_stream(args.out) else None
    # Written with edges; without, an earlier run's summary there is emptied
    # (csvio.write_export): either way never an input.
    if summary is not None and (edges or csvio.holds_edge_summary(summary)):
        outputs.append(("--out's edge summary", str(summary)))
    if args.sweep:
        if is_stream(args.out):
            raise UsageError(
                f"--sweep writes <out>_sweep.csv and a plot folder beside --out, so --out "
                f"{args.out} must be a file name, not standard output or a stream."
            )
        csv_path, plots = sweep_paths(args.out)
        outputs.append(("--sweep's CSV", str(csv_path)))
        if plots.exists() and not plots.is_dir():
            raise UsageError(f"--sweep: {plots} (its plot folder) is a file; move it away.")
    elif args.out and not is_stream(args.out):
        # Without --sweep an earlier run's sweep there is emptied (Run.empty_earlier_sweep).
        csv_path, _ = sweep_paths(args.out)
        if csvio.holds_sweep(csv_path):
            outputs.append(
                ("--out's earlier sweep CSV (emptied by a run without --sweep)", str(csv_path))
            )
    outputs += partial_outputs(args, bool(edges))
    inputs = input_files(args)
    if args.out == files.STDOUT and (victim := _stdout_input(inputs)):
        raise UsageError(
            f"--out {args.out} writes to standard output, which goes to {victim}: writing there "
            "would destroy an input. Send standard output elsewhere or give --out a file name; "
            "nothing was read or written."
        )
    for option, path in outputs:
        if victim := input_of(path, inputs):
            raise UsageError(
                f"{option} {path} is {victim}: writing there would destroy an input. Choose "
                "another file name; nothing was read or written."
            )
    if args.out and not is_stream(args.out):
        for path in partial_paths(args.out):
            if _holds_something(path):
                raise UsageError(
                    f"{path} is there: the results so far of a run to {args.out} that was "
                    "stopped (or a file of yours of that name). A run would replace it: move it "
                    "away, or delete it, and run again; nothing was read or written."
                )
    if args.sweep and _holds_something(csv_path) and not csvio.holds_sweep(csv_path):
        raise UsageError(
            f"--sweep writes {csv_path}, which holds a file that is not a radius-sweep CSV (the "
            "user's notes, or another list): move it away or give --out another name; nothing "
            "was read or written."
        )
    for at, (option, path) in enumerate(outputs):
        for other, other_path in outputs[at + 1 :]:
            if _same_file(path, other_path):
                raise UsageError(
                    f"{option} and {other} are the same file ({path}): give them different names."
                )
    if args.out and args.out != files.STDOUT:
        if os.path.exists(args.out):
            if _kind(args.out) == "file":
                _writable_folder(Path(args.out).resolve().parent, "--out", args.out)
        else:
            _writable_folder(Path(args.out).resolve().parent, "--out", args.out)
    if args.save_blend:
        path = Path(args.save_blend)
        if path.is_dir():
            raise UsageError(
                f"--save-blend {args.save_blend} is a folder: give a file name, e.g. "
                f"{path / 'measured.blend'}."
            )
        if path.exists() and not path.is_file():
            raise UsageError(f"--save-blend {args.save_blend} is not a regular file.")
        if path.exists() and not os.access(path, os.W_OK):
            raise UsageError(f"--save-blend {args.save_blend} is read-only; it is left as it is.")
        _writable_folder(path.resolve().parent, "--save-blend", args.save_blend)
    if args.render:
        path = Path(args.render)
        if path.exists() and not path.is_dir():
            raise UsageError(
                f"--render {args.render} is a file: --render takes a folder, where each mesh's "
                "picture is written as <mesh>.png."
            )
        _writable_folder(path.resolve(), "--render", args.render)


def make_folders(args) -> None:
    """Create the folders the outputs go into (after :func:`check_outputs`)."""
    folders = []
    if args.out and args.out != files.STDOUT:
        folders.append(Path(args.out).resolve().parent)
    if args.save_blend:
        folders.append(Path(args.save_blend).resolve().parent)
    if args.render:
        folders.append(Path(args.render).resolve())
    for folder in folders:
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError as error:
            raise UsageError(
                f"cannot create the folder {folder}: {error.strerror or error}."
            ) from None
