"""Every tooling sample builds; FreeCAD (its own OCCT, under freecadcmd) reads each part as one valid
closed solid and the assembly with four named, valid parts; the assembly carries each part's colour."""

import json
import subprocess
from pathlib import Path

import pytest

pytest.importorskip("OCP")
pytest.importorskip("manifold3d")

from support.readback import _clean_env, find_freecadcmd  # noqa: E402
from tabletcad.pipeline.design import load_design  # noqa: E402
from tabletcad.tooling import make_tooling, write_tooling  # noqa: E402
from tabletcad.tooling.assembly import PART_COLOURS, read_assembly_colours  # noqa: E402
from tabletcad.pipeline.design import Design  # noqa: E402

pytestmark = [pytest.mark.cad, pytest.mark.freecad]

SAMPLES = sorted((Path(__file__).resolve().parents[1] / "samples" / "tooling").glob("*.toml"))
FILES = ("assembly.step", "upper_punch.step", "lower_punch.step", "die.step")

_READ_ALL = """
import json, os
import FreeCAD, Import, Part
prefs = FreeCAD.ParamGet("User parameter:BaseApp/Preferences/Mod/Import")
prefs.SetBool("UseLinkGroup", False)
prefs.SetInt("ImportMode", 0)
out = {}
for path in json.loads(os.environ["TABLETCAD_FC_INPUTS"]):
    shape = Part.read(path)
    r = {"n_solids": len(shape.Solids), "valid": all(s.isValid() for s in shape.Solids),
         "closed": all(s.isClosed() for s in shape.Solids), "volume": sum(s.Volume for s in shape.Solids)}
    if path.endswith("assembly.step"):
        Import.open(path)
        doc = FreeCAD.ActiveDocument
        r["named"] = {o.Label: bool(o.Shape.isValid()) for o in doc.Objects
                      if o.TypeId == "Part::Feature" and o.Shape.Solids}
        FreeCAD.closeDocument(doc.Name)
    out[path] = r
open(os.environ["TABLETCAD_FC_OUTPUT"], "w").write(json.dumps(out))
"""


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    root = tmp_path_factory.mktemp("samples")
    res = {}
    for p in SAMPLES:
        ts = make_tooling(load_design(p), Design.from_toml(p).tooling_spec, check=False, interference_check=False)
        out = root / p.stem
        out.mkdir()
        write_tooling(ts, out, drawing=False)
        res[p.stem] = (out, ts)
    return root, res


def test_samples_cover_tsm_b_eu_d_a_scored_capsule_and_an_embossed_shaped_tablet(built):
    _, res = built
    kinds = {(ts.spec.body.standard, ts.spec.body.kind) for _, ts in res.values() if ts.spec.body is not None}
    assert {("TSM", "B"), ("EU", "D")} <= kinds
    assert any(ts.frame.outline_kind != "circle" and ts.spec.scores for _, ts in res.values())
    assert any(ts.frame.outline_kind != "circle" and ts.spec.emboss for _, ts in res.values())


def test_every_complete_punch_is_tip_minus_relief_plus_body_and_key(built):
    """The volume of each sample's complete punches: tip - relief + the body's closed form + the key's
    (a toolmaker's trial: the README's sum was 114.26 mm³, the key, short on the keyed TSM B sample)."""
    _, res = built
    keyed = 0
    for name, (_, ts) in res.items():
        for which in ("upper_punch", "lower_punch") if ts.spec.body is not None else ():
            info = ts.report[which]
            body = info["body"]
            expected = (info["tip_volume_mm3"] - body["relief_volume_mm3"] + body["body_volume_closed_form_mm3"]
                        + body["key_volume_mm3"])
            assert body["volume_mm3"] == pytest.approx(expected, rel=1e-7), (name, which)
            keyed += body["key_volume_mm3"] > 0.0
    assert keyed >= 2  # (the TSM B sample's two keyed punches: 114.27 mm³ each, 4.76 x 1.5 proud x 15 long)


def test_assembly_names_and_colours_each_part(built):
    _, res = built
    for out, _ in res.values():
        colours = read_assembly_colours(out / "assembly.step")
        assert set(colours) == set(PART_COLOURS)
        for k, rgb in PART_COLOURS.items():
            assert colours[k] == pytest.approx(rgb, abs=2e-3)


def test_freecad_reads_every_sample_part_as_one_valid_solid(built, tmp_path):
    fc = find_freecadcmd()
    if fc is None:
        pytest.skip("freecadcmd not installed")
    _, res = built
    paths = [str(out / f) for out, _ in res.values() for f in FILES]
    script = tmp_path / "read_all.py"
    script.write_text(_READ_ALL)
    env = _clean_env()
    env.update(FREECAD_USER_HOME=str(tmp_path), TABLETCAD_FC_INPUTS=json.dumps(paths),
               TABLETCAD_FC_OUTPUT=str(tmp_path / "r.json"))
    subprocess.run([fc, str(script)], env=env, cwd=tmp_path, capture_output=True, timeout=900)
    got = json.loads((tmp_path / "r.json").read_text())
    from tabletcad.cad.solid import mass_properties

    for out, ts in res.values():
        for f in FILES:
            r = got[str(out / f)]
            n = 4 if f == "assembly.step" else 1
            assert (r["n_solids"], r["valid"], r["closed"]) == (n, True, True), (out.name, f)
            if f != "assembly.step":
                v = mass_properties(ts.parts[f[:-5]], None).volume
                assert r["volume"] == pytest.approx(v, rel=1e-6), (out.name, f)
        named = got[str(out / "assembly.step")]["named"]
        assert named == {"tablet": True, "upper_punch": True, "lower_punch": True, "die": True}, out.name


def test_a_lettered_part_read_back_meshes_for_stl_glb_and_notebooks(built, tmp_path):
    """OCCT's Delabella leaves the faces of letters cut into a face untriangulated: the EU D oval's lettered tablet
    and upper punch, read back from their STEP files, had failed export to STL/GLB/3MF and a notebook's picture
    ("a face has no triangulation after meshing"); :func:`tessellate` meshes them by Watson then, as the tooling's
    own checks do.  The closed mesh's volume is the solid's within the deflection times the area."""
    import trimesh
    from OCP.GProp import GProp_GProps
    from OCP.BRepGProp import BRepGProp
    from OCP.STEPControl import STEPControl_Reader

    from tabletcad.cad.export import export

    _, ts = built[1]["eu_d_oval"]
    assert ts.spec.emboss
    for name in ("tablet", "upper_punch"):
        step = export(ts.parts[name], tmp_path / f"{name}.step")  # (a fresh shape: no triangulation on it)
        reader = STEPControl_Reader()
        assert reader.ReadFile(str(step)) == 1 and reader.TransferRoots() == 1
        shape = reader.OneShape()
        props, area = GProp_GProps(), GProp_GProps()
        BRepGProp.VolumeProperties_s(shape, props)
        BRepGProp.SurfaceProperties_s(shape, area)
        mesh = trimesh.load(export(shape, tmp_path / f"{name}.stl"))
        assert mesh.is_watertight
        assert abs(mesh.volume - props.Mass()) <= 0.005 * area.Mass(), name  # (0.005 mm: export's deflection)
