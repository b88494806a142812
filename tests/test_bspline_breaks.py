"""Breakpoint-aware periodic knots of :mod:`tabletcad.brep` (numpy only, no CAD kernel)."""

import math

import numpy as np
import pytest

from tabletcad.brep.fit import fit_patches, fit_surface
from tabletcad.brep.knots import flat_knots, normalise_breaks, periodic_knots
from tabletcad.errors import GeometryError

TWO_PI = 2 * math.pi


def c1_surface(u, v):
    """A cylinder-like surface whose radius is only C1 in v at v = 0 and v = pi."""
    u, v = np.broadcast_arrays(np.asarray(u, float), np.asarray(v, float))
    r = 2.0 + 0.3 * np.maximum(0.0, np.sin(v)) ** 2 + 0.1 * u
    return np.stack([r * np.cos(v), r * np.sin(v), 3.0 * u], axis=-1)


def test_normalise_breaks_sorts_wraps_and_merges():
    b = normalise_breaks([TWO_PI, 3.0, 3.0 + 1e-12, -1.0, 1e-13])
    np.testing.assert_allclose(b, [0.0, 3.0, TWO_PI - 1.0])
    assert normalise_breaks(None).size == 0 and normalise_breaks([]).size == 0


@pytest.mark.parametrize("degree", [3, 4, 5])
@pytest.mark.parametrize("mult", ["c1", "c0"])
def test_periodic_knots_structure_and_greville(degree, mult):
    m = degree - 1 if mult == "c1" else degree
    k, mm, s = periodic_knots(20, degree, [0.0, 1.0, 4.0], m)
    assert k[0] == 0.0 and k[-1] == TWO_PI and mm[0] == mm[-1] == m
    for b in (1.0, 4.0):
        assert mm[np.argmin(abs(k - b))] == m and np.min(abs(k - b)) < 1e-15
    n = int(mm[:-1].sum())
    assert s.size == n and np.all(np.diff(s) > 0) and s[0] >= 0 and s[-1] < TWO_PI
    # Schoenberg-Whitney: B-spline i contains its Greville point strictly inside its support
    t = flat_knots(k, mm, degree, True)
    grev = np.array([t[i + 1 : i + degree + 1].mean() for i in range(n)])
    assert np.all((t[:n] < grev) & (grev < t[degree + 1 : degree + 1 + n]))


def test_uniform_knots_unchanged_without_breaks():
    k, _mm, s = periodic_knots(16, 5)
    np.testing.assert_array_equal(k, np.linspace(0, TWO_PI, 17))
    np.testing.assert_array_equal(s, k[:-1])
    _, _, s4 = periodic_knots(16, 4)
    np.testing.assert_allclose(s4, k[:-1] + TWO_PI / 32)


def _dev(nv, breaks):
    fit = fit_surface(c1_surface, 5, 5, nu=9, nv=nv, tol=1e-15, fixed_nv=True, max_iterations=1,
                      v_breaks=breaks, raise_on_failure=False)
    return fit.max_deviation


def test_breakpoint_knots_restore_full_order():
    # with C1 knots at the breaks: ~h^6 (quintic); uniform knots: ~h^3 (the C1 kink)
    e1, e2 = _dev(24, [0.0, math.pi]), _dev(48, [0.0, math.pi])
    u1, u2 = _dev(24, None), _dev(48, None)
    assert e1 / e2 > 25, (e1, e2)
    assert u1 / u2 < 12, (u1, u2)
    assert e2 < u2 / 100


def test_fit_patches_share_breakpoint_knots():
    f0 = c1_surface
    f1 = lambda u, v: c1_surface(1.0 + 0 * u, v) + np.stack(
        [0 * u, 0 * u, 2.0 * np.broadcast_to(u, np.broadcast(u, v).shape)], axis=-1)
    fits = fit_patches([f0, f1], 1e-6, u_degree=5, v_degree=5, v_breaks=[math.pi, 0.0])
    a, b = fits[0].surface, fits[1].surface
    np.testing.assert_array_equal(a.v_knots, b.v_knots)
    np.testing.assert_array_equal(a.v_mults, b.v_mults)
    np.testing.assert_array_equal(a.poles[-1], b.poles[0])
    assert max(f.max_deviation for f in fits) <= 1e-6
    assert a.shape[1] < 120


def test_unreachable_tolerance_raises_with_name():
    with pytest.raises(GeometryError, match=r"fit of side .* max deviation"):
        fit_surface(c1_surface, 5, 5, tol=1e-14, max_nv=40, max_iterations=2, v_breaks=[0.0, math.pi], name="side")


def test_bad_break_multiplicity():
    with pytest.raises(ValueError):
        periodic_knots(10, 3, [1.0], 4)


@pytest.mark.parametrize("name", ["capsule", "rounded_rectangle", "custom_outline"])
def test_shared_rows_put_into_the_first_fit_give_the_refit_poles_and_a_bound_on_its_deviation(name, monkeypatch):
    """``fit_patches`` solves a patch again with its neighbour's boundary row without sampling
    it again: the poles are those of a full refit, bit for bit, and the deviation it reports
    (the first fit's plus the largest pole change) is at least what a fresh measurement finds."""
    from pathlib import Path

    import tabletcad.brep.fit as fit_module
    from tabletcad.brep.fit import _deviation
    from tabletcad.brep.surfaces import fit_options, tablet_surface_functions
    from tabletcad.pipeline.design import load_design

    tablet = load_design(Path(__file__).resolve().parents[1] / "samples" / "families" / f"{name}.toml")
    funcs, names = tablet_surface_functions(tablet)
    used = []
    real = fit_module._with_rows
    monkeypatch.setattr(fit_module, "_with_rows", lambda *a, **k: used.append(real(*a, **k)) or used[-1])
    quick = fit_patches(funcs, tablet.tol.fit, names=names, **fit_options(tablet))
    assert used and all(u is not None for u in used)  # every patch with a shared row took the quick path
    monkeypatch.setattr(fit_module, "_with_rows", lambda *a, **k: None)  # the full refit of every patch
    full = fit_patches(funcs, tablet.tol.fit, names=names, **fit_options(tablet))
    for f, q, r in zip(funcs, quick, full):
        assert np.array_equal(q.surface.poles, r.surface.poles)
        measured = _deviation(f, q.surface, q.u_samples, q.v_samples, 4)[0]
        assert measured <= q.max_deviation <= q.tol
        assert q.max_deviation - measured <= 1e-8  # the bound is tight: the rows moved by ~1e-9


def test_periodic_knots_are_kept_read_only_for_the_same_arguments():
    """A chain's fit asks for the same knots again and again: the first answer is kept (read-only),
    the one the computation gives, and other arguments get their own."""
    from tabletcad.brep.knots import _periodic_knots

    first = periodic_knots(24, 5, [0.0, 1.0, 4.0], 4)
    again = periodic_knots(24, 5, np.array([4.0, 1.0, 0.0]), 4)  # the same breakpoints, normalised alike
    assert all(a is b and not a.flags.writeable for a, b in zip(first, again))
    for a, b in zip(first, _periodic_knots(24, 5, [0.0, 1.0, 4.0], 4)):
        np.testing.assert_array_equal(a, b)
    assert periodic_knots(24, 5, [0.0, 1.0, 4.0], 3)[1] is not first[1]
