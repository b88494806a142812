"""A swept family's data are combinations ``alpha O + beta N + const`` of one outline ``O`` and its
inward normal ``N``: its patches take their Fourier coefficients and their residuals above their modes
from that basis's, computed once (:func:`tabletcad.geometry.curves.combination_of`).  Checked here
against each curve's own FFT and its own residual summed mode by mode; and the two shortcuts of the
plan's polish (grid rows for points on a few ``u`` lines, no step below rounding) against single
points and closed forms."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tabletcad.geometry.curves import Curve, basis_spectrum, combination_of, evaluate_curves, fourier_coefficients, fourier_tail, modes_needed
from tabletcad.pipeline.design import Design

ROOT = Path(__file__).resolve().parents[1]
SWEPT = ["capsule", "oval", "almond", "rounded_triangle", "rounded_square", "custom_outline", "modified_capsule"]


def _tablet(name: str, folder: str = "families"):
    return Design.from_toml(ROOT / "samples" / folder / f"{name}.toml").build()


@pytest.fixture(scope="module")
def swept():
    return {name: _tablet(name) for name in SWEPT}


def _scale(p) -> float:
    return max(1.0, float(np.max(np.abs(p._a0))), float(np.max(np.abs(p._ac))))


def _samples(p) -> int:
    return p._comb[2]


@pytest.mark.parametrize("name", SWEPT)
def test_coefficients_from_the_basis_equal_each_curves_own_fft(swept, name):
    t = swept[name]
    for p in t.patches:
        assert combination_of(p.data) is not None and p._comb is not None, p.name
        tol = 1e-13 * _scale(p)
        for k, c in enumerate(p.data):
            a0, a, b = fourier_coefficients(c, p.modes, _samples(p))
            assert np.max(np.abs(a0 - p._a0[k])) <= tol, (p.name, k)
            assert np.max(np.abs(a - p._ac[k])) <= tol, (p.name, k)
            assert np.max(np.abs(b - p._bc[k])) <= tol, (p.name, k)


class _Plain(Curve):
    """The same curve without its basis: :func:`modes_needed` measures it from its own samples and FFT."""

    def __init__(self, curve) -> None:
        self.curve = curve

    def evaluate(self, v, der: int = 0):
        return self.curve.evaluate(v, der)

    def band_limit(self):
        return self.curve.band_limit()


@settings(max_examples=25, deadline=None)
@given(name=st.sampled_from(SWEPT), log_tol=st.floats(-8.0, -1.0), max_modes=st.sampled_from([4, 16, 48, 100]),
       which=st.integers(0, 1000))
def test_modes_needed_from_the_basis_equals_each_curves_own(swept, name, log_tol, max_modes, which):
    """The fewest modes of a swept datum (and the root-mean-square tail that screens it), taken from its
    outline basis's spectrum and partial sums, are the curve's own: its samples, its FFT, its residuals."""
    t = swept[name]
    curves = [c for p in t.patches for c in p.data]  # the points among them too (0 modes)
    c = curves[which % len(curves)]
    basis, W, _ = combination_of([c])
    tol = 10.0**log_tol
    assert modes_needed(c, tol, max_modes) == modes_needed(_Plain(c), tol, max_modes)
    gram = basis_spectrum(basis, max_modes, 1024)[3]
    want = fourier_tail(_Plain(c), max_modes, 1024)
    assert math.sqrt(max(float(W[0] @ gram @ W[0]), 0.0)) == pytest.approx(want, rel=1e-9, abs=1e-15)


def _residual_by_hand(p, v: np.ndarray, dv: int) -> np.ndarray:
    """Each datum (or its ``v``-derivative) less its series of the patch's active modes, summed mode by mode."""
    out = evaluate_curves(p.data, v, dv).copy()
    if dv == 0:
        out -= p._a0[:, None, :]
    for n in p._active:
        # d^dv/dv^dv of cos(nv), sin(nv)
        c = n**dv * np.cos(n * v + dv * math.pi / 2.0)
        s = n**dv * np.sin(n * v + dv * math.pi / 2.0)
        out -= c[None, :, None] * p._ac[:, n - 1][:, None, :] + s[None, :, None] * p._bc[:, n - 1][:, None, :]
    return out


@settings(max_examples=12, deadline=None)
@given(name=st.sampled_from(SWEPT), seed=st.integers(0, 2**31 - 1), m=st.sampled_from([5, 64, 300]),
       dv=st.sampled_from([0, 1, 2]))
def test_residuals_from_the_basis_equal_each_curves_own(swept, name, seed, m, dv):
    """At any ``v`` (a few, or grid-sized ones that the basis keeps), every patch's residuals and their
    derivatives: those of its own data curves less the series, to 1e-12 of the coefficients' scale (times
    ``n^dv`` of the top mode for the derivatives)."""
    t = swept[name]
    v = np.sort(np.random.default_rng(seed).uniform(0.0, math.tau, m))
    for p in t.patches:
        got = p._residuals(v, dv)
        want = _residual_by_hand(p, v, dv)
        tol = 1e-12 * _scale(p) * max(p._active, default=1) ** dv
        assert np.max(np.abs(got - want)) <= tol, (p.name, float(np.max(np.abs(got - want))))
        if dv == 0 and p._has_remainder:
            assert np.max(np.abs(got)) > 1e-9  # there is something above the modes to agree on


def test_patches_on_one_outline_share_one_basis(swept):
    t = swept["rounded_triangle"]
    bases = {id(p._comb[0]) for p in t.patches}
    assert len(bases) == 1


@settings(max_examples=10, deadline=None)
@given(name=st.sampled_from(SWEPT), seed=st.integers(0, 2**31 - 1), rows=st.integers(1, 5),
       du=st.sampled_from([0, 1, 2]), dv=st.sampled_from([0, 1]))
def test_points_on_a_few_u_lines_evaluate_as_single_points(swept, name, seed, rows, du, dv):
    """``PDEPatch.evaluate`` of many points on a few ``u`` lines (taken as grid rows) equals each point
    evaluated alone (the general path) to 1e-12 of the surface's size."""
    t = swept[name]
    rng = np.random.default_rng(seed)
    p = t.patches[int(rng.integers(len(t.patches)))]
    lines = rng.uniform(0.0, 1.0, rows)
    u = lines[rng.integers(rows, size=16 * rows + 64)]
    v = rng.uniform(0.0, math.tau, u.size)
    got = p.evaluate(u, v, du=du, dv=dv)
    want = np.array([p.evaluate(ui, vi, du=du, dv=dv) for ui, vi in zip(u, v)])
    assert got.shape == want.shape == (u.size, 3)
    assert np.max(np.abs(got - want)) <= 1e-12 * max(1.0, float(np.max(np.abs(want))))


@pytest.mark.parametrize("sample", [("spherical", ""), ("concave_round", "families")])
@pytest.mark.parametrize("nu", [34, 35, 50])
def test_the_plan_polish_finds_a_widest_line_between_the_samples(sample, nu):
    """With ``nu`` samples that miss the widest line (the sphere's equator), the sampled plan still
    equals ``π R_max²`` to 1e-13: the polish steps where they gain (unpolished, ~1e-3 short)."""
    name, folder = sample
    t = _tablet(name, folder)
    exact = t.plan_area()  # a tablet of revolution: pi R_max^2, R_max polished along its profile
    assert t._plan_area_sampled(nu, 256) == pytest.approx(exact, rel=1e-13)


@pytest.mark.parametrize("name", SWEPT)
def test_a_remainder_evident_from_the_basis_is_the_dense_tests(swept, name):
    """A patch has a remainder term when its data less every mode's series exceed ``1e-14`` of its scale
    at ``4 samples`` dense samples; on a shared basis the answer is first read from the basis's residuals
    at every 45th of those samples, less their rounding
    (:func:`~tabletcad.geometry.patch._basis_evidently_above`).
    It gives the dense test's answer on every patch of the swept samples (their outlines of lines and arcs
    leave content above any mode count), and it never reports a limit exceeded that the dense maximum does
    not exceed (at the maximum itself, or just below the largest of its own samples' combined residuals)."""
    from tabletcad.geometry.curves import sample_v
    from tabletcad.geometry.patch import _basis_evidently_above, _basis_residuals
    from tabletcad.geometry.vectors import einsum

    for p in swept[name].patches:
        basis, W, samples = p._comb
        dense = float(np.abs(einsum("jk,kmc->jmc", W, _basis_residuals(basis, p.modes, samples, None,
                                                                        sample_v(4 * samples), 0))).max())
        limit = 1e-14 * _scale(p)
        assert p._has_remainder == (dense > limit), p.name
        assert _basis_evidently_above(p._comb, p.modes, limit) == p._has_remainder, p.name
        assert not _basis_evidently_above(p._comb, p.modes, dense), p.name
        few = _basis_residuals(basis, p.modes, samples, None, sample_v(4 * samples)[::45], 0)
        own = float(np.abs(einsum("jk,kmc->jmc", W, few)).max())
        assert not _basis_evidently_above(p._comb, p.modes, own * (1.0 - 1e-15)), p.name
