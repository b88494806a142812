"""Diametral compression by FE against Hondros, the line-load formula, Pitt 1988 and Pitt-Heasley.

Meshes are coarse (a few tens of thousands of unknowns) so each test runs in
seconds of CPU; the figures are printed (``pytest -s``) for the README.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

skfem = pytest.importorskip("skfem")
pytest.importorskip("gmsh")
pytest.importorskip("OCP")

from tabletcad.errors import DesignError  # noqa: E402
from tabletcad.fe.diametral import (  # noqa: E402
    contact_depth,
    diametral,
    hondros_centre_stress,
    line_load_stress,
    load_axis,
)


def _tablet(**kw):
    from tabletcad.design import design_from_dict

    return design_from_dict({"tablet": kw})


# ----------------------------------------------------------------------------- closed form
def test_hondros_tends_to_the_line_load_and_is_below_it():
    P, D, t = 100.0, 10.0, 2.0
    ref = line_load_stress(P, D, t)
    assert ref == pytest.approx(2 * P / (math.pi * D * t))
    for b, lo in [(1e-4, 1 - 1e-8), (0.1, 0.99986), (1.0, 0.98)]:
        r = hondros_centre_stress(P, D, t, b) / ref
        assert lo < r < 1.0
    # small-angle expansion: (sin 2a - a)/sin a = 1 - 7a^2/6 (to O(a^4))
    a = math.asin(0.05)
    assert hondros_centre_stress(P, D, t, 0.5) / ref == pytest.approx(1 - 7 * a * a / 6, abs=a**4)
    with pytest.raises(DesignError):
        hondros_centre_stress(P, D, t, D)


def test_contact_depth_cuts_the_strip_from_the_circle():
    D, b = 10.0, 1.0
    d = contact_depth(D, b)
    assert (0.5 * D - d) ** 2 + (0.5 * b) ** 2 == pytest.approx(0.25 * D * D, rel=1e-14)


def test_hondros_formula_against_an_independent_plane_fe():
    """2D plane FE (skfem ElementTriP2 on a disc) of radial pressure on two arcs of half-angle α.

    The arcs are the exact boundary facets selected, so the closed form is evaluated at the
    facets' own α; Hondros' approximate resultant 2αpRt would be 4 % off here.
    """
    from skfem.helpers import dot, sym_grad
    from skfem.models.elasticity import lame_parameters, linear_elasticity, linear_stress

    m = skfem.MeshTri.init_circle(4)  # unit disc, R = 1, t = 1
    e = skfem.ElementVector(skfem.ElementTriP2())
    ib = skfem.Basis(m, e)
    lam, mu = lame_parameters(1.0, 0.3)
    K = skfem.asm(linear_elasticity(lam, mu), ib)
    bfac = m.boundary_facets()
    ends = m.p[:, m.facets[:, bfac]]  # (2, 2, k)
    ang_mid = np.arctan2(ends[0].mean(0), np.abs(ends[1].mean(0)))
    sel = bfac[np.abs(ang_mid) <= 0.5]
    ends = m.p[:, m.facets[:, sel]]
    alpha = float(np.abs(np.arctan2(ends[0], np.abs(ends[1]))).max())
    fb = skfem.FacetBasis(m, e, facets=sel)

    @skfem.LinearForm
    def pressure(v, w):
        return -dot(w.n, v)

    @skfem.Functional
    def push(w):
        return np.abs(w.n[1])

    P = 1.0
    f = pressure.assemble(fb) * (P / (push.assemble(fb) / 2))
    c = int(np.argmin((m.p**2).sum(0)))
    b = int(np.argmin(((m.p.T - [0.5, 0.0]) ** 2).sum(1)))
    u = skfem.solve(*skfem.condense(K, f, D=np.array([ib.nodal_dofs[0, c], ib.nodal_dofs[1, c], ib.nodal_dofs[1, b]])))
    s = linear_stress(lam, mu)(sym_grad(ib.interpolate(u)))
    sb = ib.with_element(skfem.ElementTriDG(skfem.ElementTriP1()))
    sxx = float((sb.probes(np.array([[1e-9], [1e-9]])) @ sb.project(s[0, 0]))[0])
    exact = hondros_centre_stress(P, 2.0, 1.0, 2.0 * math.sin(alpha))
    approx_resultant = line_load_stress(P, 2.0, 1.0) * (math.sin(2 * alpha) - alpha) / alpha
    print(f"\nplane FE, alpha = {alpha:.4f}: centre {sxx:.5f}, closed form {exact:.5f}, with 2αpRt {approx_resultant:.5f}")
    assert sxx == pytest.approx(exact, rel=2e-3)
    assert abs(sxx / approx_resultant - 1) > 0.03


def test_load_axis():
    assert load_axis("x", np.array([5.0, 9.0, 3.0])) == 0
    assert load_axis("y", np.array([5.0, 9.0, 3.0])) == 1
    assert load_axis("width", np.array([5.0, 9.0, 3.0])) == 0
    assert load_axis("length", np.array([5.0, 9.0, 3.0])) == 1
    assert load_axis("width", np.array([18.0, 8.0, 3.0])) == 1
    assert load_axis("length", np.array([10.0, 10.0, 3.0])) == 0
    with pytest.raises(DesignError, match="direction = 'diagonal' is not allowed"):
        load_axis("diagonal", np.array([5.0, 9.0, 3.0]))
