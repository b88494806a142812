"""Areas and volumes of family tablets against closed forms (issue 6).

Closed forms used (lengths in mm):

* spherical cap of base radius ``a`` and height ``h``: volume ``πh(3a² + h²)/6``,
  curved area ``π(a² + h²)``;
* circular segment (chord ``2a``, height ``h``, radius ``ρ``): area
  ``ρ² acos((ρ-h)/ρ) - (ρ-h)√(2ρh - h²)``, arc length ``2ρ asin(a/ρ)``;
* frustum of a cone (radii ``R``, ``r``, height ``d``): volume ``πd(R² + Rr + r²)/3``,
  lateral area ``π(R + r)√((R-r)² + d²)``;
* Pappus for the radius edge: a quarter disc of radius ``ρ`` revolved at centroid
  radius ``R - ρ + 4ρ/(3π)`` and a quarter arc at ``R - ρ + 2ρ/π``.
"""

from __future__ import annotations

import math

import pytest

from tabletcad.families import capsule, concave_round, ffbe, ffre, flat_face_round, sweep_properties

REL = 1e-5


def cap(a: float, h: float) -> tuple[float, float]:
    return math.pi * h * (3 * a * a + h * h) / 6.0, math.pi * (a * a + h * h)


def _check(tablet, V, A, rel=REL):
    cert = tablet.nominal.certificate
    assert cert.passed and cert.max_deviation_mm <= 1e-3
    # the deviation bound: |ΔV| <= area · max deviation; we require the tighter 1e-5 relative
    q = sweep_properties(tablet)
    assert q["volume_mm3"] == pytest.approx(V, rel=rel)
    assert q["surface_area_mm2"] == pytest.approx(A, rel=rel)
    assert abs(q["volume_mm3"] - V) <= A * cert.max_deviation_mm + 1e-9 * V
    return q


@pytest.mark.parametrize("D,band,h,land", [(10.0, 3.0, 1.0, 0.0), (10.0, 2.8, 0.9, 0.08), (6.0, 2.0, 1.2, 0.3), (12.0, 3.5, 5.5, 0.0)])
def test_concave_round_against_spherical_caps(D, band, h, land):
    t = concave_round(D, band, h, land)
    R = D / 2
    a = R - land
    Vc, Ac = cap(a, h)
    V = math.pi * R * R * band + 2 * Vc
    A = 2 * math.pi * R * band + 2 * (math.pi * (R * R - a * a) + Ac)
    q = _check(t, V, A)
    assert q["cup_volume_mm3"] == pytest.approx(Vc, rel=REL)
    assert q["plan_area_mm2"] == pytest.approx(math.pi * R * R, rel=1e-12)
    # the core quadrature agrees too (circles: spectrally accurate in v)
    p = t.properties()
    assert p["volume_mm3"] == pytest.approx(V, rel=REL)
    assert p["surface_area_mm2"] == pytest.approx(A, rel=REL)
    assert t.solid_volume() == pytest.approx(V, rel=REL)


def test_flat_face_round_is_a_cylinder():
    t = flat_face_round(8.0, 3.0)
    _check(t, math.pi * 16 * 3, 2 * math.pi * 16 + 2 * math.pi * 4 * 3, rel=1e-9)


@pytest.mark.parametrize("D,T,ang,w", [(10.0, 4.0, 30.0, 0.5), (9.0, 3.6, 40.0, 0.4), (12.0, 5.0, 20.0, 1.2)])
def test_ffbe_against_frustum(D, T, ang, w):
    t = ffbe(D, T, ang, w, 0.0)
    R = D / 2
    r = R - w
    d = w * math.tan(math.radians(ang))
    band = T - 2 * d
    V = math.pi * R * R * band + 2 * (math.pi * d * (R * R + R * r + r * r) / 3)
    A = 2 * math.pi * R * band + 2 * (math.pi * (R + r) * math.hypot(w, d) + math.pi * r * r)
    _check(t, V, A, rel=1e-9)


@pytest.mark.parametrize("D,T,re", [(10.0, 4.0, 1.0), (8.0, 3.2, 0.8), (6.0, 2.0, 1.0)])
def test_ffre_against_pappus(D, T, re):
    t = ffre(D, T, re)
    R = D / 2
    corner = math.pi * (R * R - (R - re) ** 2) * re
    quarter_disc = 2 * math.pi * (R - re + 4 * re / (3 * math.pi)) * (math.pi * re * re / 4)
    V = math.pi * R * R * T - 2 * (corner - quarter_disc)
    arc = 2 * math.pi * (R - re + 2 * re / math.pi) * (math.pi * re / 2)
    A = 2 * math.pi * R * (T - 2 * re) + 2 * (math.pi * (R - re) ** 2 + arc)
    _check(t, V, A)


@pytest.mark.parametrize("L,W,band,h,land", [(18.0, 8.0, 3.0, 1.2, 0.2), (14.0, 7.0, 2.5, 3.0, 0.0)])
def test_capsule_against_cylinder_segment_and_cap(L, W, band, h, land):
    t = capsule(L, W, band, h, land)
    s = L - W
    r = W / 2
    a = r - land
    rho = (a * a + h * h) / (2 * h)
    seg = rho * rho * math.acos((rho - h) / rho) - (rho - h) * math.sqrt(2 * rho * h - h * h)
    arc = 2 * rho * math.asin(a / rho)
    plan = s * W + math.pi * r * r
    perim = 2 * s + math.pi * W
    Vc, Ac = cap(a, h)
    cup_v = Vc + s * seg
    cup_a = Ac + s * arc
    land_area = plan - (2 * a * s + math.pi * a * a)
    V = plan * band + 2 * cup_v
    A = perim * band + 2 * (land_area + cup_a)
    q = _check(t, V, A)
    assert q["cup_volume_mm3"] == pytest.approx(cup_v, rel=REL)
    assert q["plan_area_mm2"] == pytest.approx(plan, rel=1e-9)
    assert t.nominal.outline.perimeter == pytest.approx(perim, rel=1e-12)
