"""Refusals state the true range and name a parameter the design gave (session 35's trial).

Each refusal: exactly one line ``error: <parameter> = <value> is not allowed: <range>``, exit
status 2, nothing written; and values just inside each stated range are taken (built through the
core API, without the CAD stage, except the tests marked ``cad``).

* a modified capsule's side radius had been refused "> length/2 = 9.5 mm" below the true limit
  (L² + W²)/(4 W), where its ends vanish, which a second message then gave;
* a cup width left out (the default: as wide as the outline allows) had been refused naming
  ``cup_width``, from a rounded triangle's corner radius of 3 mm of its allowed < 3.175 mm on and from
  a modified capsule's side radius of 100 mm: the plateau's inner curve stopped shrinking at λ = 0.1;
* a thesis ring 11.999 mm inside 12 had been refused naming ``trim.w``, a curve's ``z = true`` naming
  ``center``, a flat-face round 0.001 mm across naming the family, and a diameter of 1000.001 mm
  had been shown as ``1000 mm`` beside "must be within ±1000 mm";
* a reshaped tablet had built 1501 mm wide (the limit is an overall dimension, as a diameter's).
"""

from __future__ import annotations

import math
import re

import pytest

from tabletcad import families as F
from tabletcad.cli import main
from tabletcad.errors import DesignError, format_bound
from tabletcad.families.outline import four_arc_oval_from_side_radius
from tabletcad.pipeline.design import Design

ONE_LINE = re.compile(r"^error: (\S+) = (.+) is not allowed: (.+)$")
MC = '[tablet]\nfamily = "modified_capsule"\nlength = 19.0\nwidth = 8.5\nband = 3.4\ncup_depth = 0.6\n'
TRI = '[tablet]\nfamily = "rounded_triangle"\nside = 11\nband = 2.6\ncup_depth = 0.6\n'
FREE = ('[tablet]\nfamily = "free_form"\n[[patch]]\ncurves = [{type="circle", radius=0.0, z=true},'
        '{type="circle", radius=4.0, z=0.0},{type="circle", radius=4.0, z=3.0},{type="circle", radius=0.0, z=3.0}]\n')
LEAST = ("a part the dimensions leave must be at least 0.001 mm (Tolerances.min_length, the least length a design "
         "takes) or, where the family allows it, none")


@pytest.mark.parametrize("text, line", [
    (MC + "side_radius = 9.51\n", "error: tablet.side_radius = 9.51 mm is not allowed: must be >= 12.7435 mm for a "
     "19 x 8.5 mm oval (its end radius would be below 0.001 mm, Tolerances.min_length)"),
    (MC + "side_radius = 4.0\n", "error: tablet.side_radius = 4 mm is not allowed: must be >= 12.7435 mm for a "
     "19 x 8.5 mm oval (its end radius would be below 0.001 mm, Tolerances.min_length)"),
    (TRI + "corner_radius = 3.2\n", "error: tablet.corner_radius = 3.2 mm is not allowed: must be > 0 and < 3.17542 mm"),
    (TRI + "corner_radius = 3.17542\ncup_width = 3.17542\n", "error: tablet.cup_width = 3.17542 mm is not allowed: "
     "must be <= 3.17442 mm (cupped further in, the flat centre would reach less than 0.001 mm from the centroid "
     "(Tolerances.min_length), too narrow to build)"),
    ('[tablet]\nfamily = "thesis.ring"\nouter_diameter = 12.0\ninner_diameter = 11.999\nthickness = 4.5\n',
     "error: tablet.inner_diameter = 11.999 mm is not allowed: must be > 0 and <= 11.988 mm"),
    (FREE, "error: patch[0].curves[0].z = true is not allowed: must be a number (true and false are not numbers)"),
    ('[tablet]\nfamily = "flat_face_round"\ndiameter = 0.001\nthickness = 0.001\n',
     f"error: tablet.diameter = 0.001 mm is not allowed: leaves a flat face of 0.0005 mm: {LEAST}"),
    ('[tablet]\nfamily = "concave_round"\ndiameter = 1000.001\nband = 100\ncup_depth = 50\n',
     "error: tablet.diameter = 1000.001 mm is not allowed: must be within ±1000 mm (size limit, Tolerances.max_length)"),
    ('[tablet]\nfamily = "thesis.flat_faced_round"\ndiameter = 10\nthickness = 6\n[reshape]\nradius = 150\n',
     "error: reshape = {'radius': 150} is not allowed: must keep the tablet's length, width and height at most "
     "1000 mm (size limit, Tolerances.max_length, as a diameter or length; the largest is 1500.76 mm)"),
    ('[tablet]\nfamily = "concave_round"\ndiameter = 10.0\nband = 2.8\ncup_depth = 0.9\n[reshape]\nradius = 150\n',
     "error: reshape = {'radius': 150} is not allowed: must keep the tablet's length, width and height at most "
     "1000 mm (size limit, Tolerances.max_length, as a diameter or length; the largest is 1500 mm)"),
], ids=["side_radius_951", "side_radius_4", "corner_radius", "cup_width_centre", "ring", "z_true", "ffr_tiny",
        "diameter_1000.001", "reshape_ffr", "reshape_concave"])
def test_refusal_is_one_line_exit_2_nothing_written(tmp_path, capsys, text, line):
    design = tmp_path / "d.toml"
    design.write_text(text, encoding="utf-8")
    out = tmp_path / "out"
    assert main(["build", str(design), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [line] and ONE_LINE.match(err[0])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d.toml"]


def _stated_bound(exc: DesignError, sign: str) -> float:
    return float(re.search(rf"{re.escape(sign)} (-?[0-9.e+-]+) mm", exc.allowed).group(1))


def test_side_radius_just_inside_its_stated_range_is_taken():
    with pytest.raises(DesignError) as err:
        F.modified_capsule(19.0, 8.5, side_radius=9.51, band=3.4, cup_depth=0.6)
    lo = _stated_bound(err.value, ">=")
    t = Design.from_dict({"tablet": dict(family="modified_capsule", length=19.0, width=8.5, side_radius=lo,
                                         band=3.4, cup_depth=0.0)}).build()
    assert t.nominal.certificate.passed and t.nominal.outline.min_convex_radius >= 0.001 * (1 - 1e-9)
    # the end radius it gives limits the cup depth, named as cup_depth (a parameter the design gave)
    with pytest.raises(DesignError) as deep:
        Design.from_dict({"tablet": dict(family="modified_capsule", length=19.0, width=8.5, side_radius=lo,
                                         band=3.4, cup_depth=0.6)}).build()
    assert deep.value.parameter == "tablet.cup_depth"


@pytest.mark.parametrize("L, W", [(19.0, 8.5), (18.0, 8.0), (5.0, 4.999), (1000.0, 0.01)])
def test_side_radius_limit_is_the_least_that_builds_an_outline(L, W):
    with pytest.raises(DesignError) as err:
        four_arc_oval_from_side_radius(L, W, L / 2.0)
    lo = _stated_bound(err.value, ">=")
    assert four_arc_oval_from_side_radius(L, W, lo).min_convex_radius >= 0.001 * (1 - 1e-9)
    with pytest.raises(DesignError):
        four_arc_oval_from_side_radius(L, W, lo * (1 - 1e-5))


R_IN = 11.0 / (2.0 * math.sqrt(3.0))


@pytest.mark.parametrize("r", [2.9, 3.0, 3.1, 3.17, 3.175, 3.1754, 3.17542])
def test_the_default_cup_width_builds_up_to_the_largest_corner_radius(r):
    assert r < float(format_bound(R_IN, upper=True)) + 1e-12  # inside the stated "< 3.17542 mm"
    t = F.rounded_triangle(side=11, corner_radius=r, band=2.6, cup_depth=0.6)
    assert t.nominal.certificate.passed
    assert t.nominal.info["cup_width_mm"] == pytest.approx(min(r, R_IN - 0.001), abs=1e-9)


@pytest.mark.parametrize("side_radius", [60.0, 100.0, 200.0, 500.0, 1000.0])
def test_the_default_cup_width_builds_for_any_side_radius(side_radius):
    t = F.modified_capsule(19.0, 8.5, side_radius=side_radius, band=3.4, cup_depth=0.6)
    assert t.nominal.certificate.passed
    assert t.nominal.info["cup_width_mm"] == pytest.approx(t.nominal.outline.min_convex_radius, rel=1e-12)


@pytest.mark.parametrize("make", [
    lambda: F.rounded_rectangle(14, 8, 3.9999, band=3, cup_depth=0.6),
    lambda: F.rounded_square(9, 4.4995, band=3, cup_depth=0.6),
    lambda: F.oval(12, 7, 3.4999, band=3, cup_depth=0.6),
], ids=["rectangle", "square", "oval"])
def test_the_default_cup_width_builds_where_the_plateau_is_narrowest(make):
    assert make().nominal.certificate.passed


def test_a_cup_width_at_its_stated_bound_is_taken():
    with pytest.raises(DesignError) as err:
        F.rounded_triangle(side=11, corner_radius=3.175, band=2.6, cup_depth=0.6, cup_width=3.175)
    bound = _stated_bound(err.value, "<=")
    assert bound < 3.175
    assert F.rounded_triangle(side=11, corner_radius=3.175, band=2.6, cup_depth=0.6,
                              cup_width=bound).nominal.certificate.passed


def test_ring_inner_diameter_at_its_stated_bound_is_taken():
    for outer, inner in ((12.0, 11.988), (1.0, 0.998), (1000.0, 999.0)):
        t = F.family("thesis.ring").build(outer_diameter=outer, inner_diameter=inner, thickness=4.5)
        assert t.trim.w == pytest.approx((inner / outer, 1.0))
    with pytest.raises(DesignError, match=r"^outer_diameter = 0.002 mm is not allowed: must be > 0.002 mm"):
        F.family("thesis.ring").build(outer_diameter=0.002, inner_diameter=0.001, thickness=4.5)


def test_a_reshaped_tablet_just_inside_the_size_limit_is_taken():
    t = Design.from_dict({"tablet": dict(family="thesis.flat_faced_round", diameter=10, thickness=6),
                          "reshape": {"radius": 99.9}}).build()
    lo, hi = t.bounds()
    assert 999.0 < max(hi - lo) <= 1000.0
    t = Design.from_dict({"tablet": dict(family="concave_round", diameter=1000.0, band=100, cup_depth=50)}).build()
    assert t.params["diameter"] == 1000.0
    # at the limit itself, whatever the bounds' rounding (a review: 1000.0000000000003 across was refused)
    for tablet, radius in ((dict(diameter=10.0, thickness=3.0), 100.0), (dict(diameter=1000.0, thickness=3.0), 1.0)):
        t = Design.from_dict({"tablet": dict(family="flat_face_round", **tablet), "reshape": {"radius": radius}}).build()
        lo, hi = t.bounds()
        assert max(hi - lo) == pytest.approx(1000.0, rel=1e-12)


@pytest.mark.parametrize("x", [3.1754264805429417, 12.743410214, 2.0 / 3.0, 1e-7 / 3.0, 123456.789, -3.14159265])
def test_a_stated_bound_holds_every_value_it_states(x):
    hi, lo = float(format_bound(x, upper=True)), float(format_bound(x, upper=False))
    assert hi <= x <= lo and (hi == lo == x or abs(lo - hi) <= 2e-5 * abs(x))
    assert format_bound(9.5, upper=True) == "9.5" and format_bound(1000.0, upper=False) == "1000"


def test_a_value_is_shown_as_given():
    assert str(DesignError("d", 1000.001, "must be within ±1000 mm", "mm")).startswith("d = 1000.001 mm")
    assert str(DesignError("d", 10.0, "x", "mm")).startswith("d = 10 mm")
    assert str(DesignError("d", 4.097723610557038, "x", "mm")).startswith("d = 4.09772 mm")  # a computed value


@pytest.mark.cad
@pytest.mark.parametrize("text", [TRI + "corner_radius = 3.17542\n", MC + "side_radius = 1000.0\n"],
                         ids=["triangle_largest_corner", "capsule_side_1000"])
def test_the_default_cup_width_reaches_the_solid(tmp_path, capsys, text):
    design = tmp_path / "d.toml"
    design.write_text(text, encoding="utf-8")
    assert main(["build", str(design), "--out", str(tmp_path / "out")]) == 0
    assert (tmp_path / "out" / "tablet.step").exists()


def test_an_outline_of_lines_and_arcs_has_its_true_centroid():
    """The plateau's fan and the cup-width limits start from the centroid: a rounded triangle's is its
    centre (it had been 0.068 mm off at a corner radius of 3 mm), an irregular one's the polygon's."""
    import numpy as np

    from tabletcad.families.outline import rounded_polygon

    R = 11.0 / math.sqrt(3.0)
    tri = rounded_polygon([(R * math.cos(t), R * math.sin(t)) for t in (-math.pi / 6, math.pi / 2, 7 * math.pi / 6)], 3.0)
    assert np.allclose(tri.centroid(), 0.0, atol=1e-12)
    ol = rounded_polygon([(1.0, 1.0), (5.0, 1.0), (1.0, 4.0)], 0.3)
    p = ol.point(np.linspace(0.0, math.tau, 200001)[:-1])
    x, y = p[:, 0], p[:, 1]
    x1, y1 = np.roll(x, -1), np.roll(y, -1)
    cross = x * y1 - x1 * y
    area = cross.sum() / 2.0
    assert np.allclose(ol.centroid(), [(x + x1) @ cross / (6 * area), (y + y1) @ cross / (6 * area)], atol=1e-8)


def test_a_refusal_of_a_default_says_so(tmp_path, capsys):
    """A parameter left out that is refused is named with its default, said as such."""
    design = tmp_path / "d.toml"
    design.write_text('[tablet]\nfamily = "capsule"\nlength = 18.0\nwidth = 8.0\nband = 3.0\ncup_depth = 1.2\n'
                      'central_radius = 10.0\n', encoding="utf-8")
    assert main(["build", str(design), "--out", str(tmp_path / "out")]) == 2
    assert capsys.readouterr().err.strip().splitlines() == [
        "error: tablet.edge_radius = 0 mm is not allowed: must be > 0 for a compound cup (give both radii, or neither) "
        "(edge_radius is not given: the value it takes by default)"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d.toml"]


def test_a_curve_without_its_height_is_refused_not_placed_at_zero(tmp_path, capsys):
    """The stadium sample with its first curve's ``z = 0.0`` left out had built (the curve put at z = 0 by
    default, exit 0): a height guessed.  A curve needs ``z`` or ``center``, or ``[x, y, z]`` points."""
    from pathlib import Path

    sample = (Path(__file__).resolve().parents[1] / "samples" / "free_form_stadium.toml").read_text(encoding="utf-8")
    text = sample.replace('{ type = "circle", radius = 0.0, z = 0.0 }', '{ type = "circle", radius = 0.0 }', 1)
    assert text != sample
    design = tmp_path / "d.toml"
    design.write_text(text, encoding="utf-8")
    assert main(["build", str(design), "--out", str(tmp_path / "out")]) == 2
    assert capsys.readouterr().err.strip().splitlines() == [
        "error: patch[0].curves[0].z = (not given) is not allowed: a circle curve needs its height z (mm) or its "
        "center [x, y, z] (mm)"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d.toml"]
