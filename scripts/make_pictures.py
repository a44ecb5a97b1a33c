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

``--refinement`` makes instead the pictures of docs/REFINEMENT_STUDY.md: ``sample_mesh.ply``
(from ``../shared/data``) is imported in the GUI Blender and measured, through the Python console
as a user would type it (``bpy.ops.vg.measure_xyz`` with a location and a rule), at the vertices
whose readings the refined rule moves most (of the study's 300 break-edge points,
``scripts/compare_rules.py``), with each rule in turn; the painted sides are
photographed looking along the refined crease from 30° above the ridge and from straight above
(``refinement_view_<vertex>_along.png``, ``..._above.png``: refined left, oriented right).
"""

from __future__ import annotations

import argparse
import contextlib
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT), str(ROOT / "tests" / "gui")]

import numpy as np  # noqa: E402
from compare_rules import compare_on  # noqa: E402 (the study's own draw and measurements)
from driver import GUEST_TMP, GuiBlender  # noqa: E402 (the GUI lane's driver)

from vg_addon.formats.meshio import read_mesh  # noqa: E402
from vg_addon.synthetic_meshes import bone_fragment  # noqa: E402 (the fragment of scene.py)

SITES = ("oblique/outer acute", "oblique/outer 45°", "oblique/outer side")
TOOL = "vg.measure_drag_tool"
SAMPLE = ROOT.parent / "shared" / "data" / "sample_mesh.ply"
N_MOVED = 3  # the largest moves of docs/REFINEMENT_STUDY.md pictured
TILT = 30.0  # degrees above the crease the "along" view looks down
RULES = ("refined", "oriented")
HALF = 260  # half the side of each rule's square of the viewport, in pixels


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


def _unit(vector: np.ndarray) -> np.ndarray:
    return vector / np.linalg.norm(vector)


def view_rotation(look: np.ndarray, up: np.ndarray) -> list[list[float]]:
    """Rows of the view's rotation matrix (view to world) looking along ``look``, ``up`` up."""
    back = -_unit(look)
    up = _unit(up - (up @ back) * back)
    right = np.cross(up, back)
    return np.column_stack([right, up, back]).round(6).tolist()


def console_line(gui: GuiBlender, console, line: str) -> None:
    """Type ``line`` into Blender's Python console (at screen point ``console``) and run it."""
    gui.move(console)
    gui.type_text(line)
    gui.key("Return")
    gui.settle(5)


def refinement_pictures(gui: GuiBlender, out_dir: Path) -> None:
    """Measure the study's largest moves with both rules and photograph the painted sides."""
    mesh = read_mesh(SAMPLE)
    points = mesh.points.astype(np.float64)
    _row, _surface, radius, readings = compare_on(SAMPLE.name, points, mesh.triangles)
    readings.sort(key=lambda reading: -abs(reading[1].angle - reading[2].angle))
    shutil.copy(SAMPLE, gui.tmp / SAMPLE.name)
    before = gui.state()["regions"]["WINDOW"]
    gui.move((before[0] + before[2] // 2, before[1] + before[3] // 2))
    for _ in range(3):  # the window's first key may be swallowed, as its first click is
        gui.key("ctrl+Prior")  # the workspace before Layout: Scripting, with a Python console
        with contextlib.suppress(TimeoutError):
            window = gui.wait_for(
                lambda s: s["regions"].get("WINDOW", before) != before, 5, "the Scripting tab"
            )["regions"]["WINDOW"]
            break
    else:
        raise RuntimeError("Ctrl+Page Up did not open the Scripting workspace")
    gui.settle(10)
    below = window[1] + window[3]
    console = (window[0] + window[2] // 2, below + 80)
    console_line(gui, console, 'bpy.data.objects.remove(bpy.data.objects["Wedge"])')
    console_line(gui, console, f'bpy.ops.wm.ply_import(filepath="{GUEST_TMP}/{SAMPLE.name}")')
    gui.wait_for(lambda s: "sample_mesh" in s["objects"], 60, "the imported sample mesh")
    console_line(
        gui,
        console,
        'sp = [a for a in C.screen.areas if a.type == "VIEW_3D"][0].spaces.active; '
        "from mathutils import Matrix; "
        "sp.show_region_ui = sp.show_region_toolbar = sp.show_gizmo_navigate = False; "
        "sp.overlay.show_floor = sp.overlay.show_axis_x = sp.overlay.show_axis_y = False; "
        "C.object.select_set(False); "
        'r = sp.region_3d; r.view_perspective = "ORTHO"; r.view_distance = 8.0',
    )
    window = gui.state()["regions"]["WINDOW"]
    middle = (window[0] + window[2] // 2, window[1] + window[3] // 2)
    half = min(HALF, (min(window[2], window[3]) - 10) // 2)
    square = (middle[0] - half, middle[1] - half, 2 * half, 2 * half)
    for vertex, refined, oriented in readings[:N_MOVED]:
        center = points[vertex]
        expected = {"refined": refined.angle, "oriented": oriented.angle}
        crease = _unit(np.cross(refined.normal_plus, refined.normal_minus))
        up = _unit(refined.normal_plus + refined.normal_minus)
        tilt = np.radians(TILT)
        views = {
            "along": view_rotation(np.cos(tilt) * crease - np.sin(tilt) * up, up),
            "above": view_rotation(-up, crease),
        }
        location = ", ".join(f"{v:.6f}" for v in center)
        console_line(gui, console, f"r.view_location = ({location})")
        shots = {}
        for rule in RULES:
            console_line(
                gui, console, "bpy.ops.vg.clear_measurements() if C.object.vg.measurements else 0"
            )
            console_line(
                gui,
                console,
                f"bpy.ops.vg.measure_xyz(location=({location}), radius={radius:.6f}, "
                f'rule="{rule}")',
            )
            items = gui.wait_for(
                lambda s: len(s["objects"]["sample_mesh"]["measurements"]) == 1,
                120,
                f"the {rule} measurement at vertex {vertex}",
            )["objects"]["sample_mesh"]["measurements"]
            angle = items[0]["exact"]["angle"]
            print(
                f"vertex {vertex}, rule {rule}: {angle:.2f}° (outside Blender {expected[rule]:.2f}°)"
            )
            if abs(angle - expected[rule]) > 1e-6:  # a picture of another reading is no evidence
                raise RuntimeError(f"vertex {vertex}, {rule}: Blender read {angle}°")
            for name, rows in views.items():
                console_line(gui, console, f"r.view_rotation = Matrix({rows}).to_quaternion()")
                gui.settle(10)
                shots[name, rule] = f"{vertex}_{name}_{rule}"
                gui.save_png(
                    shots[name, rule], gui.tmp / f"{shots[name, rule]}_cut.png", crop=square
                )
        for name in views:
            refined_shot, oriented_shot = (
                f"{GUEST_TMP}/{shots[name, rule]}_cut.png" for rule in RULES
            )
            target = f"refinement_view_{vertex}_{name}.png"
            gui.shell.check(
                f"pnmcat -lr <(pngtopnm {refined_shot}) <(pngtopnm {oriented_shot}) "
                f"| pnmtopng -compression 9 >{GUEST_TMP}/{target}"
            )
            shutil.copy(gui.tmp / target, out_dir / target)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--suite", default="unstable", help="Debian suite of the Blender root")
    parser.add_argument("--out-dir", type=Path, default=ROOT / "docs" / "images")
    parser.add_argument(
        "--refinement", action="store_true", help="the refinement study's pictures instead"
    )
    args = parser.parse_args(argv)
    subprocess.run(["bash", str(ROOT / "scripts" / "provision_blender.sh"), args.suite], check=True)
    args.out_dir.mkdir(parents=True, exist_ok=True)
    if args.refinement:
        with tempfile.TemporaryDirectory() as dist:
            gui = GuiBlender(args.suite, build_zip(Path(dist)), {}, scene="wedge")
        try:
            refinement_pictures(gui, args.out_dir)
        finally:
            gui.close()
        print(f"pictures in {args.out_dir}")
        return 0
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
