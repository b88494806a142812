"""A free-form or custom-outline design keeps its plan within the size limit a family's diameter or
length keeps (``Tolerances.max_length``, 1000 mm): each of its numbers lay within ±1000 mm, but a circle
of radius 1000 mm built a tablet 2000 mm across (a free form's 2001 mm: its surface bulges past its
curves), and an arc of radius 400 mm about (900, 0) reached x = 1300 mm.  Core only."""

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
