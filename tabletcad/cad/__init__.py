"""CAD layer: the only package of tabletcad that imports OCP, build123d or cadquery.

* :mod:`tabletcad.cad.faces`   - kernel-neutral B-spline data -> ``Geom_BSplineSurface`` -> ``TopoDS_Face``
* :mod:`tabletcad.cad.solid`   - fit, sew and validate a closed solid; adaptive mass properties
* :mod:`tabletcad.cad.mesh`    - tessellation + manifold3d and edge checks
* :mod:`tabletcad.cad.export`  - STEP / STL / 3MF / GLB / BREP writers chosen by suffix
* :mod:`tabletcad.cad.interop` - build123d / cadquery wrappers (imported lazily)
"""

from importlib import import_module
from typing import Any

_LAZY = {
    "make_face": "faces",
    "make_geom_surface": "faces",
    "surface_data_from_geom": "faces",
    "MassProperties": "solid",
    "TabletSolid": "solid",
    "build_solid": "solid",
    "mass_properties": "solid",
    "solid_from_surfaces": "solid",
    "solid_from_tablet": "solid",
    "MeshResult": "mesh",
    "tessellate": "mesh",
    "export": "export",
}

__all__ = sorted(_LAZY)


def __getattr__(name: str) -> Any:  # PEP 562: OCP is imported only when needed
    if name in _LAZY:
        return getattr(import_module(f"tabletcad.cad.{_LAZY[name]}"), name)
    raise AttributeError(f"module 'tabletcad.cad' has no attribute {name!r}")
