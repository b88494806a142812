"""The tablet-die overlap proofs of every family sample, timed in CPU seconds.

Run: ``python benchmarks/bench_overlap.py [NAME ...]``.  Prints figures; no assertions.

For each sample of ``samples/families`` (or the ones named), the tooling of the family samples' test
(``ToolingSpec(clearance_mm=0.02, taper_deg=1.0)``, no checks) and then, each timed alone by the
process's CPU time (user + system, every thread):

* ``column``: :func:`~tabletcad.tooling.interference.inside_bore`, the two exact Commons with the
  bore's column (the proof the overlap check tries first);
* ``distance + common``: the proof it replaced and falls back on, ``BRepExtrema_DistShapeShape`` of
  the tablet and the die and, when that finds them within 1e-7 mm, the fuzzy (1e-6 mm) Common of the
  tablet with the tapered die.
"""

from __future__ import annotations

import os
import resource
import sys
import warnings
from pathlib import Path

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))

from tabletcad.cli.report import load_family_design  # noqa: E402
from tabletcad.tooling import ToolingSpec, make_tooling  # noqa: E402
from tabletcad.tooling.booleans import raw_boolean, volume  # noqa: E402
from tabletcad.tooling.die import bore_wire  # noqa: E402
from tabletcad.tooling.interference import _distance_shapes, inside_bore  # noqa: E402
from tabletcad.tooling.spec import MIN_BORE_OFFSET_MM  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def cpu() -> float:
    """This process's CPU time so far (s), user + system, all threads."""
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def old_proof(tablet, die) -> str:
    """The distance-then-fuzzy-Common proof of a zero overlap; what it found."""
    d = _distance_shapes(tablet, die)
    if d.IsDone() and d.Value() > 1e-7:
        return f"apart by {d.Value():.3g} mm"
    return f"fuzzy Common {volume(raw_boolean('common', tablet, die, fuzzy=MIN_BORE_OFFSET_MM)):.3g} mm^3"


def main(names: list[str]) -> None:
    paths = sorted((ROOT / "samples" / "families").glob("*.toml"))
    paths = [p for p in paths if not names or p.stem in names]
    total_new = total_old = 0.0
    print(f"machine: {os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f}; python {sys.version.split()[0]}")
    print(f"{'sample':18s} {'column s':>9s} {'old s':>7s} {'ratio':>6s}  old proof found")
    for path in paths:
        tablet, _ = load_family_design(path)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            ts = make_tooling(tablet, ToolingSpec(clearance_mm=0.02, taper_deg=1.0), check=False,
                              interference_check=False)
        t, d = ts.parts["tablet"], ts.parts["die"]
        c0 = cpu()
        ok = inside_bore(t, d, bore_wire(ts.frame))
        c1 = cpu()
        found = old_proof(t, d)
        c2 = cpu()
        total_new, total_old = total_new + c1 - c0, total_old + c2 - c1
        print(f"{path.stem:18s} {c1 - c0:9.2f} {c2 - c1:7.2f} {(c1 - c0) / max(c2 - c1, 1e-9):6.2f}  {found}"
              + ("" if ok else "  (column proof failed)"),
              flush=True)
    print(f"{'total':18s} {total_new:9.2f} {total_old:7.2f} {total_new / max(total_old, 1e-9):6.2f}"
          "  (CPU seconds, user + sys; ratio: the column proof over the old one, in this process)")
    print("load average", " ".join(f"{x:.2f}" for x in os.getloadavg()),
          f"; peak resident memory {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MiB")


if __name__ == "__main__":
    main(sys.argv[1:])
