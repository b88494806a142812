"""``tabletcad kawakita``, ``walker`` and ``profiles`` on closed-form synthetic tables."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from tabletcad.cli import main
from tabletcad.errors import _fmt

A, B, H0 = 0.4, 0.05, 10.0  # Kawakita a, b (1/MPa), initial height (mm)
W, C = 12.0, 95.0  # Walker % per decade, intercept %
SIGMA0, K = 8.0, 6.0  # Ryshkewitch-Duckworth sigma0 (MPa), k
P = np.array([0.0, 5, 10, 20, 40, 60, 80, 120, 160, 200])


def run(capsys, *args):
    rc = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return rc, out, err


def _write(path: Path, header: str, cols) -> Path:
    rows = [header] + [",".join(f"{v:.15g}" for v in r) for r in zip(*cols)]
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")
    return path


def test_kawakita_recovers_a_and_b(capsys, tmp_path):
    h = H0 * (1 - A * B * P / (1 + B * P))
    data = _write(tmp_path / "k.csv", "pressure_MPa,thickness_mm", (P, h))
    rc, out, err = run(capsys, "kawakita", data, "--json")
    assert rc == 0, err
    d = json.loads(out)
    assert d["a"] == pytest.approx(A, rel=1e-9) and d["b_per_MPa"] == pytest.approx(B, rel=1e-9)
    assert d["inv_b_MPa"] == pytest.approx(1 / B, rel=1e-9) and d["r2"] == pytest.approx(1.0, abs=1e-12)
    assert d["h0_mm"] == H0 and d["n_points"] == 9
    rc, out, err = run(capsys, "kawakita", data, "--window", 10, 120)
    assert rc == 0 and "a = 0.4," in out and "1/b = 20 MPa" in out and out.count("\n") == 1


def test_walker_recovers_w_and_json_file(capsys, tmp_path):
    Pp = P[1:]
    h = H0 * (C - W * np.log10(Pp)) / 100
    data = _write(tmp_path / "w.csv", "Pressure_MPa,Thickness_mm", (Pp, h))
    jf = tmp_path / "sub" / "walker.json"
    rc, out, err = run(capsys, "walker", data, "--h0", H0, "--json-file", jf)
    assert rc == 0, err
    d = json.loads(jf.read_text())
    assert d["W_percent_per_decade"] == pytest.approx(W, rel=1e-9)
    assert d["intercept_percent"] == pytest.approx(C, rel=1e-9)
    assert f"json -> {jf}" in out and "W = 12 % per decade" in out


def test_profiles_and_ryshkewitch(capsys, tmp_path):
    Pp = P[1:]
    sf = 0.6 + 0.35 * (1 - np.exp(-Pp / 80))
    s = SIGMA0 * np.exp(K * (sf - 1))
    data = _write(tmp_path / "p.csv", "pressure_MPa,solid_fraction,tensile_strength_MPa", (Pp, sf, s))
    plot = tmp_path / "profiles.png"
    rc, out, err = run(capsys, "profiles", data, "--json", "--plot", plot)
    assert rc == 0, err
    d = json.loads(out)
    rd = d["ryshkewitch_duckworth"]
    assert rd["sigma0_MPa"] == pytest.approx(SIGMA0, rel=1e-9) and rd["k"] == pytest.approx(K, rel=1e-9)
    pr = d["profiles"]
    assert pr["tabletability"]["y"] == pytest.approx(list(s), rel=1e-12)
    assert pr["compressibility"]["y"] == pytest.approx(list(1 - sf), rel=1e-12)
    assert pr["compactibility"]["x"] == pytest.approx(sorted(1 - sf), rel=1e-12)
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("args, param", [
    (["--pressure-column", "nope"], "column = 'nope'"),
    (["--window", 50, 10], "--window"),
    (["--json-file", "out.txt"], "--json-file"),
    (["--h0", -1], "--h0"),
])
def test_bad_input_is_one_line_and_writes_nothing(capsys, tmp_path, monkeypatch, args, param):
    monkeypatch.chdir(tmp_path)
    data = _write(tmp_path / "k.csv", "pressure_MPa,thickness_mm", (P, H0 * (1 - A * B * P / (1 + B * P))))
    before = sorted(tmp_path.iterdir())
    rc, out, err = run(capsys, "kawakita", data, *args)
    assert rc == 2 and out == ""
    assert err.count("\n") == 1 and err.startswith(f"error: {param}")
    assert sorted(tmp_path.iterdir()) == before


@pytest.mark.parametrize("command", ["kawakita", "walker"])
@pytest.mark.parametrize("rows, extra, line", [
    # --h0 = 1e300 mm had fitted Walker's W = 1.5e-298 % per decade, exit 0
    ("0,6\n10,5\n20,4.5\n40,4\n", ["--h0", "1e300"], "error: --h0 = 1e+300 mm is not allowed: must be > 0 and <= 1000 mm"),
    # thicknesses of 1e300 mm had been fitted as a compact's, exit 0
    ("0,1e300\n10,5e299\n20,4e299\n40,3e299\n", [],
     "error: \"k.csv\".line[2].thickness_mm = 1e+300 mm is not allowed: must be > 0 and <= 1000 mm (the compact's "
     "thickness)"),
    # a pressure of 1e300 MPa had given Kawakita's a = inf, R² = nan, exit 0
    ("0,6\n1e300,5\n2e300,4\n4e300,3\n", [],
     "error: \"k.csv\".line[3].pressure_MPa = 1e+300 MPa is not allowed: must be >= 0 and <= 100000 MPa (a "
     "compaction pressure)"),
])
def test_compression_tables_keep_a_compacts_sizes(capsys, tmp_path, command, rows, extra, line):
    data = tmp_path / "k.csv"
    data.write_text("pressure_MPa,thickness_mm\n" + rows, encoding="utf-8")
    rc, out, err = run(capsys, command, data, *extra, "--json-file", tmp_path / "k.json")
    assert rc == 2 and out == "" and err.splitlines() == [line]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["k.csv"]


def test_non_numeric_cell(capsys, tmp_path):
    data = tmp_path / "bad.csv"
    data.write_text("pressure_MPa,thickness_mm\n10,9.5\nx,9\n", encoding="utf-8")
    rc, out, err = run(capsys, "walker", data)
    assert rc == 2 and err == "error: \"bad.csv\".line[3].pressure_MPa = 'x' is not allowed: must be a number\n"


ROOT = Path(__file__).resolve().parents[1]
_JSON_COMMANDS = {
    "heckel": [ROOT / "samples" / "press" / "lactose_appendix_b.csv"],
    "strength": ["diametral", "--force", 100, "--diameter", 10, "--thickness", 4],
    "contact": ["--force", 10, "--force", 20],
    "shell": ["--outer", 5, "--inner", 4, "--E", 1000, "--nu", 0.3, "--p-ext", 1, "--terms", 40],
    "love": [],
    "shapes": [],
}


def _no_warnings(d):
    return {k: v for k, v in d.items() if k != "warnings"}


@pytest.mark.parametrize("command", list(_JSON_COMMANDS))
def test_json_file_writes_what_json_prints(capsys, tmp_path, command):
    """--json prints and --json-file writes the same document, on every command that has a result."""
    args = _JSON_COMMANDS[command]
    rc, out, err = run(capsys, command, *args, "--json")
    assert rc == 0, err
    printed = json.loads(out)
    target = tmp_path / "result.json"
    rc, out, err = run(capsys, command, *args, "--json-file", target)
    assert rc == 0, err
    assert out.rstrip().endswith(f"json -> {target}")
    written = json.loads(target.read_text(encoding="utf-8"))
    assert _no_warnings(written) == _no_warnings(printed) and written
    bad = tmp_path / "result.txt"
    rc, out, err = run(capsys, command, *args, "--json-file", bad)
    # the value as the error line shows it (a path longer than 80 characters is shortened)
    assert rc == 2 and err == f"error: --json-file = {_fmt(str(bad))} is not allowed: must end in .json\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["result.json"]


def test_shapes_json_gives_no_default_for_a_required_dimension(capsys):
    rc, out, err = run(capsys, "shapes", "--json")
    d = json.loads(out)["concave_round"]
    assert d["defaults"] == {"diameter": None, "band": None, "cup_depth": None, "land": 0.0}
    assert d["required"] == ["diameter", "band", "cup_depth"] and d["optional"] == ["land"]


@pytest.mark.parametrize("command", ["kawakita", "walker"])
def test_a_press_record_is_fitted_on_its_loading_branch(capsys, tmp_path, command):
    """Rows after the peak pressure (unloading, reloading) are left out, as heckel does, and said so."""
    h = H0 * (1 - A * B * P / (1 + B * P))
    load = _write(tmp_path / "load.csv", "pressure_MPa,thickness_mm", (P, h))
    back = np.array([150.0, 90.0, 30.0, 5.0, 60.0, 180.0])  # unloading, then reloading the compact
    h_back = h[-1] + 0.02 * (1 - back / P[-1])  # elastic recovery: thicker than on the way up
    record = _write(tmp_path / "record.csv", "pressure_MPa,thickness_mm", (np.r_[P, back], np.r_[h, h_back]))
    rc, out, err = run(capsys, command, load, "--json")
    assert rc == 0, err
    alone = json.loads(out)
    rc, out, err = run(capsys, command, record, "--json")
    assert rc == 0, err
    d = json.loads(out)
    assert d["loading_rows"] == [1, len(P)] and d["n_points"] == alone["n_points"]
    keys = ("a", "b_per_MPa") if command == "kawakita" else ("W_percent_per_decade", "intercept_percent")
    assert [d[k] for k in keys] == pytest.approx([alone[k] for k in keys], rel=1e-12)
    rc, out, err = run(capsys, command, record)
    assert out.splitlines()[0] == (f"record.csv: loading rows 1-{len(P)} of {len(P) + len(back)} used (up to the peak "
                                   "pressure; the rows after it unload or reload the compact)")


def _write_as(path: Path, header: list[str], cols, sep: str = ",", comma: bool = False, scale=(1.0, 1.0, 1.0)) -> Path:
    """A table with ``sep`` between cells, decimal commas if ``comma``, each column multiplied by its ``scale``."""
    def cell(v):
        text = f"{v:.15g}"
        return text.replace(".", ",") if comma else text
    rows = [sep.join(header)] + [sep.join(cell(v * f) for v, f in zip(r, scale)) for r in zip(*cols)]
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")
    return path


@pytest.mark.parametrize("header, sep, comma, scale", [
    (["pressure_MPa", "thickness_mm"], ";", True, (1.0, 1.0)),
    (["pressure_MPa", "thickness_mm"], "\t", False, (1.0, 1.0)),
    (["Pressure (kPa)", "Thickness (µm)"], ",", False, (1e3, 1e3)),
    (["Pressure (kPa)", "Thickness (µm)"], ";", True, (1e3, 1e3)),
    (["Pressure [bar]", "Thickness [cm]"], ",", False, (10.0, 0.1)),
    (["pressure_psi", "thickness_in"], ",", False, (1 / 0.0068947572931683625, 1 / 25.4)),
])
def test_kawakita_reads_separators_decimal_commas_and_the_headers_units(capsys, tmp_path, header, sep, comma, scale):
    """Tables of compacts read as press records are: ``;``/tab, decimal commas and units in the header,
    converted to MPa and mm, give the fit of the plain file (a table in kPa and µm had been taken as MPa
    and mm: b 1,000 times too small, h0 8000 mm)."""
    h = H0 * (1 - A * B * P / (1 + B * P))
    data = _write_as(tmp_path / "k.csv", header, (P, h), sep, comma, scale)
    rc, out, err = run(capsys, "kawakita", data, "--json")
    assert rc == 0, err
    d = json.loads(out)
    assert d["a"] == pytest.approx(A, rel=1e-9) and d["b_per_MPa"] == pytest.approx(B, rel=1e-9)
    assert d["h0_mm"] == pytest.approx(H0, rel=1e-14)


def test_profiles_read_a_solid_fraction_in_percent_and_a_strength_in_kpa(capsys, tmp_path):
    Pp = P[1:]
    sf = 0.6 + 0.35 * (1 - np.exp(-Pp / 80))
    s = SIGMA0 * np.exp(K * (sf - 1))
    data = _write_as(tmp_path / "p.csv", ["Pressure (MPa)", "Solid fraction (%)", "Tensile strength (kPa)"],
                     (Pp, sf, s), ";", True, (1.0, 100.0, 1e3))
    rc, out, err = run(capsys, "profiles", data, "--json", "--pressure-column", "Pressure (MPa)",
                       "--solid-fraction-column", "Solid fraction (%)", "--strength-column", "Tensile strength (kPa)")
    assert rc == 0, err
    rd = json.loads(out)["ryshkewitch_duckworth"]
    assert rd["sigma0_MPa"] == pytest.approx(SIGMA0, rel=1e-9) and rd["k"] == pytest.approx(K, rel=1e-9)
    # without the options: the default names (pressure, solid_fraction, tensile_strength) find the headers
    # whose words are spaced (a new user's "Solid fraction (%)" had been "not one of the header's columns")
    rc, out2, err = run(capsys, "profiles", data, "--json")
    assert rc == 0, err
    assert json.loads(out2)["ryshkewitch_duckworth"] == rd


@pytest.mark.parametrize("header, line", [
    ("Pressure (mm),thickness_mm", "error: column = 'Pressure (mm)' is not allowed: states the unit 'mm', which is not a known "
                                   "pressure unit (MPa, N/mm², N/mm2, kPa, Pa, GPa, bar, psi)"),
    ("Pressure (atm),thickness_mm", "error: column = 'Pressure (atm)' is not allowed: states the unit 'atm', which is not a known "
                                    "pressure unit"),
    ("pressure_MPa,Thickness (kN)", "error: column = 'Thickness (kN)' is not allowed: states the unit 'kN', which is not a known "
                                    "length unit (mm, µm, um, cm, m, in, inch)"),
])
def test_a_header_unit_of_another_quantity_is_refused(capsys, tmp_path, header, line):
    data = tmp_path / "k.csv"
    data.write_text(header + "\n10,5\n20,4.5\n", encoding="utf-8")
    cols = header.split(",")
    rc, out, err = run(capsys, "kawakita", data, "--pressure-column", cols[0], "--thickness-column", cols[1])
    assert rc == 2 and out == "" and len(err.splitlines()) == 1 and err.startswith(line), err


def test_an_h0_below_the_compacts_is_named_as_the_option(capsys, tmp_path):
    """``--h0`` thinner than every compact leaves no volume reduction: the option is named (it was
    ``data = '0 points with volume reduction'``)."""
    h = H0 * (1 - A * B * P / (1 + B * P))
    data = _write(tmp_path / "k.csv", "pressure_MPa,thickness_mm", (P, h))
    rc, out, err = run(capsys, "kawakita", data, "--h0", 0.5)
    assert rc == 2 and out == ""
    assert err == (f"error: --h0 = 0.5 mm is not allowed: must exceed the thickness at 3 or more of the fitted "
                   f"pressures (it exceeds 0 of them; the thinnest compact is {h.min():.6g} mm)\n")


@pytest.mark.parametrize("args, line", [
    (["elongated-flat", "--force", 100, "--diameter", 6, "--thickness", 3, "--length", 3],
     "error: --length = 3 mm is not allowed: must be >= the width (the diameter given, 6 mm): the width is the short axis"),
])
def test_strength_geometry_that_cannot_exist_is_refused(capsys, args, line):
    """A length below the width (the width is the short axis): refused, not warned of.  (A face radius
    below D/2 is possible: a cup inside a land spans less than D; Podczeck's range warns of it.)"""
    rc, out, err = run(capsys, "strength", *args)
    assert (rc, out, err) == (2, "", line + "\n")


@pytest.mark.parametrize("bracket", ["(-)", "[1]", "()", "(dimensionless)"])
def test_a_bracket_saying_no_unit_is_no_unit(capsys, tmp_path, bracket):
    """``solid_fraction (-)`` and the like: read as a fraction (the bracket had been refused as an unknown unit)."""
    Pp = P[1:]
    sf = 0.6 + 0.35 * (1 - np.exp(-Pp / 80))
    s = SIGMA0 * np.exp(K * (sf - 1))
    name = f"solid_fraction {bracket}"
    data = _write(tmp_path / "p.csv", f"pressure_MPa,{name},tensile_strength_MPa", (Pp, sf, s))
    rc, out, err = run(capsys, "profiles", data, "--json", "--solid-fraction-column", name)
    assert rc == 0, err
    assert json.loads(out)["ryshkewitch_duckworth"]["k"] == pytest.approx(K, rel=1e-9)


@pytest.mark.parametrize("rows, line", [
    # a new user's trial: a solid fraction of 70 had been "error: solid.fraction = 70 is not allowed", no file or row
    ("50.0,70,1.32\n100.0,0.78,2.14\n150.0,0.83,2.88\n",
     "error: \"prof6.csv\".line[2].solid_fraction = 70 is not allowed: must be > 0 and < 1 (a solid fraction; a "
     "percentage needs '%' in its header, as 'Solid fraction (%)')"),
    ("50.0,0.7,1.32\n100.0,0.78,-2.14\n150.0,0.83,2.88\n",
     "error: \"prof6.csv\".line[3].tensile_strength_MPa = -2.14 MPa is not allowed: must be > 0 (a tablet's tensile "
     "strength)"),
    ("50.0,0.7,1.32\n-100.0,0.78,2.14\n150.0,0.83,2.88\n",
     "error: \"prof6.csv\".line[3].pressure_MPa = -100 MPa is not allowed: must be >= 0 (a compaction pressure)"),
    # 1e300 MPa of a pressure or a strength had been fitted and plotted, exit 0
    ("50.0,0.7,1.32\n1e300,0.78,2.14\n150.0,0.83,2.88\n",
     "error: \"prof6.csv\".line[3].pressure_MPa = 1e+300 MPa is not allowed: must be >= 0 and <= 100000 MPa (a "
     "compaction pressure)"),
    ("50.0,0.7,1.32\n100.0,0.78,1e300\n150.0,0.83,2.88\n",
     "error: \"prof6.csv\".line[3].tensile_strength_MPa = 1e+300 MPa is not allowed: must be > 0 and <= 1000 MPa "
     "(a tablet's tensile strength)"),
])
def test_profiles_name_the_row_and_column_of_a_bad_value(capsys, tmp_path, rows, line):
    data = tmp_path / "prof6.csv"
    data.write_text("pressure_MPa,solid_fraction,tensile_strength_MPa\n" + rows, encoding="utf-8")
    rc, out, err = run(capsys, "profiles", data, "--json-file", tmp_path / "p.json")
    assert rc == 2 and out == "" and err.splitlines() == [line]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["prof6.csv"]
