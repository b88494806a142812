"""What tooling needs to know about a tablet: its band, plan outline and faces.

:func:`tablet_frame` finds the band (the cylindrical side wall the die forms)
and the plan outline:

* industry families (:mod:`tabletcad.families`) carry their exact outline of
  lines and arcs and the band heights in their nominal;
* the thesis's coaxial tablets have a band patch whose curves are circles or
  ellipses (read from the patch data);
* otherwise the B-rep is cut by the plane through the band's middle.

The outline becomes an OCC wire at ``z = 0``; :func:`offset_wire` moves it
outward (> 0) or inward (< 0), :func:`prism` extrudes it.  An offset that OCC
keeps as a ``Geom_OffsetCurve`` (an ellipse's: the thesis's ovals and caplet)
becomes a B-spline within :data:`OFFSET_CURVE_TOL_MM` of it, whose p-curves on
the tips' planes agree with it (:func:`bspline_offset_curves`).

A custom outline through points (a :class:`~tabletcad.families.outline.SplineOutline`) is not offset
by OCC (its planar offset failed on every such outline tried): its wire and each offset the tooling
asks for (:meth:`TabletFrame.offset`) are B-splines built from the outline's exact offset
``O + d N`` (:func:`spline_offset_wire`), within :data:`SPLINE_OFFSET_TOL_MM` of it, measured
densely; an offset that is no regular offset of the outline is refused
(:meth:`~tabletcad.families.outline.SplineOutline.offset_bound`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np
from OCP.BRepAlgoAPI import BRepAlgoAPI_Section
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakeWire
from OCP.BRepGProp import BRepGProp
from OCP.BRepOffsetAPI import BRepOffsetAPI_MakeOffset
from OCP.BRepPrimAPI import BRepPrimAPI_MakePrism
from OCP.GC import GC_MakeArcOfCircle
from OCP.GeomAbs import GeomAbs_JoinType
from OCP.GProp import GProp_GProps
from OCP.gp import gp_Ax2, gp_Circ, gp_Dir, gp_Elips, gp_Pln, gp_Pnt, gp_Vec
from OCP.ShapeAnalysis import ShapeAnalysis_FreeBounds
from OCP.TopoDS import TopoDS_Shape

from tabletcad.cad._occ import cast, explore
from tabletcad.errors import DesignError, GeometryError
from tabletcad.families.outline import SplineOutline
from tabletcad.families.thesis import NO_LAND
from tabletcad.geometry.tablet import Tablet
from tabletcad.tooling.booleans import translated
from tabletcad.tooling.spec import band_heights, spline_offset_error

__all__ = ["TabletFrame", "tablet_frame", "offset_wire", "spline_offset_wire", "prism", "plan_face", "wire_length",
           "face_area"]

#: why a tablet whose band's section OCC cannot offset gets no tooling (a free-form band that is none of the
#: outlines the frame takes exactly)
SECTION_OFFSET_REFUSAL = ("tooling needs an outline it can offset for the tips and the bore: lines and arcs, a circle, "
                          "an ellipse or a spline through points (custom_outline); the section of this tablet's band "
                          "cannot be offset")



@dataclass(eq=False)
class TabletFrame:
    """Facts about a tablet used to make its tooling (mm).

    ``band_z`` is the band's (bottom, top) height, ``z_min``/``z_max`` the
    tablet's lowest and highest points, ``cup_depth`` the top cup's depth above
    the band (``z_max - band_z[1]``; the bottom one is ``band_z[0] - z_min``),
    ``outline`` a closed OCC wire at ``z = 0``, ``shape`` the tablet solid;
    ``band_bulge`` how far the band's PDE surface leaves the outline (mm); ``revolved`` the solid with
    faces of revolution whose rational B-spline form ``shape`` is (None when it had none); ``spline`` the
    tablet's :class:`~tabletcad.families.outline.SplineOutline` when its plan is a spline through points
    (``outline`` is then its B-spline, and :meth:`offset` builds each offset from its exact offset).
    """

    tablet: Tablet
    shape: TopoDS_Shape
    band_z: tuple[float, float]
    band_bulge: float
    z_min: float
    z_max: float
    outline: Any
    outline_kind: str
    round_radius: float | None
    land: float | None
    length: float
    width: float
    info: dict = field(default_factory=dict)
    revolved: TopoDS_Shape | None = None
    spline: Any = None
    _offsets: dict = field(default_factory=dict, repr=False)

    @property
    def band(self) -> float:
        return self.band_z[1] - self.band_z[0]

    @property
    def bore_offset(self) -> float:
        """How far (mm) the die bore stands outside the outline: the band's PDE bulge (at least
        ``MIN_BORE_OFFSET_MM`` when the band bulges at all), 0 for a band that is a prism
        (:func:`~tabletcad.tooling.spec.bore_offset`)."""
        from tabletcad.tooling.spec import bore_offset

        return bore_offset(self.band_bulge)

    def tip_inset(self, clearance: float) -> float:
        """How far (mm) the punch tips' walls stand inside the outline for a radial ``clearance`` (mm)
        between tip and die bore (:func:`~tabletcad.tooling.spec.tip_inset` of :attr:`bore_offset`)."""
        from tabletcad.tooling.spec import tip_inset

        return tip_inset(clearance, self.bore_offset)

    def offset(self, distance: float) -> Any:
        """The outline offset by ``distance`` mm (> 0 outward: a die bore; < 0 inward: a punch tip), a closed
        wire at ``z = 0``: OCC's planar offset (:func:`offset_wire`), or for a spline outline the B-spline of
        its exact offset (:func:`spline_offset_wire`, remembered per distance; a :class:`DesignError` for an
        offset that is no regular offset of it)."""
        if self.spline is None:
            return offset_wire(self.outline, distance)
        return self._spline_offset(distance)[0]

    def offset_deviation(self, distance: float) -> float | None:
        """How far (mm) the wire :meth:`offset` gives for ``distance`` leaves the outline's exact offset, as
        measured densely (:func:`spline_offset_wire`); ``None`` where OCC offsets the outline."""
        return None if self.spline is None else self._spline_offset(distance)[1]

    def _spline_offset(self, distance: float) -> tuple[Any, float]:
        key = float(distance)
        hit = self._offsets.get(key)
        if hit is None:
            hit = self._offsets[key] = spline_offset_wire(self.spline, key)
        return hit

    @property
    def cup_depth_top(self) -> float:
        return self.z_max - self.band_z[1]

    @property
    def cup_depth_bottom(self) -> float:
        return self.band_z[0] - self.z_min

    def edge_land(self, face: str = "top") -> float:
        """The land to keep figures and short scores away from (mm): the family's land, except on a
        flat face (no cup), where the whole face is flat and there is no land ring."""
        cup = self.cup_depth_top if face == "top" else self.cup_depth_bottom
        return 0.0 if cup < 1e-9 else (self.land or 0.0)

    @property
    def thickness(self) -> float:
        return self.z_max - self.z_min

    @cached_property
    def plan_diameter(self) -> float:
        """The tablet's largest extent in plan, in any direction (mm; a rounded square's diagonal): the size
        the standards' die types and punch bodies are rated by
        (:func:`~tabletcad.pipeline.designreport.plan_diameter`, never below :attr:`length` and :attr:`width`,
        the same bounds; computed once)."""
        from tabletcad.pipeline.designreport import plan_diameter

        return plan_diameter(self.tablet)

    @property
    def plan_area(self) -> float:
        return face_area(plan_face(self.outline))

    @property
    def perimeter(self) -> float:
        return wire_length(self.outline)


# ----------------------------------------------------------------------------- wires
def _wire(edges) -> Any:
    mk = BRepBuilderAPI_MakeWire()
    for e in edges:
        mk.Add(e)
    if not mk.IsDone():
        raise GeometryError("outline edges do not form a wire", edges)
    return mk.Wire()


def circle_wire(radius: float, center=(0.0, 0.0)) -> Any:
    ax = gp_Ax2(gp_Pnt(float(center[0]), float(center[1]), 0.0), gp_Dir(0, 0, 1))
    return _wire([BRepBuilderAPI_MakeEdge(gp_Circ(ax, float(radius))).Edge()])


def ellipse_wire(rx: float, ry: float, center=(0.0, 0.0)) -> Any:
    if abs(rx - ry) <= 1e-12 * max(rx, ry):
        return circle_wire(rx, center)
    xdir = gp_Dir(1, 0, 0) if rx >= ry else gp_Dir(0, 1, 0)
    ax = gp_Ax2(gp_Pnt(float(center[0]), float(center[1]), 0.0), gp_Dir(0, 0, 1), xdir)
    return _wire([BRepBuilderAPI_MakeEdge(gp_Elips(ax, max(rx, ry), min(rx, ry))).Edge()])


def segments_wire(segs) -> Any:
    """Wire of lines and arcs (objects with ``kind, p0, p1, center, radius, theta0, sweep``)."""
    edges = []
    for s in segs:
        p0 = gp_Pnt(float(s.p0[0]), float(s.p0[1]), 0.0)
        p1 = gp_Pnt(float(s.p1[0]), float(s.p1[1]), 0.0)
        if s.kind == "line":
            edges.append(BRepBuilderAPI_MakeEdge(p0, p1).Edge())
        else:
            tm = s.theta0 + 0.5 * s.sweep
            pm = gp_Pnt(s.center[0] + s.radius * math.cos(tm), s.center[1] + s.radius * math.sin(tm), 0.0)
            edges.append(BRepBuilderAPI_MakeEdge(GC_MakeArcOfCircle(p0, pm, p1).Value()).Edge())
    return _wire(edges)


def polyline_wire(points) -> Any:
    """The closed polygon wire through the plan points (n, 2) at z = 0 (shared vertices; a point
    equal to the one before it is skipped)."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakePolygon

    mk = BRepBuilderAPI_MakePolygon()
    for x, y in points:
        mk.Add(gp_Pnt(float(x), float(y), 0.0))
    mk.Close()
    if not mk.IsDone():
        raise GeometryError("polyline points do not form a closed wire", points)
    return mk.Wire()


def plan_face(wire) -> Any:
    mk = BRepBuilderAPI_MakeFace(wire, True)
    if not mk.IsDone():
        raise GeometryError("outline wire is not a planar closed wire", wire)
    return mk.Face()


def plan_face_properties(face) -> GProp_GProps:
    """The plan face's area properties (area, centroid, inertia): OCC's Gauss integration, adaptive to 1e-10 on
    a face bounded by a spline outline's periodic B-spline (its fixed rule had given a tip 64.0303 mm² for
    64.0461, and the tip's least second moment 2.4 % high)."""
    from tabletcad.tooling.booleans import has_periodic_bspline_curve

    p = GProp_GProps()
    if has_periodic_bspline_curve(face):
        BRepGProp.SurfaceProperties_s(face, p, 1e-10)
    else:
        BRepGProp.SurfaceProperties_s(face, p)
    return p


def face_area(face) -> float:
    """The plan face's area (mm², :func:`plan_face_properties`)."""
    return abs(plan_face_properties(face).Mass())


def wire_length(wire) -> float:
    p = GProp_GProps()
    BRepGProp.LinearProperties_s(wire, p)
    return p.Mass()


#: wires smaller than this (mm, bounding-box diagonal) are offset at this size and scaled back: OCCT
#: 7.9's planar offset crashed the process (SIGSEGV) offsetting a 1 mm circle inward by 0.02 mm (a
#: 2 mm mini-tablet's punch tip), where a 10 mm circle by 0.2 mm works; the similarity is exact
OFFSET_MIN_SIZE_MM = 10.0


def _scaled(shape, factor: float):
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Transform
    from OCP.gp import gp_Pnt, gp_Trsf

    tr = gp_Trsf()
    tr.SetScale(gp_Pnt(0.0, 0.0, 0.0), float(factor))
    return BRepBuilderAPI_Transform(shape, tr, True).Shape()


def offset_wire(wire, distance: float) -> Any:
    """The planar closed ``wire`` offset by ``distance`` mm (> 0 outward, arcs at corners)."""
    if distance == 0.0:
        return wire
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib

    box = Bnd_Box()
    BRepBndLib.Add_s(wire, box)
    size = box.CornerMin().Distance(box.CornerMax())
    if size < OFFSET_MIN_SIZE_MM:  # offset a similar copy of the size OCCT handles, then scale it back
        k = OFFSET_MIN_SIZE_MM / max(size, 1e-9)
        return cast(_scaled(offset_wire(cast(_scaled(wire, k), "Wire"), k * distance), 1.0 / k), "Wire")
    face = plan_face(wire)
    mk = BRepOffsetAPI_MakeOffset(face, GeomAbs_JoinType.GeomAbs_Arc)
    mk.Perform(float(distance))
    if not mk.IsDone():
        raise GeometryError(f"offsetting the outline by {distance} mm failed", wire)
    wires = explore(mk.Shape(), "Wire")
    if len(wires) != 1:
        raise GeometryError(f"offsetting the outline by {distance} mm gave {len(wires)} wires", wire)
    out = wires[0]
    a0, a1 = face_area(face), face_area(plan_face(out))
    if (a1 - a0) * distance < 0:  # the library's sign convention differs: flip
        mk = BRepOffsetAPI_MakeOffset(face, GeomAbs_JoinType.GeomAbs_Arc)
        mk.Perform(-float(distance))
        out = explore(mk.Shape(), "Wire")[0]
    return bspline_offset_curves(out)


#: how far (mm) the B-spline that stands for an offset curve may leave it (:func:`bspline_offset_curves`)
OFFSET_CURVE_TOL_MM = 1e-9


def bspline_offset_curves(wire) -> Any:
    """``wire`` with each edge whose curve is a ``Geom_OffsetCurve`` made a C2 B-spline within
    :data:`OFFSET_CURVE_TOL_MM` of it (``GeomConvert_ApproxCurve``, the edge's own vertices); other
    edges are kept.

    OCC offsets an ellipse (or a B-spline) to a ``Geom_OffsetCurve``, and the p-curves it gives such an
    edge on a plane are B-spline approximations: 3e-7 mm from the curve on the thesis caplet's punch tip
    (a 3.5 x 1.75 mm ellipse inset 0.016 mm), 9e-7 mm at a 0.05 mm inset, past the edge's 1e-7 mm
    tolerance.  The prism on such a wire failed ``BRepCheck_Analyzer`` (an invalid curve on its end
    faces), and so did every Boolean made with it: the tips of the thesis's ovals and caplet.  A B-spline
    in a plane is its own p-curve there.

    Parameters
    ----------
    wire : TopoDS_Wire
        A closed planar wire, as :func:`offset_wire` gets it from OCC.

    Returns
    -------
    TopoDS_Wire
        The same wire when no edge is an offset curve, else a new one through the same vertices.
    """
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.BRepTools import BRepTools_WireExplorer
    from OCP.GeomAbs import GeomAbs_CurveType

    edges, changed = [], False
    explorer = BRepTools_WireExplorer(cast(wire, "Wire"))
    while explorer.More():
        edge = explorer.Current()
        if BRepAdaptor_Curve(edge).GetType() == GeomAbs_CurveType.GeomAbs_OffsetCurve:
            edge, changed = _bspline_edge(edge), True
        edges.append(edge)
        explorer.Next()
    return _wire(edges) if changed else wire


def _bspline_edge(edge) -> Any:
    """The edge on the B-spline within :data:`OFFSET_CURVE_TOL_MM` of ``edge``'s curve between its own
    vertices, oriented as ``edge``."""
    from OCP.BRep import BRep_Tool
    from OCP.Geom import Geom_TrimmedCurve
    from OCP.GeomAbs import GeomAbs_Shape
    from OCP.GeomConvert import GeomConvert_ApproxCurve
    from OCP.TopAbs import TopAbs_Orientation
    from OCP.TopExp import TopExp
    from OCP.TopoDS import TopoDS_Vertex

    forward = cast(edge.Oriented(TopAbs_Orientation.TopAbs_FORWARD), "Edge")
    first, last = BRep_Tool.Range_s(forward)
    curve = BRep_Tool.Curve_s(forward, first, last)
    if not forward.Location().IsIdentity():
        curve = curve.Transformed(forward.Location().Transformation())
    approx = GeomConvert_ApproxCurve(Geom_TrimmedCurve(curve, first, last), OFFSET_CURVE_TOL_MM,
                                     GeomAbs_Shape.GeomAbs_C2, 1000, 14)
    if not approx.HasResult() or approx.MaxError() > OFFSET_CURVE_TOL_MM:
        raise GeometryError(f"an offset outline edge did not become a B-spline within {OFFSET_CURVE_TOL_MM} mm "
                            f"(error {approx.MaxError() if approx.HasResult() else None} mm)", edge)
    v0, v1 = TopoDS_Vertex(), TopoDS_Vertex()
    TopExp.Vertices_s(forward, v0, v1)
    mk = BRepBuilderAPI_MakeEdge(approx.Curve(), v0, v1)
    if not mk.IsDone():
        raise GeometryError("an offset outline edge's B-spline does not join its vertices", edge)
    return cast(mk.Edge().Oriented(edge.Orientation()), "Edge")


#: how far (mm) the B-spline standing for a spline outline's exact offset may leave it (:func:`spline_offset_wire`)
SPLINE_OFFSET_TOL_MM = 1e-6

#: the points per span at which :func:`spline_offset_wire` measures its B-spline against the exact offset
SPLINE_OFFSET_SAMPLES = 16


def spline_offset_wire(outline: Any, distance: float, tol: float = SPLINE_OFFSET_TOL_MM) -> tuple[Any, float]:
    """The spline ``outline`` offset by ``distance`` mm (> 0 outward, < 0 inward) as one closed B-spline edge,
    and its deviation (mm) from the exact offset.

    The exact offset is ``O(v) - distance N(v)`` (``N`` the inward unit normal,
    :meth:`~tabletcad.families.outline.SplineOutline.offset`).  Its B-spline is the cubic Hermite
    interpolant of it in ``v``: on each span the exact point and derivative at both ends, one knot of
    multiplicity 2 at each span's end (C1 there, as the offset of a cubic spline is at its knots).  The
    spans are the spline's own (on which a zero offset is the spline itself), halved where the B-spline
    leaves the exact offset by more than ``tol`` at :data:`SPLINE_OFFSET_SAMPLES` points per span; the
    deviation returned is the largest distance so measured between points of the same ``v``.

    Raises
    ------
    DesignError
        An offset beyond the outline's regular offsets
        (:meth:`~tabletcad.families.outline.SplineOutline.offset_bound`).
    GeometryError
        No B-spline within ``tol`` of the offset (after 15 halvings).
    """
    err = spline_offset_error(outline, distance)
    if err is not None:
        raise err
    knots, poles, deviation = _hermite_offset(outline, float(distance), tol)
    return _wire([_periodic_bspline_edge(knots, poles)]), deviation


def spline_offset_deviation(frame: TabletFrame, distance: float, name: str) -> dict:
    """The report's entries for the B-spline of a spline outline's offset by ``distance`` mm
    (:meth:`TabletFrame.offset`): ``<name>_deviation_mm``, its largest distance from the exact offset as
    measured, ``<name>_tolerance_mm`` (:data:`SPLINE_OFFSET_TOL_MM`) and how it was measured."""
    return {f"{name}_deviation_mm": frame.offset_deviation(distance), f"{name}_tolerance_mm": SPLINE_OFFSET_TOL_MM,
            f"{name}_deviation_method": "the outline's exact offset O + d N (tabletcad.families.outline.SplineOutline) "
                                        "as a C1 cubic Hermite B-spline in its parameter, spans halved until within "
                                        f"the tolerance at {SPLINE_OFFSET_SAMPLES} points a span"}


def _hermite_offset(outline: Any, distance: float, tol: float) -> tuple[np.ndarray, np.ndarray, float]:
    """Knots (n + 1, from 0 to 2 pi), poles (2 n, 2: each span's two inner Bezier poles) and measured
    deviation (mm) of the C1 cubic B-spline within ``tol`` of the exact offset (:func:`spline_offset_wire`)."""
    breaks = np.asarray(outline.smooth_breaks, dtype=float)
    ends = np.append(breaks, math.tau)
    split = np.ones(len(breaks), dtype=int)
    f = (np.arange(SPLINE_OFFSET_SAMPLES) + 0.5) / SPLINE_OFFSET_SAMPLES
    for _ in range(16):
        v = np.concatenate([np.linspace(a, b, m, endpoint=False) for a, b, m in zip(ends[:-1], ends[1:], split)] +
                           [[math.tau]])
        p, dp = outline.offset(v, 0, 1.0, -distance), outline.offset(v, 1, 1.0, -distance)
        h = np.diff(v)[:, None]
        inner = np.stack([p[:-1] + h / 3.0 * dp[:-1], p[1:] - h / 3.0 * dp[1:]], axis=1)  # (spans, 2, 2)
        u = f[None, :, None]
        bez = ((1 - u) ** 3 * p[:-1, None] + 3 * u * (1 - u) ** 2 * inner[:, :1] + 3 * u * u * (1 - u) * inner[:, 1:]
               + u ** 3 * p[1:, None])
        exact = outline.offset((v[:-1, None] + f[None, :] * h).reshape(-1), 0, 1.0, -distance)
        gap = np.linalg.norm(bez.reshape(-1, 2) - exact, axis=1).reshape(len(h), -1).max(axis=1)
        owner = np.repeat(np.arange(len(split)), split)
        worst = np.zeros(len(split))
        np.maximum.at(worst, owner, gap)
        if np.all(worst <= tol):
            return v, inner.reshape(-1, 2), float(gap.max())
        split = np.where(worst > tol, 2 * split, split)
    raise GeometryError(f"the spline outline's offset by {distance} mm did not become a B-spline within {tol} mm "
                        f"(deviation {float(worst.max()):.3g} mm)", None)


def _periodic_bspline_edge(knots: np.ndarray, poles: np.ndarray) -> Any:
    """The closed edge at ``z = 0`` on the periodic cubic B-spline of ``knots`` (each of multiplicity 2,
    the last the first's period) and plan ``poles`` (two a span)."""
    from OCP.Geom import Geom_BSplineCurve
    from OCP.TColgp import TColgp_Array1OfPnt
    from OCP.TColStd import TColStd_Array1OfInteger, TColStd_Array1OfReal

    n = len(knots)
    kn, mu = TColStd_Array1OfReal(1, n), TColStd_Array1OfInteger(1, n)
    for i, k in enumerate(knots, start=1):
        kn.SetValue(i, float(k))
        mu.SetValue(i, 2)
    pts = TColgp_Array1OfPnt(1, len(poles))
    # a periodic curve's span from its first knot starts at its last pole pair's second pole
    for i, (x, y) in enumerate(np.roll(poles, 1, axis=0), start=1):
        pts.SetValue(i, gp_Pnt(float(x), float(y), 0.0))
    mk = BRepBuilderAPI_MakeEdge(Geom_BSplineCurve(pts, kn, mu, 3, True))
    if not mk.IsDone():
        raise GeometryError("the spline outline's B-spline gave no edge", None)
    return mk.Edge()


def prism(wire, z0: float, z1: float) -> TopoDS_Shape:
    """Solid extrusion of the plan ``wire`` (at z = 0) from ``z0`` to ``z1``."""
    face = plan_face(wire)
    solid = BRepPrimAPI_MakePrism(face, gp_Vec(0.0, 0.0, float(z1 - z0))).Shape()
    return translated(solid, dz=z0)


# ----------------------------------------------------------------------------- band
def _section_wire(shape, z: float) -> Any:
    sec = BRepAlgoAPI_Section(shape, gp_Pln(gp_Pnt(0, 0, z), gp_Dir(0, 0, 1)))
    sec.Build()
    edges = explore(sec.Shape(), "Edge")
    if not edges:
        raise GeometryError(f"no section of the tablet at z = {z}", shape)
    from OCP.TopTools import TopTools_HSequenceOfShape

    seq = TopTools_HSequenceOfShape()
    for e in edges:
        seq.Append(e)
    wires = TopTools_HSequenceOfShape()
    ShapeAnalysis_FreeBounds.ConnectEdgesToWires_s(seq, 1e-6, False, wires)  # (OCP: the wires are an out-argument)
    if wires.Length() != 1:
        raise GeometryError(f"the band section gives {wires.Length()} wires, expected one", shape)
    return cast(translated(wires.Value(1), dz=-z), "Wire")


def _rational_bspline_solid(shape: TopoDS_Shape) -> TopoDS_Shape:
    """``shape`` with every face of revolution converted to the rational B-spline surface that is
    the same surface (``BRepBuilderAPI_NurbsConvert``: the profile's poles swept by the rational
    quadratic circle, exact), p-curves recomputed; one valid solid or :class:`GeometryError`.

    Few spans around (a 10 mm concave round's cup: 6 x 17 poles against 17 x 32 for a B-spline fit
    of the same PDE surface), so OCC's surface intersections with letters and scores cost about
    half as much."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_NurbsConvert
    from OCP.BRepCheck import BRepCheck_Analyzer

    from tabletcad.cad.planes import flat_faces_as_planes

    solids = explore(BRepBuilderAPI_NurbsConvert(shape, True).Shape(), "Solid")
    if len(solids) != 1 or not BRepCheck_Analyzer(solids[0]).IsValid():
        raise GeometryError(f"the tablet's faces of revolution did not convert to one valid B-spline solid "
                            f"({len(solids)} solids)", shape)
    # the conversion turns the flat faces' planes into B-splines too: planes again (a punch tip's flat face
    # as a trimmed B-spline plane had carried a 10 N side load in tabletcad.fe.punch's mesh)
    return flat_faces_as_planes(solids[0])[0]


def _has_faces_of_revolution(shape: TopoDS_Shape) -> bool:
    from OCP.BRep import BRep_Tool
    from OCP.Geom import Geom_SurfaceOfRevolution

    return any(isinstance(BRep_Tool.Surface_s(cast(f, "Face")), Geom_SurfaceOfRevolution) for f in explore(shape, "Face"))


def tablet_frame(tablet: Tablet, shape: TopoDS_Shape | None = None) -> TabletFrame:
    """Band, outline and heights of ``tablet`` (its solid is built unless ``shape`` is given; a
    solid with faces of revolution gets them as the rational B-spline surfaces they are).

    Raises :class:`DesignError` for tablets a pair of punches in a die cannot
    make: no band (spheres, spheroids), hollow (ring) or cut-away tablets.
    """
    t = tablet.trim
    if t.w[0] > 0.0:
        raise DesignError("[tooling]", tablet.family, "tooling is made for solid tablets, not hollow ones (a ring needs a core rod)")
    if t.u != (0.0, 1.0) or not t.full_v:
        raise DesignError("[tooling]", tablet.family, "tooling is made for whole tablets: remove [trim] u/v")
    nom = tablet.nominal
    outline_nom = getattr(nom, "outline", None)
    band_z = band_heights(tablet)  # (a DesignError without a band)
    found = tablet.band()
    if shape is None:
        from tabletcad.cad.tablet_solid import tablet_solid

        shape = tablet_solid(tablet).shape
    revolved = None
    if _has_faces_of_revolution(shape):
        # the tooling cuts scores and letters into the tablet: it works on B-spline faces, since a
        # Boolean-trimmed face of revolution written to STEP read back invalid (BRepCheck_Analyzer,
        # OCCT 7.9: the concave round bisect sample's score)
        revolved, shape = shape, _rational_bspline_solid(shape)
    lo, hi = tablet.bounds()
    info = dict(getattr(nom, "info", {}) or {})
    round_radius, spline = None, None
    if isinstance(outline_nom, SplineOutline):  # its exact outline, as a B-spline; offsets from its exact offsets
        spline, wire, kind = outline_nom, spline_offset_wire(outline_nom, 0.0)[0], "spline"
    elif outline_nom is not None and getattr(outline_nom, "segs", None):  # (a spline outline has none)
        segs = outline_nom.segs
        if len(segs) == 1 or all(s.kind == "arc" and abs(s.radius - segs[0].radius) < 1e-12 and
                                  np.allclose(s.center, segs[0].center) for s in segs):
            round_radius = float(segs[0].radius)
            wire, kind = circle_wire(round_radius, segs[0].center), "circle"
        else:
            wire, kind = segments_wire(segs), "lines and arcs"
    else:
        curve = tablet.patches[found.patch].data[0] if found is not None else None
        from tabletcad.geometry.curves import Circle, Ellipse, Outline, Transformed

        shift = np.zeros(2)
        while isinstance(curve, Transformed) and np.array_equal(curve.matrix[:2, :2], np.eye(2)) \
                and not np.any(curve.matrix[:2, 2]):  # moved along the axis (a free-form chain's z): the same plan
            shift, curve = shift + curve.offset[:2], curve.base
        if isinstance(curve, Circle):
            round_radius = float(curve.radius)
            wire, kind = circle_wire(curve.radius, curve.center[:2] + shift), "circle"
        elif isinstance(curve, Ellipse):
            wire, kind = ellipse_wire(curve.rx, curve.ry, curve.center[:2] + shift), "ellipse"
        elif isinstance(curve, Outline):  # a free-form band of lines and arcs (a stadium): exact
            wire, kind = segments_wire(curve.segs), "lines and arcs"
            if np.any(shift):
                wire = cast(translated(wire, float(shift[0]), float(shift[1]), 0.0), "Wire")
        else:
            wire, kind = _section_wire(shape, 0.5 * (band_z[0] + band_z[1])), "section of the band"
            try:  # the tips and the bore are offsets of it: refused here, named, when OCC cannot offset it
                offset_wire(wire, -0.01)
            except GeometryError:
                raise DesignError("tablet.family", tablet.family, SECTION_OFFSET_REFUSAL) from None
    land = info.get("land_mm")
    if land is None and tablet.family in NO_LAND:  # the thesis's shapes say so in the catalogue
        land = 0.0
    # the die bore clears the whole plan, not only the band: a PDE dome may overhang its band
    bulge = tablet.plan_overhang() if found is not None else 0.0
    return TabletFrame(tablet, shape, (float(band_z[0]), float(band_z[1])), bulge, float(lo[2]), float(hi[2]), wire, kind,
                       round_radius, None if land is None else float(land), float(hi[0] - lo[0]), float(hi[1] - lo[1]), info,
                       revolved, spline)
