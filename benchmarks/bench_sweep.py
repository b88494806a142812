"""Throughput of a concave-round sweep (report only) on the sweep engine, against the serial loop.

Run: ``.venv/bin/python benchmarks/bench_sweep.py [--designs 1000] [--serial 20]``.

A Latin hypercube over diameter (8-12 mm), band (2-3.6 mm) and cup depth
(0.5-1.4 mm) of a concave round tablet.  Measured in one process:

* the serial loop: :func:`tabletcad.sweep.engine.evaluate_design` over the first
  ``--serial`` designs in this process (s/design), before and after the cluster
  runs (their mean is the baseline, which evens out a changing machine load);
* a local Dask cluster of one worker process and one of two (cluster start-up
  and each worker's first import of tabletcad timed apart): designs/s, the speed-up of two workers over one, the peak
  resident memory of each worker (``ru_maxrss``), and the engine's overhead per
  design (one worker's time per design minus the serial loop's);
* a projection of the wall time of 10^6 designs on N workers:
  ``1e6 / (N x one-worker rate x efficiency)``, the efficiency being the
  measured two-worker speed-up / 2 (an estimate: it assumes N idle cores).

The default of 1,000 designs takes about 1,000 x the serial time per design
per worker count; use ``--designs`` for a shorter run (the figures printed
name the count actually run).
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from tabletcad.sweep import parse_sweep  # noqa: E402
from tabletcad.sweep.engine import evaluate_design, open_client  # noqa: E402
from tabletcad.sweep.run import run_sweep  # noqa: E402


def _sweep(n: int) -> dict:
    return {"design": {"tablet": {"family": "concave_round", "diameter": 10.0, "band": 2.8, "cup_depth": 0.9,
                                  "land": 0.08},
                       "report": {"solid_fraction": 0.85, "true_density_mg_mm3": 1.5, "breaking_force_N": 100.0}},
            "sweep": {"method": "lhs", "samples": n, "seed": 2026,
                      "vary": {"tablet.diameter": {"min": 8.0, "max": 12.0}, "tablet.band": {"min": 2.0, "max": 3.6},
                               "tablet.cup_depth": {"min": 0.5, "max": 1.4}}}}


def _peak_rss_mb() -> float:
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0  # kB on Linux


def _serial(designs: list[dict]) -> float:
    t0 = time.perf_counter()
    for d in designs:
        r = evaluate_design(d, name="bench")
        assert r["status"] == "ok", r["error"]
    return (time.perf_counter() - t0) / len(designs)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--designs", type=int, default=1000, help="designs per cluster run (default 1000)")
    ap.add_argument("--serial", type=int, default=20, help="designs in the serial loop (default 20)")
    args = ap.parse_args()
    spec = parse_sweep(_sweep(args.designs))
    designs = spec.designs()
    print(f"concave-round Latin hypercube sweep, report only: {len(designs)} designs per cluster run, "
          f"{min(args.serial, len(designs))} in the serial loop; {os.cpu_count()} CPUs, load "
          f"{os.getloadavg()[0]:.1f} at start")
    evaluate_design(designs[0], name="bench")  # imports and caches warm, as in a worker after its first task
    serial_runs = [_serial(designs[: args.serial])]
    print(f"serial loop in this process: {serial_runs[0]:.3f} s/design (load {os.getloadavg()[0]:.1f})")
    rates = {}
    for n in (1, 2):
        t0 = time.perf_counter()
        with open_client(n) as client:
            client.wait_for_workers(n)
            t1 = time.perf_counter()
            client.run(evaluate_design, designs[0], name="bench")  # every worker imports tabletcad once
            t2 = time.perf_counter()
            df = run_sweep(spec, client=client, progress=False)
            t3 = time.perf_counter()
            rss = client.run(_peak_rss_mb)
        ok = int((df["status"] == "ok").sum())
        rates[n] = len(designs) / (t3 - t2)
        print(f"{n} worker{'s' if n > 1 else ' '}: start-up {t1 - t0:5.2f} s + warm-up {t2 - t1:5.2f} s, "
              f"{len(designs)} designs ({ok} ok) in {t3 - t2:7.2f} s = {rates[n]:.3f} designs/s "
              f"(load {os.getloadavg()[0]:.1f}); peak memory per worker " + ", ".join(f"{v:.0f} MB" for v in rss.values()))
    serial_runs.append(_serial(designs[: args.serial]))
    serial = sum(serial_runs) / 2
    print(f"serial loop again: {serial_runs[1]:.3f} s/design; mean {serial:.3f} s/design ({1 / serial:.3f} designs/s)")
    speedup = rates[2] / rates[1]
    overhead = 1 / rates[1] - serial
    print(f"speed-up 2 workers / 1 worker: {speedup:.2f}x (efficiency {speedup / 2:.0%})")
    print(f"overhead per design (1 worker vs serial loop): {overhead * 1000:+.1f} ms ({overhead / serial:+.1%})")
    eff = min(1.0, speedup / 2)
    print("projection for 10^6 designs at the measured one-worker rate and two-worker efficiency:")
    for n in (1, 2, 16, 64, 256):
        s = 1e6 / (n * rates[1] * (eff if n > 1 else 1.0))
        print(f"  {n:4d} workers: {s / 3600:9.1f} h")


if __name__ == "__main__":
    main()
