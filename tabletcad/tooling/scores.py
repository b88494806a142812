"""Bisect and quadrisect score grooves, cut from the tablet solid by exact OCC Booleans.

A groove is a prism along ``direction_deg`` (plan angle from x) through the
tablet's axis, long enough to leave the tablet at both ends, whose cross
section hangs from the face's highest point (``z_max``, or ``z_min`` for the
bottom face) down to ``depth_mm``:

* ``v``: a V of ``angle_deg`` (included angle); its width at the depth's top
  is ``2 depth tan(angle/2)``;
* ``u``: a round bottom of radius ``width_mm/2`` with vertical walls;
* ``pressure_sensitive``: a V (``angle_deg``) ending ``depth/3`` above the
  bottom in a parallel slot ``slot_width_mm`` wide (the break line).

The groove bottom is straight.  A *standard* score must run out on the face
(depth below the cup depth, so the punch's score bar stays above its tip edge);
a *cut-through* score (``cut_through = true``) continues through the band edge
and may be at most the cup depth plus a quarter of the band deep (two
cut-through grooves leave at least half the band).  Quadrisects are two
grooves crossing at 90 degrees.  A *short* (decorative) score (``length_mm``)
is a groove of that length centred on the axis, with vertical ends; it must
end inside the face (its footprint inside the outline inset by the land and
the clearance, so its punch bar stays clear of the tip edge) and may be as deep
as a cut-through score.  Each cut is checked against manifold3d
(:func:`tabletcad.tooling.booleans.checked_boolean`).
"""

from __future__ import annotations

import math
from typing import Any

from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakePolygon
from OCP.BRepPrimAPI import BRepPrimAPI_MakePrism
from OCP.gp import gp_Pnt, gp_Vec

from tabletcad.errors import DesignError, GeometryError
from tabletcad.tooling.booleans import boolean, checked_boolean
from tabletcad.tooling.outline import TabletFrame
from tabletcad.tooling.spec import ScoreSpec, check_score_size, groove_width

__all__ = ["groove_profile", "groove_solid", "score_cutter", "apply_scores", "check_score"]

ABOVE_MM = 0.5  # the groove's walls continue this far above the face


def groove_profile(s: ScoreSpec, z_bottom: float, z_top: float) -> list[tuple[float, float]]:
    """Cross-section polygon ``(across, z)`` of a groove whose bottom is at ``z_bottom``,
    opening towards ``z_top`` (above for the top face, below for the bottom face)."""
    sg = 1.0 if z_top > z_bottom else -1.0
    H = abs(z_top - z_bottom)
    t = math.tan(math.radians(0.5 * s.angle_deg))
    if s.profile == "v":
        return [(0.0, z_bottom), (H * t, z_top), (-H * t, z_top)]
    if s.profile == "u":
        r = 0.5 * s.width_mm
        zc = z_bottom + sg * r
        pts = [(r * math.cos(a), zc - sg * r * math.sin(a)) for a in (math.pi * k / 24 for k in range(25))]
        if H > r:
            return [(r, z_top)] + pts + [(-r, z_top)]
        raise DesignError("[[tooling.score]] width_mm", s.width_mm, "must be < 2 x (depth + 0.5 mm) for a U profile", "mm")
    sw = 0.5 * s.slot_width_mm
    sd = s.depth_mm / 3.0
    z1 = z_bottom + sg * sd
    h = H - sd
    return [(-sw, z_bottom), (sw, z_bottom), (sw, z1), (sw + h * t, z_top), (-sw - h * t, z_top), (-sw, z1)]


def groove_solid(profile: list[tuple[float, float]], direction_deg: float, length: float):
    """Prism of ``profile`` (in the plane across ``direction_deg`` through the axis), ``length`` long, centred."""
    th = math.radians(direction_deg)
    d = (math.cos(th), math.sin(th))
    n = (-math.sin(th), math.cos(th))
    poly = BRepBuilderAPI_MakePolygon()
    for s_, z in profile:
        poly.Add(gp_Pnt(-0.5 * length * d[0] + s_ * n[0], -0.5 * length * d[1] + s_ * n[1], z))
    poly.Close()
    face = BRepBuilderAPI_MakeFace(poly.Wire(), True).Face()
    return BRepPrimAPI_MakePrism(face, gp_Vec(length * d[0], length * d[1], 0.0)).Shape()


def _check_short(frame: TabletFrame, s: ScoreSpec, i: int) -> None:
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut

    from tabletcad.cad._occ import explore
    from tabletcad.tooling.outline import face_area, plan_face
    from tabletcad.tooling.spec import SHORT_SCORE_MARGIN_MM

    th = math.radians(s.direction_deg)
    d, n = (math.cos(th), math.sin(th)), (-math.sin(th), math.cos(th))
    a, b = 0.5 * s.length_mm, 0.5 * groove_width(s)
    poly = BRepBuilderAPI_MakePolygon()
    for u, v in ((-a, -b), (a, -b), (a, b), (-a, b)):
        poly.Add(gp_Pnt(u * d[0] + v * n[0], u * d[1] + v * n[1], 0.0))
    poly.Close()
    foot = BRepBuilderAPI_MakeFace(poly.Wire(), True).Face()
    inset = max(frame.edge_land(f) for f in s.face_list) + SHORT_SCORE_MARGIN_MM
    outside = sum(face_area(f) for f in explore(BRepAlgoAPI_Cut(foot, plan_face(frame.offset(-inset))).Shape(),
                                                  "Face"))
    if outside > 1e-9:
        raise DesignError(f"[[tooling.score]] {i} length_mm", s.length_mm,
                          f"the short score must end on the face: its {2 * a:.3g} x {2 * b:.3g} mm footprint leaves the "
                          f"outline inset by the land + 0.05 mm ({inset:.3g} mm)", "mm")


def check_score(frame: TabletFrame, s: ScoreSpec, i: int = 0) -> None:
    """Raise :class:`DesignError` if the score is deeper than the cup (and band) allow, wider at the face than half
    the tablet (:func:`~tabletcad.tooling.spec.check_score_size`) or, a short one, does not end on the face."""
    check_score_size(s, i, {"top": frame.cup_depth_top, "bottom": frame.cup_depth_bottom}, frame.band,
                     0.5 * min(frame.length, frame.width))
    if s.length_mm is not None:
        _check_short(frame, s, i)


def score_footprints(frame: TabletFrame, s: ScoreSpec) -> list:
    """Plan faces (z = 0) of the score's grooves at the face: each its width at the face (:func:`groove_width`)
    across and its length along (a full score: across the whole tablet); two for a quadrisect."""
    from tabletcad.tooling.outline import plan_face, polyline_wire

    length = 2.0 * max(frame.length, frame.width) + 4.0 if s.length_mm is None else s.length_mm
    a, b = 0.5 * length, 0.5 * groove_width(s)
    out = []
    for deg in (s.direction_deg,) if s.kind == "bisect" else (s.direction_deg, s.direction_deg + 90.0):
        th = math.radians(deg)
        d, n = (math.cos(th), math.sin(th)), (-math.sin(th), math.cos(th))
        out.append(plan_face(polyline_wire([(sa * a * d[0] + sb * b * n[0], sa * a * d[1] + sb * b * n[1])
                                            for sa, sb in ((-1, -1), (1, -1), (1, 1), (-1, 1))])))
    return out


def score_cutter(frame: TabletFrame, s: ScoreSpec, face: str):
    """The solid removed by score ``s`` on ``face`` (one groove, or two fused for a quadrisect)."""
    length = 2.0 * max(frame.length, frame.width) + 4.0 if s.length_mm is None else s.length_mm
    if face == "top":
        zb = frame.z_max - s.depth_mm
        zt = frame.z_max + ABOVE_MM
    else:
        zb = frame.z_min + s.depth_mm
        zt = frame.z_min - ABOVE_MM
    prof = groove_profile(s, zb, zt)
    cutter = groove_solid(prof, s.direction_deg, length)
    if s.kind == "quadrisect":
        cutter = boolean("fuse", cutter, groove_solid(prof, s.direction_deg + 90.0, length), what="quadrisect cutter")
    return cutter


def apply_scores(frame: TabletFrame, shape, scores, *, check: bool = True, deflection: float = 0.005,
                 a_manifold=None) -> tuple[Any, list, list[dict]]:
    """Cut every score from ``shape``; returns ``(solid, Boolean checks, per-score info)``."""
    checks, infos = [], []
    for i, s in enumerate(scores):
        check_score(frame, s, i)
        for face in s.face_list:
            cutter = score_cutter(frame, s, face)
            try:
                shape, chk = checked_boolean("cut", shape, cutter, what=f"score {i} ({s.kind}, {face})",
                                             deflection=deflection, check=check, a_manifold=a_manifold)
            except GeometryError as exc:
                raise GeometryError(f"score {i} on the {face} face: {exc}", exc.obj) from None
            a_manifold = None
            if chk is not None:
                checks.append(chk)
            infos.append(dict(index=i, kind=s.kind, profile=s.profile, face=face, depth_mm=s.depth_mm,
                              width_at_face_centre_mm=groove_width(s), angle_deg=s.angle_deg, cut_through=s.cut_through,
                              length_mm=s.length_mm,
                              direction_deg=s.direction_deg,
                              removed_mm3=None if chk is None else chk.occ_change_mm3))
    return shape, checks, infos
