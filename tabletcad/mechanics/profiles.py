"""Tabletability, compressibility and compactibility profiles; Ryshkewitch-Duckworth fit.

Vocabulary of USP general chapter <1062> (tablet compression characterisation):

* tabletability: tensile strength against compaction pressure;
* compressibility: porosity (or solid fraction) against compaction pressure;
* compactibility: tensile strength against porosity (or solid fraction).

The Ryshkewitch-Duckworth equation (thesis eq 2.6) relates tensile strength
and relative density: ``ln(σ_T / σ_T*) = k (ρ_rel - 1)``, i.e.
``σ_T = σ_T* exp(-k ε)`` with porosity ``ε = 1 - ρ_rel``; ``σ_T*`` (MPa) is
the strength at zero porosity and ``k`` a bonding-capacity constant.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tabletcad.errors import DesignError

__all__ = [
    "Profile",
    "RyshkewitchFit",
    "compactibility",
    "compressibility",
    "fit_ryshkewitch_duckworth",
    "plot_profiles",
    "tabletability",
]


@dataclass(frozen=True)
class Profile:
    """A sorted (x, y) profile with axis labels (units in the labels)."""

    name: str
    x: np.ndarray
    y: np.ndarray
    x_label: str
    y_label: str


def _pair(x, y, xname, yname) -> tuple[np.ndarray, np.ndarray]:
    x = np.asarray(x, dtype=float).ravel()
    y = np.asarray(y, dtype=float).ravel()
    if x.size != y.size:
        raise DesignError(yname, f"{y.size} values", f"must match the {x.size} values of {xname}")
    if x.size == 0:
        raise DesignError(xname, "empty", "needs at least one value")
    ok = np.isfinite(x) & np.isfinite(y)
    if not ok.all():
        raise DesignError(xname if not np.isfinite(x).all() else yname, "non-finite", "must be finite numbers")
    o = np.argsort(x, kind="stable")
    return x[o], y[o]


def _check_fraction(name: str, v: np.ndarray) -> None:
    if np.any((v <= 0) | (v >= 1)):
        raise DesignError(name, float(v[(v <= 0) | (v >= 1)][0]), "must be strictly between 0 and 1")


def tabletability(pressure, tensile_strength) -> Profile:
    """Tensile strength (MPa) against compaction pressure (MPa)."""
    x, y = _pair(pressure, tensile_strength, "pressure", "tensile strength")
    return Profile("tabletability", x, y, "Compaction pressure (MPa)", "Tensile strength (MPa)")


def compressibility(pressure, solid_fraction, *, as_porosity: bool = True) -> Profile:
    """Porosity (or solid fraction) against compaction pressure (MPa)."""
    x, sf = _pair(pressure, solid_fraction, "pressure", "solid fraction")
    _check_fraction("solid fraction", sf)
    if as_porosity:
        return Profile("compressibility", x, 1.0 - sf, "Compaction pressure (MPa)", "Porosity (–)")
    return Profile("compressibility", x, sf, "Compaction pressure (MPa)", "Solid fraction (–)")


def compactibility(solid_fraction, tensile_strength, *, as_porosity: bool = True) -> Profile:
    """Tensile strength (MPa) against porosity (or solid fraction)."""
    sf, y = _pair(solid_fraction, tensile_strength, "solid fraction", "tensile strength")
    _check_fraction("solid fraction", sf)
    if as_porosity:
        eps = 1.0 - sf
        o = np.argsort(eps, kind="stable")
        return Profile("compactibility", eps[o], y[o], "Porosity (–)", "Tensile strength (MPa)")
    return Profile("compactibility", sf, y, "Solid fraction (–)", "Tensile strength (MPa)")


@dataclass(frozen=True)
class RyshkewitchFit:
    """Ryshkewitch-Duckworth parameters (eq 2.6).

    Attributes
    ----------
    sigma0_MPa : float
        Tensile strength at zero porosity σ_T*, MPa.
    k : float
        Bonding-capacity constant, dimensionless.
    r2 : float
        R² of ``ln σ_T`` against relative density.
    n_points : int
    """

    sigma0_MPa: float
    k: float
    r2: float
    n_points: int

    def strength(self, relative_density) -> np.ndarray:
        """Predicted tensile strength (MPa) at ``relative_density``."""
        return self.sigma0_MPa * np.exp(self.k * (np.asarray(relative_density, dtype=float) - 1.0))


def fit_ryshkewitch_duckworth(relative_density, tensile_strength) -> RyshkewitchFit:
    """Fit ``ln σ_T = ln σ_T* + k (ρ_rel - 1)`` by least squares on ``ln σ_T``.

    Parameters
    ----------
    relative_density : array_like
        Solid fractions in (0, 1).
    tensile_strength : array_like
        MPa, > 0.
    """
    D, s = _pair(relative_density, tensile_strength, "relative density", "tensile strength")
    _check_fraction("relative density", D)
    if np.any(s <= 0):
        raise DesignError("tensile strength", float(s[s <= 0][0]), "must be > 0", "MPa")
    if D.size < 3:
        raise DesignError("data", f"{D.size} points", "need >= 3 (density, strength) pairs")
    y = np.log(s)
    k, c = np.polyfit(D - 1.0, y, 1)
    yhat = k * (D - 1.0) + c
    ss = float(np.sum((y - y.mean()) ** 2))
    r2 = 1.0 - float(np.sum((y - yhat) ** 2)) / ss if ss > 0 else 1.0
    return RyshkewitchFit(sigma0_MPa=float(np.exp(c)), k=float(k), r2=r2, n_points=int(D.size))


def plot_profiles(profiles: list[Profile], path: str | Path) -> Path:
    """Write the profiles side by side (PNG/SVG by suffix), atomically."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from tabletcad.io.figures import save_figure

    n = max(len(profiles), 1)
    fig = Figure(figsize=(4.0 * n, 3.6), dpi=120)
    FigureCanvasAgg(fig)  # its own canvas: the global backend is left alone
    for i, p in enumerate(profiles):
        ax = fig.add_subplot(1, n, i + 1)
        ax.plot(p.x, p.y, "o-", ms=3)
        ax.set_xlabel(p.x_label)
        ax.set_ylabel(p.y_label)
        ax.set_title(p.name)
        ax.grid(True, alpha=0.3)
    fig.tight_layout()
    return save_figure(fig, Path(path))
