"""Kawakita and Walker compression equations (volume reduction against pressure).

Kawakita
    Degree of volume reduction ``C = (V0 - V) / V0 = a b P / (1 + b P)``,
    fitted in its linear form ``P / C = P / a + 1 / (a b)``.  ``a`` is the
    limiting volume reduction (≈ initial porosity), ``b`` (1/MPa) a rate
    constant; ``1/b`` (MPa) is the pressure that achieves half of ``a``.

Walker
    ``100 V / V0 = -W log10(P) + c``: the relative volume (per cent of the
    initial volume) falls linearly with the decade of pressure; ``W``
    (per cent per decade) is the Walker compressibility coefficient.

In a die of constant cross-section ``V / V0 = h / h0``.  ``V0`` is the volume
at the first loading point unless given.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tabletcad.errors import DesignError, check_positive
from tabletcad.mechanics.compaction import CompactionCurves
from tabletcad.mechanics.validity import FitQualityWarning, warn

__all__ = ["KawakitaFit", "WalkerFit", "fit_kawakita", "fit_walker"]


@dataclass(frozen=True)
class KawakitaFit:
    """Kawakita parameters.

    Attributes
    ----------
    a : float
        Limiting degree of volume reduction, dimensionless.
    b_per_MPa : float
        1/MPa.
    inv_b_MPa : float
        1/b, MPa.
    r2 : float
        R² of the linear form ``P/C`` against ``P``.
    window_MPa : (float, float)
    n_points : int
    h0 : float
        Reference thickness (mm) defining ``V0``.
    """

    a: float
    b_per_MPa: float
    inv_b_MPa: float
    r2: float
    window_MPa: tuple[float, float]
    n_points: int
    h0: float

    def to_dict(self) -> dict:
        return {"a": self.a, "b_per_MPa": self.b_per_MPa, "inv_b_MPa": self.inv_b_MPa, "r2": self.r2,
                "window_MPa": list(self.window_MPa), "n_points": self.n_points, "h0_mm": self.h0}


@dataclass(frozen=True)
class WalkerFit:
    """Walker parameters.

    Attributes
    ----------
    W_percent_per_decade : float
        Walker coefficient W, per cent of V0 per decade of pressure.
    intercept_percent : float
        ``100 V/V0`` extrapolated to P = 1 MPa.
    r2 : float
    window_MPa : (float, float)
    n_points : int
    h0 : float
        mm.
    """

    W_percent_per_decade: float
    intercept_percent: float
    r2: float
    window_MPa: tuple[float, float]
    n_points: int
    h0: float

    def to_dict(self) -> dict:
        return {"W_percent_per_decade": self.W_percent_per_decade, "intercept_percent": self.intercept_percent,
                "r2": self.r2, "window_MPa": list(self.window_MPa), "n_points": self.n_points, "h0_mm": self.h0}


def _prepare(pressure, thickness, window, h0):
    P = np.asarray(pressure, dtype=float).ravel()
    h = np.asarray(thickness, dtype=float).ravel()
    if P.size != h.size:
        raise DesignError("data", f"{P.size} pressures, {h.size} thicknesses", "must have equal length")
    h0 = float(h[0]) if h0 is None else check_positive("h0", h0, "mm")
    sel = np.isfinite(P) & np.isfinite(h) & (P > 0)
    if window is not None:
        lo, hi = float(window[0]), float(window[1])
        if not lo < hi:
            raise DesignError("window", f"{lo:g}-{hi:g}", "must be two increasing pressures", "MPa")
        sel &= (P >= lo) & (P <= hi)
    if sel.sum() < 3:  # named as what limited the points: the window given, else the data
        if window is not None:
            raise DesignError("window", f"{lo:g}-{hi:g}", f"holds {int(sel.sum())} usable points; need >= 3", "MPa")
        raise DesignError("data", f"{int(sel.sum())} points with a pressure > 0", "need >= 3")
    return P[sel], h[sel], h0


def _r2(y, yhat):
    ss = float(np.sum((y - y.mean()) ** 2))
    return 1.0 - float(np.sum((y - yhat) ** 2)) / ss if ss > 0 else 1.0


def fit_kawakita(pressure, thickness, *, window: tuple[float, float] | None = None, h0: float | None = None) -> KawakitaFit:
    """Fit the Kawakita equation to loading-branch pressure (MPa) and thickness (mm).

    Points with ``C <= 0`` (no volume reduction yet) are skipped.
    """
    given = h0 is not None
    P, h, h0 = _prepare(pressure, thickness, window, h0)
    C = (h0 - h) / h0
    keep = C > 0
    P, C = P[keep], C[keep]
    if P.size < 3:
        if given:  # the reference thickness the user gave is below the compact's: no reduction to fit
            raise DesignError("h0", h0, f"must exceed the thickness at 3 or more of the fitted pressures "
                              f"(it exceeds {P.size} of them; the thinnest compact is {float(np.min(h)):.6g} mm)", "mm")
        raise DesignError("data", f"{P.size} points with volume reduction", "need >= 3")
    y = P / C
    slope, icpt = np.polyfit(P, y, 1)
    if slope <= 0 or icpt <= 0:
        warn(FitQualityWarning, f"Kawakita fit gives non-physical parameters (1/a = {slope:.3g}, 1/(ab) = {icpt:.3g})")
    a = 1.0 / slope
    b = slope / icpt
    return KawakitaFit(a=float(a), b_per_MPa=float(b), inv_b_MPa=float(1.0 / b), r2=_r2(y, slope * P + icpt),
                       window_MPa=(float(P.min()), float(P.max())), n_points=int(P.size), h0=h0)


def fit_walker(pressure, thickness, *, window: tuple[float, float] | None = None, h0: float | None = None) -> WalkerFit:
    """Fit the Walker equation ``100 V/V0 = -W log10 P + c`` (P in MPa, h in mm).

    A coefficient ``W <= 0`` (the compact not getting thinner as the pressure rises) is fitted and
    warned of with a :class:`~tabletcad.mechanics.validity.FitQualityWarning`, as Heckel's ``K <= 0``
    and Kawakita's non-physical parameters are.
    """
    P, h, h0 = _prepare(pressure, thickness, window, h0)
    y = 100.0 * h / h0
    x = np.log10(P)
    slope, icpt = np.polyfit(x, y, 1)
    W = 0.0 - float(slope)  # (0.0 -: never a "-0")
    if W <= 0:  # as heckel's K <= 0 and kawakita's non-physical a, b: a fit, warned of
        warn(FitQualityWarning, f"Walker fit: non-positive coefficient W = {W:.4g} % per decade: the volume "
                                "does not fall as the pressure rises (check the thickness column and h0)")
    return WalkerFit(W_percent_per_decade=W, intercept_percent=float(icpt), r2=_r2(y, slope * x + icpt),
                     window_MPa=(float(P.min()), float(P.max())), n_points=int(P.size), h0=h0)


def fit_kawakita_curves(curves: CompactionCurves, **kw) -> KawakitaFit:
    """:func:`fit_kawakita` on the loading branch of a record."""
    sl = curves.loading
    return fit_kawakita(curves.pressure[sl], curves.thickness[sl], **kw)


def fit_walker_curves(curves: CompactionCurves, **kw) -> WalkerFit:
    """:func:`fit_walker` on the loading branch of a record."""
    sl = curves.loading
    return fit_walker(curves.pressure[sl], curves.thickness[sl], **kw)


__all__ += ["fit_kawakita_curves", "fit_walker_curves"]
