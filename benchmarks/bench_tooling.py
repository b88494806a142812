"""Tooling timings beside a plain-OCC peer run in the same process.

Run: ``python benchmarks/bench_tooling.py [--no-build] [--no-preview]``.  Prints figures; no assertions.

* ``build``: ``tabletcad build samples/tooling/concave_round_bisect.toml`` end to end in a fresh
  process (import, PDE, report, CAD stage, tooling with every check, STEP/STL/GLB, drawings,
  picture), and the same tooling in this process split into its phases;
* ``one tablet``: :func:`~tabletcad.tooling.make_tooling` of a 10 mm shallow convex round with a
  bisect score and every check (manifold3d cross-checks, overlap, largest gap);
* ``batch``: :func:`~tabletcad.tooling.tooling_batch` of 20 sizes (6 to 15.5 mm, no cross-checks,
  no files), the issue 12 goal being 20 s;
* ``peer``: the same punch tips and die made the plain way, by hand in OCC - prism on the outline
  inset by the clearance minus the tablet (``BRepAlgoAPI_Cut``), die blank minus the bore prism -
  with no check, measured here in the same process: each figure is printed with its ratio to the
  peer of the same tablets, which makes runs on a loaded machine comparable.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))

from tabletcad.families import FAMILIES  # noqa: E402
from tabletcad.families.thesis import shallow_convex_round  # noqa: E402
from tabletcad.tooling import ScoreSpec, ToolingSpec, make_tooling, tooling_batch  # noqa: E402
from tabletcad.tooling.booleans import (TIMER, manifold_op, manifold_volume, raw_boolean, to_manifold,  # noqa: E402
                                        translated, volume)
from tabletcad.tooling.outline import offset_wire, prism, tablet_frame  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "samples" / "tooling" / "concave_round_bisect.toml"
FAMILY = "thesis.shallow_convex_round"
SIZES = [dict(diameter=d, thickness=0.3 * d, band=0.2 * d) for d in [6.0 + 0.5 * k for k in range(20)]]


def peer(frame, clearance: float = 0.02, tip: float = 8.0) -> float:
    """Seconds for the plain punch tips and die of ``frame``: two OCC Cuts of a prism by the tablet,
    one of a cylinder by the bore prism (no check, no unification)."""
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeCylinder
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt

    t0 = time.perf_counter()
    w = offset_wire(frame.outline, -clearance)
    zm = 0.5 * (frame.band_z[0] + frame.band_z[1])
    raw_boolean("cut", prism(w, zm, frame.band_z[1] + tip), frame.shape)
    raw_boolean("cut", prism(w, frame.band_z[0] - tip, zm), frame.shape)
    r = 0.5 * max(frame.length, frame.width) + 10.0
    blank = translated(BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), r, 22.0).Shape(),
                       dz=frame.band_z[1] + 3.0 - 22.0)
    raw_boolean("cut", blank, prism(frame.outline, frame.band_z[1] + 3.0 - 23.0, frame.band_z[1] + 4.0))
    return time.perf_counter() - t0


def build() -> None:
    from tabletcad.pipeline.design import Design
    from tabletcad.tooling.stage import write_finished_tablet, write_tooling

    import resource

    with tempfile.TemporaryDirectory() as tmp:
        c0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-m", "tabletcad", "build", str(SAMPLE), "--out", tmp], check=True,
                       capture_output=True, env=dict(os.environ, PYTHONPATH=str(ROOT)))
        wall = time.perf_counter() - t0
        c1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (c1.ru_utime - c0.ru_utime) + (c1.ru_stime - c0.ru_stime)
    d = Design.from_toml(SAMPLE)
    t = d.build()
    t0 = time.perf_counter()
    ts = make_tooling(t, d.tooling_spec, options=d.report_options)
    t1 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        write_tooling(ts, Path(tmp))
        write_finished_tablet(ts, Path(tmp))
    t2 = time.perf_counter()
    p = peer(ts.frame, d.tooling_spec.clearance_mm, d.tooling_spec.tip_length_mm)
    s, r = ts.report["seconds"], ts.report
    print(f"tabletcad build {SAMPLE.relative_to(ROOT)} (fresh process, everything): {wall:.2f} s wall, "
          f"{cpu:.2f} s CPU = {wall / p:.1f} x peer (goal 8 s)")
    print(f"  in process: tooling {t1 - t0:.2f} s (features {s['features']:.2f}, parts {s['parts']:.2f}, "
          f"closed-position check {s['interference']:.2f}: overlap {r['interference']['seconds']['overlap']:.2f} + gap "
          f"{r['interference']['seconds']['gap']:.2f}; OCC Booleans {s['occ_booleans']:.2f}, manifold3d "
          f"{s['manifold3d']:.2f}) + STEP/STL/GLB and drawings {t2 - t1:.2f} s = {(t2 - t0) / p:.1f} x peer {p:.2f} s")
    print(f"  overlap {r['interference_mm3']:.3g} mm^3, largest gap {r['max_gap_mm']:.6g} mm "
          f"(+{r['interference']['max_gap_resolution_mm'] or 0:.2g} resolution), punch vs quadrature "
          f"{r['upper_punch']['volume_rel_diff_vs_quadrature']:.1e}")


def one_tablet() -> None:
    t = shallow_convex_round()
    spec = ToolingSpec(clearance_mm=0.025, scores=(ScoreSpec(depth_mm=0.3),))
    t0 = time.perf_counter()
    ts = make_tooling(t, spec)
    dt = time.perf_counter() - t0
    p = peer(tablet_frame(t), 0.025)
    s = ts.report["seconds"]
    print(f"one tablet (10 mm shallow convex round, bisect, all checks): {dt:.2f} s = {dt / p:.1f} x peer {p:.2f} s; "
          f"OCC Booleans {s['occ_booleans']:.2f} s ({100 * s['occ_booleans'] / dt:.0f} %), manifold3d "
          f"{s['manifold3d']:.2f} s, closed-position check {s['interference']:.2f} s")
    print(f"  interference {ts.report['interference_mm3']:.3g} mm^3, max gap {ts.report['max_gap_mm']:.4g} mm, "
          f"OCC vs manifold3d max rel diff {ts.report['boolean_max_rel_diff_occ_vs_manifold3d']:.2e}")


def batch() -> None:
    b0 = TIMER["occ_boolean_s"]
    t0 = time.perf_counter()
    rows = tooling_batch(FAMILY, SIZES, ToolingSpec(clearance_mm=0.02), progress=False, check=False)
    dt = time.perf_counter() - t0
    occ = TIMER["occ_boolean_s"] - b0
    worst = max(abs(r["upper_punch_rel_diff_vs_quadrature"]) for r in rows)
    p = sum(peer(tablet_frame(FAMILIES[FAMILY].build(**size))) for size in SIZES)
    print(f"batch of 20 sizes (6-15.5 mm, no cross-checks, no files): {dt:.2f} s ({dt / 20:.2f} s each; goal 20 s) = "
          f"{dt / p:.2f} x peer {p:.2f} s; OCC Booleans {occ:.2f} s ({100 * occ / dt:.0f} %); punch vs quadrature worst "
          f"{worst:.1e}")


def preview_vs_exact() -> None:
    print("punch tip: manifold3d preview vs OCC exact")
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
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--no-build", action="store_true", help="skip the sample build")
    ap.add_argument("--no-preview", action="store_true", help="skip the manifold3d preview figures")
    a = ap.parse_args()
    print(f"machine: {os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f}; python {sys.version.split()[0]}")
    if not a.no_build:
        build()
    one_tablet()
    batch()
    if not a.no_preview:
        preview_vs_exact()
