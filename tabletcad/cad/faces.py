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

A boundary row that collapses to a *segment* (a stadium's offsets at its
inscribed radius: the capsule's innermost cup patch) is a *slit*: the row
curve runs along the segment and back, with the end arcs collapsed to points.
Such a face is built by hand (:func:`slit_pieces`, ``_make_slit_face``): the
row is cut at its C0 knots into pieces, the constant pieces become
degenerated edges and each pair of pieces running along the same segment in
opposite directions becomes ONE edge used twice by the face, with a p-curve
on each side - a seam, like the periodic ``v`` seam, so the face closes on
itself there and sewing sees no free edge.

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
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRep import BRep_Builder, BRep_Tool
from OCP.Geom import Geom_BSplineSurface
from OCP.Geom2d import Geom2d_BSplineCurve
from OCP.Geom2d import Geom2d_Line
from OCP.gp import gp_Dir2d, gp_Pnt, gp_Pnt2d
from OCP.TopAbs import TopAbs_Orientation
from OCP.TopoDS import TopoDS_Edge, TopoDS_Face, TopoDS_Shape, TopoDS_Vertex, TopoDS_Wire

try:  # OCP >= 8.0
    from OCP.collections import Array1_gp_Pnt2d as Array1OfPnt2d
except ImportError:  # pragma: no cover - OCP 7.x
    from OCP.TColgp import TColgp_Array1OfPnt2d as Array1OfPnt2d

from tabletcad.bspline import BSplineSurfaceData
from tabletcad.cad._occ import Array1OfInteger, Array1OfReal, Array2OfPnt
from tabletcad.errors import GeometryError

__all__ = ["make_geom_surface", "make_face", "surface_data_from_geom", "knot_boundary_pcurves", "slit_pieces"]


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
    slits = {k: slit_pieces(data, k, tol_degen) for k in (0, -1)}
    if any(v is not None for v in slits.values()):
        face = _make_slit_face(data, surf, slits, tol_degen, name)
    else:
        maker = BRepBuilderAPI_MakeFace(surf, float(tol_degen))
        if not maker.IsDone():
            raise GeometryError(f"BRepBuilderAPI_MakeFace failed for {name} (error {maker.Error()})", data)
        face = maker.Face()
    knot_boundary_pcurves(face)
    if not BRepCheck_Analyzer(face).IsValid():
        raise GeometryError(f"face of {name} is not valid (BRepCheck_Analyzer)", data)
    return face


def slit_pieces(data: BSplineSurfaceData, row: int, tol: float = 1e-7):
    """The pieces of boundary row ``row`` (0: ``u`` first, -1: ``u`` last) if it is a slit, else None.

    The row curve ``S(u_row, v)`` is cut at the C0 ``v`` knots (multiplicity >=
    degree, where the fit puts the outline's junctions) into pieces
    ``(v0, v1, kind, partner)``: ``kind`` is ``"point"`` (the piece stays within
    ``tol`` of one point) or ``"run"``; every run must have a partner run that
    traverses the same points backwards (``S(v0 + t (v1 - v0)) = S(w1 - t (w1 - w0))``
    within ``tol``).  A row that is one point (a pole), has no run, or has an
    unpaired run is not a slit.
    """
    if not data.v_periodic or data.u_periodic:
        return None
    u_row = float(data.u_knots[0] if row == 0 else data.u_knots[-1])
    knots = np.asarray(data.v_knots, dtype=float)
    mults = np.asarray(data.v_mults)
    period_lo, period_hi = float(knots[0]), float(knots[-1])
    cuts = sorted({period_lo, period_hi, *[float(k) for k, m in zip(knots, mults) if m >= data.v_degree]})
    if len(cuts) < 4:  # fewer than three pieces cannot be a fold with collapsed ends
        return None
    t = np.linspace(0.0, 1.0, 17)
    pts = []
    for a, b in zip(cuts[:-1], cuts[1:]):
        v = a + (b - a) * t
        pts.append(np.asarray(data.evaluate(np.full_like(v, u_row), v), dtype=float))
    scale = max(1.0, float(np.max(np.abs(np.concatenate(pts)))))
    kinds = ["point" if float(np.max(np.linalg.norm(p - p[0], axis=-1))) <= tol else "run" for p in pts]
    runs = [i for i, k in enumerate(kinds) if k == "run"]
    if not runs or len(runs) % 2 or all(k == "point" for k in kinds):
        return None
    partner: dict[int, int] = {}
    for i in runs:
        if i in partner:
            continue
        for j in runs:
            if j != i and j not in partner and float(np.max(np.linalg.norm(pts[i] - pts[j][::-1], axis=-1))) <= tol * scale:
                partner[i], partner[j] = j, i
                break
        else:
            return None
    return [(cuts[i], cuts[i + 1], kinds[i], partner.get(i)) for i in range(len(kinds))], u_row


def _line2d(p, d) -> Geom2d_Line:
    return Geom2d_Line(gp_Pnt2d(float(p[0]), float(p[1])), gp_Dir2d(float(d[0]), float(d[1])))


def _affine2d(t0: float, t1: float, p0, p1) -> Geom2d_BSplineCurve:
    """The straight p-curve from ``p0`` at parameter ``t0`` to ``p1`` at ``t1`` (degree 1)."""
    poles = Array1OfPnt2d(1, 2)
    poles.SetValue(1, gp_Pnt2d(float(p0[0]), float(p0[1])))
    poles.SetValue(2, gp_Pnt2d(float(p1[0]), float(p1[1])))
    return Geom2d_BSplineCurve(poles, _real_array([t0, t1]), _int_array([2, 2]), 1)


def _make_slit_face(data: BSplineSurfaceData, surf: Geom_BSplineSurface, slits: dict, tol_degen: float,
                    name: str) -> TopoDS_Face:
    """The face of a periodic-in-v surface one or both of whose boundary rows are slits
    (see :func:`slit_pieces`), built edge by edge; the other row is a closed edge or a pole."""
    from OCP.TopLoc import TopLoc_Location

    FWD, REV = TopAbs_Orientation.TopAbs_FORWARD, TopAbs_Orientation.TopAbs_REVERSED
    B = BRep_Builder()
    tol = max(float(tol_degen), 1e-7)
    v_lo, v_hi = float(data.v_knots[0]), float(data.v_knots[-1])
    u_lo, u_hi = float(data.u_knots[0]), float(data.u_knots[-1])
    face = TopoDS_Face()
    B.MakeFace(face, surf, TopLoc_Location(), tol)
    vertices: list[tuple[np.ndarray, TopoDS_Vertex]] = []

    def vertex(u: float, v: float) -> TopoDS_Vertex:
        p = np.asarray(data.evaluate(np.array([u]), np.array([v])), dtype=float).reshape(3)
        for q, vx in vertices:
            if float(np.linalg.norm(q - p)) <= tol:
                return vx
        vx = TopoDS_Vertex()
        B.MakeVertex(vx, gp_Pnt(*map(float, p)), tol)
        vertices.append((p, vx))
        return vx

    def bounded(edge: TopoDS_Edge, v0: TopoDS_Vertex, v1: TopoDS_Vertex, a: float, b: float) -> TopoDS_Edge:
        B.Add(edge, v0.Oriented(FWD))
        B.Add(edge, v1.Oriented(REV))
        B.Range(edge, a, b)
        return edge

    def degenerated(u: float, a: float, b: float) -> TopoDS_Edge:
        e = TopoDS_Edge()
        B.MakeEdge(e)
        B.UpdateEdge(e, _line2d((u, 0.0), (0.0, 1.0)), face, tol)
        B.Degenerated(e, True)
        vx = vertex(u, a)
        return bounded(e, vx, vx, a, b)

    def row_side(k: int) -> list[tuple[TopoDS_Edge, TopAbs_Orientation]]:
        """Edges of row ``k`` in the order of increasing v, each with its orientation along +v."""
        u = u_lo if k == 0 else u_hi
        slit = slits[k]
        row = data.poles[k]
        if slit is None:
            if float(np.max(np.linalg.norm(row - row[0], axis=-1))) <= tol:  # a pole
                return [(degenerated(u, v_lo, v_hi), FWD)]
            e = TopoDS_Edge()
            B.MakeEdge(e, surf.UIso(u), tol)
            B.UpdateEdge(e, _line2d((u, 0.0), (0.0, 1.0)), face, tol)
            vx = vertex(u, v_lo)
            return [(bounded(e, vx, vx, v_lo, v_hi), FWD)]
        pieces, _ = slit
        out: list = [None] * len(pieces)
        # the side is walked with +v on u = u_hi and with -v on u = u_lo (counter-clockwise in (u, v))
        walk_fwd = k != 0
        for i, (a, b, kind, j) in enumerate(pieces):
            if kind == "point":
                out[i] = (degenerated(u, a, b), FWD)
            elif j is not None and out[j] is None and out[i] is None:
                c, d = pieces[j][0], pieces[j][1]
                e = TopoDS_Edge()
                B.MakeEdge(e, surf.UIso(u), tol)
                pc_i = _line2d((u, 0.0), (0.0, 1.0))  # piece i: parameter = v
                pc_j = _affine2d(a, b, (u, d), (u, c))  # piece j: the same points backwards
                # a closed edge's first p-curve is the one used where the edge is FORWARD in the wire
                if walk_fwd:
                    B.UpdateEdge(e, pc_i, pc_j, face, tol)
                else:
                    B.UpdateEdge(e, pc_j, pc_i, face, tol)
                bounded(e, vertex(u, a), vertex(u, b), a, b)
                out[i] = (e, FWD)
                out[j] = (e, REV)
        return out

    seam = TopoDS_Edge()
    B.MakeEdge(seam, surf.VIso(v_lo), tol)
    B.UpdateEdge(seam, _line2d((0.0, v_lo), (1.0, 0.0)), _line2d((0.0, v_hi), (1.0, 0.0)), face, tol)
    side0 = row_side(0)
    side1 = row_side(-1)
    bounded(seam, vertex(u_lo, v_lo), vertex(u_hi, v_lo), u_lo, u_hi)
    wire = TopoDS_Wire()
    B.MakeWire(wire)
    B.Add(wire, seam.Oriented(FWD))  # (u_lo, v_lo) -> (u_hi, v_lo)
    for e, o in side1:  # u = u_hi, +v
        B.Add(wire, e.Oriented(o))
    B.Add(wire, seam.Oriented(REV))  # (u_hi, v_hi) -> (u_lo, v_hi)
    for e, o in reversed(side0):  # u = u_lo, -v
        B.Add(wire, e.Oriented(REV if o == FWD else FWD))
    B.Add(face, wire)
    from OCP.BRepLib import BRepLib

    BRepLib.SameParameter_s(face, tol)
    BRepLib.UpdateTolerances_s(face)
    return face


def _v_breaks(surf: Geom_BSplineSurface) -> list[float]:
    """Interior ``v`` knots where the surface is at most C1 (multiplicity >= degree - 1)."""
    deg = surf.VDegree()
    n = surf.NbVKnots()
    return [surf.VKnot(i) for i in range(1, n + 1) if surf.VMultiplicity(i) >= max(deg - 1, 1)]


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
            if BRep_Tool.IsClosed_s(edge, face):  # the seam (an iso-v line: no v range) or a slit
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
            m = len(ks)
            poles = Array1OfPnt2d(1, m)
            for i, k in enumerate(ks, start=1):
                poles.SetValue(i, gp_Pnt2d(u0, k))
            mults = [2] + [1] * (m - 2) + [2]
            curve = Geom2d_BSplineCurve(poles, _real_array(ks), _int_array(mults), 1)
            builder.UpdateEdge(edge, curve, face, BRep_Tool.Tolerance_s(edge))
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
