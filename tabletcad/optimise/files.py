"""Problem files (TOML) for ``tabletcad optimise``.

A thesis problem::

    [problem]
    kind = "spherical_tablet"      # flat_faced_round | spherical_tablet | softgel_capsule
    method = "SLSQP"               # optional default: SLSQP | trust-constr | multistart | differential_evolution

    [parameters]                   # keyword arguments of tabletcad.optimise.thesis.<kind>_problem
    variant = "a"

    [solver]                       # optional: maxiter, ftol, fd_step, fd_scheme, starts, seed, popsize
    maxiter = 200

A problem over the parameters of any tablet family (``tabletcad shapes``)::

    [problem]
    kind = "family"
    family = "flat_faced_round"
    sense = "min"
    objective = "surface_area_mm2"   # or { linear = { diameter = 1.0, thickness = 1.0 } }

    [variables]
    diameter = { lower = 5.0, upper = 15.0, initial = 10.0 }
    thickness = { lower = 1.0, upper = 8.0, initial = 3.0 }

    [fixed]                          # other family parameters (optional)

    [[constraint]]
    quantity = "volume_mm3"          # volume_mm3 | surface_area_mm2 | plan_area_mm2 |
    target = 235.0                   #   length_mm | width_mm | height_mm
    relative = true                  # or lower = / upper = ; optional tol, scale

Quantities are computed by :meth:`Tablet.properties` and :meth:`Tablet.dimensions`.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

from tabletcad.errors import DesignError, check_finite
from tabletcad.optimise.problem import Constraint, Objective, Problem, Variable

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

__all__ = ["load_problem", "problem_from_dict", "family_problem", "QUANTITIES", "SOLVER_KEYS"]

QUANTITIES = {
    "volume_mm3": ("mm3", lambda t: t.volume()),
    "surface_area_mm2": ("mm2", lambda t: t.surface_area()),
    "plan_area_mm2": ("mm2", lambda t: t.plan_area()),
    "length_mm": ("mm", lambda t: t.dimensions()["length_mm"]),
    "width_mm": ("mm", lambda t: t.dimensions()["width_mm"]),
    "height_mm": ("mm", lambda t: t.dimensions()["height_mm"]),
}
SOLVER_KEYS = {"maxiter": int, "ftol": float, "fd_step": float, "fd_scheme": str, "starts": int, "seed": int, "popsize": int}
_TOP = {"problem", "parameters", "solver", "variables", "fixed", "constraint"}


def load_problem(path: str | Path) -> tuple[Problem, str, dict]:
    """Read a problem file; return ``(problem, default method, solver options)``."""
    path = Path(path)
    if not path.is_file():
        raise DesignError("problem file", str(path), "must be an existing TOML file")
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise DesignError("problem file", path.name, f"must be valid TOML ({exc})") from None
    return problem_from_dict(data)


def _check_keys(where: str, table: Any, allowed: set) -> dict:
    if not isinstance(table, dict):
        raise DesignError(where, table, "must be a table")
    for k in table:
        if k not in allowed:
            raise DesignError(f"{where} key {k!r}", table[k], f"allowed keys are {', '.join(sorted(allowed))}")
    return table


def problem_from_dict(data: dict) -> tuple[Problem, str, dict]:
    from tabletcad.optimise import thesis
    from tabletcad.optimise.solvers import METHODS

    _check_keys("top-level", data, _TOP)
    prob = _check_keys("[problem]", data.get("problem", {}), {"kind", "method", "family", "sense", "objective", "name"})
    kind = prob.get("kind")
    if kind is None:
        raise DesignError("[problem] kind", "missing", "must be one of " + ", ".join(thesis.PROBLEMS) + " or family")
    method = prob.get("method", "SLSQP")
    if method not in METHODS:
        raise DesignError("[problem] method", method, "must be one of " + ", ".join(METHODS))
    solver = dict(_check_keys("[solver]", data.get("solver", {}), set(SOLVER_KEYS)))
    for k, typ in SOLVER_KEYS.items():
        if k in solver and not isinstance(solver[k], typ if typ is not float else (int, float)):
            raise DesignError(f"[solver] {k}", solver[k], f"must be of type {typ.__name__}")
    if kind == "family":
        for k in ("parameters",):
            if k in data:
                raise DesignError(f"[{k}]", "given", "family problems take [variables], [fixed] and [[constraint]]")
        return family_problem(prob, data.get("variables"), data.get("fixed", {}), data.get("constraint", [])), method, solver
    for k in ("variables", "fixed", "constraint"):
        if k in data:
            raise DesignError(f"[{k}]", "given", f"only family problems take it, not {kind!r}")
    params = data.get("parameters", {})
    if not isinstance(params, dict):
        raise DesignError("[parameters]", params, "must be a table")
    params = {k: (tuple(v) if isinstance(v, list) else v) for k, v in params.items()}
    return thesis.make_problem(kind, **params), method, solver


def family_problem(prob: dict, variables: Any, fixed: dict, constraints: Any) -> Problem:
    """A :class:`Problem` over the parameters of a registered tablet family."""
    from tabletcad.design import design_to_toml
    from tabletcad.shapes import FAMILIES, _load_plugins

    _load_plugins()
    fam_name = prob.get("family")
    if fam_name not in FAMILIES:
        raise DesignError("[problem] family", fam_name, "must be one of " + ", ".join(FAMILIES))
    fam = FAMILIES[fam_name]
    if not isinstance(variables, dict) or not variables:
        raise DesignError("[variables]", variables, "must be a table of family parameters with lower/upper/initial")
    vs = []
    for name, spec in variables.items():
        if name not in fam.params:
            raise DesignError(f"[variables] {name}", spec, f"family {fam_name!r} takes {', '.join(fam.params)}")
        _check_keys(f"[variables] {name}", spec, {"lower", "upper", "initial"})
        if "lower" not in spec or "upper" not in spec:
            raise DesignError(f"[variables] {name}", spec, "needs lower and upper")
        vs.append(Variable(name, spec["lower"], spec["upper"], spec.get("initial"), fam.params[name]))
    _check_keys("[fixed]", fixed, set(fam.params) - set(variables))
    fixed = {k: check_finite(f"[fixed] {k}", v, fam.params[k]) for k, v in fixed.items()}
    sense = prob.get("sense", "max")
    name = prob.get("name", f"{fam_name}_optimum")

    def build(x):
        return fam.build(**fixed, **x)

    obj_spec = prob.get("objective")
    if isinstance(obj_spec, str):
        if obj_spec not in QUANTITIES:
            raise DesignError("[problem] objective", obj_spec, "must be one of " + ", ".join(QUANTITIES) + " or {linear = {...}}")
        unit, f = QUANTITIES[obj_spec]
        objective = Objective(f, obj_spec, unit)
    elif isinstance(obj_spec, dict) and set(obj_spec) == {"linear"} and isinstance(obj_spec["linear"], dict):
        coef = {k: check_finite(f"[problem] objective linear {k}", v) for k, v in obj_spec["linear"].items()}
        for k in coef:
            if k not in variables:
                raise DesignError("[problem] objective linear", k, "must name variables")
        objective = Objective(lambda t: sum(c * float(t.params[k]) for k, c in coef.items()),
                              " + ".join(f"{c:g} {k}" for k, c in coef.items()), "", grad=lambda x, d: dict(coef))
    else:
        raise DesignError("[problem] objective", obj_spec, "must be a quantity name or {linear = {variable = coefficient}}")
    if not isinstance(constraints, list):
        raise DesignError("[[constraint]]", constraints, "must be an array of tables")
    cons = []
    for k, c in enumerate(constraints):
        _check_keys(f"[[constraint]] {k}", c, {"quantity", "target", "lower", "upper", "relative", "tol", "scale", "name"})
        q = c.get("quantity")
        if q not in QUANTITIES:
            raise DesignError(f"[[constraint]] {k} quantity", q, "must be one of " + ", ".join(QUANTITIES))
        unit, f = QUANTITIES[q]
        kw = {kk: c[kk] for kk in ("target", "lower", "upper", "tol", "scale") if kk in c}
        cons.append(Constraint(c.get("name", q), f, kind="eq" if "target" in c else "ineq", relative=bool(c.get("relative", False)),
                               unit=unit, **kw))

    def to_toml(x, d):
        return design_to_toml(fam_name, {**fixed, **x}, name=name)

    return Problem(name=name, variables=vs, objective=objective, sense=sense, constraints=cons, build=build,
                   to_toml=to_toml, description=f"family {fam_name}: {sense} {objective.name}")
