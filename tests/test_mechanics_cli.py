"""The mechanics commands through ``tabletcad.cli.main``."""

from __future__ import annotations

import json
import math
import os
import shutil
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

from tabletcad.cli import main

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "samples" / "press" / "lactose_appendix_b.csv"


def run(capsys, *args):
    rc = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return rc, out, err


def test_heckel_json_with_thesis_window(capsys, tmp_path):
    plot = tmp_path / "heckel.png"
    rc, out, err = run(capsys, "heckel", SAMPLE, "--window", 10, 50, "--plot", plot, "--json")
    assert rc == 0, err
    d = json.loads(out)
    assert {"K_per_MPa", "A", "Py_MPa", "r2", "window_MPa", "n_points"} <= set(d)
    assert d["K_per_MPa"] == pytest.approx(0.0095647, rel=1e-4)
    assert d["A"] == pytest.approx(0.87921, rel=1e-4)
    assert d["Py_MPa"] == pytest.approx(104.55, rel=1e-4)
    assert d["n_points"] == 29 and len(d["window_MPa"]) == 2
    assert d["window_MPa"][0] >= 10 and d["window_MPa"][1] <= 50
    assert d["loading_rows"] == [1, 81] and d["fitted_rows"] == [35, 63]
    assert plot.stat().st_size > 1000


def test_heckel_options_replace_metadata_file(capsys, tmp_path):
    data = tmp_path / "run.csv"
    shutil.copy(SAMPLE, data)  # no .toml beside it
    rc, out, err = run(capsys, "heckel", data, "--mass", 300, "--true-density", 1.3, "--diameter", 10,
                       "--compliance", 2e-5, 0.0267, "--window", 10, 50, "--json")
    assert rc == 0, err
    assert json.loads(out)["K_per_MPa"] == pytest.approx(0.0095647, rel=1e-4)
    rc, out, err = run(capsys, "heckel", data, "--meta", SAMPLE.with_suffix(".toml"), "--window", 10, 50, "--json")
    assert rc == 0 and json.loads(out)["A"] == pytest.approx(0.87921, rel=1e-4)


@pytest.mark.parametrize(
    "extra,match",
    [
        (["--mass", "-3"], "mass = -3 mg"),
        (["--true-density", "0"], "--true-density = 0"),
        (["--diameter", "0"], "diameter"),
        (["--window", "10", "10.5"], "need >= 3"),
        (["--window", "50", "10"], "--window = (50.0, 10.0) is not allowed: must be two increasing pressures"),
        (["--window", "-1", "10"], "--window = -1 MPa is not allowed: must be >= 0"),
        (["--window", "10", "1e300"], "--window = 1e+300 MPa is not allowed: must be > 0 and <= 100000 MPa"),
        # a new user's trial: each of these had been exit 0 (K = -2.6e-303; Py = inf; D 0.0008, Py 3.6e5 MPa)
        (["--compliance", "1e300", "0"], "--compliance = 1e+300 mm/N is not allowed: must be >= 0 and <= 0.001 mm/N"),
        (["--compliance", "0", "1e300"], "--compliance = 1e+300 mm is not allowed: must be >= -1000 and <= 1000 mm"),
        (["--mass", "0.3"], "relative_density = 'at most 0.000819' is not allowed: must reach 0.05 under load"),
    ],
)
def test_heckel_bad_input_exit_2_and_no_file(capsys, tmp_path, extra, match):
    plot = tmp_path / "bad.png"
    rc, _, err = run(capsys, "heckel", SAMPLE, *extra, "--plot", plot)
    assert rc == 2
    assert err.startswith("error: ") and match in err and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1
    assert not plot.exists() and list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "text,match",
    [
        ("force_N,displacement_mm\n1,-5\nabc,-4\n3,-3\n", "must be a number"),
        ("force,time\n1,0\n2,1\n3,2\n", "displacement or thickness"),
        ("force_N,displacement_mm\n100,-5\n90,-4.9\n80,-4.8\n", "no loading branch"),
    ],
)
def test_heckel_bad_data(capsys, tmp_path, text, match):
    data = tmp_path / "bad.csv"
    data.write_text(text)
    rc, _, err = run(capsys, "heckel", data, "--mass", 300, "--true-density", 1.3, "--diameter", 10,
                     "--plot", tmp_path / "p.png")
    assert rc == 2 and match in err and not (tmp_path / "p.png").exists()


def test_heckel_missing_rows_warning(capsys, tmp_path):
    lines = SAMPLE.read_text().splitlines()
    lines[10] = ",".join([""] + lines[10].split(",")[1:])  # blank force in one data row
    data = tmp_path / "gappy.csv"
    data.write_text("\n".join(lines) + "\n")
    rc, out, err = run(capsys, "heckel", data, "--meta", SAMPLE.with_suffix(".toml"), "--window", 10, 50, "--json")
    assert rc == 0
    assert "dropped 1 row" in err
    d = json.loads(out)
    assert d["rows_dropped"] == 1 and any("dropped 1 row" in w for w in d["warnings"])


def test_strength_commands(capsys):
    rc, out, _ = run(capsys, "strength", "diametral", "--force", 100, "--diameter", 10, "--thickness", 3, "--json")
    assert rc == 0 and json.loads(out)["tensile_strength_MPa"] == pytest.approx(200 / (3.141592653589793 * 30))
    rc, out, err = run(capsys, "strength", "pitt", "--force", 100, "--diameter", 10, "--thickness", 6, "--band", 5,
                       "--json")
    assert rc == 0 and "W/D" in err and json.loads(out)["warnings"]
    rc, out, err = run(capsys, "strength", "sphere", "--force", 8.6, "--material", "kostrolith", "--radius", 0.7047)
    assert rc == 0 and "MPa" in out
    # an option replaces the material's value, and the result says where each input came from
    assert "radius 0.7047 mm from --radius" in out and "E 820 MPa from material kostrolith" in out
    rc, out, err = run(capsys, "strength", "sphere", "--force", 8.6, "--material", "kostrolith", "--radius", 0.7047,
                       "--json")
    d = json.loads(out)
    from tabletcad.mechanics import strength as st
    from tabletcad.mechanics.materials import get_material

    m = get_material("kostrolith")
    assert d["inputs"] == {"E_MPa": m.E, "nu": m.nu, "radius_mm": 0.7047, "s_y_MPa": m.s_y,
                           "source": {"E": "material kostrolith", "nu": "material kostrolith", "radius": "--radius",
                                      "s_y": "material kostrolith"}}
    assert d["tensile_strength_MPa"] == pytest.approx(st.sphere_hertz(8.6, m.E, m.nu, 0.7047, m.s_y), rel=1e-15)
    rc, out, err = run(capsys, "strength", "pitt", "--force", 100, "--diameter", 10)
    assert rc == 2 and "--thickness" in err


def test_contact_command(capsys, tmp_path):
    plot = tmp_path / "fd.svg"
    rc, out, err = run(capsys, "contact", "--material", "kostrolith", "--force", 3.5, "--plot", plot, "--json")
    assert rc == 0, err
    d = json.loads(out)
    assert d["results"][0]["height_mm"] == pytest.approx(1.3444, abs=5e-5)
    assert d["results"][0]["contact_radius_per_contact_mm"] == pytest.approx(0.1395, abs=5e-5)
    assert len(d["results"][0]["circles"]) == 7 and plot.exists()
    rc, out, err = run(capsys, "contact", "--material", "steel", "--force", 1)
    assert rc == 2 and "must be one of" in err


def test_shell_command(capsys, tmp_path):
    csv = tmp_path / "u.csv"
    rc, out, err = run(capsys, "shell", "--outer", 2.5, "--inner", 2.0, "--E", 100, "--nu", 0.3, "--p-ext", 3,
                       "--p-int", 1, "--psi", 90, "--terms", 20, "--csv", csv, "--json")
    assert rc == 0, err
    d = json.loads(out)
    from tabletcad.mechanics.shell import lame_displacement

    assert d["u_r_outer_mm"]["at_90_deg"] == pytest.approx(float(lame_displacement(2.5, 2.5, 2.0, 100, 0.3, 3, 1)),
                                                          rel=1e-10)
    assert len(csv.read_text().splitlines()) == 182
    bad = tmp_path / "bad.csv"
    rc, out, err = run(capsys, "shell", "--outer", 2.0, "--inner", 2.5, "--E", 100, "--nu", 0.3, "--p-ext", 3,
                       "--csv", bad)
    assert rc == 2 and "inner radius" in err and not bad.exists()


def test_love_command(capsys):
    rc, out, err = run(capsys, "love", "--json")
    assert rc == 0
    d = json.loads(out)
    assert d["omega_z0_mm"] == pytest.approx(-1.2935 + 0.2155033388, rel=1e-9)  # default z = 2.9635 mm
    assert d["n_points"] == 41 and "poor linearity" in err


def test_subprocess_entry_point(tmp_path):
    r = subprocess.run([sys.executable, "-m", "tabletcad", "heckel", str(SAMPLE), "--window", "10", "50"],
                       capture_output=True, text=True, cwd=ROOT, timeout=120, check=False)
    assert r.returncode == 0 and "Py = 104.6 MPa" in r.stdout


def _kN_um_ms_copy(tmp_path: Path, lower: bool = False) -> Path:
    """Appendix B as a ';'-separated, decimal-comma export in kN, µm and ms (optionally with a lower punch)."""
    from decimal import Decimal

    rows = [ln.split(",") for ln in SAMPLE.read_text().splitlines() if ln and not ln.startswith("#")][1:]
    head = "Time [ms];Upper Punch Force (kN);Punch distance (µm)" + (";Lower Punch Force (kN)" if lower else "")
    out = [head]
    for k, r in enumerate(rows):
        cells = [str(k), format(Decimal(r[0]).scaleb(-3), "f"), format(Decimal(r[1]).scaleb(3), "f")]
        out.append(";".join(c.replace(".", ",") for c in cells + (["0,001"] if lower else [])))
    p = tmp_path / "export.csv"
    p.write_text("\ufeff" + "\n".join(out) + "\n", encoding="utf-8")
    return p


def test_heckel_reads_units_from_headers(capsys, tmp_path):
    data = _kN_um_ms_copy(tmp_path)
    meta = SAMPLE.with_suffix(".toml")
    rc, out, err = run(capsys, "heckel", data, "--meta", meta, "--window", 10, 50, "--json")
    assert rc == 0, err
    ref_rc, ref, _ = run(capsys, "heckel", SAMPLE, "--window", 10, 50, "--json")
    d, r = json.loads(out), json.loads(ref)
    assert ref_rc == 0 and (d["K_per_MPa"], d["A"], d["Py_MPa"]) == (r["K_per_MPa"], r["A"], r["Py_MPa"])
    assert not d["warnings"]  # Py is plausible: the kN header was honoured (read as N it gives ~0.1 MPa)
    # the same file with its force unit overridden as N (the misreading): Py falls 1000x and is flagged
    rc, out, err = run(capsys, "heckel", data, "--meta", meta, "--window", 0.01, 0.05, "--force-unit", "N",
                       "--displacement-unit", "µm", "--json")
    assert rc == 0 and "implausible yield pressure" in err
    assert json.loads(out)["Py_MPa"] < 0.2  # (the compliance line then also sees 1000x smaller forces)


def test_heckel_ambiguous_force_column_and_bad_unit(capsys, tmp_path):
    data = _kN_um_ms_copy(tmp_path, lower=True)
    meta = SAMPLE.with_suffix(".toml")
    plot = tmp_path / "p.png"
    rc, _, err = run(capsys, "heckel", data, "--meta", meta, "--window", 10, 50, "--plot", plot)
    assert rc == 2 and err.count("\n") == 1 and "--force-column" in err and not plot.exists()
    rc, out, err = run(capsys, "heckel", data, "--meta", meta, "--window", 10, 50, "--force-column",
                       "Upper Punch Force (kN)", "--json")
    assert rc == 0 and json.loads(out)["K_per_MPa"] == pytest.approx(0.0095647, rel=1e-4)
    rc, _, err = run(capsys, "heckel", data, "--meta", meta, "--force-unit", "kip", "--plot", plot)
    assert rc == 2 and err.startswith("error: --force-unit = 'kip' is not allowed") and not plot.exists()


SHELL = ["shell", "--outer", 2.5, "--inner", 2.0, "--E", 100, "--nu", 0.3, "--p-ext", 3, "--terms", 20]


def _one_line_error(rc, err, *names):
    assert rc == 2 and err.startswith("error: ") and err.count("\n") == 1 and "Traceback" not in err
    for n in names:
        assert n in err


def test_shell_plot_under_a_file_writes_nothing(capsys, tmp_path):
    (tmp_path / "blk").write_text("a file")
    rc, _, err = run(capsys, *SHELL, "--csv", tmp_path / "u.csv", "--plot", tmp_path / "blk" / "p.png")
    _one_line_error(rc, err, "--plot = ", "is a file, not a folder")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["blk"]


def test_outputs_are_written_only_when_all_succeed(capsys, tmp_path, monkeypatch):
    """A failure while making the second output (the plot) leaves neither it nor the first (the table)."""
    import tabletcad.mechanics.shell as shell

    def broken(sol, path):
        Path(path).write_bytes(b"partial")
        raise DesignError("plot", str(path), "failed on purpose")

    from tabletcad.errors import DesignError

    monkeypatch.setattr(shell, "plot_shell", broken)
    rc, _, err = run(capsys, *SHELL, "--csv", tmp_path / "u.csv", "--plot", tmp_path / "p.png")
    assert rc == 2 and err.splitlines()[-1].endswith("failed on purpose") and "Traceback" not in err
    assert list(tmp_path.iterdir()) == []
    monkeypatch.undo()
    rc, _, err = run(capsys, *SHELL, "--csv", tmp_path / "u.csv", "--plot", tmp_path / "sub" / "p.svg")
    assert rc == 0, err
    assert (tmp_path / "u.csv").stat().st_size > 1000 and "<svg" in (tmp_path / "sub" / "p.svg").read_text()


@pytest.mark.parametrize(
    "args,names",
    [
        (["love", "--omega-z0", "nan"], ["--omega-z0 = nan"]),
        (["love", "--z", "inf"], ["--z = inf"]),
        (["love", "--h0", "-1"], ["--h0 = -1"]),
        (["love", "--window", "10", "inf"], ["--window"]),
        # a trial: a window too narrow for the model's densities to change had been named "window"
        (["love", "--window", "1e-300", "1e-299"], ["error: --window = "]),
        (["shell", "--outer", "nan", "--inner", "2", "--E", "100", "--nu", "0.3", "--p-ext", "3"], ["--outer = nan"]),
        (["shell", "--outer", "2.5", "--inner", "2", "--E", "100", "--nu", "0.3", "--p-ext", "nan"], ["--p-ext = nan"]),
        (["contact", "--force", "nan"], ["--force = nan"]),
        (["heckel", SAMPLE, "--window", "nan", "50"], ["--window = nan"]),
        (["heckel", "missing.csv"], ["DATA = 'missing.csv'", "must be an existing file"]),
        (["heckel", SAMPLE, "--meta", "."], ["--meta = '.'", "is a folder"]),
        (["heckel", SAMPLE, "--plot", "out.txt"], ["--plot = 'out.txt'"]),
    ],
)
def test_every_mechanics_option_is_named_in_its_error(capsys, tmp_path, monkeypatch, args, names):
    monkeypatch.chdir(tmp_path)
    rc, _, err = run(capsys, *args)
    _one_line_error(rc, err, *names)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("cmd", [["contact", "--force", "3.5"], ["heckel", SAMPLE, "--window", "10", "50"]])
def test_plot_under_a_file_is_refused_before_computing(capsys, tmp_path, cmd):
    (tmp_path / "blk").write_text("")
    rc, _, err = run(capsys, *cmd, "--plot", tmp_path / "blk" / "x.png")
    _one_line_error(rc, err, "--plot")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["blk"]


from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

_TOKENS = st.sampled_from([
    "force", "Upper Punch Force (kN)", "Lower punch force [N]", "displacement", "Punch distance (µm)", "gap",
    "Time [ms]", "thickness (furlong)", "load", "x", "1", "-5", "0,5", "2.5e3", "nan", "inf", "-", "", "1e400",
    "#", '"', ",", ";", "\t", "\n", "\n", "\n", " ", "é", "\x00",
])


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(body=st.lists(_TOKENS, min_size=0, max_size=60), window=st.booleans())
def test_fuzzed_press_files_keep_the_one_line_contract(capsys, tmp_path, body, window):
    data = tmp_path / "fuzz.csv"
    data.write_text("".join(body), encoding="utf-8")
    plot = tmp_path / "fuzz.png"
    args = ["heckel", data, "--mass", 300, "--true-density", 1.3, "--diameter", 10, "--json"]
    rc, out, err = run(capsys, *args, *(["--window", 1, 100] if window else []))
    assert rc in (0, 2) and "Traceback" not in err
    if rc == 2:
        errors = [ln for ln in err.splitlines() if ln.startswith("error: ")]
        assert len(errors) == 1 and err.splitlines()[-1] == errors[0] and " is not allowed: " in errors[0]
        assert not plot.exists()
    else:
        assert math.isfinite(json.loads(out)["K_per_MPa"])


@pytest.mark.parametrize("cmd, line", [
    (["shell", "--outer", "5", "--inner", "4", "--E", "1000", "--nu", "0.3", "--p-ext", "1e300"],
     "error: --p-ext = 1e+300 MPa is not allowed: must be >= -100000 and <= 100000 MPa"),
    (["shell", "--outer", "5", "--inner", "4", "--E", "1e300", "--nu", "0.3", "--p-ext", "10"],
     "error: --E = 1e+300 MPa is not allowed: must be > 0 and <= 1e+07 MPa"),
    (["love", "--E", "1e300"], "error: --E = 1e+300 MPa is not allowed: must be > 0 and <= 1e+07 MPa"),
    (["love", "--z", "10"], "error: --z = 10 mm is not allowed: must be >= 0 and <= 6 mm"),
])
def test_absurd_moduli_pressures_and_heights_are_refused(capsys, cmd, line):
    """A new user's trial: a platen pressure of 1e300 MPa gave u_r = -7.5e297 mm, E = 1e300 a Heckel Py of
    inf (printed into the JSON as Infinity), and a height above the 6 mm bed K = -0.015 1/MPa: all exit 0."""
    rc, out, err = run(capsys, *cmd)
    assert rc == 2 and err.strip().splitlines() == [line] and out == ""


def test_json_is_strict_json_where_a_figure_is_not_finite(capsys):
    """A Heckel slope of 0 (a constant relative density: eq 5.18 with a huge modulus) has Py = 1/K = inf,
    which had been written as ``Infinity``; strict JSON has no such value, so it is null now."""
    from tabletcad.io.jsontext import json_text

    text = json_text({"Py_MPa": float("inf"), "K": np.float64(0.0), "v": np.array([1.0, np.nan]), "n": np.int64(3)})
    strict = json.loads(text, parse_constant=lambda c: pytest.fail(f"{c} in JSON"))
    assert strict == {"Py_MPa": None, "K": 0.0, "v": [1.0, None], "n": 3}
    rc, out, _ = run(capsys, "love", "--E", "1e7", "--json")
    assert rc == 0
    json.loads(out, parse_constant=lambda c: pytest.fail(f"{c} in JSON"))


def test_json_keys_carry_their_units(capsys):
    """A new user's trial: heckel's metadata (true_density, diameter, compliance slope/offset), love's
    assumptions (h0, z, E...) and shell's angles (theta_0) had keys without units."""
    rc, out, _ = run(capsys, "heckel", SAMPLE, "--json")
    meta = json.loads(out)["metadata"]
    assert rc == 0 and set(meta) == {"mass_mg", "true_density_mg_mm3", "diameter_mm", "compliance"}
    assert meta["true_density_mg_mm3"] == 1.3 and meta["diameter_mm"] == 10.0
    assert set(meta["compliance"]) == {"slope_mm_per_N", "offset_mm"}
    rc, out, _ = run(capsys, "love", "--json")
    assert rc == 0 and set(json.loads(out)["assumptions"]) == {
        "h0_mm", "z_mm", "r_mm", "c_mm", "E_MPa", "nu", "scale", "reference_pressure_MPa",
        "model_displacement_at_reference_mm", "experimental_displacement_mm"}
    rc, out, _ = run(capsys, "shell", "--outer", "5", "--inner", "4", "--E", "1000", "--nu", "0.3", "--p-ext", "10",
                     "--json")
    d = json.loads(out)
    assert rc == 0 and set(d["u_r_outer_mm"]) == {"at_0_deg", "at_45_deg", "at_90_deg", "min", "max"}



@pytest.mark.parametrize("args, line", [
    (("contact", "--force", 3.5, "--material", "foo"), "error: --material = 'foo' is not allowed: must be one of "),
    (("contact", "--force", 3.5, "--radius", -1), "error: --radius = -1 mm is not allowed: must be > 0"),
    (("strength", "sphere", "--force", 3, "--material", "foo"), "error: --material = 'foo' is not allowed: "),
    (("strength", "sphere", "--force", 3, "--material", "kostrolith", "--radius", -1),
     "error: --radius = -1 mm is not allowed: must be > 0"),
    (("heckel", SAMPLE, "--window", 1000, 2000), "error: --window = '1000-2000' is not allowed: holds 0 loading points"),
])
def test_a_refusal_names_the_option_as_typed(capsys, args, line):
    """A value that reached a library function was named by its keyword there (``material``, ``r_s`` of the
    sphere's radius, heckel's ``window``) where the user had typed ``--material``, ``--radius``, ``--window``."""
    rc, out, err = run(capsys, *args)
    assert rc == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and err.startswith(line), err


# ----------------------------------------------------------------------------- a tester's press-data trial (h35c)
_TOML_HEAD = "mass_mg = 300.0\ntrue_density = 1.3\ndiameter = 10.0\ndisplacement_sign = -1\n[compliance]\n"
_STEP = "a step must be >= 0 and <= 0.001 mm/N (a press frame shortens under force, about 2e-5 mm/N): forces in N, " \
        "deflections in mm"


def _refused_writing_nothing(capsys, tmp_path, args, line):
    """``args`` exit 2 with exactly ``line`` on stderr, nothing on stdout, and ``tmp_path`` as it was."""
    before = sorted(p.name for p in tmp_path.iterdir())
    rc, out, err = run(capsys, *args, "--json-file", tmp_path / "r.json")
    assert rc == 2 and out == "" and err.splitlines() == [line], err
    assert sorted(p.name for p in tmp_path.iterdir()) == before


@pytest.mark.parametrize("args, line", [
    # had been exit 1: OverflowError in eq 2.1's cubic
    (["contact", "--force", "100", "--radius", "1e300"],
     "error: --radius = 1e+300 mm is not allowed: must be > 0 and <= 1000 mm"),
    # had been exit 1: ZeroDivisionError (the contact radius at yield underflowed to 0)
    (["strength", "sphere", "--force", "100", "--E", "1e300", "--nu", "0.3", "--radius", "5", "--s-y", "10"],
     "error: --E = 1e+300 MPa is not allowed: must be > 0 and <= 1e+07 MPa"),
    # had been exit 0 with "tensile strength = 0 MPa"
    (["strength", "sphere", "--force", "100", "--E", "1000", "--nu", "0.3", "--radius", "1e300", "--s-y", "10"],
     "error: --radius = 1e+300 mm is not allowed: must be > 0 and <= 1000 mm"),
    (["strength", "sphere", "--force", "100", "--E", "1000", "--nu", "0.3", "--radius", "5", "--s-y", "1e300"],
     "error: --s-y = 1e+300 MPa is not allowed: must be > 0 and <= 10000 MPa"),
])
def test_sphere_inputs_out_of_range_are_refused_by_their_options(capsys, tmp_path, args, line):
    _refused_writing_nothing(capsys, tmp_path, args, line)


@pytest.mark.parametrize("option", ["--outer", "--inner"])
def test_shell_radii_keep_the_size_limit(capsys, tmp_path, option):
    """--outer 1e300 had run: u_r(a) = -4e+297 mm, exit 0; the radii are lengths, at most 1000 mm."""
    radii = {"--outer": "5", "--inner": "3", option: "1e300"}
    args = ["shell", "--outer", radii["--outer"], "--inner", radii["--inner"], "--E", "1000", "--nu", "0.3",
            "--p-ext", "10"]
    _refused_writing_nothing(capsys, tmp_path, args,
                             f"error: {option} = 1e+300 mm is not allowed: must be > 0 and <= 1000 mm")
    rc, out, err = run(capsys, "shell", "--outer", 1000, "--inner", 999, "--E", 1000, "--nu", 0.3, "--p-ext", 10)
    assert rc == 0 and "a = 1000 mm" in out


def test_sphere_at_the_length_limit_still_runs(capsys):
    """A 1000 mm sphere (the size limit itself) is taken by contact and strength alike."""
    rc, out, err = run(capsys, "contact", "--force", 100, "--radius", 1000)
    assert rc == 0 and err == "" and "r_s = 1000 mm" in out
    rc, out, err = run(capsys, "strength", "sphere", "--force", 100, "--E", 1e7, "--nu", 0.3, "--radius", 1000,
                       "--s-y", 10000)
    assert rc == 0 and err == "" and "tensile strength" in out


@pytest.mark.parametrize("table, line", [
    # an empty table had been taken as no compliance: exit 0, K = 0.00988 instead of 0.008557 1/MPa, no word
    ("force = []\ndeflection = []\n",
     "error: compliance.table = 0 is not allowed: needs >= 2 finite (force, deflection) pairs"),
    # a deflection falling as the force rises had been accepted (K = 0.01103), unlike a negative slope
    ("force = [0, 5000, 10000]\ndeflection = [0, -0.1, -0.2]\n",
     "error: compliance.deflection[1] = -0.1 mm is not allowed: its step from 0 mm at 0 N to -0.1 mm at 5000 N is "
     f"-2e-05 mm/N; {_STEP}"),
    ("force = [0, 5000, 10000]\ndeflection = [0, 0.1, 0.05]\n",
     "error: compliance.deflection[2] = 0.05 mm is not allowed: its step from 0.1 mm at 5000 N to 0.05 mm at "
     f"10000 N is -1e-05 mm/N; {_STEP}"),
    # the forces had been shown as [np.float64(5000.0), np.float64(0.0), np.float64(10000.0)]
    ("force = [5000, 0, 10000]\ndeflection = [0.1, 0, 0.2]\n",
     "error: compliance.force[1] = 0 N is not allowed: must be > compliance.force[0] = 5000 N (the forces strictly "
     "increasing)"),
])
def test_a_compliance_table_no_press_has_is_refused_by_its_entry(capsys, tmp_path, table, line):
    meta = tmp_path / "m.toml"
    meta.write_text(_TOML_HEAD + table, encoding="utf-8")
    _refused_writing_nothing(capsys, tmp_path, ["heckel", SAMPLE, "--meta", meta, "--plot", tmp_path / "h.png"], line)


@pytest.mark.parametrize("table", [
    "force = [0, 6000]\ndeflection = [0.0267, 0.1467]\n",                # the sample's line as a table
    "force = [0, 3000, 6000]\ndeflection = [0.0267, 0.0867, 0.1467]\n",
])
def test_a_valid_compliance_table_gives_the_samples_K(capsys, tmp_path, table):
    meta = tmp_path / "m.toml"
    meta.write_text(_TOML_HEAD + table, encoding="utf-8")
    rc, out, err = run(capsys, "heckel", SAMPLE, "--meta", meta, "--json")
    assert rc == 0, err
    got = json.loads(out)
    assert got["K_per_MPa"] == pytest.approx(0.0085565, abs=5e-7) and got["n_points"] == 13
    rc, out, _ = run(capsys, "heckel", SAMPLE, "--json")  # its own compensation line
    assert rc == 0 and got["K_per_MPa"] == pytest.approx(json.loads(out)["K_per_MPa"], rel=1e-9)


@pytest.mark.parametrize("cmd", ["kawakita", "walker"])
@pytest.mark.parametrize("rows, extra, line", [
    # a pressure had been named "row[1].force = -10 N"
    ("-10,5\n10,4\n20,3\n", [],
     'error: "p.csv".line[2].pressure_MPa = -10 MPa is not allowed: must be >= 0 (a compaction pressure)'),
    # "--window = None" though no --window was given
    ("0,5\n10,4\n20,3\n", [], "error: data = '2 points with a pressure > 0' is not allowed: need >= 3"),
    ("0,5\n10,4\n20,3\n", ["--window", "5", "15"],
     "error: --window = '5-15' is not allowed: holds 1 usable points; need >= 3"),
    # "peak force at row 3" for a table that has no force column
    ("10,5\n10,5\n10,5\n", [],
     "error: data = 'peak pressure at row 3' is not allowed: has no loading branch (pressure must rise over >= 3 rows)"),
])
def test_a_compression_table_refusal_names_its_pressures(capsys, tmp_path, cmd, rows, extra, line):
    data = tmp_path / "p.csv"
    data.write_text("pressure_MPa,thickness_mm\n" + rows, encoding="utf-8")
    _refused_writing_nothing(capsys, tmp_path, [cmd, data, *extra], line)


def test_walker_warns_of_a_volume_that_does_not_fall(capsys, tmp_path):
    """A thickness rising with the pressure gave W = -96.94 % per decade, exit 0, without a word.  It is a
    fit the equation can make (unlike Kawakita's, which has no volume reduction to fit and refuses), so it is
    warned of, as Heckel's K <= 0 is; a falling thickness gives no warning."""
    data = tmp_path / "p.csv"
    data.write_text("pressure_MPa,thickness_mm\n10,5\n20,6\n30,7\n40,8\n", encoding="utf-8")
    rc, out, err = run(capsys, "walker", data, "--json")
    warning = ("Walker fit: non-positive coefficient W = -96.94 % per decade: the volume does not fall as the "
               "pressure rises (check the thickness column and h0)")
    assert rc == 0 and err.splitlines() == [f"warning: {warning}"]
    d = json.loads(out)
    assert d["warnings"] == [warning] and d["W_percent_per_decade"] == pytest.approx(-96.935, abs=1e-3)
    rc, out, err = run(capsys, "walker", ROOT / "samples" / "press" / "lactose_appendix_b.csv", "--json")
    assert rc == 0 and err == "" and json.loads(out)["W_percent_per_decade"] > 0


OMEGA_WHY = ("(so that the bed stays thicker than 0, at least 3 of the 41 "
             "simulated points keep a relative density below 1 for the Hec"
             "kel fit and the densest reaches 0.05; and within ±6 mm, a sh"
             "ift of the punch face by at most the bed's height)")


@pytest.mark.parametrize("args, line", [
    (["--r", "100"], "error: --r = 100 mm is not allowed: must be >= 0.001 and <= 5 mm"),  # had been "r = 100 mm"
    # had been exit 1: ZeroDivisionError (r * r underflowed to 0)
    (["--r", "1e-300"], "error: --r = 1e-300 mm is not allowed: must be >= 0.001 and <= 5 mm"),
    # had been refused as "relative_density = 'at most 2.94e-300'"
    (["--omega-z0", "1e300"], "error: --omega-z0 = 1e+300 mm is not allowed: must be > -2.80315 and <= 6 mm " + OMEGA_WHY),
    # had been "pressure = 10 MPa", then "the model then compresses the 6 mm bed to zero thickness at 10 MPa"
    # although "must be >= -6 and <= 6 mm" had offered it
    (["--omega-z0", "-5.9"], "error: --omega-z0 = -5.9 mm is not allowed: must be > -2.80315 and <= 6 mm " + OMEGA_WHY),
    (["--window", "10", "1000"], "error: --window = 232.75 MPa is not allowed: compresses the model bed to zero "
                                 "thickness (h0 = 6 mm, ω_z0 = -1.078 mm)"),
])
def test_love_names_its_options(capsys, tmp_path, args, line):
    _refused_writing_nothing(capsys, tmp_path, ["love", *args], line)


MODEL_WHY = ("(where the model runs with the other options: the bed stays thicker than 0, at least 3 of the 41 "
             "simulated points keep a relative density below 1 for the Heckel fit and the densest reaches 0.05)")


@pytest.mark.parametrize("args, line", [
    # had been "relative_density = 'at most 0.0298' ... check the mass (mg, not g), the true density (mg/mm³), the
    # die diameter (mm) and the displacement's unit": options love does not have, and --h0 not named
    (["--h0", "100"], "error: --h0 = 100 mm is not allowed: must be >= 4.292 and <= 60.1443 mm " + MODEL_WHY),
    # over the 1000 mm length limit: had been refused as a relative density too
    (["--h0", "6000"], "error: --h0 = 6000 mm is not allowed: must be > 0 and <= 1000 mm"),
    # GPa typed as MPa had been "--window = 11 MPa is not allowed: compresses the model bed to zero thickness"
    (["--E", "2.64"], "error: --E = 2.64 MPa is not allowed: must be >= 483.527 and <= 1e+07 MPa " + MODEL_WHY
                      + "; Young's modulus in MPa: 2.64 GPa is 2640 MPa"),
    # a bed below the default --z had been "--z = 2.9635 mm is not allowed", an option not given
    (["--h0", "2"], "error: --h0 = 2 mm is not allowed: must be >= 2.9635 mm, the default --z (the height where "
                    "ω_z is taken lies within the bed; or give a lower --z)"),
    # an option with no working value while another is out of its range: the other is named (an ordinary
    # --nu 0.3, tried first, had been blamed: "no value works with the other options")
    (["--z", "0.5", "--h0", "0.6", "--nu", "0.3"], "error: --h0 = 0.6 mm is not allowed: must be >= 4.23377 and "
                                                   "<= 60.0612 mm " + MODEL_WHY),
])
def test_love_names_the_option_given_not_the_models_quantity(capsys, tmp_path, args, line):
    _refused_writing_nothing(capsys, tmp_path, ["love", *args], line)


@pytest.mark.parametrize("option, value, lo, hi", [("--h0", 100.0, "4.292", "60.1443"), ("--E", 2.64, "483.527", "1e+07")])
def test_loves_model_range_ends_run(capsys, option, value, lo, hi):
    """The ends of the stated range compute (exit 0); a step outside the lower end is refused again."""
    for end in (lo, hi):
        rc, out, err = run(capsys, "love", option, end, "--json")
        assert rc == 0 and math.isfinite(json.loads(out)["K_per_MPa"]), err
    rc, _, err = run(capsys, "love", option, float(lo) * (1 - 1e-5))
    assert rc == 2 and err.startswith(f"error: {option} = ") and f"must be >= {lo} and <= {hi}" in err


@pytest.mark.parametrize("options", [[], ["--h0", "10", "--z", "5"], ["--h0", "60"], ["--window", "10", "500"],
                                     ["--E", "900", "--nu", "0.4"]])
def test_loves_omega_z0_range_is_what_it_computes(capsys, tmp_path, options):
    """The stated ``--omega-z0`` range had been ``[-h0, h0]``; in a 6 mm bed -5.9 mm was refused as a bed
    pressed to nothing and -3 to -4.5 mm as the Heckel fit's window (every point denser than the solid).
    Now it is where the model runs: its printed ends compute (exit 0, a fit over the window), and a value
    just outside either end is refused with the same range."""
    import re

    rc, out, err = run(capsys, "love", *options, "--omega-z0", "-1e6")
    m = re.fullmatch(r"error: --omega-z0 = -1e\+06 mm is not allowed: must be (>=?) (\S+) and <= (\S+) mm(.*)\n", err)
    assert rc == 2 and out == "" and m, err
    lo, hi = float(m.group(2)), float(m.group(3))
    assert lo < hi
    for end in (lo, hi):
        rc, out, err = run(capsys, "love", *options, "--omega-z0", repr(end), "--json")
        assert rc == 0, err
        d = json.loads(out)
        assert d["omega_z0_mm"] == end and d["n_points"] >= 3 and math.isfinite(d["K_per_MPa"])
    h0 = float(options[options.index("--h0") + 1]) if "--h0" in options else 6.0
    for out_of in (lo - 2e-5 * max(abs(lo), 1.0), hi + 2e-5 * max(abs(hi), 1.0)):
        rc, _, err = run(capsys, "love", *options, "--omega-z0", repr(out_of))
        assert rc == 2 and err.endswith(f"must be {m.group(1)} {m.group(2)} and <= {m.group(3)} mm{m.group(4)}\n"), err
    assert -h0 <= lo and hi <= h0


def test_simulate_compressions_omega_z0_range_from_python():
    """The model's own rules as bounds on omega_z0, checked against the thickness and density they give."""
    from tabletcad.errors import DesignError
    from tabletcad.mechanics.love import omega_z0_range, simulate_compression

    P = np.linspace(10.0, 50.0, 41)
    lo, hi = omega_z0_range(P)
    h_dense = 300.0 / (1.3 * math.pi * 25.0)  # thickness at relative density 1 (mm)
    for w0 in (lo + 1e-9, hi):
        sim = simulate_compression(P, omega_z0=w0)
        assert np.all(sim.thickness > 0) and np.sum(sim.thickness > h_dense) >= 3
        assert sim.relative_density.max() >= 0.05
    # just below lo the third thickest point is as dense as the solid (or the bed is gone)
    sim = simulate_compression(P, omega_z0=lo + 1e-6)
    assert np.sort(sim.thickness)[::-1][2] == pytest.approx(h_dense, abs=2e-6)
    with pytest.raises(DesignError, match=r"^omega_z0 = -5.9 mm is not allowed: must be > -2.80315 and <= "):
        simulate_compression(P, omega_z0=-5.9)
    with pytest.raises(DesignError, match=r"^omega_z0 = "):
        simulate_compression(P, omega_z0=hi + 1e-6)


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs Linux's /dev/full")
@pytest.mark.parametrize("args", [
    ["heckel", str(SAMPLE), "--plot", "h.png", "--json-file", "h.json"],
    ["shell", "--outer", "5", "--inner", "4", "--E", "100", "--nu", "0.3", "--p-ext", "1", "--psi", "10",
     "--csv", "u.csv", "--plot", "u.png", "--json-file", "u.json"],
])
def test_a_refused_standard_output_leaves_no_file(tmp_path, args):
    """A trial: ``heckel ... --plot h.png > /dev/full`` exited 2 with one line and left h.png; the files
    are moved into place only once the result is printed."""
    env = {**os.environ, "XDG_CACHE_HOME": str(tmp_path / "cache"), "PYTHONPATH": str(ROOT)}
    work = tmp_path / "work"
    work.mkdir()
    with open("/dev/full", "w") as full:
        proc = subprocess.run([sys.executable, "-m", "tabletcad", *args], stdout=full, stderr=subprocess.PIPE,
                              text=True, env=env, cwd=work, timeout=120)
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1, proc.stderr
    assert sorted(work.iterdir()) == []
    proc = subprocess.run([sys.executable, "-m", "tabletcad", *args], capture_output=True, text=True, env=env,
                          cwd=work, timeout=120)
    assert proc.returncode == 0 and len(list(work.iterdir())) == 2 + ("--csv" in args), proc.stderr


@pytest.mark.parametrize("model", [{}, {"h0": 4.3}, {"E": 483.6}, {"nu": 1e-9}, {"h0": 60.0}, {"z": 6.0}])
def test_omega_z0_ranges_ends_are_exact_in_floating_point(capsys, model):
    """The closed-form ends round differently from the model's sums: the value next to the lower end had
    been let through and then refused by the model, as the fit's window from Python and as ``--h0 = 4.3 mm
    ... must be >= 4.30001`` (an option given in range) on the command line.  Now the next value above
    ``lo`` runs, ``lo`` does not, ``hi`` runs and the next above it does not."""
    from tabletcad.errors import DesignError
    from tabletcad.mechanics.love import omega_z0_range, simulate_compression

    P = np.linspace(10.0, 50.0, 41)
    lo, hi = omega_z0_range(P, **model)
    for w0 in (math.nextafter(lo, math.inf), hi):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            assert simulate_compression(P, omega_z0=w0, **model).heckel.n_points >= 3
    for w0 in (lo, math.nextafter(hi, math.inf)):
        with pytest.raises(DesignError, match=r"^omega_z0 = "):
            simulate_compression(P, omega_z0=w0, **model)
    if model in ({"h0": 4.3}, {"E": 483.6}):  # the command line: the option at fault is --omega-z0
        options = [a for k, v in model.items() for a in (f"--{k}", repr(v))]
        rc, _, err = run(capsys, "love", *options, "--omega-z0", repr(lo))
        assert rc == 2 and err.startswith("error: --omega-z0 = ") and err.count("\n") == 1, err
        rc, out, err = run(capsys, "love", *options, "--omega-z0", repr(math.nextafter(lo, math.inf)), "--json")
        assert rc == 0 and json.loads(out)["omega_z0_mm"] == math.nextafter(lo, math.inf), err


def test_heckel_refuses_punch_travel_taken_as_the_gap(capsys, tmp_path):
    """A new user's trial: 'Punch Travel (mm)' rising with the force, metadata without displacement_sign, gave
    K = -0.0003289 1/MPa and Py = -3040 MPa with exit 0.  One line now, exit 2, nothing written."""
    F = np.linspace(0.05, 15.0, 40)
    travel = 8.0 - 300.0 / (1.3 * np.pi * 25.0 * (1.0 - np.exp(-(10.0 * F / (np.pi * 25.0) + 0.9))))
    data = tmp_path / "travel.csv"
    data.write_text("Upper Punch Force (kN),Punch Travel (mm)\n" + "".join(f"{f:.5f},{x:.5f}\n" for f, x in zip(F, travel)))
    (tmp_path / "travel.toml").write_text("mass_mg = 300.0\ntrue_density = 1.3\ndiameter = 10.0\n")
    rc, out, err = run(capsys, "heckel", data, "--json-file", tmp_path / "h.json")
    assert rc == 2 and out == "" and not (tmp_path / "h.json").exists()
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    assert err.startswith("error: displacement_sign = 'auto' is not allowed: makes the punch gap 0 + "
                          "'Punch Travel (mm)' grow from")
    assert "displacement_zero" in err
