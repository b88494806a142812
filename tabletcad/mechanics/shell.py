"""Thick elastic spherical shell under a platen band load and internal pressure (section 6.2.3).

Problem (thesis eqs 6.21a-c): a linear-elastic shell, outer radius ``a``,
inner radius ``b`` (mm), Young's modulus ``E`` (MPa), Poisson's ratio ``ν``.
``θ`` is the polar angle from the axis of symmetry.  Boundary conditions::

    σ_rr(a, θ) = -p_ext  on the loaded region, 0 elsewhere
    σ_rr(b, θ) = -p_int
    τ_rθ(a, θ) = τ_rθ(b, θ) = 0

The loaded region is the band ``|θ - π/2| <= ψ`` as printed in eq 6.21a
(``region="equator"``), or the two polar caps ``θ <= ψ`` and ``θ >= π - ψ``
(``region="poles"``, platens touching at the poles).

Method (derived here, not taken from Appendix C)
-------------------------------------------------
The outer pressure is expanded in Legendre polynomials,
``p(θ) = Σ f_n P_n(cos θ)``; for the equatorial band ``s = sin ψ``,
``f_0 = s`` and ``f_n = P_{n+1}(s) - P_{n-1}(s)`` for even ``n``, 0 for odd
``n``.  For each order ``n`` the displacement is a combination of the four
axisymmetric solutions of Navier's equations (Love's solid/hollow-sphere
solutions; each was checked symbolically for n = 0…5)::

    k = n+1:   u_r = (n+1)(n-2+4ν) r^k P_n,   u_θ = (n+5-4ν) r^k dP_n/dθ
    k = n-1:   u_r = n r^k P_n,               u_θ = r^k dP_n/dθ
    k = -n:    u_r = n(n+3-4ν) r^k P_n,       u_θ = (4-n-4ν) r^k dP_n/dθ
    k = -n-2:  u_r = -(n+1) r^k P_n,          u_θ = r^k dP_n/dθ

For ``u_r = α r^k P_n``, ``u_θ = β r^k dP_n/dθ`` the tractions are
``σ_rr = r^(k-1) [λ((k+2)α - n(n+1)β) + 2Gkα] P_n`` and
``τ_rθ = G r^(k-1) [α + (k-1)β] dP_n/dθ``.  The four boundary conditions give
a 4×4 linear system per order (2×2 for ``n = 0``, whose modes are ``k = 1``
and ``k = -2``), solved numerically with growing modes scaled by ``(r/a)^k``
and decaying ones by ``(r/b)^k`` so that the system stays well conditioned
for high orders.  For ``n = 1`` the ``k = 0`` mode is a rigid translation,
fixed to zero; a load with a net force is rejected.

For a uniform load (``ψ = π/2``) only ``n = 0`` survives and the solution is
Lamé's (:func:`lame_displacement`).  For a band the outer traction is a step,
``f_n`` decays like ``n^(-1/2)`` and the surface displacement terms like
``n^(-3/2)``; :attr:`ShellSolution.term_size` lists them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tabletcad.errors import DesignError, check_positive, check_range, format_bound
from tabletcad.tolerance import DEFAULT

__all__ = [
    "ShellSolution",
    "band_coefficients",
    "lame_displacement",
    "lame_stresses",
    "plot_shell",
    "solve_shell",
]


def _legendre(n: int | np.ndarray, x: float | np.ndarray) -> float | np.ndarray:
    """Legendre polynomial ``P_n(x)`` (dimensionless) by :func:`scipy.special.eval_legendre`, scipy.special
    imported on first use: the design report reads the strength formulas, which import this package, and
    scipy.special took 0.03-0.06 s of CPU of every report or refusal that never solves a shell."""
    from scipy.special import eval_legendre

    return eval_legendre(n, x)


def band_coefficients(psi: float, n_max: int, region: str = "equator") -> np.ndarray:
    """Legendre coefficients ``f_0..f_n_max`` of the unit indicator of the loaded region.

    Parameters
    ----------
    psi : float
        Half-angle of the band (rad), ``0 <= psi <= π/2``; for ``region="poles"``
        the half-angle of each polar cap.
    n_max : int
    region : {"equator", "poles"}
    """
    psi = check_range("psi", psi, 0.0, math.pi / 2, "rad")
    if region not in ("equator", "poles"):
        raise DesignError("region", region, "must be 'equator' or 'poles'")
    n = np.arange(int(n_max) + 1)
    if region == "equator":
        s = math.sin(psi)
        f = np.zeros(n.size)
        f[0] = s
        even = n[(n >= 2) & (n % 2 == 0)]
        f[even] = _legendre(even + 1, s) - _legendre(even - 1, s)
        return f
    # caps: indicator = 1 - band with sin(band half-angle) = cos(psi)
    f = -band_coefficients(math.pi / 2 - psi, n_max, "equator")
    f[0] += 1.0
    return f


def _modes(n: int, nu: float) -> list[tuple[int, float, float]]:
    """(k, α, β) of the independent modes of order n."""
    if n == 0:
        return [(1, 4 * nu - 2.0, 0.0), (-2, -1.0, 0.0)]
    modes = [
        (n + 1, (n + 1) * (n - 2 + 4 * nu), n + 5 - 4 * nu),
        (n - 1, float(n), 1.0),
        (-n, n * (n + 3 - 4 * nu), 4 - n - 4 * nu),
        (-n - 2, -(n + 1.0), 1.0),
    ]
    if n == 1:
        modes.pop(1)  # rigid translation along the axis: no stress, fixed to zero
    return modes


def _dP(n: int, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """P_n(cos θ), dP_n/dθ and d²P_n/dθ² at x = cos θ."""
    P = _legendre(n, x)
    if n == 0:
        z = np.zeros_like(x)
        return P, z, z
    Pm = _legendre(n - 1, x)
    s = np.sqrt(np.clip(1.0 - x * x, 0.0, None))
    pole = s < 1e-12
    safe = np.where(pole, 1.0, s)
    d1 = np.where(pole, 0.0, -n * (Pm - x * P) / safe)
    cot_d1 = np.where(pole, -n * (n + 1) / 2.0 * np.where(x > 0, 1.0, (-1.0) ** n), x * d1 / safe)
    d2 = -n * (n + 1) * P - cot_d1
    return P, d1, d2


@dataclass(frozen=True)
class ShellSolution:
    """Solution of the shell problem, as per-order mode coefficients.

    Attributes
    ----------
    a, b : float
        Outer and inner radius, mm.
    E : float
        MPa.
    nu : float
    outer, inner : ndarray
        Legendre coefficients of the outer and inner *pressure* (MPa).
    coeffs : tuple of ndarray
        Per order, the amplitudes of the modes of :func:`_modes` (scaled form).
    """

    a: float
    b: float
    E: float
    nu: float
    outer: np.ndarray
    inner: np.ndarray
    coeffs: tuple[np.ndarray, ...]

    @property
    def n_terms(self) -> int:
        return len(self.coeffs)

    def _scale(self, k: int) -> float:
        return self.a if k >= 0 else self.b

    def _radial_parts(self, n: int, r: np.ndarray):
        """U_n, V_n and their stress factors at radii r (arrays)."""
        nu = self.nu
        G = self.E / (2 * (1 + nu))
        lam = 2 * G * nu / (1 - 2 * nu)
        U = np.zeros_like(r)
        V = np.zeros_like(r)
        Ud = np.zeros_like(r)
        Vd = np.zeros_like(r)
        for c, (k, al, be) in zip(self.coeffs[n], _modes(n, nu)):
            L = self._scale(k)
            rho = r / L
            U += c * al * rho**k
            V += c * be * rho**k
            Ud += c * al * k * rho ** (k - 1) / L
            Vd += c * be * k * rho ** (k - 1) / L
        return U, V, Ud, Vd, G, lam

    def displacement(self, r, theta, n_terms: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Radial and polar displacement ``(u_r, u_θ)`` (mm) at radius r (mm) and polar angle θ (rad)."""
        r, th = np.broadcast_arrays(np.asarray(r, dtype=float), np.asarray(theta, dtype=float))
        x = np.cos(th)
        ur = np.zeros(r.shape)
        ut = np.zeros(r.shape)
        for n in range(self.n_terms if n_terms is None else min(n_terms, self.n_terms)):
            if not np.any(self.coeffs[n]):
                continue
            U, V, *_ = self._radial_parts(n, r)
            P, d1, _ = _dP(n, x)
            ur += U * P
            ut += V * d1
        return ur, ut

    def radial_displacement(self, r, theta, n_terms: int | None = None) -> np.ndarray:
        """``u_r`` (mm) at (r, θ), summed over the first ``n_terms`` orders (all by default)."""
        return self.displacement(r, theta, n_terms)[0]

    def stresses(self, r, theta) -> dict[str, np.ndarray]:
        """``sigma_rr``, ``sigma_thth``, ``sigma_phph``, ``tau_rth`` (MPa) at (r, θ)."""
        r, th = np.broadcast_arrays(np.asarray(r, dtype=float), np.asarray(theta, dtype=float))
        x = np.cos(th)
        sin_t = np.sin(th)
        out = {k: np.zeros(r.shape) for k in ("sigma_rr", "sigma_thth", "sigma_phph", "tau_rth")}
        for n in range(self.n_terms):
            if not np.any(self.coeffs[n]):
                continue
            U, V, Ud, Vd, G, lam = self._radial_parts(n, r)
            P, d1, d2 = _dP(n, x)
            e = (Ud + 2 * U / r - n * (n + 1) * V / r) * P
            out["sigma_rr"] += lam * e + 2 * G * Ud * P
            out["tau_rth"] += G * (U / r + Vd - V / r) * d1
            out["sigma_thth"] += lam * e + 2 * G * (V / r * d2 + U / r * P)
            pole = np.abs(sin_t) < 1e-12
            cot_d1 = np.where(pole, d2, x * d1 / np.where(pole, 1.0, sin_t))
            out["sigma_phph"] += lam * e + 2 * G * (U / r * P + V / r * cot_d1)
        return out

    def term_size(self, theta: float = math.pi / 2) -> np.ndarray:
        """``|U_n(a) P_n(cos θ)|`` per order (mm): the size of each term of u_r on the outer surface."""
        out = np.zeros(self.n_terms)
        for n in range(self.n_terms):
            if np.any(self.coeffs[n]):
                U = self._radial_parts(n, np.array([self.a]))[0][0]
                out[n] = abs(U * _legendre(n, math.cos(theta)))
        return out

    def max_abs_coefficient(self) -> np.ndarray:
        """``|U_n(a)|`` per order (mm): the amplitude of each order of u_r on the outer surface."""
        out = np.zeros(self.n_terms)
        for n in range(self.n_terms):
            if np.any(self.coeffs[n]):
                out[n] = abs(self._radial_parts(n, np.array([self.a]))[0][0])
        return out


def solve_shell(
    a: float,
    b: float,
    E: float,
    nu: float,
    *,
    p_ext: float,
    p_int: float = 0.0,
    psi: float = math.pi / 2,
    n_terms: int = 200,
    region: str = "equator",
    outer_coefficients=None,
) -> ShellSolution:
    """Solve the shell problem order by order (see the module docstring).

    Parameters
    ----------
    a, b : float
        Outer and inner radius, mm, ``a > b > 0``.
    E : float
        Young's modulus, MPa.
    nu : float
        Poisson's ratio, ``-1 < nu < 0.5``.
    p_ext : float
        Platen pressure on the loaded region, MPa (compressive positive).
    p_int : float
        Internal pressure, MPa.
    psi : float
        Half-angle of the loaded region, rad (π/2 with ``region="equator"``: the
        whole outer surface).
    n_terms : int
        Number of Legendre orders kept (0 … n_terms-1).
    region : {"equator", "poles"}
    outer_coefficients : array_like, optional
        Legendre coefficients of the outer pressure (MPa) instead of the band.

    Returns
    -------
    ShellSolution
    """
    # radii are lengths, as a design's: at most Tolerances.max_length (a = 1e300 mm had given u_r = -4e297 mm,
    # exit 0)
    a = check_range("a", a, 0.0, DEFAULT.max_length, "mm", lo_open=True)
    b = check_range("b", b, 0.0, DEFAULT.max_length, "mm", lo_open=True)
    if not b < a:
        raise DesignError("b", b, f"must be < a = {format_bound(a, upper=True)} (inner radius below outer)", "mm")
    E = check_positive("E", E, "MPa")
    nu = check_range("nu", nu, -1.0, 0.5, lo_open=True, hi_open=True)
    p_ext = float(p_ext)
    p_int = float(p_int)
    if not (math.isfinite(p_ext) and math.isfinite(p_int)):
        raise DesignError("pressure", (p_ext, p_int), "must be finite", "MPa")
    n_terms = int(check_range("n_terms", n_terms, 1, 100000))
    if outer_coefficients is None:
        outer = p_ext * band_coefficients(psi, n_terms - 1, region)
    else:
        outer = np.zeros(n_terms)
        oc = np.asarray(outer_coefficients, dtype=float).ravel()[:n_terms]
        outer[: oc.size] = oc
    inner = np.zeros(n_terms)
    inner[0] = p_int
    G = E / (2 * (1 + nu))
    lam = 2 * G * nu / (1 - 2 * nu)
    if n_terms > 1 and abs(a * a * outer[1] - b * b * inner[1]) > 1e-12 * max(1.0, abs(outer).max()) * a * a:
        raise DesignError("load", "order-1 term", "has a net axial force; the shell would not be in equilibrium")
    coeffs = []
    for n in range(n_terms):
        if outer[n] == 0.0 and inner[n] == 0.0:
            coeffs.append(np.zeros(len(_modes(n, nu))))
            continue
        modes = _modes(n, nu)
        rows = []
        rhs = []
        for R, p in ((a, outer[n]), (b, inner[n])):
            srow, trow = [], []
            for k, al, be in modes:
                L = a if k >= 0 else b
                f = (R / L) ** (k - 1) / L
                srow.append(f * (lam * ((k + 2) * al - n * (n + 1) * be) + 2 * G * k * al))
                trow.append(f * G * (al + (k - 1) * be))
            rows.append(srow)
            rhs.append(-p)
            if n > 0:
                rows.append(trow)
                rhs.append(0.0)
        M = np.array(rows)
        y = np.array(rhs)
        if M.shape[0] == M.shape[1]:
            c = np.linalg.solve(M, y)
        else:
            c, *_ = np.linalg.lstsq(M, y, rcond=None)
        coeffs.append(c)
    return ShellSolution(a=a, b=b, E=E, nu=nu, outer=outer, inner=inner, coeffs=tuple(coeffs))


def lame_displacement(r, a: float, b: float, E: float, nu: float, p_ext: float, p_int: float) -> np.ndarray:
    """Lamé's radial displacement (mm) of a thick sphere under uniform pressures (MPa).

    ``u = (1-2ν)/E · (p_int b³ - p_ext a³)/(a³ - b³) · r
    + (1+ν)/(2E) · (p_int - p_ext) a³ b³ / ((a³ - b³) r²)``.
    """
    r = np.asarray(r, dtype=float)
    d = a**3 - b**3
    return ((1 - 2 * nu) / E * (p_int * b**3 - p_ext * a**3) / d * r
            + (1 + nu) / (2 * E) * (p_int - p_ext) * a**3 * b**3 / (d * r**2))


def lame_stresses(r, a: float, b: float, p_ext: float, p_int: float) -> tuple[np.ndarray, np.ndarray]:
    """Lamé's ``(σ_rr, σ_θθ)`` (MPa) of a thick sphere under uniform pressures."""
    r = np.asarray(r, dtype=float)
    d = a**3 - b**3
    A = (p_int * b**3 - p_ext * a**3) / d
    B = (p_int - p_ext) * a**3 * b**3 / d
    return A - B / r**3, A + B / (2 * r**3)


def plot_shell(sol: ShellSolution, path, n_theta: int = 361) -> Path:
    """Plot u_r on the outer and inner surfaces against θ (degrees); PNG/SVG by suffix."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from tabletcad.io.figures import save_figure

    th = np.linspace(0.0, math.pi, n_theta)
    fig = Figure(figsize=(6.4, 4.2), dpi=120)
    FigureCanvasAgg(fig)  # its own canvas: the global backend is left alone
    ax = fig.add_subplot(111)
    ax.plot(np.degrees(th), sol.radial_displacement(sol.a, th), label=f"outer surface r = {sol.a:g} mm")
    ax.plot(np.degrees(th), sol.radial_displacement(sol.b, th), label=f"inner surface r = {sol.b:g} mm")
    ax.set_xlabel("Polar angle θ (degrees)")
    ax.set_ylabel("Radial displacement u_r (mm)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return save_figure(fig, Path(path))
