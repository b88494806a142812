"""Embossing by the rules: stroke angle, SVG logos, legibility numbers against closed forms."""

import math
from pathlib import Path

import pytest

pytest.importorskip("OCP")
pytest.importorskip("build123d")

from tabletcad.pipeline.design import load_design  # noqa: E402
from tabletcad.errors import DesignError  # noqa: E402
from tabletcad.tooling.emboss import check_emboss  # noqa: E402
from tabletcad.tooling.outline import tablet_frame  # noqa: E402
from tabletcad.tooling.spec import EmbossSpec, ToolingSpec, parse_tooling  # noqa: E402

pytestmark = pytest.mark.cad

ROOT = Path(__file__).resolve().parents[1]
CLEARANCE = 0.02
TIP_R = 5.0 - CLEARANCE  # the 10 mm concave round's punch tip radius

CIRCLE_SVG = ('<svg xmlns="http://www.w3.org/2000/svg" width="100" height="100" viewBox="0 0 100 100">'
              '<circle cx="50" cy="50" r="40" fill="black"/></svg>')


@pytest.fixture(scope="module")
def frame():
    return tablet_frame(load_design(ROOT / "samples" / "families" / "concave_round.toml"))


@pytest.fixture(scope="module")
def logo(tmp_path_factory):
    p = tmp_path_factory.mktemp("svg") / "circle.svg"
    p.write_text(CIRCLE_SVG)
    return str(p)


def test_bar_legibility_numbers_are_the_closed_forms(frame):
    L, w = 3.0, 0.3
    bar = ((-L / 2, -w / 2), (L / 2, -w / 2), (L / 2, w / 2), (-L / 2, w / 2))
    _, info = check_emboss(frame, EmbossSpec(outline=bar, depth_mm=0.1), CLEARANCE)
    leg = info["legibility"]
    assert leg["stroke_width_mm"] == pytest.approx(w * L / (w + L), rel=1e-12)  # 2A/P of a rectangle
    assert leg["land_to_tip_edge_mm"] == pytest.approx(TIP_R - math.hypot(L / 2, w / 2), abs=1e-7)
    assert leg["sharp_corners"] == 4 and leg["min_edge_radius_mm"] is None
    assert leg["depth_over_cup_depth"] == pytest.approx(0.1 / 0.9, rel=1e-6)
    assert leg["stroke_width_over_tablet_size"] == pytest.approx(leg["stroke_width_mm"] / 10.0, rel=1e-6)


def test_svg_logo_is_centred_scaled_and_measured(frame, logo):
    _, info = check_emboss(frame, EmbossSpec(svg=logo, height_mm=3.0, depth_mm=0.1), CLEARANCE)
    leg = info["legibility"]
    assert info["size_mm"] == pytest.approx([3.0, 3.0], abs=1e-6)
    assert leg["stroke_width_mm"] == pytest.approx(1.5, rel=1e-6)  # 2A/P of a disc = its radius
    assert leg["min_edge_radius_mm"] == pytest.approx(1.5, rel=1e-6)
    assert leg["sharp_corners"] == 0
    assert leg["land_to_tip_edge_mm"] == pytest.approx(TIP_R - 1.5, abs=1e-6)


@pytest.mark.parametrize("emboss, parameter", [
    ({"text": "A", "stroke_angle_deg": 60.0}, "stroke_angle_deg"),
    ({"text": "A", "stroke_angle_deg": -1.0}, "stroke_angle_deg"),
    ({"text": "A", "stroke_angle_deg": 30.0, "draft_deg": 30.0}, "draft_deg"),
    ({"svg": "/no/such/logo.svg"}, "svg"),
    ({"text": "A", "svg": "x.svg"}, "text"),
])
def test_bad_emboss_input_is_one_design_error(emboss, parameter):
    with pytest.raises(DesignError) as e:
        parse_tooling({"emboss": [emboss]})
    assert parameter in e.value.parameter and "\n" not in str(e.value)


def test_stroke_angle_that_closes_the_strokes_is_a_design_error(frame):
    bar = ((-1.0, -0.25), (1.0, -0.25), (1.0, 0.25), (-1.0, 0.25))  # 2A/P = 0.4 mm
    limit = math.degrees(math.atan(0.2 / 0.3))
    assert check_emboss(frame, EmbossSpec(outline=bar, depth_mm=0.3, draft_deg=limit - 1.0), CLEARANCE)
    with pytest.raises(DesignError, match=f"must be < {limit:.3g} deg"):
        check_emboss(frame, EmbossSpec(outline=bar, depth_mm=0.3, draft_deg=limit + 1.0), CLEARANCE)


def test_debossed_logo_with_stroke_angle_removes_the_frustum(logo):
    """On a flat face a disc of radius r debossed d deep with walls at angle a removes the frustum
    pi d (r^2 + r r' + r'^2) / 3 with r' = r - d tan(a): the figure is nominal at the face."""
    from tabletcad.tooling.toolset import make_tooling

    t = load_design(ROOT / "samples" / "families" / "ffbe.toml")
    d, a, r = 0.2, 30.0, 1.5
    spec = ToolingSpec(emboss=(EmbossSpec(svg=logo, height_mm=2 * r, depth_mm=d, draft_deg=a),))
    ts = make_tooling(t, spec, check=False, interference_check=False)
    rp = r - d * math.tan(math.radians(a))
    removed = ts.report["tablet"]["volume_plain_mm3"] - ts.report["tablet"]["volume_mm3"]
    assert removed == pytest.approx(math.pi * d * (r * r + r * rp + rp * rp) / 3.0, rel=1e-6)
    assert ts.report["emboss"][0]["width_variation_at_face_mm"] == pytest.approx(0.0, abs=1e-9)
