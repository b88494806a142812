"""Contact laws (eqs 2.1, 5.19-5.26), their inverses and the thesis's Köstrolith check."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tabletcad.errors import DesignError
from tabletcad.mechanics import contact as ct
from tabletcad.mechanics.materials import get_material, load_materials


def test_materials_table_5_2():
    lac, kos = get_material("lactose"), get_material("Köstrolith")
    assert (lac.radius, lac.E, lac.nu, lac.s_y) == (0.1, 2080.0, 0.30, 616.6)
    assert (kos.radius, kos.E, kos.nu, kos.s_y) == (0.7, 820.0, 0.28, 71.007)
    assert "Table 5.2" in kos.cited
    assert get_material("koestrolith") is kos
    assert "alpha_lactose_monohydrate" in load_materials()
    with pytest.raises(DesignError, match="must be one of"):
        get_material("unobtainium")


def test_yield_displacement_inverts_eq_5_22():
    m = get_material("kostrolith")
    wy = ct.yield_displacement(m.E, m.nu, m.radius, m.s_y)
    assert ct.micro_yield_strength(m.E, m.nu, m.radius, wy) == pytest.approx(m.s_y, rel=1e-13)
    # eq 2.11 is eq 5.23 at the yield point
    assert ct.contact_radius_at_yield(m.E, m.nu, m.radius, m.s_y) == pytest.approx(
        float(ct.contact_radius(wy, m.radius)), rel=1e-13)


@settings(max_examples=60, deadline=None)
@given(
    r_s=st.floats(0.05, 5.0),
    s_y=st.floats(1.0, 1000.0),
    ratio=st.floats(1.0, 1e4),
    wy_frac=st.floats(1e-4, 0.2),
)
def test_eq_5_20_inverts_eq_2_1(r_s, s_y, ratio, wy_frac):
    """The printed closed form 5.20-5.21, Cardano and brentq all invert eq 2.1."""
    wy = wy_frac * r_s
    F = ct.yield_force(r_s, s_y, wy) * ratio
    w_printed = ct.elastic_plastic_displacement_printed(F, r_s, s_y, wy)
    w_cardano = ct.elastic_plastic_displacement_cardano(F, r_s, s_y, wy)
    w_brent = ct.elastic_plastic_displacement(F, r_s, s_y, wy)
    for w in (w_printed, w_cardano, w_brent):
        assert float(ct.elastic_plastic_force(w, r_s, s_y, wy)) == pytest.approx(F, rel=1e-9)
    assert float(w_printed) == pytest.approx(float(w_brent), rel=1e-9)
    assert float(w_cardano) == pytest.approx(float(w_brent), rel=1e-9)


def test_elastic_plastic_law_below_yield_is_rejected():
    with pytest.raises(DesignError, match="yield"):
        ct.elastic_plastic_force(0.001, 0.7, 71.0, 0.011)
    with pytest.raises(DesignError, match="yield force"):
        ct.elastic_plastic_displacement_cardano(0.1, 0.7, 71.0, 0.011)


def test_hertz_inverse_and_jump_at_yield():
    m = get_material("kostrolith")
    w = np.linspace(0, 0.01, 7)
    assert np.allclose(ct.hertz_displacement(ct.hertz_force(w, m.E, m.nu, m.radius), m.E, m.nu, m.radius), w)
    c = ct.force_displacement_curve(m, 0.1)
    # the printed eq 5.19 and eq 2.1 differ by sqrt(2) at the yield point
    assert c.force_at_yield_ep / c.force_at_yield_hertz == pytest.approx(math.sqrt(2), rel=1e-12)
    assert c.force_at_yield_ep == pytest.approx(0.5726, abs=1e-4)
    # force is monotone on each side of the jump
    assert np.all(np.diff(c.force[c.omega < c.omega_y]) > 0) and np.all(np.diff(c.force[c.omega >= c.omega_y]) > 0)
    assert float(ct.displacement(0.5, m)) == pytest.approx(c.omega_y)  # inside the jump


def test_kostrolith_3_5_N_check():
    """Thesis section 5.3.2: theoretical height 1.3444 mm and '0.1395' at 3.5 N."""
    cs = ct.compress_sphere(3.5, "kostrolith")
    assert cs.height == pytest.approx(1.3444, abs=5e-5)
    assert cs.displacement == pytest.approx(0.05563, abs=1e-5)
    # the quoted 0.1395 is sqrt(r_s ω / 2) in mm, not an area from eq 5.23
    assert cs.contact_radius_per_contact == pytest.approx(0.1395, abs=5e-5)
    assert math.pi * cs.contact_radius**2 == pytest.approx(0.1223, abs=1e-4)


def test_compressed_sphere_circles():
    cs = ct.compress_sphere(3.5, "kostrolith")
    r = cs.radius
    radii = np.array([c[0] for c in cs.circles])
    z = np.array([c[1] for c in cs.circles])
    assert len(cs.circles) == 7
    assert z[0] == 0.0 and z[-1] == pytest.approx(cs.height) and z[3] == pytest.approx(cs.height / 2)
    assert radii[3] == r and np.all(np.diff(z) > 0)
    # every circle lies on the undeformed sphere centred at h/2
    assert np.allclose(radii**2 + (z - cs.height / 2) ** 2, r * r)
    assert cs.flat_radius == pytest.approx(cs.contact_radius, rel=0.02)
    # zero force: the 30° circles of eq 4.1 and eq 4.3 for r = 2.5 mm
    s = ct.compress_sphere(0.0, "kostrolith", radius=2.5)
    assert [round(c[0], 2) for c in s.circles] == [0.0, 1.25, 2.17, 2.5, 2.17, 1.25, 0.0]
    assert [round(c[1] - 2.5, 2) for c in s.circles] == [-2.5, -2.17, -1.25, 0.0, 1.25, 2.17, 2.5]


def test_contact_radius_curve_starts_at_yield():
    F, rc = ct.contact_radius_curve("lactose", np.linspace(0.1, 10, 50))
    assert F.min() >= ct.yield_force(0.1, 616.6, ct.yield_displacement(2080, 0.3, 0.1, 616.6))
    assert np.all(np.diff(rc) > 0)


def test_plots(tmp_path):
    c = [ct.force_displacement_curve(m, 0.05) for m in ("lactose", "kostrolith")]
    p = ct.plot_force_displacement(c, tmp_path / "fd.png")
    q = ct.plot_contact_radius({"Köstrolith": ct.contact_radius_curve("kostrolith", np.linspace(0.5, 9, 30))},
                               tmp_path / "rc.svg")
    assert p.stat().st_size > 1000 and "Contact radius" in q.read_text()


def test_compressed_sphere_tablet():
    t = ct.compressed_sphere_tablet(3.5, "kostrolith")
    dims = t.dimensions()
    assert dims["height_mm"] == pytest.approx(1.3444, abs=5e-5)
    assert dims["width_mm"] == pytest.approx(1.4, abs=0.01)
