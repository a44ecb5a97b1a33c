"""The child processes of a batch run (``--jobs`` workers, the map's renderer): the command that
runs this script again, and how a child ends with the process that started it."""

from __future__ import annotations

import contextlib
import ctypes
import os
import signal
import subprocess
import sys
import threading
from collections.abc import Callable

import bpy

from . import extension

PARENT_POLL_SECONDS = 0.2  # how often a child without a parent-death signal checks its parent
PR_SET_PDEATHSIG = 1  # Linux prctl option: the signal a process gets when its parent ends
MARK = "@@vg-batch@@"  # prefix of the lines a child sends to its parent on stdout


def command(*args: str) -> list[str]:
    """The command line of a child: the same Blender binary, or the same Python with bpy,
    running ``vg_batch.py`` with ``args``."""
    script = str(extension.package_folder() / "vg_batch.py")
    if bpy.app.binary_path:
        return [
            bpy.app.binary_path,
            "-b",
            "--factory-startup",
            "-noaudio",
            "--python",
            script,
            "--",
            *args,
        ]
    return [sys.executable, script, *args]


def start(arguments: list[str], temporary: str) -> subprocess.Popen:
    """Start a child running ``vg_batch.py`` with ``arguments``, talking in lines of text on its
    stdin and stdout (stderr is this process's), its temporary files in ``temporary``."""
    return subprocess.Popen(
        command(*arguments),
        env=environment(temporary),
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
        encoding="utf-8",
        errors="replace",
        bufsize=1,
    )


def environment(temporary: str) -> dict[str, str]:
    """The environment of a child: one BLAS/OpenMP thread (the processes are the parallelism),
    and its temporary files (Blender's session folder among them) in ``temporary``, so removing
    that folder removes them however the child ended."""
    env = dict(os.environ)
    for name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        env.setdefault(name, "1")
    for name in ("TMPDIR", "TEMP", "TMP"):
        env[name] = temporary
    return env


def end_with_parent(parent: int, on_orphan: Callable[[], None]) -> None:
    """In a child: be killed the moment the process ``parent`` ends.

    On Linux the kernel sends SIGKILL (a parent-death signal), which ends the child even in the
    middle of a Cycles render, where no Python code runs. Elsewhere a thread checks the parent
    every :data:`PARENT_POLL_SECONDS` and calls ``on_orphan`` (which must end the process).
    """
    if sys.platform.startswith("linux"):
        with contextlib.suppress(OSError, AttributeError):
            libc = ctypes.CDLL(None, use_errno=True)
            if libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0) == 0:
                if os.getppid() != parent:  # the parent ended before the signal was set
                    on_orphan()
                return

    def watch():
        while os.getppid() == parent:
            threading.Event().wait(PARENT_POLL_SECONDS)
        on_orphan()

    threading.Thread(target=watch, name="vg-parent-watch", daemon=True).start()
