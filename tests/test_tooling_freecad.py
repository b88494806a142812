"""FreeCAD (its own OCCT) reads the tooling STEP files: valid solids with the right names.

Every check runs under each FreeCAD (Debian's 0.20 and 1.0 from the .ci/freecad1 root,
``tests/freecads.py``).  FreeCAD's GUI import (``ImportGui.insert``, names and colours) is
checked by the workbench's GUI test (tests/test_freecad_workbench.py).
"""


import pytest



pytest.importorskip("OCP")
pytest.importorskip("manifold3d")

import freecads  # noqa: E402
from support.readback import freecad_read_steps  # noqa: E402
from tabletcad.families.thesis import shallow_convex_round  # noqa: E402
from tabletcad.tooling import ToolingSpec, make_tooling, write_tooling  # noqa: E402

pytestmark = [pytest.mark.cad, pytest.mark.freecad]


@pytest.fixture(scope="module", params=freecads.params())
def fc(request) -> freecads.FreeCADInstall:
    return request.param


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
res = {"version": ".".join(FreeCAD.Version()[:3])}
if os.environ["TABLETCAD_FC_MODE"] != "boxes":
    shape = Part.read(os.environ["TABLETCAD_FC_INPUT"])
    res.update({"n_solids": len(shape.Solids), "valid": [bool(s.isValid()) for s in shape.Solids],
           "closed": [bool(s.isClosed()) for s in shape.Solids], "volumes": [s.Volume for s in shape.Solids]})
if os.environ["TABLETCAD_FC_MODE"] == "no_link_group":  # Import's own preference
    # FreeCAD 0.20's Import.insert (ImportOCAF2 with link groups) crashes on every multi-part
    # STEP file, FreeCAD's own two-box export too (test below); without link groups it reads it
    prefs = FreeCAD.ParamGet("User parameter:BaseApp/Preferences/Mod/Import")
    prefs.SetBool("UseLinkGroup", False)
if os.environ["TABLETCAD_FC_MODE"] == "boxes":  # FreeCAD's own two-part STEP
    d = FreeCAD.newDocument("boxes")
    a, b = d.addObject("Part::Box", "BoxA"), d.addObject("Part::Box", "BoxB")
    b.Placement.Base.x = 20.0
    d.recompute()
    Import.export([a, b], os.environ["TABLETCAD_FC_INPUT"])
doc = FreeCAD.newDocument("imported")
print("TABLETCAD_INSERT", flush=True)
Import.insert(os.environ["TABLETCAD_FC_INPUT"], doc.Name)
res["named_solids"] = {o.Label: bool(o.Shape.isValid()) for o in doc.Objects
                       if o.TypeId == "Part::Feature" and o.Shape.Solids}
open(os.environ["TABLETCAD_FC_OUTPUT"], "w").write(json.dumps(res))
"""


def _freecad_part_read(fc, path, tmp_path, mode="read"):
    """FreeCAD reads the file with ``Part.read`` (solids) and ``Import.insert`` (named parts).
    Returns ``(result or None, process)``."""
    import json
    import subprocess

    script = tmp_path / "fc_part_read.py"
    script.write_text(_PART_READ)
    out = tmp_path / f"r_{mode}.json"
    env = freecads.clean_env()
    env.update(FREECAD_USER_HOME=str(tmp_path), TABLETCAD_FC_INPUT=str(path), TABLETCAD_FC_OUTPUT=str(out),
               TABLETCAD_FC_MODE=mode)
    proc = subprocess.run([*fc.cmd, str(script)], env=env, cwd=tmp_path, capture_output=True, text=True,
                          timeout=300)
    return (json.loads(out.read_text()) if out.exists() else None), proc


def test_freecad_reads_the_assembly_as_valid_solids_with_named_parts(fc, files, ocp_products, tmp_path):
    """Part.read gives the four valid solids; Import.insert the four named parts - with
    FreeCAD's default import settings on 1.0, and without link groups on 0.20 (whose
    default crashes on any multi-part STEP, see the next test)."""
    out, ts = files
    r, proc = _freecad_part_read(fc, out / "assembly.step", tmp_path, "no_link_group" if fc.version == "0.20" else "default")
    assert r is not None, proc.stdout[-2000:] + proc.stderr[-2000:]
    assert r["n_solids"] == 4 and all(r["valid"]) and all(r["closed"])
    from tabletcad.cad.solid import mass_properties

    expected = sorted(mass_properties(s, None).volume for s in ts.parts.values())
    assert sorted(r["volumes"]) == pytest.approx(expected, rel=1e-6)
    # names as FreeCAD's own importer sees them: four valid, named solids
    assert r["named_solids"] == {"tablet": True, "upper_punch": True, "lower_punch": True, "die": True}
    # and the XCAF product names as OCP's STEP reader sees them in a fresh process
    products = ocp_products["assembly"]
    assert {"tablet", "upper_punch", "lower_punch", "die"} <= set(products)


def test_freecad020_import_insert_crash_is_freecads_own(fc, files, tmp_path):
    """FreeCAD 0.20's Import.insert with its default settings (link groups) dies with SIGSEGV
    on a multi-part STEP file whoever wrote it: FreeCAD's own export of two boxes too.  So no
    STEP form can avoid it; the workbench's reader and the tests above import without link
    groups there.  1.0 reads FreeCAD's two boxes and our assembly with its defaults."""
    out, ts = files
    r, proc = _freecad_part_read(fc, tmp_path / "boxes.step", tmp_path, "boxes")
    if fc.version == "0.20":
        assert r is None and "TABLETCAD_INSERT" in proc.stdout and "SIGSEGV" in proc.stdout + proc.stderr
    else:
        assert r is not None and set(r["named_solids"]) == {"BoxA", "BoxB"}


PARTS = ["upper_punch", "lower_punch", "die"]


@pytest.fixture(scope="module")
def parts_read(files):
    """``read(fc)``: ``{part: freecad_read_step's result}`` of that FreeCAD, the three part files read in one
    ``freecadcmd`` process per FreeCAD (three had each started FreeCAD for one file)."""
    out, _ = files
    cache: dict = {}

    def read(fc: freecads.FreeCADInstall) -> dict:
        if fc.version not in cache:
            cache[fc.version] = dict(zip(PARTS, freecad_read_steps([out / f"{n}.step" for n in PARTS],
                                                                   freecadcmd=fc.cmd)))
        return cache[fc.version]

    return read


@pytest.mark.parametrize("name", PARTS)
def test_freecad_reads_each_part(fc, files, parts_read, name):
    out, ts = files
    r = parts_read(fc)[name]
    assert r["n_solids"] == 1 and r["valid"]
    from tabletcad.cad.solid import mass_properties

    assert r["volume"] == pytest.approx(mass_properties(ts.parts[name], None).volume, rel=1e-6)
    assert name in " ".join(r.get("labels", []))


_NAME_READ = """
import json, os
import FreeCAD, Import
doc = FreeCAD.newDocument("n")
Import.insert(os.environ["TABLETCAD_FC_INPUT"], doc.Name)
open(os.environ["TABLETCAD_FC_OUTPUT"], "w", encoding="utf-8").write(
    json.dumps([o.Label for o in doc.Objects if o.TypeId == "Part::Feature"]))
"""

NAME = "Paracétamol 500 µg – 錠剤 O'Brien\\x 😀"


@pytest.fixture(scope="module")
def named_step(tmp_path_factory):
    """A box written by tabletcad's STEP writer under a product name outside ASCII (once: both FreeCADs
    read it)."""
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox

    from tabletcad.cad.export import export_step

    path = tmp_path_factory.mktemp("named") / "named.step"
    return export_step(BRepPrimAPI_MakeBox(1.0, 2.0, 3.0).Shape(), path, name=NAME)


@pytest.fixture(scope="module")
def ocp_products(files, named_step):
    """The STEP product names of the assembly and of the named box as OCP's STEP reader sees them, read
    once in one fresh process (OCP's import took 1.4 CPU-s a process; the tests read the names only)."""
    from support.readback import ocp_read_steps

    out, _ = files
    assembly, named = ocp_read_steps([out / "assembly.step", named_step], measure=())
    return {"assembly": assembly["products"], "named": named["products"]}


def test_a_unicode_name_is_written_in_part21_directives_and_read_back(fc, named_step, ocp_products, tmp_path):
    """OCC writes a product name outside ASCII as raw UTF-8 bytes under a header of Part 21's second
    edition (basic alphabet only); tabletcad writes ``\\X2\\...\\X0\\`` (``\\X4\\`` beyond U+FFFF), and
    OCC's reader and FreeCAD's importer give the name back."""
    import json
    import subprocess

    path = named_step
    raw = path.read_bytes()
    assert max(raw) < 0x80  # the whole file is ASCII
    text = raw.decode("ascii")
    assert "'Parac\\X2\\00E9\\X0\\tamol 500 \\X2\\00B5\\X0\\g \\X2\\2013\\X0\\ \\X2\\93205264\\X0\\ O''Brien\\\\x " \
           "\\X4\\0001F600\\X0\\'" in text
    assert NAME in ocp_products["named"]
    script = tmp_path / "fc_name.py"
    script.write_text(_NAME_READ)
    out = tmp_path / "names.json"
    env = freecads.clean_env()
    env.update(FREECAD_USER_HOME=str(tmp_path), TABLETCAD_FC_INPUT=str(path), TABLETCAD_FC_OUTPUT=str(out))
    proc = subprocess.run([*fc.cmd, str(script)], env=env, cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert out.exists(), proc.stdout[-2000:] + proc.stderr[-2000:]
    assert json.loads(out.read_text(encoding="utf-8")) == [NAME]
