"""The layout's import rules, read from the source: imports run one way.

ui → operators → bridge → vg_addon, batch → bridge → vg_addon; properties.py (the saved
PropertyGroups) may be used by every Blender layer; vg_addon never imports Blender; the thin
vg_batch.py reaches the batch package only through the extension package it loads.
"""

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BLENDER_MODULES = {
    "bpy",
    "bpy_extras",
    "bmesh",
    "mathutils",
    "gpu",
    "gpu_extras",
    "blf",
    "addon_utils",
}
# What each layer of the extension may import from the others (besides itself).
ALLOWED = {
    "vg_addon": set(),
    "bridge": {"vg_addon", "properties"},
    "operators": {"bridge", "vg_addon", "properties"},
    "ui": {"operators", "bridge", "vg_addon", "properties"},
    "batch": {"bridge", "vg_addon", "properties"},
    "properties": {"vg_addon"},
    "__init__": {"operators", "ui", "bridge", "properties"},
}
LAYERS = set(ALLOWED) - {"__init__"}


def layer_of(path: Path) -> str:
    parts = path.relative_to(ROOT).parts
    return (
        parts[0].removesuffix(".py") if len(parts) > 1 or parts[0] != "__init__.py" else "__init__"
    )


def imports(path: Path) -> list[tuple[int, str]]:
    """(line, target) for every import: ``target`` is a layer name for relative imports that
    leave the file's own layer, else the absolute top-level module name."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    depth_of_file = len(path.relative_to(ROOT).parts) - 1  # 0 for root files
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(node.lineno, alias.name.split(".")[0]) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level == 0:
                found.append((node.lineno, node.module.split(".")[0]))
                continue
            up = node.level - 1  # package levels above the file's own package
            if up < depth_of_file:
                continue  # inside the file's own layer
            # A relative import reaching the extension root: its first name is the layer.
            names = (node.module or "").split(".") if node.module else []
            targets = names[:1] or [alias.name for alias in node.names]
            found += [(node.lineno, target) for target in targets]
    return found


def extension_sources() -> list[Path]:
    files = [ROOT / "__init__.py", ROOT / "properties.py"]
    for layer in LAYERS - {"properties"}:
        files += sorted((ROOT / layer).rglob("*.py"))
    return files


def test_every_layer_is_found():
    found = {layer_of(path) for path in extension_sources()}
    assert found == set(ALLOWED), found


@pytest.mark.parametrize("path", extension_sources(), ids=lambda p: str(p.relative_to(ROOT)))
def test_imports_run_one_way(path):
    layer = layer_of(path)
    wrong = []
    for line, target in imports(path):
        if target in ALLOWED and target != layer and target not in ALLOWED[layer]:
            wrong.append(f"line {line}: {layer} imports {target}")
        if layer == "vg_addon" and target in BLENDER_MODULES:
            wrong.append(f"line {line}: vg_addon imports Blender's {target}")
    assert not wrong, wrong


def test_the_method_package_holds_the_method_only():
    """A newcomer opening vg_addon/method finds Algorithm 1, the patch index and the normals."""
    modules = {p.stem for p in (ROOT / "vg_addon" / "method").glob("*.py")}
    assert {"algorithm", "withinss", "spatial", "normals", "surface"} <= modules
    for path in (ROOT / "vg_addon" / "method").glob("*.py"):
        for line, target in imports(path):
            assert target not in {"formats", "workflow", "palette", "synthetic_meshes"}, (
                f"{path.name} line {line} imports {target}"
            )


def test_vg_batch_is_a_thin_entry():
    text = (ROOT / "vg_batch.py").read_text(encoding="utf-8")
    assert len(text.splitlines()) < 150
    for line, target in imports(ROOT / "vg_batch.py"):
        assert target not in LAYERS, f"vg_batch.py line {line} imports {target} directly"


def module_imports(path: Path) -> set[Path]:
    """The extension's own source files that ``path`` imports, at run time (also inside
    functions; not under ``if TYPE_CHECKING:``)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    checking_only = {
        id(node)
        for branch in ast.walk(tree)
        if isinstance(branch, ast.If) and getattr(branch.test, "id", "") == "TYPE_CHECKING"
        for statement in branch.body
        for node in ast.walk(statement)
    }

    def source(base: Path) -> Path | None:
        for candidate in (base.with_suffix(".py"), base / "__init__.py"):
            if candidate.is_file():
                return candidate
        return None

    found = set()
    for node in ast.walk(tree):
        if not isinstance(node, ast.ImportFrom) or node.level == 0 or id(node) in checking_only:
            continue
        package = path.parent
        for _ in range(node.level - 1):
            package = package.parent
        base = package.joinpath(*node.module.split(".")) if node.module else package
        for alias in node.names:
            target = source(base / alias.name) or source(base)
            if target is not None and target != path:
                found.add(target)
    return found


def test_no_import_cycle():
    """Following the extension's imports from any module never leads back to it."""
    graph = {path: module_imports(path) for path in extension_sources()}
    cycles = []

    done: set = set()

    def visit(path, trail):
        for target in sorted(graph.get(path, ())):
            if target in trail:
                cycles.append([*trail[trail.index(target) :], target])
            elif target not in done:
                visit(target, [*trail, target])
        done.add(path)

    for path in sorted(graph):
        if path not in done:
            visit(path, [path])
    named = {" -> ".join(str(p.relative_to(ROOT)) for p in cycle) for cycle in cycles}
    assert not named, sorted(named)


MAX_LINES = 700  # issue 21: small modules with one job; a longer file is split by topic


def python_files() -> list[Path]:
    """Every Python file of the repository, tests and scripts included (not the environments)."""
    return [
        path
        for path in sorted(ROOT.rglob("*.py"))
        if not any(
            part.startswith(".") or part in {"__pycache__", "build", "dist"}
            for part in path.relative_to(ROOT).parts[:-1]
        )
    ]


def test_no_source_file_is_longer_than_700_lines():
    lengths = {path: len(path.read_text(encoding="utf-8").splitlines()) for path in python_files()}
    assert len(lengths) > 100  # the walk found the tree
    long = {str(p.relative_to(ROOT)): n for p, n in lengths.items() if n > MAX_LINES}
    assert not long, f"split these by topic (at most {MAX_LINES} lines): {long}"
