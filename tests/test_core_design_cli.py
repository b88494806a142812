"""Design files, the geometry CLI (shapes, build, mesh), reports and reshaping (thesis section 4.4)."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tabletcad import families
from tabletcad.families import reshape
from tabletcad.families import thesis as shapes
from tabletcad.cli import main
from tabletcad.pipeline.design import design_from_dict, load_design
from tabletcad.errors import DesignError

ROOT = Path(__file__).resolve().parents[1]
SAMPLES = sorted(p for p in (ROOT / "samples").glob("*.toml"))


def _core_only_build(tablet, out):
    """Build without the optional CAD stages (they have their own tests)."""
    from tabletcad.pipeline.build import build_tablet

    return build_tablet(tablet, out, cad=False, progress=False)


@pytest.mark.parametrize("path", SAMPLES, ids=lambda p: p.stem)
def test_every_sample_design_loads_and_reports(path, tmp_path):
    t = load_design(path)
    rep = _core_only_build(t, tmp_path / "out")
    for key in ("volume_mm3", "surface_area_mm2", "height_mm", "width_mm", "length_mm", "patches", "seams"):
        assert key in rep
    assert rep["volume_mm3"] > 0 and rep["surface_area_mm2"] > 0
    assert abs(rep["solid_volume_mm3"] - rep["volume_mm3"]) <= 1e-9 * rep["volume_mm3"]
    for p in rep["patches"]:
        assert {"surface_area_mm2", "volume_mm3"} <= set(p)
    for s in rep["seams"]:
        assert s["max_gap_mm"] <= 1e-9
    on_disk = json.loads((tmp_path / "out" / "report.json").read_text())
    assert on_disk["volume_mm3"] == pytest.approx(rep["volume_mm3"], rel=1e-15)
    png = (tmp_path / "out" / "tablet.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 10_000


def test_family_design_matches_constructor():
    t = design_from_dict({"tablet": {"family": "thesis.shallow_convex_round", "diameter": 8.0, "thickness": 3.2, "band": 2.0}})
    ref = shapes.shallow_convex_round(8.0, 3.2, 2.0)
    assert t.volume() == pytest.approx(ref.volume(), rel=1e-14)
    assert t.params == {"diameter": 8.0, "thickness": 3.2, "band": 2.0}


def test_free_form_design_with_previous_and_trim():
    d = {
        "tablet": {"family": "free_form", "name": "cyl"},
        "patch": [
            {"curves": [{"type": "circle", "radius": r, "z": 0.0} for r in (0.0, 1.0, 2.0, 3.0)]},
            {"curves": ["previous"] + [{"type": "circle", "radius": 3.0, "z": z} for z in (1.0, 2.0, 3.0)]},
            {"curves": ["previous"] + [{"type": "circle", "radius": r, "z": 3.0} for r in (2.0, 1.0, 0.0)]},
        ],
        "trim": {"v": [0.0, math.pi]},
    }
    t = design_from_dict(d)
    assert t.patches[1].data[0] is t.patches[0].data[3]
    full = design_from_dict({k: v for k, v in d.items() if k != "trim"})
    assert t.volume() == pytest.approx(full.volume() / 2, rel=1e-9)


@pytest.mark.parametrize(
    "data, fragment",
    [
        ({"tablet": {"family": "thesis.flat_faced_round", "diameter": 0.0, "thickness": 6.0}}, "diameter = 0"),
        ({"tablet": {"family": "thesis.flat_faced_round", "diameter": -3.0, "thickness": 6.0}}, "diameter = -3"),
        ({"tablet": {"family": "thesis.flat_faced_round", "diameter": float("nan"), "thickness": 6.0}}, "diameter"),
        ({"tablet": {"family": "thesis.flat_faced_round", "diameter": float("inf"), "thickness": 6.0}}, "diameter"),
        ({"tablet": {"family": "thesis.spherical", "diameter": "five"}}, "diameter"),
        ({"tablet": {"family": "octagon", "diameter": 5.0}}, "family"),
        ({"tablet": {"family": "thesis.spherical", "diamter": 5.0}}, "diamter"),
        ({"tablet": {"family": "thesis.spherical"}, "colour": {}}, "colour"),
        ({"shape": {}}, "shape"),
        ({"tablet": {"family": "thesis.shallow_convex_round", "band": 5.0}}, "band"),
        ({"tablet": {"family": "free_form"}, "patch": [{"curves": [{"type": "circle", "radius": 1.0}] * 3}]}, "curves"),
        (
            {"tablet": {"family": "free_form"},
             "patch": [{"curves": [{"type": "circle", "radius": r, "z": z} for r, z in ((5, 0), (0.1, 1), (0.1, 2), (5, 3))]}]},
            "radius",
        ),
        # each end of a [trim] range named by its place (it had been "trim.w = 'pi'" for w = [0, "pi"])
        ({"tablet": {"family": "concave_round", "diameter": 10.0, "band": 3.0, "cup_depth": 1.0},
          "trim": {"w": [0.0, "pi"]}}, "trim.w[1] = 'pi' is not allowed: must be a number"),
    ],
)
def test_bad_designs_name_the_parameter(data, fragment):
    with pytest.raises(DesignError) as exc:
        design_from_dict(data)
    msg = str(exc.value)
    assert fragment in msg and "\n" not in msg and "not allowed" in msg


def _run_cli(args, cwd):
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.run([sys.executable, "-m", "tabletcad", *args], cwd=cwd, env=env, capture_output=True, text=True, timeout=300)


def test_cli_bad_design_exits_2_without_traceback_or_files(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('[tablet]\nfamily = "thesis.flat_faced_round"\ndiameter = -10.0\nthickness = 6.0\n')
    out = tmp_path / "out"
    r = _run_cli(["build", str(bad), "--out", str(out)], tmp_path)
    assert r.returncode == 2
    assert r.stderr.strip().count("\n") == 0 and "Traceback" not in r.stderr
    assert r.stderr.startswith("error: tablet.diameter = -10 mm is not allowed: must be > 0")
    assert not out.exists()
    assert [p.name for p in tmp_path.iterdir()] == ["bad.toml"]  # no staging folder left behind
    r = _run_cli(["mesh", str(bad), "--nodes", "5", "9", "3", "--out", str(tmp_path / "m.vtu")], tmp_path)
    assert r.returncode == 2 and not (tmp_path / "m.vtu").exists()


#: what the commands below must not import: the CAD libraries, trimesh, matplotlib, and scipy's larger parts;
#: a refusal and a help text need no scipy at all
_LIGHT = '''
import sys
from tabletcad.cli import main

HEAVY = ("OCP", "build123d", "cadquery", "trimesh", "matplotlib", "sklearn", "pandas", "scipy.special",
         "scipy.optimize", "scipy.spatial", "scipy.stats", "scipy.interpolate")
def loaded(names):
    return sorted(m for m in sys.modules if any(m == n or m.startswith(n + ".") for n in names))

bad, out, sample = sys.argv[1:4]
assert main(["build", bad, "--out", out]) == 2
assert main(["mesh", bad, "--nodes", "5", "9", "3", "--out", out + ".vtu"]) == 2
for args in (["sweep", "--help"], ["fe", "diametral", "--help"], ["optimise", "--help"]):
    assert main(args) == 0
assert not loaded(HEAVY + ("scipy",)), loaded(HEAVY + ("scipy",))
assert main(["report", sample]) == 0
assert not loaded(HEAVY), loaded(HEAVY)
print("light")
'''


def test_refusals_help_and_report_keep_their_imports_light(tmp_path):
    """A refused design and the help texts load no scipy, no CAD library and no matplotlib; the
    report adds scipy.linalg only (the patches' products), not scipy.special (the shell model's
    Legendre polynomials) nor trimesh or build123d; measured in a fresh process."""
    bad = tmp_path / "bad.toml"
    bad.write_text('[tablet]\nfamily = "thesis.flat_faced_round"\ndiameter = -10.0\nthickness = 6.0\n')
    r = subprocess.run([sys.executable, "-c", _LIGHT, str(bad), str(tmp_path / "out"),
                        str(ROOT / "samples" / "families" / "concave_round.toml")],
                       env={**os.environ, "PYTHONPATH": str(ROOT)}, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0 and r.stdout.splitlines()[-1] == "light", r.stderr


def test_cli_mesh_and_shapes(tmp_path):
    out = tmp_path / "sphere.vtu"
    assert main(["mesh", str(ROOT / "samples" / "spherical.toml"), "--nodes", "11", "21", "5", "--out", str(out)]) == 0
    import meshio

    m = meshio.read(out)
    assert len(m.points) > 100
    assert main(["mesh", str(ROOT / "samples" / "spherical.toml"), "--nodes", "1", "21", "5", "--out", str(tmp_path / "x.vtu")]) == 2
    assert main(["mesh", str(ROOT / "samples" / "spherical.toml"), "--nodes", "5", "21", "5", "--out", str(tmp_path / "x.obj")]) == 2
    assert not (tmp_path / "x.vtu").exists() and not (tmp_path / "x.obj").exists()
    r = _run_cli(["shapes"], tmp_path)
    assert r.returncode == 0
    for name in families.FAMILIES:
        assert name in r.stdout


def test_height_and_radius_expressions_eqs_4_16_4_22():
    t = shapes.flat_faced_round(10.0, 6.0)
    body = t.patches[1]
    assert reshape.spine_height(body) == pytest.approx(6.0, abs=1e-12)
    # eq 4.22: the radius from the first mode equals the surface's distance from the axis
    u = np.linspace(0.0, 1.0, 11)
    X = body.evaluate(u, 0.3)
    assert np.allclose(reshape.radius(body, u), np.hypot(X[:, 0], X[:, 1]), atol=1e-12)
    c = reshape.circularity(body)
    assert c["eq_4_23_a"] < 1e-12 and c["eq_4_23_b"] < 1e-12 and c["higher_modes"] == 0.0
    # thesis-form coefficients (eqs 3.13-3.15) give the spine height: A0z(1) - A0z(0)
    a0, _ = body.mode_coefficients(0)
    assert a0[1:, 2].sum() == pytest.approx(6.0, abs=1e-12)


def test_table_4_5_by_coefficient_scaling():
    tab = reshape.thesis_table_4_5()
    dims = {n: d["tablet"].dimensions() for n, d in tab.items()}
    assert dims["ring"]["height_mm"] == pytest.approx(4.5, abs=1e-9)
    assert dims["ring"]["length_mm"] == pytest.approx(12.0, abs=0.01)
    assert dims["deep_convex_round"]["height_mm"] == pytest.approx(4.0, abs=1e-6)  # domes dip ~0.2 µm at the poles
    assert dims["oblate_spheroid"]["length_mm"] == pytest.approx(10.0, abs=0.02)
    assert dims["oblate_spheroid"]["height_mm"] == pytest.approx(2.5, abs=0.005)
    assert dims["prolate_spheroid"]["height_mm"] == pytest.approx(10.0, abs=0.01)
    assert dims["caplet"]["height_mm"] == pytest.approx(15.0, abs=5e-3)
    assert dims["deep_convex_oval"]["height_mm"] == pytest.approx(3.1, abs=1e-4)
    # scaling the radius by k scales the volume of a band (ring) by k² (w-range kept)
    ring = tab["ring"]["tablet"]
    assert ring.trim.w == (0.5, 1.0)
    body = reshape.scale_heights(reshape.select_patches(shapes.flat_faced_round(), [1]), [0.75])
    from dataclasses import replace

    from tabletcad.geometry.tablet import Trim

    v1 = replace(body, trim=Trim(w=(0.5, 1.0))).volume()
    assert ring.volume() == pytest.approx(1.44 * v1, rel=1e-9)


def test_thesis_tables_sample_runs():
    r = subprocess.run([sys.executable, str(ROOT / "samples" / "thesis_tables.py")], capture_output=True, text=True,
                       env={**os.environ, "PYTHONPATH": str(ROOT)}, timeout=300)
    assert r.returncode == 0, r.stderr
    assert "| flat_faced_round | 345.604 | 345.062 | 345.575 | 471.382 |" in r.stdout


def test_a_free_form_chain_with_a_gap_is_refused():
    """Patches that do not meet make no solid: the report gave a volume for the open surface (and
    called the seam 'gap 1000 um, an edge'), the build failed late in the B-spline fit.  Now one
    line for the patch's first curve; the sample (every seam "previous") still loads."""
    import tomllib

    from tabletcad.errors import DesignError
    from tabletcad.pipeline.design import design_from_dict

    root = Path(__file__).resolve().parents[1]
    text = (root / "samples" / "free_form_stadium.toml").read_text()
    assert design_from_dict(tomllib.loads(text)).volume() > 0
    gapped = text.replace('curves = [\n  "previous",\n  { type = "stadium", length = 12.0, width = 6.0, z = 1.0 },',
                          'curves = [\n  { type = "stadium", length = 12.0, width = 6.0, z = 0.5 },\n'
                          '  { type = "stadium", length = 12.0, width = 6.0, z = 1.0 },', 1)
    assert gapped != text
    with pytest.raises(DesignError) as exc:
        design_from_dict(tomllib.loads(gapped))
    assert exc.value.parameter == "patch[1].curves[0]" and "a gap of 0.5 mm" in str(exc.value)


def test_toml_files_with_a_byte_order_mark_load_and_binary_ones_are_refused(tmp_path, capsys):
    """Some editors save UTF-8 with a byte-order mark: design, sweep and problem files read the same
    with it.  A binary file is one line for the file, not an internal error."""
    from tabletcad.cli import main

    for rel in ("samples/families/concave_round.toml", "samples/sweep/concave_round_grid.toml",
                "samples/optimise/cylinder_min_area.toml"):
        src = ROOT / rel
        bom = tmp_path / f"bom_{src.name}"
        bom.write_bytes(b"\xef\xbb\xbf" + src.read_bytes())
        if "families" in rel:
            assert load_design(bom).volume() == load_design(src).volume()
        elif "sweep" in rel:
            from tabletcad.sweep.spec import load_sweep

            assert load_sweep(bom).designs() == load_sweep(src).designs()
        else:
            from tabletcad.optimise.files import load_problem

            assert load_problem(bom)[1:] == load_problem(src)[1:]
    junk = tmp_path / "junk.toml"
    junk.write_bytes(b"\x89PNG\r\n\x1a\n\xff\xfe\x00")
    for args, parameter in ((["report", str(junk)], "DESIGN"),
                            (["optimise", str(junk), "--out", str(tmp_path / "o")], "PROBLEM.toml")):
        assert main(args) == 2
        err = capsys.readouterr().err
        assert err.startswith(f"error: {parameter} = ") and "UTF-8" in err and len(err.splitlines()) == 1


@pytest.mark.parametrize("table, parameter, fragment", [
    ('family = "thesis.caplet"\nwidth = 3.5\nlength = 7.0\nheight = 15.0\nband = 20.0', "tablet.band",
     "<= height = 15 mm"),  # the caplet's key is height (the oval it is made from says thickness)
    ('family = "concave_round"\ndiameter = 10\nband = 3\ncup_depth = 1\na = "autox"', "tablet.a", 'or "auto"'),
    ('family = "concave_round"\nname = ""\ndiameter = 10\nband = 3\ncup_depth = 1', "tablet.name", "non-empty"),
])
def test_messages_name_the_keys_and_values_a_design_takes(tmp_path, capsys, table, parameter, fragment):
    from tabletcad.cli import main

    p = tmp_path / "d.toml"
    p.write_text(f"[tablet]\n{table}\n")
    assert main(["report", str(p)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"error: {parameter} = ") and fragment in err and len(err.splitlines()) == 1, err


def test_heckel_input_that_would_be_misread(tmp_path, capsys):
    from tabletcad.cli import main

    data = ROOT / "samples" / "press" / "lactose_appendix_b.csv"
    for args, parameter, fragment in (
            ([str(data), "--diameter", "12", "--face-area", "78.54"], "--face-area", "not both"),  # one was ignored
            (["/dev/null"], "DATA", "must be a file"),  # it said "does not exist"
            ([str(data), "--diameter", "1e200"], "--diameter", "<= 1000 mm")):  # an OverflowError, exit 1
        assert main(["heckel", *args]) == 2
        err = capsys.readouterr().err
        assert err.startswith(f"error: {parameter} = ") and fragment in err and len(err.splitlines()) == 1, err


def test_thesis_and_free_form_reports_carry_their_design_report():
    """``report.json`` (the geometry report) of a thesis shape gives the design report ``tabletcad report``
    prints (weight, strength by eq 2.7): it had none, for thesis shapes and free-form designs alike."""
    from tabletcad.pipeline.design import Design
    from tabletcad.pipeline.designreport import shape_report
    from tabletcad.pipeline.report import geometry_report

    d = Design.from_dict({"tablet": {"family": "thesis.shallow_convex_round", "diameter": 10.0, "thickness": 3.0, "band": 2.0},
                          "report": {"solid_fraction": 0.85, "true_density_mg_mm3": 1.5, "breaking_force_N": 100.0}})
    t = d.build()
    rep = geometry_report(t, d.report_options)
    dr = rep["design_report"]
    assert dr == shape_report(t, d.report_options)["design_report"]
    assert dr["weight_mg"] == pytest.approx(rep["volume_mm3"] * 0.85 * 1.5, rel=1e-12)
    assert "eq 2.7" in dr["tensile_strength"]["formula"] and dr["tensile_strength"]["tensile_strength_MPa"] > 0


@pytest.mark.parametrize("trim, token", [("v = [0.0, 1e-9]", "trim.v"), ("w = [0.0, 1e-12]", "trim.w"),
                                         ("u = [0.5, 0.5000001]", "trim.u")])
def test_a_trim_thinner_than_a_thousandth_is_refused(tmp_path, capsys, trim, token):
    """``v = [0, 1e-9]`` failed late in the CAD stage ("0 solids"), ``w = [0, 1e-12]`` built a solid 1e-11 mm
    wide: a trim narrower than 0.001 (rad for v) is refused by the report, before any geometry."""
    from tabletcad.cli import main

    d = tmp_path / "t.toml"
    d.write_text('[tablet]\nfamily = "concave_round"\ndiameter = 10.0\nband = 3.0\ncup_depth = 1.0\n[trim]\n' + trim + "\n")
    assert main(["report", str(d)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"error: {token} = ") and "at least 0.001" in err and len(err.splitlines()) == 1, err


def test_a_free_form_tablet_table_names_its_keys(tmp_path, capsys):
    """An extra key in a free-form design's [tablet] listed no allowed keys ("allowed keys of tablet are")."""
    from tabletcad.cli import main

    circles = ", ".join(f'{{ type = "circle", radius = 5.0, z = {z:.1f} }}' for z in (0, 1, 2, 3))
    d = tmp_path / "ff.toml"
    d.write_text(f'[tablet]\nfamily = "free_form"\ndiameter = 3\n[[patch]]\ncurves = [ {circles} ]\n')
    assert main(["report", str(d)]) == 2
    assert capsys.readouterr().err.strip() == ("error: tablet.diameter = 3 is not allowed: allowed keys of tablet for "
                                               "free_form are a, family, name (the shape is in the [[patch]] tables)")


def test_a_unit_for_a_column_the_record_lacks_is_refused(capsys):
    """``heckel --time-unit ms`` on a record with no time column was ignored without a word (the README
    promises that options a method does not read are refused)."""
    from tabletcad.cli import main

    press = Path(__file__).resolve().parents[1] / "samples" / "press"
    args = ["heckel", str(press / "lactose_appendix_b.csv"), "--meta", str(press / "lactose_appendix_b.toml")]
    assert main(args + ["--time-unit", "ms"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("error: --time-unit = 'ms' is not allowed: is for a time column, which "
                          "lactose_appendix_b.csv has none of (columns: force_N, displacement_mm,"), err
    assert main(args + ["--force-unit", "N"]) == 0  # a unit for a column it has is read


def test_every_report_states_the_same_units(capsys):
    """``report.json`` of a build and ``tabletcad report --json`` name the same units (the build's had
    only length, area, volume and angle beside a weight in mg and a strength in MPa); the tensile
    strength's "almond" plan takes "an"."""
    import json as _json

    from tabletcad.cli import main as _main
    from tabletcad.pipeline.design import Design as _Design
    from tabletcad.pipeline.report import REPORT_UNITS, geometry_report

    d = _Design.from_toml(ROOT / "samples" / "families" / "almond.toml")
    rep = geometry_report(d.build(), d.report_options)
    assert rep["units"] == REPORT_UNITS and REPORT_UNITS["mass"] == "mg" and REPORT_UNITS["stress"] == "MPa"
    assert _main(["report", str(ROOT / "samples" / "families" / "almond.toml"), "--json", "--breaking-force", "100"]) == 0
    payload = _json.loads(capsys.readouterr().out)
    assert payload["units"] == REPORT_UNITS
    flags = payload["design_report"]["tensile_strength"]["range_flags"]
    assert flags == ["no published tensile-strength formula for an almond plan"]


def test_a_concave_bevels_report_gives_both_cup_depths(capsys):
    """Its ``cup_depth`` is measured from the bevel's inner edge; the report's cup depth from the band
    (adding the bevel's depth ``w tan(angle)``), and it names the design's figure beside it."""
    import tomllib

    from tabletcad.cli import main as _main
    from tabletcad.pipeline.design import Design as _Design
    from tabletcad.pipeline.designreport import design_report

    path = ROOT / "samples" / "families" / "concave_bevel.toml"
    tab = tomllib.loads(path.read_text())["tablet"]
    rep = design_report(_Design.from_toml(path).build())["design_report"]
    below = tab["bevel_width"] * math.tan(math.radians(tab["bevel_angle"]))
    assert rep["params"]["cup_depth_below_bevel_mm"] == tab["cup_depth"]
    assert rep["cup_depth_mm"] == pytest.approx(tab["cup_depth"] + below, rel=1e-14)
    assert _main(["report", str(path)]) == 0
    line = next(ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("cup depth"))
    assert line.endswith(f"(from the band; {tab['cup_depth']:g} mm below the bevel: the design's cup_depth)")


def test_a_compaction_force_without_a_limit_is_shown_as_its_tip_pressure(tmp_path, capsys):
    """A new user's ``compaction_force_kN = 15000`` (newtons typed for kilonewtons) with no limit had printed
    only "not checked: no limit given": the force is shown as the pressure it puts on the tip's face now,
    15000 kN over the 10 mm face's 78.54 mm² = 1.91e5 MPa, which no punch steel bears."""
    p = tmp_path / "d.toml"
    p.write_text('[tablet]\nfamily = "flat_face_round"\ndiameter = 10.0\nthickness = 4.0\n'
                 '[report]\ncompaction_force_kN = 15000.0\n')
    assert main(["report", str(p)]) == 0
    (line,) = [ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("punch-tip check")]
    pressure = 15000.0 * 1000.0 / (math.pi * 25.0)
    assert f"not checked: 15000 kN is {pressure:.4g} MPa on {math.pi * 25.0:.4g} mm2; no limit given" in line


def test_a_file_name_that_cannot_be_a_tablet_name_says_where_the_name_came_from(tmp_path, capsys):
    """A design without [tablet] name takes its file's name; one holding a backslash had been refused as
    "tablet.name", a key not in the file: the line says the file's name stands for it, and what to do."""
    src = tmp_path / "O'Brien \\ 50% x.toml"
    src.write_text((ROOT / "samples" / "families" / "concave_round.toml").read_text(encoding="utf-8"), encoding="utf-8")
    assert main(["report", str(src)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith('error: tablet.name = "O\'Brien \\\\ 50% x" is not allowed: must be a plain ')
    assert "the design file's name is the tablet's when its [tablet] table gives none" in err[0]
    ok = tmp_path / "O'Brien 50% x.toml"  # an apostrophe is taken
    ok.write_text(src.read_text(encoding="utf-8"), encoding="utf-8")
    assert main(["report", str(ok)]) == 0


@pytest.mark.parametrize("family, params, measured, note", [
    # a rod's and an oblong's length run along their axis: the nominal reads length x width x thickness as the
    # measure does (it had printed "nominal 7.5 x 3 mm" beside "3.002 x 3.002 x 7.5 mm")
    ("thesis.rod", {"diameter": 3.0, "length": 7.5, "dome": 1.0}, (3.002, 3.002, 7.5), " (PDE surface; nominal 3 x 3 x 7.5 mm)"),
    ("thesis.oblong", {"diameter": 5.0, "length": 15.0, "dome": 2.0}, (5.003, 5.003, 15.0),
     " (PDE surface; nominal 5 x 5 x 15 mm)"),
    # a spheroid's height and a sphere's diameter are their thickness (they had been left out)
    ("thesis.prolate_spheroid", {"diameter": 5.0, "height": 10.0}, (5.005, 5.005, 10.0),
     " (PDE surface; nominal 5 x 5 x 10 mm)"),
    ("thesis.spherical", {"diameter": 5.0}, (5.005, 5.005, 5.002), " (PDE surface; nominal 5 x 5 x 5 mm)"),
    ("thesis.ring", {"outer_diameter": 12.0, "inner_diameter": 6.0, "thickness": 4.5}, (12.01, 12.01, 4.5),
     " (PDE surface; nominal 12 x 12 x 4.5 mm)"),
    ("thesis.shallow_convex_oval", {"length": 12.0, "width": 6.0, "thickness": 3.1, "band": 1.5}, (12.0, 6.0, 3.1), ""),
    ("concave_round", {"diameter": 10.0, "band": 3.0, "cup_depth": 1.0}, (10.0001, 10.0001, 5.0), ""),
])
def test_the_nominal_note_reads_as_the_measure(family, params, measured, note):
    from tabletcad.cli.report import nominal_note

    assert nominal_note(family, params, *measured) == note


@pytest.mark.skipif(not Path("/dev/null").exists(), reason="needs /dev/null")
@pytest.mark.parametrize("command, line", [
    (["report", "/dev/null"], "error: DESIGN = '/dev/null' is not allowed: is a pipe or device, not a file (save the "
                              "design to a .toml file)"),
    (["build", "/dev/null", "--out", "OUT"], "error: DESIGN = '/dev/null' is not allowed: must be a TOML file, not a pipe "
                                             "or device"),
])
def test_a_design_given_as_a_device_is_not_said_to_be_missing(tmp_path, capsys, command, line):
    """``tabletcad report <(cat design.toml)`` (a pipe) and /dev/null exist: they had been refused as "does not exist"."""
    args = [str(tmp_path / "out") if a == "OUT" else a for a in command]
    assert main(args) == 2
    assert capsys.readouterr().err.splitlines() == [line]
    assert list(tmp_path.iterdir()) == []
