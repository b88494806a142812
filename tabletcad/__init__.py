"""tabletcad: pharmaceutical tablets and their compression tooling, from PDE surfaces to exact STEP solids.

Units throughout: millimetres, newtons, megapascals (N/mm^2), milligrams, mg/mm^3.
The numerical core (this package's top-level modules, ``families``,
``mechanics``, ``optimise``) needs numpy and scipy only; ``tabletcad.cad`` and
``tabletcad.tooling`` add OpenCascade (OCP), build123d and manifold3d.
"""


_LAZY = {"make": "model", "load": "model", "show": "model", "TabletModel": "model", "Design": "design"}


def __getattr__(name: str):  # PEP 562: `import tabletcad` stays light
    if name == "__version__":
        # looked up on first use: importlib.metadata costs ~50 ms at start-up, a window in
        # which Ctrl-C would escape the command line's handler
        from importlib import metadata

        try:
            return metadata.version("tabletcad")
        except metadata.PackageNotFoundError:  # run from a source tree (e.g. inside FreeCAD)
            return "0+source"
    if name in _LAZY:
        from importlib import import_module

        return getattr(import_module(f"tabletcad.{_LAZY[name]}"), name)
    raise AttributeError(f"module 'tabletcad' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted([*globals(), *_LAZY, "__version__"])
