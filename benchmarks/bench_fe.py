"""Benchmark of one FE diametral evaluation (the cost of FE inside an optimisation loop).

For a few tablets, one coarse-mesh evaluation (``mesh_size`` = plan extent / 6,
strip size = plan extent / 10, no error estimate) is timed after the B-rep
solid (CAD layer, built once per tablet and timed apart); the centre stress is
compared with a finer mesh of the same tablet (plan / 12, strips plan / 20,
measured in the same run; not for the capsule, whose finer mesh needs 2-3 GB) so that the coarse mesh's error
is printed beside its time.  CPU time (``time.process_time``) is printed too:
on a loaded machine wall time overstates the cost.

Run: ``.venv/bin/python benchmarks/bench_fe.py`` (no assertions on time).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tabletcad.pipeline.design import design_from_dict  # noqa: E402
from tabletcad.fe.diametral import diametral  # noqa: E402

# design -> (tablet table, compare with a finer mesh?); the capsule's finer mesh needs ~2-3 GB
DESIGNS = {
    "flat_face_round 10 x 3.5": ({"family": "flat_face_round", "diameter": 10.0, "thickness": 3.5}, True),
    "concave_round 10, band 2.8, cup 0.9": ({"family": "concave_round", "diameter": 10.0, "band": 2.8,
                                             "cup_depth": 0.9, "land": 0.08}, True),
    "capsule 18 x 8, cup 1.3": ({"family": "capsule", "length": 18.0, "width": 8.0, "band": 3.2, "cup_depth": 1.3,
                                 "land": 0.08, "central_radius": 12.0, "edge_radius": 2.0}, False),
}


def main() -> None:
    from tabletcad.cad.tablet_solid import tablet_solid

    print(f"{'design':38s} {'solid s':>8s} {'coarse s':>9s} {'cpu s':>7s} {'dofs':>7s} {'σc coarse':>10s} "
          f"{'σc fine':>10s} {'diff %':>7s} {'fine s':>9s}")
    for name, (d, compare) in DESIGNS.items():
        t = design_from_dict({"tablet": d})
        t0 = time.perf_counter()
        solid = tablet_solid(t)
        t_solid = time.perf_counter() - t0
        lo, hi = t.bounds()
        plan = float(min(hi[0] - lo[0], hi[1] - lo[1]))
        c0, w0 = time.process_time(), time.perf_counter()
        coarse = diametral(t, 100.0, "width", mesh_size=plan / 6, strip_mesh_size=plan / 10, error_estimate=False,
                           solid=solid)
        w_coarse, c_coarse = time.perf_counter() - w0, time.process_time() - c0
        a = coarse.centre_tensile_stress_MPa
        if compare:
            w0 = time.perf_counter()
            fine = diametral(t, 100.0, "width", mesh_size=plan / 12, strip_mesh_size=plan / 20, error_estimate=False,
                             solid=solid)
            w_fine = time.perf_counter() - w0
            b = fine.centre_tensile_stress_MPa
            tail = f"{b:10.5f} {100 * (a - b) / b:7.2f} {w_fine:9.2f}"
        else:
            tail = f"{'-':>10s} {'-':>7s} {'-':>9s}"
        print(f"{name:38s} {t_solid:8.2f} {w_coarse:9.2f} {c_coarse:7.2f} {coarse.dofs:7d} {a:10.5f} {tail}", flush=True)


if __name__ == "__main__":
    main()
