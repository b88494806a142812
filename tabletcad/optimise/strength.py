"""The finite-element breaking force as an optimisation objective or constraint.

Both evaluate :func:`tabletcad.fe.objective.breaking_force` (coarse mesh; needs
the ``fe`` extra, imported on the first evaluation).  The predicted force rests
on a mesh-independent stress (averaged over the strip width), but every
evaluation remeshes the design, so neighbouring designs differ by about 1 % of
scatter on top of the trend: use finite differences over several per cent of
each range (``fd_step = 0.05``, ``fd_scheme = "central"``) or the
derivative-free ``differential_evolution``, and re-check the optimum on the
default mesh (problem files with ``[fe]`` do it and report it in ``extras``;
``tabletcad fe strength`` prints it).
"""

from __future__ import annotations

from typing import Any

from tabletcad.errors import check_positive
from tabletcad.optimise.problem import Constraint, Objective

__all__ = ["breaking_force_objective", "breaking_force_constraint", "fe_breaking_force"]

_NAME = "FE breaking force (elastic first crack, coarse mesh)"


def _force(tensile_strength_MPa: float, direction: str, symmetric: bool = False):
    def force(tablet: Any) -> float:
        from tabletcad.fe.objective import breaking_force

        return breaking_force(tablet, tensile_strength_MPa, direction, symmetric=symmetric)

    return force


def fe_breaking_force(tensile_strength_MPa: float, direction: str = "width", symmetric: bool = False):
    """``f(tablet) -> N``: the coarse-mesh FE breaking force, as a quantity of a problem file.

    ``symmetric``: the designs are mirror symmetric (see :func:`tabletcad.fe.objective.breaking_force`).
    """
    check_positive("tensile_strength_MPa", tensile_strength_MPa, "MPa")
    return _force(tensile_strength_MPa, direction, symmetric)


def breaking_force_objective(tensile_strength_MPa: float, direction: str = "width") -> Objective:
    """An :class:`~tabletcad.optimise.problem.Objective`: the predicted breaking force (N), to maximise.

    ``tensile_strength_MPa`` is the formulation's tensile strength (MPa); ``direction`` the
    loading direction in plan (``width``, ``length``, ``x`` or ``y``).
    """
    check_positive("tensile_strength_MPa", tensile_strength_MPa, "MPa")
    return Objective(func=_force(tensile_strength_MPa, direction), name=_NAME, unit="N")


def breaking_force_constraint(tensile_strength_MPa: float, lower_N: float, direction: str = "width") -> Constraint:
    """A :class:`~tabletcad.optimise.problem.Constraint`: predicted breaking force >= ``lower_N`` (N)."""
    check_positive("tensile_strength_MPa", tensile_strength_MPa, "MPa")
    check_positive("lower_N", lower_N, "N")
    return Constraint(name=_NAME, func=_force(tensile_strength_MPa, direction), kind="ineq",
                      lower=lower_N, unit="N", scale=lower_N)
