"""Shared test setup: the repository root on sys.path, the reference data folder, and the
extension zip the Blender and GUI tests install."""

import os
import shutil
import signal
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SHARED_DATA = ROOT.parent / "shared" / "data"

if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

import unprivileged  # noqa: E402  (tests/ is on sys.path once this file is imported)

# Started in the background by a shell without job control (or by nohup), pytest would pass
# Ctrl-C and SIGQUIT on ignored to every run it starts, and the stop tests' runs would not stop.
for _signal, _default in (
    (signal.SIGINT, signal.default_int_handler),
    (getattr(signal, "SIGQUIT", None), signal.SIG_DFL),  # no SIGQUIT on Windows
):
    if _signal is not None and signal.getsignal(_signal) == signal.SIG_IGN:
        signal.signal(_signal, _default)


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """The reference meshes folder ``../shared/data``; tests using it skip when it is absent."""
    if not SHARED_DATA.is_dir():
        pytest.skip(
            f"reference meshes not found at {SHARED_DATA} (../shared is not beside the clone)"
        )
    return SHARED_DATA


@pytest.fixture
def user_folder():
    """An empty folder the unprivileged user owns, where it can reach it (pytest's own
    temporary folders are private to root)."""
    folder = Path(tempfile.mkdtemp(prefix="vg-user-test-"))
    if os.geteuid() == 0:
        os.chown(folder, unprivileged.NOBODY, unprivileged.NOBODY)
    folder.chmod(0o755)
    yield folder
    shutil.rmtree(folder, ignore_errors=True)


@pytest.fixture(scope="session")
def extension_zip(tmp_path_factory) -> Path:
    """The extension zip, built and validated by scripts/build_extension.py."""
    out = tmp_path_factory.mktemp("dist")
    result = subprocess.run(
        [sys.executable, str(ROOT / "scripts" / "build_extension.py"), "--output-dir", str(out)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert result.returncode == 0, result.stdout + result.stderr
    return out / Path(result.stdout.strip().splitlines()[-1]).name
