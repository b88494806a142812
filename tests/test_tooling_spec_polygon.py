"""A closed emboss outline must be a simple polygon: checked when the design is read.

A bow-tie outline reached OCC and stopped the build with "fails BRepCheck_Analyzer" after the
tablet was built; it is now one line naming ``outline``.  No CAD library is needed.
"""

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tabletcad.errors import DesignError
from tabletcad.tooling.polygon import polygon_problem
from tabletcad.tooling.spec import parse_tooling


def _convex(n: int, phase: float) -> list[tuple[float, float]]:
    return [(2.0 * math.cos(phase + 2 * math.pi * k / n), 1.0 * math.sin(phase + 2 * math.pi * k / n)) for k in range(n)]


def _cyclic_or_reversed(perm: tuple[int, ...]) -> bool:
    n = len(perm)
    forward = [tuple((s + k) % n for k in range(n)) for s in range(n)]
    return perm in forward or perm[::-1] in forward


@settings(max_examples=60, deadline=None)
@given(n=st.integers(4, 7), phase=st.floats(0.0, 6.28), data=st.data())
def test_points_in_convex_position_are_simple_only_in_their_hull_order(n, phase, data):
    """Through points in convex position (an ellipse's), the only simple polygons go round the hull,
    either way: every other order of the vertices makes two edges cross."""
    pts = _convex(n, phase)
    perm = tuple(data.draw(st.permutations(range(n))))
    problem = polygon_problem([pts[i] for i in perm])
    if _cyclic_or_reversed(perm):
        assert problem is None
    else:
        assert problem is not None and "cross" in problem


@settings(max_examples=60, deadline=None)
@given(radii=st.lists(st.floats(0.2, 3.0), min_size=3, max_size=24), twist=st.floats(0.0, 1.0))
def test_star_shaped_polygons_are_simple(radii, twist):
    """A polygon whose vertices go round the origin at rising angles with any radii is simple."""
    n = len(radii)
    pts = [(r * math.cos(2 * math.pi * (k + twist * 0.5) / n), r * math.sin(2 * math.pi * (k + twist * 0.5) / n))
           for k, r in enumerate(radii)]
    assert polygon_problem(pts) is None
    assert polygon_problem(pts + [pts[0]]) is None  # the closing point repeated


def test_float_round_off_is_not_a_defect():
    """Lengths compare within 1e-7 mm: a scripted outline that repeats its first point closes on
    sin(2 pi) = -2.4e-16 (42 of the ellipses below were refused when points were compared exactly),
    and a closing point 1e-9 mm off is the first point."""
    for n in range(3, 120):
        ellipse = [(1.5 * math.cos(2 * math.pi * k / n), math.sin(2 * math.pi * k / n)) for k in range(n + 1)]
        assert polygon_problem(ellipse) is None, n
    assert polygon_problem([(0, 0), (1, 0), (1, 1), (0, 1), (1e-9, 0)]) is None


@pytest.mark.parametrize("points, fragment", [
    ([(0, 0), (1.5, 0.15), (0.5, 0.05), (0, 2.5)], "double back"),            # 0.15 is no binary fraction
    ([(0, 0), (2, 0), (2, 2), (1, 1e-17), (0, 2)], "cross or touch"),         # a vertex 1e-17 from an edge
    ([(0, 0), (0, 0), (1, 1), (1, 0), (0, 1)], "edges 1 and 3 cross"),        # numbered as given
    ([(0, 0), (1, 1), (1, 0), (0, 1)], "edges 0 and 2 cross"),                # the bow-tie
    ([(0, 0), (2, 0), (2, 2), (1, 0), (0, 2)], "cross or touch"),              # a vertex on an edge
    ([(0, 0), (2, 0), (1, 0), (1, 1)], "double back"),                         # an edge folding back
    ([(0, 0), (1, 0), (2, 0)], "double back"),                                  # all on a line
    ([(0, 0), (1, 0), (1, 0), (0, 0)], "fewer than 3 distinct points"),
])
def test_degenerate_outlines_say_why(points, fragment):
    assert fragment in polygon_problem(points)


def test_a_bow_tie_outline_is_one_design_error():
    with pytest.raises(DesignError) as e:
        parse_tooling({"emboss": [{"outline": [[-1, -1], [1, 1], [1, -1], [-1, 1]], "depth_mm": 0.1}]})
    assert e.value.parameter.endswith("outline") and "must be a simple closed polygon: edges 0 and 2 cross" in str(e.value)
    # the same points in hull order are accepted
    assert parse_tooling({"emboss": [{"outline": [[-1, -1], [1, -1], [1, 1], [-1, 1]], "depth_mm": 0.1}]}).emboss
