"""Tooling for the thesis's elliptic tablets (shallow convex oval, caplet): the tips' outline is an ellipse
inset by the clearance, an offset curve OCC kept with p-curves outside its tolerance (the tips failed
BRepCheck_Analyzer); it is a B-spline within 1e-9 mm of the offset now."""

import json
import math

import pytest

pytest.importorskip("OCP")
pytest.importorskip("build123d")
pytest.importorskip("manifold3d")
pytest.importorskip("ezdxf")

from tabletcad.cad.solid import check_solid  # noqa: E402
from tabletcad.cli import main  # noqa: E402
from tabletcad.families.thesis import shallow_convex_oval  # noqa: E402
from tabletcad.tooling import ToolingSpec, make_tooling  # noqa: E402

pytestmark = pytest.mark.cad

CLEARANCE = 0.02

CAPLET_TOML = """\
[tablet]
family = "thesis.caplet"
width = 3.5
length = 7.0
height = 15.0
band = 10.0

[tooling]
clearance_mm = 0.02
tip_length_mm = 8.0
taper_deg = 0.0
"""


@pytest.fixture(scope="module")
def oval():
    """The thesis's 12 x 6 x 3 mm shallow convex oval with plain tooling (every Boolean cross-checked)."""
    with pytest.warns(UserWarning, match="the punch tips have no land"):
        return make_tooling(shallow_convex_oval(), ToolingSpec(clearance_mm=CLEARANCE, tip_length_mm=8.0))


@pytest.fixture(scope="module")
def caplet(tmp_path_factory):
    """``tabletcad build`` of the thesis's 3.5 x 7 x 15 mm caplet with a bare [tooling] table: its exit
    code, output folder and report."""
    folder = tmp_path_factory.mktemp("caplet")
    design = folder / "caplet.toml"
    design.write_text(CAPLET_TOML)
    out = folder / "out"
    code = main(["build", str(design), "--out", str(out), "--quiet"])
    report = json.loads((out / "report.json").read_text()) if code == 0 else None
    return code, out, report


def _ellipse_perimeter(a: float, b: float) -> float:
    from scipy.special import ellipe

    return 4.0 * a * float(ellipe(1.0 - (b / a) ** 2))


def _inset_ellipse_area(a: float, b: float, d: float) -> float:
    """Steiner: a convex outline of area A and perimeter L inset by d (below its least radius of curvature
    b²/a) encloses A - d L + π d²."""
    return math.pi * a * b - d * _ellipse_perimeter(a, b) + math.pi * d * d


@pytest.mark.parametrize("rx, ry", [(6.0, 3.0), (3.5, 1.75), (10.0, 2.0), (3.0, 4.0)])
@pytest.mark.parametrize("d", [-0.0162, -0.02, -0.05, 0.003])
def test_an_offset_ellipse_makes_a_valid_prism_on_the_offset(rx, ry, d):
    """OCC kept an ellipse's offset as a Geom_OffsetCurve whose p-curves on the prism's end faces strayed up
    to 9e-7 mm from it (tolerance 1e-7 mm): prism invalid at 0.0162 (the caplet's tip inset), 0.02 and 0.05 mm
    inward.  Its B-spline lies d from the ellipse (the exact offset) to 2e-9 mm, and the prism is valid."""
    import numpy as np
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeVertex
    from OCP.BRepCheck import BRepCheck_Analyzer
    from OCP.BRepExtrema import BRepExtrema_DistShapeShape
    from OCP.GeomAbs import GeomAbs_CurveType

    from tabletcad.cad._occ import explore
    from tabletcad.tooling.outline import ellipse_wire, face_area, offset_wire, plan_face, prism

    outline = ellipse_wire(rx, ry)
    wire = offset_wire(outline, d)
    assert BRepCheck_Analyzer(prism(wire, 1.5, 10.5)).IsValid()
    edges = explore(wire, "Edge")
    assert {BRepAdaptor_Curve(e).GetType() for e in edges} == {GeomAbs_CurveType.GeomAbs_BSplineCurve}
    for e in edges:
        c = BRepAdaptor_Curve(e)
        for u in np.linspace(c.FirstParameter(), c.LastParameter(), 9):
            dist = BRepExtrema_DistShapeShape(BRepBuilderAPI_MakeVertex(c.Value(u)).Vertex(), outline)
            dist.Perform()
            assert dist.Value() == pytest.approx(abs(d), abs=2e-9)
    a, b = max(rx, ry), min(rx, ry)
    assert face_area(plan_face(wire)) == pytest.approx(_inset_ellipse_area(a, b, -d), rel=1e-9)


def test_oval_parts_are_valid_and_enclose_exactly_the_tablet(oval):
    for name, shape in oval.parts.items():
        check_solid(shape, name)
    r = oval.report
    assert r["interference_mm3"] == pytest.approx(0.0, abs=1e-9)
    assert 0.0 < r["max_gap_mm"] <= CLEARANCE
    f = r["interference"]
    assert f["punch_die_clearance_mm"] == pytest.approx(CLEARANCE, abs=f["punch_die_clearance_tolerance_mm"] + 1e-7)
    assert f["punch_die_clearance_tolerance_mm"] < 1e-4


def test_oval_tip_is_inset_ellipse_times_length_minus_cup_by_quadrature(oval):
    """The tip's plan is the 12 x 6 mm ellipse inset by the clearance less the bore's growth (Steiner's
    formula), its volume that plan times the tip's length from the band's edge plane less the cup within it
    by the faces' profiles (:func:`~tabletcad.tooling.punch.elliptic_tip_quadrature`): 434.34171 mm³."""
    bore = oval.report["die"]["bore_enlarged_by_band_bulge_mm"]
    for which in ("upper_punch", "lower_punch"):
        info = oval.report[which]
        d = info["tip_inset_from_outline_mm"]
        assert d == pytest.approx(CLEARANCE - bore, abs=1e-15) and 0.0169 < d < 0.0170
        assert info["tip_plan_area_mm2"] == pytest.approx(_inset_ellipse_area(6.0, 3.0, d), rel=1e-9)
        assert info["tip_plan_area_mm2"] == pytest.approx(56.0563432, abs=1e-7)
        quad = info["volume_quadrature_mm3"]
        assert quad == pytest.approx(434.34171, abs=1e-5)
        # OCC's volume of these tips is good to ~1e-7 only (its section edges carry 5e-6 mm tolerance): the
        # adaptive integration at 1e-9 gives -1.6e-7, at 1e-11 -0.6e-7, the Gauss one -0.9e-7 to 0
        assert info["volume_rel_diff_vs_quadrature"] == pytest.approx(0.0, abs=1e-6)
        assert info["volume_mm3"] == pytest.approx(434.3416, abs=2e-4)
        # the tip's edge stands up the 0.5 mm cup where its wall meets it: 2.9 µm (the cup's slope there)
        rise = info["tip_edge_z_mm"] - 2.5 if which == "upper_punch" else 0.5 - info["tip_edge_z_mm"]
        assert 0.0029 < rise < 0.0030


def test_caplet_design_with_tooling_builds(caplet):
    """``tabletcad build`` of the caplet with [tooling] had ended with exit 2, "upper punch tip fails
    BRepCheck_Analyzer"."""
    code, out, r = caplet
    assert code == 0
    for name in ("upper_punch", "lower_punch", "die", "assembly"):
        assert (out / f"{name}.step").stat().st_size > 0
    t = r["tooling"]
    assert t["interference_mm3"] == pytest.approx(0.0, abs=1e-9)
    assert 0.0 < t["max_gap_mm"] <= CLEARANCE
    f = t["interference"]
    assert f["punch_die_clearance_mm"] == pytest.approx(CLEARANCE, abs=f["punch_die_clearance_tolerance_mm"] + 1e-7)


def test_caplet_tips_match_the_quadrature(caplet):
    """The caplet's tips: the 7 x 3.5 mm ellipse inset by 0.0162 mm, volume 126.04415 mm³ by the faces'
    profiles; its half-spheroid cups meet the tips' walls 0.337 mm above the band's edges."""
    _, _, r = caplet
    bore = r["tooling"]["die"]["bore_enlarged_by_band_bulge_mm"]
    for which in ("upper_punch", "lower_punch"):
        info = r["tooling"][which]
        d = info["tip_inset_from_outline_mm"]
        assert d == pytest.approx(CLEARANCE - bore, abs=1e-15) and 0.0161 < d < 0.0162
        assert info["tip_plan_area_mm2"] == pytest.approx(_inset_ellipse_area(3.5, 1.75, d), rel=1e-9)
        assert info["volume_quadrature_mm3"] == pytest.approx(126.04415, abs=1e-5)
        assert info["volume_rel_diff_vs_quadrature"] == pytest.approx(0.0, abs=1e-6)  # (measured -3.0e-7)
        rise = info["tip_edge_z_mm"] - 12.5 if which == "upper_punch" else 2.5 - info["tip_edge_z_mm"]
        assert rise == pytest.approx(0.3369, abs=1e-4)


def test_section_cup_is_the_round_quadrature_on_a_round_tablet():
    """The cup within a section by the faces' profiles (the elliptic tips' quadrature) is the round tips'
    :func:`~tabletcad.tooling.punch.cup_volume_within` on the thesis's shallow convex round; the elliptic
    quadrature is for ellipses only."""
    import numpy as np

    from tabletcad.families.thesis import shallow_convex_round
    from tabletcad.tooling.outline import tablet_frame
    from tabletcad.tooling.punch import _face_patches, _section_cup, cup_volume_within, elliptic_tip_quadrature

    frame = tablet_frame(shallow_convex_round())
    for which, z_e in (("upper", frame.band_z[1]), ("lower", frame.band_z[0])):
        sections = [p.section for p in _face_patches(frame, which)]
        rho = np.array([3.0, 4.5, 4.9825])
        expected = [cup_volume_within(frame, r, which) for r in rho]
        assert _section_cup(sections, rho, z_e) == pytest.approx(expected, rel=1e-12)
        assert expected[2] == pytest.approx(19.7063784, abs=1e-7)
        assert elliptic_tip_quadrature(frame, 0.02, which) is None
