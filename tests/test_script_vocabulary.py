"""One vocabulary: the industry families own the plain names, the thesis's shapes live under
``thesis.``; the old plain names still work for a release, with one line of warning."""

from __future__ import annotations

import subprocess
import sys
import warnings
from pathlib import Path

import pytest

from tabletcad.pipeline.design import design_from_dict, load_design
from tabletcad.errors import DesignError
from tabletcad.families import FAMILIES, INDUSTRY_FAMILIES, RENAMED, THESIS_FAMILIES, family
from tabletcad.families.thesis import THESIS_SHAPES

ROOT = Path(__file__).resolve().parents[1]
SAMPLES = sorted(p for p in ROOT.joinpath("samples").rglob("*.toml") if "[tablet]" in p.read_text(encoding="utf-8"))


def test_names_are_one_namespace():
    assert set(THESIS_FAMILIES) == {f"thesis.{n}" for n in THESIS_SHAPES}
    assert not set(INDUSTRY_FAMILIES) & set(THESIS_SHAPES)  # no plain name is both
    assert list(FAMILIES) == [*INDUSTRY_FAMILIES, *THESIS_FAMILIES]
    assert all(FAMILIES[n].name == n for n in FAMILIES)
    assert dict(RENAMED) == {n: f"thesis.{n}" for n in THESIS_SHAPES}
    # the near-twins of the first wave are told apart by the prefix
    assert "flat_face_round" in FAMILIES and "thesis.flat_faced_round" in FAMILIES and "flat_faced_round" not in FAMILIES


@pytest.mark.parametrize("old", sorted(RENAMED))
def test_an_old_name_builds_the_same_tablet_with_one_warning(old):
    dims = FAMILIES[f"thesis.{old}"].defaults
    with pytest.warns(FutureWarning) as rec:
        t = design_from_dict({"tablet": {"family": old, **dims}})
    assert [str(w.message) for w in rec] == [
        f"family {old!r} is now 'thesis.{old}'; the old name is accepted until tabletcad 0.3"]
    assert rec[0].filename == __file__  # attributed to the caller, not to tabletcad's internals
    new = FAMILIES[f"thesis.{old}"].build()
    assert t.family == new.family == f"thesis.{old}"
    assert t.volume() == new.volume()


def test_lookup_refuses_unknown_names_naming_the_parameter():
    with pytest.raises(DesignError) as e:
        family("flat_faced_rnd", parameter="problem.family")
    assert e.value.parameter == "problem.family" and "thesis.flat_faced_round" in str(e.value)
    with pytest.raises(DesignError):
        family(["capsule"])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert family("capsule") is FAMILIES["capsule"]


@pytest.mark.parametrize("path", SAMPLES, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_sample_uses_the_current_names(path):
    with warnings.catch_warnings():
        warnings.simplefilter("error", FutureWarning)
        load_design(path)


def test_command_line_prints_the_warning_as_one_line(tmp_path):
    design = tmp_path / "old.toml"
    design.write_text('[tablet]\nfamily = "spherical"\ndiameter = 6.0\n', encoding="utf-8")
    exe = Path(sys.executable).with_name("tabletcad")
    cmd = [str(exe)] if exe.exists() else [sys.executable, "-m", "tabletcad"]
    out = subprocess.run([*cmd, "mesh", str(design), "--nodes", "9", "9", "5", "--out", str(tmp_path / "m.vtu")], capture_output=True, text=True,
                         timeout=300, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    lines = [ln for ln in out.stderr.splitlines() if ln.strip()]
    assert lines[0] == "warning: family 'spherical' is now 'thesis.spherical'; the old name is accepted until tabletcad 0.3"
    assert not any("Warning" in ln or "File " in ln for ln in lines)


def test_every_command_takes_the_new_names(tmp_path):
    """Design files, the scripting facade, tooling batches and optimisation problems read thesis.* names."""
    import tabletcad
    from tabletcad.optimise.files import family_problem

    with warnings.catch_warnings():
        warnings.simplefilter("error", FutureWarning)
        assert tabletcad.make("thesis.spherical", diameter=6.0).tablet.family == "thesis.spherical"
        prob = family_problem({"family": "thesis.flat_faced_round", "objective": "surface_area_mm2", "sense": "min"},
                              {"thickness": {"lower": 2.0, "upper": 6.0, "initial": 4.0}}, {"diameter": 10.0}, [])
    assert prob.variables[0].name == "thickness"
    with pytest.warns(FutureWarning):
        old = family_problem({"family": "flat_faced_round", "objective": "surface_area_mm2", "sense": "min"},
                             {"thickness": {"lower": 2.0, "upper": 6.0, "initial": 4.0}}, {"diameter": 10.0}, [])
    assert old.description == prob.description


THESIS_SAMPLES = sorted(ROOT.joinpath("samples").glob("*.toml"))


@pytest.mark.parametrize("path", THESIS_SAMPLES, ids=lambda p: p.stem)
def test_report_serves_the_thesis_shapes_and_free_form_designs(path, capsys):
    """The design report of a tablet without a family nominal: its own geometry, the strength formula
    its shape has (eq 2.4 flat round, eq 2.7 convex round, eq 2.9 convex oval), no certificate."""
    import json
    import math

    from tabletcad.cli import main

    rc = main(["report", str(path), "--json", "--breaking-force", "100", "--solid-fraction", "0.8", "--true-density", "1.5"])
    out, err = capsys.readouterr()
    assert rc == 0, err
    doc = json.loads(out)
    r, t = doc["design_report"], load_design(path)
    dims, props = t.dimensions(), t.properties()
    assert r["family"] == t.family and doc["nominal_certified"] is None
    assert r["volume_mm3"] == props["volume_mm3"] and r["surface_area_mm2"] == props["surface_area_mm2"]
    assert r["weight_mg"] == pytest.approx(props["volume_mm3"] * 0.8 * 1.5, rel=1e-12)
    D, T, F = dims["width_mm"], dims["height_mm"], 100.0
    ts = r["tensile_strength"]["tensile_strength_MPa"]
    p = t.params
    if t.family == "thesis.flat_faced_round":
        assert ts == pytest.approx(2 * F / (math.pi * D * T), rel=1e-12)
    elif t.family in ("thesis.shallow_convex_round", "thesis.deep_convex_round") and path.stem != "cutaway_convex_round":
        W = p["band"]
        assert r["cup_depth_mm"] == pytest.approx((p["thickness"] - W) / 2, rel=1e-12)
        pitt = 10 * F / (math.pi * D * D * (2.84 * T / D - 0.126 * T / W + 3.15 * W / D + 0.01))
        assert ts == pytest.approx(pitt, rel=1e-12)
    elif t.family in ("thesis.shallow_convex_oval", "thesis.deep_convex_oval"):
        W = p["band"]
        pitt = 10 * F / (math.pi * D * D * (2.84 * T / D - 0.126 * T / W + 3.15 * W / D + 0.01))
        assert ts == pytest.approx(2 / 3 * pitt, rel=1e-12)
    else:
        assert ts is None and r["shape"] is None


def test_report_solve_for_names_the_families_it_serves(capsys):
    from tabletcad.cli import main

    rc = main(["report", str(ROOT / "samples" / "spherical.toml"), "--solve-for", "band", "--target-volume", "100"])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and err.startswith("error: --solve-for = 'band' is not allowed: thesis.spherical ")
    rc = main(["report", str(ROOT / "samples" / "oblate_spheroid.toml"), "--solve-for", "band", "--target-volume", "100"])
    err = capsys.readouterr().err
    assert rc == 2 and err.strip().endswith("thesis.oblate_spheroid can solve for height")
    assert main(["report", str(ROOT / "samples" / "oblate_spheroid.toml"), "--solve-for", "height", "--target-volume", "100"]) == 0
    assert capsys.readouterr().out.startswith("oblate_spheroid: height = ")


def test_report_compares_designs_of_any_family(capsys):
    from tabletcad.cli import main

    rc = main(["report", str(ROOT / "samples" / "spherical.toml"), str(ROOT / "samples" / "flat_faced_round.toml"),
               str(ROOT / "samples" / "families" / "concave_round.toml")])
    out, err = capsys.readouterr()
    assert rc == 0, err
    rows = {ln.split()[0]: ln.split() for ln in out.splitlines()[1:]}
    assert rows["spherical"][1] == "thesis.spherical" and rows["spherical"][7:9] == ["-", "-"]  # no band, no cup
    assert rows["flat_faced_round"][7:9] == ["6", "0"] and rows["concave_round"][7:9] == ["2.8", "0.9"]


def test_report_of_a_reshaped_thesis_shape_claims_no_formula(tmp_path, capsys):
    """[reshape] scales the patches: the family's band and thickness no longer describe the tablet."""
    import json

    from tabletcad.cli import main

    d = tmp_path / "r.toml"
    d.write_text('[tablet]\nfamily = "thesis.shallow_convex_round"\ndiameter = 10.0\nthickness = 3.0\nband = 2.0\n'
                 '[reshape]\nspine = [3, 0.5, 3]\n', encoding="utf-8")
    assert main(["report", str(d), "--json", "--breaking-force", "50"]) == 0
    r = json.loads(capsys.readouterr().out)["design_report"]
    assert r["band_mm"] is None and r["cup_depth_mm"] is None and r["tensile_strength"]["tensile_strength_MPa"] is None
    assert r["overall_thickness_mm"] == pytest.approx(4.0, abs=1e-6)
