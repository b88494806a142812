"""Tooling timings: one tablet (all checks), a batch of 20 sizes, manifold3d previews vs OCC exact Booleans.

Run: ``python benchmarks/bench_tooling.py``.  Prints figures; no assertions.
"""

from __future__ import annotations

import time

from tabletcad.families.thesis import shallow_convex_round
from tabletcad.tooling import ScoreSpec, ToolingSpec, make_tooling, tooling_batch
from tabletcad.tooling.booleans import TIMER, manifold_op, manifold_volume, raw_boolean, to_manifold, volume
from tabletcad.tooling.outline import offset_wire, prism, tablet_frame


def one_tablet() -> None:
    t = shallow_convex_round()
    spec = ToolingSpec(clearance_mm=0.025, scores=(ScoreSpec(depth_mm=0.3),))
    t0 = time.perf_counter()
    ts = make_tooling(t, spec)
    dt = time.perf_counter() - t0
    s = ts.report["seconds"]
    print(f"one tablet (10 mm shallow convex round, bisect, all checks): {dt:.2f} s; OCC Booleans {s['occ_booleans']:.2f} s "
          f"({100 * s['occ_booleans'] / dt:.0f} %), manifold3d {s['manifold3d']:.2f} s, interference check {s['interference']:.2f} s")
    print(f"  interference {ts.report['interference_mm3']:.3g} mm^3, max gap {ts.report['max_gap_mm']:.4g} mm, "
          f"OCC vs manifold3d max rel diff {ts.report['boolean_max_rel_diff_occ_vs_manifold3d']:.2e}")


def batch() -> None:
    sizes = [dict(diameter=d, thickness=0.3 * d, band=0.2 * d) for d in [6.0 + 0.5 * k for k in range(20)]]
    b0 = TIMER["occ_boolean_s"]
    t0 = time.perf_counter()
    rows = tooling_batch("thesis.shallow_convex_round", sizes, ToolingSpec(clearance_mm=0.02), progress=True, check=False)
    dt = time.perf_counter() - t0
    occ = TIMER["occ_boolean_s"] - b0
    worst = max(abs(r["upper_punch_rel_diff_vs_quadrature"]) for r in rows)
    print(f"batch of 20 sizes (6-15.5 mm, no cross-checks, no files): {dt:.2f} s ({dt / 20:.2f} s each); "
          f"OCC Booleans {occ:.2f} s ({100 * occ / dt:.0f} %); punch vs quadrature worst {worst:.1e}")


def preview_vs_exact() -> None:
    t = shallow_convex_round()
    fr = tablet_frame(t)
    body = prism(offset_wire(fr.outline, -0.025), 1.5, 10.5)
    for defl in (0.05, 0.01, 0.005):
        t0 = time.perf_counter()
        mt, mb = to_manifold(fr.shape, defl), to_manifold(body, defl)
        t1 = time.perf_counter()
        mv = manifold_volume(manifold_op("cut", mb, mt))
        t2 = time.perf_counter()
        print(f"  manifold3d preview at {defl} mm: mesh {t1 - t0:.3f} s + Boolean {t2 - t1:.4f} s, punch {mv:.6f} mm^3")
    t0 = time.perf_counter()
    ex = volume(raw_boolean("cut", body, fr.shape))
    print(f"  OCC exact Boolean: {time.perf_counter() - t0:.3f} s, punch {ex:.6f} mm^3")


if __name__ == "__main__":
    one_tablet()
    batch()
    print("punch tip: manifold3d preview vs OCC exact")
    preview_vs_exact()
