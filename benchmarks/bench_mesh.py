"""Timing of tabletcad.volume_mesh.hex_mesh against the thesis's MATLAB times and a naive baseline.

Run:  .venv/bin/python benchmarks/bench_mesh.py [--family NAME]

Prints, for the node counts of the thesis's Table 4.4 (11×21×5, 21×39×6 and
41×39×6 nodes per patch; MATLAB R2008a on a 2.2 GHz Core 2 Duo took 8, 88
and 195 s) and for a mesh of about one million cells:

* the vectorised :func:`~tabletcad.volume_mesh.hex_mesh` time (best of several runs,
  one core, checks on);
* a baseline measured in the same run: a straightforward per-cell Python loop
  building the same cells (per-point evaluation of eq 4.12, node merging by a
  dictionary of rounded coordinates, cell type from the distinct corners) on
  the smallest size, extrapolated per cell to the other sizes;
* the ratio baseline / vectorised.

Figures only; nothing is asserted.
"""

from __future__ import annotations

import argparse
import os
import sys
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("MKL_NUM_THREADS", "1")

import numpy as np  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))

from tabletcad.families import FAMILIES  # noqa: E402
from tabletcad.volume_mesh import THESIS_NODES, hex_mesh, mesh_volume  # noqa: E402
from tabletcad.volume_mesh.hexahedra import _hex_volumes  # noqa: E402
from tabletcad.geometry.tablet import solid_map  # noqa: E402

MATLAB_S = {(11, 21, 5): 8.0, (21, 39, 6): 88.0, (41, 39, 6): 195.0}
CORNERS = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]


def naive_mesh(tablet, nodes) -> tuple[int, float]:
    """Per-cell loop: evaluate each corner, merge by rounded coordinates, classify."""
    t = tablet.trim
    sx, sy, sz = nodes
    u = np.linspace(t.u[0], t.u[1], sx)
    v = np.linspace(t.v[0], t.v[1], sy)
    w = np.linspace(t.w[0], t.w[1], sz)
    ids: dict[tuple, int] = {}
    pts: list[np.ndarray] = []
    n_cells = 0
    volume = 0.0
    for patch in tablet.patches:
        for i in range(sx - 1):
            for j in range(sy - 1):
                for k in range(sz - 1):
                    corner_ids = []
                    xs = []
                    for a, b, c in CORNERS:
                        x = solid_map(patch, u[i + a], v[j + b], w[k + c])
                        key = tuple(np.round(x * 1e8).astype(np.int64).tolist())
                        if key not in ids:
                            ids[key] = len(pts)
                            pts.append(x)
                        corner_ids.append(ids[key])
                        xs.append(x)
                    distinct = len(set(corner_ids))
                    if distinct < 4:
                        continue
                    vol = abs(float(_hex_volumes(np.array(xs)[None])[0]))
                    if vol <= 1e-12:
                        continue
                    n_cells += 1
                    volume += vol
    return n_cells, volume


def best_time(fn, repeat: int) -> float:
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--family", default="thesis.oblate_spheroid", help="tablet family (default: a spheroid, as Fig. 4.5)")
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args(argv)

    tab = FAMILIES[args.family].build()
    npatch = len(tab.patches)
    hex_mesh(tab, (5, 9, 3))  # warm-up (imports, caches)
    print(f"tablet: {args.family} ({npatch} patches), numpy {np.__version__}, one core")
    print(f"solid volume (triple integral of eq 4.12): {tab.solid_volume():.6f} mm^3\n")

    t0 = time.perf_counter()
    n_base, _ = naive_mesh(tab, THESIS_NODES[0])
    t_base = time.perf_counter() - t0
    per_cell = t_base / max(n_base, 1)
    print(f"baseline (per-cell Python loop) on {THESIS_NODES[0]}: {n_base} cells in {t_base:.2f} s "
          f"= {per_cell * 1e6:.0f} us/cell\n")

    rows = []
    sizes = list(THESIS_NODES) + [(71, 151, 33) if npatch == 3 else (86, 181, 34)]
    hdr = (f"{'nodes sx x sy x sz':>20} {'cells/patch':>11} {'cells':>9} {'hex_mesh s':>11} "
           f"{'Mcells/s':>9} {'baseline s':>11} {'ratio':>8} {'MATLAB s':>9} {'vol err':>9}")
    print(hdr)
    print("-" * len(hdr))
    for nodes in sizes:
        rep = args.repeat if np.prod(nodes) < 2e5 else max(2, args.repeat // 2)
        m = hex_mesh(tab, nodes)
        t = best_time(lambda: hex_mesh(tab, nodes), rep)
        base = per_cell * m.n_cells if nodes != THESIS_NODES[0] else t_base
        err = mesh_volume(m) / tab.solid_volume() - 1.0
        per_patch = (nodes[0] - 1) * (nodes[1] - 1) * (nodes[2] - 1)
        matlab = MATLAB_S.get(tuple(nodes))
        ms = f"{matlab:9.0f}" if matlab else f"{'-':>9}"
        print(f"{'x'.join(map(str, nodes)):>20} {per_patch:11d} {m.n_cells:9d} {t:11.4f} "
              f"{m.n_cells / t / 1e6:9.2f} {base:11.2f} {base / t:8.0f} {ms} {err:9.1e}")
        rows.append((nodes, m.n_cells, t))
    print("\nbaseline times above the smallest size are extrapolated per cell; MATLAB times are the")
    print("thesis's Table 4.4 (MATLAB R2008a, 2.2 GHz Core 2 Duo T7500, 800/3800/7600 cuboids).")


if __name__ == "__main__":
    main()
