"""FE in optimisation: the strongest 10 mm concave round of a given volume (samples/optimise/strongest_concave_round_fe.toml).

The problem file's objective is the coarse-mesh FE breaking force (``fe_breaking_force_N``, σ_t = 2 MPa,
across the width), band and cup depth vary, the volume is held at 289.1 mm³.  The run is checked against
evaluations made independently of the solver: the start and a grid of feasible designs (cup depths 0.5 to
1.5 mm, the band solved for the volume).  Remeshing gives the coarse force about 1 % of scatter between
neighbouring designs, so "at least as strong" is asserted with a 2 % tolerance (``SCATTER``); the
re-check on the default (finer) mesh must agree with the coarse value within 10 % (``RECHECK``).
"""

from __future__ import annotations

from pathlib import Path

import pytest

pytestmark = [pytest.mark.fe, pytest.mark.slow]
pytest.importorskip("skfem")
pytest.importorskip("gmsh")
pytest.importorskip("OCP")

SAMPLE = Path(__file__).resolve().parents[1] / "samples" / "optimise" / "strongest_concave_round_fe.toml"
#: Relative scatter of the coarse-mesh force between neighbouring designs that the comparisons allow.
SCATTER = 0.02
#: Largest relative difference between the optimum's coarse-mesh force and its default-mesh re-check.
RECHECK = 0.10


def test_problem_file_with_the_fe_objective_is_checked():
    from tabletcad.errors import DesignError
    from tabletcad.optimise.files import problem_from_dict

    base = {"problem": {"kind": "family", "family": "concave_round", "objective": "fe_breaking_force_N"},
            "variables": {"band": {"lower": 2.0, "upper": 3.0}}, "fixed": {"diameter": 10.0, "cup_depth": 0.9}}
    with pytest.raises(DesignError, match=r"\[fe\] tensile_strength_MPa = 'missing' is not allowed"):
        problem_from_dict(base)
    with pytest.raises(DesignError, match=r"\[fe\] tensile_strength_MPa = -2 MPa is not allowed: must be a finite number > 0"):
        problem_from_dict({**base, "fe": {"tensile_strength_MPa": -2}})
    with pytest.raises(DesignError, match=r"\[fe\] direction = 'diagonal' is not allowed"):
        problem_from_dict({**base, "fe": {"tensile_strength_MPa": 2.0, "direction": "diagonal"}})
    with pytest.raises(DesignError, match=r"\[fe\] = 'given' is not allowed: only problems using fe_breaking_force_N"):
        problem_from_dict({**base, "problem": {**base["problem"], "objective": "volume_mm3"},
                           "fe": {"tensile_strength_MPa": 2.0}})
    prob, _, _ = problem_from_dict({**base, "fe": {"tensile_strength_MPa": 2.0}})
    assert prob.objective.unit == "N" and prob.extras is not None


def test_strongest_concave_round_of_a_given_volume():
    from scipy.optimize import brentq

    from tabletcad.fe.objective import breaking_force
    from tabletcad.optimise.files import load_problem
    from tabletcad.optimise.solvers import solve

    prob, method, opts = load_problem(SAMPLE)
    res = solve(prob, method, **opts)
    assert res.success, res.message
    vol = next(c for c in res.constraints if c.name == "volume_mm3")
    assert vol.value == pytest.approx(289.1, rel=1e-6)

    def force(x):
        return breaking_force(prob.build(x), 2.0, "width")

    start = force(prob.x0())
    grid = {}
    for cup in (0.5, 0.75, 1.0, 1.25, 1.5):
        band = brentq(lambda b: prob.build({"band": b, "cup_depth": cup}).volume() - 289.1, 2.0, 3.6, xtol=1e-9)
        grid[(round(band, 4), cup)] = force({"band": band, "cup_depth": cup})
    ex = res.extras
    print(f"\n{res.status}: x = {res.x}, coarse force {res.objective:.2f} N ({res.nfev} builds, {res.wall_time_s:.0f} s); "
          f"start {start:.2f} N; feasible grid (band, cup) -> N: "
          + ", ".join(f"{k}: {v:.2f}" for k, v in grid.items())
          + f"; re-check on the default mesh {ex['fe_breaking_force_fine_N']:.2f} N "
            f"({100 * ex['fe_fine_minus_coarse_relative']:+.1f} %)")
    assert res.objective >= start
    assert res.objective >= (1 - SCATTER) * max(grid.values())
    assert ex["fe_breaking_force_coarse_N"] == pytest.approx(res.objective, rel=SCATTER)
    assert abs(ex["fe_fine_minus_coarse_relative"]) < RECHECK
