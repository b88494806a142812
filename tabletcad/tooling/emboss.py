"""Embossed (raised) and debossed (cut) text or logo outlines on a tablet face.

The figure is a set of plan faces at ``z = 0`` — text from a DejaVu font by
build123d's ``Text`` (OCC ``Font_BRepTextBuilder``), or a closed polyline —
rotated, moved to ``position_mm`` and, on the bottom face, mirrored so that
it reads correctly when the tablet is turned over.  It is extruded along the
axis into a prism (with ``draft_deg`` on its walls when asked) and made to
follow the face at a constant axial depth, the way a punch is engraved:

* deboss: cutter = prism − (tablet moved by ``depth`` into itself);
  tablet − cutter;
* emboss: adder = prism ∩ (tablet moved by ``depth`` out of itself);
  tablet ∪ adder.

Figures must lie inside the punch tip (outline inset by the clearance, the
tablet's land and ``margin_mm``), else :class:`DesignError`.
"""

from __future__ import annotations

import math
from typing import Any

from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut
from OCP.BRepBuilderAPI import BRepBuilderAPI_Transform
from OCP.gp import gp_Ax1, gp_Ax2, gp_Dir, gp_Pnt, gp_Trsf, gp_Vec
from OCP.TopoDS import TopoDS_Shape

from tabletcad.cad._occ import explore
from tabletcad.errors import DesignError, GeometryError
from tabletcad.tooling.booleans import checked_boolean, translated
from tabletcad.tooling.outline import TabletFrame, face_area, offset_wire, plan_face, polyline_wire
from tabletcad.tooling.spec import EmbossSpec, font_path

__all__ = ["figure_faces", "figure_prism", "apply_emboss", "check_fit", "check_emboss", "face_heights"]


def _transform(shape: TopoDS_Shape, trsf: gp_Trsf) -> TopoDS_Shape:
    return BRepBuilderAPI_Transform(shape, trsf, True).Shape()


def figure_faces(e: EmbossSpec) -> TopoDS_Shape:
    """Plan faces (a compound at ``z = 0``) of the text or outline, placed and, for the bottom, mirrored."""
    if e.text is not None:
        import build123d as bd

        txt = bd.Text(e.text, font_size=e.height_mm, font_path=str(font_path(e.font)))
        shape = txt.wrapped
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
        raise DesignError("[[tooling.emboss]] text", e.text, "gives no glyphs in this font")
    return shape


def _inset(frame: TabletFrame, clearance: float, e: EmbossSpec) -> float:
    return clearance + (frame.land or 0.0) + e.margin_mm


def check_fit(frame: TabletFrame, e: EmbossSpec, figure: TopoDS_Shape, clearance: float, i: int = 0) -> dict:
    """Raise :class:`DesignError` unless the figure lies inside the punch tip inset by land and margin."""
    inset = _inset(frame, clearance, e)
    what = "text" if e.text is not None else "outline"
    value = e.text if e.text is not None else f"{len(e.outline)} points"
    try:
        region = plan_face(offset_wire(frame.outline, -inset))
    except GeometryError:
        raise DesignError(f"[[tooling.emboss]] {i} {what}", value, f"does not fit: the face inset by {inset:.3g} mm is empty") from None
    cut = BRepAlgoAPI_Cut(figure, region)
    outside = sum(face_area(f) for f in explore(cut.Shape(), "Face"))
    area = sum(face_area(f) for f in explore(figure, "Face"))
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib

    box = Bnd_Box()
    BRepBndLib.Add_s(figure, box)
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
    figure = figure_faces(e)
    info = check_fit(frame, e, figure, clearance, i)
    cup = frame.cup_depth_top if e.face == "top" else frame.cup_depth_bottom
    limit = cup + 0.25 * frame.band
    if e.mode == "deboss" and e.depth_mm > limit:
        raise DesignError(f"[[tooling.emboss]] {i} depth_mm", e.depth_mm, f"must be <= cup depth + band/4 = {limit:.4g} mm", "mm")
    return figure, info


def figure_prism(figure: TopoDS_Shape, z0: float, z1: float, draft_deg: float = 0.0, narrow_at: str = "z1") -> TopoDS_Shape:
    """Prism of the plan figure from ``z0`` to ``z1``; with ``draft_deg`` the walls lean so that the
    figure is nominal at ``z0`` and narrower towards ``z1``."""
    faces = explore(figure, "Face")
    if draft_deg <= 0.0:
        from OCP.BRepPrimAPI import BRepPrimAPI_MakePrism

        solids = [translated(BRepPrimAPI_MakePrism(f, gp_Vec(0.0, 0.0, z1 - z0)).Shape(), dz=z0) for f in faces]
    else:
        solids = [_placed(_draft_prism(f, abs(z1 - z0), draft_deg), z0, z1) for f in faces]
    if len(solids) == 1:
        return solids[0]
    from OCP.BRep import BRep_Builder
    from OCP.TopoDS import TopoDS_Compound

    comp = TopoDS_Compound()
    b = BRep_Builder()
    b.MakeCompound(comp)
    for s in solids:
        b.Add(comp, s)
    return comp


def _mirror_z(shape):
    m = gp_Trsf()
    m.SetMirror(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)))
    return _transform(shape, m)


def _draft_prism(face, height: float, draft_deg: float):
    """``LocOpe_DPrism`` of a plan face at z = 0: ``z ∈ [0, height]``, walls leaning inward by ``draft_deg``."""
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib
    from OCP.LocOpe import LocOpe_DPrism

    from OCP.BRepCheck import BRepCheck_Analyzer
    from OCP.ShapeFix import ShapeFix_Shape

    solid = LocOpe_DPrism(face, float(height), math.radians(draft_deg)).Shape()
    if not BRepCheck_Analyzer(solid).IsValid():
        fix = ShapeFix_Shape(solid)
        fix.Perform()
        solid = fix.Shape()
    box = Bnd_Box()
    BRepBndLib.Add_s(solid, box)
    if box.CornerMax().Z() < 0.5 * height:  # the (mirrored) face pointed down
        solid = _mirror_z(solid)
    solids = explore(solid, "Solid")
    if len(solids) != 1:
        raise GeometryError(f"drafted prism of a glyph gave {len(solids)} solids", face)
    return solids[0]


def _placed(solid, z0: float, z1: float):
    """Move a prism built on ``[0, h]`` so that its base is at ``z0`` and it extends towards ``z1``."""
    if z1 < z0:
        solid = _mirror_z(solid)
    return translated(solid, dz=z0)


def apply_emboss(frame: TabletFrame, shape, items, clearance: float, *, check: bool = True,
                 deflection: float = 0.005, a_manifold=None) -> tuple[Any, list, list[dict]]:
    """Emboss/deboss every item on ``shape``; returns ``(solid, Boolean checks, per-item info)``."""
    checks, infos = [], []
    for i, e in enumerate(items):
        figure, info = check_emboss(frame, e, clearance, i)
        top = e.face == "top"
        sg = 1.0 if top else -1.0
        # short prisms (OCC's surface intersections cost grows with the walls' height): from just
        # inside the tablet under the figure to just beyond the face's highest point
        zs = face_heights(shape, figure, top)
        near = min(zs) if top else max(zs)
        far = frame.z_max if top else frame.z_min
        inner = near - sg * ((e.depth_mm if e.mode == "deboss" else 0.0) + 0.05)
        outer = far + sg * ((e.depth_mm if e.mode == "emboss" else 0.0) + 0.05)
        if e.mode == "deboss":
            # draft: nominal at the face side, narrower towards the letter bottom
            prism = figure_prism(figure, outer, inner, e.draft_deg)
            shifted = translated(shape, dz=-sg * e.depth_mm)
            tool = _cut_each(prism, shifted, i)
            op = "cut"
        else:
            prism = figure_prism(figure, inner, outer, e.draft_deg)
            shifted = translated(shape, dz=sg * e.depth_mm)
            tool = _common_each(prism, shifted, i)
            op = "fuse"
        shape, chk = checked_boolean(op, shape, tool, what=f"{e.mode} {i} ({e.text or 'outline'}, {e.face})",
                                     deflection=deflection, check=check, a_manifold=a_manifold)
        a_manifold = None
        if chk is not None:
            checks.append(chk)
        infos.append(dict(index=i, text=e.text, outline_points=None if e.outline is None else len(e.outline), mode=e.mode,
                          face=e.face, height_mm=e.height_mm, depth_mm=e.depth_mm, draft_deg=e.draft_deg,
                          font=e.font if e.text else None, volume_changed_mm3=None if chk is None else chk.occ_change_mm3,
                          **info))
    return shape, checks, infos


def face_heights(shape, figure, top: bool) -> list[float]:
    """Heights (mm) where vertical lines through the figure's vertices meet the top (bottom) face of ``shape``."""
    from OCP.gp import gp_Lin
    from OCP.IntCurvesFace import IntCurvesFace_ShapeIntersector

    inter = IntCurvesFace_ShapeIntersector()
    inter.Load(shape, 1e-7)
    from OCP.BRepAdaptor import BRepAdaptor_Curve

    pts = []
    for edge in explore(figure, "Edge"):
        c = BRepAdaptor_Curve(edge)
        a, b = c.FirstParameter(), c.LastParameter()
        pts.extend(c.Value(a + (b - a) * k / 6.0) for k in range(7))
    out = []
    for p in pts:
        inter.Perform(gp_Lin(gp_Pnt(p.X(), p.Y(), -1e3), gp_Dir(0, 0, 1)), -1e9, 1e9)
        zs = [inter.Pnt(k).Z() for k in range(1, inter.NbPnt() + 1)]
        if zs:
            out.append(max(zs) if top else min(zs))
    if not out:
        raise GeometryError("the figure does not lie over the tablet", figure)
    return out


def _compound(shapes):
    from OCP.BRep import BRep_Builder
    from OCP.TopoDS import TopoDS_Compound

    comp = TopoDS_Compound()
    b = BRep_Builder()
    b.MakeCompound(comp)
    for s in shapes:
        b.Add(comp, s)
    return comp


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
