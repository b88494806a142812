"""Tensile strength formulas (eqs 2.4-2.11) and their validity warnings."""

from __future__ import annotations

import math
import warnings

import pytest

from tabletcad.errors import DesignError
from tabletcad.mechanics import strength as st
from tabletcad.mechanics.materials import get_material
from tabletcad.mechanics.validity import ValidityWarning


def _quiet(fn, *a, **k):
    with warnings.catch_warnings():
        warnings.simplefilter("error", ValidityWarning)
        return fn(*a, **k)


def test_flat_faced():
    assert _quiet(st.diametral_flat, 100.0, 10.0, 3.0) == pytest.approx(200 / (math.pi * 30))
    assert _quiet(st.axial_flat, 100.0, 10.0) == pytest.approx(400 / (math.pi * 100))


def test_pitt_printed_form_equals_usual_form():
    F, D, t, W = 120.0, 10.0, 4.0, 2.2
    printed = 50 * F / (math.pi * D**2 * (71 * t / (5 * D) - 63 * t / (100 * W) + 63 * W / (4 * D) + 1 / 20))
    assert _quiet(st.pitt_convex, F, D, t, W) == pytest.approx(printed, rel=1e-12)


@pytest.mark.parametrize("t_over_D", [0.1, 0.2, 0.3])
def test_pitt_at_w_equal_t_versus_flat_faced(t_over_D):
    """At W = t eq 2.7 is the flat-disc formula times 5 (t/D) / (5.99 t/D - 0.116)."""
    D = 10.0
    t = t_over_D * D
    ratio = st.pitt_convex(50.0, D, t, t) / st.diametral_flat(50.0, D, t)
    assert ratio == pytest.approx(5 * t_over_D / (5.99 * t_over_D - 0.116), rel=1e-12)
    assert abs(ratio - 1.0) < 0.12  # same family, within 12 % over the usual range


def test_elongated_is_two_thirds():
    assert _quiet(st.pitt_heasley_elongated_flat, 90.0, 8.0, 4.0, length=16.0) == pytest.approx(
        2 / 3 * st.diametral_flat(90.0, 8.0, 4.0))
    assert _quiet(st.pitt_heasley_elongated_convex, 90.0, 8.0, 4.0, 2.0, length=16.0) == pytest.approx(
        2 / 3 * st.pitt_convex(90.0, 8.0, 4.0, 2.0))
    assert _quiet(st.pitt_heasley_elongated_flat, 90.0, 8.0, 4.0, length=8.0 * 1.7) > 0


def test_podczeck_equals_flat_formula_with_total_thickness():
    assert _quiet(st.podczeck_convex, 80.0, 10.0, 4.0, W=2.0, R=10.0) == pytest.approx(
        st.diametral_flat(80.0, 10.0, 4.0))


@pytest.mark.parametrize(
    "call,match",
    [
        (lambda: st.pitt_convex(10, 10, 6, 5), "W/D"),
        (lambda: st.pitt_heasley_elongated_flat(10, 8, 4, length=10), "length/width"),
        (lambda: st.podczeck_convex(10, 10, 4, W=0.3), "W/D"),
        (lambda: st.podczeck_convex(10, 10, 4, R=3.0), "D/R"),
        (lambda: st.diametral_flat(10, 5, 6), "exceeds diameter"),
    ],
)
def test_validity_warnings(call, match):
    with pytest.warns(ValidityWarning, match=match):
        call()


def test_a_band_thicker_than_the_tablet_is_refused():
    """No tablet has a band thicker than itself: refused (it was a warning and a strength)."""
    for call in (lambda: st.pitt_convex(10, 20, 4, 4.5), lambda: st.pitt_heasley_elongated_convex(10, 8, 4, 4.5, 12)):
        with pytest.raises(DesignError, match=r"band\.thickness = 4\.5 mm is not allowed: must be <= the total thickness t = 4 mm"):
            call()
    assert st.pitt_convex(10, 20, 4, 4) > 0  # a band as thick as the tablet: a flat-faced one


def test_bad_input_raises_design_error():
    with pytest.raises(DesignError, match="diameter"):
        st.diametral_flat(10, -1, 3)
    with pytest.raises(DesignError, match="force"):
        st.axial_flat(0, 10)


def test_sphere_hertz_and_table_6_2_contact_radii():
    """Eq 2.11 gives the contact radii of Table 6.2 (0.0883 and 0.0948 mm for r = 0.7047 and 0.7561 mm)."""
    k = get_material("kostrolith")
    from tabletcad.mechanics.contact import contact_radius_at_yield

    assert contact_radius_at_yield(k.E, k.nu, 0.7047, k.s_y) == pytest.approx(0.0883, abs=5e-5)
    assert contact_radius_at_yield(k.E, k.nu, 0.7561, k.s_y) == pytest.approx(0.0948, abs=5e-5)
    rc = contact_radius_at_yield(k.E, k.nu, 0.7047, k.s_y)
    sigma = _quiet(st.sphere_hertz, 8.6, k.E, k.nu, 0.7047, k.s_y)
    assert sigma == pytest.approx(8.6 * (1 - 2 * k.nu) / (2 * math.pi * rc**2), rel=1e-12)
    # eq 6.7 is eq 2.10 rewritten: 2E²F(1-2ν)/(π³ r² (s_y (1-ν²))²)
    eq67 = 2 * k.E**2 * 8.6 * (1 - 2 * k.nu) / (math.pi**3 * 0.7047**2 * (k.s_y * (1 - k.nu**2)) ** 2)
    assert sigma == pytest.approx(eq67, rel=1e-12)
