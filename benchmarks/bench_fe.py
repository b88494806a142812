"""Benchmark of one FE diametral evaluation (the cost of FE inside an optimisation loop).

For a few tablets, one coarse-mesh evaluation as the optimiser makes it
(:func:`tabletcad.fe.objective.coarse_mesh`: ``mesh_size`` = plan extent / 6,
strips plan / 10, ``1.2 R`` about the loaded diametral plane, ``mesh_size / 2``
about the centre; mirror symmetry declared, so the quarter model is solved and
unfolded; no error estimate) is timed after the B-rep solid (CAD layer, built
once per tablet and timed apart; an optimiser pays both, "eval s" is their
sum).  Each evaluation is run twice and the faster run is printed (the machine
is shared); CPU seconds (``time.process_time``, solid + FE) are printed too: on
a loaded machine wall time overstates the cost.

Two in-process references:

* *baseline*: a fixed sparse direct solve (scipy ``splu`` of the 7-point
  Laplacian on a 28³ grid, 21 952 unknowns), run just before; it slows down
  with the machine's load as the FE solve does, so "/base" (evaluation wall
  seconds over baseline seconds) compares runs made under different loads;
* *full model*: the same coarse mesh sizes without the symmetry declaration
  (the whole tablet meshed and solved, as every evaluation was before the
  quarter model), timed in the same process: "full s" and "speed-up".

Accuracy: the largest (averaged) tensile stress and the centre stress of the
coarse evaluation against the default mesh (the optimum's re-check, quarter
model) and against a reference mesh (the default sizes divided by ``REFINE``,
quarter model), all in the same run.

Run: ``.venv/bin/python benchmarks/bench_fe.py`` (no assertions on time).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import numpy as np  # noqa: E402

from tabletcad.pipeline.design import design_from_dict  # noqa: E402
from tabletcad.fe.diametral import STRIP_FRACTION, diametral, load_axis  # noqa: E402
from tabletcad.fe.objective import coarse_mesh  # noqa: E402

#: design -> tablet table
DESIGNS = {
    "flat_face_round 10 x 3.5": {"family": "flat_face_round", "diameter": 10.0, "thickness": 3.5},
    "concave_round 10, band 2.8, cup 0.9": {"family": "concave_round", "diameter": 10.0, "band": 2.8,
                                            "cup_depth": 0.9, "land": 0.08},
    "concave_round 10, band 2.184, cup 1.5": {"family": "concave_round", "diameter": 10.0, "band": 2.184,
                                              "cup_depth": 1.5, "land": 0.08},
    "capsule 18 x 8, cup 1.3": {"family": "capsule", "length": 18.0, "width": 8.0, "band": 3.2, "cup_depth": 1.3,
                                "land": 0.08, "central_radius": 12.0, "edge_radius": 2.0},
}
#: The reference mesh: the default element sizes divided by this.
REFINE = 1.5
#: Timed runs of each coarse evaluation (the fastest is printed).
REPEAT = 2


def baseline() -> float:
    """Wall seconds of a fixed sparse direct solve (the machine's speed under its current load)."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    n = 28
    d = sp.diags([-np.ones(n - 1), 2 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1])
    i = sp.identity(n)
    A = (sp.kron(sp.kron(d, i), i) + sp.kron(sp.kron(i, d), i) + sp.kron(sp.kron(i, i), d)).tocsc()
    t0 = time.perf_counter()
    spla.splu(A, permc_spec="MMD_AT_PLUS_A").solve(np.ones(A.shape[0]))
    return time.perf_counter() - t0


def default_sizes(t, refine: float) -> dict[str, float]:
    """The default mesh sizes of :func:`tabletcad.fe.diametral.diametral` divided by ``refine`` (mm), but no
    finer than fits in memory (``fe.mesh.finest_size``: the capsule's would need 2.5e5 unknowns)."""
    from tabletcad.fe.mesh import finest_size

    lo, hi = (np.asarray(a, float) for a in t.bounds())
    ext = hi - lo
    h = max(min(ext[2] / 2.0, float(min(ext[0], ext[1])) / 12.0) / refine, 1.01 * finest_size(float(t.volume())))
    b = STRIP_FRACTION * float(ext[load_axis("width", ext)])
    return {"mesh_size": h, "strip_mesh_size": min(h, b / 3.0)}


def timed(fn):
    """(result, wall s, CPU s) of the fastest of ``REPEAT`` calls."""
    best = None
    for _ in range(REPEAT):
        c0, w0 = time.process_time(), time.perf_counter()
        r = fn()
        w, c = time.perf_counter() - w0, time.process_time() - c0
        if best is None or w < best[1]:
            best = (r, w, c)
    return best


def main() -> None:
    from tabletcad.cad.tablet_solid import tablet_solid

    base = min(baseline() for _ in range(3))
    print(f"baseline (splu, 28^3 Laplacian): {base:.3f} s wall; coarse evaluations: fastest of {REPEAT}")
    print(f"{'design':38s} {'solid s':>7s} {'coarse s':>8s} {'eval s':>6s} {'/base':>5s} {'cpu s':>11s} "
          f"{'dofs':>6s} {'full s':>6s} {'speed-up':>8s} {'σmax/P':>9s} {'vs default':>10s} {'vs ref':>7s} "
          f"{'σc vs def':>9s} {'σc vs ref':>9s} {'ref dofs':>8s}")
    for name, d in DESIGNS.items():
        t = design_from_dict({"tablet": d})
        c0, t0 = time.process_time(), time.perf_counter()
        solid = tablet_solid(t)
        t_solid, c_solid = time.perf_counter() - t0, time.process_time() - c0
        kw = {**coarse_mesh(t, "width"), "error_estimate": False, "solid": solid}
        coarse, w_coarse, c_coarse = timed(lambda: diametral(t, 1.0, "width", symmetric=True, **kw))
        _, w_full, _ = timed(lambda: diametral(t, 1.0, "width", symmetric=False, **kw))
        fine = diametral(t, 1.0, "width", error_estimate=False, symmetric=True, solid=solid)
        ref = diametral(t, 1.0, "width", **default_sizes(t, REFINE), error_estimate=False, symmetric=True,
                        solid=solid)
        a, ac = coarse.max_tensile_stress_MPa, coarse.centre_tensile_stress_MPa

        def pct(x: float, y: float) -> str:
            return f"{100.0 * (x - y) / y:+.2f}"

        ev = t_solid + w_coarse
        cpu = f"{c_solid:.2f}+{c_coarse:.2f}"
        print(f"{name:38s} {t_solid:7.2f} {w_coarse:8.2f} {ev:6.2f} {ev / base:5.2f} {cpu:>11s} "
              f"{coarse.dofs:6d} {w_full:6.2f} {w_full / w_coarse:8.1f} {a:9.6f} "
              f"{pct(a, fine.max_tensile_stress_MPa):>10s} {pct(a, ref.max_tensile_stress_MPa):>7s} "
              f"{pct(ac, fine.centre_tensile_stress_MPa):>9s} {pct(ac, ref.centre_tensile_stress_MPa):>9s} "
              f"{ref.dofs:8d}", flush=True)


if __name__ == "__main__":
    main()
