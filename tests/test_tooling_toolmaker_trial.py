"""Tooling a toolmaker would refuse or misread (session 26's trial): a modified standard punch labelled as
the standard, tips too short for their cups, V scores too narrow to make, bounds quoted that were refused in
turn, heads smaller than their barrels, and a batch that stopped half-way with files written.

Each refusal: the one ``error: <parameter> = <value> is not allowed: <range>`` line, exit 2, nothing written.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

pytest.importorskip("OCP")

from tabletcad.cli import main  # noqa: E402
from tabletcad.errors import DesignError  # noqa: E402
from tabletcad.tooling.standards import resolve_body  # noqa: E402
from support.refusals import build_refused as _refused  # noqa: E402

pytestmark = pytest.mark.cad

ROUND = ('[tablet]\nfamily = "concave_round"\ndiameter = 10.0\nband = 3.0\ncup_depth = 0.9\nland = 0.08\n'
         '[tooling]\nclearance_mm = 0.02\n')
#: the sample's punch figures (TSM B's bundled values lack the head flat, rim and neck)
PUNCH = {"head_diameter_mm": 25.4, "head_top_angle_deg": 10.0, "head_flat_diameter_mm": 12.0, "head_rim_mm": 2.5, "neck_diameter_mm": 12.7, "neck_length_mm": 12.0,
         "tip_straight_mm": 4.0, "tip_relief_mm": 0.1}


@pytest.mark.parametrize("tip, lower, parameter, least", [
    (0.9, 19.0, "tooling.tip_length_mm", 1.9),        # had built with no steel behind the cup's centre
    (1e-9, 19.0, "tooling.tip_length_mm", 1.9),       # had failed as "the cut gave 0 solids"
    (8.0, 1.5, "tooling.lower_tip_length_mm", 1.9),
])
def test_a_tip_shorter_than_its_cup_and_the_backing_is_refused(capsys, tmp_path, tip, lower, parameter, least):
    extra = f"tip_length_mm = {tip!r}\nlower_tip_length_mm = {lower!r}\n"
    name, _, why = _refused(capsys, tmp_path, ROUND + extra)
    assert name == parameter and f">= {least:g} mm" in why


def test_a_v_score_narrower_than_it_can_be_made_is_refused(capsys, tmp_path):
    name, _, why = _refused(capsys, tmp_path, ROUND + "[[tooling.score]]\ndepth_mm = 0.3\nangle_deg = 2.0\n")
    assert name == "tooling.score[0].angle_deg" and ">= 20 and" in why
    name, _, why = _refused(capsys, tmp_path, ROUND + "[[tooling.score]]\ndepth_mm = 0.3\nwidth_mm = 0.05\n")
    assert name == "tooling.score[0].width_mm" and "below 20 deg" in why


def test_the_least_die_height_quoted_is_accepted(capsys, tmp_path):
    """The bound had been computed for the given height's punch entry (min(3, H/4)), so each quoted bound
    was refused in turn (3 -> 4.55 -> 4.938 -> ...)."""
    name, _, why = _refused(capsys, tmp_path, ROUND + "die_height_mm = 3.0\n")
    least = float(re.search(r">= ([0-9.]+) mm", why).group(1))
    assert name == "tooling.die_height_mm" and least == pytest.approx(4.0 / 0.75, abs=1e-3)
    from tabletcad.pipeline.design import Design
    from tabletcad.tooling.die import die
    from tabletcad.tooling.outline import tablet_frame

    frame = tablet_frame(Design.from_toml(_write(tmp_path, ROUND)).build())
    shape, info = die(frame, 30.16, least)
    assert info["height_mm"] == least and info["bottom_z_mm"] <= frame.band_z[0] - 1.0 + 1e-12
    with pytest.raises(DesignError):
        die(frame, 30.16, least - 0.002)


def _write(tmp_path: Path, text: str) -> Path:
    p = tmp_path / "ok.toml"
    p.write_text(text, encoding="utf-8")
    return p


def test_the_least_die_diameter_quoted_is_accepted(tmp_path):
    from tabletcad.pipeline.design import Design
    from tabletcad.tooling.die import die
    from tabletcad.tooling.outline import tablet_frame

    frame = tablet_frame(Design.from_toml(_write(tmp_path, ROUND)).build())
    with pytest.raises(DesignError) as err:
        die(frame, 11.0, 22.22)
    least = float(re.search(r">= ([0-9.]+) mm", str(err.value)).group(1))
    die(frame, least, 22.22)  # the bound, rounded up to the micrometre, is a diameter the die takes


@pytest.mark.parametrize("table, parameter", [
    ({"head_diameter_mm": 15.0}, "head_diameter_mm"),   # a head smaller than the 19 mm barrel had been built
    ({"neck_diameter_mm": 0.5}, "neck_diameter_mm"),    # a 0.5 mm neck had been built
])
def test_a_head_inside_the_barrel_and_a_needle_neck_are_refused(table, parameter):
    with pytest.raises(DesignError) as err:
        resolve_body("TSM", "B", {**PUNCH, **table}, 8.0, 19.0)
    assert err.value.parameter.endswith(parameter)


def test_a_modified_standard_punch_says_so():
    """An overall length or barrel other than TSM B's had been drawn as "TSM B tooling" with the standard's
    data file as the source of its dimensions."""
    same = resolve_body("TSM", "B", PUNCH, 8.0, 19.0)
    assert same.modified == {}
    body = resolve_body("TSM", "B", {**PUNCH, "overall_length_mm": 120.0, "barrel_diameter_mm": 19.0}, 8.0, 19.0)
    assert body.modified == {"overall_length_mm": {"given": 120.0, "standard": 133.35}}


def test_the_drawing_of_a_modified_standard_punch_says_modified(tmp_path):
    text = (Path(__file__).resolve().parents[1] / "samples" / "tooling" / "tsm_b_round.toml").read_text()
    text = re.sub(r"^(\[tooling\.punch\][^\n]*\n)", r"\1overall_length_mm = 120.0\n", text, count=1, flags=re.M)
    assert "overall_length_mm = 120.0" in text
    src = tmp_path / "m.toml"
    src.write_text(text, encoding="utf-8")
    assert main(["build", str(src), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    import json

    rep = json.loads((tmp_path / "out" / "report.json").read_text())["tooling"]
    assert rep["upper_punch"]["body"]["modified_from_standard"] == {"overall_length_mm": {"given": 120.0,
                                                                                          "standard": 133.35}}
    first = rep["tooling_drawing"]["notes"][0]
    assert "TSM B tooling, MODIFIED" in first and "overall length 120.00 (standard 133.35)" in first


def test_a_batch_refused_at_one_size_writes_nothing(tmp_path):
    from tabletcad.tooling import tooling_batch

    sizes = [dict(diameter=8.0, thickness=2.4, band=1.6), dict(diameter=40.0, thickness=12.0, band=8.0)]
    with pytest.raises(DesignError):
        tooling_batch("thesis.shallow_convex_round", sizes, {"clearance_mm": 0.02}, out_dir=tmp_path / "b",
                      progress=False, check=False, drawing=False)
    assert not (tmp_path / "b").exists() or list((tmp_path / "b").iterdir()) == []


def test_a_raised_figure_counts_in_the_finished_thickness():
    """A raised figure stands above the cup: the finished tablet's thickness (report and drawing) had stayed
    the plain tablet's."""
    from tabletcad.families import FAMILIES
    from tabletcad.tooling import make_tooling
    from tabletcad.tooling.drawing import drawing_model
    from tabletcad.tooling.spec import parse_tooling

    t = FAMILIES["concave_round"].build(diameter=10.0, band=3.0, cup_depth=0.9, land=0.08)
    spec = parse_tooling({"clearance_mm": 0.02, "emboss": [{"text": "I", "mode": "emboss", "depth_mm": 0.2,
                                                            "height_mm": 2.0}]})
    ts = make_tooling(t, spec, check=False, interference_check=False)
    r = ts.report["tablet"]
    assert r["thickness_plain_mm"] == pytest.approx(4.8, abs=1e-9)
    assert 4.8 + 0.15 < r["thickness_mm"] <= 4.8 + 0.2 + 1e-6
    texts = [d.text for d in drawing_model(ts).dims]
    assert any(x.startswith(f"T {r['thickness_mm']:.2f}") for x in texts) and not any(x.startswith("T 4.80") for x in texts)


def test_a_standard_punch_length_is_quoted_whole():
    """The 133.35 mm TSM punch had been quoted as "133.3 mm" in the refusal of a tip too long for it."""
    with pytest.raises(DesignError) as err:
        resolve_body("TSM", "B", PUNCH, 200.0, 19.0)
    assert "the punch is 133.35 mm long" in str(err.value)


@pytest.mark.parametrize("sample, kind", [("capsule", "B"), ("concave_round", "B")])
def test_an_18_mm_capsule_gets_the_b_die_blank_its_standard_takes(sample, kind):
    """The tips-only placeholder die of the 18 mm capsule sample is TSM B (shaped tablets up to 19 mm), as
    the 10 mm round's: the frame's outline kind chooses the standard's round or shaped limit (the capsule had
    been given a D blank, 38.10 mm, by the round tablets' 16 mm)."""
    from tabletcad.pipeline.design import load_design
    from tabletcad.tooling.die import default_die_size
    from tabletcad.tooling.outline import tablet_frame

    frame = tablet_frame(load_design(Path(__file__).resolve().parents[1] / "samples" / "families" / f"{sample}.toml"),
                         None)
    assert max(frame.length, frame.width) == pytest.approx({"capsule": 18.0, "concave_round": 10.0}[sample], abs=1e-6)
    assert default_die_size(frame) == (30.16, 22.22, kind)
