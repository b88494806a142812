"""``tabletcad report`` refuses what ``tabletcad build`` refuses for a design's ``[tooling]``, with the same
line, before any geometry: a spline outline, which a trial found ``report`` accepting (exit 0) while
``build`` refused it after ~2 s of CAD."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest

from tabletcad.cli import main

ROOT = Path(__file__).resolve().parents[1]
ONE_LINE = re.compile(r"^error: (\S+) = (.+) is not allowed: (.+)$")

SPLINE = """[tablet]
family = "custom_outline"
outline = [[4, 0], [3, 3], [0, 4], [-3, 3], [-4, 0], [-3, -3], [0, -4], [3, -3]]
band = 2.5
cup_depth = 0.5

[tooling]
clearance_mm = 0.02
tip_length_mm = 8.0
"""

#: an outline of lines and arcs (the custom-outline sample's "D"), which tooling takes
SEGMENTS = """[tablet]
family = "custom_outline"
segments = [
  ["line", [-2.5, -3.5], [2.5, -3.5]],
  ["arc",  [2.5, 0.0], 3.5, -1.5707963267948966, 3.141592653589793],
  ["line", [2.5, 3.5], [-2.5, 3.5]],
  ["arc",  [-2.5, 2.0], 1.5, 1.5707963267948966, 1.5707963267948966],
  ["line", [-4.0, 2.0], [-4.0, -2.0]],
  ["arc",  [-2.5, -2.0], 1.5, 3.141592653589793, 1.5707963267948966],
]
band = 2.8
cup_depth = 0.5

[tooling]
clearance_mm = 0.02
tip_length_mm = 8.0
"""


def _refusal(capsys, tmp_path: Path, design: str, command: str) -> str:
    """The one line of ``tabletcad report`` or ``build`` refusing ``design``: exit 2, nothing written."""
    src = tmp_path / "d.toml"
    src.write_text(design, encoding="utf-8")
    args = ["report", str(src), "--json-file", str(tmp_path / "r.json")] if command == "report" else \
        ["build", str(src), "--out", str(tmp_path / "out"), "--quiet"]
    assert main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and ONE_LINE.match(err[0]), err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d.toml"]
    return err[0]


# ----------------------------------------------------------------------------- spline outline (no CAD)

def test_report_refuses_tooling_of_a_spline_outline(capsys, tmp_path):
    """A custom outline through points with [tooling]: report had printed its table (exit 0); build refused it
    after the solid, OCC failing to offset the band's section for the tips and the bore."""
    line = _refusal(capsys, tmp_path, SPLINE, "report")
    assert line.startswith("error: tablet.outline = 'points (a spline through them)' is not allowed: tooling needs "
                           "an outline OpenCascade can offset")


def test_the_same_outline_of_lines_and_arcs_is_reported(tmp_path):
    src = tmp_path / "d.toml"
    src.write_text(SEGMENTS, encoding="utf-8")
    assert main(["report", str(src)]) == 0


# ----------------------------------------------------------------------------- against OpenCascade

@pytest.mark.cad
def test_report_and_build_refuse_with_the_same_line(capsys, tmp_path):
    report = _refusal(capsys, tmp_path, SPLINE, "report")
    assert report == _refusal(capsys, tmp_path, SPLINE, "build")


@pytest.mark.cad
def test_the_spline_refusal_is_occs():
    """The refusal is decided from the outline's kind: OCC's planar offset fails on the band section of every
    spline outline tried (a circle through 24 points, ovals through 8 and 64)."""
    from tabletcad.cad.tablet_solid import tablet_solid
    from tabletcad.errors import GeometryError
    from tabletcad.families.shaped import outline_tablet
    from tabletcad.tooling.outline import _section_wire, offset_wire
    from tabletcad.tooling.spec import band_heights

    for n, a, b in ((24, 5.0, 5.0), (8, 4.0, 4.0), (64, 6.0, 4.0)):
        t = outline_tablet([[a * math.cos(math.tau * k / n), b * math.sin(math.tau * k / n)] for k in range(n)],
                           band=2.5, cup_depth=0.5)
        z = band_heights(t)
        with pytest.raises(GeometryError):
            offset_wire(_section_wire(tablet_solid(t).shape, 0.5 * (z[0] + z[1])), -0.01)
