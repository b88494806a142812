"""The FE breaking-force prediction on a coarse mesh: the figure an optimisation evaluates.

:func:`breaking_force` evaluates :func:`tabletcad.fe.prediction.predict_breaking_force`
on a coarse mesh (element size = smallest plan extent / 6, strips at plan / 10,
no error estimate: about 5 000 unknowns and under 2 s for a round tablet, see
``benchmarks/bench_fe.py``); :mod:`tabletcad.optimise.strength` wraps it as an
objective or constraint of :class:`tabletcad.optimise.Problem`, and problem
files use it as the quantity ``fe_breaking_force_N``.

The figure rests on the largest tensile stress averaged over a ball of the
strip width's radius on the loaded diametral plane (see
:mod:`tabletcad.fe.diametral`), which converges under refinement: the coarse
mesh only adds a small, slowly varying bias (on a 10 mm concave round it
reads 3-6 % below the default mesh) and a scatter of about 1 % between
neighbouring designs, because each evaluation remeshes.  Finite differences
for gradients must therefore step over several per cent of a variable's range
(``fd_step = 0.05``, central), and the optimum is re-checked on the default
(finer) mesh (``coarse=False``, ``tabletcad fe strength``).
"""

from __future__ import annotations

from typing import Any

from tabletcad.fe.prediction import StrengthInputs, predict_breaking_force

__all__ = ["COARSE_MESH_FRACTION", "COARSE_STRIP_FRACTION", "breaking_force"]

#: Coarse element size as a fraction of the smallest plan extent.
COARSE_MESH_FRACTION = 1.0 / 6.0
#: Coarse element size at the platens as a fraction of the smallest plan extent.
COARSE_STRIP_FRACTION = 1.0 / 10.0


def breaking_force(tablet: Any, tensile_strength_MPa: float, direction: str = "width", *, coarse: bool = True,
                   symmetric: bool = False) -> float:
    """Predicted breaking force (N) of ``tablet`` (elastic first-crack estimate), coarse mesh by default.

    ``symmetric`` declares the tablet mirror symmetric about the plane across the load and its
    mid-thickness plane (see :func:`tabletcad.fe.diametral.diametral`): the sampled stresses are
    averaged over their mirror images, which halves the coarse mesh's scatter.
    """
    fe: dict[str, Any] = {"error_estimate": False, "symmetric": symmetric}
    if coarse:
        lo, hi = tablet.bounds()
        plan = float(min(hi[0] - lo[0], hi[1] - lo[1]))
        fe.update(mesh_size=plan * COARSE_MESH_FRACTION, strip_mesh_size=plan * COARSE_STRIP_FRACTION)
    return predict_breaking_force(tablet, StrengthInputs(tensile_strength_MPa=tensile_strength_MPa), direction,
                                  **fe).breaking_force_N
