"""`tabletcad report` over many designs (--csv, --xlsx, --json, --json-file) and the inverse
calculation from the command line (--solve-for with --target-weight or --target-volume).

* Rows agree with the single-design JSON report, and the workbook (read back by openpyxl)
  with the CSV.
* A concave round's volume is linear in its band, ``V(b) = V(b0) + π R² (b - b0)``, so the
  band that gives a target volume has a closed form; the solved weight equals the target.
* Bad use is the one-line error with exit 2 and nothing written.
"""

from __future__ import annotations

import csv
import json
import math
import sys
from pathlib import Path

import pytest

from tabletcad.cli import main

ROOT = Path(__file__).resolve().parents[1]
FAM = ROOT / "samples" / "families"
DESIGNS = [FAM / "concave_round.toml", FAM / "capsule.toml", FAM / "rounded_triangle.toml"]


def _json(capsys, *argv) -> object:
    assert main(["report", *map(str, argv), "--json"]) == 0
    return json.loads(capsys.readouterr().out)


@pytest.mark.tables
def test_csv_rows_equal_the_single_reports_and_the_workbook_equals_the_csv(tmp_path, capsys):
    openpyxl = pytest.importorskip("openpyxl")
    assert main(["report", *map(str, DESIGNS), "--csv", str(tmp_path / "r.csv"), "--xlsx", str(tmp_path / "r.xlsx"),
                 "--json-file", str(tmp_path / "r.json")]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].split()[:2] == ["design", "family"] and [ln.split()[0] for ln in out[1:4]] == [p.stem for p in DESIGNS]
    rows = list(csv.DictReader((tmp_path / "r.csv").open(encoding="utf-8")))
    assert [r["design"] for r in rows] == [p.stem for p in DESIGNS]
    many = json.loads((tmp_path / "r.json").read_text())
    assert [m["design"]["name"] for m in many] == [p.stem for p in DESIGNS]
    for path, row, doc in zip(DESIGNS, rows, many):
        single = _json(capsys, path)
        r = single["design_report"]
        assert doc["design_report"] == r
        for key in ("volume_mm3", "surface_area_mm2", "cup_depth_mm", "plan_area_mm2"):
            assert float(row[f"design_report.{key}"]) == r[key]  # repr() in the CSV: bit-identical
        assert row["tablet.family"] == single["design"]["family"]
        for k, v in single["design"]["params"].items():
            if isinstance(v, float):
                assert float(row[f"tablet.{k}"]) == v
    ws = openpyxl.load_workbook(tmp_path / "r.xlsx").active
    header = [c.value for c in ws[1]]
    assert header == list(rows[0].keys())
    for i, row in enumerate(rows, start=2):
        cells = dict(zip(header, (c.value for c in ws[i])))
        assert cells["design"] == row["design"]
        # a spreadsheet number keeps 15-17 significant digits (openpyxl 3.1.5 writes 16: 289.1169189063439
        # for 289.11691890634387), not repr()'s round trip
        assert cells["design_report.volume_mm3"] == pytest.approx(float(row["design_report.volume_mm3"]), rel=1e-15, abs=0)


def test_json_flag_prints_a_list_for_several_designs_and_writes_nothing(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    doc = _json(capsys, *DESIGNS[:2])
    assert isinstance(doc, list) and [d["design"]["name"] for d in doc] == ["concave_round", "capsule"]
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("target", [250.0, 320.0])
def test_solved_band_of_a_concave_round_is_the_closed_form(capsys, target):
    base = _json(capsys, FAM / "concave_round.toml")["design_report"]
    b0, v0, R = base["band_mm"], base["volume_mm3"], 0.5 * base["width_mm"]
    doc = _json(capsys, FAM / "concave_round.toml", "--solve-for", "band", "--target-volume", target)
    inv = doc["inverse"]
    assert inv["solved_for"] == "band" and inv["given_mm"] == pytest.approx(b0)
    assert inv["value_mm"] == pytest.approx(b0 + (target - v0) / (math.pi * R * R), abs=1e-6)
    assert doc["design_report"]["band_mm"] == pytest.approx(inv["value_mm"], abs=1e-12)
    assert doc["design_report"]["volume_mm3"] == pytest.approx(target, rel=2e-6)  # PDE quadrature vs nominal


def test_solved_weight_matches_the_python_api(capsys):
    from tabletcad.families.inverse import solve_for

    doc = _json(capsys, FAM / "concave_round.toml", "--solve-for", "cup_depth", "--target-weight", 330,
                "--solid-fraction", 0.8, "--true-density", 1.4)
    py = solve_for("concave_round", target_weight_mg=330, vary="cup_depth", diameter=10.0, band=2.8, cup_depth=0.9,
                   land=0.08, solid_fraction=0.8, true_density_mg_mm3=1.4)
    assert doc["inverse"]["value_mm"] == pytest.approx(py.value, abs=1e-9)
    assert doc["design_report"]["weight_mg"] == pytest.approx(330.0, rel=2e-6)


@pytest.mark.parametrize("extra, parameter", [
    (["--json", "OUT/r.json"], "DESIGN"),  # the old `--json FILE`: a hint, not a missing file
    (["--target-weight", "300"], "--solve-for"),
    (["--solve-for", "band"], "--target-weight/--target-volume"),
    (["--solve-for", "band", "--target-volume", "1", "--target-weight", "2"], "--target-weight/--target-volume"),
    (["--solve-for", "band", "--target-volume", "1e6"], "--target-volume"),
    (["--csv", "OUT/r.csv", "--xlsx", "OUT/r.csv"], "--xlsx"),
    (["--csv", "OUT/r.csv", "--json-file", "OUT/r.csv"], "--json-file"),
    (["--csv", "OUT/r.txt"], "--csv"),
    ([str(FAM / "missing.toml"), "--csv", "OUT/r.csv"], "DESIGN"),
    ([str(ROOT / "samples" / "spherical.toml"), "--solve-for", "band", "--target-volume", "300", "--csv", "OUT/r.csv"],
     "--solve-for"),  # the thesis's sphere has no band (nor any dimension the inverse solves for)
    (["--solve-for", "thickness", "--target-volume", "300"], "--solve-for"),  # concave_round takes no thickness
    (["--solve-for", "band", "--target-weight", "300", "--solid-fraction", "1.5"], "--solid-fraction"),
])
def test_bad_use_is_one_line_and_writes_nothing(tmp_path, capsys, extra, parameter):
    out = tmp_path / "OUT"
    out.mkdir()
    first = [] if extra[0].endswith(".toml") else [str(FAM / "concave_round.toml")]
    argv = ["report", *first, *[a.replace("OUT", str(out)) for a in extra]]
    assert main(argv) == 2
    cap = capsys.readouterr()
    assert cap.out == "" and cap.err.splitlines() == [cap.err.strip()]
    assert cap.err.startswith(f"error: {parameter} = ")
    assert "must end in or" not in cap.err  # "must end in .csv", not "must end in or .csv"
    assert list(out.iterdir()) == []


def test_a_bad_design_among_several_is_named(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text('[tablet]\nfamily = "concave_round"\ndiameter = 10\nband = 2\ncup_depth = -1\n', encoding="utf-8")
    assert main(["report", str(FAM / "ffre.toml"), str(bad), "--csv", str(tmp_path / "r.csv")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: tablet.cup_depth = -1 mm is not allowed: ") and err.endswith(f" (in {bad})\n")
    assert err.count("\n") == 1 and sorted(p.name for p in tmp_path.iterdir()) == ["bad.toml"]
    assert main(["report", str(bad)]) == 2  # one design: the line needs no file name
    assert "(in " not in capsys.readouterr().err


def test_xlsx_without_openpyxl_names_the_extra(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "openpyxl", None)
    assert main(["report", str(FAM / "concave_round.toml"), "--xlsx", str(tmp_path / "r.xlsx")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: --xlsx = ") and "pip install 'tabletcad[tables]'" in err
    assert list(tmp_path.iterdir()) == []


def test_solve_for_carries_the_smoothing_and_refuses_a_reshape_or_trim_it_would_drop(tmp_path, capsys):
    from tabletcad.cli.report import _solved, load_family_design

    d = tmp_path / "a.toml"
    d.write_text((FAM / "concave_round.toml").read_text().replace("[tablet]\n", "[tablet]\na = 0.05\n", 1))
    tablet, design = load_family_design(d)
    solved, inv = _solved(tablet, design, design.report_options, "band", None, 280.0)
    assert {p.a for p in solved.patches} == {0.05} and {p.a for p in tablet.patches} == {0.05}
    assert inv["nominal_volume_mm3"] == pytest.approx(280.0, rel=1e-9)
    for table in ("[reshape]\nradius = 1.1\n", "[trim]\nu = [0.0, 0.5]\n"):
        d.write_text((FAM / "concave_round.toml").read_text().split("[report]")[0] + table)
        assert main(["report", str(d), "--solve-for", "band", "--target-volume", "280"]) == 2
        err = capsys.readouterr().err
        assert err.startswith(f"error: --solve-for = 'band' is not allowed: the design sets {table.split()[0]},"), err


def test_solve_for_a_custom_outline_keeps_its_outline(capsys):
    """A custom outline's volume is linear in its band: b = b0 + (V - V0) / A_plan (the exact plan area)."""
    import json

    design = str(FAM / "custom_outline.toml")
    assert main(["report", design, "--json"]) == 0
    before = json.loads(capsys.readouterr().out)["design_report"]
    assert main(["report", design, "--solve-for", "band", "--target-volume", "300", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    expected = before["band_mm"] + (300.0 - before["volume_mm3"]) / before["plan_area_exact_mm2"]
    # V0 is the report's volume of the PDE surface, certified within 1 µm of the nominal the solver
    # uses: 1e-4 mm3 here, 2e-6 mm of band
    assert doc["inverse"]["value_mm"] == pytest.approx(expected, abs=1e-5)
    assert doc["inverse"]["nominal_volume_mm3"] == pytest.approx(300.0, rel=1e-9)
    assert doc["design_report"]["volume_mm3"] == pytest.approx(300.0, rel=1e-6)
    assert doc["design_report"]["plan_area_exact_mm2"] == pytest.approx(before["plan_area_exact_mm2"], rel=1e-15)

