"""Punch tips at a clearance near 0 or equal to the tablet's land: walls within a micrometre of a tablet edge.

Found by a random trial of ``tabletcad build`` over the family samples and tooling tables:

* a capsule with a 0.1 mm land tooled at 0.1 mm clearance (a rounded triangle likewise) was refused with
  "upper punch tip: OCC and manifold3d disagree on the cut: -2.03e-08 vs 240.33 mm^3": the tips follow the
  die bore, which stands the band's 1 µm bulge outside the outline, so their walls cut the land 1 µm outside
  its inner edge; OCC's splitter gave no cell and its Boolean left the prism whole.  The cut is now taken
  again with OCC's fuzzy tolerance where nothing was removed;
* an almond (no land) at clearance 0 was refused after 2 minutes with "overlap 84.4 mm^3": its tips' walls
  on the outline held the skin between them and a band bowing inward by 7e-8 mm, down to the band's middle,
  where their edges were measured (2.1 mm, not the band's 3.6), so they were cut 1.5 mm short.  A wall within
  the band's certified micrometre of the outline is now cut from the band's edge;
* a line-to-line fit (clearance 0) of a tablet whose band bulges was refused for a largest gap of 1e-6 mm
  (the bore stands the bulge out): the gap allowed is now the larger of the clearance and how far the band
  may stand inside the bore.
"""

import math

import pytest

pytest.importorskip("OCP")
pytest.importorskip("manifold3d")

from tabletcad.cad.solid import check_solid  # noqa: E402
from tabletcad.families.thesis import shallow_convex_round  # noqa: E402
from tabletcad.pipeline.design import Design  # noqa: E402
from tabletcad.tooling import ToolingSpec, make_tooling  # noqa: E402

pytestmark = pytest.mark.cad

LENGTH, WIDTH, BAND, CUP, LAND = 18.0, 8.0, 2.6, 1.0, 0.1


def _stadium_area(length: float, width: float) -> float:
    """Plan area (mm²) of a capsule outline: a rectangle of the straight sides and two half discs."""
    return (length - width) * width + math.pi * (0.5 * width) ** 2


def test_tips_inset_by_the_land_are_cut_and_pass_every_check():
    tablet = Design.from_dict({"tablet": {"family": "capsule", "length": LENGTH, "width": WIDTH, "band": BAND,
                                          "cup_depth": CUP, "land": LAND}}).build()
    tip = 3.0
    ts = make_tooling(tablet, ToolingSpec(clearance_mm=LAND, tip_length_mm=tip), check=True)
    for name, shape in ts.parts.items():
        check_solid(shape, name)
    r = ts.report
    assert all(c["ok"] for c in r["booleans"])  # each Boolean agrees with manifold3d's
    assert r["interference_mm3"] == pytest.approx(0.0, abs=1e-9) and 0.0 < r["max_gap_mm"] <= LAND
    # the tip's face is the whole cup (it starts at the land's inner edge, on the tip's wall) and the land
    # ring outside it is flat at the band's edge: tip = its prism from the band's edge up, less the cup,
    # the cup being half of what the tablet holds beyond its band (the tip's land, 1 µm wide, is flat too)
    cup = 0.5 * (r["tablet"]["volume_plain_mm3"] - _stadium_area(LENGTH, WIDTH) * BAND)
    for which in ("upper_punch", "lower_punch"):
        p = r[which]
        inset = p["tip_inset_from_outline_mm"]
        assert LAND - 2e-6 < inset <= LAND and p["land_mm"] == pytest.approx(LAND - inset, abs=1e-15)
        assert p["cup_depth_on_tip_mm"] == pytest.approx(CUP, abs=2e-6)  # its edge is the band's
        area = _stadium_area(LENGTH - 2 * inset, WIDTH - 2 * inset)
        assert p["tip_plan_area_mm2"] == pytest.approx(area, rel=1e-9)
        assert p["volume_mm3"] == pytest.approx(area * tip - cup, rel=1e-7), which


def test_tips_on_the_outline_of_a_bowed_band_end_at_its_edge():
    """The almond at clearance 0 (no land): each tip's edge is the band's, its face the whole cup, and
    its volume its prism from the band's edge less the cup (checked against manifold3d's cut)."""
    tablet = Design.from_dict({"tablet": {"family": "almond", "length": 15.0, "width": 7.5, "end_radius": 1.5,
                                          "band": 3.0, "cup_depth": 0.6}}).build()
    assert tablet.band().inward > 0.0  # the band bows inward somewhere (7e-8 mm)
    tip = 3.0
    with pytest.warns(UserWarning, match="clearance_mm = 0: the punch tips fit the die bore line to line"):
        ts = make_tooling(tablet, ToolingSpec(clearance_mm=0.0, tip_length_mm=tip), check=True,
                          interference_check=False)
    for name, shape in ts.parts.items():
        check_solid(shape, name)
    r = ts.report
    assert all(c["ok"] for c in r["booleans"])
    band_z = r["tablet"]["band_z_mm"]
    area = r["upper_punch"]["tip_plan_area_mm2"]  # the outline's (the tips stand on it)
    cup = 0.5 * (r["tablet"]["volume_plain_mm3"] - area * (band_z[1] - band_z[0]))
    for which, edge in (("upper_punch", band_z[1]), ("lower_punch", band_z[0])):
        p = r[which]
        assert p["tip_inset_from_outline_mm"] == 0.0 and p["tip_plan_area_mm2"] == pytest.approx(area, rel=1e-12)
        assert p["tip_edge_z_mm"] == edge and p["cup_depth_on_tip_mm"] == pytest.approx(0.6, abs=2e-6), which
        assert p["volume_mm3"] == pytest.approx(area * tip - cup, rel=1e-7), which


def test_a_line_to_line_fit_of_a_bulging_band_passes_the_closed_position_check():
    """The thesis's shallow convex round (its PDE band bulges 2.5 µm and bows 1.4 µm inward) at clearance 0:
    no overlap, and the largest gap within how far the band may stand inside the bore (the bore's offset,
    the bulge, plus the inward bow and the B-rep's fit to the PDE surface)."""
    t = shallow_convex_round()
    band = t.band()
    with pytest.warns(UserWarning, match="clearance_mm = 0"):
        ts = make_tooling(t, ToolingSpec(clearance_mm=0.0, tip_length_mm=5.0), check=False)
    r, f = ts.report, ts.report["interference"]
    assert r["interference_mm3"] == pytest.approx(0.0, abs=1e-9)
    assert f["gap_allowed_mm"] == ts.frame.bore_offset + band.inward + t.tol.fit and ts.frame.bore_offset >= band.bulge > 0.0
    assert 0.0 < r["max_gap_mm"] <= f["gap_allowed_mm"] and f["gap_within_clearance"]


def test_slivers_of_a_common_thinner_than_the_breps_fit_are_no_overlap():
    """An almond with 1.235 mm end arcs at 0.02 mm clearance: its band's B-spline faces, within the fit of
    its PDE surface (which the bore, 1e-6 mm out, clears), pass 7.5e-6 mm through the bore at the ends.
    OCC's Common of tablet and die gives four such slivers; they are left out as thinner than the fit, and
    the build passes (it had been refused for an overlap of 4.04e-5 mm^3)."""
    tablet = Design.from_dict({"tablet": {"family": "almond", "length": 22.56, "width": 9.997, "end_radius": 1.235,
                                          "band": 4.817, "cup_depth": 0.6}}).build()
    ts = make_tooling(tablet, ToolingSpec(clearance_mm=0.02, tip_length_mm=3.0), check=False)
    r = ts.report
    (pair,) = [p for p in r["interference"]["pairs"] if p["parts"] == ["tablet", "die"]]
    assert pair["occ_mm3"] == 0.0 and 0.0 < pair["occ_thinner_than_the_fit_mm3"] < 1e-4, pair
    assert "solids thinner than the B-rep's fit (0.0001 mm) left out" in pair["occ_method"]
    assert r["interference_mm3"] == 0.0 and 0.0 < r["max_gap_mm"] <= 0.02
