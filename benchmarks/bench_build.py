"""``tabletcad build`` end to end (a new process: imports, PDE tablet, report, solid, checks,
STEP/STL/GLB, picture) beside the hand-built peer's whole process.

Run:  .venv/bin/python benchmarks/bench_build.py [--repeat 5] [samples/families/concave_round.toml ...]

The peer is a new Python process that imports build123d, revolves a 10 mm round
tablet's profile of exact lines and an arc (band 3 mm, cup 1 mm), checks it is
valid, takes its volume and writes STEP and STL at 0.005 mm / 0.2 rad: what a
CAD user would script by hand.  The two commands are run alternately, ``--repeat``
times each, and the best wall times are compared: the issue's goal is a ratio of
at most 1.5.  Figures only; nothing is asserted.
"""

from __future__ import annotations

import argparse
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PY = sys.executable
TABLETCAD = str(Path(PY).with_name("tabletcad"))

PEER = r"""
import sys
from build123d import (Axis, BuildLine, BuildPart, BuildSketch, Line, Plane, ThreePointArc, export_step,
                       export_stl, make_face, revolve)
with BuildPart() as p:
    with BuildSketch(Plane.XZ):
        with BuildLine():
            ThreePointArc((0, -2.5), (2.5, -2.2574), (5, -1.5)); Line((5, -1.5), (5, 1.5))
            ThreePointArc((5, 1.5), (2.5, 2.2574), (0, 2.5)); Line((0, 2.5), (0, -2.5))
        make_face()
    revolve(axis=Axis.Z)
s = p.part
assert s.is_valid and s.volume > 0
export_step(s, sys.argv[1] + "/peer.step")
export_stl(s, sys.argv[1] + "/peer.stl", tolerance=0.005, angular_tolerance=0.2)
"""


def _run(cmd: list[str]) -> float:
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("designs", nargs="*", default=[str(ROOT / "samples" / "families" / "concave_round.toml"),
                                                   str(ROOT / "samples" / "flat_faced_round.toml")])
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    print(f"python {platform.python_version()}, {os.cpu_count()} cores, load {os.getloadavg()[0]:.2f}; "
          f"best of {args.repeat} alternating runs, wall seconds")
    with tempfile.TemporaryDirectory() as tmp:
        peer_py = Path(tmp) / "peer.py"
        peer_py.write_text(PEER)
        for design in args.designs:
            peer, ours = [], []
            for i in range(args.repeat):
                peer.append(_run([PY, str(peer_py), tmp]))
                ours.append(_run([TABLETCAD, "build", design, "--out", str(Path(tmp) / f"out{i}"), "--quiet"]))
            print(f"  {Path(design).stem:22s} tabletcad build {min(ours):6.2f} s   peer process {min(peer):6.2f} s"
                  f"   ratio {min(ours) / min(peer):5.2f}  (goal <= 1.5)")


if __name__ == "__main__":
    main()
