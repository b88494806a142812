"""Heckel fits: synthetic data with known K and A, the thesis's Table 5.1 experiment."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tabletcad.errors import DesignError
from tabletcad.mechanics.compaction import compaction_curves
from tabletcad.mechanics.heckel import fit_heckel, fit_heckel_arrays, plot_heckel
from tabletcad.mechanics.pressdata import PressData, PressMetadata, read_press_data
from tabletcad.mechanics.validity import FitQualityWarning

SAMPLE = Path(__file__).resolve().parents[1] / "samples" / "press" / "lactose_appendix_b.csv"
META = PressMetadata(mass_mg=250.0, true_density=1.5, diameter=10.0)


def synthetic_record(K=0.005, A=1.0, noise=0.001, seed=0, B=0.4, P0=15.0, pmax=250.0):
    """Loading branch with a curved rearrangement zone, then an unloading branch, as press data."""
    rng = np.random.default_rng(seed)
    P = np.linspace(1.0, pmax, 120)
    H = K * P + A - B * np.exp(-P / P0) + rng.normal(0.0, noise, P.size)
    D = 1.0 - np.exp(-H)
    h = META.mass_mg / (META.true_density * META.area * D)
    # unloading: pressure falls to ~2 % while the compact springs back by 2 %
    Pu = np.linspace(pmax * 0.97, 5.0, 40)
    hu = h[-1] * (1.0 + 0.02 * (1.0 - Pu / pmax))
    F = np.concatenate([P, Pu]) * META.area
    disp = -np.concatenate([h, hu])
    return PressData.from_arrays(F, displacement=disp, metadata=META)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_synthetic_auto_window_recovers_K_and_A(seed):
    c = compaction_curves(synthetic_record(seed=seed))
    assert c.branches.loading == (0, 120)
    assert c.elastic_recovery == pytest.approx(0.02 * (1 - 5.0 / 250.0), rel=1e-6)
    fit = fit_heckel(c)  # automatic window
    assert fit.K_per_MPa == pytest.approx(0.005, rel=0.02)
    assert fit.A == pytest.approx(1.0, rel=0.02)
    assert fit.Py_MPa == pytest.approx(200.0, rel=0.02)
    # the curved rearrangement zone (B e^{-P/P0} > 0.005 below ~65 MPa) is excluded
    assert fit.window_MPa[0] > 40.0
    assert all(r < 120 for r in fit.rows)  # no unloading point used


def test_synthetic_given_window():
    c = compaction_curves(synthetic_record(noise=0.0))
    fit = fit_heckel(c, window=(150.0, 250.0))
    assert fit.K_per_MPa == pytest.approx(0.005, rel=1e-4)
    assert fit.A == pytest.approx(1.0, rel=1e-4)
    assert fit.r2 > 0.9999
    assert 150.0 <= fit.window_MPa[0] < fit.window_MPa[1] <= 250.0
    assert fit.n_points == int(np.sum((c.pressure[:120] >= 150) & (c.pressure[:120] <= 250)))


@settings(max_examples=25, deadline=None)
@given(
    K=st.floats(0.001, 0.05),
    A=st.floats(0.2, 1.5),
)
def test_exact_line_is_recovered(K, A):
    P = np.linspace(5.0, 60.0, 30)
    D = 1.0 - np.exp(-(K * P + A))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FitQualityWarning)
        fit = fit_heckel_arrays(P, D, window=(5.0, 60.0))
    assert fit.K_per_MPa == pytest.approx(K, rel=1e-8)
    assert fit.A == pytest.approx(A, rel=1e-8)
    assert fit.n_points == 30 and fit.window_MPa == (5.0, 60.0)


def test_table_5_1_experiment_with_thesis_window():
    """Thesis Table 5.1: K 0.0098 1/MPa, A 0.8738, Py 102.04 MPa from the 10-50 MPa window."""
    fit = fit_heckel(compaction_curves(read_press_data(SAMPLE)), window=(10.0, 50.0))
    assert fit.n_points == 29
    assert fit.window_MPa == pytest.approx((10.70049612, 49.48980251), abs=1e-6)
    assert fit.K_per_MPa == pytest.approx(0.0095647, rel=1e-4)
    assert fit.A == pytest.approx(0.87921, rel=1e-4)
    assert fit.Py_MPa == pytest.approx(104.55, rel=1e-4)
    # within a few per cent of the thesis
    assert fit.K_per_MPa == pytest.approx(0.0098, rel=0.03)
    assert fit.A == pytest.approx(0.8738, rel=0.01)
    assert fit.Py_MPa == pytest.approx(102.04, rel=0.03)
    assert fit.r2 > 0.996


def test_table_5_1_depends_on_using_only_the_loading_branch():
    """Points of the reloading part of Appendix B also lie in 10-50 MPa; mixing them in ruins the fit."""
    c = compaction_curves(read_press_data(SAMPLE))
    with pytest.warns(FitQualityWarning, match="poor linearity"):
        mixed = fit_heckel_arrays(c.pressure, heckel=c.heckel, window=(10.0, 50.0))
    assert mixed.n_points > 29 and mixed.r2 < 0.5


def test_window_with_too_few_points():
    c = compaction_curves(read_press_data(SAMPLE))
    with pytest.raises(DesignError, match="need >= 3"):
        fit_heckel(c, window=(10.0, 11.0))
    with pytest.raises(DesignError, match="increasing"):
        fit_heckel(c, window=(50.0, 10.0))


def test_warnings_for_negative_slope_and_implausible_py():
    P = np.linspace(10, 50, 10)
    with pytest.warns(FitQualityWarning, match="non-positive slope"):
        fit_heckel_arrays(P, heckel=1.0 - 0.001 * P, window=(10, 50))
    with pytest.warns(FitQualityWarning, match="implausible yield pressure"):
        fit_heckel_arrays(P, heckel=1.0 + 1e-5 * P, window=(10, 50))


def test_auto_window_fails_cleanly_on_curved_data():
    P = np.linspace(1, 100, 40)
    with pytest.raises(DesignError, match="linear"):
        fit_heckel_arrays(P, heckel=np.sqrt(P), max_residual=1e-4)


def test_plot_is_written(tmp_path):
    fit = fit_heckel(compaction_curves(read_press_data(SAMPLE)), window=(10.0, 50.0))
    out = plot_heckel(fit, tmp_path / "heckel.svg")
    text = out.read_text()
    assert "<svg" in text and "Pressure P (MPa)" in text
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]
    assert math.isfinite(fit.relative_density_at_zero)
