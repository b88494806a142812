"""The FE breaking-force prediction as an optimisation objective or constraint.

:func:`breaking_force` evaluates :func:`tabletcad.fe.prediction.predict_breaking_force`
on a coarse mesh (element size = smallest plan extent / 6, strips at plan / 10,
no error estimate: about 5 000 unknowns and under 2 s for a round tablet, see
``benchmarks/bench_fe.py``); :func:`breaking_force_objective` and
:func:`breaking_force_constraint` wrap it for :class:`tabletcad.optimise.Problem`.
Re-check the final design with the default (finer) mesh, e.g. ``tabletcad fe
strength``.  Every evaluation remeshes the design, so the value is not a
smooth function of the variables at the scale of the mesh: prefer the
derivative-free ``differential_evolution`` method.
"""

from __future__ import annotations

from typing import Any

from tabletcad.fe.prediction import StrengthInputs, predict_breaking_force

__all__ = ["COARSE_MESH_FRACTION", "COARSE_STRIP_FRACTION", "breaking_force", "breaking_force_objective",
           "breaking_force_constraint"]

#: Coarse element size as a fraction of the smallest plan extent.
COARSE_MESH_FRACTION = 1.0 / 6.0
#: Coarse element size at the platens as a fraction of the smallest plan extent.
COARSE_STRIP_FRACTION = 1.0 / 10.0


def breaking_force(tablet: Any, tensile_strength_MPa: float, direction: str = "width", *, coarse: bool = True) -> float:
    """Predicted breaking force (N) of ``tablet`` (elastic first-crack estimate), coarse mesh by default."""
    fe: dict[str, Any] = {"error_estimate": False}
    if coarse:
        lo, hi = tablet.bounds()
        plan = float(min(hi[0] - lo[0], hi[1] - lo[1]))
        fe.update(mesh_size=plan * COARSE_MESH_FRACTION, strip_mesh_size=plan * COARSE_STRIP_FRACTION)
    return predict_breaking_force(tablet, StrengthInputs(tensile_strength_MPa=tensile_strength_MPa), direction,
                                  **fe).breaking_force_N


def breaking_force_objective(tensile_strength_MPa: float, direction: str = "width") -> Any:
    """An :class:`~tabletcad.optimise.problem.Objective` (N) to maximise."""
    from tabletcad.optimise.problem import Objective

    StrengthInputs(tensile_strength_MPa=tensile_strength_MPa)  # validates
    return Objective(func=lambda t: breaking_force(t, tensile_strength_MPa, direction),
                     name="FE breaking force (elastic first crack, coarse mesh)", unit="N")


def breaking_force_constraint(tensile_strength_MPa: float, lower_N: float, direction: str = "width") -> Any:
    """A :class:`~tabletcad.optimise.problem.Constraint`: predicted breaking force >= ``lower_N`` N."""
    from tabletcad.optimise.problem import Constraint

    StrengthInputs(tensile_strength_MPa=tensile_strength_MPa)
    return Constraint(name="FE breaking force (elastic first crack, coarse mesh)",
                      func=lambda t: breaking_force(t, tensile_strength_MPa, direction), kind="ineq",
                      lower=lower_N, unit="N", scale=lower_N)
