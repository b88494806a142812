"""Tip-force rating (projected-area pressure rule) and Euler buckling of the tip, against closed forms."""

import math

import pytest

pytest.importorskip("OCP")

from tabletcad.pipeline.designreport import ReportOptions  # noqa: E402
from tabletcad.errors import DesignError  # noqa: E402
from tabletcad.families.thesis import shallow_convex_round  # noqa: E402
from tabletcad.tooling.outline import tablet_frame  # noqa: E402
from tabletcad.tooling.rating import section_properties, tip_rating  # noqa: E402
from tabletcad.tooling.spec import parse_tooling  # noqa: E402

pytestmark = pytest.mark.cad

SRC = "a test value, not a recommendation"


@pytest.fixture(scope="module")
def frame():
    return tablet_frame(shallow_convex_round())  # 10 mm round


def test_rating_and_buckling_are_the_closed_forms_for_a_round_tip(frame):
    spec = parse_tooling(dict(clearance_mm=0.02, tip_length_mm=8.0, lower_tip_length_mm=19.0,
                              allowed_tip_pressure_MPa=300.0, allowed_tip_pressure_source=SRC,
                              punch_youngs_modulus_MPa=210000.0, punch_youngs_modulus_source=SRC))
    r = tip_rating(frame, spec, ReportOptions(compaction_force_kN=15.0))
    rt = 5.0 - (0.02 - frame.bore_offset)  # the tip: the die bore (clearing the band's bulge) less the clearance
    assert 0.002 < frame.bore_offset < 0.003 and r["overloaded"] is False
    assert r["tip_projected_area_mm2"] == pytest.approx(math.pi * rt ** 2, rel=1e-9)
    assert r["rated_force_kN"] == pytest.approx(300.0 * math.pi * rt ** 2 / 1000.0, rel=1e-9)
    assert r["utilisation"] == pytest.approx(15.0 / r["rated_force_kN"], rel=1e-12)
    assert r["allowed_pressure_source"] == SRC
    i = math.pi * rt ** 4 / 4.0  # disc: I = pi r^4 / 4 about any diameter
    assert r["buckling"]["section_min_second_moment_mm4"] == pytest.approx(i, rel=1e-9)
    for name, L in (("upper", 8.0), ("lower", 19.0)):
        b = r["buckling"]["tips"][name]
        p_cr = math.pi ** 2 * 210000.0 * i / (2.0 * L) ** 2 / 1000.0
        assert b["buckling_load_kN"] == pytest.approx(p_cr, rel=1e-9)
        assert b["safety_factor"] == pytest.approx(p_cr / 15.0, rel=1e-9)
    # a mini-tablet tip (2 mm) of the same length buckles (1/5)^4 = 1/625 as easily
    assert r["buckling"]["tips"]["lower"]["buckling_load_kN"] / 625.0 == pytest.approx(
        math.pi ** 2 * 210000.0 * math.pi * (rt / 5) ** 4 / 4 / 38.0 ** 2 / 1000.0, rel=1e-9)


def test_rectangle_section_has_the_smaller_principal_moment():
    from tabletcad.tooling.outline import polyline_wire

    a, b = 6.0, 2.0
    area, i_min = section_properties(polyline_wire([(-a / 2, -b / 2), (a / 2, -b / 2), (a / 2, b / 2), (-a / 2, b / 2)]))
    assert area == pytest.approx(a * b, rel=1e-12)
    assert i_min == pytest.approx(a * b ** 3 / 12.0, rel=1e-9)


def test_without_a_sourced_pressure_there_is_no_rating(frame):
    r = tip_rating(frame, parse_tooling({}), None)
    assert r["rated_force_kN"] is None and "no allowed pressure" in r["note"]
    assert r["buckling"]["tips"]["upper"]["buckling_load_kN"] is None
    r = tip_rating(frame, parse_tooling({}), ReportOptions(max_punch_pressure_MPa=250.0))
    assert r["rated_force_kN"] == pytest.approx(0.25 * r["tip_projected_area_mm2"]) and "user-given" in r["allowed_pressure_source"]


def test_buckling_takes_each_tip_s_own_smallest_section(frame):
    """A complete punch's tip is relieved only beyond its straight part: the upper tip (8 mm, straight 8 mm) keeps
    its full section, the lower (25.4 mm) is relieved by 0.5 mm; the figures are the discs' (the relieved
    section had been taken for both, and its offset asked for where no relief is cut)."""
    spec = parse_tooling(dict(standard="EU", type="B", die_height_mm=22.0, tip_length_mm=8.0,
                              lower_tip_length_mm=25.4, clearance_mm=0.02, punch_youngs_modulus_MPa=210000.0,
                              punch_youngs_modulus_source=SRC,
                              punch=dict(head_diameter_mm=25.0, head_flat_diameter_mm=12.0, head_rim_mm=3.0,
                                         dome_radius_mm=30.0, neck_diameter_mm=13.0, neck_length_mm=10.0,
                                         tip_straight_mm=8.0, tip_relief_mm=0.5)))
    r = tip_rating(frame, spec, ReportOptions(compaction_force_kN=15.0))["buckling"]
    rt = 5.0 - (0.02 - frame.bore_offset)
    for name, radius, relief in (("upper", rt, 0.0), ("lower", rt - 0.5, 0.5)):
        tip = r["tips"][name]
        assert tip["relieved_by_mm"] == relief
        assert tip["section_min_second_moment_mm4"] == pytest.approx(math.pi * radius ** 4 / 4.0, rel=1e-9)
        L = tip["free_length_mm"]
        assert tip["buckling_load_kN"] == pytest.approx(
            math.pi ** 2 * 210000.0 * (math.pi * radius ** 4 / 4.0) / (2.0 * L) ** 2 / 1000.0, rel=1e-9)
    assert r["section_min_second_moment_mm4"] == pytest.approx(math.pi * (rt - 0.5) ** 4 / 4.0, rel=1e-9)


@pytest.mark.parametrize("table, parameter", [
    ({"allowed_tip_pressure_MPa": 300.0}, "allowed_tip_pressure_source"),
    ({"allowed_tip_pressure_MPa": -3.0, "allowed_tip_pressure_source": SRC}, "allowed_tip_pressure_MPa"),
    ({"punch_youngs_modulus_source": SRC}, "punch_youngs_modulus_source"),
])
def test_unsourced_or_bad_limits_are_design_errors(table, parameter):
    with pytest.raises(DesignError) as e:
        parse_tooling(table)
    assert parameter in e.value.parameter


@pytest.mark.parametrize("key, value, line", [
    # figures typed in GPa had been taken: tips rated (and buckling loads computed) a thousand times too low
    ("allowed_tip_pressure_MPa", 0.3,
     "error: tooling.allowed_tip_pressure_MPa = 0.3 MPa is not allowed: must be >= 10 and <= 10000 MPa"),
    ("allowed_tip_pressure_MPa", 3e5,
     "error: tooling.allowed_tip_pressure_MPa = 300000 MPa is not allowed: must be >= 10 and <= 10000 MPa"),
    ("punch_youngs_modulus_MPa", 210.0,
     "error: tooling.punch_youngs_modulus_MPa = 210 MPa is not allowed: must be >= 50000 and <= 1e+07 MPa"),
])
def test_sourced_figures_in_the_wrong_unit_are_refused_however_the_spec_is_made(key, value, line):
    from dataclasses import replace

    table = {key: value, key.replace("_MPa", "_source"): SRC}
    for make in (lambda: parse_tooling(table), lambda: replace(parse_tooling({}), **table)):
        with pytest.raises(DesignError) as e:
            make()
        assert f"error: {e.value}" == line
    # the range's ends are taken
    lo, hi = (10.0, 10000.0) if key.startswith("allowed") else (5e4, 1e7)
    assert [getattr(parse_tooling({**table, key: x}), key) for x in (lo, hi)] == [lo, hi]


def test_a_compaction_force_above_the_rating_is_warned_of_and_drawn(frame):
    """A force above the tips' rating is an overload: a warning, ``overloaded`` in the report and a line on
    the drawing (a 1 kN force on a 2 mm tip rated 0.924 kN had passed in silence)."""
    from tabletcad.tooling.drawing import rating_notes

    spec = parse_tooling(dict(clearance_mm=0.02, allowed_tip_pressure_MPa=300.0, allowed_tip_pressure_source=SRC))
    rated = 300.0 * math.pi * (5.0 - (0.02 - frame.bore_offset)) ** 2 / 1000.0
    force = 1.08 * rated
    with pytest.warns(UserWarning, match=r"exceeds the tips' rated force .* utilisation 1\.08"):
        r = tip_rating(frame, spec, ReportOptions(compaction_force_kN=force))
    assert r["overloaded"] is True and r["utilisation"] == pytest.approx(1.08, rel=1e-9)
    assert any(n.startswith("OVERLOADED: compaction force") for n in rating_notes(r))
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # within the rating: no warning
        ok = tip_rating(frame, spec, ReportOptions(compaction_force_kN=0.99 * rated))
    assert ok["overloaded"] is False and not any("OVERLOADED" in n for n in rating_notes(ok))
