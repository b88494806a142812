"""Section 6.2.1: the flat-faced round tablet of maximum tensile strength (eqs 6.1-6.6)."""

from __future__ import annotations

from dataclasses import dataclass
import functools
import math

import numpy as np

from tabletcad.errors import DesignError
from tabletcad.mechanics import love
from tabletcad.optimise.problem import Constraint, Objective, Problem, Variable
from tabletcad.optimise.thesis.common import (
    LACTOSE, THESIS_RESULTS, _disc, _profile_max_radius, _update_initial, free_form_toml, min_height_slope,
    round_tablet,
)
from tabletcad.geometry.tablet import Tablet

__all__ = ["RoundDesign", "flat_faced_round_problem"]


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


@functools.lru_cache(maxsize=32)
def _round_geometry(key: bytes, n: int, check: bool, fast: bool) -> tuple[Tablet, float, float]:
    """The tablet of the ``n`` radii and ``n`` heights packed in ``key`` (float64), its volume (mm³) and
    largest radius (mm).
    A solver's finite differences in ``P`` and ``A`` (and its line searches) ask for the same shape
    again: it is built once (the same floats give the same tablet, bit for bit)."""
    rz = np.frombuffer(key, dtype=float)
    t = round_tablet(tuple(float(r) for r in rz[:n]), tuple(float(z) for z in rz[n:]), check=check, fast=fast)
    return t, t.volume(), _profile_max_radius(t.patches[1])


def _round_eval(radii, heights, P, A, *, mass_mg, true_density, E, nu, displacement, omega_z0, density="volume",
                check=False, fast=True) -> RoundDesign:
    key = np.asarray([*radii, *heights], dtype=float).tobytes()
    t, vol, c = _round_geometry(key, len(radii), bool(check), bool(fast))
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
