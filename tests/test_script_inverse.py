"""Inverse design (tabletcad.families.inverse.solve_for) against closed forms; cup radii in the report."""

import math

import pytest

from tabletcad.errors import DesignError
from tabletcad.families import compound_cup, concave_round, flat_face_round
from tabletcad.pipeline.designreport import design_report
from tabletcad.families.inverse import solve_for


def test_flat_faced_round_thickness_for_a_volume():
    r = solve_for("flat_face_round", target_volume_mm3=300.0, vary="thickness", diameter=10.0)
    assert r.value == pytest.approx(300.0 / (math.pi * 25.0), abs=1e-9)
    assert r.volume_mm3 == pytest.approx(300.0, rel=1e-12)
    assert r.tablet.volume() == pytest.approx(300.0, rel=1e-6)  # the PDE tablet agrees


def test_flat_faced_round_thickness_for_a_weight():
    sf, rho = 0.85, 1.52
    r = solve_for(flat_face_round, target_weight_mg=250.0, vary="thickness", diameter=8.0,
                  solid_fraction=sf, true_density_mg_mm3=rho)
    assert r.value == pytest.approx(250.0 / (sf * rho * math.pi * 16.0), abs=1e-9)
    assert r.weight_mg == pytest.approx(250.0, rel=1e-12)


def test_concave_round_band_and_cup_depth():
    a, h = 5.0, 1.0
    cap = math.pi * h * (3 * a**2 + h**2) / 6  # spherical cap on a base of radius a
    r = solve_for("concave_round", target_volume_mm3=300.0, vary="band", diameter=10.0, cup_depth=h)
    assert r.value == pytest.approx((300.0 - 2 * cap) / (math.pi * a**2), abs=1e-9)
    band = 2.0
    r = solve_for("concave_round", target_volume_mm3=260.0, vary="cup_depth", diameter=10.0, band=band)
    hh = r.value
    assert math.pi * a**2 * band + 2 * math.pi * hh * (3 * a**2 + hh**2) / 6 == pytest.approx(260.0, rel=1e-10)
    assert r.params == {"diameter": 10.0, "band": band, "cup_depth": hh}


DIMS = dict(diameter=10.0, cup_depth=1.0)  # what a concave round needs besides its band


@pytest.mark.parametrize("kw, param", [
    (dict(family="flat_face_round", vary="band", target_volume_mm3=100.0), "vary"),
    (dict(family="concave_round", vary="band", **DIMS), "target"),
    (dict(family="concave_round", vary="band", target_volume_mm3=1.0, target_weight_mg=1.0, **DIMS), "target"),
    (dict(family="concave_round", vary="band", target_weight_mg=100.0, solid_fraction=0.9, **DIMS), "true_density_mg_mm3"),
    (dict(family="concave_round", vary="band", target_volume_mm3=-5.0, **DIMS), "target_volume_mm3"),
    (dict(family="concave_round", vary="band", target_volume_mm3=300.0, diameter=10.0), "cup_depth"),  # a default stood in
    (dict(family="no_such", vary="band", target_volume_mm3=5.0), "family"),
    (dict(family="concave_round", vary="band", target_volume_mm3=5.0, length=3.0), "length"),
])
def test_bad_requests(kw, param):
    with pytest.raises(DesignError) as ei:
        solve_for(kw.pop("family"), **kw)
    assert ei.value.parameter.startswith(param)


def test_unreachable_target_names_the_range():
    # (the band at most 998 mm: with two 1 mm cups the tablet's height is at the size limit)
    with pytest.raises(DesignError, match=r"must be within \S+ to \S+ mm3 for band in \[0.001, 998\] mm"):
        solve_for("concave_round", target_volume_mm3=10.0, vary="band", diameter=10.0, cup_depth=1.0)


def test_cup_radii_in_the_design_report():
    rep = design_report(concave_round(diameter=10.0, band=2.0, cup_depth=1.0))["design_report"]
    assert rep["cup_radius_mm"] == pytest.approx((25.0 + 1.0) / 2.0, rel=1e-12)
    assert rep["cup_radii_mm"] == {"cup": pytest.approx(13.0, rel=1e-12)}
    rep = design_report(compound_cup())["design_report"]
    assert rep["cup_radii_mm"] == {"central": 15.0, "edge": 3.0} and rep["cup_radius_mm"] == 15.0
    rep = design_report(flat_face_round())["design_report"]
    assert rep["cup_radius_mm"] is None and rep["cup_radii_mm"] == {}
