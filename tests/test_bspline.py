"""Kernel-neutral B-spline fit (numpy only, no CAD kernel needed)."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tabletcad.brep.fit import fit_patches, fit_surface
from tabletcad.brep.surface import BSplineSurfaceData, enclosed_volume, volume_and_area
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
    # derivatives too, on a surface whose poles are not square (the grid's two matrix products
    # against the point-by-point sum)
    S = fit_surface(sphere(2.5).patches[0], tol=TOL).surface
    assert S.poles.shape[0] != S.poles.shape[1]
    u, v = np.linspace(0, 1, 13), np.linspace(0, 2 * np.pi, 29)
    U, V = np.meshgrid(u, v, indexing="ij")
    for du, dv in ((0, 0), (1, 0), (0, 1)):
        np.testing.assert_allclose(S.evaluate_grid(u, v, du, dv), S.evaluate(U, V, du, dv), atol=1e-12)


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
    # volume_and_area: the same exact volume, and the area within the fit's reach of the closed form
    v2, a2 = volume_and_area([f.surface for f in fits])
    assert abs(abs(v2) - vol) <= 1e-13 * vol
    assert abs(a2 - standin.area) <= 4 * dev * standin.area


@given(st.lists(st.floats(0.05, 2.0), min_size=4, max_size=9), st.lists(st.floats(0.05, 2.0), min_size=4, max_size=9))
@settings(max_examples=25)
def test_area_of_a_plane_patch_with_uneven_parametrisation(dx, dy):
    """A cubic B-spline patch with poles on a rectangular grid in z = 0 (increasing, uneven steps)
    maps its domain one to one onto the rectangle of its corner poles: area = its product, and the
    rule is exact (the integrand ``x'(u) y'(v)`` is a polynomial on every span)."""
    x, y = np.concatenate([[0.0], np.cumsum(dx)]), np.concatenate([[0.0], np.cumsum(dy)])
    P = np.stack(np.broadcast_arrays(x[:, None], y[None, :], 0.0), axis=-1)

    def clamped(n):  # n poles, degree 3: n - 2 knots, end multiplicities 4
        k = np.linspace(0.0, 1.0, n - 2) ** 1.3
        return k, np.r_[4, np.ones(n - 4, int), 4]

    (uk, um), (vk, vm) = clamped(len(x)), clamped(len(y))
    s = BSplineSurfaceData(P, uk, um, vk, vm, 3, 3, False, False)
    vol, area = volume_and_area([s])
    assert area == pytest.approx(x[-1] * y[-1], rel=1e-13)
    assert vol == pytest.approx(0.0, abs=1e-13 * area)  # the plane z = 0 encloses nothing by itself


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


def _cox_de_boor_guarded(t, degree, x, span):
    """Textbook Cox-de Boor (The NURBS Book, A2.2) point by point, zero denominators guarded."""
    out = np.zeros((x.size, degree + 1))
    for m, (xm, i) in enumerate(zip(x, span)):
        N, left, right = [1.0] + [0.0] * degree, [0.0] * (degree + 1), [0.0] * (degree + 1)
        for j in range(1, degree + 1):
            left[j], right[j] = xm - t[i + 1 - j], t[i + j] - xm
            saved = 0.0
            for r in range(j):
                denom = right[r + 1] + left[j - r]
                temp = N[r] / denom if denom != 0.0 else 0.0
                N[r] = saved + right[r + 1] * temp
                saved = left[j - r] * temp
            N[j] = saved
        out[m] = N
    return out


def _random_clamped_knots(seed: int, degree: int, repeat: bool) -> tuple[int, np.ndarray, np.ndarray]:
    """``(n, t, x)``: a random clamped knot vector ``t`` on [0, 1] of ``n`` B-splines of ``degree`` (its
    second interior knot repeated when ``repeat``) and parameters ``x`` on it, the ends and knots included."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(degree + 1, 30))
    interior = np.sort(rng.uniform(0.0, 1.0, n - degree - 1))
    if repeat and interior.size > 2:
        interior[1] = interior[2]
    t = np.concatenate([np.zeros(degree + 1), interior, np.ones(degree + 1)])
    return n, t, np.concatenate([rng.uniform(0.0, 1.0, 50), [0.0, 1.0], interior])


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), degree=st.integers(1, 6), repeat=st.booleans())
def test_basis_on_whole_columns_is_the_textbook_recursion_bit_for_bit(seed, degree, repeat):
    """The B-spline values the fit, the checks and the revolved faces use (every ``x`` in its
    non-empty span, computed on whole columns) equal the textbook recursion point by point, to the
    last bit, with repeated interior knots too; and they sum to 1 (partition of unity)."""
    from tabletcad.brep.knots import _find_span, basis_functions

    n, t, x = _random_clamped_knots(seed, degree, repeat)
    span, N = basis_functions(t, degree, n, x)
    np.testing.assert_array_equal(span, _find_span(t, degree, n, x))
    np.testing.assert_array_equal(N, _cox_de_boor_guarded(t, degree, x, span))
    assert np.max(np.abs(N.sum(axis=1) - 1.0)) < 1e-14


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), degree=st.integers(1, 6), repeat=st.booleans())
def test_basis_derivatives_are_the_textbook_formula_bit_for_bit(seed, degree, repeat):
    """First derivatives of the B-splines equal, to the last bit, the textbook formula term by term
    (``N'_{i,p} = p/(t_{i+p}-t_i) N_{i,p-1} - p/(t_{i+p+1}-t_{i+1}) N_{i+1,p-1}``, a zero support's term
    dropped), with repeated interior knots too, and sum to 0."""
    from tabletcad.brep.knots import _find_span, basis_derivatives

    n, t, x = _random_clamped_knots(seed, degree, repeat)
    span, dN = basis_derivatives(t, degree, n, x, 1)
    np.testing.assert_array_equal(span, _find_span(t, degree, n, x))
    lower = _cox_de_boor_guarded(t, degree - 1, x, span) if degree > 1 else np.ones((x.size, 1))
    expected = np.zeros((x.size, degree + 1))
    for m, i0 in enumerate(span - degree):
        for k in range(degree + 1):
            i = i0 + k
            if k >= 1 and t[i + degree] != t[i]:
                expected[m, k] += degree / (t[i + degree] - t[i]) * lower[m, k - 1]
            if k <= degree - 1 and t[i + degree + 1] != t[i + 1]:
                expected[m, k] -= degree / (t[i + degree + 1] - t[i + 1]) * lower[m, k]
    np.testing.assert_array_equal(dN, expected)
    assert np.max(np.abs(dN.sum(axis=1))) <= 1e-12 * np.max(np.abs(dN))


def test_collocation_is_shared_between_surfaces_with_the_same_knots():
    """The faces of a chain share their knots: their collocation matrices are one read-only table
    (:data:`tabletcad.geometry.tables.COLLOCATION`), what each would compute alone, and a surface
    with other knots or other samples gets its own."""
    from tabletcad.geometry.tables import COLLOCATION

    fits = fit_patches(cylinder(2.5, 3.0).patches, 1e-4)
    a, b = fits[0].surface, fits[1].surface
    assert np.array_equal(a.v_knots, b.v_knots) and np.array_equal(a.v_mults, b.v_mults)
    v = np.linspace(0.0, math.tau, 41)
    COLLOCATION.clear()
    alone = np.array(a.collocation("v", v, 1))
    shared = b.collocation("v", v, 1)
    assert shared is a.collocation("v", v, 1) and not shared.flags.writeable
    np.testing.assert_array_equal(shared, alone)
    assert a.collocation("v", v + 1e-12, 1) is not shared and a.collocation("v", v, 0) is not shared
    # and it is the B-splines' derivative: the surface's own v-derivative at the samples
    u = np.array([0.3])
    np.testing.assert_allclose(np.einsum("ai,ijk,bj->abk", a.collocation("u", u), a.poles, shared)[0],
                               a.evaluate(np.full(v.shape, 0.3), v, dv=1), atol=1e-12)


@pytest.mark.parametrize("nu, nv", [(5, 300), (200, 7), (40, 40), (1, 90)])
def test_grid_products_in_either_order_agree_and_the_cheaper_one_is_taken(nu, nv):
    """``evaluate_grid`` and ``grid_components`` contract the direction with more samples than poles
    last (fewer multiply-adds: ``_v_first``); both orders sum the same terms, so they agree to
    rounding, and with the point-by-point evaluation."""
    from tabletcad.brep.surface import _v_first

    S = fit_surface(sphere(2.5).patches[0], tol=TOL).surface
    pu, pv = S.shape
    u, v = np.linspace(0, 1, nu), np.linspace(0, 2 * np.pi, nv)
    Bu, Bu1, Bv, Bv1 = S.collocation("u", u), S.collocation("u", u, 1), S.collocation("v", v), S.collocation("v", v, 1)
    P = np.ascontiguousarray(S.poles.transpose(2, 0, 1))
    for (a, b), got in zip(((Bu, Bv), (Bu1, Bv), (Bu, Bv1)), S.grid_components(u, v)):
        for X in ((a @ P) @ b.T, a @ (P @ b.T)):
            np.testing.assert_allclose(got, X, rtol=0, atol=1e-13)
    U, V = np.meshgrid(u, v, indexing="ij")
    np.testing.assert_allclose(S.evaluate_grid(u, v), S.evaluate(U, V), atol=1e-13)
    cost = {True: 2 * pu * pv * nv + 3 * nu * pu * nv, False: 2 * nu * pu * pv + 3 * nu * pv * nv}
    assert cost[_v_first(nu, nv, pu, pv, 2, 3)] == min(cost.values())
    assert _v_first(nu, nv, pu, pv) == (pu * pv * nv + nu * pu * nv < nu * pu * pv + nu * pv * nv)
