"""tabletcad: pharmaceutical tablets and their compression tooling, from PDE surfaces to exact STEP solids.

Units throughout: millimetres, newtons, megapascals (N/mm^2), milligrams, mg/mm^3.
The numerical core (this package's top-level modules, ``families``,
``mechanics``, ``optimise``) needs numpy and scipy only; ``tabletcad.cad`` and
``tabletcad.tooling`` add OpenCascade (OCP), build123d and manifold3d.
"""



def __getattr__(name: str) -> str:
    # ``__version__`` is looked up on first use: importlib.metadata costs ~50 ms at start-up,
    # a window in which Ctrl-C would escape the command line's handler
    if name != "__version__":
        raise AttributeError(f"module 'tabletcad' has no attribute {name!r}")
    from importlib import metadata

    try:
        return metadata.version("tabletcad")
    except metadata.PackageNotFoundError:  # run from a source tree (e.g. inside FreeCAD)
        return "0+source"
