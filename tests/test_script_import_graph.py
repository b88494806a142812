"""One-way flow, statically: the core Tablet never imports the CAD layer or the facade, not even lazily."""

import ast
from pathlib import Path

import pytest

PKG = Path(__file__).resolve().parents[1] / "tabletcad"
CAD = ("OCP", "build123d", "cadquery", "tabletcad.cad", "tabletcad.tooling")


def _imports(path: Path, top_level_only: bool = False) -> set[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    nodes = tree.body if top_level_only else list(ast.walk(tree))
    out = set()
    for n in nodes:
        if isinstance(n, ast.Import):
            out |= {a.name for a in n.names}
        elif isinstance(n, ast.ImportFrom) and n.module and n.level == 0:
            out.add(n.module)
    return out


def _bad(mods: set[str], banned) -> set[str]:
    return {m for m in mods if any(m == b or m.startswith(b + ".") for b in banned)}


@pytest.mark.parametrize("module", ["geometry/tablet.py", "geometry/patch.py", "pipeline/plot.py", "families/inverse.py"])
def test_core_modules_never_import_cad(module):
    assert _bad(_imports(PKG / module), (*CAD, "tabletcad.pipeline.model")) == set()


def test_facade_imports_cad_only_inside_methods():
    path = PKG / "pipeline" / "model.py"
    assert _bad(_imports(path, top_level_only=True), CAD) == set()
    assert _bad(_imports(path), CAD)  # ...and does use the CAD layer, lazily (the check can fail)
