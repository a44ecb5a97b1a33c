"""The batch command line: the parser, its help text and the checks made before anything runs."""

from __future__ import annotations

import argparse
import math
import re
from pathlib import Path

from ..bridge.map_edges import EDGE_ENDS
from ..vg_addon import GoniometerError
from ..vg_addon.formats import picked_points
from ..vg_addon.method.break_edges import BreakEdgeParameters
from ..vg_addon.method.inputs import as_lambda
from ..vg_addon.method.sweep import sweep_radii

# --units: Blender's unit system, unit scale and length unit for what one coordinate unit is.
UNITS = {
    "none": ("NONE", 1.0, None),
    "m": ("METRIC", 1.0, "METERS"),
    "cm": ("METRIC", 0.01, "CENTIMETERS"),
    "mm": ("METRIC", 0.001, "MILLIMETERS"),
    "um": ("METRIC", 1e-6, "MICROMETERS"),
    "in": ("IMPERIAL", 0.0254, "INCHES"),
}

FINDER_SETTINGS = (
    ("--min-length", "L", "min_length"),
    ("--find-scale", "S", "find_scale"),
    ("--min-bend", "DEG", "min_bend"),
)
"""The finder's settings on the command line (flag, metavar, argument name); each needs
--find-edges."""

# argparse takes an argument for a negative number only in plain notation (-0.05, not -5e-2,
# which this project's own CSVs write) and reads anything else starting with "-" as an option;
# this is the pattern it is given instead (not-finite values get through to their refusal).
NEGATIVE_NUMBER = re.compile(
    r"^-(?:(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|inf|infinity|nan)$", re.IGNORECASE
)

# --render-size and --render-samples: a map's cost grows with pixels times samples, and Cycles
# cannot be stopped inside a view, so both are bounded before anything is rendered.
MAX_RENDER_SIDE = 8192
MAX_RENDER_SAMPLES = 4096

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

rule and checks:
  --rule refined (the default) is the oriented rule, then each face's plane from the vertices
  on it (exact where the crease runs between vertex rows); --rule oriented (the earlier
  default) reads concave edges and inward-wound meshes right; --rule paper is Algorithm 1 as
  printed. Rows of MeshLab and earlier add-on CSVs, and extension exports without a Rule
  column, are always re-measured with the paper's rule they were taken with. Edge stations
  (--edge, --edges, --find-edges) are measured with --rule; an edges CSV's edges with the
  Rule of their row (with --rule for files written before that column). --stability adds each measurement's and each station's stability
  figure (the Stability columns; it costs about ten measurements). A closed mesh wound
  inward is named once in the output: its angles are
  right, its convex/concave labels swapped.
  --sweep R0 R1 N also measures every point at N radii from R0 to R1: rows in
  <out>_sweep.csv, and a plot per point in the folder <out>_sweep/.

edges:
  --edge X1 Y1 Z1 X2 Y2 Z2 (repeatable) measures a whole break edge on every mesh given: the
  path from the first point to the second is traced along the ridge (through the --via X Y Z
  points that follow that --edge, in order) and measured at stations every --spacing D of arc
  length, each with --radius, --lambda and --patch. Its stations are rows of --out (after the
  points, with Edge #, Arc Length and Spacing), its summary a row of OUT_edges.csv, and its
  profile plot OUT_<mesh>_edge<N>.png beside --out. --edges CSV re-measures the edges of an
  edge summary file (an export's NAME_edges.csv): each row's Points with its own Spacing,
  Radius, SegParam and Patch Mode, on the mesh its Mesh Name names. --edges also takes MeshLab
  picked-points files, a .pp file or a folder of them: each file's active points in order
  (start, via points, end) are an edge, measured with --spacing and --radius on the mesh its
  file name names (NAME.pp or NAME_*.pp for the mesh NAME). Edges run in this process (not
  with --jobs or --shard).
  --find-edges finds every break edge of each mesh (ridges between smooth faces; see
  docs/EDGE_DETECTION.md) and profiles each like an --edge, with --spacing D and --radius R:
  stations in --out, summaries in OUT_edges.csv (each row re-measures with --edges), a plot
  per edge, and with --render the map with the edges drawn. --min-length L drops edges
  shorter than L, --find-scale S judges bends over S (rounded edges need S about their
  size), --min-bend DEG keeps edges bending at least DEG (defaults: from the mesh's
  resolution; 30°). It works with --jobs (not --shard).

output:
  --out CSV gets one row per requested point, in input order, in the extension's export
  schema (MeshLab's 14 columns first). A row that cannot be measured has its message in the
  `error` column and the run goes on. While meshes finish, the CSV is rewritten every few
  seconds, so a run that is stopped keeps what it measured. --out - writes it to standard
  output (once, at the end). An output that is an input, or cannot be written, is refused
  before anything is read or written.

exit status:
  0  every point measured (--report: every row read was used)
  1  some rows failed (see their `error` column; --report: some rows or files left out, each
     named in the report and on stderr)
  2  bad arguments, missing or unreadable files, a malformed points CSV, an output refused
     or a .blend/picture that could not be written

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
  python vg_batch.py scan.ply --edge 0 0 0 10 2 0 --via 5 1.5 0.2 --spacing 1 --radius 2 \
      --out edge.csv
  python vg_batch.py scans/ --edges scans/ --spacing 2 --radius 2.5 --out picked.csv
  python vg_batch.py scans/ --find-edges --spacing 2 --radius 2.5 --jobs 2 --out found.csv \
      --render maps/
  python vg_batch.py --report report/ obs1_drag_1.csv obs1_drag_2.csv obs1_xyz_1.csv manual.csv
  python vg_batch.py --demo
"""


class EdgeAction(argparse.Action):
    """``--edge X1 Y1 Z1 X2 Y2 Z2``: a new edge ``{"start", "end", "via"}`` on ``args.edge``."""

    def __call__(self, parser, namespace, values, option_string=None):
        edges = list(getattr(namespace, self.dest) or [])
        edges.append({"start": list(values[:3]), "end": list(values[3:]), "via": []})
        setattr(namespace, self.dest, edges)


class ViaAction(argparse.Action):
    """``--via X Y Z``: a via point of the last ``--edge`` given before it."""

    def __call__(self, parser, namespace, values, option_string=None):
        edges = getattr(namespace, "edge", None)
        if not edges:
            parser.error("--via X Y Z must follow the --edge it belongs to.")
        edges[-1]["via"].append(list(values))


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="vg_batch.py",
        usage="blender -b [file.blend] --python vg_batch.py -- ARGS\n"
        "       python vg_batch.py ARGS\n\n"
        "ARGS:  MESH... [--object NAME] (--at X Y Z ... | --points CSV) [--radius R]\n"
        "       [--edge X1 Y1 Z1 X2 Y2 Z2 [--via X Y Z]... --spacing D]... [--edges CSV|PP]\n"
        "       [--find-edges --spacing D [--min-length L] [--find-scale S] [--min-bend DEG]]\n"
        "       [--lambda L] [--patch euclidean|geodesic] [--rule refined|oriented|paper]\n"
        "       [--stability] [--sweep R0 R1 N] --out CSV [--save-blend PATH]\n"
        "       [--render DIR] [--jobs N] [--shard K/N]\n"
        "   or: --report DIR CSV... [--method M]... [--observer O]... [--compare A B]...\n"
        "   or: --demo [--out-dir DIR]",
        description="Measure break-edge angles (the Virtual Goniometer) on meshes and point "
        "lists, headless, and write them to a CSV.",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser._negative_number_matcher = NEGATIVE_NUMBER  # see NEGATIVE_NUMBER
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
    edges = parser.add_argument_group("edges (with or without points)")
    edges.add_argument(
        "--edge",
        nargs=6,
        type=float,
        action=EdgeAction,
        default=[],
        metavar=("X1", "Y1", "Z1", "X2", "Y2", "Z2"),
        help="a whole break edge from the first point to the second, traced along the ridge "
        "(repeatable)",
    )
    edges.add_argument(
        "--via",
        nargs=3,
        type=float,
        action=ViaAction,
        metavar=("X", "Y", "Z"),
        help="a point the path of the preceding --edge passes through (repeatable, in order)",
    )
    edges.add_argument(
        "--edges",
        dest="edges_csv",
        metavar="CSV",
        help="an edge summary CSV (NAME_edges.csv): re-measure each of its edges on its mesh; "
        "or MeshLab picked-points files (a .pp file or a folder of them): each file's points "
        "are an edge on the mesh its name names (NAME.pp, NAME_*.pp)",
    )
    edges.add_argument(
        "--find-edges",
        action="store_true",
        help="find every break edge of each mesh and profile each (needs --spacing and --radius)",
    )
    edges.add_argument(
        "--min-length",
        type=float,
        metavar="L",
        help="with --find-edges: drop edges shorter than L (mesh units; default: from the mesh)",
    )
    edges.add_argument(
        "--find-scale",
        type=float,
        metavar="S",
        help="with --find-edges: the neighbourhood a bend is judged at (mesh units; default: "
        "from the mesh); about the size of rounded edges to find",
    )
    edges.add_argument(
        "--min-bend",
        type=float,
        metavar="DEG",
        help="with --find-edges: an edge bends at least this much, 180° minus its angle "
        f"(default {BreakEdgeParameters().min_bend_deg:g})",
    )
    edges.add_argument(
        "--spacing",
        type=float,
        metavar="D",
        help="arc length between the stations of every --edge, .pp edge and found edge (needed "
        "with them)",
    )
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
        "--rule",
        choices=("refined", "oriented", "paper"),
        default="refined",
        help="how the measurement is taken: refined (default; exact where the crease runs between "
        "vertex rows), oriented (the earlier default; right on concave edges) or paper (Algorithm 1 as "
        "printed); rows of MeshLab/earlier add-on CSVs keep the paper's",
    )
    how.add_argument(
        "--stability",
        action="store_true",
        help="also compute each measurement's stability figure (about ten measurements' cost)",
    )
    how.add_argument(
        "--sweep",
        nargs=3,
        type=float,
        metavar=("R0", "R1", "N"),
        help="also measure each point at N radii from R0 to R1: <out>_sweep.csv and plots",
    )
    how.add_argument(
        "--units",
        choices=tuple(UNITS),
        help="what one coordinate unit of the meshes is, recorded in the CSV's Units column and "
        "the .blend's scene units (default: the unit a replayed CSV's Units cells all name, "
        "else none, i.e. the file's own units, unnamed; a .blend input keeps its scene's units)",
    )
    how.add_argument(
        "--ignore-mesh-names",
        action="store_true",
        help="with a single mesh, measure every CSV row on it whatever mesh the row names",
    )
    out = parser.add_argument_group("output")
    out.add_argument(
        "--out", metavar="CSV", help="the measurements CSV to write (required; - for stdout)"
    )
    out.add_argument(
        "--save-blend",
        metavar="PATH",
        help="also save a .blend with the meshes, their side colours and stored measurements",
    )
    out.add_argument(
        "--render",
        metavar="DIR",
        help="write the measurement map of each mesh into DIR: DIR/<mesh>_map_<view>.png per "
        "view and the contact sheet DIR/<mesh>_map.png (the coloured sides and numbered labels, "
        "Cycles on the CPU; the same map as the extension's Render Map)",
    )
    out.add_argument(
        "--render-views",
        choices=("six", "flake"),
        default="six",
        help="the map's views: six orthographic views, or the two faces of a flat flake "
        "(default six)",
    )
    out.add_argument(
        "--render-size",
        nargs=2,
        type=int,
        default=[640, 480],
        metavar=("W", "H"),
        help="resolution of each view in pixels, 16 to 8192 (default 640 480)",
    )
    out.add_argument(
        "--render-samples",
        type=int,
        default=16,
        metavar="N",
        help="Cycles samples per pixel, 1 to 4096 (default 16)",
    )
    out.add_argument(
        "--render-edge-ends",
        type=int,
        default=EDGE_ENDS,
        metavar="N",
        help="of the edges' stations no view has room to label, the first and last station of "
        "the first N edges by number (for --find-edges the most confident) get close-ups; the "
        f"others are labelled where a view has room. 0 or more (default {EDGE_ENDS})",
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
        "--out-dir", metavar="DIR", help="the demo's output folder (default ./vg_demo_output)"
    )
    report = parser.add_argument_group("report (see docs/REPORT.md)")
    report.add_argument(
        "--report",
        metavar="DIR",
        help="instead of measuring: the replication report over the CSVs given (one session "
        "each), written into DIR (report.html, breaks.csv, summary.csv, figures/)",
    )
    report.add_argument(
        "--method",
        action="append",
        default=[],
        metavar="M",
        help="the sessions' method (manual, drag, xyz or any name): once for all CSVs or once "
        "per CSV in order; default: the Method column, else a method word in the file name",
    )
    report.add_argument(
        "--observer",
        action="append",
        default=[],
        metavar="O",
        help="the sessions' observer, as --method; default: the Observer column, else obsN in "
        "the file name",
    )
    report.add_argument(
        "--compare",
        nargs=2,
        action="append",
        default=[],
        metavar=("A", "B"),
        help="also a Bland-Altman analysis of A against B, each a method or a session's file "
        "name (repeatable)",
    )
    parser.add_argument("--worker", help=argparse.SUPPRESS)
    parser.add_argument("--map-worker", help=argparse.SUPPRESS)
    return parser


class UsageError(Exception):
    """Bad arguments or input files: exit status 2."""


def check_render_settings(size, samples: int) -> None:
    """Refuse a map size or sample count outside the stated bounds, before anything renders."""
    if not all(16 <= side <= MAX_RENDER_SIDE for side in size):
        raise UsageError(
            f"--render-size W H: each side must be 16 to {MAX_RENDER_SIDE:,} pixels (got "
            f"{size[0]} {size[1]})."
        )
    if not 1 <= samples <= MAX_RENDER_SAMPLES:
        raise UsageError(
            f"--render-samples must be 1 to {MAX_RENDER_SAMPLES:,} (got {samples}); 16 to 64 "
            "show the sides clearly."
        )


def check_edge_points(edges) -> None:
    """Refuse an ``--edge`` or ``--via`` coordinate that is not a finite number."""
    for number, edge in enumerate(edges, start=1):
        points = [edge["start"], *edge["via"], edge["end"]]
        if not all(math.isfinite(v) for point in points for v in point):
            raise UsageError(
                f"--edge {number}: every coordinate of its points must be a finite number (got "
                f"{'; '.join(' '.join(f'{v:g}' for v in p) for p in points)})."
            )


def check_find_edges(args) -> None:
    """Refuse ``--find-edges`` without a spacing and radius, with ``--shard``, and finder
    settings (``--min-length``, ``--find-scale``, ``--min-bend``) that are out of range or come
    without ``--find-edges``."""
    for flag, metavar, name in FINDER_SETTINGS:
        if getattr(args, name) is not None and not args.find_edges:
            raise UsageError(f"{flag} {metavar} is for --find-edges.")
    if not args.find_edges:
        return
    if args.spacing is None or args.radius is None:
        raise UsageError("--find-edges needs --spacing D and --radius R (in the mesh's units).")
    if args.shard:
        raise UsageError(
            "--find-edges profiles every edge of each mesh, which does not split into shares of "
            "rows: drop --shard (--jobs N measures N meshes at a time)."
        )
    check_positive("--min-length", args.min_length)
    check_positive("--find-scale", args.find_scale)
    if args.min_bend is not None and not 0 < args.min_bend < 180:
        raise UsageError(
            f"--min-bend must be a number of degrees above 0 and below 180 (got {args.min_bend:g})."
        )


def check_positive(flag: str, value) -> None:
    """Refuse ``value`` of ``flag`` unless it is absent or a finite number greater than 0."""
    if value is not None and not (math.isfinite(value) and value > 0):
        raise UsageError(f"{flag} must be a positive, finite number (got {value:g}).")


def is_picked_points(path: str) -> bool:
    """Whether ``--edges`` names MeshLab picked-points files: a ``.pp`` file or a folder."""
    return Path(path).is_dir() or Path(path).suffix.lower() == picked_points.SUFFIX


def check_edge_settings(args) -> None:
    """Refuse, for ``--edge``, ``--edges`` and ``--find-edges``, a ``--spacing`` or ``--radius``
    that is not a finite number greater than 0 and a ``--lambda`` outside its range, before any
    mesh is read: otherwise every edge of the run is traced and fails."""
    if not (args.edge or args.edges_csv or args.find_edges):
        return
    check_positive("--spacing", args.spacing)
    check_positive("--radius", args.radius)
    try:
        as_lambda(args.lam)
    except GoniometerError as error:
        raise UsageError(f"--lambda: {error}") from None


def _given(value, default) -> bool:
    """Whether an option's parsed ``value`` is not its ``default`` (an empty list, None and
    False all mean "not given")."""
    return value != default and bool(value or default)


DEMO_OPTIONS = frozenset({"demo", "out_dir", "quiet", "help"})
"""The options ``--demo`` takes (its run, outputs and settings are its own)."""


def check_nothing_ignored(args) -> None:
    """Refuse an option that would do nothing with the others given (it was ignored without a
    word): ``--spacing`` with no edges, ``--ignore-mesh-names`` with no CSV rows, an empty
    ``--save-blend`` or ``--render`` path."""
    if args.spacing is not None and not (args.edge or args.edges_csv or args.find_edges):
        raise UsageError(
            "--spacing D is the distance between an edge's stations: it is for --edge, --edges "
            "and --find-edges (--at and --points measure single points, with --radius R)."
        )
    if args.ignore_mesh_names and not (args.points or args.edges_csv):
        raise UsageError(
            "--ignore-mesh-names is for the rows of a --points or --edges file (it measures "
            "each on the one mesh given, whatever mesh the row names); --at, --edge and "
            "--find-edges name no mesh."
        )
    for flag, value in (("--save-blend", args.save_blend), ("--render", args.render)):
        if value is not None and not value.strip():
            raise UsageError(f"{flag} needs a path (got an empty one).")


def check_args(args) -> None:
    if args.demo:
        # The demo sets up its own run: any other option would be ignored without a word.
        extra = [
            (action.option_strings or [action.metavar or action.dest])[0]
            for action in build_parser()._actions
            if action.dest not in DEMO_OPTIONS
            and _given(getattr(args, action.dest, action.default), action.default)
        ]
        if extra:
            raise UsageError(f"--demo takes no {', '.join(extra)} (only --out-dir and --quiet).")
        return
    if args.out_dir:
        raise UsageError("--out-dir is for --demo; use --out CSV for a batch run.")
    if args.method or args.observer or args.compare:
        raise UsageError("--method, --observer and --compare are for --report DIR CSV ...")
    if args.at and args.points:
        raise UsageError(
            "give the points to measure with --at X Y Z (repeatable) or --points CSV, not both."
        )
    if not (args.at or args.points or args.edge or args.edges_csv or args.find_edges):
        raise UsageError(
            "give what to measure: --at X Y Z (repeatable), --points CSV, --edge "
            "X1 Y1 Z1 X2 Y2 Z2 (repeatable), --edges CSV or --find-edges."
        )
    if args.edge and (args.spacing is None or args.radius is None):
        raise UsageError("--edge needs --spacing D and --radius R (in the mesh's units).")
    check_nothing_ignored(args)
    summary_only = args.edges_csv and not is_picked_points(args.edges_csv)
    if args.spacing is not None and summary_only and not (args.edge or args.find_edges):
        raise UsageError(
            "--spacing is for --edge, --find-edges and .pp files: each row of the edge summary "
            f"{args.edges_csv} keeps its own Spacing and Radius (edit those cells to measure "
            "with others)."
        )
    if (
        args.radius is not None
        and summary_only
        and not (args.edge or args.find_edges or args.at or args.points)
    ):
        raise UsageError(
            "--radius is for --at, --points, --edge, --find-edges and .pp files: each row of the "
            f"edge summary {args.edges_csv} keeps its own Spacing and Radius (edit those cells "
            "to measure with others)."
        )
    if (args.edge or args.edges_csv) and (args.jobs > 1 or args.shard):
        raise UsageError("edges are measured in this process: drop --jobs and --shard.")
    check_find_edges(args)
    check_edge_settings(args)
    if not args.out:
        raise UsageError("--out CSV is required: the measurements CSV to write.")
    if args.jobs < 1:
        raise UsageError(f"--jobs must be 1 or more (got {args.jobs}).")
    check_render_settings(args.render_size, args.render_samples)
    if args.render_edge_ends < 0:
        raise UsageError(f"--render-edge-ends must be 0 or more (got {args.render_edge_ends}).")
    check_edge_points(args.edge)
    if args.sweep:
        start, stop, count = args.sweep
        if not all(math.isfinite(value) for value in args.sweep):
            raise UsageError(
                f"--sweep R0 R1 N: every value must be a finite number (got {args.sweep})."
            )
        if count != int(count):
            raise UsageError(f"--sweep R0 R1 N: N must be a whole number (got {count:g}).")
        try:
            sweep_radii(start, stop, int(count))
        except GoniometerError as error:
            raise UsageError(f"--sweep R0 R1 N: {error}") from None
