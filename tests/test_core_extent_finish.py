"""The extents' zoom ends with one Newton step from its grid's central differences
(:meth:`~tabletcad.geometry.tablet.Tablet._newton_finish`): the extents equal those of a zoom carried
on to a step 10,000 times finer, on whole and trimmed tablets of every kind of sample."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import tabletcad.geometry.tablet as tablet_module
from tabletcad.pipeline.design import Design

ROOT = Path(__file__).resolve().parents[1]
SAMPLES = ["families/capsule", "families/almond", "families/rounded_triangle", "families/oval", "families/ffre",
           "oblate_spheroid", "free_form_stadium", "caplet"]
TRIMS = [{}, {"v": (0.3, 2.0)}, {"u": (0.0, 0.6)}]


@pytest.mark.parametrize("name", SAMPLES)
def test_extents_equal_a_zoom_carried_on_to_a_step_of_1e_10(name, monkeypatch):
    whole = Design.from_toml(ROOT / "samples" / f"{name}.toml").build()
    finishes = []
    step = tablet_module.Tablet._newton_finish

    def counted(self, *args):
        out = step(self, *args)
        finishes.append(out is not None)
        return out

    for trim in TRIMS:
        t = whole.trimmed(**trim) if trim else whole
        with monkeypatch.context() as m:
            m.setattr(tablet_module.Tablet, "_newton_finish", counted)
            lo, hi = t._bounds_sampled()
        with monkeypatch.context() as m:  # the reference: no Newton step, the zoom on to 1e-10
            m.setattr(tablet_module, "_NEWTON_FINISH", 0.0)
            m.setattr(tablet_module, "_ZOOM_STOP", 1e-10)
            lo_ref, hi_ref = t._bounds_sampled()
        np.testing.assert_allclose(lo, lo_ref, rtol=0.0, atol=5e-14)
        np.testing.assert_allclose(hi, hi_ref, rtol=0.0, atol=5e-14)
    assert any(finishes)  # the step was taken (else this only compared two zooms)
