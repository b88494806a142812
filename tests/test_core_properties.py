"""Property-based tests of the core (hypothesis; derandomized profile from conftest, no deadline)."""

from __future__ import annotations

import math

import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from tabletcad.geometry.curves import Ellipse, Stadium, Transformed  # noqa: E402
from tabletcad.geometry.patch import PDEPatch  # noqa: E402
from tabletcad.families.thesis import coaxial_tablet  # noqa: E402

TWO_PI = 2 * math.pi
V = np.linspace(0.0, TWO_PI, 256, endpoint=False) + 0.011
Q = dict(nu=32, nv=64)  # geometry tests, not accuracy tests: modest quadrature
SETTINGS = dict(deadline=None, derandomize=True, max_examples=8)


@st.composite
def domed_sections(draw):
    """Cap - band - cap: curves on spherical caps of random rim radius and depths (radii monotone in
    each dome, the package's own dome layout) around a band of random height; random plan aspect."""
    from tabletcad.families.thesis import _band, _cap

    R = draw(st.floats(2.0, 8.0))
    d_bot = draw(st.floats(0.15, 1.0)) * R
    d_top = draw(st.floats(0.15, 1.0)) * R
    band = draw(st.floats(0.3, 4.0))
    secs = [_cap(R, d_bot, d_bot, up=False), _band(R, d_bot, d_bot + band), _cap(R, d_bot + band, d_top, up=True)]
    for sec in secs:  # the generated case is what the test claims
        radii = [r for r, _ in sec]
        assert radii == sorted(radii) or radii == sorted(radii, reverse=True)
        assert all(z1 >= z0 for (_, z0), (_, z1) in zip(sec, sec[1:]))
    aspect = draw(st.sampled_from([1.0, 1.0, 1.4, 2.0]))
    return secs, aspect


def _tablet(sections, aspect):
    return coaxial_tablet(sections, aspect, a=1.0, tol=_tol())


def _tol():
    from dataclasses import replace

    from tabletcad.tolerance import DEFAULT

    return replace(DEFAULT, quad_u=32, quad_v=64)


def _rotz(t):
    c, s = math.cos(t), math.sin(t)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])


@settings(**SETTINGS)
@given(domed_sections())
def test_random_domes_positive_volume_and_interpolate(case):
    sections, aspect = case
    t = _tablet(sections, aspect)
    p = t.properties()
    assert p["volume_mm3"] > 0 and p["surface_area_mm2"] > 0
    assert abs(p["volume_mm3"] - t.solid_volume()) <= 1e-9 * p["volume_mm3"]
    for patch in t.patches:
        for uk, c in zip(patch.u_nodes, patch.data):
            assert np.max(np.linalg.norm(patch.evaluate(uk, V) - c.evaluate(V), axis=-1)) <= 1e-9
    # a closed tablet: bounded by a box around its curves' heights
    R = sections[0][-1][0] * aspect
    assert p["volume_mm3"] < math.pi * R * R * 2 * sections[-1][-1][1]


@settings(**SETTINGS)
@given(case=domed_sections(), theta=st.floats(0.01, TWO_PI - 0.01))
def test_rotation_about_axis_leaves_volume_and_area(case, theta, kit):
    sections, aspect = case
    t = _tablet(sections, aspect)
    rot = kit.rebuild(t, lambda c: Transformed(c, _rotz(theta), np.zeros(3)))
    p0, p1 = t.properties(), rot.properties()
    assert p1["volume_mm3"] == pytest.approx(p0["volume_mm3"], rel=1e-9)
    assert p1["surface_area_mm2"] == pytest.approx(p0["surface_area_mm2"], rel=1e-9)


@settings(**SETTINGS)
@given(case=domed_sections())
def test_mirror_z_leaves_volume_and_area(case, kit):
    sections, aspect = case
    t = _tablet(sections, aspect)
    mir = kit.rebuild(t, lambda c: Transformed(c, np.diag([1.0, 1.0, -1.0]), np.zeros(3)))
    p0, p1 = t.properties(), mir.properties()
    assert p1["orientation"] == -p0["orientation"]
    assert p1["volume_mm3"] == pytest.approx(p0["volume_mm3"], rel=1e-9)
    assert p1["surface_area_mm2"] == pytest.approx(p0["surface_area_mm2"], rel=1e-9)
    assert mir.solid_volume() == pytest.approx(p0["volume_mm3"], rel=1e-9)


@st.composite
def plan_stacks(draw):
    kind = draw(st.sampled_from(["ellipse", "stadium"]))
    L = draw(st.floats(5.0, 16.0))
    W = draw(st.floats(0.35, 0.95)) * L
    scales = [draw(st.floats(0.7, 1.0)) for _ in range(4)]
    # nearly even gaps: uneven ones make the cubic spine run backwards (a genuine fold, refused)
    base = draw(st.floats(0.5, 2.0))
    gaps = [base * draw(st.floats(0.85, 1.15)) for _ in range(3)]
    z = np.concatenate([[0.0], np.cumsum(gaps)])
    if kind == "ellipse":
        curves = tuple(Ellipse(s * L / 2, s * W / 2, (0.0, 0.0, zz)) for s, zz in zip(scales, z))
    else:
        curves = tuple(Stadium(s * L, s * W, z=zz) for s, zz in zip(scales, z))
    return kind, curves


@settings(deadline=None, derandomize=True, max_examples=6)
@given(plan_stacks())
def test_random_plan_stacks_auto_a_interpolate_within_stray(case):
    kind, curves = case
    p = PDEPatch(curves, a="auto")
    for uk, c in zip(p.u_nodes, curves):
        assert np.max(np.linalg.norm(p.evaluate(uk, V) - c.evaluate(V), axis=-1)) <= 1e-9
    assert p.stray() <= p.tol.stray
    if kind == "ellipse":
        assert p.modes == 1 and not p.has_remainder and p.a == 1.0
