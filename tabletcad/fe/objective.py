"""The FE breaking-force prediction on a coarse mesh: the figure an optimisation evaluates.

:func:`breaking_force` evaluates :func:`tabletcad.fe.prediction.predict_breaking_force`
on a coarse mesh (element size = smallest plan extent / 6, strips at plan / 10,
``1.2 R`` within ``R`` of the loaded diametral plane where the largest tensile
stress is averaged over balls of radius ``R``, size / 2 within ``1.5`` sizes of
the centre where the centre stress is recovered; no error estimate).  With
``symmetric=True`` only the quarter of the tablet is solved (see
:func:`tabletcad.fe.diametral.diametral`): about 3 500 unknowns for a 10 mm
round and 7 900 for an 18 x 8 mm capsule, and under a second of CPU for the
FE of one evaluation (``benchmarks/bench_fe.py``; the whole
tablet costs 1.8-6 times as much).  :mod:`tabletcad.optimise.strength` wraps it as an
objective or constraint of :class:`tabletcad.optimise.Problem`, and problem
files use it as the quantity ``fe_breaking_force_N``.

The figure rests on the largest tensile stress averaged over a ball of the
strip width's radius on the loaded diametral plane (see
:mod:`tabletcad.fe.diametral`), which converges under refinement: the coarse
mesh only adds a small, slowly varying bias (on ten 10 mm concave rounds of
289.1 mm³, cup depths 0.5-1.5 mm, symmetric: 0.9 % rms and at most 2.2 % off
a mesh twice finer than the default) and a scatter of about 1 % between
neighbouring designs, because each evaluation remeshes.  Finite differences
for gradients must therefore step over several per cent of a variable's range
(``fd_step = 0.05``, central), and the optimum is re-checked on the default
(finer) mesh (``coarse=False``, ``tabletcad fe strength``).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from tabletcad.errors import DesignError
from tabletcad.fe.prediction import STRENGTH_KEYS, StrengthInputs, StrengthPrediction, predict_breaking_force

__all__ = ["COARSE_MESH_FRACTION", "COARSE_STRIP_FRACTION", "breaking_force", "coarse_mesh", "coarse_prediction",
           "report_breaking_force"]

#: Coarse element size as a fraction of the smallest plan extent.
COARSE_MESH_FRACTION = 1.0 / 6.0
#: Coarse element size at the platens as a fraction of the smallest plan extent.
COARSE_STRIP_FRACTION = 1.0 / 10.0


def coarse_mesh(tablet: Any, direction: str = "width") -> dict[str, float]:
    """The coarse mesh's sizes (mm) for ``tablet``: ``mesh_size``, ``strip_mesh_size``, ``centre_mesh_size``
    (keyword arguments of :func:`tabletcad.fe.diametral.diametral`); the loaded plane takes diametral's
    default, ``PLANE_MESH_FACTOR · R`` where that fits.  ``direction`` is the signature's of
    :func:`~tabletcad.fe.prediction.predict_breaking_force`'s ``sizes``."""
    lo, hi = (np.asarray(a, float) for a in tablet.bounds())
    ext = hi - lo
    plan = float(min(ext[0], ext[1]))
    return {"mesh_size": plan * COARSE_MESH_FRACTION, "strip_mesh_size": plan * COARSE_STRIP_FRACTION,
            "centre_mesh_size": plan * COARSE_MESH_FRACTION / 2.0}


def breaking_force(tablet: Any, tensile_strength_MPa: float, direction: str = "width", *, coarse: bool = True,
                   symmetric: bool = False) -> float:
    """Predicted breaking force (N) of ``tablet`` (elastic first-crack estimate), coarse mesh by default.

    ``symmetric`` declares the tablet mirror symmetric about the plane across the load and its
    mid-thickness plane (see :func:`tabletcad.fe.diametral.diametral`): only its quarter is meshed
    and solved, and the unfolded field is exactly symmetric (1.8-6 times faster than the whole tablet).
    """
    fe: dict[str, Any] = {"error_estimate": False, "symmetric": symmetric}
    if coarse:
        fe.update(coarse_mesh(tablet, direction))
    return predict_breaking_force(tablet, StrengthInputs(tensile_strength_MPa=tensile_strength_MPa), direction,
                                  **fe).breaking_force_N


def coarse_prediction(tablet: Any, inputs: StrengthInputs, direction: str = "width", *,
                      solid: Any = None) -> StrengthPrediction:
    """:func:`tabletcad.fe.prediction.predict_breaking_force` on the coarse mesh (whole tablet, no error
    estimate): what ``tabletcad fe strength --coarse`` prints and the design report shows.  ``solid``:
    the tablet's B-rep when it is not the plain one (scored, embossed)."""
    # the tablet and a reference disc each on its own coarse mesh
    return predict_breaking_force(tablet, inputs, direction, solid=solid, sizes=coarse_mesh, error_estimate=False)


def report_breaking_force(tablet: Any, options: Any, tooling: Any = None) -> dict[str, Any]:
    """The design report's FE breaking force (``[report] fe_breaking_force = true``): :func:`coarse_prediction`
    across the width from the ``[report]`` strength inputs of ``options`` (a
    :class:`~tabletcad.pipeline.designreport.ReportOptions`); an elastic first-crack estimate.

    The plain (PDE) tablet is meshed: ``tablet_meshed`` says so, and when ``tooling`` (the design's
    ``[tooling]`` specification) scores or embosses it, ``note`` says that ``tabletcad fe strength``
    meshes the finished tablet (a bisect score lowers the force: 100 N against 130 N on the
    concave round bisect sample)."""
    try:
        import gmsh  # noqa: F401
        import skfem  # noqa: F401
    except ImportError as exc:
        raise DesignError("[report] fe_breaking_force", True, f"needs the fe extra ({exc.name} is missing): "
                          "pip install 'tabletcad[fe]'") from None
    inputs = StrengthInputs(**{k: getattr(options, k) for k in STRENGTH_KEYS})
    pred = coarse_prediction(tablet, inputs, "width")
    out = {**pred.to_dict(), "mesh": "coarse (tabletcad fe strength --coarse)", "dofs": pred.result.dofs,
           "tablet_meshed": "plain"}
    features = [] if tooling is None else [w for w, on in (("score", tooling.scores), ("embossing", tooling.emboss)) if on]
    if features:
        out["note"] = (f"the plain tablet, without the design's {' and '.join(features)}: tabletcad fe strength "
                       "meshes the finished tablet")
    return out
