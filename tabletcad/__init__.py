"""tabletcad: pharmaceutical tablets and their compression tooling, from PDE surfaces to exact STEP solids.

Units throughout: millimetres, newtons, megapascals (N/mm^2), milligrams, mg/mm^3.
The numerical core (this package's top-level modules, ``families``,
``mechanics``, ``optimise``) needs numpy and scipy only; ``tabletcad.cad`` and
``tabletcad.tooling`` add OpenCascade (OCP), build123d and manifold3d.
"""

from importlib import metadata as _metadata

try:
    __version__ = _metadata.version("tabletcad")
except _metadata.PackageNotFoundError:  # run from a source tree (e.g. inside FreeCAD)
    __version__ = "0+source"

_LAZY = {"make": "model", "load": "model", "show": "model", "TabletModel": "model"}


def __getattr__(name: str):  # PEP 562: `import tabletcad` stays light
    if name in _LAZY:
        from importlib import import_module

        return getattr(import_module(f"tabletcad.{_LAZY[name]}"), name)
    raise AttributeError(f"module 'tabletcad' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted([*globals(), *_LAZY])
