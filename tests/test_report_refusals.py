"""``tabletcad report`` refuses what ``tabletcad build`` refuses for a design's ``[tooling]``, with the same
line, before any geometry: lettering that does not fit its face, which a trial found ``report`` accepting
(exit 0) while ``build`` refused it after ~2 s of CAD, and a clearance beyond a spline outline's regular
offsets (a custom outline through points; its tooling is tested in tests/test_tooling_spline_outline.py).

The fit is decided without OCC (:mod:`tabletcad.geometry.lettering`); the tests marked ``cad`` hold it
against OpenCascade's own figure and Boolean (:func:`tabletcad.tooling.emboss.check_fit`)."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

from tabletcad.cli import main
from tabletcad.errors import DesignError

ROOT = Path(__file__).resolve().parents[1]
ONE_LINE = re.compile(r"^error: (\S+) = (.+) is not allowed: (.+)$")

#: the concave round sample's tablet (10 mm, 0.08 mm land) with one debossed text on its bottom face
ROUND = """[tablet]
family = "concave_round"
diameter = 10.0
band = 2.8
cup_depth = 0.9
land = 0.08

[tooling]
clearance_mm = 0.02
tip_length_mm = 8.0

[[tooling.emboss]]
text = "ABCDEFGH"
mode = "deboss"
face = "bottom"
height_mm = {height}
depth_mm = 0.12
"""

#: the tallest "ABCDEFGH" that fits (DejaVu Sans Bold; the face inset by 0.02 + 0.08 + 0.2 mm is a circle
#: of 4.7 mm): 1.52836089096 mm by bisection of the exact area outside, where OCC's Boolean agrees to 1e-9 mm
TALLEST = 1.5283608900960957

#: "AB" (2.5 mm, DejaVu Sans Bold: strokes 0.41356 mm wide by 2A/P) debossed 0.5 mm: its walls meet at 22.468 deg
STROKE = ROUND.replace('"ABCDEFGH"', '"AB"').replace("depth_mm = 0.12", "depth_mm = 0.5\nstroke_angle_deg = {angle}")

#: a thesis oval (its tooling outline an ellipse: the core does not decide the fit) with "A" (2 mm, DejaVu Sans
#: Bold: strokes 0.323 mm wide) debossed 0.25 mm at 55 deg: its walls meet at 32.8 deg
OVAL_STROKE = """[tablet]
family = "thesis.shallow_convex_oval"
width = 6.0
length = 12.0
thickness = 3.0
band = 2.0

[tooling]
clearance_mm = 0.02
tip_length_mm = 8.0

[[tooling.emboss]]
text = "A"
mode = "deboss"
face = "top"
height_mm = 2.0
depth_mm = 0.25
stroke_angle_deg = 55.0
"""

#: a peanut of four arcs (lobes of 2 mm, a neck 1.374868 mm across between concave arcs of 0.5 mm: its inward
#: offsets are clean up to half that) with a bar across the neck, inset by 0.02 + {margin} mm
PEANUT = """[tablet]
family = "custom_outline"
segments = [
  ["arc", [2.2, 0], 2.0, -2.646658527248898, 5.293317054497796],
  ["arc", [0, 1.1874342087037915], 0.5, -0.4949341263408954, -2.1517244009080025],
  ["arc", [-2.2, 0], 2.0, 0.4949341263408953, 5.293317054497796],
  ["arc", [0, -1.1874342087037915], 0.5, 2.646658527248898, -2.1517244009080025],
]
band = 2.5
cup_depth = 0.05

[tooling]
clearance_mm = 0.02
tip_length_mm = 8.0

[[tooling.emboss]]
outline = [[-0.3, -0.25], [2.5, -0.25], [2.5, 0.25], [-0.3, 0.25]]
mode = "deboss"
face = "top"
depth_mm = 0.1
margin_mm = {margin}
"""

SPLINE = """[tablet]
family = "custom_outline"
outline = [[4, 0], [3, 3], [0, 4], [-3, 3], [-4, 0], [-3, -3], [0, -4], [3, -3]]
band = 2.5
cup_depth = 0.5

[tooling]
clearance_mm = 0.02
tip_length_mm = 8.0
"""

#: a rounded square through points whose corners' smallest radius of curvature is 0.276 mm: its tips, inset by a
#: 0.3 mm clearance, would pass it (the largest regular inset is 0.273248 mm, 1 % short of that radius)
SPLINE_CORNER = """[tablet]
family = "custom_outline"
outline = [[4.0, -1.8], [4.0, 0.0], [4.0, 1.8], [3.9864, 3.7035], [3.8828, 3.8828], [3.7035, 3.9864], [1.8, 4.0],
           [0.0, 4.0], [-1.8, 4.0], [-3.7035, 3.9864], [-3.8828, 3.8828], [-3.9864, 3.7035], [-4.0, 1.8], [-4.0, 0.0],
           [-4.0, -1.8], [-3.9864, -3.7035], [-3.8828, -3.8828], [-3.7035, -3.9864], [-1.8, -4.0], [0.0, -4.0],
           [1.8, -4.0], [3.7035, -3.9864], [3.8828, -3.8828], [3.9864, -3.7035]]
band = 2.5
cup_depth = 0.2

[tooling]
clearance_mm = {clearance}
tip_length_mm = 8.0
"""

#: an outline of lines and arcs (the custom-outline sample's "D"), which tooling takes
SEGMENTS = """[tablet]
family = "custom_outline"
segments = [
  ["line", [-2.5, -3.5], [2.5, -3.5]],
  ["arc",  [2.5, 0.0], 3.5, -1.5707963267948966, 3.141592653589793],
  ["line", [2.5, 3.5], [-2.5, 3.5]],
  ["arc",  [-2.5, 2.0], 1.5, 1.5707963267948966, 1.5707963267948966],
  ["line", [-4.0, 2.0], [-4.0, -2.0]],
  ["arc",  [-2.5, -2.0], 1.5, 3.141592653589793, 1.5707963267948966],
]
band = 2.8
cup_depth = 0.5

[tooling]
clearance_mm = 0.02
tip_length_mm = 8.0
"""


def _refusal(capsys, tmp_path: Path, design: str, command: str) -> str:
    """The one line of ``tabletcad report`` or ``build`` refusing ``design``: exit 2, nothing written."""
    src = tmp_path / "d.toml"
    src.write_text(design, encoding="utf-8")
    args = ["report", str(src), "--json-file", str(tmp_path / "r.json")] if command == "report" else \
        ["build", str(src), "--out", str(tmp_path / "out"), "--quiet"]
    assert main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and ONE_LINE.match(err[0]), err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d.toml"]
    return err[0]


def _design(tmp_path: Path, text: str):
    from tabletcad.pipeline.design import Design

    src = tmp_path / "d.toml"
    src.write_text(text, encoding="utf-8")
    return Design.from_toml(src)


# ----------------------------------------------------------------------------- lettering (no CAD)

def test_report_refuses_text_that_does_not_fit_its_face(capsys, tmp_path):
    """The text 9.2 x 1.9 mm on a face whose punch tip, less land and margin, is 9.4 mm across: report had
    printed its table (exit 0), build refused it after the solid."""
    line = _refusal(capsys, tmp_path, ROUND.format(height=2.5), "report")
    assert line == ("error: tooling.emboss[0].text = 'ABCDEFGH' is not allowed: does not fit the bottom face: "
                    "15.1 x 1.89 mm with 5.79 mm^2 outside the punch tip inset by 0.3 mm (clearance + land + "
                    "margin); use a smaller height_mm or move it")


@pytest.mark.parametrize("height, refused", [(1.528, False), (1.529, True)])
def test_the_fit_is_decided_at_the_tallest_text_that_fits(capsys, tmp_path, height, refused):
    """A micrometre below the tallest fitting height the report passes, one above it refuses (1.87e-5 mm^2
    outside, above the 1e-6 of the figure's area that the tooling allows)."""
    src = tmp_path / "d.toml"
    src.write_text(ROUND.format(height=height), encoding="utf-8")
    assert main(["report", str(src)]) == (2 if refused else 0)
    err = capsys.readouterr().err
    assert ("1.87e-05 mm^2 outside" in err) if refused else err == ""


def test_the_area_outside_is_exact_for_a_rectangle_across_a_circle():
    """A polyline figure across the inset circle: the area outside by Green's theorem equals the closed form
    (the rectangle's area less its part in the disc: a rectangle to the corner's x, then the circular segment
    beyond it, ∫ 2 sqrt(r^2 - x^2) dx = [x sqrt(r^2 - x^2) + r^2 asin(x / r)]) to 1e-12 mm^2."""
    from tabletcad.families.outline import circle_outline
    from tabletcad.geometry.lettering import outside_area, polyline_contours

    R, inset, (x0, x1, h) = 5.0, 0.3, (2.0, 6.0, 1.2)
    r = R - inset
    xk = math.sqrt(r * r - h * h)  # where the rectangle's long sides cross the circle
    F = lambda x: x * math.sqrt(max(r * r - x * x, 0.0)) + r * r * math.asin(x / r)  # noqa: E731
    inside = 2 * h * (xk - x0) + F(r) - F(xk)
    area, outside = outside_area(polyline_contours([[x0, -h], [x1, -h], [x1, h], [x0, h]]), circle_outline(R), inset)
    assert area == pytest.approx((x1 - x0) * 2 * h, abs=1e-12)
    assert outside == pytest.approx(area - inside, abs=1e-12)


def test_text_is_laid_out_as_occ_lays_it_out():
    """"AB" at 2.5 mm in DejaVu Sans Bold: the area and box OCC's text builder gives (3.868877018491427 mm^2,
    3.65234375 x 1.822509765625 mm, measured), and "LT" 47 font units wider than its advances (OCC pairs the
    last symbol with itself for kerning: 'T','T' is +47 in the font's kern table)."""
    from tabletcad.geometry.lettering import figure_area, figure_box, text_contours
    from tabletcad.tooling.spec import font_path

    ab = text_contours("AB", 2.5, font_path("DejaVuSans-Bold"))
    assert abs(figure_area(ab)) == pytest.approx(3.868877018491427, abs=1e-13)
    assert figure_box(ab) == pytest.approx((3.65234375, 1.822509765625), abs=1e-13)
    lt = text_contours("LT", 2048.0, font_path("DejaVuSans-Bold"))  # one font unit a millimetre
    assert min(float(np.min(c[:, 0])) for contour in lt for c in contour) == pytest.approx(-1017.0, abs=1e-9)


def test_the_numerical_core_imports_only_declared_dependencies():
    """Every library imported by tabletcad.geometry (the lettering: fontTools, which had arrived only through
    matplotlib), tabletcad.families and tabletcad.mechanics is the distribution of one of [project]'s
    dependencies, so a plain install runs ``report``."""
    import ast
    import sys
    from importlib.metadata import packages_distributions

    try:
        import tomllib
    except ImportError:  # Python 3.10
        import tomli as tomllib

    deps = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["dependencies"]
    declared = {re.split(r"[<>=!~;\[ ]", r, maxsplit=1)[0].lower().replace("_", "-") for r in deps}
    imported = set()
    for package in ("geometry", "families", "mechanics"):
        for f in (ROOT / "tabletcad" / package).rglob("*.py"):
            for node in ast.walk(ast.parse(f.read_text(encoding="utf-8"))):
                if isinstance(node, ast.Import):
                    imported |= {a.name.split(".")[0] for a in node.names}
                elif isinstance(node, ast.ImportFrom) and node.level == 0:
                    imported.add(node.module.split(".")[0])
    third = sorted(n for n in imported if n not in sys.stdlib_module_names and n != "tabletcad")
    assert "fontTools" in third
    dists = packages_distributions()
    missing = [n for n in third if not {d.lower().replace("_", "-") for d in dists.get(n, [n])} & declared]
    assert missing == []


def _mpl_font(name: str) -> Path:
    """A font file that matplotlib bundles (STIX: 1000 units per em; the Computer Modern cmr10: 2048)."""
    import matplotlib

    return Path(matplotlib.get_data_path()) / "fonts" / "ttf" / f"{name}.ttf"


def test_text_the_font_has_no_glyph_for_is_refused_for_what_would_be_cut(capsys, tmp_path):
    """Computer Modern cmr10 has no 'Å': the refusal had said OCC would cut it "as an empty box", but OCC's
    text shape takes a fallback system font's glyph for it (another 'Å', 26 vertices, where 'A' has 25; an
    empty box only where no font has the character, as DejaVu's missing '日'): what is refused is cutting
    something that is not the letter asked for."""
    font = _mpl_font("cmr10")
    design = ROUND.format(height=2.0).replace('"ABCDEFGH"', '"AÅ"') + f'font = "{font}"\n'
    line = _refusal(capsys, tmp_path, design, "report")
    assert line == (f"error: tooling.emboss[0].text = 'AÅ' is not allowed: has characters the font '{font}' has no "
                    "glyph for: 'Å' (the figure cut would not be them: OpenCascade puts another font's glyph or an "
                    "empty box in their place); give a font that has them")


def test_a_font_of_1000_units_per_em_is_rounded_as_freetype_rounds_it():
    """STIX General Bold (1000 units per em) "D1" at 3 mm: the area of OCC's faces (3.0368605419794705 mm^2,
    measured) to 1e-12; scaled by size / unitsPerEm in double precision it had been 3.036840 (FreeType's 26.6
    points at 4800 ppem, 0.2 of a step a unit off the grid, and OCC's single-precision layout)."""
    from tabletcad.geometry.lettering import _font, figure_area, text_contours

    assert abs(figure_area(text_contours("D1", 3.0, _mpl_font("STIXGeneralBol")))) == \
        pytest.approx(3.0368605419794705, abs=1e-12)
    from tabletcad.geometry.glyphs import div_fix, face_scale, mul_fix

    assert face_scale(_font(str(_mpl_font("STIXGeneralBol")))) == div_fix(307200, 1000) == 20132659
    assert div_fix(307200, 2048) == 150 << 16
    assert [mul_fix(v, 0x8000) for v in (3, -3, 1, -1)] == [2, -2, 1, -1]  # halves away from zero


def test_report_refuses_a_stroke_angle_that_closes_the_strokes(capsys, tmp_path):
    """The build's other refusal of a figure after the solid: walls at 25 deg meet before 0.5 mm in strokes
    0.414 mm wide (report had printed its table); at 22 deg the report passes."""
    line = _refusal(capsys, tmp_path, STROKE.format(height=2.5, angle=25.0), "report")
    assert line == ("error: tooling.emboss[0].stroke_angle_deg = 25 deg is not allowed: must be < 22.5 deg: the walls "
                    "of 0.414 mm strokes would meet before the depth 0.5 mm")
    src = tmp_path / "d.toml"
    src.write_text(STROKE.format(height=2.5, angle=22.0), encoding="utf-8")
    assert main(["report", str(src)]) == 0


def test_report_refuses_a_stroke_angle_on_a_tablet_whose_fit_it_leaves_to_the_build(capsys, tmp_path):
    """The stroke angle needs no outline: on a thesis oval (tooling outline an ellipse) report had skipped it with
    the fit (exit 0) while build refused it before the solid."""
    line = _refusal(capsys, tmp_path, OVAL_STROKE, "report")
    assert line == ("error: tooling.emboss[0].stroke_angle_deg = 55 deg is not allowed: must be < 32.8 deg: the walls "
                    "of 0.323 mm strokes would meet before the depth 0.25 mm")


def test_the_fit_beyond_the_offset_limit_is_left_to_the_build(capsys, tmp_path):
    """Inset by 0.72 mm the peanut's neck (0.6875 mm half width) parts its offset: the closing integral ran along
    the crossing offset and report refused the bar with 0.464 mm^2 outside (a grid gives 0.440); now the core
    leaves it to the build's OCC check.  Below the offset limit the area outside is the grid's."""
    src = tmp_path / "d.toml"
    src.write_text(PEANUT.format(margin=0.7), encoding="utf-8")
    assert main(["report", str(src), "--json-file", str(tmp_path / "r.json")]) == 0
    assert capsys.readouterr().err == ""

    from tabletcad.geometry.lettering import outside_area, polyline_contours
    from tabletcad.tooling.spec import fit_is_decided, tooling_plan_outline

    outline = tooling_plan_outline(_design(tmp_path, PEANUT.format(margin=0.7)).build())
    neck = 1.1874342087037915 - 0.5  # the half width of the neck: the offset parts there
    assert [fit_is_decided(outline, d) for d in (0.68, neck - 1e-8, neck + 1e-8, 0.72, 2.0)] == \
        [True, True, False, False, True]  # (2 mm: the inscribed radius, nothing left: refused as the tooling)
    bar = polyline_contours([[-0.3, -0.25], [2.5, -0.25], [2.5, 0.25], [-0.3, 0.25]])
    xs, ys = (np.arange(2000) + 0.5) * 2.8 / 2000 - 0.3, (np.arange(500) + 0.5) * 0.5 / 500 - 0.25
    grid = np.stack(np.meshgrid(xs, ys), -1).reshape(-1, 2)
    depth = np.concatenate([outline.signed_distance(grid[k:k + 1000]) for k in range(0, len(grid), 1000)])
    for inset in (0.5, 0.68):
        area, outside = outside_area(bar, outline, inset)
        assert outside == pytest.approx(float(np.mean(depth < inset)) * area, abs=1e-4)


# ----------------------------------------------------------------------------- spline outline (no CAD)

def test_report_passes_tooling_of_a_spline_outline(tmp_path):
    """A custom outline through points with [tooling]: refused by report and build alike (OCC could not offset
    it), it is reported now (the tips and the bore are the B-splines of its exact offsets)."""
    src = tmp_path / "d.toml"
    src.write_text(SPLINE, encoding="utf-8")
    assert main(["report", str(src)]) == 0


def test_report_refuses_a_clearance_beyond_a_spline_corner(capsys, tmp_path):
    """The tips inset by the clearance past the spline's smallest convex radius of curvature (less 1 %,
    Tolerances.offset_regularity) would loop there: refused, with the largest clearance that is allowed, said
    once.  The line had quoted two bounds for the one limit, "<= 0.273249 mm" and "at most 0.273248 mm" (the
    offset's limit, 0.273248630 mm, less the die bore's 1e-06 mm: the tips stand the clearance less it inside
    the outline); this test had pinned them."""
    line = _refusal(capsys, tmp_path, SPLINE_CORNER.format(clearance=0.3), "report")
    assert line == ("error: tooling.clearance_mm = 0.3 mm is not allowed: must be <= 0.273249 mm: the tooling offsets "
                    "the spline outline 0.3 mm inward for it (the clearance less the die bore's 1e-06 mm outside the "
                    "outline), beyond its largest regular inward offset (its smallest convex radius of curvature is "
                    "0.276 mm, and the offset must stay regular and clear of the narrowest place)")


def test_the_largest_clearance_stated_is_reported(tmp_path):
    src = tmp_path / "d.toml"
    src.write_text(SPLINE_CORNER.format(clearance=0.273249), encoding="utf-8")
    assert main(["report", str(src)]) == 0


#: SPLINE_CORNER's clearance 0.02 mm with a complete TSM B punch relieved {relief} mm behind its 4 mm straight tip
SPLINE_RELIEF = SPLINE_CORNER.format(clearance=0.02).replace(
    "tip_length_mm = 8.0\n", 'tip_length_mm = 8.0\nstandard = "TSM"\ntype = "B"\ndie_height_mm = 22.22\n'
    "lower_tip_length_mm = 25.4\n\n[tooling.punch]\nhead_diameter_mm = 25.4\nhead_flat_diameter_mm = 12.0\n"
    "head_rim_mm = 2.5\nhead_top_angle_deg = 10.0\nneck_diameter_mm = 12.7\nneck_length_mm = 12.0\n"
    "tip_straight_mm = 4.0\ntip_relief_mm = {relief}\n")

#: SPLINE_CORNER's clearance 0.02 mm with a figure {margin} mm inside the tip edge
SPLINE_MARGIN = SPLINE_CORNER.format(clearance=0.02) + (
    '\n[[tooling.emboss]]\ntext = "A"\nheight_mm = 1.0\ndepth_mm = 0.05\nmargin_mm = {margin}\n')

_CORNER = ("beyond its largest regular inward offset (its smallest convex radius of curvature is 0.276 mm, and the "
           "offset must stay regular and clear of the narrowest place)")


@pytest.mark.parametrize("design, key, over, line", [
    (SPLINE_CORNER.replace("{clearance}", "{}"), "clearance_mm", 0.27325,
     "error: tooling.clearance_mm = 0.27325 mm is not allowed: must be <= 0.273249 mm: the tooling offsets the spline "
     f"outline 0.2732 mm inward for it (the clearance less the die bore's 1e-06 mm outside the outline), {_CORNER}"),
    (SPLINE_RELIEF.replace("{relief}", "{}"), "punch.tip_relief_mm", 0.253249,
     "error: tooling.punch.tip_relief_mm = 0.253249 mm is not allowed: must be <= 0.253248 mm: the tooling offsets "
     f"the spline outline 0.2732 mm inward for it (clearance + tip relief), {_CORNER}"),
    (SPLINE_MARGIN.replace("{margin}", "{}"), "emboss[0].margin_mm", 0.253249,
     "error: tooling.emboss[0].margin_mm = 0.253249 mm is not allowed: must be <= 0.253248 mm: the tooling offsets "
     f"the spline outline 0.2732 mm inward for it (clearance + land + margin), {_CORNER}"),
])
def test_each_spline_offset_bound_quoted_is_allowed_and_one_step_above_it_refused(capsys, tmp_path, design, key,
                                                                                  over, line):
    """Every bound check_spline_offsets quotes for a parameter (the clearance, a complete punch's tip relief,
    a figure's margin; the taper below) is said once, and in its printed digits it is the edge: the value
    quoted is reported, one unit of its last digit more is refused with the same bound."""
    assert _refusal(capsys, tmp_path, design.format(over), "report") == line
    bound = re.search(r"must be <= (\S+) mm", line).group(1)
    assert float(bound) == pytest.approx(over - 1e-6, abs=1e-12)
    src = tmp_path / "d.toml"
    src.write_text(design.format(bound), encoding="utf-8")
    assert main(["report", str(src), "--json-file", str(tmp_path / "r.json")]) == 0, key


def test_a_short_score_beyond_the_spline_corner_is_refused_for_what_moves_the_offset(capsys, tmp_path):
    """A short score's footprint must end 0.05 mm inside the land, whatever its length: the line had asked for a
    length_mm "<= 1.97324 mm" (2 mm less the offset's excess), which is refused as well."""
    design = SPLINE_CORNER.format(clearance=0.02).replace("cup_depth = 0.2", "cup_depth = 0.005\nland = 0.25")
    line = _refusal(capsys, tmp_path, design + "\n[[tooling.score]]\nlength_mm = 2.0\n", "report")
    assert line == ("error: tooling.score[0].length_mm = 2 mm is not allowed: a short score needs the face inset by its "
                    "land + 0.05 mm = 0.3 mm, beyond the spline outline's largest regular inward offset (its smallest "
                    "convex radius of curvature is 0.276 mm, and the offset must stay regular and clear of the "
                    "narrowest place); leave length_mm out for a score across the face")


def test_a_margin_no_value_of_which_fits_a_spline_corner_is_not_given_a_negative_bound(capsys, tmp_path):
    """Clearance and land inset the face 0.285 mm, past the 0.273249 mm limit: the line had asked for a margin
    "<= -0.0117514 mm"."""
    design = SPLINE_MARGIN.format(margin=0.1).replace("cup_depth = 0.2", "cup_depth = 0.001\nland = 0.265")
    assert _refusal(capsys, tmp_path, design.replace("depth_mm = 0.05", "depth_mm = 0.001"), "report") == (
        "error: tooling.emboss[0].margin_mm = 0.1 mm is not allowed: no margin fits: the clearance and the face's "
        f"land alone offset the spline outline 0.285 mm inward, {_CORNER}")


def test_an_upper_bound_is_stepped_down_until_it_is_allowed():
    """allowed_upper_bound: a bound whose six digits are refused (0.273249 where 0.2732489999 is the edge) is
    quoted a unit lower; one that is accepted as printed is kept."""
    from tabletcad.tooling.spec import allowed_upper_bound

    assert allowed_upper_bound(0.273249, lambda q: q <= 0.2732489999) == "0.273248"
    assert allowed_upper_bound(0.27324963044442513, lambda q: q <= 0.27324963044442513) == "0.273249"


#: a circle of 4 mm through 24 points, dented at -x: its spline's dent has a concave radius of curvature 0.6389 mm,
#: which an outward offset (the die bore drafted by taper_deg over the 3 mm entry and 1 mm above) may not pass
DENTED = """[tablet]
family = "custom_outline"
outline = [[4.0, 0.0], [3.8637, 1.0353], [3.4641, 2.0], [2.8284, 2.8284], [2.0, 3.4641], [1.0353, 3.8637], [0.0, 4.0],
           [-1.0353, 3.8637], [-1.9999, 3.464], [-2.8238, 2.8238], [-3.3717, 1.9467], [-3.3117, 0.8874], [-3.0, 0.0],
           [-3.3117, -0.8874], [-3.3717, -1.9467], [-2.8238, -2.8238], [-1.9999, -3.464], [-1.0353, -3.8637],
           [0.0, -4.0], [1.0353, -3.8637], [2.0, -3.4641], [2.8284, -2.8284], [3.4641, -2.0], [3.8637, -1.0353]]
band = 2.5
cup_depth = 0.3

[tooling]
clearance_mm = 0.02
tip_length_mm = 8.0
taper_deg = {taper}
"""


def test_report_refuses_a_taper_whose_bore_passes_a_spline_dent(capsys, tmp_path):
    """An outward offset past the spline's smallest concave radius of curvature (less 1 %) loops: the drafted
    bore, 4 mm x tan(9.5 deg) = 0.6694 mm outward at its top, is refused with the largest taper allowed."""
    line = _refusal(capsys, tmp_path, DENTED.format(taper=9.5), "report")
    assert line == ("error: tooling.taper_deg = 9.5 deg is not allowed: must be <= 8.98497 deg: the die bore drafted "
                    "over 4 mm grows 0.6694 mm outward, at most 0.632463 mm (its smallest concave radius of curvature "
                    "is 0.6389 mm, and the offset must stay regular and keep its notches open)")
    src = tmp_path / "d.toml"
    src.write_text(DENTED.format(taper=8.98497), encoding="utf-8")
    assert main(["report", str(src)]) == 0
    line = _refusal(capsys, tmp_path, DENTED.format(taper=8.98498), "report")  # one step above: the same bound
    assert line.startswith("error: tooling.taper_deg = 8.98498 deg is not allowed: must be <= 8.98497 deg: ")


def test_the_same_outline_of_lines_and_arcs_is_reported(tmp_path):
    src = tmp_path / "d.toml"
    src.write_text(SEGMENTS, encoding="utf-8")
    assert main(["report", str(src)]) == 0


# ----------------------------------------------------------------------------- against OpenCascade

@pytest.mark.cad
@pytest.mark.parametrize("design, needle", [(ROUND.format(height=2.5), "does not fit the bottom face"),
                                            (STROKE.format(height=2.5, angle=25.0), "strokes would meet"),
                                            (OVAL_STROKE, "strokes would meet"),
                                            (SPLINE_CORNER.format(clearance=0.3), "tooling.clearance_mm")])
def test_report_and_build_refuse_with_the_same_line(capsys, tmp_path, design, needle):
    report = _refusal(capsys, tmp_path, design, "report")
    build = _refusal(capsys, tmp_path, design, "build")
    assert report == build and needle in report


@pytest.mark.cad
def test_text_just_inside_the_limit_builds(tmp_path):
    """1.528 mm, below the tallest that fits (1.5283608901): reported, and the tooling is made with it, the
    figure cut (the Booleans' manifold3d checks and the closed-position check, which the text does not
    touch, left to the tooling tests: the build's fit check is the one made here)."""
    import tomllib

    from tabletcad.pipeline.design import Design
    from tabletcad.tooling.toolset import make_tooling

    src = tmp_path / "d.toml"
    src.write_text(ROUND.format(height=1.528), encoding="utf-8")
    assert main(["report", str(src)]) == 0
    d = Design.from_dict(tomllib.loads(src.read_text(encoding="utf-8")))
    ts = make_tooling(d.build(), d.tooling_spec, check=False, interference_check=False)
    (figure,) = ts.report["emboss"]
    assert figure["text"] == "ABCDEFGH" and figure["height_mm"] == 1.528 and figure["figure_area_mm2"] > 5.0
    assert ts.report["lower_punch"]["volume_mm3"] > 0


@pytest.mark.cad
def test_the_fit_on_a_concave_outline_is_occs_boolean_below_its_offset_limit(capsys, tmp_path):
    """The peanut's bar inset by 0.62 and 0.68 mm (below its neck's half width 0.687434): the core's area outside is the
    OCC Boolean's and both refuse with the same line; at 0.72 mm (beyond it) the core says nothing and the build
    refuses after the solid, OCC's offset of the outline giving two wires (the README's list), writing nothing."""
    from tabletcad.cad._occ import explore
    from tabletcad.geometry.lettering import outside_area
    from tabletcad.tooling.emboss import check_fit, figure_faces
    from tabletcad.tooling.outline import face_area, offset_wire, plan_face, tablet_frame
    from tabletcad.tooling.spec import figure_contours, figure_fit_refusal, tooling_plan_outline

    from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut

    for margin in (0.6, 0.66):
        d = _design(tmp_path, PEANUT.format(margin=margin))
        t, e = d.build(), d.tooling_spec.emboss[0]
        frame, outline, inset = tablet_frame(t), tooling_plan_outline(t), 0.02 + margin
        cut = BRepAlgoAPI_Cut(figure_faces(e), plan_face(offset_wire(frame.outline, -inset))).Shape()
        occ = sum(face_area(f) for f in explore(cut, "Face"))
        assert outside_area(figure_contours(e), outline, inset)[1] == pytest.approx(occ, abs=1e-9)
        mine = figure_fit_refusal(e, 0, figure_contours(e), outline, inset)
        with pytest.raises(DesignError) as theirs:
            check_fit(frame, e, figure_faces(e), 0.02)
        assert str(mine) == str(theirs.value)
    (tmp_path / "d.toml").write_text(PEANUT.format(margin=0.7), encoding="utf-8")
    assert main(["build", str(tmp_path / "d.toml"), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    assert not (tmp_path / "out").exists()
    assert capsys.readouterr().err.strip() == PEANUT_PARTS  # (it had said the face "is empty")


#: the build's refusal of the peanut's bar inset by 0.02 + 0.7 mm, past the neck's half width 0.6874342087 mm
PEANUT_PARTS = ("error: tooling.emboss[0].outline = '4 points' is not allowed: does not fit: the face inset by 0.72 mm "
                "(clearance + land + margin) parts in two at a neck 1.37487 mm wide; a margin_mm < 0.667434 mm would "
                "keep it one region")


def test_the_face_parted_at_a_neck_is_refused_as_parted_without_occ(tmp_path):
    """The line the build gives when OCC's offset of the peanut parts in two, made of the core's numbers: the neck's
    half width by bisection of offset_bounds_inset (to 1e-9 mm), the margin that keeps the face one region."""
    from tabletcad.families.outline import whole_inset_limit
    from tabletcad.tooling.spec import inset_face_refusal, tooling_plan_outline

    d = _design(tmp_path, PEANUT.format(margin=0.7))
    outline = tooling_plan_outline(d.build())
    assert whole_inset_limit(outline, 0.72) == pytest.approx(1.1874342087037915 - 0.5, abs=2e-9)
    assert whole_inset_limit(outline, 0.6) == 0.6  # (whole there)
    assert "error: " + str(inset_face_refusal(d.tooling_spec.emboss[0], 0, outline, 0.72)) == PEANUT_PARTS


def test_a_face_inset_past_the_inscribed_radius_is_refused_as_empty_with_the_margin_that_leaves_one(tmp_path):
    """The core's refusal of a figure whose face is inset past the outline's inscribed radius (the 10 mm round:
    5 mm) says so, and the margin below which a face is left (it had said only that the face is empty)."""
    from tabletcad.tooling.spec import figure_contours, figure_fit_refusal, tooling_plan_outline

    d = _design(tmp_path, ROUND.format(height=1.0) + "margin_mm = 5.0\n")
    e = d.tooling_spec.emboss[0]
    refusal = figure_fit_refusal(e, 0, figure_contours(e), tooling_plan_outline(d.build()), 5.1)
    assert str(refusal) == ("tooling.emboss[0].text = 'ABCDEFGH' is not allowed: does not fit: the face inset by 5.1 mm "
                            "(clearance + land + margin) is empty: the outline's inscribed radius is 5 mm; a margin_mm "
                            "< 4.9 mm would leave a face")


@pytest.mark.cad
@pytest.mark.parametrize("margin, parted", [(0.667434, False), (0.667435, True)])
def test_the_margin_quoted_keeps_occs_face_one_region(tmp_path, margin, parted):
    """OCC's offset of the peanut agrees at the printed digits: at the margin quoted the face is one region (the
    bar is refused for lying outside it, across the neck), a unit of its last digit more parts it."""
    from tabletcad.tooling.emboss import check_fit, figure_faces
    from tabletcad.tooling.outline import tablet_frame

    d = _design(tmp_path, PEANUT.format(margin=margin))
    e = d.tooling_spec.emboss[0]
    with pytest.raises(DesignError) as refused:
        check_fit(tablet_frame(d.build()), e, figure_faces(e), 0.02)
    assert ("parts in two at a neck 1.37487 mm wide; a margin_mm < 0.667434 mm" in str(refused.value)) == parted
    assert ("mm^2 outside the punch tip inset by 0.687 mm" in str(refused.value)) == (not parted)


@pytest.mark.cad
def test_glyphs_are_occs_vertex_for_vertex():
    """Random strings in five DejaVu fonts at random sizes: every vertex of OCC's glyph faces is a contour end
    of the core's and back, to 1e-12 mm (kerning, the last symbol's self-kerning, composite glyphs)."""
    import random

    from OCP.BRep import BRep_Tool
    from scipy.spatial import cKDTree

    from tabletcad.cad._occ import explore
    from tabletcad.geometry.lettering import text_contours
    from tabletcad.tooling.emboss import text_faces
    from tabletcad.tooling.spec import font_path

    rnd = random.Random(1)
    chars = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789 .,-/%&ÅÉüß"
    fonts = ["DejaVuSans-Bold", "DejaVuSans", "DejaVuSerif", "DejaVuSansMono-Bold", "DejaVuSansCondensed"]
    for text in ["LT", "AV To", "ÅÉ8"] + ["".join(rnd.choice(chars) for _ in range(rnd.randint(2, 7))) for _ in range(20)]:
        if not text.strip():
            continue
        path, size = font_path(rnd.choice(fonts)), rnd.uniform(0.5, 4.0)
        occ = np.array([(BRep_Tool.Pnt_s(v).X(), BRep_Tool.Pnt_s(v).Y())
                        for v in explore(text_faces(text, size, path), "Vertex")])
        ends = np.array([c[0] for contour in text_contours(text, size, path) for c in contour])
        assert max(cKDTree(ends).query(occ)[0].max(), cKDTree(occ).query(ends)[0].max()) < 1e-12, text


@pytest.mark.cad
@pytest.mark.parametrize("name", ["STIXGeneral", "STIXGeneralBol", "STIXGeneralItalic", "STIXGeneralBolIta", "cmr10",
                                  "cmss10", "DejaVuSansMono-Bold"])
def test_glyphs_are_occs_vertex_for_vertex_at_any_units_per_em(name):
    """The bundled fonts of 1000 units per em (STIX), the TeX ones (2048, their own encoding) and a composite
    with a 2x2 matrix (DejaVu Sans Mono Bold's 'ď'): every vertex OCC's to 1e-12 mm, random strings of the
    characters each font has (the plain scaling had left STIX up to 1.5e-5 mm off)."""
    import random

    from fontTools.ttLib import TTFont
    from OCP.BRep import BRep_Tool
    from scipy.spatial import cKDTree

    from tabletcad.cad._occ import explore
    from tabletcad.geometry.lettering import text_contours
    from tabletcad.tooling.emboss import text_faces

    path = _mpl_font(name)
    chars = [chr(u) for u in sorted(TTFont(path, lazy=True).getBestCmap()) if 33 <= u < 0x250 and chr(u).isprintable()]
    rnd = random.Random(name)
    texts = ["D1", "ď" if "ď" in chars else "AV"] + ["".join(rnd.choice(chars) for _ in range(rnd.randint(2, 6)))
                                                     for _ in range(8)]
    for text in texts:
        size = rnd.uniform(0.5, 4.0)
        occ = np.array([(BRep_Tool.Pnt_s(v).X(), BRep_Tool.Pnt_s(v).Y())
                        for v in explore(text_faces(text, size, path), "Vertex")])
        ends = np.array([c[0] for contour in text_contours(text, size, path) for c in contour])
        assert max(cKDTree(ends).query(occ)[0].max(), cKDTree(occ).query(ends)[0].max()) < 1e-12, (text, size)


@pytest.mark.cad
def test_the_fit_is_occs_boolean(tmp_path):
    """Figures placed at random on five tablets (round, oval, capsule, rounded triangle, a custom outline of
    lines and arcs; turned, on either face): the core refuses exactly those the tooling's OCC Boolean refuses,
    with the tooling's own line (the area outside to its three figures, the size the exact box of both; the
    areas agreed to 1.6e-13 mm^2 on 40 such figures when this was written)."""
    import random

    from tabletcad.pipeline.design import Design
    from tabletcad.tooling.emboss import check_fit, figure_faces
    from tabletcad.tooling.outline import tablet_frame
    from tabletcad.tooling.spec import figure_contours, figure_fit_refusal, parse_tooling, tooling_plan_outline

    rnd = random.Random(3)
    files = ["families/concave_round", "families/oval", "families/capsule", "families/rounded_triangle",
             "families/custom_outline"]
    refused = 0
    for name in files:
        t = Design.from_toml(ROOT / "samples" / f"{name}.toml").build()
        frame, outline = tablet_frame(t), tooling_plan_outline(t)
        for _ in range(4):
            e = parse_tooling({"clearance_mm": 0.02, "emboss": [{
                "text": rnd.choice(["AB", "10", "X8", "WWW", "Ag%"]), "height_mm": rnd.uniform(1.5, 4.0),
                "face": rnd.choice(["top", "bottom"]), "position_mm": [rnd.uniform(-3, 3), rnd.uniform(-2, 2)],
                "rotation_deg": rnd.uniform(0, 360), "font": rnd.choice(["DejaVuSans-Bold", "DejaVuSerif"]),
                "depth_mm": 0.05}]}).emboss[0]
            inset = 0.02 + frame.edge_land(e.face) + e.margin_mm
            mine = figure_fit_refusal(e, 0, figure_contours(e), outline, inset)
            try:
                check_fit(frame, e, figure_faces(e), 0.02)
                theirs = None
            except DesignError as exc:
                theirs = exc
            assert (mine is None) == (theirs is None), (name, e)
            if mine is not None:
                refused += 1
                assert str(mine) == str(theirs)
    assert refused >= 5


@pytest.mark.cad
@pytest.mark.parametrize("angle", [22.0, 22.468, 22.469, 25.0])
def test_the_stroke_angle_refusal_is_the_tooling_s(tmp_path, angle):
    """The core's stroke width (exact Bézier lengths) and the tooling's (OCC's lengths, asked to 1e-12) agree to
    round-off, so both refuse the same angles with the same line, even 0.001 deg either side of the limit."""
    from tabletcad.tooling.emboss import check_emboss
    from tabletcad.tooling.outline import tablet_frame
    from tabletcad.tooling.spec import figure_contours, stroke_angle_refusal

    d = _design(tmp_path, STROKE.format(height=2.5, angle=angle))
    e = d.tooling_spec.emboss[0]
    mine = stroke_angle_refusal(e, 0, figure_contours(e))
    try:
        check_emboss(tablet_frame(d.build()), e, 0.02, 0)
        theirs = None
    except DesignError as exc:
        theirs = str(exc)
    assert (None if mine is None else str(mine)) == theirs
    assert (mine is None) == (angle < 22.468013302665)  # atan(0.5 x 0.41356 / 0.5)
