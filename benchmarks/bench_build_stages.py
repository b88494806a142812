"""Where a build's seconds go: each stage of ``build_design``, when it started and how long it took,
for the one-process build (the baseline) and the parallel build of the command line, both in this
process after a warm-up build (imports and OCC's first mesh paid), and the ratio of their totals.

Run: ``python benchmarks/bench_build_stages.py [DESIGN.toml]`` (default: the tooling sample
``samples/tooling/concave_round_bisect.toml``).  Prints figures; no assertions.  The stages overlap
in the parallel build (forked helpers draw the picture and write the tooling's files), so their
seconds do not add up to the total there.
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


def _build(design: Path, parallel: bool) -> float:
    MARKS.clear()
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        build.build_design(design, Path(tmp) / "out", progress=False, parallel=parallel)
    return time.perf_counter() - t0


def main() -> None:
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    design = Path(args[0]) if args else Path(__file__).resolve().parents[1] / "samples" / "tooling" / "concave_round_bisect.toml"
    imports = MARKS[0][2]
    for module, name in ((build, "geometry_report"), (build, "plot_tablet"), (cad_stage, "cad_stage"),
                         (cad_stage, "check_tablet_solid"), (tooling_stage, "tooling_stage"),
                         (toolset, "make_tooling"), (tooling_stage, "_check_gap"),
                         (tooling_stage, "write_finished_tablet")):
        _timed(module, name)
    warm = _build(design, parallel=False)
    print(f"{design.name}; python {sys.version.split()[0]}, {os.cpu_count()} cores, load average "
          f"{os.getloadavg()[0]:.2f}; imports {imports:.2f} s, warm-up build {warm:.2f} s")
    totals = {}
    for parallel in (False, True):
        totals[parallel] = _build(design, parallel)
        start = min(m[1] for m in MARKS)
        print(f"  {'parallel (the command line)' if parallel else 'one process (baseline)'}: {totals[parallel]:.2f} s")
        for name, t, took in sorted(MARKS, key=lambda m: m[1]):
            print(f"    {name:24s} start {t - start:6.2f} s  took {took:6.2f} s")
    print(f"  parallel / one process: {totals[True] / totals[False]:.2f}")


if __name__ == "__main__":
    main()
