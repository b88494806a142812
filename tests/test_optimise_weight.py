"""Weight as an optimisation quantity: ``weight_mg`` = volume x solid fraction x true density
(the ``[report]`` table, as the design report weighs a tablet)."""

from __future__ import annotations

import pytest

from tabletcad.optimise.files import problem_from_dict
from tabletcad.optimise.solvers import solve

SF, RHO = 0.85, 1.5
WEIGHT = 300.0
VOLUME = WEIGHT / (SF * RHO)  # 235.294... mm3


def _flat_round(constraint: dict, objective="surface_area_mm2", **problem) -> dict:
    return {
        "problem": {"kind": "family", "family": "thesis.flat_faced_round", "sense": "min", "objective": objective,
                    **problem},
        "variables": {"diameter": {"lower": 4.0, "upper": 14.0, "initial": 10.0},
                      "thickness": {"lower": 1.0, "upper": 8.0, "initial": 3.0}},
        "constraint": [constraint],
        "report": {"solid_fraction": SF, "true_density_mg_mm3": RHO},
    }


def test_a_weight_target_is_the_volume_target_it_stands_for():
    """Min D + T at 300 mg: the PDE flat-faced round's volume is k D² T exactly (the PDE is linear in its
    curves), so the optimum has D = 2T; and it is the optimum of the volume 300 / (0.85 x 1.5) mm3."""
    lin = {"linear": {"diameter": 1.0, "thickness": 1.0}}
    problem, method, _ = problem_from_dict(_flat_round({"quantity": "weight_mg", "target": WEIGHT, "relative": True}, lin))
    res = solve(problem, method, ftol=1e-12, fd_scheme="central")
    assert res.success, res.message
    assert res.x["diameter"] / res.x["thickness"] == pytest.approx(2.0, rel=1e-6)
    assert res.constraints[0].value == pytest.approx(WEIGHT, rel=1e-6)
    by_volume = _flat_round({"quantity": "volume_mm3", "target": VOLUME, "relative": True}, lin)
    del by_volume["report"]
    p2, m2, _ = problem_from_dict(by_volume)
    res2 = solve(p2, m2, ftol=1e-12, fd_scheme="central")
    assert res2.x == pytest.approx(res.x, rel=1e-6)


def test_weight_as_the_objective_is_the_volume_times_the_basis():
    problem, _, _ = problem_from_dict(_flat_round({"quantity": "surface_area_mm2", "upper": 200.0}, "weight_mg"))
    t = problem.build({"diameter": 9.0, "thickness": 3.5})
    assert problem.objective.name == "weight_mg" and problem.objective.unit == "mg"
    assert problem.objective.func(t) == pytest.approx(t.volume() * SF * RHO, rel=1e-15)


def test_a_held_weight_solves_the_dimension_for_its_volume():
    """``solve_for = "thickness"`` with ``weight_mg``: every design weighs 300 mg (by the family's nominal
    volume; the PDE tablet's within its certified deviation)."""
    data = _flat_round({"quantity": "length_mm", "lower": 4.0}, solve_for="thickness", weight_mg=WEIGHT)
    del data["variables"]["thickness"]
    problem, _, _ = problem_from_dict(data)
    for d in (7.0, 9.0, 11.0):
        t = problem.build({"diameter": d})
        assert t.volume() * SF * RHO == pytest.approx(WEIGHT, rel=1e-6)
    assert "(300 mg)" in problem.description


def test_the_optimum_file_carries_the_weight_basis_so_its_build_reports_the_weight(tmp_path):
    import json
    import tomllib

    from tabletcad.cli import main

    text = """[problem]
kind = "family"
family = "thesis.flat_faced_round"
sense = "min"
objective = "weight_mg"

[variables]
diameter = { lower = 4.0, upper = 14.0, initial = 10.0 }
thickness = { lower = 1.0, upper = 10.0, initial = 3.0 }

[[constraint]]
quantity = "surface_area_mm2"
lower = 150.0

[report]
solid_fraction = 0.85
true_density_mg_mm3 = 1.5
"""
    f = tmp_path / "weight.toml"
    f.write_text(text, encoding="utf-8")
    assert main(["optimise", str(f), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    design = tomllib.loads((tmp_path / "out" / "optimum.toml").read_text(encoding="utf-8"))
    assert design["report"] == {"solid_fraction": SF, "true_density_mg_mm3": RHO}
    result = json.loads((tmp_path / "out" / "report.json").read_text(encoding="utf-8"))
    built = json.loads((tmp_path / "out" / "tablet" / "report.json").read_text(encoding="utf-8"))
    weight = built["design_report"]["weight_mg"]
    assert weight == pytest.approx(built["volume_mm3"] * SF * RHO, rel=1e-12)
    assert result["objective"]["name"] == "weight_mg" and result["objective"]["unit"] == "mg"
    assert weight == pytest.approx(result["objective"]["value"], rel=1e-9)
