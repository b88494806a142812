"""Benchmark of the automatic Heckel window on long records, against an exhaustive baseline in the same run.

1. ``fit_heckel_arrays`` with the automatic window (noise estimate, chi-square
   lack-of-fit test, widest run) on synthetic loading branches of 1e3, 1e5 and
   1e6 rows (Heckel line K = 0.005 1/MPa, A = 1, a rearrangement term
   0.4 e^{-P/15} and noise σ = 1e-3): time, peak memory of the Python heap
   (tracemalloc) and the recovered Py, window and estimated σ.
2. Baseline: the same rule with every run tested (the exhaustive search
   tabletcad uses up to 4096 points, O(n²)), on 5e3 and 1e4 rows, with the
   time ratio and the two windows.
3. The whole command path: reading a CSV export of 1e5 and 1e6 rows
   (``Upper Punch Force (kN)``, ``Punch displacement (µm)``, ``;`` and decimal
   commas), compaction curves and the automatic fit.

Run: ``.venv/bin/python benchmarks/bench_heckel.py`` (no assertions on time).
"""

from __future__ import annotations

import sys
import tempfile
import time
import tracemalloc
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import tabletcad.mechanics.heckel as hk  # noqa: E402
from tabletcad.mechanics.compaction import compaction_curves  # noqa: E402
from tabletcad.mechanics.pressdata import read_press_data  # noqa: E402

warnings.simplefilter("ignore")


def record(n: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    P = np.linspace(1.0, 250.0, n)
    return P, 0.005 * P + 1.0 - 0.4 * np.exp(-P / 15.0) + rng.normal(0.0, 1e-3, n)


def measure(fn):
    tracemalloc.start()
    t = time.perf_counter()
    out = fn()
    dt = time.perf_counter() - t
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return out, dt, peak


def describe(f) -> str:
    lo, hi = f.window_MPa
    return f"Py {f.Py_MPa:8.3f} MPa, window {lo:6.2f}-{hi:6.2f} MPa ({f.n_points} pts), σ {f.noise_sd:.3g}"


def main() -> None:
    hk.fit_heckel_arrays(*record(100)[:1], heckel=record(100)[1])  # warm-up: imports
    print("1. automatic window (sampled starts and bisection above 4096 points)")
    for n in (10**3, 10**5, 10**6):
        P, H = record(n)
        f, dt, peak = measure(lambda: hk.fit_heckel_arrays(P, heckel=H))
        print(f"  n = {n:>8}: {dt:7.3f} s, peak heap {peak / 2**20:7.1f} MiB ({peak / n:5.0f} B/row); {describe(f)}")

    print("2. exhaustive search (every run tested) vs the automatic rule")
    saved = hk.EXHAUSTIVE_MAX
    for n in (5000, 10**4):
        P, H = record(n)
        hk.EXHAUSTIVE_MAX = 10**9
        slow, t_slow, _ = measure(lambda: hk.fit_heckel_arrays(P, heckel=H))
        hk.EXHAUSTIVE_MAX = saved
        fast, t_fast, _ = measure(lambda: hk.fit_heckel_arrays(P, heckel=H))
        print(f"  n = {n:>8}: exhaustive {t_slow:7.3f} s, default {t_fast:7.3f} s, ratio {t_slow / t_fast:6.1f}x")
        print(f"    exhaustive: {describe(slow)}")
        print(f"    default:    {describe(fast)}")

    print("3. command path: read a kN/µm ';' decimal-comma export, curves, automatic fit")
    meta = {"mass_mg": 300.0, "true_density": 1.3, "diameter": 10.0}
    for n in (10**5, 10**6):
        P, H = record(n)
        D = 1.0 - np.exp(-H)
        area = np.pi * 25.0
        h = meta["mass_mg"] / (meta["true_density"] * area * D)
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "run.csv"
            lines = [f"{f / 1000:.9f};{-x * 1000:.6f}".replace(".", ",") for f, x in zip(P * area, h)]
            path.write_text("Upper Punch Force (kN);Punch displacement (µm)\n" + "\n".join(lines) + "\n")
            t = time.perf_counter()
            rec = read_press_data(path, meta)
            t_read = time.perf_counter() - t
            t = time.perf_counter()
            f = hk.fit_heckel(compaction_curves(rec))
            t_fit = time.perf_counter() - t
        print(f"  n = {n:>8}: read {t_read:6.2f} s, curves + fit {t_fit:6.2f} s; {describe(f)}")


if __name__ == "__main__":
    main()
