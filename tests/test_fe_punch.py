"""Punch-tip stress: uniform F/A for a flat tip, cups lower the rating, column buckling, cited steels."""

from __future__ import annotations

import math

import numpy as np
import pytest

pytestmark = pytest.mark.fe
pytest.importorskip("skfem")
pytest.importorskip("gmsh")
pytest.importorskip("OCP")

from tabletcad.fe.elasticity import von_mises  # noqa: E402
from tabletcad.fe.punch import column_buckling, punch_stress, punch_tip_solid, tool_steels  # noqa: E402
from tabletcad.tooling.spec import parse_tooling  # noqa: E402

TOOLING = {"clearance_mm": 0.02, "tip_length_mm": 6.0}


def _tip(**tablet):
    from tabletcad.pipeline.design import design_from_dict

    t = design_from_dict({"tablet": tablet})
    return punch_tip_solid(t, parse_tooling(TOOLING), "upper")


@pytest.fixture(scope="module")
def flat_tip():
    return _tip(family="flat_face_round", diameter=8.0, thickness=3.0)


def test_flat_tip_carries_the_uniform_stress(flat_tip):
    shape, info = flat_tip
    # one element size everywhere: the cup face and the back face are the same polygon; between them the
    # faceted side wall's sections vary by the polygon error (~1 %), so the stress is uniform to that level
    r = punch_stress(shape, info, 20.0, yield_MPa=1450.0, safety_factor=1.5, mesh_size=1.0, face_refinement=1.0)
    A = math.pi * (4.0 - 0.02) ** 2
    assert r.back_area_mm2 == pytest.approx(A, rel=0.015)  # inscribed polygon of ~25 sides: -(2π/25)²/6
    # the two faces' boundary circles are meshed as separate curves: gmsh 4.15.2 puts their nodes 1e-9
    # (relative) apart, so the two polygons' areas agree to that, against a 1 % polygon error
    assert r.axial_area_mm2 == pytest.approx(r.back_area_mm2, rel=1e-6)
    assert r.uniform_stress_MPa == pytest.approx(20000.0 / r.back_area_mm2)
    # the largest stress is where a section of the faceted wall falls short of the back face's polygon,
    # by at most an inscribed polygon's error, (2π/n)²/6 for n = perimeter / element size sides (1.05 %
    # here; a rounding-level change of the tablet moves gmsh's nodes and the peak within it)
    polygon = (2.0 * math.pi / (math.tau * (4.0 - 0.02) / 1.0)) ** 2 / 6.0
    assert r.uniform_stress_MPa * (1.0 - 0.01) <= r.max_von_mises_MPa <= r.uniform_stress_MPa * (1.0 + polygon + 2e-3)
    vm = von_mises(r.solution.vertex_stress)
    assert np.median(vm) == pytest.approx(r.uniform_stress_MPa, rel=0.003)
    assert r.reaction_N < 1e-7 * 20000.0
    # rating: yield / S / (σ per N), or the buckling force / S if lower (Johnson's parabola for a stubby tip)
    d = r.to_dict()
    assert r.buckling["method"] == "Johnson"
    assert r.allowed_force_kN == pytest.approx(min(d["allowed_force_yield_kN"], r.buckling["critical_force_kN"] / 1.5))
    # against the true circle's area: the back polygon's shortfall plus the wall's, each at most `polygon`
    assert d["allowed_force_yield_kN"] == pytest.approx(1450.0 / 1.5 * A / 1000.0, rel=2.0 * polygon + 2e-3)


def test_cup_depth_lowers_the_rating(flat_tip):
    rated = {}
    for cup, (shape, info) in [(0.0, flat_tip),
                               (0.6, _tip(family="concave_round", diameter=8.0, band=2.0, cup_depth=0.6, land=0.1)),
                               (1.2, _tip(family="concave_round", diameter=8.0, band=2.0, cup_depth=1.2, land=0.1))]:
        r = punch_stress(shape, info, 20.0, yield_MPa=1450.0, mesh_size=1.0)
        rated[cup] = r.allowed_force_kN
        print(f"\ncup depth {cup} mm: max von Mises {r.max_von_mises_MPa:.4g} MPa (F/A {r.uniform_stress_MPa:.4g}),"
              f" allowed {r.allowed_force_kN:.4g} kN, {r.dofs} unknowns")
    assert rated[0.0] > rated[0.6] > rated[1.2]


def test_column_buckling_euler_johnson_and_their_junction():
    E, sy = 206000.0, 1450.0
    d = 2.0
    A, I = math.pi * d**2 / 4, math.pi * d**4 / 64
    slender = column_buckling(A, I, 40.0, E, sy, K=2.0)
    assert slender["method"] == "Euler"
    assert slender["critical_force_N"] == pytest.approx(math.pi**2 * E * I / 80.0**2)
    stubby = column_buckling(A, I, 5.0, E, sy, K=2.0)
    assert stubby["method"] == "Johnson" and stubby["critical_force_N"] < A * sy
    # both formulas give A σy / 2 at the transition slenderness
    lam_c = math.pi * math.sqrt(2 * E / sy)
    L = lam_c * (d / 4) / 2.0
    at = column_buckling(A, I, L, E, sy, K=2.0)
    assert at["critical_force_N"] == pytest.approx(A * sy / 2, rel=1e-9)
    below = column_buckling(A, I, L * (1 - 1e-9), E, sy, K=2.0)
    assert below["method"] == "Johnson" and below["critical_force_N"] == pytest.approx(A * sy / 2, rel=1e-6)


def test_every_steel_number_has_a_source():
    steels = tool_steels()
    assert steels
    for s in steels.values():
        assert s.yield_MPa > 0 and s.E_MPa > 0
        assert s.yield_source.startswith("https://") and s.E_source.startswith("https://")
    assert steels["S7_tempered_205C"].yield_MPa == 1450
