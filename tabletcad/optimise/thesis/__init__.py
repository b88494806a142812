"""The thesis's three optimisation problems (chapter 6) as ready :class:`Problem` objects.

(a) :func:`flat_faced_round_problem` — section 6.2.1, eqs 6.1-6.6;
(b) :func:`spherical_tablet_problem` — section 6.2.2, eqs 6.7-6.13 (two variants);
(c) :func:`softgel_capsule_problem` — section 6.2.3, eqs 6.22-6.23.

Each problem builds PDE tablets from coaxial circles (the thesis's boundary
curves), evaluates volume with :meth:`Tablet.volume` (divergence theorem,
eq 6.3) and takes its mechanics from :mod:`tabletcad.mechanics`.  The places
where the thesis is ambiguous or inconsistent, and the interpretation taken
here, are listed in each function's docstring and in :data:`THESIS_RESULTS`
/ :func:`thesis_designs`, which re-evaluate the thesis's own reported optima.

Speed: the tablets are built with one Fourier mode per patch (circles need no
more) and a 16-point trapezoidal rule in ``v`` (exact for surfaces of
revolution), with the patch stray/fold checks skipped during the search; the
final design is rebuilt with the checks on and written with default settings,
so ``tabletcad build`` of the written design gives the same volume.

Modules: :mod:`~tabletcad.optimise.thesis.common` (materials, the reported optima, coaxial
builders, design files of optima), :mod:`~tabletcad.optimise.thesis.flat_round` (a),
:mod:`~tabletcad.optimise.thesis.spherical` (b), :mod:`~tabletcad.optimise.thesis.softgel` (c).
"""

from __future__ import annotations

import math
from typing import Any

from tabletcad.errors import DesignError
from tabletcad.mechanics import contact
from tabletcad.optimise.problem import Problem
from tabletcad.optimise.thesis.common import (
    GELATIN, KOSTROLITH, LACTOSE, THESIS_MINUTES, THESIS_RESULTS, _profile_max_radius, coaxial_fast, free_form_toml,
    min_height_slope, round_tablet, sphere_tablet,
)
from tabletcad.optimise.thesis.flat_round import RoundDesign, _round_eval, flat_faced_round_problem
from tabletcad.optimise.thesis.softgel import Capsule, capsule, softgel_capsule_problem
from tabletcad.optimise.thesis.spherical import SphereDesign, _sphere_eval, spherical_tablet_problem

__all__ = [
    "LACTOSE",
    "KOSTROLITH",
    "GELATIN",
    "THESIS_RESULTS",
    "THESIS_MINUTES",
    "coaxial_fast",
    "round_tablet",
    "sphere_tablet",
    "flat_faced_round_problem",
    "spherical_tablet_problem",
    "softgel_capsule_problem",
    "Capsule",
    "RoundDesign",
    "SphereDesign",
    "capsule",
    "thesis_designs",
    "PROBLEMS",
    "make_problem",
    "free_form_toml",
]


PROBLEMS = {
    "flat_faced_round": flat_faced_round_problem,
    "spherical_tablet": spherical_tablet_problem,
    "softgel_capsule": softgel_capsule_problem,
}


def make_problem(kind: str, **params: Any) -> Problem:
    """One of :data:`PROBLEMS` by name with keyword parameters (as read from a problem TOML)."""
    if kind not in PROBLEMS:
        raise DesignError("[problem] kind", kind, "must be one of " + ", ".join(PROBLEMS) + " or family")
    try:
        return PROBLEMS[kind](**params)
    except TypeError as exc:
        raise DesignError(f"[problem] {kind} parameters", sorted(params), f"are not accepted ({exc})") from None


def _fold_message(make) -> str:
    try:
        make()
        return "ok"
    except DesignError as exc:
        return str(exc)


def thesis_designs() -> dict[str, dict]:
    """Re-evaluate the thesis's reported optima with tabletcad (full-accuracy builds).

    Returns, per design: the tabletcad volume and the constraint values of the
    thesis's own formulation, to check whether the reported optima satisfy it.
    """
    out: dict[str, dict] = {}
    L = LACTOSE
    for key in ("flat_faced_round_straight", "flat_faced_round_curved"):
        d = THESIS_RESULTS[key]
        t = round_tablet(d["radii"], d["heights"], check=False, fast=False)
        fold = _fold_message(lambda: round_tablet(d["radii"], d["heights"], check=True, fast=False))
        rows = {}
        for disp, w0 in (("thesis", -1.078), ("thesis", 0.0), ("derived", 0.0)):
            for P in L["P"]:
                e = _round_eval(d["radii"], d["heights"], P, L["A"][1], mass_mg=L["mass_mg"], true_density=L["true_density"],
                                E=L["E"], nu=L["nu"], displacement=disp, omega_z0=w0)
                rows[f"{disp}, omega_z0={w0:g}, P={P:g}"] = dict(
                    thickness_mm=e.thickness, relative_density=e.relative_density,
                    strength_MPa=e.strength if e.heckel_term > 0 and e.relative_density < 1 else None)
        out[key] = dict(volume_mm3=t.volume(), volume_target_mm3=235.0, reported_strength_MPa=d["strength"],
                        min_dz_du_mm=min_height_slope(d["heights"]), fold_check=fold,
                        max_radius_mm=_profile_max_radius(t.patches[1]), evaluations=rows)
    K = KOSTROLITH
    for v, fb in (("a", (7.7, 9.9)), ("b", (8.5, 10.5))):
        d = THESIS_RESULTS[f"spherical_{v}"]
        e = _sphere_eval(d["radii"], d["heights"], E=K["E"], nu=K["nu"], s_y=K["s_y"], r0=K["radius"], fast=False,
                         check=False)
        e2 = _sphere_eval(d["radii"], d["heights"], E=K["E"], nu=K["nu"], s_y=K["s_y"], r0=None, fast=False)
        fold = _fold_message(lambda: sphere_tablet(d["radii"], d["heights"], check=True, fast=False))
        rc = contact.contact_radius_at_yield(K["E"], K["nu"], d["radii"][0], K["s_y"])
        mirrored = [round(2 * d["heights"][0] - z, 4) for z in d["heights"][3:0:-1]]
        out[f"spherical_{v}"] = dict(
            volume_mm3=e.volume, volume_target_mm3=1.44, min_dz_du_mm=min_height_slope(d["heights"]), fold_check=fold,
            force_N=e.force, force_if_omega_from_r_P21_N=e2.force, force_bounds_N=fb, omega_z_mm=e.omega_z,
            strength_MPa=e.strength, reported_strength_MPa=d["strength"], contact_radius_eq_6_11_mm=rc,
            r_P22_mm=d["radii"][3], mirrored_lower_heights_mm=mirrored, reported_lower_heights_mm=list(d["lower_heights"]),
            force_for_reported_strength_N=d["strength"] * 2 * math.pi * rc * rc / (1 - 2 * K["nu"]))
    c = THESIS_RESULTS["softgel_capsule"]
    a, b = c["a"], c["a"] - c["thickness"]
    cap = capsule(a, b, 1.25, GELATIN["P_ext"][1], model="none", fast=False)
    lame = capsule(a, b, 1.25, GELATIN["P_ext"][1], model="lame")
    out["softgel_capsule"] = dict(
        a_mm=a, b_mm=b, volume_outer_mm3=cap.volume_outer, volume_inner_mm3=cap.volume_inner,
        volume_targets_mm3=(GELATIN["V_outer"], GELATIN["V_inner"]), reported_strength_MPa=c["strength"],
        r_d22_for_reported_strength_mm={str(P): math.sqrt(c["strength"] * a * (a - b) / P) for P in GELATIN["P_ext"]},
        lame_mu_r_outer_mm=lame.mu_outer, lame_mu_r_inner_mm=lame.mu_inner)
    return out
