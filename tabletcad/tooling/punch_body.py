"""Complete upper and lower punches: the tip (:mod:`tabletcad.tooling.punch`) with its relief,
fused to a revolved barrel, neck and head (TSM angled or EU domed) and an optional key.

The body is the profile of :class:`~tabletcad.tooling.standards.PunchBody` revolved about the
punch axis; its volume has a closed form (:func:`body_volume`: cylinders, cone frustums and a
spherical zone) that the tests compare with OCC's.  The tip relief removes, behind the first
``tip_straight_mm`` of the tip, a ring ``tip_relief_mm`` wide from the tip's outline (the tip
rides in the die bore on its straight part only).  Parts are placed at the closed position:
the upper punch's tip edge at the top of the band, the lower's at its bottom.
"""

from __future__ import annotations

import math

from OCP.BRepBuilderAPI import (BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakeWire,
                                BRepBuilderAPI_Transform)
from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox, BRepPrimAPI_MakeRevol
from OCP.GC import GC_MakeArcOfCircle
from OCP.gp import gp_Ax1, gp_Ax2, gp_Dir, gp_Pnt, gp_Trsf, gp_Vec

from tabletcad.errors import DesignError
from tabletcad.tooling.booleans import boolean, volume
from tabletcad.tooling.outline import TabletFrame, face_area, plan_face, prism
from tabletcad.tooling.spec import RELIEF_RING_OVERLAP_MM
from tabletcad.tooling.standards import PunchBody

__all__ = ["body_profile", "body_solid", "body_volume", "key_volume", "relief_volume", "complete_punch",
           "check_body_fits"]


def body_profile(b: PunchBody, barrel_length: float) -> list[tuple[float, float]]:
    """The body's half profile ``(r, s)`` (mm), ``s`` along the axis from the barrel's tip end;
    the top of the head (EU) is the arc between the last two points."""
    rb, rn, rh, rf = (0.5 * d for d in (b.barrel_diameter_mm, b.neck_diameter_mm, b.head_diameter_mm,
                                        b.head_flat_diameter_mm))
    s1 = barrel_length
    s2 = s1 + b.neck_length_mm
    s3 = s2 + b.head_under_mm
    s4 = s3 + b.head_rim_mm
    s5 = s4 + b.head_top_mm
    pts = [(0.0, 0.0), (rb, 0.0), (rb, s1), (rn, s1), (rn, s2), (rh, s3)]
    if b.head_rim_mm > 0:
        pts.append((rh, s4))
    pts += [(rf, s5), (0.0, s5)]
    return pts


def _edge(p, q):
    return BRepBuilderAPI_MakeEdge(gp_Pnt(p[0], 0.0, p[1]), gp_Pnt(q[0], 0.0, q[1])).Edge()


def body_solid(b: PunchBody, barrel_length: float):
    """The revolved barrel, neck and head (with the key) in local coordinates: axis +z, the barrel's
    tip end at ``z = 0``, the head flat at ``z = barrel + neck + head``."""
    pts = body_profile(b, barrel_length)
    wire = BRepBuilderAPI_MakeWire()
    top = len(pts) - 3  # index of the rim's upper point: the head top runs pts[top] -> pts[top + 1]
    for i in range(len(pts)):
        p, q = pts[i], pts[(i + 1) % len(pts)]
        if i == top and b.head == "domed":
            rd = b.dome_radius_mm
            zc = p[1] - math.sqrt(rd * rd - p[0] * p[0])  # sphere centre on the axis
            rm = 0.5 * (p[0] + q[0])
            mid = gp_Pnt(rm, 0.0, zc + math.sqrt(rd * rd - rm * rm))
            arc = GC_MakeArcOfCircle(gp_Pnt(p[0], 0.0, p[1]), mid, gp_Pnt(q[0], 0.0, q[1])).Value()
            wire.Add(BRepBuilderAPI_MakeEdge(arc).Edge())
        elif p != q:
            wire.Add(_edge(p, q))
    face = BRepBuilderAPI_MakeFace(wire.Wire(), True).Face()
    shape = BRepPrimAPI_MakeRevol(face, gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 2.0 * math.pi).Shape()
    if b.key:
        rb = 0.5 * b.barrel_diameter_mm
        embed = rb - math.sqrt(max(rb * rb - (0.5 * b.key_width_mm) ** 2, 0.0)) + 0.2  # into the barrel
        box = BRepPrimAPI_MakeBox(gp_Ax2(gp_Pnt(rb - embed, -0.5 * b.key_width_mm, b.key_offset_mm), gp_Dir(0, 0, 1),
                                         gp_Dir(1, 0, 0)), embed + b.key_height_mm, b.key_width_mm,
                                  b.key_length_mm).Shape()
        if b.key_angle_deg:
            tr = gp_Trsf()
            tr.SetRotation(gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), math.radians(b.key_angle_deg))
            box = BRepBuilderAPI_Transform(box, tr, True).Shape()
        shape = boolean("fuse", shape, box, what="punch key")
    return shape


def body_volume(b: PunchBody, barrel_length: float) -> float:
    """Closed-form volume of the revolved body without the key (mm³): cylinders, frustums
    ``πh(R² + Rr + r²)/3`` and, for a domed head, the spherical zone ``π∫(R_d² − (z − z_c)²)dz``."""
    rb, rn, rh, rf = (0.5 * d for d in (b.barrel_diameter_mm, b.neck_diameter_mm, b.head_diameter_mm,
                                        b.head_flat_diameter_mm))
    v = math.pi * (rb * rb * barrel_length + rn * rn * b.neck_length_mm + rh * rh * b.head_rim_mm)
    v += math.pi * b.head_under_mm * (rn * rn + rn * rh + rh * rh) / 3.0
    if b.head == "angled":
        v += math.pi * b.head_top_mm * (rh * rh + rh * rf + rf * rf) / 3.0
    else:
        rd = b.dome_radius_mm
        a, c = math.sqrt(rd * rd - rh * rh), math.sqrt(rd * rd - rf * rf)  # heights above the centre
        v += math.pi * (rd * rd * (c - a) - (c ** 3 - a ** 3) / 3.0)
    return v


def key_volume(b: PunchBody) -> float:
    """Closed-form volume of the key outside the barrel (mm³), 0 without one: its section, the rectangle
    ``w`` wide reaching ``h`` beyond the barrel's radius ``r`` less the circle's part of it,
    ``w (r + h) - (w/2) sqrt(r² - w²/4) - r² asin(w / 2r)``, times its length."""
    if not b.key:
        return 0.0
    r, w, h = 0.5 * b.barrel_diameter_mm, b.key_width_mm, b.key_height_mm
    section = w * (r + h) - 0.5 * w * math.sqrt(r * r - 0.25 * w * w) - r * r * math.asin(0.5 * w / r)
    return section * b.key_length_mm


def relief_volume(frame: TabletFrame, b: PunchBody, clearance: float, tip_length: float) -> float:
    """Volume the tip relief removes (mm³): the plan ring between the tip outline and its relieved
    outline times the relieved length."""
    if b.tip_relief_mm <= 0 or tip_length <= b.tip_straight_mm:
        return 0.0
    inset = frame.tip_inset(clearance)
    a = face_area(plan_face(frame.offset(-inset)))
    r = face_area(plan_face(frame.offset(-inset - b.tip_relief_mm)))
    return (a - r) * (tip_length - b.tip_straight_mm)


def check_body_fits(frame: TabletFrame, b: PunchBody, tip_radius: float) -> None:
    """DesignError when the punch tip (the tablet's outline less the clearance, reaching ``tip_radius``
    mm from the axis) does not fit the barrel it is machined from, or the tablet exceeds the standard's
    largest tablet (a 19 mm capsule on B tooling, whose barrel is 19 mm, fits with a clearance)."""
    if tip_radius >= 0.5 * b.barrel_diameter_mm:
        raise DesignError("[tooling.punch] barrel_diameter_mm", b.barrel_diameter_mm,
                          f"must be > the punch tip's circumscribed diameter {2 * tip_radius:.4g} mm (the tablet's "
                          "less twice the clearance)", "mm")
    size = frame.plan_diameter  # (its extent in any direction: a rounded square's diagonal)
    round_ = frame.outline_kind == "circle"
    lim = b.max_round_tablet_mm if round_ else b.max_shaped_tablet_mm
    if lim is not None and size > lim + 1e-9:
        raise DesignError("[tooling] type", b.kind, f"{b.standard} {b.kind} tooling takes {'round' if round_ else 'shaped'} "
                          f"tablets up to {lim:g} mm (tabletcad/data/tooling_standards.toml); this one is {size:.4g} mm "
                          "across")


def complete_punch(frame: TabletFrame, tip_shape, which: str, b: PunchBody, clearance: float, tip_length: float,
                   edge: float | None = None):
    """The complete ``"upper"``/``"lower"`` punch from its tip solid: ``(shape, info)``.  ``edge``: the
    tip's edge z (mm; :func:`~tabletcad.tooling.punch.punch_tip`'s ``tip_edge_z_mm``, the band's edge by
    default), from which the tip length and the overall length run."""
    up = which == "upper"
    if edge is None:
        edge = frame.band_z[1] if up else frame.band_z[0]
    sign = 1.0 if up else -1.0
    shape = tip_shape
    if b.tip_relief_mm > 0 and tip_length > b.tip_straight_mm:
        a, c = sorted((edge + sign * b.tip_straight_mm, edge + sign * (tip_length + 1.0)))
        inset = frame.tip_inset(clearance)
        ring = boolean("cut", prism(frame.offset(-inset + RELIEF_RING_OVERLAP_MM), a, c),
                       prism(frame.offset(-inset - b.tip_relief_mm), a - 1.0, c + 1.0),
                       what=f"{which} tip relief ring")
        shape = boolean("cut", shape, ring, what=f"{which} tip relief")
    lb = b.barrel_length_mm(tip_length)
    body = body_solid(b, lb)
    tr = gp_Trsf()
    if up:
        tr.SetTranslation(gp_Vec(0.0, 0.0, edge + tip_length))
    else:  # mirrored: the head below
        tr.SetMirror(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)))
        t2 = gp_Trsf()
        t2.SetTranslation(gp_Vec(0.0, 0.0, edge - tip_length))
        tr = t2.Multiplied(tr)
    shape = boolean("fuse", shape, BRepBuilderAPI_Transform(body, tr, True).Shape(), what=f"{which} punch body")
    info = dict(standard=b.standard, type=b.kind, head=b.head, overall_length_mm=b.overall_length_mm,
                barrel_diameter_mm=b.barrel_diameter_mm, barrel_length_mm=lb, neck_diameter_mm=b.neck_diameter_mm,
                neck_length_mm=b.neck_length_mm, head_diameter_mm=b.head_diameter_mm,
                head_flat_diameter_mm=b.head_flat_diameter_mm, head_height_mm=b.head_height_mm,
                head_rim_mm=b.head_rim_mm, inside_head_angle_deg=b.inside_head_angle_deg,
                head_top_angle_deg=b.head_top_angle_deg, dome_radius_mm=b.dome_radius_mm,
                tip_length_mm=tip_length, tip_straight_mm=b.tip_straight_mm, tip_relief_mm=b.tip_relief_mm,
                key=b.key, head_flat_z_mm=edge + sign * b.overall_length_mm, volume_mm3=volume(shape),
                body_volume_closed_form_mm3=body_volume(b, lb), key_volume_mm3=key_volume(b),
                relief_volume_mm3=relief_volume(frame, b, clearance, tip_length),
                sources={k: v for k, v in b.sources.items()},
                modified_from_standard={k: dict(v) for k, v in b.modified.items()})
    return shape, info
