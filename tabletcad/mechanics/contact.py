"""Contact laws of a spherical granule or tablet pressed between two flat platens.

Symbols: total approach of the platens ``ω`` (mm), displacement at the yield
point ``ω'`` (mm), sphere radius ``r_s`` (mm), Young's modulus ``E`` and
micro-yield strength ``s_y`` (MPa), Poisson's ratio ``ν``, force ``F`` (N).

* Hertz, elastic (eq 5.19):  ``F = E / (3 (1 - ν²)) · sqrt(2 r_s ω³)``.
* Antonyuk et al. (2010), elastic-plastic, ``ω >= ω'`` (eq 2.1):
  ``F = π s_y r_s ω / 2 · (1 - (ω'/ω)^(1/3) / 3)``.
* Its inverse, printed as eqs 5.20-5.21 (checked here: it *does* invert eq 2.1
  to rounding error), re-derived by Cardano's formula in
  :func:`elastic_plastic_displacement_cardano`, and by bracketing
  (:func:`elastic_plastic_displacement`, :func:`scipy.optimize.brentq`).
* Micro-yield strength (eq 5.22): ``s_y = 2E / (π (1 - ν²)) · sqrt(ω'/r_s)``,
  hence ``ω' = r_s (π s_y (1 - ν²) / (2E))²``.
* Contact radius (eq 5.23): ``r_c = sqrt(r_s ω)``; eq 2.11,
  ``r_c = π s_y r_s (1 - ν²) / (2E)``, is the same expression at ``ω = ω'``.

Two caveats the thesis leaves open, reported by the functions here:

1. At ``ω = ω'`` eq 5.19 gives ``F = (sqrt 2 / 3) E/(1-ν²) sqrt(r_s) ω'^(3/2)``
   but eq 2.1 gives ``(2/3) E/(1-ν²) sqrt(r_s) ω'^(3/2)``: the printed laws
   jump by a factor ``sqrt 2`` at yield (eq 5.19 is Hertz for a sphere between
   two platens with ``ω`` the total approach; eqs 2.1/5.22 use a single-contact
   convention).  :func:`displacement` returns ``ω'`` for forces inside the jump.
2. The thesis's check for Köstrolith at 3.5 N quotes a "contact area" of
   0.1395 mm²; that number equals ``sqrt(r_s ω / 2)`` in mm, i.e. the
   contact *radius* of one of the two contacts each flattened by ``ω/2``.
   Eq 5.23 with the total ``ω`` gives 0.197 mm (area 0.122 mm²).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tabletcad.errors import DesignError, check_positive, check_range, format_bound
from tabletcad.mechanics.materials import Material, get_material
from tabletcad.tolerance import DEFAULT, MAX_MODULUS_MPA, MAX_YIELD_MPA

__all__ = [
    "CompressedSphere",
    "ForceDisplacementCurve",
    "compress_sphere",
    "compressed_sphere_tablet",
    "contact_radius",
    "contact_radius_at_yield",
    "contact_radius_curve",
    "displacement",
    "elastic_plastic_displacement",
    "elastic_plastic_displacement_cardano",
    "elastic_plastic_displacement_printed",
    "elastic_plastic_force",
    "force",
    "force_displacement_curve",
    "hertz_displacement",
    "hertz_force",
    "micro_yield_strength",
    "plot_contact_radius",
    "plot_force_displacement",
    "yield_displacement",
    "yield_force",
]


def _nu(nu: float) -> float:
    return check_range("nu", nu, -1.0, 0.5, lo_open=True, hi_open=True)


def hertz_force(omega, E: float, nu: float, r_s: float) -> np.ndarray:
    """Elastic Hertz force (N) at total approach ``omega`` (mm), eq 5.19."""
    E = check_positive("E", E, "MPa")
    r_s = check_positive("r_s", r_s, "mm")
    w = np.asarray(omega, dtype=float)
    return E / (3.0 * (1.0 - _nu(nu) ** 2)) * np.sqrt(2.0 * r_s * np.clip(w, 0.0, None) ** 3)


def hertz_displacement(F, E: float, nu: float, r_s: float) -> np.ndarray:
    """Inverse of :func:`hertz_force`: approach (mm) at force ``F`` (N)."""
    E = check_positive("E", E, "MPa")
    r_s = check_positive("r_s", r_s, "mm")
    F = np.asarray(F, dtype=float)
    return (3.0 * (1.0 - _nu(nu) ** 2) * np.clip(F, 0.0, None) / (E * math.sqrt(2.0 * r_s))) ** (2.0 / 3.0)


def yield_displacement(E: float, nu: float, r_s: float, s_y: float) -> float:
    """Displacement at the yield point ω' (mm) from eq 5.22 solved for ω'."""
    E = check_positive("E", E, "MPa")
    r_s = check_positive("r_s", r_s, "mm")
    s_y = check_positive("s_y", s_y, "MPa")
    return r_s * (math.pi * s_y * (1.0 - _nu(nu) ** 2) / (2.0 * E)) ** 2


def micro_yield_strength(E: float, nu: float, r_s: float, omega_y: float) -> float:
    """Micro-yield strength s_y (MPa), eq 5.22."""
    E = check_positive("E", E, "MPa")
    r_s = check_positive("r_s", r_s, "mm")
    omega_y = check_positive("omega_y", omega_y, "mm")
    return 2.0 * E / (math.pi * (1.0 - _nu(nu) ** 2)) * math.sqrt(omega_y / r_s)


def elastic_plastic_force(omega, r_s: float, s_y: float, omega_y: float) -> np.ndarray:
    """Antonyuk elastic-plastic force (N), eq 2.1, for ``omega >= omega_y`` (mm).

    Raises
    ------
    DesignError
        If any ``omega < omega_y`` (the law is not defined there).
    """
    r_s = check_positive("r_s", r_s, "mm")
    s_y = check_positive("s_y", s_y, "MPa")
    omega_y = check_positive("omega_y", omega_y, "mm")
    w = np.asarray(omega, dtype=float)
    if np.any(w < omega_y * (1 - 1e-12)):
        raise DesignError("omega", float(np.min(w)), f"must be >= the yield displacement {format_bound(omega_y, upper=False)} mm", "mm")
    return math.pi * s_y * r_s * w / 2.0 * (1.0 - np.cbrt(omega_y / w) / 3.0)


def yield_force(r_s: float, s_y: float, omega_y: float) -> float:
    """Force (N) of eq 2.1 at ``omega = omega_y``: ``π s_y r_s ω' / 3``."""
    return math.pi * s_y * r_s * omega_y / 3.0


def _check_force_above_yield(F, r_s, s_y, omega_y) -> np.ndarray:
    F = np.asarray(F, dtype=float)
    Fy = yield_force(r_s, s_y, omega_y)
    if np.any(F < Fy * (1 - 1e-12)):
        raise DesignError("force", float(np.min(F)), f"must be >= the yield force {format_bound(Fy, upper=False)} N for eq 2.1", "N")
    return F


def elastic_plastic_displacement_printed(F, r_s: float, s_y: float, omega_y: float) -> np.ndarray:
    """Displacement (mm) from the printed closed form, eqs 5.20-5.21."""
    F = _check_force_above_yield(F, r_s, s_y, omega_y)
    q = omega_y * math.pi * s_y * r_s
    J = q * (1458.0 * F * np.sqrt(F * (2.0 * q + 729.0 * F)) + 39366.0 * F**2 + q**2 + 486.0 * q * F)
    J3 = np.cbrt(J)
    return (J3 / math.pi + omega_y * s_y * r_s * (q + 324.0 * F) / J3 + (q + 162.0 * F) / math.pi) / (81.0 * r_s * s_y)


def elastic_plastic_displacement_cardano(F, r_s: float, s_y: float, omega_y: float) -> np.ndarray:
    """Displacement (mm) inverting eq 2.1 through its cubic, solved by Cardano's formula.

    With ``x = ω^(1/3)``, eq 2.1 reads ``x³ - q x² - c = 0`` where
    ``q = ω'^(1/3) / 3`` and ``c = 2F / (π s_y r_s)``.  Substituting
    ``x = y + q/3`` gives ``y³ + p y + s = 0`` with ``p = -q²/3``,
    ``s = -2q³/27 - c``; its discriminant ``(s/2)² + (p/3)³ > 0`` for ``c > 0``,
    so the single real root is ``y = u - p / (3u)`` with ``u = cbrt(-s/2 + √Δ)``
    (the product form of Cardano's second cube root avoids cancellation).
    """
    F = _check_force_above_yield(F, r_s, s_y, omega_y)
    q = omega_y ** (1.0 / 3.0) / 3.0
    c = 2.0 * F / (math.pi * s_y * r_s)
    p = -q * q / 3.0
    s = -2.0 * q**3 / 27.0 - c
    disc = (s / 2.0) ** 2 + (p / 3.0) ** 3
    sq = np.sqrt(disc)
    u = np.cbrt(-s / 2.0 + sq)
    y = u - p / (3.0 * u)
    return (y + q / 3.0) ** 3


def elastic_plastic_displacement(F, r_s: float, s_y: float, omega_y: float) -> np.ndarray:
    """Displacement (mm) inverting eq 2.1 numerically with :func:`scipy.optimize.brentq`.

    ``F(ω)`` is increasing for ``ω >= ω'``, and ``F(ω) >= π s_y r_s ω / 3``
    there, so the root is bracketed by ``[ω', max(ω', 3F/(π s_y r_s))]``.
    """
    from scipy.optimize import brentq  # here: scipy.optimize takes ~0.4 s to import

    F = _check_force_above_yield(F, r_s, s_y, omega_y)
    k = math.pi * s_y * r_s / 2.0
    out = np.empty(F.shape, dtype=float)
    for i, f in np.ndenumerate(F):
        def g(w, f=f):
            return k * w * (1.0 - (omega_y / w) ** (1.0 / 3.0) / 3.0) - f

        hi = max(omega_y, 3.0 * f / (2.0 * k)) * (1 + 1e-9) + 1e-300
        out[i] = omega_y if g(omega_y) >= 0 else brentq(g, omega_y, hi, xtol=1e-15, rtol=4 * np.finfo(float).eps)
    return out


def contact_radius(omega, r_s: float) -> np.ndarray:
    """Contact radius (mm), eq 5.23: ``sqrt(r_s ω)``."""
    r_s = check_positive("r_s", r_s, "mm")
    return np.sqrt(r_s * np.clip(np.asarray(omega, dtype=float), 0.0, None))


def contact_radius_at_yield(E: float, nu: float, r_s: float, s_y: float) -> float:
    """Contact radius (mm) of eq 2.11, ``π s_y r_s (1-ν²) / (2E)`` (= eq 5.23 at ω = ω').

    ``E`` (MPa) at most ``MAX_MODULUS_MPA``, ``r_s`` (mm) at most ``Tolerances.max_length`` and ``s_y``
    (MPa) at most ``MAX_YIELD_MPA``: E = 1e300 had underflowed the radius to 0 (a division by zero, exit
    1 in ``tabletcad strength sphere``), and r_s or s_y = 1e300 had read a tensile strength of 0 MPa.
    """
    s_y = check_range("s_y", s_y, 0.0, MAX_YIELD_MPA, "MPa", lo_open=True)
    r_s = _radius("r_s", r_s)
    E = check_range("E", E, 0.0, MAX_MODULUS_MPA, "MPa", lo_open=True)
    return math.pi * s_y * r_s * (1.0 - _nu(nu) ** 2) / (2.0 * E)


def _radius(name: str, r: float) -> float:
    """A sphere's radius (mm): > 0 and at most ``Tolerances.max_length``, as a design's lengths (a radius of
    1e300 mm had overflowed eq 2.1's cubic: exit 1 in ``tabletcad contact``)."""
    return check_range(name, r, 0.0, DEFAULT.max_length, "mm", lo_open=True)


def _props(material: Material | str, radius: float | None):
    m = get_material(material)
    r = radius if radius is not None else m.radius
    if r is None or m.s_y is None:
        raise DesignError("material", m.key, "needs a radius and a micro-yield strength s_y for contact laws")
    r = _radius("radius", r)
    return m, r, yield_displacement(m.E, m.nu, r, m.s_y)


def force(omega, material: Material | str, radius: float | None = None) -> np.ndarray:
    """Force (N) at approach ``omega`` (mm): Hertz below ω', eq 2.1 from ω' on."""
    m, r, wy = _props(material, radius)
    w = np.asarray(omega, dtype=float)
    el = hertz_force(np.minimum(w, wy), m.E, m.nu, r)
    ep = elastic_plastic_force(np.maximum(w, wy), r, m.s_y, wy)
    return np.where(w < wy, el, ep)


def displacement(F, material: Material | str, radius: float | None = None) -> np.ndarray:
    """Approach (mm) at force ``F`` (N), inverse of :func:`force`.

    Forces inside the jump between the Hertz force at ω' and the eq 2.1 force
    at ω' (see the module docstring) map to ω'.
    """
    m, r, wy = _props(material, radius)
    F = np.asarray(F, dtype=float)
    if np.any(F < 0) or not np.all(np.isfinite(F)):
        raise DesignError("force", float(np.min(F)), "must be finite and >= 0", "N")
    f_el = float(hertz_force(wy, m.E, m.nu, r))
    f_ep = yield_force(r, m.s_y, wy)
    el = hertz_displacement(np.minimum(F, f_el), m.E, m.nu, r)
    ep = elastic_plastic_displacement_cardano(np.maximum(F, f_ep), r, m.s_y, wy)
    return np.where(F <= f_el, el, np.where(F >= f_ep, ep, wy))


@dataclass(frozen=True)
class ForceDisplacementCurve:
    """Force-displacement curve of a sphere between platens (Fig 5.7).

    Attributes
    ----------
    omega : ndarray
        Total approach, mm.
    force : ndarray
        N.
    omega_y : float
        Yield displacement, mm.
    force_at_yield_hertz, force_at_yield_ep : float
        Force at ω' from eq 5.19 and from eq 2.1, N (they differ, see module docstring).
    """

    omega: np.ndarray
    force: np.ndarray
    omega_y: float
    force_at_yield_hertz: float
    force_at_yield_ep: float
    material: str


def force_displacement_curve(material: Material | str, omega_max: float, n: int = 200,
                             radius: float | None = None) -> ForceDisplacementCurve:
    """Sample :func:`force` on ``[0, omega_max]`` (mm) with ``n`` points plus ω' itself."""
    m, r, wy = _props(material, radius)
    omega_max = check_positive("omega_max", omega_max, "mm")
    w = np.unique(np.concatenate([np.linspace(0.0, omega_max, int(n)), [wy] if wy < omega_max else []]))
    return ForceDisplacementCurve(
        omega=w, force=force(w, m, r), omega_y=wy,
        force_at_yield_hertz=float(hertz_force(wy, m.E, m.nu, r)),
        force_at_yield_ep=yield_force(r, m.s_y, wy), material=m.name,
    )


def contact_radius_curve(material: Material | str, forces, radius: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Contact radius (mm, eq 5.23) against force (N) from the yield force on (Fig 5.9).

    Returns ``(forces, radii)`` for the forces at or above the eq 2.1 yield force.
    """
    m, r, wy = _props(material, radius)
    F = np.asarray(forces, dtype=float)
    F = F[F >= yield_force(r, m.s_y, wy)]
    return F, contact_radius(elastic_plastic_displacement_cardano(F, r, m.s_y, wy), r)


@dataclass(frozen=True)
class CompressedSphere:
    """A sphere compressed between platens (eqs 5.24-5.26) as plain numbers.

    Attributes
    ----------
    force : float
        N.
    radius : float
        Undeformed sphere radius r_s, mm.
    displacement : float
        Total approach ω, mm (eq 2.1 inverted above yield, Hertz below).
    height : float
        ``2 r_s - ω``, mm (eq 5.25 applied to the full sphere).
    contact_radius : float
        Eq 5.23, ``sqrt(r_s ω)``, mm.
    contact_radius_per_contact : float
        ``sqrt(r_s ω / 2)``, mm: the value the thesis quotes in its 3.5 N check.
    flat_radius : float
        Radius of the circle where the platen plane ``z = h`` cuts the sphere,
        ``sqrt(r_s² - (h/2)²)``, mm (≈ eq 5.23 for small ω).
    circles : tuple of (radius, height)
        The 7 boundary circles P11, d11, d12, P21, d21, d22, P22 (eqs 4.1-4.3)
        of the two-patch compressed sphere, heights from the lower platen, mm.
        The poles become the two contact flats (radius ``flat_radius`` at
        heights 0 and h); the interior circles lie on the undeformed sphere at
        latitudes ``±ψ_c/3, ±2ψ_c/3`` where ``ψ_c = asin(h / (2 r_s))`` is the
        latitude of the flats' rim (``ψ_c = π/2`` reproduces eq 4.1's 30° steps).
    """

    force: float
    radius: float
    displacement: float
    height: float
    contact_radius: float
    contact_radius_per_contact: float
    flat_radius: float
    circles: tuple[tuple[float, float], ...]

    def to_dict(self) -> dict:
        return {
            "force_N": self.force, "radius_mm": self.radius, "displacement_mm": self.displacement,
            "height_mm": self.height, "contact_radius_mm": self.contact_radius,
            "contact_radius_per_contact_mm": self.contact_radius_per_contact,
            "flat_radius_mm": self.flat_radius,
            "circles": [{"radius_mm": r, "height_mm": z} for r, z in self.circles],
        }


def compress_sphere(force_N: float, material: Material | str, radius: float | None = None) -> CompressedSphere:
    """Compressed height, contact radius and boundary circles of a spherical tablet.

    Parameters
    ----------
    force_N : float
        Platen force, N (>= 0).
    material : Material or str
        Needs ``E``, ``nu``, ``s_y`` and (unless ``radius`` is given) ``radius``.
    radius : float, optional
        Sphere radius r_s, mm.
    """
    F = check_range("force", force_N, 0.0, None, "N")
    m, r, _ = _props(material, radius)
    w = float(displacement(F, m, r))
    if w >= 2.0 * r:
        raise DesignError("force", F, f"crushes the sphere (approach {w:.4g} mm >= diameter {2 * r:g} mm)", "N")
    h = 2.0 * r - w
    half = h / 2.0
    psi_c = math.asin(min(1.0, half / r))
    flat = math.sqrt(max(r * r - half * half, 0.0))
    circles = []
    for k in range(-3, 4):
        if abs(k) == 3:
            circles.append((flat, half + math.copysign(half, k)))
        else:
            psi = psi_c * k / 3.0
            circles.append((r * math.cos(psi), half + r * math.sin(psi)))
    return CompressedSphere(
        force=F, radius=r, displacement=w, height=h, contact_radius=float(contact_radius(w, r)),
        contact_radius_per_contact=math.sqrt(r * w / 2.0), flat_radius=flat, circles=tuple(circles),
    )


def compressed_sphere_tablet(force_N: float, material: Material | str, radius: float | None = None, **kw):
    """The compressed sphere as a two-patch :class:`tabletcad.geometry.tablet.Tablet` (needs the geometry core).

    Builds the tablet from :attr:`CompressedSphere.circles` with
    :func:`tabletcad.families.thesis.coaxial_tablet`; ``kw`` is passed on to it.
    """
    from tabletcad.families.thesis import coaxial_tablet

    cs = compress_sphere(force_N, material, radius)
    pts = list(cs.circles)
    params = {"force_N": cs.force, "radius": cs.radius, "height": cs.height}
    return coaxial_tablet([pts[0:4], pts[3:7]], name="compressed_sphere", family="thesis.spherical", params=params, **kw)


def _figure():
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6.0, 4.2), dpi=120)
    FigureCanvasAgg(fig)  # its own canvas: the global backend is left alone
    return fig


def _save(fig, path) -> Path:
    from tabletcad.io.figures import save_figure

    fig.tight_layout()
    return save_figure(fig, Path(path))


def plot_force_displacement(curves: list[ForceDisplacementCurve], path) -> Path:
    """Plot force against approach (Fig 5.7 style), yield points marked; PNG/SVG by suffix."""
    fig = _figure()
    ax = fig.add_subplot(111)
    for j, c in enumerate(curves):
        ax.plot(c.omega * 1000.0, c.force, "-", color=f"C{j}", label=c.material)
        ax.plot([c.omega_y * 1000.0] * 2, [c.force_at_yield_hertz, c.force_at_yield_ep], "o", color=f"C{j}", ms=4)
    ax.set_xlabel("Total displacement ω (µm)")
    ax.set_ylabel("Force F (N)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    return _save(fig, path)


def plot_contact_radius(series: dict[str, tuple[np.ndarray, np.ndarray]], path) -> Path:
    """Plot contact radius (mm) against force (N) (Fig 5.9 style)."""
    fig = _figure()
    ax = fig.add_subplot(111)
    for name, (F, rc) in series.items():
        ax.plot(F, rc, "-", label=name)
    ax.set_xlabel("Force F (N)")
    ax.set_ylabel("Contact radius r_c (mm)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    return _save(fig, path)
