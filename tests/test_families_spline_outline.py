"""Custom outlines through points (periodic cubic splines) build into watertight solids.

Issue 13 item 7: a smooth 20-point outline of about 9 x 6 mm with a 0.19 mm cup was refused
with ``mesh check failed (... watertight False ...)``.  Root cause: the default cup width is
the outline's smallest radius of curvature, and the inward offset at exactly that distance
stands still at the curvature peak (its speed ``|O'| (1 - d κ)`` vanishes); the plateau's rim
is singular there and the B-spline faces over it fold (duplicate triangles: four triangles on
one edge).  Spline outlines now stop the cup ``Tolerances.offset_regularity`` (1 %) short of
that radius, with the peak curvature found exactly (refined, not sampled).
"""

from __future__ import annotations

import numpy as np
import pytest

from tabletcad.families.outline import SplineOutline
from tabletcad.tolerance import DEFAULT


def ellipse_points(n: int = 20, a: float = 4.5, b: float = 3.0, egg: float = 0.0) -> np.ndarray:
    t = 2.0 * np.pi * np.arange(n) / n
    return np.round(np.column_stack([a * np.cos(t), b * np.sin(t) * (1.0 + egg * np.cos(t))]), 4)


@pytest.mark.parametrize("egg", [0.0, 0.3])
def test_spline_cup_limit_keeps_the_offset_regular(egg):
    ol = SplineOutline(ellipse_points(egg=egg))
    v = np.linspace(0.0, 2.0 * np.pi, 200_001)
    k_dense = float(np.max(ol.frame(v)[3]))
    assert ol.max_curvature >= k_dense * (1.0 - 1e-12)  # no peak missed between samples
    assert ol.max_curvature >= float(np.max(ol.frame(ol._vs)[3]))
    d = ol.min_convex_radius
    assert d == pytest.approx((1.0 - DEFAULT.offset_regularity) / ol.max_curvature, rel=1e-15)
    # the rim O + d N moves at |O'| (1 - d κ) >= offset_regularity |O'| everywhere: a regular curve
    speed = np.linalg.norm(ol.point(v, 1) + d * ol.normal(v, 1), axis=1)
    base = np.linalg.norm(ol.point(v, 1), axis=1)
    assert np.min(speed / base) >= DEFAULT.offset_regularity * (1.0 - 1e-6)
    # for the ellipse-like outline the radius of curvature is near b^2 / a = 2 mm (spline of 20 points)
    if egg == 0.0:
        assert 1.8 < 1.0 / ol.max_curvature < 2.0


@pytest.mark.parametrize("kind", ["spline", "arcs"])
def test_a_patchs_data_evaluated_together_equal_each_on_its_own(kind):
    """A swept tablet's four data of a patch are offsets of one outline: evaluated together (one frame,
    ``evaluate_curves``) they are bit for bit each curve's own ``evaluate``, values and two derivatives,
    on a spline outline (its own offset rule) and on one of lines and arcs."""
    from tabletcad.families.shaped import outline_tablet, rounded_triangle
    from tabletcad.families.sweep import SweepCurve
    from tabletcad.geometry.curves import evaluate_curves

    t = outline_tablet(SplineOutline(ellipse_points(egg=0.3)), band=2.5, cup_depth=0.6) if kind == "spline" \
        else rounded_triangle()
    v = np.random.default_rng(3).uniform(-1.0, 7.5, 301)
    seen = 0
    for p in t.patches:
        if type(p.data[0]) is not SweepCurve:
            continue
        for der in (0, 1, 2):
            together = evaluate_curves(p.data, v, der)
            assert np.array_equal(together, np.stack([c.evaluate(v, der) for c in p.data]))
            seen += 1
    assert seen >= 3 * (len(t.patches) - 2)


# ----------------------------------------------------------------------------- offsets for tooling

def _peanut(n: int = 24) -> SplineOutline:
    """A 13 x 8 mm peanut through ``n`` points: convex ends, a concave waist (curvature radius ~5.6 mm)."""
    t = 2.0 * np.pi * np.arange(n) / n
    r = 4.0 + 1.2 * np.cos(2.0 * t)
    return SplineOutline(np.column_stack([1.3 * r * np.cos(t), r * np.sin(t)]))


def test_the_concave_curvature_peak_is_found_exactly():
    ol = _peanut()
    v = np.linspace(0.0, 2.0 * np.pi, 200_001)
    k_dense = float(np.max(-ol.frame(v)[3]))
    assert k_dense > 0.0 and ol.max_concave_curvature >= k_dense * (1.0 - 1e-12)
    assert ol.min_concave_radius == pytest.approx((1.0 - DEFAULT.offset_regularity) / ol.max_concave_curvature,
                                                  rel=1e-15)
    assert SplineOutline(ellipse_points()).min_concave_radius == np.inf  # convex: every outward offset is regular


def test_offsets_beyond_the_regular_ones_are_bounded_both_ways():
    """Tooling offsets a spline outline inward (punch tips) and outward (a die bore, a relief ring): an offset
    past the smallest convex (inward) or concave (outward) radius of curvature loops; its bound is that radius
    less Tolerances.offset_regularity, or less where the offset would cross the outline's narrowest place."""
    ol = _peanut()
    assert ol.offset_bound(-0.02) is None and ol.offset_bound(0.03) is None and ol.offset_bound(0.0) is None
    inward, why = ol.offset_bound(-50.0)
    assert inward == pytest.approx(ol.offset_limit(), rel=0, abs=0) and "convex radius of curvature" in why
    assert inward <= ol.min_convex_radius
    outward, why = ol.offset_bound(50.0)
    assert outward == ol.outward_offset_limit() and "concave radius of curvature" in why
    assert 0.0 < outward <= ol.min_concave_radius
    # at the bound the offset is regular and stays that far outside the outline everywhere: the exact offset's
    # speed |O'| (1 + e κ) does not vanish and its points' distance to the outline is the offset
    v = np.linspace(0.0, 2.0 * np.pi, 20_001)
    speed = np.linalg.norm(ol.point(v, 1) - outward * ol.normal(v, 1), axis=1) / np.linalg.norm(ol.point(v, 1), axis=1)
    assert np.min(speed) >= DEFAULT.offset_regularity * (1.0 - 1e-6)
    assert ol.signed_distance(ol.offset(v, 0, 1.0, -outward)) == pytest.approx(-outward, abs=1e-7)
    assert ol.offset_bound(outward) is None and ol.offset_bound(outward * (1.0 + 1e-6)) is not None
