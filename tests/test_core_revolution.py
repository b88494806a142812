"""Tablets of revolution: detection, the profile's figures against the general sampled ones,
and the kernel-neutral faces of revolution (profile fit, exact volume, mesh) against closed forms.

Numpy and scipy only (runs in the core-only pass too).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tabletcad.brep.revolved import RevolvedSurfaceData, fit_profile, fit_profiles, revolved_mesh, revolved_volume
from tabletcad.brep.surface import enclosed_volume
from tabletcad.families import FAMILIES
from tabletcad.geometry.curves import Circle, Ellipse
from tabletcad.geometry.patch import PDEPatch


def _stack(radii, heights, ellipse_b=None):
    curves = [Circle(radius=r, center=(0.0, 0.0, z)) for r, z in zip(radii, heights)]
    if ellipse_b is not None:  # one curve an ellipse: no longer a surface of revolution
        curves[2] = Ellipse(rx=radii[2], ry=ellipse_b, center=(0.0, 0.0, heights[2]))
    return PDEPatch(tuple(curves), a=0.5, check=False)  # detection only: any stack, folded or not


@settings(max_examples=25, deadline=None)
@given(r=st.lists(st.floats(0.5, 6.0), min_size=4, max_size=4), dz=st.lists(st.floats(0.2, 2.0), min_size=3, max_size=3))
def test_a_stack_of_circles_is_a_surface_of_revolution_whose_profile_is_the_surface(r, dz):
    z = np.concatenate([[0.0], np.cumsum(dz)])
    p = _stack(r, z)
    rev = p.revolution
    assert rev is not None
    u = np.linspace(0.0, 1.0, 41)
    v = np.linspace(0.0, 2 * math.pi, 37)
    X = p.evaluate_grid(u, v)
    R, Z = rev.profile(u).T
    ang = rev.phase + rev.sense * v
    S = np.stack([np.outer(R, np.cos(ang)), np.outer(R, np.sin(ang)), np.repeat(Z[:, None], v.size, 1)], -1)
    assert np.max(np.abs(S - X)) <= 1e-12 * max(r)
    # derivatives too (the profile's du = 1, 2 against the patch's)
    for du in (1, 2):
        Ru, Zu = rev.profile(u, du).T
        Xu = p.evaluate(u, np.full(u.shape, rev.v_of_angle(0.0)), du=du)
        np.testing.assert_allclose(np.column_stack([Ru, Zu]), Xu[:, [0, 2]], atol=1e-10 * max(r))


def test_an_ellipse_or_an_offset_centre_breaks_the_symmetry():
    z = [0.0, 1.0, 2.0, 3.0]
    assert _stack([4, 5, 5, 4], z).revolution is not None
    assert _stack([4, 5, 5, 4], z, ellipse_b=4.9).revolution is None
    off = tuple(Circle(radius=r, center=(0.1 if k == 1 else 0.0, 0.0, zz)) for k, (r, zz) in enumerate(zip([4, 5, 5, 4], z)))
    assert PDEPatch(off, a=0.5, check=False).revolution is None


@settings(max_examples=12, deadline=None)
@given(d=st.floats(6.0, 14.0), band=st.floats(1.5, 4.0), cup=st.floats(0.3, 1.5))
def test_profile_figures_equal_the_sampled_ones(d, band, cup):
    """Plan area, bounds, volume and area of a concave round from its profile agree with the
    general computations (dense samples of every patch, 256 meridians)."""
    t = FAMILIES["concave_round"].build(diameter=d, band=band, cup_depth=min(cup, 0.2 * d), land=0.08)
    assert t.revolution is not None
    assert t.plan_area() == pytest.approx(t._plan_area_sampled(), rel=1e-12)
    assert t.plan_area() == pytest.approx(math.pi * d * d / 4, rel=1e-12)
    lo, hi = t.bounds()
    lo2, hi2 = t._bounds_sampled()
    np.testing.assert_allclose(lo, lo2, atol=1e-9)
    np.testing.assert_allclose(hi, hi2, atol=1e-9)
    a, b = t.properties(), t.properties(nv=256)
    assert a["volume_mm3"] == pytest.approx(b["volume_mm3"], rel=1e-13)
    assert a["surface_area_mm2"] == pytest.approx(b["surface_area_mm2"], rel=1e-13)
    assert t.solid_volume() == pytest.approx(t.solid_volume(nv=256), rel=1e-13)


def _arc(r, t0, t1):
    return lambda u: np.column_stack([r * np.sin(t0 + (t1 - t0) * u), -r * np.cos(t0 + (t1 - t0) * u)])


@pytest.mark.parametrize("tol", [1e-4, 1e-6])
def test_a_fitted_sphere_has_the_sphere_volume_within_the_fit_bound(tol):
    r = 5.0
    f = _arc(r, 0.0, math.pi)  # from the south pole to the north pole
    fit = fit_profile(f, tol)
    assert fit.ok and fit.max_deviation <= tol
    assert fit.surface.poles[0, 0] == 0.0 and fit.surface.poles[-1, 0] == pytest.approx(0.0, abs=1e-12)
    u = np.linspace(0, 1, 2001)
    assert np.max(np.abs(np.hypot(*fit.surface.profile(u).T) - r)) <= tol
    exact = 4.0 / 3.0 * math.pi * r**3
    assert abs(abs(revolved_volume([fit.surface])) - exact) <= tol * 4 * math.pi * r * r
    assert enclosed_volume([fit.surface]) == revolved_volume([fit.surface])


def test_revolved_volume_of_a_polyline_profile_is_exact():
    """Degree-1 profiles: a cylinder (r = 3, h = 2) and a cone frustum, closed forms."""
    def line(p0, p1):
        return RevolvedSurfaceData(np.array([p0, p1], float), [0.0, 1.0], [2, 2], 1)

    cyl = [line((0, 0), (3, 0)), line((3, 0), (3, 2)), line((3, 2), (0, 2))]
    assert abs(revolved_volume(cyl)) == pytest.approx(math.pi * 9 * 2, rel=1e-14)
    R1, R2, h = 3.0, 1.0, 2.5
    frustum = [line((0, 0), (R1, 0)), line((R1, 0), (R2, h)), line((R2, h), (0, h))]
    assert abs(revolved_volume(frustum)) == pytest.approx(math.pi * h / 3 * (R1 * R1 + R1 * R2 + R2 * R2), rel=1e-14)


def _edges_twice(T):
    e = np.sort(np.concatenate([T[:, [0, 1]], T[:, [1, 2]], T[:, [2, 0]]]), axis=1)
    _, counts = np.unique(e, axis=0, return_counts=True)
    return bool(np.all(counts == 2)), len(counts)


@pytest.mark.parametrize("deflection", [0.02, 0.005])
def test_mesh_of_a_sphere_is_closed_and_within_the_deflection(deflection):
    r = 5.0
    fits = fit_profiles([_arc(r, 0.0, math.pi / 2), _arc(r, math.pi / 2, math.pi)], 1e-7)
    V, T, measured = revolved_mesh([f.surface for f in fits], deflection, 0.2)
    closed, n_edges = _edges_twice(T)
    assert closed and len(V) - n_edges + len(T) == 2  # a sphere: Euler characteristic 2
    assert measured <= deflection
    # independent: every triangle's points against the true sphere (closed form)
    a, b, c = V[T[:, 0]], V[T[:, 1]], V[T[:, 2]]
    q = np.concatenate([(a + b + c) / 3, (a + b) / 2, (b + c) / 2, (c + a) / 2])
    assert np.max(r - np.linalg.norm(q, axis=1)) <= deflection + 1e-7
    assert np.max(np.abs(np.linalg.norm(V, axis=1) - r)) <= 1e-7  # vertices on the surface
    vol = np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0
    exact = 4 / 3 * math.pi * r**3
    assert 0.0 < exact - vol <= deflection * 4 * math.pi * r * r  # inscribed, outward wound


def test_mesh_of_a_hollow_cylinder_is_a_closed_torus():
    """A ring (no poles): outer wall, top, inner wall, bottom; genus 1 (Euler characteristic 0)."""
    def line(p0, p1):
        p0, p1 = np.asarray(p0, float), np.asarray(p1, float)
        return lambda u: p0 + np.outer(u, p1 - p0)

    chain = [line((6, 0), (6, 4)), line((6, 4), (3, 4)), line((3, 4), (3, 0)), line((3, 0), (6, 0))]
    fits = fit_profiles(chain, 1e-9, degree=3)
    V, T, measured = revolved_mesh([f.surface for f in fits], 0.005, 0.2)
    closed, n_edges = _edges_twice(T)
    assert closed and len(V) - n_edges + len(T) == 0
    a, b, c = V[T[:, 0]], V[T[:, 1]], V[T[:, 2]]
    vol = np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0
    exact = math.pi * (36 - 9) * 4
    assert 0.0 < exact - vol <= 0.005 * (2 * math.pi * 9 * 4 + 2 * math.pi * (36 - 9))
