"""The FE breaking force in the design report: ``[report] fe_breaking_force = true`` makes ``tabletcad report``
and the build run ``tabletcad fe strength --coarse`` on the design (an elastic first-crack estimate)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

pytestmark = [pytest.mark.fe, pytest.mark.slow]
pytest.importorskip("skfem")
pytest.importorskip("gmsh")
pytest.importorskip("OCP")

from tabletcad.cli import main  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]

DESIGN = """
[tablet]
family = "concave_round"
diameter = 10.0
band = 2.8
cup_depth = 0.9
land = 0.08

[report]
tensile_strength_MPa = 2.0
fe_breaking_force = true
"""
#: Largest relative difference between the coarse-mesh force and the default mesh's (as the optimiser's re-check).
RECHECK = 0.05


def run(capsys, *args):
    rc = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return rc, out, err


def test_report_and_build_run_the_coarse_fe_strength(capsys, tmp_path):
    from tabletcad.pipeline.build import build_design

    design = tmp_path / "round.toml"
    design.write_text(DESIGN)

    rc, so, err = run(capsys, "report", design, "--json")
    assert rc == 0, err
    fe = json.loads(so)["fe_breaking_force"]
    rc, so, err = run(capsys, "fe", "strength", design, "--coarse", "--json")
    assert rc == 0, err
    strength = json.loads(so)
    rc, so, err = run(capsys, "fe", "strength", design, "--json")
    assert rc == 0, err
    default = json.loads(so)
    with capsys.disabled():
        print(f"\nreport: {fe['breaking_force_N']:.2f} N (coarse, {fe['dofs']} unknowns); fe strength --coarse "
              f"{strength['breaking_force_N']:.2f} N; default mesh {default['breaking_force_N']:.2f} N")
    assert fe["breaking_force_N"] == pytest.approx(strength["breaking_force_N"], rel=1e-9)
    assert fe["tensile_strength_MPa"] == 2.0 and fe["direction"] == "width"
    assert fe["tablet_meshed"] == "plain" and "note" not in fe  # no [tooling]: the plain tablet is the tablet
    assert fe["estimate"].startswith("elastic first-crack")
    assert fe["breaking_force_N"] == pytest.approx(default["breaking_force_N"], rel=RECHECK)
    rc, so, err = run(capsys, "report", design)
    assert rc == 0, err
    line = next(ln for ln in so.splitlines() if ln.startswith("FE breaking force"))
    assert f"{fe['breaking_force_N']:.4g} N" in line and "elastic first-crack estimate" in line
    report = build_design(design, tmp_path / "build", progress=False)
    assert report["fe_breaking_force"]["breaking_force_N"] == pytest.approx(fe["breaking_force_N"], rel=1e-9)
    on_disk = json.loads((tmp_path / "build" / "report.json").read_text())
    assert on_disk["fe_breaking_force"]["breaking_force_N"] == pytest.approx(fe["breaking_force_N"], rel=1e-9)


@pytest.mark.parametrize("report, message", [
    ('tensile_strength_MPa = 2.0\nfe_breaking_force = "yes"',
     "error: report.fe_breaking_force = 'yes' is not allowed: must be a TOML boolean (true or false)"),
    ("fe_breaking_force = true",
     "error: report.tensile_strength_MPa = (not given) is not allowed: give it, or all of reference_breaking_force_N"),
])
def test_bad_fe_report_input_is_one_line_and_writes_nothing(capsys, tmp_path, report, message):
    p = tmp_path / "bad.toml"
    p.write_text(DESIGN.split("[report]")[0] + "[report]\n" + report + "\n")
    out = tmp_path / "r.json"
    rc, so, err = run(capsys, "report", p, "--json-file", out)
    assert rc == 2
    assert err.strip().startswith(message) and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_diametral_meshes_the_scored_tablet_and_finds_the_score_root(capsys):
    """A design whose [tooling] scores it is meshed with its score (they meshed the plain tablet, with
    a warning, before).  Loaded along the bisect's line (y), the split opens the score: the largest
    tensile stress sits at the score's root, 0.5 mm below the cup's apex on the axis, and is a third
    above the unscored tablet's, which sits on the cup 2.8 mm from a platen."""
    import json

    from tabletcad.cli import main

    root = Path(__file__).resolve().parents[1]
    results = {}
    for name, path in (("scored", root / "samples" / "tooling" / "concave_round_bisect.toml"),
                       ("plain", root / "samples" / "families" / "concave_round.toml")):
        assert main(["fe", "diametral", str(path), "--force", "100", "--direction", "y", "--no-error-estimate",
                     "--json"]) == 0
        out = capsys.readouterr()
        results[name] = json.loads(out.out)
        assert "warning" not in out.err
    scored, plain = results["scored"], results["plain"]
    assert scored["tablet_meshed"].startswith("finished") and plain["tablet_meshed"] == "plain"
    assert scored["thickness_mm"] == plain["thickness_mm"] == pytest.approx(4.6)
    x, y, z = scored["max_tensile_location_mm"]
    assert abs(x) < 1e-9 and abs(y) < 1.0 and z == pytest.approx(4.6 - 0.5, abs=0.05)  # the score's root
    assert scored["max_tensile_stress_MPa"] > 1.2 * plain["max_tensile_stress_MPa"]
    assert abs(plain["max_tensile_location_mm"][1]) > 2.0  # plain: near a platen, on a cup face


def test_the_reports_fe_force_of_a_scored_design_says_it_is_the_plain_tablets(capsys, tmp_path):
    """The report meshes the plain tablet; for a scored and embossed design it now says so, and that
    fe strength meshes the finished one (which breaks at a lower force: the report had read as the
    scored tablet's, 29 % above fe strength's)."""
    text = (ROOT / "samples" / "tooling" / "concave_round_bisect.toml").read_text()
    design = tmp_path / "bisect.toml"
    design.write_text(text.replace("\n[report]", "\n[report]\ntensile_strength_MPa = 2.0\nfe_breaking_force = true", 1))
    rc, so, err = run(capsys, "report", design, "--json")
    assert rc == 0, err
    fe = json.loads(so)["fe_breaking_force"]
    assert fe["tablet_meshed"] == "plain"
    assert fe["note"] == ("the plain tablet, without the design's score and embossing: tabletcad fe strength meshes "
                          "the finished tablet")
    rc, so, err = run(capsys, "fe", "strength", design, "--coarse", "--json")
    assert rc == 0, err
    finished = json.loads(so)
    assert finished["tablet_meshed"] == "finished"
    assert finished["breaking_force_N"] < 0.9 * fe["breaking_force_N"]  # the score's root cracks first
