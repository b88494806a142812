"""Where a build's seconds go: each stage of ``build_design`` in one process, when it started and how
long it took, for the parallel build of the command line and for the one-process build.

Run: ``python benchmarks/bench_build_stages.py [DESIGN.toml] [--sequential]`` (default: the tooling
sample ``samples/tooling/concave_round_bisect.toml``).  Prints figures; no assertions.  The stages
overlap in the parallel build (forked helpers draw the picture and write the tooling's files), so
their seconds do not add up to the total there.
"""

from __future__ import annotations

import os
import sys
import tempfile
import time

T0 = time.perf_counter()
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))

import functools  # noqa: E402
from pathlib import Path  # noqa: E402

import tabletcad.cad.stage as cad_stage  # noqa: E402
import tabletcad.pipeline.build as build  # noqa: E402
import tabletcad.tooling.stage as tooling_stage  # noqa: E402
import tabletcad.tooling.toolset as toolset  # noqa: E402

MARKS: list[tuple[str, float, float]] = [("imports", 0.0, time.perf_counter() - T0)]


def _timed(module, name: str) -> None:
    f = getattr(module, name)

    @functools.wraps(f)
    def g(*a, **k):
        t = time.perf_counter()
        try:
            return f(*a, **k)
        finally:
            MARKS.append((name, t - T0, time.perf_counter() - t))

    setattr(module, name, g)


def main() -> None:
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    design = Path(args[0]) if args else Path(__file__).resolve().parents[1] / "samples" / "tooling" / "concave_round_bisect.toml"
    parallel = "--sequential" not in sys.argv
    for module, name in ((build, "geometry_report"), (build, "plot_tablet"), (cad_stage, "cad_stage"),
                         (cad_stage, "check_tablet_solid"), (tooling_stage, "tooling_stage"),
                         (toolset, "make_tooling"), (tooling_stage, "_check_gap"),
                         (tooling_stage, "write_finished_tablet")):
        _timed(module, name)
    with tempfile.TemporaryDirectory() as tmp:
        build.build_design(design, Path(tmp) / "out", progress=False, parallel=parallel)
    total = time.perf_counter() - T0
    print(f"{design.name}, {'parallel (the command line)' if parallel else 'one process'}; python "
          f"{sys.version.split()[0]}, {os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f}")
    for name, start, took in sorted(MARKS, key=lambda m: m[1]):
        print(f"  {name:24s} start {start:6.2f} s  took {took:6.2f} s")
    print(f"  {'total':24s} {total:6.2f} s (plus Python's start and exit)")


if __name__ == "__main__":
    main()
