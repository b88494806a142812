"""Thick spherical shell (section 6.2.3): Lamé limit, series convergence, equilibrium, Appendix C."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad
from scipy.special import eval_legendre

from tabletcad.errors import DesignError
from tabletcad.mechanics import shell as S

A, B, E, NU = 2.5, 2.0, 100.0, 0.3


@settings(max_examples=30, deadline=None)
@given(
    b_frac=st.floats(0.1, 0.97),
    nu=st.floats(-0.5, 0.49),
    p_ext=st.floats(-50, 50),
    p_int=st.floats(-50, 50),
)
def test_uniform_pressure_equals_lame(b_frac, nu, p_ext, p_int):
    a, b = 3.0, 3.0 * b_frac
    sol = S.solve_shell(a, b, 50.0, nu, p_ext=p_ext, p_int=p_int, psi=math.pi / 2, n_terms=40)
    r = np.linspace(b, a, 9)
    th = np.linspace(0, math.pi, 9)
    ours = sol.radial_displacement(r, th)
    ref = S.lame_displacement(r, a, b, 50.0, nu, p_ext, p_int)
    scale = np.max(np.abs(ref)) + 1e-300
    assert np.max(np.abs(ours - ref)) <= 1e-10 * scale
    assert np.max(np.abs(sol.displacement(r, th)[1])) <= 1e-12 * scale


def test_uniform_pressure_stresses_equal_lame():
    sol = S.solve_shell(A, B, E, NU, p_ext=3.0, p_int=1.0, n_terms=10)
    r = np.linspace(B, A, 5)
    s = sol.stresses(r, 0.7)
    srr, stt = S.lame_stresses(r, A, B, 3.0, 1.0)
    assert np.allclose(s["sigma_rr"], srr, rtol=1e-12) and np.allclose(s["sigma_thth"], stt, rtol=1e-12)
    assert np.allclose(s["sigma_phph"], stt, rtol=1e-12)


@pytest.mark.parametrize("region", ["equator", "poles"])
def test_band_coefficients_reproduce_the_indicator(region):
    psi = 0.4
    f = S.band_coefficients(psi, 60, region)
    # each coefficient is (2n+1)/2 times the integral of P_n over the loaded |cos θ| range
    for n in (0, 2, 4, 10):
        if region == "equator":
            lo, hi = -math.sin(psi), math.sin(psi)
            ref = (2 * n + 1) / 2 * quad(lambda x, n=n: eval_legendre(n, x), lo, hi)[0]
        else:
            cpsi = math.cos(psi)
            ref = (2 * n + 1) / 2 * (quad(lambda x, n=n: eval_legendre(n, x), cpsi, 1)[0]
                                     + quad(lambda x, n=n: eval_legendre(n, x), -1, -cpsi)[0])
        assert f[n] == pytest.approx(ref, abs=1e-12)
    assert np.all(f[1::2] == 0)


def test_boundary_conditions_of_a_band_load():
    sol = S.solve_shell(A, B, E, NU, p_ext=3.0, p_int=1.0, psi=0.3, n_terms=600)
    th = np.array([0.2, 0.8, 1.0, math.pi / 2, 2.0, 2.9])  # away from the band edges π/2 ± 0.3
    s_out = sol.stresses(A, th)
    expected = np.where(np.abs(th - math.pi / 2) <= 0.3, -3.0, 0.0)
    assert np.max(np.abs(s_out["sigma_rr"] - expected)) < 0.02  # Gibbs-free points, slow series
    assert np.max(np.abs(s_out["tau_rth"])) < 1e-10
    s_in = sol.stresses(B, th)
    assert np.allclose(s_in["sigma_rr"], -1.0, atol=1e-9) and np.max(np.abs(s_in["tau_rth"])) < 1e-10


def test_series_converges_and_terms_decay():
    sols = {N: S.solve_shell(A, B, E, NU, p_ext=3.0, p_int=1.0, psi=0.3, n_terms=N) for N in (100, 200, 400, 800)}
    u = {N: float(s.radial_displacement(A, math.pi / 2)) for N, s in sols.items()}
    d2, d3 = abs(u[400] - u[200]), abs(u[800] - u[400])
    assert d3 < d2 * 0.6 and d3 < 2e-6
    # amplitudes |U_n(a)| of the outer-surface displacement decay like n^(-3/2)
    amp = sols[800].max_abs_coefficient()
    n = np.arange(amp.size)
    m = (n % 2 == 0) & (n >= 20) & (amp > 0)
    slope = np.polyfit(np.log(n[m]), np.log(amp[m]), 1)[0]
    assert -1.7 < slope < -1.3


def test_equilibrium_of_the_upper_half():
    """Outer band force + inner pressure force on the upper half = -(σ_θθ resultant on the equatorial cut)."""
    p_ext, p_int, psi = 3.0, 1.0, 0.3
    x, w = np.polynomial.legendre.leggauss(40)
    rr = (A - B) / 2 * x + (A + B) / 2
    ww = w * (A - B) / 2
    errors = []
    for N in (100, 400, 800):
        sol = S.solve_shell(A, B, E, NU, p_ext=p_ext, p_int=p_int, psi=psi, n_terms=N)
        stt = sol.stresses(rr, np.full_like(rr, math.pi / 2))["sigma_thth"]
        f_cut = -np.sum(ww * stt * 2 * math.pi * rr)
        f_out = -math.pi * A * A * p_ext * math.sin(psi) ** 2
        f_in = math.pi * B * B * p_int
        errors.append(abs(f_cut + f_out + f_in) / abs(f_out))
    assert errors[-1] < 1e-6 and errors[0] > errors[1] > errors[2]


def test_net_force_rejected():
    with pytest.raises(DesignError, match="net axial force"):
        S.solve_shell(A, B, E, NU, p_ext=0.0, outer_coefficients=[0.0, 1.0], n_terms=4)


def test_bad_radii():
    with pytest.raises(DesignError, match="must be < a"):
        S.solve_shell(2.0, 2.5, E, NU, p_ext=1.0)


def test_appendix_c_lame_terms():
    """Eq 6.20's n = 0 part with C.1 and C.3 equals Lamé only if P_ext is set to 0 there and f0 carries the load."""
    def appendix_u(r, a, b, E, g, p_ext, p_int, f0):
        B1 = -0.75 * (-f0 + p_int - p_ext) * (a * b) ** 3 / ((b**3 - a**3) * (2 * g - 1))
        D1 = -0.3 * ((p_int - p_ext) * b**3 - f0 * a**3) / ((b**3 - a**3) * (g + 1))
        return -2 * (1 + g) / (3 * E) * ((1 - 2 * g) * B1 / r**2 + (10 * g - 5) * D1 * r)

    r = np.linspace(B, A, 5)
    lame = S.lame_displacement(r, A, B, E, NU, 3.0, 1.0)
    assert np.allclose(appendix_u(r, A, B, E, NU, 0.0, 1.0, 3.0), lame, rtol=1e-12)
    both = appendix_u(r, A, B, E, NU, 3.0, 1.0, 3.0)
    assert np.max(np.abs(both / lame - 1)) > 0.5  # P_ext in C.1/C.3 as well double-counts the load
