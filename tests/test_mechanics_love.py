"""The thesis's Love stress-function die model (eqs 5.2-5.18), checked symbolically, and the exact die solution."""

from __future__ import annotations

import numpy as np
import pytest

from tabletcad.mechanics import love
from tabletcad.mechanics.validity import FitQualityWarning

sp = pytest.importorskip("sympy")

r, z, g, P, h0, c, G = sp.symbols("r z gamma P h0 c G", positive=True)
a6, b6, a4, b4, a3, b3, a2, b2, c2 = sp.symbols("a6 b6 a4 b4 a3 b3 a2 b2 c2")
PHI = (sp.Rational(1, 3) * a6 * (16 * z**6 - 120 * z**4 * r**2 + 90 * z**2 * r**4 - 5 * r**6)
       + b6 * (8 * z**6 - 16 * z**4 * r**2 - 21 * z**2 * r**4 + 3 * r**6)
       + a4 * (8 * z**4 - 24 * z**2 * r**2 + 3 * r**4) + b4 * (2 * z**4 + z**2 * r**2 - r**4)
       + a3 * (2 * z**3 - 3 * z * r**2) + b3 * (z**3 + z * r**2) + a2 * (2 * z**2 - r**2) + b2 * (z**2 + r**2))


def lap(f):
    return sp.diff(f, r, 2) + sp.diff(f, r) / r + sp.diff(f, z, 2)


def fields(phi):
    L = lap(phi)
    return {
        "sigma_z": (2 - g) * sp.diff(L, z) - sp.diff(phi, z, 3),
        "tau_rz": (1 - g) * sp.diff(L, r) - sp.diff(phi, r, z, z),
        "mu_r": -sp.diff(phi, z, r) / (2 * G),
        "omega_z": (2 * (1 - g) * L - sp.diff(phi, z, 2)) / (2 * G),
    }


THESIS = {
    c2: -P * r**2 * (g - 2) / (8 * h0),
    a3: -P * z * (4 * z**2 - 4 * z**2 * g + 3 * c**2 * g - 3 * r**2 * g) * (5 * g - 7) / (180 * h0 * r**2 * (g - 1)),
    b3: P * z * (4 * z**2 - 4 * z**2 * g + 3 * c**2 * g - 3 * r**2 * g) / (30 * h0 * r**2 * (g - 1)),
    a4: -P * (-1 + 7 * g) / (1344 * h0), b4: P / (56 * h0),
    a6: -P * (-7 + 11 * g) / (5280 * h0 * r**2), b6: P / (528 * h0 * r**2),
}


def _with_c2(expr):
    return sp.expand(expr.subs(b2, (c2 + 4 * a2) / (10 - 12 * g)))


def test_phi_with_constant_coefficients_is_biharmonic():
    assert sp.simplify(lap(lap(PHI))) == 0


def test_eqs_5_11_to_5_14_follow_from_5_2_to_5_7():
    f = fields(PHI)
    printed_wz = (b6 * ((174 - 132 * g) * r**4 - (864 - 1056 * g) * r**2 * z**2 + (112 - 352 * g) * z**4)
                  - a6 * (160 * z**4 - 480 * r**2 * z**2 + 60 * r**4) + b4 * ((32 - 56 * g) * z**2 - (30 - 28 * g) * r**2)
                  - a4 * (96 * z**2 - 48 * r**2) + (14 - 20 * g) * b3 * z - 12 * a3 * z + (10 - 12 * g) * b2 - 4 * a2) / (2 * G)
    printed_sz = (a6 * (960 * r**2 * z - 640 * z**3) + b6 * ((448 - 704 * g) * z**3 - (1728 - 1056 * g) * z * r**2)
                  - 192 * a4 * z + 4 * b4 * (16 - 14 * g) * z - 12 * a3 + b3 * (14 - 10 * g))
    assert sp.expand(f["omega_z"] - printed_wz) == 0
    assert sp.expand(f["sigma_z"] - printed_sz) == 0


def _bc_equations():
    f = {k: _with_c2(v) for k, v in fields(PHI).items()}
    eqs = []
    for expr, var in [
        (f["sigma_z"].subs(z, 0), r), (f["tau_rz"].subs(z, 0), r),
        (f["sigma_z"].subs(z, h0) + P, r), (f["tau_rz"].subs(z, h0), r),
        (f["omega_z"].subs(z, 0) * 2 * G, r), (sp.diff(f["omega_z"], r).subs(z, 0) * 2 * G, r),
        (f["mu_r"].subs(r, c) * 2 * G, z),
    ]:
        eqs += [e for e in sp.Poly(sp.expand(expr), var).coeffs() if e != 0]
    return eqs


def test_boundary_conditions_5_10_have_no_constant_solution():
    eqs = _bc_equations()
    unknowns = [a6, b6, a4, b4, a3, b3, c2]
    M, rhs = sp.linear_eq_to_matrix(eqs, unknowns)
    assert M.rank() == 7
    assert M.row_join(rhs).rank() == 8  # inconsistent
    assert sp.solve(eqs, unknowns, dict=True) == []


def test_constants_5_15_satisfy_bcs_only_pointwise_and_break_biharmonicity():
    # every expression here is a rational function of the symbols: sp.cancel's canonical form is 0 exactly
    # when the expression is identically 0 (the check sp.simplify made, at a fifth of its time)
    f = {k: _with_c2(v).subs(THESIS) for k, v in fields(PHI).items()}
    assert sp.cancel(f["sigma_z"].subs(z, 0)) == 0
    assert sp.cancel(f["sigma_z"].subs(z, h0) + P) == 0
    assert sp.cancel(f["tau_rz"].subs(z, 0)) == 0
    assert sp.cancel(f["tau_rz"].subs(z, h0)) == 0
    assert sp.cancel(f["omega_z"].subs(z, 0)) == 0
    assert sp.cancel(f["mu_r"].subs(r, c)) == 0
    phi_sub = _with_c2(PHI).subs(THESIS)
    # not identically 0: its exact value at a point is a nonzero rational (a proof, where simplify's
    # unreduced form only said it found no zero; simplify took 1.7 s of this test)
    at = lap(lap(phi_sub)).xreplace({r: 4, z: 2, g: sp.Rational(21, 100), P: 10, h0: 6, c: 5})
    assert at.is_Rational and at != 0


def test_eq_5_16_is_100_times_what_5_15_gives():
    wz = sp.cancel(_with_c2(fields(PHI)["omega_z"]).subs(THESIS))  # (rational functions: cancel's forms are exact)
    bracket = z**2 * g / r**2 - (1 - g) / 2 + g**2 / (g - 1) * (1 - c**2 / r**2)
    eq516 = 50 * P * z**2 / (G * h0) * bracket
    assert sp.cancel(wz - P * z**2 / (2 * G * h0) * bracket) == 0
    assert sp.cancel(eq516 / wz) == 100


def test_numeric_fields_match_the_symbolic_ones():
    vals = {P: 10.0, g: 0.21, c: 5.0, h0: 6.0, r: 4.0, z: 2.0, G: 2640 / 2.42}
    k = love.thesis_constants(10.0, 0.21, 5.0, 6.0, 4.0, 2.0)
    num = love.love_fields(k, 4.0, 2.0, 2640.0, 0.21)
    sym = {name: float(_with_c2(e).subs(THESIS).subs(vals)) for name, e in fields(PHI).items()}
    for name in ("sigma_z", "tau_rz", "mu_r", "omega_z"):
        assert num[name] == pytest.approx(sym[name], rel=1e-10, abs=1e-12)
    assert float(love.axial_displacement(10.0, 2640, 0.21, 5.0, 6.0, 2.0, 4.0, scale="derived")) == pytest.approx(
        sym["omega_z"], rel=1e-10)


def test_thesis_displacement_and_table_5_1_simulation():
    # the thesis's -0.2155 mm at 10 MPa is reproduced at z = 2.9635 mm (r = c, h0 = 6); z = 3 gives -0.2196
    assert float(love.axial_displacement(10.0, 2640, 0.21, 5.0, 6.0, 3.0, 5.0)) == pytest.approx(-0.21959, abs=1e-5)
    assert float(love.axial_displacement(10.0, 2640, 0.21, 5.0, 6.0, 2.96347, 5.0)) == pytest.approx(-0.2155, abs=1e-5)
    P = np.linspace(10, 50, 41)
    with pytest.warns(FitQualityWarning, match="poor linearity"):
        sim = love.simulate_compression(P, z=2.96347)
    assert sim.omega_z0 == pytest.approx(-1.078, abs=1e-4)
    f = sim.heckel
    # Table 5.1 (simulation): K 0.0107, A 0.8402, Py 93.46 MPa; we get K 0.01143, A 0.8363, Py 87.5 MPa
    assert f.K_per_MPa == pytest.approx(0.011433, rel=1e-3)
    assert f.A == pytest.approx(0.83632, rel=1e-4)
    assert abs(f.K_per_MPa / 0.0107 - 1) < 0.08 and abs(f.A / 0.8402 - 1) < 0.01


def test_confined_compression_exact_solution():
    cc = love.confined_compression(10.0, 2640.0, 0.21, 6.0)
    eps = -10.0 * 1.21 * 0.58 / (2640.0 * 0.79)
    assert float(cc.axial_strain) == pytest.approx(eps, rel=1e-13)
    assert float(cc.axial_displacement) == pytest.approx(6.0 * eps, rel=1e-13)
    assert float(cc.radial_stress) == pytest.approx(-10.0 * 0.21 / 0.79, rel=1e-13)
    # Hooke's law check: ε_r = (σ_r - ν(σ_θ + σ_z))/E = 0
    sr = float(cc.radial_stress)
    assert (sr - 0.21 * (sr - 10.0)) / 2640.0 == pytest.approx(0.0, abs=1e-15)


def test_love_command_default_z_is_the_readme_figure(capsys):
    """`tabletcad love` with its defaults gives the README's K = 0.01143, A = 0.8363 with the thesis's
    ω_z0 = -1.078 mm, because its default z is the height where eq 5.18 gives the thesis's -0.2155 mm."""
    import json

    from scipy.optimize import brentq

    from tabletcad.cli import main
    from tabletcad.cli.mechanics import love_cmd

    z_root = brentq(lambda z: float(love.axial_displacement(10.0, 2640, 0.21, 5.0, 6.0, z, 5.0)) + 0.2155, 2.5, 3.5,
                    xtol=1e-12)
    assert love.THESIS_Z == pytest.approx(z_root, abs=5e-5)
    assert next(p.default for p in love_cmd.params if p.name == "z") == love.THESIS_Z
    assert main(["love", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["assumptions"]["z_mm"] == love.THESIS_Z
    assert d["omega_z0_mm"] == pytest.approx(-1.078, abs=5e-5)
    assert round(d["K_per_MPa"], 5) == 0.01143 and round(d["A"], 4) == 0.8363
    # at the nominal thickness z = 3 mm the same chain gives K 0.01176: z matters at the 3 % level
    assert main(["love", "--json", "--z", "3"]) == 0
    d3 = json.loads(capsys.readouterr().out)
    assert d3["K_per_MPa"] == pytest.approx(0.011763, rel=1e-4)
