"""Kernel-neutral :class:`~tabletcad.bspline.BSplineSurfaceData` -> OCCT surfaces and faces.

Design choice: the surface stays **periodic in v** (``Geom_BSplineSurface`` with
``VPeriodic=True``) and the face is made from the whole surface with
``BRepBuilderAPI_MakeFace(surface, TolDegen)``.  OCCT then creates

* one seam edge (the same 3-D edge used twice by the face, with two p-curves
  ``v = 0`` and ``v = 2 pi``) - the surface is C2 across it, no kink, no
  duplicated geometry to keep consistent;
* a degenerated edge for a boundary row that collapses to a point (the fit
  writes *one* point into the whole pole row, so ``TolDegen`` can stay tiny);
* an ordinary closed edge for a boundary circle, which ``BRepBuilderAPI_Sewing``
  matches with the neighbour's identical edge.

A clamped (non-periodic) ``v`` with a seam would need two extra coincident
boundary curves per face that sewing must pair with the face itself, gives a
C0 line on the surface and changes the knot vector the fit produced; with
OCCT 7.8/8.0 the periodic form sews, meshes and passes ``BRepCheck_Analyzer``
on spheres, cylinders and rings (see tests/test_cad_solid.py), and FreeCAD's
``buildFromPolesMultsKnots(..., periodic)`` accepts exactly the same data.
"""

from __future__ import annotations

import numpy as np
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.Geom import Geom_BSplineSurface
from OCP.gp import gp_Pnt
from OCP.TopoDS import TopoDS_Face

from tabletcad.bspline import BSplineSurfaceData
from tabletcad.cad._occ import Array1OfInteger, Array1OfReal, Array2OfPnt
from tabletcad.errors import GeometryError

__all__ = ["make_geom_surface", "make_face", "surface_data_from_geom"]


def _real_array(values) -> Array1OfReal:
    values = np.asarray(values, dtype=float)
    arr = Array1OfReal(1, values.size)
    for i, x in enumerate(values, start=1):
        arr.SetValue(i, float(x))
    return arr


def _int_array(values) -> Array1OfInteger:
    values = np.asarray(values, dtype=int)
    arr = Array1OfInteger(1, values.size)
    for i, x in enumerate(values, start=1):
        arr.SetValue(i, int(x))
    return arr


def make_geom_surface(data: BSplineSurfaceData) -> Geom_BSplineSurface:
    """Build the OCCT surface with exactly the poles, knots and multiplicities of ``data``."""
    nu, nv = data.shape
    poles = Array2OfPnt(1, nu, 1, nv)
    P = data.poles
    for i in range(nu):
        for j in range(nv):
            x, y, z = P[i, j]
            poles.SetValue(i + 1, j + 1, gp_Pnt(float(x), float(y), float(z)))
    try:
        return Geom_BSplineSurface(
            poles,
            _real_array(data.u_knots),
            _real_array(data.v_knots),
            _int_array(data.u_mults),
            _int_array(data.v_mults),
            data.u_degree,
            data.v_degree,
            data.u_periodic,
            data.v_periodic,
        )
    except Exception as exc:  # Standard_ConstructionError
        raise GeometryError(f"OCCT rejected the B-spline surface data: {exc}", data) from exc


def make_face(data: BSplineSurfaceData, *, tol_degen: float = 1e-7, name: str = "surface") -> TopoDS_Face:
    """A ``TopoDS_Face`` bounded by the natural limits of the surface; checked with ``BRepCheck_Analyzer``.

    ``tol_degen`` is the length below which a boundary iso-curve becomes a
    degenerated edge (a pole of the patch).
    """
    surf = make_geom_surface(data)
    maker = BRepBuilderAPI_MakeFace(surf, float(tol_degen))
    if not maker.IsDone():
        raise GeometryError(f"BRepBuilderAPI_MakeFace failed for {name} (error {maker.Error()})", data)
    face = maker.Face()
    if not BRepCheck_Analyzer(face).IsValid():
        raise GeometryError(f"face of {name} is not valid (BRepCheck_Analyzer)", data)
    return face


def surface_data_from_geom(surf: Geom_BSplineSurface) -> BSplineSurfaceData:
    """Read an OCCT B-spline surface back into kernel-neutral data (non-rational only)."""
    if surf.IsURational() or surf.IsVRational():
        raise GeometryError("rational B-spline surfaces are not supported", surf)
    nu, nv = surf.NbUPoles(), surf.NbVPoles()
    poles = np.empty((nu, nv, 3))
    for i in range(nu):
        for j in range(nv):
            p = surf.Pole(i + 1, j + 1)
            poles[i, j] = (p.X(), p.Y(), p.Z())
    return BSplineSurfaceData(
        poles=poles,
        u_knots=[surf.UKnot(i) for i in range(1, surf.NbUKnots() + 1)],
        u_mults=[surf.UMultiplicity(i) for i in range(1, surf.NbUKnots() + 1)],
        v_knots=[surf.VKnot(i) for i in range(1, surf.NbVKnots() + 1)],
        v_mults=[surf.VMultiplicity(i) for i in range(1, surf.NbVKnots() + 1)],
        u_degree=surf.UDegree(),
        v_degree=surf.VDegree(),
        u_periodic=surf.IsUPeriodic(),
        v_periodic=surf.IsVPeriodic(),
    )
