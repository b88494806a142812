"""Bad input gives one-line DesignErrors naming parameter and range; the report CLI and section (issue 6)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from tabletcad import families as F
from tabletcad.cli import main
from tabletcad.errors import DesignError
from tabletcad.families.outline import four_arc_oval, stadium_outline


@pytest.mark.parametrize(
    "call,param,allowed",
    [
        (lambda: F.concave_round(10, 3, 6.0), "cup_depth", "<= 5 mm"),
        (lambda: F.concave_round(10, 3, 1.0, land=6.0), "land", "< 5 mm"),
        (lambda: F.capsule(18, 8, 3, 4.5), "cup_depth", "<= 4 mm"),
        (lambda: F.compound_cup(10, 2.5, 1.2, central_radius=3.0, edge_radius=4.0), "edge_radius", "< central_radius"),
        (lambda: F.compound_cup(10, 2.5, 0.2, central_radius=15.0, edge_radius=3.0), "cup_depth", "between"),
        (lambda: F.compound_cup(10, 2.5, 1.2, blend_diameter=6.0), "blend_diameter", "not both"),
        (lambda: F.ffre(10, 4, 2.5), "edge_radius", "<= 2 mm"),
        (lambda: F.ffbe(10, 4, 30, 4.0), "bevel_width", "thickness/2"),
        (lambda: F.ffbe(10, 4, 95, 0.5), "bevel_angle", "< 90"),
        (lambda: F.rounded_triangle(10, 1.5, cup_width=2.0), "cup_width", "<= 1.5 mm"),
        (lambda: F.rounded_triangle(10, 3.5), "corner_radius", "< 2.88675"),
        (lambda: F.oval(12, 7, 4.0), "end_radius", "<= 3.5 mm"),
        # as wide as long: a circle, whose end arcs vanish (it was refused as "outline = 'segment 0 of length 0'")
        (lambda: F.oval(8, 8, 3.0), "width", "must be < length = 8 mm for ends of radius 3 mm"),
        (lambda: F.almond(8, 8, 1.0), "width", "must be < length = 8 mm for ends of radius 1 mm"),
        # the true limit: an end radius of Tolerances.min_length, just above (L² + W²)/(4 W) = 12.125 mm where the
        # ends vanish (it had said "> length/2 = 9 mm")
        (lambda: F.modified_capsule(18, 8, side_radius=5.0), "side_radius", "must be >= 12.1258 mm"),
        (lambda: F.outline_tablet([[0, 0], [4, 4], [4, 0], [0, 4]]), "outline", "must not cross itself"),
        (lambda: F.outline_tablet([("line", (0, 0), (4, 0)), ("line", (4, 0), (4, 4)), ("line", (4, 4), (0, 0))]), "outline", "tangent-continuous"),
        (lambda: F.concave_round(-10, 3, 1), "diameter", "> 0"),
    ],
)
def test_bad_input_names_parameter_and_range(call, param, allowed):
    with pytest.raises(DesignError) as ei:
        call()
    msg = str(ei.value)
    assert ei.value.parameter == param
    assert allowed in msg
    assert "\n" not in msg


def test_offset_checks():
    st = stadium_outline(18, 8)
    st.check_offset(4.0, "cup_width")  # exactly the end radius: fine
    with pytest.raises(DesignError, match="cup_width"):
        st.check_offset(4.01, "cup_width")
    ov = four_arc_oval(12, 7, 2.5)
    with pytest.raises(DesignError, match="smallest corner"):
        ov.check_offset(2.6, "cup_width")
    # a peanut: ends of ~1.3 mm radius but a 1.6 mm wide waist -> refused where it is narrowest
    th = np.linspace(0, 2 * np.pi, 240, endpoint=False)
    peanut = F.shaped.as_outline(np.column_stack([7 * np.cos(th), (0.8 + 3.2 * np.cos(th) ** 2) * np.sin(th)]))
    assert peanut.min_convex_radius > 1.2
    peanut.check_offset(0.7, "cup_width")
    with pytest.raises(DesignError, match="narrowest") as ei:
        peanut.check_offset(1.0, "cup_width")
    lim = peanut.offset_limit()
    assert 0.7 < lim < 1.0 and f"{lim:.6g}" in str(ei.value)


def test_outline_offsets_are_exact():
    ov = four_arc_oval(14, 8, 3.0)
    v = np.linspace(0, 2 * np.pi, 1001)
    O, T, N, k = ov.frame(v)
    for d in (0.5, 1.5, 2.9):
        assert np.allclose(ov.signed_distance(O + d * N), d, atol=1e-12)
    # arcs offset to concentric arcs: distance of the right end offset to its centre
    hx = 7 - 3.0
    pts = O[np.abs(O[:, 1]) < 0.5] + 1.0 * N[np.abs(O[:, 1]) < 0.5]
    right = pts[pts[:, 0] > 0]
    assert np.allclose(np.hypot(right[:, 0] - hx, right[:, 1]), 2.0, atol=1e-12)


def test_custom_outline_from_points_and_items():
    th = np.linspace(0, 2 * np.pi, 60, endpoint=False)
    pts = np.column_stack([6 * np.cos(th), 4 * np.sin(th)])  # an ellipse given as points
    t = F.outline_tablet(pts, band=2.5, cup_depth=0.4, cup_width=1.0)
    assert t.nominal.certificate.passed
    d = F.sweep_properties(t)
    assert d["plan_area_mm2"] == pytest.approx(math.pi * 24, rel=2e-3)  # spline through the points


BAD = {
    "cup too deep": '[tablet]\nfamily = "concave_round"\ndiameter = 10.0\nband = 3.0\ncup_depth = 7.0\n',
    "land too wide": '[tablet]\nfamily = "concave_round"\ndiameter = 10.0\nband = 3.0\ncup_depth = 1.0\nland = 5.5\n',
    "radii not tangent": '[tablet]\nfamily = "compound_cup"\ndiameter = 10.0\ncentral_radius = 2.0\nedge_radius = 3.0\n',
    "self-intersecting": '[tablet]\nfamily = "custom_outline"\noutline = [[0, 0], [4, 4], [4, 0], [0, 4]]\nband = 2.0\ncup_depth = 0.3\n',
    "bad report key": '[tablet]\nfamily = "concave_round"\n[report]\nweight = 3\n',
    "bad solid fraction": '[tablet]\nfamily = "concave_round"\n[report]\nsolid_fraction = 1.5\n',
    "flat centre too narrow": '[tablet]\nfamily = "modified_capsule"\nlength = 15.875\nwidth = 11.376\ncup_depth = 0.476\n',
}


def test_cup_width_at_the_corner_radius_splits_a_narrow_plateau():
    """A wide modified capsule cupped to its corner radius (the default) leaves a flat centre whose
    rim's ends have collapsed; the plateau's inner curve shrinks until it fits (it had stopped at
    λ = 0.1 and refused the default, naming cup_width): the default and the same width given build."""
    t = F.modified_capsule(length=15.875, width=11.376, cup_depth=0.476)
    r = t.nominal.outline.min_convex_radius
    assert t.nominal.info["cup_width_mm"] == pytest.approx(r, rel=1e-12) and t.nominal.certificate.passed
    assert F.modified_capsule(length=15.875, width=11.376, cup_depth=0.476, cup_width=r).nominal.certificate.passed


@pytest.mark.parametrize("case", sorted(BAD))
def test_cli_bad_design_exits_2_and_writes_nothing(tmp_path, capsys, case):
    d = tmp_path / "bad.toml"
    d.write_text(BAD[case])
    out = tmp_path / "rep.json"
    assert main(["report", str(d), "--json-file", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error:")
    assert not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.toml"]


def test_cli_build_bad_family_design_exits_2(tmp_path):
    d = tmp_path / "bad.toml"
    d.write_text(BAD["cup too deep"])
    out = tmp_path / "out"
    assert main(["build", str(d), "--out", str(out), "--quiet"]) == 2
    assert not out.exists()


def test_cli_report_writes_json_with_units(tmp_path, capsys):
    d = tmp_path / "c.toml"
    d.write_text('[tablet]\nfamily = "concave_round"\ndiameter = 10.0\nband = 2.8\ncup_depth = 0.9\nland = 0.08\n'
                 '[report]\nsolid_fraction = 0.85\ntrue_density_mg_mm3 = 1.5\nbreaking_force_N = 100.0\n')
    out = tmp_path / "rep.json"
    assert main(["report", str(d), "--json-file", str(out), "--compaction-force", "15", "--max-punch-pressure", "300"]) == 0
    text = capsys.readouterr().out
    assert "cup volume" in text and "tensile strength" in text and "FDA size" in text
    rep = json.loads(out.read_text())
    r = rep["design_report"]
    R, a, h = 5.0, 4.92, 0.9
    cap = math.pi * h * (3 * a * a + h * h) / 6
    V = math.pi * R * R * 2.8 + 2 * cap
    assert r["volume_mm3"] == pytest.approx(V, rel=1e-6)
    assert r["cup_volume_mm3"] == pytest.approx(cap, rel=1e-5)
    assert r["weight_mg"] == pytest.approx(V * 0.85 * 1.5, rel=1e-6)
    assert r["overall_thickness_mm"] == pytest.approx(4.6)
    assert r["shape_factor"] == pytest.approx(0.09)
    assert r["plan_perimeter_mm"] == pytest.approx(10 * math.pi)
    t = r["tensile_strength"]
    assert "Pitt" in t["formula"]
    den = 2.84 * 4.6 / 10 - 0.126 * 4.6 / 2.8 + 3.15 * 2.8 / 10 + 0.01
    assert t["tensile_strength_MPa"] == pytest.approx(10 * 100 / (math.pi * 100 * den), rel=1e-12)
    pc = r["punch_tip_check"]
    assert pc["ok"] is True and pc["allowed_force_kN"] == pytest.approx(300 * math.pi * 25 / 1000)
    assert "user-given" in pc["limit_basis"]
    assert r["fda_size"]["ok"] is True
    assert rep["nominal_max_deviation_um"] <= 1.0 and rep["nominal_certified"]
    assert all("g1" in s and "expected_sharp" in s for s in rep["seams"])


def test_design_report_is_part_of_the_geometry_report():
    from tabletcad.pipeline.report import geometry_report

    rep = geometry_report(F.compound_cup())
    assert rep["nominal_max_deviation_um"] <= 1.0
    assert rep["design_report"]["cup_depth_mm"] == pytest.approx(1.2)
    kinds = [(s["g1"], s["expected_sharp"]) for s in rep["seams"]]
    assert all(g1 != sharp for g1, sharp in kinds)
    assert (True, False) in kinds and (False, True) in kinds


def test_design_files_of_every_family_build(tmp_path):
    from pathlib import Path

    from tabletcad.cli.report import load_family_design

    root = Path(__file__).resolve().parents[1] / "samples" / "families"
    names = sorted(p.stem for p in root.glob("*.toml"))
    assert {f.__name__ for f in F.FAMILY_FUNCTIONS} <= set(names)
    for n in ("concave_round", "capsule", "custom_outline"):
        t, _ = load_family_design(root / f"{n}.toml")
        assert t.nominal.certificate.passed


@pytest.mark.parametrize("length", [7.5, 9.0, 12.75])
def test_elongated_strength_below_pitt_heasleys_ratio(length):
    """Pitt & Heasley's 2/3 of the round value holds from length/width 1.7 (eq 2.9).  A capsule as long as
    wide is the round tablet of its width (eq 2.7: the same solid's strength); in between no formula is
    published, so no value but the range from eq 2.9 to eq 2.7 (it had been eq 2.9's, up to a third low)."""
    from tabletcad.pipeline.designreport import ReportOptions, design_report

    W, band, h, F_N = 7.5, 3.0, 1.0, 100.0
    T = band + 2 * h
    round_ = 10 * F_N / (math.pi * W * W * (2.84 * T / W - 0.126 * T / band + 3.15 * band / W + 0.01))  # eq 2.7
    ts = design_report(F.capsule(length, W, band, h), ReportOptions(breaking_force_N=F_N))["design_report"]["tensile_strength"]
    if length == W:
        assert ts["tensile_strength_MPa"] == pytest.approx(round_, rel=1e-12) and "eq 2.7" in ts["formula"]
        same = design_report(F.concave_round(W, band, h), ReportOptions(breaking_force_N=F_N))["design_report"]
        assert same["tensile_strength"]["tensile_strength_MPa"] == pytest.approx(ts["tensile_strength_MPa"], rel=1e-12)
    elif length / W < 1.7:
        assert ts["tensile_strength_MPa"] is None and ts["within_range"] is False
        assert ts["tensile_strength_range_MPa"] == pytest.approx([2 / 3 * round_, round_], rel=1e-12)
        assert ts["range_flags"][0].startswith("length/width = 1.2 < 1.7")
    else:
        assert ts["tensile_strength_MPa"] == pytest.approx(2 / 3 * round_, rel=1e-12) and "eq 2.9" in ts["formula"]


def test_elongated_strength_uses_pitt_heasley():
    from tabletcad.pipeline.designreport import ReportOptions, design_report

    t = F.capsule(18, 8, 2.0, 1.2)
    r = design_report(t, ReportOptions(breaking_force_N=150.0))["design_report"]
    ts = r["tensile_strength"]
    assert "Pitt & Heasley" in ts["formula"]
    den = 2.84 * 4.4 / 8 - 0.126 * 4.4 / 2.0 + 3.15 * 2.0 / 8 + 0.01
    assert ts["tensile_strength_MPa"] == pytest.approx(2 / 3 * 10 * 150 / (math.pi * 64 * den), rel=1e-12)
    flat = design_report(F.flat_face_round(10, 3), ReportOptions(breaking_force_N=100.0))["design_report"]
    assert flat["tensile_strength"]["tensile_strength_MPa"] == pytest.approx(200 / (math.pi * 30))
    tri = design_report(F.rounded_triangle(), ReportOptions(breaking_force_N=100.0))["design_report"]
    assert tri["tensile_strength"]["tensile_strength_MPa"] is None
    big = design_report(F.capsule(23, 9, 3, 1.0))["design_report"]
    assert big["fda_size"]["ok"] is False and big["weight_mg"] is None


def test_a_smoothing_parameter_that_fails_the_certificate_is_named(tmp_path, capsys):
    """A family's ``a`` (0.01 by default) taken so large that the PDE surface leaves the 1 µm certificate
    is refused naming ``tablet.a`` (it was a line naming no parameter); a moderate one builds."""
    base = '[tablet]\nfamily = "capsule"\nlength = 16.0\nwidth = 7.0\nband = 3.0\ncup_depth = 1.0\n'
    d = tmp_path / "a1.toml"
    d.write_text(base + "a = 1.0\n")
    out = tmp_path / "out"
    assert main(["build", str(d), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1
    assert err[0].startswith("error: tablet.a = 1 is not allowed: must leave the PDE surface within 1 µm of the "
                             "capsule's nominal (it deviates ")
    assert not out.exists()
    with pytest.raises(DesignError) as ei:
        F.capsule(16, 7, 3, 1, a=1.0)
    assert ei.value.parameter == "a"
    t = F.capsule(16, 7, 3, 1, a=0.05)  # within the certificate
    assert t.nominal.certificate.passed
