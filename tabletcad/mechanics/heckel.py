"""Heckel analysis: ``ln(1/(1 - D)) = K P + A`` (thesis eqs 2.2-2.3).

``K`` (1/MPa) is the slope, ``A`` the intercept, and ``Py = 1/K`` (MPa) the
apparent mean yield pressure.  Only the loading branch is fitted (see
:mod:`tabletcad.mechanics.compaction`).

Choosing the linear region
--------------------------
With ``window=(lo, hi)`` the fit uses every loading point with
``lo <= P <= hi`` (MPa, closed interval).

With ``window=None`` the linear region is chosen by this rule (all numbers are
parameters of :func:`fit_heckel`):

1. Candidates are the contiguous runs of loading points (ordered by pressure,
   with ``P > 0`` and ``D < 1``) holding at least ``min_points`` points.
2. Each candidate is fitted by ordinary least squares; it is *linear* when its
   largest absolute residual is at most ``max_residual`` (in units of the
   Heckel term; default 0.005, i.e. the data stay within ±0.005 of the line)
   and its R² is at least ``min_r2`` (default 0.99).
3. The selected window is the linear candidate with the widest pressure span;
   ties go to the smaller residual standard deviation.

The bound in (2) must exceed about three times the noise standard deviation
of the Heckel term, otherwise noise rather than curvature limits the window.
If no candidate is linear, a :class:`DesignError` is raised.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from tabletcad.errors import DesignError, check_positive
from tabletcad.mechanics.compaction import CompactionCurves
from tabletcad.mechanics.validity import FitQualityWarning, warn

__all__ = ["PY_PLAUSIBLE_MPA", "HeckelFit", "fit_heckel", "fit_heckel_arrays", "plot_heckel"]

#: Range of apparent yield pressure (MPa) outside which a warning is issued.
PY_PLAUSIBLE_MPA = (10.0, 2000.0)
#: R² below which the fit is reported as poorly linear.
R2_WARN = 0.99


@dataclass(frozen=True)
class HeckelFit:
    """Result of a Heckel fit.

    Attributes
    ----------
    K_per_MPa : float
        Slope K, 1/MPa.
    A : float
        Intercept A, dimensionless.
    Py_MPa : float
        Apparent yield pressure 1/K, MPa (``inf`` if K = 0).
    r2 : float
        Coefficient of determination of the fit.
    window_MPa : (float, float)
        Lowest and highest pressure of the points used, MPa.
    n_points : int
        Number of points fitted.
    rows : tuple of int
        0-based indices (into the record) of the points fitted.
    method : str
        ``"window"`` or ``"auto"``.
    residual_sd : float
        Residual standard deviation (n - 2 degrees of freedom).
    max_abs_residual : float
    requested_window_MPa : (float, float) or None
    warnings : tuple of str
        Messages also issued as :class:`FitQualityWarning`.
    pressure, heckel : ndarray
        The loading-branch data the fit was chosen from (for plots).
    """

    K_per_MPa: float
    A: float
    Py_MPa: float
    r2: float
    window_MPa: tuple[float, float]
    n_points: int
    rows: tuple[int, ...]
    method: str
    residual_sd: float
    max_abs_residual: float
    requested_window_MPa: tuple[float, float] | None = None
    warnings: tuple[str, ...] = ()
    pressure: np.ndarray = field(default_factory=lambda: np.empty(0), repr=False)
    heckel: np.ndarray = field(default_factory=lambda: np.empty(0), repr=False)

    @property
    def relative_density_at_zero(self) -> float:
        """``D_A = 1 - exp(-A)``: relative density extrapolated to zero pressure."""
        return float(1.0 - np.exp(-self.A))

    def to_dict(self) -> dict:
        """JSON-ready summary (the CLI's ``--json`` output)."""
        return {
            "K_per_MPa": self.K_per_MPa,
            "A": self.A,
            "Py_MPa": self.Py_MPa,
            "r2": self.r2,
            "window_MPa": [self.window_MPa[0], self.window_MPa[1]],
            "n_points": self.n_points,
            "method": self.method,
            "residual_sd": self.residual_sd,
            "warnings": list(self.warnings),
        }


def _ols(x: np.ndarray, y: np.ndarray) -> tuple[float, float, float, np.ndarray]:
    xm, ym = x.mean(), y.mean()
    sxx = float(np.sum((x - xm) ** 2))
    if sxx <= 0.0:
        raise DesignError("window", "all points at one pressure", "must span a pressure range")
    k = float(np.sum((x - xm) * (y - ym)) / sxx)
    a = float(ym - k * xm)
    res = y - (k * x + a)
    syy = float(np.sum((y - ym) ** 2))
    r2 = 1.0 - float(np.sum(res**2)) / syy if syy > 0 else 1.0
    return k, a, r2, res


def _auto_window(P: np.ndarray, H: np.ndarray, min_points: int, max_residual: float, min_r2: float):
    n = P.size
    best = None
    # prefix sums give every window's OLS in O(1); residual maxima are then checked in O(len)
    cx = np.concatenate([[0.0], np.cumsum(P)])
    cy = np.concatenate([[0.0], np.cumsum(H)])
    cxx = np.concatenate([[0.0], np.cumsum(P * P)])
    cxy = np.concatenate([[0.0], np.cumsum(P * H)])
    cyy = np.concatenate([[0.0], np.cumsum(H * H)])
    for i in range(n - min_points + 1):
        j = np.arange(i + min_points, n + 1)
        m = j - i
        sx, sy = cx[j] - cx[i], cy[j] - cy[i]
        sxx = cxx[j] - cxx[i] - sx * sx / m
        sxy = cxy[j] - cxy[i] - sx * sy / m
        syy = cyy[j] - cyy[i] - sy * sy / m
        ok = sxx > 0
        k = np.where(ok, sxy / np.where(ok, sxx, 1.0), 0.0)
        sse = np.maximum(syy - k * sxy, 0.0)
        r2 = np.where(syy > 0, 1.0 - sse / np.where(syy > 0, syy, 1.0), 1.0)
        span = P[j - 1] - P[i]
        for idx in np.flatnonzero(ok & (r2 >= min_r2)):
            jj = int(j[idx])
            if best is not None and span[idx] < best[0] - 1e-12:
                continue
            kk = float(k[idx])
            a = (sy[idx] - kk * sx[idx]) / m[idx]
            res = H[i:jj] - (kk * P[i:jj] + a)
            if np.max(np.abs(res)) > max_residual:
                continue
            sd = float(np.sqrt(sse[idx] / max(m[idx] - 2, 1)))
            cand = (float(span[idx]), -sd, i, jj)
            if best is None or cand[:2] > best[:2]:
                best = cand
    return best


def fit_heckel_arrays(
    pressure,
    relative_density=None,
    *,
    heckel=None,
    window: tuple[float, float] | None = None,
    min_points: int = 8,
    max_residual: float = 0.005,
    min_r2: float = 0.99,
    rows=None,
) -> HeckelFit:
    """Heckel fit of loading-branch arrays.

    Parameters
    ----------
    pressure : array_like
        MPa, loading branch only.
    relative_density : array_like, optional
        Solid fraction D; or give ``heckel`` = ln(1/(1-D)) directly.
    window : (float, float) or None
        Pressure window in MPa; ``None`` selects it automatically (module docstring).
    min_points, max_residual, min_r2
        Parameters of the automatic rule.
    rows : array_like of int, optional
        Row index of each point, reported in the result.

    Returns
    -------
    HeckelFit

    Raises
    ------
    DesignError
        Window with fewer than 3 points, inverted window, or no linear region.
    """
    P = np.asarray(pressure, dtype=float).ravel()
    if heckel is None:
        if relative_density is None:
            raise DesignError("relative_density", None, "give relative_density or heckel")
        D = np.asarray(relative_density, dtype=float).ravel()
        with np.errstate(divide="ignore", invalid="ignore"):
            H = np.where(D < 1.0, -np.log1p(-np.minimum(D, 1.0 - 1e-300)), np.nan)
    else:
        H = np.asarray(heckel, dtype=float).ravel()
    if H.size != P.size:
        raise DesignError("data", f"{P.size} pressures, {H.size} densities", "must have equal length")
    idx = np.arange(P.size) if rows is None else np.asarray(rows, dtype=int).ravel()
    good = np.isfinite(P) & np.isfinite(H) & (P > 0)
    order = np.argsort(P[good], kind="stable")
    Pg, Hg, ig = P[good][order], H[good][order], idx[good][order]
    if window is not None:
        lo, hi = (float(window[0]), float(window[1]))
        check_positive("window upper bound", hi, "MPa")
        if not (np.isfinite(lo) and lo < hi):
            raise DesignError("window", (lo, hi), "must be two increasing pressures", "MPa")
        sel = (Pg >= lo) & (Pg <= hi)
        if sel.sum() < 3:
            raise DesignError("window", f"{lo:g}-{hi:g}", f"holds {int(sel.sum())} loading points; need >= 3", "MPa")
        x, y, used = Pg[sel], Hg[sel], ig[sel]
        method = "window"
        requested = (lo, hi)
    else:
        if min_points < 3:
            raise DesignError("min_points", min_points, "must be >= 3")
        if Pg.size < min_points:
            raise DesignError("data", f"{Pg.size} loading points", f"need >= {min_points} for automatic window")
        best = _auto_window(Pg, Hg, min_points, max_residual, min_r2)
        if best is None:
            raise DesignError(
                "window", "auto",
                f"no run of >= {min_points} points is linear within {max_residual:g} (R² >= {min_r2:g}); give --window",
            )
        i, j = best[2], best[3]
        x, y, used = Pg[i:j], Hg[i:j], ig[i:j]
        method = "auto"
        requested = None
    k, a, r2, res = _ols(x, y)
    sd = float(np.sqrt(np.sum(res**2) / max(x.size - 2, 1)))
    msgs: list[str] = []
    if r2 < R2_WARN:
        msgs.append(f"poor linearity: R² = {r2:.4f} < {R2_WARN}")
    if k <= 0:
        msgs.append(f"non-positive slope K = {k:.3g} 1/MPa: the window is not a densification range")
        py = float("inf") if k == 0 else 1.0 / k
    else:
        py = 1.0 / k
        if not (PY_PLAUSIBLE_MPA[0] <= py <= PY_PLAUSIBLE_MPA[1]):
            msgs.append(f"implausible yield pressure Py = {py:.4g} MPa (expected {PY_PLAUSIBLE_MPA[0]:g}-"
                        f"{PY_PLAUSIBLE_MPA[1]:g} MPa)")
    for m in msgs:
        warn(FitQualityWarning, "Heckel fit: " + m)
    return HeckelFit(
        K_per_MPa=k, A=a, Py_MPa=py, r2=r2, window_MPa=(float(x.min()), float(x.max())),
        n_points=int(x.size), rows=tuple(int(r) for r in used), method=method, residual_sd=sd,
        max_abs_residual=float(np.max(np.abs(res))), requested_window_MPa=requested,
        warnings=tuple(msgs), pressure=Pg, heckel=Hg,
    )


def fit_heckel(curves: CompactionCurves, window: tuple[float, float] | None = None, **auto) -> HeckelFit:
    """Heckel fit of the loading branch of :func:`~tabletcad.mechanics.compaction.compaction_curves`.

    See :func:`fit_heckel_arrays` for ``window`` and the automatic-rule keywords.
    """
    sl = curves.loading
    rows = np.arange(curves.pressure.size)[sl]
    return fit_heckel_arrays(curves.pressure[sl], heckel=curves.heckel[sl], window=window, rows=rows, **auto)


def plot_heckel(fit: HeckelFit, path: str | Path, *, title: str = "", others: dict | None = None) -> Path:
    """Write a Heckel plot (PNG or SVG by suffix) with data, fit and shaded window.

    Parameters
    ----------
    fit : HeckelFit
    path : path
        Output file; written atomically.
    title : str
    others : dict of str to HeckelFit, optional
        Further fits (e.g. a model) drawn as labelled lines over their windows.
    """
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    from tabletcad.io import atomic_path

    fig = Figure(figsize=(6.4, 4.4), dpi=120)
    ax = fig.add_subplot(111)
    ax.plot(fit.pressure, fit.heckel, "o", ms=3, color="0.6", label="loading branch")
    lo, hi = fit.window_MPa
    inwin = (fit.pressure >= lo) & (fit.pressure <= hi)
    ax.plot(fit.pressure[inwin], fit.heckel[inwin], "o", ms=3.5, color="C0", label=f"fitted points (n = {fit.n_points})")
    ax.axvspan(lo, hi, color="C0", alpha=0.12, lw=0, label=f"window {lo:.3g}-{hi:.3g} MPa")
    xs = np.linspace(0.0, max(float(fit.pressure.max()), hi), 100)
    ax.plot(xs, fit.K_per_MPa * xs + fit.A, "-", color="C1",
            label=f"K = {fit.K_per_MPa:.4g} 1/MPa, A = {fit.A:.4f}, Py = {fit.Py_MPa:.4g} MPa, R² = {fit.r2:.4f}")
    for j, (name, other) in enumerate((others or {}).items()):
        o_lo, o_hi = other.window_MPa
        xo = np.linspace(o_lo, o_hi, 50)
        ax.plot(xo, other.K_per_MPa * xo + other.A, "--", color=f"C{j + 2}",
                label=f"{name}: K = {other.K_per_MPa:.4g} 1/MPa, A = {other.A:.4f}")
    ax.set_xlabel("Pressure P (MPa)")
    ax.set_ylabel("ln(1/(1 − D))  (–)")
    ax.set_title(title or "Heckel plot")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="lower right")
    fig.tight_layout()
    path = Path(path)
    fmt = path.suffix.lstrip(".").lower() or "png"
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format=fmt)
    return path
