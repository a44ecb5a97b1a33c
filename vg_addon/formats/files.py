"""How every output file of the project is written: a regular file replaced in one step
(never half-written, its old content kept on any failure), a stream (standard output, a pipe,
a device) written into, which targets are refused before anything is written, and the names of
picture files (safe on every file system, one per mesh)."""

from __future__ import annotations

import contextlib
import os
import re
import secrets
import stat

from ..errors import GoniometerError

STDOUT = "-"  # the target name of standard output

TEMP_STEM_BYTES = 200  # of a file's name, at most, in the temporary name it is written under


def _replace_atomically(path: str, data: bytes) -> None:
    folder = os.path.dirname(os.path.abspath(path)) or "."
    if not os.path.isdir(folder):
        raise GoniometerError(
            f"The folder {folder!r} does not exist: choose an existing folder to write to."
        )
    try:
        mode = stat.S_IMODE(os.stat(path).st_mode)
    except OSError:
        mode = None
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0)
    # The temporary name adds 14 bytes: cut a long name's stem so that it stays a name the
    # disk takes (255 bytes on most), where the file's own name fits.
    base = os.path.basename(path).encode("utf-8", "surrogateescape")[:TEMP_STEM_BYTES]
    base = base.decode("utf-8", "ignore")
    while True:
        temp = os.path.join(folder, f".{base}.{secrets.token_hex(4)}.tmp")
        try:
            handle = os.open(temp, flags, 0o666)
            break
        except FileExistsError:
            continue
    try:
        with os.fdopen(handle, "wb") as stream:
            stream.write(data)
            stream.flush()
            os.fsync(stream.fileno())
        if mode is not None:
            with contextlib.suppress(OSError):
                os.chmod(temp, mode)
        try:
            os.replace(temp, path)
        except OSError as error:
            raise GoniometerError(
                f"Could not replace {path!r}: {error.strerror or error}. Is it open in another "
                "program (e.g. a spreadsheet)? Close it and try again; the old file is unchanged."
            ) from error
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(temp)
        raise


def _write_into(path: str, data: bytes) -> None:
    """Write ``data`` into an open-ended target (a pipe, a terminal, standard output), in place."""
    try:
        if path == STDOUT:
            handle = os.dup(1)
        else:
            # No O_CREAT and no O_TRUNC: the target exists and is never replaced or emptied;
            # O_APPEND keeps what a shell's ">>" already put in a file behind /dev/stdout.
            handle = os.open(path, os.O_WRONLY | os.O_APPEND | getattr(os, "O_BINARY", 0))
        with os.fdopen(handle, "wb") as stream:
            stream.write(data)
            stream.flush()
    except OSError as error:
        where = "standard output" if path == STDOUT else repr(path)
        raise GoniometerError(
            f"Could not write the CSV to {where}: {error.strerror or error}."
        ) from error


def _is_descriptor_alias(path: str) -> bool:
    """Whether ``path`` reaches, through its symbolic links, a name of an open file descriptor
    (``/dev/stdout`` -> ``/proc/self/fd/1``, ``/dev/fd/1``): writing to it means writing into
    the file this process already has open, never replacing it."""
    current = os.path.abspath(path)
    for _ in range(40):  # the kernel's own limit on links followed
        if current.startswith(("/proc/", "/dev/fd/")):
            return True
        if not os.path.islink(current):
            return False
        current = os.path.normpath(os.path.join(os.path.dirname(current), os.readlink(current)))
    return False


def output_target(path) -> str:
    """How :func:`write_measurements_csv` will write to ``path``, or why it cannot.

    Returns
    -------
    str
        ``"file"``: a regular file (new, or replaced atomically; through a symbolic link, its
        target is replaced and the link kept). ``"stream"``: ``"-"`` (standard output), a pipe,
        a terminal or another character device such as ``/dev/null``, or a name of an open file
        descriptor such as ``/dev/stdout``: the text is written into it, once, never replacing
        it.

    Raises
    ------
    GoniometerError
        A folder, a block device or a socket, or a folder that does not exist.
    """
    path = os.fspath(path)
    if path == STDOUT:
        return "stream"
    try:
        info = os.stat(path)  # follows symbolic links
    except FileNotFoundError:
        target = os.path.realpath(path)  # a dangling link is created at its target
        folder = os.path.dirname(target) or "."
        if not os.path.isdir(folder):
            raise GoniometerError(
                f"The folder {folder!r} does not exist: choose an existing folder to write "
                f"{os.path.basename(path)!r} to."
            ) from None
        return "file"
    except OSError as error:
        raise GoniometerError(f"Cannot write to {path!r}: {error.strerror or error}.") from None
    if stat.S_ISDIR(info.st_mode):
        raise GoniometerError(
            f"{path!r} is a folder: give a file name for the CSV, e.g. "
            f"{os.path.join(path, 'measurements.csv')!r}."
        )
    if stat.S_ISREG(info.st_mode):
        if _is_descriptor_alias(path):
            return "stream"
        if not os.access(path, os.W_OK):
            raise GoniometerError(
                f"{path!r} is read-only: it is left as it is. Choose another file name, or make "
                "it writable first."
            )
        return "file"
    if stat.S_ISCHR(info.st_mode) or stat.S_ISFIFO(info.st_mode):
        return "stream"
    kind = "a block device" if stat.S_ISBLK(info.st_mode) else "a socket or other special file"
    raise GoniometerError(
        f"{path!r} is {kind}, not a file: choose a file name, or '-' for standard output."
    )


def replace_atomically(path, data: bytes) -> None:
    """Write ``data`` to ``path``, the way every output file of the project is written.

    A regular file (or a new one) is replaced in one step, through a temporary file beside it,
    so it holds its old content or the new one, never part of it; a symbolic link keeps its link
    and its target is replaced. ``-`` (standard output), devices and pipes are written into,
    never replaced. See :func:`output_target` for what is refused.
    """
    path = os.fspath(path)
    if output_target(path) == "stream":
        _write_into(path, data)
    else:
        _replace_atomically(os.path.realpath(path), data)


def safe_file_name(name: str) -> str:
    """``name`` with every character that is not safe in a file name replaced by ``_``."""
    return "".join(c if c.isalnum() or c in "-_.+" else "_" for c in name) or "mesh"


def picture_names(names: list[str], taken=()) -> tuple[list[str], list[str]]:
    """A file-name stem per mesh, unique within the run (also ignoring case, for file systems
    that do), and a note for each mesh whose stem had to be changed.

    ``safe_file_name`` maps "bone 1" and "bone_1" to the same "bone_1": the second gets
    "bone_1-2", so its pictures never replace the first's. Stems in ``taken`` (held by meshes
    not named here) are never given.
    """
    taken = {stem.casefold() for stem in taken}
    stems, notes = [], []
    for name in names:
        base = stem = safe_file_name(name)
        suffix = 1
        while stem.casefold() in taken:
            suffix += 1
            stem = f"{base}-{suffix}"
        taken.add(stem.casefold())
        stems.append(stem)
        if stem != base:
            notes.append(
                f"the pictures of {name!r} are named {stem!r}: another mesh of this run "
                f"already has the file name {base!r}"
            )
    return stems, notes


def kept_picture_name(name: str, records: dict) -> str:
    """The file-name stem of the pictures of ``name`` among the meshes of ``records`` (each
    mesh's name, ``name`` included, and the stem its pictures were last written under, or
    ``""``), unique ignoring case.

    Every recorded stem is held, so no other mesh is given it and writes over those pictures:
    not one made later under the same file name, nor one named like a mesh since renamed. A mesh
    keeps its own recorded stem while the stem still comes from its name (its safe file name,
    maybe with "-2", "-3", … after it); where two meshes record one stem (a copy carries its
    original's record), the one whose name it comes from keeps it. Any other mesh gets a stem
    from its name as it is now: a safe name keeps it, the others, in name order, take "-2",
    "-3", … after it (:func:`picture_names`).
    """
    order = sorted(records, key=lambda other: (safe_file_name(other) != other, other))
    held: dict[str, str] = {}  # casefolded stem -> the mesh that keeps it
    for other in order:
        stem = records[other] or ""
        if re.fullmatch(re.escape(safe_file_name(other)) + r"(-[0-9]+)?", stem):
            held.setdefault(stem.casefold(), other)
    recorded = records.get(name) or ""
    if held.get(recorded.casefold()) == name:
        return recorded
    taken = set(held) | {(records[other] or "").casefold() for other in records} - {""}
    names = [other for other in order if other not in set(held.values())]
    return picture_names(names, taken=taken)[0][names.index(name)]
