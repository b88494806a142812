"""``tabletcad fe``: JSON keys, files, and one-line errors with exit status 2 and nothing written."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

pytestmark = pytest.mark.fe
pytest.importorskip("skfem")
pytest.importorskip("gmsh")
pytest.importorskip("OCP")
pytest.importorskip("meshio")

from tabletcad.cli import main  # noqa: E402

THIN = """
[tablet]
family = "flat_face_round"
diameter = 8.0
thickness = 1.0
"""


def run(capsys, *args):
    rc = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return rc, out, err


@pytest.fixture
def thin(tmp_path) -> Path:
    p = tmp_path / "thin.toml"
    p.write_text(THIN)
    return p


def test_diametral_json_and_files(capsys, tmp_path, thin):
    import meshio

    out = tmp_path / "res"
    rc, so, err = run(capsys, "fe", "diametral", thin, "--force", 50, "--direction", "x", "--mesh-size", 0.6,
                      "--out", out, "--json")
    assert rc == 0, err
    d = json.loads(so)
    for k in ("centre_tensile_stress_MPa", "max_tensile_stress_MPa", "max_tensile_location_mm", "nodes", "elements",
              "discretisation_error_MPa", "discretisation_error_relative", "shape_factor"):
        assert k in d
    ref = 2 * 50 / (3.141592653589793 * 8.0 * 1.0)
    assert d["line_load_stress_MPa"] == pytest.approx(ref, rel=1e-12)
    assert d["strip_width_mm"] == pytest.approx(0.8, rel=1e-12)  # D/10
    assert d["centre_tensile_stress_MPa"] == pytest.approx(0.988 * ref, rel=0.03)
    assert abs(d["discretisation_error_relative"]) < 0.03
    assert d["discretisation_error_relative"] * d["centre_tensile_stress_MPa"] == pytest.approx(
        d["discretisation_error_MPa"], rel=1e-12)
    assert d["reaction_N"] < 1e-8 * 50
    assert len(d["max_tensile_location_mm"]) == 3
    assert d["max_tensile_stress_MPa"] >= d["centre_tensile_stress_MPa"] * 0.999
    assert sorted(p.name for p in out.iterdir()) == [".tabletcad-fe.json", "section.png", "stress.vtu"]
    mesh = meshio.read(out / "stress.vtu")
    assert len(mesh.points) == d["nodes"]
    assert len(mesh.cells_dict["tetra"]) == d["elements"]
    assert (out / "section.png").read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize(
    "extra, match",
    [
        (["--force", "0"], "--force = 0 N is not allowed: must be >= 1e-06 and <= 1e+09 N"),  # the range 1e12 gets
        (["--force", "-5"], "--force = -5 N is not allowed: must be >= 1e-06"),
        # a force so small its stresses underflowed: a centre stress of -0 MPa, shape factor -0
        (["--force", "1e-320"], "--force = 9.99989e-321 N is not allowed: must be >= 1e-06 and <= 1e+09 N"),
        # a mesh size whose cube underflowed to 0: a ZeroDivisionError (exit 1) in the unknowns' estimate
        (["--force", "10", "--mesh-size", "1e-200"], "--mesh-size = 1e-200 mm is not allowed: must be >="),
        (["--force", "10", "--direction", "diagonal"], "--direction = 'diagonal' is not allowed"),
        # the FE functions' keyword arguments are named as the options that set them
        (["--force", "10", "--strip-width", "5"], "error: --strip-width = 5 mm is not allowed"),
        (["--force", "10", "--mesh-size", "0.001"], "error: --mesh-size = 0.001 mm is not allowed: must be >= "),
        (["--force", "10", "--mesh-size", "0"], "error: --mesh-size = 0 mm is not allowed: must be > 0"),
        # the strip's own width, not its mesh size b/3 (which was shown as --strip-width's value)
        (["--force", "10", "--strip-width", "0.02"], "error: --strip-width = 0.02 mm is not allowed: meshes its strips "
                                                     "at b/3 = 0.00667 mm, a size that must be >= "),
        (["--force", "10", "--nu", "0.5"], "error: --nu = 0.5 is not allowed"),
        (["--force", "10", "--E", "-1"], "error: --E = -1 MPa is not allowed: must be >= 0.001"),
        # E = 1e-300 with a 1e9 N force overflowed the solve (LinAlgError, exit 1)
        (["--force", "1e9", "--E", "1e-300"], "error: --E = 1e-300 MPa is not allowed: must be >= 0.001 and <= 1e+07 MPa"),
    ],
)
def test_diametral_bad_input_one_line_exit_2_nothing_written(capsys, tmp_path, thin, extra, match):
    out = tmp_path / "never"
    rc, so, err = run(capsys, "fe", "diametral", thin, *extra, "--out", out)
    assert rc == 2
    assert err.count("\n") == 1 and err.startswith("error: ") and match in err, err
    assert not out.exists()


def test_a_mesh_size_gmsh_cannot_mesh_is_refused_by_its_name(capsys, tmp_path):
    """A trial: ``--mesh-size 10`` (within its stated range, up to the tablet's 10 mm) on the concave round
    sample printed "error: mesh: gmsh produced no tetrahedra" (the error estimate's 15 mm mesh); without the
    estimate the 10 mm mesh itself is made."""
    sample = Path(__file__).resolve().parents[1] / "samples" / "families" / "concave_round.toml"
    out = tmp_path / "never"
    rc, _, err = run(capsys, "fe", "diametral", sample, "--force", "100", "--mesh-size", "10", "--out", out)
    assert rc == 2 and err == ("error: --mesh-size = 10 mm is not allowed: gmsh makes no tetrahedra of this solid at "
                               "15 mm (the error estimate's mesh, 1.5 times coarser): give a finer size\n"), err
    assert not out.exists()
    rc, _, err = run(capsys, "fe", "diametral", sample, "--force", "100", "--mesh-size", "10", "--no-error-estimate")
    assert rc == 0, err


def test_punch_needs_tooling(capsys, tmp_path, thin):
    out = tmp_path / "never"
    rc, so, err = run(capsys, "fe", "punch", thin, "--force", 10, "--yield-stress", 1450)
    assert rc == 2
    # the missing table is "(not given)" (the design's name had stood as the value)
    assert err.startswith("error: tooling = (not given) is not allowed: a punch tip is made from the design's "
                          "[tooling] table"), err
    assert err.count("\n") == 1
    assert not out.exists()


TOOLED = THIN.replace("thickness = 1.0", "thickness = 2.0") + """
[tooling]
clearance_mm = 0.02
tip_length_mm = 5.0
"""


def test_punch_json_and_files(capsys, tmp_path):
    design = tmp_path / "tooled.toml"
    design.write_text(TOOLED)
    out = tmp_path / "punch"
    rc, so, err = run(capsys, "fe", "punch", design, "--force", 5, "--steel", "S7_tempered_205C", "--mesh-size", 1.0,
                      "--out", out, "--json")
    assert rc == 0, err
    d = json.loads(so)
    assert d["steel"] == "S7_tempered_205C" and d["yield_MPa"] == 1450
    # flat tip: σ_vM ≈ F/A, so the yield-based rating is ≈ σ_y/S · A
    assert d["max_von_mises_MPa"] == pytest.approx(d["uniform_stress_MPa"], rel=0.02)
    assert d["allowed_force_kN"] == pytest.approx(
        min(1450 / 1.5 * 5 / d["max_von_mises_MPa"], d["buckling"]["critical_force_kN"] / 1.5), rel=1e-9)
    assert sorted(p.name for p in out.iterdir()) == [".tabletcad-fe.json", "section.png", "stress.vtu"]


@pytest.mark.parametrize(
    "extra, match",
    [
        (["--force", "5"], "--yield-stress = (not given) is not allowed: give --yield-stress (MPa) or --steel"),
        (["--force", "5", "--steel", "unobtainium"], "--steel = 'unobtainium' is not allowed: must be one of"),
        (["--force", "0", "--yield-stress", "1000"], "--force = 0 kN is not allowed: must be >= 1e-09 and <= 1e+06 kN"),
        # 1e-200 kN left no stress to divide by (ZeroDivisionError, exit 1)
        (["--force", "1e-200", "--yield-stress", "1000"], "--force = 1e-200 kN is not allowed: must be >= 1e-09"),
        # a yield stress in pascals had rated the punch at 2508 kN; K = 1e9 at 1e-14 kN
        (["--force", "12", "--yield-stress", "1.45e9"], "--yield-stress = 1.45e+09 MPa is not allowed: must be >= 100 and "
                                                        "<= 10000 MPa"),
        # a new user's trial: S7's 1.45 GPa typed as 1.45 had been taken, a tool steel of 1.45 MPa (the lower bound
        # had been 0; the case above pinned "> 0")
        (["--force", "20", "--yield-stress", "1.45"], "--yield-stress = 1.45 MPa is not allowed: must be >= 100 and "
                                                      "<= 10000 MPa"),
        (["--force", "12", "--yield-stress", "1000", "--effective-length-factor", "1e9"],
         "--effective-length-factor = 1e+09 is not allowed: must be > 0 and <= 10"),
        (["--force", "5", "--yield-stress", "1000", "--steel", "S7_tempered_205C"], "not both"),
    ],
)
def test_punch_bad_input(capsys, tmp_path, extra, match):
    design = tmp_path / "tooled.toml"
    design.write_text(TOOLED)
    out = tmp_path / "never"
    rc, so, err = run(capsys, "fe", "punch", design, *extra, "--out", out)
    assert rc == 2 and err.startswith("error: ") and match in err and err.count("\n") == 1, err
    assert not out.exists()


def test_strength_needs_its_inputs(capsys, tmp_path, thin):
    """A new user's trial: the refusal named only the [report] keys (``report.tensile_strength_MPa = (not given)
    ... reference_breaking_force_N, ...``), not the options this command line takes.  It names the options
    now, the keys as the alternative (this test had pinned the keys-only line)."""
    rc, so, err = run(capsys, "fe", "strength", thin)
    assert rc == 2 and so == "" and err.splitlines() == [
        "error: --tensile-strength = (not given) is not allowed: give it (MPa), or all of --reference-force (N), "
        "--reference-diameter and --reference-thickness (mm) of a flat-faced round reference compact; or in "
        "DESIGN's [report] table tensile_strength_MPa, or all of reference_breaking_force_N, reference_diameter_mm "
        "and reference_thickness_mm"]
    begun = tmp_path / "begun.toml"  # a reference test begun in the file: its key named, and its option
    begun.write_text(THIN + "[report]\nreference_breaking_force_N = 80.0\n")
    rc, so, err = run(capsys, "fe", "strength", begun)
    assert rc == 2 and err.splitlines() == [
        "error: report.reference_diameter_mm = (not given) is not allowed: the reference test needs "
        "reference_breaking_force_N, reference_diameter_mm, reference_thickness_mm (or give tensile_strength_MPa "
        "instead); or give it as --reference-diameter"]


def test_diametral_refuses_a_ring_fast(capsys):
    ring = Path(__file__).resolve().parents[1] / "samples" / "ring.toml"
    rc, so, err = run(capsys, "fe", "diametral", ring, "--force", 10)
    assert rc == 2 and err.startswith("error: tablet.inner_diameter = 6 mm is not allowed: a hollow tablet (a ring) is "
                                      "not supported by the diametral FE test")


def test_json_file_writes_what_json_prints(capsys, tmp_path, thin):
    args = ["fe", "strength", thin, "--tensile-strength", "2.0", "--mesh-size", "1.5"]
    rc, out, err = run(capsys, *args, "--json")
    assert rc == 0, err
    printed = json.loads(out)
    target = tmp_path / "r.json"
    rc, out, err = run(capsys, *args, "--json-file", target)
    assert rc == 0, err
    assert out.rstrip().endswith(f"json -> {target}") and json.loads(target.read_text()) == printed
    rc, out, err = run(capsys, *args, "--json-file", tmp_path / "r.txt")
    assert rc == 2 and err.startswith("error: --json-file = ") and not (tmp_path / "r.txt").exists()


@pytest.mark.parametrize("extra", [["--force", "1e7"], ["--force", "20", "--mesh-size", "0.001"]])
def test_a_punch_refusal_is_one_line_even_where_the_tip_warns(capsys, tmp_path, extra):
    """The shallow convex round's tips have no land (a warning); a refusal of the solve's inputs was printed
    after that warning, two lines.  Now the warning waits for the solve: the refusal is the one line."""
    from pathlib import Path

    design = Path(__file__).resolve().parents[1] / "samples" / "tooling" / "shallow_convex_round.toml"
    rc, so, err = run(capsys, "fe", "punch", design, *extra, "--steel", "S7_tempered_205C", "--out", tmp_path / "o")
    assert rc == 2 and err.count("\n") == 1 and err.startswith(f"error: {extra[-2]} = "), err
    assert list(tmp_path.iterdir()) == []


def test_a_punch_force_above_its_rating_is_warned_of(capsys, tmp_path):
    """20,000 kN (newtons typed as kN) printed a von Mises stress of 3.6e5 MPa beside the rating without a word."""
    design = tmp_path / "tooled.toml"
    design.write_text(TOOLED)
    rc, so, err = run(capsys, "fe", "punch", design, "--force", 5000, "--steel", "S7_tempered_205C", "--mesh-size", 1.0,
                      "--json")
    assert rc == 0
    d = json.loads(so)
    assert err.splitlines() == [f"warning: --force 5000 kN is {5000 / d['allowed_force_kN']:.3g} times the allowed force "
                                f"({d['allowed_force_kN']:.4g} kN): the tip would yield or buckle (--force is in kN)"]
    rc, so, err = run(capsys, "fe", "punch", design, "--force", 5, "--steel", "S7_tempered_205C", "--mesh-size", 1.0)
    assert rc == 0 and "times the allowed force" not in err


def test_the_relative_discretisation_error_keeps_the_sign_of_the_estimate():
    """A negative Richardson estimate (-0.0226 MPa on a concave round) was reported as +0.0091 relative."""
    import dataclasses

    from tabletcad.families import flat_face_round
    from tabletcad.fe.diametral import diametral

    r = diametral(flat_face_round(diameter=8.0, thickness=1.0), 50.0, "x", mesh_size=0.8, error_estimate=False)
    for err in (-0.0226, 0.0085):
        d = dataclasses.replace(r, discretisation_error_MPa=err).to_dict()
        assert d["discretisation_error_relative"] == pytest.approx(err / r.centre_tensile_stress_MPa, rel=1e-15)
