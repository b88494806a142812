"""A build owns its output folder: real ``tabletcad build`` runs (CAD stage).

A tooling build (finished tablet as ``tablet.*``, plain one as ``tablet_plain.step``)
rebuilt as a cut-away and as a plain tablet, and builds killed with SIGKILL and SIGTERM.
The publishing rules themselves are tested on plain files in ``test_build_outputs.py``.
"""

from __future__ import annotations

import json
import math
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from tabletcad.cli import main
from tabletcad.io.outputs import MANIFEST, STAGING_MARKER, read_manifest

pytestmark = pytest.mark.cad

pytest.importorskip("OCP")
pytest.importorskip("manifold3d")
pytest.importorskip("ezdxf")

ROOT = Path(__file__).resolve().parents[1]


def _build(design: Path, out: Path, capsys, warned: list | None = None) -> tuple[dict, str]:
    assert main(["build", str(design), "--out", str(out), "--quiet"]) == 0
    said = capsys.readouterr()
    if warned is not None:
        warned.extend(said.err.strip().splitlines())
    line = said.out.strip().splitlines()[-1]
    return json.loads((out / "report.json").read_text()), line


def _listed(line: str) -> list[str]:
    return line.rsplit("(", 1)[1].rstrip(")").split(", ")


@pytest.mark.cad
@pytest.mark.slow
def test_tooling_build_then_cutaway_then_plain_rebuild(tmp_path, tmp_path_factory, capsys):
    import shutil

    from support.readback import ocp_read_steps

    out = tmp_path / "out"
    rep, line = _build(ROOT / "samples" / "tooling" / "concave_round_bisect.toml", out, capsys)
    tool_files = {"assembly.step", "upper_punch.step", "lower_punch.step", "die.step", "drawing.svg", "drawing.dxf",
                  "tablet_plain.step", "tablet.step", "tablet.stl", "tablet.glb"}
    assert tool_files <= set(rep["outputs"])
    assert _listed(line) == rep["outputs"] == sorted(read_manifest(out))
    # exactly the files the build checks before its geometry (tooling_outputs)
    from tabletcad.pipeline.design import Design
    from tabletcad.tooling.stage import tooling_outputs

    spec = Design.from_toml(ROOT / "samples" / "tooling" / "concave_round_bisect.toml").tooling_spec
    assert set(rep["outputs"]) == {"report.json", "tablet.png", "tablet.step", "tablet.stl", "tablet.glb",
                                   *tooling_outputs(spec)}
    # the two STEP files are read back after the cut-away's build, with its tablet.step, in one fresh
    # process (one OCP import): copies outside tmp_path, where the next build replaces tablet.step and
    # removes tablet_plain.step
    first = tmp_path_factory.mktemp("first_build")
    for name in ("tablet.step", "tablet_plain.step"):
        shutil.copy2(out / name, first / name)

    (out / "notes.txt").write_text("mine")
    (out / "drawing.svg").write_text((out / "drawing.svg").read_text() + "<!-- edited -->")
    rep2, line2 = _build(ROOT / "samples" / "cutaway_convex_round.toml", out, capsys)
    fin, plain, cut = ocp_read_steps([first / "tablet.step", first / "tablet_plain.step", out / "tablet.step"],
                                     measure=("volume_default",))
    # tablet.step is the finished (scored, debossed) tablet, tablet_plain.step the PDE tablet
    assert fin["valid"] and plain["valid"] and fin["n_solids"] == plain["n_solids"] == 1
    assert fin["volume"] == pytest.approx(rep["tooling"]["tablet"]["volume_mm3"], rel=1e-6)
    assert plain["volume"] == pytest.approx(rep["volume_mm3"], rel=1e-6)
    removed = rep["tooling"]["tablet"]["volume_plain_mm3"] - rep["tooling"]["tablet"]["volume_mm3"]
    # tablet_plain.step has faces of revolution: OCC's adaptive integration is 3e-7 low on them, its
    # non-adaptive one splits at the profile's knots and is exact (README, "CAD solids")
    assert plain["volume_default"] - fin["volume"] == pytest.approx(removed, rel=1e-5) and removed > 0.05
    assert fin["n_faces"] > plain["n_faces"]
    # weights at the sample's [report] density (0.85 x 1.5 mg/mm^3): design_report's is the plain
    # tablet's, tooling.tablet's the finished one's, which the halves share and the summary prints
    tab, rho = rep["tooling"]["tablet"], 0.85 * 1.5
    assert rep["design_report"]["weight_mg"] == pytest.approx(plain["volume"] * rho, rel=1e-6)
    assert tab["weight_plain_mg"] == pytest.approx(plain["volume"] * rho, rel=1e-6)
    assert tab["weight_mg"] == pytest.approx(fin["volume"] * rho, rel=1e-6)
    assert sum(p["mass_mg"] for p in rep["tooling"]["split"]["parts"]) == pytest.approx(tab["weight_mg"], rel=1e-6)
    assert f"finished (scored/embossed) tablet: volume {fin['volume']:.4g} mm3, weight {fin['volume'] * rho:.4g} mg" in line

    expected = set(rep2["outputs"]) | {MANIFEST, "notes.txt", "drawing.svg"}
    assert {p.name for p in out.iterdir()} == expected
    assert _listed(line2) == rep2["outputs"] and "drawing.svg" not in rep2["outputs"]
    assert "assembly.step" not in expected and "upper_punch.step" not in expected
    # the cut-away is a solid: its STEP holds the trimmed volume of the report
    assert {"tablet.step", "tablet.stl", "tablet.glb"} <= set(rep2["outputs"]) and "tablet_plain.step" not in expected
    assert cut["valid"] and cut["n_solids"] == 1
    assert cut["volume"] == pytest.approx(rep2["volume_mm3"], rel=1e-6)
    assert rep2["volume_mm3"] == pytest.approx(0.75 * rep3_full_volume(), rel=1e-9)  # 3/4 of the round

    # a plain design into the folder: exactly its files (and the two that are not tabletcad's now)
    rep3, _ = _build(ROOT / "samples" / "flat_faced_round.toml", out, capsys)
    assert {p.name for p in out.iterdir()} == set(rep3["outputs"]) | {MANIFEST, "notes.txt", "drawing.svg"}
    assert set(rep3["outputs"]) == {"report.json", "tablet.png", "tablet.step", "tablet.stl", "tablet.glb"}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def rep3_full_volume() -> float:
    from dataclasses import replace

    from tabletcad.pipeline.design import load_design
    from tabletcad.geometry.tablet import Trim

    return replace(load_design(ROOT / "samples" / "cutaway_convex_round.toml"), trim=Trim()).volume()


@pytest.mark.parametrize("design, trim", [
    ("almond", (0.0, 3.0)), ("rounded_triangle", (0.5, 4.0)), ("capsule", (0.3, 2.0)),
], ids=["almond", "rounded_triangle", "capsule"])
def test_cutaway_with_curved_cut_faces_is_a_solid(tmp_path, capsys, design, trim):
    """A swept outline's sections at constant v are ruled surfaces, not planes: the cut-away is
    fitted and sewn directly.  Its STEP, read back in a fresh process, holds one valid solid
    whose volume is the core's quadrature over the trimmed domain (Gauss-Legendre per smooth
    piece between the outline's joins), which itself agrees with the independent Jacobian
    integral at 8x the nodes."""
    from dataclasses import replace

    from support.readback import mesh_volume, ocp_read_steps
    from tabletcad.cad.stage import _cut_plane_angle
    from tabletcad.pipeline.design import load_design
    from tabletcad.geometry.tablet import Trim

    t = replace(load_design(ROOT / "samples" / "families" / f"{design}.toml"), trim=Trim(v=trim))
    assert _cut_plane_angle(t, trim[0]) is None  # not a half-plane: the direct construction
    assert t.volume() == pytest.approx(t.solid_volume(nv=2048), rel=1e-10)
    src = tmp_path / "cut.toml"
    src.write_text((ROOT / "samples" / "families" / f"{design}.toml").read_text() + f"\n[trim]\nv = [{trim[0]}, {trim[1]}]\n")
    warned = []
    rep, _ = _build(src, tmp_path / "out", capsys, warned)
    assert rep["brep"]["valid"] and "ruled cut faces" in rep["brep"]["cutaway"]
    # a view, said so (a trial: gmsh refused these STEP files, "overlapping facets", which BRepCheck passes)
    assert any(w.startswith("warning: ") and "the cut-away of a shaped tablet is a view" in w for w in warned), warned
    assert rep["volume_mm3"] == pytest.approx(t.volume(), rel=1e-12)
    assert abs(rep["brep"]["volume_rel_diff_vs_quadrature"]) < 1e-7
    # meshed on the chain's parameter grids where they close (the almond's and the triangle's; OCC's
    # BRepMesh left cracks in the almond's), else by BRepMesh (the capsule's slit)
    assert rep["mesh"]["watertight"] and rep["mesh"]["genus"] == 0 and "tablet.stl" in rep["outputs"]
    brep = rep["brep"]
    assert abs(rep["mesh"]["volume_rel_diff_vs_brep"]) * brep["volume_mm3"] <= 0.005 * brep["surface_area_mm2"]
    # the mesh section's volume is the written file's (it had been manifold3d's, which parts from it where the
    # cut faces fold: a trial), and its difference from the B-rep's is that volume's
    import trimesh

    # the file's triangles as written (process=False): merging the STL's repeated corners (0.9 s of the
    # rounded triangle's 500,000 triangles) moves no corner, and the volume, a sum over the triangles, is
    # the same to the bit (checked on the three cut-aways)
    stl = trimesh.load(tmp_path / "out" / "tablet.stl", process=False)
    assert rep["mesh"]["volume_mm3"] == pytest.approx(mesh_volume(stl.triangles), rel=1e-7)  # (stl.volume's)
    assert rep["mesh"]["volume_mm3"] == pytest.approx(brep["volume_mm3"] * (1 + rep["mesh"]["volume_rel_diff_vs_brep"]),
                                                      rel=1e-12)
    (cut,) = ocp_read_steps([tmp_path / "out" / "tablet.step"], measure=())  # (area, box unread)
    assert cut["valid"] and cut["n_solids"] == 1
    assert cut["volume"] == pytest.approx(rep["volume_mm3"], rel=1e-6)


def test_cut_planes_of_rounds_and_ovals_are_half_planes():
    """A round's section at v lies in the half-plane at angle v; the thesis oval's (ellipses of one
    aspect ratio) in a half-plane too, at the ellipse's polar angle atan(b/a tan v)."""
    from tabletcad.cad.stage import _cut_plane_angle
    from tabletcad.pipeline.design import design_from_dict

    r = design_from_dict({"tablet": {"family": "thesis.shallow_convex_round", "diameter": 10.0, "thickness": 3.0, "band": 2.0},
                          "trim": {"v": [0.0, 3.0]}})
    assert _cut_plane_angle(r, 0.0) == pytest.approx(0.0, abs=1e-12)
    assert _cut_plane_angle(r, 3.0) == pytest.approx(3.0, abs=1e-9)
    o = design_from_dict({"tablet": {"family": "thesis.shallow_convex_oval", "width": 6.0, "length": 12.0, "thickness": 3.0,
                                       "band": 2.0}, "trim": {"v": [0.0, 1.0]}})
    a, b = 6.0, 3.0  # half length and half width of the 12 x 6 mm oval
    assert _cut_plane_angle(o, 1.0) == pytest.approx(math.atan2(b * math.sin(1.0), a * math.cos(1.0)), abs=1e-9)


def _wait_for_staging(parent: Path, name: str, proc, timeout: float = 300.0) -> Path:
    t_end = time.monotonic() + timeout
    while time.monotonic() < t_end:
        found = [p for p in parent.glob(f".{name}.*") if (p / STAGING_MARKER).is_file()]
        if found:
            return found[0]
        assert proc.poll() is None, proc.communicate()
        time.sleep(0.05)
    raise AssertionError("no staging folder appeared")


@pytest.mark.cad
@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGTERM], ids=["SIGKILL", "SIGTERM"])
def test_killed_build_leaves_no_staging_folder_after_the_next_build(tmp_path, capsys, sig):
    design = ROOT / "samples" / "flat_faced_round.toml"
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-m", "tabletcad", "build", str(design), "--out", str(out), "--quiet"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        staging = _wait_for_staging(tmp_path, "out", proc)
        proc.send_signal(sig)
        proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
    if sig == signal.SIGKILL:
        assert staging.is_dir()  # nothing could clean up ...
    else:
        assert proc.returncode == 128 + signal.SIGTERM
        assert not staging.exists()  # ... SIGTERM removes the build's own staging folder
    assert not out.exists()
    rep, _ = _build(design, out, capsys)  # ... and the next build removes the stale one
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]
    assert {p.name for p in out.iterdir()} == set(rep["outputs"]) | {MANIFEST}


#: libraries a plain ``tabletcad build`` does not need: build123d and cadquery (2.3 s of CPU to import: they
#: pull scikit-learn, pandas and scipy.stats); only embossed tooling (fonts) and the interop functions use them
NOT_FOR_A_BUILD = ("build123d", "cadquery", "sklearn", "pandas")


def test_a_build_writes_its_cad_files_without_build123d_or_cadquery(tmp_path, capsys, monkeypatch):
    """Every file of a plain build, STEP, STL and GLB included, with :data:`NOT_FOR_A_BUILD` unimportable
    (``None`` in ``sys.modules``: an import of one of them, at any depth, raises ImportError)."""
    for name in NOT_FOR_A_BUILD:
        monkeypatch.setitem(sys.modules, name, None)
    out = tmp_path / "out"
    rep, _ = _build(ROOT / "samples" / "flat_faced_round.toml", out, capsys)
    assert set(rep["outputs"]) == {"report.json", "tablet.png", "tablet.step", "tablet.stl", "tablet.glb"}
    assert (out / "tablet.glb").read_bytes()[:4] == b"glTF"


@pytest.mark.parametrize("extra", ["[tooling]\nbogus = 1\n", "[tooling]\n[[tooling.score]]\nprofile = \"w\"\n",
                                   "[trim]\nv = [0.0, 3.0]\n[tooling]\nclearance_mm = 0.02\n"])
def test_bad_tooling_table_is_refused_before_any_geometry(tmp_path, capsys, monkeypatch, extra):
    import tabletcad.pipeline.build as build

    def no_geometry(*a, **k):
        raise AssertionError("geometry built before [tooling] was checked")

    monkeypatch.setattr(build, "geometry_report", no_geometry)
    d = tmp_path / "bad.toml"
    d.write_text('[tablet]\nfamily = "thesis.shallow_convex_round"\ndiameter = 10.0\nthickness = 3.0\nband = 2.0\n\n' + extra)
    assert main(["build", str(d), "--out", str(tmp_path / "out")]) == 2  # progress on: still one line
    cap = capsys.readouterr()
    assert cap.out == "" and len(cap.err.strip().splitlines()) == 1 and cap.err.startswith(("error: tooling", "error: trim"))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.toml"]


def test_a_free_form_band_without_caps_writes_its_report_and_picture(tmp_path, capsys):
    """One free-form patch of four equal circles, no caps: the core closes it with the solid map's flat
    end faces (nearly the cylinder's volume), the CAD chain of patch surfaces cannot; the build
    stopped with "sewing ... left 2 free edges" (not the one-line form).  Now report and picture,
    ``brep.skipped`` saying which end is open; a capped chain is unaffected (every sample builds)."""
    design = tmp_path / "band.toml"
    circles = ", ".join(f'{{ type = "circle", radius = 5.0, z = {z:.1f} }}' for z in (0, 1, 2, 3))
    design.write_text(f'[tablet]\nfamily = "free_form"\n[[patch]]\ncurves = [ {circles} ]\n')
    assert main(["build", str(design), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    rep = json.loads((tmp_path / "out" / "report.json").read_text())
    assert sorted(read_manifest(tmp_path / "out")) == ["report.json", "tablet.png"]
    assert "the chain's first curve encloses an area" in rep["brep"]["skipped"] and rep["brep"]["valid"] is None
    from tabletcad.pipeline.design import load_design

    # the divergence theorem over band and end faces = the triple integral of the solid map's Jacobian
    assert rep["volume_mm3"] == pytest.approx(load_design(design).solid_volume(), rel=1e-9)
    assert rep["volume_mm3"] == pytest.approx(math.pi * 25.0 * 3.0, rel=1e-3)  # nearly the cylinder


@pytest.mark.parametrize("end, expected", [
    ("pole", None), ("segment", None), ("circle", "last"),
])
def test_open_end_is_decided_by_the_curve_not_by_rounding(end, expected):
    """A pole 1000 mm up the axis whose points differ by rounding (under 1e-11 mm, its ends at v = 0
    and 2π too) encloses nothing: its vector area about the origin was |x| times the rounding, and it skipped the rounded triangle's
    solid on a machine whose BLAS rounded its top pole differently.  A curve folded onto a segment
    encloses nothing either; a 1 µm circle up there does."""
    from types import SimpleNamespace

    from tabletcad.cad.stage import _open_end

    def curve(u, v):
        v = np.asarray(v, float)
        if end == "pole":
            return np.column_stack([1e-13 * v, 1e-13 * v * v, np.full(v.shape, 1000.0)])  # v = 0 and 2π apart
        if end == "segment":
            return np.column_stack([2.0 * np.cos(v), np.zeros(v.shape), np.full(v.shape, 1000.0)])
        return np.column_stack([1e-3 * np.cos(v), 1e-3 * np.sin(v), np.full(v.shape, 1000.0)])

    def first(u, v):  # a pole at the origin: a closed bottom
        return np.zeros((np.asarray(v).size, 3))

    tablet = SimpleNamespace(patches=[SimpleNamespace(evaluate=first), SimpleNamespace(evaluate=curve)])
    assert _open_end(tablet) == expected


def test_a_hollow_tablet_of_several_patches_writes_its_report_and_picture(tmp_path, capsys):
    """The README's ``[trim] w`` on the thesis's flat-faced round (three patches): the report (its
    volume, by quadrature, the solid's minus the hollow core's) and the picture, with ``brep.skipped``
    saying why there is no solid; it stopped the build with a geometry error after the report."""
    design = tmp_path / "hollow.toml"
    design.write_text('[tablet]\nfamily = "thesis.flat_faced_round"\ndiameter = 10.0\nthickness = 6.0\n'
                      "[trim]\nw = [0.5, 1.0]\n")
    assert main(["build", str(design), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    rep = json.loads((tmp_path / "out" / "report.json").read_text())
    assert sorted(read_manifest(tmp_path / "out")) == ["report.json", "tablet.png"]
    assert "one-patch tablets only" in rep["brep"]["skipped"] and rep["brep"]["valid"] is None
    from tabletcad.pipeline.design import load_design

    v_full = load_design(ROOT / "samples" / "flat_faced_round.toml").volume()
    # every patch's spine lies on the axis, so w scales the sections about it in x and y only:
    # the core with w < 1/2 holds (1/2)² of the volume
    assert rep["volume_mm3"] == pytest.approx(0.75 * v_full, rel=1e-12)


@pytest.mark.parametrize("design, theirs", [("families/concave_round.toml", ["tablet.step"]),
                                            ("tooling/concave_round_bisect.toml", ["drawing.pdf", "die.step"])])
def test_a_folder_holding_files_the_build_writes_is_refused_before_the_geometry(tmp_path, capsys, monkeypatch,
                                                                               design, theirs):
    """Every file a build may write is checked before any geometry (it was report.json and tablet.png
    only: a user's tablet.step was found after the solid, 2-12 s later), and every clash is named."""
    import tabletcad.pipeline.build as build

    def no_geometry(*args, **kwargs):
        raise AssertionError("the geometry was computed before the folder was checked")

    monkeypatch.setattr(build, "geometry_report", no_geometry)
    out = tmp_path / "out"
    out.mkdir()
    for name in theirs:
        (out / name).write_text("mine")
    assert main(["build", str(ROOT / "samples" / design), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"error: --out = '{out}' is not allowed: must not hold files")
    for name in theirs:
        assert name in err[0] and (out / name).read_text() == "mine"
    assert sorted(p.name for p in out.iterdir()) == sorted(theirs)
