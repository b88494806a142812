"""A tablet's complete tooling: featured tablet, punch tips, die and their checks.

:func:`make_tooling` is the one entry point used by the build stage, the
batch API and the benchmarks; it returns a :class:`ToolSet` whose ``report``
is the ``tooling`` section of ``report.json``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

from tabletcad.errors import DesignError
from tabletcad.geometry.tablet import Tablet
from tabletcad.pipeline.designreport import ReportOptions
from tabletcad.tooling.booleans import TIMER, to_manifold, volume
from tabletcad.tolerance import DEFAULT
from tabletcad.tooling.spec import (ToolingSpec, check_numbers, check_punch_lengths, die_height_for, fit_warnings,
                                   relief_refused)

__all__ = ["ToolSet", "make_tooling", "check_closed_position", "finished_solid", "DEFLECTION_MM"]

DEFLECTION_MM = DEFAULT.mesh_deflection


@dataclass(frozen=True, eq=False)
class ToolSet:
    """Solids at the closed position (``parts``: tablet, upper_punch, lower_punch, die; read-only, a
    :class:`~tabletcad.readonly.TableDict`), the upper punch's lift for the chosen gap, and the report section."""

    tablet: Tablet
    spec: ToolingSpec
    frame: Any
    parts: dict
    lift_mm: float
    report: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        from tabletcad.readonly import TableDict

        object.__setattr__(self, "parts", TableDict(self.parts))  # (a part set to None had been taken)

    def placed(self) -> dict:
        """Parts at the press position of ``spec.gap_mm`` (the upper punch lifted by ``lift_mm``)."""
        from tabletcad.tooling.booleans import translated

        out = dict(self.parts)
        if self.lift_mm:
            out["upper_punch"] = translated(out["upper_punch"], dz=self.lift_mm)
        return out


def die_height(frame, spec: ToolingSpec) -> float:
    """The die height (mm) a build uses (:func:`~tabletcad.tooling.spec.die_height_for` of the tablet's plan
    diameter): the given one, else 22.22 mm beside a given outer diameter, else the TSM die table's."""
    return die_height_for(spec, frame.plan_diameter, frame.outline_kind != "circle")


def check_on_frame(frame, spec: ToolingSpec) -> list:
    """Every check of ``spec`` against the tablet (its :func:`~tabletcad.tooling.outline.tablet_frame`) that
    needs no tooling geometry: the gap, the scores, the figures, the tips' lengths, a complete punch's body;
    a :class:`DesignError` before any Boolean.  Returns :func:`~tabletcad.tooling.emboss.check_emboss`'s
    result for each figure."""
    from tabletcad.tooling.emboss import check_emboss
    from tabletcad.tooling.scores import check_score

    # the checks of numbers alone (clearance, gap, scores' and figures' depths, tips' lengths), as
    # tabletcad.tooling.stage.check_tooling runs them on the PDE tablet before any geometry
    check_numbers(spec, band_z=frame.band_z, z_range=(frame.z_min, frame.z_max), length=frame.length,
                  width=frame.width, bore_offset_mm=frame.bore_offset)
    for i, s in enumerate(spec.scores):  # fail on bad input before any Boolean
        check_score(frame, s, i)
    emb_checked = [check_emboss(frame, e, spec.clearance_mm, i) for i, e in enumerate(spec.emboss)]
    _warn_crossings(frame, spec, emb_checked)
    _warn_sharp_edge(frame, spec.clearance_mm)
    import warnings

    for message in fit_warnings(spec):  # (and on the drawings' notes: tabletcad.tooling.drawing)
        warnings.warn(message, stacklevel=3)
    if spec.body is not None:
        _check_complete_punches(frame, spec)
    return emb_checked


def _check_complete_punches(frame, spec: ToolingSpec) -> None:
    """Bad complete-punch input (tablet larger than the barrel or the standard, a tip too short to keep
    the barrel out of the die) as a DesignError, before any tooling geometry is built."""
    from tabletcad.tooling.die import _max_radius
    from tabletcad.tooling.punch_body import check_body_fits

    check_body_fits(frame, spec.body, _max_radius(frame.outline) - frame.tip_inset(spec.clearance_mm))
    if frame.round_radius is None and not spec.body.key:
        import warnings

        warnings.warn("the shaped punch tips have no key: a shaped tip turns in its die bore unless a "
                      "key in the barrel holds it; set key = true with key_* in [tooling.punch]", stacklevel=3)
    _check_relief(frame, spec)
    check_punch_lengths(spec, frame.band_z, die_height(frame, spec))


def _warn_crossings(frame, spec: ToolingSpec, emb_checked: list) -> None:
    """One warning for each embossed figure that crosses a score groove on its face: the letters are cut
    in two when the tablet is split, and the narrow land between groove and stroke picks and sticks.
    Checked in plan, on the figure's faces and the groove's width at the face
    (:func:`~tabletcad.tooling.scores.score_footprints`), before any Boolean.
    """
    if not (spec.scores and spec.emboss):
        return
    import warnings

    from OCP.BRepAlgoAPI import BRepAlgoAPI_Common

    from tabletcad.cad._occ import explore
    from tabletcad.tooling.outline import face_area
    from tabletcad.tooling.scores import score_footprints

    feet = [(j, s, score_footprints(frame, s)) for j, s in enumerate(spec.scores)]
    for i, (e, (figure, _)) in enumerate(zip(spec.emboss, emb_checked)):
        for j, s, footprints in feet:
            if e.face not in s.face_list:
                continue
            shared = sum(face_area(f) for fp in footprints for f in explore(BRepAlgoAPI_Common(figure, fp).Shape(), "Face"))
            if shared > 1e-6:
                what = repr(e.text) if e.text is not None else "svg" if e.svg is not None else "outline"
                warnings.warn(f"emboss {i} ({what}) crosses score {j} on the {e.face} face ({shared:.3g} mm^2 of it "
                              "lies in the groove): it is cut in two when the tablet is split and picks at the "
                              "groove's edge; move it (position_mm) or make it smaller", stacklevel=3)


def _warn_sharp_edge(frame, clearance: float) -> None:
    """One warning when cupped punch tips have no land: the tablet's land (0 without one) is narrower than
    the clearance (or equal to it), so the tip's outline meets the cup surface and the cup runs into the
    tip's wall at a sharp edge.  A flat face meets the wall square, and a flat face's bevel or edge radius
    (FFBE, FFRE) and a concave face's bevel are the edge's own design: none of them warns."""
    cupped = max(frame.cup_depth_top, frame.cup_depth_bottom) > 1e-9
    edge_designed = frame.info.get("face") == "flat" or bool(frame.info.get("bevel_width_mm"))
    inset = frame.tip_inset(clearance)  # the clearance less the bore's growth over the outline
    if cupped and not edge_designed and frame.land is not None and frame.land - inset <= 1e-9:
        import warnings

        what = ("clearance" if frame.bore_offset < 1e-4 else
                f"tip inset (the {clearance:.4g} mm clearance less the bore's {frame.bore_offset * 1000:.3g} µm growth)")
        warnings.warn(f"the punch tips have no land ({frame.land:.4g} mm tablet land - {inset:.4g} mm {what} "
                      f"= {frame.land - inset:.4g} mm): the cup runs into the tip's wall at a sharp edge, which "
                      "chips in service; give the tablet a land wider than the clearance", stacklevel=3)


def _check_relief(frame, spec: ToolingSpec) -> None:
    """A tip relief that leaves no relieved outline (the tip's outline offset inwards by the clearance
    and the relief is empty or falls apart) as a DesignError naming ``tip_relief_mm``."""
    from tabletcad.errors import GeometryError
    from tabletcad.tooling.outline import face_area, plan_face

    b = spec.body
    if b.tip_relief_mm <= 0 or max(spec.tip_length_mm, spec.lower_tip) <= b.tip_straight_mm:
        return  # no relief is cut
    d = spec.clearance_mm + b.tip_relief_mm
    try:
        relieved = face_area(plan_face(frame.offset(-d)))
    except GeometryError:
        relieved = 0.0
    if not relieved > 0.0:
        raise relief_refused(spec, frame.width)


def finished_solid(tablet: Tablet, spec: ToolingSpec, *, shape=None, deflection: float = DEFLECTION_MM):
    """The finished tablet of ``spec`` alone: the solid with its scores and embossing, no tools.

    The same checks and the same Booleans as :func:`make_tooling` (which also cross-checks each with
    manifold3d); for analyses of the finished shape such as ``tabletcad fe diametral``.  Returns
    ``(solid, frame)``; the frame's solid is the plain tablet.  Raises :class:`DesignError` for
    scores and figures that do not fit, :class:`GeometryError` when a Boolean fails.
    """
    from tabletcad.tooling.emboss import apply_emboss, check_emboss
    from tabletcad.tooling.outline import tablet_frame
    from tabletcad.tooling.scores import apply_scores

    frame = tablet_frame(tablet, shape)
    checked = [check_emboss(frame, e, spec.clearance_mm, i) for i, e in enumerate(spec.emboss)]
    solid, _, _ = apply_scores(frame, frame.shape, spec.scores, check=False, deflection=deflection)  # (checks each)
    solid, _, _ = apply_emboss(frame, solid, spec.emboss, spec.clearance_mm, check=False, deflection=deflection,
                               checked=checked)
    return solid, frame


def make_tooling(tablet: Tablet, spec: ToolingSpec | None = None, *, shape=None, check: bool = True,
                 interference_check: bool = True, deflection: float = DEFLECTION_MM,
                 options: ReportOptions | None = None) -> ToolSet:
    """Scores, embossing, punch tips and die for ``tablet`` (see :mod:`tabletcad.tooling`).

    ``shape``: the tablet's B-rep if already built.  ``options``: the design's report options;
    their solid fraction and true density give the masses of the parts a score splits.  ``check``: cross-check every Boolean with
    manifold3d; ``interference_check``: the closed-position overlap and gap check.
    Raises :class:`DesignError` for impossible tooling and :class:`GeometryError` when a
    Boolean or a check fails.
    """
    from tabletcad.tooling.die import die
    from tabletcad.tooling.emboss import apply_emboss
    from tabletcad.tooling.outline import tablet_frame
    from tabletcad.tooling.punch import punch_tip
    from tabletcad.tooling.scores import apply_scores

    spec = spec or ToolingSpec()
    t0 = time.perf_counter()
    b0 = dict(TIMER)
    # (CACHE is kept from the previous build: a build of the same tablet, e.g. the plain and the scored
    # tooling of one design, asks again for the plain tablet's mesh and volume, its faces' integrals
    # and a tip cut from the same faces; its entries hold their shapes, so a match is that shape)
    frame = tablet_frame(tablet, shape)
    emb_checked = check_on_frame(frame, spec)
    gap_closed = frame.band
    solid = frame.shape
    v0 = volume(solid)
    a_man = to_manifold(solid, deflection) if check and (spec.scores or spec.emboss) else None
    solid, score_checks, score_info = apply_scores(frame, solid, spec.scores, check=check, deflection=deflection, a_manifold=a_man)
    a_man = None
    solid, emb_checks, emb_info = apply_emboss(frame, solid, spec.emboss, spec.clearance_mm, check=check, deflection=deflection,
                                               checked=emb_checked)
    sf, rho = (None, None) if options is None else (options.solid_fraction, options.true_density_mg_mm3)
    density = None if sf is None or rho is None else sf * rho  # mg/mm^3 of the compact
    split = None
    if spec.scores:  # the finished tablet (scores and figures) split along its score planes
        from tabletcad.tooling.split import split_parts

        split = split_parts(frame, solid, spec.scores, density_mg_mm3=density)
    t1 = time.perf_counter()
    upper, chk_u = punch_tip(frame, solid, "upper", spec.clearance_mm, spec.tip_length_mm, check=check, deflection=deflection)
    lower, chk_l = punch_tip(frame, solid, "lower", spec.clearance_mm, spec.lower_tip, check=check, deflection=deflection)
    if spec.body is not None:
        from tabletcad.tooling.punch_body import complete_punch

        for tip, tl in ((upper, spec.tip_length_mm), (lower, spec.lower_tip)):
            which = tip.name.split("_")[0]
            shape_, info_ = complete_punch(frame, tip.shape, which, spec.body, spec.clearance_mm, tl,
                                           edge=tip.info["tip_edge_z_mm"])
            # working length: head flat to the cup's bottom (the tip's datum note), the length a press sets
            info_["working_length_mm"] = abs(info_["head_flat_z_mm"]
                                             - tip.info["working_length_datum"]["cup_bottom_point_mm"][2])
            tip.info.update(tip_volume_mm3=tip.volume_mm3, body=info_)
            tip.shape, tip.volume_mm3 = shape_, info_["volume_mm3"]
    die_shape, die_info = die(frame, spec.die_outer_diameter_mm, die_height(frame, spec), spec.taper_deg)
    t2 = time.perf_counter()
    v1 = volume(solid)  # the finished (scored, embossed) tablet's
    z_range = (frame.z_min, frame.z_max)
    if any(e.mode == "emboss" for e in spec.emboss):  # raised figures stand above the cups
        from tabletcad.tooling.punch import tight_z_range

        lo, hi = tight_z_range(solid)
        z_range = (min(lo, frame.z_min), max(hi, frame.z_max))
    parts = {"tablet": solid, "upper_punch": upper.shape, "lower_punch": lower.shape, "die": die_shape}
    gap = gap_closed if spec.gap_mm is None else spec.gap_mm
    checks = [c for c in [*score_checks, *emb_checks, chk_u, chk_l] if c is not None]
    report: dict[str, Any] = dict(
        keys=dict(clearance_mm=spec.clearance_mm, tip_length_mm=spec.tip_length_mm,
                  die_outer_diameter_mm=die_info["outer_diameter_mm"], die_height_mm=die_info["height_mm"],
                  taper_deg=spec.taper_deg, gap_mm=gap),
        tablet=dict(volume_plain_mm3=v0, volume_mm3=v1, weight_plain_mg=None if density is None else v0 * density,
                    weight_mg=None if density is None else v1 * density, band_mm=frame.band, band_z_mm=list(frame.band_z),
                    band_bulge_mm=frame.band_bulge, cup_depth_top_mm=frame.cup_depth_top,
                    cup_depth_bottom_mm=frame.cup_depth_bottom, thickness_mm=z_range[1] - z_range[0],
                    thickness_plain_mm=frame.thickness, z_range_mm=list(z_range),
                    land_mm=frame.land, outline=frame.outline_kind, length_mm=frame.length, width_mm=frame.width),
        scores=score_info,
        split=split,
        emboss=emb_info,
        upper_punch=upper.info,
        lower_punch=lower.info,
        die=die_info,
        press_position=dict(punch_gap_mm=gap, closed_gap_mm=gap_closed, upper_punch_lift_mm=gap - gap_closed,
                            closed=abs(gap - gap_closed) <= 1e-9),
        booleans=[c.as_dict() for c in checks],
        boolean_max_rel_diff_occ_vs_manifold3d=max((c.rel_diff for c in checks), default=None),
    )
    from tabletcad.tooling.rating import tip_rating

    report["tip_rating"] = tip_rating(frame, spec, options)
    ts = ToolSet(tablet, spec, frame, parts, gap - gap_closed, report)
    report["seconds"] = dict(features=t1 - t0, parts=t2 - t1, interference=0.0, total=t2 - t0,
                             occ_booleans=TIMER["occ_boolean_s"] - b0["occ_boolean_s"],
                             manifold3d=TIMER["manifold_s"] - b0["manifold_s"])
    if interference_check:
        check_closed_position(ts, deflection=deflection)
    return ts


def _band_gap(ts: ToolSet) -> float:
    """How far (mm) the tablet's B-rep band may stand inside the die bore: the bore's offset from the
    outline, the PDE band's inward bow and the B-rep's fit to the PDE surface (``Tolerances.fit``); 0 for
    a band that is a prism (its B-rep is exact)."""
    if ts.frame.bore_offset == 0.0:
        return 0.0
    band = ts.tablet.band()
    return ts.frame.bore_offset + (band.inward if band is not None else 0.0) + ts.tablet.tol.fit


def check_closed_position(ts: ToolSet, *, deflection: float = DEFLECTION_MM, forked: bool = False) -> dict[str, Any]:
    """The closed-position check of a tool set made with ``interference_check=False``: overlaps of
    every pair of parts and the tablet's largest gap (:func:`tabletcad.tooling.interference.interference`).

    Adds ``interference_mm3``, ``max_gap_mm`` and ``interference`` to ``ts.report`` (and the
    check's seconds to ``seconds``) and returns the check's result.  ``forked``: the gap is measured
    by a forked process beside the overlaps (the command line's build, see
    :func:`tabletcad.tooling.interference.interference`).
    """
    from tabletcad.tooling.die import bore_wire
    from tabletcad.tooling.interference import interference

    t0 = time.perf_counter()
    b0 = dict(TIMER)
    parts = ts.parts
    res = interference(parts["tablet"], {k: v for k, v in parts.items() if k != "tablet"}, ts.spec.clearance_mm,
                       deflection=deflection, tablet_model=ts.tablet, forked=forked, bore=bore_wire(ts.frame),
                       band_gap=_band_gap(ts))
    report = ts.report
    seconds = report.pop("seconds")  # kept last, as the sum of the steps
    report.update(interference_mm3=res["interference_mm3"], max_gap_mm=res["max_gap_mm"], interference=res)
    dt = time.perf_counter() - t0
    seconds.update(interference=dt, total=seconds["total"] + dt,
                   occ_booleans=seconds["occ_booleans"] + TIMER["occ_boolean_s"] - b0["occ_boolean_s"],
                   manifold3d=seconds["manifold3d"] + TIMER["manifold_s"] - b0["manifold_s"])
    report["seconds"] = seconds
    return res
