"""A model speaks build123d's words: ``area``, ``bounding_box()`` and the Booleans ``-``, ``+``, ``&``
(a scripting user's trial found only ``volume`` and the ``to_*`` conversions)."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

pytest.importorskip("OCP")
bd = pytest.importorskip("build123d")

import tabletcad  # noqa: E402
from tabletcad.pipeline.model import BoundingBox  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]

pytestmark = pytest.mark.cad


def test_bounding_box_is_the_core_extents_and_agrees_with_build123d():
    m = tabletcad.make("concave_round", diameter=10, band=2, cup_depth=1)
    box = m.bounding_box()
    assert isinstance(box, BoundingBox)
    assert box.size == pytest.approx((10.0, 10.0, 4.0), abs=1e-9)  # diameter, diameter, band + 2 cups
    assert box.center() == pytest.approx((0.0, 0.0, 2.0), abs=1e-9)
    assert box.diagonal == pytest.approx(math.sqrt(216.0), abs=1e-9)
    other = m.to_build123d().bounding_box(optimal=True)  # OCC on the B-rep, an independent reading
    assert tuple(other.min) == pytest.approx(box.min, abs=1e-6)
    assert tuple(other.max) == pytest.approx(box.max, abs=1e-6)
    # a shaped tablet: length x width from its design, the PDE band within its certified distance of the
    # nominal (its band bows out by 0.28 µm)
    c = tabletcad.make("capsule", length=14, width=6, band=2, cup_depth=0.8)
    assert c.bounding_box().size == pytest.approx((14.0, 6.0, 3.6), abs=c.tablet.tol.nominal)
    assert c.bounding_box().size == pytest.approx(tuple(map(float, c.tablet.bounds()[1] - c.tablet.bounds()[0])), abs=0)


def test_area_is_the_core_quadrature_and_agrees_with_opencascade():
    m = tabletcad.make("flat_face_round", diameter=8, thickness=3)
    assert m.area == pytest.approx(2 * math.pi * 16 + 8 * math.pi * 3, rel=1e-10)
    assert m.area == pytest.approx(m.to_build123d().area, rel=1e-7)
    o = tabletcad.load(ROOT / "samples" / "families" / "oval.toml")
    assert o.area == pytest.approx(o.to_build123d().area, rel=1e-7)


def test_booleans_with_build123d_shapes_and_with_models():
    m = tabletcad.make("flat_face_round", diameter=8, thickness=3)
    pin = bd.Cylinder(1.0, 20.0)
    drilled = m - pin
    assert isinstance(drilled, bd.Shape)
    assert drilled.volume == pytest.approx(m.volume - math.pi * 3, rel=1e-7)
    # two models: a copy moved 4 mm along x overlaps the lens of two discs of radius 4 whose centres are 4 apart
    moved = m.to_build123d().moved(bd.Location((4, 0, 0)))
    lens = 2 * 16 * math.acos(0.5) - 2 * math.sqrt(64 - 16)  # 2 r² acos(d / 2r) - (d / 2) √(4r² - d²)
    assert (m & moved).volume == pytest.approx(3 * lens, rel=1e-7)
    assert (m + moved).volume == pytest.approx(2 * m.volume - 3 * lens, rel=1e-7)
    # the model is unchanged by its Booleans
    assert m.to_build123d().volume == pytest.approx(m.volume, rel=1e-7)


def test_tooling_parts_have_the_same_words():
    m = tabletcad.make("flat_face_round", diameter=8, thickness=3)
    die = m.tooling(clearance_mm=0.03).die
    box = die.bounding_box()
    od = box.size[0]
    assert box.size[1] == pytest.approx(od, abs=1e-6)
    assert die.area == pytest.approx(die.to_build123d().area, rel=1e-9)
    z = box.center()[2]
    half = die & bd.Box(od, 2 * od, 4 * box.size[2]).moved(bd.Location((od / 2, 0, z)))  # x >= 0
    assert half.volume == pytest.approx(die.volume / 2, rel=1e-9)  # a round die is symmetric about x = 0


def test_a_box_reads_as_build123d_vectors():
    box = tabletcad.make("flat_face_round", diameter=8, thickness=3).bounding_box()
    assert box.size.X == pytest.approx(8.0, abs=1e-9) and box.size.Z == pytest.approx(3.0, abs=1e-9)
    assert box.min.Y == pytest.approx(-4.0, abs=1e-9) and box.center().Z == pytest.approx(1.5, abs=1e-9)


def test_operands_that_are_not_shapes_are_a_type_error():
    m = tabletcad.make("flat_face_round", diameter=8, thickness=3)
    for other in (5, "pin", m.tooling(clearance_mm=0.03)):
        with pytest.raises(TypeError, match="unsupported operand"):
            m - other


SHAPED_CUTAWAY = r"""
import math, sys
import build123d as bd
import tabletcad
cut = tabletcad.make("oval", length=14.0, width=8.0, end_radius=3.0, band=2.0, cup_depth=1.0,
                     trim={"v": [0.0, math.pi]})
pin = bd.Cylinder(0.5, 20.0).moved(bd.Location((0.0, 1.5, 0.0)))
a, b = cut - pin, cut & pin
whole = cut.to_build123d().volume
print(a.is_valid, b.is_valid, a.volume, b.volume, whole)
"""


def test_booleans_on_a_shaped_cut_away_run_and_add_up(tmp_path):
    """A shaped cut-away keeps flat B-spline faces, on which OCC's face merging (build123d runs it after every
    Boolean) crashed the process: its Booleans skip the merge.  In a subprocess (a crash is an exit status);
    the cut and the common of the same pin add up to the cut-away."""
    import subprocess
    import sys

    p = subprocess.run([sys.executable, "-c", SHAPED_CUTAWAY],
                       capture_output=True, text=True, timeout=600, cwd=tmp_path)
    assert p.returncode == 0, (p.returncode, p.stderr[-2000:])
    a_ok, b_ok, va, vb, whole = p.stdout.split()[-5:]
    assert a_ok == "True" and b_ok == "True"
    va, vb, whole = map(float, (va, vb, whole))
    assert 0.0 < vb < math.pi * 0.25 * 4.0  # the pin's part inside (under r² π x the overall thickness)
    assert va + vb == pytest.approx(whole, rel=1e-9)
