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
                                    "caplet", "ring", "free_form_stadium"])
def test_assembled_shell_is_the_sewn_one(sample, monkeypatch):
    """Cut chains (collapsed corners: degenerated edges between runs), periodic chains (seams)
    and a chain closed on itself (the ring) are assembled, not sewn: a valid closed solid with the
    sewn solid's faces, every edge but the degenerated ones shared by exactly two faces, and
    OCC's volume and area equal to the sewn solid's and to the faces' own Gauss-Legendre volume."""
    tablet = Design.from_toml(ROOT / "samples" / f"{sample}.toml").build()
    made = tablet_solid(tablet, revolved=False)
    sewn = _sewn(monkeypatch, lambda: tablet_solid(tablet, revolved=False))
    assert not made.sewn and sewn.sewn
    assert BRepCheck_Analyzer(made.shape).IsValid()
    shells = explore(made.shape, "Shell")
    assert len(shells) == 1 and BRep_Tool.IsClosed_s(shells[0])
    edges = _edge_faces(made.shape)
    assert all(n == 2 for deg, n in edges if not deg)
    assert all(n == 1 for deg, n in edges if deg)
    assert len(made.faces) == len(sewn.faces)
    m, ms = mass_properties(made.shape), mass_properties(sewn.shape)
    data_volume, data_area = made.data_volume_area
    assert abs(m.volume - ms.volume) <= 1e-10 * ms.volume
    assert abs(m.area - ms.area) <= 1e-10 * ms.area
    assert abs(m.volume - abs(data_volume)) <= 1e-9 * m.volume
    assert abs(m.area - data_area) <= 1e-9 * m.area


@pytest.mark.parametrize("standin", [sphere(2.5), cylinder(2.5, 3.0), ring(1.5, 3.0, 2.0)], ids=lambda s: s.name)
def test_standins_are_assembled_to_their_closed_forms(standin):
    """The sphere (two poles), cylinder (flat ends) and ring (a chain closed on itself): assembled,
    valid, and OCC's volume within the fit's bound of the closed form."""
    s = build_solid(standin.patches, 1e-4, name=standin.name)
    assert not s.sewn and BRepCheck_Analyzer(s.shape).IsValid()
    assert abs(s.volume - standin.volume) <= s.max_fit_deviation * standin.area


def test_a_slit_or_mismatched_chain_is_left_to_sewing():
    """The capsule's innermost cup ends on a segment run there and back (an open end that is not a
    pole): not assembled, and the build sews it.  A chain whose neighbours' rows differ by one
    pole is not assembled either."""
    capsule = Design.from_toml(ROOT / "samples/families/capsule.toml").build()
    s = tablet_solid(capsule)
    assert s.sewn and BRepCheck_Analyzer(s.shape).IsValid()
    pieces = chain_face_surfaces(s.surfaces)
    assert assemble_shell(pieces, [[make_geom_surface(p) for p in ps] for ps in pieces]) is None

    oval = tablet_solid(Design.from_toml(ROOT / "samples/families/oval.toml").build())
    pieces = [list(ps) for ps in chain_face_surfaces(oval.surfaces)]
    geoms = [[make_geom_surface(p) for p in ps] for ps in pieces]
    assert assemble_shell(pieces, geoms) is not None
    d = pieces[3][1]
    poles = np.array(d.poles)
    poles[0, 2] += 1e-9
    from dataclasses import replace

    pieces[3][1] = replace(d, poles=poles)
    assert assemble_shell(pieces, geoms) is None
