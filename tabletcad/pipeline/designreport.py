"""Design report of a family tablet: dimensions, cup, weight, punch-tip check, tensile strength, size.

:func:`tabletcad.pipeline.report.geometry_report` adds it to the report of every tablet
built from a family of this package, so its ``report.json`` gains

* ``nominal_max_deviation_um``, ``nominal_tolerance_um``, ``nominal_certified``:
  the certificate of :func:`tabletcad.families.sweep.certify`;
* ``seams``: per seam ``max_gap_mm``, ``max_angle_deg``, ``g1``, ``expected_sharp``
  (the nominal has an edge there) and ``as_expected``;
* ``design_report``: the figures below, keys named with their units.

Options that are not geometry (solid fraction, true density, breaking force,
punch limits) come from :class:`ReportOptions`, set by ``tabletcad report``
from the design file's ``[report]`` table or its command-line options.
"""

from __future__ import annotations

import contextlib
import math
import sys
import warnings
from collections.abc import Iterator
from dataclasses import asdict, dataclass
from importlib import resources
from typing import Any

import numpy as np

from tabletcad.errors import DesignError, check_range
from tabletcad.families.sweep import SweepNominal, certify, sweep_properties
from tabletcad.geometry.tablet import Tablet
from tabletcad.geometry.vectors import clip, cross, norm3
from tabletcad.mechanics.strength import MAX_FORCE_N
from tabletcad.tolerance import (DEFAULT, MAX_TENSILE_STRENGTH_MPA, MAX_TRUE_DENSITY_MG_MM3, MAX_YIELD_MPA, MIN_TIP_PRESSURE_MPA,
                                 MIN_TRUE_DENSITY_MG_MM3)

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

__all__ = ["ReportOptions", "design_report", "shape_report", "shape_design_report", "family_seams",
           "punch_rating_table", "tensile_strength", "plan_diameter", "FDA_MAX_DIMENSION_MM", "REPORT_KEYS"]

#: FDA guidance "Size, Shape, and Other Physical Attributes of Generic Tablets and Capsules"
#: (2015): the largest dimension of a generic tablet should not exceed 22 mm.
FDA_MAX_DIMENSION_MM = 22.0

#: Keys accepted in a design file's ``[report]`` table (and their units).
REPORT_KEYS = {
    "solid_fraction": "-",
    "true_density_mg_mm3": "mg/mm3",
    "breaking_force_N": "N",
    "compaction_force_kN": "kN",
    "max_punch_force_kN": "kN",
    "max_punch_pressure_MPa": "MPa",
    # read by `tabletcad fe strength` (tabletcad.fe.prediction), which validates them
    "tensile_strength_MPa": "MPa",
    "reference_breaking_force_N": "N",
    "reference_diameter_mm": "mm",
    "reference_thickness_mm": "mm",
    # true: `tabletcad report` and `build` run that prediction on the coarse mesh (tabletcad.fe.objective)
    "fe_breaking_force": "true or false",
}


#: The largest value of each number of ``[report]`` (all must be > 0): a true density in mg/mm³ (not
#: kg/m³), forces as a breaking test's (:data:`tabletcad.mechanics.strength.MAX_FORCE_N`, 1e9 N; in kN,
#: 1e6), a punch-tip pressure as the tooling's allowed tip pressure (10 MPa to a steel's
#: 10 GPa: neither in GPa nor in Pa), a tensile strength as the FE prediction's (1000 MPa: not
#: pascals); the reference tablet's lengths as a design's.
_REPORT_LIMITS = {
    "true_density_mg_mm3": MAX_TRUE_DENSITY_MG_MM3,
    "breaking_force_N": MAX_FORCE_N,
    "compaction_force_kN": 1e6,
    "max_punch_force_kN": 1e6,
    "max_punch_pressure_MPa": MAX_YIELD_MPA,
    "tensile_strength_MPa": MAX_TENSILE_STRENGTH_MPA,
    "reference_breaking_force_N": MAX_FORCE_N,
    "reference_diameter_mm": None,
    "reference_thickness_mm": None,
}


@dataclass(frozen=True)
class ReportOptions:
    """Non-geometric inputs of the design report (None = not given).

    Attributes
    ----------
    solid_fraction : float
        Tablet solid fraction (1 - porosity), in (0, 1].
    true_density_mg_mm3 : float
        True density of the formulation, mg/mm³ (= g/cm³).
    breaking_force_N : float
        Diametral breaking force (N) for the tensile strength.
    compaction_force_kN : float
        Compaction force (kN) to check against the punch-tip limit.
    max_punch_force_kN, max_punch_pressure_MPa : float
        User-given punch-tip limits (no public rating table is bundled).
    tensile_strength_MPa, reference_breaking_force_N, reference_diameter_mm, reference_thickness_mm : float
        Inputs of the FE breaking-force prediction (``tabletcad fe strength``).
    fe_breaking_force : bool
        Run that prediction (across the width, coarse mesh: ``tabletcad fe strength --coarse``) in the
        design report and the build (an elastic first-crack estimate; needs the CAD layer and FE).
    """

    solid_fraction: float | None = None
    true_density_mg_mm3: float | None = None
    breaking_force_N: float | None = None
    compaction_force_kN: float | None = None
    max_punch_force_kN: float | None = None
    max_punch_pressure_MPa: float | None = None
    tensile_strength_MPa: float | None = None
    reference_breaking_force_N: float | None = None
    reference_diameter_mm: float | None = None
    reference_thickness_mm: float | None = None
    fe_breaking_force: bool = False

    def __post_init__(self) -> None:
        if self.solid_fraction is not None:
            check_range("[report] solid_fraction", self.solid_fraction, 0.0, 1.0, lo_open=True)
        for k, hi in _REPORT_LIMITS.items():
            v = getattr(self, k)
            if v is not None:
                if REPORT_KEYS[k] == "mm":  # a reference tablet's lengths as a design's (0.001 mm to 1 m)
                    check_range(f"[report] {k}", v, DEFAULT.min_length, DEFAULT.max_length, "mm")
                elif k == "true_density_mg_mm3":  # neither kg/m³ nor g/mm³
                    check_range(f"[report] {k}", v, MIN_TRUE_DENSITY_MG_MM3, hi, REPORT_KEYS[k])
                elif k == "max_punch_pressure_MPa":  # as [tooling] allowed_tip_pressure_MPa
                    check_range(f"[report] {k}", v, MIN_TIP_PRESSURE_MPA, hi, REPORT_KEYS[k])
                else:
                    check_range(f"[report] {k}", v, 0.0, hi, REPORT_KEYS[k], lo_open=True)

    @classmethod
    def from_table(cls, table: Any) -> "ReportOptions":
        if table is None:
            return cls()
        if not isinstance(table, dict):
            raise DesignError("[report]", table, f"must be a table with keys {', '.join(REPORT_KEYS)}")
        for k in table:
            if k not in REPORT_KEYS:
                raise DesignError(f"[report] key {k!r}", table[k], f"allowed keys are {', '.join(REPORT_KEYS)}")
        flag = table.get("fe_breaking_force", False)
        if not isinstance(flag, bool):
            raise DesignError("[report] fe_breaking_force", flag, "must be a TOML boolean (true or false)")
        return cls(fe_breaking_force=flag, **{k: float(v) if isinstance(v, (int, float)) and not isinstance(v, bool)
                                              else _bad(k, v) for k, v in table.items() if k != "fe_breaking_force"})

    def merged(self, **kw) -> "ReportOptions":
        d = asdict(self)
        d.update({k: v for k, v in kw.items() if v is not None})
        return ReportOptions(**d)


def _bad(k, v):
    raise DesignError(f"[report] {k}", v, "must be a number", REPORT_KEYS[k])


# ---------------------------------------------------------------------------- pieces
def family_seams(tablet: Tablet, nv: int = 720) -> list[dict[str, Any]]:
    """Seam continuity of a family tablet.

    Like :meth:`Tablet.seams` but (1) normals are ``X_u × X_v`` of each patch at
    the shared curve and (2) points where the shared curve is degenerate
    (``|X_v| ≈ 0``: a corner arc collapsed by the offset, where the seam is a
    single point and one side has no surface) are skipped and counted.  A tablet of
    revolution is measured on 4 meridians.
    """
    nom = tablet.nominal
    expected = list(getattr(nom, "expected_sharp", []))
    # the geometry report's seams' samples (each side of the outline's joins included) and rows
    rows = tablet.seam_rows(nv)
    out = []
    for i in range(len(tablet.patches) - 1):
        (xa, xua, xv), (xb, xub, xvb) = rows[i][:, 1], rows[i + 1][:, 0]
        # lengths by norm3: numpy.linalg.norm's values along the last axis (the same squares, summed in
        # the same order) without its general reduction's cost; |X_v| once for the scale and the test
        gap = float(norm3(xa - xb).max())
        speed = norm3(xv)
        scale = max(1e-300, float(speed.max()))
        good = speed > 1e-6 * scale
        na = cross(xua, xv)
        nb = cross(xub, xvb)
        la, lb = norm3(na), norm3(nb)
        good &= (la > 1e-9 * la.max()) & (lb > 1e-9 * lb.max())
        if good.any():
            c = np.einsum("ij,ij->i", na[good], nb[good]) / (la[good] * lb[good])
            ang = float(np.degrees(np.arccos(clip(c, -1.0, 1.0)).max()))
        else:
            ang = float("nan")
        g1 = bool(ang == ang and ang <= tablet.tol.seam_angle_deg)
        sharp = bool(expected[i]) if i < len(expected) else None
        out.append(dict(
            patches=[i, i + 1],
            max_gap_mm=gap,
            max_angle_deg=ang,
            g1=g1,
            expected_sharp=sharp,
            as_expected=None if sharp is None else (g1 != sharp),
            degenerate_points=int(np.sum(~good)),
        ))
    return out


def punch_rating_table() -> dict[str, Any]:
    """The bundled punch-tip rating table (``tabletcad/data/punch_ratings.toml``)."""
    try:
        text = resources.files("tabletcad").joinpath("data/punch_ratings.toml").read_text(encoding="utf-8")
    except (FileNotFoundError, ModuleNotFoundError, OSError):
        return dict(source=None, ratings=[])
    data = tomllib.loads(text)
    return dict(source=data.get("source"), note=data.get("note"), ratings=list(data.get("rating", [])))


def _strength_module():
    try:
        from tabletcad.mechanics import strength as st  # noqa: PLC0415

        return st
    except ImportError:  # pragma: no cover - fallback when the mechanics package is absent
        return _LocalStrength()


class _LocalStrength:
    """Fallback formulas (thesis eqs 2.4, 2.7-2.9), F in N, lengths in mm, result MPa."""

    ELONGATED_RATIO = 1.7  # length/width from which eqs 2.8, 2.9 hold

    @staticmethod
    def diametral_flat(F, D, t):  # eq 2.4
        return 2.0 * F / (math.pi * D * t)

    @staticmethod
    def pitt_convex(F, D, t, W):  # eq 2.7, Pitt et al. 1988
        return 10.0 * F / (math.pi * D * D * (2.84 * t / D - 0.126 * t / W + 3.15 * W / D + 0.01))

    @classmethod
    def pitt_heasley_elongated_flat(cls, F, D, t, length=None):  # eq 2.8
        return 2.0 / 3.0 * cls.diametral_flat(F, D, t)

    @classmethod
    def pitt_heasley_elongated_convex(cls, F, D, t, W, length=None):  # eq 2.9
        return 2.0 / 3.0 * cls.pitt_convex(F, D, t, W)


def tensile_strength(info: dict, thickness: float, F: float) -> dict[str, Any]:
    """Tensile strength (MPa) for breaking force ``F`` (N) by the formula valid for the shape.

    Flat round: eq 2.4 ``2F/(πDt)``; convex round: eq 2.7 (Pitt et al. 1988);
    elongated (capsule, oval, modified capsule): eqs 2.8/2.9 (Pitt & Heasley,
    2/3 of the round value, ``D`` the width) from length/width 1.7; as long as wide, the
    round formula; in between no value but ``tensile_strength_range_MPa`` (from the
    elongated to the round value).  Other plans: none.  Range warnings of the formulas
    are returned in ``range_flags``.
    """
    st = _strength_module()
    shape = info.get("shape")
    flat = info.get("face") == "flat"
    band = info.get("band_mm")
    D = info.get("width_mm")
    Ln = info.get("length_mm")
    flags: list[str] = []
    with warnings.catch_warnings(record=True) as rec, _no_value(F) as refused:
        warnings.simplefilter("always")
        if shape == "round":
            if flat:
                val, formula = st.diametral_flat(F, D, thickness), "eq 2.4: 2F/(pi D t) (flat-faced round)"
                if info.get("cup_depth_mm", 0) > 0:
                    flags.append("bevel/radius edge: the flat-disc formula is applied with the overall thickness (approximation)")
            else:
                val, formula = st.pitt_convex(F, D, thickness, band), "eq 2.7: Pitt et al. (1988), convex-faced round"
        elif info.get("elongated") and Ln is not None and abs(Ln - D) <= 1e-9 * D:  # length = width: a round tablet
            if flat:
                val, formula = st.diametral_flat(F, D, thickness), "eq 2.4: 2F/(pi D t) (length = width: a flat-faced round)"
            else:
                val, formula = st.pitt_convex(F, D, thickness, band), "eq 2.7: Pitt et al. (1988) (length = width: a convex round)"
        elif info.get("elongated") and Ln is not None and Ln / D < st.ELONGATED_RATIO:
            return _between_round_and_elongated(st, F, D, Ln, thickness, band, flat)
        elif info.get("elongated"):
            if flat:
                val, formula = st.pitt_heasley_elongated_flat(F, D, thickness, length=Ln), "eq 2.8: Pitt & Heasley (2013), flat elongated, 2/3 of eq 2.4"
            else:
                val, formula = st.pitt_heasley_elongated_convex(F, D, thickness, band, length=Ln), "eq 2.9: Pitt & Heasley (2013), convex elongated, 2/3 of eq 2.7"
        else:
            return dict(tensile_strength_MPa=None, formula=None, breaking_force_N=F,
                        range_flags=[f"no published tensile-strength formula for {'an' if shape[:1] in 'aeiou' else 'a'} {shape} plan"])
    if refused:
        return refused[0]
    flags += [str(w.message) for w in rec]
    return dict(tensile_strength_MPa=float(val), formula=formula, breaking_force_N=F, range_flags=flags,
                within_range=not any(True for w in rec))


def _between_round_and_elongated(st, F: float, D: float, Ln: float, t: float, band, flat: bool) -> dict[str, Any]:
    """The tensile strength of an elongated tablet shorter than Pitt & Heasley's 2/3 limit (``1 < L/W < 1.7``):
    no published formula gives it, so no value, but the range it lies in: from the elongated limit
    (eq 2.8 or 2.9, 2/3 of the round value) up to the round value (eq 2.4 or 2.7) on the width."""
    with warnings.catch_warnings(record=True) as rec, _no_value(F) as refused:
        warnings.simplefilter("always")
        if flat:
            hi, lo = st.diametral_flat(F, D, t), st.pitt_heasley_elongated_flat(F, D, t)
            names = "eq 2.8", "eq 2.4"
        else:
            hi, lo = st.pitt_convex(F, D, t, band), st.pitt_heasley_elongated_convex(F, D, t, band)
            names = "eq 2.9", "eq 2.7"
    if refused:
        return refused[0]
    return dict(tensile_strength_MPa=None, formula=None, breaking_force_N=F,
                tensile_strength_range_MPa=[float(lo), float(hi)],
                range_flags=[f"length/width = {Ln / D:.3g} < {st.ELONGATED_RATIO}: Pitt & Heasley's 2/3 of the round value "
                             f"holds from about {st.ELONGATED_RATIO}; the strength lies between {names[0]}'s {lo:.4g} MPa "
                             f"(elongated) and {names[1]}'s {hi:.4g} MPa (round, on the width)"]
                + list(dict.fromkeys(str(w.message) for w in rec)),
                within_range=False)


@contextlib.contextmanager
def _no_value(F: float) -> Iterator[list[dict[str, Any]]]:
    """Turn a formula's refusal of the geometry (eq 2.7 with a band so thin that its denominator is <= 0)
    into a tensile strength of None with the reason, in the list it yields."""
    out: list[dict[str, Any]] = []
    try:
        yield out
    except DesignError as exc:
        out.append(dict(tensile_strength_MPa=None, formula=None, breaking_force_N=F,
                        range_flags=[f"{exc.parameter} = {exc.value:g}{' ' + exc.unit if exc.unit else ''} {exc.allowed}"],
                        within_range=False))


def _punch_check(plan_area: float | None, opts: ReportOptions) -> dict[str, Any]:
    """The punch-tip check against the user's limits; ``plan_area`` None (a shaped cut-away whose plan
    area is not known, :meth:`Tablet.plan_area`): no pressure figures."""
    table = punch_rating_table()
    out: dict[str, Any] = dict(
        tip_face_area_mm2=plan_area,
        rating_table_source=table.get("source"),
        rating_table_entries=len(table["ratings"]),
        compaction_force_kN=opts.compaction_force_kN,
        max_punch_force_kN=opts.max_punch_force_kN,
        max_punch_pressure_MPa=opts.max_punch_pressure_MPa,
    )
    lim_force = None
    basis = None
    if opts.max_punch_force_kN is not None:
        lim_force, basis = opts.max_punch_force_kN, "user-given max_punch_force_kN"
    if opts.max_punch_pressure_MPa is not None and plan_area is not None:
        f = opts.max_punch_pressure_MPa * plan_area / 1000.0
        if lim_force is None or f < lim_force:
            lim_force, basis = f, "user-given max_punch_pressure_MPa x tip face area"
    if opts.max_punch_pressure_MPa is not None and plan_area is None and basis is None:
        basis = "max_punch_pressure_MPa given, but this cut-away's plan area is not known"
    both = opts.max_punch_force_kN is not None and opts.max_punch_pressure_MPa is not None
    if basis and both and plan_area is not None:
        basis += " (the stricter of the two limits given)"
    out["allowed_force_kN"] = lim_force
    out["limit_basis"] = basis or ("no limit given (no citable public punch-tip rating table is bundled: "
                                    "give [report] max_punch_force_kN or max_punch_pressure_MPa)")
    if opts.compaction_force_kN is not None and plan_area is not None:
        out["compaction_pressure_MPa"] = opts.compaction_force_kN * 1000.0 / plan_area
    if opts.compaction_force_kN is not None and lim_force is not None:
        out["ok"] = bool(opts.compaction_force_kN <= lim_force)
        out["utilisation"] = opts.compaction_force_kN / lim_force
    else:
        out["ok"] = None
    return out


_RADIUS_KEYS = {"cup_radius_mm": "cup", "central_radius_mm": "central", "edge_radius_mm": "edge"}


def _cup_radii(info: dict) -> dict[str, float]:
    """The face's radii of curvature (mm) named ``cup`` (single-radius cup), ``central`` and
    ``edge`` (compound cup, radius edge); empty for a flat face."""
    return {name: float(info[k]) for k, name in _RADIUS_KEYS.items() if info.get(k) is not None}


def _cup_radius(info: dict) -> float | None:
    """The cup's (central) radius of curvature, mm, or None for a flat-faced tablet."""
    r = _cup_radii(info)
    return r.get("cup", r.get("central"))


def design_report(tablet: Tablet, opts: ReportOptions | None = None) -> dict[str, Any]:
    """The design report of a family tablet (see module docstring); keys carry units."""
    nom = tablet.nominal
    if not isinstance(nom, SweepNominal):
        raise DesignError("tablet", tablet.name, "is not built from a tabletcad.families family")
    opts = ReportOptions() if opts is None else opts
    cert = nom.certificate
    recert = cert is None or nom.patch_ids != tuple(id(p) for p in tablet.patches)
    if recert:
        cert = certify(tablet)
    props = sweep_properties(tablet)
    info = nom.info
    T = nom.thickness
    W = float(info.get("width_mm"))
    Ln = float(info.get("length_mm"))
    V = props["volume_mm3"]
    A = props["surface_area_mm2"]
    h = float(info.get("cup_depth_mm", 0.0))
    rep: dict[str, Any] = dict(
        family=tablet.family,
        shape=info.get("shape"),
        face=info.get("face"),
        # a cut-away view ([trim]) of a family tablet: these are the uncut design's figures; the
        # geometry report's volume, area and extents are the cut-away's
        cut_away=not tablet.trim.whole,
        volume_mm3=V,
        surface_area_mm2=A,
        sa_to_volume_per_mm=A / V,
        cup_volume_mm3=props["cup_volume_mm3"],
        cup_surface_area_mm2=props["cup_surface_area_mm2"],
        cup_depth_mm=h,
        overall_thickness_mm=T,
        band_mm=float(info.get("band_mm")),
        land_mm=float(info.get("land_mm", 0.0)),
        length_mm=Ln,
        width_mm=W,
        plan_area_mm2=props["plan_area_mm2"],
        plan_area_exact_mm2=float(nom.outline.area),
        plan_perimeter_mm=float(nom.outline.perimeter),
        shape_factor=h / W,
        cup_radius_mm=_cup_radius(info),
        cup_radii_mm=_cup_radii(info),
        params={k: v for k, v in info.items() if k not in ("shape", "face")},
    )
    _add_figures(rep, dict(info, width_mm=W, length_mm=Ln, plan_diameter_mm=float(nom.outline.diameter)), T, opts)
    seams = family_seams(tablet)
    return dict(
        nominal_max_deviation_um=cert.max_deviation_mm * 1000.0,
        nominal_tolerance_um=cert.tolerance_mm * 1000.0,
        nominal_certified=bool(cert.passed),
        nominal_recertified=bool(recert),
        seams=seams,
        seams_as_expected=all(s["as_expected"] is not False for s in seams),
        design_report=rep,
    )


def _add_figures(rep: dict[str, Any], info: dict[str, Any], T: float, opts: ReportOptions) -> None:
    """Weight, punch-tip check, tensile strength and FDA size from ``rep``'s volume and plan area."""
    V, W, Ln = rep["volume_mm3"], info["width_mm"], info["length_mm"]
    if opts.solid_fraction is not None and opts.true_density_mg_mm3 is not None:
        rep["weight_mg"] = V * opts.solid_fraction * opts.true_density_mg_mm3
        rep["weight_basis"] = dict(solid_fraction=opts.solid_fraction, true_density_mg_mm3=opts.true_density_mg_mm3)
    else:
        rep["weight_mg"] = None
        rep["weight_basis"] = "give [report] solid_fraction and true_density_mg_mm3"
    rep["punch_tip_check"] = _punch_check(rep["plan_area_mm2"], opts)
    if opts.breaking_force_N is None:
        rep["tensile_strength"] = dict(tensile_strength_MPa=None, note="give [report] breaking_force_N")
    elif info.get("shape") is None:
        rep["tensile_strength"] = dict(tensile_strength_MPa=None, breaking_force_N=opts.breaking_force_N,
                                       note="no published tensile-strength formula for this shape")
    else:
        rep["tensile_strength"] = tensile_strength(info, T, opts.breaking_force_N)
    # the plan's largest extent in any direction (the diagonal of a rounded square), not along the axes
    largest = max(Ln, W, info.get("plan_diameter_mm") or 0.0, T)
    rep["fda_size"] = dict(largest_dimension_mm=largest, limit_mm=FDA_MAX_DIMENSION_MM,
                           ok=bool(largest <= FDA_MAX_DIMENSION_MM),
                           basis="the largest of the plan's diameter (its largest extent in any direction) "
                                 "and the thickness",
                           source="FDA guidance for industry: Size, Shape, and Other Physical Attributes of Generic Tablets and Capsules (2015)")


# The thesis's shapes whose faces the strength formulas know: (shape, face) and how to read
# the band (the cylindrical wall, mm) from the family's parameters.
_THESIS_SHAPES = {
    "thesis.flat_faced_round": ("round", "flat", lambda p: p["thickness"]),
    "thesis.shallow_convex_round": ("round", "convex", lambda p: p["band"]),
    "thesis.deep_convex_round": ("round", "convex", lambda p: p["band"]),
    "thesis.shallow_convex_oval": ("oval", "convex", lambda p: p["band"]),
    "thesis.deep_convex_oval": ("oval", "convex", lambda p: p["band"]),
}


def shape_report(tablet: Tablet, opts: ReportOptions | None = None) -> dict[str, Any]:
    """The design report of a tablet without a family nominal (:func:`shape_design_report`) with the
    nominal deviation and seams, as :func:`design_report` gives them for a family tablet."""
    dev = tablet.nominal_deviation()
    seams = [dict(s, expected_sharp=None, as_expected=None) for s in tablet.seams()]
    return dict(
        nominal_max_deviation_um=None if dev is None else dev * 1000.0,
        nominal_tolerance_um=None,
        nominal_certified=None,
        nominal_recertified=False,
        seams=seams,
        seams_as_expected=None,
        design_report=shape_design_report(tablet, opts),
    )


def shape_design_report(tablet: Tablet, opts: ReportOptions | None = None) -> dict[str, Any]:
    """The design report of a tablet without a family nominal: the thesis's shapes, free-form designs.

    The same keys as :func:`design_report`'s ``design_report``, from the tablet's own geometry (quadrature volume and
    area, plan area, overall dimensions); band and cup depth come from the family's parameters
    where it has them (the thesis's convex rounds and ovals: cup depth = (thickness - band) / 2),
    else they are None (also for a trimmed, cut-away tablet and a reshaped one).  The tensile strength uses eq 2.4 (flat round), eq 2.7 (convex round) or
    eqs 2.8/2.9 (convex oval, Pitt & Heasley, across the width); other shapes have no formula.
    There is no certificate: ``nominal_max_deviation_um`` is the PDE surface's largest distance
    from the exact shape when the family has one (the thesis's curves, not a tolerance).
    """
    opts = ReportOptions() if opts is None else opts
    props = tablet.properties()
    dims = tablet.dimensions()
    V, A = props["volume_mm3"], props["surface_area_mm2"]
    Ln, W, T = dims["length_mm"], dims["width_mm"], dims["height_mm"]
    p = dict(tablet.params)
    whole = tablet.trim.whole
    # a cut-away view, or a reshaped tablet (its family's dimensions no longer describe it): no formula
    known = whole and bool(p)
    shape, face, band_of = _THESIS_SHAPES.get(tablet.family, (None, None, None)) if known else (None, None, None)
    band = float(band_of(p)) if band_of is not None else None
    cup = None if band is None else (0.0 if face == "flat" else (float(p["thickness"]) - band) / 2.0)
    rep: dict[str, Any] = dict(
        family=tablet.family, shape=shape, face=face, cut_away=not whole, volume_mm3=V, surface_area_mm2=A,
        sa_to_volume_per_mm=A / V,
        cup_volume_mm3=None, cup_surface_area_mm2=None, cup_depth_mm=cup, overall_thickness_mm=T, band_mm=band,
        land_mm=0.0 if shape is not None else None, length_mm=Ln, width_mm=W, plan_area_mm2=tablet.plan_area(),
        plan_area_exact_mm2=None, plan_perimeter_mm=None, shape_factor=None if cup is None else cup / W,
        cup_radius_mm=None, cup_radii_mm={}, params=p,
    )
    if shape == "round" and face == "convex" and cup:  # the thesis's caps lie on spheres
        r_cup = ((float(p["diameter"]) / 2.0) ** 2 + cup**2) / (2.0 * cup)
        rep.update(cup_radius_mm=r_cup, cup_radii_mm={"cup": r_cup})
    _add_figures(rep, dict(shape=shape, face=face, band_mm=band, cup_depth_mm=cup or 0.0, width_mm=W, length_mm=Ln,
                           elongated=shape == "oval", plan_diameter_mm=_sampled_plan_diameter(tablet)), T, opts)
    return rep


def plan_diameter(tablet: Tablet) -> float:
    """The tablet's largest extent in plan, in any direction (mm): a round tablet's diameter, a capsule's
    length, a rounded square's diagonal: the size a die is chosen by (a TSM B die takes shaped tablets up to
    19 mm across) and the FDA's size guidance reads.  The family outline's closed form
    (:attr:`~tabletcad.families.outline.Outline.diameter`) where the tablet has one, else
    :func:`_sampled_plan_diameter`; never less than the tablet's extents along x and y (a PDE band may stand
    micrometres outside its outline)."""
    lo, hi = tablet.bounds()
    extent = max(float(hi[0] - lo[0]), float(hi[1] - lo[1]))
    outline = getattr(tablet.nominal, "outline", None)
    across = float(outline.diameter) if hasattr(outline, "diameter") else _sampled_plan_diameter(tablet)
    return max(extent, across or 0.0)


def _sampled_plan_diameter(tablet: Tablet) -> float | None:
    """The largest distance (mm) between two of the surface's points in plan: a free-form design need
    not lie along the axes.  None for a tablet of revolution or a cut-away (the extents say it).  A
    tablet whose patches are scaled copies of one centred plan ellipse (the thesis's ovals and caplet:
    ``(x, y) = R(u) N (cos v, sin v)``) has ``2 R_max σ_max(N)``, its extent along x being ``2 R_max
    |Nᵀ x|``; any other, a 33 x 256 sample of every patch, low by at most the square of the sample
    step over the curvature radius."""
    if tablet.revolution is not None or not tablet.trim.whole:
        return None
    sec = tablet.section
    if sec is not None:
        N = np.asarray(sec[0].plan, dtype=float).T
        (lo, hi) = tablet.bounds()
        r_max = max(float(hi[k] - lo[k]) / (2.0 * float(np.linalg.norm(N[k]))) for k in (0, 1) if np.linalg.norm(N[k]) > 0)
        return 2.0 * r_max * float(np.linalg.svd(N, compute_uv=False)[0])
    from tabletcad.families.outline import point_set_diameter

    return point_set_diameter(tablet.sample(33, 256)[..., :2].reshape(-1, 2))
