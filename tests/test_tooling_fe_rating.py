"""The tip-force rating beside the drawing from the FE punch analysis (``[tooling.fe_rating]``): the
figure a tooling build prints is the one ``tabletcad fe punch`` gives for the same design, and the
report holds it beside the projected-area pressure rule's, each with its source."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

pytest.importorskip("OCP")
pytest.importorskip("skfem")
pytest.importorskip("gmsh")

from tabletcad.cli import main  # noqa: E402
from tabletcad.errors import DesignError  # noqa: E402
from tabletcad.tooling.spec import parse_tooling  # noqa: E402

pytestmark = [pytest.mark.cad, pytest.mark.fe]

STEEL = "S7_tempered_205C"
DESIGN = f"""
[tablet]
family = "concave_round"
diameter = 8.0
band = 2.0
cup_depth = 0.6
land = 0.1

[report]
compaction_force_kN = 12.0

[tooling]
clearance_mm = 0.02
tip_length_mm = 6.0
allowed_tip_pressure_MPa = 300.0
allowed_tip_pressure_source = "test value"

[tooling.fe_rating]
steel = "{STEEL}"
safety_factor = 1.5
mesh_size_mm = 1.0
"""


@pytest.fixture(scope="module")
def design(tmp_path_factory) -> Path:
    p = tmp_path_factory.mktemp("fe_rating") / "design.toml"
    p.write_text(DESIGN)
    return p


@pytest.fixture(scope="module")
def built(design):
    out = design.parent / "out"
    assert main(["build", str(design), "--out", str(out), "--quiet"]) == 0
    return out, json.loads((out / "report.json").read_text(encoding="utf-8"))


def test_drawing_states_the_fe_rating_of_tabletcad_fe_punch(built, design, capsys):
    out, rep = built
    capsys.readouterr()
    assert main(["fe", "punch", str(design), "--force", "12", "--steel", STEEL, "--mesh-size", "1.0", "--json"]) == 0
    cli = json.loads(capsys.readouterr().out)
    fe = rep["tooling"]["tip_rating"]["fe"]
    assert fe["allowed_force_kN"] == pytest.approx(cli["allowed_force_kN"], rel=1e-9)
    assert fe["tips"]["upper"]["max_von_mises_MPa"] == pytest.approx(cli["max_von_mises_MPa"], rel=1e-9)
    assert fe["force_kN"] == 12.0 and fe["utilisation"] == pytest.approx(12.0 / cli["allowed_force_kN"])
    svg = (out / "drawing.svg").read_text(encoding="utf-8")
    from tabletcad.tooling.rating import rating_text

    assert f"{rating_text(cli['allowed_force_kN'])} kN" in svg  # (rounded down: a rating is never drawn above itself)
    assert "FE punch analysis" in svg
    from tabletcad.tooling.drawing import rating_notes

    first, second = rating_notes(rep["tooling"]["tip_rating"])
    assert first.startswith(f"tip force rating {rating_text(cli['allowed_force_kN'])} kN (FE punch analysis")
    assert second.startswith("pressure-rule rating")


def test_report_holds_both_ratings_with_their_sources(built):
    _, rep = built
    r = rep["tooling"]["tip_rating"]
    # the pressure rule: 300 MPa over the tip's plan area, a circle of radius 4 - clearance
    import math

    assert r["rated_force_kN"] == pytest.approx(300.0 * math.pi * 3.98 ** 2 / 1000.0, rel=1e-9)
    assert r["allowed_pressure_source"] == "test value"
    from tabletcad.fe.punch import tool_steels

    steel = tool_steels()[STEEL]
    fe = r["fe"]
    assert (fe["yield_MPa"], fe["yield_source"]) == (steel.yield_MPa, steel.yield_source)
    assert fe["youngs_modulus_source"] == steel.E_source and fe["safety_factor"] == 1.5
    # the cup and the stress concentration: the FE rating lies below yield/S x tip area
    assert fe["allowed_force_kN"] < steel.yield_MPa / 1.5 * math.pi * 3.98 ** 2 / 1000.0


def test_without_fe_rating_the_drawing_keeps_the_pressure_rule():
    from tabletcad.tooling.drawing import rating_notes

    r = dict(rated_force_kN=14.9, allowed_pressure_MPa=300.0, tip_projected_area_mm2=49.76, allowed_pressure_source="x")
    for fe in (None, {"allowed_force_kN": None, "note": "not computed: the fe extra"}):
        (line,) = rating_notes({**r, "fe": fe})
        assert line.startswith("tip force rating 14.9 kN = 300 MPa x 49.76 mm2")


@pytest.mark.parametrize("table, parameter", [
    ({"steel": "NoSuchSteel"}, "steel"),
    ({}, "steel"),
    ({"steel": STEEL, "yield_stress_MPa": 1400.0}, "steel"),
    ({"yield_stress_MPa": 1400.0}, "yield_stress_source"),
    ({"yield_stress_MPa": -1.0, "yield_stress_source": "x"}, "yield_stress_MPa"),
    # a yield stress in pascals (1.45e9) had been taken: the punch rated at 2508 kN
    ({"yield_stress_MPa": 1.45e9, "yield_stress_source": "x"}, "yield_stress_MPa"),
    # and one in GPa (1.45 for S7's 1450 MPa): below any punch steel (tabletcad.tolerance.MIN_YIELD_MPA, as fe punch's)
    ({"yield_stress_MPa": 1.45, "yield_stress_source": "x"}, "yield_stress_MPa"),
    ({"steel": STEEL, "punch": "middle"}, "punch"),
    ({"steel": STEEL, "safety_factor": 0.0}, "safety_factor"),
    ({"steel": STEEL, "bogus": 1}, "bogus"),
])
def test_bad_fe_rating_is_one_design_error(table, parameter):
    with pytest.raises(DesignError) as e:
        parse_tooling({"fe_rating": table})
    assert parameter in e.value.parameter and "\n" not in str(e.value)


def test_a_mesh_size_too_fine_for_the_tip_is_named_by_the_design_key(monkeypatch):
    """``[tooling.fe_rating] mesh_size_mm`` finer than the tip's memory allows is refused naming that key
    (it had been named ``--mesh-size``, the command's option).  The tip is a stand-in: the size is
    checked against its plan area and length before it is meshed."""
    import tabletcad.fe.punch as P

    tip = dict(tip_plan_area_mm2=78.54, tip_length_mm=19.0)
    monkeypatch.setattr(P, "tool_set_tip", lambda ts, which: (None, tip))
    rating = parse_tooling({"fe_rating": {"steel": STEEL, "mesh_size_mm": 0.05}}).fe_rating
    with pytest.raises(DesignError) as e:
        P.fe_tip_rating(None, rating)
    assert str(e.value).startswith("tooling.fe_rating.mesh_size_mm = 0.05 mm is not allowed: must be >= ")


def test_fe_rating_spec():
    r = parse_tooling({"fe_rating": {"yield_stress_MPa": 1400.0, "yield_stress_source": "mill certificate",
                                     "punch": "both"}}).fe_rating
    assert r.punches == ("upper", "lower") and r.safety_factor == 1.5 and r.steel is None
    assert parse_tooling({}).fe_rating is None


def test_fe_rating_note_stays_inside_the_sheet(built, design):
    """The longer rating notes still fit the title block: every text inside the sheet, none on another."""
    import matplotlib.pyplot as plt

    from tabletcad.pipeline.design import Design
    from tabletcad.tooling import make_tooling
    from tabletcad.tooling.drawing import drawing_model, sheet_figure

    _, rep = built
    d = Design.from_toml(design)
    ts = make_tooling(d.build(), d.tooling_spec, check=False, interference_check=False, options=d.report_options)
    ts.report["tip_rating"]["fe"] = rep["tooling"]["tip_rating"]["fe"]
    dr = drawing_model(ts)
    assert any("FE punch analysis" in n for n in dr.notes)
    fig = sheet_figure(dr, rep["tooling"]["drawing"]["paper"])
    try:
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        texts = [t for t in fig.texts + fig.axes[0].texts if t.get_text()]
        boxes = [(t.get_text(), t.get_window_extent(renderer)) for t in texts]
        assert any("FE punch analysis" in s for s, _ in boxes)
        for s, bb in boxes:
            assert fig.bbox.x0 <= bb.x0 and bb.x1 <= fig.bbox.x1 and fig.bbox.y0 <= bb.y0 and bb.y1 <= fig.bbox.y1, s
        for k, (sa, a) in enumerate(boxes):
            for sb, b in boxes[k + 1:]:
                assert not a.expanded(0.98, 0.9).overlaps(b.expanded(0.98, 0.9)), (sa, sb)
    finally:
        plt.close(fig)


def test_complete_punches_are_rated_on_their_tips():
    """With complete punches (TSM B) the analysis takes the tip alone, the solid fused to the barrel:
    its volume is the report's tip volume, and its rating is the tips-only tooling's for the same tablet."""
    from tabletcad.fe.punch import fe_tip_rating, tool_set_tip
    from tabletcad.pipeline.design import Design
    from tabletcad.tooling import make_tooling
    from tabletcad.tooling.booleans import volume
    from tabletcad.tooling.spec import FeRatingSpec

    sample = Path(__file__).resolve().parents[1] / "samples" / "tooling" / "tsm_b_round.toml"
    d = Design.from_toml(sample)
    tablet, spec = d.build(), d.tooling_spec
    assert spec.body is not None
    rating = FeRatingSpec(steel=STEEL, mesh_size_mm=1.0)
    ts = make_tooling(tablet, spec, check=False, interference_check=False)
    shape, info = tool_set_tip(ts, "upper")
    assert volume(shape) == pytest.approx(ts.report["upper_punch"]["tip_volume_mm3"], rel=1e-9)
    tips_only = make_tooling(tablet, spec.with_(body=None), check=False, interference_check=False)
    full, alone = fe_tip_rating(ts, rating, 10.0), fe_tip_rating(tips_only, rating, 10.0)
    assert full["allowed_force_kN"] == pytest.approx(alone["allowed_force_kN"], rel=1e-9)
    assert 0.0 < full["allowed_force_kN"] < 1450.0 / 1.5 * info["tip_plan_area_mm2"] / 1000.0
