"""Benchmark of tablet pictures: time per stage of ``tabletcad.pipeline.plot`` for three families.

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
from tabletcad.pipeline.plot import side_profile, tablet_figure, tablet_png  # noqa: E402


def _best(factory, f, n: int = 3) -> float:
    """Best of ``n`` runs of ``f(tablet)``, each on a tablet just built by ``factory`` (a tablet caches
    its polished bounds, so a second call on the same one would not pay for them)."""
    best = float("inf")
    for _ in range(n):
        t = factory()
        t0 = time.perf_counter()
        f(t)
        best = min(best, time.perf_counter() - t0)
    return best


def main() -> None:
    cases = [("flat_face_round", flat_face_round), ("concave_round", concave_round), ("capsule", capsule)]
    print(f"{'family':18s} {'picture ms':>11s} {'profile ms':>11s} {'figure only ms':>15s} {'png/profile':>12s}")
    for name, factory in cases:
        tablet_png(factory())  # warm caches (fonts, imports)
        png = _best(factory, tablet_png)
        prof = _best(factory, side_profile)
        fig = _best(factory, tablet_figure)
        print(f"{name:18s} {png * 1e3:11.0f} {prof * 1e3:11.0f} {fig * 1e3:15.0f} {png / prof:12.1f}")


if __name__ == "__main__":
    main()
