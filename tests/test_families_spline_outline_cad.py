"""Custom outlines through points build into watertight, checked solids (CAD stage).

The outline's own regularity (the cup stops short of the smallest radius of curvature) is
tested without CAD in ``test_families_spline_outline.py``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from tabletcad.families import outline_tablet
from tabletcad.families.outline import SplineOutline
from test_families_spline_outline import ellipse_points

pytestmark = pytest.mark.cad

pytest.importorskip("OCP")
pytest.importorskip("manifold3d")
pytest.importorskip("trimesh")


def _check(tablet):
    from tabletcad.cad.stage import AGREEMENT_REL, check_tablet_solid

    solid, mesh, sec = check_tablet_solid(tablet)  # raises GeometryError on any failed check
    assert sec["mesh"]["watertight"] and sec["mesh"]["manifold"] and sec["mesh"]["genus"] == 0
    assert abs(sec["brep"]["volume_rel_diff_vs_quadrature"]) <= AGREEMENT_REL
    assert abs(sec["mesh"]["volume_rel_diff_vs_brep"]) < 2e-3
    return sec


@pytest.mark.cad
def test_v025_like_outline_builds_through_the_cli(tmp_path, capsys):
    """The issue's design: 20 points on a smooth closed 9 x 6 mm curve, cup 0.19 mm, default cup width."""
    import json

    from tabletcad.cli import main

    pts = ellipse_points().tolist()
    d = tmp_path / "v025.toml"
    d.write_text(f'[tablet]\nfamily = "custom_outline"\noutline = {pts}\nband = 2.5\ncup_depth = 0.19\n')
    assert main(["build", str(d), "--out", str(tmp_path / "out"), "--quiet"]) == 0, capsys.readouterr().err
    rep = json.loads((tmp_path / "out" / "report.json").read_text())
    assert rep["mesh"]["watertight"] is True and rep["mesh"]["genus"] == 0
    assert abs(rep["brep"]["volume_rel_diff_vs_quadrature"]) <= 1e-6
    assert rep["length_mm"] == pytest.approx(9.0, abs=0.01) and rep["width_mm"] == pytest.approx(6.0, abs=0.01)


hypothesis = pytest.importorskip("hypothesis")
from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402


@st.composite
def smooth_outlines(draw):
    """Points on a smooth star-shaped closed curve: an ellipse of 7-12 x 4-8 mm whose radius is
    perturbed by modes 2-4 (amplitudes up to 6 %), sampled at 12-30 points; a cup 5-60 % as deep
    as the default cup is wide."""
    n = draw(st.integers(12, 30))
    a = draw(st.floats(3.5, 6.0))
    b = draw(st.floats(2.0, min(a, 4.0)))
    amps = [draw(st.floats(-0.06, 0.06)) for _ in range(3)]
    phases = [draw(st.floats(0.0, 2.0 * math.pi)) for _ in range(3)]
    frac = draw(st.floats(0.05, 0.6))  # cup depth over the cup width (at most a hemisphere)
    t = 2.0 * np.pi * np.arange(n) / n
    r = 1.0 + sum(A * np.cos((m + 2) * t + p) for m, (A, p) in enumerate(zip(amps, phases)))
    pts = np.round(np.column_stack([a * r * np.cos(t), b * r * np.sin(t)]), 4)
    ol = SplineOutline(pts)
    return pts, frac * min(ol.min_convex_radius, ol.inscribed_radius())


@pytest.mark.cad
@pytest.mark.slow
@settings(max_examples=6, deadline=None)
@given(smooth_outlines())
def test_random_smooth_outlines_give_watertight_solids(case):
    pts, cup = case
    tablet = outline_tablet(pts, band=2.5, cup_depth=cup, name="random_outline")
    _check(tablet)
