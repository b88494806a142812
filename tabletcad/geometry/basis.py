"""Stable cardinal functions of the Bloor-Wilson ODE in ``u``.

Separating variables in ``(d²/du² + a² d²/dv²)² X = 0`` (thesis eq 3.9 with
order 2) leaves, for Fourier mode ``n``, the ODE ``(D² - λ²)² A = 0`` with
``λ = a·n``, whose solutions are spanned by ``e^{λu}, u e^{λu}, e^{-λu},
u e^{-λu}`` (eqs 3.13-3.15; a cubic when ``λ = 0``).  A patch is fixed by four
conditions per mode: values at four parameters ``u0 = 0 < u1 < u2 < u3 = 1``
(four boundary curves, eq 3.11) or values and first derivatives at ``u = 0``
and ``u = 1`` (Bloor and Wilson's form).

This module returns the *cardinal functions* ``L_k(u; λ)``: the solutions that
take the value 1 for condition ``k`` and 0 for the other three.  A mode's
profile is then ``Σ_k L_k(u; λ) c_k`` with ``c_k`` the mode's coefficient in
boundary datum ``k``.  The cardinal functions do not depend on the basis used
to compute them, so the basis is chosen for accuracy:

* ``λ > 1``: scaled exponentials ``e^{λ(u-1)}, u e^{λ(u-1)}, e^{-λu},
  u e^{-λu}``, all bounded by 1 on ``[0, 1]`` (no overflow for any ``λ``);
  the condition matrix is row-equilibrated before it is solved.  With
  interior nodes the cardinal functions themselves grow to ~``e^{λ/4}``
  between the nodes, so they are accurate to ~1e-12 *relative to that
  size*; a patch refuses modes amplified more than
  ``Tolerances.max_amplification`` (1000-fold), which keeps the absolute
  error at the nodes below ~1e-12.
* ``0 <= λ <= 1``: ``cosh λu``, ``u sinhc λu``, ``u² sinhc λu`` and
  ``u³ g(λu)`` with ``g(x) = (x cosh x - sinh x)/x³``, which tend smoothly to
  ``1, u, u², u³/3`` as ``λ -> 0`` (the exponential basis degenerates there).
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

__all__ = ["basis", "cardinal_coefficients", "cardinal", "cardinals", "lebesgue_max", "LAMBDA_MAX"]

_SMALL = 1.0  # λ at or below which the hyperbolic basis is used

#: Largest λ accepted in the four-curve form (the Hermite form has no limit).  Beyond ~2200 the interior-node rows underflow; long
#: before that (λ ≳ 30 for nodes at 1/3, 2/3) a mode is amplified more than
#: 1000-fold between the curves, which :class:`tabletcad.geometry.patch.PDEPatch` refuses.
#: For large λ the cardinal functions are accurate relative to their own size
#: (~e^{λ/4} between the nodes), i.e. to ``eps·max|L|`` absolutely.
LAMBDA_MAX = 1500.0


#: Taylor coefficients of ``g(x) = (x cosh x - sinh x) / x³ = Σ_j 2(j + 1) x^{2j} / (2j + 3)!``, enough
#: for full precision where ``|x| <= 1`` (the next term is below 4e-19)
_G_SERIES = tuple(2.0 * (j + 1) / math.factorial(2 * j + 3) for j in range(10))


def _sinhc(x: np.ndarray) -> np.ndarray:
    """sinh(x)/x, accurate near 0 (1 at 0; ``sinh`` is accurate to an ulp relative to itself there)."""
    x = np.asarray(x, dtype=float)
    out = np.ones_like(x)
    np.divide(np.sinh(x), x, out=out, where=x != 0.0)
    return out


def _g(x: np.ndarray) -> np.ndarray:
    """(x cosh x - sinh x) / x³, accurate near 0 (limit 1/3): its Taylor series where ``|x| <= 1``
    (every ``λ u`` of the hyperbolic basis), the closed form beyond."""
    x = np.asarray(x, dtype=float)
    x2 = x * x
    out = np.full_like(x, _G_SERIES[-1])
    for c in _G_SERIES[-2::-1]:  # Horner in x²
        out *= x2
        out += c
    big = np.abs(x) > 1.0
    if np.any(big):
        xl = x[big]
        out[big] = (xl * np.cosh(xl) - np.sinh(xl)) / xl**3
    return out


def _exp_columns(u: np.ndarray, lam, der: int) -> tuple:
    """Scaled exponential basis (λ > 1) or its u-derivative; ``lam`` may be a column of rates."""
    e1 = np.exp(lam * (u - 1.0))
    e3 = np.exp(-lam * u)
    if der == 0:
        return e1, u * e1, e3, u * e3
    if der == 1:
        return lam * e1, e1 + lam * u * e1, -lam * e3, e3 - lam * u * e3
    l2 = lam * lam
    return l2 * e1, 2 * lam * e1 + l2 * u * e1, l2 * e3, -2 * lam * e3 + l2 * u * e3


def _hyp_columns(u: np.ndarray, lam, der: int) -> tuple:
    """Hyperbolic basis (0 <= λ <= 1) tending to the cubic; ``lam`` may be a column of rates."""
    x = lam * u
    ch = np.cosh(x)
    sc = _sinhc(x)
    l2 = lam * lam
    if der == 0:
        return ch, u * sc, u * u * sc, u**3 * _g(x)
    if der == 1:
        return l2 * u * sc, ch, u * sc + u * ch, u * u * sc
    return l2 * ch, l2 * u * sc, 2 * ch + l2 * u * u * sc, u * sc + u * ch


def basis(u: np.ndarray, lam: float, der: int = 0) -> np.ndarray:
    """Evaluate the four basis functions (or a derivative in ``u``) for one ``λ``.

    Parameters
    ----------
    u : array_like, shape (m,)
        Parameter values in [0, 1].
    lam : float
        Decay rate ``λ = a·n >= 0``.
    der : {0, 1, 2}
        Derivative order in ``u``.

    Returns
    -------
    ndarray, shape (m, 4)
    """
    u = np.asarray(u, dtype=float).reshape(-1)
    lam = float(lam)
    if der not in (0, 1, 2):
        raise ValueError(f"der = {der} is not allowed: must be 0, 1 or 2")
    cols = _exp_columns(u, lam, der) if lam > _SMALL else _hyp_columns(u, lam, der)
    return np.stack(cols, axis=-1)


@lru_cache(maxsize=4096)
def cardinal_coefficients(lam: float, nodes: tuple[float, float, float, float], form: str) -> np.ndarray:
    """Coefficients ``C`` (4×4) such that ``basis(u, λ) @ C`` are the cardinal functions.

    Parameters
    ----------
    lam : float
        Decay rate ``λ >= 0``.
    nodes : tuple of 4 floats
        ``form == "curves"``: the parameters ``(0, u1, u2, 1)`` of the four curves.
        ``form == "hermite"``: ignored except ``nodes[0]`` and ``nodes[3]``
        (the ends); conditions are ``X(0), X(1), X_u(0), X_u(1)`` in that order.
    form : {"curves", "hermite"}
    """
    if lam < 0.0 or (form == "curves" and lam > LAMBDA_MAX):
        raise ValueError(f"λ = {lam:g} is not allowed: must be between 0 and {LAMBDA_MAX:g}")
    if form == "curves":
        m = basis(np.asarray(nodes, dtype=float), lam, 0)
    elif form == "hermite":
        ends = np.array([nodes[0], nodes[3]], dtype=float)
        m = np.vstack([basis(ends, lam, 0), basis(ends, lam, 1)])
    else:
        raise ValueError(f"form = {form!r} is not allowed: must be 'curves' or 'hermite'")
    scale = 1.0 / np.max(np.abs(m), axis=1)
    c = np.linalg.solve(m * scale[:, None], np.diag(scale))
    c.setflags(write=False)
    return c


def cardinal(u: np.ndarray, lam: float, nodes, form: str = "curves", der: int = 0) -> np.ndarray:
    """Cardinal functions ``L_k(u; λ)`` (or their ``u``-derivative), shape (m, 4)."""
    c = cardinal_coefficients(float(lam), tuple(float(x) for x in nodes), form)
    return basis(u, lam, der) @ c


def cardinals(u: np.ndarray, lams, nodes, form: str = "curves", der: int = 0) -> np.ndarray:
    """Cardinal functions of several decay rates at once, shape ``(len(lams), m, 4)``.

    The same functions as :func:`cardinal` for each ``λ`` of ``lams``; the
    exponential basis (``λ > 1``) is evaluated for all rates in one array
    expression, so a patch's modes cost a few vector operations instead of a
    Python loop per mode.
    """
    u = np.asarray(u, dtype=float).reshape(-1)
    lams = np.asarray(lams, dtype=float).reshape(-1)
    nodes = tuple(float(x) for x in nodes)
    if der not in (0, 1, 2):
        raise ValueError(f"der = {der} is not allowed: must be 0, 1 or 2")
    out = np.empty((lams.size, u.size, 4))
    for sel, cols in ((lams > _SMALL, _exp_columns), (lams <= _SMALL, _hyp_columns)):
        if np.any(sel):
            b = np.stack(cols(u, lams[sel][:, None], der), axis=-1)  # (k, m, 4)
            out[sel] = np.matmul(b, _stacked_coefficients(lams[sel].tobytes(), nodes, form))
    return out


@lru_cache(maxsize=512)
def _stacked_coefficients(lams: bytes, nodes: tuple[float, ...], form: str) -> np.ndarray:
    """:func:`cardinal_coefficients` of every rate in ``lams`` (a float64 array's bytes), stacked
    ``(k, 4, 4)`` and read-only: a patch's modes ask for the same rates at every evaluation."""
    C = np.stack([cardinal_coefficients(float(lam), nodes, form) for lam in np.frombuffer(lams)])
    C.setflags(write=False)
    return C


def lebesgue_max(lam: float, nodes, form: str = "curves", samples: int = 401) -> float:
    """Largest value over ``u ∈ [0, 1]`` of ``Σ_k |L_k(u; λ)|`` (value conditions only).

    It bounds how much a mode of unit amplitude at the curves can grow between
    them; for ``form == "hermite"`` only the two positional cardinals count.
    """
    u = np.linspace(0.0, 1.0, samples)
    lk = cardinal(u, lam, nodes, form)
    if form == "hermite":
        lk = lk[:, :2]
    return float(np.max(np.sum(np.abs(lk), axis=1)))
