"""Level patches (:attr:`PDEPatch.level`): a swept family's data are plan curves lifted to heights, so every line
``u`` of its patches lies in one plane and the tablet's z extent is its spines' (``Tablet._spine_z_range``), taken
without the two-dimensional polish of every other extent."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tabletcad.geometry.curves import Circle, Ellipse
from tabletcad.geometry.patch import PDEPatch
from tabletcad.geometry.tablet import solid_map
from tabletcad.pipeline.design import load_design

ROOT = Path(__file__).resolve().parents[1]
SHAPED = ["capsule", "oval", "rounded_triangle", "almond", "custom_outline"]


@pytest.fixture(scope="module")
def shaped():
    return {n: load_design(ROOT / "samples" / "families" / f"{n}.toml") for n in SHAPED}


@pytest.mark.parametrize("name", SHAPED)
def test_a_swept_tablets_z_is_its_spines(shaped, name):
    """Every patch is level, and its surface's z at random points is its spine's there (to round-off)."""
    t = shaped[name]
    rng = np.random.default_rng(7)
    u, v = rng.random(40), rng.random(40) * 2 * np.pi
    for p in t.patches:
        assert p.level
        np.testing.assert_allclose(p.evaluate_grid(u, v)[..., 2], p.spine(u)[:, None, 2] + 0 * v, rtol=0, atol=1e-13)


@settings(max_examples=10, deadline=None)
@given(name=st.sampled_from(SHAPED), u=st.sampled_from([(0.0, 1.0), (0.0, 0.6), (0.3, 1.0), (0.15, 0.85)]),
       v=st.sampled_from([None, (0.4, 2.9), (-1.0, 3.5)]), w=st.sampled_from([(0.0, 1.0), (0.0, 0.8), (0.5, 1.0)]))
def test_the_spines_z_extent_equals_the_general_polish_and_holds_the_solid(shaped, monkeypatch, name, u, v, w):
    """Any trim: the z extent taken from the spines equals the one the general polish finds when the patches
    are not known to be level (to 1e-12 mm), holds every point of a dense solid-map grid and comes within
    1e-3 mm of the highest and lowest."""
    t = shaped[name].trimmed(u=u, v=v, w=w)
    lo, hi = t._bounds_sampled()
    with monkeypatch.context() as m:
        m.setattr(PDEPatch, "level", property(lambda self: False))
        lo2, hi2 = t._bounds_sampled()
    np.testing.assert_allclose([lo[2], hi[2]], [lo2[2], hi2[2]], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(np.concatenate([lo[:2], hi[:2]]), np.concatenate([lo2[:2], hi2[:2]]))
    uu, vv, ww = np.linspace(*t.trim.u, 61), np.linspace(*t.trim.v, 121), np.linspace(*t.trim.w, 2)
    z = np.concatenate([solid_map(p, uu[:, None, None], vv[None, :, None], ww[None, None, :])[..., 2].ravel()
                        for p in t.patches])
    assert lo[2] <= z.min() + 1e-12 and z.max() <= hi[2] + 1e-12
    assert z.min() - lo[2] <= 1e-3 and hi[2] - z.max() <= 1e-3


def test_a_patch_with_a_tilted_datum_is_not_level():
    """Circles and ellipses at heights are flat, and stay flat moved, turned about z or scaled; tilted (a
    z that takes from y) the curve is not, nor is its patch, which takes the general polish."""
    data = [Circle(4.0, (0, 0, 0)), Circle(4.5, (0, 0, 1)), Ellipse(4.5, 4.0, (0, 0, 2)), Circle(3.5, (0, 0, 3))]
    assert PDEPatch(tuple(data), a=0.5).level
    c, s = np.cos(0.3), np.sin(0.3)
    turned = data[2].moved((0.1, 0.2, 0.3))
    turned = type(turned)(turned, np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]), np.zeros(3))
    assert turned.flat and PDEPatch((data[0], data[1], turned, data[3]), a=0.5).level
    tilted = type(turned)(data[2], np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]), np.zeros(3))
    assert not tilted.flat
    p = PDEPatch((data[0], data[1], tilted, data[3]), a=0.5, check=False)  # (it folds: only its z matters here)
    assert not p.level
    u, v = np.linspace(0, 1, 7), np.linspace(0, 6, 11)
    assert np.ptp(p.evaluate_grid(u, v)[..., 2], axis=1).max() > 0.1  # its z does change with v
