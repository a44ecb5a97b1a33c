"""Run a test's function as an unprivileged user, also when the tests run as root.

Root may replace files and device nodes a normal user cannot, so a promise about what the code
does to a user's files is checked both ways. ``as_user`` forks (the child keeps the modules
already imported: the interpreter itself may sit in a folder only root can read), drops to
``nobody`` when running as root, calls the function and sends back its result or the text of
the exception it raised.
"""

from __future__ import annotations

import os
import pickle
import traceback

NOBODY = 65534
"""The user id (and group id) of ``nobody``."""


def as_user(function, *args):
    """``("ok", result)`` or ``("error", "TypeName: message")`` of ``function(*args)``, run
    without root privileges."""
    read_end, write_end = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: never returns into pytest
        status = 0
        try:
            os.close(read_end)
            if os.geteuid() == 0:
                os.setgroups([])
                os.setgid(NOBODY)
                os.setuid(NOBODY)
            try:
                outcome = ("ok", function(*args))
            except BaseException as error:
                outcome = ("error", f"{type(error).__name__}: {error}")
            with os.fdopen(write_end, "wb") as stream:
                pickle.dump(outcome, stream)
        except BaseException:
            traceback.print_exc()
            status = 1
        finally:
            os._exit(status)
    os.close(write_end)
    with os.fdopen(read_end, "rb") as stream:
        data = stream.read()
    _, status = os.waitpid(pid, 0)
    assert os.waitstatus_to_exitcode(status) == 0 and data, "the unprivileged child failed"
    return pickle.loads(data)
