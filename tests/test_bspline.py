"""Kernel-neutral B-spline fit (numpy only, no CAD kernel needed)."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tabletcad.brep.fit import fit_patches, fit_surface
from tabletcad.brep.surface import BSplineSurfaceData, enclosed_volume
from support.standins import cylinder, ring, sphere
from tabletcad.errors import GeometryError

TOL = 1e-4  # mm


def test_sphere_fit_within_tolerance_and_exact_pole():
    s = sphere(2.5)
    fit = fit_surface(s.patches[0], tol=TOL)
    assert fit.max_deviation <= TOL
    assert fit.pole_u0 and not fit.pole_u1
    P = fit.surface.poles
    assert np.all(P[0] == P[0, 0])  # one point, bit-exact
    np.testing.assert_array_equal(P[0, 0], [0.0, 0.0, 2.5])
    # independent random check points (not on the check grid)
    rng = np.random.default_rng(1)
    u, v = rng.random(5000), rng.random(5000) * 2 * np.pi
    err = np.linalg.norm(fit.surface.evaluate(u, v) - s.patches[0].evaluate(u, v), axis=-1)
    assert err.max() <= TOL


def test_periodicity_and_derivatives():
    fit = fit_surface(sphere(2.5).patches[1], tol=TOL)
    S = fit.surface
    rng = np.random.default_rng(2)
    u, v = rng.random(200), rng.random(200) * 2 * np.pi
    np.testing.assert_allclose(S.evaluate(u, v + 2 * np.pi), S.evaluate(u, v), atol=1e-13)
    np.testing.assert_allclose(S.evaluate(u, v - 4 * np.pi), S.evaluate(u, v), atol=1e-13)
    h = 1e-6
    fd_u = (S.evaluate(u + h, v) - S.evaluate(u - h, v)) / (2 * h)
    fd_v = (S.evaluate(u, v + h) - S.evaluate(u, v - h)) / (2 * h)
    inner = (u > 2 * h) & (u < 1 - 2 * h)
    np.testing.assert_allclose(S.evaluate(u, v, du=1)[inner], fd_u[inner], atol=1e-7)
    np.testing.assert_allclose(S.evaluate(u, v, dv=1), fd_v, atol=1e-7)


def test_grid_evaluation_matches_pointwise():
    S = fit_surface(cylinder().patches[1], tol=TOL).surface
    u, v = np.linspace(0, 1, 7), np.linspace(0, 2 * np.pi, 11)
    U, V = np.meshgrid(u, v, indexing="ij")
    np.testing.assert_allclose(S.evaluate_grid(u, v), S.evaluate(U, V), atol=1e-14)


def test_refinement_reaches_tight_tolerance():
    fit = fit_surface(sphere(2.5).patches[0], tol=1e-7)
    assert fit.max_deviation <= 1e-7
    assert fit.iterations > 1 and fit.nv > 32


def test_unreachable_tolerance_names_the_patch():
    with pytest.raises(GeometryError, match="north cap.*misses tolerance"):
        fit_surface(sphere(2.5).patches[0], tol=1e-12, max_nu=20, max_nv=40, name="north cap")


@pytest.mark.parametrize("standin", [sphere(2.5), cylinder(2.5, 3.0), ring(1.5, 3.0, 2.0)], ids=lambda s: s.name)
def test_chain_shares_bit_identical_rows_and_volume(standin):
    fits = fit_patches(standin.patches, tol=TOL)
    n = len(fits)
    pairs = [(j, j + 1) for j in range(n - 1)] + ([(n - 1, 0)] if standin.genus == 1 else [])
    for a, b in pairs:
        np.testing.assert_array_equal(fits[a].surface.poles[-1], fits[b].surface.poles[0])
    assert len({f.nv for f in fits}) == 1
    dev = max(f.max_deviation for f in fits)
    assert dev <= TOL
    vol = abs(enclosed_volume([f.surface for f in fits]))
    # |V_bspline - V| <= max pointwise deviation * area
    assert abs(vol - standin.volume) <= dev * standin.area


def test_non_matching_chain_is_rejected():
    a = sphere(2.5).patches[0]
    b = sphere(2.6).patches[1]
    with pytest.raises(GeometryError, match="do not share their boundary"):
        fit_patches([a, b], names=["top", "bottom"])


def test_dict_round_trip_and_validation():
    S = fit_surface(sphere(1.0).patches[0]).surface
    S2 = BSplineSurfaceData.from_dict(S.as_dict())
    np.testing.assert_array_equal(S2.poles, S.poles)
    assert S2.v_periodic and not S2.u_periodic
    with pytest.raises(GeometryError):
        BSplineSurfaceData(S.poles[:, :-1], S.u_knots, S.u_mults, S.v_knots, S.v_mults)
    assert not S.poles.flags.writeable


@settings(max_examples=15, deadline=None)
@given(
    kind=st.sampled_from(["sphere", "cylinder"]),
    r=st.floats(0.5, 8.0),
    h=st.floats(0.5, 8.0),
)
def test_fit_random_sizes(kind, r, h):
    standin = sphere(r) if kind == "sphere" else cylinder(r, h)
    fits = fit_patches(standin.patches, tol=TOL)
    dev = max(f.max_deviation for f in fits)
    assert dev <= TOL
    vol = abs(enclosed_volume([f.surface for f in fits]))
    assert abs(vol - standin.volume) <= dev * standin.area
    assert math.isfinite(vol)
