"""Recompute time of a family Tablet inside FreeCAD (freecadcmd), per FreeCAD version.

Run:  .venv/bin/python benchmarks/bench_freecad.py [--repeat 5] [--families concave_round capsule]

For each FreeCAD found (Debian's 0.20 ``freecadcmd``; FreeCAD 1.0 in the ``.ci/freecad1``
root when it is built and we are root) and each family, one ``freecadcmd`` process
creates the Tablet and then times, best of ``--repeat``:

* ``change``: ``Diameter`` (or the first dimension) changed by 1 % and ``doc.recompute()``:
  the full rebuild (PDE tablet, B-spline fit, Part faces, sewing, solid, quadrature);
* ``cached``: ``Density`` changed and ``doc.recompute()``: the geometry is unchanged, so
  the workbench only rescales the weight;
* ``core``: the baseline in the same process, ``Family.build(**params)`` plus
  ``tablet.properties()`` - the pure core's share of a rebuild;

and prints ``change / core`` (what the workbench adds on top of the core) and the goal
ratio ``change / 0.5 s``.  Figures only; nothing is asserted.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

SCRIPT = r"""
import json, os, time
import FreeCAD
import freecad.tabletcad_wb  # noqa: F401  (puts the core on sys.path)
from freecad.tabletcad_wb import objects
from freecad.tabletcad_wb.make import make_tablet

cfg = json.loads(os.environ["BENCH_CFG"])
out = {}
for fam in cfg["families"]:
    doc = FreeCAD.newDocument(fam)
    t0 = time.perf_counter()
    obj = make_tablet(doc, fam)
    first = time.perf_counter() - t0
    spec = obj.Proxy.spec(obj)
    key = "diameter" if "diameter" in spec["params"] else next(iter(spec["params"]))
    prop = objects.prop_name(key)
    base = float(getattr(obj, prop).Value)
    change, cached, core = [], [], []
    for i in range(cfg["repeat"]):
        setattr(obj, prop, base * (1.01 if i % 2 == 0 else 1.0))
        t0 = time.perf_counter(); doc.recompute(); change.append(time.perf_counter() - t0)
        obj.Density = 1.2 + 0.01 * (i + 1)
        t0 = time.perf_counter(); doc.recompute(); cached.append(time.perf_counter() - t0)
        params = obj.Proxy.spec(obj)["params"]
        t0 = time.perf_counter()
        objects._family(fam).build(**params).properties()
        core.append(time.perf_counter() - t0)
    out[fam] = dict(first=first, change=min(change), cached=min(cached), core=min(core),
                    valid=bool(obj.isValid()), version=".".join(FreeCAD.Version()[:3]))
    FreeCAD.closeDocument(doc.Name)
json.dump(out, open(cfg["out"], "w"))
"""


def main() -> None:
    import freecads

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--families", nargs="+", default=["thesis.flat_faced_round", "concave_round", "thesis.ring", "capsule"])
    args = ap.parse_args()
    print(f"{'FreeCAD':8s} {'family':18s} {'first s':>8s} {'change s':>9s} {'cached s':>9s} {'core s':>8s}"
          f" {'chg/core':>9s} {'chg/0.5s':>9s}")
    for fc in freecads.FREECADS:
        if fc.cmd is None:
            print(f"{fc.version:8s} not available: {fc.missing}")
            continue
        with tempfile.TemporaryDirectory(prefix="bench-fc-") as tmp:
            script = Path(tmp) / "bench.py"
            script.write_text(SCRIPT)
            out = Path(tmp) / "out.json"
            env = freecads.clean_env()
            env.update(FREECAD_USER_HOME=tmp, TABLETCAD_ROOT=str(ROOT),
                       BENCH_CFG=json.dumps(dict(families=args.families, repeat=args.repeat, out=str(out))))
            # the workbench from this repository, as install.sh would put it
            mod = Path(tmp) / "Mod" / "tabletcad_wb" / "freecad"
            mod.mkdir(parents=True)
            (mod / "tabletcad_wb").symlink_to(ROOT / "freecad_workbench" / "freecad" / "tabletcad_wb")
            proc = subprocess.run([*fc.cmd, str(script)], env=env, cwd=tmp, capture_output=True, text=True,
                                  timeout=1800)
            if not out.exists():
                print(f"{fc.version:8s} failed: {proc.stdout[-1500:]} {proc.stderr[-1500:]}")
                continue
            res = json.loads(out.read_text())
        for fam, r in res.items():
            print(f"{r['version']:8s} {fam:18s} {r['first']:8.3f} {r['change']:9.3f} {r['cached']:9.4f} {r['core']:8.3f}"
                  f" {r['change'] / r['core']:9.2f} {r['change'] / 0.5:9.2f}" + ("" if r["valid"] else "  INVALID"))


if __name__ == "__main__":
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    main()
