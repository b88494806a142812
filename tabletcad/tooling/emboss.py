"""Embossed (raised) and debossed (cut) text or logo outlines on a tablet face.

The figure is a set of plan faces at ``z = 0`` — text from a DejaVu font (or
any TTF) by build123d's ``Text`` (OCC ``Font_BRepTextBuilder``), a closed
polyline, or a logo's filled outlines from an SVG file (build123d's
``import_svg``, centred and scaled to ``height_mm`` tall) —
rotated, moved to ``position_mm`` and, on the bottom face, mirrored so that
it reads correctly when the tablet is turned over.  It is extruded along the
axis into a prism (with ``draft_deg`` on its walls when asked: a ruled loft of
each outline's in-plane offsets, narrower towards the letter floor) and cut to
the layer of the face the engraving occupies:

* ``projection = "normal"`` (default): the layer between the face and its
  normal offset by ``depth`` (OCC's simple offset,
  ``BRepOffsetAPI_MakeOffsetShape.PerformBySimple``: every face of the plain
  tablet replaced by its ``Geom_OffsetSurface``), so a deboss floor lies at
  normal distance ``depth`` below the cup and an emboss stands ``depth`` proud
  along the normal everywhere — on a spherical cup of radius ``R`` the floor
  is the concentric sphere ``R - depth``:

  - deboss: cutter = prism − (plain tablet offset inwards by ``depth``);
  - emboss: adder = prism ∩ (plain tablet offset outwards by ``depth``);

* ``projection = "axial"``: a constant axial depth, the tablet moved by
  ``depth`` along the axis instead of offset (on a face sloping at ``θ`` the
  layer is ``depth·cos θ`` thick along the normal).

The offset is of the plain tablet (before scores and earlier figures), so a
figure crossing a score groove keeps the cup's layer; OCC leaves an invalid
face on some offsets (the almond's tip), which ``ShapeFix_Shape`` repairs.
Then tablet − cutter or tablet ∪ adder.  The plan figure is placed on the
face by projection along the axis (a vertical line through each point of the
figure meets the face once, the cups being graphs over the plan).  The stroke
walls keep their stroke angle to the axis; where the face is tilted by ``θ``
to the axis, a wall's angle to the local normal lies within ``stroke angle ±
θ``: the largest ``θ`` over the figure's footprint is reported
(``max_normal_tilt_deg``), with the deepest axial reach of the normal layer
(``depth / cos θ``).

Figures must lie inside the punch tip (outline inset by the clearance, the
tablet's land and ``margin_mm``), else :class:`DesignError`.

:func:`legibility` states the figures the trade checks against picking and
sticking, as numbers (no pass/fail threshold is bundled, none being citable):
the mean stroke width ``2A/P`` (area over half the perimeter, exact for long
strokes of constant width), its ratio to the tablet's size, depth against cup
depth and against stroke width, the land left between the figure and the tip
edge, the smallest radius of the figure's curved edges and its sharp corners.
A stroke angle that closes a stroke before its full depth
(``depth · tan(angle) >= stroke width / 2``) is a :class:`DesignError`.
"""

from __future__ import annotations

import math
from typing import Any

from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut
from OCP.BRepBuilderAPI import BRepBuilderAPI_Transform
from OCP.gp import gp_Ax1, gp_Ax2, gp_Dir, gp_Pnt, gp_Trsf, gp_Vec
from OCP.TopoDS import TopoDS_Shape

from tabletcad.cad._occ import explore
from tabletcad.errors import DesignError, GeometryError
from tabletcad.tooling.booleans import checked_boolean, translated
from tabletcad.tooling.booleans import compound as _compound
from tabletcad.tooling.outline import TabletFrame, face_area, plan_face, polyline_wire, wire_length
from tabletcad.tooling.spec import EmbossSpec, check_emboss_depth, font_path

__all__ = ["figure_faces", "figure_prism", "apply_emboss", "check_fit", "check_emboss", "face_heights", "offset_solid",
           "tool_check"]


def _transform(shape: TopoDS_Shape, trsf: gp_Trsf) -> TopoDS_Shape:
    return BRepBuilderAPI_Transform(shape, trsf, True).Shape()


def figure_faces(e: EmbossSpec, i: int = 0) -> TopoDS_Shape:
    """Plan faces (a compound at ``z = 0``) of the text or outline, placed and, for the bottom, mirrored
    (``i``: the figure's index in ``[[tooling.emboss]]``, for errors)."""
    w = f"[[tooling.emboss]] {i}"
    if e.text is not None:
        shape = text_faces(e.text, e.height_mm, font_path(e.font, f"{w} font"), f"{w} font")
    elif e.svg is not None:
        shape = svg_faces(e.svg, e.height_mm, f"{w} svg")
    else:
        shape = plan_face(polyline_wire(e.outline))
    trsf = gp_Trsf()
    trsf.SetRotation(gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), math.radians(e.rotation_deg))
    shape = _transform(shape, trsf)
    shape = translated(shape, e.position_mm[0], e.position_mm[1], 0.0)
    if e.face == "bottom":
        m = gp_Trsf()
        m.SetMirror(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(1, 0, 0)))  # x -> -x: reads correctly from below
        shape = _transform(shape, m)
    if not explore(shape, "Face"):
        raise DesignError(f"{w} text", e.text, "gives no glyphs in this font")
    return shape


def text_faces(text: str, size: float, path, where: str = "[[tooling.emboss]] font") -> TopoDS_Shape:
    """The glyph faces of ``text`` in the font file ``path`` at ``size`` mm, centred on the origin both ways.

    OCC's ``StdPrs_BRepTextBuilder`` with the font loaded from the file, as build123d's ``Text`` does
    (``Graphic3d_HTA_CENTER``/``VTA_CENTER`` at the origin; its faces gathered in one compound) without
    importing build123d (2 s): the same vertices and areas for the DejaVu fonts."""
    from OCP.gp import gp_Ax3
    from OCP.Graphic3d import Graphic3d_HTA_CENTER, Graphic3d_VTA_CENTER
    from OCP.NCollection import NCollection_Utf8String
    from OCP.StdPrs import StdPrs_BRepFont, StdPrs_BRepTextBuilder

    font = StdPrs_BRepFont()
    if not font.Init(NCollection_Utf8String(str(path)), float(size), 0):
        raise DesignError(where, str(path), "must be a TrueType/OpenType font file OCC can read")
    shape = StdPrs_BRepTextBuilder().Perform(font, NCollection_Utf8String(text), gp_Ax3(), Graphic3d_HTA_CENTER,
                                             Graphic3d_VTA_CENTER)
    return _compound(explore(shape, "Face"))


def svg_faces(path: str, height: float, where: str = "[[tooling.emboss]] svg") -> TopoDS_Shape:
    """The filled outlines of an SVG logo as plan faces, centred on the origin and ``height`` mm tall."""
    import build123d as bd
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib

    try:
        faces = [s for s in bd.import_svg(path, align=None) if isinstance(s, bd.Face)]
    except (ValueError, TypeError, KeyError, IndexError, AttributeError, SyntaxError) as exc:  # the file's content
        why = " ".join(str(exc).split())[:200]  # the library's text, on one line
        raise DesignError(where, path, f"must be an SVG file whose paths can be read ({type(exc).__name__}: {why})") from None
    if not faces:
        raise DesignError(where, path, "has no filled outline (closed, filled path) to emboss")
    comp = bd.Compound(faces).wrapped
    box = Bnd_Box()
    BRepBndLib.Add_s(comp, box)
    lo, hi = box.CornerMin(), box.CornerMax()
    tr = gp_Trsf()
    tr.SetTranslation(gp_Vec(-0.5 * (lo.X() + hi.X()), -0.5 * (lo.Y() + hi.Y()), 0.0))
    sc = gp_Trsf()
    sc.SetScale(gp_Pnt(0, 0, 0), height / max(hi.Y() - lo.Y(), 1e-12))
    return _transform(comp, sc.Multiplied(tr))


def legibility(frame: TabletFrame, e: EmbossSpec, figure: TopoDS_Shape, clearance: float) -> dict:
    """The figure's picking/legibility numbers (mm); see the module docstring."""
    from OCP.BRepExtrema import BRepExtrema_DistShapeShape
    from OCP.BRepLProp import BRepLProp_CLProps
    from OCP.BRepAdaptor import BRepAdaptor_Curve

    faces = explore(figure, "Face")
    area = sum(face_area(f) for f in faces)
    edges = explore(figure, "Edge")
    perimeter = 0.0
    r_min, sharp = math.inf, 0
    for ed in edges:
        c = BRepAdaptor_Curve(ed)
        a, b = c.FirstParameter(), c.LastParameter()
        from OCP.GCPnts import GCPnts_AbscissaPoint

        perimeter += GCPnts_AbscissaPoint.Length_s(c, 1e-12)  # (its default tolerance left ~2e-7 relative)
        props = BRepLProp_CLProps(c, 2, 1e-9)
        for k in range(9):
            props.SetParameter(a + (b - a) * k / 8.0)
            if props.IsTangentDefined():
                kappa = props.Curvature()
                if kappa > 1e-9:
                    r_min = min(r_min, 1.0 / kappa)
    for w in explore(figure, "Wire"):  # corners: tangent jumps between consecutive edges
        from OCP.BRepTools import BRepTools_WireExplorer
        from OCP.TopoDS import TopoDS

        ex, tans = BRepTools_WireExplorer(TopoDS.Wire_s(w)), []
        while ex.More():
            c = BRepAdaptor_Curve(ex.Current())
            p, v0, v1 = gp_Pnt(), gp_Vec(), gp_Vec()
            c.D1(c.FirstParameter(), p, v0)
            c.D1(c.LastParameter(), p, v1)
            rev = ex.Current().Orientation().name == "TopAbs_REVERSED"
            tans.append((v1.Reversed(), v0.Reversed()) if rev else (v0, v1))
            ex.Next()
        for k in range(len(tans)):
            t_end, t_start = tans[k][1], tans[(k + 1) % len(tans)][0]
            if t_end.Magnitude() > 1e-12 and t_start.Magnitude() > 1e-12 and t_end.Angle(t_start) > math.radians(5.0):
                sharp += 1
    tip_edge = frame.offset(-frame.tip_inset(clearance))
    dss = BRepExtrema_DistShapeShape(figure, tip_edge)
    land = float(dss.Value()) if dss.IsDone() else None
    width = 2.0 * area / perimeter if perimeter > 0 else 0.0
    cup = frame.cup_depth_top if e.face == "top" else frame.cup_depth_bottom
    size = max(frame.length, frame.width)
    return dict(stroke_width_mm=width, stroke_width_over_tablet_size=width / size, depth_mm=e.depth_mm,
                depth_over_cup_depth=e.depth_mm / cup if cup > 0 else None,
                depth_over_stroke_width=e.depth_mm / width if width > 0 else None,
                land_to_tip_edge_mm=land, min_edge_radius_mm=None if math.isinf(r_min) else r_min,
                sharp_corners=sharp, stroke_angle_deg=e.draft_deg,
                stroke_closes_at_depth_mm=(0.5 * width / math.tan(math.radians(e.draft_deg))) if e.draft_deg > 0 else None,
                method="stroke width = 2 x area / perimeter of the plan figure; land = exact distance figure to tip edge "
                       "(outline inset by the clearance); radii sampled at 9 points per edge; corners: tangent jump > 5 deg")


def _inset(frame: TabletFrame, clearance: float, e: EmbossSpec) -> float:
    return clearance + frame.edge_land(e.face) + e.margin_mm


def check_fit(frame: TabletFrame, e: EmbossSpec, figure: TopoDS_Shape, clearance: float, i: int = 0) -> dict:
    """Raise :class:`DesignError` unless the figure lies inside the punch tip inset by land and margin."""
    inset = _inset(frame, clearance, e)
    what = "text" if e.text is not None else "svg" if e.svg is not None else "outline"
    value = e.text if e.text is not None else e.svg if e.svg is not None else f"{len(e.outline)} points"
    try:
        region = plan_face(frame.offset(-inset))
    except GeometryError:  # (no wire, or more than one: empty, or parted at a neck; said as the core says it)
        from tabletcad.tooling.spec import inset_face_refusal, tooling_plan_outline

        raise inset_face_refusal(e, i, tooling_plan_outline(frame.tablet), inset,
                                 0.5 * min(frame.length, frame.width)) from None
    cut = BRepAlgoAPI_Cut(figure, region)
    outside = sum(face_area(f) for f in explore(cut.Shape(), "Face"))
    area = sum(face_area(f) for f in explore(figure, "Face"))
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib

    box = Bnd_Box()  # the exact box (the poles' box that BRepBndLib.Add gives had grown with the figure's turn)
    BRepBndLib.AddOptimal_s(figure, box, False, False)
    lo, hi = box.CornerMin(), box.CornerMax()
    size = (hi.X() - lo.X(), hi.Y() - lo.Y())
    if outside > 1e-6 * max(area, 1e-9):
        raise DesignError(f"[[tooling.emboss]] {i} {what}", value,
                          f"does not fit the {e.face} face: {size[0]:.3g} x {size[1]:.3g} mm with {outside:.3g} mm^2 "
                          f"outside the punch tip inset by {inset:.3g} mm (clearance + land + margin); "
                          "use a smaller height_mm or move it")
    return dict(figure_area_mm2=area, size_mm=list(size), inset_mm=inset)


def check_emboss(frame: TabletFrame, e: EmbossSpec, clearance: float, i: int = 0):
    """The placed figure and its fit facts; :class:`DesignError` if it does not fit or is too deep."""
    figure = figure_faces(e, i)
    info = check_fit(frame, e, figure, clearance, i)
    info["legibility"] = leg = legibility(frame, e, figure, clearance)
    if e.draft_deg > 0 and e.depth_mm * math.tan(math.radians(e.draft_deg)) >= 0.5 * leg["stroke_width_mm"]:
        raise DesignError(f"[[tooling.emboss]] {i} stroke_angle_deg", e.draft_deg,
                          f"must be < {math.degrees(math.atan(0.5 * leg['stroke_width_mm'] / e.depth_mm)):.3g} deg: the "
                          f"walls of {leg['stroke_width_mm']:.3g} mm strokes would meet before the depth "
                          f"{e.depth_mm:.3g} mm", "deg")
    check_emboss_depth(e, i, frame.cup_depth_top if e.face == "top" else frame.cup_depth_bottom, frame.band)
    return figure, info


def figure_prism(figure: TopoDS_Shape, z0: float, z1: float, draft_deg: float = 0.0,
                 z_nominal: float | None = None) -> TopoDS_Shape:
    """Prism of the plan figure from ``z0`` to ``z1``; with ``draft_deg`` (the stroke angle) the walls
    lean so that the figure is nominal at ``z_nominal`` (default ``z0``), narrower towards ``z1`` and
    wider towards ``z0``."""
    faces = explore(figure, "Face")
    if draft_deg <= 0.0:
        from OCP.BRepPrimAPI import BRepPrimAPI_MakePrism

        solids = [translated(BRepPrimAPI_MakePrism(f, gp_Vec(0.0, 0.0, z1 - z0)).Shape(), dz=z0) for f in faces]
    else:
        zn = z0 if z_nominal is None else z_nominal
        solids = [_drafted(f, zn, abs(z1 - zn), abs(zn - z0), draft_deg, up=z1 > z0) for f in faces]
    return solids[0] if len(solids) == 1 else _compound(solids)


def _mirror_z(shape):
    m = gp_Trsf()
    m.SetMirror(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)))
    return _transform(shape, m)


def _drafted(face, z_n: float, narrow: float, wide: float, draft_deg: float, up: bool):
    """Drafted prism of a plan face (holes included): nominal at ``z_n``, narrowing over ``narrow`` mm
    along the axis (upwards if ``up``) and widening over ``wide`` mm the other way, walls at
    ``draft_deg`` to the axis.

    Each wire of the face is lofted (``BRepOffsetAPI_ThruSections``, ruled) between its in-plane
    offsets (``BRepOffsetAPI_MakeOffset``) at the two ends — the outer wire shrinking towards the
    narrow end, the holes growing there — and the holes' lofts are cut from the outer one.  A
    straight edge's offsets bound a plane and a circle's a cone, so lines and arcs are drafted
    exactly (a disc gives the frustum, a polygon the pyramid frustum: the offsets keep sharp corners,
    ``GeomAbs_Intersection``, or round the convex ones, ``GeomAbs_Arc``, where OCC cannot intersect
    them); a glyph's Bézier edges get the ruled surface between their offset curves.  Where a wire's
    offset ceases to exist before an end (a hole closes, a stroke vanishes or splits) the wall turns
    axial at the last height it exists (found by bisection) and runs straight to the end.
    ``LocOpe_DPrism`` segfaulted on the glyphs "6", "8", "9" (DejaVu Sans Bold)."""
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut
    from OCP.BRepTools import BRepTools
    from OCP.TopTools import TopTools_ListOfShape

    t = math.tan(math.radians(draft_deg))
    outer = BRepTools.OuterWire_s(face)
    holes = [w for w in explore(face, "Wire") if not w.IsSame(outer)]
    for smooth in (True, False):  # smooth paired walls; polygons where the holes' cut fails with them
        solid = _ruled_draft(outer, narrow, wide, t, grow=1.0, smooth=smooth)
        if not holes:
            break
        args, tools = TopTools_ListOfShape(), TopTools_ListOfShape()
        args.Append(solid)
        for w in holes:
            tools.Append(_ruled_draft(w, narrow, wide, t, grow=-1.0, smooth=smooth))
        cut = BRepAlgoAPI_Cut()
        cut.SetArguments(args)
        cut.SetTools(tools)
        cut.Build()
        solids = explore(cut.Shape(), "Solid") if cut.IsDone() else []
        if len(solids) == 1:
            solid = solids[0]
            break
    else:
        raise GeometryError(f"drafted prism of a glyph with holes gave {len(solids)} solids", face)
    if not up:
        solid = _mirror_z(solid)
    return translated(solid, dz=z_n)


def _offset_section(wire, d: float):
    """The planar ``wire`` offset in its plane by ``d`` mm (> 0: its area grows), sharp corners if OCC
    can intersect the offset edges, else arcs; ``None`` if it does not exist as one wire."""
    from OCP.BRepOffsetAPI import BRepOffsetAPI_MakeOffset
    from OCP.GeomAbs import GeomAbs_JoinType

    if d == 0.0:
        return wire
    face = plan_face(wire)
    a0 = face_area(face)
    # OCC's sign depends on the face's orientation, the same for both joins: keep the one that grows by
    # d, trying the sign that grows a plan face first (it always did: the other sign's Intersection
    # offset, tried before the Arc one, cost a failed offset where OCC cannot intersect the edges)
    for s in (1.0, -1.0):
        for join in (GeomAbs_JoinType.GeomAbs_Intersection, GeomAbs_JoinType.GeomAbs_Arc):
            try:
                mk = BRepOffsetAPI_MakeOffset(face, join)
                mk.Perform(s * d)
                wires = explore(mk.Shape(), "Wire") if mk.IsDone() else []
            except Exception:  # OCC raises StdFail_NotDone & co. where the offset breaks up
                wires = []
            try:
                grown = len(wires) == 1 and (face_area(plan_face(wires[0])) - a0) * d > 0.0
            except GeometryError:  # an offset that is not one closed planar wire (OCC's offset of an SVG
                grown = False      # circle drawn as one arc and a closing sliver of a line: an open wire)
            if grown:
                return wires[0]
    return None


def _section_to(wire, d: float, steps: int = 8):
    """``(offset wire, fraction of d reached)``: the full offset by ``d`` if it exists, else the
    furthest found by bisection (``None`` and 0 if none)."""
    w = _offset_section(wire, d)
    if w is not None:
        return w, 1.0
    lo, best = 0.0, (wire, 0.0)
    hi = 1.0
    for _ in range(steps):
        mid = 0.5 * (lo + hi)
        w = _offset_section(wire, mid * d)
        if w is None:
            hi = mid
        else:
            lo, best = mid, (w, mid)
    return best


def _ruled_draft(wire, narrow: float, wide: float, t: float, grow: float, smooth: bool = True):
    """Ruled solid through ``wire``'s offsets: at ``z = narrow`` offset by ``-grow*narrow*t``, at
    ``z = -wide`` by ``+grow*wide*t`` (nominal at 0), axial beyond where an offset ceases to exist.
    Where the two ends have different numbers of edges (OCC's offsets split Bézier edges
    differently at the two ends) or OCC cannot loft them as they are they are replaced by wires through
    paired points (:func:`_paired`, held in order where a feature vanishes): with ``smooth``, points
    0.01 mm apart fitted by a few cubic B-spline edges (:func:`_smooth_pair`), else (or where those
    do not loft) polygons through points 0.08 mm apart; where that fails too the drafted part is
    shortened (to 1/2, 1/4, 0 at one end or both) until it lofts.  (OCC's Booleans of the tablet with
    the smooth walls took a third of the time of the polygons' bilinear faces: "A8 69" at 15 deg on
    a concave round, 395 wall faces -> 140.)"""
    d_hi, d_lo = -grow * narrow * t, grow * wide * t
    w_hi, f_hi = _section_to(wire, d_hi)
    w_lo, f_lo = _section_to(wire, d_lo)
    for s_lo, s_hi in ((1.0, 1.0), (0.5, 1.0), (1.0, 0.5), (0.5, 0.5), (0.25, 0.25), (0.0, 0.0)):
        lo = w_lo if s_lo == 1.0 else _offset_section(wire, s_lo * f_lo * d_lo)
        hi = w_hi if s_hi == 1.0 else _offset_section(wire, s_hi * f_hi * d_hi)
        if lo is None or hi is None:
            continue
        sections = [(lo, -wide), (lo, -s_lo * f_lo * wide), (hi, s_hi * f_hi * narrow), (hi, narrow)]
        # OCC pairs sections of unequal edge counts by arc length, twisting the walls (the glyph "R"
        # at 15 deg lost 4 % of its volume) and slowly (seconds): paired polygons then
        solid = _loft(sections) if len(explore(lo, "Edge")) == len(explore(hi, "Edge")) else None
        longer = wire_length(lo) >= wire_length(hi)
        for smooth_walls, spacing in ((True, SMOOTH_SPACING), (False, 0.08))[0 if smooth else 1:]:
            if solid is not None:
                break
            pair = _paired(*((lo, hi) if longer else (hi, lo)), spacing, smooth_walls)
            if pair is not None:  # (None: an offset too small to hold a polygon; a shorter draft next)
                a, b = pair if longer else pair[::-1]
                solid = _loft([(a if w is lo else b, z) for w, z in sections])
        if solid is not None:
            return solid
    raise GeometryError("ruled drafted prism of a glyph wire failed", wire)


def _wire_points(wire, spacing: float):
    """Points (n, 2) about ``spacing`` mm apart along the planar closed ``wire``, counter-clockwise."""
    import numpy as np
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.BRepTools import BRepTools_WireExplorer
    from OCP.GCPnts import GCPnts_AbscissaPoint, GCPnts_UniformAbscissa
    from OCP.TopAbs import TopAbs_REVERSED

    pts = []
    ex = BRepTools_WireExplorer(wire)
    while ex.More():  # the edges in the wire's order, each along the wire's direction
        edge = ex.Current()
        curve = BRepAdaptor_Curve(edge)
        u0, u1 = curve.FirstParameter(), curve.LastParameter()
        n = max(2, int(math.ceil(GCPnts_AbscissaPoint.Length_s(curve) / spacing)))
        ua = GCPnts_UniformAbscissa(curve, n + 1, u0, u1)
        us = [ua.Parameter(i) for i in range(1, ua.NbPoints() + 1)] if ua.IsDone() else list(np.linspace(u0, u1, n + 1))
        if edge.Orientation() == TopAbs_REVERSED:
            us = us[::-1]
        for u in us[:-1]:
            p = curve.Value(u)
            pts.append((p.X(), p.Y()))
        ex.Next()
    pts = np.array(pts)
    keep = np.linalg.norm(pts - np.roll(pts, 1, axis=0), axis=1) > 0.1 * spacing  # OCC's offsets have 0-length edges
    pts = pts[keep]
    x, y = pts[:, 0], pts[:, 1]
    return pts if np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y) > 0.0 else pts[::-1]


#: spacing (mm) of the paired points fitted by the smooth walls, and the fit's tolerance (mm) across the wire
SMOOTH_SPACING = 0.01
SMOOTH_TOL = 1e-4


def _paired(wa, wb, spacing: float = 0.08, smooth: bool = False):
    """Two closed wires (None where either wire holds fewer than three points) through the paired
    points of :func:`_paired_points`, edge for edge: polygons, or with ``smooth`` the smooth runs of
    pairs as one cubic B-spline edge on each wire (:func:`_smooth_pair`), the rest as segments."""
    pts = _paired_points(wa, wb, spacing)
    if pts is None:
        return None
    if smooth:  # no more edges than the polygons 0.08 mm apart would have
        return _smooth_pair(*pts, max_edges=int(wire_length(wa) / 0.08))
    return polyline_wire(pts[0]), polyline_wire(pts[1])


def _runs(pa, pb, corner_deg: float = 30.0, jump: float = 1.5, min_len: int = 4):
    """The smooth runs of the closed paired polygons ``pa``, ``pb`` (n, 2): a list of index pairs
    ``(i, j)`` (``j > i``, indices taken modulo n), each a run of at least ``min_len`` segments along
    which neither polygon turns by more than ``corner_deg`` degrees at a vertex nor by 2 degrees
    and 3 times the mean turn of the four vertices around it (a corner), the turn changes by less
    than 1 degree from one vertex to the next (a curvature jump: a line meeting an arc), ``pb``'s
    segments are shorter than 5 times ``pa``'s and the ratio of their lengths changes by less than
    the factor ``jump`` from one segment to the next (a held stretch is a run of its own)."""
    import numpy as np

    n = len(pa)
    la = np.linalg.norm(np.roll(pa, -1, axis=0) - pa, axis=1)  # segment k: point k to k + 1
    lb = np.linalg.norm(np.roll(pb, -1, axis=0) - pb, axis=1)
    ratio = lb / np.maximum(la, 1e-30)
    good = ratio < 5.0
    bend = np.zeros(n, dtype=bool)  # at vertex k, between segments k - 1 and k
    for p, ln in ((pa, la), (pb, lb)):
        d = (np.roll(p, -1, axis=0) - p) / np.maximum(ln, 1e-30)[:, None]
        turn = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", np.roll(d, 1, axis=0), d), -1.0, 1.0)))
        around = sum(np.roll(turn, s) for s in (-2, -1, 1, 2)) / 4.0
        bend |= (turn > corner_deg) | ((turn > 2.0) & (turn > 3.0 * around))
        bend |= np.abs(turn - np.roll(turn, 1)) > 1.0
    r_prev = np.roll(ratio, 1)
    bend |= (ratio > jump * r_prev) | (r_prev > jump * ratio)
    breaks = [k for k in range(n) if bend[k] or not good[k] or not good[k - 1]]
    if not breaks:  # a smooth closed loop: four runs
        breaks = [0, n // 4, n // 2, (3 * n) // 4]
    runs = []
    for a, b in zip(breaks, breaks[1:] + [breaks[0] + n]):
        if b - a >= min_len and all(good[k % n] for k in range(a, b)):
            runs.append((a, b))
    return runs


def _smooth_pair(pa, pb, tol: float = SMOOTH_TOL, max_edges: int | None = None):
    """Two closed wires through the paired points ``pa``, ``pb`` (n, 2, mm) with one edge each per
    run of :func:`_runs` and per chord between runs (:func:`_chord_end`, within ``10 tol``; at corners
    segment by segment): a run's points fitted by cubic C2 B-splines on
    one knot vector with common parameters (:func:`_run_curves`), so that the ruled surface between
    the two edges joins each pair of points (and the points between, smoothly).  ``None`` where a
    run has no fit within ``tol`` mm or the wires would have more than ``max_edges`` edges."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeVertex, BRepBuilderAPI_MakeWire

    n = len(pa)
    runs = _runs(pa, pb)
    start = runs[0][0] if runs else 0
    spans, k = [], start  # (i, j): one edge from point i to point j (mod n)
    for a, b in runs + [(start + n, start + n)]:
        a, b = (a, b) if a >= start else (a + n, b + n)
        while k < a:  # segments between runs, as long as both polygons stay within tol of them
            e = _chord_end(pa, pb, k, a, 10.0 * tol)
            spans.append((k, e))
            k = e
        if b > a:
            spans.append((a, b))
            k = b
    if max_edges is not None and len(spans) > max_edges:
        return None
    wires = []
    for p in (pa, pb):
        verts = [BRepBuilderAPI_MakeVertex(gp_Pnt(float(x), float(y), 0.0)).Vertex() for x, y in p]
        wires.append((p, verts, BRepBuilderAPI_MakeWire()))
    for i, j in spans:
        run = (i, j) in runs or (i - n, j - n) in runs
        curves = _run_curves(pa, pb, i, j, tol) if run else None
        if run and curves is None:
            return None
        for (p, verts, mk), c in zip(wires, curves if curves is not None else (None, None)):
            v0, v1 = verts[i % n], verts[j % n]
            edge = BRepBuilderAPI_MakeEdge(v0, v1) if c is None else BRepBuilderAPI_MakeEdge(c, v0, v1)
            mk.Add(edge.Edge())
    return tuple(mk.Wire() for _, _, mk in wires)


def _chord_end(pa, pb, i: int, a: int, tol: float, longest: int = 8) -> int:
    """The furthest point ``j`` (``i < j <= min(a, i + longest)``, indices mod n) such that the points
    between ``i`` and ``j`` of the closed polygons ``pa`` and ``pb`` (n, 2) lie within ``tol`` mm of
    the chords from ``i`` to ``j``."""
    import numpy as np

    n, best = len(pa), i + 1
    for j in range(i + 2, min(a, i + longest) + 1):
        for p in (pa, pb):
            c0, c1 = p[i % n], p[j % n]
            d = c1 - c0
            ln = float(np.hypot(*d))
            mid = p[np.arange(i + 1, j) % n] - c0
            off = np.abs(mid[:, 0] * d[1] - mid[:, 1] * d[0]) / ln if ln > 1e-12 else np.hypot(mid[:, 0], mid[:, 1])
            if off.max() > tol:
                return best
        best = j
    return best


def _run_curves(pa, pb, i: int, j: int, tol: float):
    """Cubic C2 B-splines (``Geom_BSplineCurve``, z = 0) on one knot vector fitted by least squares to
    ``pa`` and ``pb`` from point ``i`` to point ``j`` (indices mod n) at common parameters (arc length
    along ``pa``, mm), through both ends, the knots halved where a point lies more than ``tol`` mm off;
    ``None`` where no fit within ``tol`` with knots at least 4 points apart exists."""
    import numpy as np
    from scipy.interpolate import make_lsq_spline
    from OCP.Geom import Geom_BSplineCurve
    from OCP.TColgp import TColgp_Array1OfPnt
    from OCP.TColStd import TColStd_Array1OfInteger, TColStd_Array1OfReal

    n = len(pa)
    idx = np.arange(i, j + 1) % n
    q = np.hstack([pa[idx], pb[idx]])  # (m, 4): both ends' points at one parameter
    u = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pa[idx], axis=0), axis=1))])
    if len(u) < 5:
        return None
    w = np.ones(len(u))
    w[[0, -1]] = 1e4  # (the ends are then set exactly)
    inner = list(np.linspace(0.0, u[-1], max(2, int(math.ceil(u[-1] / 0.4))) + 1)[1:-1])
    for _ in range(12):
        knots = np.concatenate([[0.0] * 4, inner, [u[-1]] * 4])
        try:
            spl = make_lsq_spline(u, q, knots, k=3, w=w)
        except (ValueError, np.linalg.LinAlgError):  # Schoenberg-Whitney: too few points in a span
            return None
        c = np.array(spl.c)
        c[0], c[-1] = q[0], q[-1]
        err = np.maximum(*(_fit_error(_bspline_values(knots, c[:, s], u), q[:, s])
                           for s in (slice(0, 2), slice(2, 4))))
        if err.max() <= tol:
            break
        bad = set(np.clip(np.searchsorted(knots[3:-3], u[err > tol], side="right") - 1, 0, len(knots) - 8))
        edges = knots[3:-3]
        new = [0.5 * (edges[k] + edges[k + 1]) for k in sorted(bad)]
        if min(np.diff(np.sort(inner + new + [0.0, u[-1]]))) < 4.0 * u[-1] / (len(u) - 1):
            return None
        inner = sorted(inner + new)
    else:
        return None
    uniq, mult = np.unique(knots, return_counts=True)
    tk, tm = TColStd_Array1OfReal(1, len(uniq)), TColStd_Array1OfInteger(1, len(uniq))
    for k, (x, m) in enumerate(zip(uniq, mult)):
        tk.SetValue(k + 1, float(x))
        tm.SetValue(k + 1, int(m))
    curves = []
    for s in (slice(0, 2), slice(2, 4)):
        poles = TColgp_Array1OfPnt(1, len(c))
        for k, (x, y) in enumerate(c[:, s]):
            poles.SetValue(k + 1, gp_Pnt(float(x), float(y), 0.0))
        curves.append(Geom_BSplineCurve(poles, tk, tm, 3))
    return curves


def _fit_error(fit, pts, along: float = 20.0):
    """The fit's errors (m,) in mm: the larger of the distance of ``fit`` (m, 2) from ``pts`` (m, 2)
    across the polygon through ``pts`` and 1/``along`` of the distance along it (the pairs' positions
    along the wire, nearest points on a polygon, jitter by a few um: held to ``along * tol`` there)."""
    import numpy as np

    tng = np.gradient(pts, axis=0)
    tng /= np.maximum(np.linalg.norm(tng, axis=1), 1e-30)[:, None]
    r = fit - pts
    across = np.abs(r[:, 0] * tng[:, 1] - r[:, 1] * tng[:, 0])
    return np.maximum(across, np.abs(np.einsum("ij,ij->i", r, tng)) / along)


def _bspline_values(knots, poles, u):
    """Values (m, 2) at ``u`` of the cubic B-spline with ``knots`` and ``poles`` (p, 2)."""
    from scipy.interpolate import BSpline

    return BSpline(knots, poles, 3)(u)


def _paired_points(wa, wb, spacing: float = 0.08):
    """Paired plan points ``(pa, pb)``, arrays (n, 2) in mm, or None where either wire holds fewer
    than three points: ``wa``'s points (``spacing`` apart) and the nearest points of ``wb`` to them,
    so that a ruled loft between polygons through them joins each point of one offset to its
    counterpart along the normal on the other (OCC's offsets of one outline split its edges
    differently, and pairing by arc length drifts where a feature vanishes).

    The positions along ``wb`` are kept in order once round it: held where they step back
    (:func:`_held_in_order`: over a stroke's end that ``wb`` has lost, whose points on ``wa`` then
    fan into where it vanished), or, where that finds no such order, every step back made a step of
    1e-3 ``spacing`` and all steps scaled to go once round (:func:`_rescaled_in_order`, which twists
    the walls where many points step back)."""
    pa, pb = _wire_points(wa, spacing), _wire_points(wb, 0.25 * spacing)
    if len(pa) < 3 or len(pb) < 3:  # a wire shorter than a few spacings (a vanishing stroke's offset)
        return None
    sig, near, per = _nearest_positions(pa, pb) if spacing >= 0.08 else _nearest_positions_near(pa, pb)
    eps = 1e-3 * spacing  # distinct vertices
    held = _held_in_order(sig, near, per, eps)
    return pa, _points_at(pb, held if held is not None else _rescaled_in_order(sig, per, eps))


def _nearest_positions(pa, pb):
    """``(sig, near, per)``: the arc-length positions (mm, from ``pb[0]``) along the closed polygon
    ``pb`` (m, 2) of its nearest points to the points ``pa`` (n, 2), their distances (mm) and the
    polygon's perimeter (mm)."""
    import numpy as np

    seg = np.roll(pb, -1, axis=0) - pb
    slen = np.linalg.norm(seg, axis=1)
    cum = np.concatenate([[0.0], np.cumsum(slen)])
    rel = pa[:, None, :] - pb[None, :, :]
    u = np.clip(np.einsum("ijk,jk->ij", rel, seg) / np.maximum(slen * slen, 1e-30), 0.0, 1.0)
    dist = np.linalg.norm(rel - u[..., None] * seg[None], axis=2)
    j = np.argmin(dist, axis=1)
    rows = np.arange(len(pa))
    return cum[j] + u[rows, j] * slen[j], dist[rows, j], cum[-1]


def _nearest_positions_near(pa, pb):
    """:func:`_nearest_positions` looking only at the segments of ``pb`` that can hold the nearest
    point (a vertex within the nearest vertex's distance plus the longest segment; a k-d tree), for
    dense polygons: the same minimum, found among fewer segments (all points' candidates at once,
    each point's in ascending order: the first of equal distances wins, as in a loop over them)."""
    import numpy as np
    from scipy.spatial import cKDTree

    seg = np.roll(pb, -1, axis=0) - pb
    slen = np.linalg.norm(seg, axis=1)
    cum = np.concatenate([[0.0], np.cumsum(slen)])
    tree = cKDTree(pb)
    dv, _ = tree.query(pa)
    i, j = _candidate_segments(tree.query_ball_point(pa, dv + slen.max() + 1e-12), len(pb))
    rel = pa[i] - pb[j]
    u = np.clip(np.einsum("jk,jk->j", rel, seg[j]) / np.maximum(slen[j] * slen[j], 1e-30), 0.0, 1.0)
    dist = np.linalg.norm(rel - u[:, None] * seg[j], axis=1)
    best = _first_minima(i, dist, len(pa))
    return cum[j[best]] + u[best] * slen[j[best]], dist[best], cum[-1]


def _candidate_segments(verts, m: int):
    """``(i, j)``, int arrays: for each point ``i`` (in order) the segments ``j`` (ascending, each
    once) that start or end at one of its vertices ``verts[i]`` (indices into a closed polygon of
    ``m`` vertices; segment ``j`` runs from vertex ``j`` to ``j + 1``)."""
    import numpy as np

    counts = np.fromiter((len(v) for v in verts), dtype=np.intp, count=len(verts))
    flat = np.fromiter((k for v in verts for k in v), dtype=np.intp, count=int(counts.sum()))
    owner = np.repeat(np.arange(len(verts)), counts)
    i = np.concatenate([owner, owner])
    j = np.concatenate([flat, (flat - 1) % m])
    order = np.lexsort((j, i))
    i, j = i[order], j[order]
    keep = np.ones(len(i), dtype=bool)
    keep[1:] = (i[1:] != i[:-1]) | (j[1:] != j[:-1])
    return i[keep], j[keep]


def _first_minima(group, values, n: int):
    """Index (into ``values``) of the first smallest value of each of the ``n`` groups; ``group``:
    each value's group, ascending, every group present."""
    import numpy as np

    starts = np.flatnonzero(np.r_[True, group[1:] != group[:-1]])
    low = np.minimum.reduceat(values, starts)
    at = np.flatnonzero(values == low[group])
    first = np.r_[True, group[at][1:] != group[at][:-1]]
    out = at[first]
    if len(out) != n:  # a group without a candidate or a NaN distance: no minimum to take
        raise GeometryError("nearest positions: a point without a finite nearest segment", None)
    return out


def _round_steps(sig, per: float):
    """The steps (mm) from each position ``sig`` along a closed wire of perimeter ``per`` to the next
    (the last back to the first), each taken the short way round: in [-per/2, per/2)."""
    import numpy as np

    return np.mod(np.diff(np.concatenate([sig, sig[:1]])) + 0.5 * per, per) - 0.5 * per


def _held_in_order(sig, near, per: float, eps: float, tries: int = 16):
    """The positions ``sig`` (mm along a closed wire of perimeter ``per``, the nearest points to
    consecutive points of another wire, at distances ``near`` mm) made to go once round in order:
    kept where they advance, held (``eps`` mm further on per point) where they step back, counted
    from a point at the typical distance (the median of ``near``: the offsets' distance apart, on
    the normal).  ``None`` where the positions do not go once round or none of the ``tries`` points
    nearest the typical distance starts an order that closes (the last at most ``per - eps``)."""
    import numpy as np

    steps = _round_steps(sig, per)
    if abs(steps.sum() - per) > 1e-9 * per:  # not once round (none, or twice)
        return None
    k = eps * np.arange(len(sig))
    for start in np.argsort(np.abs(near - np.median(near)), kind="stable")[:tries]:
        ahead = np.roll(steps, -int(start))
        pos = np.concatenate([[0.0], np.cumsum(ahead[:-1])])  # from sig[start], unwrapped
        held = np.maximum.accumulate(pos - k) + k
        if held[-1] <= per - eps:
            return np.mod(sig[start] + np.roll(held, int(start)), per)
    return None


def _rescaled_in_order(sig, per: float, eps: float):
    """The positions ``sig`` (mm along a closed wire of perimeter ``per``) made to go once round in
    order by making every step back (or shorter than ``eps`` mm) a step of ``eps`` and scaling all
    steps to sum to ``per``, from ``sig[0]``."""
    import numpy as np

    steps = np.maximum(_round_steps(sig, per), eps)
    steps *= per / steps.sum()
    return np.mod(sig[0] + np.concatenate([[0.0], np.cumsum(steps[:-1])]), per)


def _points_at(pb, sig):
    """The points (n, 2) at the arc-length positions ``sig`` (mm, from ``pb[0]``) along the closed
    polygon ``pb`` (m, 2)."""
    import numpy as np

    seg = np.roll(pb, -1, axis=0) - pb
    slen = np.linalg.norm(seg, axis=1)
    cum = np.concatenate([[0.0], np.cumsum(slen)])
    k = np.clip(np.searchsorted(cum, sig, side="right") - 1, 0, len(pb) - 1)
    return pb[k] + ((sig - cum[k]) / np.maximum(slen[k], 1e-30))[:, None] * seg[k]


def _loft(sections):
    """One ruled solid (``BRepOffsetAPI_ThruSections``) through the planar ``(wire, z)`` sections
    (a section repeating its neighbour's height is dropped), or ``None`` (failed or invalid)."""
    from OCP.BRepCheck import BRepCheck_Analyzer
    from OCP.BRepOffsetAPI import BRepOffsetAPI_ThruSections
    from OCP.TopoDS import TopoDS

    kept = [sections[0]]
    for w, z in sections[1:]:
        if abs(z - kept[-1][1]) > 1e-9:
            kept.append((w, z))
    loft = BRepOffsetAPI_ThruSections(True, True, 1e-6)
    for w, z in kept:
        loft.AddWire(TopoDS.Wire_s(translated(w, dz=z)))
    try:
        loft.Build()
        solids = explore(loft.Shape(), "Solid") if loft.IsDone() else []
    except Exception:  # StdFail_NotDone
        return None
    return solids[0] if len(solids) == 1 and BRepCheck_Analyzer(solids[0]).IsValid() else None


def apply_emboss(frame: TabletFrame, shape, items, clearance: float, *, check: bool = True,
                 deflection: float = 0.005, a_manifold=None, checked=None) -> tuple[Any, list, list[dict]]:
    """Emboss/deboss every item on ``shape``; returns ``(solid, Boolean checks, per-item info)``.

    ``checked``: what :func:`check_emboss` returned for each item, when the caller has checked them."""
    checks, infos = [], []
    offsets = _Offsets(_offset_base(frame))
    for i, e in enumerate(items):
        figure, info = checked[i] if checked is not None else check_emboss(frame, e, clearance, i)
        info = dict(info)
        top = e.face == "top"
        sg = 1.0 if top else -1.0
        # short prisms (OCC's surface intersections cost grows with the walls' height): from just
        # inside the tablet under the figure to just beyond the face's highest point
        zs, tilts = _footprint(shape, figure, top)
        tilt = max(tilts)
        normal = e.projection == "normal"
        reach = e.depth_mm / math.cos(tilt) if normal else e.depth_mm  # axial extent of the layer
        near = min(zs) if top else max(zs)
        far = frame.z_max if top else frame.z_min
        inner = near - sg * ((reach if e.mode == "deboss" else 0.0) + 0.05)
        outer = far + sg * ((reach if e.mode == "emboss" else 0.0) + 0.05)
        # stroke angle: the figure is nominal at the mean height of the face under it (exact on a flat
        # face; on a cup its width at the face varies by +-spread/2 * tan(angle), reported)
        z_face = sum(zs) / len(zs)
        info["projection"] = e.projection
        info["max_normal_tilt_deg"] = math.degrees(tilt)
        info["max_axial_depth_mm"] = reach
        info["face_height_spread_mm"] = max(zs) - min(zs)
        info["width_variation_at_face_mm"] = 0.5 * (max(zs) - min(zs)) * math.tan(math.radians(e.draft_deg))
        if e.mode == "deboss":
            # narrower towards the letter bottom, wider out of the tablet
            prism = figure_prism(figure, outer, inner, e.draft_deg, z_nominal=z_face)
            floor = offsets.get(-e.depth_mm) if normal else translated(shape, dz=-sg * e.depth_mm)
            part = _around(floor, prism)
            tool = _cut_each(prism, part, i)
            op = "cut"
        else:
            prism = figure_prism(figure, inner, outer, e.draft_deg, z_nominal=z_face)
            roof = offsets.get(e.depth_mm) if normal else translated(shape, dz=sg * e.depth_mm)
            part = _around(roof, prism)
            tool = _common_each(prism, part, i)
            op = "fuse"
        if check:
            info["tool_check"] = tool_check("cut" if op == "cut" else "common", prism, part, tool,
                                            f"{e.mode} {i} tool", deflection)
        shape, chk = checked_boolean(op, shape, tool, what=f"{e.mode} {i} ({e.text or e.svg or 'outline'}, {e.face})",
                                     deflection=deflection, check=check, a_manifold=a_manifold)
        a_manifold = None
        if chk is not None:
            checks.append(chk)
        infos.append(dict(index=i, text=e.text, svg=e.svg, outline_points=None if e.outline is None else len(e.outline), mode=e.mode,
                          face=e.face, height_mm=e.height_mm, depth_mm=e.depth_mm, draft_deg=e.draft_deg,
                          font=e.font if e.text else None, volume_changed_mm3=None if chk is None else chk.occ_change_mm3,
                          **info))
    return shape, checks, infos


def face_heights(shape, figure, top: bool) -> list[float]:
    """Heights (mm) where vertical lines through the figure's vertices meet the top (bottom) face of ``shape``."""
    return _footprint(shape, figure, top)[0]


def _footprint(shape, figure, top: bool) -> tuple[list[float], list[float]]:
    """Heights (mm) and tilts of the face normal from the axis (rad) where vertical lines through points
    of the figure's edges (7 per edge) meet the top (bottom) face of ``shape``."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.BRepLProp import BRepLProp_SLProps
    from OCP.gp import gp_Lin
    from OCP.IntCurvesFace import IntCurvesFace_ShapeIntersector

    inter = IntCurvesFace_ShapeIntersector()
    inter.Load(shape, 1e-7)
    pts = []
    for edge in explore(figure, "Edge"):
        c = BRepAdaptor_Curve(edge)
        a, b = c.FirstParameter(), c.LastParameter()
        pts.extend(c.Value(a + (b - a) * k / 6.0) for k in range(7))
    zs, tilts = [], []
    for p in pts:
        inter.Perform(gp_Lin(gp_Pnt(p.X(), p.Y(), -1e3), gp_Dir(0, 0, 1)), -1e9, 1e9)
        hits = [(inter.Pnt(k).Z(), k) for k in range(1, inter.NbPnt() + 1)]
        if not hits:
            continue
        z, k = max(hits) if top else min(hits)
        zs.append(z)
        props = BRepLProp_SLProps(BRepAdaptor_Surface(inter.Face(k)), inter.UParameter(k), inter.VParameter(k), 1, 1e-9)
        tilts.append(math.acos(min(1.0, abs(props.Normal().Z()))) if props.IsNormalDefined() else 0.0)
    if not zs:
        raise GeometryError("the figure does not lie over the tablet", figure)
    return zs, tilts


def _offset_base(frame: TabletFrame):
    """The solid whose normal offsets are the floors (deboss) and tops (emboss): the tablet's own,
    except for a tablet of revolution, whose faces of revolution (``frame.revolved``) are offset rather
    than their rational B-spline form (``frame.shape``, the same surfaces), because OCC approximates
    the offsets of the rational faces at degree 15 with 46 poles around (a 10 mm concave round's cup:
    its "A8 69" took 53-67 s instead of 36 s), those of the faces of revolution with 15 x 6 poles."""
    return frame.revolved if frame.revolved is not None else frame.shape


class _Offsets:
    """The plain tablet offset along its normals by ``d`` mm (outwards > 0), built once per depth."""

    def __init__(self, plain):
        self.plain, self.done = plain, {}

    def get(self, d: float):
        if d not in self.done:
            self.done[d] = offset_solid(self.plain, d)
        return self.done[d]


def offset_solid(shape, d: float):
    """``shape`` with every face replaced by its offset surface at ``d`` mm along the outward normal
    (``d < 0``: inwards), by OCC's simple offset (no intersections: exact on smooth faces; where faces
    meet at an angle the offset edges take the gap as tolerance, which the figures, inset from the
    tablet's edges by land and margin, never reach).  The offset surfaces are then approximated by
    B-splines (``ShapeCustom.ConvertToBSpline``, to ``Precision::Approximation``, 1e-6 mm): OCC's
    meshers leave trimmed faces on ``Geom_OffsetSurface`` untriangulated, and the Booleans are
    cross-checked on meshes.  A single valid solid or :class:`GeometryError`."""
    from OCP.BRepCheck import BRepCheck_Analyzer
    from OCP.BRepOffsetAPI import BRepOffsetAPI_MakeOffsetShape
    from OCP.ShapeCustom import ShapeCustom
    from OCP.ShapeFix import ShapeFix_Shape

    mk = BRepOffsetAPI_MakeOffsetShape()
    mk.PerformBySimple(shape, float(d))
    out = ShapeCustom.ConvertToBSpline_s(mk.Shape(), False, False, True, False) if mk.IsDone() else None
    if out is not None and not BRepCheck_Analyzer(out).IsValid():  # (the almond: one face's wire, at its tip)
        fix = ShapeFix_Shape(out)
        fix.Perform()
        out = fix.Shape()
    solids = [] if out is None else explore(out, "Solid")
    if len(solids) != 1 or not BRepCheck_Analyzer(solids[0]).IsValid():
        raise GeometryError(f"normal offset of the tablet by {d:g} mm failed ({len(solids)} solids)", shape)
    return solids[0]


def _around(solid: TopoDS_Shape, prism: TopoDS_Shape, margin: float = 0.1) -> TopoDS_Shape:
    """The part of ``solid`` inside the box of ``prism`` widened by ``margin`` mm, or ``solid`` where
    that is not one solid.

    The prism lies inside the box, so ``prism - solid`` and ``prism & solid`` are the same with the
    part: the figure's walls meet the same surface, on a face that ends near them (OCC's Boolean
    of "A8 69" drafted 15 deg with the floor of a 10 mm concave round: 7.2-8.0 s of one core instead
    of 9.6-11.0 s; the capsule's the same, 3.8-4.2 s; the box's own Boolean 0.05-0.3 s)."""
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib

    from tabletcad.tooling.booleans import box_solid, raw_boolean

    box = Bnd_Box()
    BRepBndLib.Add_s(prism, box)  # (contains the prism: its geometry's box, widened by tolerances)
    block = box_solid(box.CornerMin().Coord(), box.CornerMax().Coord(), margin)
    try:
        part = explore(raw_boolean("common", solid, block), "Solid")
    except GeometryError:
        return solid
    return part[0] if len(part) == 1 else solid


def tool_check(op: str, prism, layer, tool, what: str, deflection: float = 0.005) -> dict:
    """Cross-check of the tool Boolean ``tool = prism op layer`` (``"cut"``: the deboss cutter,
    ``"common"``: the emboss adder) with manifold3d on meshes of chord height ``deflection`` mm:
    the volume (mm^3) taken from the prism (cut) or kept (common) by OCC and on the meshes may
    differ by ``deflection`` times the area of the surface bounding that volume (the meshes'
    common's area over ``cos 0.2``, the angular deflection); :class:`GeometryError` if more.

    The final Boolean's check (tablet op tool) meshes the tool OCC made, so it cannot see a wrong
    tool: an invalid-free but wrong prism - floor (0.106 mm^3 too much, a capsule's "A8 69") is
    caught here (measured differences: 0.006 mm^3 at 0.005 mm)."""
    from tabletcad.tooling.booleans import manifold_op, manifold_volume, to_manifold, volume

    mp, ml = to_manifold(prism, deflection), to_manifold(layer, deflection)
    common = manifold_op("common", mp, ml)
    if op == "cut":
        occ, mesh = volume(prism) - volume(tool), manifold_volume(common)
    else:
        occ, mesh = volume(tool), manifold_volume(common)
    bound = deflection * (0.0 if common.is_empty() else float(common.surface_area())) / math.cos(0.2)
    if abs(occ - mesh) > bound:
        raise GeometryError(f"{what}: OCC and manifold3d disagree on the prism {op}: {occ:.6g} vs {mesh:.6g} "
                            f"mm^3 (allowed {bound:.3g} mm^3 at {deflection} mm deflection)", (prism, layer))
    return dict(occ_mm3=occ, mesh_mm3=mesh, abs_diff_mm3=abs(occ - mesh), bound_mm3=bound)


def _cut_each(prism, shifted, i):
    from tabletcad.tooling.booleans import raw_boolean

    solids = explore(raw_boolean("cut", prism, shifted), "Solid")
    if not solids:
        raise GeometryError(f"deboss {i}: the cut figure is empty", prism)
    return solids[0] if len(solids) == 1 else _compound(solids)


def _common_each(prism, shifted, i):
    from tabletcad.tooling.booleans import raw_boolean

    solids = explore(raw_boolean("common", prism, shifted), "Solid")
    if not solids:
        raise GeometryError(f"emboss {i}: the raised figure is empty", prism)
    return solids[0] if len(solids) == 1 else _compound(solids)
