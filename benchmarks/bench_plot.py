"""Benchmark of tablet pictures: time per stage of ``tabletcad.plot`` for three families.

Figures, measured in the same run: the whole picture (``tablet_png``: sampling, the
three panels and the PNG encoding), the side profile alone (sampling, silhouette,
plan outline, polished bounds) as the baseline, and the figure without the PNG
encoding.  The target is 100 ms per picture; no assertion on time.

Run: ``python benchmarks/bench_plot.py``.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tabletcad.families import capsule, concave_round, flat_face_round  # noqa: E402
from tabletcad.plot import side_profile, tablet_figure, tablet_png  # noqa: E402


def _best(f, n: int = 3) -> float:
    best = float("inf")
    for _ in range(n):
        t0 = time.perf_counter()
        f()
        best = min(best, time.perf_counter() - t0)
    return best


def main() -> None:
    cases = [("flat_face_round", flat_face_round()), ("concave_round", concave_round()), ("capsule", capsule())]
    print(f"{'family':18s} {'picture ms':>11s} {'profile ms':>11s} {'figure only ms':>15s} {'png/profile':>12s}")
    for name, t in cases:
        tablet_png(t)  # warm caches (fonts, imports)
        png = _best(lambda: tablet_png(t))
        prof = _best(lambda: side_profile(t))
        fig = _best(lambda: tablet_figure(t))
        print(f"{name:18s} {png * 1e3:11.0f} {prof * 1e3:11.0f} {fig * 1e3:15.0f} {png / prof:12.1f}")


if __name__ == "__main__":
    main()
