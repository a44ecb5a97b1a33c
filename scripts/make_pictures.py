"""Make the README's pictures from the real Blender GUI (Debian's Blender in a provisioned root).

    .venv/bin/python scripts/make_pictures.py            # -> docs/images/*.png
    .venv/bin/python scripts/make_pictures.py --suite trixie --out-dir /tmp/pictures

Needs root (scripts/provision_blender.sh makes the root on first use). The extension zip is built,
installed into a fresh Blender user folder, and a synthetic bone fragment (mm) is measured by
real drags with the Goniometer tool at three of its break sites, as a user would, driven with
xdotool (the same driver as the GUI test lane, tests/gui/driver.py). Pictures:

- ``panel.png``: the Goniometer sidebar with the list of measurements and the selected one;
- ``drag.png``: a drag in progress (the patch, its sides and the radius circle);
- ``sides.png``: the coloured sides of the measured patches on the fragment.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT), str(ROOT / "tests" / "gui")]

from driver import GuiBlender  # noqa: E402 (the GUI lane's driver)

from vg_addon.synthetic_meshes import bone_fragment  # noqa: E402 (the fragment of scene.py)

SITES = ("oblique/outer acute", "oblique/outer 45°", "oblique/outer side")
TOOL = "vg.measure_drag_tool"


def build_zip(out: Path) -> Path:
    result = subprocess.run(
        [sys.executable, str(ROOT / "scripts" / "build_extension.py"), "--output-dir", str(out)],
        capture_output=True,
        text=True,
        check=True,
    )
    return Path(result.stdout.strip().splitlines()[-1])


def drag(gui: GuiBlender, site: str, pixels: float, *, hold: bool = False) -> None:
    """Press on a break site, drag ``pixels`` to the right; release unless ``hold``."""
    start = gui.state()["points"][site]
    gui.move(start)
    gui.xdotool("mousedown", "1")
    gui.wait_for(lambda s: s["drag"] is not None, 30, "the drag to start")
    for i in range(1, 7):
        gui.move((start[0] + pixels * i / 6, start[1]))
    gui.settle(5)
    if not hold:
        gui.xdotool("mouseup", "1")
        gui.wait_for(lambda s: s["drag"] is None, 30, "the drag to end")
        gui.settle(5)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--suite", default="unstable", help="Debian suite of the Blender root")
    parser.add_argument("--out-dir", type=Path, default=ROOT / "docs" / "images")
    args = parser.parse_args(argv)
    subprocess.run(["bash", str(ROOT / "scripts" / "provision_blender.sh"), args.suite], check=True)
    args.out_dir.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as dist:
        gui = GuiBlender(args.suite, build_zip(Path(dist)), {}, scene="fragment")
    try:
        state = gui.state()
        left, top, width, height = state["regions"]["UI"]
        gui.click((left + width // 2, top + height - 15))  # the swallowed first click
        for y in range(top + 10, top + height - 10, 12):  # the Goniometer tab
            gui.click((left + width - 12, y))
            if gui.state()["sidebar_category"] == "Goniometer":
                break
        gui.click(gui.find_button("TOOLS", TOOL, step=12))
        gui.wait_for(lambda s: s["tool"] == TOOL, 10, "the Goniometer tool")
        gui.settle(5)
        for site in SITES[:2]:
            drag(gui, site, 40)
        drag(gui, SITES[2], 40, hold=True)
        window = gui.state()["regions"]["WINDOW"]
        tall = min(window[3], 800)  # the middle of the (tall) viewport, where the view centre is
        view = (window[0], window[1] + (window[3] - tall) // 2, left - window[0], tall)
        gui.save_png("drag", args.out_dir / "drag.png", crop=view)
        gui.xdotool("mouseup", "1")
        gui.wait_for(lambda s: s["drag"] is None, 30, "the drag to end")
        gui.settle(10)
        gui.save_png("sides", args.out_dir / "sides.png", crop=view)
        gui.save_png("panel", args.out_dir / "panel.png", crop=(left, top, width, 900))
        items = gui.state()["objects"]["BoneFragment"]["measurements"]
        truth = {site.label: site.angle for site in bone_fragment(spacing=0.4).sites}
        for site, item in zip(SITES, items, strict=False):
            exact = item["exact"]
            print(
                f"measurement {item['number']} at {site} (true {truth[site]:.2f}°): "
                f"{exact['angle']:.4f}°, radius {exact['radius']:.3f} mm, "
                f"{item['n_vertices']} vertices"
            )
    finally:
        gui.close()
    print(f"pictures in {args.out_dir}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
