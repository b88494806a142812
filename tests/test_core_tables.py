"""The tables shared between patches (:mod:`tabletcad.geometry.tables`) and the core's cross product."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import array_shapes, arrays

from tabletcad.geometry.tables import CARDINAL, SharedTables
from tabletcad.geometry.vectors import cross, length2, norm3


def test_least_recently_used_goes_first_and_results_are_read_only():
    t = SharedTables(2, 1000)
    made = []

    def make(x):
        made.append(x)
        return np.full(3, float(x))

    a = t.get("a", lambda: make(1))
    t.get("b", lambda: make(2))
    assert t.get("a", lambda: make(9)) is a  # a hit: not made again, now the most recent
    t.get("c", lambda: make(3))  # evicts b, the least recently used
    assert made == [1, 2, 3] and len(t) == 2
    t.get("b", lambda: make(4))
    assert made == [1, 2, 3, 4]
    with pytest.raises(ValueError):
        a[0] = 5.0


def test_results_above_the_size_limits_are_made_but_not_kept():
    t = SharedTables(8, 100, total_bytes=200)
    big = t.get("big", lambda: np.zeros(20))  # 160 bytes > 100
    assert big.flags.writeable and len(t) == 0
    for k in range(4):  # 96 bytes each: two fit in 200
        t.get(k, lambda: (np.zeros(6), np.zeros(6)))
    assert len(t) == 2
    t.clear()
    assert len(t) == 0


def test_patches_alike_share_a_table_and_unlike_ones_do_not():
    from tabletcad.families import FAMILIES

    tablet = FAMILIES["concave_round"].build(diameter=9.0, band=2.5, cup_depth=0.8)
    u = np.linspace(0.0, 1.0, 37)
    CARDINAL.clear()
    p, q = tablet.patches[0], tablet.patches[-1]
    assert p._u_key == q._u_key
    assert p._u_tables(u, 1)[1] is q._u_tables(u, 1)[1]
    assert p._u_tables(u, 1)[1] is not p._u_tables(u, 0)[1]
    assert p._u_tables(u + 1e-12, 1)[1] is not p._u_tables(u, 1)[1]
    # what is shared is what the patch would compute alone
    CARDINAL.clear()
    alone = p.evaluate_grid(u, np.linspace(0.0, 6.0, 5), du=1)
    q.evaluate_grid(u, np.linspace(0.0, 6.0, 5), du=1)
    np.testing.assert_array_equal(p.evaluate_grid(u, np.linspace(0.0, 6.0, 5), du=1), alone)


vec = arrays(np.float64, array_shapes(min_dims=1, max_dims=3, min_side=1, max_side=4).map(lambda s: s[:-1] + (3,)),
             elements=st.floats(-1e6, 1e6))


@settings(max_examples=80, deadline=None)
@given(a=vec, b=st.floats(-1e3, 1e3), data=st.data())
def test_cross_equals_numpy_cross(a, b, data):
    other = data.draw(arrays(np.float64, a.shape, elements=st.floats(-1e6, 1e6)))
    np.testing.assert_array_equal(cross(a, other), np.cross(a, other))
    np.testing.assert_array_equal(cross(a, other * b), np.cross(a, other * b))
    if a.ndim >= 2:  # broadcast along a leading axis
        np.testing.assert_array_equal(cross(a[..., :1, :], other), np.cross(a[..., :1, :], other))


@settings(max_examples=80, deadline=None)
@given(a=arrays(np.float64, array_shapes(min_dims=1, max_dims=3, min_side=1, max_side=5).map(lambda s: s[:-1] + (3,)),
                elements=st.floats(-1e150, 1e150) | st.floats(-1e-150, 1e-150)))
def test_norm3_equals_numpy_norm(a):
    """The core's lengths of 3-vectors are numpy's, to the last bit (the same squares in the same order)."""
    np.testing.assert_array_equal(norm3(a), np.linalg.norm(a, axis=-1))


@settings(max_examples=80, deadline=None)
@given(xy=arrays(np.float64, st.tuples(st.integers(1, 50), st.just(2)),
                 elements=st.just(0.0) | st.floats(1e-9, 1e4) | st.floats(-1e4, -1e-9)))
def test_length2_is_hypot_within_two_ulp(xy):
    """Plan distances (mm; coordinates 0 or from 1 pm to 10 m, far from under- and overflow) by
    ``sqrt(x² + y²)``: within two ulp of ``np.hypot``."""
    got, want = length2(xy[:, 0], xy[:, 1]), np.hypot(xy[:, 0], xy[:, 1])
    assert np.all(np.abs(got - want) <= 2.0 * np.spacing(want))
