"""The ``[tooling]`` table of a design file, checked key by key.

::

    [tooling]
    clearance_mm = 0.025           # radial clearance, punch tip to die bore (>= 0)
    tip_length_mm = 8.0            # punch tip length above (below) the tip edge
    die_outer_diameter_mm = 30.16  # die outer diameter
    die_height_mm = 22.22          # die height
    taper_deg = 0.0                # die bore taper above the tablet, degrees (0 = straight)
    gap_mm = 2.8                   # distance between the punch tip edges; default: closed (= band)
    standard = "TSM"               # complete punches: "TSM" | "EU" | "custom" (absent: punch tips only)
    type = "B"                     # "B" | "D" (TSM and EU; see tabletcad/data/tooling_standards.toml)
    lower_tip_length_mm = 25.4     # lower punch tip length (default: tip_length_mm); with complete
                                   # punches longer than the die is high (ejection)
    allowed_tip_pressure_MPa = 300.0          # tip-force rating F = p x tip area; needs its source:
    allowed_tip_pressure_source = "..."       # (no allowed pressure is bundled)
    punch_youngs_modulus_MPa = 210000.0       # tip buckling (Euler); needs its source:
    punch_youngs_modulus_source = "..."

    [tooling.fe_rating]            # tip-force rating by the FE punch analysis as well (tabletcad.fe.punch;
    steel = "S7_tempered_205C"     # needs the fe extra): a steel of tabletcad/data/tool_steels.toml, or
                                   # yield_stress_MPa = 1450.0 with yield_stress_source = "..."
    safety_factor = 1.5            # divides the yield stress and the buckling force
    punch = "upper"                # "upper" | "lower" | "both"
    mesh_size_mm = 0.5             # element size (default: tip width/8, as tabletcad fe punch)

    [tooling.drawing]              # title block and tolerances of the drawings
    name = "Example 10 mm"         # name, number, revision, material, date, author: strings
    tolerance_mm = 0.076           # general +- tolerance (default 0.076 mm, stated on the sheet)
    tolerances = { cup_depth = 0.05 }   # per dimension: diameter, length, width, band, cup_depth, thickness,
                                   # land, score_depth, cup_radius, bevel_width, bevel_angle (deg);
                                   # overall_length, tip_length,
                                   # barrel_diameter, head_diameter, die_diameter, die_height; the fit's
                                   # working_length, tip_diameter, bore_diameter (bore and tips default
                                   # one-sided, +t/0 and 0/-t with t <= the clearance: DrawingSpec.deviations)

    [tooling.punch]                # body dimensions the standard file does not hold (see standards.py)
    head_diameter_mm = 25.4        # ... every key of tabletcad.tooling.standards.BODY_KEYS

    [[tooling.score]]              # bisect or quadrisect score
    kind = "bisect"                # "bisect" | "quadrisect"
    profile = "v"                  # "v" | "u" | "pressure_sensitive"
    depth_mm = 0.3
    angle_deg = 90.0               # included angle of a V (or of the V above a pressure-sensitive slot)
    width_mm = 0.0                 # U width (also an alternative to angle_deg for a V)
    cut_through = false            # true: the groove runs out through the band edge
    faces = "top"                  # "top" | "bottom" | "both"
    direction_deg = 90.0           # groove direction in plan, from the x axis
    length_mm = 4.0                # short (decorative) score: groove length, centred; default: across the face

    [[tooling.emboss]]             # text or a logo outline, debossed (cut) or embossed (raised)
    text = "A10"                   # or: outline = [[x, y], ...] (closed polyline, mm), or svg = "logo.svg"
    mode = "deboss"                # "deboss" | "emboss"
    face = "top"                   # "top" | "bottom"
    height_mm = 2.0                # font size (text)
    depth_mm = 0.15                # depth (deboss) or height (emboss), along the face normal
    projection = "normal"          # "normal": depth along the local face normal | "axial": along the axis
    stroke_angle_deg = 0.0         # stroke angle: draft of the letter walls from the axis, 0 <= . < 60
                                   # (``draft_deg`` is accepted as the same key)
    font = "DejaVuSans-Bold"       # a DejaVu font name or a .ttf path
    position_mm = [0.0, 0.0]
    rotation_deg = 0.0
    margin_mm = 0.2                # required distance from the punch tip edge
"""

from __future__ import annotations

import copy
import datetime
import math
from dataclasses import dataclass, field, replace
from functools import lru_cache
from pathlib import Path
from typing import Any

from tabletcad.errors import MISSING, DesignError, check_finite, check_positive, check_range, format_bound
from tabletcad.tolerance import DEFAULT
from tabletcad.tolerance import (MAX_MODULUS_MPA, MAX_YIELD_MPA, MIN_PUNCH_MODULUS_MPA, MIN_TIP_PRESSURE_MPA,
                                 MIN_YIELD_MPA)
from tabletcad.tooling.polygon import polygon_problem
from tabletcad.tooling.standards import PunchBody, resolve_body

__all__ = ["ToolingSpec", "ScoreSpec", "EmbossSpec", "FeRatingSpec", "parse_tooling", "FONT_DIR", "font_path"]

FONT_DIR = Path("/usr/share/fonts/truetype/dejavu")

#: the narrowest V of a score (deg): a narrower one is a knife edge on the punch's score bar (a 2 deg V
#: had failed in the mesh check, "NotManifold", rather than as an input)
MIN_SCORE_ANGLE_DEG = 20.0

#: the largest radial clearance between punch tip and die bore (mm)
MAX_CLEARANCE_MM = 1.0

#: smallest outward offset (mm) of a die bore: OCCT's planar offset returns no wire for distances near
#: its confusion tolerance (1.1e-7 mm gave none, 5e-7 mm works), so a band bulge below this is cleared
#: by this much instead (far below any die-bore tolerance)
MIN_BORE_OFFSET_MM = 1e-6


def bore_offset(overhang_mm: float) -> float:
    """How far (mm) a die bore stands outside the tablet's outline for a plan ``overhang_mm`` beyond it (a PDE
    band's bulge, a dome's overhang): the overhang, at least :data:`MIN_BORE_OFFSET_MM`; 0 without one."""
    return max(overhang_mm, MIN_BORE_OFFSET_MM) if overhang_mm > 0 else 0.0


def tip_inset(clearance_mm: float, bore_offset_mm: float) -> float:
    """How far (mm) the punch tips' walls stand inside the outline for a radial clearance to a bore
    ``bore_offset_mm`` outside it: the tips follow the bore, so the punch-to-die clearance is the one asked
    for (tips cut from the outline had left 0.0275 mm for 0.025 on a thesis tablet); never negative (a
    clearance below the bore's offset leaves the tips on the outline)."""
    return max(clearance_mm - bore_offset_mm, 0.0)

#: the least steel (mm) a punch tip keeps behind the deepest point of its face (the cup's, or a raised
#: figure's engraving in it): a 0.9 mm tip on a 0.9 mm cup had been built with nothing behind the cup's centre
MIN_TIP_BACKING_MM = 1.0

#: a cup shallower than this (mm) is a flat face (a flat face's cup depth is the round-off of its heights)
FLAT_FACE_MM = 1e-9

#: how near (mm) a tip's measured edge must lie to the band's edge to be taken as the band's edge (OCC's
#: optimal box is good to ~1e-7 mm: a land's edge is the band's)
EDGE_SNAP_MM = 1e-6

#: how far (mm) a standard score's groove stays shallower than its cup: it runs out on the face
RUN_OUT_MARGIN_MM = 0.005


def band_heights(tablet: Any) -> tuple[float, float]:
    """The (bottom, top) heights (mm) of the band of ``tablet`` (a :class:`~tabletcad.geometry.tablet.Tablet`), the
    cylindrical side wall the die forms: an industry family's nominal ``band_z``, else the band patch the tablet
    finds (:meth:`~tabletcad.geometry.tablet.Tablet.band`).  A :class:`DesignError` for a tablet with none (a
    sphere, a spheroid): no pair of punches in a die makes it."""
    band_z = getattr(tablet.nominal, "band_z", None)
    if band_z is None:
        found = tablet.band()
        band_z = None if found is None else (found.z0, found.z1)
    if band_z is None or not band_z[1] - band_z[0] > 1e-6:
        raise DesignError("[tooling]", tablet.family,
                          "tooling needs a tablet with a band (a cylindrical side wall the die forms); this one has none")
    return float(band_z[0]), float(band_z[1])


def groove_width(s: ScoreSpec) -> float:
    """The score's groove width at the face (mm) where it is ``depth_mm`` deep."""
    t = math.tan(math.radians(0.5 * s.angle_deg))
    return {"v": 2 * s.depth_mm * t, "u": s.width_mm,
            "pressure_sensitive": s.slot_width_mm + 2 * (2 * s.depth_mm / 3) * t}[s.profile]


def check_clearance(spec: ToolingSpec, narrow: float, bore_offset_mm: float) -> None:
    """The punch tips, inset by the clearance (:func:`tip_inset`), keep at least half the tablet's ``narrow``
    (mm) plan width; a :class:`DesignError` naming ``clearance_mm`` else."""
    if not tip_inset(spec.clearance_mm, bore_offset_mm) <= 0.25 * narrow:  # (a trial: 1 mm on a 2 mm round failed in
        # OCC's offset of the outline by -3.54 mm, a figure of its own scaling; 0.7 mm on 1.5 mm built a 0.1 mm tip)
        raise DesignError("[tooling] clearance_mm", spec.clearance_mm,
                          f"must leave the punch tips at least half the tablet's {narrow:.4g} mm width: at most "
                          f"{0.25 * narrow - tip_inset(0.0, bore_offset_mm):.4g} mm", "mm")


def check_gap(spec: ToolingSpec, band: float) -> None:
    """The punch gap is at least the ``band`` (mm), the closed position; a :class:`DesignError` else."""
    if spec.gap_mm is not None and spec.gap_mm < band - 1e-9:
        raise DesignError("[tooling] gap_mm", spec.gap_mm, f"must be >= the band {band:.4g} mm (the closed position)", "mm")


def check_score_size(s: ScoreSpec, i: int, cups: dict[str, float], band: float, room: float) -> None:
    """Score ``i``'s depth against the cup depth of each face it is on (``cups``: face -> mm) and the ``band``,
    and its width at the face against ``room`` (mm, half the tablet's plan width); a :class:`DesignError` else."""
    w = f"[[tooling.score]] {i} depth_mm"
    for face in s.face_list:
        cup = cups[face]
        if s.cut_through or s.length_mm is not None:
            limit = cup + 0.25 * band
            if s.depth_mm > limit:
                raise DesignError(w, s.depth_mm, f"must be <= cup depth + band/4 = {limit:.4g} mm on the {face} face "
                                  "(a cut-through or short score must leave half the band)", "mm")
        elif s.depth_mm > cup - RUN_OUT_MARGIN_MM:
            if cup < FLAT_FACE_MM:  # (a flat face's cup is its round-off, 8.9e-16 mm had been quoted as the bound)
                raise DesignError(w, s.depth_mm, f"a standard score runs out in a cup and the {face} face is flat; set "
                                  f"cut_through = true to cut it across the face, at most band/4 = {0.25 * band:.4g} mm "
                                  "deep", "mm")
            raise DesignError(w, s.depth_mm, f"must be < the {face} cup depth {cup:.4g} mm minus {RUN_OUT_MARGIN_MM} mm "
                              "(a standard score runs out on the face; set cut_through = true to cut the band)", "mm")
    if groove_width(s) >= room:  # (a depth within its bounds): a V of 179.9 deg was a 687 mm wide "score"
        _refuse_wide(s, i, room)


def _refuse_wide(s: ScoreSpec, i: int, room: float) -> None:
    """DesignError naming what makes the groove at least ``room`` mm wide at the face, with its own limit:
    a U's width, a V's angle, a pressure-sensitive groove's slot (when it alone is too wide) or angle."""
    w = f"[[tooling.score]] {i}"
    flank = {"v": s.depth_mm, "pressure_sensitive": 2.0 * s.depth_mm / 3.0}.get(s.profile)  # a flank's depth
    if s.profile == "u" or (s.profile == "pressure_sensitive" and s.slot_width_mm >= room):
        key = "width_mm" if s.profile == "u" else "slot_width_mm"
        raise DesignError(f"{w} {key}", getattr(s, key), f"must be < {room:.4g} mm, half the tablet's width (the "
                          "groove's width at the face)", "mm")
    slot = s.slot_width_mm if s.profile == "pressure_sensitive" else 0.0
    most = 2.0 * math.degrees(math.atan(0.5 * (room - slot) / flank))
    raise DesignError(f"{w} angle_deg", s.angle_deg, f"must be < {most:.4g} deg: the groove, {groove_width(s):.4g} mm "
                      f"wide at the face, must be narrower than half the tablet's width, {room:.4g} mm", "deg")


def check_emboss_depth(e: EmbossSpec, i: int, cup: float, band: float) -> None:
    """Figure ``i``, debossed into the tablet or raised on it (cut as deep into the punch), is at most its face's
    ``cup`` depth + a quarter of the ``band`` (mm) deep; a :class:`DesignError` else."""
    limit = cup + 0.25 * band
    if e.depth_mm > limit:
        raise DesignError(f"[[tooling.emboss]] {i} depth_mm", e.depth_mm, f"must be <= cup depth + band/4 = {limit:.4g} mm",
                          "mm")


def check_tip_lengths(spec: ToolingSpec, cups: dict[str, float]) -> None:
    """Each tip at least as long as its face is deep (the cup, ``cups``: face -> mm, and a raised figure's
    engraving) plus :data:`MIN_TIP_BACKING_MM`; a :class:`DesignError` else."""
    for name, tl, face in (("tip_length_mm", spec.tip_length_mm, "top"), ("lower_tip_length_mm", spec.lower_tip, "bottom")):
        cup = cups[face]
        raised = max((e.depth_mm for e in spec.emboss if e.face == face and e.mode == "emboss"), default=0.0)
        need = cup + raised + MIN_TIP_BACKING_MM
        if not tl >= need:
            raise DesignError(f"[tooling] {name}", tl, f"must be >= {need:.4g} mm: the {face} face is {cup + raised:.4g} mm "
                              f"deep and the tip keeps {MIN_TIP_BACKING_MM:g} mm of steel behind it", "mm")


def check_numbers(spec: ToolingSpec, *, band_z: tuple[float, float], z_range: tuple[float, float], length: float,
                  width: float, bore_offset_mm: float) -> None:
    """Every check of ``spec`` against the tablet that needs only its numbers (mm: the band's heights ``band_z``,
    its lowest and highest points ``z_range``, its plan ``length`` and ``width``, the die bore's offset), in the
    order the tooling meets them: the clearance, the gap, each score's depth and width, each figure's depth, the
    tips' lengths.  :func:`check_on_tablet` runs it on the PDE tablet before any geometry (``report``,
    ``build``, a sweep's rows), :func:`tabletcad.tooling.toolset.check_on_frame` on the solid's frame."""
    band = band_z[1] - band_z[0]
    cups = {"top": z_range[1] - band_z[1], "bottom": band_z[0] - z_range[0]}
    check_clearance(spec, min(length, width), bore_offset_mm)
    check_gap(spec, band)
    room = 0.5 * min(length, width)
    for i, s in enumerate(spec.scores):
        check_score_size(s, i, cups, band, room)
    for i, e in enumerate(spec.emboss):
        check_emboss_depth(e, i, cups[e.face], band)
    check_tip_lengths(spec, cups)


def check_on_tablet(tablet: Any, spec: ToolingSpec) -> None:
    """:func:`check_numbers` on the PDE ``tablet`` (a :class:`~tabletcad.geometry.tablet.Tablet`): its band
    (:func:`band_heights`: a tablet without one is refused), its extents and plan overhang, which are the
    tooling frame's (:func:`tabletcad.tooling.outline.tablet_frame`); then whether each figure fits its face
    (:func:`check_figures_on_tablet`).  No solid is built."""
    band_z = band_heights(tablet)
    lo, hi = tablet.bounds()
    overhang = tablet.plan_overhang() if tablet.band() is not None else 0.0
    z_range = (float(lo[2]), float(hi[2]))
    check_numbers(spec, band_z=band_z, z_range=z_range, length=float(hi[0] - lo[0]),
                  width=float(hi[1] - lo[1]), bore_offset_mm=bore_offset(overhang))
    check_figures_on_tablet(tablet, spec, {"top": z_range[1] - band_z[1], "bottom": band_z[0] - z_range[0]})


def spline_offset_error(outline: Any, distance: float) -> DesignError | None:
    """The refusal of an offset by ``distance`` mm (> 0 outward, < 0 inward) of a spline plan ``outline`` (a
    :class:`~tabletcad.families.outline.SplineOutline`) that is no regular offset of it
    (:meth:`~tabletcad.families.outline.SplineOutline.offset_bound`), naming the outline, else ``None``."""
    bound = outline.offset_bound(distance)
    if bound is None:
        return None
    lim, why = bound
    way = "outward" if distance > 0 else "inward"
    return DesignError("tablet.outline", "points (a spline through them)",
                       f"the tooling offsets it {abs(distance):.4g} mm {way}, beyond its regular offsets that way: at "
                       f"most {format_bound(lim, upper=True)} mm ({why})")


#: how far (mm) a complete punch's relief ring reaches outside its tip (:func:`tabletcad.tooling.punch_body.complete_punch`)
RELIEF_RING_OVERLAP_MM = 0.05

#: how far (mm) inside the face's land a short score's footprint must end (:func:`tabletcad.tooling.scores.check_score`)
SHORT_SCORE_MARGIN_MM = 0.05


def allowed_upper_bound(most: float, accepted: Any) -> str:
    """``most`` as a refusal's upper end (:func:`~tabletcad.errors.format_bound`, rounded down), stepped down
    a unit of its last printed digit while ``accepted`` (a float -> bool) refuses the value printed: the
    value quoted as allowed is then allowed though ``most`` came of a difference in floating point (a
    clearance's bound of a spline outline's offset limit plus the die bore's offset)."""
    text = format_bound(most, upper=True)
    for _ in range(4):
        if accepted(float(text)):
            break
        text = format_bound(math.nextafter(float(text), -math.inf), upper=True)
    return text


def _spline_inward_refusal(outline: Any, parameter: str, value: Any, distance: float, how: str) -> DesignError:
    """The refusal of ``parameter`` (``value`` mm) for which the tooling offsets the spline ``outline``
    ``-distance`` mm inward (``how``: of what), beyond its largest regular inward offset: the largest value
    allowed, said once and accepted (each of these parameters moves the offset by as much as it changes;
    a short score's length does not move it, nor does a margin below 0)."""
    lim, why = outline.offset_bound(distance)
    beyond = f"beyond its largest regular inward offset ({why})"
    if parameter.endswith("length_mm"):  # (a short score: the face inset by its land + the margin, whatever its length)
        return DesignError(parameter, value, f"a short score needs the face inset by {how} = {-distance:.4g} mm, "
                           f"beyond the spline outline's largest regular inward offset ({why}); leave length_mm out "
                           "for a score across the face", "mm")
    most = value - (-distance - lim)
    if most < 0.0:  # (a margin: the clearance and the land alone reach past it)
        return DesignError(parameter, value, f"no margin fits: the clearance and the face's land alone offset the "
                           f"spline outline {-distance - value:.4g} mm inward, {beyond}", "mm")
    bound = allowed_upper_bound(most, lambda q: outline.offset_bound(distance - (q - value)) is None)
    return DesignError(parameter, value, f"must be <= {bound} mm: the tooling offsets the spline outline "
                       f"{-distance:.4g} mm inward for it ({how}), {beyond}", "mm")


def check_spline_offsets(tablet: Any, spec: ToolingSpec, size: float) -> None:
    """On the design, before any geometry: every offset of a spline plan outline (a custom outline through
    points) that the tooling will build is a regular offset of it
    (:meth:`~tabletcad.families.outline.SplineOutline.offset_bound`: inward within its smallest convex
    radius of curvature and its inscribed radius, outward within its smallest concave one), each refusal
    naming what asks for it: ``clearance_mm`` (the tips), ``tip_relief_mm`` (a complete punch's relieved
    tip), ``taper_deg`` (the bore drafted from the band's top to 1 mm above the die), a figure's ``margin_mm`` (the face it must fit in), a short score's ``length_mm`` (the face inset by
    its land + 0.05 mm), the outline itself (the die bore grown by the band's bulge, the relief ring).
    Nothing for another outline.  ``size``: the tablet's plan diameter (mm,
    :func:`tabletcad.pipeline.designreport.plan_diameter`: the die's height goes by it).  The tooling frame
    builds the same offsets (:meth:`tabletcad.tooling.outline.TabletFrame.offset`) and refuses them alike."""
    from tabletcad.families.outline import SplineOutline
    from tabletcad.families.thesis import NO_LAND

    outline = getattr(tablet.nominal, "outline", None)
    if not isinstance(outline, SplineOutline):
        return
    band_z = band_heights(tablet)
    lo, hi = tablet.bounds()
    bore = bore_offset(tablet.plan_overhang() if tablet.band() is not None else 0.0)
    inset = tip_inset(spec.clearance_mm, bore)
    cups = {"top": float(hi[2]) - band_z[1], "bottom": band_z[0] - float(lo[2])}
    land = dict(getattr(tablet.nominal, "info", {}) or {}).get("land_mm")
    land = 0.0 if land is None and tablet.family in NO_LAND else (land or 0.0)

    def edge_land(face: str) -> float:
        return 0.0 if cups[face] < 1e-9 else float(land)

    clear = "the clearance" + (f" less the die bore's {bore:g} mm outside the outline" if bore > 0 else "")
    asks: list[tuple[str, Any, float, str]] = [("[tooling] clearance_mm", spec.clearance_mm, -inset, clear)]
    b = spec.body
    if b is not None and b.tip_relief_mm > 0 and max(spec.tip_length_mm, spec.lower_tip) > b.tip_straight_mm:
        asks += [("[tooling.punch] tip_relief_mm", b.tip_relief_mm, -(spec.clearance_mm + b.tip_relief_mm),
                  "clearance + tip relief"),
                 ("tablet.outline", "points (a spline through them)", RELIEF_RING_OVERLAP_MM - inset, "")]
    asks.append(("tablet.outline", "points (a spline through them)", bore, ""))
    if spec.taper_deg > 0:  # the bore drafted from the band's top to 1 mm above the die (die_faces_z: the entry)
        rise = die_faces_z(band_z, die_height_for(spec, size, True))[0] + 1.0
        top = bore + rise * math.tan(math.radians(spec.taper_deg))
        bound = outline.offset_bound(top)
        if bound is not None:
            most = allowed_upper_bound(math.degrees(math.atan((bound[0] - bore) / rise)), lambda q: outline.offset_bound(
                bore + rise * math.tan(math.radians(q))) is None)
            raise DesignError("[tooling] taper_deg", spec.taper_deg, f"must be <= {most} deg: "
                              f"the die bore drafted over {rise:.4g} mm grows {top:.4g} mm outward, at most "
                              f"{format_bound(bound[0], upper=True)} mm ({bound[1]})", "deg")
    asks += [(f"[[tooling.emboss]] {i} margin_mm", e.margin_mm, -(spec.clearance_mm + edge_land(e.face) + e.margin_mm),
              "clearance + land + margin") for i, e in enumerate(spec.emboss)]
    asks += [(f"[[tooling.score]] {i} length_mm", s.length_mm,
              -(max(edge_land(f) for f in s.face_list) + SHORT_SCORE_MARGIN_MM), f"its land + {SHORT_SCORE_MARGIN_MM:g} mm")
             for i, s in enumerate(spec.scores) if s.length_mm is not None]
    for parameter, value, distance, how in asks:
        if outline.offset_bound(distance) is None:
            continue
        if parameter == "tablet.outline":  # (the bore grown by the band's bulge, the relief ring: as the frame says)
            raise spline_offset_error(outline, distance)
        raise _spline_inward_refusal(outline, parameter, value, distance, how)


def tooling_plan_outline(tablet: Any) -> Any:
    """The plan outline (a :class:`~tabletcad.families.outline.PlanOutline` of lines and arcs) that the tooling
    frame (:func:`tabletcad.tooling.outline.tablet_frame`) makes its wire of: the family's nominal outline, or
    the band's circle or line-and-arc outline; ``None`` where it takes an ellipse or the band's section."""
    from tabletcad.families.outline import PlanOutline, circle_outline
    from tabletcad.geometry.curves import Circle, Outline, Transformed

    outline = getattr(tablet.nominal, "outline", None)
    if outline is not None and getattr(outline, "segs", None):
        return outline
    found = tablet.band()
    if outline is not None or found is None:
        return None
    curve, shift = tablet.patches[found.patch].data[0], [0.0, 0.0]
    while isinstance(curve, Transformed) and all(curve.matrix[i][j] == (i == j) for i in range(2) for j in range(2)) \
            and not any(curve.matrix[i][2] for i in range(2)):  # moved along the axis only: the same plan
        shift, curve = [shift[0] + curve.offset[0], shift[1] + curve.offset[1]], curve.base
    if isinstance(curve, Circle):
        segs = circle_outline(float(curve.radius)).segs
        shift = [shift[0] + curve.center[0], shift[1] + curve.center[1]]
    elif isinstance(curve, Outline):
        segs = curve.segs
    else:
        return None
    return PlanOutline([q.translated(float(shift[0]), float(shift[1])) for q in segs])


def figure_contours(e: EmbossSpec, i: int = 0) -> list | None:
    """The placed plan contours (mm) of figure ``i`` as :func:`tabletcad.tooling.emboss.figure_faces` places its
    faces (:mod:`tabletcad.geometry.lettering`), ``None`` for an SVG logo (read by build123d only); a
    :class:`DesignError` for text that gives no glyphs, as the tooling's."""
    from tabletcad.geometry import lettering

    if e.svg is not None:
        return None
    if e.text is not None:
        contours = lettering.text_contours(e.text, e.height_mm, font_path(e.font, f"[[tooling.emboss]] {i} font"))
    else:
        contours = lettering.polyline_contours(e.outline)
    if not contours:
        raise DesignError(f"[[tooling.emboss]] {i} text", e.text, "gives no glyphs in this font")
    return lettering.placed(contours, e.rotation_deg, e.position_mm, e.face == "bottom")


def inset_face_refusal(e: EmbossSpec, i: int, outline: Any, inset: float, half_width: float | None = None) -> DesignError:
    """The refusal of figure ``i`` whose face, the punch tip inset by ``inset`` mm (clearance + land +
    margin), is no single region: empty (``inset`` at least the ``outline``'s inscribed radius) or parted in
    two at a neck (its inward offsets stay whole up to the neck's half width,
    :func:`~tabletcad.families.outline.whole_inset_limit`), with the margin below which it is one region.
    ``outline``: the :class:`~tabletcad.families.outline.PlanOutline`, or ``None`` where the tooling offsets
    another curve (an ellipse, a band's section): then ``half_width`` (mm, half the tablet's smaller
    extent, at least its inscribed radius) tells an empty face, and a face that is not is called not one
    region."""
    from tabletcad.families.outline import whole_inset_limit

    what = "text" if e.text is not None else "svg" if e.svg is not None else "outline"
    value = e.text if e.text is not None else e.svg if e.svg is not None else f"{len(e.outline)} points"
    head = f"does not fit: the face inset by {inset:.4g} mm (clearance + land + margin)"
    if outline is None:
        empty = half_width is not None and not inset < half_width
        return DesignError(f"[[tooling.emboss]] {i} {what}", value, f"{head} is empty: the tablet is "
                           f"{2.0 * half_width:.4g} mm wide" if empty else f"{head} is not one region (the offset "
                           "of the tablet's outline is not one wire)")
    deep = outline.inscribed_radius()
    if not inset < deep:
        whole, why, keep = deep, f"{head} is empty: the outline's inscribed radius is {deep:.4g} mm", "leave a face"
    else:
        whole = whole_inset_limit(outline, inset)  # (a neck's half width, unless a convex arc's radius stops it first)
        where = f"at a neck {2.0 * whole:.6g} mm wide" if whole < outline.min_convex_radius - 1e-7 else \
            f"where the outline is less than {2.0 * inset:.4g} mm across"
        why, keep = f"{head} parts in two {where}", "keep it one region"
    fixed = inset - e.margin_mm  # (the clearance and the land)
    tail = (f"; a margin_mm < {format_bound(whole - fixed, upper=True)} mm would {keep}" if whole > fixed
            else f"; the clearance and land alone inset it {fixed:.4g} mm: no margin would {keep}")
    return DesignError(f"[[tooling.emboss]] {i} {what}", value, why + tail)


def figure_fit_refusal(e: EmbossSpec, i: int, contours: list, outline: Any, inset: float) -> DesignError | None:
    """The refusal of figure ``i`` (its placed ``contours``) that does not lie inside ``outline`` offset inwards
    by ``inset`` mm (the punch tip less the land and margin), in the words of
    :func:`tabletcad.tooling.emboss.check_fit`, else ``None`` (the figure's size is its exact box, as there)."""
    from tabletcad.geometry import lettering

    what = "text" if e.text is not None else "outline"
    value = e.text if e.text is not None else f"{len(e.outline)} points"
    if not inset < outline.inscribed_radius():
        return inset_face_refusal(e, i, outline, inset)
    area, outside = lettering.outside_area(contours, outline, inset)
    if outside > 1e-6 * max(area, 1e-9):
        w, h = lettering.figure_box(contours)
        return DesignError(f"[[tooling.emboss]] {i} {what}", value,
                           f"does not fit the {e.face} face: {w:.3g} x {h:.3g} mm with {outside:.3g} mm^2 "
                           f"outside the punch tip inset by {inset:.3g} mm (clearance + land + margin); "
                           "use a smaller height_mm or move it")
    return None


def check_figures_on_tablet(tablet: Any, spec: ToolingSpec, cups: dict[str, float]) -> None:
    """Refuse, as the tooling stage would after building the solid (:func:`tabletcad.tooling.emboss.check_emboss`),
    a figure of ``spec`` that does not fit its face: text or a polyline outside the tablet's outline offset
    inwards by the clearance, the face's land and the figure's margin, one whose text gives no glyphs, or one
    whose stroke angle closes its strokes before its depth (:func:`stroke_angle_refusal`).
    Decided on the same curves without OCC (:mod:`tabletcad.geometry.lettering`); ``cups`` (face -> mm) tell
    a flat face (no land).  The stroke angle is decided for every text or polyline figure (it needs no
    outline).  The fit is not decided here (the build still checks it after the solid) for an SVG logo, an
    outline the tooling takes as an ellipse, a spline through points or its band's section, and an inset
    whose offset of the outline crosses itself or parts in two (:func:`fit_is_decided`)."""
    from tabletcad.families.thesis import NO_LAND

    if not spec.emboss:
        return
    outline = tooling_plan_outline(tablet)
    info = dict(getattr(tablet.nominal, "info", {}) or {})
    land = info.get("land_mm")
    if land is None and tablet.family in NO_LAND:
        land = 0.0
    for i, e in enumerate(spec.emboss):
        contours = figure_contours(e, i)
        if contours is None:
            continue
        inset = spec.clearance_mm + (0.0 if cups[e.face] < 1e-9 else (land or 0.0)) + e.margin_mm
        decided = outline is not None and fit_is_decided(outline, inset)
        # the fit first, as the tooling's check_emboss; the stroke angle, which needs no outline, in any case
        refusal = (figure_fit_refusal(e, i, contours, outline, inset) if decided else None) \
            or stroke_angle_refusal(e, i, contours)
        if refusal is not None:
            raise refusal


def fit_is_decided(outline: Any, inset: float) -> bool:
    """Whether :func:`figure_fit_refusal` decides a figure's fit inside ``outline`` (a
    :class:`~tabletcad.families.outline.PlanOutline`) offset inwards by ``inset`` mm as the tooling's OCC
    Boolean does: where that offset bounds the inset region
    (:func:`tabletcad.families.outline.offset_bounds_inset`: the curve the area outside is closed along) or
    at and beyond the outline's inscribed radius (no face left).  Between the two (a convex arc turned inside
    out, a narrow neck whose offset crosses itself or parts in two) the build decides it after the solid."""
    from tabletcad.families.outline import offset_bounds_inset

    return not inset < outline.inscribed_radius() or offset_bounds_inset(outline, inset)


def stroke_angle_refusal(e: EmbossSpec, i: int, contours: list) -> DesignError | None:
    """The refusal of figure ``i`` whose stroke angle closes its strokes before its depth, in the words of
    :func:`tabletcad.tooling.emboss.check_emboss` (the mean stroke width ``2 A / P`` of its placed ``contours``),
    else ``None``."""
    from tabletcad.geometry import lettering

    if not e.draft_deg > 0:
        return None
    width = 2.0 * abs(lettering.figure_area(contours)) / lettering.figure_length(contours)
    if e.depth_mm * math.tan(math.radians(e.draft_deg)) >= 0.5 * width:
        return DesignError(f"[[tooling.emboss]] {i} stroke_angle_deg", e.draft_deg,
                           f"must be < {math.degrees(math.atan(0.5 * width / e.depth_mm)):.3g} deg: the "
                           f"walls of {width:.3g} mm strokes would meet before the depth {e.depth_mm:.3g} mm", "deg")
    return None


#: the die height (mm) beside a given outer diameter when no height is given (a TSM B die's)
DEFAULT_DIE_HEIGHT_MM = 22.22


def die_height_for(spec: ToolingSpec, size_mm: float, shaped: bool) -> float:
    """The die height (mm) a build uses: the given one, else :data:`DEFAULT_DIE_HEIGHT_MM` beside a given outer
    diameter, else the TSM die's (:func:`standard_die_size`) for a tablet ``size_mm`` across (its plan's
    largest extent), round or ``shaped``."""
    if spec.die_height_mm is not None:
        return spec.die_height_mm
    if spec.die_outer_diameter_mm is not None:
        return DEFAULT_DIE_HEIGHT_MM
    return standard_die_size(size_mm, shaped)[1]


def die_faces_z(band_z: tuple[float, float], height: float, penetration: float | None = None) -> tuple[float, float, float]:
    """``(upper punch entry, top z, bottom z)`` (mm) of a die ``height`` mm high at the closed position, the
    tablet's band at ``band_z``: the upper punch enters ``min(3 mm, height / 4)`` unless ``penetration`` is given."""
    pen = min(3.0, 0.25 * height) if penetration is None else penetration
    return pen, band_z[1] + pen, band_z[1] + pen - height


def check_punch_lengths(spec: ToolingSpec, band_z: tuple[float, float], height: float) -> None:
    """Complete punches' tips against a die ``height`` mm high (the tablet's band at ``band_z``, mm): the upper
    tip longer than its entry into the die, the lower one longer than the die (at ejection its edge rises to
    the die's top face and the barrel's shoulder must stay below the die); a :class:`DesignError` else.  Run on
    the PDE tablet before any geometry (``report`` and ``build`` alike) and on the tooling frame."""
    _, top, bottom = die_faces_z(band_z, height)
    need_up = top - band_z[1]
    if spec.tip_length_mm <= need_up:
        raise DesignError("[tooling] tip_length_mm", spec.tip_length_mm,
                          f"must be > {need_up:.4g} mm, the upper punch's entry into the die (the barrel stays out)", "mm")
    need_low = top - bottom
    if spec.lower_tip <= need_low:
        raise DesignError("[tooling] lower_tip_length_mm", spec.lower_tip,
                          f"must be > {need_low:.4g} mm, the die's height: at ejection the lower tip edge rises to "
                          f"the die's top face and the barrel must stay below the die"
                          + ("" if spec.lower_tip_length_mm is not None else
                             " (not given, it is tip_length_mm: give lower_tip_length_mm)"), "mm")


def relief_refused(spec: ToolingSpec, width: float) -> DesignError:
    """The refusal of a complete punch's ``tip_relief_mm`` that leaves no relieved tip outline (the tablet's
    ``width``, mm, quoted)."""
    d = spec.clearance_mm + spec.body.tip_relief_mm
    return DesignError("[tooling.punch] tip_relief_mm", spec.body.tip_relief_mm,
                       f"must leave a relieved tip: the outline offset inwards by the clearance and the relief "
                       f"({d:.4g} mm) leaves no single outline (tablet width {width:.4g} mm)", "mm")


def check_relief_reach(spec: ToolingSpec, narrow: float, width: float) -> None:
    """On the PDE tablet, before any geometry: a relief that, with the clearance, reaches half the tablet's
    narrowest extent ``narrow`` (mm) or more leaves no tip outline (no plan outline is thicker than its narrowest
    extent); :func:`relief_refused` then.  The tooling build checks the exact offset of the outline too."""
    b = spec.body
    if b is None or b.tip_relief_mm <= 0 or max(spec.tip_length_mm, spec.lower_tip) <= b.tip_straight_mm:
        return  # no relief is cut
    if spec.clearance_mm + b.tip_relief_mm >= 0.5 * narrow:
        raise relief_refused(spec, width)


#: TSM die blanks: (outer diameter, height, type), mm; the largest tablet each takes, round and shaped,
#: is the standard's (``max_round_tablet_mm``, ``max_shaped_tablet_mm`` in tabletcad/data/tooling_standards.toml)
TSM_DIES = ((30.16, 22.22, "B"), (38.10, 23.81, "D"))


def tsm_die_limits(kind: str) -> tuple[float, float]:
    """``(largest round, largest shaped)`` tablet (mm) a TSM ``kind`` ("B"/"D") die takes, from the standards file."""
    from tabletcad.tooling.standards import load_standards

    entry = load_standards()["TSM"][kind]
    return float(entry["max_round_tablet_mm"]["value"]), float(entry["max_shaped_tablet_mm"]["value"])


#: how far (mm) a tablet may measure beyond a die type's largest tablet and still be taken as that size: a
#: PDE surface leaves its nominal outline by micrometres (a 19 mm rounded rectangle measured 19.00000088 mm
#: and had been given a D die, a 19 mm capsule a B)
DIE_SIZE_SLACK_MM = 0.01


def standard_die_size(size_mm: float, shaped: bool = False) -> tuple[float, float, str]:
    """``(outer diameter, height, TSM type)`` of the die for a tablet whose largest plan dimension (its extent
    in any direction) is ``size_mm`` (:data:`TSM_DIES`): the smallest type that takes it, round or ``shaped`` (a B die takes
    round tablets up to 16 mm and shaped ones up to 19 mm; :data:`DIE_SIZE_SLACK_MM` beyond a limit is at
    it); a :class:`DesignError` for one larger than a 'D' die takes."""
    for od, h, name in TSM_DIES:
        lim = tsm_die_limits(name)[1 if shaped else 0]
        if size_mm <= lim + DIE_SIZE_SLACK_MM:
            return od, h, name
    raise DesignError("[tooling] die_outer_diameter_mm", MISSING,
                      f"give it for a {'shaped' if shaped else 'round'} tablet {size_mm:.4g} mm across (larger than a "
                      f"TSM 'D' die takes, {lim:g} mm)", "mm")


@dataclass(frozen=True)
class ScoreSpec:
    kind: str = "bisect"
    profile: str = "v"
    depth_mm: float = 0.3
    angle_deg: float = 90.0
    width_mm: float = 0.0
    cut_through: bool = False
    faces: str = "top"
    direction_deg: float = 90.0
    slot_width_mm: float = 0.1
    length_mm: float | None = None

    @property
    def face_list(self) -> tuple[str, ...]:
        return ("top", "bottom") if self.faces == "both" else (self.faces,)


@dataclass(frozen=True)
class EmbossSpec:
    text: str | None = None
    outline: tuple | None = None
    mode: str = "deboss"
    face: str = "top"
    height_mm: float = 2.0
    depth_mm: float = 0.15
    draft_deg: float = 0.0
    font: str = "DejaVuSans-Bold"
    position_mm: tuple[float, float] = (0.0, 0.0)
    rotation_deg: float = 0.0
    margin_mm: float = 0.2
    svg: str | None = None
    projection: str = "normal"


@dataclass(frozen=True)
class FeRatingSpec:
    """``[tooling.fe_rating]``: rate the tips by the FE punch analysis too (:mod:`tabletcad.fe.punch`, the
    same computation as ``tabletcad fe punch``).  The yield stress (MPa) and Young's modulus (MPa) come
    from ``steel`` (tabletcad/data/tool_steels.toml, each with its source) or from ``yield_stress_MPa``
    with its ``yield_stress_source`` (E then 206000 MPa, as ``tabletcad fe punch``)."""

    steel: str | None = None
    yield_stress_MPa: float | None = None
    yield_stress_source: str | None = None
    safety_factor: float = 1.5
    punch: str = "upper"
    mesh_size_mm: float | None = None

    @property
    def punches(self) -> tuple[str, ...]:
        return ("upper", "lower") if self.punch == "both" else (self.punch,)


def steel_names() -> list[str]:
    """The steels of ``tabletcad/data/tool_steels.toml`` (read as data: the FE layer owns their use)."""
    import sys
    from importlib import resources

    if sys.version_info >= (3, 11):
        import tomllib
    else:  # pragma: no cover
        import tomli as tomllib
    text = resources.files("tabletcad").joinpath("data/tool_steels.toml").read_text(encoding="utf-8")
    return list(tomllib.loads(text).get("steel", {}))


#: the range (MPa) of each figure the [tooling] table takes with its source: a tip pressure below any
#: punch steel's yield and from 10 MPa, a punch's Young's modulus of steel or carbide (neither in GPa)
_SOURCED_RANGES = {"allowed_tip_pressure_MPa": (MIN_TIP_PRESSURE_MPA, MAX_YIELD_MPA),
                   "punch_youngs_modulus_MPa": (MIN_PUNCH_MODULUS_MPA, MAX_MODULUS_MPA)}


def _sourced_figure(key: str, value: Any) -> float:
    """``[tooling] allowed_tip_pressure_MPa`` or ``punch_youngs_modulus_MPa`` as a float in its range (MPa)."""
    return check_range(f"[tooling] {key}", value, *_SOURCED_RANGES[key], "MPa")


def _fe_rating(t: Any) -> FeRatingSpec | None:
    w = "[tooling.fe_rating]"
    if t is None:
        return None
    t = _keys(w, t, set(FeRatingSpec.__dataclass_fields__))
    d = FeRatingSpec()
    steel, y = t.get("steel"), t.get("yield_stress_MPa")
    if (steel is None) == (y is None):
        raise DesignError(f"{w} steel", steel if steel is not None else MISSING,
                          "give steel (one of " + ", ".join(steel_names()) + ") or yield_stress_MPa with its "
                          "yield_stress_source: no allowed stress is invented")
    src = t.get("yield_stress_source")
    if steel is not None:
        _choice(f"{w} steel", steel, tuple(steel_names()))
        if src is not None:
            raise DesignError(f"{w} yield_stress_source", src, "give it with yield_stress_MPa (a steel has its own)")
    else:
        # (tabletcad.tolerance.MIN_YIELD_MPA: below any punch steel, as fe punch's --yield-stress; 1.45, a value in
        # GPa, had rated the tips a thousand times too weak)
        y = check_range(f"{w} yield_stress_MPa", y, MIN_YIELD_MPA, MAX_YIELD_MPA, "MPa")
        if not (isinstance(src, str) and src.strip()):
            raise DesignError(f"{w} yield_stress_source", src if src is not None else MISSING,
                              "must name the source of yield_stress_MPa (a non-empty string)")
    mesh = t.get("mesh_size_mm")
    return FeRatingSpec(steel, y, src, check_range(f"{w} safety_factor", t.get("safety_factor", d.safety_factor), 1.0, 100.0),
                        _choice(f"{w} punch", t.get("punch", d.punch), ("upper", "lower", "both")),
                        None if mesh is None else check_positive(f"{w} mesh_size_mm", mesh, "mm"))


#: general +- tolerance (mm) printed on the drawings when the design gives none: 0.003 in, stated on the sheet
#: as this program's default, not as a standard's value
#: the most characters of one embossed text (a tablet face holds a few: "A8 69", a name)
MAX_EMBOSS_CHARS = 40

#: the die's thinnest wall (mm) around its bore: checked against the tablet's plan when the design is read
MIN_DIE_WALL_MM = 2.0

DEFAULT_TOLERANCE_MM = 0.076
TOLERANCE_KEYS = ("diameter", "length", "width", "band", "cup_depth", "thickness", "land", "score_depth", "cup_radius",
                  "bevel_width", "bevel_angle",  # bevel_angle in degrees, the others mm
                  # the punches and die sheet (complete punches)
                  "overall_length", "tip_length", "barrel_diameter", "head_diameter", "die_diameter", "die_height",
                  # the fit: working length (head flat to cup bottom), punch tip and die bore sizes
                  "working_length", "tip_diameter", "bore_diameter")
TITLE_KEYS = ("name", "number", "revision", "material", "date", "author")
#: the most characters a title-block text may have: what fits the A4 sheet's title block in its
#: smallest type (``tabletcad.tooling.drawing.sheet_figure`` shrinks long texts to fit)
TITLE_MAX_CHARS = {"name": 60, "number": 30, "revision": 30, "material": 60, "date": 30, "author": 30}


#: the fit's dimensions: toleranced one-sided by default so that the running clearance survives at the limits
FIT_KEYS = ("bore_diameter", "tip_diameter")


@dataclass(frozen=True)
class DrawingSpec:
    """Title block texts and tolerances (mm) of the drawings (``[tooling.drawing]``).

    ``clearance_mm``: the fit's radial clearance (mm a side), set by :class:`ToolingSpec`: the die bore and
    the punch tips not given a tolerance of their own take one-sided limits from it (:meth:`deviations`).
    """

    name: str | None = None
    number: str | None = None
    revision: str | None = None
    material: str | None = None
    date: str | None = None
    author: str | None = None
    tolerance_mm: float = DEFAULT_TOLERANCE_MM
    tolerance_given: bool = False
    tolerances: tuple = ()
    clearance_mm: float | None = None

    def deviations(self, key: str) -> float | tuple[float, float]:
        """Dimension ``key``'s tolerance (mm): a ``±`` number, or ``(upper, lower)`` limit deviations.

        As given in ``tolerances``, else the general ``tolerance_mm``, but for the fit's bore and tips
        (:data:`FIT_KEYS`) with a known clearance: the bore ``(+t, 0)`` and the tips ``(0, -t)``, ``t`` the
        general tolerance but at most the clearance (the whole general one at a clearance of 0), so that
        the bore's smallest size less the tips' largest leaves at least the nominal clearance a side and
        the largest at most ``t`` more (a ``±`` tolerance on both had let a tip at its largest jam in a
        bore at its smallest).
        """
        given = dict(self.tolerances)
        if key in given or key not in FIT_KEYS or self.clearance_mm is None:
            return given.get(key, self.tolerance_mm)
        t = min(self.tolerance_mm, self.clearance_mm) if self.clearance_mm > 0.0 else self.tolerance_mm
        return (t, 0.0) if key == "bore_diameter" else (0.0, -t)

    def limits(self, key: str) -> tuple[float, float]:
        """``(upper, lower)`` deviations (mm) of dimension ``key`` (a ``±t`` tolerance is ``(t, -t)``)."""
        t = self.deviations(key)
        return t if isinstance(t, tuple) else (t, -t)

    def tolerance(self, key: str) -> float:
        """The largest deviation (mm) dimension ``key`` may have: its ``±`` tolerance, or the larger of its
        limit deviations' sizes."""
        up, lo = self.limits(key)
        return max(abs(up), abs(lo))

    def tolerance_text(self, key: str) -> str:
        """The tolerance of dimension ``key`` as drawn: ``±0.076``, or limit deviations ``+0.000/-0.013``."""
        t = self.deviations(key)
        if isinstance(t, tuple):
            return f"{micrometre_text(t[0], signed=True)}/{micrometre_text(t[1], signed=True)}"
        return f"±{t:.2f}" if t >= 0.1 else f"±{t:.3f}"  # (as the sheets print sizes)

    def fit_clearance(self) -> tuple[float, float] | None:
        """``(least, most)`` punch-to-die clearance (mm a side) the bore's and tips' tolerances allow: the
        nominal clearance plus half of (bore lower - tip upper) and of (bore upper - tip lower); None without
        a clearance."""
        if self.clearance_mm is None:
            return None
        (b_up, b_lo), (t_up, t_lo) = self.limits("bore_diameter"), self.limits("tip_diameter")
        return self.clearance_mm + 0.5 * (b_lo - t_up), self.clearance_mm + 0.5 * (b_up - t_lo)


def micrometre_text(x: float, signed: bool = False) -> str:
    """``x`` (mm) to the micrometre, or to 0.1 µm where that is its size (a 0.0125 mm clearance); with its sign
    (``+0.000``) when ``signed``, as a limit deviation is drawn."""
    x = round(x, 9) + 0.0  # (no -0.000)
    sign = "+" if signed else ""
    text = f"{x:{sign}.3f}"
    return text if abs(float(text) - x) < 1e-9 else f"{x:{sign}.4f}"


def _tolerance(name: str, value: Any, unit: str) -> float | tuple[float, float]:
    """A tolerance as given: a number > 0 (``±``), or limit deviations ``[upper, lower]`` with upper > lower
    (``[0.0, -0.013]``: a punch barrel's fit), each finite and at most :data:`MAX_LIMIT_DEVIATION` in size."""
    if isinstance(value, list):
        if len(value) != 2 or not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in value):
            raise DesignError(name, value, "must be a number > 0 (±) or two limit deviations [upper, lower]")
        up, lo = (float(check_range(name, x, -MAX_LIMIT_DEVIATION, MAX_LIMIT_DEVIATION, unit)) for x in value)
        if not up > lo:
            raise DesignError(name, value, "must be [upper, lower] limit deviations with upper > lower", unit)
        return (up, lo)
    return check_positive(name, value, unit)


#: the largest limit deviation (mm, or deg for bevel_angle) a tolerance may give
MAX_LIMIT_DEVIATION = 10.0


def printable_line(text: str) -> bool:
    """No control, format, private or unassigned character and no line or paragraph separator
    (spaces of every width, such as a no-break space, are text)."""
    import unicodedata

    return not any(unicodedata.category(c)[0] == "C" or unicodedata.category(c) in ("Zl", "Zp") for c in text)


@lru_cache(maxsize=8)
def _charmap(path: str) -> frozenset[int]:
    """The code points the font file ``path`` has a glyph for."""
    from matplotlib.ft2font import FT2Font

    return frozenset(FT2Font(path).get_charmap())


def missing_glyphs(text: str, path: str | Path, where: str = "[[tooling.emboss]] font") -> str:
    """The characters of ``text`` (each once, in order) that the font file ``path`` has no glyph for: not
    those letters would be drawn (matplotlib draws the .notdef glyph, an empty box; OCC's text shape takes a
    fallback system font's glyph where one has the character, cmr10's missing 'Å' came out as another glyph,
    else an empty box).  The plain space needs none.  A file that is no font is a :class:`DesignError` of
    ``where``."""
    try:
        cmap = _charmap(str(path))
    except (RuntimeError, OSError, ValueError):
        raise DesignError(where, str(path), "must be a TrueType/OpenType font file that can be read") from None
    return "".join(dict.fromkeys(c for c in text if c != " " and ord(c) not in cmap))


def drawing_font() -> str:
    """The drawings' font file (matplotlib's DejaVu Sans)."""
    from matplotlib import font_manager

    return font_manager.findfont(font_manager.FontProperties(family="DejaVu Sans"), fallback_to_default=False)


def _drawing(t: Any) -> DrawingSpec:
    w = "[tooling.drawing]"
    t = _keys(w, t, set(TITLE_KEYS) | {"tolerance_mm", "tolerances"})
    kw = {}
    for k in TITLE_KEYS:
        if k in t:
            v = t[k]
            if k == "date" and isinstance(v, datetime.date):  # a TOML date, unquoted (date = 2026-12-01): its
                v = v.isoformat()  # ISO text, as quoted (it had been refused as "must be a non-empty string")
            if not isinstance(v, (str, int, float)) or isinstance(v, bool) or not str(v).strip():
                raise DesignError(f"{w} {k}", v, "must be a non-empty string")
            if not printable_line(str(v)):  # a line break or a NUL would leave its line in the title block
                raise DesignError(f"{w} {k}", v, "must be printable text on one line (no control characters)")
            if len(str(v)) > TITLE_MAX_CHARS[k]:
                raise DesignError(f"{w} {k}", v, f"must be at most {TITLE_MAX_CHARS[k]} characters (the title block's room)")
            missing = missing_glyphs(str(v), drawing_font())
            if missing:
                raise DesignError(f"{w} {k}", v, f"has characters the drawings' font (DejaVu Sans) cannot draw: {missing!r}")
            kw[k] = str(v)
    if "tolerance_mm" in t:
        kw["tolerance_mm"] = check_positive(f"{w} tolerance_mm", t["tolerance_mm"], "mm")
        kw["tolerance_given"] = True
    tol = _keys(f"{w} tolerances", t.get("tolerances", {}), set(TOLERANCE_KEYS))
    kw["tolerances"] = tuple((k, _tolerance(f"{w} tolerances.{k}", v, "deg" if k == "bevel_angle" else "mm"))
                             for k, v in tol.items())
    return DrawingSpec(**kw)


@dataclass(frozen=True)
class ToolingSpec:
    clearance_mm: float = 0.025
    tip_length_mm: float = 8.0
    die_outer_diameter_mm: float | None = None
    die_height_mm: float | None = None  # None: 22.22 mm, or the TSM die table's when no outer diameter is given
    taper_deg: float = 0.0
    gap_mm: float | None = None
    scores: tuple[ScoreSpec, ...] = ()
    emboss: tuple[EmbossSpec, ...] = ()
    extra: dict = field(default_factory=dict)
    body: PunchBody | None = None
    lower_tip_length_mm: float | None = None
    drawing: DrawingSpec = DrawingSpec()
    allowed_tip_pressure_MPa: float | None = None
    allowed_tip_pressure_source: str | None = None
    punch_youngs_modulus_MPa: float | None = None
    punch_youngs_modulus_source: str | None = None
    fe_rating: FeRatingSpec | None = None
    #: ``(table, base folder)`` the spec was parsed from (:func:`parse_tooling`), which :meth:`with_` parses
    #: again with its changes, so that the table's rules between keys hold too
    source: Any = field(default=None, compare=False, repr=False)

    def __post_init__(self) -> None:
        # the [tooling] table's ranges hold however the spec is made: parsed (parse_tooling), built in
        # Python or changed by with_/replace (a negative clearance given so had built punches as wide as
        # the bore); numbers are stored as floats
        for key in _RANGES:
            value = getattr(self, key)
            if value is not None or key in ("clearance_mm", "tip_length_mm", "taper_deg"):
                object.__setattr__(self, key, _in_range(key, value))
        for key in ("allowed_tip_pressure_MPa", "punch_youngs_modulus_MPa"):
            skey = key.replace("_MPa", "_source")
            src = getattr(self, skey)
            if getattr(self, key) is not None:
                object.__setattr__(self, key, _sourced_figure(key, getattr(self, key)))
                if not (isinstance(src, str) and src.strip()):  # no figure without its source (as in the table)
                    raise DesignError(f"[tooling] {skey}", src if src is not None else MISSING,
                                      f"must name the source of {key} (a non-empty string)")
            elif src is not None:
                raise DesignError(f"[tooling] {skey}", src, f"give it together with {key}")
        if not isinstance(self.drawing, DrawingSpec):
            raise DesignError("[tooling.drawing]", self.drawing, "must be a DrawingSpec (parse_tooling makes it from the table)")
        if self.drawing.clearance_mm != self.clearance_mm:  # the fit's default tolerances follow the clearance
            object.__setattr__(self, "drawing", replace(self.drawing, clearance_mm=self.clearance_mm))
        for key, kind, name in (("scores", ScoreSpec, "[[tooling.score]]"), ("emboss", EmbossSpec, "[[tooling.emboss]]")):
            items = getattr(self, key)
            if not isinstance(items, (tuple, list)) or not all(isinstance(x, kind) for x in items):
                raise DesignError(name, items, f"must be a tuple of {kind.__name__} (parse_tooling makes them from tables)")
            object.__setattr__(self, key, tuple(items))

    @property
    def lower_tip(self) -> float:
        """The lower punch's tip length (mm)."""
        return self.tip_length_mm if self.lower_tip_length_mm is None else self.lower_tip_length_mm

    def with_(self, **kw: Any) -> "ToolingSpec":
        """A copy with fields replaced (``clearance_mm=0.03``), checked as the ``[tooling]`` table is: a spec
        parsed from a table (:func:`parse_tooling`) changed only in the table's own keys is that table with
        them changed, parsed again (a standard punch's tip length is checked against its body; ``None``
        takes a key's default); any other change is range-checked (:meth:`__post_init__`)."""
        if self.source is not None and kw and set(kw) <= _TABLE_FIELDS:
            table, base = self.source
            return parse_tooling({k: v for k, v in {**table, **kw}.items() if v is not None}, base=base)
        return replace(self, **kw, source=None)


#: a punch-to-die clearance (mm a side) above which a build warns
WIDE_CLEARANCE_MM = 0.1


def fit_warnings(spec: ToolingSpec) -> list[str]:
    """What a build warns of in the punch-to-die fit, one line each, for stderr and the drawings' notes: a
    clearance of 0 (line to line) or wider than :data:`WIDE_CLEARANCE_MM` a side, and bore and tip
    tolerances (``[tooling.drawing] tolerances``) that let a tip at its largest meet a bore at its smallest
    (:meth:`DrawingSpec.fit_clearance`)."""
    out = []
    c = spec.clearance_mm
    if c == 0.0:  # allowed (a model of the nominal fit), but no punch runs in its die so
        out.append("clearance_mm = 0: the punch tips fit the die bore line to line, with no running clearance "
                   "(presses use about 0.01-0.05 mm a side); the parts model the nominal fit")
    elif c > WIDE_CLEARANCE_MM:  # (1 mm a side had been built without a word)
        out.append(f"clearance_mm = {c:g}: wider than {WIDE_CLEARANCE_MM:g} mm a side (presses use about "
                   "0.01-0.05 mm): powder flashes into the gap and the tablet's band edge gets a burr")
    d = spec.drawing
    least, _ = d.fit_clearance()
    if least < -1e-9 or (c > 1e-9 and least < 1e-9):  # (a ±0.076 bore and tips: a 9.960 tip could be 10.036)
        bound = f"above {-2.0 * c:g} mm (twice the clearance)" if c > 0.0 else "at least 0"
        out.append(f"the fit's tolerances can close the {c:g} mm clearance: a tip at its largest in a bore at its "
                   f"smallest leaves {least:.4g} mm a side (bore {d.tolerance_text('bore_diameter')}, tips "
                   f"{d.tolerance_text('tip_diameter')}); [tooling.drawing] tolerances.bore_diameter's lower deviation "
                   f"less tolerances.tip_diameter's upper one must be {bound}, such as [0.01, 0.0] and [0.0, -0.01]")
    return out


#: the [tooling] table's numbers and their ranges, for the table (parse_tooling) and every ToolingSpec alike;
#: steel longer than a metre is no tablet tooling (1e300 reached OCC as a zero vector)
_RANGES = {"clearance_mm": dict(lo=0.0, hi=MAX_CLEARANCE_MM), "tip_length_mm": dict(lo=0.0, hi=DEFAULT.max_length, lo_open=True),
           "die_outer_diameter_mm": dict(lo=0.0, hi=DEFAULT.max_length, lo_open=True),
           "die_height_mm": dict(lo=0.0, hi=DEFAULT.max_length, lo_open=True),
           "taper_deg": dict(lo=0.0, hi=10.0, hi_open=True), "gap_mm": dict(lo=0.0, hi=DEFAULT.max_length, lo_open=True),
           "lower_tip_length_mm": dict(lo=0.0, hi=DEFAULT.max_length, lo_open=True)}


def _in_range(key: str, value: Any) -> float:
    """``float(value)`` of the [tooling] number ``key`` within :data:`_RANGES`, else a :class:`DesignError`."""
    return check_range(f"[tooling] {key}", value, unit="deg" if key.endswith("_deg") else "mm", **_RANGES[key])


#: the ToolingSpec fields that are keys of the [tooling] table of the same meaning (see ToolingSpec.with_)
_TABLE_FIELDS = frozenset({"clearance_mm", "tip_length_mm", "die_outer_diameter_mm", "die_height_mm", "taper_deg",
                           "gap_mm", "lower_tip_length_mm", "allowed_tip_pressure_MPa", "allowed_tip_pressure_source",
                           "punch_youngs_modulus_MPa", "punch_youngs_modulus_source"})


def _keys(where: str, table: Any, allowed: set[str]) -> dict:
    if not isinstance(table, dict):
        raise DesignError(where, table, "must be a table")
    for k in table:
        if k not in allowed:
            raise DesignError(f"{where} key {k!r}", table[k], f"allowed keys are {', '.join(sorted(allowed))}")
    return table


def _choice(where: str, value: Any, options: tuple[str, ...]) -> str:
    if value not in options:
        raise DesignError(where, value, f"must be one of {', '.join(repr(o) for o in options)}")
    return value


def _bool(where: str, value: Any) -> bool:
    if not isinstance(value, bool):
        raise DesignError(where, value, "must be true or false")
    return value


def font_path(font: str, where: str = "[[tooling.emboss]] font") -> Path:
    """A ``.ttf`` file: a path, or a DejaVu font name (``"DejaVuSans-Bold"``); ``where`` names the key."""
    if not isinstance(font, str) or not font.strip():
        raise DesignError(where, font, "must be a font name or the path of a .ttf/.otf file (a string)")
    p = Path(font)
    if p.suffix.lower() in (".ttf", ".otf") and p.is_file():
        return p
    q = FONT_DIR / f"{font}.ttf"
    if q.is_file():
        return q
    names = sorted(x.stem for x in FONT_DIR.glob("*.ttf")) if FONT_DIR.is_dir() else []
    raise DesignError(where, font, f"must be a .ttf path or one of {', '.join(names[:8]) or 'the DejaVu fonts (not installed)'}...")


def _score(i: int, t: Any) -> ScoreSpec:
    w = f"[[tooling.score]] {i}"
    d = ScoreSpec()
    t = _keys(w, t, set(ScoreSpec.__dataclass_fields__))
    kind = _choice(f"{w} kind", t.get("kind", d.kind), ("bisect", "quadrisect"))
    profile = _choice(f"{w} profile", t.get("profile", d.profile), ("v", "u", "pressure_sensitive"))
    depth = check_positive(f"{w} depth_mm", t.get("depth_mm", d.depth_mm), "mm")
    angle = check_range(f"{w} angle_deg", t.get("angle_deg", d.angle_deg), MIN_SCORE_ANGLE_DEG, 180.0, "deg",
                        hi_open=True)
    width = check_range(f"{w} width_mm", t.get("width_mm", d.width_mm), 0.0, None, "mm")
    if profile == "u" and width <= 0:
        raise DesignError(f"{w} width_mm", width, "must be > 0 for a U profile", "mm")
    if profile == "v" and width > 0 and "angle_deg" not in t:
        angle = math.degrees(2.0 * math.atan(0.5 * width / depth))
        if angle < MIN_SCORE_ANGLE_DEG:
            raise DesignError(f"{w} width_mm", width, f"must be >= {2 * depth * math.tan(math.radians(MIN_SCORE_ANGLE_DEG / 2)):.4g}"
                              f" mm for a V {depth:g} mm deep: its angle {angle:.3g} deg is below {MIN_SCORE_ANGLE_DEG:g} deg", "mm")
    slot = check_positive(f"{w} slot_width_mm", t.get("slot_width_mm", d.slot_width_mm), "mm")
    cut = _bool(f"{w} cut_through", t.get("cut_through", d.cut_through))
    length = t.get("length_mm")
    if length is not None:
        length = check_positive(f"{w} length_mm", length, "mm")
        if cut:
            raise DesignError(f"{w} length_mm", length, "a short score cannot be cut_through (it ends on the face)", "mm")
    return ScoreSpec(kind, profile, depth, angle, width, cut,
                     _choice(f"{w} faces", t.get("faces", d.faces), ("top", "bottom", "both")),
                     check_range(f"{w} direction_deg", t.get("direction_deg", d.direction_deg), -360.0, 360.0, "deg"), slot, length)


def _check_svg(where: str, path: str) -> None:
    """DesignError unless ``path`` is well-formed XML with an ``svg`` root element."""
    import xml.etree.ElementTree as ET

    try:
        root = ET.parse(path).getroot()
    except (ET.ParseError, OSError, UnicodeError) as exc:
        raise DesignError(where, path, f"must be a readable SVG file: {exc}") from None
    if root.tag.rsplit("}", 1)[-1] != "svg":
        raise DesignError(where, path, f"must be an SVG file: its root element is <{root.tag}>, not <svg>")


def _emboss(i: int, t: Any, base: Path | None = None) -> EmbossSpec:
    w = f"[[tooling.emboss]] {i}"
    d = EmbossSpec()
    t = _keys(w, t, set(EmbossSpec.__dataclass_fields__) | {"stroke_angle_deg"})
    text, outline, svg = t.get("text"), t.get("outline"), t.get("svg")
    if sum(x is not None for x in (text, outline, svg)) != 1:
        raise DesignError(f"{w} text", text, "give exactly one of text, outline (a closed polyline [[x, y], ...]) or svg "
                          "(a logo file)")
    if svg is not None:
        path = Path(svg) if isinstance(svg, str) else None
        if path is not None and base is not None and not path.is_absolute():
            path = base / path  # relative to the design file's folder
        if path is None or path.suffix.lower() != ".svg" or not path.is_file():
            raise DesignError(f"{w} svg", svg, "must be the path of an existing .svg file"
                              + (f" (relative paths start in the design's folder, {base})" if base is not None else ""))
        svg = str(path)
    if "stroke_angle_deg" in t and "draft_deg" in t:
        raise DesignError(f"{w} draft_deg", t["draft_deg"], "give stroke_angle_deg or draft_deg, not both", "deg")
    stroke = t.get("stroke_angle_deg", t.get("draft_deg", d.draft_deg))
    if text is not None and (not isinstance(text, str) or not text.strip()):
        raise DesignError(f"{w} text", text, "must be a non-empty string")
    if text is not None and not printable_line(text):  # a NUL or a line break is no glyph
        raise DesignError(f"{w} text", text, "must be printable text on one line (no control characters)")
    if text is not None and len(text) > MAX_EMBOSS_CHARS:  # (whether it fits the face is checked on the face)
        raise DesignError(f"{w} text", text, f"must be at most {MAX_EMBOSS_CHARS} characters")
    if outline is not None:
        ok = isinstance(outline, list) and len(outline) >= 3 and all(isinstance(p, list) and len(p) == 2 for p in outline)
        if not ok:
            raise DesignError(f"{w} outline", outline, "must be a list of at least 3 [x, y] points (mm)")
        outline = tuple((check_finite(f"{w} outline", p[0], "mm"), check_finite(f"{w} outline", p[1], "mm")) for p in outline)
        problem = polygon_problem(outline)
        if problem:
            raise DesignError(f"{w} outline", [list(p) for p in outline], f"must be a simple closed polygon: {problem}")
    pos = t.get("position_mm", list(d.position_mm))
    if not (isinstance(pos, list) and len(pos) == 2):
        raise DesignError(f"{w} position_mm", pos, "must be [x, y] in mm")
    big = DEFAULT.max_length
    pos = tuple(check_range(f"{w} position_mm", x, -big, big, "mm") for x in pos)
    font = t.get("font", d.font)
    if text is not None:
        missing = missing_glyphs(text, font_path(font, f"{w} font"), f"{w} font")
        if missing:
            raise DesignError(f"{w} text", text, f"has characters the font {font!r} has no glyph for: {missing!r} "
                              "(the figure cut would not be them: OpenCascade puts another font's glyph or an empty "
                              "box in their place); give a font that has them")
    if svg is not None:
        _check_svg(f"{w} svg", svg)
    return EmbossSpec(
        text, outline,
        _choice(f"{w} mode", t.get("mode", d.mode), ("deboss", "emboss")),
        _choice(f"{w} face", t.get("face", d.face), ("top", "bottom")),
        check_positive(f"{w} height_mm", t.get("height_mm", d.height_mm), "mm"),
        check_positive(f"{w} depth_mm", t.get("depth_mm", d.depth_mm), "mm"),
        check_range(f"{w} stroke_angle_deg", stroke, 0.0, 60.0, "deg", hi_open=True),
        font,
        pos,
        check_finite(f"{w} rotation_deg", t.get("rotation_deg", d.rotation_deg), "deg"),
        check_range(f"{w} margin_mm", t.get("margin_mm", d.margin_mm), 0.0, None, "mm"),
        svg,
        _choice(f"{w} projection", t.get("projection", d.projection), ("normal", "axial")),
    )


def parse_tooling(table: Any, base: Path | None = None) -> ToolingSpec:
    """A :class:`ToolingSpec` from the ``[tooling]`` table (raises :class:`DesignError`).

    ``base``: the folder relative file names (an emboss ``svg``) start in, the design file's
    (default: the current folder).
    """
    d = ToolingSpec()
    keys = {"clearance_mm", "tip_length_mm", "die_outer_diameter_mm", "die_height_mm", "taper_deg", "gap_mm", "score", "emboss",
            "standard", "type", "punch", "lower_tip_length_mm", "drawing", "allowed_tip_pressure_MPa",
            "allowed_tip_pressure_source", "punch_youngs_modulus_MPa", "punch_youngs_modulus_source", "fe_rating"}
    t = _keys("[tooling]", table, keys)
    clearance = _in_range("clearance_mm", t.get("clearance_mm", d.clearance_mm))
    tip = _in_range("tip_length_mm", t.get("tip_length_mm", d.tip_length_mm))
    od = t.get("die_outer_diameter_mm")
    od = None if od is None else _in_range("die_outer_diameter_mm", od)
    height = t.get("die_height_mm")  # given, it is kept (22.22 given was taken for the default and replaced)
    height = None if height is None else _in_range("die_height_mm", height)
    taper = _in_range("taper_deg", t.get("taper_deg", d.taper_deg))
    gap = t.get("gap_mm")
    gap = None if gap is None else _in_range("gap_mm", gap)
    scores = t.get("score", [])
    emb = t.get("emboss", [])
    if not isinstance(scores, list):
        raise DesignError("[[tooling.score]]", scores, "must be an array of tables")
    if not isinstance(emb, list):
        raise DesignError("[[tooling.emboss]]", emb, "must be an array of tables")
    lower = t.get("lower_tip_length_mm")
    lower = None if lower is None else _in_range("lower_tip_length_mm", lower)
    body = None
    if "standard" in t or "type" in t or "punch" in t:
        std = _choice("[tooling] standard", t.get("standard", MISSING), ("TSM", "EU", "custom"))
        kind = None
        if std != "custom":
            kind = _choice("[tooling] type", t.get("type", MISSING), ("B", "D"))
        body = resolve_body(std, kind, t.get("punch"), tip, tip if lower is None else lower)
        if "die_height_mm" not in t:
            raise DesignError("[tooling] die_height_mm", MISSING, "required with complete punches: no citable "
                              "public die height is bundled (tabletcad/data/tooling_standards.toml)", "mm")
        if od is None:
            if body.die_outer_diameter_mm is None:
                raise DesignError("[tooling] die_outer_diameter_mm", MISSING, "required with standard = 'custom'", "mm")
            od = body.die_outer_diameter_mm
        elif body.die_outer_diameter_mm is not None and od != body.die_outer_diameter_mm:
            # (a 27 mm die had gone out on a sheet saying plain "TSM B tooling")
            body = replace(body, modified={**body.modified, "die_outer_diameter_mm": {
                "given": float(od), "standard": float(body.die_outer_diameter_mm)}})
    sourced = {}
    for key in ("allowed_tip_pressure_MPa", "punch_youngs_modulus_MPa"):
        skey = key.replace("_MPa", "_source")
        if key in t:
            sourced[key] = _sourced_figure(key, t[key])
            src = t.get(skey)
            if not (isinstance(src, str) and src.strip()):
                raise DesignError(f"[tooling] {skey}", src if src is not None else MISSING,
                                  f"must name the source of {key} (a non-empty string)")
            sourced[skey] = src
        elif skey in t:
            raise DesignError(f"[tooling] {skey}", t[skey], f"give it together with {key}")
    return ToolingSpec(clearance, tip, od, height, taper, gap,
                       tuple(_score(i, s) for i, s in enumerate(scores)),
                       tuple(_emboss(i, e, base) for i, e in enumerate(emb)), body=body, lower_tip_length_mm=lower,
                       drawing=_drawing(t.get("drawing", {})), fe_rating=_fe_rating(t.get("fe_rating")),
                       source=(copy.deepcopy(dict(t)), base), **sourced)
