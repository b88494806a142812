"""The FE breaking-force prediction on a coarse mesh: the figure an optimisation evaluates.

:func:`breaking_force` evaluates :func:`tabletcad.fe.prediction.predict_breaking_force`
on a coarse mesh (element size = smallest plan extent / 6, strips at plan / 10,
no error estimate: about 5 000 unknowns and under 2 s for a round tablet, see
``benchmarks/bench_fe.py``); :mod:`tabletcad.optimise.strength` wraps it as an
objective or constraint of :class:`tabletcad.optimise.Problem`.  Re-check the final design with the default (finer) mesh, e.g. ``tabletcad fe
strength``.  Every evaluation remeshes the design, so the value is not a
smooth function of the variables at the scale of the mesh: prefer the
derivative-free ``differential_evolution`` method.
"""

from __future__ import annotations

from typing import Any

from tabletcad.fe.prediction import StrengthInputs, predict_breaking_force

__all__ = ["COARSE_MESH_FRACTION", "COARSE_STRIP_FRACTION", "breaking_force"]

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
