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
* the CPU time the workers spend per design (``ru_utime + ru_stime``), which a
  shared, loaded machine changes far less than the wall-clock rate, and the
  share of a core used meanwhile by this process (client, scheduler, nannies);
* projections of the wall time of 10^6 designs on N workers: (a)
  ``1e6 / (N x one-worker rate x efficiency)``, the efficiency being the
  measured two-worker speed-up / 2; (b) ``1e6 x worker CPU per design / N``,
  i.e. N idle cores and a scheduler that keeps up (not measured at that scale).

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


def _cpu_s() -> float:
    import resource

    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def _serial(designs: list[dict]) -> tuple[float, float]:
    """Wall and CPU seconds per design of the loop in this process."""
    t0, c0 = time.perf_counter(), _cpu_s()
    for d in designs:
        r = evaluate_design(d, name="bench")
        assert r["status"] == "ok", r["error"]
    return (time.perf_counter() - t0) / len(designs), (_cpu_s() - c0) / len(designs)


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
    print(f"serial loop in this process: {serial_runs[0][0]:.3f} s/design, CPU {serial_runs[0][1]:.3f} s/design "
          f"(load {os.getloadavg()[0]:.1f})")
    rates, cpu = {}, {}
    for n in (1, 2):
        t0 = time.perf_counter()
        with open_client(n) as client:
            client.wait_for_workers(n)
            t1 = time.perf_counter()
            client.run(evaluate_design, designs[0], name="bench")  # every worker imports tabletcad once
            w0, c0 = client.run(_cpu_s), _cpu_s()
            t2 = time.perf_counter()
            df = run_sweep(spec, client=client, progress=False)
            t3 = time.perf_counter()
            w1, c1 = client.run(_cpu_s), _cpu_s()
            rss = client.run(_peak_rss_mb)
        cpu[n] = (sum(w1[k] - w0[k] for k in w1) / len(designs), (c1 - c0) / (t3 - t2))
        ok = int((df["status"] == "ok").sum())
        rates[n] = len(designs) / (t3 - t2)
        print(f"{n} worker{'s' if n > 1 else ' '}: start-up {t1 - t0:5.2f} s + warm-up {t2 - t1:5.2f} s, "
              f"{len(designs)} designs ({ok} ok) in {t3 - t2:7.2f} s = {rates[n]:.3f} designs/s "
              f"(load {os.getloadavg()[0]:.1f}); peak memory per worker " + ", ".join(f"{v:.0f} MB" for v in rss.values()))
        print(f"          CPU: workers {cpu[n][0]:.3f} s per design; this process (client, scheduler, nannies) "
              f"{cpu[n][1]:.1%} of one core while the sweep ran")
    serial_runs.append(_serial(designs[: args.serial]))
    serial = sum(r[0] for r in serial_runs) / 2
    serial_cpu = sum(r[1] for r in serial_runs) / 2
    print(f"serial loop again: {serial_runs[1][0]:.3f} s/design, CPU {serial_runs[1][1]:.3f} s/design; "
          f"mean {serial:.3f} s/design ({1 / serial:.3f} designs/s), CPU {serial_cpu:.3f} s/design")
    speedup = rates[2] / rates[1]
    overhead = 1 / rates[1] - serial
    print(f"speed-up 2 workers / 1 worker (wall clock): {speedup:.2f}x (efficiency {speedup / 2:.0%})")
    print(f"overhead per design, 1 worker vs serial loop: wall {overhead * 1000:+.1f} ms ({overhead / serial:+.1%}); "
          f"worker CPU {(cpu[1][0] - serial_cpu) * 1000:+.1f} ms ({(cpu[1][0] - serial_cpu) / serial_cpu:+.1%}), "
          f"plus this process's {cpu[1][1] / rates[1] * 1000:.1f} ms of CPU per design at that rate")
    eff = min(1.0, speedup / 2)
    wcpu = max(cpu[1][0], cpu[2][0])
    print("projection for 10^6 designs: (a) from the wall-clock rate of one worker and the two-worker efficiency")
    print(f"(this machine's load included); (b) on N idle cores from the workers' CPU time, {wcpu:.3f} s per design")
    for n in (1, 2, 16, 64, 256):
        a = 1e6 / (n * rates[1] * (eff if n > 1 else 1.0))
        b = 1e6 * wcpu / n
        print(f"  {n:4d} workers: (a) {a / 3600:9.1f} h   (b) {b / 3600:9.1f} h")


if __name__ == "__main__":
    main()
