"""Tooling inputs a fourth new user gave that were cut as something else, crashed, or were refused under
the wrong name (session 23's trial).

Each case: the exact ``error: <parameter> = <value> is not allowed: <range>`` line (the parameter the
key path of the file), exit status 2, nothing written; or, where the input is valid, what it gives.
"""

from __future__ import annotations

import re
from pathlib import Path
from types import SimpleNamespace

import pytest

pytest.importorskip("OCP")

from tabletcad.cli import main  # noqa: E402
from tabletcad.errors import DesignError  # noqa: E402
from tabletcad.tooling.spec import FONT_DIR, missing_glyphs  # noqa: E402
from tabletcad.tooling.standards import resolve_body  # noqa: E402

pytestmark = pytest.mark.cad

ONE_LINE = re.compile(r"^error: (\S+) = (.+) is not allowed: (.+)$")
ROUND = '[tablet]\nfamily = "concave_round"\ndiameter = 10.0\nband = 3.0\ncup_depth = 1.0\n[tooling]\nclearance_mm = 0.02\n'
TSM_B = ('[tooling]\nstandard = "TSM"\ntype = "B"\nclearance_mm = 0.02\ntip_length_mm = 8.0\ndie_height_mm = 22.22\n'
         '[tooling.punch]\nhead_diameter_mm = 25.4\nhead_flat_diameter_mm = 12.0\nhead_rim_mm = 2.5\n'
         'neck_diameter_mm = 12.7\nneck_length_mm = 12.0\ntip_straight_mm = 4.0\ntip_relief_mm = 0.1\n')


def _refused(capsys, tmp_path: Path, design: str, command: str = "report") -> tuple[str, str]:
    """The (parameter, reason) of the one error line; exit 2 and nothing written beside the design."""
    before = sorted(p.name for p in tmp_path.iterdir())
    src = tmp_path / "d.toml"
    src.write_text(design, encoding="utf-8")
    args = [command, str(src)] + (["--out", str(tmp_path / "out")] if command == "build" else [])
    assert main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    m = ONE_LINE.match(err[0])
    assert m, err[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(set(before) | {"d.toml"})
    return m.group(1), m.group(3)


@pytest.mark.parametrize("extra, parameter, reason", [
    # DejaVu Sans Bold has no 日 or 本: two empty boxes were debossed (0.171 mm³), exit 0
    ('[[tooling.emboss]]\ntext = "A日本"\n', "tooling.emboss[0].text", "no glyph for: '日本'"),
    ('[[tooling.emboss]]\ntext = "A"\nfont = 5\n', "tooling.emboss[0].font", "(a string)"),  # TypeError, exit 1
    ('[[tooling.emboss]]\ntext = "A"\nposition_mm = [1e308, 0]\n', "tooling.emboss[0].position_mm", "<= 1000"),
    ('[tooling.drawing]\nname = "Ibuprofène — 日本語"\n', "tooling.drawing.name", "cannot draw: '日本語'"),
])
def test_text_a_font_cannot_draw_and_wrong_font_values(capsys, tmp_path, extra, parameter, reason):
    name, why = _refused(capsys, tmp_path, ROUND + extra)
    assert name == parameter and reason in why


def test_glyph_lookup_reads_the_fonts_own_table():
    bold = FONT_DIR / "DejaVuSans-Bold.ttf"
    assert missing_glyphs("Paracétamol 500 µg — ✓", bold) == ""  # all in DejaVu, the spaces need none
    assert missing_glyphs("日本日", bold) == "日本"
    with pytest.raises(DesignError) as e:
        missing_glyphs("A", Path(__file__))  # no font
    assert e.value.parameter == "tooling.emboss.font"


@pytest.mark.parametrize("svg, reason", [
    ("<svg", "must be a readable SVG file"),  # truncated XML: ParseError, exit 1
    ("<html/>", "its root element is <html>"),
])
def test_an_svg_that_is_not_one_is_refused_by_report(capsys, tmp_path, svg, reason):
    (tmp_path / "logo.svg").write_text(svg)
    parameter, why = _refused(capsys, tmp_path, ROUND + '[[tooling.emboss]]\nsvg = "logo.svg"\n')
    assert parameter == "tooling.emboss[0].svg" and reason in why


def test_a_file_that_is_no_font_is_refused(capsys, tmp_path):
    (tmp_path / "fake.ttf").write_bytes(b"not a font at all")
    parameter, why = _refused(capsys, tmp_path, ROUND + f'[[tooling.emboss]]\ntext = "A"\nfont = "{tmp_path / "fake.ttf"}"\n')
    assert parameter == "tooling.emboss[0].font" and "font file" in why


@pytest.mark.parametrize("punch, parameter", [
    ("head_top_angle_deg = 10.0\nkey = true\nkey_width_mm = 18\nkey_length_mm = 10\nkey_height_mm = 500\n"
     "key_offset_mm = 5\n", "key_height_mm"),
    # near 90° the head grows without bound: the tip length had been blamed ("must be < -3.838e+05 mm")
    ("head_top_angle_deg = 89.999\n", "head_top_angle_deg"),
    ("head_top_angle_deg = 10.0\ninside_head_angle_deg = 89.9999\n", "inside_head_angle_deg"),
])
def test_punch_body_values_are_named(capsys, tmp_path, punch, parameter):
    design = ROUND.split("[tooling]")[0] + TSM_B + punch
    name, why = _refused(capsys, tmp_path, design)
    assert name == f"tooling.punch.{parameter}"
    assert ("leaves no barrel" in why) == parameter.endswith("angle_deg")
    if parameter.endswith("angle_deg"):  # with the angle's own bound: its head then just fills the punch
        bound = float(why.split("must be < ")[1].split(" deg")[0])
        assert 80.0 < bound < 89.9


def test_a_head_that_leaves_a_barrel_is_accepted():
    body = resolve_body("TSM", "B", {"head_diameter_mm": 25.4, "head_flat_diameter_mm": 12.0, "head_rim_mm": 2.5,
                                     "head_top_angle_deg": 10.0, "neck_diameter_mm": 12.7, "neck_length_mm": 12.0,
                                     "tip_straight_mm": 4.0, "tip_relief_mm": 0.1}, 8.0, 8.0)
    assert 0.0 < body.head_height_mm < body.overall_length_mm - 12.0


def test_a_tip_is_checked_against_the_barrel_less_the_clearance():
    """B tooling takes shaped tablets up to 19 mm and its barrel is 19 mm (TSM 18.99): a 19 mm capsule's
    tip (19 mm less twice the clearance) fits; it was refused for the tablet's own 19 mm."""
    from tabletcad.tooling.punch_body import check_body_fits

    b = SimpleNamespace(barrel_diameter_mm=19.0, max_round_tablet_mm=16.0, max_shaped_tablet_mm=19.0, standard="TSM",
                        kind="B")
    frame = SimpleNamespace(length=19.0, width=8.0, plan_diameter=19.0, outline_kind="capsule")
    check_body_fits(frame, b, 9.5 - 0.02)
    with pytest.raises(DesignError) as e:
        check_body_fits(frame, b, 9.5)
    assert e.value.parameter == "tooling.punch.barrel_diameter_mm"
    # the standard's largest tablet is its largest extent in plan: a square 14 mm on the axes is 19.4 mm across
    # its corners, over B's 19 mm (it had been read as 14 mm), though its tips fit the barrel
    square = SimpleNamespace(length=14.0, width=14.0, plan_diameter=19.4, outline_kind="lines and arcs")
    with pytest.raises(DesignError) as e:
        check_body_fits(square, b, 9.0)
    assert e.value.parameter == "tooling.type" and e.value.allowed.endswith("this one is 19.4 mm across")


def test_make_tooling_passes_the_tip_radius_and_warns_of_a_keyless_shaped_tip(monkeypatch):
    """The barrel check gets the tip's reach (the 19 mm capsule's 9.5 mm less the 0.02 mm clearance), and a
    shaped tip without a key is warned of (it turns in its bore); the build is stopped after the checks."""
    import tomllib

    import tabletcad.tooling.punch_body as pb
    import tabletcad.tooling.toolset as toolset
    from tabletcad.pipeline.design import Design

    seen = []
    monkeypatch.setattr(pb, "check_body_fits", lambda frame, body, radius: seen.append(radius))

    def stop(*a, **k):
        raise DesignError("stop", 0, "after the checks")

    monkeypatch.setattr(toolset, "_check_relief", stop)
    punch = TSM_B + "head_top_angle_deg = 10.0\n"
    d = Design.from_dict(dict(tablet=dict(family="capsule", length=19.0, width=8.0, band=3.0, cup_depth=1.0, land=0.05),
                              **tomllib.loads(punch)))
    with pytest.warns(UserWarning, match="shaped punch tips have no key"), pytest.raises(DesignError, match="after"):
        toolset.make_tooling(d.build(), d.tooling_spec, check=False, interference_check=False)
    assert seen == [pytest.approx(9.5 - 0.02, abs=1e-6)]
    keyed = tomllib.loads(punch + "key = true\nkey_width_mm = 4.76\nkey_length_mm = 10\nkey_height_mm = 2\n"
                          "key_offset_mm = 5\n")
    d = Design.from_dict(dict(tablet=dict(family="capsule", length=19.0, width=8.0, band=3.0, cup_depth=1.0, land=0.05),
                              **keyed))
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(DesignError, match="after"):
            toolset.make_tooling(d.build(), d.tooling_spec, check=False, interference_check=False)


def test_raised_figures_have_the_debossed_depth_limit(capsys, tmp_path):
    """A raised figure 50 mm tall stopped the build with "emboss 0: the raised figure is empty" (no
    parameter, no range); now refused like a debossed one, before any Boolean."""
    parameter, why = _refused(capsys, tmp_path, ROUND + '[[tooling.emboss]]\ntext = "A"\nmode = "emboss"\ndepth_mm = 50.0\n',
                              command="build")
    assert parameter == "tooling.emboss[0].depth_mm" and "cup depth + band/4 = 1.75 mm" in why


def test_a_score_wider_than_half_the_tablet_and_a_huge_direction(capsys, tmp_path):
    """A V score of 179.9° was cut 687 mm wide on a 10 mm tablet, and direction_deg = 1e308 was taken."""
    name, why = _refused(capsys, tmp_path, ROUND + '[[tooling.score]]\ndepth_mm = 0.3\nangle_deg = 179.9\n', command="build")
    assert name == "tooling.score[0].angle_deg" and "687.5 mm wide" in why and "5 mm" in why
    # a groove too deep is named by its depth, not by the default angle that makes it wide
    name, why = _refused(capsys, tmp_path, ROUND + '[[tooling.score]]\ndepth_mm = 5.0\n', command="build")
    assert name == "tooling.score[0].depth_mm", why
    name, why = _refused(capsys, tmp_path, ROUND + '[[tooling.score]]\ndepth_mm = 0.3\ndirection_deg = 1e308\n')
    assert name == "tooling.score[0].direction_deg" and "<= 360" in why


def test_an_optimise_variable_is_named_by_its_table(capsys, tmp_path):
    problem = ('[problem]\nkind = "family"\nfamily = "concave_round"\nsense = "min"\nobjective = "surface_area_mm2"\n'
               '[variables]\ndiameter = { lower = 7.0, upper = 11.0, initial = 20.0 }\n[fixed]\nband = 3.0\n'
               'cup_depth = 1.0\n')
    (tmp_path / "p.toml").write_text(problem)
    assert main(["optimise", str(tmp_path / "p.toml"), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("error: variables.diameter.initial = 20 mm is not allowed: must lie within [7, 11]"), err
    assert not (tmp_path / "out").exists()


def test_the_head_angle_bound_is_where_the_barrel_ends():
    """The bound "leaves no barrel" gives for head_top_angle_deg is exact: just below it a barrel is left
    (the tip length, not the head, then limits the punch); at it the neck and head fill the punch."""
    table = {"head_diameter_mm": 25.4, "head_flat_diameter_mm": 12.0, "head_rim_mm": 2.5, "neck_diameter_mm": 12.7,
             "neck_length_mm": 12.0, "tip_straight_mm": 4.0, "tip_relief_mm": 0.1, "head_top_angle_deg": 89.999}
    with pytest.raises(DesignError) as e:
        resolve_body("TSM", "B", table, 8.0, 8.0)
    bound = float(str(e.value).split("must be < ")[1].split(" deg")[0])
    for angle, barrel in ((bound - 0.01, True), (bound + 0.01, False)):
        try:
            resolve_body("TSM", "B", dict(table, head_top_angle_deg=angle), 1e-3, 1e-3)
            left = True
        except DesignError as err:
            left = "leaves no barrel" not in str(err)
        assert left == barrel, angle


@pytest.mark.parametrize("diameter, clearance, most", [(2.0, 1.0, "0.5"), (1.5, 0.7, "0.375")])
def test_a_clearance_that_would_eat_the_tips_is_named(capsys, tmp_path, diameter, clearance, most):
    """A clearance within its range (<= 1 mm) that leaves a small tablet's tips narrower than half of it (a
    trial: 1 mm on a 2 mm round failed in OCC's offset "by -3.54 mm", a figure of its own scaling, and
    0.7 mm on a 1.5 mm round built a 0.1 mm tip) is refused as the clearance, before any geometry of the
    tooling; 0.35 mm on the 1.5 mm round builds (tests/test_tooling_mini.py builds mini tablets' tools)."""
    design = (f'[tablet]\nfamily = "concave_round"\ndiameter = {diameter}\nband = 1.0\ncup_depth = 0.2\nland = 0.05\n'
              f'[tooling]\nclearance_mm = {clearance}\ntip_length_mm = 3.0\n')
    parameter, reason = _refused(capsys, tmp_path, design, "build")
    assert parameter == "tooling.clearance_mm"
    assert reason == f"must leave the punch tips at least half the tablet's {diameter:g} mm width: at most {most} mm"


_NO_BAND = '[tablet]\nfamily = "thesis.spherical"\ndiameter = 5\n[tooling]\nclearance_mm = 0.02\n'
_LAND = '[tablet]\nfamily = "concave_round"\ndiameter = 10.0\nband = 2.8\ncup_depth = 0.9\nland = 0.08\n[tooling]\n'


@pytest.mark.parametrize("command", ["report", "build"])
@pytest.mark.parametrize("design, line", [
    (_NO_BAND, "error: tooling = 'thesis.spherical' is not allowed: tooling needs a tablet with a band (a cylindrical "
               "side wall the die forms); this one has none"),
    (_LAND + '[[tooling.emboss]]\ntext = "10"\nface = "top"\nheight_mm = 2\ndepth_mm = 5\n',
     "error: tooling.emboss[0].depth_mm = 5 mm is not allowed: must be <= cup depth + band/4 = 1.6 mm"),
    (_LAND + '[[tooling.score]]\nkind = "bisect"\ndepth_mm = 5\n',
     "error: tooling.score[0].depth_mm = 5 mm is not allowed: must be < the top cup depth 0.9 mm minus 0.005 mm (a "
     "standard score runs out on the face; set cut_through = true to cut the band)"),
    # a flat face has no cup for a standard score to run out in (its cup depth, 8.9e-16 mm, had been quoted as the
    # bound: "< the top cup depth 8.882e-16 mm minus 0.005 mm")
    ('[tablet]\nfamily = "flat_face_round"\ndiameter = 10.0\nthickness = 3.5\n[tooling]\n[[tooling.score]]\n'
     'depth_mm = 0.3\n',
     "error: tooling.score[0].depth_mm = 0.3 mm is not allowed: a standard score runs out in a cup and the top face is "
     "flat; set cut_through = true to cut it across the face, at most band/4 = 0.875 mm deep"),
    # complete punches: a lower tip no longer than the die (report had passed it; build refused it after the solid)
    (ROUND.replace("[tooling]\nclearance_mm = 0.02\n", "") + TSM_B + "head_top_angle_deg = 10.0\n",
     "error: tooling.lower_tip_length_mm = 8 mm is not allowed: must be > 22.22 mm, the die's height: at ejection the "
     "lower tip edge rises to the die's top face and the barrel must stay below the die (not given, it is "
     "tip_length_mm: give lower_tip_length_mm)"),
    # a tip relief that leaves no tip outline (report had passed it; build refused it after the solid)
    (ROUND.replace("[tooling]\nclearance_mm = 0.02\n", "")
     + TSM_B.replace("tip_relief_mm = 0.1", "tip_relief_mm = 10.0").replace(
         "tip_length_mm = 8.0\n", "tip_length_mm = 8.0\nlower_tip_length_mm = 25.4\n") + "head_top_angle_deg = 10.0\n",
     "error: tooling.punch.tip_relief_mm = 10 mm is not allowed: must leave a relieved tip: the outline offset inwards "
     "by the clearance and the relief (10.02 mm) leaves no single outline (tablet width 10 mm)"),
    # a rounded square 24 mm on the axes is 33.1 mm across its corners: larger than a D die takes (it had been
    # read as 24 mm, and an 18 mm one, 24.6 mm across, given a B die, which takes shaped tablets up to 19 mm)
    ('[tablet]\nfamily = "rounded_square"\nside = 24.0\ncorner_radius = 1.0\nband = 3.0\ncup_depth = 0.5\n'
     '[tooling]\nclearance_mm = 0.03\n',
     "error: tooling.die_outer_diameter_mm = (not given) is not allowed: give it for a shaped tablet 33.11 mm across "
     "(larger than a TSM 'D' die takes, 25 mm)"),
])
def test_tooling_numbers_are_refused_by_report_and_build_before_the_cad(capsys, tmp_path, monkeypatch, command, design,
                                                                         line):
    """`report` took these [tooling] tables (exit 0) that `build` refused after 3-5 s of solid building: a sphere
    has no band, a figure or a score deeper than its face.  Both now refuse them from the PDE tablet's numbers
    (tabletcad.tooling.spec.check_on_tablet), before any CAD step (which would fail the test here)."""
    import tabletcad.cad.stage

    def no_cad(**_):
        raise AssertionError("the CAD stage was reached")

    monkeypatch.setattr(tabletcad.cad.stage, "cad_stage", no_cad)
    (tmp_path / "d.toml").write_text(design, encoding="utf-8")
    args = [command, str(tmp_path / "d.toml")] + (["--out", str(tmp_path / "out")] if command == "build" else [])
    rc = main(args)
    out, err = capsys.readouterr()
    assert rc == 2 and err.splitlines() == [line] and out == ""
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d.toml"]


def test_tooling_numbers_within_their_limits_pass_the_report(capsys, tmp_path):
    """The limits themselves still pass: a 0.89 mm score on a 0.9 mm cup, a 1.59 mm deboss (cup + band/4 is 1.6)."""
    d = tmp_path / "d.toml"
    d.write_text(_LAND + '[[tooling.score]]\ndepth_mm = 0.3\n[[tooling.emboss]]\ntext = "10"\nface = "bottom"\n'
                 'height_mm = 2\ndepth_mm = 1.59\n', encoding="utf-8")
    assert main(["report", str(d)]) == 0, capsys.readouterr().err
    from tabletcad.pipeline.design import Design
    from tabletcad.tooling.spec import check_on_tablet, parse_tooling

    tablet = Design.from_toml(d).build()
    check_on_tablet(tablet, parse_tooling({"score": [{"depth_mm": 0.894}], "emboss": [{"text": "1", "depth_mm": 1.59}]}))
    with pytest.raises(DesignError, match="minus 0.005 mm"):
        check_on_tablet(tablet, parse_tooling({"score": [{"depth_mm": 0.896}]}))
