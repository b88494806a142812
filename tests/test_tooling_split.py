"""Scores of every kind and the split tablet: parts, masses and break surface against closed forms."""

import math
from dataclasses import replace
from pathlib import Path

import pytest

pytest.importorskip("OCP")
pytest.importorskip("manifold3d")

from scipy.integrate import quad  # noqa: E402

from tabletcad.pipeline.design import Design, load_design  # noqa: E402
from tabletcad.errors import DesignError  # noqa: E402
from tabletcad.tooling.spec import ScoreSpec, ToolingSpec, parse_tooling  # noqa: E402
from tabletcad.tooling.split import split_directions  # noqa: E402
from tabletcad.tooling.toolset import make_tooling  # noqa: E402

pytestmark = pytest.mark.cad

ROOT = Path(__file__).resolve().parents[1]
FLAT = ROOT / "samples" / "families" / "flat_face_round.toml"  # 10 mm x 3.5 mm cylinder, [report] 0.85 x 1.5 mg/mm3
R, H, DENSITY = 5.0, 3.5, 0.85 * 1.5


def _groove_volume(d: float) -> float:
    """A 90-degree V groove d deep across a flat disc face of radius R: its depth is d - |s| at offset s
    from the centre line and its length the chord 2 sqrt(R^2 - s^2)."""
    return quad(lambda s: (d - abs(s)) * 2.0 * math.sqrt(R * R - s * s), -d, d, epsabs=1e-13)[0]


@pytest.fixture(scope="module")
def flat():
    return load_design(FLAT)


def test_cut_through_bisect_splits_into_equal_halves_with_the_closed_form_break_surface(flat):
    d = 0.3
    # the design's [report] table gives the density of the parts' masses
    ts = make_tooling(flat, ToolingSpec(scores=(ScoreSpec(depth_mm=d, cut_through=True),)), check=False,
                      interference_check=False, options=Design.from_toml(FLAT).report_options)
    sp = ts.report["split"]
    half = 0.5 * (math.pi * R * R * H - _groove_volume(d))
    assert sp["n_parts"] == 2
    for p in sp["parts"]:
        assert p["volume_mm3"] == pytest.approx(half, rel=1e-7)
        assert p["mass_mg"] == pytest.approx(half * DENSITY, rel=1e-7)
        assert abs(p["deviation_from_equal_share_percent"]) < 1e-5
    # the break plane holds the groove's bottom line: a 2R x (H - d) rectangle
    assert sp["break_surface_area_mm2"] == pytest.approx(2 * R * (H - d), rel=1e-9)
    assert sp["within_limit"] and sp["split_loss_limit_percent"] == 3.0 and "FDA" in sp["split_loss_limit_source"]


def test_short_score_removes_its_prism_and_breaks_nothing(flat):
    """A short score ends on the face: decorative, no break plane (a tablet with only one is not split).
    Beside a full bisect across it, the tablet splits in two along the bisect alone (it had been
    counted as a second plane: four quarters), and the break plane loses the short V's section, d²."""
    d, L = 0.3, 4.0
    s = ScoreSpec(depth_mm=d, length_mm=L, direction_deg=90.0)
    ts = make_tooling(flat, ToolingSpec(scores=(s,)), check=False, interference_check=False)
    removed = ts.report["tablet"]["volume_plain_mm3"] - ts.report["tablet"]["volume_mm3"]
    # triangle d x 2d / 2 times the length (difference of two 275 mm3 B-rep volumes: abs 1e-6)
    assert removed == pytest.approx(d * d * L, abs=1e-6)
    assert ts.report["split"] is None
    bisect = ScoreSpec(depth_mm=d, cut_through=True, direction_deg=0.0)
    ts = make_tooling(flat, ToolingSpec(scores=(bisect, replace(s, faces="bottom"))), check=False,
                      interference_check=False)
    sp = ts.report["split"]
    assert sp["directions_deg"] == [0.0] and sp["n_parts"] == 2
    assert sp["break_surface_area_mm2"] == pytest.approx(2 * R * (H - d) - d * d, rel=1e-9)


@pytest.mark.parametrize("scores, dirs", [
    ([ScoreSpec(direction_deg=90.0)], [90.0]),
    ([ScoreSpec(kind="quadrisect", direction_deg=30.0)], [30.0, 120.0]),
    ([ScoreSpec(direction_deg=0.0, faces="both"), ScoreSpec(direction_deg=180.0)], [0.0]),
    ([ScoreSpec(direction_deg=0.0), ScoreSpec(direction_deg=90.0, length_mm=4.0)], [0.0]),
    ([ScoreSpec(kind="quadrisect", length_mm=3.0)], []),
])
def test_split_directions(scores, dirs):
    assert split_directions(scores) == pytest.approx(dirs)


@pytest.mark.parametrize("score, parameter", [
    ({"length_mm": 4.0, "cut_through": True}, "length_mm"),
    ({"length_mm": -1.0}, "length_mm"),
])
def test_bad_short_scores(score, parameter):
    with pytest.raises(DesignError) as e:
        parse_tooling({"score": [score]})
    assert parameter in e.value.parameter


def test_short_score_must_end_on_the_face(flat):
    with pytest.raises(DesignError, match="short score must end on the face"):
        make_tooling(flat, ToolingSpec(scores=(ScoreSpec(depth_mm=0.3, length_mm=9.9),)), check=False,
                     interference_check=False)
