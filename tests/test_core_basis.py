"""Cardinal functions of the per-mode ODE (tabletcad.geometry.basis).

For mode ``n`` the Bloor-Wilson equation of order 2 reduces to
``(D² - λ²)² A = 0`` with ``λ = a n``; the cardinal functions ``L_k(u; λ)``
are its solutions that equal 1 for boundary condition ``k`` and 0 for the
other three.  These tests check that definition directly (conditions, ODE,
derivatives) rather than against the implementation's own formulae.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tabletcad.geometry.basis import basis, cardinal, cardinal_coefficients, lebesgue_max

LAMS = [0.0, 1e-12, 1e-6, 1e-3, 0.05, 0.1, 0.5, 0.999, 1.0, 1.0 + 1e-12, 1.5, 3.0, 10.0, 30.0, 48.0, 100.0, 700.0, 1000.0]
NODE_SETS = [(0.0, 1 / 3, 2 / 3, 1.0), (0.0, 0.1, 0.85, 1.0), (0.0, 0.45, 0.55, 1.0)]
U = np.linspace(0.0, 1.0, 201)
#: λ = a·n over the range the package reaches in practice (a <= 1, N <= 48 and a = "auto")
PRACTICAL_LAMS = np.linspace(0.0, 30.0, 301)
#: λ beyond it (a up to 50 is accepted by PDEPatch)
LARGE_LAMS = np.linspace(30.0, 1000.0, 971)


def _node_error(lam, nodes, form="curves"):
    if form == "curves":
        return float(np.max(np.abs(cardinal(np.array(nodes), lam, nodes) - np.eye(4))))
    ends = np.array([0.0, 1.0])
    e0 = np.max(np.abs(cardinal(ends, lam, nodes, "hermite") - np.eye(4)[:2]))
    e1 = np.max(np.abs(cardinal(ends, lam, nodes, "hermite", der=1) - np.eye(4)[2:])) / max(1.0, lam)
    return float(max(e0, e1))


# ----------------------------------------------------------------------------- interpolation
@pytest.mark.parametrize("nodes", NODE_SETS)
def test_curves_form_is_identity_at_nodes_practical_range(nodes):
    """L_k(u_j; λ) = δ_kj for λ in [0, 30] (dense sweep of 301 values), every node set."""
    errs = np.array([_node_error(lam, nodes) for lam in PRACTICAL_LAMS])
    assert np.all(np.isfinite(errs))
    worst = int(np.argmax(errs))
    # ill-conditioning grows like eps·e^{λ·u1}; 1e-9 keeps a 10 mm curve within 1e-8 mm
    assert errs[worst] <= 1e-9, f"λ = {PRACTICAL_LAMS[worst]:.3g}: |L(nodes) - I| = {errs[worst]:.3g}"


@pytest.mark.parametrize("lam", LAMS)
def test_curves_form_identity_at_selected_lambdas(lam):
    """Selected λ (including 100, 700, 1000) where the default node set is exact."""
    assert _node_error(lam, NODE_SETS[0]) <= 1e-12


@pytest.mark.parametrize("nodes", NODE_SETS)
def test_curves_form_is_identity_at_nodes_relative_to_size_up_to_lambda_1000(nodes):
    """For large λ the cardinals reach ~e^{λ/4} between the nodes; they are exact at the
    nodes to working precision *relative to that size* (the best a float64 representation
    can do).  PDEPatch refuses any mode amplified more than 1000-fold, so in use the
    absolute error stays below 1e-12."""
    u = np.linspace(0.0, 1.0, 401)
    for lam in LARGE_LAMS[::10]:
        size = float(np.max(np.abs(cardinal(u, lam, nodes))))
        err = _node_error(lam, nodes)
        assert np.isfinite(err) and err <= 1e-11 * max(size, 1.0), (lam, err, size)


def test_curves_form_refuses_lambda_beyond_its_range():
    """Beyond LAMBDA_MAX the interior rows underflow: a clear error instead of NaN."""
    from tabletcad.geometry.basis import LAMBDA_MAX

    with pytest.raises(ValueError, match="λ = 3000"):
        cardinal(np.array(NODE_SETS[0]), 3000.0, NODE_SETS[0])
    L = cardinal(np.array(NODE_SETS[0]), LAMBDA_MAX, NODE_SETS[0])
    assert np.all(np.isfinite(L))


@pytest.mark.parametrize("lam", LAMS + [3000.0, 1e4, 3e4])
def test_hermite_form_values_and_slopes_at_ends(lam):
    """Conditions in order X(0), X(1), X_u(0), X_u(1); slopes compared relative to max(1, λ).

    The Hermite system stays well conditioned for any λ (no growing cardinal)."""
    assert _node_error(lam, NODE_SETS[0], "hermite") <= 1e-11


@pytest.mark.parametrize("lam", LAMS + [3000.0, 1e4])
def test_hermite_positional_cardinals_bounded_by_one(lam):
    """The positional Hermite cardinals are (1 + λu)e^{-λu}-like: Σ|L| <= 1 on [0, 1] for every λ."""
    L = cardinal(U, lam, NODE_SETS[0], "hermite")
    assert np.all(np.isfinite(L))
    assert np.max(np.sum(np.abs(L[:, :2]), axis=1)) <= 1.0 + 1e-12
    assert lebesgue_max(lam, NODE_SETS[0], "hermite") <= 1.0 + 1e-12


@pytest.mark.parametrize("lam", [0.0, 0.5, 1.0, 5.0, 20.0])
def test_curves_form_lebesgue_at_least_one(lam):
    L = cardinal(U, lam, NODE_SETS[0])
    assert np.all(np.isfinite(L))
    assert lebesgue_max(lam, NODE_SETS[0]) >= 1.0 - 1e-12


def test_partition_of_unity_only_for_lambda_zero():
    """Constants solve the ODE only when λ = 0, so only then do the value cardinals sum to 1."""
    nodes = NODE_SETS[0]
    np.testing.assert_allclose(cardinal(U, 0.0, nodes).sum(axis=1), 1.0, atol=1e-13)
    np.testing.assert_allclose(cardinal(U, 0.0, nodes, "hermite")[:, :2].sum(axis=1), 1.0, atol=1e-13)
    s = cardinal(U, 1.0, nodes).sum(axis=1)
    assert np.max(np.abs(s - 1.0)) > 1e-4  # λ = 1: a constant is not reproduced


# ----------------------------------------------------------------------------- ODE
@pytest.mark.parametrize("lam", [0.0, 0.3, 1.0, 2.0, 5.0])
@pytest.mark.parametrize("form", ["curves", "hermite"])
def test_cardinals_solve_the_mode_ode(lam, form):
    """(D² - λ²)² L = L'''' - 2λ² L'' + λ⁴ L = 0, with L'''' by central differences of L''."""
    nodes = NODE_SETS[1]
    h = 1e-3
    u = np.linspace(0.05, 0.95, 37)
    L = cardinal(u, lam, nodes, form)
    L2 = cardinal(u, lam, nodes, form, der=2)
    L2p = cardinal(u + h, lam, nodes, form, der=2)
    L2m = cardinal(u - h, lam, nodes, form, der=2)
    L4 = (L2p - 2 * L2 + L2m) / h**2
    res = L4 - 2 * lam**2 * L2 + lam**4 * L
    scale = np.max(np.abs(L4)) + lam**2 * np.max(np.abs(L2)) + lam**4 * np.max(np.abs(L)) + 1.0
    assert np.max(np.abs(res)) < 1e-5 * scale


# ----------------------------------------------------------------------------- derivatives
@pytest.mark.parametrize(
    "lam, form",
    [(lam, "curves") for lam in (0.0, 0.05, 0.7, 1.0, 1.0 + 1e-9, 2.5, 20.0)]
    + [(lam, "hermite") for lam in (0.0, 0.05, 0.7, 1.0, 1.0 + 1e-9, 2.5, 20.0, 200.0, 1000.0)],
)
def test_derivatives_agree_with_finite_differences(lam, form):
    nodes = NODE_SETS[0]
    h = 1e-5 / max(1.0, lam)
    u = np.linspace(0.01, 0.99, 61)
    for der in (1, 2):
        f = lambda x: cardinal(x, lam, nodes, form, der=der - 1)  # noqa: E731
        fd = (f(u + h) - f(u - h)) / (2 * h)
        exact = cardinal(u, lam, nodes, form, der=der)
        scale = max(1.0, lam) ** der
        # curves form: cardinals grow like e^{λ/3}; compare relative to their size
        scale *= max(1.0, float(np.max(np.abs(exact))))
        assert np.max(np.abs(fd - exact)) <= 2e-6 * scale, (lam, form, der)


@pytest.mark.parametrize("lam", [0.0, 0.4, 1.0, 3.0, 60.0])
def test_raw_basis_derivatives_agree_with_finite_differences(lam):
    h = 1e-6
    u = np.linspace(0.02, 0.98, 25)
    for der in (1, 2):
        fd = (basis(u + h, lam, der - 1) - basis(u - h, lam, der - 1)) / (2 * h)
        assert np.max(np.abs(fd - basis(u, lam, der))) < 1e-6 * max(1.0, lam) ** der


def test_bad_derivative_order_rejected():
    with pytest.raises(ValueError):
        basis(U, 2.0, 3)
    with pytest.raises(ValueError):
        basis(U, 0.5, 3)
    with pytest.raises(ValueError):
        cardinal_coefficients(1.0, (0.0, 0.3, 0.6, 1.0), "nope")


# ----------------------------------------------------------------------------- λ = 1 switch
@pytest.mark.parametrize("form", ["curves", "hermite"])
@pytest.mark.parametrize("der", [0, 1, 2])
def test_continuous_across_basis_switch(form, der):
    """The hyperbolic basis is used for λ <= 1, the exponential one above.

    The cardinals are analytic in λ, so across the switch they may change
    only by their true variation: (1) at λ = 1 and the next double above 1
    they agree to rounding; (2) between λ = 1 ∓ 1e-9 the jump equals the
    first-order change 2e-9·∂L/∂λ (slope from the λ <= 1 side) to 1e-12.
    """
    nodes = NODE_SETS[0]
    u = np.linspace(0.0, 1.0, 101)
    scale = max(1.0, float(np.max(np.abs(cardinal(u, 1.0, nodes, form, der)))))
    at = cardinal(u, 1.0, nodes, form, der)
    above = cardinal(u, float(np.nextafter(1.0, 2.0)), nodes, form, der)
    assert np.max(np.abs(at - above)) < 1e-12 * scale

    eps, d = 1e-9, 1e-4
    lo = cardinal(u, 1.0 - eps, nodes, form, der)
    hi = cardinal(u, 1.0 + eps, nodes, form, der)
    slope = (lo - cardinal(u, 1.0 - eps - d, nodes, form, der)) / d
    assert np.max(np.abs((hi - lo) - 2 * eps * slope)) < 1e-12 * scale
    # and the raw jump is of the size of the true variation, not of a basis mismatch
    assert np.max(np.abs(hi - lo)) < 1e-7 * scale


@pytest.mark.parametrize("lam", [0.1, 0.5, 0.9])
def test_continuous_in_u_across_series_switches(lam):
    """Internal series switch at λu = 1e-3 (sinh x / x) and λu = 0.1 ((x cosh x - sinh x)/x³)."""
    nodes = NODE_SETS[0]
    for x in (1e-3, 0.1):
        u0 = x / lam
        if u0 > 1.0:
            continue
        for der in (0, 1, 2):
            a = cardinal(np.array([u0 * (1 - 1e-13)]), lam, nodes, "curves", der)
            b = cardinal(np.array([u0 * (1 + 1e-13)]), lam, nodes, "curves", der)
            # the direct formula of (x cosh x - sinh x)/x³ loses ~eps/x² near the switch
            assert np.max(np.abs(a - b)) < 1e-11 * 10**der


# ----------------------------------------------------------------------------- λ -> 0
def _lagrange(u, nodes):
    out = np.ones((u.size, 4))
    for k in range(4):
        for j in range(4):
            if j != k:
                out[:, k] *= (u - nodes[j]) / (nodes[k] - nodes[j])
    return out


def _hermite(u):
    # order X(0), X(1), X_u(0), X_u(1)
    return np.column_stack([2 * u**3 - 3 * u**2 + 1, -2 * u**3 + 3 * u**2, u**3 - 2 * u**2 + u, u**3 - u**2])


@pytest.mark.parametrize("nodes", NODE_SETS)
def test_lambda_zero_is_cubic_lagrange(nodes):
    np.testing.assert_allclose(cardinal(U, 0.0, nodes, "curves"), _lagrange(U, np.array(nodes)), atol=1e-13, rtol=0)


def test_lambda_zero_hermite_is_cubic_hermite():
    np.testing.assert_allclose(cardinal(U, 0.0, NODE_SETS[0], "hermite"), _hermite(U), atol=1e-13, rtol=0)


@pytest.mark.parametrize("lam", [1e-8, 1e-5, 1e-3, 1e-2])
def test_small_lambda_tends_to_cubic_with_order_lambda_squared(lam):
    """L(u; λ) = L(u; 0) + O(λ²): the error divided by λ² stays bounded (and the limit is smooth)."""
    for nodes in NODE_SETS:
        err = np.max(np.abs(cardinal(U, lam, nodes, "curves") - _lagrange(U, np.array(nodes))))
        assert err <= 0.1 * lam**2 + 1e-13
    err = np.max(np.abs(cardinal(U, lam, NODE_SETS[0], "hermite") - _hermite(U)))
    assert err <= 0.1 * lam**2 + 1e-13


def _g_exact(x: float) -> float:
    """(x cosh x - sinh x) / x³ in exact rational arithmetic: its Taylor series Σ 2(j+1) x^{2j} / (2j+3)!
    to 40 terms (the tail is below 1e-60 for |x| <= 1.5), rounded once.  The terms over one common
    denominator, 81! b^39 for x² = a/b, in integers (Fractions reduced every partial sum by a gcd of
    numbers of up to 80,000 bits: 12 ms a call, now 0.3 ms); int / int is correctly rounded, so the
    float is the one ``float(Fraction)`` of the same sum gives."""
    from fractions import Fraction
    from math import factorial

    a, b = Fraction(x).as_integer_ratio()
    a, b = a * a, b * b
    top = factorial(2 * 39 + 3)
    return sum(2 * (j + 1) * (top // factorial(2 * j + 3)) * a**j * b ** (39 - j) for j in range(40)) / (top * b**39)


@given(st.floats(min_value=-1.5, max_value=1.5, allow_nan=False))
@settings(max_examples=300, deadline=None)
def test_hyperbolic_basis_g_against_its_exact_series(x):
    """The hyperbolic basis's ``g(x) = (x cosh x - sinh x)/x³`` (its Taylor series where ``|x| <= 1``,
    the closed form beyond) is within 2e-15 relative of the exact series (rational arithmetic), and
    ``sinh(x)/x`` within 2 ulp of ``math.sinh(x)/x`` (1 at 0)."""
    import math

    from tabletcad.geometry.basis import _g, _sinhc

    got = float(_g(np.array([x]))[0])
    assert abs(got - _g_exact(x)) <= 2e-15 * _g_exact(x)
    s = float(_sinhc(np.array([x]))[0])
    assert s == 1.0 if x == 0.0 else abs(s - math.sinh(x) / x) <= 4.5e-16 * s
