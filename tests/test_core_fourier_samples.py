"""Samples of a curve's Fourier coefficients keep a symmetric outline's symmetry (curves.fourier_samples).

A curve with k-fold symmetry about the z axis has plan content only at frequencies ≡ 1 (mod k).  Its
coefficients from m samples alias mode n onto n ± j m: when k divides m the modes the curve lacks stay
zero to rounding, else they take on aliased content (a rounded triangle at 512 samples: 2e-5 mm in
modes 3, 6, 9, …, and its spine off the axis).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tabletcad.families.outline import rounded_polygon
from tabletcad.families.sweep import SweepCurve
from tabletcad.geometry.curves import SYMMETRY_SAMPLES, fourier_coefficients, fourier_samples
from tabletcad.pipeline.design import Design
from tabletcad.tolerance import DEFAULT

ROOT = Path(__file__).resolve().parents[1]


@settings(max_examples=200, deadline=None)
@given(modes=st.integers(0, 400), least=st.one_of(st.none(), st.integers(1, 5000)))
def test_the_count_is_the_least_multiple_of_240_above_both_bounds(modes, least):
    m = fourier_samples(modes, least)
    floor = max(DEFAULT.samples if least is None else least, 8 * modes + 8)
    assert m % SYMMETRY_SAMPLES == 0 and SYMMETRY_SAMPLES == 240
    assert floor <= m < floor + SYMMETRY_SAMPLES


def _polygon_curve(k: int, radius: float, corner: float, turn: float, offset: float) -> SweepCurve:
    """A rounded regular k-gon's offset curve (inward by ``offset`` mm), lifted to z = 1 mm."""
    verts = [(radius * math.cos(turn + math.tau * j / k), radius * math.sin(turn + math.tau * j / k)) for j in range(k)]
    return SweepCurve(rounded_polygon(verts, corner, name=f"{k}-gon"), 1.0, offset, (0.0, 0.0, 1.0))


def _absent(k: int, modes: int) -> np.ndarray:
    n = np.arange(1, modes + 1)
    return (n % k != 1 % k) & (n % k != (k - 1) % k)


@settings(max_examples=25, deadline=None)
@given(k=st.sampled_from([3, 4, 5, 6, 8, 10, 12]), radius=st.floats(3.0, 8.0), corner=st.floats(0.2, 0.9),
       turn=st.floats(0.0, math.tau), offset=st.floats(0.0, 0.5))
def test_a_k_fold_outline_s_absent_modes_are_zero_and_its_centre_on_the_axis(k, radius, corner, turn, offset):
    """Every mode the k-gon lacks (not ±1 mod k) and the plan part of its mean are zero to rounding
    (1e-14 mm; measured ≤ 7e-16) with the default count; the present modes are not."""
    corner = corner * radius * math.cos(math.pi / k)  # below the inscribed radius
    c = _polygon_curve(k, radius, corner, turn, offset * corner)
    a0, a, b = fourier_coefficients(c, 48)
    absent = _absent(k, 48)
    assert np.abs(a[absent]).max() < 1e-14 and np.abs(b[absent]).max() < 1e-14
    assert np.abs(a0[:2]).max() < 1e-14 and a0[2] == pytest.approx(1.0, abs=1e-14)
    assert np.hypot(a[0, 0], b[0, 0]) > 0.5 * radius  # (the first mode, present: the curve's size)


def test_at_512_samples_a_triangle_took_on_aliased_modes():
    """The reason for the count: 512 (not a multiple of 3) gave the triangle ~1e-5 mm in modes 3, 6, 9."""
    c = _polygon_curve(3, 5.0, 1.0, 0.3, 0.7)
    a0, a, b = fourier_coefficients(c, 48, 512)
    absent = _absent(3, 48)
    assert np.abs(np.concatenate([a[absent], b[absent]])).max() > 1e-6
    assert np.abs(a0[:2]).max() > 1e-6


def test_the_rounded_triangle_sample_sums_only_the_modes_a_triangle_has():
    """Its patches carry modes ≢ 0 (mod 3) only (32 of 48), their spines stay on the axis (1e-13 mm), and
    so its cut-aways have a plan area (the spine had wandered 6e-6 mm: none)."""
    t = Design.from_toml(ROOT / "samples" / "families" / "rounded_triangle.toml").build()
    for p in t.patches:
        assert p.modes == 48 and len(p._n_active) == 32 and not np.any(p._n_active % 3 == 0)
        assert np.abs(p.spine(np.linspace(0.0, 1.0, 33))[:, :2]).max() < 1e-13
    assert t.trimmed(v=(0.3, 2.0)).plan_area() > 0.0
