"""Solvers for :class:`~tabletcad.optimise.problem.Problem`, built on :mod:`scipy.optimize`.

=========================  ==============================================================
``method``                 what runs
=========================  ==============================================================
``"SLSQP"``                sequential least squares QP (an active-set SQP method, the
                           counterpart of the MATLAB active-set method the thesis used)
``"trust-constr"``         trust-region interior-point / equality-constrained SQP
``"multistart"``           SLSQP from the initial point and from a scrambled Sobol set
                           of starts (``starts``, seeded); the best feasible point wins
``"differential_evolution"``  scipy's differential evolution with the constraints as
                           :class:`~scipy.optimize.NonlinearConstraint`, then SLSQP
                           polishing from its best member
=========================  ==============================================================

All methods see the variables scaled to ``[0, 1]`` and the objective divided
by its magnitude at the start, so the tolerances (``ftol``/``gtol``, default
1e-9) are relative.  Gradients: see :class:`~tabletcad.optimise.problem.Evaluator`.

A run is reported as ``success`` only if the solver converged and the final
point satisfies every constraint within its tolerance; otherwise ``status`` is
``"infeasible"`` (a constraint is violated: ``message`` names it with the
absolute and relative violation), ``"not_converged"`` (the solver stopped
without meeting its convergence test; the point may be feasible) or
``"build_failed"`` (the design could not be built at the starting point).
"""

from __future__ import annotations

import math
import warnings
from typing import Any, Callable

import numpy as np
from scipy.optimize import Bounds, NonlinearConstraint, minimize

from tabletcad.errors import DesignError
from tabletcad.optimise.polish import KKT_TOL, kkt_residual, polish
from tabletcad.optimise.problem import FD_STEP, METHODS, Evaluator, Iteration, Problem, Result, now

__all__ = ["solve", "METHODS"]


class _Scaled:
    """Objective/constraint callables for scipy on one evaluator, with history."""

    def __init__(self, ev: Evaluator, fscale: float) -> None:
        self.ev = ev
        self.fscale = fscale
        self.eq = ev.residuals_kind("eq")
        self.ineq = ev.residuals_kind("ineq")
        self.history: list[Iteration] = []

    def f(self, z):
        v = self.ev.fun(z)
        return v / self.fscale if math.isfinite(v) else 1e30

    def g(self, z):
        return self.ev.grad(z) / self.fscale

    def c_eq(self, z):
        return self.ev.residuals(z)[self.eq]

    def c_ineq(self, z):
        return self.ev.residuals(z)[self.ineq]

    def j_eq(self, z):
        return self.ev.jac(z)[self.eq]

    def j_ineq(self, z):
        return self.ev.jac(z)[self.ineq]

    def record(self, z) -> None:
        r = self.ev.evaluate(z)
        self.history.append(Iteration(len(self.history), float(r["f"]), float(self.ev.max_violation(z)), self.ev.nfev))

    def slsqp_constraints(self) -> list[dict]:
        out = []
        if self.eq:
            out.append(dict(type="eq", fun=self.c_eq, jac=self.j_eq))
        if self.ineq:
            out.append(dict(type="ineq", fun=self.c_ineq, jac=self.j_ineq))
        return out

    def nonlinear_constraints(self) -> list:
        out = []
        if self.eq:
            out.append(NonlinearConstraint(self.c_eq, 0.0, 0.0, jac=self.j_eq))
        if self.ineq:
            out.append(NonlinearConstraint(self.c_ineq, 0.0, np.inf, jac=self.j_ineq))
        return out


#: the solvers' default iteration limit; a run given fewer that stops there is "not_converged", not "infeasible"
DEFAULT_MAXITER = 200


def _slsqp(sc: _Scaled, z0, maxiter: int, ftol: float, restarts: int = 2):
    """SLSQP, warm-restarted from its own end point (at most ``restarts`` times) when it stops
    without success, with a constraint still violated (e.g. "positive directional derivative
    for linesearch" after a finite-difference gradient misled the line search) or at a point that
    is no KKT point to ``KKT_TOL`` (scipy >= 1.15's SLSQP reported success on ``cylinder_min_area``
    where the gradients of area and volume were 6 % from parallel, 0.18 % above the optimum's area)."""
    n = sc.ev.n
    sc.record(z0)
    nit = 0
    z = np.asarray(z0, float)
    scheme = sc.ev.fd_scheme
    for attempt in range(restarts + 1):
        res = minimize(
            sc.f, z, jac=sc.g, method="SLSQP", bounds=[(0.0, 1.0)] * n, constraints=sc.slsqp_constraints(),
            options=dict(maxiter=max(1, maxiter - nit), ftol=ftol), callback=sc.record,
        )
        nit += int(getattr(res, "nit", 0))
        feas, _ = _feasible_value(sc.ev, res.x)
        if (res.success and feas and kkt_residual(sc.ev, res.x) <= KKT_TOL) or nit >= maxiter or np.array_equal(res.x, z):
            break
        z = np.clip(res.x, 0.0, 1.0)
        sc.ev.fd_scheme = "central"  # restarts use central differences (error ~ step² instead of ~ step)
    sc.ev.fd_scheme = scheme
    msg = str(res.message) + (f" (after {attempt} warm restart{'s' if attempt > 1 else ''})" if attempt else "")
    return res, bool(res.success), nit, msg


def _trust_constr(sc: _Scaled, z0, maxiter: int, ftol: float):
    from scipy.optimize import BFGS

    n = sc.ev.n
    sc.record(z0)

    def cb(zk, *args):
        sc.record(zk)
        return False

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "delta_grad == 0.0" chatter from BFGS updates
        res = minimize(
            sc.f, z0, jac=sc.g, hess=BFGS(), method="trust-constr", bounds=Bounds(np.zeros(n), np.ones(n)),
            constraints=sc.nonlinear_constraints(),
            options=dict(maxiter=maxiter, gtol=ftol, xtol=1e-12, barrier_tol=1e-10), callback=cb,
        )
    ok = bool(res.status in (1, 2))
    return res, ok, int(getattr(res, "nit", len(sc.history) - 1)), str(res.message)


#: a solver's end point closer than this to a bound (a fraction of the variable's range) is put on it
BOUND_SNAP = 1e-9


def _land(ev: Evaluator, z, ok: bool, msg: str) -> tuple[np.ndarray, bool, str]:
    """Feasibility polish of a solver's end point (:mod:`tabletcad.optimise.polish`), put first on a
    bound it lies within ``BOUND_SNAP`` of.

    A solver that stopped without success (e.g. a line-search failure) counts as
    converged when the polished point is feasible and a KKT point to ``KKT_TOL``.
    """
    z = np.clip(np.asarray(z, float), 0.0, 1.0)
    # a solver stops within its tolerance of an active bound (band = 9e-12 mm for a bound of 0, a
    # length no design file takes): the bound itself, the user's value, when it stays feasible
    zs = _least_values(ev, np.where(z < BOUND_SNAP, 0.0, np.where(z > 1.0 - BOUND_SNAP, 1.0, z)))
    zp, note = polish(ev, zs)
    if not np.array_equal(zs, z) and not _feasible_value(ev, zp)[0]:
        zp, note = polish(ev, z)
    if note:
        msg = f"{msg}; {note}"
    if not ok and _feasible_value(ev, zp)[0]:
        kkt = kkt_residual(ev, zp)
        if kkt <= KKT_TOL:
            ok = True
            msg = f"{msg}; first-order optimality (KKT) residual {kkt:.2g} <= {KKT_TOL:g} at the polished point"
    return zp, ok, msg


def _least_values(ev: Evaluator, z: np.ndarray) -> np.ndarray:
    """``z`` with each variable that lies between 0 and its :attr:`Variable.least` (a length no design
    file takes: an interior-point solver stopped at band = 3.3e-4 mm for a bound of 0) moved to 0 or
    ``least``, whichever is within its bounds, feasible and better; left alone if neither is."""
    x = ev.to_x(z)
    for i in ev.free:
        v = ev.vars[i]
        if v.least is None or not 0.0 < x[i] < v.least:
            continue
        best = None
        for c in (0.0, v.least):
            if v.lower <= c <= v.upper:
                xc = x.copy()
                xc[i] = c
                feas, val = _feasible_value(ev, ev.to_z(xc))
                if feas and (best is None or val < best[0]):
                    best = (val, xc)
        if best is not None:
            x = best[1]
    return ev.to_z(x)


def _feasible_value(ev: Evaluator, z) -> tuple[bool, float]:
    r, vals = ev.assess(z)
    feas = r["ok"] and all(v.satisfied for v in vals)
    return feas, float(ev.sign * r["f"]) if r["ok"] else math.inf


def solve(
    problem: Problem,
    method: str = "SLSQP",
    *,
    x0: dict | None = None,
    maxiter: int = DEFAULT_MAXITER,
    ftol: float = 1e-9,
    fd_step: float = FD_STEP,
    fd_scheme: str = "forward",
    starts: int = 8,
    seed: int = 0,
    popsize: int = 12,
    progress: bool | Callable[[int], None] = False,
) -> Result:
    """Solve ``problem`` and return a :class:`~tabletcad.optimise.problem.Result`.

    Parameters
    ----------
    method : {"SLSQP", "trust-constr", "multistart", "differential_evolution"}
    x0 : dict, optional
        Starting values overriding the variables' ``initial``.
    maxiter : int
        Iteration limit per local solve (generations for differential evolution).
    ftol : float
        Relative convergence tolerance on the objective (SLSQP ``ftol``,
        trust-constr ``gtol``).
    fd_step : float
        Finite-difference step in the scaled variables (fraction of each range).
    fd_scheme : {"forward", "central"}
        Forward differences (n builds per gradient, error ~ step) or central
        differences (2n builds, error ~ step², used for tight tolerances).
    starts : int
        Number of Sobol starts for ``"multistart"`` (besides the initial point).
    seed : int
        Seed of the Sobol scrambling / differential evolution.
    progress : bool or callable
        True shows a tqdm counter of design builds; a callable receives the count.
    """
    if method not in METHODS:
        raise DesignError("method", method, "must be one of " + ", ".join(METHODS))
    if not (isinstance(maxiter, int) and maxiter >= 1):
        raise DesignError("maxiter", maxiter, "must be an integer >= 1")
    if not (isinstance(starts, int) and starts >= 0):
        raise DesignError("starts", starts, "must be an integer >= 0")
    bar = None
    cb_progress = None
    if progress is True:
        try:
            from tqdm import tqdm

            bar = tqdm(desc=f"optimise {problem.name}", unit=" builds", leave=False)
            cb_progress = lambda n: bar.update(1)  # noqa: E731
        except ImportError:  # pragma: no cover
            cb_progress = None
    elif callable(progress):
        cb_progress = progress
    t0 = now()
    ev = Evaluator(problem, fd_step=fd_step, fd_scheme=fd_scheme, progress=cb_progress)
    if x0:
        unknown = set(x0) - set(problem.names)
        if unknown:
            raise DesignError("x0", sorted(unknown)[0], "is not a variable of the problem")
        xs = np.array([float(x0.get(v.name, v.initial)) for v in problem.variables])
        for v, val in zip(problem.variables, xs):
            if not v.lower <= val <= v.upper:
                raise DesignError(f"x0 {v.name}", val, f"must lie within [{v.lower:g}, {v.upper:g}]", v.unit)
        z0 = ev.to_z(xs)
    else:
        z0 = ev.z0()
    try:
        start = ev.evaluate(z0)
        if not start["ok"]:
            return _finish(problem, ev, z0, method, False, 0, t0, [], f"design cannot be evaluated at the start: {start['error']}",
                           status="build_failed", starts=1, bar=bar)
        fscale = max(abs(start["f"]), 1e-12)
        if ev.n == 0:
            return _finish(problem, ev, z0, method, True, 0, t0, [], "no free variable", starts=1, bar=bar)

        if method in ("SLSQP", "trust-constr"):
            sc = _Scaled(ev, fscale)
            runner = _slsqp if method == "SLSQP" else _trust_constr
            res, ok, nit, msg = runner(sc, z0, maxiter, ftol)
            z, ok, msg = _land(ev, res.x, ok, msg)
            return _finish(problem, ev, z, method, ok, nit, t0, sc.history, msg, starts=1, bar=bar,
                           capped=maxiter < DEFAULT_MAXITER)

        if method == "multistart":
            from scipy.stats import qmc

            pts = [z0]
            if starts:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")  # balance warning for non powers of 2
                    pts += list(qmc.Sobol(ev.n, scramble=True, seed=seed).random(starts))
            best = None
            total_it = 0
            for k, zs in enumerate(pts):
                sc = _Scaled(ev, fscale)
                res, ok, nit, msg = _slsqp(sc, np.asarray(zs, float), maxiter, ftol)
                total_it += nit
                z, ok, msg = _land(ev, res.x, ok, msg)
                feas, val = _feasible_value(ev, z)
                cand = (not feas, val, k)
                if best is None or cand < best[0]:
                    best = (cand, z, ok, msg, sc.history)
            (_, _, kbest), z, ok, msg, hist = best
            return _finish(problem, ev, z, method, ok, total_it, t0, hist,
                           f"best of {len(pts)} starts (start {kbest}): {msg}", starts=len(pts), bar=bar,
                           capped=maxiter < DEFAULT_MAXITER)

        # differential evolution + SLSQP polish
        from scipy.optimize import differential_evolution

        sc = _Scaled(ev, fscale)
        gen = [0]

        def cb(xk, convergence=None):
            gen[0] += 1
            sc.record(xk)
            return False

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            de = differential_evolution(
                sc.f, [(0.0, 1.0)] * ev.n, constraints=sc.nonlinear_constraints(), maxiter=maxiter, popsize=popsize,
                tol=1e-8, seed=seed, polish=False, init="sobol", x0=z0, callback=cb,
            )
        res, ok, nit, msg = _slsqp(sc, de.x, maxiter, ftol)
        z, ok, msg = _land(ev, res.x, ok, msg)
        return _finish(problem, ev, z, method, ok, gen[0] + nit, t0, sc.history,
                       f"differential evolution: {de.message}; SLSQP polish: {msg}", starts=1, bar=bar,
                       capped=maxiter < DEFAULT_MAXITER)
    finally:
        if bar is not None:
            bar.close()


_LIMIT_WORDS = ("iteration limit", "maximum number of iterations", "maximum number of function evaluations",
                "maxiter", "max_nfev", "maximum number of generations")


def _stopped_by_limit(message: str) -> bool:
    """Whether a solver's message says it stopped at an iteration or evaluation limit (scipy's wordings)."""
    m = message.lower()
    return any(w in m for w in _LIMIT_WORDS)


def _finish(problem: Problem, ev: Evaluator, z, method: str, solver_ok: bool, nit: int, t0: float,
            history: list, solver_msg: str, *, status: str | None = None, starts: int = 1, bar=None,
            capped: bool = False) -> Result:
    r, vals = ev.assess(np.clip(np.asarray(z, float), 0.0, 1.0))
    bad = [v for v in vals if not v.satisfied]
    # a run given fewer iterations than the default that stops at its limit: cut short by its caller
    stopped = capped and not solver_ok and _stopped_by_limit(solver_msg)
    if status is None:
        if not r["ok"]:
            status = "build_failed"
        elif bad and stopped:  # cut short (--maxiter): its last point says nothing of the problem's feasibility
            status = "not_converged"
        elif bad:
            status = "infeasible"
        elif not solver_ok:
            status = "not_converged"
        else:
            status = "converged"
    success = status == "converged"
    if status == "infeasible":
        parts = []
        for v in sorted(bad, key=lambda c: -c.relative_violation):
            if v.kind == "eq":
                want = f"= {v.target:.10g}"
            elif v.lower is not None and v.value < v.lower:
                want = f">= {v.lower:.10g}"
            else:
                want = f"<= {v.upper:.10g}"
            u = f" {v.unit}" if v.unit else ""
            parts.append(f"constraint '{v.name}' violated: value {v.value:.10g}{u}, required {want}{u}, "
                         f"by {v.violation:.4g}{u} ({v.relative_violation:.3g} relative)")
        message = "no feasible design found; " + "; ".join(parts) + f" [solver: {solver_msg}]"
    elif status == "build_failed":
        message = solver_msg if solver_msg.startswith("design cannot") else f"design cannot be built: {r['error'] or ev.last_error}"
    elif status == "not_converged" and bad:
        worst = max(bad, key=lambda c: c.relative_violation)
        message = (f"solver stopped at its iteration limit before converging: {solver_msg} (the last point violates "
                   f"constraint '{worst.name}' by {worst.relative_violation:.3g} relative; not a proof that no "
                   "feasible design exists: give a larger --maxiter)")
    elif status == "not_converged":
        message = f"solver did not converge: {solver_msg} (the last point satisfies the constraints but is not certified optimal)"
    else:
        message = f"converged: {solver_msg}"
    history = list(history)
    if r["ok"] and history and (history[-1].objective != float(r["f"])):
        # the solver's returned point is not its last callback point: end the history with it
        history.append(Iteration(len(history), float(r["f"]), float(ev.max_violation(z)), ev.nfev))
    extras: dict[str, Any] = {}
    if r["ok"] and problem.extras is not None:
        try:
            extras = dict(problem.extras(r["x"], r["design"]))
        except Exception as exc:  # extras are informative only
            extras = {"error": str(exc)}
    obj = problem.objective
    return Result(
        problem=problem.name, method=method, x=dict(r["x"]), objective=float(r["f"]), constraints=vals,
        success=success, status=status, message=message, iterations=int(nit), nfev=ev.nfev, ngrad=ev.ngrad,
        wall_time_s=now() - t0, history=list(history), design=r["design"], sense=problem.sense,
        objective_name=obj.name, objective_unit=obj.unit, solver_message=solver_msg, extras=extras, starts=starts,
    )
