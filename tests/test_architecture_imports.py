"""The package's structure, read from its source: the import graph (lazy imports included) has
no cycle and every import follows the flow design -> curves -> PDE patches -> B-spline data ->
B-rep and meshes -> exports and tooling, with mechanics, FE and optimisation reading designs and
solids; the family catalogue is one static mapping; nothing registers itself at import time."""

from __future__ import annotations

import ast
import functools
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PKG = ROOT / "tabletcad"

# Layers of the flow, lowest first.  A module may import its own layer (without a cycle) and the
# layers below it, never a layer above.  Keys are module names or package prefixes.  The package
# itself (``tabletcad/__init__.py``) imports nothing: its ``make``, ``load`` and ``show`` are
# looked up in ``tabletcad.pipeline.model`` on first use, as attributes, never by an import of the package.
LAYERS: list[tuple[str, ...]] = [
    ("tabletcad", "tabletcad.errors", "tabletcad.tolerance", "tabletcad.io", "tabletcad.parallel",
     "tabletcad.readonly", "tabletcad.collector"),  # support
    ("tabletcad.geometry", "tabletcad.geometry.basis", "tabletcad.geometry.curves",
     "tabletcad.geometry.nominal"),  # maths: the PDE's cardinal functions, boundary curves, nominal shapes
    ("tabletcad.geometry.patch",),  # PDE patches
    ("tabletcad.geometry.tablet",),  # a tablet: patches, trims, checks
    ("tabletcad.families",),  # the catalogue: the thesis's shapes and the industry families
    ("tabletcad.mechanics",),  # compaction and strength formulas (they read dimensions)
    ("tabletcad.brep",),  # kernel-neutral B-spline data of the solid's faces
    ("tabletcad.volume_mesh",),  # hexahedral meshes from the PDE solid map
    ("tabletcad.tooling.spec", "tabletcad.tooling.standards", "tabletcad.tooling.polygon"),  # the [tooling]
    # table as data (no kernel):
    # a Design holds it parsed
    ("tabletcad.pipeline.design", "tabletcad.pipeline.designreport", "tabletcad.pipeline.report",
     "tabletcad.pipeline.plot"),  # design files, the design and geometry reports, pictures
    ("tabletcad.cad",),  # B-rep solids, meshes, exports: OpenCascade
    ("tabletcad.tooling",),  # punches, die, drawings from the solids
    ("tabletcad.fe",),  # finite elements on the solids and the punch tips
    ("tabletcad.optimise",),  # optimisation reads designs, mechanics and FE
    ("tabletcad.pipeline", "tabletcad.pipeline.model", "tabletcad.pipeline.build"),  # the scripting
    # facade and the build, which run everything above
    ("tabletcad.sweep",),  # sweeps drive builds
    ("tabletcad.cli", "tabletcad.__main__"),  # the command line
]
CAD_LIBRARIES = ("OCP", "build123d", "cadquery")


def _modules() -> dict[str, Path]:
    mods = {}
    for p in PKG.rglob("*.py"):
        parts = list(p.relative_to(ROOT).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        mods[".".join(parts)] = p
    return mods


MODULES = _modules()


def _resolve(name: str) -> str | None:
    while name and name not in MODULES:
        name = name.rpartition(".")[0]
    return name or None


@functools.lru_cache(maxsize=None)
def _source(path: Path) -> str:
    return path.read_text(encoding="utf-8")


@functools.lru_cache(maxsize=None)
def _imports(module: str) -> tuple[tuple[str, int], ...]:
    """Every import of ``module`` anywhere in its file (functions included): (imported name, line).
    Each file is parsed once per test session (the files do not change while the tests run)."""
    path = MODULES[module]
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    out = []
    for node in ast.walk(ast.parse(_source(path))):
        if isinstance(node, ast.Import):
            out += [(a.name, node.lineno) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            out.append((mod, node.lineno))
            out += [(f"{mod}.{a.name}", node.lineno) for a in node.names]
    return tuple(out)


def _graph() -> dict[str, dict[str, int]]:
    """Module -> {imported tabletcad module: line} (a fresh dict each call, from the cached parses)."""
    graph: dict[str, dict[str, int]] = {m: {} for m in MODULES}
    for m in MODULES:
        for name, line in _imports(m):
            if name.split(".")[0] == "tabletcad":
                target = _resolve(name)
                if target is not None and target != m:
                    graph[m].setdefault(target, line)
    return graph


def _layer(module: str) -> int:
    best, rank = -1, None
    for i, layer in enumerate(LAYERS):
        for key in layer:
            inside = module == key or (key != "tabletcad" and module.startswith(key + "."))
            if inside and len(key) > best:
                best, rank = len(key), i
    assert rank is not None, f"{module} is in no layer: add it to LAYERS"
    return rank


def _cycles(graph: dict[str, dict[str, int]]) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    found: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                found.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def test_the_graph_is_read_from_every_import_including_lazy_ones():
    graph = _graph()
    # a lazy import inside a function counts: the build imports the CAD stage only when it runs
    assert "tabletcad.cad.stage" in graph["tabletcad.pipeline.build"]
    assert len(MODULES) > 100 and sum(map(len, graph.values())) > 300


def test_no_import_cycle():
    assert _cycles(_graph()) == []


def test_a_cycle_is_found_when_there_is_one():
    graph = {"a": {"b": 1}, "b": {"c": 1}, "c": {"a": 1}, "d": {"a": 1}}
    assert _cycles(graph) == [["a", "b", "c"]]


def test_every_import_follows_the_flow():
    against = [
        f"{m} (layer {_layer(m)}) imports {t} (layer {_layer(t)}) at line {line}"
        for m, targets in _graph().items() for t, line in targets.items() if _layer(t) > _layer(m)
    ]
    assert against == []


def test_only_the_cad_layer_imports_opencascade():
    """OCP, build123d and cadquery are imported by tabletcad.cad and tabletcad.tooling alone."""
    bad = [
        f"{m}:{line} {name}" for m in MODULES if not m.startswith(("tabletcad.cad", "tabletcad.tooling"))
        for name, line in _imports(m) if name.split(".")[0] in CAD_LIBRARIES
    ]
    assert bad == []


def test_nothing_registers_itself_at_import_time():
    """No in-tree code adds to a registry when imported: the catalogue, the report and the build's
    steps are written out where they are used."""
    for name in ("register_stage", "register_family", "register_report_section", "_load_plugins"):
        hits = [str(p.relative_to(ROOT)) for p in PKG.rglob("*.py") if name in _source(p)]
        assert hits == [], name


FRESH = r"""
import sys
sys.path.insert(0, {root!r})
import tabletcad.families as F
before = dict(F.FAMILIES)
from tabletcad.pipeline.report import geometry_report
from tabletcad.pipeline.design import load_design
geometry_report(F.FAMILIES["concave_round"].build())
import tabletcad.pipeline.build, tabletcad.pipeline.model, tabletcad.optimise.files
assert dict(F.FAMILIES) == before
try:
    F.FAMILIES["mine"] = None
except TypeError:
    pass
else:
    raise SystemExit("FAMILIES is writable")
print(len(before), ",".join(before))
"""


def test_the_family_catalogue_is_static():
    """The same families whatever was imported before, and a read-only mapping."""
    from tabletcad.families import FAMILIES, INDUSTRY_FAMILIES, THESIS_FAMILIES

    out = subprocess.run([sys.executable, "-c", FRESH.format(root=str(ROOT))], capture_output=True, text=True,
                         timeout=300, cwd="/")
    assert out.returncode == 0, out.stderr[-2000:]
    n, names = out.stdout.split()
    assert int(n) == len(FAMILIES) == 25 and names.split(",") == list(FAMILIES)
    assert list(FAMILIES) == [*INDUSTRY_FAMILIES, *THESIS_FAMILIES]
    import tabletcad.families.thesis as thesis

    assert not hasattr(thesis, "FAMILIES")


@pytest.mark.parametrize("layer", range(len(LAYERS)))
def test_every_layer_names_modules_that_exist(layer):
    for key in LAYERS[layer]:
        assert key in MODULES, key



def test_every_module_compiles_without_a_warning():
    """No invalid escape sequence or other compile-time warning in the package, the workbench, the tests or the
    benchmarks: FreeCAD 1.0's Python 3.13 printed ``SyntaxWarning: invalid escape sequence '\\ '`` on importing
    tabletcad.tooling.spec (a docstring's ``\\ ``), and a later Python makes it an error."""
    import warnings

    files = sorted(p for d in ("tabletcad", "freecad_workbench", "tests", "benchmarks") for p in (ROOT / d).rglob("*.py"))
    assert len(files) > 200
    found = []
    for f in files:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            compile(f.read_text(encoding="utf-8"), str(f), "exec")
        found += [f"{f.relative_to(ROOT)}:{w.lineno}: {w.message}" for w in caught
                  if issubclass(w.category, (SyntaxWarning, DeprecationWarning))]
    assert found == []
