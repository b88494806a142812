"""The inscribed radius's polishing steps (tabletcad.families.deepest) against closed forms and against
an independent search (Nelder-Mead on the vectorised signed distance from a finer grid's peaks)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from scipy.optimize import minimize

from tabletcad.families.deepest import deepest_near, distance_jets
from tabletcad.families.outline import PlanOutline, outline_from_items, rounded_polygon
from test_families_concave_outline import RANDOM_OUTLINES, _TWO_LOBES, _outline_of

_D_SHAPE = [("line", [-2.5, -3.5], [2.5, -3.5]), ("arc", [2.5, 0.0], 3.5, -math.pi / 2, math.pi),
            ("line", [2.5, 3.5], [-2.5, 3.5]), ("arc", [-2.5, 2.0], 1.5, math.pi / 2, math.pi / 2),
            ("line", [-4.0, 2.0], [-4.0, -2.0]), ("arc", [-2.5, -2.0], 1.5, math.pi, math.pi / 2)]


@pytest.mark.parametrize("side, corner", [(11.0, 2.0), (9.0, 0.5), (7.0, 1.9)])
def test_a_rounded_triangle_s_inscribed_radius_is_its_incircle_s(side, corner):
    # the fillets lie outside the incircle (corner < s / (2√3)): the three sides touch it
    R = side / math.sqrt(3.0)
    verts = [(R * math.cos(t), R * math.sin(t)) for t in (-math.pi / 6, math.pi / 2, 7 * math.pi / 6)]
    ol = rounded_polygon(verts, corner, name="rounded_triangle")
    assert ol.inscribed_radius() == pytest.approx(side / (2.0 * math.sqrt(3.0)), rel=1e-13)


def test_the_d_shape_s_ridge_is_half_its_width_exactly():
    # the deepest points: the middle line between the two long sides, 3.5 mm from each
    assert outline_from_items(_D_SHAPE).inscribed_radius() == 3.5


@pytest.mark.parametrize("start", [(0.3, 0.2), (1.0, -0.4), (2.4, 0.05)])  # (x in -0.5 .. 2.5: 3.5 mm deep)
def test_a_step_from_off_the_ridge_lands_on_it_straight_across(start):
    ol = outline_from_items(_D_SHAPE)
    x, y = deepest_near(distance_jets(ol.segs), ol._point_signed_distance(), *start, 1.0, 8.0)
    assert (x, y) == (start[0], 0.0) or (abs(x - start[0]) <= 1e-15 and abs(y) <= 1e-15)


def test_the_centre_of_a_circle_of_arcs_is_found():
    # four quarter arcs of radius 2 about (1, -1): no straight side, the depth bends everywhere
    items = [("arc", [1.0, -1.0], 2.0, k * math.pi / 2, math.pi / 2) for k in range(4)]
    ol = outline_from_items(items)
    x, y = deepest_near(distance_jets(ol.segs), ol._point_signed_distance(), 1.2, -0.9, 0.5, 4.0)
    assert math.hypot(x - 1.0, y + 1.0) <= 1e-9
    assert ol._point_signed_distance()(x, y) == pytest.approx(2.0, abs=1e-12)


def _nelder_mead_restarted(ol, x0) -> float:
    """The depth (mm) Nelder-Mead reaches from ``x0`` on ``ol.signed_distance``, restarted from its own result
    until a restart gains nothing (at most 6 runs): one run can stall on the ridge where two segments' distances
    meet (a fresh clone's run found an outline, pinned below by @example, where one run stopped 1.1e-4 mm
    short of the deepest point and a restart reached it to 1e-13)."""
    def objective(x):
        return -float(ol.signed_distance(x[None])[0])

    best = minimize(objective, x0, method="Nelder-Mead", options=dict(xatol=1e-11, fatol=1e-13, maxiter=4000))
    for _ in range(5):
        again = minimize(objective, best.x, method="Nelder-Mead", options=dict(xatol=1e-11, fatol=1e-13, maxiter=4000))
        if not again.fun < best.fun:
            break
        best = again
    return -float(best.fun)


#: an outline on which one Nelder-Mead run stalls 1.1e-4 mm short (found by hypothesis in a fresh clone)
_STALLS = ([(1.34375, 6.375), (2.907142973626543, 6.578125), (2.9682795090471408, 5.62890625), (3.97265625, 4.75),
            (4.1875, 4.4375), (4.75390625, 6.3125), (6.158307446697017, 5.14453125), (0.0, 4.837890625)],
           0.4458145369208247, 0, True)


@settings(max_examples=40, deadline=None)
@given(RANDOM_OUTLINES)
@example(_outline_of(*_TWO_LOBES))
@example(_outline_of(*_STALLS))
def test_the_steps_find_the_depth_an_independent_search_finds(ol):
    """Nelder-Mead on the vectorised signed distance, from the four best local peaks of a 161 x 161 grid,
    finds no point deeper than the inscribed radius (to its 1e-9 mm) and the radius is no deeper than a
    point it reached (the steps polish to at least Nelder-Mead's depth)."""
    if ol is None:
        return
    from scipy.ndimage import maximum_filter

    radius = ol.inscribed_radius()
    c = ol.frame(np.linspace(0.0, math.tau, 512, endpoint=False))[0]
    lo, hi = c.min(axis=0), c.max(axis=0)
    n = 161
    g = np.stack(np.meshgrid(np.linspace(lo[0], hi[0], n), np.linspace(lo[1], hi[1], n)), -1).reshape(-1, 2)
    sd = ol.signed_distance(g)
    grid = sd.reshape(n, n)
    peaks = np.flatnonzero(grid >= maximum_filter(grid, size=3, mode="constant", cval=-np.inf))
    found = -math.inf
    for k in peaks[np.argsort(sd[peaks])[::-1][:4]]:
        found = max(found, _nelder_mead_restarted(ol, g[k]))
    assert found - 1e-9 <= radius <= found + 1e-9
    assert radius >= float(sd.max())


def test_a_circle_outline_keeps_its_search():
    ol = PlanOutline(outline_from_items([("arc", [0.5, 0.0], 3.0, 0.0, math.tau)]).segs)
    assert ol.inscribed_radius() == pytest.approx(3.0, abs=1e-9)
