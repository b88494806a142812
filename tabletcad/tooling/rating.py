"""Punch-tip force rating by the projected-area pressure rule, and the tip's Euler buckling load.

* **Rating**: ``F = p_allowed × A``, ``A`` the tip's projected (plan) area — the outline
  inset by the clearance (mm²), ``p_allowed`` in MPa (= N/mm²).  No allowed pressure is
  bundled (no citable public value was found, see ``tabletcad/data/punch_ratings.toml``):
  it comes from ``[tooling] allowed_tip_pressure_MPa`` with its
  ``allowed_tip_pressure_source``, else from the design's ``[report]
  max_punch_pressure_MPa`` (reported as user-given).  The finite-element punch analysis
  belongs to :mod:`tabletcad.fe`: with ``[tooling.fe_rating]`` the build
  (:func:`tabletcad.pipeline.build.fe_tip_rating`) adds its rating as ``fe`` and the drawing
  states it first (:func:`tabletcad.tooling.drawing.rating_notes`); this is the rule of thumb
  beside it, and alone when the FE analysis is not asked for or not installed.
* **Buckling** (what limits mini-tablet tips): the tip as an Euler column fixed at the barrel
  and free at the face, ``P_cr = π² E I_min / (K L)²`` with ``K = 2`` (the conservative end
  condition), ``L`` the tip length and ``I_min`` the smaller principal second moment of the
  tip's smallest section (the relieved one when the tip has a relief).  ``E`` of the punch
  steel comes from ``[tooling] punch_youngs_modulus_MPa`` with its source.
"""

from __future__ import annotations

import math

from tabletcad.pipeline.designreport import ReportOptions
from tabletcad.tooling.outline import TabletFrame, plan_face, plan_face_properties

__all__ = ["section_properties", "tip_rating", "rating_text", "overload_texts", "EULER_K"]

#: effective-length factor of a column fixed at one end and free at the other
EULER_K = 2.0


def rating_text(force_kN: float, digits: int = 4) -> str:
    """A rated force (kN) to ``digits`` significant digits, rounded down: a rating is never printed above
    what it is (14.967 kN is "14.96", where ``.3g`` had printed "15").  The float is read to 15 significant
    digits first, so that its round-off is not taken for a fall below a round value (14.999999999999998 kN, a
    product's last bit, is "15", not "14.99")."""
    from decimal import ROUND_FLOOR, Decimal

    d = Decimal(f"{float(force_kN):.15g}")
    if not d.is_finite() or d.is_zero():
        return f"{force_kN:g}"
    q = d.quantize(Decimal(1).scaleb(d.adjusted() - (digits - 1)), rounding=ROUND_FLOOR)
    return format(q.normalize(), "f")


def overload_texts(force_kN: float, rated_kN: float) -> tuple[str, str, str]:
    """``(force, rating, utilisation)`` texts of an overload (force > rating), with as many digits as it takes
    for the force to read above the rating (rounded down, :func:`rating_text`) and the utilisation above 1:
    a 15 kN force on a 14.967 kN rating had read "1 x the rated 15 kN"."""
    digits = 4  # (up to 17: a force one float step above the rating needs them all)
    while digits < 17 and not float(f"{force_kN:.{digits}g}") > float(rating_text(rated_kN, min(digits, 15))):
        digits += 1
    u = force_kN / rated_kN
    places = 3
    while places < 17 and not float(f"{u:.{places}g}") > 1.0:
        places += 1
    return f"{force_kN:.{digits}g}", rating_text(rated_kN, min(digits, 15)), f"{u:.{places}g}"


def section_properties(wire) -> tuple[float, float]:
    """``(area mm², smallest principal second moment of area mm⁴)`` of the plan region bounded by ``wire``."""
    props = plan_face_properties(plan_face(wire))  # (adaptive on a spline outline's periodic B-spline)
    m = props.MatrixOfInertia()  # about the centroid; for a plane region in z = 0: [[Iyy, -Ixy], [-Ixy, Ixx]] block
    a, b, c = m.Value(1, 1), m.Value(1, 2), m.Value(2, 2)
    i_min = 0.5 * (a + c) - math.sqrt(0.25 * (a - c) ** 2 + b * b)
    return props.Mass(), i_min


def tip_rating(frame: TabletFrame, spec, options: ReportOptions | None = None) -> dict:
    """The rating and buckling figures for the tool set's tips (see the module docstring).

    ``options``: the design's report options (its user-given punch pressure limit and compaction
    force), or None.
    """
    options = ReportOptions() if options is None else options
    inset = frame.tip_inset(spec.clearance_mm)  # the tips' outline (the die bore less the clearance)
    area, _ = section_properties(frame.offset(-inset))
    out: dict = dict(tip_projected_area_mm2=area, rule="F = p_allowed x tip projected area")
    p, src = spec.allowed_tip_pressure_MPa, spec.allowed_tip_pressure_source
    if p is None and options.max_punch_pressure_MPa is not None:
        p, src = options.max_punch_pressure_MPa, "the design's [report] max_punch_pressure_MPa (user-given)"
    out.update(allowed_pressure_MPa=p, allowed_pressure_source=src,
               rated_force_kN=None if p is None else p * area / 1000.0)
    force = options.compaction_force_kN
    out["compaction_force_kN"] = force
    out["utilisation"] = None if force is None or p is None else force / out["rated_force_kN"]
    out["overloaded"] = None if out["utilisation"] is None else out["utilisation"] > 1.0
    if out["overloaded"]:
        import warnings

        f_text, r_text, u_text = overload_texts(force, out["rated_force_kN"])
        warnings.warn(f"the compaction force {f_text} kN exceeds the tips' rated force {r_text} kN "
                      f"({p:g} MPa x {area:.4g} mm2 tip area; utilisation {u_text}): the tips would be "
                      "overloaded; lower [report] compaction_force_kN or enlarge the tablet", stacklevel=2)
    if p is None:
        out["note"] = "no allowed pressure given ([tooling] allowed_tip_pressure_MPa with its source): no rating"
    E = spec.punch_youngs_modulus_MPa
    body = spec.body
    tips, sections = {}, {}
    for name, L in (("upper", spec.tip_length_mm), ("lower", spec.lower_tip)):
        # the smallest section of the tip: its relieved part, where one is cut (a tip no longer than its
        # straight part has none: punch_body; its offset had been asked for anyway, and refused on a spline)
        relief = body.tip_relief_mm if body is not None and body.tip_relief_mm > 0 and L > body.tip_straight_mm else 0.0
        if relief not in sections:
            sections[relief] = section_properties(frame.offset(-inset - relief))[1]
        i_min = sections[relief]
        p_cr = None if E is None else math.pi ** 2 * E * i_min / (EULER_K * L) ** 2 / 1000.0
        load = force if force is not None else out["rated_force_kN"]
        tips[name] = dict(free_length_mm=L, buckling_load_kN=p_cr, section_min_second_moment_mm4=i_min,
                          relieved_by_mm=relief, safety_factor=None if p_cr is None or not load else p_cr / load)
    out["buckling"] = dict(model="Euler column fixed at the barrel, free at the face (K = 2)", K=EULER_K,
                           section_min_second_moment_mm4=min(sections.values()), youngs_modulus_MPa=E,
                           youngs_modulus_source=spec.punch_youngs_modulus_source, tips=tips,
                           note=None if E is not None else "no punch_youngs_modulus_MPa given: not computed")
    return out
