"""Virtual Goniometer batch runs: measure break angles on many meshes and points, headless.

Runs inside Blender or with the ``bpy`` module from PyPI, with the same arguments and results:

    blender -b [file.blend] --python vg_batch.py -- ARGS
    python vg_batch.py ARGS

The repository root is the extension package: this script imports it from the folder it sits in
and registers it, so the measurements are taken, stored and coloured exactly as the extension
does it (see the README, "Batch runs from the command line").
"""

from __future__ import annotations

import argparse
import contextlib
import csv
import dataclasses
import functools
import importlib
import importlib.util
import json
import os
import shutil
import subprocess
import sys
import tempfile
import threading
import time
import traceback
from collections import deque
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent
PACKAGE = "virtual_goniometer"  # the name the repository root is imported under
# Blender's own Python has imported bpy before it runs a --python script; a plain Python has not.
IN_BLENDER = "bpy" in sys.modules
MARK = "@@vg-batch@@"  # prefix of the lines a worker sends to its parent on stdout
DEMO_DIR = "vg_demo_output"
# Testing aid: a worker process (--jobs 2 or more) aborts, as a native crash would, when it
# starts on the mesh named by this environment variable.
ABORT_VARIABLE = "VG_BATCH_ABORT_ON_MESH"
# --units: Blender's unit system, unit scale and length unit for what one coordinate unit is.
UNITS = {
    "none": ("NONE", 1.0, None),
    "m": ("METRIC", 1.0, "METERS"),
    "cm": ("METRIC", 0.01, "CENTIMETERS"),
    "mm": ("METRIC", 0.001, "MILLIMETERS"),
    "um": ("METRIC", 1e-6, "MICROMETERS"),
    "in": ("IMPERIAL", 0.0254, "INCHES"),
}
# mm: the demo's patch radius. Larger patches average more of the curved cylinder walls, which
# pulls the measured angles away from the ideal ones at the rims (about 1° at 1 mm, 3° at 2 mm).
DEMO_RADIUS = 1.0

EPILOG = """\
inputs:
  MESH is a .ply, .obj or .stl file, a folder (its .ply/.obj/.stl files, not subfolders), or a
  .blend file (then name the objects with --object; under `blender -b file.blend` the open file
  is used). Coordinates and radii are in the mesh file's own units; the file's coordinates are
  used as they are (no axis conversion).

points:
  --at X Y Z (repeatable) measures each point on every mesh given.
  --points CSV reads a plain CSV (x,y,z and optional radius, lambda, patch, label, break, mesh
  columns) or a measurements CSV exported by the extension, the MeshLab plugin or the earlier
  Blender add-on: each row is re-measured with its own radius and lambda and matched to its
  mesh by its mesh name (the file name without extension). --radius, --lambda and --patch are
  the defaults for rows that carry none.

output:
  --out CSV gets one row per requested point, in input order, in the extension's export
  schema (MeshLab's 14 columns first). A row that cannot be measured has its message in the
  `error` column and the run goes on. While meshes finish, the CSV is rewritten every few
  seconds, so a run that is stopped keeps what it measured.

exit status:
  0  every point measured
  1  some rows failed (see their `error` column)
  2  bad arguments, missing or unreadable files, a malformed points CSV

scaling:
  --jobs N measures N meshes at a time, each in its own Blender/bpy process (a crash in one
  mesh loses only that mesh's rows). --shard K/N keeps the K-th of N equal, contiguous shares
  of the rows: shard CSVs concatenated in K order (headers dropped after the first) equal the
  unsharded CSV. Measurements per second are printed (mesh import and surface preparation
  excluded).

examples:
  python vg_batch.py scan.ply --at 12.1 3.4 -7.9 --radius 2 --out angles.csv
  python vg_batch.py scans/ --points sites.csv --radius 2 --jobs 2 --out angles.csv
  python vg_batch.py scan.ply --points old_meshlab.csv --out replicated.csv --save-blend s.blend
  blender -b study.blend --python vg_batch.py -- --object Bone_12 --points p.csv --out a.csv
  python vg_batch.py --demo
"""


# --------------------------------------------------------------------------- command line


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="vg_batch.py",
        usage="blender -b [file.blend] --python vg_batch.py -- ARGS\n"
        "       python vg_batch.py ARGS\n\n"
        "ARGS:  MESH... [--object NAME] (--at X Y Z ... | --points CSV) [--radius R]\n"
        "       [--lambda L] [--patch euclidean|geodesic] --out CSV [--save-blend PATH]\n"
        "       [--render DIR] [--jobs N] [--shard K/N]\n"
        "   or: --demo [--out-dir DIR]",
        description="Measure break-edge angles (the Virtual Goniometer) on meshes and point "
        "lists, headless, and write them to a CSV.",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "inputs",
        nargs="*",
        metavar="MESH",
        help="mesh files (.ply .obj .stl), folders of them, or one .blend file",
    )
    parser.add_argument(
        "--object",
        action="append",
        default=[],
        metavar="NAME",
        help="an object of the .blend to measure (repeatable; default: its only mesh object)",
    )
    where = parser.add_argument_group("points (one of)")
    where.add_argument(
        "--at",
        nargs=3,
        type=float,
        action="append",
        default=[],
        metavar=("X", "Y", "Z"),
        help="a point to measure at (repeatable); it snaps to the nearest vertex",
    )
    where.add_argument("--points", metavar="CSV", help="a points or measurements CSV")
    how = parser.add_argument_group("measuring")
    how.add_argument(
        "--radius",
        type=float,
        metavar="R",
        help="patch radius in the mesh's units (needed with --at; default for CSV rows without one)",
    )
    how.add_argument(
        "--lambda",
        dest="lam",
        type=float,
        default=2.0,
        metavar="L",
        help="segmentation parameter λ (MeshLab's SegParam); default 2",
    )
    how.add_argument(
        "--patch",
        choices=("euclidean", "geodesic"),
        default="euclidean",
        help="patch shape: a ball (euclidean, default) or along mesh edges (geodesic)",
    )
    how.add_argument(
        "--units",
        choices=tuple(UNITS),
        help="what one coordinate unit of the meshes is, recorded in the CSV's Units column and "
        "the .blend's scene units (default: none, i.e. the file's own units, unnamed; a .blend "
        "input keeps its scene's units)",
    )
    how.add_argument(
        "--ignore-mesh-names",
        action="store_true",
        help="with a single mesh, measure every CSV row on it whatever mesh the row names",
    )
    out = parser.add_argument_group("output")
    out.add_argument("--out", metavar="CSV", help="the measurements CSV to write (required)")
    out.add_argument(
        "--save-blend",
        metavar="PATH",
        help="also save a .blend with the meshes, their side colours and stored measurements",
    )
    out.add_argument(
        "--render",
        metavar="DIR",
        help="write DIR/<mesh>.png per mesh: the coloured sides, Cycles on the CPU",
    )
    out.add_argument(
        "--render-size",
        nargs=2,
        type=int,
        default=[640, 480],
        metavar=("W", "H"),
        help="render resolution in pixels (default 640 480)",
    )
    out.add_argument(
        "--render-samples",
        type=int,
        default=16,
        metavar="N",
        help="Cycles samples per pixel (default 16)",
    )
    out.add_argument("--quiet", action="store_true", help="no progress lines (summary only)")
    scale = parser.add_argument_group("scaling")
    scale.add_argument(
        "--jobs",
        type=int,
        default=1,
        metavar="N",
        help="meshes measured in parallel, one process each (default 1: in this process)",
    )
    scale.add_argument(
        "--shard", metavar="K/N", help="do only the K-th of N equal shares of the rows"
    )
    demo = parser.add_argument_group("demo")
    demo.add_argument(
        "--demo",
        action="store_true",
        help="generate a bone-shaft fragment with known break angles, measure it, print true "
        "against measured angles and write CSV, .blend and PNG",
    )
    demo.add_argument(
        "--out-dir", metavar="DIR", help=f"the demo's output folder (default ./{DEMO_DIR})"
    )
    parser.add_argument("--worker", help=argparse.SUPPRESS)
    return parser


def script_argv() -> list[str]:
    """The script's own arguments: after ``--`` under Blender, else after the script name."""
    if IN_BLENDER:
        return sys.argv[sys.argv.index("--") + 1 :] if "--" in sys.argv else []
    return sys.argv[1:]


# The extension packages this script registered, to unregister before the process ends: the bpy
# 4.2 module crashes at exit if Python classes are still registered then.
_registered: list = []


class UsageError(Exception):
    """Bad arguments or input files: exit status 2."""


def check_args(args) -> None:
    if args.demo:
        extra = [
            name
            for name, value in (
                ("MESH", args.inputs),
                ("--object", args.object),
                ("--at", args.at),
                ("--points", args.points),
                ("--out", args.out),
                ("--shard", args.shard),
            )
            if value
        ]
        if extra:
            raise UsageError(f"--demo takes no {', '.join(extra)} (only --out-dir and --jobs).")
        return
    if args.out_dir:
        raise UsageError("--out-dir is for --demo; use --out CSV for a batch run.")
    if bool(args.at) == bool(args.points):
        raise UsageError("give the points to measure: --at X Y Z (repeatable) or --points CSV.")
    if not args.out:
        raise UsageError("--out CSV is required: the measurements CSV to write.")
    if args.jobs < 1:
        raise UsageError(f"--jobs must be 1 or more (got {args.jobs}).")
    if min(args.render_size) < 1 or args.render_samples < 1:
        raise UsageError("--render-size and --render-samples must be positive.")


# --------------------------------------------------------------------------- the extension


class Context:
    """The imported extension and the modules of it this script uses."""

    def __init__(self, package):
        self.package = package
        self.bpy = importlib.import_module("bpy")
        name = package.__name__
        self.csvio = importlib.import_module(f"{name}.vg_addon.formats.csvio")
        self.meshio = importlib.import_module(f"{name}.vg_addon.formats.meshio")
        self.batchplan = importlib.import_module(f"{name}.vg_addon.workflow.batchplan")
        self.mesh_data = importlib.import_module(f"{name}.bridge.mesh_data")
        self.measuring = importlib.import_module(f"{name}.bridge.measuring")
        self.records = importlib.import_module(f"{name}.bridge.records")
        self.colors = importlib.import_module(f"{name}.bridge.colors")
        self.GoniometerError = package.vg_addon.GoniometerError


def import_bpy():
    try:
        return importlib.import_module("bpy")
    except ImportError:
        raise UsageError(
            "the bpy module is not installed in this Python. Run `bash scripts/setup.sh` and use "
            ".venv/bin/python vg_batch.py ..., or run it in Blender: "
            "blender -b --python vg_batch.py -- ..."
        ) from None


def load_extension() -> Context:
    """Import the repository root as the extension package and register it (once)."""
    bpy = import_bpy()
    addon_utils = importlib.import_module("addon_utils")
    for name in list(bpy.context.preferences.addons.keys()):
        if name.rpartition(".")[2] != "virtual_goniometer" or name == PACKAGE:
            continue
        module = sys.modules.get(name)
        if module is not None and Path(module.__file__).resolve().parent == ROOT:
            return Context(module)  # Blender already runs this very copy
        # Another copy (e.g. an installed older version) owns the vg.* names: switch it off for
        # this session only (default_set=False leaves the preferences as they are).
        addon_utils.disable(name, default_set=False)
    if PACKAGE in sys.modules:
        return Context(sys.modules[PACKAGE])
    spec = importlib.util.spec_from_file_location(
        PACKAGE, ROOT / "__init__.py", submodule_search_locations=[str(ROOT)]
    )
    package = importlib.util.module_from_spec(spec)
    sys.modules[PACKAGE] = package
    spec.loader.exec_module(package)
    package.register()
    _registered.append(package)
    return Context(package)


# --------------------------------------------------------------------------- input meshes


@dataclasses.dataclass
class MeshSource:
    """A mesh to measure: a file to import, or an object of the open .blend."""

    name: str
    path: str = ""  # the mesh file; "" for a .blend object
    aliases: tuple[str, ...] = ()

    @property
    def names(self) -> tuple[str, ...]:
        return (self.name, *self.aliases)


def start_file(ctx_bpy, inputs: list[str]) -> tuple[list[str], str]:
    """Open the .blend among ``inputs`` (or keep the one Blender opened), else start empty.

    Returns the other inputs and the .blend path ("" if none).
    """
    blends = [p for p in inputs if p.lower().endswith(".blend")]
    others = [p for p in inputs if not p.lower().endswith(".blend")]
    if len(blends) > 1:
        raise UsageError(f"give at most one .blend file (got {', '.join(blends)}).")
    if blends:
        path = Path(blends[0])
        if not path.is_file():
            raise UsageError(f"{blends[0]}: no such .blend file.")
        try:
            with quiet_stdout():
                ctx_bpy.ops.wm.open_mainfile(filepath=str(path.resolve()), load_ui=False)
        except RuntimeError as error:
            raise UsageError(
                f"{blends[0]}: cannot open it as a .blend file ({str(error).strip()})."
            ) from None
        return others, str(path)
    if IN_BLENDER and ctx_bpy.data.filepath:
        return others, ctx_bpy.data.filepath
    ctx_bpy.ops.wm.read_homefile(use_empty=True)
    return others, ""


def blend_objects(ctx: Context, names: list[str], blend: str) -> list[MeshSource]:
    bpy = ctx.bpy
    if not blend:
        if names:
            raise UsageError("--object names an object of a .blend file: give the .blend too.")
        return []
    if not names:
        meshes = [o for o in bpy.context.scene.objects if o.type == "MESH"]
        if len(meshes) != 1:
            listed = ", ".join(o.name for o in meshes[:10]) or "none"
            raise UsageError(
                f"{blend} has {len(meshes)} mesh objects ({listed}): name the ones to measure "
                "with --object NAME."
            )
        names = [meshes[0].name]
    sources, problems = [], []
    for name in names:
        obj = bpy.data.objects.get(name)
        if obj is None:
            problems.append(f"{blend} has no object named {name!r}")
            continue
        try:
            ctx.mesh_data.check_measurable(obj)
        except ctx.GoniometerError as error:
            problems.append(str(error))
            continue
        sources.append(MeshSource(obj.name, "", (obj.data.name,)))
    if problems:
        raise UsageError("\n  ".join(["cannot measure these objects:", *problems]))
    return sources


def file_sources(ctx: Context, inputs: list[str]) -> list[MeshSource]:
    if not inputs:
        return []
    try:
        files = ctx.batchplan.find_mesh_files(inputs)
        names = ctx.batchplan.mesh_names(files)
    except ctx.GoniometerError as error:
        raise UsageError(str(error)) from None
    return [MeshSource(name, str(path)) for name, path in zip(names, files, strict=True)]


def import_mesh(ctx: Context, source: MeshSource):
    """A new mesh object made from ``source``'s file (float32 coordinates, as Blender stores
    them), linked to the scene at the world origin."""
    bpy = ctx.bpy
    data = ctx.meshio.read_mesh(source.path)
    points = np.ascontiguousarray(data.points, dtype=np.float32)
    mesh = bpy.data.meshes.new(source.name)
    mesh.vertices.add(points.shape[0])
    mesh.vertices.foreach_set("co", points.ravel())
    if data.triangles is not None:
        triangles = np.ascontiguousarray(data.triangles, dtype=np.int32)
        mesh.loops.add(triangles.size)
        mesh.loops.foreach_set("vertex_index", triangles.ravel())
        mesh.polygons.add(triangles.shape[0])
        mesh.polygons.foreach_set("loop_start", np.arange(0, triangles.size, 3, dtype=np.int32))
    mesh.update(calc_edges=True)
    # Drop degenerate and duplicate faces as Blender's own importers do, so the object is the
    # one File > Import would make from the same file.
    mesh.validate(verbose=False)
    obj = bpy.data.objects.new(source.name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


# --------------------------------------------------------------------------- measuring one mesh


@dataclasses.dataclass
class MeshResult:
    """What measuring one mesh produced (sent from a worker to its parent as JSON)."""

    mesh: int
    rows: list = dataclasses.field(default_factory=list)  # [(task index, MeasurementRow)]
    object_name: str = ""
    bad_file: str = ""  # why the mesh file could not be read
    n_vertices: int = 0
    measured: int = 0
    failed: int = 0
    load_seconds: float = 0.0
    prepare_seconds: float = 0.0
    measure_seconds: float = 0.0
    render: str = ""
    render_error: str = ""
    blend: str = ""  # a worker's one-object .blend, for --save-blend

    def to_json(self) -> dict:
        out = dataclasses.asdict(self)
        out["rows"] = [[index, dataclasses.asdict(row)] for index, row in self.rows]
        return out

    @classmethod
    def from_json(cls, data: dict, row_type) -> MeshResult:
        rows = []
        for index, fields in data.pop("rows"):
            for key in ("normal_plus", "normal_minus", "requested"):
                if fields.get(key) is not None:
                    fields[key] = tuple(fields[key])
            rows.append((index, row_type(**fields)))
        return cls(rows=rows, **data)


def error_row(ctx: Context, task, mesh_name: str, message: str, units: str):
    """The output row of a task that could not be measured."""
    return ctx.csvio.MeasurementRow(
        mesh_name=mesh_name,
        date=ctx.csvio.now_iso(),
        number=task.number or None,
        break_number=task.break_number,
        user_data=task.label,
        radius=task.radius,
        seg_param=task.lam,
        patch=task.patch,
        requested=tuple(task.center),
        units=units,
        extension_version=ctx.records.extension_version(),
        blender_version=ctx.bpy.app.version_string,
        error=message,
    )


def measure_mesh(ctx: Context, index: int, source: MeshSource, tasks, options, progress=None):
    """Load (or find) one mesh, measure its tasks, record them on the object, colour it and
    optionally render it. Never raises for a problem of this mesh: it becomes the rows' error.

    The numbers come from the extension's own pipeline: the object's evaluated mesh in world
    space (``mesh_data.evaluated_geometry``), its cached ``Surface`` (``mesh_data.surface_for``)
    and ``records.add_measurement``; ``measuring.measure_on_object`` does the same per click,
    re-evaluating the mesh and repainting each time, which a batch does once per mesh instead.
    """
    bpy = ctx.bpy
    result = MeshResult(mesh=index)
    units = ctx.records.units_label(bpy.context.scene)

    def fail_all(message: str) -> MeshResult:
        name = result.object_name or source.name
        result.rows = [(t.index, error_row(ctx, t, name, message, units)) for t in tasks]
        result.failed = len(tasks)
        return result

    start = time.perf_counter()
    try:
        obj = import_mesh(ctx, source) if source.path else bpy.data.objects[source.name]
    except ctx.GoniometerError as error:
        result.bad_file = str(error)
        return fail_all(f"could not read the mesh: {error}")
    except MemoryError:
        result.bad_file = f"'{source.path}' is too large for this machine's memory"
        return fail_all(f"could not read the mesh: {result.bad_file}")
    result.object_name = obj.name
    result.load_seconds = time.perf_counter() - start

    start = time.perf_counter()
    try:
        ctx.mesh_data.check_measurable(obj)
        geometry = ctx.mesh_data.evaluated_geometry(obj)
        surface = ctx.mesh_data.surface_for(obj, geometry)
    except ctx.GoniometerError as error:
        return fail_all(str(error))
    result.n_vertices = int(geometry.points.shape[0])
    result.prepare_seconds = time.perf_counter() - start

    data = obj.vg
    base = data.next_number - 1  # measurements already on a .blend object keep their numbers
    fresh = len(data.measurements) == 0
    # Per vertex, the break number and side of the last measurement covering it (0: none), so
    # the colours are painted once at the end without keeping every measurement in memory.
    painter = np.zeros(result.n_vertices, dtype=np.int64)
    plus_side = np.zeros(result.n_vertices, dtype=bool)
    view = np.zeros(3)
    last_report = start = time.perf_counter()
    for done, task in enumerate(tasks, start=1):
        try:
            m = surface.measure(task.center, task.radius, task.lam, task.patch)
        except ctx.GoniometerError as error:
            result.rows.append((task.index, error_row(ctx, task, obj.name, str(error), units)))
            result.failed += 1
        else:
            data.next_number = base + task.number
            item = ctx.records.add_measurement(
                obj, m, geometry.fingerprint, note=task.label, break_number=task.break_number
            )
            result.rows.append(
                (task.index, ctx.records.to_row(obj, item, stale=False, units=units))
            )
            painter[m.indices] = item.break_number
            plus_side[m.indices] = m.labels
            view += m.mean_normal
            result.measured += 1
        now = time.perf_counter()
        if progress is not None and now - last_report >= 1.0:
            progress(done)
            last_report = now
    result.measure_seconds = time.perf_counter() - start
    if len(data.measurements):
        data.next_number = max(item.number for item in data.measurements) + 1
        ctx.records.continue_after_recorded_breaks(obj)

    if result.measured:
        if fresh and len(obj.data.vertices) == result.n_vertices:
            # Every measurement is this run's, on these vertices: paint them as repaint() would
            # (later over earlier), without measuring each one again.
            painted = np.flatnonzero(painter)
            sides = [
                (vertices, plus_side[vertices], int(number))
                for number in np.unique(painter[painted])
                for vertices in [painted[painter[painted] == number]]
            ]
            rgba = ctx.colors.side_colours(result.n_vertices, sides)
            ctx.colors.write_attribute(obj.data, rgba)
        else:
            ctx.measuring.repaint(obj, geometry=geometry)
        add_sides_material(bpy, obj, ctx.colors.ATTRIBUTE_NAME)

    if options.get("render"):
        path = Path(options["render"]) / f"{safe_file_name(obj.name)}.png"
        try:
            render_object(bpy, obj, path, options, view.tolist())
            result.render = str(path)
        except Exception as error:  # a render problem must not lose the measurements
            result.render_error = f"{type(error).__name__}: {error}"
    return result


def set_units(scene, unit: str | None) -> None:
    """Set the scene's length units to ``unit`` (a key of :data:`UNITS`); None: leave them."""
    if not unit:
        return
    system, scale, length = UNITS[unit]
    settings = scene.unit_settings
    settings.system = system
    settings.scale_length = scale
    if length is not None:
        settings.length_unit = length


def safe_measure_mesh(ctx: Context, index: int, source: MeshSource, tasks, options, progress):
    """:func:`measure_mesh`, with an unexpected error (a bug) turned into failed rows for this
    mesh only, its traceback on stderr, so the other meshes are still measured."""
    try:
        return measure_mesh(ctx, index, source, tasks, options, progress)
    except Exception as error:
        traceback.print_exc()
        message = (
            f"internal error while measuring this mesh ({type(error).__name__}: {error}); "
            "please report it with the traceback printed on stderr"
        )
        units = ctx.records.units_label(ctx.bpy.context.scene)
        result = MeshResult(mesh=index, failed=len(tasks))
        result.rows = [(t.index, error_row(ctx, t, source.name, message, units)) for t in tasks]
        return result


def safe_file_name(name: str) -> str:
    return "".join(c if c.isalnum() or c in "-_.+" else "_" for c in name) or "mesh"


# --------------------------------------------------------------------------- colour and render


def add_sides_material(bpy, obj, attribute: str):
    """Give a mesh without materials one that shows the side colours (Color Attribute node)."""
    material = bpy.data.materials.get("VG Sides")
    if material is None:
        material = bpy.data.materials.new("VG Sides")
        if material.node_tree is None:  # Blender < 5: nodes are off by default
            material.use_nodes = True
        nodes = material.node_tree.nodes
        shader = next(n for n in nodes if n.type == "BSDF_PRINCIPLED")
        shader.inputs["Roughness"].default_value = 0.6
        colour = nodes.new("ShaderNodeVertexColor")
        colour.layer_name = attribute
        colour.location = (shader.location.x - 300, shader.location.y)
        material.node_tree.links.new(colour.outputs["Color"], shader.inputs["Base Color"])
    if not obj.data.materials:
        obj.data.materials.append(material)
    return material


@contextlib.contextmanager
def quiet_stdout():
    """Silence what Blender prints on the C level (render and save chatter) for a while."""
    sys.stdout.flush()
    try:
        saved = os.dup(1)
    except OSError:
        yield
        return
    try:
        with open(os.devnull, "wb") as null:
            os.dup2(null.fileno(), 1)
            yield
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(saved)


def render_object(bpy, obj, path: Path, options: dict, view) -> None:
    """Render ``obj`` alone with Cycles on the CPU: an orthographic camera framing it, looking
    along ``view`` (e.g. the sum of the measured patches' mean normals), a sun and a grey sky,
    every surface shown with the side colours."""
    import mathutils

    width, height = options.get("render_size", (640, 480))
    direction = mathutils.Vector(view)
    if direction.length < 1e-9:
        direction = mathutils.Vector((1.0, -1.0, 0.8))
    direction.normalize()
    # Look from ``direction`` but a little from above, so the sides read as 3D.
    direction = (direction + mathutils.Vector((0.0, 0.0, 0.35))).normalized()

    scene = bpy.data.scenes.new("VG Render")
    made = []
    try:
        scene.collection.objects.link(obj)
        material = add_sides_material(bpy, obj, "VG Sides")
        scene.view_layers[0].material_override = material

        camera_data = bpy.data.cameras.new("VG Camera")
        camera_data.type = "ORTHO"
        camera = bpy.data.objects.new("VG Camera", camera_data)
        made += [camera, camera_data]
        scene.collection.objects.link(camera)
        scene.camera = camera
        matrix = (-direction).to_track_quat("-Z", "Y").to_matrix()
        right, up, back = (np.array(matrix.col[i]) for i in range(3))
        corners = np.array([obj.matrix_world @ mathutils.Vector(c) for c in obj.bound_box])
        along = [corners @ axis for axis in (right, up, back)]
        extent = [a.max() - a.min() for a in along]
        if width != height and (extent[1] > extent[0]) == (width > height):
            # Roll the camera a quarter turn so the mesh's long side runs along the image's.
            right, up = up, -right
            along[0], along[1] = along[1], -along[0]
            extent[0], extent[1] = extent[1], extent[0]
        rotation = mathutils.Matrix(np.column_stack([right, up, back]).tolist()).to_quaternion()
        size = max(max(extent), 1e-6)
        aspect = width / height
        camera_data.ortho_scale = 1.1 * max(extent[0], extent[1] * aspect, size * 1e-3)
        camera_data.clip_start = size * 1e-3
        camera_data.clip_end = extent[2] + 2.0 * size
        centre = sum(
            axis * (a.max() + a.min()) / 2 for axis, a in zip((right, up), along[:2], strict=True)
        )
        camera.location = mathutils.Vector(centre + back * (along[2].max() + size))
        camera.rotation_euler = rotation.to_euler()

        sun_data = bpy.data.lights.new("VG Sun", "SUN")
        sun_data.energy = 3.0
        sun_data.angle = 0.2
        sun = bpy.data.objects.new("VG Sun", sun_data)
        made += [sun, sun_data]
        scene.collection.objects.link(sun)
        key = direction + mathutils.Vector(right) * 0.5 + mathutils.Vector(up) * 0.5
        sun.rotation_euler = (-key.normalized()).to_track_quat("-Z", "Y").to_euler()

        world = bpy.data.worlds.new("VG Sky")
        made.append(world)
        world.color = (0.8, 0.8, 0.8)
        if world.node_tree is None:
            world.use_nodes = True
        background = world.node_tree.nodes.get("Background")
        if background is not None:
            background.inputs["Color"].default_value = (0.85, 0.85, 0.85, 1.0)
            background.inputs["Strength"].default_value = 0.7
        scene.world = world

        scene.render.engine = "CYCLES"
        scene.cycles.device = "CPU"
        scene.cycles.samples = options.get("render_samples", 16)
        scene.cycles.use_denoising = False
        scene.cycles.use_adaptive_sampling = False
        scene.render.resolution_x, scene.render.resolution_y = width, height
        scene.render.resolution_percentage = 100
        scene.render.image_settings.file_format = "PNG"
        scene.view_settings.view_transform = "Standard"
        scene.render.filepath = str(Path(path).resolve())
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        with quiet_stdout():
            bpy.ops.render.render(write_still=True, scene=scene.name)
        if not Path(path).is_file():
            raise RuntimeError(f"Cycles wrote no image to {path}")
    finally:
        bpy.data.scenes.remove(scene)
        for block in made:
            with contextlib.suppress(ReferenceError, RuntimeError):
                if isinstance(block, bpy.types.Object):
                    bpy.data.objects.remove(block)
                elif isinstance(block, bpy.types.Camera):
                    bpy.data.cameras.remove(block)
                elif isinstance(block, bpy.types.Light):
                    bpy.data.lights.remove(block)
                elif isinstance(block, bpy.types.World):
                    bpy.data.worlds.remove(block)


def prepare_saved_file(bpy, objects) -> None:
    """Make the saved .blend open on the measurements: the first object active, solid views
    showing attribute colours and framing the meshes."""
    import mathutils

    objects = [o for o in objects if o is not None]
    if not objects:
        return
    view_layer = bpy.context.view_layer
    view_layer.objects.active = objects[0]
    for obj in objects:
        obj.select_set(obj == objects[0])
    corners = np.array(
        [list(obj.matrix_world @ mathutils.Vector(c)) for obj in objects for c in obj.bound_box]
    )
    centre = (corners.min(axis=0) + corners.max(axis=0)) / 2
    size = float(np.linalg.norm(corners.max(axis=0) - corners.min(axis=0))) or 1.0
    for screen in bpy.data.screens:
        for area in screen.areas:
            for space in area.spaces:
                if space.type != "VIEW_3D":
                    continue
                space.shading.color_type = "VERTEX"
                space.clip_end = max(space.clip_end, size * 20)
                space.clip_start = min(space.clip_start, size * 1e-4)
                region = space.region_3d
                if region is not None:
                    region.view_location = centre
                    region.view_distance = size * 1.2


def save_blend(bpy, path: str, objects) -> None:
    prepare_saved_file(bpy, objects)
    Path(path).resolve().parent.mkdir(parents=True, exist_ok=True)
    with quiet_stdout():
        bpy.ops.wm.save_as_mainfile(filepath=str(Path(path).resolve()), copy=True)


def forget(bpy, ctx: Context, object_name: str) -> None:
    """Remove an object and its mesh, and the cached surfaces (frees memory between meshes)."""
    obj = bpy.data.objects.get(object_name)
    if obj is not None:
        mesh = obj.data
        bpy.data.objects.remove(obj)
        if mesh is not None and mesh.users == 0:
            bpy.data.meshes.remove(mesh)
    ctx.mesh_data.clear_cache()
    ctx.measuring.clear_cache()


# --------------------------------------------------------------------------- progress and results


class Run:
    """The state of a batch run in the parent process: results, progress, partial CSV writes."""

    def __init__(self, ctx: Context, args, sources, tasks, total_meshes):
        self.ctx, self.args, self.sources, self.tasks = ctx, args, sources, tasks
        self.total_meshes = total_meshes
        self.jobs = 1  # processes measuring at once
        self.rows: dict[int, object] = {}
        self.results: list[MeshResult] = []
        self.bad_files: list[str] = []
        self.lock = threading.Lock()
        self.started = time.perf_counter()
        self.last_progress = 0.0
        self.last_write = 0.0  # when the CSV was last written (perf_counter seconds)
        self.write_seconds = 0.0  # how long that took
        self.in_flight: dict[int, int] = {}  # mesh -> points done so far (running meshes)
        self.units = ctx.records.units_label(ctx.bpy.context.scene)
        for task in tasks:
            if task.mesh < 0:
                self.rows[task.index] = error_row(ctx, task, task.mesh_name, task.error, self.units)

    @property
    def done_points(self) -> int:
        return len(self.rows) + sum(self.in_flight.values())

    def say(self, text: str) -> None:
        print(f"vg_batch: {text}", file=sys.stderr, flush=True)

    def progress(self, mesh: int, done: int, force: bool = False) -> None:
        with self.lock:
            self.in_flight[mesh] = done
            now = time.perf_counter()
            if self.args.quiet or (not force and now - self.last_progress < 1.0):
                return
            self.last_progress = now
            failed = sum(1 for row in self.rows.values() if row.error)
            self.say(
                f"[{now - self.started:6.1f} s] {len(self.results)}/{self.total_meshes} meshes, "
                f"{self.done_points:,}/{len(self.tasks):,} points, {failed:,} failed"
            )

    def add(self, result: MeshResult) -> None:
        with self.lock:
            self.in_flight.pop(result.mesh, None)
            self.results.append(result)
            for index, row in result.rows:
                self.rows[index] = row
            if result.bad_file:
                self.bad_files.append(result.bad_file)
            # Rewrite the CSV now and then (each write costs more as rows accumulate), so a run
            # that is killed keeps what it measured; finish() always writes.
            if time.perf_counter() - self.last_write >= max(5.0, 10.0 * self.write_seconds):
                self.write_csv()
        source = self.sources[result.mesh]
        rate = result.measured / result.measure_seconds if result.measure_seconds > 0 else 0
        note = f", render failed: {result.render_error}" if result.render_error else ""
        if not self.args.quiet:
            self.say(
                f"{source.name}: {result.measured:,} measured, {result.failed:,} failed"
                + (f" ({result.n_vertices:,} vertices, {rate:,.0f}/s)" if result.n_vertices else "")
                + note
            )
        elif note:
            self.say(f"{source.name}{note}")

    def write_csv(self) -> None:
        start = time.perf_counter()
        rows = [self.rows[i] for i in sorted(self.rows)]
        self.ctx.csvio.write_measurements_csv(self.args.out, rows)
        self.last_write = time.perf_counter()
        self.write_seconds = self.last_write - start

    def finish(self) -> int:
        missing = [t for t in self.tasks if t.index not in self.rows]
        for task in missing:  # e.g. a worker that could not even start
            name = self.sources[task.mesh].name if task.mesh >= 0 else task.mesh_name
            self.rows[task.index] = error_row(
                self.ctx, task, name, "not measured: the run stopped before this mesh", self.units
            )
        self.write_csv()
        failed = [(i, row) for i, row in sorted(self.rows.items()) if row.error]
        measured = len(self.rows) - len(failed)
        elapsed = time.perf_counter() - self.started
        load = sum(r.load_seconds for r in self.results)
        prepare = sum(r.prepare_seconds for r in self.results)
        measuring = sum(r.measure_seconds for r in self.results)
        tried = sum(r.measured + r.failed for r in self.results if r.measure_seconds > 0)
        rate = tried / measuring if measuring > 0 else 0.0
        self.say(
            f"{measured:,} measured, {len(failed):,} failed, {len(self.rows):,} points on "
            f"{self.total_meshes:,} mesh(es) in {elapsed:.1f} s"
        )
        per = f" per process, {self.jobs} processes" if self.jobs > 1 else ""
        self.say(
            f"mesh import {load:.1f} s, surface preparation {prepare:.1f} s, measuring "
            f"{measuring:.2f} s: {rate:,.0f} measurements/s{per} (import excluded)"
        )
        by_index = {t.index: t for t in self.tasks}
        for index, row in failed[:10]:
            task = by_index[index]
            where = f"row {task.source_row}" if task.source_row else f"point {task.number}"
            self.say(f"  failed: {where} on {row.mesh_name!r}: {row.error}")
        if len(failed) > 10:
            self.say(f"  ... and {len(failed) - 10} more failed rows (see the error column)")
        for message in self.bad_files:
            self.say(f"  unreadable mesh: {message}")
        self.say(f"wrote {self.args.out}")
        return self.ctx.batchplan.exit_code(len(failed), len(self.bad_files))


# --------------------------------------------------------------------------- parallel workers


def worker_command(plan_path: str) -> list[str]:
    bpy = importlib.import_module("bpy")
    if IN_BLENDER and bpy.app.binary_path:
        return [
            bpy.app.binary_path,
            "-b",
            "--factory-startup",
            "-noaudio",
            "--python",
            str(Path(__file__).resolve()),
            "--",
            "--worker",
            plan_path,
        ]
    return [sys.executable, str(Path(__file__).resolve()), "--worker", plan_path]


def run_workers(run: Run, groups: dict, plan: dict, jobs: int) -> None:
    """Measure the meshes in ``groups`` in up to ``jobs`` worker processes, handing each idle
    worker the next mesh. A worker that dies loses only the mesh it was on; a new one takes
    over the rest."""
    folder = plan["folder"]
    plan_path = str(Path(folder) / "plan.json")
    with open(plan_path, "w", encoding="utf-8") as handle:
        json.dump(plan, handle)
    queue = deque(groups)
    lock = threading.Lock()
    row_type = run.ctx.csvio.MeasurementRow

    # One BLAS/OpenMP thread per worker: the workers are the parallelism.
    env = dict(os.environ)
    for name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        env.setdefault(name, "1")

    def start():
        return subprocess.Popen(
            worker_command(plan_path),
            env=env,
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
            encoding="utf-8",
            errors="replace",
            bufsize=1,
        )

    def fail(mesh: int, message: str) -> None:
        name = run.sources[mesh].name
        result = MeshResult(mesh=mesh, failed=len(groups[mesh]))
        result.rows = [
            (t.index, error_row(run.ctx, t, name, message, run.units)) for t in groups[mesh]
        ]
        run.add(result)

    def slot():
        process = None
        while True:
            with lock:
                if not queue:
                    break
                mesh = queue.popleft()
            if process is None:
                try:
                    process = start()
                except OSError as error:
                    fail(mesh, f"could not start a worker process: {error}")
                    continue
            finished = False
            try:
                process.stdin.write(f"{mesh}\n")
                process.stdin.flush()
                for line in process.stdout:
                    at = line.find(MARK)
                    if at < 0:
                        continue
                    words = line[at + len(MARK) :].split()
                    if words[:1] == ["progress"]:
                        run.progress(mesh, int(words[2]))
                    elif words[:1] == ["done"]:
                        finished = True
                        break
            except (BrokenPipeError, OSError):
                pass
            if finished:
                with open(Path(folder) / f"mesh-{mesh}.json", encoding="utf-8") as handle:
                    run.add(MeshResult.from_json(json.load(handle), row_type))
                continue
            code = process.wait()
            process = None
            fail(
                mesh,
                f"the worker process measuring this mesh stopped (exit status {code}); see its "
                "messages above. The other meshes are not affected.",
            )
        if process is not None:
            with contextlib.suppress(OSError):
                process.stdin.close()
            process.wait()

    threads = [threading.Thread(target=slot, daemon=True) for _ in range(min(jobs, len(queue)))]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()


def worker_main(plan_path: str) -> int:
    """A worker: measure the meshes whose indices arrive on stdin, one JSON result each."""
    bpy = import_bpy()
    bpy.ops.wm.read_homefile(use_empty=True)
    ctx = load_extension()
    with open(plan_path, encoding="utf-8") as handle:
        plan = json.load(handle)
    set_units(bpy.context.scene, plan["options"]["units"])
    sources = [MeshSource(**s) for s in plan["sources"]]
    tasks = {int(k): [ctx.batchplan.Task(**t) for t in v] for k, v in plan["tasks"].items()}
    for t in tasks.values():
        for i, task in enumerate(t):
            t[i] = dataclasses.replace(task, center=tuple(task.center))
    options = plan["options"]
    for line in sys.stdin:
        line = line.strip()
        if not line:
            continue
        mesh = int(line)
        if os.environ.get(ABORT_VARIABLE) == sources[mesh].name:
            os.abort()  # a stand-in for a crash in native code, to test crash isolation

        def progress(done, mesh=mesh):
            print(f"{MARK} progress {mesh} {done}", flush=True)

        result = safe_measure_mesh(ctx, mesh, sources[mesh], tasks[mesh], options, progress)
        if options.get("save_blend") and result.object_name:
            obj = bpy.data.objects.get(result.object_name)
            if obj is not None:
                path = str(Path(plan["folder"]) / f"mesh-{mesh}.blend")
                with quiet_stdout():
                    bpy.data.libraries.write(path, {obj})
                result.blend = path
        if result.object_name:
            forget(bpy, ctx, result.object_name)
        target = Path(plan["folder"]) / f"mesh-{mesh}.json"
        temporary = target.with_suffix(".tmp")
        temporary.write_text(json.dumps(result.to_json()), encoding="utf-8")
        temporary.replace(target)
        print(f"{MARK} done {mesh}", flush=True)
    return 0


def append_objects(bpy, results: list[MeshResult]) -> list:
    """Bring the objects the workers saved into this file, in mesh order."""
    objects = []
    for result in sorted(results, key=lambda r: r.mesh):
        if not result.blend or not Path(result.blend).is_file():
            continue
        with bpy.data.libraries.load(result.blend, link=False) as (source, target):
            target.objects = [name for name in source.objects if name == result.object_name]
        for obj in target.objects:
            if obj is not None:
                bpy.context.scene.collection.objects.link(obj)
                objects.append(obj)
    return objects


# --------------------------------------------------------------------------- the batch run


def run_batch(args, ctx: Context | None = None, blend: str = "") -> tuple[int, Run | None]:
    """Run a batch from parsed arguments; returns the exit status and the run's results."""
    bpy = import_bpy()
    if ctx is None:
        inputs, blend = start_file(bpy, list(args.inputs))
        ctx = load_extension()
    else:
        inputs = list(args.inputs)
    bp = ctx.batchplan
    sources = blend_objects(ctx, list(args.object), blend) + file_sources(ctx, inputs)
    if not sources:
        raise UsageError("no mesh given: name mesh files, folders, or a .blend with --object.")
    seen = {}
    for source in sources:
        if source.name in seen:
            raise UsageError(f"two inputs are both named {source.name!r}: rename one.")
        seen[source.name] = source
    try:
        if args.at:
            tasks = bp.plan_points(
                len(sources), args.at, radius=args.radius, lam=args.lam, patch=args.patch
            )
        else:
            try:
                rows = ctx.csvio.read_replication_csv(args.points)
            except OSError as error:
                raise UsageError(f"{args.points}: {error.strerror or error}") from None
            tasks = bp.plan_rows(
                [s.names for s in sources],
                rows,
                radius=args.radius,
                lam=args.lam,
                patch=args.patch,
                ignore_mesh_names=args.ignore_mesh_names,
                source=f"'{Path(args.points).name}'",
            )
        if args.shard:
            k, n = bp.parse_shard(args.shard)
            tasks = bp.shard(tasks, k, n)
    except ctx.GoniometerError as error:
        raise UsageError(str(error)) from None
    groups = {mesh: ts for mesh, ts in bp.by_mesh(tasks).items() if mesh >= 0}
    units = args.units or ("none" if not blend else None)
    set_units(bpy.context.scene, units)
    for path in (args.out, args.save_blend):
        if path:
            Path(path).resolve().parent.mkdir(parents=True, exist_ok=True)
    options = {
        "render": str(Path(args.render).resolve()) if args.render else "",
        "render_size": list(args.render_size),
        "render_samples": args.render_samples,
        "save_blend": bool(args.save_blend),
        "units": units,
    }
    run = Run(ctx, args, sources, tasks, len(groups))
    if args.shard and not args.quiet:
        run.say(f"shard {args.shard}: {len(tasks):,} point(s) on {len(groups)} mesh(es)")
    try:
        run.write_csv()
    except (OSError, ctx.GoniometerError) as error:
        raise UsageError(f"cannot write {args.out}: {error}") from None

    parallel = args.jobs > 1 and len(groups) > 1 and not blend
    if args.jobs > 1 and blend and not args.quiet:
        run.say("a .blend input is measured in this process (--jobs applies to mesh files only)")
    folder = tempfile.mkdtemp(prefix="vg-batch-") if parallel else ""
    kept = []  # objects measured in this process, kept for --save-blend
    try:
        try:
            if parallel:
                plan = {
                    "folder": folder,
                    "sources": [dataclasses.asdict(s) for s in sources],
                    "tasks": {
                        str(m): [dataclasses.asdict(t) for t in ts] for m, ts in groups.items()
                    },
                    "options": options,
                }
                run.jobs = min(args.jobs, len(groups))
                run_workers(run, groups, plan, args.jobs)
            else:
                for mesh, mesh_tasks in groups.items():
                    progress = functools.partial(run.progress, mesh)
                    result = safe_measure_mesh(
                        ctx, mesh, sources[mesh], mesh_tasks, options, progress
                    )
                    run.add(result)
                    if args.save_blend or not sources[mesh].path:
                        kept.append(result.object_name)
                    elif result.object_name:
                        forget(bpy, ctx, result.object_name)
        finally:
            code = run.finish()  # also after an error or Ctrl-C: write what was measured
        if args.save_blend:
            if parallel:
                objects = append_objects(bpy, run.results)
            else:
                objects = [bpy.data.objects.get(name) for name in kept if name]
            save_blend(bpy, args.save_blend, objects)
    finally:
        if folder:
            shutil.rmtree(folder, ignore_errors=True)
    if args.save_blend:
        run.say(f"wrote {args.save_blend}")
    if args.render:
        rendered = sum(1 for r in run.results if r.render)
        run.say(f"wrote {rendered} render(s) to {args.render}")
    return code, run


# --------------------------------------------------------------------------- the demo


def run_demo(args) -> int:
    """Generate a bone-shaft fragment with known break angles, measure its break sites in a
    batch run, print true against measured angles and name the output folder."""
    bpy = import_bpy()
    bpy.ops.wm.read_homefile(use_empty=True)
    ctx = load_extension()
    synth = importlib.import_module(f"{ctx.package.__name__}.vg_addon.synthetic_meshes")
    out = Path(args.out_dir or DEMO_DIR).resolve()
    out.mkdir(parents=True, exist_ok=True)
    say = lambda text: print(f"vg_batch: {text}", file=sys.stderr, flush=True)  # noqa: E731

    say("generating a long-bone shaft fragment (millimetres) ...")
    fragment = synth.bone_fragment()
    ply = out / "bone_fragment.ply"
    ctx.meshio.write_ply(ply, fragment.points, fragment.triangles)
    say(f"{len(fragment.points):,} vertices, {len(fragment.sites)} break sites -> {ply}")
    points = out / "break_sites.csv"
    with open(points, "w", encoding="utf-8", newline="") as handle:
        writer = csv.writer(handle, lineterminator="\n")
        writer.writerow(["mesh", "label", "break", "x", "y", "z", "radius", "true angle"])
        for number, site in enumerate(fragment.sites, start=1):
            writer.writerow(
                [
                    "bone_fragment",
                    site.label,
                    number,
                    *(repr(float(v)) for v in site.point),
                    repr(DEMO_RADIUS),
                    repr(site.angle),
                ]
            )

    outputs = {
        "--out": out / "measurements.csv",
        "--save-blend": out / "bone_fragment.blend",
        "--render": out,
    }
    argv = [str(ply), "--points", str(points), "--units", "mm", "--render-size", "800", "600"]
    argv += [str(value) for option in outputs.items() for value in option]
    batch = build_parser().parse_args([*argv, "--jobs", str(args.jobs)])
    batch.quiet = args.quiet
    code, run = run_batch(batch, ctx)

    rows = [run.rows[i] for i in sorted(run.rows)]
    width = max(len("break site"), *(len(site.label) for site in fragment.sites))
    print(f"\n{'break site':<{width}}  true angle    measured  difference  fit error")
    for site, row in zip(fragment.sites, rows, strict=True):
        if row.error:
            print(f"{site.label:<{width}}  {site.angle:9.2f}°      failed  {row.error}")
            continue
        print(
            f"{site.label:<{width}}  {site.angle:9.2f}°  {row.angle:9.2f}°  "
            f"{row.angle - site.angle:+9.2f}°  {row.fit:.2g}"
        )
    print(
        f"\nPatch radius {DEMO_RADIUS:g} mm. Measured and true angles differ because each side's "
        "plane is fitted to a patch\nof a curved cylinder wall; a larger radius averages more of "
        "the curvature.\n"
    )
    print(f"Output folder: {out}")
    for path in (
        ply,
        points,
        *(p for p in outputs.values() if p != out),
        out / "bone_fragment.png",
    ):
        if path.is_file():
            print(f"  {path.name}")
    return code


# --------------------------------------------------------------------------- entry point


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(script_argv() if argv is None else argv)
    try:
        if args.worker:
            return worker_main(args.worker)
        check_args(args)
        if args.demo:
            return run_demo(args)
        code, _ = run_batch(args)
        return code
    except UsageError as error:
        print(f"vg_batch: error: {error}", file=sys.stderr, flush=True)
        return 2
    except KeyboardInterrupt:
        print("vg_batch: interrupted; the CSV holds what was measured so far", file=sys.stderr)
        return 130


def _exit(code: int) -> None:
    while _registered:
        try:
            _registered.pop().unregister()
        except Exception:
            traceback.print_exc()
    sys.stdout.flush()
    sys.stderr.flush()
    if IN_BLENDER:
        # Blender would otherwise carry on and exit with 0; end the process with our status.
        os._exit(code)
    sys.exit(code)


if __name__ == "__main__":
    try:
        status = main()
    except SystemExit as stop:  # argparse: --help (0) and usage errors (2)
        status = stop.code if isinstance(stop.code, int) else 2
    except Exception:
        traceback.print_exc()
        status = 2
    _exit(status)
