"""Time and design builds per thesis optimisation, beside the thesis's run times.

Run: ``python benchmarks/bench_optimise.py [--method SLSQP]`` (one core).  The
thesis's MATLAB active-set runs took 27, 43, 39 and 51 minutes (section 6.2).
"""

from __future__ import annotations

import argparse
import os

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from tabletcad.optimise import solve  # noqa: E402
from tabletcad.optimise import thesis as T  # noqa: E402

CASES = [
    ("flat-faced round (6.2.1)", "flat_faced_round", lambda: T.flat_faced_round_problem(), "strength", 103.333),
    ("spherical, Fig 6.3(a)", "spherical_a", lambda: T.spherical_tablet_problem("a"), "strength", 77.1736),
    ("spherical, Fig 6.3(b)", "spherical_b", lambda: T.spherical_tablet_problem("b"), "strength", 69.1043),
    ("softgel shell (6.2.3), mu_r = 0", "softgel_capsule",
     lambda: T.softgel_capsule_problem(model="none", radius_constraints=False), "strength", 53.66),
]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--method", default="SLSQP")
    args = ap.parse_args()
    print(f"{'problem':34s} {'status':10s} {'objective':>12s} {'thesis':>9s} {'iter':>5s} {'builds':>7s} "
          f"{'time [s]':>9s} {'thesis [min]':>12s} {'speed-up':>9s}")
    for label, key, make, _, thesis_val in CASES:
        res = solve(make(), args.method)
        minutes = T.THESIS_MINUTES[key]
        print(f"{label:34s} {res.status:10s} {res.objective:12.6g} {thesis_val:9.6g} {res.iterations:5d} {res.nfev:7d} "
              f"{res.wall_time_s:9.2f} {minutes:12d} {minutes * 60 / res.wall_time_s:9.0f}x")


if __name__ == "__main__":
    main()
