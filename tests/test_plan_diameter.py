"""The plan's diameter (its largest extent in any direction) and the FDA size check that reads it.

The FDA size line took the largest of length, width and thickness along the axes, so a 20 mm rounded
square with 1 mm corners (diagonal 2 √2 x 9 + 2 = 27.46 mm) was "OK" under the 22 mm guidance.  The
outline's diameter is now exact (lines, arcs: :attr:`PlanOutline.diameter`); checked against closed
forms and against dense samples of random outlines.  Core only.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from tabletcad.families.outline import outline_from_items
from tabletcad.pipeline.design import Design
from tabletcad.pipeline.designreport import design_report

ROOT = Path(__file__).resolve().parents[1]


def _outline(tablet: dict):
    return Design.from_dict({"tablet": tablet}).build().nominal.outline


def _largest_distance(xy: np.ndarray, directions: int = 256) -> float:
    """The largest distance (mm) between any two of the points ``xy`` (m, 2): the largest of every pair's
    that can be it, each computed as ``np.linalg.norm`` of the pair's difference, as all pairs' would be.

    Only pairs near the two ends of one of ``directions`` directions ``u`` spread over a half-turn can be
    it: the farthest pair ``p, q`` (``p - q`` within ``α <= π / (2 directions)`` of some ``u``) has
    ``(p - q)·u = D cos α`` while no two points are farther apart along ``u`` than ``D``, so ``p·u`` lies
    within ``D (1 - cos α)`` of the largest ``x·u`` and ``q·u`` as near the least; ``D`` is at most the
    bounding box's diagonal, and 1e-9 of it more covers the rounding of the projections.  (All pairs of
    3,000 samples, 200 rows at a time, had taken most of this file's time: 4.5 million distances per
    outline, of which these are a few thousand.)"""
    turn = np.arange(directions) * (math.pi / directions)
    proj = xy @ np.array([np.cos(turn), np.sin(turn)])  # (m, directions)
    bound = float(np.hypot(*np.ptp(xy, axis=0)))
    margin = bound * (1.0 - math.cos(math.pi / (2 * directions))) + 1e-9 * bound
    high = proj >= proj.max(axis=0) - margin
    low = proj <= proj.min(axis=0) + margin
    return max(float(np.max(np.linalg.norm(xy[high[:, k], None, :] - xy[None, low[:, k], :], axis=2)))
               for k in range(directions))


def _sampled(outline, n: int = 3000) -> float:
    """The largest distance between any two of ``n`` samples of ``outline`` (its hull's vertices)."""
    from scipy.spatial import ConvexHull

    xy = outline.point(np.linspace(0.0, math.tau, n, endpoint=False))
    return _largest_distance(xy[ConvexHull(xy).vertices])


@pytest.mark.parametrize("tablet, exact", [
    (dict(family="rounded_square", side=20.0, corner_radius=1.0, band=3.0, cup_depth=0.5), 2 * math.hypot(9, 9) + 2),
    (dict(family="rounded_rectangle", length=21.5, width=9.0, corner_radius=0.5, band=3.0, cup_depth=0.3),
     2 * math.hypot(10.25, 4.0) + 1.0),
    (dict(family="capsule", length=19.0, width=8.0, band=3.0, cup_depth=1.0), 19.0),
    (dict(family="oval", length=12.0, width=7.0, end_radius=2.0, band=3.0, cup_depth=0.5), 12.0),
    (dict(family="concave_round", diameter=10.0, band=3.0, cup_depth=1.0), 10.0),
])
def test_diameter_closed_forms(tablet, exact):
    assert _outline(tablet).diameter == pytest.approx(exact, rel=1e-14)


@pytest.mark.parametrize("sample", sorted((ROOT / "samples" / "families").glob("*.toml")), ids=lambda p: p.stem)
def test_diameter_of_every_family_sample_against_dense_samples(sample):
    o = Design.from_toml(sample).build().nominal.outline
    d, s = o.diameter, _sampled(o)
    assert s <= d * (1 + 1e-12) and d - s <= 2e-5 * d  # 3,000 samples: a step of ~0.02 mm


@settings(max_examples=40, deadline=None)
@given(side=st.floats(6.0, 20.0), r=st.floats(0.3, 0.45), stretch=st.floats(1.0, 2.5), turn=st.floats(0.0, math.pi))
def test_diameter_of_random_rotated_rounded_rectangles(side, r, stretch, turn):
    """A rounded rectangle turned by ``turn``: the diameter is the turned one's (2 |c| + 2 r for the
    corner centres c), whatever the direction, and no dense sample exceeds it."""
    L, W, rc = side * stretch, side, r * side
    c, sn = math.cos(turn), math.sin(turn)
    segs = []
    corners = [(L / 2 - rc, W / 2 - rc), (-L / 2 + rc, W / 2 - rc), (-L / 2 + rc, -W / 2 + rc), (L / 2 - rc, -W / 2 + rc)]
    rot = lambda x, y: (c * x - sn * y, sn * x + c * y)  # noqa: E731
    for k, (cx, cy) in enumerate(corners):
        a0 = 0.5 * math.pi * k + turn
        segs.append(("arc", rot(cx, cy), rc, a0, 0.5 * math.pi))
        nx, ny = corners[(k + 1) % 4]
        a1 = a0 + 0.5 * math.pi
        p0 = (rot(cx, cy)[0] + rc * math.cos(a1), rot(cx, cy)[1] + rc * math.sin(a1))
        p1 = (rot(nx, ny)[0] + rc * math.cos(a1), rot(nx, ny)[1] + rc * math.sin(a1))
        segs.append(("line", p0, p1))
    o = outline_from_items(segs)
    exact = 2 * math.hypot(L / 2 - rc, W / 2 - rc) + 2 * rc
    assert o.diameter == pytest.approx(exact, rel=1e-12)
    assert o.diameter * (1 - 1e-4) <= _sampled(o, 2000) <= o.diameter * (1 + 1e-12)


def test_the_fda_size_line_reads_the_diagonal():
    rep = design_report(Design.from_dict({"tablet": dict(family="rounded_square", side=20.0, corner_radius=1.0,
                                                           band=3.0, cup_depth=0.5)}).build())["design_report"]
    fda = rep["fda_size"]
    assert fda["largest_dimension_mm"] == pytest.approx(2 * math.hypot(9, 9) + 2, rel=1e-14) and fda["ok"] is False
    assert rep["length_mm"] == rep["width_mm"] == 20.0  # the extents stay what they are


def test_a_shape_design_report_samples_the_plan_diameter():
    """A tablet without a family outline (free-form, the thesis's shapes not of revolution) takes the
    largest distance between its surface samples in plan: never above the extents' diagonal, and the
    stadium's length when it lies along the axes."""
    from tabletcad.pipeline.designreport import _sampled_plan_diameter, shape_design_report

    t = Design.from_toml(ROOT / "samples" / "free_form_stadium.toml").build()
    d = _sampled_plan_diameter(t)
    dims = t.dimensions()
    assert dims["length_mm"] * (1 - 1e-4) <= d <= dims["length_mm"] * (1 + 1e-12)
    assert shape_design_report(t)["fda_size"]["largest_dimension_mm"] == dims["length_mm"]
    assert _sampled_plan_diameter(Design.from_toml(ROOT / "samples" / "flat_faced_round.toml").build()) is None


@pytest.mark.parametrize("name", ["caplet", "deep_convex_oval"])
def test_an_ellipse_section_tablets_diameter_agrees_with_its_samples(name):
    """The thesis's ovals and caplet (scaled copies of one plan ellipse): ``2 R_max σ_max(N)`` against the
    largest distance between 33 x 256 samples of every patch (an independent computation)."""
    from scipy.spatial import ConvexHull

    from tabletcad.pipeline.designreport import _sampled_plan_diameter

    t = Design.from_toml(ROOT / "samples" / f"{name}.toml").build()
    assert t.section is not None
    xy = t.sample(33, 256)[..., :2].reshape(-1, 2)
    xy = xy[ConvexHull(xy).vertices]
    sampled = float(np.max(np.linalg.norm(xy[:, None, :] - xy[None, :, :], axis=2)))
    d = _sampled_plan_diameter(t)
    assert sampled <= d * (1 + 1e-12) and d - sampled <= 1e-4 * d


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.floats(-50, 50), st.floats(-50, 50)), min_size=1, max_size=60), st.integers(0, 2))
def test_rotating_calipers_agree_with_every_pair(pts, shape):
    """The hull's diameter by rotating calipers against the largest of all pairwise distances (random
    points, points on a circle, points on one line)."""
    from tabletcad.families.outline import point_set_diameter

    P = np.array(pts, dtype=float)
    if shape == 1:  # on a circle: every point a hull vertex
        t = np.linspace(0.0, math.tau, len(P), endpoint=False)
        P = 7.0 * np.stack([np.cos(t), np.sin(t)], axis=1) + P[:1]
    elif shape == 2:  # on one line
        P = P[:, :1] * np.array([[1.0, 0.5]])
    brute = float(np.max(np.linalg.norm(P[:, None, :] - P[None, :, :], axis=2)))
    assert point_set_diameter(P) == pytest.approx(brute, rel=1e-12, abs=1e-12)


def test_a_point_outline_s_diameter_is_cheap():
    """A custom outline through points (a periodic spline, 8,192 samples nearly all on its hull): the
    pairwise distances had taken 3 GB and 7 s; an ellipse's diameter is its major axis."""
    import tracemalloc

    from tabletcad.families.outline import SplineOutline

    t = np.linspace(0.0, math.tau, 24, endpoint=False)
    o = SplineOutline(np.stack([6.0 * np.cos(t), 4.0 * np.sin(t)], axis=1))
    tracemalloc.start()
    d = o.diameter
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert d == pytest.approx(12.0, rel=1e-3) and peak < 50e6


@pytest.mark.parametrize("tablet, across", [
    ({"family": "rounded_square", "side": 18.0, "corner_radius": 1.0, "band": 3.0, "cup_depth": 0.5},
     18.0 * math.sqrt(2.0) - 2.0 * (math.sqrt(2.0) - 1.0)),  # corner centres 8 mm from the axes, + their radius
    ({"family": "capsule", "length": 19.0, "width": 8.0, "band": 3.0, "cup_depth": 1.0}, 19.0),
    ({"family": "concave_round", "diameter": 10.0, "band": 3.0, "cup_depth": 1.0}, 10.0),
])
def test_the_plan_diameter_a_die_is_chosen_by_is_the_largest_extent_in_any_direction(tablet, across):
    """:func:`plan_diameter` (what the TSM die and the punch standard's largest tablet are read from): the
    rounded square's diagonal in closed form (the extents along the axes, 18 mm, had chosen a B die for a
    24.6 mm-across square), a capsule's length, a round's diameter; never below the PDE tablet's extents,
    which stand micrometres outside the nominal outline."""
    from tabletcad.pipeline.designreport import plan_diameter

    t = Design.from_dict({"tablet": tablet}).build()
    d = plan_diameter(t)
    lo, hi = t.bounds()
    assert d >= max(hi[0] - lo[0], hi[1] - lo[1]) and d == pytest.approx(across, rel=1e-12, abs=1e-5)
    if tablet["family"] == "rounded_square":
        assert d == pytest.approx(across, rel=1e-12) and d > 1.3 * (hi[0] - lo[0])
