"""Optimisation problems over any design parameters.

A :class:`Problem` names its design variables (:class:`Variable`, each with
bounds and a starting value), a ``build(x) -> design`` function that turns a
dict of variable values into a design object (a :class:`~tabletcad.geometry.tablet.Tablet`
or any small model object), an objective computed from that design and
constraints (:class:`Constraint`) computed from the design or from ``x``.

:class:`Evaluator` is the bridge to :mod:`scipy.optimize`: it works on the
variables scaled to ``[0, 1]``, builds each point once (an LRU cache keyed by
the exact bits of the scaled vector, so the objective and all constraints at
one point share one build), counts builds, and supplies gradients: analytic
where a function carries ``grad``, otherwise forward differences with a
*controlled step* in the scaled variable (default ``1e-6`` of each variable's
range, i.e. a relative step of 1e-6 with respect to the design space; the
step is reversed at an upper bound so that no point outside the bounds is
ever built).  One difference point is one build shared by every function.

Feasibility is judged on the unscaled values: a constraint is met when its
violation is at most ``tol`` (absolute, default 1e-6) or, for constraints
declared ``relative=True`` such as volumes, at most ``tol * |target|``.
"""

from __future__ import annotations

import math
import time
from collections import OrderedDict
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from tabletcad.errors import MISSING, DesignError, TabletcadError, check_finite

__all__ = [
    "Variable",
    "Constraint",
    "Objective",
    "Problem",
    "ConstraintValue",
    "Iteration",
    "Result",
    "Evaluator",
    "FEASIBILITY_TOL",
    "FD_STEP",
    "METHODS",
]

#: Solver methods of :func:`tabletcad.optimise.solve` (defined here so that problem files can be
#: checked without importing :mod:`scipy.optimize`).
METHODS = ("SLSQP", "trust-constr", "multistart", "differential_evolution")

#: Default absolute feasibility tolerance (relative for ``relative=True`` constraints).
FEASIBILITY_TOL = 1e-6
#: Default forward-difference step in the scaled variable (fraction of the variable's range).
FD_STEP = 1e-6


@dataclass(frozen=True)
class Variable:
    """A design variable with bounds ``lower <= x <= upper`` and a starting value.

    ``unit`` is only used in reports.  ``lower == upper`` fixes the variable.  ``least``: the
    smallest non-zero value a design takes (a family's lengths: ``Tolerances.min_length``); a
    solver's end point between 0 and it is moved to whichever of the two is feasible and better.
    """

    name: str
    lower: float
    upper: float
    initial: float | None = None
    unit: str = ""
    least: float | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise DesignError("variable name", self.name, "must be a non-empty string")
        lo = check_finite(f"variables.{self.name}.lower", self.lower, self.unit)
        hi = check_finite(f"variables.{self.name}.upper", self.upper, self.unit)
        if lo > hi:
            raise DesignError(f"variables.{self.name}.bounds", (lo, hi), "must have lower <= upper", self.unit)
        x0 = 0.5 * (lo + hi) if self.initial is None else check_finite(f"variables.{self.name}.initial", self.initial, self.unit)
        if not lo <= x0 <= hi:
            raise DesignError(f"variables.{self.name}.initial", x0, f"must lie within [{lo:g}, {hi:g}]", self.unit)
        object.__setattr__(self, "lower", lo)
        object.__setattr__(self, "upper", hi)
        object.__setattr__(self, "initial", x0)

    @property
    def span(self) -> float:
        return self.upper - self.lower


@dataclass(frozen=True)
class Objective:
    """An objective ``func(design) -> float`` with an optional analytic gradient.

    ``grad(x: dict, design) -> dict`` returns the partial derivatives with
    respect to the (unscaled) variables by name; missing names count as 0.
    """

    func: Callable[[Any], float]
    name: str = "objective"
    unit: str = ""
    grad: Callable[[dict, Any], dict] | None = None


@dataclass(frozen=True)
class Constraint:
    """A constraint on a quantity computed from the design (or from ``x``).

    Parameters
    ----------
    name : str
        Shown in reports and failure messages (e.g. ``"volume (eq 6.3)"``).
    func : callable
        ``func(design) -> float``, or ``func(x: dict) -> float`` when ``uses="x"``.
    kind : {"eq", "ineq"}
        ``"eq"`` needs ``target``; ``"ineq"`` needs ``lower`` and/or ``upper``.
    scale : float, optional
        Divides the residual seen by the solver (default ``max(|target|, 1)`` or
        the width of ``[lower, upper]``); it does not change feasibility.
    tol : float
        Feasibility tolerance: absolute, or relative to ``|target|`` (``|bound|``)
        when ``relative`` is true.
    grad : callable, optional
        ``grad(x: dict, design) -> dict`` of partial derivatives by variable name.
    """

    name: str
    func: Callable[[Any], float]
    kind: str = "ineq"
    target: float | None = None
    lower: float | None = None
    upper: float | None = None
    scale: float | None = None
    tol: float = FEASIBILITY_TOL
    relative: bool = False
    unit: str = ""
    uses: str = "design"
    grad: Callable[[dict, Any], dict] | None = None

    def __post_init__(self) -> None:
        if self.kind not in ("eq", "ineq"):
            raise DesignError(f"constraint {self.name} kind", self.kind, "must be 'eq' or 'ineq'")
        if self.uses not in ("design", "x"):
            raise DesignError(f"constraint {self.name} uses", self.uses, "must be 'design' or 'x'")
        if self.kind == "eq":
            if self.target is None:
                raise DesignError(f"constraint {self.name} target", MISSING, "an equality constraint needs a target")
            check_finite(f"constraint {self.name} target", self.target, self.unit)
            if self.lower is not None or self.upper is not None:
                raise DesignError(f"constraint {self.name}", "lower/upper", "an equality constraint takes only a target")
        else:
            if self.lower is None and self.upper is None:
                raise DesignError(f"constraint {self.name}", "no bound", "an inequality constraint needs lower and/or upper")
            if self.target is not None:
                raise DesignError(f"constraint {self.name} target", self.target, "an inequality constraint takes lower/upper")
            lo = None if self.lower is None else check_finite(f"constraint {self.name} lower", self.lower, self.unit)
            hi = None if self.upper is None else check_finite(f"constraint {self.name} upper", self.upper, self.unit)
            if lo is not None and hi is not None and lo > hi:
                raise DesignError(f"constraint {self.name} bounds", (lo, hi), "must have lower <= upper", self.unit)
        if not (self.tol > 0 and math.isfinite(self.tol)):
            raise DesignError(f"constraint {self.name} tol", self.tol, "must be a finite number > 0")
        if self.scale is not None and not (self.scale > 0 and math.isfinite(self.scale)):
            raise DesignError(f"constraint {self.name} scale", self.scale, "must be a finite number > 0")

    # -------------------------------------------------------------- helpers
    @property
    def residual_scale(self) -> float:
        if self.scale is not None:
            return float(self.scale)
        if self.kind == "eq":
            return max(abs(self.target), 1.0)
        if self.lower is not None and self.upper is not None and self.upper > self.lower:
            return max(self.upper - self.lower, 1e-12 * max(abs(self.lower), abs(self.upper), 1.0))
        b = self.lower if self.lower is not None else self.upper
        return max(abs(b), 1.0)

    def abs_tol(self, bound: float) -> float:
        return self.tol * abs(bound) if self.relative else self.tol

    def violation(self, value: float) -> tuple[float, float, float]:
        """``(violation >= 0, relative violation, slack)``; slack < 0 means violated.

        Slack is the distance to the nearest bound (``-|g - target|`` for an equality).
        """
        if not math.isfinite(value):
            return math.inf, math.inf, -math.inf
        if self.kind == "eq":
            d = abs(value - self.target)
            return d, d / (abs(self.target) if self.target != 0 else self.residual_scale), -d
        viol = 0.0
        slack = math.inf
        ref = 1.0
        if self.lower is not None:
            slack = min(slack, value - self.lower)
            if value < self.lower:
                viol, ref = self.lower - value, self.lower
        if self.upper is not None:
            slack = min(slack, self.upper - value)
            if value > self.upper:
                viol, ref = value - self.upper, self.upper
        return viol, viol / (abs(ref) if ref != 0 else self.residual_scale), slack

    def satisfied(self, value: float) -> bool:
        viol, _, _ = self.violation(value)
        if self.kind == "eq":
            return viol <= self.abs_tol(self.target)
        bound = self.lower if (self.lower is not None and value < self.lower) else self.upper
        return viol <= self.abs_tol(bound if bound is not None else 1.0)

    def scaled_residuals(self, value: float) -> list[float]:
        """Residuals ``r`` for the solver: ``r = 0`` (eq) or ``r >= 0`` (ineq), divided by the scale."""
        s = self.residual_scale
        if self.kind == "eq":
            return [(value - self.target) / s]
        out = []
        if self.lower is not None:
            out.append((value - self.lower) / s)
        if self.upper is not None:
            out.append((self.upper - value) / s)
        return out

    def residual_signs(self) -> list[float]:
        """d(residual)/d(value) for each entry of :meth:`scaled_residuals`."""
        s = self.residual_scale
        if self.kind == "eq":
            return [1.0 / s]
        out = []
        if self.lower is not None:
            out.append(1.0 / s)
        if self.upper is not None:
            out.append(-1.0 / s)
        return out


@dataclass(frozen=True)
class Problem:
    """An optimisation problem.

    Parameters
    ----------
    name : str
    variables : sequence of Variable
    objective : Objective or callable ``f(design) -> float``
    sense : {"max", "min"}
    constraints : sequence of Constraint
    build : callable ``build(x: dict) -> design``
    description : str
        One paragraph shown in reports.
    to_toml : callable, optional
        ``to_toml(x: dict, design) -> str``: a design file for ``tabletcad build``.
    extras : callable, optional
        ``extras(x: dict, design) -> dict``: additional figures for the report.
    reference : dict, optional
        A published optimum to compare with (shown in reports).
    """

    name: str
    variables: tuple
    objective: Any
    build: Callable[[dict], Any]
    sense: str = "max"
    constraints: tuple = ()
    description: str = ""
    to_toml: Callable[[dict, Any], str] | None = None
    extras: Callable[[dict, Any], dict] | None = None
    reference: dict | None = None

    def __post_init__(self) -> None:
        vs = tuple(self.variables)
        if not vs:
            raise DesignError("variables", 0, "a problem needs at least one variable")
        names = [v.name for v in vs]
        if len(set(names)) != len(names):
            dup = sorted({n for n in names if names.count(n) > 1})[0]
            raise DesignError("variable name", dup, "must be unique")
        for v in vs:
            if not isinstance(v, Variable):
                raise DesignError("variable", type(v).__name__, "must be a Variable")
        cs = tuple(self.constraints)
        for c in cs:
            if not isinstance(c, Constraint):
                raise DesignError("constraint", type(c).__name__, "must be a Constraint")
        if self.sense not in ("max", "min"):
            raise DesignError("sense", self.sense, "must be 'max' or 'min'")
        obj = self.objective if isinstance(self.objective, Objective) else Objective(self.objective)
        if not callable(obj.func):
            raise DesignError("objective", type(obj.func).__name__, "must be callable")
        object.__setattr__(self, "variables", vs)
        object.__setattr__(self, "constraints", cs)
        object.__setattr__(self, "objective", obj)

    @property
    def names(self) -> list[str]:
        return [v.name for v in self.variables]

    def x0(self) -> dict[str, float]:
        return {v.name: v.initial for v in self.variables}


@dataclass(frozen=True)
class ConstraintValue:
    """A constraint evaluated at a design: value, bounds, slack and violation."""

    name: str
    kind: str
    value: float
    target: float | None
    lower: float | None
    upper: float | None
    slack: float
    violation: float
    relative_violation: float
    satisfied: bool
    unit: str = ""

    def to_dict(self) -> dict:
        d = dict(self.__dict__)
        for k, v in list(d.items()):
            if isinstance(v, float) and not math.isfinite(v):
                d[k] = None if math.isnan(v) else (str(v))
        return d


@dataclass(frozen=True)
class Iteration:
    """One solver iteration: objective (in the problem's sense) and worst scaled violation."""

    iteration: int
    objective: float
    max_violation: float
    nfev: int


@dataclass
class Result:
    """Outcome of :func:`tabletcad.optimise.solve`.

    ``success`` is True only when the solver converged *and* the final point
    meets every bound and constraint within its tolerance; otherwise
    ``message`` names what failed and by how much.
    """

    problem: str
    method: str
    x: dict
    objective: float
    constraints: list
    success: bool
    status: str
    message: str
    iterations: int
    nfev: int
    ngrad: int
    wall_time_s: float
    history: list = field(default_factory=list)
    design: Any = None
    sense: str = "max"
    objective_name: str = "objective"
    objective_unit: str = ""
    solver_message: str = ""
    extras: dict = field(default_factory=dict)
    starts: int = 1

    @property
    def max_violation(self) -> float:
        return max([c.violation for c in self.constraints], default=0.0)

    def worst_constraint(self) -> ConstraintValue | None:
        bad = [c for c in self.constraints if not c.satisfied]
        if not bad:
            return None
        return max(bad, key=lambda c: c.relative_violation)

    def to_dict(self) -> dict:
        return dict(
            problem=self.problem,
            method=self.method,
            success=self.success,
            status=self.status,
            message=self.message,
            solver_message=self.solver_message,
            sense=self.sense,
            objective=dict(name=self.objective_name, value=self.objective, unit=self.objective_unit),
            x=dict(self.x),
            constraints=[c.to_dict() for c in self.constraints],
            iterations=self.iterations,
            function_evaluations=self.nfev,
            gradient_evaluations=self.ngrad,
            starts=self.starts,
            wall_time_s=self.wall_time_s,
            history=[dict(iteration=h.iteration, objective=h.objective, max_violation=h.max_violation, nfev=h.nfev)
                     for h in self.history],
            extras=self.extras,
        )


class BuildFailure(TabletcadError):
    """A design could not be built or evaluated at some point of the search."""


class Evaluator:
    """Scaled-variable evaluation of a :class:`Problem` with a build cache.

    Works on ``z ∈ [0, 1]^n`` (``x = lower + z (upper - lower)``); fixed variables
    (``lower == upper``) are removed from the vector the solver sees.
    """

    def __init__(self, problem: Problem, *, fd_step: float = FD_STEP, fd_scheme: str = "forward", cache_size: int = 256,
                 progress=None) -> None:
        self.p = problem
        self.vars = problem.variables
        self.free = [i for i, v in enumerate(self.vars) if v.span > 0]
        self.lo = np.array([v.lower for v in self.vars])
        self.span = np.array([v.span for v in self.vars])
        if not fd_step > 0:
            raise DesignError("fd_step", fd_step, "must be > 0")
        self.fd_step = float(fd_step)
        if fd_scheme not in ("forward", "central"):
            raise DesignError("fd_scheme", fd_scheme, "must be 'forward' or 'central'")
        self.fd_scheme = fd_scheme
        self.cache: OrderedDict = OrderedDict()
        self.cache_size = cache_size
        self.nfev = 0
        self.ngrad = 0
        self.progress = progress
        self.sign = -1.0 if problem.sense == "max" else 1.0
        self.rows = []  # (constraint index, residual index within it)
        for ci, c in enumerate(problem.constraints):
            for k in range(len(c.scaled_residuals(0.0 if c.kind == "ineq" else c.target))):
                self.rows.append((ci, k))
        self.last_error: str = ""
        self._last_grad: tuple | None = None

    # -------------------------------------------------------------- conversions
    @property
    def n(self) -> int:
        return len(self.free)

    def z0(self) -> np.ndarray:
        x = np.array([v.initial for v in self.vars])
        return self.to_z(x)

    def to_z(self, x: np.ndarray) -> np.ndarray:
        z = np.zeros(len(self.free))
        for j, i in enumerate(self.free):
            z[j] = (x[i] - self.lo[i]) / self.span[i]
        return np.clip(z, 0.0, 1.0)

    def to_x(self, z: np.ndarray) -> np.ndarray:
        x = self.lo.copy()
        z = np.clip(np.asarray(z, dtype=float), 0.0, 1.0)
        for j, i in enumerate(self.free):
            x[i] = self.lo[i] + z[j] * self.span[i]
        # exact bounds at the ends (no round-off outside)
        for j, i in enumerate(self.free):
            x[i] = min(max(x[i], self.vars[i].lower), self.vars[i].upper)
        return x

    def xdict(self, z: np.ndarray) -> dict[str, float]:
        return {v.name: float(val) for v, val in zip(self.vars, self.to_x(z))}

    # -------------------------------------------------------------- evaluation
    def evaluate(self, z: np.ndarray) -> dict:
        """Build the design at ``z`` once; return dict(x, design, f, g (constraint values), ok)."""
        z = np.clip(np.asarray(z, dtype=float), 0.0, 1.0)
        key = z.tobytes()
        hit = self.cache.get(key)
        if hit is not None:
            self.cache.move_to_end(key)
            return hit
        x = self.xdict(z)
        self.nfev += 1
        if self.progress is not None:
            self.progress(self.nfev)
        try:
            design = self.p.build(x)
            f = float(self.p.objective.func(design))
            g = [float(c.func(x if c.uses == "x" else design)) for c in self.p.constraints]
            ok = math.isfinite(f) and all(math.isfinite(v) for v in g)
            err = "" if ok else "objective or constraint is not finite"
        except (TabletcadError, ValueError, ArithmeticError) as exc:
            design, f, g, ok, err = None, math.nan, [math.nan] * len(self.p.constraints), False, str(exc).splitlines()[0]
        if not ok:
            self.last_error = err
        rec = dict(x=x, design=design, f=f, g=g, ok=ok, error=err)
        self.cache[key] = rec
        if len(self.cache) > self.cache_size:
            self.cache.popitem(last=False)
        return rec

    # solver-facing (scaled, minimisation form) -----------------------------------
    def fun(self, z) -> float:
        r = self.evaluate(z)
        return self.sign * r["f"] if r["ok"] else math.nan

    def residuals(self, z) -> np.ndarray:
        r = self.evaluate(z)
        out = []
        for c, v in zip(self.p.constraints, r["g"]):
            out.extend(c.scaled_residuals(v) if math.isfinite(v) else [math.nan] * len(c.scaled_residuals(0.0 if c.kind == "ineq" else c.target)))
        return np.array(out, dtype=float)

    def residuals_kind(self, kind: str):
        idx = [k for k, (ci, _) in enumerate(self.rows) if self.p.constraints[ci].kind == kind]
        return idx

    def max_violation(self, z) -> float:
        """Worst constraint violation, each divided by its solver scale (0 when feasible)."""
        r = self.evaluate(z)
        worst = 0.0
        for c, v in zip(self.p.constraints, r["g"]):
            viol, _, _ = c.violation(v)
            worst = max(worst, viol / c.residual_scale)
        return worst

    def _grad_entries(self, z) -> tuple[np.ndarray, np.ndarray]:
        """Gradients of the objective (minimisation sign) and of every residual row w.r.t. z.

        The last point's gradients are kept: scipy asks for the objective gradient and for
        each constraint block's Jacobian at the same point in separate calls."""
        z = np.clip(np.asarray(z, dtype=float), 0.0, 1.0)
        key = (z.tobytes(), self.fd_scheme)
        if self._last_grad is not None and self._last_grad[0] == key:
            return self._last_grad[1], self._last_grad[2]
        gf, rows = self._grad_compute(z)
        self._last_grad = (key, gf, rows)
        return gf, rows

    def _grad_compute(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        base = self.evaluate(z)
        n = self.n
        p = self.p
        self.ngrad += 1
        need_fd_obj = p.objective.grad is None
        need_fd_con = [c.grad is None for c in p.constraints]
        gf = np.zeros(n)
        gc = np.zeros((len(p.constraints), n))
        if need_fd_obj or any(need_fd_con):
            for j in range(n):
                h = self.fd_step
                zp = z.copy()
                zm = z.copy()
                central = self.fd_scheme == "central" and z[j] - h >= 0.0 and z[j] + h <= 1.0
                if not central and zp[j] + h > 1.0:
                    h = -h
                zp[j] += h
                r = self.evaluate(zp)
                if central:
                    zm[j] -= h
                    b, den = self.evaluate(zm), 2.0 * h
                else:
                    b, den = base, h
                if need_fd_obj:
                    gf[j] = (r["f"] - b["f"]) / den
                for ci, c in enumerate(p.constraints):
                    if need_fd_con[ci]:
                        gc[ci, j] = (r["g"][ci] - b["g"][ci]) / den
        x = base["x"]
        des = base["design"]
        free_names = [self.vars[i].name for i in self.free]
        free_span = [self.span[i] for i in self.free]
        if not need_fd_obj:
            d = p.objective.grad(x, des)
            gf = np.array([float(d.get(nm, 0.0)) * s for nm, s in zip(free_names, free_span)])
        for ci, c in enumerate(p.constraints):
            if not need_fd_con[ci]:
                d = c.grad(x, des)
                gc[ci] = [float(d.get(nm, 0.0)) * s for nm, s in zip(free_names, free_span)]
        rows = np.zeros((len(self.rows), n))
        for k, (ci, ri) in enumerate(self.rows):
            rows[k] = p.constraints[ci].residual_signs()[ri] * gc[ci]
        return self.sign * gf, rows

    def grad(self, z) -> np.ndarray:
        return self._grad_entries(z)[0]

    def jac(self, z) -> np.ndarray:
        return self._grad_entries(z)[1]

    # -------------------------------------------------------------- final assessment
    def assess(self, z) -> tuple[dict, list[ConstraintValue]]:
        r = self.evaluate(z)
        vals = []
        for c, v in zip(self.p.constraints, r["g"]):
            viol, rel, slack = c.violation(v)
            vals.append(ConstraintValue(
                name=c.name, kind=c.kind, value=v, target=c.target, lower=c.lower, upper=c.upper,
                slack=slack, violation=viol, relative_violation=rel,
                satisfied=bool(math.isfinite(v) and c.satisfied(v)), unit=c.unit,
            ))
        return r, vals


def now() -> float:
    return time.perf_counter()
