"""Feasibility polish: land a solver's end point on its active constraints exactly.

A local solver stops when its own tests are met; how close its last point is to
the constraints then depends on line-search details, finite-difference noise
and even the BLAS kernel (SLSQP on one CPU ends 1.3e-6 relative outside the
force bound of the thesis's spherical tablet, on another inside it).  The
polish makes the reported point feasible by construction instead:

1. the *active set* ``A`` is every equality row and every inequality row whose
   scaled residual is below its feasibility tolerance (violated or on the
   bound); variables at a bound of ``[0, 1]`` stay there;
2. Gauss-Newton projection: ``r_A(z + dz) = 0`` is solved for the
   minimum-norm step ``dz`` over the free variables
   (``J_A dz = -r_A`` by least squares, ``J`` by central differences), and
   repeated until every active row is within ``TARGET`` of its tolerance;
3. every constraint is re-evaluated at the new point; an inactive row that the
   step violated joins ``A``, a variable the step pushed past its bound is
   fixed at that bound, and step 2 runs again.

The polished point replaces the solver's point only when it satisfies every
constraint; otherwise the solver's point is reported as it is (and its
violation named).  The step is of the size of the violation, so the objective
moves by the same order (first-order optimality is kept to within it).

:func:`kkt_residual` measures first-order optimality at the polished point
(Lagrange multipliers of the active rows and bounds by non-negative least
squares): a solver that stopped on a line-search failure at a point that then
meets the KKT conditions to ``KKT_TOL`` is reported as converged.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import nnls

from tabletcad.optimise.problem import Evaluator

__all__ = ["polish", "kkt_residual", "TARGET", "MAX_STEPS", "KKT_TOL"]

#: An active row is landed within ``TARGET`` × its feasibility tolerance.
TARGET = 1e-3
#: Largest number of Gauss-Newton steps (each costs 2n + 1 builds).
MAX_STEPS = 12
#: Largest relative first-order optimality residual ``|∇f - Jᵀλ| / |∇f|`` accepted as converged.
KKT_TOL = 1e-4


def _row_tols(ev: Evaluator) -> np.ndarray:
    """Feasibility tolerance of every residual row in the solver's scaled units."""
    out = []
    for ci, ri in ev.rows:
        c = ev.p.constraints[ci]
        if c.kind == "eq":
            ref = c.target
        else:
            bounds = [b for b in (c.lower, c.upper) if b is not None]
            ref = bounds[ri] if ri < len(bounds) else 1.0
        out.append(c.abs_tol(ref) / c.residual_scale)
    return np.array(out, dtype=float)


def _is_eq(ev: Evaluator) -> np.ndarray:
    return np.array([ev.p.constraints[ci].kind == "eq" for ci, _ in ev.rows], dtype=bool)


def _jac(ev: Evaluator, z: np.ndarray) -> np.ndarray:
    scheme = ev.fd_scheme
    ev.fd_scheme = "central"
    try:
        return ev.jac(z)
    finally:
        ev.fd_scheme = scheme


def _feasible(ev: Evaluator, z) -> bool:
    r, vals = ev.assess(z)
    return bool(r["ok"]) and all(v.satisfied for v in vals)


def polish(ev: Evaluator, z) -> tuple[np.ndarray, str]:
    """Project ``z`` (scaled variables) onto its active constraints; return ``(z, note)``.

    ``note`` says what was done (for the run's message).  The returned point
    is the polished one only if it satisfies every constraint, else ``z``.
    """
    z0 = np.clip(np.asarray(z, dtype=float), 0.0, 1.0)
    if ev.n == 0 or not ev.rows or not ev.evaluate(z0)["ok"]:
        return z0, ""
    eq = _is_eq(ev)
    tol = _row_tols(ev)
    res = ev.residuals(z0)
    if not np.all(np.isfinite(res)):
        return z0, ""
    active = eq | (res < tol)
    if not active.any():
        return z0, ""
    fixed = (z0 <= 0.0) | (z0 >= 1.0)
    z = z0.copy()
    steps = 0
    best, stalled = math.inf, 0
    while steps < MAX_STEPS:
        res = ev.residuals(z)
        if not np.all(np.isfinite(res)):
            break
        active |= (~eq) & (res < 0.0)
        done = np.all(np.abs(res[active]) <= TARGET * tol[active])
        if done and np.all(res[~eq] > -tol[~eq]) and _feasible(ev, z):
            break
        # Gauss-Newton converges quadratically near a regular point: two steps without halving the
        # worst active residual mean the active set cannot be met from here (e.g. an infeasible problem)
        worst = float(np.max(np.abs(res[active]) / np.maximum(tol[active], 1e-300)))
        stalled = stalled + 1 if worst > 0.5 * best else 0
        best = min(best, worst)
        if stalled >= 2:
            break
        free = ~fixed
        if not free.any():
            break
        J = _jac(ev, z)[np.ix_(active, free)]
        dz = np.zeros_like(z)
        dz[free] = np.linalg.lstsq(J, -res[active], rcond=None)[0]
        zn = z + dz
        out = (zn < 0.0) | (zn > 1.0)
        fixed |= out
        z = np.clip(zn, 0.0, 1.0)
        steps += 1
    if _feasible(ev, z):
        rows = f"{int(active.sum())} active row{'s' if active.sum() != 1 else ''}"
        if steps == 0:
            return z, f"feasibility polish: the end point already lies on its {rows}"
        moved = float(np.max(np.abs(z - z0)))
        return z, (f"feasibility polish: {rows} landed in {steps} step{'s' if steps != 1 else ''} "
                   f"(largest move {moved:.2g} of a variable's range)")
    return z0, "feasibility polish did not reach a feasible point"


def kkt_residual(ev: Evaluator, z) -> float:
    """Relative first-order optimality residual at ``z`` (0 = KKT point).

    ``min |∇f - Σ λ_i ∇r_i - Σ μ_j ± e_j| / |∇f|`` over multipliers ``λ_i >= 0``
    of the inequality rows within tolerance of their bound (free sign for
    equalities) and ``μ_j >= 0`` of the variables at a bound, by non-negative
    least squares (an equality's multiplier is split into two signs).
    """
    z = np.clip(np.asarray(z, dtype=float), 0.0, 1.0)
    g = ev.grad(z)
    gn = float(np.linalg.norm(g))
    if gn == 0.0:
        return 0.0
    cols = []
    if ev.rows:
        res = ev.residuals(z)
        tol = _row_tols(ev)
        eq = _is_eq(ev)
        J = _jac(ev, z)
        for k in range(len(ev.rows)):
            if eq[k]:
                cols += [J[k], -J[k]]
            elif res[k] <= tol[k]:
                cols.append(J[k])
    for j in range(ev.n):  # bounds 0 <= z_j (gradient e_j) and z_j <= 1 (gradient -e_j) as residuals >= 0
        e = np.zeros(ev.n)
        if z[j] <= 0.0:
            e[j] = 1.0
            cols.append(e)
        elif z[j] >= 1.0:
            e[j] = -1.0
            cols.append(e)
    if not cols:
        return float(np.linalg.norm(g) / gn)
    A = np.array(cols).T
    if not np.all(np.isfinite(A)):
        return math.inf
    # minimise f subject to r >= 0: ∇f = Σ λ ∇r, λ >= 0
    _, rnorm = nnls(A, g)
    return float(rnorm / gn)
