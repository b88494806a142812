"""A free-form or custom-outline design keeps its plan within the size limit a family's diameter or
length keeps (``Tolerances.max_length``, 1000 mm): each of its numbers lay within ±1000 mm, but a circle
of radius 1000 mm built a tablet 2000 mm across (a free form's 2001 mm: its surface bulges past its
curves), and an arc of radius 400 mm about (900, 0) reached x = 1300 mm.  So does every tablet's height (a concave
round's band and cups had added up to 1799 mm).  Core only."""

from __future__ import annotations

import math
import re

import pytest

from tabletcad.cli import main
from tabletcad.errors import DesignError
from tabletcad.pipeline.design import Design

ONE_LINE = re.compile(r"^error: (\S+) = '(.+)' is not allowed: must keep the tablet's plan within ±1000 mm and its "
                      r"length and width \(along x and y\) at most 1000 mm \(size limit, Tolerances\.max_length, as a "
                      r"family's diameter or length\)$")
TURN = 2.0 * math.pi


def _circle_segments(r: float, cx: float = 0.0) -> dict:
    return {"tablet": {"family": "custom_outline", "segments": [["arc", [cx, 0.0], r, 0.0, TURN]],
                       "band": 2.0, "cup_depth": 0.5}}


def _circle_points(r: float, n: int = 64) -> dict:
    pts = [[r * math.cos(TURN * k / n), r * math.sin(TURN * k / n)] for k in range(n)]
    return {"tablet": {"family": "custom_outline", "outline": pts, "band": 2.0, "cup_depth": 0.5}}


def _free_form_disc(r: float) -> dict:
    face = lambda z, up: [{"type": "circle", "radius": q, "z": z} for q in ((0.0, r / 3, 2 * r / 3, r) if up  # noqa: E731
                                                                           else (r, 2 * r / 3, r / 3, 0.0))]
    band = ["previous"] + [{"type": "circle", "radius": r, "z": z} for z in (1.0, 2.0, 3.0)]
    return {"tablet": {"family": "free_form"},
            "patch": [{"curves": face(0.0, True)}, {"curves": band}, {"curves": ["previous"] + face(3.0, False)[1:]}]}


@pytest.mark.parametrize("data, where, plan", [
    (_circle_segments(1000.0), "tablet.segments", "a plan 2000 x 2000 mm reaching 1000 mm"),
    (_circle_points(1000.0), "tablet.outline", "a plan 2000 x 2000 mm reaching 1000 mm"),
    (_circle_segments(400.0, cx=900.0), "tablet.segments", "a plan 800 x 800 mm reaching 1300 mm"),
    (_circle_segments(500.0 * (1 + 1e-6)), "tablet.segments", "a plan 1000.001 x 1000.001 mm reaching 500.0005 mm"),
    (_free_form_disc(1000.0), "patch", None),
    (_free_form_disc(500.0), "patch", None),  # (1000.5 mm across: the surface bulges 0.25 mm past its curves)
])
def test_a_plan_beyond_the_size_limit_is_refused(tmp_path, capsys, data, where, plan):
    with pytest.raises(DesignError) as e:
        Design.from_dict(data).build()
    m = ONE_LINE.match("error: " + str(e.value))
    assert m and m.group(1) == where, str(e.value)
    if plan is not None:
        assert m.group(2) == plan
    else:  # the free form's own extents, larger than its curves' 2 r
        L, W, reach = map(float, re.fullmatch(r"a plan (\S+) x (\S+) mm reaching (\S+) mm", m.group(2)).groups())
        r = data["patch"][0]["curves"][3]["radius"]
        assert L == W and 2 * r < L < 2 * r * 1.002 and reach == pytest.approx(L / 2, rel=1e-5)
    p = tmp_path / "d.toml"
    p.write_text(Design.from_dict(data).to_toml(), encoding="utf-8")
    assert main(["build", str(p), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["error: " + str(e.value)]
    assert sorted(q.name for q in tmp_path.iterdir()) == ["d.toml"]


@pytest.mark.parametrize("data, size", [(_circle_segments(500.0), 1000.0), (_circle_points(499.0), 998.0),
                                        (_free_form_disc(499.0), None)])
def test_a_plan_within_the_size_limit_builds(data, size):
    t = Design.from_dict(data).build()
    lo, hi = t.bounds()
    if size is not None:  # a circle's plan: its diameter (the 64 points' spline through the circle: within 1e-3)
        assert hi[0] - lo[0] == pytest.approx(size, abs=1e-3) and hi[1] - lo[1] == pytest.approx(size, abs=1e-3)
    assert max(hi[0] - lo[0], hi[1] - lo[1]) <= 1000.0 * (1 + 1e-12) and t.volume() > 0.0  # (the bounds' rounding)


# -- the height: a family's band and cups, a custom outline's, a free form's curves each within the limit, but
# not what they add up to (a concave round's 999 mm band with 400 mm cups had made a tablet 1799 mm thick)

HEIGHT_LINE = re.compile(r"^error: (\S+) = (.+) is not allowed: must keep the tablet's height at most 1000 mm "
                         r"\(size limit, Tolerances\.max_length, as a diameter or length(; the tablet is (\S+) mm tall)?\)$")


def _free_form_cylinder(r: float, z: float) -> dict:
    """A free form: flat discs of radius ``r`` at ``z = ±z`` joined by a band (height ``2 z``)."""
    face = lambda h, up: [{"type": "circle", "radius": q, "z": h} for q in ((0.0, r / 3, 2 * r / 3, r) if up  # noqa: E731
                                                                           else (r, 2 * r / 3, r / 3, 0.0))]
    band = ["previous"] + [{"type": "circle", "radius": r, "z": -z + 2 * z * k / 3} for k in (1, 2, 3)]
    return {"tablet": {"family": "free_form"},
            "patch": [{"curves": face(-z, True)}, {"curves": band}, {"curves": ["previous"] + face(z, False)[1:]}]}


@pytest.mark.parametrize("data, where, value, height", [
    ({"tablet": {"family": "concave_round", "diameter": 999.0, "band": 999.0, "cup_depth": 400.0}},
     "tablet.band", "999 mm", 1799.0),
    ({"tablet": {"family": "concave_round", "diameter": 999.0, "band": 300.0, "cup_depth": 400.0}},
     "tablet.cup_depth", "400 mm", 1100.0),  # (the largest of the lengths that add up: the cups here)
    ({"tablet": {"family": "custom_outline", "segments": [["arc", [0.0, 0.0], 5.0, 0.0, TURN]], "band": 999.0,
                 "cup_depth": 2.0}}, "tablet.band", "999 mm", 1003.0),
    (_free_form_cylinder(400.0, 501.0), "patch", "'a tablet 1002 mm tall'", None),
])
def test_a_tablet_taller_than_the_size_limit_is_refused(tmp_path, capsys, data, where, value, height):
    with pytest.raises(DesignError) as e:
        Design.from_dict(data).build()
    m = HEIGHT_LINE.match("error: " + str(e.value))
    assert m and m.group(1) == where and m.group(2) == value, str(e.value)
    assert (m.group(4) is None) == (height is None) and (height is None or float(m.group(4)) == pytest.approx(height))
    p = tmp_path / "d.toml"
    p.write_text(Design.from_dict(data).to_toml(), encoding="utf-8")
    assert main(["build", str(p), "--out", str(tmp_path / "out")]) == 2
    assert capsys.readouterr().err.strip().splitlines() == ["error: " + str(e.value)]
    assert sorted(q.name for q in tmp_path.iterdir()) == ["d.toml"]


@pytest.mark.parametrize("data, height", [
    ({"tablet": {"family": "concave_round", "diameter": 999.0, "band": 999.0, "cup_depth": 0.5}}, 1000.0),
    (_free_form_cylinder(400.0, 499.0), 998.0),
])
def test_a_tablet_as_tall_as_the_size_limit_builds(data, height):
    t = Design.from_dict(data).build()
    lo, hi = t.bounds()
    assert hi[2] - lo[2] == pytest.approx(height, rel=1e-12) and t.volume() > 0.0


def test_dimensions_a_familys_pde_cannot_follow_are_refused_as_input(tmp_path, capsys):
    """A 999 mm rounded square with 1.8 mm corners: each dimension allowed, but the PDE surface the family
    makes of them lies 1.09 µm from its nominal (allowed 1 µm); refused by one line naming the family (it had
    been a GeometryError's message), a 700 mm one built and certified."""
    data = {"tablet": {"family": "rounded_square", "side": 999.0, "corner_radius": 1.8, "band": 2.6, "cup_depth": 0.6}}
    with pytest.raises(DesignError) as e:
        Design.from_dict(data).build()
    m = re.fullmatch(r"tablet = 'rounded_square' is not allowed: must leave the PDE surface within 1 µm of the "
                     r"rounded_square's nominal \(Tolerances\.nominal; these dimensions leave it (\S+) µm from it\)",
                     str(e.value))
    assert m and 1.0 < float(m.group(1)) < 1.2, str(e.value)
    p = tmp_path / "d.toml"
    p.write_text(Design.from_dict(data).to_toml(), encoding="utf-8")
    assert main(["report", str(p)]) == 2
    assert capsys.readouterr().err.strip().splitlines() == ["error: " + str(e.value)]
    data["tablet"]["side"] = 700.0
    t = Design.from_dict(data).build()
    assert t.nominal_deviation() <= 1e-3
