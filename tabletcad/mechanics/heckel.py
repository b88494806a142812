"""Heckel analysis: ``ln(1/(1 - D)) = K P + A`` (thesis eqs 2.2-2.3).

``K`` (1/MPa) is the slope, ``A`` the intercept, and ``Py = 1/K`` (MPa) the
apparent mean yield pressure.  Only the loading branch is fitted (see
:mod:`tabletcad.mechanics.compaction`).

Choosing the linear region
--------------------------
With ``window=(lo, hi)`` the fit uses every loading point with
``lo <= P <= hi`` (MPa, closed interval).

With ``window=None`` the linear region is the widest run of points whose
scatter about their own line is no larger than the data's noise.  No band,
tolerance or scale is given by the user; the rule is:

1. **Noise from the data.**  Each point ``i`` (ordered by pressure) is
   compared with the straight line through its two neighbours; the
   difference, divided by its standard deviation factor
   ``sqrt(1 + w² + (1 - w)²)`` (``w`` the relative position of ``P_i``
   between its neighbours), has the noise's standard deviation σ wherever the
   curve is locally straight.  σ is estimated robustly as 1.4826 × the median
   absolute deviation of these scaled differences about their median
   (:func:`heckel_noise_sd`); the median absorbs a slowly varying curvature,
   and outliers do not inflate it.  ``noise_sd=`` replaces the estimate.
2. **Lack-of-fit test.**  A run of ``m`` consecutive points is *linear* when
   the residual sum of squares of its least-squares line is at most
   ``σ² · χ²_{m-2}(1 - α/n)``: the upper ``α/n`` quantile of the chi-square
   distribution with ``m - 2`` degrees of freedom, ``n`` the number of
   loading points (a Bonferroni bound over the ``n`` places a window can end,
   so that pure noise fails a linear run with probability at most ``α``,
   default 0.05, anywhere in the record).
3. **Widest run.**  Among runs of at least ``min_points`` points (default 8)
   that are linear, the one with the widest pressure span is chosen; ties go
   to the smaller residual standard deviation.  Up to ``EXHAUSTIVE_MAX``
   (4096) loading points every run is tested.  Above, two shortcuts bound
   the work: the first points tried are every ``s``-th of those that start a
   linear run of ``min_points`` (``s`` = their number / 4096, rounded up),
   then every one between the best of them and its grid neighbours; and the
   longest linear run from a first point is found by bisection on its length,
   which treats the test as monotone in the length (curvature only adds to
   the residual sum as a run grows; noise can make a longer run pass where a
   shorter one failed, and the bisection may then stop short).  The tests
   check the result against the exhaustive search (span within 2 %).

Both quantities in (2) scale with the square of the Heckel term's noise, so
the chosen window does not depend on the units of pressure or on the noise
level except through what the data can resolve: noisier data give a longer
window (curvature hidden by noise), cleaner data a shorter one.  Adding a
straight line to the Heckel term leaves the window unchanged.  Sums over a run
come from prefix sums of the data centred and detrended by their global line
(numerically stable), so any run's fit costs O(1) and the whole search
O(n²) time up to 4096 points, O(n) above (4096 bisections plus the
prefix sums), and O(n) memory (``benchmarks/bench_heckel.py``: 2.6-4 s and
a 162 MiB peak heap for 10⁶ rows on a loaded 2-core machine).  If no run is linear a :class:`DesignError` asks for a
window.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from tabletcad.errors import MISSING, DesignError, check_positive, check_range
from tabletcad.mechanics.compaction import CompactionCurves, check_peak_relative_density
from tabletcad.mechanics.validity import FitQualityWarning, warn

__all__ = ["PY_PLAUSIBLE_MPA", "HeckelFit", "fit_heckel", "fit_heckel_arrays", "heckel_noise_sd", "plot_heckel"]

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
    noise_sd : float or None
        Noise standard deviation of the Heckel term the automatic rule used
        (estimated or given); ``None`` for a given window.
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
    noise_sd: float | None = None
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
            "noise_sd": self.noise_sd,
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


def heckel_noise_sd(pressure, heckel) -> float:
    """Robust estimate of the noise standard deviation of the Heckel term (module docstring, step 1).

    Parameters
    ----------
    pressure, heckel : array_like
        MPa and ln(1/(1-D)), sorted by pressure.

    Returns
    -------
    float
        σ (dimensionless, the Heckel term's unit); 0 if fewer than three
        distinct pressures.
    """
    P = np.asarray(pressure, dtype=float)
    H = np.asarray(heckel, dtype=float)
    left, right = P[1:-1] - P[:-2], P[2:] - P[1:-1]
    span = left + right
    ok = span > 0
    if not ok.any():
        return 0.0
    w = left[ok] / span[ok]
    e = H[1:-1][ok] - ((1.0 - w) * H[:-2][ok] + w * H[2:][ok])
    z = e / np.sqrt(1.0 + w * w + (1.0 - w) ** 2)
    return float(_MAD_TO_SD * np.median(np.abs(z - np.median(z))))


#: Up to this many loading points every run is tested (exact); above, starts are sampled and lengths bisected.
EXHAUSTIVE_MAX = 4096
#: 1/Φ⁻¹(3/4): the median absolute deviation of a normal sample times this is its standard deviation.
_MAD_TO_SD = 1.482602218505602


class _RunSums:
    """Prefix sums giving the least-squares residual sum of squares of any run ``[i, j)`` in O(1)."""

    def __init__(self, P: np.ndarray, H: np.ndarray) -> None:
        x = P - P.mean()
        y = H - H.mean()
        sxx = float(np.dot(x, x))
        y = y - (float(np.dot(x, y)) / sxx if sxx > 0 else 0.0) * x  # detrend: small sums, no cancellation
        zero = np.zeros(1)
        self.x = np.concatenate([zero, np.cumsum(x)])
        self.y = np.concatenate([zero, np.cumsum(y)])
        self.xx = np.concatenate([zero, np.cumsum(x * x)])
        self.xy = np.concatenate([zero, np.cumsum(x * y)])
        self.yy = np.concatenate([zero, np.cumsum(y * y)])

    def sse(self, i: np.ndarray, j: np.ndarray) -> np.ndarray:
        """Residual sum of squares of the runs ``[i, j)``; ``inf`` where the run has no pressure spread."""
        m = j - i
        sx, sy = self.x[j] - self.x[i], self.y[j] - self.y[i]
        sxx = self.xx[j] - self.xx[i] - sx * sx / m
        sxy = self.xy[j] - self.xy[i] - sx * sy / m
        syy = self.yy[j] - self.yy[i] - sy * sy / m
        spread = sxx > 0
        out = syy - np.where(spread, sxy * sxy / np.where(spread, sxx, 1.0), 0.0)
        return np.where(spread, np.maximum(out, 0.0), np.inf)


def _auto_window(P: np.ndarray, H: np.ndarray, min_points: int, sigma: float, alpha: float) -> tuple[int, int] | None:
    """First and end index of the widest linear run (module docstring, steps 2-3), or None."""
    from scipy.special import gammainccinv

    n = P.size
    sums = _RunSums(P, H)

    def limit(m: np.ndarray) -> np.ndarray:
        """σ² χ²_{m-2}(1 - α/n): the largest residual sum of squares of a linear run of m points."""
        return sigma * sigma * 2.0 * gammainccinv((m - 2) / 2.0, alpha / n)

    # every length is needed when every run is tested: tabulate once
    table = limit(np.arange(n + 1).clip(min_points)) if n <= EXHAUSTIVE_MAX else None

    def linear(i: np.ndarray, m: np.ndarray) -> np.ndarray:
        return sums.sse(i, i + m) <= (limit(m) if table is None else table[m])

    start = np.arange(0, n - min_points + 1)
    start = start[sums.sse(start, start + min_points) <= limit(np.array([min_points]))[0]]
    if start.size == 0:
        return None

    def longest(i: np.ndarray) -> np.ndarray:
        """Length of the longest linear run from each start ``i``."""
        if n <= EXHAUSTIVE_MAX:
            out = np.empty(i.size, dtype=int)
            for k, s in enumerate(i):  # every run from s, vectorised over its ends: exact
                m = np.arange(min_points, n - s + 1)
                out[k] = m[np.flatnonzero(linear(np.full(m.size, s), m))[-1]]
            return out
        lo, hi = np.full(i.size, min_points), n - i
        while np.any(lo < hi):  # bisection on the length, all starts at once: lo passes, hi bounds the longest
            active = lo < hi
            mid = (lo + hi + 1) // 2
            ok = linear(i, mid)
            lo = np.where(active & ok, mid, lo)
            hi = np.where(active & ~ok, mid - 1, hi)
        return lo

    if n <= EXHAUSTIVE_MAX:
        cand = start
    else:  # every stride-th linear start, then every start between the best one's grid neighbours
        stride = -(-start.size // EXHAUSTIVE_MAX)
        coarse = start[::stride]
        k = int(np.argmax(P[np.minimum(coarse + longest(coarse) - 1, n - 1)] - P[coarse]))
        near = start[max(0, (k - 1) * stride): (k + 1) * stride + 1]
        cand = np.union1d(coarse, near)
    length = longest(cand)
    span = P[cand + length - 1] - P[cand]
    sd = np.sqrt(sums.sse(cand, cand + length) / (length - 2))
    best = np.lexsort((sd, -span))[0]
    return int(cand[best]), int(cand[best] + length[best])


def fit_heckel_arrays(
    pressure,
    relative_density=None,
    *,
    heckel=None,
    window: tuple[float, float] | None = None,
    min_points: int = 8,
    noise_sd: float | None = None,
    alpha: float = 0.05,
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
    min_points : int
        Fewest points of an automatic window (module docstring, step 3).
    noise_sd : float, optional
        Noise standard deviation of the Heckel term; default: estimated from
        the data (:func:`heckel_noise_sd`).
    alpha : float
        Family-wise level of the lack-of-fit test (module docstring, step 2).
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
            raise DesignError("relative_density", MISSING, "give relative_density or heckel")
        D = np.asarray(relative_density, dtype=float).ravel()
        check_peak_relative_density(D[np.isfinite(P) & (P > 0)] if D.size == P.size else D)
        with np.errstate(divide="ignore", invalid="ignore"):
            H = np.where(D < 1.0, -np.log1p(-np.minimum(D, 1.0 - 1e-300)), np.nan)
    else:
        H = np.asarray(heckel, dtype=float).ravel()
    if H.size != P.size:
        raise DesignError("data", f"{P.size} pressures, {H.size} densities", "must have equal length")
    idx = np.arange(P.size) if rows is None else np.asarray(rows, dtype=int).ravel()
    good = np.isfinite(P) & np.isfinite(H) & (P > 0)
    n_dense = int(np.sum(np.isfinite(P) & (P > 0) & ~np.isfinite(H)))  # relative density >= 1: no Heckel term
    why = (f" ({n_dense} loaded row(s) have relative density >= 1 and no Heckel term: check the mass, the true "
           "density, the die diameter or face area (mm, mm²), the compliance)") if n_dense else ""
    order = np.argsort(P[good], kind="stable")
    Pg, Hg, ig = P[good][order], H[good][order], idx[good][order]
    if window is not None:
        lo, hi = (float(window[0]), float(window[1]))
        check_positive("window upper bound", hi, "MPa")
        if not (np.isfinite(lo) and lo < hi):
            raise DesignError("window", (lo, hi), "must be two increasing pressures", "MPa")
        sel = (Pg >= lo) & (Pg <= hi)
        if sel.sum() < 3:
            raise DesignError("window", f"{lo:g}-{hi:g}", f"holds {int(sel.sum())} loading points; need >= 3{why}", "MPa")
        x, y, used = Pg[sel], Hg[sel], ig[sel]
        method = "window"
        requested = (lo, hi)
        sigma = None
    else:
        if min_points < 3:
            raise DesignError("min_points", min_points, "must be >= 3")
        if Pg.size < min_points:
            raise DesignError("data", f"{Pg.size} loading points", f"need >= {min_points} for automatic window{why}")
        if noise_sd is None:
            # the floor is the double-precision resolution of the Heckel term (exact, noise-free data)
            sigma = max(heckel_noise_sd(Pg, Hg), 16.0 * np.finfo(float).eps * float(np.max(np.abs(Hg))))
        else:
            sigma = check_positive("noise_sd", noise_sd)
        check_range("alpha", alpha, 0.0, 1.0, lo_open=True, hi_open=True)
        best = _auto_window(Pg, Hg, min_points, sigma, alpha)
        if best is None:
            raise DesignError(
                "window", "auto",
                f"no run of >= {min_points} points is linear within the noise (σ = {sigma:.3g}) at the "
                f"{alpha:g} level; give --window",
            )
        i, j = best
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
        warnings=tuple(msgs), noise_sd=sigma, pressure=Pg, heckel=Hg,
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
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from tabletcad.io.figures import save_figure

    fig = Figure(figsize=(6.4, 4.4), dpi=120)
    FigureCanvasAgg(fig)  # its own canvas: the global backend is left alone
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
    return save_figure(fig, Path(path))
