"""Exact ``v`` pieces of B-spline surfaces and the slit cut (numpy only, no CAD kernel)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tabletcad.brep.fit import fit_patches
from tabletcad.brep.surface import BSplineSurfaceData, enclosed_volume, segment_v, segments_v
from tabletcad.errors import GeometryError
from tabletcad.brep.slit import chain_face_surfaces, row_pieces

ROOT = Path(__file__).resolve().parents[1]


def _random_surface(rng, degree: int, interior: list[tuple[float, int]], periodic: bool, m0: int = 1):
    """Random poles on a knot vector over [0, 2]: ``interior`` = [(knot, multiplicity), ...]."""
    knots = [0.0] + [k for k, _ in interior] + [2.0]
    if periodic:
        mults = [m0] + [m for _, m in interior] + [m0]
        nv = sum(mults[:-1])
    else:
        mults = [degree + 1] + [m for _, m in interior] + [degree + 1]
        nv = sum(mults) - degree - 1
    poles = rng.normal(size=(2, nv, 3))
    return BSplineSurfaceData(poles, np.array([0.0, 1.0]), np.array([2, 2]), np.array(knots), np.array(mults),
                              u_degree=1, v_degree=degree, u_periodic=False, v_periodic=periodic)


@settings(max_examples=60, deadline=None)
@given(
    degree=st.integers(1, 5),
    seed=st.integers(0, 2**31 - 1),
    periodic=st.booleans(),
    c0_first=st.booleans(),
)
def test_segment_v_is_exact(degree, seed, periodic, c0_first):
    """Pieces between C0 knots (and across a periodic surface's seam) evaluate exactly as the
    whole surface, and the pieces' poles are the whole's poles (no new geometry)."""
    rng = np.random.default_rng(seed)
    cuts = sorted(rng.choice(np.arange(1, 20) / 10.0, size=2, replace=False).tolist())
    smooth = [k for k in (0.35, 0.85, 1.45) if all(abs(k - c) > 1e-9 for c in cuts)]
    interior = sorted([(c, degree) for c in cuts] + [(k, 1) for k in smooth])
    m0 = degree if (periodic and c0_first) else 1
    S = _random_surface(rng, degree, interior, periodic, m0)
    u = np.linspace(0.0, 1.0, 5)
    ranges = [(cuts[0], cuts[1])]
    if periodic:
        ranges.append((cuts[1], cuts[0] + 2.0))  # across the seam
        if c0_first:
            ranges += [(0.0, cuts[0]), (cuts[1], 2.0)]
    else:
        ranges += [(0.0, cuts[0]), (cuts[1], 2.0)]
    together = segments_v(S, ranges)  # the same pieces, the knot vector set up once
    for (a, b), same in zip(ranges, together):
        piece = segment_v(S, a, b)
        assert not piece.v_periodic and piece.v_range == (a, b)
        # made without the constructor's checks: they pass, and the data are read-only
        checked = BSplineSurfaceData(**{k: getattr(piece, k) for k in BSplineSurfaceData.__dataclass_fields__})
        for k in ("poles", "v_knots", "v_mults"):
            assert np.array_equal(getattr(checked, k), getattr(piece, k))
            assert np.array_equal(getattr(same, k), getattr(piece, k)) and not getattr(piece, k).flags.writeable
        v = np.linspace(a, b, 41)
        U, V = np.meshgrid(u, v)
        np.testing.assert_allclose(piece.evaluate(U, V), S.evaluate(U, V), atol=1e-12)
        assert all(any(np.array_equal(p, q) for q in S.poles[1]) for p in piece.poles[1])


def test_segment_v_refuses_a_smooth_knot():
    S = _random_surface(np.random.default_rng(0), 3, [(0.5, 3), (1.0, 1), (1.5, 3)], periodic=True)
    with pytest.raises(GeometryError, match="multiplicity >= 3"):
        segment_v(S, 0.5, 1.0)
    with pytest.raises(GeometryError, match="within one period"):
        segment_v(S, 0.5, 3.0)


@pytest.fixture(scope="module")
def capsule_surfaces():
    from tabletcad.brep.surfaces import tablet_breakpoints, tablet_surface_functions  # numpy-only helpers
    from tabletcad.pipeline.design import load_design

    t = load_design(ROOT / "samples" / "families" / "capsule.toml")
    funcs, names = tablet_surface_functions(t)
    fits = fit_patches(funcs, t.tol.fit, names=names, u_degree=5, v_degree=5, v_break_mult=5,
                       v_breaks=tablet_breakpoints(t))
    return t, [f.surface for f in fits]


def test_capsule_slit_cut_into_runs_and_fans(capsule_surfaces):
    """The innermost cup surfaces of the 18 x 8 mm capsule: cut into (end, run, end, run);
    the runs lie on the centre segment x in [-5, 5], y = 0, traversed in opposite
    directions; the ends are single poles at (+-5, 0); the pieces' enclosed volume is the
    whole's, to round-off."""
    t, surfaces = capsule_surfaces
    chain = chain_face_surfaces(surfaces)
    for pieces, data, row in ((chain[0], surfaces[0], 0), (chain[-1], surfaces[-1], -1)):
        assert len(pieces) == 4
        raw, pts, _ = row_pieces(data, row)
        assert [k for _, _, k in raw] == ["point", "run", "point", "run"]
        np.testing.assert_allclose(pts[1], pts[3][::-1], atol=1e-7)  # one segment, there and back
        ends = [pieces[0].poles[row], pieces[2].poles[row]]
        for r in ends:
            assert np.all(r == r[0])  # snapped: one pole
        assert sorted(round(float(r[0][0]), 6) for r in ends) == [-5.0, 5.0]
        runs = [pieces[1].poles[row], pieces[3].poles[row]]
        for r in runs:
            assert np.allclose(r[:, 1], 0.0, atol=1e-7) and np.ptp(r[:, 0]) == pytest.approx(10.0, abs=1e-6)
        assert np.sign(runs[0][-1, 0] - runs[0][0, 0]) == -np.sign(runs[1][-1, 0] - runs[1][0, 0])
        # continuity of the cut: consecutive pieces share their boundary rows exactly
        for p, q in zip(pieces, pieces[1:] + pieces[:1]):
            np.testing.assert_allclose(p.poles[:, -1], q.poles[:, 0], atol=1e-7)
    whole = enclosed_volume(surfaces)
    cut = enclosed_volume([p for ps in chain for p in ps])
    assert cut == pytest.approx(whole, rel=1e-12)
    assert abs(whole) == pytest.approx(t.properties()["volume_mm3"], rel=1e-6)


def test_ordinary_chains_are_not_cut(capsule_surfaces):
    """Rows that move everywhere (the capsule's band) leave a chain alone: one face per surface."""
    _, surfaces = capsule_surfaces
    middle = surfaces[len(surfaces) // 2 - 1: len(surfaces) // 2 + 2]
    assert chain_face_surfaces(middle) == [(s,) for s in middle]


def test_chain_is_cut_alike_and_neighbours_meet_row_to_row(capsule_surfaces):
    """Every surface of the capsule chain is cut at the same four v values, so that the pieces
    of neighbouring surfaces share their boundary rows bit for bit (sewing never splits an edge)."""
    _, surfaces = capsule_surfaces
    chain = chain_face_surfaces(surfaces)
    assert [len(ps) for ps in chain] == [4] * len(surfaces)
    for left, right in zip(chain, chain[1:]):
        for p, q in zip(left, right):
            assert p.v_range == q.v_range
            np.testing.assert_array_equal(p.poles[-1], q.poles[0])


def test_rounded_square_cupped_to_its_corner_radius_is_cut_at_the_corners():
    """Rounded square, cup width = corner radius (the default): the rim's corner arcs collapse
    to points; the chain is cut at the 8 outline junctions and each corner piece of the rim
    rows is a single pole at the corner arc's centre (offset by the corner radius)."""
    from tabletcad import families
    from tabletcad.brep.surfaces import fit_options, tablet_surface_functions

    side, rc = 9.0, 1.5
    t = families.FAMILIES["rounded_square"].build(side=side, corner_radius=rc)
    funcs, names = tablet_surface_functions(t)
    fits = fit_patches(funcs, t.tol.fit, names=names, **fit_options(t))
    surfaces = [f.surface for f in fits]
    chain = chain_face_surfaces(surfaces, names=names)
    assert {len(ps) for ps in chain} == {8}
    corner = side / 2 - rc
    poles = []
    for ps in chain:
        for p in ps:
            for row in (p.poles[0], p.poles[-1]):
                if np.all(row == row[0]) and abs(abs(row[0][0]) - corner) < 1e-9:
                    poles.append(tuple(np.round(row[0], 9)))
    # the four corners, on the top and bottom rim (each shared by the ring and cup pieces)
    xy = {(abs(x), abs(y)) for x, y, _ in poles}
    assert xy == {(corner, corner)} and len(set(poles)) == 8
    whole = enclosed_volume(surfaces)
    assert enclosed_volume([p for ps in chain for p in ps]) == pytest.approx(whole, rel=1e-12)
