"""``tabletcad optimise``: round trip through ``tabletcad build``, exit statuses."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tabletcad.cli import main

SAMPLES = Path(__file__).resolve().parent.parent / "samples" / "optimise"


@pytest.mark.parametrize("sample", ["spherical_tablet_a", "spherical_tablet_b"])  # a: the README's example
def test_round_trip_build(tmp_path, sample):
    out = tmp_path / "opt"
    assert main(["optimise", str(SAMPLES / f"{sample}.toml"), "--out", str(out), "--quiet"]) == 0
    for name in ("optimum.toml", "report.json", "convergence.png"):
        assert (out / name).is_file()
    rep = json.loads((out / "report.json").read_text())
    assert rep["success"] and rep["status"] == "converged"
    assert rep["function_evaluations"] > 0 and rep["iterations"] > 0 and rep["wall_time_s"] > 0
    vol = next(c for c in rep["constraints"] if c["name"].startswith("volume"))
    assert "slack" in vol
    build = tmp_path / "built"
    assert main(["build", str(out / "optimum.toml"), "--out", str(build), "--quiet"]) == 0
    built = json.loads((build / "report.json").read_text())
    assert built["volume_mm3"] == pytest.approx(vol["value"], rel=1e-6)
    assert built["volume_mm3"] == pytest.approx(1.44, rel=1e-6)


def test_failure_exit_3(tmp_path, capsys):
    out = tmp_path / "fail"
    assert main(["optimise", str(SAMPLES / "softgel_capsule.toml"), "--out", str(out), "--quiet"]) == 3
    rep = json.loads((out / "report.json").read_text())
    assert rep["success"] is False and rep["status"] == "infeasible"
    assert "mu_r" in rep["message"]
    assert not (out / "optimum.toml").exists()
    assert "infeasible" in capsys.readouterr().err


def test_bad_input_exit_2_nothing_written(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text('[problem]\nkind = "spherical_tablet"\n[parameters]\nvariant = "z"\n')
    out = tmp_path / "out"
    assert main(["optimise", str(bad), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error:")
    assert not out.exists()
    bad.write_text('[problem]\nkind = "family"\nfamily = "thesis.flat_faced_round"\nobjective = "volume_mm3"\n'
                   '[variables]\ndiameter = { lower = 5, upper = 4 }\n')
    assert main(["optimise", str(bad), "--out", str(out), "--quiet"]) == 2
    assert not out.exists()


def test_a_run_cut_short_by_maxiter_is_not_called_infeasible(tmp_path, capsys):
    """``--maxiter 1`` on a feasible problem (the smallest area of a 235 mm³ flat round, D = T = 6.6885 mm)
    stops at an infeasible point: "not_converged", naming the limit, never "no feasible design found"."""
    import json as _json

    from tabletcad.cli import main as _main

    p = tmp_path / "p.toml"
    p.write_text('[problem]\nkind = "family"\nfamily = "flat_face_round"\nsense = "min"\nobjective = "surface_area_mm2"\n'
                 '[variables]\ndiameter = { lower = 4.0, upper = 14.0, initial = 10.0 }\n'
                 'thickness = { lower = 1.0, upper = 10.0, initial = 3.0 }\n'
                 '[[constraint]]\nquantity = "volume_mm3"\ntarget = 235.0\nrelative = true\n', encoding="utf-8")
    assert _main(["optimise", str(p), "--out", str(tmp_path / "o"), "--maxiter", "1", "--quiet"]) == 3
    out, err = capsys.readouterr()
    rep = _json.loads((tmp_path / "o" / "report.json").read_text())
    assert rep["status"] == "not_converged" and "no feasible design found" not in rep["message"]
    if not all(c["satisfied"] for c in rep["constraints"]):  # (scipy 1.10's polish lands a feasible point)
        assert "iteration limit" in rep["message"] and "give a larger --maxiter" in rep["message"]
    assert err.strip().splitlines()[-1].startswith("error: optimisation not_converged")
    assert _main(["optimise", str(p), "--out", str(tmp_path / "o2"), "--quiet"]) == 0
    capsys.readouterr()
    rep = _json.loads((tmp_path / "o2" / "report.json").read_text())
    assert rep["x"]["diameter"] == pytest.approx(rep["x"]["thickness"], rel=1e-4)  # an exact cylinder's optimum
