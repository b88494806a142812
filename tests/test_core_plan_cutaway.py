"""The plan area of a shaped cut-away (``[trim] v``, ``w`` from 0), against the union of the projected
boundary of its solid computed by scanlines: an independent construction (Cartesian intervals of
triangles, not polar fans)."""

from __future__ import annotations

import functools
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tabletcad.geometry.tablet import Tablet, _cover, solid_map
from tabletcad.pipeline.design import Design

ROOT = Path(__file__).resolve().parents[1]


#: the sort of the scanlines' interval ends (the same values either way): numpy 2's vectorised quicksort
#: took 0.7 times the time of its timsort ("stable") on the references below, numpy 1.24's quicksort 1.6 times
_SORT = "quicksort" if np.lib.NumpyVersion(np.__version__) >= "2.0.0" else "stable"


@functools.lru_cache(maxsize=None)
def _family(name: str) -> Tablet:
    """The family sample ``name``'s tablet, built once for the module (tablets are immutable; the tests
    take cut-aways of it, which are new tablets)."""
    return Design.from_toml(ROOT / "samples" / "families" / f"{name}.toml").build()


@functools.lru_cache(maxsize=None)
def _plan_area(name: str, v: tuple[float, float], u: tuple[float, float] | None = None,
               nv: int = 2048) -> float | None:
    """The plan area (mm²) of the family sample ``name`` cut to ``v`` (and ``u``), from ``nv`` lines: computed
    once for the module (the half capsule's is asked for by three tests)."""
    return _family(name).trimmed(v=v, u=u).plan_area(nv=nv)


def _line_intervals(tris: np.ndarray, k0: np.ndarray, k1: np.ndarray, lo: float,
                    dy: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(k, x0, x1)``: the interval ``[x0, x1]`` that line ``k`` (at ``y = lo + (k + 1/2) dy``) cuts
    from each triangle of ``tris`` (n, 3, 2) it crosses, lines ``k0`` to ``k1`` of each triangle.

    A line between a triangle's lowest and highest corner crosses the edge joining them and, below the
    middle corner, the edge from the lowest to it, else the edge from it to the highest: the crossings of
    the three edges without testing each edge for each line."""
    n = np.maximum(k1 - k0 + 1, 0)
    t = np.repeat(np.arange(len(tris)), n)
    k = np.arange(n.sum()) - np.repeat(np.cumsum(n) - n - k0, n)
    yl = lo + (k + 0.5) * dy
    order = np.argsort(tris[..., 1], axis=1, kind="stable")
    p = np.take_along_axis(tris, order[..., None], axis=1)
    (xa, ya), (xb, yb), (xc, yc) = p[:, 0].T, p[:, 1].T, p[:, 2].T
    with np.errstate(divide="ignore", invalid="ignore"):  # (a level edge: no slope, never used)
        slopes = [(x1 - x0) / (y1 - y0)
                  for x0, y0, x1, y1 in ((xa, ya, xc, yc), (xa, ya, xb, yb), (xb, yb, xc, yc))]
    ac, ab, bc = (np.where(np.isfinite(m), m, 0.0) for m in slopes)
    xa, ya, yb = xa[t], ya[t], yb[t]
    up = yl - ya
    long = xa + up * ac[t]
    short = np.where(yl < yb, xa + up * ab[t], xb[t] + (yl - yb) * bc[t])
    return k, np.minimum(long, short), np.maximum(long, short)


def _union_area(tris: np.ndarray, ny: int, block: int = 250) -> float:
    """Area (mm²) of the union of the plan triangles ``tris`` (n, 3, 2): on each of ``ny`` horizontal
    lines (midpoints) the union of the triangles' exact intervals, summed.

    The union of intervals ``[a_i, b_i]`` is that of ``[a_(i), b_(i)]``, the starts and the ends each
    sorted on their own (the number of intervals covering a point depends only on how many starts lie
    before it and how many ends, and ``a_(i) <= b_(i)``): two sorts, no sort of the pairs, and the ends'
    running largest is the sorted ends themselves.  The lines are taken ``block`` at a time, each line's
    intervals shifted apart from the others' (the same sums: each line's union is its own; the arrays of
    all lines at once, 8 million intervals for the finest reference, took 2.5 times as long)."""
    y = tris[..., 1]
    lo, hi = float(y.min()), float(y.max())
    dy = (hi - lo) / ny
    k0 = np.ceil((y.min(axis=1) - lo) / dy - 0.5).astype(int)
    k1 = np.floor((y.max(axis=1) - lo) / dy - 0.5).astype(int)
    big = 4.0 * (float(np.abs(tris[..., 0]).max()) + 1.0)
    total = 0.0
    for first in range(0, ny, block):
        last = first + block - 1
        sel = (k1 >= first) & (k0 <= last)
        k, x0, x1 = _line_intervals(tris[sel], np.maximum(k0[sel], first), np.minimum(k1[sel], last), lo, dy)
        shift = k * big
        x0, x1 = np.sort(x0 + shift, kind=_SORT), np.sort(x1 + shift, kind=_SORT)
        before = np.concatenate(([-np.inf], x1[:-1]))
        total += float(np.sum(np.maximum(x1 - np.maximum(x0, before), 0.0)))
    return total * dy


def _boundary_triangles(t, nu: int, nv: int) -> np.ndarray:
    """The plan projections of the cut-away's boundary: its outer surface on an ``nu × nv`` grid of every
    patch and its two cut faces (``v = v0, v1`` over ``(u, w)``: the solid map is linear in ``w``)."""
    u = np.linspace(t.trim.u[0], t.trim.u[1], nu)
    v = np.linspace(t.trim.v[0], t.trim.v[1], nv)
    tris = []
    for p in t.patches:
        X = p.evaluate_grid(u, v)[..., :2]
        a, b, c, d = X[:-1, :-1], X[1:, :-1], X[1:, 1:], X[:-1, 1:]
        tris += [np.stack([a, b, c], -2).reshape(-1, 3, 2), np.stack([a, c, d], -2).reshape(-1, 3, 2)]
        for ve in t.trim.v:
            uu = np.linspace(t.trim.u[0], t.trim.u[1], 4 * nu)
            E = solid_map(p, uu, np.full(uu.shape, ve), np.ones(uu.shape))[:, :2]
            A = solid_map(p, uu, np.full(uu.shape, ve), np.zeros(uu.shape))[:, :2]
            tris += [np.stack([A[:-1], E[:-1], E[1:]], -2), np.stack([A[:-1], E[1:], A[1:]], -2)]
    return np.concatenate(tris)


CASES = [("capsule", (0.0, math.pi)), ("capsule", (math.pi / 2, 2 * math.pi)), ("almond", (1.0, 4.0)),
         ("rounded_triangle", (0.3, 2.0))]


@pytest.mark.parametrize("name, v", CASES)
def test_a_shaped_cut_away_s_plan_is_the_union_of_its_projected_boundary(name, v):
    t = _family(name).trimmed(v=v)
    area = _plan_area(name, v)
    # the reference's chords and lines leave an error of second order, which converges to the plan
    # area (measured 2.3e-5 and 5.6e-6 on the half capsule, 1.0e-5 at the finer on its three quarters)
    coarse = _union_area(_boundary_triangles(t, 33, 257), 1000)
    fine = _union_area(_boundary_triangles(t, 49, 513), 2000)
    assert abs(fine - area) < 2e-5 * area
    assert abs(fine - area) < abs(coarse - area) / 3.0


CONVERGED = [("capsule", (0.0, math.pi), None), ("capsule", (0.2, 2 * math.pi), None),
             ("capsule", (0.0, math.pi), (0.2, 0.8)), ("almond", (1.0, 1.05), (0.1, 0.6)),
             ("rounded_rectangle", (0.5, 2 * math.pi), None)]


@pytest.mark.parametrize("name, v, u", CONVERGED)
def test_a_shaped_cut_away_s_plan_area_is_converged(name, v, u):
    """Small wedges, cuts of nearly the whole turn (the fans then reach round every direction) and trims
    in ``u``: four times the lines agree to 1e-8 (measured at most 3.6e-9; a step of the angle grid
    straddling a fan's end had left errors of first order, 1e-6 to 2.5e-5 here)."""
    assert _plan_area(name, v, u, nv=8192) == pytest.approx(_plan_area(name, v, u), rel=1e-8)


def test_the_two_halves_of_a_capsule_are_mirror_images():
    t = _family("capsule")
    # the sweep is symmetric about the long (x) axis, v -> 2π - v: the plans of v in (0, π) and in
    # (π, 2π) are mirror images; both reach past the axis (the cut faces lean), so each is more than
    # half the whole plan
    top, bottom = _plan_area("capsule", (0.0, math.pi)), t.trimmed(v=(math.pi, 2 * math.pi)).plan_area()
    assert top == pytest.approx(bottom, rel=1e-9)
    assert 0.5 * t.plan_area() < top < t.plan_area()


def test_a_moving_spine_or_a_hollow_shaped_cut_away_has_no_plan_area():
    # (the rounded triangle's spine had moved 0.07 mm only because its centroid was computed off its
    # centre; the custom-outline sample, a "D", has no such symmetry)
    d_shape = _family("custom_outline")
    spine = np.concatenate([p.spine(np.linspace(0, 1, 33))[:, :2] for p in d_shape.patches])
    assert np.ptp(spine, axis=0).max() > 0.05  # the D's spine moves in plan
    assert d_shape.trimmed(v=(0.0, math.pi)).plan_area() is None
    assert _family("capsule").trimmed(v=(0.0, math.pi), w=(0.5, 1.0)).plan_area() is None
    # the whole tablets keep theirs
    assert d_shape.plan_area() > 0.0


def test_a_fan_whose_angle_pauses_at_its_turn_is_still_covered():
    from tabletcad.geometry.tablet import _cover, _monotone_pieces

    psi = np.array([0.0, 0.1, 0.2, 0.2, 0.1, 0.0])  # out and back, the turn a pause
    x, y = 2.0 * np.cos(psi), 2.0 * np.sin(psi)
    x[:3], y[:3] = np.cos(psi[:3]), np.sin(psi[:3])  # radius 1 out, 2 back
    pieces = _monotone_pieces(psi, x, y)
    assert len(pieces) == 2 and all(np.all(np.diff(q) >= 0.0) for q, _, _ in pieces)
    grid = np.linspace(0.01, 0.19, 19)
    env = np.zeros(grid.size)
    for piece in pieces:
        _cover(env, grid, (np.cos(grid), np.sin(grid)), *piece)
    # the chords of radius-2 points at 0.1 rad apart: 2 cos(0.05) / cos(g - mid) between them
    mid = np.where(grid < 0.1, 0.05, 0.15)
    assert env == pytest.approx(2.0 * math.cos(0.05) / np.cos(grid - mid), rel=1e-12)


def test_the_report_of_a_cut_away_without_a_plan_area(tmp_path, capsys):
    """A hollow free-form cut-away has no plan area: the report says so instead of failing."""
    from tabletcad.cli import main

    path = tmp_path / "ff_cut.toml"
    path.write_text((ROOT / "samples" / "free_form_stadium.toml").read_text(encoding="utf-8")
                    + "[trim]\nv = [0.0, 3.14159]\nw = [0.5, 1.0]\n[report]\ncompaction_force_kN = 10.0\n"
                      "max_punch_force_kN = 30.0\n", encoding="utf-8")
    assert main(["report", str(path)]) == 0
    out = capsys.readouterr().out
    assert "plan area                         -" in out
    assert "punch-tip check                   OK: 10 kN of 30 kN (plan area not known" in out


@pytest.mark.parametrize("name", ["capsule", "rounded_triangle", "almond", "oval"])
def test_a_hollow_family_tablet_has_its_whole_plan(name):
    """A family tablet made hollow (``[trim] w`` from 0.3 or 0.5) hides its cavity: each face closes at a
    point or a segment, where the solid between w0 and 1 covers every direction, so nothing inside the
    outline is seen through and the plan is the whole tablet's.  (The capsule read 126.73 instead of
    130.27 mm² on numpy 1.24, from the noise in its centre segment's angles; the rounded triangle 43.92
    instead of 44.18 on any numpy, a 'hole' about the box centre, which its pole is not at.)"""
    t = _family(name)
    whole = t.plan_area()
    for trim in (dict(w=(0.3, 1.0)), dict(u=(0.0, 0.5), w=(0.5, 1.0))):
        assert t.trimmed(**trim).plan_area() == pytest.approx(whole, rel=1e-12), trim


def test_a_ring_keeps_its_see_through_hole():
    """The thesis's ring (samples/ring.toml, hollow by its own ``[trim] w``) is seen through: its plan is
    its outline's disc less a hole that shrinks as ``w0`` does, and the solid ring (``w`` from 0) has none."""
    t = Design.from_toml(ROOT / "samples" / "ring.toml").build()
    w0 = t.trim.w[0]
    assert w0 > 0.0
    ring, thicker, solid = t.plan_area(), t.trimmed(w=(0.5 * w0, 1.0)).plan_area(), t.trimmed(w=(0.0, 1.0)).plan_area()
    assert ring < thicker < solid
    assert solid - ring > 0.1 * solid


@settings(max_examples=60, deadline=None)
@given(st.integers(2, 200), st.integers(1, 40), st.integers(0, 2**32 - 1), st.floats(0.0, 1.5))
def test_the_envelope_passes_over_only_blocks_it_already_reaches(n, block, seed, level):
    """:func:`_cover` by blocks of chords, each passed over where the envelope already reaches its farthest
    point, raises the envelope exactly as the whole piece at every angle does (one block, the envelope at 0):
    random monotone pieces, envelopes partly above them (``level`` times a radius of 1 mm)."""
    rng = np.random.default_rng(seed)
    q = np.sort(rng.uniform(-0.3, 2.5, n))
    q[1:] += np.cumsum(rng.random(n - 1) < 0.1) * 1e-9  # (strictly increasing)
    r = rng.uniform(0.5, 1.5, n)
    px, py = r * np.cos(q), r * np.sin(q)
    grid = np.sort(rng.uniform(-0.5, 3.0, 400))
    cs = (np.cos(grid), np.sin(grid))
    env = level * rng.uniform(0.8, 1.2, grid.size)
    whole = np.zeros(grid.size)
    _cover(whole, grid, cs, q, px, py, block=10**9)
    blocks = env.copy()
    _cover(blocks, grid, cs, q, px, py, block=block)
    np.testing.assert_array_equal(blocks, np.maximum(env, whole))
