"""Tablets of revolution: detection, the profile's figures against the general sampled ones,
and the kernel-neutral faces of revolution (profile fit, exact volume, mesh) against closed forms.

Numpy and scipy only (runs in the core-only pass too).
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from tabletcad.brep.revolved import RevolvedSurfaceData, fit_profile, fit_profiles, revolved_mesh, revolved_volume
from tabletcad.brep.surface import enclosed_volume
from tabletcad.families import FAMILIES
from tabletcad.geometry.curves import Circle, Ellipse, sample_v
from tabletcad.geometry.patch import PDEPatch
from tabletcad.geometry.tablet import solid_map


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


def test_shared_profile_tables_are_what_each_profile_computes_alone():
    """Profiles with the same knots share their B-spline values on a common grid (a read-only table of
    :data:`tabletcad.geometry.tables.COLLOCATION`): each gets, bit for bit, what it computes alone,
    at any shape of samples; other knots or other samples get their own."""
    from tabletcad.geometry.tables import COLLOCATION

    fits = fit_profiles([_arc(5.0, 0.0, math.pi / 2), _arc(5.0, math.pi / 2, math.pi)], 1e-6)
    a, b = fits[0].surface, fits[1].surface
    assert np.array_equal(a.knots, b.knots) and np.array_equal(a.mults, b.mults)
    COLLOCATION.clear()
    for u in (np.linspace(0.0, 1.0, 77), np.linspace(0.0, 1.0, 60).reshape(5, 12)):
        for du in (0, 1):
            for s in (a, b):
                np.testing.assert_array_equal(s.profile(u, du, shared=True), s.profile(u, du))
            assert a._basis(u, du, True) is b._basis(u, du, True)
    assert a._basis(np.linspace(0.0, 1.0, 77), 0, True) is not a._basis(np.linspace(0.0, 1.0, 78), 0, True)
    other = fit_profile(_arc(5.0, 0.0, math.pi), 1e-9).surface
    assert other.knots.size != a.knots.size
    u = np.linspace(0.0, 1.0, 77)
    np.testing.assert_array_equal(other.profile(u, 1, shared=True), other.profile(u, 1))


def test_mesh_deviation_of_a_chain_is_the_largest_of_its_bands_measured_alone(monkeypatch):
    """The deflection measured with one B-spline evaluation for all faces with the same knots (and one
    for each other knot vector) is, bit for bit, the largest of every band measured on its own."""
    import tabletcad.brep.revolved as rv

    seen, real = [], rv._mesh_deviation
    monkeypatch.setattr(rv, "_mesh_deviation", lambda *a: seen.append(a) or real(*a))
    arc = [_arc(5.0, k * math.pi / 6, (k + 1) * math.pi / 6) for k in range(5)]
    fits = fit_profiles(arc, 1e-7)
    fits.append(fit_profile(_arc(5.0, 5 * math.pi / 6, math.pi), 1e-10, start=fits[-1].surface.poles[-1]))
    surfaces = [f.surface for f in fits]
    assert len({s.knots.size for s in surfaces}) == 2  # two knot vectors: two groups
    measured = revolved_mesh(surfaces, 0.005, 0.2)[2]
    surfaces, P, bands, dth = seen[-1]
    assert measured == max(real(surfaces, P, [band], dth) for band in bands) and 0.0 < measured <= 0.005


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


# ----------------------------------------------------------------------------- one plan ellipse
class _Section:
    """``ρ (p cos v + q sin v) + (0, 0, z)``: a scaled copy of one centred plan ellipse, any orientation."""

    def __init__(self, rho, p, q, z):
        self.rho, self.p, self.q, self.z = rho, np.asarray(p, float), np.asarray(q, float), z

    def evaluate(self, v, der=0):
        v = np.asarray(v, float).reshape(-1)
        # d/dv of (cos, sin), der times: only the pair asked for (the same values as building all four)
        cv, sv = np.cos(v), np.sin(v)
        c, s = [(cv, sv), (-sv, cv), (-cv, -sv), (sv, -cv)][der % 4]
        out = np.zeros((v.size, 3))
        out[:, :2] = self.rho * (np.outer(c, self.p) + np.outer(s, self.q))
        if der == 0:
            out[:, 2] = self.z
        return out


def _plan_vectors(angle, aspect):
    """An ellipse of semi-axes ``aspect`` and 1 turned by ``angle``, started at a quarter of its own way round."""
    rot = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
    p, q = rot @ np.array([aspect, 0.0]), rot @ np.array([0.0, 1.0])
    return math.cos(0.7) * p + math.sin(0.7) * q, -math.sin(0.7) * p + math.cos(0.7) * q


@settings(max_examples=25, deadline=None)
@given(rho=st.lists(st.floats(-1.0, 5.0).filter(lambda x: abs(x) > 0.05), min_size=4, max_size=4),
       z=st.lists(st.floats(0.0, 3.0), min_size=4, max_size=4), angle=st.floats(0.0, math.pi),
       aspect=st.floats(0.3, 3.0), form=st.sampled_from(["curves", "hermite"]))
def test_scaled_copies_of_one_ellipse_are_a_section_whose_profile_is_the_surface(rho, z, angle, aspect, form):
    """Every point of the patch lies on its section's ellipse ``xᵀ S⁻¹ x = R(u)²`` at height Z(u), and
    ``det S = 1`` (so the section's area is ``π R²``): a datum of another aspect, or off centre, is no section."""
    p, q = _plan_vectors(angle, aspect)
    patch = PDEPatch(tuple(_Section(r, p, q, zz) for r, zz in zip(rho, z)), a=0.7, form=form, check=False)
    sec = patch.section
    assert sec is not None
    assert np.linalg.det(sec.shape) == pytest.approx(1.0, rel=1e-12)
    u = np.linspace(0.0, 1.0, 33)
    X = patch.evaluate_grid(u, np.linspace(0.0, math.tau, 29))
    R, Z = sec.profile(u).T
    lhs = np.einsum("uvi,ij,uvj->uv", X[..., :2], np.linalg.inv(sec.shape), X[..., :2])
    np.testing.assert_allclose(lhs, np.repeat(R[:, None] ** 2, 29, 1), atol=1e-11 * max(1.0, max(rho)) ** 2)
    np.testing.assert_allclose(X[..., 2], np.repeat(Z[:, None], 29, 1), atol=1e-12)
    np.testing.assert_allclose(sec.reach(), np.sqrt(np.diag(sec.shape)))
    other = [_Section(r, p, q, zz) for r, zz in zip(rho, z)]
    other[1] = _Section(rho[1], p, 1.1 * q, z[1])
    assert PDEPatch(tuple(other), a=0.7, form=form, check=False).section is None
    other[1] = _Section(rho[1], p, q, z[1])
    other[2] = _Section(rho[2], p, q, z[2])
    other[2].evaluate = lambda v, der=0, c=other[2]: _Section.evaluate(c, v, der) + (0.01 * (der == 0)) * np.array([1.0, 0.0, 0.0])
    assert PDEPatch(tuple(other), a=0.7, form=form, check=False).section is None


def _oval_tablet(angle, aspect, band=2.0, cup=0.8, r=3.0):
    """A convex oval of one plan ellipse turned by ``angle`` (three coaxial patches, as the thesis's ovals)."""
    from tabletcad.geometry.tablet import Tablet

    from tabletcad.families.thesis import _band, _cap

    p, q = _plan_vectors(angle, aspect)
    secs = [_cap(r, cup, cup, up=False), _band(r, cup, cup + band), _cap(r, cup + band, cup, up=True)]
    curves, patches = {}, []
    for sec in secs:
        data = tuple(curves.setdefault((rr, zz), _Section(rr, p, q, zz)) for rr, zz in sec)
        patches.append(PDEPatch(data, a=1.0))
    return Tablet(tuple(patches), name="oval")


@settings(max_examples=10, deadline=None)
@given(angle=st.floats(0.0, math.pi), aspect=st.floats(1.05, 3.0))
def test_section_figures_equal_the_sampled_ones(angle, aspect):
    """A tablet of one plan ellipse, turned by any angle: extents from the profile (``R_max √S_xx``)
    equal the polished samples of every patch to 1e-12 mm; the plan area ``π R_max²`` is what the
    sampled plan comes within 2e-8 of at 2048 meridians; the solid map's
    volume on 4 meridians equals that on 256 (its Jacobian does not depend on v); each patch's fold
    depth on its 4 principal meridians is that on 37 more."""
    t = _oval_tablet(angle, aspect)
    assert t.section is not None and t.revolution is None
    lo, hi = t.bounds()
    lo2, hi2 = t._bounds_sampled()
    np.testing.assert_allclose(lo, lo2, atol=1e-12 * 10)
    np.testing.assert_allclose(hi, hi2, atol=1e-12 * 10)
    exact = t.plan_area()
    assert abs(t._plan_area_sampled(33, 2048) - exact) <= 2e-8 * exact
    assert t.solid_volume() == pytest.approx(t.solid_volume(nv=256), rel=1e-13)
    assert t.solid_volume() == pytest.approx(t.volume(), rel=1e-12)
    for patch in t.patches:  # with the principal meridians, which set the round-off threshold's scale
        v = np.concatenate([patch._principal_v(), np.linspace(0.0, math.tau, 37)])
        assert patch.fold_depth() == pytest.approx(patch._fold_depth_of(257, 0, v)[0], abs=1e-15)


def test_the_thesis_ovals_plan_is_their_widest_ellipse():
    """The caplet and the ovals (Table 4.1, 4.5): bounds from the profile equal the polished samples;
    the plan area is π a b of the widest section (a = R_max √S_xx, b = R_max √S_yy); the sampled plan
    with twice the meridians is four times nearer or better."""
    for name, kw in (("caplet", {}), ("shallow_convex_oval", {}), ("deep_convex_oval", {})):
        t = FAMILIES[f"thesis.{name}"].build(**kw)
        assert t.section is not None
        lo, hi = t.bounds()
        lo2, hi2 = t._bounds_sampled()
        np.testing.assert_allclose(np.concatenate([lo, hi]), np.concatenate([lo2, hi2]), atol=1e-12)
        a, b = hi[0], hi[1]
        assert t.plan_area() == pytest.approx(math.pi * a * b, rel=1e-14)
        e1, e2 = (abs(t._plan_area_sampled(33, nv) / t.plan_area() - 1.0) for nv in (1024, 2048))
        assert e2 <= 1e-8 and e2 <= e1 / 3


@settings(max_examples=40, deadline=None)
@given(rho=st.lists(st.floats(-5.0, 5.0).filter(lambda x: abs(x) > 0.05), min_size=4, max_size=4),
       z=st.lists(st.floats(0.0, 3.0), min_size=4, max_size=4), angle=st.floats(0.0, math.pi),
       aspect=st.floats(0.3, 3.0), a=st.floats(0.2, 2.0), form=st.sampled_from(["curves", "hermite"]))
@example(rho=[1.0] * 4, z=[0.0] * 4, angle=0.0, aspect=2.0, a=1.0, form="curves")  # level: folds in its plane
# a fold on a principal meridian alone (v = -0.871, near u = 0.26): none of the 32 sampled meridians shows it
@example(rho=[0.8984375, 3.6875, 0.8984375, 0.8984375], z=[0.8984375, 0.0, 0.8984375, 0.5], angle=0.0,
         aspect=2.21875, a=0.3125, form="curves")
def test_fold_checks_of_a_section_decide_as_the_sampled_ones(rho, z, angle, aspect, a, form):
    """The radius and fold-back checks from the profile refuse exactly the patches the sampled grid
    refuses on the same meridians (the given ones and the ellipse's four principal ones, which the
    profile's checks add), with the same reason, and never a smaller negative radius; so they refuse
    every patch the given meridians alone refuse."""
    from tabletcad.errors import DesignError

    p, q = _plan_vectors(angle, aspect)
    patch = PDEPatch(tuple(_Section(r, pp, p, zz) for r, zz, pp in zip(rho, z, [q] * 4)), a=a, form=form, check=False)
    assert patch.section is not None
    saved = patch.section
    u, v = np.linspace(0.0, 1.0, 201), np.linspace(0.0, math.tau, 32, endpoint=False)

    def outcome(section, meridians):
        object.__setattr__(patch, "_section", section)
        try:
            (patch._check_fold_section if section is not None else patch._check_fold_sampled)(u, meridians)
            return ("ok", 0.0)
        except DesignError as exc:
            what = str(exc).split("'")[1]
            return (what.split()[0], float(what.split()[1]) if what.startswith("radius") else 0.0)
        finally:
            object.__setattr__(patch, "_section", saved)

    profile = outcome(saved, v)
    same = outcome(None, np.concatenate([v, patch._principal_v()]))
    given = outcome(None, v)
    assert profile[0] == same[0]
    assert profile[1] <= same[1] + 1e-12
    assert given[0] == "ok" or profile[0] != "ok"
    assert profile[1] <= given[1] + 1e-12
    # the figures the checks read, against the patch's own surface: the radius about the spine and
    # X_u × X_v (in-plane length and z part)
    u, v = np.linspace(0.0, 1.0, 23), np.linspace(0.0, math.tau, 19)
    radial, a_, b_ = patch._section_normals(u, v)
    X = patch.evaluate_grid(u, v)
    n = np.cross(patch.evaluate_grid(u, v, du=1), patch.evaluate_grid(u, v, dv=1))
    scale = max(1.0, float(np.max(np.abs(n))))
    np.testing.assert_allclose(np.abs(radial), np.hypot(*(X - patch.spine(u)[:, None, :])[..., :2].transpose(2, 0, 1)),
                               atol=1e-10 * max(1.0, max(map(abs, rho))))
    np.testing.assert_allclose(np.abs(a_), np.hypot(n[..., 0], n[..., 1]), atol=1e-10 * scale)
    np.testing.assert_allclose(b_, n[..., 2], atol=1e-10 * scale)
    # the depth, measured on the four principal meridians only, is the deepest meridian's: the same with 64
    # others beside them.  (Raised above the ground, every meridian folds alike; a level patch's in-plane
    # speed |R'| |det M| / |M e'(v)| differs between meridians and is largest on a principal one, so 64
    # meridians alone measure less: 0.0025828 against 0.0025834 mm for rho 1, z 0, aspect 2, a 1.)
    v = np.concatenate([sample_v(64), patch._principal_v()])
    assert patch.fold_depth() == pytest.approx(patch._fold_depth_of(257, None, v)[0], abs=1e-9 * max(1.0, max(map(abs, rho))))


@functools.lru_cache(maxsize=None)
def _caplet_and_round():
    """The two whole tablets the trim test cuts (each example trims them afresh; built once)."""
    return (FAMILIES["thesis.caplet"].build(),
            FAMILIES["concave_round"].build(diameter=10.0, band=3.0, cup_depth=1.0, land=0.08))


@settings(max_examples=8, deadline=None)
@given(v0=st.floats(-3.0, 3.0), dv=st.floats(0.2, 6.2), u0=st.sampled_from([0.0, 0.1]), w=st.sampled_from([(0.0, 1.0), (0.0, 0.7), (0.4, 1.0)]))
def test_trimmed_section_bounds_equal_the_sampled_ones_and_a_cut_away_plan_is_a_sector(v0, dv, u0, w):
    """Any trim of the caplet and of a concave round (cut-aways, shells, cut ends): extents from the
    profiles and the plan vectors' closed-form spans hold every point of the solid map on a dense grid
    and come within 1e-3 mm of the outermost, and equal the polished samples of every patch plus
    the cut faces' inner edges to 1e-12 mm.  The plan of a solid cut-away (w from 0) is the sector
    of its widest section: ``(v1 - v0) / 2π`` of the whole plan, ``½ (D/2)² (v1 - v0)`` for the round
    (with or without a shell: both reach the axis).
    The solid map's volume (and the round's area and volume) on four points in v equal 256."""
    d = 10.0
    caplet, rnd = _caplet_and_round()
    for t in (caplet, rnd):
        cut = t.trimmed(u=(u0, 1.0 - u0), v=(v0, v0 + dv), w=w)
        assert cut.section is not None
        lo, hi = cut.bounds()
        # every point of the solid map on a dense (u, v, w) grid lies inside, the nearest within 1e-3 mm
        uu, vv, ww = np.linspace(*cut.trim.u, 81), np.linspace(*cut.trim.v, 241), np.linspace(*cut.trim.w, 2)
        pts = np.concatenate([solid_map(p, uu[:, None, None], vv[None, :, None], ww[None, None, :]).reshape(-1, 3)
                              for p in cut.patches])
        assert np.all(pts.min(axis=0) >= lo - 1e-12) and np.all(pts.max(axis=0) <= hi + 1e-12)
        assert np.all(pts.min(axis=0) - lo <= 1e-3) and np.all(hi - pts.max(axis=0) <= 1e-3)
        # the polished samples of every patch plus the cut faces' inner edges (the spine from w = 0)
        lo2, hi2 = cut._bounds_sampled()
        np.testing.assert_allclose(np.concatenate([lo, hi]), np.concatenate([lo2, hi2]), atol=1e-12)
        # the solid map's Jacobian does not depend on v (nor, on the round, the faces' integrands): a few
        # points in v are exact on any v range
        assert cut.solid_volume() == pytest.approx(cut.solid_volume(nv=256), rel=1e-13)
        if t is rnd:
            a, b = cut.properties(), cut.properties(nv=256)
            assert a["volume_mm3"] == pytest.approx(b["volume_mm3"], rel=1e-13)
            assert a["surface_area_mm2"] == pytest.approx(b["surface_area_mm2"], rel=1e-13)
        if u0 == 0.0:  # both reach the axis (R = 0 at the poles): a shell's plan has no hole
            whole = t.trimmed(w=(0.0, w[1])).plan_area()
            assert cut.plan_area() == pytest.approx(whole * dv / math.tau, rel=1e-13)
            if t is rnd:
                assert cut.plan_area() == pytest.approx(0.5 * (w[1] * d / 2) ** 2 * dv, rel=1e-13)


def test_the_ring_s_plan_is_its_annulus():
    """The ring (w from 0.5): the plan from its profiles, π ((w1 R_max)² - (w0 R_min)²), equals the
    sampled plan (outer envelope minus the see-through hole) to 1e-12, and a quarter cut of it a quarter."""
    from tabletcad.families.thesis import ring

    t = ring()
    assert t.trim.w[0] > 0.0 and t.section is not None
    assert t.plan_area() == pytest.approx(t._plan_area_sampled(), rel=1e-12)
    assert t.trimmed(v=(0.0, 0.5 * math.pi), w=t.trim.w).plan_area() == pytest.approx(0.25 * t.plan_area(), rel=1e-13)
