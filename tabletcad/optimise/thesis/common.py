"""The thesis's chapter 6 data and the builders its problems share: materials (sections 5.2, 6.2.3),
the reported optima, coaxial PDE tablets of circles, and the free_form design files of optima."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from tabletcad.errors import DesignError
from tabletcad.mechanics.materials import get_material
from tabletcad.geometry.patch import PDEPatch
from tabletcad.families.thesis import coaxial_tablet
from tabletcad.geometry.tablet import Tablet
from tabletcad.tolerance import DEFAULT

__all__ = ["LACTOSE", "KOSTROLITH", "GELATIN", "THESIS_MINUTES", "THESIS_RESULTS", "coaxial_fast", "round_tablet", "sphere_tablet", "min_height_slope", "free_form_toml"]


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


def coaxial_fast(sections, *, name: str = "tablet", check: bool = False, a: float = 1.0, fast: bool = True) -> Tablet:
    """:func:`tabletcad.families.thesis.coaxial_tablet` of circles ``[(radius, z) × 4]`` with one Fourier
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
    from tabletcad.pipeline.design import Design

    patches = [{"curves": ["previous" if k == 0 and j > 0 else {"type": "circle", "radius": float(r), "z": float(z)}
                           for k, (r, z) in enumerate(sec)]} for j, sec in enumerate(sections)]
    return Design({"family": "free_form", "name": name, "a": 1.0}, patches, comment=comment).to_toml()
