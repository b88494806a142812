"""Tensile strength of tablets from breaking tests.

Every function takes plain numbers: force ``F`` (N) and lengths (mm), and
returns a stress in MPa.  Outside the range of geometry a formula was derived
for it still returns a value but issues a :class:`ValidityWarning`.

=====================================  ===========  =====================================
formula                                thesis eq    validity checked here
=====================================  ===========  =====================================
diametral, flat-faced round            2.4          0 < t <= D
axial, flat-faced round                2.5          yield force from an axial test
convex-faced round (Pitt et al. 1988)  2.7          t >= W; 0.06 <= W/D <= 0.3 (see below)
elongated flat (Pitt & Heasley)        2.8          length/width >= 1.7 when length given
elongated convex (Pitt & Heasley)      2.9          as 2.7 and 2.8
convex, Podczeck et al. 2013           --           t >= W; 0.06 <= W/D <= 0.5; 0.25 <= D/R <= 1.85
sphere, Hertz (Antonyuk et al. 2010)   2.10, 2.11   0 <= nu < 0.5
=====================================  ===========  =====================================

Notes
-----
* Eq 2.7 as printed, ``50F / (πD² (71t/(5D) - 63t/(100W) + 63W/(4D) + 1/20))``,
  is the same as the usual form ``10F / (πD² (2.84 t/D - 0.126 t/W + 3.15 W/D + 0.01))``.
  At ``W = t`` it does *not* reduce to eq 2.4: the ratio eq2.7/eq2.4 is
  ``5 (t/D) / (5.99 t/D - 0.116)`` (0.89 at t/D = 0.3), because it is a fit to
  stresses in domed discs.  The W/D range 0.06-0.3 is the one usually quoted
  for the photoelastic study behind it; treat it as indicative.
* Pitt & Heasley (Powder Technology 238 (2013) 169-175, online 2011) found that
  the peak tensile stress of elongated tablets reaches a limit of about 2/3 of
  the round-tablet value once length/width exceeds about 1.7; ``D`` is then the
  width (short axis).
* Podczeck, Drake & Newton (Int. J. Pharm. 454 (2013) 412-424) give
  ``σ = 2F / (π D T)`` with ``T`` the *total* thickness for doubly-convex
  tablets (FEM study over W/D 0.06-0.50 and D/R 0.25-1.85); ``W`` and the face
  radius ``R`` only serve the validity check.
* Eq 2.10 is ``σ = F (1 - 2ν) / (2π r_c²)`` with the contact radius r_c of
  eq 2.11, ``π s_y r_s (1 - ν²) / (2E)`` (the contact radius at the yield point).
"""

from __future__ import annotations

import math

from tabletcad.errors import DesignError, check_range, format_bound
from tabletcad.mechanics.contact import contact_radius_at_yield
from tabletcad.mechanics.validity import ValidityWarning, warn
from tabletcad.tolerance import DEFAULT

__all__ = [
    "ELONGATED_FACTOR",
    "ELONGATED_RATIO",
    "axial_flat",
    "diametral_flat",
    "pitt_convex",
    "pitt_heasley_elongated_convex",
    "pitt_heasley_elongated_flat",
    "podczeck_convex",
    "sphere_hertz",
]

#: length/width above which the elongated-tablet factor applies (Pitt & Heasley).
ELONGATED_RATIO = 1.7
#: limiting ratio of elongated to round tablet strength (Pitt & Heasley).
ELONGATED_FACTOR = 2.0 / 3.0

#: the largest force (N) a breaking test is read with (1e308 gave an infinite strength)
MAX_FORCE_N = 1e9


def _force(F: float) -> float:
    return check_range("force", F, 0.0, MAX_FORCE_N, "N", lo_open=True)


def _length(name: str, x: float) -> float:
    """A tablet's length (mm) as a design's: at least ``Tolerances.min_length``, at most ``max_length``."""
    return check_range(name, x, DEFAULT.min_length, DEFAULT.max_length, "mm")

def diametral_flat(F: float, D: float, t: float) -> float:
    """Diametral tensile strength of a flat-faced round tablet, eq 2.4: ``2F / (π D t)`` (MPa).

    Parameters
    ----------
    F : float
        Breaking force, N.
    D : float
        Diameter, mm.
    t : float
        Thickness, mm.
    """
    F = _force(F)
    D = _length("diameter", D)
    t = _length("thickness", t)
    if t > D:
        warn(ValidityWarning, f"eq 2.4: thickness {t:g} mm exceeds diameter {D:g} mm (outside the usual disc test range)")
    return 2.0 * F / (math.pi * D * t)


def axial_flat(F: float, D: float) -> float:
    """Axial strength of a flat-faced round tablet, eq 2.5: ``4F / (π D²)`` (MPa); F the yield force (N)."""
    F = _force(F)
    D = _length("diameter", D)
    return 4.0 * F / (math.pi * D * D)


def _pitt_denominator(D: float, t: float, W: float) -> float:
    """``2.84 t/D - 0.126 t/W + 3.15 W/D + 0.01`` of eq 2.7; a band so thin that it is <= 0 (the fit
    would give a negative or infinite strength) is refused: the formula has no value there."""
    den = 2.84 * t / D - 0.126 * t / W + 3.15 * W / D + 0.01
    if not den > 0:
        raise DesignError("band thickness", W, f"makes eq 2.7's denominator 2.84 t/D - 0.126 t/W + 3.15 W/D + 0.01 "
                          f"= {den:.3g} <= 0 (D = {D:g}, t = {t:g} mm): the fit has no value for so thin a band", "mm")
    return den


def _check_convex(name: str, D: float, t: float, W: float, wd: tuple[float, float]) -> None:
    if W > t * (1 + 1e-12):  # the band is part of the tablet's thickness: no such tablet
        raise DesignError("band thickness", W, f"must be <= the total thickness t = {format_bound(t, upper=True)} mm ({name})", "mm")
    r = W / D
    if not wd[0] <= r <= wd[1]:
        warn(ValidityWarning, f"{name}: W/D = {r:.3g} is outside {wd[0]:g}-{wd[1]:g}")


def pitt_convex(F: float, D: float, t: float, W: float) -> float:
    """Convex-faced round tablet (Pitt et al. 1988), eq 2.7 (MPa).

    ``σ = 10F / (πD² (2.84 t/D - 0.126 t/W + 3.15 W/D + 0.01))``.

    Parameters
    ----------
    F : float
        Breaking force, N.
    D : float
        Diameter, mm.
    t : float
        Total thickness, mm.
    W : float
        Thickness of the central cylinder (band), mm.
    """
    F = _force(F)
    D = _length("diameter", D)
    t = _length("thickness", t)
    W = _length("band thickness", W)
    _check_convex("eq 2.7 (Pitt 1988)", D, t, W, (0.06, 0.3))
    return 10.0 * F / (math.pi * D * D * _pitt_denominator(D, t, W))


def _check_elongation(name: str, D: float, length: float | None) -> None:
    if length is None:
        return
    L = _length("length", length)
    if L < D:  # the width is the short axis: a length below it is a swapped pair, not a short tablet
        raise DesignError("length", L, f"must be >= the width (the diameter given, {D:g} mm): the width is the "
                          "short axis", "mm")
    if L / D < ELONGATED_RATIO:
        warn(ValidityWarning, f"{name}: length/width = {L / D:.3g} < {ELONGATED_RATIO}; the 2/3 limit is not yet reached")


def pitt_heasley_elongated_flat(F: float, D: float, t: float, length: float | None = None) -> float:
    """Flat-faced elongated tablet, eq 2.8: ``(2/3) · 2F/(π D t) = 4F / (3π D t)`` (MPa).

    ``D`` is the width (short axis), mm; ``length`` (mm), if given, is checked
    against the ratio ``length/width >= 1.7``.
    """
    F = _force(F)
    D = _length("width", D)
    t = _length("thickness", t)
    _check_elongation("eq 2.8", D, length)
    return ELONGATED_FACTOR * 2.0 * F / (math.pi * D * t)


def pitt_heasley_elongated_convex(F: float, D: float, t: float, W: float, length: float | None = None) -> float:
    """Convex-faced elongated tablet, eq 2.9: 2/3 of eq 2.7 with ``D`` the width (MPa)."""
    F = _force(F)
    D = _length("width", D)
    t = _length("thickness", t)
    W = _length("band thickness", W)
    _check_convex("eq 2.9", D, t, W, (0.06, 0.3))
    _check_elongation("eq 2.9", D, length)
    return ELONGATED_FACTOR * 10.0 * F / (math.pi * D * D * _pitt_denominator(D, t, W))


def podczeck_convex(F: float, D: float, t: float, W: float | None = None, R: float | None = None) -> float:
    """Doubly-convex round tablet (Podczeck et al. 2013): ``2F / (π D t)`` with total thickness t (MPa).

    ``W`` (band thickness, mm) and ``R`` (face radius of curvature, mm), when
    given, are checked against the study's range W/D 0.06-0.50, D/R 0.25-1.85.
    """
    F = _force(F)
    D = _length("diameter", D)
    t = _length("thickness", t)
    if W is not None:
        _check_convex("Podczeck 2013", D, t, _length("band thickness", W), (0.06, 0.5))
    if R is not None:  # (R < D/2 is possible: a cup inside a land spans less than D; the range warns)
        dr = D / _length("face radius", R)
        if not 0.25 <= dr <= 1.85:
            warn(ValidityWarning, f"Podczeck 2013: D/R = {dr:.3g} is outside 0.25-1.85")
    return 2.0 * F / (math.pi * D * t)


def sphere_hertz(F: float, E: float, nu: float, r_s: float, s_y: float) -> float:
    """Tensile strength of a spherical granule/tablet, eqs 2.10-2.11 (MPa).

    ``σ = F (1 - 2ν) / (2π r_c²)``, ``r_c = π s_y r_s (1 - ν²) / (2E)``.

    Parameters
    ----------
    F : float
        Force, N.
    E : float
        Young's modulus, MPa.
    nu : float
        Poisson's ratio (warning unless 0 <= nu < 0.5).
    r_s : float
        Sphere radius, mm.
    s_y : float
        Micro-yield strength, MPa.
    """
    F = _force(F)
    nu = check_range("nu", nu, -1.0, 0.5, lo_open=True, hi_open=True)
    if nu < 0:
        warn(ValidityWarning, f"eq 2.10: negative Poisson's ratio {nu:g} is outside the granular materials it was derived for")
    rc = contact_radius_at_yield(E, nu, r_s, s_y)
    return F * (1.0 - 2.0 * nu) / (2.0 * math.pi * rc * rc)
