"""Benchmark of one FE diametral evaluation (the cost of FE inside an optimisation loop).

For a few tablets, one coarse-mesh evaluation (the mesh of
:func:`tabletcad.fe.objective.breaking_force`: ``mesh_size`` = plan extent / 6,
strips plan / 10, 1.5 R about the loaded diametral plane; mirror symmetry
declared; no error estimate) is timed after the B-rep solid (CAD layer, built
once per tablet and timed apart; an optimiser pays both, "eval s" is their
sum); the largest (averaged) tensile stress and the centre stress are
compared with the default mesh of the same tablet (the optimum's re-check,
measured in the same run; not for the capsule, whose default mesh needs
2-3 GB).  CPU time (``time.process_time``) is printed too: on a
loaded machine wall time overstates the cost.

Because the machine is shared, every figure is also given as a ratio to a
*baseline* run in the same process just before: a fixed sparse direct solve
(scipy ``splu`` of the 7-point Laplacian on a 28³ grid, 21 952 unknowns),
which slows down with the machine's load as the FE solve does.

Run: ``.venv/bin/python benchmarks/bench_fe.py`` (no assertions on time).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tabletcad.pipeline.design import design_from_dict  # noqa: E402
from tabletcad.fe.diametral import diametral  # noqa: E402
from tabletcad.fe.objective import coarse_mesh  # noqa: E402

# design -> (tablet table, compare with a finer mesh?); the capsule's finer mesh needs ~2-3 GB
DESIGNS = {
    "flat_face_round 10 x 3.5": ({"family": "flat_face_round", "diameter": 10.0, "thickness": 3.5}, True),
    "concave_round 10, band 2.8, cup 0.9": ({"family": "concave_round", "diameter": 10.0, "band": 2.8,
                                             "cup_depth": 0.9, "land": 0.08}, True),
    "concave_round 10, band 2.184, cup 1.5": ({"family": "concave_round", "diameter": 10.0, "band": 2.184,
                                               "cup_depth": 1.5, "land": 0.08}, True),
    "capsule 18 x 8, cup 1.3": ({"family": "capsule", "length": 18.0, "width": 8.0, "band": 3.2, "cup_depth": 1.3,
                                 "land": 0.08, "central_radius": 12.0, "edge_radius": 2.0}, False),
}


def baseline() -> float:
    """Wall seconds of a fixed sparse direct solve (the machine's speed under its current load)."""
    import numpy as np
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    n = 28
    d = sp.diags([-np.ones(n - 1), 2 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1])
    i = sp.identity(n)
    A = (sp.kron(sp.kron(d, i), i) + sp.kron(sp.kron(i, d), i) + sp.kron(sp.kron(i, i), d)).tocsc()
    t0 = time.perf_counter()
    spla.splu(A, permc_spec="MMD_AT_PLUS_A").solve(np.ones(A.shape[0]))
    return time.perf_counter() - t0


def main() -> None:
    from tabletcad.cad.tablet_solid import tablet_solid

    base = min(baseline() for _ in range(3))
    print(f"baseline (splu, 28^3 Laplacian): {base:.3f} s wall")
    print(f"{'design':38s} {'solid s':>8s} {'coarse s':>9s} {'eval s':>7s} {'/base':>6s} {'cpu s':>6s} {'dofs':>6s} "
          f"{'σmax/P':>9s} {'fine':>9s} {'diff %':>7s} {'σc diff %':>9s} {'fine s':>7s}")
    for name, (d, compare) in DESIGNS.items():
        t = design_from_dict({"tablet": d})
        t0 = time.perf_counter()
        solid = tablet_solid(t)
        t_solid = time.perf_counter() - t0
        c0, w0 = time.process_time(), time.perf_counter()
        coarse = diametral(t, 1.0, "width", **coarse_mesh(t, "width"), error_estimate=False, symmetric=True,
                           solid=solid)
        w_coarse, c_coarse = time.perf_counter() - w0, time.process_time() - c0
        a, ac = coarse.max_tensile_stress_MPa, coarse.centre_tensile_stress_MPa
        if compare:
            w0 = time.perf_counter()
            fine = diametral(t, 1.0, "width", error_estimate=False, symmetric=True, solid=solid)
            w_fine = time.perf_counter() - w0
            b, bc = fine.max_tensile_stress_MPa, fine.centre_tensile_stress_MPa
            tail = f"{b:9.5f} {100 * (a - b) / b:7.2f} {100 * (ac - bc) / bc:9.2f} {w_fine:7.2f}"
        else:
            tail = f"{'-':>9s} {'-':>7s} {'-':>9s} {'-':>7s}"
        ev = t_solid + w_coarse
        print(f"{name:38s} {t_solid:8.2f} {w_coarse:9.2f} {ev:7.2f} {ev / base:6.1f} {c_coarse:6.2f} "
              f"{coarse.dofs:6d} {a:9.5f} {tail}", flush=True)


if __name__ == "__main__":
    main()
