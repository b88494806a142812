"""Kawakita, Walker, Ryshkewitch-Duckworth and the USP <1062> profiles."""

from __future__ import annotations

import numpy as np
import pytest

from tabletcad.errors import DesignError
from tabletcad.mechanics.kawakita import fit_kawakita, fit_walker
from tabletcad.mechanics.profiles import (
    compactibility,
    compressibility,
    fit_ryshkewitch_duckworth,
    plot_profiles,
    tabletability,
)


def test_kawakita_recovers_a_and_b():
    a, b, h0 = 0.45, 0.08, 6.0
    P = np.linspace(0.5, 100, 60)
    C = a * b * P / (1 + b * P)
    fit = fit_kawakita(P, h0 * (1 - C), h0=h0)
    assert fit.a == pytest.approx(a, rel=1e-10)
    assert fit.b_per_MPa == pytest.approx(b, rel=1e-10)
    assert fit.inv_b_MPa == pytest.approx(12.5, rel=1e-10)
    assert fit.r2 == pytest.approx(1.0)


def test_walker_recovers_coefficient():
    P = np.geomspace(1, 100, 30)
    h0 = 5.0
    h = h0 * (90.0 - 12.0 * np.log10(P)) / 100.0
    fit = fit_walker(P, h, h0=h0)
    assert fit.W_percent_per_decade == pytest.approx(12.0, rel=1e-10)
    assert fit.intercept_percent == pytest.approx(90.0, rel=1e-10)


def test_kawakita_window_too_small():
    with pytest.raises(DesignError):
        fit_kawakita([1, 2, 3, 4], [5, 4.9, 4.8, 4.7], window=(1.5, 2.5))


def test_ryshkewitch_duckworth():
    D = np.linspace(0.7, 0.95, 8)
    s = 12.0 * np.exp(7.5 * (D - 1.0))
    fit = fit_ryshkewitch_duckworth(D, s)
    assert fit.sigma0_MPa == pytest.approx(12.0, rel=1e-10)
    assert fit.k == pytest.approx(7.5, rel=1e-10)
    assert fit.strength(1.0) == pytest.approx(12.0)
    with pytest.raises(DesignError, match="between 0 and 1"):
        fit_ryshkewitch_duckworth([0.5, 1.2, 0.8], [1, 2, 3])
    with pytest.raises(DesignError, match="> 0"):
        fit_ryshkewitch_duckworth([0.5, 0.6, 0.8], [1, 0, 3])


def test_profiles_sort_and_convert(tmp_path):
    P = [150.0, 50.0, 100.0]
    sf = [0.9, 0.7, 0.8]
    ts = [3.0, 1.0, 2.0]
    t = tabletability(P, ts)
    assert list(t.x) == [50, 100, 150] and list(t.y) == [1, 2, 3]
    c = compressibility(P, sf)
    assert np.allclose(c.y, [0.3, 0.2, 0.1]) and "Porosity" in c.y_label
    k = compactibility(sf, ts)
    assert np.allclose(k.x, [0.1, 0.2, 0.3]) and np.allclose(k.y, [3, 2, 1])
    out = plot_profiles([t, c, k], tmp_path / "profiles.png")
    assert out.stat().st_size > 1000
    with pytest.raises(DesignError):
        tabletability([1, 2], [1, 2, 3])


def test_walker_warns_of_a_non_positive_coefficient():
    """A thickness rising with the pressure is fitted (W = -96.94 % per decade) and warned of, as Heckel's
    K <= 0 is; a falling one is not."""
    import warnings

    from tabletcad.mechanics.validity import FitQualityWarning

    with pytest.warns(FitQualityWarning, match=r"^Walker fit: non-positive coefficient W = -96\.94 % per decade"):
        fit = fit_walker([10, 20, 30, 40], [5, 6, 7, 8])
    assert fit.W_percent_per_decade == pytest.approx(-96.935, abs=1e-3)
    with warnings.catch_warnings():
        warnings.simplefilter("error", FitQualityWarning)
        assert fit_walker([10, 20, 30, 40], [5, 4.5, 4.2, 4.0]).W_percent_per_decade > 0
