"""Design optimisation: maximum strength at fixed volume on PDE and model parameters.

Public API::

    from tabletcad.optimise import Variable, Constraint, Objective, Problem, solve
    from tabletcad.optimise import thesis          # the thesis's three problems (chapter 6)

See :mod:`tabletcad.optimise.problem` (problem definition, scaling, caching,
finite differences), :mod:`tabletcad.optimise.solvers` (SLSQP, trust-constr,
multi-start, differential evolution), :mod:`tabletcad.optimise.thesis`,
:mod:`tabletcad.optimise.report`, :mod:`tabletcad.optimise.plot` and
:mod:`tabletcad.optimise.strength` (the FE breaking force as objective or constraint).
"""

from tabletcad.optimise.problem import (
    FD_STEP,
    FEASIBILITY_TOL,
    METHODS,
    Constraint,
    ConstraintValue,
    Iteration,
    Objective,
    Problem,
    Result,
    Variable,
)


def __getattr__(name: str):
    # solve imports scipy.optimize (~0.3 s): loaded on first use, so that a bad problem
    # file is refused by `tabletcad optimise` before the solvers are imported
    if name == "solve":
        from tabletcad.optimise.solvers import solve

        return solve
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

__all__ = [
    "Variable",
    "Constraint",
    "Objective",
    "Problem",
    "Result",
    "ConstraintValue",
    "Iteration",
    "solve",
    "METHODS",
    "FEASIBILITY_TOL",
    "FD_STEP",
]
