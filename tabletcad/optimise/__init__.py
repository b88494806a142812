"""Design optimisation: maximum strength at fixed volume on PDE and model parameters.

Public API::

    from tabletcad.optimise import Variable, Constraint, Objective, Problem, solve
    from tabletcad.optimise import thesis          # the thesis's three problems (chapter 6)

See :mod:`tabletcad.optimise.problem` (problem definition, scaling, caching,
finite differences), :mod:`tabletcad.optimise.solvers` (SLSQP, trust-constr,
multi-start, differential evolution), :mod:`tabletcad.optimise.thesis`,
:mod:`tabletcad.optimise.report` and :mod:`tabletcad.optimise.plot`.
"""

from tabletcad.optimise.problem import (
    FD_STEP,
    FEASIBILITY_TOL,
    Constraint,
    ConstraintValue,
    Iteration,
    Objective,
    Problem,
    Result,
    Variable,
)
from tabletcad.optimise.solvers import METHODS, solve

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
