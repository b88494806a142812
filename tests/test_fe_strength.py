"""Breaking-force prediction (elastic first-crack estimate) from a tensile strength or a reference test."""

from __future__ import annotations

import math

import pytest

pytestmark = pytest.mark.fe
pytest.importorskip("skfem")
pytest.importorskip("gmsh")
pytest.importorskip("OCP")

from tabletcad.errors import DesignError  # noqa: E402
from tabletcad.fe.prediction import StrengthInputs, predict_breaking_force  # noqa: E402


def test_reference_of_the_same_shape_predicts_its_own_breaking_force():
    """A thin flat-faced round reference broken at 80 N predicts 80 N for the same tablet (same mesh, same criterion)."""
    from tabletcad.families import flat_face_round

    t = flat_face_round(diameter=8.0, thickness=0.8)
    inputs = StrengthInputs(reference_breaking_force_N=80.0, reference_diameter_mm=8.0, reference_thickness_mm=0.8)
    p = predict_breaking_force(t, inputs, "x", error_estimate=False)
    assert p.breaking_force_N == pytest.approx(80.0, rel=1e-9)
    # and the tensile strength is close to eq 2.4's 2F/(π D t) (Hondros factor, first crack near the centre)
    eq24 = 2 * 80.0 / (math.pi * 8.0 * 0.8)
    assert p.tensile_strength_MPa == pytest.approx(eq24, rel=0.05)
    print(f"\nreference 8 x 0.8 mm at 80 N: σ_t = {p.tensile_strength_MPa:.4g} MPa (eq 2.4: {eq24:.4g} MPa)")


def test_tensile_strength_scales_the_force_linearly():
    from tabletcad.families import flat_face_round

    t = flat_face_round(diameter=8.0, thickness=1.6)
    a = predict_breaking_force(t, StrengthInputs(tensile_strength_MPa=2.0), "x", mesh_size=0.8, error_estimate=False)
    b = predict_breaking_force(t, StrengthInputs(tensile_strength_MPa=3.0), "x", mesh_size=0.8, error_estimate=False)
    assert b.breaking_force_N / a.breaking_force_N == pytest.approx(1.5, rel=1e-12)
    assert a.breaking_force_N <= a.breaking_force_centre_N
    d = a.to_dict()
    assert d["estimate"].startswith("elastic first-crack")


@pytest.mark.parametrize(
    "kw, match",
    [
        ({}, "give it, or all of reference_breaking_force_N"),
        ({"tensile_strength_MPa": -1.0}, "tensile_strength_MPa = -1 MPa is not allowed: must be > 0"),
        # a reference test lacking one input names it (it was "tensile_strength_MPa = 'missing'")
        ({"reference_breaking_force_N": 50.0, "reference_diameter_mm": 10.0},
         r"^report\.reference_thickness_mm = \(not given\) is not allowed: the reference test needs"),
        ({"reference_diameter_mm": 10.0, "reference_thickness_mm": 3.0},
         r"^report\.reference_breaking_force_N = \(not given\)"),
        ({"tensile_strength_MPa": 2.0, "reference_breaking_force_N": 50.0}, "not both"),
        ({"reference_breaking_force_N": 50.0, "reference_diameter_mm": 5.0, "reference_thickness_mm": 6.0},
         "must be <= reference_diameter_mm"),
    ],
)
def test_bad_inputs(kw, match):
    with pytest.raises(DesignError, match=match):
        StrengthInputs(**kw)


def test_inputs_from_the_report_table_command_line_first():
    t = {"tensile_strength_MPa": 1.5, "solid_fraction": 0.85}
    assert StrengthInputs.from_table(t).tensile_strength_MPa == 1.5
    assert StrengthInputs.from_table(t, tensile_strength_MPa=2.5).tensile_strength_MPa == 2.5
    with pytest.raises(DesignError, match="must be a number"):
        StrengthInputs.from_table({"tensile_strength_MPa": "strong"})


def test_design_report_accepts_the_fe_inputs_in_report():
    from tabletcad.pipeline.designreport import ReportOptions

    o = ReportOptions.from_table({"tensile_strength_MPa": 2.0, "reference_breaking_force_N": 80.0,
                                  "reference_diameter_mm": 10.0, "reference_thickness_mm": 3.0})
    assert o.tensile_strength_MPa == 2.0 and o.reference_thickness_mm == 3.0


def test_fe_objective_and_constraint_in_an_optimisation_problem():
    """The coarse-mesh FE prediction plugs into tabletcad.optimise; one evaluation, checked against the API."""
    from tabletcad.families import flat_face_round
    from tabletcad.fe.objective import breaking_force
    from tabletcad.optimise.strength import breaking_force_constraint, breaking_force_objective
    from tabletcad.optimise.problem import Evaluator, Problem, Variable

    prob = Problem(
        name="strongest flat round of a given diameter", variables=(Variable("thickness", 1.5, 3.0, 2.0, "mm"),),
        objective=breaking_force_objective(2.0, "x"),
        build=lambda x: flat_face_round(diameter=8.0, thickness=x["thickness"]),
        constraints=(breaking_force_constraint(2.0, 10.0, "x"),))
    ev = Evaluator(prob)
    t = prob.build(prob.x0())
    direct = breaking_force(t, 2.0, "x")
    assert prob.objective.func(t) == pytest.approx(direct, rel=1e-12)
    assert prob.constraints[0].satisfied(direct)
    # the re-check on the default (finer) mesh
    fine = breaking_force(t, 2.0, "x", coarse=False)
    print(f"\nFE breaking force of an 8 x 2 mm disc at σ_t = 2 MPa: coarse {direct:.4g} N, default mesh {fine:.4g} N")
    assert direct == pytest.approx(fine, rel=0.1)
    assert ev.n == 1
    with pytest.raises(DesignError):
        breaking_force_objective(-1.0)


def test_a_reference_disc_too_thin_to_mesh_is_named_by_its_thickness(capsys):
    """A 10 x 0.01 mm reference compact needs a mesh far beyond memory: the refusal named --mesh-size,
    which was not given; it names the reference thickness now (the option, as given)."""
    from pathlib import Path

    from tabletcad.cli import main

    design = Path(__file__).resolve().parents[1] / "samples" / "families" / "concave_round.toml"
    rc = main(["fe", "strength", str(design), "--reference-force", "80", "--reference-diameter", "10",
               "--reference-thickness", "0.01"])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1
    assert err[0].startswith("error: --reference-thickness = 0.01 mm is not allowed: makes a 10 x 0.01 mm reference "
                             "disc that the FE cannot mesh: its mesh size's default for this tablet, "
                             "min(thickness/2, plan width/12) = 0.005 mm, gives about ")
    rc = main(["fe", "strength", str(design), "--reference-force", "80", "--reference-diameter", "10"])
    err = capsys.readouterr().err.strip().splitlines()
    # (the options, not the [report] keys, as the test is begun with options; this had pinned the keys)
    assert rc == 2 and err == ["error: --reference-thickness = (not given) is not allowed: the reference test needs "
                               "all of --reference-force (N), --reference-diameter and --reference-thickness (mm) "
                               "(or give --tensile-strength instead)"]
