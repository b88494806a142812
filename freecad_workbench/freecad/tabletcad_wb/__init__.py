"""tabletcad as a FreeCAD workbench (``freecad.tabletcad_wb``).

Inside FreeCAD only the *pure* tabletcad core is used (numpy, scipy and
:mod:`tabletcad.brep`); faces, shells, solids and Booleans come from
FreeCAD's own ``Part`` module.  The project's virtual environment (OCP,
build123d) is never imported into FreeCAD's Python.

Importing this package makes the ``tabletcad`` core importable: the repository
root is taken from, in this order,

1. the environment variable ``TABLETCAD_ROOT``;
2. ``tabletcad_core_path.txt`` written by ``freecad_workbench/install.sh`` into
   the installed Mod folder (``Mod/tabletcad_wb/tabletcad_core_path.txt``);
3. the real location of this file (``<repo>/freecad_workbench/freecad/tabletcad_wb``),
   which is right when the Mod folder holds a symlink to the repository.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

__all__ = ["ICON_DIR", "core_root", "icon"]

__version__ = "0.1.0"

ICON_DIR = Path(__file__).resolve().parent / "icons"


def _is_root(p: Path) -> bool:
    return (p / "tabletcad" / "families" / "thesis.py").is_file()


def core_root() -> Path | None:
    """The tabletcad repository root used for ``import tabletcad`` (None if not found)."""
    env = os.environ.get("TABLETCAD_ROOT")
    if env and _is_root(Path(env)):
        return Path(env).resolve()
    here = Path(os.path.abspath(__file__))  # not resolved: inside the Mod folder when symlinked
    for parent in list(here.parents)[:4]:
        rec = parent / "tabletcad_core_path.txt"
        if rec.is_file():
            p = Path(rec.read_text(encoding="utf-8").strip())
            if _is_root(p):
                return p.resolve()
    real = Path(__file__).resolve()
    if len(real.parents) > 3 and _is_root(real.parents[3]):
        return real.parents[3]
    return None


def _add_core_to_path() -> None:
    root = core_root()
    if root is None:
        return
    root_s = str(root)
    if root_s not in sys.path:
        sys.path.insert(0, root_s)


def icon(name: str) -> str:
    """Absolute path of an icon (``Tablet`` -> ``icons/Tablet.svg``)."""
    return str(ICON_DIR / f"{name}.svg")


_add_core_to_path()
