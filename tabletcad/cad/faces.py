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
inscribed radius: the capsule's innermost cup patch) is a *slit*
(:func:`slit_pieces`): the row curve runs along the segment and back, with
the end arcs collapsed to points.  :func:`make_faces` gives such a surface
as two faces, cut in ``v`` through one collapsed end, so that each half
bounds the segment once and sewing joins the halves along it (and along the
cut); one face using the segment edge twice would be valid in OCCT but is
torn open by STEP readers.

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
from OCP.Geom import Geom_BSplineSurface
from OCP.Geom2d import Geom2d_BSplineCurve, Geom2d_Line
from OCP.gp import gp_Dir2d, gp_Pnt, gp_Pnt2d
from OCP.TopoDS import TopoDS_Face, TopoDS_Shape

try:  # OCP >= 8.0
    from OCP.collections import Array1_gp_Pnt2d as Array1OfPnt2d
except ImportError:  # pragma: no cover - OCP 7.x
    from OCP.TColgp import TColgp_Array1OfPnt2d as Array1OfPnt2d

from tabletcad.bspline import BSplineSurfaceData
from tabletcad.cad._occ import Array1OfInteger, Array1OfReal, Array2OfPnt
from tabletcad.errors import GeometryError

__all__ = ["knot_boundary_pcurves", "make_face", "make_faces", "make_geom_surface", "slit_pieces", "surface_data_from_geom"]


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
    pieces = [(cuts[i], cuts[i + 1], kinds[i], partner.get(i)) for i in range(len(kinds))]
    # consecutive collapsed pieces (e.g. two corner arcs of one end) are one point piece
    merged: list = []
    index: dict[int, int] = {}
    for i, pc in enumerate(pieces):
        if pc[2] == "point" and merged and merged[-1][2] == "point":
            merged[-1] = (merged[-1][0], pc[1], "point", None)
        else:
            merged.append(pc)
        index[i] = len(merged) - 1
    merged = [(a, b, k, None if j is None else index[j]) for a, b, k, j in merged]
    return merged, u_row


def _slit_split(slit) -> float | None:
    """``v`` at which a slit face is cut in two: the middle of the collapsed end that does not
    hold the periodic seam; None for slits of another pattern (more than one segment)."""
    pieces, _ = slit
    v_first, v_last = pieces[0][0], pieces[-1][1]
    runs = [p for p in pieces if p[2] == "run"]
    inner = [p for p in pieces if p[2] == "point" and p[0] > v_first and p[1] < v_last]
    if len(runs) != 2 or len(inner) != 1:
        return None
    return 0.5 * (inner[0][0] + inner[0][1])


def _line2d(p, d) -> Geom2d_Line:
    return Geom2d_Line(gp_Pnt2d(float(p[0]), float(p[1])), gp_Dir2d(float(d[0]), float(d[1])))


def _affine2d(t0: float, t1: float, p0, p1) -> Geom2d_BSplineCurve:
    """The straight p-curve from ``p0`` at parameter ``t0`` to ``p1`` at ``t1`` (degree 1)."""
    poles = Array1OfPnt2d(1, 2)
    poles.SetValue(1, gp_Pnt2d(float(p0[0]), float(p0[1])))
    poles.SetValue(2, gp_Pnt2d(float(p1[0]), float(p1[1])))
    return Geom2d_BSplineCurve(poles, _real_array([t0, t1]), _int_array([2, 2]), 1)


def make_faces(data: BSplineSurfaceData, *, tol_degen: float = 1e-7, name: str = "surface") -> tuple[TopoDS_Face, ...]:
    """The face(s) of one fitted surface: one periodic face (:func:`make_face`), or two halves
    when a boundary row is a slit (:func:`slit_pieces`).

    A slit row runs along a segment and back; as ONE face that segment would be an edge
    used twice by the face, the two uses meeting around the segment's far end through a
    degenerated edge.  STEP has no degenerated edges, so a reader sees that edge go out and
    straight back and deletes it as a spike (the solid comes back open).  Cut in ``v``
    through the middle of the collapsed end that does not hold the seam, each half uses the
    segment once: two faces built edge by edge that share the segment edge (a p-curve on
    each, the second one running backwards), the cut and the seam; only the other row is
    left for sewing, as two edges.
    """
    slits = {k: slit_pieces(data, k, tol_degen) for k in (0, -1)}
    if all(sl is None for sl in slits.values()):
        return (make_face(data, tol_degen=tol_degen, name=name),)
    if all(sl is not None for sl in slits.values()):
        raise GeometryError(f"{name}: both boundary rows collapse to segments", data)
    k_slit = 0 if slits[0] is not None else -1
    slit = slits[k_slit]
    v_cut = _slit_split(slit)
    if v_cut is None:
        raise GeometryError(f"{name}: a boundary row collapses to a pattern of segments this kernel does not cut", data)
    return _slit_halves(data, k_slit, slit[0], v_cut, tol_degen, name)


def _slit_halves(data: BSplineSurfaceData, k_slit: int, pieces, v_cut: float, tol_degen: float,
                 name: str) -> tuple[TopoDS_Face, TopoDS_Face]:
    from OCP.BRepLib import BRepLib
    from OCP.TopAbs import TopAbs_Orientation
    from OCP.TopLoc import TopLoc_Location
    from OCP.TopoDS import TopoDS_Edge, TopoDS_Vertex, TopoDS_Wire

    FWD, REV = TopAbs_Orientation.TopAbs_FORWARD, TopAbs_Orientation.TopAbs_REVERSED
    B = BRep_Builder()
    tol = max(float(tol_degen), 1e-7)
    surf = make_geom_surface(data)
    u0, u1 = float(data.u_knots[0]), float(data.u_knots[-1])
    v0, v1 = float(data.v_knots[0]), float(data.v_knots[-1])
    u_s = u0 if k_slit == 0 else u1
    u_o = u1 if k_slit == 0 else u0
    row_o = data.poles[-1 if k_slit == 0 else 0]
    if float(np.max(np.linalg.norm(row_o - row_o[0], axis=-1))) <= tol:
        raise GeometryError(f"{name}: a slit opposite a pole is not supported", data)
    faces = [TopoDS_Face(), TopoDS_Face()]
    # one surface object per half: OCCT keys an edge's p-curves by (surface, location), so
    # halves on a shared surface object would overwrite each other's p-curve of a shared edge
    for f in faces:
        B.MakeFace(f, make_geom_surface(data), TopLoc_Location(), tol)
    ranges = [(v0, v_cut), (v_cut, v1)]
    vertices: list = []

    def vertex(u: float, v: float):
        p = np.asarray(data.evaluate(np.array([u]), np.array([v])), dtype=float).reshape(3)
        for q, vx in vertices:
            if float(np.linalg.norm(q - p)) <= 10 * tol:
                return vx
        vx = TopoDS_Vertex()
        B.MakeVertex(vx, gp_Pnt(*map(float, p)), tol)
        vertices.append((p, vx))
        return vx

    def bounded(edge, va, vb, a: float, b: float):
        B.Add(edge, va.Oriented(FWD))
        B.Add(edge, vb.Oriented(REV))
        B.Range(edge, a, b)
        return edge

    def iso_v(v: float):
        e = TopoDS_Edge()
        B.MakeEdge(e, surf.VIso(v), tol)
        return bounded(e, vertex(u0, v), vertex(u1, v), u0, u1)

    seam = iso_v(v0)
    cut = iso_v(v_cut)
    B.UpdateEdge(seam, _line2d((0.0, v0), (1.0, 0.0)), faces[0], tol)
    B.UpdateEdge(seam, _line2d((0.0, v1), (1.0, 0.0)), faces[1], tol)
    for f in faces:
        B.UpdateEdge(cut, _line2d((0.0, v_cut), (1.0, 0.0)), f, tol)

    # The slit side of each half is ONE edge: the segment with its collapsed ends (the 3-D
    # curve stands still there, as on a rim whose corners collapsed; no degenerated edges,
    # which STEP cannot carry).  Parameter: v of half 0; on half 1 the p-curve runs the other
    # way, piecewise linear so that it meets the same points: half 0's (start, run start, run
    # end, end) match half 1's (end, run end, run start, start).
    def run_of(h: int):
        a_h, b_h = ranges[h]
        rs = [p for p in pieces if p[2] == "run" and p[0] >= a_h - 1e-12 and p[1] <= b_h + 1e-12]
        if len(rs) != 1:
            raise GeometryError(f"{name}: each half of the slit face must hold one run of the segment", data)
        return rs[0][0], rs[0][1]

    (lo0, hi0), (lo1, hi1) = ranges
    (r00, r10), (r01, r11) = run_of(0), run_of(1)
    pairs = [(lo0, hi1), (r00, r11), (r10, r01), (hi0, lo1)]
    ts, ws = [pairs[0][0]], [pairs[0][1]]
    for t_, w_ in pairs[1:]:
        if t_ - ts[-1] <= 1e-12:
            if abs(w_ - ws[-1]) > 1e-12:
                raise GeometryError(f"{name}: the slit's collapsed ends do not match between the halves", data)
            continue
        ts.append(t_)
        ws.append(w_)
    m = len(ts)
    poles = Array1OfPnt2d(1, m)
    for i, w_ in enumerate(ws, start=1):
        poles.SetValue(i, gp_Pnt2d(u_s, float(w_)))
    back = Geom2d_BSplineCurve(poles, _real_array(ts), _int_array([2] + [1] * (m - 2) + [2]), 1)
    seg = TopoDS_Edge()
    B.MakeEdge(seg, surf.UIso(u_s), tol)
    B.UpdateEdge(seg, _line2d((u_s, 0.0), (0.0, 1.0)), faces[0], tol)
    B.UpdateEdge(seg, back, faces[1], tol)
    bounded(seg, vertex(u_s, lo0), vertex(u_s, hi0), lo0, hi0)

    def slit_side(h: int):
        """The slit row of half ``h``, walked with increasing v."""
        return [(seg, FWD if h == 0 else REV)]

    def other_side(h: int):
        a, b = ranges[h]
        e = TopoDS_Edge()
        B.MakeEdge(e, surf.UIso(u_o), tol)
        B.UpdateEdge(e, _line2d((u_o, 0.0), (0.0, 1.0)), faces[h], tol)
        return [(bounded(e, vertex(u_o, a), vertex(u_o, b), a, b), FWD)]

    bottom = [(seam, FWD), (cut, FWD)]  # v = v_lo of each half, walked u0 -> u1
    top = [(cut, REV), (seam, REV)]  # v = v_hi of each half, walked u1 -> u0
    for h, f in enumerate(faces):
        right = slit_side(h) if k_slit == -1 else other_side(h)  # u = u1, +v
        left = slit_side(h) if k_slit == 0 else other_side(h)  # u = u0, walked -v
        wire = TopoDS_Wire()
        B.MakeWire(wire)
        B.Add(wire, bottom[h][0].Oriented(bottom[h][1]))
        for e, o in right:
            B.Add(wire, e.Oriented(o))
        B.Add(wire, top[h][0].Oriented(top[h][1]))
        for e, o in reversed(left):
            B.Add(wire, e.Oriented(REV if o == FWD else FWD))
        B.Add(f, wire)
    for f in faces:
        BRepLib.SameParameter_s(f, tol)
        knot_boundary_pcurves(f)
        if not BRepCheck_Analyzer(f).IsValid():
            raise GeometryError(f"half face of {name} is not valid (BRepCheck_Analyzer)", data)
    return faces[0], faces[1]


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
