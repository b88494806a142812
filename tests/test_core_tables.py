"""The tables shared between patches (:mod:`tabletcad.geometry.tables`) and the core's cross product."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import array_shapes, arrays

from tabletcad.geometry.tables import CARDINAL, SharedTables
from tabletcad.geometry.vectors import clip, cross, length2, linspace, norm3, points_last


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


@pytest.mark.parametrize("family, dims", [
    ("rounded_triangle", dict(side=11.0, corner_radius=3.0, band=2.8, cup_depth=0.6)),
    ("capsule", dict(length=17.0, width=7.0, band=3.0, cup_depth=0.8, land=0.05)),
])
def test_a_shaped_family_s_trigonometric_tables_are_kept_between_builds(family, dims):
    """A shaped tablet's load and report read ~100 trigonometric tables (check grids, quadrature, polish
    lines), nearly all of them the same for every design of its family: all are kept, so the same design
    again makes none and another band (as in an optimisation or a sweep) only the few of its polish lines
    (measured 0 on the capsule, 7 of the triangle's 262 reads).  With 32 kept the least recently used
    went before its next read and ~150 were made again on every build."""
    from tabletcad.families import FAMILIES
    from tabletcad.geometry.tables import TRIG
    from tabletcad.pipeline.report import geometry_report

    def load_and_report(band):
        geometry_report(FAMILIES[family].build(**{**dims, "band": band}))

    load_and_report(dims["band"])
    reads, made, get = [], [], TRIG.get

    def counting(key, make):
        reads.append(key)
        return get(key, lambda: made.append(key) or make())

    TRIG.get = counting
    try:
        load_and_report(dims["band"])
        assert len(reads) > 100 and made == []
        load_and_report(dims["band"] * 1.05)
    finally:
        del TRIG.get
    assert len(made) <= 10 and len(TRIG) > 60


def test_four_shaped_families_built_in_turn_keep_their_tables():
    """A sweep or a workbench document of several families builds them in turn: their tables (~100
    trigonometric and ~70 cardinal ones a family) are all kept within the byte limits, so a second round
    makes no trigonometric table and at most a few cardinal ones (measured 0 and 2).  With 256 and 96 kept
    a round made 363 and 163 again (73 ms a tablet against 58-62, best of eight rounds)."""
    from tabletcad.geometry.tables import TRIG
    from tabletcad.pipeline.design import Design
    from tabletcad.pipeline.report import geometry_report

    root = Path(__file__).resolve().parents[1] / "samples" / "families"
    designs = [Design.from_toml(root / f"{n}.toml")
               for n in ("rounded_triangle", "capsule", "almond", "oval")]

    def a_round():
        for d in designs:
            geometry_report(d.build(), d.report_options)

    TRIG.clear()
    CARDINAL.clear()
    a_round()
    made = {"trig": 0, "cardinal": 0}
    gets = {}
    for name, store in (("trig", TRIG), ("cardinal", CARDINAL)):
        gets[name] = store.get

        def counting(key, make, name=name):
            return gets[name](key, lambda: made.__setitem__(name, made[name] + 1) or make())

        store.get = counting
    try:
        a_round()
    finally:
        del TRIG.get, CARDINAL.get
    assert made["trig"] == 0 and made["cardinal"] <= 10, made


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


@settings(max_examples=60, deadline=None)
@given(a=arrays(np.float64, array_shapes(min_dims=2, max_dims=4, min_side=1, max_side=12),
                elements=st.floats(allow_nan=True, allow_infinity=True)))
def test_points_last_is_the_transposed_copy(a):
    """Coordinates-first grids as points: the values of numpy's copy of the transposed view, bit for bit
    (NaN payloads and signed zeros included), C-contiguous, above and below 64 points."""
    for x in (a, a.transpose(0, *range(a.ndim - 1, 0, -1))):  # a C-ordered block and a strided view
        got, want = points_last(x), np.ascontiguousarray(np.moveaxis(x, 0, -1))
        assert got.shape == want.shape and got.flags.c_contiguous
        assert got.tobytes() == want.tobytes()
    big = np.arange(3 * 9 * 11, dtype=float).reshape(3, 9, 11)
    assert points_last(big).tobytes() == np.ascontiguousarray(big.transpose(1, 2, 0)).tobytes()


ends = st.floats(-1e6, 1e6) | st.floats(-1e-9, 1e-9) | st.sampled_from([0.0, -0.0, 1.0, 2.0 * np.pi, 5e-324])


@settings(max_examples=150, deadline=None)
@given(a=ends, b=ends, num=st.integers(0, 2100), endpoint=st.booleans(), near=st.booleans())
def test_linspace_is_numpys(a, b, num, endpoint, near):
    """The core's samples are ``numpy.linspace``'s, bit for bit (signed zeros included): any two ends, an
    empty step (equal ends, or a difference that underflows), with and without the end point."""
    if near:  # ends a few ulp apart: a step that is zero, subnormal or rounded
        b = float(np.nextafter(np.nextafter(a, np.inf), np.inf))
    got, want = linspace(a, b, num, endpoint=endpoint), np.linspace(a, b, num, endpoint=endpoint)
    assert got.dtype == want.dtype and got.shape == want.shape
    assert got.tobytes() == want.tobytes()


@settings(max_examples=80, deadline=None)
@given(x=arrays(np.float64, st.integers(1, 40), elements=st.floats(allow_nan=True, allow_infinity=True)),
       lo=st.floats(-10, 10), width=st.floats(0, 10))
def test_clip_is_numpys(x, lo, width):
    """The polishes' clip is ``numpy.clip``'s ufunc: the same values (NaN and signed zeros included)."""
    for bounds in ((lo, lo + width), (0.0, 1.0), (-0.0, 0.0)):
        assert clip(x, *bounds).tobytes() == np.clip(x, *bounds).tobytes()
