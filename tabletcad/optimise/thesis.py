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
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from tabletcad.errors import DesignError
from tabletcad.mechanics import contact, love, shell, strength
from tabletcad.mechanics.materials import get_material
from tabletcad.optimise.problem import Constraint, Objective, Problem, Variable
from tabletcad.patch import PDEPatch
from tabletcad.shapes import coaxial_tablet
from tabletcad.tablet import Tablet
from tabletcad.tolerance import DEFAULT

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
    "capsule",
    "thesis_designs",
    "PROBLEMS",
    "make_problem",
    "free_form_toml",
]

#: α-lactose monohydrate, section 5.2.1/5.2.2 (E, ν chosen there; Heckel A from Table 5.1).
LACTOSE = dict(E=2640.0, nu=0.21, true_density=1.3, mass_mg=300.0, A=(0.8402, 0.8738), P=(20.0, 60.0),
               heckel_K=(0.0098, 0.0107))
_k = get_material("kostrolith")
#: Köstrolith, Table 5.2.
KOSTROLITH = dict(E=_k.E, nu=_k.nu, s_y=_k.s_y, radius=_k.radius)
#: Gelatin shell, section 6.2.3.
GELATIN = dict(E=0.11, nu=0.4, P_int=7.33, P_ext=(31.36, 36.56), V_outer=65.45, V_inner=34.0)

#: Thesis run times (minutes) of the four optimisations, for the benchmark.
THESIS_MINUTES = {"flat_faced_round": 27, "spherical_a": 43, "spherical_b": 39, "softgel_capsule": 51}

#: The thesis's reported optima (Tables 6.1, 6.2 and section 6.2.3).
THESIS_RESULTS = {
    "flat_faced_round_straight": dict(
        radii=(5.0, 5.0, 5.0, 5.0), heights=(0.0, 0.3, 0.34, 2.99), strength=103.095, iterations=4, minutes=27),
    "flat_faced_round_curved": dict(
        radii=(4.83, 5.15, 5.15, 4.83), heights=(0.0, 0.9, 2.0, 2.93), strength=103.333, iterations=4, minutes=27),
    "spherical_a": dict(  # Table 6.2, Figure 6.3(a): P21, d21, d22, P22 of the upper half
        radii=(0.7047, 0.6255, 0.4251, 0.0883), heights=(0.7000, 1.0245, 1.2620, 1.3489),
        lower_heights=(0.0512, 0.1381, 0.3756), strength=77.1736, iterations=5, minutes=43),
    "spherical_b": dict(
        radii=(0.7561, 0.6975, 0.5625, 0.0948), heights=(0.7000, 1.0499, 1.2500, 1.3335),
        lower_heights=(0.0666, 0.1501, 0.3501), strength=69.1043, iterations=None, minutes=39),
    "softgel_capsule": dict(a=2.5, thickness=0.4252, strength=53.66, iterations=9, minutes=51,
                            start=dict(P_ext=31.4, r_d22=1.28, a=2.7, b=2.1)),
}

_FAST = replace(DEFAULT, quad_v=16)


# ---------------------------------------------------------------------------- geometry
def coaxial_fast(sections, *, name: str = "tablet", check: bool = False, a: float = 1.0, fast: bool = True) -> Tablet:
    """:func:`tabletcad.shapes.coaxial_tablet` of circles ``[(radius, z) × 4]`` with one Fourier
    mode per patch (exact for circles); ``fast=True`` uses a 16-point rule in ``v`` (exact for
    surfaces of revolution); ``check`` runs the patches' stray and fold checks."""
    return coaxial_tablet(sections, a=a, name=name, modes=1, check=check, tol=_FAST if fast else DEFAULT)


def _disc(r: float, z: float, up: bool) -> list[tuple[float, float]]:
    radii = [r, 2 * r / 3, r / 3, 0.0]
    return [(x, z) for x in (radii if up else radii[::-1])]


def round_tablet(radii, heights, *, name: str = "flat_faced_round", check: bool = False, fast: bool = True) -> Tablet:
    """Round tablet of section 6.2.1: flat bottom disc, body patch through the four
    circles ``(radii[k], heights[k])`` (P21, d21, d22, P22), flat top disc."""
    body = list(zip(radii, heights))
    secs = [_disc(radii[0], heights[0], up=False), body, _disc(radii[3], heights[3], up=True)]
    return coaxial_fast(secs, name=name, check=check, fast=fast)


def sphere_tablet(radii, heights, *, name: str = "spherical_tablet", check: bool = False, fast: bool = True) -> Tablet:
    """Two-patch tablet of section 6.2.2 from the upper half's circles P21, d21, d22, P22
    (``radii``, ``heights``), the lower half mirrored about the plane of P21 (eq 6.13:
    P11 = P22, d11 = d22, d12 = d21).  A top circle of radius > 0 gets flat disc
    patches (the contact faces) at both ends."""
    return coaxial_fast(_sphere_sections(radii, heights), name=name, check=check, fast=fast)


def _sphere_sections(radii, heights):
    ze = heights[0]
    up = list(zip(radii, heights))
    low = [(radii[3 - k], 2 * ze - heights[3 - k]) for k in range(4)]
    secs = [low, up]
    if radii[3] > 0:  # flat contact faces as patches, so that the CAD layer sees a closed chain
        secs = [_disc(radii[3], low[0][1], up=False), low, up, _disc(radii[3], heights[3], up=True)]
    return secs


def _profile_max_radius(patch: PDEPatch) -> float:
    """Largest radius of a surface of revolution patch (mm): dense samples + bounded refinement."""
    from scipy.optimize import minimize_scalar

    u = np.linspace(0.0, 1.0, 65)
    rr = patch.radius_profile(u)  # sqrt(A1x² + A1y²), eq 4.22
    k = int(np.argmax(rr))
    if k in (0, len(u) - 1):
        return float(rr[k])
    res = minimize_scalar(lambda s: -float(patch.radius_profile(np.array([s]))[0]),
                          bounds=(u[k - 1], u[k + 1]), method="bounded", options=dict(xatol=1e-12))
    return max(float(rr[k]), -float(res.fun))


def min_height_slope(heights) -> float:
    """Smallest ``dz/du`` on ``[0, 1]`` of a patch's spine through ``heights`` at ``u = 0, 1/3, 2/3, 1``.

    For circles stacked along z the spine is the mode-0 profile, a cubic
    polynomial (λ = 0 cardinal functions), and the solid folds over its spine
    exactly when ``dz/du`` changes sign (the Jacobian of eq 4.12 is ``-R² dz/du``).
    The minimum of the quadratic ``dz/du`` is at an end or at its vertex.
    """
    z0, z1, z2, z3 = (float(h) for h in heights)
    # z(u) = c0 + c1 u + c2 u² + c3 u³ through the four nodes (exact Newton form at 0, 1/3, 2/3, 1)
    d1 = 3 * (z1 - z0)
    d2 = 9 * (z2 - 2 * z1 + z0) / 2
    d3 = 9 * (z3 - 3 * z2 + 3 * z1 - z0) / 2
    # Newton: z = z0 + d1 u + d2 u (u - 1/3) + d3 u (u - 1/3)(u - 2/3)
    c1 = d1 - d2 / 3 + d3 * 2 / 9
    c2 = d2 - d3
    c3 = d3
    cand = [0.0, 1.0]
    if c3 != 0.0:
        uv = -c2 / (3 * c3)
        if 0.0 < uv < 1.0:
            cand.append(uv)
    return min(c1 + 2 * c2 * u + 3 * c3 * u * u for u in cand)


def _update_initial(init: dict, initial: dict | None) -> None:
    """Override starting values by variable name; an unknown name is refused (not ignored)."""
    for k in initial or {}:
        if k not in init:
            raise DesignError(f"initial {k}", initial[k], "is not a variable; variables are " + ", ".join(init))
    init.update(initial or {})


def free_form_toml(tablet: Tablet, sections, *, name: str, comment: str = "") -> str:
    """A ``free_form`` design file (``[[patch]]`` circle curves, ``"previous"``) for ``tabletcad build``."""
    from tabletcad.design import Design

    patches = [{"curves": ["previous" if k == 0 and j > 0 else {"type": "circle", "radius": float(r), "z": float(z)}
                           for k, (r, z) in enumerate(sec)]} for j, sec in enumerate(sections)]
    return Design({"family": "free_form", "name": name, "a": 1.0}, patches, comment=comment).to_toml()


# ---------------------------------------------------------------------------- (a) round tablet
@dataclass(frozen=True)
class RoundDesign:
    """A round-tablet design of section 6.2.1 with its mechanics evaluated."""

    tablet: Tablet
    radii: tuple
    heights: tuple
    P: float
    A: float
    volume: float
    c: float
    h0: float
    omega_z: float
    thickness: float
    relative_density: float
    heckel_term: float
    strength: float
    c_load: float  # radius of the cylinder of eqs 5.18 and 6.1 (mm)


def _round_eval(radii, heights, P, A, *, mass_mg, true_density, E, nu, displacement, omega_z0, density="volume",
                check=False, fast=True) -> RoundDesign:
    t = round_tablet(radii, heights, check=check, fast=fast)
    vol = t.volume()
    c = _profile_max_radius(t.patches[1])
    h0 = float(heights[3] - heights[0])
    # the cylinder of eqs 5.18 and 6.1: the one with the tablet's volume and height ("volume"), whose
    # π c² t is the loaded volume (V/h0) t, or the one of the largest radius (eq 6.2 as printed, "cylinder")
    cl = math.sqrt(vol / (math.pi * h0)) if density == "volume" and vol > 0 and h0 > 0 else c
    # eq 5.18 at the loaded top face (z = h0) on the die wall (r = c), where its ν²/(ν-1) term vanishes
    w = float(love.axial_displacement(P, E, nu, cl, h0, h0, cl, omega_z0=omega_z0, scale=displacement))
    th = h0 + w
    dens = mass_mg / (true_density * math.pi * cl * cl * th) if th > 0 else math.inf
    # eq 6.1/6.2: σ = P / (ln(1/(1-D)) - A); undefined for D >= 1 (reported by a constraint)
    H = -math.log1p(-min(dens, 1.0 - 1e-12)) if dens > 0 else 0.0
    den = H - A
    sig = P / den if den > 0 else P / 1e-12
    return RoundDesign(t, tuple(radii), tuple(heights), P, A, vol, c, h0, w, th, dens, den, sig, cl)


def flat_faced_round_problem(
    *,
    mass_mg: float = LACTOSE["mass_mg"],
    true_density: float = LACTOSE["true_density"],
    E: float = LACTOSE["E"],
    nu: float = LACTOSE["nu"],
    volume: float = 235.0,
    radius_bounds=(4.5, 5.15),
    height_max: float = 3.5,
    P_bounds=LACTOSE["P"],
    A_bounds=LACTOSE["A"],
    displacement: str = "derived",
    omega_z0: float = 0.0,
    density: str = "volume",
    initial: dict | None = None,
) -> Problem:
    """Section 6.2.1: maximise σ of eq 6.2 of a round tablet at fixed volume (eq 6.3).

    Design variables: radii of the body patch's circles P21, d21, d22, P22
    (eq 6.5) and the heights of d21, d22, P22 (eq 6.6; ``z_P21 = 0``), plus the
    pressure ``P`` and the Heckel constant ``A`` within the ranges the thesis
    allows (both end at a bound: σ grows with P and with A).

    Interpretation (the thesis leaves these open):

    * ``c`` of eq 6.2 (``A1x² + A1y²``) is the tablet's largest radius (its
      half-width, the die radius of the load model); ``h0`` is its height.
    * ``ω_z`` is eq 5.18 at the top face ``z = h0`` on the die wall ``r = c``
      (:func:`tabletcad.mechanics.love.axial_displacement`).  ``displacement``
      ="thesis" uses the printed prefactor, "derived" the one eq 5.15 gives
      (100× smaller, see :mod:`tabletcad.mechanics.love`); ``omega_z0`` is the
      adjustment of eq 5.18 (the thesis's -1.078 mm was fitted to a 6 mm powder
      bed, not to a finished tablet; default 0).
    * ``m`` = 300 mg, the tablets of section 5.2.1 (10 mm × 3 mm, 235.6 mm³,
      which is where the volume 235 mm³ comes from); ρ_true = 1.3 mg/mm³.
    * The radius bounds of eq 6.5 hold for the circles *and* for the surface's
      largest radius ``c`` (between close circles a PDE surface bulges beyond
      them; without this the optimiser exploits the bulge, reaching c ≈ 5.35 mm).
    * Relative density (``density``): eq 6.1 is the Heckel density
      ``D = m / (ρ_true π c² t)`` of a flat-faced cylinder of radius ``c``
      under load (thickness ``t = h0 + ω_z``), and eq 5.18 is the displacement
      of such a cylinder in a die.  ``density="volume"`` (default) applies both
      to the cylinder with the tablet's volume ``V`` and height ``h0``,
      ``c = sqrt(V / (π h0))``, so that ``π c² t = (V/h0) t`` is the tablet's
      loaded volume and D agrees with the volume constraint:
      ``D = m h0 / (ρ_true V t)`` (0.982 h0/t for 300 mg in 235 mm³); for a
      cylindrical tablet this is eq 6.1 exactly.  ``density="cylinder"`` takes
      ``c`` = the largest radius (eq 6.2 as printed, ``A1x² + A1y²``): for a
      tablet that is not a cylinder it counts the empty space of the bounding
      cylinder as pores (D = 0.798 at c = 5.15 mm, h0 = 3.5 mm, although 300 mg
      in 235 mm³ is 0.98 dense), and its optimum is the largest bounding cylinder.
    * With ``density="volume"`` σ depends on the design only through ``h0``,
      P and A (the volume is fixed): the taller the tablet, the smaller the
      axial strain ``ω_z/h0 = P/(2G) (ν h0²/c² - (1-ν)/2)`` of eq 5.18 and the
      lower D.  The optimum is ``h0 = height_max`` with P and A at their upper
      bounds, for any profile of that height and volume (the profile the
      solver returns is one of them).
    * Two constraints make the objective meaningful: ``D <= 1`` and
      ``ln(1/(1-D)) - A > 0``.
    """
    if density not in ("volume", "cylinder"):
        raise DesignError("density", density, "must be 'volume' (V t / h0) or 'cylinder' (π c² t, eq 6.2 as printed)")
    rlo, rhi = radius_bounds
    init = dict(r_P21=5.0, r_d21=5.0, r_d22=5.0, r_P22=5.0, z_d21=1.0, z_d22=2.0, z_P22=3.0,
                P=float(np.mean(P_bounds)), A=float(np.mean(A_bounds)))
    _update_initial(init, initial)
    vs = [Variable(n, rlo, rhi, init[n], "mm") for n in ("r_P21", "r_d21", "r_d22", "r_P22")]
    vs += [Variable(n, 0.0, height_max, init[n], "mm") for n in ("z_d21", "z_d22", "z_P22")]
    vs += [Variable("P", P_bounds[0], P_bounds[1], init["P"], "MPa"), Variable("A", A_bounds[0], A_bounds[1], init["A"])]
    kw = dict(mass_mg=mass_mg, true_density=true_density, E=E, nu=nu, displacement=displacement, omega_z0=omega_z0,
              density=density)

    def parts(x):
        return ((x["r_P21"], x["r_d21"], x["r_d22"], x["r_P22"]), (0.0, x["z_d21"], x["z_d22"], x["z_P22"]))

    def build(x):
        r, z = parts(x)
        return _round_eval(r, z, x["P"], x["A"], **kw)

    def lin(a, b):
        return Constraint(f"z_{a} <= z_{b} (eq 6.6)", lambda x: x[f"z_{b}"] - x[f"z_{a}"], lower=0.0, uses="x", unit="mm",
                          scale=height_max, grad=lambda x, d: {f"z_{b}": 1.0, f"z_{a}": -1.0})

    cons = [
        Constraint("volume (eq 6.3)", lambda d: d.volume, kind="eq", target=volume, relative=True, unit="mm3"),
        lin("d21", "d22"),
        lin("d22", "P22"),
        Constraint("body spine monotone, no fold (min dz/du >= 0)", lambda x: min_height_slope(parts(x)[1]), lower=0.0,
                   uses="x", unit="mm", scale=height_max),
        Constraint("largest radius c <= r_max (eq 6.5 on the surface)", lambda d: d.c, upper=rhi, unit="mm", scale=rhi),
        Constraint("relative density D <= 1", lambda d: d.relative_density if math.isfinite(d.relative_density) else 1e6,
                   upper=1.0, scale=1.0),
        Constraint("ln(1/(1-D)) - A > 0 (eq 6.1 defined)", lambda d: d.heckel_term, lower=1e-3, scale=1.0),
    ]

    def to_toml(x, d):
        r, z = parts(x)
        secs = [_disc(r[0], z[0], False), list(zip(r, z)), _disc(r[3], z[3], True)]
        return free_form_toml(d.tablet, secs, name="flat_faced_round_optimum",
                              comment=f"Optimum of the thesis's section 6.2.1 problem (tabletcad optimise).\n"
                                      f"sigma_T^a (eq 6.2) = {d.strength:.6g} MPa at P = {x['P']:.6g} MPa, A = {x['A']:.6g}; "
                                      f"volume {d.volume:.9g} mm3")

    def extras(x, d):
        return dict(volume_mm3=d.volume, max_radius_mm=d.c, height_mm=d.h0, omega_z_mm=d.omega_z,
                    compressed_thickness_mm=d.thickness, relative_density=d.relative_density,
                    heckel_denominator=d.heckel_term,
                    interpretation=dict(mass_mg=mass_mg, true_density=true_density, E=E, nu=nu,
                                        displacement=displacement, omega_z0=omega_z0, density=density))

    def bound(P=P_bounds[1], A=A_bounds[1]):
        """σ of the best shape the bounds allow (MPa): with ``density="volume"`` the cylinder of height
        ``height_max`` holding the volume (the optimum), with ``"cylinder"`` the largest bounding cylinder
        (an upper bound of the optimum)."""
        h = height_max
        c = math.sqrt(volume / (math.pi * h)) if density == "volume" else rhi
        w = float(love.axial_displacement(P, E, nu, c, h, h, c, omega_z0=omega_z0, scale=displacement))
        D = mass_mg / (true_density * math.pi * c * c * (h + w))
        den = -math.log1p(-D) - A if 0 < D < 1 else math.nan
        return P / den if den > 0 else math.nan  # nan: no admissible design (eq 6.1 undefined)

    return Problem(
        name="flat_faced_round", variables=vs, objective=Objective(lambda d: d.strength, "tensile strength (eq 6.2)", "MPa"),
        sense="max", constraints=cons, build=build, to_toml=to_toml, extras=extras,
        description="Thesis 6.2.1: round tablet, body patch circles (eqs 6.5, 6.6), fixed volume (6.3), max sigma of eq 6.2",
        reference=dict(THESIS_RESULTS["flat_faced_round_curved"], upper_bound_MPa=bound()),
    )


# ---------------------------------------------------------------------------- (b) spherical tablet
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


# ---------------------------------------------------------------------------- (c) softgel capsule
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


# ---------------------------------------------------------------------------- registry
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


# ---------------------------------------------------------------------------- the thesis's own optima
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
