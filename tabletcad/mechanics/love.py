"""The thesis's Love stress-function model of a powder bed in a die (eqs 5.2-5.18).

What the thesis does
--------------------
A polynomial biharmonic Love function φ(r, z) (eq 5.9, eight terms with
constants a₂…a₆, b₂…b₆) gives stresses and displacements through eqs 5.2-5.7
(reproduced by :func:`love_fields`).  Boundary conditions 5.10a-d (free top
and bottom shear, ``σ_z = 0`` at ``z = 0``, ``σ_z = -P`` at ``z = h0``,
``ω_z = ∂ω_z/∂r = 0`` at ``z = 0`` and ``μ_r = 0`` at the die wall ``r = c``)
are imposed on eqs 5.11-5.14 to give the "constants" 5.15, which yield the
axial displacement 5.16, shifted by an empirical ``ω_z0`` in eq 5.18::

    ω_z = ω_z0 + 100 P z² (1+ν) / (E h0) · [z² ν / r² - (1-ν)/2 + ν²/(ν-1) · (1 - c²/r²)]

What a symbolic check shows (``tests/test_mechanics_love.py`` repeats it with sympy)
-----------------------------------------------------------------------------------
* φ of eq 5.9 with *constant* coefficients is biharmonic, and eqs 5.11-5.14
  are exactly eqs 5.2-5.7 applied to it.
* With constant coefficients, conditions 5.10a-d have **no solution**: they are
  15 linear equations in 7 unknowns of rank 7 whose augmented rank is 8.
* The printed 5.15 depend on r and z.  They satisfy every condition when
  substituted *after* differentiation (pointwise), but then φ is no longer
  biharmonic and the fields are not an elasticity solution.
* Substituting 5.15 into 5.14 gives ``ω_z = P z²/(2 G h0) · [...]``, the
  bracket of eq 5.16 but with ``1/2`` where eq 5.16 has ``50``: eq 5.16 is
  100 times the expression it is said to follow from.

Assumptions made here where the thesis is silent
------------------------------------------------
* ``h0 = 6.0 mm``: the thesis quotes the experimental displacement at 10 MPa
  as -1.2935 mm, which is 4.7065 - 6.0 (the Appendix B thickness at the first
  row at or above 10 MPa, 10.70 MPa, minus 6.0 mm).
* The displacement is taken on the die wall ``r = c`` (the ν²/(ν-1) term
  vanishes; on the axis ``r → 0`` eq 5.16 diverges) at the height
  ``z = 2.9635 mm`` above the fixed lower punch (:data:`THESIS_Z`): the height
  at which eq 5.18 gives the thesis's model displacement, -0.2155 mm at
  10 MPa, so that ω_z0 is the thesis's -1.078 mm.  It lies 0.04 mm below the
  nominal 3 mm tablet thickness, which gives -0.2196 mm instead (no rounder
  choice of z, r, h0 reproduces -0.2155).  Both are parameters.
* The simulated compact thickness is ``h = h0 + ω_z`` and its relative density
  ``m / (ρ_true π c² h)``.
* ``ω_z0`` is the experimental displacement at the reference pressure minus
  the model's (thesis: -1.2935 - (-0.2155) = -1.078 mm).

For comparison, :func:`confined_compression` gives the exact linear-elastic
answer for a frictionless rigid die (uniaxial strain).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from tabletcad.errors import DesignError, check_positive, check_range, format_bound
from tabletcad.mechanics.compaction import MIN_PEAK_RELATIVE_DENSITY, relative_density
from tabletcad.mechanics.heckel import HeckelFit, fit_heckel_arrays
from tabletcad.tolerance import DEFAULT, MAX_MODULUS_MPA

__all__ = [
    "THESIS_DIAMETER",
    "THESIS_H0",
    "THESIS_Z",
    "ConfinedCompression",
    "LoveConstants",
    "SimulatedCompression",
    "adjustment_omega_z0",
    "axial_displacement",
    "confined_compression",
    "love_fields",
    "model_allowed",
    "model_range",
    "omega_z0_allowed",
    "omega_z0_range",
    "simulate_compression",
    "thesis_constants",
]

#: Initial powder-bed height inferred from the thesis's numbers, mm.
THESIS_H0 = 6.0
#: Die diameter of the thesis's α-lactose case, mm (``simulate_compression``'s default).
THESIS_DIAMETER = 10.0
#: Height above the fixed lower punch at which the model displacement is evaluated, mm: where eq 5.18
#: (r = c, h0 = 6 mm) gives the thesis's -0.2155 mm at 10 MPa (root 2.96347; the nominal thickness 3 mm gives -0.2196).
THESIS_Z = 2.9635


@dataclass(frozen=True)
class LoveConstants:
    """Coefficients of eq 5.9 (``c2 = (10 - 12ν) b2 - 4 a2``); units follow from φ in N·mm."""

    a6: float
    b6: float
    a4: float
    b4: float
    a3: float
    b3: float
    c2: float


def thesis_constants(P: float, nu: float, c: float, h0: float, r: float, z: float) -> LoveConstants:
    """The printed eq 5.15 evaluated at a point (they depend on r and z, see module docstring)."""
    g = nu
    return LoveConstants(
        a6=-P * (-7 + 11 * g) / (5280 * h0 * r**2),
        b6=P / (528 * h0 * r**2),
        a4=-P * (-1 + 7 * g) / (1344 * h0),
        b4=P / (56 * h0),
        a3=-P * z * (4 * z**2 - 4 * z**2 * g + 3 * c**2 * g - 3 * r**2 * g) * (5 * g - 7) / (180 * h0 * r**2 * (g - 1)),
        b3=P * z * (4 * z**2 - 4 * z**2 * g + 3 * c**2 * g - 3 * r**2 * g) / (30 * h0 * r**2 * (g - 1)),
        c2=-P * r**2 * (g - 2) / (8 * h0),
    )


def love_fields(k: LoveConstants, r, z, E: float, nu: float) -> dict[str, np.ndarray]:
    """Stresses (MPa) and displacements (mm) of eqs 5.11-5.14 for given coefficients.

    Returns a dict with ``sigma_z``, ``tau_rz``, ``mu_r`` and ``omega_z``.
    """
    g = nu
    G = E / (2.0 * (1.0 + nu))
    r = np.asarray(r, dtype=float)
    z = np.asarray(z, dtype=float)
    sz = (k.a6 * (960 * r**2 * z - 640 * z**3) + k.b6 * ((448 - 704 * g) * z**3 - (1728 - 1056 * g) * z * r**2)
          - 192 * k.a4 * z + 4 * k.b4 * (16 - 14 * g) * z - 12 * k.a3 + k.b3 * (14 - 10 * g))
    trz = (k.a6 * (960 * z**2 * r - 240 * r**3) + k.b6 * ((432 - 264 * g) * r**3 + (-672 + 1056 * g) * r * z**2)
           + 96 * k.a4 * r - 2 * k.b4 * (16 - 14 * g) * r)
    mur = (k.a6 * (320 * z**3 * r - 240 * r**3 * z) + k.b6 * (128 * z**3 * r + 168 * z * r**3) + 96 * k.a4 * r * z
           - 4 * k.b4 * r * z + 6 * k.a3 * r - 2 * k.b3 * r) / (2 * G)
    wz = (k.b6 * ((174 - 132 * g) * r**4 - (864 - 1056 * g) * r**2 * z**2 + (112 - 352 * g) * z**4)
          - k.a6 * (160 * z**4 - 480 * r**2 * z**2 + 60 * r**4) + k.b4 * ((32 - 56 * g) * z**2 - (30 - 28 * g) * r**2)
          - k.a4 * (96 * z**2 - 48 * r**2) + (14 - 20 * g) * k.b3 * z - 12 * k.a3 * z + k.c2) / (2 * G)
    return {"sigma_z": sz, "tau_rz": trz, "mu_r": mur, "omega_z": wz}


def axial_displacement(
    P, E: float, nu: float, c: float, h0: float, z: float, r: float, *, omega_z0: float = 0.0,
    scale: str = "thesis",
) -> np.ndarray:
    """Axial displacement ω_z (mm) of eqs 5.16/5.18 at pressure ``P`` (MPa).

    Parameters
    ----------
    P : array_like
        Axial pressure, MPa (compressive positive).
    E, nu : float
        Young's modulus (MPa) and Poisson's ratio.
    c : float
        Die radius, mm.
    h0 : float
        Initial bed height, mm.
    z, r : float
        Point at which the displacement is evaluated, mm (``Tolerances.min_length <= r <= c``).
    omega_z0 : float
        Adjustment of eq 5.18, mm.
    scale : {"thesis", "derived"}
        ``"thesis"`` uses the printed prefactor ``50 P z²/(G h0)``;
        ``"derived"`` the prefactor ``P z²/(2 G h0)`` that substituting 5.15
        into 5.14 actually gives (100 times smaller).
    """
    E = check_positive("E", E, "MPa")
    nu = check_range("nu", nu, 0.0, 0.5, hi_open=True)
    c = check_positive("c", c, "mm")
    h0 = check_positive("h0", h0, "mm")
    # a radius is a length: 0 or at least Tolerances.min_length, and 0 divides (r = 1e-300 mm had squared to
    # 0: ZeroDivisionError, exit 1 in `tabletcad love --r 1e-300`)
    r = check_range("r", r, DEFAULT.min_length, c, "mm")
    z = check_range("z", z, 0.0, None, "mm")
    if scale not in ("thesis", "derived"):
        raise DesignError("scale", scale, "must be 'thesis' or 'derived'")
    G = E / (2.0 * (1.0 + nu))
    pref = 50.0 if scale == "thesis" else 0.5
    bracket = z * z * nu / (r * r) - (1.0 - nu) / 2.0 + nu * nu / (nu - 1.0) * (1.0 - c * c / (r * r))
    return omega_z0 + pref * np.asarray(P, dtype=float) * z * z / (G * h0) * bracket


def adjustment_omega_z0(experimental_displacement: float, model_displacement: float) -> float:
    """ω_z0 of eq 5.18: experimental minus model displacement at the reference pressure (mm)."""
    return float(experimental_displacement) - float(model_displacement)


@dataclass(frozen=True)
class SimulatedCompression:
    """A compression curve simulated with eq 5.18 and its Heckel fit.

    Attributes
    ----------
    pressure : ndarray
        MPa.
    omega_z : ndarray
        Axial displacement, mm.
    thickness : ndarray
        ``h0 + ω_z``, mm.
    relative_density : ndarray
    heckel : HeckelFit
        Fit over the whole simulated pressure range.
    omega_z0 : float
        mm.
    assumptions : dict
        h0_mm, z_mm, r_mm, c_mm, E_MPa, nu, scale, reference_pressure_MPa and the model's and the
        experiment's displacements there (mm).
    """

    pressure: np.ndarray
    omega_z: np.ndarray
    thickness: np.ndarray
    relative_density: np.ndarray
    heckel: HeckelFit
    omega_z0: float
    assumptions: dict


def simulate_compression(
    pressures,
    *,
    E: float = 2640.0,
    nu: float = 0.21,
    diameter: float = THESIS_DIAMETER,
    mass_mg: float = 300.0,
    true_density: float = 1.3,
    h0: float = THESIS_H0,
    z: float = THESIS_Z,
    r: float | None = None,
    omega_z0: float | None = None,
    reference_pressure: float = 10.0,
    experimental_displacement: float = -1.2935,
    scale: str = "thesis",
) -> SimulatedCompression:
    """Simulate the die compression of eq 5.18 and fit Heckel's equation to it.

    Defaults are the thesis's α-lactose case (E = 2640 MPa, ν = 0.21, 10 mm die,
    300 mg, 1.3 mg/mm³) with the assumptions listed in the module docstring.
    If ``omega_z0`` is None it is set so that the model matches
    ``experimental_displacement`` (mm) at ``reference_pressure`` (MPa).
    """
    P = np.asarray(pressures, dtype=float).ravel()
    c = check_positive("diameter", diameter, "mm") / 2.0
    r = c if r is None else r
    model_ref = float(axial_displacement(reference_pressure, E, nu, c, h0, z, r, scale=scale))
    given = omega_z0 is not None
    if not given:
        omega_z0 = adjustment_omega_z0(experimental_displacement, model_ref)
    else:  # (-5.9 mm in a 6 mm bed had been refused as a bed pressed to nothing, -4 mm as the fit's window)
        lo, hi = omega_z0_range(P, E=E, nu=nu, diameter=diameter, mass_mg=mass_mg, true_density=true_density,
                                h0=h0, z=z, r=r, scale=scale)
        w0 = check_range("omega_z0", omega_z0, None, None, "mm")
        if not lo < w0 <= hi:
            raise DesignError("omega_z0", omega_z0, omega_z0_allowed(lo, hi, P.size), "mm")
    w = axial_displacement(P, E, nu, c, h0, z, r, omega_z0=omega_z0, scale=scale)
    h = h0 + w
    if np.any(h <= 0):
        _refuse_collapse(float(P[h <= 0][0]), float(omega_z0), h0, given)
    D = relative_density(h, mass_mg, true_density, math.pi * c * c)
    fit = fit_heckel_arrays(P, D, window=(float(P.min()), float(P.max())))
    return SimulatedCompression(
        pressure=P, omega_z=w, thickness=h, relative_density=D, heckel=fit, omega_z0=float(omega_z0),
        assumptions={"h0_mm": h0, "z_mm": z, "r_mm": r, "c_mm": c, "E_MPa": E, "nu": nu, "scale": scale,
                     "reference_pressure_MPa": reference_pressure, "model_displacement_at_reference_mm": model_ref,
                     "experimental_displacement_mm": experimental_displacement},
    )


#: Fewest simulated points with a Heckel term (relative density < 1) that the fit takes (its window's rule).
_MIN_FIT_POINTS = 3


def omega_z0_range(pressures, *, E: float = 2640.0, nu: float = 0.21, diameter: float = THESIS_DIAMETER,
                   mass_mg: float = 300.0, true_density: float = 1.3, h0: float = THESIS_H0, z: float = THESIS_Z,
                   r: float | None = None, scale: str = "thesis") -> tuple[float, float]:
    """The adjustments ``omega_z0`` (mm) with which :func:`simulate_compression` runs: ``lo < omega_z0 <= hi``,
    or ``(nan, nan)`` when none does.

    The thickness is ``h(P) = h0 + omega_z0 + w(P)``, ``w`` the model displacement without adjustment, and
    the relative density ``D = h_D / h`` with ``h_D = m / (rho A)``, so each rule is a bound on ``omega_z0``:
    the bed stays thicker than 0 at every pressure (``> -h0 - min w``), at least 3 points keep ``D < 1``
    for the Heckel fit (``> h_D - h0 - w_3``, ``w_3`` the third largest), and the densest point reaches
    ``MIN_PEAK_RELATIVE_DENSITY`` (``<= h_D / 0.05 - h0 - min w``)."""
    P = np.asarray(pressures, dtype=float).ravel()
    c = check_positive("diameter", diameter, "mm") / 2.0
    r = c if r is None else r
    w = np.sort(axial_displacement(P, E, nu, c, h0, z, r, scale=scale))[::-1]  # largest (thickest) first
    if w.size < _MIN_FIT_POINTS:
        return (math.nan, math.nan)
    h_dense = float(relative_density(1.0, mass_mg, true_density, math.pi * c * c))  # h at D = 1
    lo = max(-h0 - float(w[-1]), h_dense - h0 - float(w[_MIN_FIT_POINTS - 1]))
    hi = h_dense / MIN_PEAK_RELATIVE_DENSITY - h0 - float(w[-1])
    if not lo < hi:
        return (math.nan, math.nan)

    def runs(omega_z0: float) -> bool:  # the three rules in the model's own arithmetic
        h = h0 + axial_displacement(P, E, nu, c, h0, z, r, omega_z0=omega_z0, scale=scale)
        if np.any(h <= 0.0):
            return False
        D = relative_density(h, mass_mg, true_density, math.pi * c * c)
        return int(np.sum(D < 1.0)) >= _MIN_FIT_POINTS and float(np.max(D)) >= MIN_PEAK_RELATIVE_DENSITY

    # the closed forms round differently from the model's sums: the value next to lo had been let through
    # and refused by the model as the fit's window (h0 = 4.3 mm) or a bed pressed to nothing (E = 483.6 MPa)
    scale_mm = max(abs(lo), abs(hi), h0, float(np.max(np.abs(w))))
    lo = _exact_edge(runs, lo, math.inf, scale_mm)
    hi = _exact_edge(runs, hi, -math.inf, scale_mm, closed=True)
    return (lo, hi) if lo < hi else (math.nan, math.nan)


def _exact_edge(runs, edge: float, inward: float, scale: float, closed: bool = False) -> float:
    """``edge`` of a range of ``omega_z0`` (mm) moved inward to where ``runs`` holds in floating point.

    ``runs`` is monotonic in ``omega_z0`` (each rule is a bound on ``h0 + omega_z0 + w``).  An open edge
    (``closed`` False) must be followed, towards ``inward`` (``±inf``), by a value that runs; a closed one
    must run itself.  Where not, the edge is moved by doubling steps from an ulp of ``scale`` (mm) and
    bisection to the last value that does not run (open) or the first that does (closed)."""
    first = edge if closed else math.nextafter(edge, inward)
    if runs(first):
        return edge
    step = math.ulp(scale)
    sign = 1.0 if inward > 0 else -1.0
    bad, good = edge, edge + sign * step
    for _ in range(64):  # (a few ulps in practice)
        if runs(good):
            break
        bad, step = good, 2.0 * step
        good = edge + sign * step
    else:
        return math.nan
    while True:
        mid = bad + (good - bad) / 2.0
        if mid in (bad, good):
            break
        if runs(mid):
            good = mid
        else:
            bad = mid
    return good if closed else bad


def omega_z0_allowed(lo: float, hi: float, n: int, cap: float | None = None) -> str:
    """The refusal's range of ``omega_z0`` for :func:`omega_z0_range`'s ``(lo, hi)`` over ``n`` pressures
    (``cap``: a caller's own limit ``|omega_z0| <= cap``, already applied to ``lo`` and ``hi``)."""
    why = (f"so that the bed stays thicker than 0, at least {_MIN_FIT_POINTS} of the {n} simulated points keep a "
           f"relative density below 1 for the Heckel fit and the densest reaches {MIN_PEAK_RELATIVE_DENSITY:g}"
           + (f"; and within ±{cap:g} mm, a shift of the punch face by at most the bed's height" if cap else ""))
    if math.isnan(lo):
        return f"no value works with these options ({why})"
    low = ">=" if cap is not None and lo == -cap else ">"
    return f"must be {low} {format_bound(lo, upper=False)} and <= {format_bound(hi, upper=True)} mm ({why})"


#: Points of :func:`model_range`'s scan of a parameter's limits, and its bisection steps at each end.
_SCAN_POINTS = 400
_BISECTIONS = 48


def _model_limits(name: str, model: dict) -> tuple[float, float, bool]:
    """The scan of :func:`model_range` for ``name``: ``(low, high, log scale)``, within the model's own
    checks (E > 0 MPa up to 1e7, 0 <= nu < 0.5, z <= h0 <= 1000 mm, 0 <= z <= h0, 0.001 mm <= r <= c)."""
    c = model.get("diameter", THESIS_DIAMETER) / 2.0
    h0 = model.get("h0", THESIS_H0)
    z = model.get("z", THESIS_Z)
    limits = {"E": (MAX_MODULUS_MPA * 1e-12, MAX_MODULUS_MPA, True),
              "nu": (0.0, math.nextafter(0.5, 0.0), False),
              "h0": (max(z, 1e-3), DEFAULT.max_length, True),
              "z": (0.0, h0, False),
              "r": (DEFAULT.min_length, c, False)}
    if name not in limits:
        raise DesignError("name", name, f"must be one of {', '.join(limits)}")
    return limits[name]


def _model_runs(pressures: np.ndarray, model: dict) -> bool:
    """Whether :func:`simulate_compression` runs (no refusal) with the keyword arguments ``model``."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            simulate_compression(pressures, **model)
    except DesignError:
        return False
    return True


def model_range(name: str, pressures, **model) -> tuple[float, float]:
    """The values of one parameter of :func:`simulate_compression` with which it runs, the others fixed.

    The bed must stay thicker than 0 mm, at least 3 simulated points must keep a relative density
    below 1 for the Heckel fit and the densest must reach
    :data:`~tabletcad.mechanics.compaction.MIN_PEAK_RELATIVE_DENSITY` (with ``omega_z0`` matched to the
    experiment, a bed of ``h0 = 100`` mm reached 0.03 and ``E = 2.64`` MPa, a modulus typed in GPa,
    pressed the bed to nothing).  The parameter's limits are scanned at 400 points (logarithmically for
    ``E`` and ``h0``) and the ends of the run of working values nearest ``model[name]`` refined by
    bisection, so both ends returned run.

    Parameters
    ----------
    name : {"E", "nu", "h0", "z", "r"}
        The parameter: MPa, dimensionless or mm.
    pressures : array_like
        Simulated pressures, MPa.
    **model
        Keyword arguments of :func:`simulate_compression` (``name`` among them: the value whose
        neighbourhood is searched).

    Returns
    -------
    (float, float)
        ``(lo, hi)``, both inclusive, in the parameter's unit; ``(nan, nan)`` when no value runs.
    """
    P = np.asarray(pressures, dtype=float).ravel()
    lo, hi, log = _model_limits(name, model)
    grid = np.geomspace(lo, hi, _SCAN_POINTS) if log else np.linspace(lo, hi, _SCAN_POINTS)
    ok = np.array([_model_runs(P, model | {name: float(x)}) for x in grid])
    if not ok.any():
        return (math.nan, math.nan)
    here = int(np.argmin(np.abs(grid - float(model.get(name, grid[0])))))
    good = np.flatnonzero(ok)
    k = int(good[np.argmin(np.abs(good - here))])
    a = k
    while a > 0 and ok[a - 1]:
        a -= 1
    b = k
    while b < grid.size - 1 and ok[b + 1]:
        b += 1
    ends = []
    for inside, outside in ((a, a - 1), (b, b + 1)):
        x_in = float(grid[inside])
        if 0 <= outside < grid.size:
            x_out = float(grid[outside])
            for _ in range(_BISECTIONS):
                mid = 0.5 * (x_in + x_out)
                if mid in (x_in, x_out):
                    break
                if _model_runs(P, model | {name: mid}):
                    x_in = mid
                else:
                    x_out = mid
        ends.append(x_in)
    return (ends[0], ends[1])


def model_allowed(lo: float, hi: float, n: int, unit: str) -> str:
    """The refusal's range of a parameter for :func:`model_range`'s ``(lo, hi)`` over ``n`` pressures."""
    why = (f"where the model runs with the other options: the bed stays thicker than 0, at least "
           f"{_MIN_FIT_POINTS} of the {n} simulated points keep a relative density below 1 for the Heckel fit "
           f"and the densest reaches {MIN_PEAK_RELATIVE_DENSITY:g}")
    if math.isnan(lo):
        return f"no value works with the other options ({why})"
    unit = f" {unit}" if unit else ""
    return f"must be >= {format_bound(lo, upper=False)} and <= {format_bound(hi, upper=True)}{unit} ({why})"


def _refuse_collapse(pressure: float, omega_z0: float, h0: float, given: bool) -> None:
    """Refuse a simulated bed pressed to zero thickness, naming what the caller chose: ``omega_z0`` when
    it was given (-5.9 mm in a 6 mm bed had been refused as ``pressure = 10 MPa``), else the pressure.

    Raises
    ------
    DesignError
        Always.
    """
    if given:
        raise DesignError("omega_z0", omega_z0, f"the model then compresses the {h0:.6g} mm bed to zero thickness at "
                          f"{pressure:.6g} MPa (h0 + ω_z must stay > 0)", "mm")
    raise DesignError("pressure", pressure, f"compresses the model bed to zero thickness (h0 = {h0:.6g} mm, "
                      f"ω_z0 = {omega_z0:.4g} mm)", "MPa")


@dataclass(frozen=True)
class ConfinedCompression:
    """Exact linear-elastic confined compression in a frictionless rigid die.

    Attributes
    ----------
    axial_strain : ndarray
        ε_z (negative in compression).
    axial_displacement : ndarray
        Top-face displacement ``ε_z h``, mm.
    radial_stress : ndarray
        σ_r = σ_θ = ν/(1-ν) σ_z, MPa.
    constrained_modulus : float
        ``M = E (1-ν) / ((1+ν)(1-2ν))``, MPa.
    """

    axial_strain: np.ndarray
    axial_displacement: np.ndarray
    radial_stress: np.ndarray
    constrained_modulus: float


def confined_compression(P, E: float, nu: float, h: float) -> ConfinedCompression:
    """Uniaxial-strain solution: a cylinder of height ``h`` (mm) pressed by ``P`` (MPa) in a rigid frictionless die.

    ``σ_z = -P`` everywhere, ``ε_r = ε_θ = 0``, so
    ``ε_z = -P (1+ν)(1-2ν) / (E (1-ν))`` and ``σ_r = σ_θ = ν/(1-ν) σ_z``; the
    displacement grows linearly from 0 at the fixed punch to ``ε_z h`` at the
    moving one.  All stresses satisfy equilibrium and every boundary condition
    (no shear anywhere, zero radial displacement at the wall).
    """
    E = check_positive("E", E, "MPa")
    nu = check_range("nu", nu, -1.0, 0.5, lo_open=True, hi_open=True)
    h = check_positive("h", h, "mm")
    P = np.asarray(P, dtype=float)
    M = E * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu))
    eps = -P / M
    return ConfinedCompression(axial_strain=eps, axial_displacement=eps * h,
                               radial_stress=nu / (1.0 - nu) * (-P), constrained_modulus=M)
