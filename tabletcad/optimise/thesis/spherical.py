"""Section 6.2.2: the spherical tablet of maximum tensile strength under a platen force (eqs 6.7-6.13)."""

from __future__ import annotations

from dataclasses import dataclass
import math

from tabletcad.errors import DesignError
from tabletcad.mechanics import contact, strength
from tabletcad.optimise.problem import Constraint, Objective, Problem, Variable
from tabletcad.optimise.thesis.common import (
    KOSTROLITH, THESIS_RESULTS, _sphere_sections, _update_initial, free_form_toml, min_height_slope,
    sphere_tablet,
)
from tabletcad.geometry.tablet import Tablet

__all__ = ["SphereDesign", "spherical_tablet_problem"]


@dataclass(frozen=True)
class SphereDesign:
    tablet: Tablet
    radii: tuple
    heights: tuple
    volume: float
    height: float
    omega_z: float
    omega_yield: float
    force: float
    contact_radius: float
    strength: float


def _sphere_eval(radii, heights, *, E, nu, s_y, r0=None, check=False, fast=True) -> SphereDesign:
    t = sphere_tablet(radii, heights, check=check, fast=fast)
    vol = t.volume()
    rs = float(radii[0])
    h = 2.0 * (heights[3] - heights[0])
    # approach of the platens: from the undeformed sphere of radius r0 (Table 5.2), or of radius r_P21
    w = 2.0 * (rs if r0 is None else r0) - h
    wy = contact.yield_displacement(E, nu, rs, s_y)
    # eq 6.8 = eq 2.1 (Antonyuk) with ω' from eq 5.22; below yield it is continued smoothly
    ww = max(w, 1e-12)
    F = math.pi * s_y * rs * ww / 2.0 * (1.0 - (wy / ww) ** (1.0 / 3.0) / 3.0)
    if w >= wy:
        F = float(contact.elastic_plastic_force(w, rs, s_y, wy))
    rc = contact.contact_radius_at_yield(E, nu, rs, s_y)
    sig = strength.sphere_hertz(F, E, nu, rs, s_y) if F > 0 else F * (1 - 2 * nu) / (2 * math.pi * rc * rc)
    return SphereDesign(t, tuple(radii), tuple(heights), vol, h, w, wy, F, rc, sig)


def spherical_tablet_problem(
    variant: str = "a",
    *,
    force_bounds=None,
    radius_bounds=None,
    volume: float = 1.44,
    material: dict | None = None,
    reference_radius: float | None = KOSTROLITH["radius"],
    initial: dict | None = None,
) -> Problem:
    """Section 6.2.2: maximise σ of eq 6.7 of a Köstrolith tablet at fixed volume 1.44 mm³.

    ``variant="a"``: force 7.7-9.9 N, r_P21 0.7-0.8 mm; ``"b"``: 8.5-10.5 N, 0.75-0.85 mm.
    Variables: radii of P21, d21, d22, P22 and heights of d21, d22, P22 of the
    upper half (``z_P21 = 0.7`` mm; the lower half is mirrored, eq 6.13).

    Interpretation: the platen approach ``ω_z`` in eq 6.8 is ``2 r0 - h``, the
    flattening of the undeformed Köstrolith sphere of radius ``r0 = 0.7`` mm
    (Table 5.2, ``reference_radius``) to the tablet's height
    ``h = 2 (z_P22 - z_P21)``: this is how the thesis's "7.31 % vertical
    reduction, 0.67 % horizontal enlargement" of Figure 6.3(a) are measured,
    and the volume 1.44 mm³ is that sphere's (4/3 π 0.7³ = 1.437 mm³), i.e.
    the compression conserves volume.  ``reference_radius=None`` measures
    from the sphere of radius ``r_P21`` instead.  ``r_s = r_P21`` in eq 6.8 as
    printed.  ``r_P22`` is the contact radius of eq 6.11, so the top and
    bottom are flat contact faces of that radius.
    """
    mat = dict(KOSTROLITH, **(material or {}))
    E, nu, s_y = mat["E"], mat["nu"], mat["s_y"]
    if variant not in ("a", "b"):
        raise DesignError("variant", variant, "must be 'a' (7.7-9.9 N) or 'b' (8.5-10.5 N)")
    fb = force_bounds or ((7.7, 9.9) if variant == "a" else (8.5, 10.5))
    rb = radius_bounds or ((0.7, 0.8) if variant == "a" else (0.75, 0.85))
    ze = 0.7
    k_rc = math.pi * s_y * (1 - nu * nu) / (2 * E)  # r_P22 = k_rc r_P21 (eq 6.11)
    r0 = rb[0] + 0.25 * (rb[1] - rb[0])
    hh = 0.93 * (reference_radius or r0)  # half-height of the start: 7 % flatter than the reference sphere
    init = dict(r_P21=r0, r_d21=0.87 * r0, r_d22=0.55 * r0, r_P22=k_rc * r0,
                z_d21=ze + 0.5 * hh, z_d22=ze + 0.85 * hh, z_P22=ze + hh)
    _update_initial(init, initial)
    vs = [Variable("r_P21", rb[0], rb[1], init["r_P21"], "mm")]
    vs += [Variable(n, 0.0, rb[1], init[n], "mm") for n in ("r_d21", "r_d22", "r_P22")]
    vs += [Variable(n, ze, ze + 1.2 * rb[1], init[n], "mm") for n in ("z_d21", "z_d22", "z_P22")]

    def parts(x):
        return ((x["r_P21"], x["r_d21"], x["r_d22"], x["r_P22"]), (ze, x["z_d21"], x["z_d22"], x["z_P22"]))

    def build(x):
        r, z = parts(x)
        return _sphere_eval(r, z, E=E, nu=nu, s_y=s_y, r0=reference_radius)

    def order(a, b, kind):
        return Constraint(f"{kind}_{a} <= {kind}_{b} (eq {'6.10' if kind == 'r' else 'ordering'})",
                          lambda x: x[f"{kind}_{b}"] - x[f"{kind}_{a}"], lower=0.0, uses="x", unit="mm", scale=rb[1],
                          grad=lambda x, d: {f"{kind}_{b}": 1.0, f"{kind}_{a}": -1.0})

    cons = [
        Constraint("axial force F_ep (eq 6.8)", lambda d: d.force, lower=fb[0], upper=fb[1], unit="N"),
        Constraint("volume (eq 6.12)", lambda d: d.volume, kind="eq", target=volume, relative=True, unit="mm3"),
        Constraint("r_P22 = contact radius (eq 6.11)", lambda x: x["r_P22"] - k_rc * x["r_P21"], kind="eq", target=0.0,
                   uses="x", unit="mm", scale=0.1, grad=lambda x, d: {"r_P22": 1.0, "r_P21": -k_rc}),
        order("P22", "d22", "r"), order("d22", "d21", "r"), order("d21", "P21", "r"),
        order("d21", "d22", "z"), order("d22", "P22", "z"),
        Constraint("spine monotone, no fold (min dz/du >= 0)", lambda x: min_height_slope(parts(x)[1]), lower=0.0,
                   uses="x", unit="mm", scale=rb[1]),
    ]

    def to_toml(x, d):
        r, z = parts(x)
        return free_form_toml(d.tablet, _sphere_sections(r, z), name=f"spherical_tablet_{variant}_optimum",
                              comment=f"Optimum of the thesis's section 6.2.2 problem, variant {variant} (tabletcad optimise).\n"
                                      f"sigma_T^s (eq 6.7) = {d.strength:.6g} MPa at F_ep = {d.force:.6g} N; volume {d.volume:.9g} mm3")

    def extras(x, d):
        return dict(volume_mm3=d.volume, height_mm=d.height, omega_z_mm=d.omega_z, yield_displacement_mm=d.omega_yield,
                    force_N=d.force, contact_radius_mm=d.contact_radius,
                    material=dict(E=E, nu=nu, s_y=s_y), force_bounds_N=list(fb), radius_bounds_mm=list(rb))

    return Problem(
        name=f"spherical_tablet_{variant}", variables=vs,
        objective=Objective(lambda d: d.strength, "tensile strength (eq 6.7)", "MPa"), sense="max", constraints=cons,
        build=build, to_toml=to_toml, extras=extras,
        description=f"Thesis 6.2.2 variant {variant}: Köstrolith sphere, force {fb[0]}-{fb[1]} N, r_P21 {rb[0]}-{rb[1]} mm, "
                    f"volume {volume} mm3, max sigma of eq 6.7",
        reference=THESIS_RESULTS[f"spherical_{variant}"],
    )
