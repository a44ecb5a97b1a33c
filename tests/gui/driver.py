"""Drive a real Blender under Xvfb inside a Blender root (scripts/provision_blender.sh).

Everything runs inside the root through one long-lived shell (scripts/blender_root.sh, so the
mounts live in a private mount namespace and vanish with it): Xvfb, the GUI Blender started with
``harness_startup.py``, xdotool for the mouse and keys, xwd for screenshots. The test reads what
Blender shows through the JSON state the startup script writes.
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import select
import shlex
import shutil
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
ROOT_SCRIPT = REPO / "scripts" / "blender_root.sh"
SCREEN = (1280, 1800)  # tall: the whole sidebar shows without scrolling
GUEST_REPO, GUEST_TMP = "/vg/repo", "/vg/tmp"
GUEST_REPORT_LIBS = "/vg/report-libs"  # harness_startup.REPORT_LIBS
END = "__vg_end__"
EXTENSION_PACKAGE = "virtual_goniometer"  # in every path and module name of the installed zip


class RootShell:
    """A bash inside a Blender root; :meth:`run` runs one command line and returns its output."""

    def __init__(self, suite: str, host_tmp: Path, log: Path, report_libs: Path | None = None):
        # Background jobs (Xvfb, Blender) end with the shell, which ends when this side closes
        # its input (also when the test process is killed).
        loop = (
            "trap 'kill $(jobs -p) 2>/dev/null' EXIT; "
            f'while IFS= read -r line; do eval "$line" </dev/null 2>&1; echo "{END} $?"; done'
        )
        self._log = open(log, "ab")  # noqa: SIM115 (closed in close())
        self.process = subprocess.Popen(
            [
                str(ROOT_SCRIPT),
                suite,
                "--ro-bind",
                str(REPO),
                GUEST_REPO,
                "--bind",
                str(host_tmp),
                GUEST_TMP,
                *(("--ro-bind", str(report_libs), GUEST_REPORT_LIBS) if report_libs else ()),
                "--",
                "bash",
                "-c",
                loop,
            ],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=self._log,
        )
        self._buffer = b""

    def run(self, command: str, timeout: float = 60.0) -> tuple[int, str]:
        """Run ``command`` (a bash line, output merged); return ``(status, output)``."""
        self.process.stdin.write(command.replace("\n", " ").encode() + b"\n")
        self.process.stdin.flush()
        deadline = time.monotonic() + timeout
        marker = END.encode() + b" "
        while marker not in self._buffer:
            left = deadline - time.monotonic()
            if left <= 0:
                raise TimeoutError(f"no answer within {timeout} s from: {command}")
            ready, _, _ = select.select([self.process.stdout], [], [], left)
            if ready:
                chunk = os.read(self.process.stdout.fileno(), 65536)
                if not chunk:
                    raise RuntimeError(f"the root shell ended while running: {command}")
                self._buffer += chunk
        output, _, rest = self._buffer.partition(marker)
        status_line, _, self._buffer = rest.partition(b"\n")
        return int(status_line), output.decode(errors="replace")

    def check(self, command: str, timeout: float = 60.0) -> str:
        status, output = self.run(command, timeout)
        if status:
            raise RuntimeError(f"exit status {status} from: {command}\n{output[-3000:]}")
        return output

    def close(self) -> None:
        with contextlib.suppress(BrokenPipeError, OSError):
            self.process.stdin.close()
        try:
            self.process.wait(timeout=20)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
        self._log.close()


class GuiBlender:
    """One real Blender window under Xvfb, with the extension installed from ``zip_path``."""

    def __init__(
        self,
        suite: str,
        zip_path: Path,
        points: dict[str, list[float]],
        scene: str = "wedge",
        report_libs: Path | None = None,
    ):
        self.suite = suite
        self.scene = scene
        self.report_libs = report_libs
        self.tmp = Path(tempfile.mkdtemp(prefix=f"vg-gui-{suite}-"))
        os.chmod(self.tmp, 0o755)
        shutil.copy(zip_path, self.tmp / "extension.zip")
        (self.tmp / "points.json").write_text(json.dumps(points))
        self.shell = RootShell(suite, self.tmp, self.tmp / "shell.log", report_libs)
        self.display = None
        self.state_path = self.tmp / "state.json"
        try:
            self._start()
        except BaseException:
            self.close()
            raise

    # -- start and stop ---------------------------------------------------------------------
    def _start(self) -> None:
        run = self.shell.check
        run(f"mkdir -p {GUEST_TMP}/home && export HOME={GUEST_TMP}/home && cd {GUEST_TMP}")
        self.version = run("blender --version | head -n 1").strip()
        run(
            "blender --command extension install-file -r user_default -e "
            f"{GUEST_TMP}/extension.zip",
            timeout=180,
        )
        # The splash would cover the viewport: a user closes it once, the harness turns it off.
        # Developer extras let F3 find operators by name, as they do for many users. The file
        # browser opens as a maximized area of the main window (Preferences > Interface >
        # Temporary Editors), not a window of its own: with no window manager under Xvfb, 5.2's
        # new window ignores synthetic clicks.
        run(
            "blender -b --python-expr 'import bpy; view = bpy.context.preferences.view; "
            "view.show_splash = False; view.show_developer_ui = True; "
            'view.filebrowser_display_type = "SCREEN"; '
            "bpy.ops.wm.save_userpref()'",
            timeout=180,
        )
        width, height = SCREEN
        run(
            f"Xvfb -displayfd 1 -screen 0 {width}x{height}x24 -nolisten tcp "
            f">{GUEST_TMP}/display 2>{GUEST_TMP}/xvfb.log & echo $! >{GUEST_TMP}/xvfb.pid"
        )
        deadline, display = time.monotonic() + 30, self.tmp / "display"
        while not (display.exists() and display.read_text().strip()):
            if time.monotonic() > deadline:
                raise RuntimeError("Xvfb did not start: " + (self.tmp / "xvfb.log").read_text())
            time.sleep(0.1)
        self.display = ":" + display.read_text().strip()
        # Console output line by line (stdbuf, PYTHONUNBUFFERED), so a warning Blender prints on
        # stdout stands beside the source line it prints on stderr (console_errors reads both).
        run(
            f"DISPLAY={self.display} VG_GUI_SCENE={self.scene} VG_GUI_STATE={GUEST_TMP}/state.json "
            f"VG_GUI_POINTS={GUEST_TMP}/points.json PYTHONUNBUFFERED=1 "
            f"stdbuf -oL -eL blender -p 0 0 {width} {height} "
            f"--python {GUEST_REPO}/tests/gui/harness_startup.py "
            f">{GUEST_TMP}/blender.log 2>&1 & echo $! >{GUEST_TMP}/blender.pid"
        )
        self.wait_for(lambda s: s.get("ready"), 120, "Blender's window and the test scene")

    def close(self) -> None:
        for name in ("blender", "xvfb"):
            pid_file = self.tmp / f"{name}.pid"
            if pid_file.exists() and pid_file.read_text().strip():
                with contextlib.suppress(Exception):
                    self.shell.run(f"kill {pid_file.read_text().strip()}; sleep 0.5", timeout=10)
        self.shell.close()

    def log(self) -> str:
        path = self.tmp / "blender.log"
        return path.read_text(errors="replace")[-4000:] if path.exists() else ""

    def log_size(self) -> int:
        """How far Blender's console output (stdout and stderr) has come, in bytes."""
        path = self.tmp / "blender.log"
        return path.stat().st_size if path.exists() else 0

    def console_errors(self, since: int = 0) -> list[str]:
        """The complaints in Blender's console after byte ``since``
        (:func:`console_complaints`)."""
        path = self.tmp / "blender.log"
        if not path.exists():
            return []
        with path.open("rb") as handle:
            handle.seek(since)
            return console_complaints(handle.read().decode(errors="replace"))

    # -- reading Blender's state -------------------------------------------------------------
    def state(self) -> dict:
        for _ in range(50):
            with contextlib.suppress(FileNotFoundError, ValueError):
                return json.loads(self.state_path.read_text())
            time.sleep(0.02)
        raise RuntimeError("no state from the GUI Blender; its log:\n" + self.log())

    def wait_for(self, predicate, timeout: float, what: str) -> dict:
        deadline = time.monotonic() + timeout
        while True:
            with contextlib.suppress(FileNotFoundError, ValueError):
                state = json.loads(self.state_path.read_text())
                if state.get("errors"):
                    raise RuntimeError("the harness failed:\n" + state["errors"][-1])
                if predicate(state):
                    return state
            if time.monotonic() > deadline:
                with contextlib.suppress(Exception):
                    self.save_png("timeout", self.tmp / "timeout.png")
                raise TimeoutError(
                    f"waited {timeout} s for {what} (screen: {self.tmp}/timeout.png); "
                    f"Blender's log:\n{self.log()}"
                )
            time.sleep(0.05)

    def settle(self, ticks: int = 3) -> dict:
        """Wait until the harness has reported ``ticks`` more times (events processed)."""
        seq = self.state()["seq"]
        return self.wait_for(lambda s: s["seq"] >= seq + ticks, 30, "the harness to report")

    def measurements(self, obj: str) -> list[dict]:
        return self.state()["objects"][obj]["measurements"]

    # -- real input events -------------------------------------------------------------------
    def xdotool(self, *args) -> None:
        self.shell.check(f"DISPLAY={self.display} xdotool " + " ".join(map(shlex.quote, args)))

    def move(self, xy) -> None:
        """Move the pointer and let Blender see it (keys go where Blender last saw it)."""
        self.xdotool("mousemove", str(round(xy[0])), str(round(xy[1])))
        self.settle(1)

    def click(self, xy, button: int = 1, modifier: str | None = None) -> None:
        """Press and release ``button`` at ``xy``, holding ``modifier`` (e.g. ``"shift"``)."""
        self.move(xy)
        if modifier:
            self.xdotool("keydown", modifier)
            self.settle(1)
        self.xdotool("mousedown", str(button))
        self.settle(1)
        self.xdotool("mouseup", str(button))
        if modifier:
            self.settle(1)
            self.xdotool("keyup", modifier)
        self.settle()

    def key(self, *keys: str) -> None:
        self.xdotool("key", "--delay", "60", *keys)
        self.settle()

    def type_text(self, text: str) -> None:
        self.xdotool("type", "--delay", "60", text)
        self.settle()

    def copies(self, xy, key: str = "ctrl+c") -> str | None:
        """What ``key`` over ``xy`` copies to the clipboard (None: nothing, not a button)."""
        self.move(xy)
        seq = self.state()["seq"]
        self.xdotool("key", key)
        state = self.settle(2)
        return next((text for s, text in state["clipboard"] if s >= seq), None)

    def find_button(
        self,
        region: str,
        copied: str,
        step: int = 8,
        key: str = "ctrl+c",
        upward: bool = False,
        rows: range | None = None,
    ) -> tuple[float, float]:
        """Screen position of the button in ``region`` whose copy to the clipboard contains
        ``copied``: Ctrl+C over an operator button copies its Python call, Ctrl+Shift+C over a
        property its data path. Buttons are hovered top to bottom (or bottom to top; only ``rows``
        when given), as a user would."""
        left, top, width, height = self.state()["regions"][region]
        rows = range(top + 4, top + height - 4, step) if rows is None else rows
        for x in (left + width // 2, left + width // 4, left + 3 * width // 4):
            for y in reversed(rows) if upward else rows:
                self.move((x, y))
                seq = self.state()["seq"]
                self.xdotool("key", key)
                state = self.settle(2)
                if any(s >= seq and copied in text for s, text in state["clipboard"]):
                    return x, y
        raise LookupError(f"no button copying {copied!r} in the {region} region")

    # -- the sidebar ---------------------------------------------------------------------------
    def open_goniometer_tab(self) -> None:
        """Spend the swallowed first click on the sidebar's empty foot, then click the sidebar's
        tabs (on its right edge) until the Goniometer tab is active, as a user would (in Blender
        4.3 the tab cannot be set from Python)."""
        left, top, width, height = self.state()["regions"]["UI"]
        self.click((left + width // 2, top + height - 15))
        for y in range(top + 10, top + height - 10, 12):
            if self.state()["sidebar_category"] == "Goniometer":
                return
            self.click((left + width - 12, y))
        if self.state()["sidebar_category"] != "Goniometer":
            raise LookupError("no Goniometer tab on the sidebar")

    def open_panel_with(self, copied: str, below: float) -> tuple[float, float]:
        """Open the closed sidebar panel (below screen row ``below``) holding the button whose
        Ctrl+C copies ``copied``; return that button's position. The closed panels' headers are
        found by their disclosure triangles and tried in turn (a row where Ctrl+C copies
        something is a button, not a header); a wrong one is closed again."""
        region = self.state()["regions"]["UI"]
        left, _top, width, _height = region
        x = left + width // 3
        for header in closed_headers(self.screenshot("panels"), region, below):
            if self.copies((x, header)):
                continue
            self.click((x, header))
            try:
                return self.find_button("UI", copied, rows=range(header + 10, header + 90, 8))
            except LookupError:
                self.click((x, header))  # not this one: back as it was
        raise LookupError(f"no closed panel below row {below} with a button copying {copied!r}")

    def scroll_sidebar(self, clicks: int) -> None:
        """Turn the mouse wheel over the sidebar: ``clicks`` notches down (negative: up)."""
        left, top, width, height = self.state()["regions"]["UI"]
        self.move((left + width // 2, top + height // 2))
        button = "5" if clicks > 0 else "4"
        self.xdotool("click", "--repeat", str(abs(clicks)), "--delay", "40", button)
        self.settle()

    def open_last_panel_with(self, copied: str) -> tuple[float, float]:
        """Open the sidebar's last panel (scrolled to the end, the last header at its foot) and
        return the position of its button whose Ctrl+C copies ``copied`` (the sidebar is
        scrolled to the end again, so the whole panel shows)."""
        self.scroll_sidebar(30)
        left, top, width, height = region = self.state()["regions"]["UI"]
        bottom = top + height
        headers = closed_headers(self.screenshot("panels"), region, bottom - 160)
        if not headers:
            raise LookupError("no panel header at the foot of the sidebar")
        self.click((left + width // 3, headers[-1]))
        self.scroll_sidebar(30)
        return self.find_button("UI", copied, upward=True, rows=range(bottom - 240, bottom - 4, 6))

    def open_foot_panel(self, copied: str, from_end: int) -> tuple[float, float]:
        """Open the closed panel ``from_end`` places from the sidebar's foot (1: the last; the
        panels below a long Selected panel are only seen scrolled there) and return the position
        of its button whose Ctrl+C copies ``copied`` (scrolled to the end again)."""
        self.scroll_sidebar(30)
        left, top, width, height = region = self.state()["regions"]["UI"]
        bottom = top + height
        shot = self.screenshot("panels")
        headers = closed_headers(shot, region, bottom - 200)
        if len(headers) < from_end:  # a short sidebar: its panels end above its foot
            headers = closed_headers(shot, region, top)
        if len(headers) < from_end:
            raise LookupError(f"fewer than {from_end} panel headers at the sidebar's foot")
        self.click((left + width // 3, headers[-from_end]))
        self.scroll_sidebar(30)
        return self.find_button("UI", copied, upward=True, rows=range(bottom - 300, bottom, 6))

    def list_span(self, copied: str, rows: range) -> list[int]:
        """The screen rows (y) of ``rows`` over which a UI list in the sidebar shows: where
        Ctrl+Shift+C copies the list's active-index property (``copied``, e.g.
        ``"active_edge_index"``; every row of a list copies the same), hovered in turn."""
        left, _top, width, _height = self.state()["regions"]["UI"]
        x = left + width // 3
        return [
            y
            for y in rows
            if (text := self.copies((x, y), key="ctrl+shift+c")) is not None
            and text.endswith(copied)
        ]

    # -- pictures ----------------------------------------------------------------------------
    def screenshot(self, name: str = "shot") -> np.ndarray:
        """The whole X screen as an (height, width, 3) uint8 array (also kept as ``name``.ppm)."""
        path = f"{GUEST_TMP}/{name}.ppm"
        self.shell.check(
            f"xwd -root -silent -display {self.display} | xwdtopnm >{path} 2>/dev/null"
        )
        return read_ppm(self.tmp / f"{name}.ppm")

    def wait_for_change(self, before: np.ndarray, box, timeout: float, what: str) -> None:
        """Wait until a fifth of the pixels in ``box`` (left, top, width, height) differ from
        the screenshot ``before`` (e.g. a popup opened there)."""
        left, top, width, height = (int(v) for v in box)
        deadline = time.monotonic() + timeout
        while True:
            now = self.screenshot("change")
            cut = (slice(max(top, 0), top + height), slice(max(left, 0), left + width))
            changed = np.any(now[cut] != before[cut], axis=2).mean()
            if changed > 0.2:
                return
            if time.monotonic() > deadline:
                raise TimeoutError(f"waited {timeout} s for {what} to show")
            time.sleep(0.2)

    def save_png(self, name: str, destination: Path, crop=None) -> None:
        """Screenshot as PNG (optionally cropped to ``(left, top, width, height)``)."""
        path = f"{GUEST_TMP}/{name}.png"
        cut = ""
        if crop is not None:
            left, top, width, height = (int(v) for v in crop)
            cut = f"| pnmcut -left {left} -top {top} -width {width} -height {height} "
        self.shell.check(
            f"xwd -root -silent -display {self.display} | xwdtopnm 2>/dev/null {cut}"
            f"| pnmtopng -compression 9 >{path} 2>/dev/null"
        )
        shutil.copy(self.tmp / f"{name}.png", destination)


def read_ppm(path: Path) -> np.ndarray:
    """A binary PPM (P6, maxval 255) as an (height, width, 3) uint8 array."""
    data = path.read_bytes()
    fields, position = [], 0
    while len(fields) < 4:
        while data[position : position + 1].isspace():
            position += 1
        if data[position : position + 1] == b"#":
            position = data.index(b"\n", position)
            continue
        end = position
        while not data[end : end + 1].isspace():
            end += 1
        fields.append(data[position:end])
        position = end
    magic, width, height, maxval = fields[0], int(fields[1]), int(fields[2]), int(fields[3])
    if magic != b"P6" or maxval != 255:
        raise ValueError(f"{path}: not an 8-bit binary PPM")
    pixels = np.frombuffer(data, dtype=np.uint8, count=width * height * 3, offset=position + 1)
    return pixels.reshape(height, width, 3)


def closed_headers(shot, region, below: float) -> list[int]:
    """Screen rows of the panel headers in the sidebar below row ``below``: the rows where a
    disclosure triangle shows in the column just inside the panels' left edge."""
    left, top, _width, height = (int(v) for v in region)
    band = shot[int(below) + 12 : top + height, left + 18 : left + 36].min(axis=2) > 140
    rows = np.flatnonzero(band.any(axis=1)) + int(below) + 12
    if rows.size == 0:
        return []
    groups = np.split(rows, np.flatnonzero(np.diff(rows) > 8) + 1)
    return [int(group.mean()) for group in groups]


_TRACEBACK = "Traceback (most recent call last)"
_COMPLAINT = re.compile(r"error|warn|traceback|not found|exception", re.IGNORECASE)
_EXTENSION_NAME = re.compile(rf"{EXTENSION_PACKAGE}|\bVG_[A-Z]+_\w+|\bvg\.[a-z_]+\(")
_SOURCE_LINE = re.compile(rf"{EXTENSION_PACKAGE}/\S+\.py:\d+")


def console_complaints(text: str) -> list[str]:
    """Blender's console complaints in ``text``: every Python traceback, the extension's or
    Blender's own (a traceback in Blender's bundled add-ons means the root lacks a module
    Blender needs, and hides what the test would see), with its exception line; each line naming the
    extension (its package, a ``VG_*`` class, a ``vg.*(`` call) that says error, warning,
    traceback, exception or "not found", and each bare ``file.py:line`` of the extension that
    Blender prints under an RNA warning (with the warning line before it)."""
    lines = text.splitlines()
    found, index = [], 0
    while index < len(lines):
        line = lines[index]
        if _TRACEBACK in line:
            end = index + 1
            while end < len(lines) and (lines[end].startswith((" ", "\t")) or not lines[end]):
                end += 1
            found.append("\n".join(lines[index : end + 1]))
            index = end + 1
            continue
        if _SOURCE_LINE.search(line) and not line.lstrip().startswith("File "):
            found.append("\n".join(lines[max(index - 1, 0) : index + 1]))
        elif _EXTENSION_NAME.search(line) and _COMPLAINT.search(line):
            found.append(line)
        index += 1
    return found
