"""Inputs a new user gave that were taken silently or refused under another name (second trial).

Each case: the exact ``error: <parameter> = <value> is not allowed: <range>`` line with the name the
user wrote (the option, the file key), exit status 2, nothing written; or, where the input is valid, the
value it must give.  Core only (numpy, scipy): the optimiser runs without the CAD stage.
"""

from __future__ import annotations

import math

import pytest

from tabletcad.cli import main
from tabletcad.errors import DesignError

CONCAVE = """[problem]
kind = "family"
family = "concave_round"
sense = "{sense}"
objective = "volume_mm3"

[variables]
{variables}

[fixed]
{fixed}
"""


def _optimise(tmp_path, capsys, text: str, *extra: str) -> tuple[int, list[str], list[str]]:
    f = tmp_path / "problem.toml"
    f.write_text(text, encoding="utf-8")
    rc = main(["optimise", str(f), "--out", str(tmp_path / "out"), "--quiet", *extra])
    cap = capsys.readouterr()
    return rc, cap.out.strip().splitlines(), cap.err.strip().splitlines()


@pytest.mark.parametrize("variables, fixed, line", [
    # cup_depth neither varied nor fixed: the constructor's default 1.0 mm stood in for it, and the
    # optimum file (without it) could not be built
    ("diameter = { lower = 6.0, upper = 12.0 }", "band = 2.8",
     "error: fixed.cup_depth = (not given) is not allowed: family 'concave_round' needs diameter, band, cup_depth"),
    # band from 0: the solver stopped at 9.1e-12 mm, which no design takes
    ("band = { lower = 0.0, upper = 3.0, initial = 1.0 }", "diameter = 10.0\ncup_depth = 0.9",
     "error: variables.band.lower = 0 mm is not allowed: family 'concave_round' refuses band = 0 (must be > 0)"),
    # (a band of 0 is refused too: "must be 0 or at least 0.001 mm" had offered it)
    ("band = { lower = 0.0005, upper = 3.0 }", "diameter = 10.0\ncup_depth = 0.9",
     "error: variables.band.lower = 0.0005 mm is not allowed: must be at least 0.001 mm"),
    ("land = { lower = 0.0005, upper = 0.2 }", "diameter = 10.0\nband = 2.8\ncup_depth = 0.9",
     "error: variables.land.lower = 0.0005 mm is not allowed: must be 0 or at least 0.001 mm"),
])
def test_family_problem_refused_before_the_solve(tmp_path, capsys, variables, fixed, line):
    rc, out, err = _optimise(tmp_path, capsys, CONCAVE.format(sense="min", variables=variables, fixed=fixed))
    assert rc == 2 and len(err) == 1 and err[0].startswith(line), err
    assert out == [] and sorted(p.name for p in tmp_path.iterdir()) == ["problem.toml"]


@pytest.mark.parametrize("method", ["SLSQP", "trust-constr", "differential_evolution"])
def test_a_length_ending_below_the_least_length_is_put_on_zero(method):
    """Volume grows as the land shrinks: the optimum is land = 0 exactly, whatever the solver.  The
    interior-point solver stopped at 3.3e-4 mm and differential evolution at 6e-9 mm before, lengths no
    design file takes (0 or at least Tolerances.min_length)."""
    from tabletcad.families import concave_round
    import tomllib

    from tabletcad.optimise.files import problem_from_dict
    from tabletcad.optimise.solvers import solve
    from tabletcad.pipeline.design import Design

    text = CONCAVE.format(sense="max", variables="land = { lower = 0.0, upper = 0.3, initial = 0.1 }",
                          fixed="diameter = 10.0\nband = 2.5\ncup_depth = 0.8")
    problem, _, opts = problem_from_dict(tomllib.loads(text))
    r = solve(problem, method, progress=False, **opts)
    assert r.success and r.x["land"] == 0.0
    assert r.objective == pytest.approx(concave_round(diameter=10.0, band=2.5, cup_depth=0.8, land=0.0).volume(),
                                        rel=1e-9)
    d = Design.from_dict({"tablet": dict(family="concave_round", diameter=10.0, band=2.5, cup_depth=0.8,
                                         land=r.x["land"])})
    assert d.build().volume() == pytest.approx(r.objective, rel=1e-12)


def test_starts_with_a_single_start_method_is_refused(tmp_path, capsys):
    text = CONCAVE.format(sense="max", variables="land = { lower = 0.0, upper = 0.3 }",
                          fixed="diameter = 10.0\nband = 2.5\ncup_depth = 0.8")
    rc, out, err = _optimise(tmp_path, capsys, text, "--starts", "3")
    assert rc == 2 and err == ["error: --starts = '3' is not allowed: is read by --method multistart only "
                               "(this run: SLSQP)"]


def test_solve_for_needs_every_dimension_of_a_named_family():
    from tabletcad.families import concave_round
    from tabletcad.families.inverse import solve_for

    with pytest.raises(DesignError) as e:
        solve_for("concave_round", target_volume_mm3=300, vary="band", diameter=10)
    assert str(e.value) == "cup_depth = (not given) is not allowed: concave_round needs diameter, cup_depth besides band"
    # a constructor passed in keeps its defaults (documented)
    r = solve_for(concave_round, target_volume_mm3=300, vary="band", diameter=10)
    assert r.volume_mm3 == pytest.approx(300, rel=1e-9)
    with pytest.raises(DesignError, match=r"true_density_mg_mm3 = 1540 mg/mm3 is not allowed: must be >= 0.1 and <= 25"):
        solve_for("concave_round", target_weight_mg=300, vary="band", diameter=10, cup_depth=1,
                  solid_fraction=0.8, true_density_mg_mm3=1540)


@pytest.mark.parametrize("args, line", [
    # Pitt's eq 2.7 with so thin a band that its denominator is negative: a negative strength was printed
    (["strength", "pitt", "--force", "100", "--diameter", "10", "--thickness", "4.6", "--band", "0.01"],
     "error: --band = 0.01 mm is not allowed: makes eq 2.7's denominator"),
    (["strength", "pitt", "--force", "-100", "--diameter", "10", "--thickness", "4.6", "--band", "1"],
     "error: --force = -100 N is not allowed: must be > 0"),
    (["strength", "pitt", "--force", "100", "--thickness", "4.6", "--band", "1"],
     "error: --diameter = (not given) is not allowed: is required for method 'pitt'"),
    (["strength", "elongated-convex", "--force", "100", "--diameter", "0", "--thickness", "4", "--band", "1"],
     "error: --diameter = 0 mm is not allowed: must be >= 0.001 and <= 1000 mm"),
    # an infinite strength was printed with exit 0; a 1e-9 mm tablet only warned (1.6e10 MPa)
    (["strength", "diametral", "--force", "1e308", "--diameter", "10", "--thickness", "4"],
     "error: --force = 1e+308 N is not allowed: must be > 0 and <= 1e+09 N"),
    (["strength", "diametral", "--force", "100", "--diameter", "1e-9", "--thickness", "4"],
     "error: --diameter = 1e-09 mm is not allowed: must be >= 0.001 and <= 1000 mm"),
])
def test_strength_options_named_as_given(capsys, args, line):
    assert main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(line), err


def test_pitt_denominator_is_the_edge_of_the_formula():
    """eq 2.7 has a value while its denominator is positive and none at or beyond zero."""
    from tabletcad.mechanics.strength import pitt_convex

    D, t, F = 10.0, 4.6, 100.0
    # the denominator's root in W: 3.15 W²/D + (2.84 t/D + 0.01) W - 0.126 t = 0
    a, b, c = 3.15 / D, 2.84 * t / D + 0.01, -0.126 * t
    W0 = (-b + math.sqrt(b * b - 4 * a * c)) / (2 * a)
    assert pitt_convex(F, D, t, W0 * 1.001) > 0
    with pytest.raises(DesignError, match=r"band\.thickness"):
        pitt_convex(F, D, t, W0 * 0.999)


def test_design_report_gives_no_strength_where_the_formula_has_none(capsys, tmp_path):
    rc = main(["report", "samples/families/concave_round.toml", "--solve-for", "band", "--target-volume", "70",
               "--json"])
    assert rc == 0
    import json

    ts = json.loads(capsys.readouterr().out)
    ts = ts[0] if isinstance(ts, list) else ts
    strength = ts["design_report"]["tensile_strength"]
    assert strength["tensile_strength_MPa"] is None and "eq 2.7's denominator" in strength["range_flags"][0]


@pytest.mark.parametrize("args, line", [
    (["--true-density", "1540"], "error: --true-density = 1540 mg/mm3 is not allowed: must be >= 0.1 and <= 25 mg/mm3"),
    # g/mm³ (lactose 0.00154) had been taken: a weight 1000 times low
    (["--true-density", "0.00154"], "error: --true-density = 0.00154 mg/mm3 is not allowed: must be >= 0.1 and <= 25 mg/mm3"),
    (["--solid-fraction", "1.2"], "error: --solid-fraction = 1.2 is not allowed: must be > 0 and <= 1"),
    (["--breaking-force", "inf"], "error: --breaking-force = inf N is not allowed"),
])
def test_report_options_named_as_given(capsys, args, line):
    assert main(["report", "samples/families/concave_round.toml", *args]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(line), err


def test_a_density_in_kg_per_m3_in_the_design_file(tmp_path, capsys):
    d = tmp_path / "d.toml"
    d.write_text('[tablet]\nfamily = "concave_round"\ndiameter = 10.0\nband = 3.0\ncup_depth = 1.0\n\n'
                 '[report]\nsolid_fraction = 0.85\ntrue_density_mg_mm3 = 1540\n')
    assert main(["report", str(d)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["error: report.true_density_mg_mm3 = 1540 mg/mm3 is not allowed: must be >= 0.1 and <= 25 mg/mm3"]


def test_heckel_says_why_no_row_is_left(tmp_path, capsys):
    """A mass far too large makes every row denser than the solid: the refusal says so (it said only
    '0 loading points')."""
    import numpy as np

    P = np.linspace(5.0, 200.0, 60)  # MPa on a 10 mm die
    F = P * math.pi * 25.0
    D = 1.0 - 0.5 * np.exp(-0.01 * P)
    h = 300.0 / (1.5 * math.pi * 25.0 * D)  # 300 mg at 1.5 mg/mm³
    csv = tmp_path / "run.csv"
    csv.write_text("force_N,thickness_mm\n" + "".join(f"{float(f)!r},{float(x)!r}\n" for f, x in zip(F, h)))
    (tmp_path / "run.toml").write_text("mass_mg = 300\ntrue_density = 1.5\ndiameter = 10\n")
    assert main(["heckel", str(csv)]) == 0
    capsys.readouterr()
    assert main(["heckel", str(csv), "--mass", "3000"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "60 loaded row(s) have relative density >= 1" in err[0], err


def test_a_thesis_shapes_smoothing_parameter_is_named_as_written(tmp_path, capsys):
    """``a = 50`` in [tablet] of a thesis shape was reported as
    ``patch.flat_faced_round[0].smoothing.parameter.a``; the file says ``tablet.a``."""
    d = tmp_path / "d.toml"
    d.write_text('[tablet]\nfamily = "thesis.flat_faced_round"\ndiameter = 10\nthickness = 3\na = 50\n')
    assert main(["report", str(d)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: tablet.a = 50 is not allowed: mode 1"), err


def test_optimise_names_itself_when_it_will_not_replace_a_file(tmp_path, capsys):
    """The refusal said "no tabletcad build wrote there" for an optimise run (and a build may well have)."""
    out = tmp_path / "out"
    out.mkdir()
    (out / "report.json").write_text("{}")
    text = CONCAVE.format(sense="max", variables="land = { lower = 0.0, upper = 0.3 }",
                          fixed="diameter = 10.0\nband = 2.5\ncup_depth = 0.8")
    rc, _, err = _optimise(tmp_path, capsys, text)
    assert rc == 2 and err == [f"error: --out = '{out}' is not allowed: must not hold files this run writes that no "
                               "earlier tabletcad optimise run wrote there or that were edited since (report.json): "
                               "move them or write into another folder"]
    assert (out / "report.json").read_text() == "{}"


@pytest.mark.parametrize("force, pressure, expected", [(20.0, 100.0, "pressure"), (5.0, 100.0, "force")])
def test_two_punch_limits_use_the_stricter_and_say_so(capsys, force, pressure, expected):
    import json

    assert main(["report", "samples/families/concave_round.toml", "--max-punch-force", str(force),
                 "--max-punch-pressure", str(pressure), "--compaction-force", "5", "--json"]) == 0
    rep = json.loads(capsys.readouterr().out)
    pc = (rep[0] if isinstance(rep, list) else rep)["design_report"]["punch_tip_check"]
    area = math.pi * 25.0  # the 10 mm round's tip face, mm2
    assert pc["allowed_force_kN"] == pytest.approx(min(force, pressure * area / 1000.0), rel=1e-9)
    assert f"max_punch_{expected}" in pc["limit_basis"] and "the stricter of the two limits given" in pc["limit_basis"]


def test_extents_and_plan_area_of_a_w_trim_are_the_solid_s():
    """``[trim] w = [w0, w1]`` with w1 < 1 keeps the solid between the spine's w0 and w1 (eq 4.12);
    the report gave the whole surface's extents (12.01 mm for a ring whose STEP is 10.81 mm wide) and
    plan area.  The ring's spine is on the axis, so its plan scales exactly: outer radius by w1, the
    hole's by w0 / 0.5 (the design's own w0); the sphere's by w1 alone."""
    from tabletcad.pipeline.design import Design

    def build(tablet: dict, w=None):
        return Design.from_dict({"tablet": tablet, **({"trim": {"w": w}} if w else {})}).build()

    ring = dict(family="thesis.ring", outer_diameter=12.0, inner_diameter=6.0, thickness=4.5)
    full, cut = build(ring), build(ring, [0.2, 0.9])
    R = full.dimensions()["length_mm"] / 2.0
    Rh2 = R * R - full.plan_area() / math.pi  # the hole's radius², at w0 = 0.5
    assert cut.dimensions()["length_mm"] == pytest.approx(0.9 * 2.0 * R, rel=1e-9)
    assert cut.plan_area() == pytest.approx(math.pi * ((0.9 * R) ** 2 - (0.2 / 0.5) ** 2 * Rh2), rel=1e-7)
    sphere = dict(family="thesis.spherical", diameter=5.0)
    full, cut = build(sphere), build(sphere, [0.0, 0.5])
    assert cut.dimensions()["width_mm"] == pytest.approx(0.5 * full.dimensions()["width_mm"], rel=1e-9)
    assert cut.plan_area() == pytest.approx(0.25 * full.plan_area(), rel=1e-7)


@pytest.mark.parametrize("reshape, line", [
    ("spine = [1.0, 2.0]", "error: reshape.spine = [1.0, 2.0] is not allowed: need one per patch (3)"),
    ("spine = [1.0, -2.0, 1.0]", "error: reshape.spine[1] = -2 is not allowed"),
    ("radius = 1000.0", "error: reshape = {'radius': 1000.0} is not allowed: must keep the tablet within ±1000 mm"),
    # a trial: radius 1e-5 mm built a tablet 1e-4 mm across, below the least length a design takes
    ("radius = 1e-5", "error: reshape = {'radius': 1e-05} is not allowed: must leave the tablet's length, width and "
                      "height at least 0.001 mm (Tolerances.min_length, the least length a design takes; the smallest "
                      "is 0.000100051 mm)"),
])
def test_reshape_refusals_name_the_key(tmp_path, capsys, reshape, line):
    """They said ``spine.factors = 2`` and ``reshape = 'factors'``."""
    d = tmp_path / "d.toml"
    d.write_text(f'[tablet]\nfamily = "thesis.flat_faced_round"\ndiameter = 10\nthickness = 3\n[reshape]\n{reshape}\n')
    assert main(["report", str(d)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(line), err


def test_mesh_nodes_named_as_the_option(tmp_path, capsys):
    d = tmp_path / "d.toml"
    d.write_text('[tablet]\nfamily = "thesis.flat_faced_round"\ndiameter = 10\nthickness = 3\n')
    assert main(["mesh", str(d), "--nodes", "2", "2", "2", "--out", str(tmp_path / "m.vtu")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: --nodes = (2, 2, 2) is not allowed: must be integers"), err
    assert not (tmp_path / "m.vtu").exists()


def test_a_cut_away_s_extents_reach_its_cut_faces():
    """The cut faces run in to the spine (eq 4.12): a capsule cut to v = [0, 1] spans x from its axis,
    0, to its end, L/2 (4.0 mm was reported for this 9 mm wide solid: the outer surface's span)."""
    from tabletcad.pipeline.design import Design

    d = Design.from_dict({"tablet": dict(family="capsule", length=18.0, width=8.0, band=3.0, cup_depth=1.2),
                          "trim": {"v": [0.0, 1.0]}})
    lo, hi = d.build().bounds()
    assert lo[0] == pytest.approx(0.0, abs=1e-9) and hi[0] == pytest.approx(9.0, abs=1e-6)


ROUND = '[tablet]\nfamily = "concave_round"\ndiameter = 12.0\nband = 3.0\ncup_depth = 1.2\n'


@pytest.mark.parametrize("report, line", [
    # taken, and printed as "force = 1e+300 mm must be > 0 and <= 1e+09 N" in the report's strength row
    ("breaking_force_N = 1e300", "error: report.breaking_force_N = 1e+300 N is not allowed: must be > 0 and <= 1e+09 N"),
    ("compaction_force_kN = 2e6", "error: report.compaction_force_kN = 2e+06 kN is not allowed: must be > 0 and <= 1e+06 kN"),
    # built with every file written; only `tabletcad fe strength` refused them
    ("tensile_strength_MPa = -3", "error: report.tensile_strength_MPa = -3 MPa is not allowed: must be > 0"),
    # a strength in pascals: the report had printed an FE breaking force of 1.3e8 N
    ("tensile_strength_MPa = 2e6", "error: report.tensile_strength_MPa = 2e+06 MPa is not allowed: must be > 0 and <= 1000 MPa"),
    ("reference_diameter_mm = -1", "error: report.reference_diameter_mm = -1 mm is not allowed: must be >= 0.001"),
    # a tip pressure in GPa (0.3 for 300 MPa) had been taken, rating the punch tips a thousand times too weak
    ("max_punch_pressure_MPa = 0.3", "error: report.max_punch_pressure_MPa = 0.3 MPa is not allowed: must be >= 10 and <= 10000 MPa"),
    ("max_punch_pressure_MPa = 1e9", "error: report.max_punch_pressure_MPa = 1e+09 MPa is not allowed: must be >= 10 and <= 10000 MPa"),
    ("reference_thickness_mm = 0", "error: report.reference_thickness_mm = 0 mm is not allowed: must be >= 0.001"),
])
@pytest.mark.parametrize("command", ["report", "build"])
def test_report_numbers_out_of_range_refused_by_every_command(tmp_path, capsys, report, line, command):
    d = tmp_path / "d.toml"
    d.write_text(ROUND + "[report]\n" + report + "\n", encoding="utf-8")
    extra = ["--out", str(tmp_path / "out")] if command == "build" else []
    assert main([command, str(d), *extra]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(line), err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d.toml"]


@pytest.mark.parametrize("fixed, line", [
    # a fixed value the family refuses at the start: the solver had stopped at once (exit 3, files written)
    ("band = 3.0\ncup_depth = 0.0", "error: fixed.cup_depth = 0 mm is not allowed: must be > 0 and <= 6 mm "
     "(a hemisphere over the 12 mm wide cup) (at the start: diameter = 12;"),
    ("band = 3.0\ncup_depth = 7.0", "error: fixed.cup_depth = 7 mm is not allowed: must be > 0 and <= 6 mm"),
])
def test_a_start_the_family_refuses_is_the_files_error(tmp_path, capsys, fixed, line):
    rc, out, err = _optimise(tmp_path, capsys, CONCAVE.format(
        sense="min", variables="diameter = { lower = 8.0, upper = 14.0, initial = 12.0 }", fixed=fixed))
    assert rc == 2 and len(err) == 1 and err[0].startswith(line), err
    assert out == [] and sorted(p.name for p in tmp_path.iterdir()) == ["problem.toml"]


def test_a_ffbe_is_given_by_its_bevel_width_or_its_bevel_depth(tmp_path, capsys):
    """``bevel_width`` and ``bevel_depth`` are alternatives (give one): a design, a script, an inverse
    design and an optimisation take the depth alone (a trial: "tablet.bevel_width = (not given) is not
    allowed" until a width of 0 was written), and the refusal of neither names both."""
    import math

    from tabletcad.families.inverse import solve_for
    from tabletcad.pipeline.design import Design

    base = dict(family="ffbe", diameter=10.0, thickness=3.0, bevel_angle=30.0)
    by_depth = Design.from_dict({"tablet": {**base, "bevel_depth": 0.3}}).build()
    by_width = Design.from_dict({"tablet": {**base, "bevel_width": 0.3 / math.tan(math.radians(30.0))}}).build()
    assert by_depth.volume() == pytest.approx(by_width.volume(), rel=1e-12)
    assert by_depth.params["bevel_width"] == 0.0 and by_depth.params["bevel_depth"] == 0.3
    d = tmp_path / "d.toml"
    d.write_text('[tablet]\nfamily = "ffbe"\ndiameter = 10.0\nthickness = 3.0\nbevel_angle = 30.0\n')
    assert main(["report", str(d)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["error: tablet.bevel_width = (not given) is not allowed: family 'ffbe' needs diameter, thickness, "
                   "bevel_angle, bevel_width (or bevel_depth) (optional: bevel_depth)"]
    solved = solve_for("ffbe", target_volume_mm3=by_depth.volume(), vary="thickness", diameter=10.0, bevel_angle=30.0,
                       bevel_depth=0.3)
    assert solved.value == pytest.approx(3.0, rel=1e-9)
    rc, out, err = _optimise(tmp_path, capsys, '[problem]\nkind = "family"\nfamily = "ffbe"\nsense = "min"\n'
                             'objective = "surface_area_mm2"\n[variables]\nthickness = { lower = 2.0, upper = 4.0 }\n'
                             '[fixed]\ndiameter = 10.0\nbevel_angle = 30.0\nbevel_depth = 0.3\n', "--maxiter", "30")
    assert rc == 0, err
