"""The shell assembled edge by edge (tabletcad.cad.shell) against the sewn one (OCP)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("OCP")

from OCP.BRep import BRep_Tool  # noqa: E402
from OCP.BRepCheck import BRepCheck_Analyzer  # noqa: E402
from OCP.TopAbs import TopAbs_ShapeEnum  # noqa: E402
from OCP.TopExp import TopExp  # noqa: E402
from OCP.TopTools import TopTools_IndexedDataMapOfShapeListOfShape  # noqa: E402

import freecads  # noqa: E402
import tabletcad.cad.solid as solid_module  # noqa: E402
from tabletcad import Design  # noqa: E402
from tabletcad.brep.slit import chain_face_surfaces  # noqa: E402
from tabletcad.cad._occ import cast, explore  # noqa: E402
from tabletcad.cad.faces import make_geom_surface  # noqa: E402
from tabletcad.cad.shell import assemble_shell  # noqa: E402
from tabletcad.cad.solid import build_solid, mass_properties  # noqa: E402
from tabletcad.cad.tablet_solid import tablet_solid  # noqa: E402
from support.standins import cylinder, ring, sphere  # noqa: E402

pytestmark = pytest.mark.cad
ROOT = Path(__file__).resolve().parents[1]


def _edge_faces(shape) -> list[tuple[bool, int]]:
    """Per edge of ``shape``: (degenerated?, how many faces use it)."""
    m = TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapesAndAncestors_s(shape, TopAbs_ShapeEnum.TopAbs_EDGE, TopAbs_ShapeEnum.TopAbs_FACE, m)
    out = []
    for i in range(1, m.Extent() + 1):
        e = cast(m.FindKey(i), "Edge")
        out.append((BRep_Tool.Degenerated_s(e), m.FindFromIndex(i).Size()))
    return out


def _sewn(monkeypatch, make):
    """The same solid with its shell sewn (the assembly refused)."""
    with monkeypatch.context() as m:
        m.setattr(solid_module, "assemble_shell", lambda *a, **k: None)
        return make()


@pytest.mark.parametrize("sample", ["families/rounded_rectangle", "families/oval", "families/modified_capsule",
                                    "families/capsule",
                                    "caplet", "ring", "free_form_stadium"])
def test_assembled_shell_is_the_sewn_one(sample, monkeypatch):
    """Cut chains (collapsed corners: degenerated edges between runs), periodic chains (seams)
    and a chain closed on itself (the ring) are assembled, not sewn: a valid closed solid with the
    sewn solid's faces (a flat region one plane face either way), every edge but the degenerated ones
    shared by exactly two faces, and OCC's volume and area equal to the sewn solid's and to the faces'
    own Gauss-Legendre volume."""
    tablet = Design.from_toml(ROOT / "samples" / f"{sample}.toml").build()
    made = tablet_solid(tablet, revolved=False)
    sewn = _sewn(monkeypatch, lambda: tablet_solid(tablet, revolved=False))
    assert len(made.faces) == len(sewn.faces) and made.planes == sewn.planes
    assert not made.sewn and sewn.sewn
    # the summary names a sewing tolerance only for the solid that was sewn
    assert made.summary()["sew_tolerance_mm"] is None and made.summary()["sewn"] is False
    assert sewn.summary()["sew_tolerance_mm"] == sewn.sew_tolerance > 0.0 and sewn.summary()["sewn"] is True
    assert BRepCheck_Analyzer(made.shape).IsValid()
    shells = explore(made.shape, "Shell")
    assert len(shells) == 1 and BRep_Tool.IsClosed_s(shells[0])
    edges = _edge_faces(made.shape)
    assert all(n == 2 for deg, n in edges if not deg)
    assert all(n == 1 for deg, n in edges if deg)
    m, ms = mass_properties(made.shape), mass_properties(sewn.shape)
    data_volume, data_area = made.data_volume_area
    assert abs(m.volume - ms.volume) <= 1e-10 * ms.volume
    assert abs(m.area - ms.area) <= 1e-10 * ms.area
    assert abs(m.volume - abs(data_volume)) <= 1e-9 * m.volume
    assert abs(m.area - data_area) <= 1e-9 * m.area


def test_a_flat_region_round_a_slit_is_one_plane_face(monkeypatch, tmp_path):
    """A capsule without cups (cup depth 0): its flat top ends on the centre segment, run there and back
    inside the flat region; the region is one plane face bounded by the land's row alone, assembled at the
    first attempt (no fallback to the pieces or to sewing): six faces, two planes, valid, OCC's volume the
    faces' own."""
    text = (ROOT / "samples/families/capsule.toml").read_text()
    assert "cup_depth = 1.3" in text
    path = tmp_path / "capsule_flat.toml"
    path.write_text(text.replace("cup_depth = 1.3", "cup_depth = 0.0"))
    calls = []
    real = solid_module._solid_from_faces
    monkeypatch.setattr(solid_module, "_solid_from_faces",
                        lambda *a, **k: calls.append(k.get("planes")) or real(*a, **k))
    s = tablet_solid(Design.from_toml(path).build())
    assert calls == [2] and not s.sewn and s.planes == 2 and len(s.faces) == 6
    assert BRepCheck_Analyzer(s.shape).IsValid()
    v = mass_properties(s.shape).volume
    assert abs(v - abs(s.data_volume_area[0])) <= 1e-9 * v


@pytest.mark.parametrize("standin", [sphere(2.5), cylinder(2.5, 3.0), ring(1.5, 3.0, 2.0)], ids=lambda s: s.name)
def test_standins_are_assembled_to_their_closed_forms(standin):
    """The sphere (two poles), cylinder (flat ends) and ring (a chain closed on itself): assembled,
    valid, and OCC's volume within the fit's bound of the closed form."""
    s = build_solid(standin.patches, 1e-4, name=standin.name)
    assert not s.sewn and BRepCheck_Analyzer(s.shape).IsValid()
    assert abs(s.volume - standin.volume) <= s.max_fit_deviation * standin.area


def test_a_slit_is_assembled_and_a_mismatched_chain_is_left_to_sewing():
    """The capsule's innermost cup ends on a segment run there and back (an open end that is not a
    pole): the two runs share one edge, each face's p-curve on it at its own ``v`` (the way back's
    ``v = c - t``), and the solid is assembled, not sewn.  A way back that is not the way there
    reversed (one pole moved 1e-6 mm) is not assembled; nor is a chain whose neighbours' rows differ
    by one pole."""
    from dataclasses import replace

    capsule = Design.from_toml(ROOT / "samples/families/capsule.toml").build()
    s = tablet_solid(capsule)
    assert not s.sewn and BRepCheck_Analyzer(s.shape).IsValid()
    segment = [n for deg, n in _edge_faces(s.shape) if not deg]
    assert segment and all(n == 2 for n in segment)
    pieces = [list(ps) for ps in chain_face_surfaces(s.surfaces)]
    assert [len(ps) for ps in pieces] == [4] * 9
    geoms = [[make_geom_surface(p) for p in ps] for ps in pieces]
    assert assemble_shell(pieces, geoms) is not None
    d = pieces[0][3]  # the way back along the top's segment
    poles = np.array(d.poles)
    poles[0, 5] += [0.0, 1e-6, 0.0]
    pieces[0][3] = replace(d, poles=poles)
    assert assemble_shell(pieces, geoms) is None

    oval = tablet_solid(Design.from_toml(ROOT / "samples/families/oval.toml").build())
    pieces = [list(ps) for ps in chain_face_surfaces(oval.surfaces)]
    geoms = [[make_geom_surface(p) for p in ps] for ps in pieces]
    assert assemble_shell(pieces, geoms) is not None
    d = pieces[3][1]
    poles = np.array(d.poles)
    poles[0, 2] += 1e-9
    pieces[3][1] = replace(d, poles=poles)
    assert assemble_shell(pieces, geoms) is None


def _rounded_square_surfaces():
    t = Design.from_toml(ROOT / "samples/families/rounded_square.toml").build()
    return list(tablet_solid(t).surfaces)


def _collapsed_poles(s, row: int) -> list[int]:
    """Indices of row ``row``'s poles on the pieces where it stands still (the collapsed corners)."""
    from tabletcad.brep.slit import _standing_rows

    found = _standing_rows(s, 1e-7)[row]
    knots = np.asarray(s.v_knots)
    out = []
    for a, b, kind in found:
        if kind == "point":
            lo, hi = int(np.argmin(abs(knots - a))), int(np.argmin(abs(knots - b)))
            first, last = int(np.sum(s.v_mults[:lo])), int(np.sum(s.v_mults[:hi]))
            out += list(range(first + 1, last - s.v_degree + 1))  # the piece's interior poles
    return out


def test_assembly_refuses_chains_it_cannot_make_right():
    """Rows equal pole for pole but knots shifted, or another v degree on one patch (the same
    number of poles on a periodic v): not assembled (the solid would fail its check).  A single
    patch closed on itself (a torus-like ring of one patch): not assembled."""
    from dataclasses import replace

    surfs = _rounded_square_surfaces()
    pieces = [list(ps) for ps in chain_face_surfaces(surfs)]
    geoms = [[make_geom_surface(p) for p in ps] for ps in pieces]
    assert assemble_shell(pieces, geoms) is not None
    d = pieces[2][3]
    shifted = [list(ps) for ps in pieces]
    shifted[2][3] = replace(d, v_knots=d.v_knots + np.linspace(0.0, 1e-6, d.v_knots.size) * 0.0 + np.r_[
        0.0, np.full(d.v_knots.size - 2, 1e-6), 0.0])
    assert assemble_shell(shifted, geoms) is None
    sphere_patches = build_solid(sphere(2.5).patches, 1e-4).surfaces
    one = [(sphere_patches[0],)]
    assert assemble_shell(one, [[make_geom_surface(sphere_patches[0])]]) is None  # open, not closed in a pole
    ring_surfaces = build_solid(ring(1.5, 3.0, 2.0).patches, 1e-4).surfaces
    tube = replace(ring_surfaces[0], poles=np.concatenate([ring_surfaces[0].poles[:-1], ring_surfaces[0].poles[:1]]))
    assert assemble_shell([(tube,)], [[make_geom_surface(tube)]]) is None


@pytest.mark.parametrize("noise, cut", [(3e-8, 8), (1.5e-7, 8), (3e-7, 1)])
def test_collapsed_corners_with_round_off_are_still_cut_and_assembled(noise, cut):
    """Collapsed-corner poles a little apart (alternating ±noise mm along z): rows whose poles
    spread just beyond the point tolerance (1e-7 mm) are sampled, as before the poles decided
    (the row's curve within 1e-7 mm at ±1.5e-7: still cut at every corner; at ±3e-7 it moves,
    and the patches stay whole); a row snapped to one pole leaves its neighbours' shared cut
    edges up to the snap apart, which their tolerance covers: the solid is assembled, valid,
    with the faces' own volume."""
    from dataclasses import replace

    surfs = _rounded_square_surfaces()
    ss = list(surfs)
    for a, b in ((1, 2), (4, 5)):
        idx = _collapsed_poles(surfs[b], 0)
        assert idx
        sign = np.array([(-1.0) ** (i % 2) for i in idx])
        Pa, Pb = np.array(surfs[a].poles), np.array(surfs[b].poles)
        Pa[-1, idx, 2] += sign * noise
        Pb[0, idx, 2] += sign * noise
        ss[a], ss[b] = replace(surfs[a], poles=Pa), replace(surfs[b], poles=Pb)
    assert [len(p) for p in chain_face_surfaces(surfs)] == [8] * 7
    assert [len(p) for p in chain_face_surfaces(ss)] == [cut] * 7
    s = solid_module.solid_from_surfaces(ss, name="noisy")
    assert not s.sewn and BRepCheck_Analyzer(s.shape).IsValid()
    v = mass_properties(s.shape).volume
    assert abs(v - abs(s.data_volume_area[0])) <= 1e-9 * v


def test_a_snapped_corner_is_covered_by_its_cut_edges_tolerance():
    """Two collapsed corners' interior poles moved at random by up to 9e-7 mm (seeded): the row
    still stands within 1e-7 mm there (sampled) and is snapped to one pole, off where the
    neighbouring pieces' cut edges end; their tolerance covers it, and the solid is assembled and valid
    (with the cut edges at the 1e-7 mm default it failed its check and was sewn)."""
    from dataclasses import replace

    surfs = _rounded_square_surfaces()
    idx = _collapsed_poles(surfs[2], 0)[:4]  # two corners' interior poles
    rng = np.random.default_rng(1)
    delta = rng.standard_normal((len(idx), 3))
    delta *= 9e-7 / np.max(np.linalg.norm(delta, axis=1))
    P1, P2 = np.array(surfs[1].poles), np.array(surfs[2].poles)
    P1[-1, idx] += delta
    P2[0, idx] += delta
    ss = list(surfs)
    ss[1], ss[2] = replace(surfs[1], poles=P1), replace(surfs[2], poles=P2)
    assert [len(p) for p in chain_face_surfaces(ss)] == [8] * 7
    s = solid_module.solid_from_surfaces(ss, name="snapped")
    assert not s.sewn and BRepCheck_Analyzer(s.shape).IsValid()
    v = mass_properties(s.shape).volume
    assert abs(v - abs(s.data_volume_area[0])) <= 1e-9 * v


@pytest.mark.freecad
@pytest.mark.parametrize("fc", freecads.params())
def test_freecad_reads_an_assembled_shell_with_collapsed_corners(fc, tmp_path):
    """The rounded square's assembled shell (26 faces: the cups' and band's pieces, degenerated edges between
    the runs of the collapsed corners' rows, each flat centre's 16 pieces one plane) as STEP, read by FreeCAD 0.20 and 1.0 (their own OCCT): one valid
    closed solid, named, whose volume by OCC's default rule is ours to 1e-9."""
    from support.readback import freecad_read_step
    from tabletcad.cad.export import export

    s = tablet_solid(Design.from_toml(ROOT / "samples/families/rounded_square.toml").build())
    degenerated = [e for e in explore(s.shape, "Edge") if BRep_Tool.Degenerated_s(e)]
    assert not s.sewn and len(s.faces) == 26 and s.planes == 2 and len(degenerated) == 8
    r = freecad_read_step(export(s, tmp_path / "rounded_square.step"), freecadcmd=fc.cmd)
    assert r["n_solids"] == 1 and r["valid"] and r["solids_valid"] == [True] and r["solids_closed"] == [True]
    assert r["labels"] == [s.name]
    assert r["volume"] == pytest.approx(mass_properties(s.shape, eps=None).volume, rel=1e-9)
