"""Where a measurement CSV is written: files are replaced atomically, everything else is written
into or refused, never replaced (symbolic links, devices, pipes, standard output, folders,
read-only files). Checked as the user running the tests and, where it differs, as an
unprivileged user."""

import os
import stat
import subprocess
import sys
import textwrap
import threading
from pathlib import Path

import pytest
from unprivileged import as_user

from vg_addon import GoniometerError
from vg_addon.formats import csvio, files
from vg_addon.formats.csvio import MeasurementRow

ROOT = Path(__file__).resolve().parents[2]
ROWS = [MeasurementRow(mesh_name="bone", number=1, break_number=1, angle=97.5, radius=2.0)]
TEXT = csvio.format_measurements_csv(ROWS)
IS_ROOT = os.geteuid() == 0
posix_only = pytest.mark.skipif(os.name != "posix", reason="POSIX files and devices")


def write(path):
    csvio.write_measurements_csv(path, ROWS)


def listing(folder):
    return sorted(p.name for p in Path(folder).iterdir())


@posix_only
def test_through_a_symbolic_link_the_target_is_replaced_and_the_link_kept(tmp_path):
    target = tmp_path / "real.csv"
    target.write_text("old\n")
    link = tmp_path / "link.csv"
    link.symlink_to(target)
    write(link)
    assert link.is_symlink() and os.readlink(link) == str(target)
    assert target.read_text() == TEXT
    assert listing(tmp_path) == ["link.csv", "real.csv"]


@posix_only
def test_a_dangling_link_creates_its_target(tmp_path):
    (tmp_path / "sub").mkdir()
    link = tmp_path / "link.csv"
    link.symlink_to(tmp_path / "sub" / "new.csv")
    write(link)
    assert link.is_symlink()
    assert (tmp_path / "sub" / "new.csv").read_text() == TEXT


@posix_only
def test_a_link_into_a_missing_folder_is_refused(tmp_path):
    link = tmp_path / "link.csv"
    link.symlink_to(tmp_path / "gone" / "new.csv")
    with pytest.raises(GoniometerError, match=r"gone.* does not exist"):
        write(link)
    assert link.is_symlink() and listing(tmp_path) == ["link.csv"]


def test_a_folder_is_refused_and_left_alone(tmp_path):
    (tmp_path / "out").mkdir()
    with pytest.raises(GoniometerError, match="is a folder: give a file name"):
        write(tmp_path / "out")
    assert (tmp_path / "out").is_dir() and listing(tmp_path / "out") == []


def device(tmp_path, name, minor):
    """A character device node like /dev/null (minor 3) or /dev/full (minor 7): a private copy
    when root (so no test can ever damage the real ones), the real one otherwise."""
    if not IS_ROOT:
        return Path("/dev") / name
    node = tmp_path / name
    os.mknod(node, stat.S_IFCHR | 0o666, os.makedev(1, minor))
    return node


@posix_only
@pytest.mark.skipif(not Path("/dev/null").exists(), reason="needs /dev/null")
def test_a_character_device_is_written_into_never_replaced(tmp_path):
    null = device(tmp_path, "null", 3)
    write(null)
    assert stat.S_ISCHR(null.stat().st_mode)
    assert sorted(p for p in listing(null.parent) if p.startswith(".null")) == []


@posix_only
@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full")
def test_a_full_device_gives_a_clear_error_and_stays_a_device(tmp_path):
    full = device(tmp_path, "full", 7)
    with pytest.raises(GoniometerError, match=r"Could not write the CSV to .*full.*No space left"):
        write(full)
    assert stat.S_ISCHR(full.stat().st_mode)


@posix_only
def test_a_named_pipe_receives_the_csv(tmp_path):
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    received = []
    reader = threading.Thread(target=lambda: received.append(fifo.read_text()), daemon=True)
    reader.start()
    write(fifo)
    reader.join(timeout=10)
    assert received == [TEXT]
    assert stat.S_ISFIFO(fifo.stat().st_mode)


def run_writer(target, **popen):
    """A separate process that writes the CSV to ``target``; its stdout is a pipe."""
    code = textwrap.dedent(
        f"""
        import sys
        sys.path.insert(0, {str(ROOT)!r})
        from vg_addon.formats import csvio
        print("before", flush=True)
        csvio.write_measurements_csv(sys.argv[1], [csvio.MeasurementRow(
            mesh_name="bone", number=1, break_number=1, angle=97.5, radius=2.0)])
        print("after", flush=True)
        """
    )
    popen = {"stdout": subprocess.PIPE, "stderr": subprocess.PIPE, **popen}
    return subprocess.run([sys.executable, "-c", code, target], text=True, check=False, **popen)


def stdout_alias(folder):
    """A private link to this process's standard output, like /dev/stdout. Tests never aim at
    the real /dev/stdout as root: code that replaced it would break the machine for everyone."""
    link = Path(folder) / "my_stdout"
    link.symlink_to("/proc/self/fd/1")
    return str(link)


needs_proc_fd = pytest.mark.skipif(
    not Path("/proc/self/fd/1").exists(), reason="no /proc file-descriptor links on this system"
)


def test_dash_is_standard_output(tmp_path):
    result = run_writer("-", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert result.stdout == "before\n" + TEXT + "after\n"
    assert listing(tmp_path) == []


@needs_proc_fd
def test_a_standard_output_alias_into_a_pipe(tmp_path):
    alias = stdout_alias(tmp_path)
    result = run_writer(alias)
    assert result.returncode == 0, result.stderr
    assert result.stdout == "before\n" + TEXT + "after\n"
    assert Path(alias).is_symlink() and listing(tmp_path) == ["my_stdout"]


@needs_proc_fd
def test_a_standard_output_alias_redirected_to_a_file_appends_to_it(tmp_path):
    alias = stdout_alias(tmp_path)
    out = tmp_path / "out.txt"
    out.write_text("kept\n")
    with open(out, "a") as stream:
        result = run_writer(alias, stdout=stream)
    assert result.returncode == 0, result.stderr
    assert out.read_text() == "kept\nbefore\n" + TEXT + "after\n"
    assert Path(alias).is_symlink() and listing(tmp_path) == ["my_stdout", "out.txt"]


def write_to_redirected_stdout(name, into_file):
    """Point this process's fd 1 at a pipe (or ``into_file``), write the CSV to ``name``
    (e.g. /dev/stdout) and return what arrived."""
    saved = os.dup(1)
    try:
        if into_file:
            target = os.open(into_file, os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o644)
            os.dup2(target, 1)
            os.close(target)
            write(name)
            return Path(into_file).read_text()
        read_end, write_end = os.pipe()
        os.dup2(write_end, 1)
        os.close(write_end)
        write(name)
        os.dup2(saved, 1)  # closes the pipe's last write end
        with os.fdopen(read_end) as stream:
            return stream.read()
    finally:
        os.dup2(saved, 1)
        os.close(saved)


@posix_only
@pytest.mark.skipif(not Path("/dev/stdout").is_symlink(), reason="/dev/stdout is not a link")
def test_unprivileged_dev_stdout_into_a_pipe_and_a_file(user_folder):
    assert as_user(write_to_redirected_stdout, "/dev/stdout", None) == ("ok", TEXT)
    out = user_folder / "out.txt"
    assert as_user(write_to_redirected_stdout, "/dev/stdout", str(out)) == ("ok", TEXT)
    assert Path("/dev/stdout").is_symlink()


def test_output_target_names_the_kind():
    assert files.output_target("-") == "stream"


@posix_only
def test_output_target_of_files_and_streams(tmp_path):
    assert files.output_target(tmp_path / "new.csv") == "file"
    (tmp_path / "old.csv").write_text("x\n")
    assert files.output_target(tmp_path / "old.csv") == "file"
    assert files.output_target("/dev/null") == "stream"


# --------------------------------------------------------------------------- as a normal user


@posix_only
def test_unprivileged_read_only_file_is_refused_and_kept(user_folder):
    tmp_path = user_folder
    target = tmp_path / "frozen.csv"
    target.write_text("precious\n")
    target.chmod(0o444)
    if IS_ROOT:
        os.chown(target, 0, 0)
    outcome = as_user(write, target)
    assert outcome[0] == "error" and "is read-only: it is left as it is" in outcome[1]
    assert target.read_text() == "precious\n"
    assert listing(tmp_path) == ["frozen.csv"]


@posix_only
def test_unprivileged_dev_null_and_full():
    assert as_user(write, "/dev/null") == ("ok", None)
    kind, message = as_user(write, "/dev/full")
    assert kind == "error" and "No space left" in message
    assert stat.S_ISCHR(os.stat("/dev/null").st_mode)
    assert stat.S_ISCHR(os.stat("/dev/full").st_mode)


@posix_only
def test_unprivileged_symbolic_link_and_new_file(user_folder):
    tmp_path = user_folder
    target = tmp_path / "real.csv"
    link = tmp_path / "link.csv"
    link.symlink_to(target)
    assert as_user(write, link) == ("ok", None)
    assert link.is_symlink() and target.read_text() == TEXT
