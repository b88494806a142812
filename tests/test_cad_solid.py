"""Faces, sewn solids and adaptive mass properties against closed forms (OCP)."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st



pytest.importorskip("OCP")

from tabletcad.brep.surface import enclosed_volume, volume_and_area  # noqa: E402
from tabletcad.cad.faces import make_face, make_geom_surface, surface_data_from_geom  # noqa: E402
from tabletcad.cad.solid import build_solid, mass_properties, solid_from_tablet  # noqa: E402
from support.standins import cylinder, ring, sphere  # noqa: E402
from tabletcad.errors import GeometryError  # noqa: E402

pytestmark = pytest.mark.cad
TOL = 1e-4
STANDINS = [sphere(2.5), cylinder(2.5, 3.0), ring(1.5, 3.0, 2.0)]


@pytest.fixture(scope="module", params=STANDINS, ids=lambda s: s.name)
def built(request):
    s = request.param
    return s, build_solid(s.patches, TOL, name=s.name)


def test_occ_surface_is_the_kernel_neutral_surface():
    fit_surface_data = build_solid(sphere(2.5).patches).surfaces[1]
    g = make_geom_surface(fit_surface_data)
    rng = np.random.default_rng(0)
    for u, v in zip(rng.random(50), rng.random(50) * 2 * np.pi):
        p = g.Value(u, v)
        np.testing.assert_allclose([p.X(), p.Y(), p.Z()], fit_surface_data.evaluate(u, v), atol=1e-13)
    back = surface_data_from_geom(g)
    np.testing.assert_array_equal(back.poles, fit_surface_data.poles)
    np.testing.assert_array_equal(back.v_knots, fit_surface_data.v_knots)
    assert back.v_periodic


def test_valid_solid_and_closed_forms(built):
    s, ts = built
    from OCP.BRepCheck import BRepCheck_Analyzer

    assert BRepCheck_Analyzer(ts.shape).IsValid()
    assert len(ts.faces) == len(s.patches)
    assert ts.max_fit_deviation <= TOL
    # Fit-induced bound: the B-spline surface is within d = max deviation of the
    # exact surface pointwise, so |V_bspline - V| <= d * A (and |A_bspline - A|
    # is of the same order: d * total curvature-weighted area, bounded here by 4 d A / min radius).
    bound = ts.max_fit_deviation * s.area
    assert abs(ts.volume - s.volume) <= bound
    assert abs(ts.area - s.area) <= 4 * ts.max_fit_deviation * s.area
    # the adaptive integration reproduces the exact B-spline volume (Gauss, exact) to ~eps
    exact_bs = abs(enclosed_volume(ts.surfaces))
    assert abs(ts.volume - exact_bs) <= 1e-8 * exact_bs
    # and is no worse than the default integration
    default = mass_properties(ts.shape, eps=None).volume
    assert abs(ts.volume - exact_bs) <= abs(default - exact_bs)
    assert ts.volume > 0
    # the Gauss rule on the faces' data (what the build's cross-check uses) against OCC's adaptive
    # integration, which converges to it: ~1e-9 apart at eps = 1e-9, ~1e-15 at eps = 1e-12
    v, a = volume_and_area(ts.surfaces)
    assert abs(abs(v) - exact_bs) <= 1e-13 * exact_bs
    assert abs(a - ts.area) <= 3e-9 * ts.area
    assert abs(a - mass_properties(ts.shape, eps=1e-12).area) <= 1e-12 * a


def test_centroid_of_sphere_at_centre():
    ts = build_solid(sphere(1.7, centre=(1.0, -2.0, 0.5)).patches)
    np.testing.assert_allclose(ts.mass.centroid, (1.0, -2.0, 0.5), atol=1e-6)


def test_gap_between_patches_is_rejected():
    top = sphere(2.5).patches[0]
    bottom = sphere(2.5 + 1e-3).patches[1]  # 1 micrometre gap on the equator
    with pytest.raises(GeometryError, match="patch 0.*patch 1|do not share"):
        build_solid([top, bottom])


def test_open_chain_is_rejected_by_sewing():
    from tabletcad.brep.fit import fit_surface
    from tabletcad.cad.solid import solid_from_surfaces

    s = cylinder(2.5, 3.0)
    surfaces = [fit_surface(p).surface for p in s.patches[:2]]  # top disc missing
    with pytest.raises(GeometryError, match="free"):
        solid_from_surfaces(surfaces, names=["bottom", "band"])


def test_tablet_like_object_with_patches_attribute():
    class FakeTablet:
        name = "fake"
        patches = sphere(2.0).patches

    ts = solid_from_tablet(FakeTablet())
    assert ts.name == "fake" and ts.volume > 0
    assert ts.patch_names[0].startswith("patch 0")


def test_face_of_degenerate_row_is_valid():
    from tabletcad.brep.fit import fit_surface
    from tabletcad.cad._occ import explore
    from OCP.BRep import BRep_Tool

    face = make_face(fit_surface(sphere(2.5).patches[0]).surface)
    degenerated = [e for e in explore(face, "Edge") if BRep_Tool.Degenerated_s(e)]
    assert len(degenerated) == 1


@settings(max_examples=8, deadline=None)
@given(kind=st.sampled_from(["sphere", "cylinder"]), r=st.floats(0.5, 8.0), h=st.floats(0.5, 8.0))
def test_random_sizes(kind, r, h):
    s = sphere(r) if kind == "sphere" else cylinder(r, h)
    ts = build_solid(s.patches, TOL)
    assert abs(ts.volume - s.volume) <= ts.max_fit_deviation * s.area
    assert math.isclose(ts.area, s.area, rel_tol=1e-4)


@pytest.mark.parametrize("turn", [None, 0, 1])
def test_solid_is_outward_whichever_way_its_faces_come(turn, monkeypatch):
    """The solid is turned outward by the sign of its faces' own Gauss-Legendre volume when
    sewing kept every face as made (no point classification), and by OCC's classification
    (``BRepLib::OrientClosedSolid``) when a face comes turned: the cylinder's faces enclose a
    negative volume as parametrised, and OCC's volume of the result is positive and equals the
    closed form (to the fit's deviation times the area) either way."""
    import tabletcad.cad.solid as solid_module
    from tabletcad.cad._occ import cast

    calls, orient = [], solid_module.BRepLib.OrientClosedSolid_s

    class Spy:
        @staticmethod
        def OrientClosedSolid_s(shape):
            calls.append(shape)
            return orient(shape)

    ts = build_solid(cylinder(radius=2.0, height=3.0).patches)
    faces = tuple(cast(f.Reversed(), "Face") if k == turn else f for k, f in enumerate(ts.faces))
    monkeypatch.setattr(solid_module, "BRepLib", Spy)
    s = solid_module._solid_from_faces(faces, [f"f{k}" for k in range(len(faces))], ts.surfaces, ts.patch_names,
                                       ts.fits, ts.sew_tolerance, 1e-9, "cylinder", 0.0)
    # the first face leads the sewing: turned, the shell comes turned against the data (classified);
    # a later face turned is turned back by the sewing (the data's sign serves)
    assert len(calls) == (1 if turn == 0 else 0)
    assert s.data_volume_area[0] < 0.0  # the data's own sign: the solid had to be turned
    v = mass_properties(s.shape, 1e-9).volume
    assert v > 0.0 and abs(v + s.data_volume_area[0]) <= 1e-8 * v  # the faces' own volume, outward
    area = 2 * math.pi * 2.0 * 2.0 + 2 * math.pi * 2.0 * 3.0
    assert abs(v - math.pi * 4.0 * 3.0) <= ts.max_fit_deviation * area  # the closed form, to the fit


def test_a_solid_that_fails_its_check_names_the_invalid_face(monkeypatch):
    """Faces are checked once, as part of the solid; when that check fails (for the assembled
    shell, then for the sewn one), each face is checked on its own and the first invalid one is named (spied: OCC makes valid faces of
    every B-spline it accepts)."""
    import tabletcad.cad.solid as solid_module

    def fail(*args, **kwargs):
        raise GeometryError("solid fails BRepCheck_Analyzer")

    class Analyzer:
        def __init__(self, face):
            self.face = face

        def IsValid(self):
            return not self.face.IsSame(made[1])

    made = []
    real_face_of = solid_module.face_of
    monkeypatch.setattr(solid_module, "face_of", lambda *a, **k: made.append(real_face_of(*a, **k)) or made[-1])
    monkeypatch.setattr(solid_module, "_solid_from_faces", fail)
    monkeypatch.setattr(solid_module, "BRepCheck_Analyzer", Analyzer)
    with pytest.raises(GeometryError, match=r"^face of patch 1 is not valid"):
        build_solid(cylinder(2.0, 3.0).patches, 1e-4, names=["patch 0", "patch 1", "patch 2"])


def test_explore_gives_each_sub_shape_once_as_the_explorer_first_meets_it():
    """``explore`` (``TopExp::MapShapes``) lists what a walk with ``TopExp_Explorer`` keeping the first of
    each ``IsSame`` group lists: the same shapes, in the same order, with the same orientations."""
    from OCP.TopExp import TopExp_Explorer

    from tabletcad.cad._occ import _KINDS, cast, explore

    shape = build_solid(ring(1.5, 3.0, 2.0).patches, TOL).shape
    for kind in ("Vertex", "Edge", "Wire", "Face", "Shell", "Solid"):
        walk, it = [], TopExp_Explorer(shape, _KINDS[kind])
        while it.More():
            if not any(it.Current().IsSame(o) for o in walk):
                walk.append(it.Current())
            it.Next()
        got = explore(shape, kind)
        assert len(got) == len(walk) > 0
        assert all(a.IsEqual(b) and type(a) is type(cast(b, kind)) for a, b in zip(got, walk))


def test_mass_properties_are_integrated_once_per_shape_content():
    """:func:`mass_properties` is memoised by shape content: a box made again (a new ``TShape``) is
    not integrated again and gives the same result; a moved, a reversed or a 1-ulp taller box is
    another content, integrated on its own (its centroid moved, its volume negated or larger)."""
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
    from OCP.gp import gp_Trsf, gp_Vec
    from OCP.TopLoc import TopLoc_Location

    from tabletcad.cad.solid import MASS_MEMO

    MASS_MEMO.clear()
    first = mass_properties(BRepPrimAPI_MakeBox(1.0, 2.0, 3.0).Shape())
    hits, misses = MASS_MEMO.hits, MASS_MEMO.misses
    again = mass_properties(BRepPrimAPI_MakeBox(1.0, 2.0, 3.0).Shape())
    assert again is first and (MASS_MEMO.hits, MASS_MEMO.misses) == (hits + 1, misses)
    box = BRepPrimAPI_MakeBox(1.0, 2.0, 3.0).Shape()
    shift = gp_Trsf()
    shift.SetTranslation(gp_Vec(10.0, 0.0, 0.0))
    moved = mass_properties(box.Moved(TopLoc_Location(shift)))
    assert moved.centroid == pytest.approx((10.5, 1.0, 1.5), abs=1e-12) and moved.volume == pytest.approx(6.0)
    assert mass_properties(box.Reversed()).volume == pytest.approx(-6.0)
    taller = mass_properties(BRepPrimAPI_MakeBox(1.0, 2.0, math.nextafter(3.0, 4.0)).Shape())
    assert MASS_MEMO.misses == misses + 3 and taller is not first and taller.volume == pytest.approx(6.0)
