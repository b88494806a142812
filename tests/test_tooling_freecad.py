"""FreeCAD (its own OCCT) reads the tooling STEP files: valid solids with the right names."""


import pytest



pytest.importorskip("OCP")
pytest.importorskip("manifold3d")

from tabletcad.cad.readback import find_freecadcmd, freecad_read_step  # noqa: E402
from tabletcad.shapes import shallow_convex_round  # noqa: E402
from tabletcad.tooling import ToolingSpec, make_tooling, write_tooling  # noqa: E402

pytestmark = [pytest.mark.cad, pytest.mark.freecad]

if find_freecadcmd() is None:
    pytest.skip("freecadcmd not installed", allow_module_level=True)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    ts = make_tooling(shallow_convex_round(), ToolingSpec(clearance_mm=0.02, gap_mm=2.5), check=False,
                      interference_check=False)
    out = tmp_path_factory.mktemp("fc")
    write_tooling(ts, out, drawing=False)
    return out, ts


_PART_READ = """
import json, os
import FreeCAD, Import, Part
shape = Part.read(os.environ["TABLETCAD_FC_INPUT"])
res = {"n_solids": len(shape.Solids), "valid": [bool(s.isValid()) for s in shape.Solids],
       "closed": [bool(s.isClosed()) for s in shape.Solids], "volumes": [s.Volume for s in shape.Solids]}
# names: FreeCAD's own STEP import into a document.  Import.insert (ImportOCAF2) crashes on
# multi-part assemblies in FreeCAD 0.20; the plain ImportOCAF path (mode 0, no link groups) works.
prefs = FreeCAD.ParamGet("User parameter:BaseApp/Preferences/Mod/Import")
prefs.SetBool("UseLinkGroup", False)
prefs.SetInt("ImportMode", 0)
Import.open(os.environ["TABLETCAD_FC_INPUT"])
doc = FreeCAD.ActiveDocument
res["named_solids"] = {o.Label: bool(o.Shape.isValid()) for o in doc.Objects
                       if o.TypeId == "Part::Feature" and o.Shape.Solids}
open(os.environ["TABLETCAD_FC_OUTPUT"], "w").write(json.dumps(res))
"""


def _freecad_part_read(path, tmp_path):
    """FreeCAD reads the file with ``Part.read`` (solids) and ``Import.open`` (named parts)."""
    import json
    import subprocess

    from tabletcad.cad.readback import _clean_env

    script = tmp_path / "fc_part_read.py"
    script.write_text(_PART_READ)
    env = _clean_env()
    env.update(FREECAD_USER_HOME=str(tmp_path), TABLETCAD_FC_INPUT=str(path), TABLETCAD_FC_OUTPUT=str(tmp_path / "r.json"))
    subprocess.run([find_freecadcmd(), str(script)], env=env, cwd=tmp_path, capture_output=True, timeout=300)
    return json.loads((tmp_path / "r.json").read_text())


def test_freecad_reads_the_assembly_as_valid_solids_with_named_parts(files, tmp_path):
    out, ts = files
    r = _freecad_part_read(out / "assembly.step", tmp_path)
    assert r["n_solids"] == 4 and all(r["valid"]) and all(r["closed"])
    from tabletcad.cad.solid import mass_properties

    expected = sorted(mass_properties(s, None).volume for s in ts.parts.values())
    assert sorted(r["volumes"]) == pytest.approx(expected, rel=1e-6)
    # names as FreeCAD's own importer sees them: four valid, named solids
    assert r["named_solids"] == {"tablet": True, "upper_punch": True, "lower_punch": True, "die": True}
    # and the XCAF product names as OCP's STEP reader sees them in a fresh process
    from tabletcad.cad.readback import ocp_read_step

    products = ocp_read_step(out / "assembly.step")["products"]
    assert {"tablet", "upper_punch", "lower_punch", "die"} <= set(products)


@pytest.mark.parametrize("name", ["upper_punch", "lower_punch", "die"])
def test_freecad_reads_each_part(files, name):
    out, ts = files
    r = freecad_read_step(out / f"{name}.step")
    assert r["n_solids"] == 1 and r["valid"]
    from tabletcad.cad.solid import mass_properties

    assert r["volume"] == pytest.approx(mass_properties(ts.parts[name], None).volume, rel=1e-6)
    assert name in " ".join(r.get("labels", []))
