"""Section 6.2.3: the spherical softgel shell of maximum strength (eqs 6.22-6.23)."""

from __future__ import annotations

from dataclasses import dataclass
import math

from tabletcad.errors import DesignError
from tabletcad.mechanics import shell
from tabletcad.optimise.problem import Constraint, Objective, Problem, Variable
from tabletcad.optimise.thesis.common import (
    GELATIN, THESIS_RESULTS, _update_initial, coaxial_fast, free_form_toml,
)
from tabletcad.geometry.tablet import Tablet

__all__ = ["Capsule", "capsule", "softgel_capsule_problem"]


def _sphere_curves(radius: float, r_d22: float | None = None):
    """Curves (radius, z) of the thesis's PDE sphere (30° steps, eqs 4.1-4.3) centred at the
    origin; ``r_d22`` replaces the radius of the curves at ±60° (d22 and, mirrored, d11)."""
    psi = [-math.pi / 2, -math.pi / 3, -math.pi / 6, 0.0, math.pi / 6, math.pi / 3, math.pi / 2]
    pts = [(0.0 if abs(p) == math.pi / 2 else radius * math.cos(p), radius * math.sin(p)) for p in psi]
    if r_d22 is not None:
        pts[1] = (r_d22, pts[1][1])
        pts[5] = (r_d22, pts[5][1])
    return [pts[0:4], pts[3:7]]


@dataclass(frozen=True)
class Capsule:
    """A spherical softgel shell of section 6.2.3: outer and inner PDE spheres and its mechanics."""

    outer: Tablet
    inner: Tablet
    a: float
    b: float
    r_d22: float
    P_ext: float
    volume_outer: float
    volume_inner: float
    mu_outer: float
    mu_inner: float
    mu_contact: float
    strength: float

    @property
    def thickness(self) -> float:
        return self.a - self.b


def capsule(a, b, r_d22, P_ext, *, E=GELATIN["E"], nu=GELATIN["nu"], P_int=GELATIN["P_int"], model="lame",
            n_terms: int = 40, fast=True, check=False) -> Capsule:
    """Evaluate a capsule design: PDE volumes and the radial displacements μ_r of the shell model.

    ``model``: ``"lame"`` (uniform P_ext on the whole outer surface and P_int inside:
    the n = 0 term of eq 6.20, Lamé's solution), ``"band"`` (P_ext on the polar caps
    of half-angle asin(r_d22/a) touched by the platens,
    :func:`tabletcad.mechanics.shell.solve_shell`), or ``"none"`` (μ_r = 0, geometry only).
    μ_r is taken at the equator for ``a`` and ``b`` and at the edge of the contact for ``r_d22``.
    """
    outer = coaxial_fast(_sphere_curves(a, r_d22), name="capsule_outer", check=check, fast=fast)
    inner = coaxial_fast(_sphere_curves(b), name="capsule_inner", check=check, fast=fast)
    Vo, Vi = outer.volume(), inner.volume()
    if model == "none" or not a > b:
        mo = mi = md = 0.0
    elif model == "lame":
        mo = float(shell.lame_displacement(a, a, b, E, nu, P_ext, P_int))
        mi = float(shell.lame_displacement(b, a, b, E, nu, P_ext, P_int))
        md = mo
    elif model == "band":
        psi = math.asin(min(1.0, r_d22 / a))
        sol = shell.solve_shell(a, b, E, nu, p_ext=P_ext, p_int=P_int, psi=psi, n_terms=n_terms, region="poles")
        mo = float(sol.radial_displacement(a, math.pi / 2))
        mi = float(sol.radial_displacement(b, math.pi / 2))
        md = float(sol.radial_displacement(a, psi))
    else:
        raise DesignError("shell model", model, "must be 'lame', 'band' or 'none'")
    sig = P_ext * r_d22 ** 2 / (a * (a - b)) if a > b else math.inf  # eq 6.22
    return Capsule(outer, inner, a, b, r_d22, P_ext, Vo, Vi, mo, mi, md, sig)


def softgel_capsule_problem(*, model: str = "lame", E: float = GELATIN["E"], nu: float = GELATIN["nu"],
                            P_int: float = GELATIN["P_int"], radius_constraints: bool = True,
                            initial: dict | None = None) -> Problem:
    """Section 6.2.3: maximise σ of eq 6.22 of a spherical softgel shell (eqs 6.23a-f).

    Variables ``P_ext`` (31.36-36.56 MPa), ``r_d22`` (contact radius on the outer
    surface), ``a`` (outer radius, P21 of the outer sphere) and ``b`` (inner radius);
    start as in the thesis (31.4 MPa, 1.28, 2.7, 2.1 mm).  Constraints: outer and
    inner volumes 65.45 and 34 mm³ (PDE volumes), and the deformed radii
    ``a + μ_r``, ``b + μ_r``, ``r_d22 + μ_r`` within 2.5-2.8, 2.0-2.3 and 1.25-1.35 mm.

    ``model`` chooses μ_r (see :func:`capsule`); with the thesis's gelatin
    (E = 0.11 MPa) and pressures (31-37 MPa) any linear-elastic μ_r is tens of
    millimetres, so the deformed-radius constraints cannot hold: the problem as
    stated is infeasible, which the solver reports.  ``model="none"`` (μ_r = 0)
    keeps the constraints on the undeformed radii; they are still infeasible by
    0.4 %: the thesis's PDE sphere of radius 2.5 mm encloses 65.69 mm³, not the
    exact sphere's 65.45 mm³, so ``a >= 2.5`` and the outer volume conflict.
    ``radius_constraints=False`` drops 6.23c and 6.23d (the radii are then set
    by the two volumes) and keeps 6.23e: the geometric problem that can be solved.
    """
    st = THESIS_RESULTS["softgel_capsule"]["start"]
    init = dict(st)
    _update_initial(init, initial)
    vs = [Variable("P_ext", GELATIN["P_ext"][0], GELATIN["P_ext"][1], init["P_ext"], "MPa"),
          Variable("r_d22", 1.0, 1.6, init["r_d22"], "mm"),
          Variable("a", 2.2, 3.0, init["a"], "mm"),
          Variable("b", 1.7, 2.5, init["b"], "mm")]

    def build(x):
        return capsule(x["a"], x["b"], x["r_d22"], x["P_ext"], E=E, nu=nu, P_int=P_int, model=model)

    cons = [
        Constraint("outer volume (eq 6.23a)", lambda d: d.volume_outer, kind="eq", target=GELATIN["V_outer"], relative=True, unit="mm3"),
        Constraint("inner volume (eq 6.23b)", lambda d: d.volume_inner, kind="eq", target=GELATIN["V_inner"], relative=True, unit="mm3"),
        Constraint("r_d22 + mu_r (eq 6.23e)", lambda d: d.r_d22 + d.mu_contact, lower=1.25, upper=1.35, unit="mm"),
        Constraint("b < a", lambda x: x["a"] - x["b"], lower=1e-3, uses="x", unit="mm", grad=lambda x, d: {"a": 1.0, "b": -1.0}),
    ]
    if radius_constraints:
        cons[2:2] = [
            Constraint("a + mu_r (eq 6.23c)", lambda d: d.a + d.mu_outer, lower=2.5, upper=2.8, unit="mm"),
            Constraint("b + mu_r (eq 6.23d)", lambda d: d.b + d.mu_inner, lower=2.0, upper=2.3, unit="mm"),
        ]

    def to_toml(x, d):
        return free_form_toml(d.outer, _sphere_curves(x["a"], x["r_d22"]), name="softgel_capsule_outer",
                              comment=f"Outer surface of the optimal softgel shell of section 6.2.3 (tabletcad optimise).\n"
                                      f"Inner surface: PDE sphere of radius b = {x['b']:.9g} mm (same curves), "
                                      f"shell thickness {d.thickness:.6g} mm.\n"
                                      f"sigma (eq 6.22) = {d.strength:.6g} MPa at P_ext = {x['P_ext']:.6g} MPa; "
                                      f"volumes {d.volume_outer:.9g} / {d.volume_inner:.9g} mm3; shell model {model}")

    def extras(x, d):
        return dict(thickness_mm=d.thickness, volume_outer_mm3=d.volume_outer, volume_inner_mm3=d.volume_inner,
                    mu_r_outer_mm=d.mu_outer, mu_r_inner_mm=d.mu_inner, mu_r_contact_mm=d.mu_contact,
                    shell_model=model, material=dict(E=E, nu=nu, P_int=P_int))

    return Problem(
        name="softgel_capsule" + ("" if model != "none" else "_rigid") + ("" if radius_constraints else "_volumes"),
        variables=vs,
        objective=Objective(lambda d: d.strength, "tensile strength (eq 6.22)", "MPa"), sense="max", constraints=cons,
        build=build, to_toml=to_toml, extras=extras,
        description=f"Thesis 6.2.3: spherical softgel shell, volumes 65.45/34 mm3, max sigma of eq 6.22 (shell model {model})",
        reference=THESIS_RESULTS["softgel_capsule"],
    )
