"""Tessellation checks, exporters and STEP read-back with OCP in a fresh process."""

import functools
import re
import struct
import xml.etree.ElementTree as ET
import zipfile

import numpy as np
import pytest



pytest.importorskip("OCP")
pytest.importorskip("manifold3d")
trimesh = pytest.importorskip("trimesh")

from tabletcad.cad.export import export  # noqa: E402
from tabletcad.cad.mesh import tessellate  # noqa: E402
from support.readback import ocp_read_steps  # noqa: E402
from tabletcad.cad.solid import build_solid  # noqa: E402
from support.standins import cylinder, ring, sphere  # noqa: E402

pytestmark = pytest.mark.cad
STANDINS = [sphere(2.5), cylinder(2.5, 3.0), ring(1.5, 3.0, 2.0)]


UNICODE_NAME = "Tablette Ø10 – «test» 日本"


@functools.cache
def _built(i: int):
    s = STANDINS[i]
    return s, build_solid(s.patches, 1e-4, name=s.name.replace(" ", "_"))


@pytest.fixture(scope="module", params=range(len(STANDINS)), ids=[s.name for s in STANDINS])
def built(request):
    return _built(request.param)


@pytest.fixture(scope="module")
def read_back(tmp_path_factory):
    """The STEP files the read-back tests check, read by OCP in *one* fresh process (one OCP import, not
    one per file): each stand-in as ``part.step`` (by its index), and the stand-in sphere under a name
    beyond ASCII as ``u.step`` (key ``"unicode"``).  ``{key: (path, result)}``."""
    paths = {}
    for i in range(len(STANDINS)):
        _, ts = _built(i)
        paths[i] = export(ts, tmp_path_factory.mktemp(f"standin{i}") / "part.step")
    ts = build_solid(STANDINS[0].patches, 1e-4, name="standin")
    paths["unicode"] = export(ts, tmp_path_factory.mktemp("unicode") / "u.step", name=UNICODE_NAME)
    return {k: (p, r) for (k, p), r in zip(paths.items(), ocp_read_steps(list(paths.values())))}


@pytest.mark.parametrize("deflection", [0.01, 0.002])
def test_mesh_is_closed_manifold_with_right_genus_and_volume(built, deflection):
    s, ts = built
    m = tessellate(ts.shape, deflection, 0.1)
    assert m.is_manifold and m.watertight and m.winding_consistent and m.ok
    assert m.manifold_genus == s.genus
    # inscribed chords: the mesh loses at most ~ deflection * area of volume
    assert 0 <= ts.volume - m.volume <= deflection * ts.area
    assert m.manifold_volume == pytest.approx(m.volume, rel=1e-5)  # float32 vertices in manifold3d


def test_finer_mesh_is_closer(built):
    _, ts = built
    coarse, fine = tessellate(ts.shape, 0.02, 0.2), tessellate(ts.shape, 0.002, 0.1)
    assert abs(fine.volume - ts.volume) < abs(coarse.volume - ts.volume)


def test_step_text_and_fresh_process_readback(built, read_back):
    s, ts = built
    path, r = read_back[next(i for i in range(len(STANDINS)) if STANDINS[i] is s)]
    text = path.read_text()
    assert "SI_UNIT(.MILLI.,.METRE.)" in text.replace(" ", "")
    assert re.search(r"PRODUCT\s*\(\s*'%s'" % re.escape(ts.name), text)
    assert "AP242" in text
    assert r["n_solids"] == 1 and r["valid"]
    assert r["n_faces"] == len(s.patches)
    assert r["products"] == [ts.name]
    assert r["volume"] == pytest.approx(ts.volume, rel=1e-9)
    assert r["area"] == pytest.approx(ts.area, rel=1e-9)
    # millimetres really: the bounding box matches the part (catches a x1000 unit slip)
    grid = np.meshgrid(np.linspace(0, 1, 41), np.linspace(0, 2 * np.pi, 73), indexing="ij")
    extent = max(np.abs(p.evaluate(*grid)).max() for p in s.patches)
    assert max(abs(x) for x in r["bbox"]) == pytest.approx(extent, abs=1e-3)


def test_ap214_schema(tmp_path):
    ts = build_solid(sphere(1.0).patches, name="s214")
    text = export(ts, tmp_path / "a.stp", schema="AP214").read_text()
    assert "AUTOMOTIVE_DESIGN" in text and "SI_UNIT(.MILLI.,.METRE.)" in text.replace(" ", "")


def test_mesh_formats(tmp_path):
    ts = build_solid(ring().patches, name="ring")
    m = tessellate(ts.shape, 0.005, 0.2)
    # STL (binary)
    stl = export(ts, tmp_path / "r.stl", mesh=m)
    raw = stl.read_bytes()
    (n,) = struct.unpack("<I", raw[80:84])
    assert n == len(m.triangles) and len(raw) == 84 + 50 * n
    t = trimesh.load(stl, force="mesh")
    assert t.is_watertight and t.volume == pytest.approx(m.volume, rel=1e-5)
    # 3MF: unit millimetre, one named object, same triangles
    p3 = export(ts, tmp_path / "r.3mf", mesh=m)
    with zipfile.ZipFile(p3) as zf:
        root = ET.fromstring(zf.read("3D/3dmodel.model"))
    ns = {"m": "http://schemas.microsoft.com/3dmanufacturing/core/2015/02"}
    assert root.get("unit") == "millimeter"
    obj = root.find(".//m:object", ns)
    assert obj.get("name") == "ring"
    assert len(obj.findall(".//m:triangle", ns)) == len(m.triangles)
    # GLB: metres, glTF's +Y up (the tablet's z), outward as the mesh (a rotation keeps the volume's sign)
    glb = trimesh.load(export(ts, tmp_path / "r.glb", mesh=m), force="mesh")
    assert glb.volume == pytest.approx(m.volume * 1e-9, rel=1e-5)
    lo, hi = np.asarray(m.vertices).min(axis=0) * 1e-3, np.asarray(m.vertices).max(axis=0) * 1e-3
    np.testing.assert_allclose(glb.bounds, [[lo[0], lo[2], -hi[1]], [hi[0], hi[2], -lo[1]]], rtol=0, atol=1e-9)
    # BREP
    from OCP.BRep import BRep_Builder
    from OCP.BRepTools import BRepTools
    from OCP.TopoDS import TopoDS_Shape

    from tabletcad.cad.solid import mass_properties

    shape = TopoDS_Shape()
    assert BRepTools.Read_s(shape, str(export(ts, tmp_path / "r.brep")), BRep_Builder())
    assert mass_properties(shape).volume == pytest.approx(ts.volume, rel=1e-12)


def test_unknown_suffix_and_atomicity(tmp_path):
    ts = build_solid(sphere(1.0).patches)
    from tabletcad.errors import DesignError

    with pytest.raises(DesignError, match=r"^path = '.*x\.obj' is not allowed: its file suffix '\.obj' must be one of "
                                          r"\.3mf, \.brep, \.glb, \.step, \.stl, \.stp$") as exc:
        export(ts, tmp_path / "x.obj")
    assert exc.value.parameter == "path" and isinstance(exc.value, ValueError)
    export(ts, tmp_path / "x.step")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["x.step"]  # no temporary left behind


def test_a_name_beyond_ascii_reads_back_as_written(read_back):
    """A design name in any script (design files allow it) is the STEP PRODUCT's name, read back the
    same by STEPControl (fresh process) and by STEPCAFControl's document; it came back double-encoded
    ('Ã\\x98' for 'Ø') when the name was handed to OCC as bytes of Latin-1."""
    from OCP.STEPCAFControl import STEPCAFControl_Reader
    from OCP.TCollection import TCollection_ExtendedString
    from OCP.TDataStd import TDataStd_Name
    from OCP.TDF import TDF_LabelSequence
    from OCP.TDocStd import TDocStd_Document
    from OCP.XCAFDoc import XCAFDoc_DocumentTool

    name = UNICODE_NAME
    path, r = read_back["unicode"]  # build_solid(STANDINS[0].patches, 1e-4, name="standin"), exported as `name`
    assert r["products"] == [name]
    doc = TDocStd_Document(TCollection_ExtendedString("XmlOcaf"))
    reader = STEPCAFControl_Reader()
    reader.SetNameMode(True)
    reader.ReadFile(str(path))
    assert reader.Transfer(doc)
    labels = TDF_LabelSequence()
    XCAFDoc_DocumentTool.ShapeTool_s(doc.Main()).GetFreeShapes(labels)
    attr = TDataStd_Name()
    assert labels.Length() == 1 and labels.Value(1).FindAttribute(TDataStd_Name.GetID_s(), attr)
    assert attr.Get().ToExtString() == name


@pytest.mark.parametrize("seed", range(12))
def test_edge_check_agrees_with_trimesh(seed):
    """The mesh checks' watertight and winding figures come from the triangles' edges (no trimesh import
    on a build's path): on closed meshes with triangles flipped, removed or repeated at random, they are
    trimesh's ``is_watertight`` and ``is_winding_consistent``."""
    from tabletcad.cad.mesh import _edge_check

    rng = np.random.default_rng(seed)
    base = trimesh.creation.icosphere(2) if seed % 2 else trimesh.creation.annulus(1.0, 2.0, 1.0)
    T = np.array(base.faces)
    what = seed % 4
    k = rng.choice(len(T), size=1 + seed // 4, replace=False)
    if what == 1:
        T[k] = T[k][:, ::-1]  # flipped
    elif what == 2:
        T = np.delete(T, k, axis=0)  # holes
    elif what == 3:
        T = np.vstack([T, T[k]])  # repeated
    tm = trimesh.Trimesh(base.vertices, T, process=False)
    assert _edge_check(T) == (tm.is_watertight, tm.is_winding_consistent)


@pytest.mark.parametrize("kw, parameter", [
    (dict(linear_deflection=float("nan")), "linear_deflection"),   # had meshed until the memory ran out
    (dict(linear_deflection=1e-7), "linear_deflection"),
    (dict(linear_deflection=float("inf")), "linear_deflection"),  # had written an empty mesh
    (dict(linear_deflection=0.0), "linear_deflection"),
    (dict(angular_deflection=float("nan")), "angular_deflection"),  # had given 15x the triangles, silently
    (dict(angular_deflection=2.0), "angular_deflection"),
    (dict(linear_deflection=2.0, relative=True), "linear_deflection"),
])
def test_a_deflection_out_of_range_is_refused_naming_it(tmp_path, kw, parameter):
    from tabletcad.cad.mesh import tessellate_solid
    from tabletcad.errors import DesignError

    solid = build_solid(cylinder(5.0, 3.0).patches)
    with pytest.raises(DesignError) as err:
        export(solid, tmp_path / "t.stl", **kw)
    assert err.value.parameter == parameter and "\n" not in str(err.value)
    if not kw.get("relative"):
        with pytest.raises(DesignError):
            tessellate_solid(solid, **kw)
    assert list(tmp_path.iterdir()) == []


def test_export_refuses_an_option_it_does_not_know_and_applies_relative(tmp_path):
    """A misspelt mesh option had been dropped in silence (the file byte-identical to the default's), and
    ``relative`` with it."""
    solid = build_solid(cylinder(5.0, 3.0).patches)
    with pytest.raises(TypeError, match="linear_deflexion"):
        export(solid, tmp_path / "a.stl", linear_deflexion=0.1)
    a = export(solid, tmp_path / "a.stl").read_bytes()
    b = export(solid, tmp_path / "b.stl", linear_deflection=0.01, relative=True).read_bytes()
    assert a != b and len(b) > 84


def test_edge_check_of_a_closed_mesh_with_a_degenerate_triangle_is_trimesh_s():
    """A closed mesh takes the short way (each directed edge once, its reverse once); one with a
    triangle that repeats a vertex does not, and gets trimesh's figures."""
    from tabletcad.cad.mesh import _edge_check

    base = trimesh.creation.icosphere(2)
    T = np.array(base.faces)
    assert _edge_check(T) == (True, True)
    a, b = T[0, 0], T[0, 1]
    for bad in ([a, a, b], [a, b, a]):
        T2 = np.vstack([T, [bad]])
        tm = trimesh.Trimesh(base.vertices, T2, process=False)
        assert _edge_check(T2) == (tm.is_watertight, tm.is_winding_consistent)
