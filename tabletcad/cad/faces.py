"""Kernel-neutral :class:`~tabletcad.brep.surface.BSplineSurfaceData` -> OCCT surfaces and faces.

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

A boundary row that collapses to a *segment* (a *slit*: the capsule's
innermost cup patch) is cut into exact pieces first, with the whole chain
(:func:`tabletcad.brep.slit.chain_face_surfaces`), each made into an ordinary face.

Boundary p-curves carry the surface's low-continuity ``v`` knots
(:func:`knot_boundary_pcurves`).  OCCT's mass properties (``BRepGProp``)
integrate a face as ``∮ dv ∫ du`` along its boundary edges and split the
``v`` range only at the knots of each edge's p-curve: the straight
``Geom2d_Line`` that ``BRepBuilderAPI_MakeFace`` gives an iso-``u`` boundary
has none, so a face whose area/volume integrand jumps or kinks in ``v`` (an
outline's line/arc junctions, corners whose offsets collapse to points:
knots of multiplicity ``degree`` or ``degree - 1``) was integrated across
those kinks in one piece and the adaptive Gauss rule stopped short of them
(measured -1.2e-4 volume on a rounded rectangle, with an error estimate of
1e-7).  The same straight line written as a degree-1 B-spline with knots at
the surface's junctions makes OCCT split there; the exact volume of the
B-splines is then reproduced to round-off.
"""

from __future__ import annotations

import numpy as np
from OCP.BRep import BRep_Builder, BRep_Tool
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.Geom import Geom_BSplineCurve, Geom_BSplineSurface, Geom_SurfaceOfRevolution
from OCP.Geom2d import Geom2d_BSplineCurve, Geom2d_Line
from OCP.gp import gp_Ax1, gp_Dir, gp_Dir2d, gp_Pnt, gp_Pnt2d
from OCP.TopoDS import TopoDS_Face, TopoDS_Shape

try:  # OCP >= 8.0
    from OCP.collections import Array1_gp_Pnt2d as Array1OfPnt2d
except ImportError:  # pragma: no cover - OCP 7.x
    from OCP.TColgp import TColgp_Array1OfPnt2d as Array1OfPnt2d

from tabletcad.brep.revolved import RevolvedSurfaceData
from tabletcad.brep.surface import BSplineSurfaceData
from tabletcad.cad._occ import Array1OfInteger, Array1OfPnt, Array1OfReal, Array2OfPnt
from tabletcad.errors import GeometryError

__all__ = ["face_of", "iso_u_pcurve", "knot_boundary_pcurves", "make_face", "v_breaks", "make_geom_surface", "make_revolved_face", "surface_data_from_geom"]


def _real_array(values) -> Array1OfReal:
    values = np.asarray(values, dtype=float).tolist()
    arr = Array1OfReal(1, len(values))
    for i, x in enumerate(values, start=1):
        arr.SetValue(i, x)
    return arr


def _int_array(values) -> Array1OfInteger:
    values = np.asarray(values, dtype=int).tolist()
    arr = Array1OfInteger(1, len(values))
    for i, x in enumerate(values, start=1):
        arr.SetValue(i, x)
    return arr


def make_geom_surface(data: BSplineSurfaceData) -> Geom_BSplineSurface:
    """Build the OCCT surface with exactly the poles, knots and multiplicities of ``data``."""
    nu, nv = data.shape
    poles = Array2OfPnt(1, nu, 1, nv)
    # Python floats (no numpy scalar per value) into one reused point, which SetValue copies:
    # 0.5 µs a pole instead of 0.8 with a new gp_Pnt each
    p = gp_Pnt()
    set_coord, set_value = p.SetCoord, poles.SetValue
    for i, row in enumerate(data.poles.tolist(), start=1):
        for j, (x, y, z) in enumerate(row, start=1):
            set_coord(x, y, z)
            set_value(i, j, p)
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


def make_face(data: BSplineSurfaceData, *, tol_degen: float = 1e-7, name: str = "surface",
              check: bool = True) -> TopoDS_Face:
    """A ``TopoDS_Face`` bounded by the natural limits of the surface; checked with
    ``BRepCheck_Analyzer`` unless ``check`` is false (a caller that checks the solid the
    faces make, which checks every face again).

    ``tol_degen`` is the length below which a boundary iso-curve becomes a
    degenerated edge (a pole of the patch).
    """
    face = face_of(make_geom_surface(data), tol_degen=tol_degen, name=name)
    if check and not BRepCheck_Analyzer(face).IsValid():
        raise GeometryError(f"face of {name} is not valid (BRepCheck_Analyzer)", data)
    return face


def face_of(surf: Geom_BSplineSurface, *, tol_degen: float = 1e-7, name: str = "surface") -> TopoDS_Face:
    """The face of the natural limits of ``surf`` (unchecked), its iso-``u`` boundary p-curves
    carrying the surface's C0/C1 ``v`` knots (:func:`knot_boundary_pcurves`)."""
    maker = BRepBuilderAPI_MakeFace(surf, float(tol_degen))
    if not maker.IsDone():
        raise GeometryError(f"BRepBuilderAPI_MakeFace failed for {name} (error {maker.Error()})", surf)
    face = maker.Face()
    knot_boundary_pcurves(face)
    return face


def make_revolved_face(data: RevolvedSurfaceData, *, tol_degen: float = 1e-7, name: str = "surface",
                       check: bool = True) -> TopoDS_Face:
    """The full turn about the z axis of the profile ``data`` (a ``Geom_BSplineCurve`` in the
    plane ``y = 0``, ``x = R``) as a ``Geom_SurfaceOfRevolution`` face; checked with
    ``BRepCheck_Analyzer`` unless ``check`` is False (a solid's own check covers its faces:
    :func:`~tabletcad.cad.solid.revolved_solid`).  A profile end on the axis becomes a degenerated
    edge (a pole)."""
    n = data.poles.shape[0]
    poles = Array1OfPnt(1, n)
    for i, (r, z) in enumerate(data.poles, start=1):
        poles.SetValue(i, gp_Pnt(float(r), 0.0, float(z)))
    try:
        curve = Geom_BSplineCurve(poles, _real_array(data.knots), _int_array(data.mults), data.degree, False)
    except Exception as exc:  # Standard_ConstructionError
        raise GeometryError(f"OCCT rejected the profile of {name}: {exc}", data) from exc
    surf = Geom_SurfaceOfRevolution(curve, gp_Ax1(gp_Pnt(0.0, 0.0, 0.0), gp_Dir(0.0, 0.0, 1.0)))
    maker = BRepBuilderAPI_MakeFace(surf, float(tol_degen))
    if not maker.IsDone():
        raise GeometryError(f"BRepBuilderAPI_MakeFace failed for {name} (error {maker.Error()})", data)
    face = maker.Face()
    if check and not BRepCheck_Analyzer(face).IsValid():
        raise GeometryError(f"face of {name} is not valid (BRepCheck_Analyzer)", data)
    return face


def v_breaks(knots, mults, degree: int) -> list[float]:
    """Interior ``v`` knots where a surface is at most C1 (multiplicity >= degree - 1)."""
    return [float(k) for k, m in zip(list(knots)[1:-1], list(mults)[1:-1]) if m >= max(degree - 1, 1)]


def _v_breaks(surf: Geom_BSplineSurface) -> list[float]:
    n = surf.NbVKnots()
    return v_breaks([surf.VKnot(i) for i in range(1, n + 1)], [surf.VMultiplicity(i) for i in range(1, n + 1)],
                    surf.VDegree())


def iso_u_pcurve(u0: float, a: float, b: float, breaks,
                 mirror: float | None = None) -> Geom2d_BSplineCurve | Geom2d_Line:
    """The p-curve ``t -> (u0, t)`` on ``[a, b]``: a ``Geom2d_Line``, or where ``breaks`` fall
    inside the range a degree-1 ``Geom2d_BSplineCurve`` with knots there (the same line, which
    ``BRepGProp`` splits its integration at: see the module docstring).  With ``mirror`` = ``c``, the
    p-curve ``t -> (u0, c - t)`` of a row run back along an edge whose parameter is ``t`` (``breaks``:
    the face's own ``v`` values, taken at ``t = c - v``)."""
    if mirror is not None:
        breaks = [mirror - k for k in breaks]
    ks = [a] + sorted(k for k in breaks if a + 1e-9 < k < b - 1e-9) + [b]
    if len(ks) == 2:
        if mirror is not None:
            return Geom2d_Line(gp_Pnt2d(u0, mirror), gp_Dir2d(0.0, -1.0))
        return Geom2d_Line(gp_Pnt2d(u0, 0.0), gp_Dir2d(0.0, 1.0))
    poles = Array1OfPnt2d(1, len(ks))
    for i, k in enumerate(ks, start=1):
        poles.SetValue(i, gp_Pnt2d(u0, k if mirror is None else mirror - k))
    return Geom2d_BSplineCurve(poles, _real_array(ks), _int_array([2] + [1] * (len(ks) - 2) + [2]), 1)


def knot_boundary_pcurves(shape: TopoDS_Shape) -> int:
    """Give every iso-``u`` boundary edge of the B-spline faces in ``shape`` a p-curve that
    carries the surface's C0/C1 ``v`` knots; returns how many p-curves were replaced.

    The p-curve stays the same straight line ``(u0, v)`` with the same parameter (so
    SameParameter and the 3-D edge are untouched); only its representation changes, from
    a ``Geom2d_Line`` (or the 2-knot B-spline sewing makes of it) to a degree-1
    ``Geom2d_BSplineCurve`` with knots at the junctions,
    which ``BRepGProp`` uses to split its integration (see the module docstring).  Seam
    edges (iso-``v``) are left alone.  Idempotent; call it again after operations that
    rebuild p-curves.
    """
    from tabletcad.cad._occ import explore

    builder = BRep_Builder()
    count = 0
    for face in explore(shape, "Face"):
        surf = BRep_Tool.Surface_s(face)
        if not isinstance(surf, Geom_BSplineSurface):
            continue
        breaks = _v_breaks(surf)
        if not breaks:
            continue
        for edge in explore(face, "Edge"):
            if BRep_Tool.IsClosed_s(edge, face):  # the seam (an iso-v line: no v range)
                continue
            pc = BRep_Tool.CurveOnSurface_s(edge, face, 0.0, 0.0)
            if pc is None:
                continue
            a, b = BRep_Tool.Range_s(edge, face)
            if not b > a:
                continue
            ks = [a] + [k for k in breaks if a + 1e-9 < k < b - 1e-9] + [b]
            # only p-curves t -> (u0, t), the straight iso-u lines MakeFace (a Geom2d_Line) or
            # sewing (a 2-knot B-spline) leave; skip those that already carry the knots
            if len(ks) == 2 or (isinstance(pc, Geom2d_BSplineCurve) and pc.NbKnots() >= len(ks)):
                continue
            ts = np.linspace(a, b, 9)
            pts = [pc.Value(float(x)) for x in ts]
            u0 = pts[0].X()
            if max(max(abs(p.X() - u0), abs(p.Y() - x)) for p, x in zip(pts, ts)) > 1e-9:
                continue
            builder.UpdateEdge(edge, iso_u_pcurve(u0, a, b, breaks), face, BRep_Tool.Tolerance_s(edge))
            builder.Range(edge, face, a, b)
            count += 1
    return count


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
