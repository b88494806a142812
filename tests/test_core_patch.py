"""PDE surface patches (tabletcad.geometry.patch.PDEPatch).

Checks the defining properties: the surface passes through its boundary data
(curves form and Hermite form, band-limited or not), it solves the
Bloor-Wilson equation mode by mode, closed-form areas, the spine, the thesis
form of the coefficients, the radius profile, the stray and fold checks, and
that the three evaluation paths agree.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from tabletcad.geometry.curves import Circle, Ellipse, PointCurve, RoundedRectangle, Stadium, Transformed
from tabletcad.errors import DesignError
from tabletcad.geometry.patch import AUTO_A_LADDER, PDEPatch
from tabletcad.tolerance import DEFAULT

TWO_PI = 2 * math.pi
V = np.linspace(0.0, TWO_PI, 720, endpoint=False) + 0.0037  # not the FFT nodes


def _coaxial(radii, heights, curve=Circle):
    return tuple(curve(r, (0.0, 0.0, z)) for r, z in zip(radii, heights))


def _polygon(scale: float, z: float) -> PointCurve:
    pts = np.array([(4, 0), (3, 2.5), (0, 3.5), (-3, 2.5), (-4, 0), (-3, -2.5), (0, -3.5), (3, -2.5)], float)
    return PointCurve(pts * scale, z=z)


def _interp_error(p: PDEPatch) -> float:
    err = 0.0
    for uk, c in zip(p.u_nodes, p.data):
        err = max(err, float(np.max(np.linalg.norm(p.evaluate(uk, V) - c.evaluate(V), axis=-1))))
    return err


def _trig_stack(kit, rng, n_modes=3, heights=(0.0, 1.0, 2.2, 3.0)):
    """Four random band-limited curves (mode-1 circle of radius ~4 plus small in-plane wobbles, slight
    tilt), centres offset sideways, at increasing heights."""
    out = []
    for z in heights:
        a = rng.normal(0.0, 0.15, (n_modes, 3)) * (1.0, 1.0, 0.1)
        b = rng.normal(0.0, 0.15, (n_modes, 3)) * (1.0, 1.0, 0.1)
        a[0] += (4.0, 0.0, 0.0)
        b[0] += (0.0, 4.0, 0.0)
        out.append(kit.TrigCurve(rng.normal(0.0, 0.3, 3) * (1.0, 1.0, 0.0) + (0.0, 0.0, z), a, b))
    return tuple(out)


# ----------------------------------------------------------------------------- interpolation
NODES = [(0.0, 1 / 3, 2 / 3, 1.0), (0.0, 0.2, 0.7, 1.0), (0.0, 0.05, 0.5, 1.0)]


@pytest.mark.parametrize("nodes", NODES)
def test_band_limited_curves_interpolated(nodes, kit):
    rng = np.random.default_rng(1)
    # (uneven nodes make the spine overshoot in z: interpolation is checked, not validity)
    p = PDEPatch(_trig_stack(kit, rng), a=1.0, u_nodes=nodes, check=False)
    assert p.modes == 3 and not p.has_remainder
    assert _interp_error(p) <= 1e-9


@pytest.mark.parametrize("nodes", NODES[:2])
@pytest.mark.parametrize(
    "make",
    [
        pytest.param(lambda s, z: Stadium(12.0 * s, 6.0 * s, z=z), id="stadium"),
        pytest.param(lambda s, z: RoundedRectangle(10.0 * s, 6.0 * s, 1.5 * s, z=z), id="rounded_rectangle"),
        pytest.param(_polygon, id="polygon_pointcurve"),
    ],
)
def test_non_band_limited_curves_interpolated_via_remainder(make, nodes):
    curves = (make(0.6, 0.0), make(1.0, 1.0), make(1.0, 2.0), make(0.7, 3.0))
    p = PDEPatch(curves, a=0.1, u_nodes=nodes, check=False)
    assert p.has_remainder
    assert p.beta_value == pytest.approx(0.1 * (p.modes + 1))
    assert _interp_error(p) <= 1e-9
    # without R the truncated series alone misses the curves by far more
    miss = max(
        float(np.max(np.linalg.norm(p.evaluate(uk, V, remainder=False) - c.evaluate(V), axis=-1)))
        for uk, c in zip(p.u_nodes, curves)
    )
    assert miss > 1e-6


def test_non_coaxial_tilted_curves_interpolated():
    rot = np.array([[1, 0, 0], [0, math.cos(0.3), -math.sin(0.3)], [0, math.sin(0.3), math.cos(0.3)]])
    curves = (
        Circle(0.0, (0.0, 0.0, 0.0)),
        Transformed(Stadium(8.0, 4.0), rot, np.array([0.5, 0.0, 1.0])),
        Transformed(Ellipse(5.0, 3.0), rot.T, np.array([0.0, 0.4, 2.0])),
        Stadium(9.0, 5.0, z=3.0),
    )
    p = PDEPatch(curves, a=0.1, check=False, u_nodes=(0.0, 0.3, 0.65, 1.0))
    assert _interp_error(p) <= 1e-9


@pytest.mark.parametrize("beta", [None, 0.3, 5.0])
def test_remainder_decay_choice_keeps_interpolation(beta):
    curves = tuple(Stadium(12.0, 6.0, z=z) for z in (0.0, 1.0, 2.0, 3.0))
    p = PDEPatch(curves, a=0.1, beta=beta, check=False)
    assert _interp_error(p) <= 1e-9
    if beta is not None:
        assert p.beta_value == beta


def test_hermite_form_band_limited(kit):
    c0 = Circle(4.0, (0.0, 0.0, 0.0))
    c1 = Ellipse(3.0, 2.0, (0.5, 0.0, 3.0))
    d0 = kit.TrigCurve((0.0, 0.0, 6.0), [(1.0, 0.0, 0.0), (0.2, 0.0, 0.0)], [(0.0, 1.0, 0.0), (0.0, 0.1, 0.0)])
    d1 = Circle(2.0, (0.0, 0.0, 4.0))
    p = PDEPatch((c0, c1, d0, d1), form="hermite", a=1.0, check=False)
    assert p.modes == 2 and not p.has_remainder
    for u, c, du in ((0.0, c0, 0), (1.0, c1, 0), (0.0, d0, 1), (1.0, d1, 1)):
        np.testing.assert_allclose(p.evaluate(u, V, du=du), c.evaluate(V), atol=1e-9)


def test_hermite_design_modes_of_derivative_curves_are_not_stray(kit):
    c0 = Circle(4.0, (0.0, 0.0, 0.0))
    c1 = Ellipse(3.0, 2.0, (0.5, 0.0, 3.0))
    d0 = kit.TrigCurve((0.0, 0.0, 6.0), [(1.0, 0.0, 0.0), (0.2, 0.0, 0.0)], [(0.0, 1.0, 0.0), (0.0, 0.1, 0.0)])
    d1 = Circle(2.0, (0.0, 0.0, 4.0))
    PDEPatch((c0, c1, d0, d1), form="hermite", a=1.0)


def test_hermite_form_non_band_limited_derivative_curves():
    c0 = Stadium(10.0, 5.0, z=0.0)
    c1 = Stadium(12.0, 6.0, z=3.0)
    d0 = Transformed(Stadium(6.0, 3.0), np.eye(3), np.array([0.0, 0.0, 4.0]))  # X_u: outward + up
    d1 = Transformed(RoundedRectangle(6.0, 3.0, 1.0), -np.eye(3), np.array([0.0, 0.0, 4.0]))
    for a in (1.0, 0.1):
        p = PDEPatch((c0, c1, d0, d1), form="hermite", a=a, check=False)
        assert p.has_remainder
        for u, c, du in ((0.0, c0, 0), (1.0, c1, 0), (0.0, d0, 1), (1.0, d1, 1)):
            got = p.evaluate(u, V, du=du)
            assert np.max(np.linalg.norm(got - c.evaluate(V), axis=-1)) <= 1e-9, (a, u, du)


def test_bad_construction_arguments():
    c = _coaxial((0, 1, 2, 3), (0, 1, 2, 3))
    with pytest.raises(DesignError, match="u_nodes"):
        PDEPatch(c, u_nodes=(0.0, 0.7, 0.3, 1.0))
    with pytest.raises(DesignError, match="a"):
        PDEPatch(c, a=-1.0)
    with pytest.raises(DesignError, match="a"):
        PDEPatch(c, a="fast")
    with pytest.raises(DesignError, match="curves"):
        PDEPatch(c[:3])
    with pytest.raises(DesignError, match="form"):
        PDEPatch(c, form="bezier")
    with pytest.raises(DesignError, match="modes"):
        PDEPatch(c, modes=-2)


# ----------------------------------------------------------------------------- the PDE itself
@pytest.mark.parametrize("a", [0.5, 1.0, 2.0])
def test_surface_solves_bloor_wilson_equation(a, kit):
    """(∂²_u + a²∂²_v)² X = X_uuuu + 2a² X_uuvv + a⁴ X_vvvv = 0 (X_uuuu by differences of X_uu)."""
    rng = np.random.default_rng(3)
    p = PDEPatch(_trig_stack(kit, rng), a=a, check=False)
    u = np.linspace(0.1, 0.9, 9)[:, None]
    v = np.linspace(0.0, TWO_PI, 24, endpoint=False)[None, :]
    h = 1e-3
    Xuu = lambda uu: p.evaluate(uu, v, du=2)  # noqa: E731
    X4u = (Xuu(u + h) - 2 * Xuu(u) + Xuu(u - h)) / h**2
    X2u2v = p.evaluate(u, v, du=2, dv=2)
    X4v = p.evaluate(u, v, dv=4)
    res = X4u + 2 * a**2 * X2u2v + a**4 * X4v
    scale = np.max(np.abs(X4u)) + 2 * a**2 * np.max(np.abs(X2u2v)) + a**4 * np.max(np.abs(X4v))
    assert np.max(np.abs(res)) < 1e-5 * scale


def test_remainder_decays_like_first_omitted_mode():
    """R = Σ L_k(u; β) r_k(v) is itself a solution profile of the mode ODE with λ = β."""
    curves = tuple(Stadium(12.0, 6.0, z=z) for z in (0.0, 1.0, 2.0, 3.0))
    p = PDEPatch(curves, a=0.1, check=False)
    u = np.linspace(0.0, 1.0, 7)
    R = p.evaluate(u[:, None], V[None, :]) - p.evaluate(u[:, None], V[None, :], remainder=False)
    from tabletcad.geometry.basis import cardinal

    L = cardinal(u, p.beta_value, p.u_nodes)
    expect = sum(
        L[:, k, None, None] * (c.evaluate(V) - p.evaluate(uk, V, remainder=False))[None]
        for k, (uk, c) in enumerate(zip(p.u_nodes, curves))
    )
    np.testing.assert_allclose(R, expect, atol=1e-12)


# ----------------------------------------------------------------------------- closed forms
@pytest.mark.parametrize(
    "radii, nodes",
    [((0.0, 1.0, 2.0, 3.0), NODES[0]), ((0.0, 1.0, 2.5, 4.0), NODES[0]), ((0.0, 0.5, 3.0, 4.0), NODES[1])],
)
def test_flat_disc_patch_area(radii, nodes, kit):
    """Point → circle of radius r in the plane z = 0: the surface is the disc, area πr² exactly."""
    p = PDEPatch(_coaxial(radii, (0.0,) * 4), a=1.0, u_nodes=nodes)
    r = radii[-1]
    prof = p.radius_profile(np.linspace(0.0, 1.0, 1001))
    assert np.all(np.diff(prof) > 0)  # the case is a simple (non-overlapping) disc
    assert kit.gauss_area(p) == pytest.approx(math.pi * r * r, rel=1e-9)
    # flat: every point in the plane
    assert np.max(np.abs(p.evaluate_grid(np.linspace(0, 1, 11), V)[..., 2])) == 0.0


def test_fold_check_refuses_flat_disc_folding_back(kit):
    curves = _coaxial((0.0, 2.0, 4.5, 5.0), (0.0,) * 4)
    p = PDEPatch(curves, a=1.0, check=False)
    assert p.radius_profile(np.linspace(0, 1, 1001)).max() > 5.2  # genuine overshoot
    assert kit.gauss_area(p) > 1.15 * math.pi * 25.0  # genuine overlap
    with pytest.raises(DesignError):
        PDEPatch(curves, a=1.0)


def test_flat_elliptic_disc_area(kit):
    curves = tuple(Ellipse(s * 6.0, s * 3.0, (1.0, 2.0, 0.5)) for s in (0.0, 0.4, 0.8, 1.0))
    p = PDEPatch(curves, a=1.0)
    assert kit.gauss_area(p) == pytest.approx(math.pi * 18.0, rel=1e-9)


def test_hemisphere_like_dome_area_vs_surface_of_revolution(kit):
    """Coaxial circles: the area equals 2π∫ r sqrt(r'² + z'²) du from radius_profile and the spine."""
    p = PDEPatch(_coaxial((0.0, 2.5, 4.3, 5.0), (5.0, 4.3, 2.5, 0.0)), a=1.0)
    x, w = np.polynomial.legendre.leggauss(64)
    u = 0.5 * (x + 1)
    r = p.radius_profile(u)
    h = 1e-6
    dr = (p.radius_profile(u + h) - p.radius_profile(u - h)) / (2 * h)
    dz = p.spine(u, du=1)[:, 2]
    area = 2 * math.pi * float(np.sum(0.5 * w * r * np.sqrt(dr**2 + dz**2)))
    assert kit.gauss_area(p, nu=64) == pytest.approx(area, rel=1e-8)


# ----------------------------------------------------------------------------- spine, coefficients
def test_spine_equals_centroids_at_nodes():
    centres = [(0.0, 0.0, 0.0), (1.0, -0.5, 1.2), (0.3, 0.7, 2.0), (-1.0, 0.2, 3.5)]
    curves = (
        Circle(0.0, centres[0]),
        Stadium(12.0, 6.0).moved(centres[1]),
        RoundedRectangle(10.0, 6.0, 1.5).moved(centres[2]),
        Ellipse(4.0, 3.0, centres[3]),
    )
    p = PDEPatch(curves, a=0.1, check=False, u_nodes=(0.0, 0.25, 0.6, 1.0))
    np.testing.assert_allclose(p.spine(np.array(p.u_nodes)), centres, atol=1e-12)
    # the spine is the cubic (λ = 0) interpolant of the centroids
    u = np.linspace(0, 1, 11)
    nodes = np.array(p.u_nodes)
    lag = np.ones((u.size, 4))
    for k in range(4):
        for j in range(4):
            if j != k:
                lag[:, k] *= (u - nodes[j]) / (nodes[k] - nodes[j])
    np.testing.assert_allclose(p.spine(u), lag @ np.array(centres), atol=1e-12)
    np.testing.assert_allclose(p.evaluate(u[:, None], V[None]).mean(axis=1), p.spine(u), atol=1e-9)


@pytest.mark.parametrize("a", [0.1, 0.3, 1.0])
def test_mode_coefficients_rebuild_surface(a, kit):
    """A_n(u) = (a_n1 + a_n3 u)e^{λu} + (a_n2 + a_n4 u)e^{-λu}, λ = a n; A_0 = Σ a_0m u^{m-1}."""
    rng = np.random.default_rng(11)
    p = PDEPatch(_trig_stack(kit, rng, n_modes=4), a=a, check=False)
    u = np.linspace(0.0, 1.0, 23)
    v = np.linspace(0.0, TWO_PI, 40, endpoint=False)
    a0, none = p.mode_coefficients(0)
    assert none is None
    X = (np.vander(u, 4, increasing=True) @ a0)[:, None, :] + np.zeros((1, v.size, 3))
    for n in range(1, p.modes + 1):
        lam = a * n
        an, bn = p.mode_coefficients(n)
        ep, em = np.exp(lam * u)[:, None], np.exp(-lam * u)[:, None]
        uu = u[:, None]
        A = (an[0] + an[2] * uu) * ep + (an[1] + an[3] * uu) * em
        B = (bn[0] + bn[2] * uu) * ep + (bn[1] + bn[3] * uu) * em
        X = X + A[:, None, :] * np.cos(n * v)[None, :, None] + B[:, None, :] * np.sin(n * v)[None, :, None]
    np.testing.assert_allclose(X, p.evaluate_grid(u, v), atol=1e-9)
    with pytest.raises(DesignError):
        p.mode_coefficients(p.modes + 1)


def test_radius_profile_of_coaxial_circles():
    radii, heights = (1.0, 3.0, 3.5, 2.0), (0.0, 1.0, 2.0, 3.0)
    p = PDEPatch(_coaxial(radii, heights), a=1.0)
    np.testing.assert_allclose(p.radius_profile(np.array(p.u_nodes)), radii, atol=1e-12)
    u = np.linspace(0.0, 1.0, 41)
    X = p.evaluate(u[:, None], V[None])
    dist = np.linalg.norm(X - p.spine(u)[:, None, :], axis=-1)
    np.testing.assert_allclose(dist, np.broadcast_to(p.radius_profile(u)[:, None], dist.shape), atol=1e-12)
    # horizontal circles: every section is at the spine's height
    np.testing.assert_allclose(X[..., 2], np.broadcast_to(p.spine(u)[:, None, 2], X.shape[:2]), atol=1e-12)


# ----------------------------------------------------------------------------- stray check
STADIUM_STACK = tuple(Stadium(12.0, 6.0, z=z) for z in (0.0, 1.0, 2.0, 3.0))


def test_stray_check_refuses_stadium_with_a_1():
    with pytest.raises(DesignError) as exc:
        PDEPatch(STADIUM_STACK, a=1.0, name="band")
    e = exc.value
    assert e.parameter == "patch.band.smoothing.parameter.a"
    assert e.value == 1.0
    assert "a = 1 is not allowed" in str(e)
    unchecked = PDEPatch(STADIUM_STACK, a=1.0, check=False)
    assert unchecked.modes == unchecked.tol.max_modes
    assert unchecked.stray() > unchecked.tol.stray


def test_stray_check_accepts_stadium_with_a_0_1():
    p = PDEPatch(STADIUM_STACK, a=0.1)
    assert 0.0 < p.stray() <= p.tol.stray
    assert _interp_error(p) <= 1e-9


def test_auto_a_picks_first_passing_ladder_value():
    p = PDEPatch(STADIUM_STACK, a="auto")
    assert p.a in AUTO_A_LADDER
    assert p.stray() <= p.tol.stray
    assert _interp_error(p) <= 1e-9
    for a in AUTO_A_LADDER[: AUTO_A_LADDER.index(p.a)]:
        with pytest.raises(DesignError):
            PDEPatch(STADIUM_STACK, a=a)
    # smooth data: auto keeps the first value
    assert PDEPatch(_coaxial((0, 2, 3, 3.2), (0, 1, 2, 3)), a="auto").a == AUTO_A_LADDER[0]


def test_band_limited_patch_has_no_stray():
    p = PDEPatch(_coaxial((0, 2, 3, 3.2), (0, 1, 2, 3)), a=1.0)
    assert not p.has_remainder
    assert p.stray() == 0.0


# ----------------------------------------------------------------------------- fold check
def test_fold_check_refuses_spine_running_backwards():
    with pytest.raises(DesignError, match="fold"):
        PDEPatch(_coaxial((5.0, 4.0, 3.0, 0.0), (0.0, 2.0, 1.0, 3.0)), a=1.0)


def test_fold_check_refuses_section_turning_inside_out():
    """x semi-axis 5 → 0.1 → 0.1 → 5 with y fixed: the x semi-axis profile turns negative mid-patch,
    the section flips orientation and the surface self-intersects."""
    curves = tuple(Ellipse(rx, 5.0, (0.0, 0.0, z)) for rx, z in zip((5.0, 0.1, 0.1, 5.0), (0.0, 1.0, 2.0, 3.0)))
    p = PDEPatch(curves, a=1.0, check=False)
    x_semi = (p.evaluate(np.linspace(0, 1, 101), 0.0) - p.spine(np.linspace(0, 1, 101)))[:, 0]
    assert x_semi.min() < -0.1  # the case is genuine
    with pytest.raises(DesignError, match="fold") as exc:
        PDEPatch(curves, a=1.0)
    assert "curves" in exc.value.parameter


@pytest.mark.parametrize("scale", [1.0, 10.0, 100.0])
def test_fold_check_is_the_same_at_every_size(scale):
    """A fold is a length: a shape scaled by k folds k times as deep, and its limit grows with it where
    ``tol.fold_fraction`` of its reach passes ``tol.fold``.  The thesis's sphere (which folds by 3.3e-4
    of its radius at the pole) builds at 5, 50 and 500 mm (a trial: refused above 30 mm), while the
    spine running backwards is refused at every size."""
    from tabletcad.families.thesis import spherical

    t = spherical(diameter=5.0 * scale)
    ratio = [p.checked_fold_depth / (2.5 * scale) for p in t.patches]
    assert ratio == pytest.approx([3.28e-4] * 2, rel=0.01)
    for p in t.patches:  # (the reach: the PDE sphere's largest radius, 0.22 % above the sphere's)
        assert p.fold_limit() == pytest.approx(max(DEFAULT.fold, DEFAULT.fold_fraction * 2.5 * scale), rel=3e-3)
    bad = _coaxial(tuple(scale * r for r in (5.0, 4.0, 3.0, 0.0)), tuple(scale * z for z in (0.0, 2.0, 1.0, 3.0)))
    depth = PDEPatch(bad, a=1.0, check=False).fold_depth()
    with pytest.raises(DesignError, match="fold"):
        PDEPatch(bad, a=1.0)
    assert depth > 0.01 * 5.0 * scale  # (a fold of a twentieth of the radius and more, at every size)


def test_fold_check_accepts_valid_dome_and_band():
    PDEPatch(_coaxial((0.0, 3.0, 4.5, 5.0), (0.0, 0.4, 1.2, 2.0)), a=1.0)
    PDEPatch(_coaxial((5.0, 5.0, 5.0, 5.0), (0.0, 1.0, 2.0, 3.0)), a=1.0)


@pytest.mark.parametrize("radii", [(5.0, 0.1, 0.1, 5.0), (5.0, 0.2, 5.0, 0.0)])
def test_fold_check_refuses_radius_turning_negative(radii):
    curves = _coaxial(radii, (0.0, 1.0, 2.0, 3.0))
    p = PDEPatch(curves, a=1.0, check=False)
    u = np.linspace(0.0, 1.0, 301)
    signed = (p.evaluate(u, 0.0) - p.spine(u))[:, 0]  # x of the point at v = 0 = signed radius
    assert signed.min() < -0.2  # the radius genuinely turns negative
    with pytest.raises(DesignError):
        PDEPatch(curves, a=1.0)


def _wobbly_stack(kit, n, eps=0.1):
    out = []
    for r, z in zip((4.0, 5.0, 5.0, 4.0), (0.0, 1.0, 2.0, 3.0)):
        a = np.zeros((n, 3))
        b = np.zeros((n, 3))
        a[0], b[0] = (r, 0, 0), (0, r, 0)
        a[n - 1, 0] += eps
        b[n - 1, 1] -= eps
        out.append(kit.TrigCurve((0.0, 0.0, z), a, b))
    return tuple(out)


def test_patch_with_exploding_design_mode_is_refused(kit):
    curves = _wobbly_stack(kit, 3)
    p = PDEPatch(curves, a=50.0, check=False)
    size = float(np.max(np.abs(p.evaluate_grid(np.linspace(0, 1, 31), V))))
    assert size > 1e6  # the surface is genuinely absurd for 5 mm curves
    with pytest.raises(DesignError):
        PDEPatch(curves, a=50.0)


def test_patch_with_nan_surface_is_refused():
    curves = _coaxial((4.0, 5.0, 5.0, 4.0), (0.0, 1.0, 2.0, 3.0))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        try:
            p = PDEPatch(curves, a=50.0, modes=48)
        except DesignError:
            return
        assert np.all(np.isfinite(p.evaluate(np.array(p.u_nodes), 0.0)))


# ----------------------------------------------------------------------------- evaluation paths
@pytest.mark.parametrize("du, dv", [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2), (2, 2)])
@pytest.mark.parametrize("which", ["trig", "stadium"])
def test_evaluate_grid_vectorised_and_scalar_agree(du, dv, which, kit):
    if which == "trig":
        p = PDEPatch(_trig_stack(kit, np.random.default_rng(5)), a=1.0)
    else:
        p = PDEPatch(STADIUM_STACK, a=0.1)
    u = np.array([0.0, 0.13, 1 / 3, 0.5, 0.9, 1.0])
    v = np.array([0.0, 0.7, 2.0, 3.9, 6.1])
    G = p.evaluate_grid(u, v, du=du, dv=dv)
    assert G.shape == (u.size, v.size, 3)
    Vv = p.evaluate(u[:, None], v[None, :], du=du, dv=dv)
    assert Vv.shape == G.shape
    loop = np.array([[p.evaluate(float(ui), float(vj), du=du, dv=dv) for vj in v] for ui in u])
    assert loop.shape == G.shape
    scale = max(1.0, float(np.max(np.abs(G))))
    np.testing.assert_allclose(Vv, G, atol=1e-12 * scale)
    np.testing.assert_allclose(loop, G, atol=1e-12 * scale)


@pytest.mark.parametrize("which", ["spine", "trig", "stadium"])
def test_evaluate_grid_writes_each_term_into_one_array(which, kit):
    """The grid's product (modes, then each coordinate's remainder and spine added in place) gives the
    scattered-point path's values for every layout: a patch with no mode and no remainder (coaxial
    points: the spine alone), modes alone, modes and remainder; every derivative, subsets of the axes
    in any order, a row or column of one, an empty side."""
    if which == "spine":
        p = PDEPatch(tuple(Circle(0.0, (0.1 * k, -0.2 * k, z)) for k, z in enumerate((0.0, 1.0, 2.2, 3.0))), a=1.0)
        assert not p._active and not p._has_remainder
    elif which == "trig":
        p = PDEPatch(_trig_stack(kit, np.random.default_rng(11)), a=1.0)
        assert p._active and not p._has_remainder
    else:
        p = PDEPatch(STADIUM_STACK, a=0.1)
        assert p._active and p._has_remainder
    u, v = np.array([0.0, 0.21, 0.5, 0.77, 1.0]), np.array([0.0, 0.4, 1.3, 2.9, 4.4, 5.5, 6.2])
    for du, dv in ((0, 0), (1, 0), (0, 1), (2, 0), (1, 2)):
        ref = p.evaluate(u[:, None], v[None, :], du=du, dv=dv)  # 35 points: the scattered path, no grid
        scale = max(1.0, float(np.max(np.abs(ref))))
        np.testing.assert_allclose(p.evaluate_grid(u, v, du, dv), ref, rtol=0, atol=1e-12 * scale)
        for axes in ((2,), (1, 0), (0, 2), (2, 1, 0)):
            G = p.evaluate_grid(u, v, du, dv, components=True, axes=axes)
            assert G.shape == (len(axes), u.size, v.size) and G.flags.c_contiguous
            np.testing.assert_allclose(G, ref[..., list(axes)].transpose(2, 0, 1), rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(p.evaluate_grid(u[2:3], v, du, dv)[0], ref[2], rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(p.evaluate_grid(u, v[3:4], du, dv)[:, 0], ref[:, 3], rtol=0, atol=1e-12 * scale)
        assert p.evaluate_grid(u[:0], v, du, dv).shape == (0, v.size, 3)
        assert p.evaluate_grid(u, v[:0], du, dv, components=True, axes=(0, 2)).shape == (2, u.size, 0)


def test_gemm_into_a_block_that_is_not_fortran_contiguous():
    """``_gemm`` writes ``a @ b`` (or adds it) into its output even where BLAS had to take a copy."""
    from tabletcad.geometry.patch import _gemm

    rng = np.random.default_rng(2)
    a, b = rng.random((6, 4)), rng.random((4, 5))
    c = np.zeros((6, 5))  # C-ordered: dgemm works on a Fortran copy
    assert _gemm(a, b, c) is c
    np.testing.assert_allclose(c, a @ b, rtol=1e-15)
    _gemm(a, b, c, fresh=False)
    np.testing.assert_allclose(c, 2.0 * (a @ b), rtol=1e-15)
    f = np.empty((6, 5), order="F")
    _gemm(a.T.copy().T, b, f)  # a Fortran block: written in place
    np.testing.assert_allclose(f, a @ b, rtol=1e-15)


def test_evaluate_broadcasting_shapes():
    p = PDEPatch(_coaxial((0, 2, 3, 3.2), (0, 1, 2, 3)), a=1.0)
    assert p.evaluate(0.5, 0.1).shape == (3,)
    assert p.evaluate(np.zeros((2, 3)), 0.1).shape == (2, 3, 3)
    assert p.evaluate(np.zeros((4, 1)), np.zeros((1, 5))).shape == (4, 5, 3)
    assert p.spine(np.zeros((2, 2))).shape == (2, 2, 3)
    assert p.radius_profile(np.zeros(7)).shape == (7,)


@pytest.mark.parametrize("which", ["trig", "stadium"])
def test_partial_derivatives_agree_with_finite_differences(which, kit):
    if which == "trig":
        p = PDEPatch(_trig_stack(kit, np.random.default_rng(9)), a=1.0)
    else:
        p = PDEPatch(STADIUM_STACK, a=0.1)
    u = np.linspace(0.05, 0.95, 7)[:, None]
    v = np.linspace(0.1, 6.0, 11)[None, :]
    h = 1e-6
    fd_u = (p.evaluate(u + h, v) - p.evaluate(u - h, v)) / (2 * h)
    fd_uu = (p.evaluate(u + h, v, du=1) - p.evaluate(u - h, v, du=1)) / (2 * h)
    np.testing.assert_allclose(p.evaluate(u, v, du=1), fd_u, atol=1e-6 * max(1, np.abs(fd_u).max()))
    np.testing.assert_allclose(p.evaluate(u, v, du=2), fd_uu, atol=1e-6 * max(1, np.abs(fd_uu).max()))
    if which == "trig":  # stadium's v-derivatives have kinks at line/arc joins
        fd_v = (p.evaluate(u, v + h) - p.evaluate(u, v - h)) / (2 * h)
        np.testing.assert_allclose(p.evaluate(u, v, dv=1), fd_v, atol=1e-6 * max(1, np.abs(fd_v).max()))
        fd_uv = (p.evaluate(u, v + h, du=1) - p.evaluate(u, v - h, du=1)) / (2 * h)
        np.testing.assert_allclose(p.evaluate(u, v, du=1, dv=1), fd_uv, atol=1e-6 * max(1, np.abs(fd_uv).max()))


def test_normal_unit_outward_and_defined_at_pole():
    """Lower dome of a sphere: point at the bottom, equator on top."""
    r = 2.5
    ang = [-math.pi / 2, -math.pi / 3, -math.pi / 6, 0.0]
    curves = tuple(Circle(r * math.cos(t) if t != -math.pi / 2 else 0.0, (0, 0, r * math.sin(t))) for t in ang)
    p = PDEPatch(curves, a=1.0)
    u = np.array([0.0, 0.2, 0.5, 0.8, 1.0])[:, None]
    v = np.linspace(0, TWO_PI, 9)[None, :]
    n = p.normal(u, v)
    assert np.all(np.isfinite(n))
    np.testing.assert_allclose(np.linalg.norm(n, axis=-1), 1.0, atol=1e-12)
    # X_u × X_v with u running up from the pole points inward on this dome; consistently one side
    radial = np.einsum("...c,...c->...", n, p.evaluate(u, v))
    assert np.all(radial < 0) or np.all(radial > 0)
    # at the pole the normal is vertical
    # (the thesis's curves give the pole a slight cone point, so only nearly vertical)
    assert np.all(np.abs(n[0, :, 2]) > 0.99)


def test_replace_data_keeps_settings():
    p = PDEPatch(STADIUM_STACK, a=0.1, u_nodes=(0.0, 0.3, 0.6, 1.0), name="x")
    q = p.replace_data([c.moved((1.0, 2.0, 3.0)) for c in STADIUM_STACK])
    assert (q.a, q.u_nodes, q.form, q.name) == (p.a, p.u_nodes, p.form, p.name)
    u = np.linspace(0, 1, 5)[:, None]
    np.testing.assert_allclose(q.evaluate(u, V[None]), p.evaluate(u, V[None]) + (1.0, 2.0, 3.0), atol=1e-11)


@pytest.mark.parametrize("family", ["capsule", "concave_round"])
def test_grid_components_layout_holds_the_same_values(family):
    """``evaluate_grid(..., components=True, axes=...)`` is the point layout's values, coordinate by
    coordinate (all three bit for bit: the same matrix product, without the transposed copy; a
    subset from a product with fewer rows, which BLAS may block differently)."""
    from tabletcad.families import FAMILIES

    t = FAMILIES[family].build()
    u, v = np.linspace(0.0, 1.0, 23), np.linspace(0.0, 6.0, 71)
    for p in t.patches[:3]:
        for du, dv in ((0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)):
            X = p.evaluate_grid(u, v, du, dv)
            np.testing.assert_array_equal(p.evaluate_grid(u, v, du, dv, components=True), X.transpose(2, 0, 1))
            tol = 1e-14 * max(1.0, float(np.abs(X).max()))
            np.testing.assert_allclose(p.evaluate_grid(u, v, du, dv, components=True, axes=(0, 1))[1], X[..., 1],
                                       rtol=0, atol=tol)
            np.testing.assert_allclose(p.evaluate_grid(u, v, du, dv, components=True, axes=(2,))[0], X[..., 2],
                                       rtol=0, atol=tol)
    with pytest.raises(ValueError):
        t.patches[0].evaluate_grid(u, v, axes=(0, 1))


@pytest.mark.parametrize("family", ["capsule", "rounded_triangle"])
def test_grid_written_into_out_is_the_same_grid(family):
    """``evaluate_grid(..., components=True, out=block)`` writes the grid into the block it is given (a
    slice of a larger array, as jet_grid's, bounds' and deviation_peaks' are) and returns it: bit for bit
    the values of the call without ``out``; an ``out`` of another shape, or without ``components``, is refused."""
    from tabletcad.families import FAMILIES

    t = FAMILIES[family].build()
    u, v = np.linspace(0.0, 1.0, 17), np.linspace(0.0, 6.0, 45)
    for p in t.patches[:3]:
        for du, dv in ((0, 0), (1, 0), (0, 1), (2, 0)):
            for axes in ((0, 1, 2), (0, 1), (2,)):
                big = np.full((len(axes) + 1, u.size, v.size), np.nan)
                got = p.evaluate_grid(u, v, du, dv, components=True, axes=axes, out=big[1:])
                assert np.shares_memory(got, big)
                np.testing.assert_array_equal(big[1:], p.evaluate_grid(u, v, du, dv, components=True, axes=axes))
                assert np.all(np.isnan(big[0]))  # nothing written outside the block
        X, Xu, Xv = p.jet_grid(u, v)
        for G, (du, dv) in zip((X, Xu, Xv), ((0, 0), (1, 0), (0, 1))):
            np.testing.assert_array_equal(G[:2], p.evaluate_grid(u, v, du, dv, components=True, axes=(0, 1)))
    p = t.patches[0]
    with pytest.raises(ValueError):
        p.evaluate_grid(u, v, components=True, out=np.empty((3, v.size, u.size)))
    with pytest.raises(ValueError):
        p.evaluate_grid(u, v, out=np.empty((3, u.size, v.size)))
