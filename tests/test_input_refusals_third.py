"""Inputs a third new user gave that crashed, were taken as something else, or were refused under a
name that is not one token (session 22's trial).

Each case: the exact ``error: <parameter> = <value> is not allowed: <range>`` line (the parameter one
token, the key path of the file or the option as given), exit status 2, nothing written; or, where
the input is valid, the value it must give.  Core only (numpy, scipy).
"""

from __future__ import annotations

import re

import pytest

from tabletcad.cli import main
from tabletcad.errors import DesignError, one_token

ONE_LINE = re.compile(r"^error: (\S+) = (.+) is not allowed: (.+)$")


def _run(capsys, tmp_path, *args: str) -> tuple[int, list[str]]:
    rc = main([str(a) for a in args])
    err = capsys.readouterr().err.strip().splitlines()
    return rc, err


@pytest.mark.parametrize("written, token", [
    ("[[tooling.score]] 0 depth_mm", "tooling.score[0].depth_mm"),
    ("[[tooling.emboss]].0.stroke_angle_deg", "tooling.emboss[0].stroke_angle_deg"),
    ("[tooling] die_outer_diameter_mm", "tooling.die_outer_diameter_mm"),
    ("[tooling].clearance_mm", "tooling.clearance_mm"),
    ("[report] key 'weight'", "report.weight"),
    ("top-level key 'extra'", "extra"),
    ("[sweep.vary] 'tablet.diameter' max", 'sweep.vary."tablet.diameter".max'),
    ("[design] key 'two words'", 'design."two\\u0020words"'),
    ("[[constraint]] 0 target", "constraint[0].target"),
    ("outline item 3", "outline[3]"),
    ("patch 2", "patch[2]"),
    ("'bad.csv' line 3 'pressure_MPa'", '"bad.csv".line[3].pressure_MPa'),
    ("'Run 1.csv' line 4 'Thickness (mm)'", '"Run\\u00201.csv".line[4]."Thickness\\u0020(mm)"'),
    ("[report] key 'a\\tb'", 'report."a\\u0009b"'),
    ("'tablet.2.x' max", '"tablet.2.x".max'),
    ("v1.2", "v1.2"),
    ("tablet.diameter", "tablet.diameter"),
    ("patch[0].curves[1].radius", "patch[0].curves[1].radius"),
    ("--nodes", "--nodes"),
])
def test_a_parameter_is_one_token_the_key_path(written, token):
    assert one_token(written) == token
    e = DesignError(written, 3.0, "must be > 4", "mm")
    assert e.parameter == token and str(e) == f"{token} = 3 mm is not allowed: must be > 4"
    assert one_token(token) == token  # a token is kept


CUSTOM = '[tablet]\nfamily = "custom_outline"\nband = 2.8\ncup_depth = 0.3\n'


@pytest.mark.parametrize("text, line", [
    # collinear points: a spline there and back, enclosing nothing (ZeroDivisionError, exit 1)
    (CUSTOM + "outline = [[0,0],[1,0],[2,0],[3,0]]\n",
     "error: tablet.outline = 'an outline enclosing 0 mm^2' is not allowed: the points must enclose an area "
     "(they lie on one line)"),
    # a quoted coordinate was read as the number
    (CUSTOM + 'outline = [[0,0],["4.5",0],[4,4],[0,4]]\n',
     "error: tablet.outline[1][0] = '4.5' is not allowed: must be a number"),
    (CUSTOM + 'segments = [["arc",[0,0],"3",0,6.283185307179586]]\n',
     "error: tablet.segments[0][2] = '3' is not allowed: must be a number"),
    (CUSTOM + 'segments = [["line", ["0", 0], [4, 0]], ["line", [4,0],[4,4]], ["line",[4,4],[0,4]], ["line",[0,4],[0,0]]]\n',
     "error: tablet.segments[0][1][0] = '0' is not allowed: must be a number"),
    # one flat patch, a disc: the report divided by its zero volume (exit 1), the build failed in Qhull
    ('[tablet]\nfamily = "free_form"\n[[patch]]\ncurves = [\n'
     + ",\n".join(f'  {{ type = "circle", radius = {r}, z = 0 }}' for r in (0, 2, 4, 5)) + "\n]\n",
     "error: patch = 'an enclosed volume of 0 mm^3' is not allowed: the patches must enclose a solid "
     "(volume >= 1e-09 mm^3)"),
    # a die narrower than the tablet: report took it, build refused it after the geometry
    ('[tablet]\nfamily = "concave_round"\ndiameter = 10.0\nband = 2.8\ncup_depth = 0.9\n'
     "[tooling]\ndie_outer_diameter_mm = 5\ndie_height_mm = 22.0\n",
     "error: tooling.die_outer_diameter_mm = 5 mm is not allowed: must be >= 14 mm (the tablet reaches 5 mm "
     "from the axis, the die's walls need 2.0 mm)"),
    ('[tablet]\nfamily = "concave_round"\ndiameter = 10.0\nband = 2.8\ncup_depth = 0.9\n'
     '[[tooling.emboss]]\ntext = "A\\u0000B"\nmode = "deboss"\n',
     "error: tooling.emboss[0].text = 'A\\x00B' is not allowed: must be printable text on one line "
     "(no control characters)"),
    ('[tablet]\nfamily = "concave_round"\ndiameter = 10.0\nband = 2.8\ncup_depth = 0.9\n'
     f'[[tooling.emboss]]\ntext = "{"X" * 41}"\nmode = "deboss"\n',
     f"error: tooling.emboss[0].text = '{'X' * 41}' is not allowed: must be at most 40 characters"),
    ('[tablet]\nfamily = "concave_round"\ndiameter = 10.0\nband = 2.8\ncup_depth = 0.9\n'
     '[tooling.fe_rating]\nsteel = "S7_tempered_205C"\nsafety_factor = 0.5\n',
     "error: tooling.fe_rating.safety_factor = 0.5 is not allowed: must be >= 1 and <= 100"),
])
def test_design_files_refused_by_report_and_build(tmp_path, capsys, text, line):
    d = tmp_path / "bad.toml"
    d.write_text(text, encoding="utf-8")
    for args in (["report", d], ["build", d, "--out", tmp_path / "out", "--quiet"]):
        rc, err = _run(capsys, tmp_path, *args)
        assert rc == 2 and err == [line], (args[0], err)
        assert ONE_LINE.match(err[0])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.toml"]


def test_python_api_refuses_text_coordinates():
    from tabletcad.families import outline_tablet

    with pytest.raises(DesignError) as e:
        outline_tablet([[0, 0], ["4", 0], [4, 4], [0, 4]], band=2.8, cup_depth=0.3)
    assert e.value.parameter == "outline[1][0]" and "not text" in str(e.value)


def test_solve_for_names_a_dimension_given_as_text():
    from tabletcad.families.inverse import solve_for

    with pytest.raises(DesignError) as e:
        solve_for("flat_face_round", target_volume_mm3=300, vary="thickness", diameter="10")
    assert str(e.value) == "diameter = '10' is not allowed: must be a finite number, not text"
    # the same with a number: the thickness of a 10 mm flat cylinder of 300 mm^3, 12/pi
    assert solve_for("flat_face_round", target_volume_mm3=300, vary="thickness", diameter=10).value == \
        pytest.approx(12.0 / 3.141592653589793, rel=1e-9)


PRESS = "pressure_MPa,thickness_mm\n10,5.0\n20,4.6\n40,4.2\n60,3.9\n80,{h}\n"


@pytest.mark.parametrize("cmd", ["kawakita", "walker"])
def test_compression_tables_refuse_a_thickness_that_is_no_length(tmp_path, capsys, cmd):
    p = tmp_path / "p.csv"
    p.write_text(PRESS.format(h="0"), encoding="utf-8")
    rc, err = _run(capsys, tmp_path, cmd, p, "--json-file", tmp_path / "r.json")
    assert rc == 2 and err == ['error: "p.csv".line[6].thickness_mm = 0 mm is not allowed: must be > 0 (the '
                               "compact's thickness)"]
    assert sorted(q.name for q in tmp_path.iterdir()) == ["p.csv"]


@pytest.mark.parametrize("cmd", ["kawakita", "walker"])
def test_compression_tables_in_windows_1252_read_as_utf_8(tmp_path, capsys, cmd):
    """A press export's comment in Windows-1252 ("Messung é") stopped kawakita and walker with a
    UnicodeDecodeError (exit 1); heckel read it.  The same fit as the UTF-8 file."""
    body = "# Messung é µm\n" + PRESS.format(h="3.7")
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    a.write_bytes(body.encode("utf-8"))
    b.write_bytes(body.encode("cp1252"))
    out = []
    for p in (a, b):
        rc, err = _run(capsys, tmp_path, cmd, p, "--json-file", tmp_path / f"{p.stem}.json")
        assert rc == 0, err
        out.append((tmp_path / f"{p.stem}.json").read_text())
    import json

    ra, rb = (json.loads(x) for x in out)
    ra.pop("data"), rb.pop("data")
    assert ra == rb


def test_heckel_window_of_a_negative_pressure_is_refused(tmp_path, capsys):
    p = tmp_path / "press.csv"
    p.write_text("force_N,thickness_mm\n100,5\n", encoding="utf-8")
    rc, err = _run(capsys, tmp_path, "heckel", p, "--window", "-5", "10", "--mass", "300", "--true-density", "1.5",
                   "--diameter", "10")
    assert rc == 2 and err == ["error: --window = -5 MPa is not allowed: must be >= 0 and <= 100000 MPa"]


@pytest.mark.parametrize("args, line", [
    (["strength", "diametral", "--force", "100", "--diameter", "10", "--thickness", "4", "--band", "2"],
     "error: --band = 2 is not allowed: is not used by method 'diametral', which takes --diameter, --thickness"),
    (["strength", "pitt", "--force", "100", "--diameter", "10", "--thickness", "4", "--band", "5"],
     "error: --band = 5 mm is not allowed: must be <= the total thickness t = 4 mm (eq 2.7 (Pitt 1988))"),
    (["heckel", "x.csv", "--mass", "-3", "--true-density", "1.5", "--diameter", "10"],
     "error: --mass = -3 mg is not allowed: must be > 0 and <= 1e+06 mg"),
])
def test_options_named_as_given(tmp_path, capsys, monkeypatch, args, line):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "x.csv").write_text("force_N,thickness_mm\n100,5\n200,4.5\n", encoding="utf-8")
    rc, err = _run(capsys, tmp_path, *args)
    assert rc == 2 and err == [line]


def test_a_table_error_names_the_file_line_past_comments(tmp_path, capsys):
    """The line named is the file's (comments and blank lines counted), not the row's."""
    p = tmp_path / "Run 1.csv"
    p.write_text("# press export\n\n# second comment\n" + PRESS.format(h="-2.8"), encoding="utf-8")
    rc, err = _run(capsys, tmp_path, "walker", p)
    assert rc == 2 and err == ['error: "Run\\u00201.csv".line[9].thickness_mm = -2.8 mm is not allowed: must be > 0 '
                               "(the compact's thickness)"]


def test_a_sweep_row_with_a_die_too_narrow_for_its_tablet_fails_as_report_refuses_it():
    """Rows are what ``tabletcad report`` gives: a 14.5 mm die takes the 10 mm round (>= 14 mm) but not
    the 12 mm one (>= 16 mm); both rows had come back "ok" without the tooling output."""
    from tabletcad.sweep.engine import evaluate_design

    def design(d):
        return {"tablet": {"family": "concave_round", "diameter": d, "band": 2.8, "cup_depth": 0.9},
                "tooling": {"die_outer_diameter_mm": 14.5, "die_height_mm": 22.0}}

    ok, bad = evaluate_design(design(10.0)), evaluate_design(design(12.0))
    assert ok["status"] == "ok" and ok["values"]["volume_mm3"] > 0
    assert bad["status"] == "error" and bad["error"].startswith(
        "tooling.die_outer_diameter_mm = 14.5 mm is not allowed: must be >= 16 mm"), bad["error"]


def test_spaces_of_every_width_are_text_control_characters_are_not():
    from tabletcad.tooling.spec import parse_tooling

    spec = parse_tooling({"drawing": {"author": "J.\u2009Smith", "material": "D2\u00a0steel"},
                          "emboss": [{"text": "10\u00a0mg", "mode": "deboss"}]})
    assert spec.drawing.author == "J.\u2009Smith" and spec.emboss[0].text == "10\u00a0mg"
    for bad in ("A\u200bB", "A\u2028B", "A\tB"):
        with pytest.raises(DesignError, match="printable text on one line"):
            parse_tooling({"emboss": [{"text": bad, "mode": "deboss"}]})


def test_a_custom_outline_s_dimension_is_named_by_its_key(tmp_path, capsys):
    d = tmp_path / "co.toml"
    d.write_text(CUSTOM.replace("cup_depth = 0.3", "cup_depth = 5") + "outline = [[0,0],[6,0],[6,4],[0,4]]\n")
    rc, err = _run(capsys, tmp_path, "report", d)
    assert rc == 2 and err[0].startswith("error: tablet.cup_depth = 5 mm is not allowed: must be > 0 and <= 2.56")


@pytest.mark.parametrize("kind", ["sweep", "optimise", "heckel"])
def test_every_toml_reader_refuses_nesting_too_deep_in_one_line(tmp_path, capsys, kind):
    """A sweep file, a problem file and a press record's metadata nested 5,000 deep (a trial: an internal
    error, exit 1, as the design file's reader had refused it in one line): one line naming the file,
    exit 2, nothing written.  Each reader is tabletcad.io.tomlfile.read_toml_file."""
    deep = "[" * 5000 + "]" * 5000
    if kind == "sweep":
        f = tmp_path / "deep.toml"
        f.write_text('[design.tablet]\nfamily = "concave_round"\ndiameter = 10.0\nband = 2.8\ncup_depth = 0.9\n'
                     f'[sweep]\nmethod = "grid"\n[sweep.vary]\n"tablet.band" = {deep}\n', encoding="utf-8")
        args, name = ["sweep", f, "--out", tmp_path / "out"], "SWEEP.toml"  # (its usage line's name)
    elif kind == "optimise":
        f = tmp_path / "deep.toml"
        f.write_text(f'[problem]\nkind = "family"\nx = {deep}\n', encoding="utf-8")
        args, name = ["optimise", f, "--out", tmp_path / "out"], "PROBLEM.toml"
    else:
        from pathlib import Path

        src = Path(__file__).resolve().parents[1] / "samples" / "press" / "lactose_appendix_b.csv"
        f = tmp_path / "deep.csv"
        f.write_bytes(src.read_bytes())
        (tmp_path / "deep.toml").write_text(f"mass_mg = {deep}\n", encoding="utf-8")
        args, name = ["heckel", f], "metadata"
    before = sorted(p.name for p in tmp_path.iterdir())
    import importlib.util

    if kind == "sweep" and importlib.util.find_spec("distributed") is None:  # the core's run: the reader itself
        from tabletcad.sweep.spec import load_sweep

        with pytest.raises(DesignError) as exc:
            load_sweep(f)
        rc, err = 2, [f"error: {exc.value}".replace("sweep.file", "SWEEP.toml")]
    else:
        rc, err = _run(capsys, tmp_path, *args)
    assert rc == 2 and len(err) == 1, err
    assert err[0] == f"error: {name} = 'deep.toml' is not allowed: must be valid TOML nested less than a few hundred " \
                     "levels deep", err
    assert sorted(p.name for p in tmp_path.iterdir()) == before
