"""tabletcad: pharmaceutical tablets and their compression tooling, from PDE surfaces to exact STEP solids.

Units throughout: millimetres, newtons, megapascals (N/mm^2), milligrams, mg/mm^3.
The packages follow the flow design -> boundary curves -> PDE patches -> B-spline data ->
B-rep solids and meshes -> exports and tooling: ``geometry`` (curves, PDE patches,
tablets), ``families`` (the catalogue), ``mechanics``, ``brep`` (kernel-neutral B-spline
data), ``volume_mesh``, ``pipeline`` (design files, reports, pictures, the build),
``cad`` and ``tooling`` (OpenCascade), ``fe``, ``optimise``, ``sweep`` and ``cli``.
Everything but ``cad`` and ``tooling`` needs numpy and scipy only; those two add
OpenCascade (OCP), build123d and manifold3d.
"""


_LAZY = {"make": "pipeline.model", "load": "pipeline.model", "show": "pipeline.model", "TabletModel": "pipeline.model",
         "Design": "pipeline.design"}


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
