"""The CAD layer on real tablets: every sample design (except cut-away views) as an exact solid.

For each sample: the B-spline faces against the PDE surfaces on a grid far denser
than the fit grid; ``BRepCheck_Analyzer`` and one solid; volume/area of the core's
quadrature vs OCC's adaptive integration vs the exact B-spline volume vs the
manifold3d mesh; genus; the STEP text (millimetres, product name); STEP read back in
a fresh OCP process and by FreeCAD's own reader.  Then random designs (hypothesis),
breakpoint knots (stadium, rounded rectangle, point curve), failures (fit that
cannot meet its tolerance: GeometryError, ``tabletcad build`` exits 2 and writes
nothing), ``tabletcad build`` end to end, and the build123d / cadquery wrappers.

With the environment variable ``CI`` set, a missing library or ``freecadcmd`` fails
instead of skipping.
"""

from __future__ import annotations

import functools
import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest




pytest.importorskip("OCP")
pytest.importorskip("manifold3d")
pytest.importorskip("trimesh")
pytest.importorskip("hypothesis")

from hypothesis import given, settings
from hypothesis import strategies as st

from tabletcad.brep.fit import _eval_f
from tabletcad.brep.knots import periodic_knots
from tabletcad.brep.surface import enclosed_volume
from tabletcad.cad._occ import explore, shape_type
from tabletcad.cad.export import export
from tabletcad.brep.revolved import RevolvedSurfaceData
from tabletcad.cad.mesh import tessellate, tessellate_solid
from support.readback import find_freecadcmd, freecad_build_bspline, freecad_read_steps, ocp_read_steps
from tabletcad.cad.solid import mass_properties
from tabletcad.cad.stage import MESH_ANGULAR_RAD, MESH_LINEAR_MM
from tabletcad.brep.surfaces import tablet_breakpoints, tablet_surface_functions
from tabletcad.cad.tablet_solid import tablet_solid
from tabletcad.pipeline.design import design_from_dict, load_design
from tabletcad.errors import GeometryError

pytestmark = pytest.mark.cad

ROOT = Path(__file__).resolve().parents[1]
SAMPLES = sorted(p for p in (ROOT / "samples").glob("*.toml") if not p.stem.startswith("cutaway"))
AGREE = 1e-6  # B-rep (adaptive OCC) vs quadrature, relative
DENSE = 7  # dense check grid: this many points per fit-sample interval in u and v (not a divisor of 4)


def _is_cutaway(t) -> bool:
    return t.trim.u != (0.0, 1.0) or not t.trim.full_v


@functools.cache
def _built(path: str, revolved: bool | None = None):
    t = load_design(path)
    s = tablet_solid(t, revolved=revolved)
    m = tessellate_solid(s, MESH_LINEAR_MM, MESH_ANGULAR_RAD)
    return t, s, m, t.volume(), t.surface_area()


def _is_revolved(s) -> bool:
    return all(isinstance(sd, RevolvedSurfaceData) for sd in s.surfaces)


# every sample as built (tablets of revolution get faces of revolution), plus two tablets of
# revolution forced onto B-spline faces so that path keeps its checks on round shapes too
BSPLINE_ROUND = ("flat_faced_round", "ring")
CASES = [(p, None) for p in SAMPLES] + [(p, False) for p in SAMPLES if p.stem in BSPLINE_ROUND]


@pytest.fixture(scope="module", params=CASES, ids=lambda c: c[0].stem + ("-bspline" if c[1] is False else ""))
def sample(request):
    return _built(str(request.param[0]), request.param[1])


@pytest.fixture(scope="module")
def step_files(tmp_path_factory):
    """Every sample written as STEP once (path per sample stem)."""
    d = tmp_path_factory.mktemp("step")
    out = {}
    for p, revolved in CASES:
        t, s, *_ = _built(str(p), revolved)
        out[(p.stem, revolved)] = export(s, d / f"{p.stem}{'-bspline' if revolved is False else ''}.step", name=t.name)
    return out


def test_samples_are_found():
    assert len(SAMPLES) >= 10
    assert not any(_is_cutaway(_built(str(p))[0]) for p in SAMPLES)
    # tablets of revolution get faces of revolution; the others (stadium, ovals) B-spline faces
    kinds = {p.stem: _is_revolved(_built(str(p))[1]) for p in SAMPLES}
    assert kinds["flat_faced_round"] and kinds["spherical"] and kinds["ring"]
    assert not kinds["free_form_stadium"] and not kinds["deep_convex_oval"]


# --------------------------------------------------------------------------- per sample


def test_fit_deviation_on_dense_grid(sample):
    t, s, *_ = sample
    funcs, names = tablet_surface_functions(t)
    assert len(funcs) == len(s.surfaces)
    if _is_revolved(s):
        for f, surf, fit, name in zip(funcs, s.surfaces, s.fits, names):
            # the PDE surface at dense u and at 97 v (all meridians), against the face of
            # revolution at the same u and the point's own plan angle: both the profile fit and
            # the exactness of the revolution (no fit in the angle) are measured
            u = np.linspace(0.0, 1.0, DENSE * (fit.u_samples.size - 1) + 1)
            v = np.linspace(0.0, 2 * math.pi, 97)
            X = _eval_f(f, u, v)
            th = np.arctan2(X[..., 1], X[..., 0])
            R, Z = np.moveaxis(surf.profile(np.repeat(u[:, None], v.size, axis=1)), -1, 0)
            S = np.stack([R * np.cos(th), R * np.sin(th), Z], axis=-1)
            err = np.linalg.norm(S - X, axis=-1)
            assert err.max() <= 1e-4, f"{name}: {err.max():.3g} mm on {err.size} points"
            assert err.max() <= 2.0 * max(fit.max_deviation, 1e-12), (name, err.max(), fit.max_deviation)
        return
    for f, surf, fit, name in zip(funcs, s.surfaces, s.fits, names):
        u, v = fit.u_samples, fit.v_samples
        # DENSE points per sample interval (includes points off every fit and check line)
        uc = np.linspace(0.0, 1.0, DENSE * (u.size - 1) + 1)
        vs = np.concatenate([v, [v[0] + 2 * math.pi]])
        vc = (vs[:-1, None] + (np.arange(DENSE) / DENSE)[None, :] * np.diff(vs)[:, None]).ravel()
        err = np.linalg.norm(surf.evaluate_grid(uc, vc) - _eval_f(f, uc, vc), axis=-1)
        assert err.max() <= 1e-4, f"{name}: {err.max():.3g} mm on {err.size} points"
        assert err.max() <= 2.0 * max(fit.max_deviation, 1e-7), (name, err.max(), fit.max_deviation)


def test_single_valid_solid(sample):
    from OCP.BRepCheck import BRepCheck_Analyzer

    t, s, *_ = sample
    assert shape_type(s.shape) == "Solid"
    assert BRepCheck_Analyzer(s.shape).IsValid()
    assert len(explore(s.shape, "Solid")) == 1 and len(explore(s.shape, "Shell")) == 1
    assert len(explore(s.shape, "Face")) == (4 if t.trim.w[0] > 0 else len(t.patches))


def test_volume_area_agreement(sample):
    _t, s, _m, V, A = sample
    assert s.volume == pytest.approx(V, rel=AGREE)
    assert s.area == pytest.approx(A, rel=AGREE)
    # the exact volume of the B-spline faces (Gauss on polynomial spans) vs OCC's integration
    # (adaptive on B-spline faces; default on faces of revolution, where it is exact to ~1e-11)
    assert abs(enclosed_volume(s.surfaces)) == pytest.approx(s.volume, rel=1e-9 if _is_revolved(s) else 1e-7)
    # fitted faces vs PDE surfaces: |dV| <= max deviation x area
    assert abs(s.volume - V) <= s.volume_fit_bound + AGREE * V


def test_mesh_checks_and_volume_bound(sample):
    t, s, m, _V, _A = sample
    assert m.ok and m.is_manifold and m.watertight and m.winding_consistent
    assert m.manifold_genus == (1 if t.trim.w[0] > 0 else 0)
    # a chordal mesh with deflection d lies within d of the B-rep: |dV| <= d x area
    # (+ float32 vertices in manifold3d: ~1e-7 relative per coordinate)
    bound = MESH_LINEAR_MM * s.area + 1e-6 * s.volume
    assert abs(m.manifold_volume - s.volume) <= bound, (m.manifold_volume, s.volume, bound)
    assert abs(m.volume - s.volume) <= MESH_LINEAR_MM * s.area
    assert m.area == pytest.approx(s.area, rel=0.01)


def test_step_text_units_and_product(sample, step_files):
    t = sample[0]
    text = Path(step_files[_stem_of(t)]).read_text(errors="replace")
    assert "SI_UNIT(.MILLI.,.METRE.)" in text.replace(" ", "")
    assert f"PRODUCT('{t.name}'" in text
    if _is_revolved(sample[1]):  # exact surfaces of revolution of B-spline profiles
        assert "SURFACE_OF_REVOLUTION" in text and "B_SPLINE_CURVE_WITH_KNOTS" in text
        assert "B_SPLINE_SURFACE_WITH_KNOTS" not in text
    else:
        assert "B_SPLINE_SURFACE_WITH_KNOTS" in text


def _stem_of(t) -> tuple[str, bool | None]:
    for p, revolved in CASES:
        if _built(str(p), revolved)[0] is t:
            return p.stem, revolved
    raise KeyError(t.name)


def test_step_read_back_by_ocp_in_fresh_process(step_files):
    stems = list(step_files)
    # the measures read below (the optimal bounding box, unread here, took half the reader's 3.2 CPU-s)
    results = ocp_read_steps([step_files[k] for k in stems], measure=("volume_default", "area"))
    for (stem, revolved), r in zip(stems, results):
        t, s, *_ = _built(str(ROOT / "samples" / f"{stem}.toml"), revolved)
        assert r["n_solids"] == 1 and r["valid"], (stem, r)
        assert r["n_faces"] == len(s.faces)
        assert r["products"] == [t.name]
        # STEP keeps the poles to ~15 significant digits: same solid up to round-off (measured with
        # the same integration: adaptive on B-spline faces, OCCT's default on faces of revolution)
        assert r["volume" if s.mass.eps else "volume_default"] == pytest.approx(s.volume, rel=1e-9), stem
        assert r["area"] == pytest.approx(s.area, rel=1e-9), stem


@pytest.fixture(scope="module")
def freecad_read_back(step_files):
    """Every sample's STEP file read by FreeCAD in *one* ``freecadcmd`` process (by the keys of
    ``step_files``); None without ``freecadcmd``."""
    if find_freecadcmd() is None:
        return None
    keys = list(step_files)
    return dict(zip(keys, freecad_read_steps([step_files[k] for k in keys])))


@pytest.mark.freecad
def test_step_read_back_by_freecad(sample, freecad_read_back):
    if freecad_read_back is None:
        pytest.skip("freecadcmd not installed")
    t, s, *_ = sample
    r = freecad_read_back[_stem_of(t)]
    assert r["n_solids"] == 1 and r["valid"] and r["solids_valid"] == [True] and r["solids_closed"] == [True]
    assert r["labels"] == [t.name]
    # FreeCAD's Shape.Volume is OCCT's default (non-adaptive) integration: equal to ours with eps=None
    # (FreeCAD's OCCT is an older build: allow 1e-9), within 2e-3 of the adaptive value
    default = mass_properties(s.shape, eps=None)
    assert r["volume"] == pytest.approx(default.volume, rel=1e-9)
    assert r["volume"] == pytest.approx(s.volume, rel=2e-3)
    assert r["area"] == pytest.approx(s.area, rel=2e-3)


# --------------------------------------------------------------------------- breakpoints


def test_stadium_uses_breakpoint_knots():
    t, s, *_ = _built(str(ROOT / "samples" / "free_form_stadium.toml"))
    br = tablet_breakpoints(t)
    assert br.size >= 4
    for surf in s.surfaces:
        # full-multiplicity knots (C0-capable) at every breakpoint, the same knots on every face
        mult_at = {round(float(k), 12): int(mm) for k, mm in zip(surf.v_knots, surf.v_mults)}
        assert all(mult_at.get(round(float(b), 12)) == surf.v_degree for b in br)
        np.testing.assert_array_equal(surf.v_knots, s.surfaces[0].v_knots)
        assert surf.shape[1] < 100  # 512 uniform poles did not reach 1e-4 mm before
    assert s.max_fit_deviation <= 1e-4


def test_stadium_fits_1e5_with_modest_poles():
    t, *_, V, A = _built(str(ROOT / "samples" / "free_form_stadium.toml"))
    s = tablet_solid(t, tol=1e-5)
    assert s.max_fit_deviation <= 1e-5
    assert max(surf.shape[1] for surf in s.surfaces) <= 160
    assert s.volume == pytest.approx(V, rel=1e-7)
    assert s.area == pytest.approx(A, rel=AGREE)


ROUNDED_RECT = """
[tablet]
family = "free_form"
name = "rounded_rect"
a = "auto"
[[patch]]
curves = [
  { type = "circle", radius = 0.0, z = 0.0 },
  { type = "rounded_rectangle", length = 4.0, width = 2.8, corner_radius = 0.6, z = 0.0 },
  { type = "rounded_rectangle", length = 8.0, width = 5.6, corner_radius = 1.2, z = 0.0 },
  { type = "rounded_rectangle", length = 10.0, width = 7.0, corner_radius = 1.5, z = 0.0 },
]
[[patch]]
curves = [
  "previous",
  { type = "rounded_rectangle", length = 10.0, width = 7.0, corner_radius = 1.5, z = 1.0 },
  { type = "rounded_rectangle", length = 10.0, width = 7.0, corner_radius = 1.5, z = 2.0 },
  { type = "rounded_rectangle", length = 10.0, width = 7.0, corner_radius = 1.5, z = 3.0 },
]
[[patch]]
curves = [
  "previous",
  { type = "rounded_rectangle", length = 8.0, width = 5.6, corner_radius = 1.2, z = 3.0 },
  { type = "rounded_rectangle", length = 4.0, width = 2.8, corner_radius = 0.6, z = 3.0 },
  { type = "circle", radius = 0.0, z = 3.0 },
]
"""

_P1 = "[[2,0],[1.5,1],[0,1.3],[-1.5,1],[-2,0],[-1.5,-1],[0,-1.3],[1.5,-1]]"
_P2 = "[[4,0],[3,2],[0,2.6],[-3,2],[-4,0],[-3,-2],[0,-2.6],[3,-2]]"
_P3 = "[[5,0],[4,2.5],[0,3.2],[-4,2.5],[-5,0],[-4,-2.5],[0,-3.2],[4,-2.5]]"
POINT_CURVE = f"""
[tablet]
family = "free_form"
name = "point_curve"
a = "auto"
[[patch]]
curves = [
  {{ type = "circle", radius = 0.0, z = 0.0 }},
  {{ type = "points", points = {_P1}, z = 0.0 }},
  {{ type = "points", points = {_P2}, z = 0.0 }},
  {{ type = "points", points = {_P3}, z = 0.0 }},
]
[[patch]]
curves = [
  "previous",
  {{ type = "points", points = {_P3}, z = 1.0 }},
  {{ type = "points", points = {_P3}, z = 2.0 }},
  {{ type = "points", points = {_P3}, z = 3.0 }},
]
[[patch]]
curves = [
  "previous",
  {{ type = "points", points = {_P2}, z = 3.0 }},
  {{ type = "points", points = {_P1}, z = 3.0 }},
  {{ type = "circle", radius = 0.0, z = 3.0 }},
]
"""


@functools.cache
def _free_form(text: str):
    import tomllib

    return design_from_dict(tomllib.loads(text))


@pytest.mark.parametrize("text", [ROUNDED_RECT, POINT_CURVE], ids=["rounded_rectangle", "point_curve"])
def test_breakpoint_designs(text):
    t = _free_form(text)
    assert tablet_breakpoints(t).size >= 8
    s = tablet_solid(t, tol=1e-5)
    assert s.max_fit_deviation <= 1e-5
    assert max(surf.shape[1] for surf in s.surfaces) <= 200
    assert s.volume == pytest.approx(t.volume(), rel=AGREE)
    assert s.area == pytest.approx(t.surface_area(), rel=AGREE)
    # uniform knots need far more poles for the same tolerance (or miss it at 512)
    try:
        u = tablet_solid(t, tol=1e-5, v_breaks=[])
        assert u.surfaces[0].shape[1] > 1.5 * s.surfaces[0].shape[1]
    except GeometryError as exc:
        assert "misses tolerance" in str(exc)


@pytest.mark.freecad
def test_periodic_breakpoint_knots_accepted_by_freecad():
    """FreeCAD's buildFromPolesMultsKnots (its own OCCT) reads multiplicity-(p-1) periodic knots
    exactly as we do, and sews the stadium's faces into a valid solid."""
    if find_freecadcmd() is None:
        pytest.skip("freecadcmd not installed")
    _t, s, *_ = _built(str(ROOT / "samples" / "free_form_stadium.toml"))
    rng = np.random.default_rng(5)
    u, v = rng.random(30), rng.random(30) * 2 * math.pi
    r = freecad_build_bspline(s.surfaces, u, v)
    for k, surf in enumerate(s.surfaces):
        np.testing.assert_allclose(np.array(r["values"][k]), surf.evaluate(u, v), atol=1e-12)
        assert r["readback"][k]["v_mults"] == surf.v_mults.tolist()
    assert all(r["faces_valid"]) and r["n_shells"] == 1 and r["shell_closed"] and r["valid"]
    assert r["volume"] == pytest.approx(s.volume, rel=2e-3)


def test_periodic_knots_match_occt():
    """Random poles on breakpoint knot vectors evaluate identically in numpy and OCCT."""
    from tabletcad.brep.surface import BSplineSurfaceData
    from tabletcad.cad.faces import make_geom_surface

    rng = np.random.default_rng(2)
    for breaks in ([0.0, 1.0, 2.5, 4.0], [0.3, 3.0], [5.9]):
        for deg in (3, 5):
            for bm in (deg - 1, deg):
                k, mm, samples = periodic_knots(10, deg, breaks, bm)
                n = int(mm[:-1].sum())
                assert samples.size == n
                d = BSplineSurfaceData(rng.normal(size=(deg + 1, n, 3)), [0.0, 1.0], [deg + 1, deg + 1], k, mm, deg, deg)
                g = make_geom_surface(d)
                uu, vv = rng.random(20), rng.random(20) * 2 * math.pi
                occ = np.array([g.Value(a, b).Coord() for a, b in zip(uu, vv)])
                np.testing.assert_allclose(d.evaluate(uu, vv), occ, atol=1e-12)


# --------------------------------------------------------------------------- random designs




def _check_random(t, genus: int) -> None:
    s = tablet_solid(t)
    assert s.max_fit_deviation <= t.tol.fit
    assert s.volume == pytest.approx(t.volume(), rel=AGREE)
    assert s.area == pytest.approx(t.surface_area(), rel=AGREE)
    m = tessellate(s.shape, 0.01, 0.3)
    assert m.ok and m.manifold_genus == genus
    assert abs(m.manifold_volume - s.volume) <= 0.01 * s.area + 1e-6 * s.volume


@settings(max_examples=4, deadline=None)
@given(D=st.floats(5.0, 12.0), T=st.floats(2.0, 5.0), frac=st.floats(0.4, 0.9))
def test_random_shallow_convex_round(D, T, frac):
    from tabletcad.families import FAMILIES

    _check_random(FAMILIES["thesis.shallow_convex_round"].build(diameter=D, thickness=T, band=frac * T), 0)


@settings(max_examples=3, deadline=None)
@given(D=st.floats(2.0, 12.0))
def test_random_spherical(D):
    from tabletcad.families import FAMILIES

    _check_random(FAMILIES["thesis.spherical"].build(diameter=D), 0)


@settings(max_examples=3, deadline=None)
@given(OD=st.floats(6.0, 14.0), frac=st.floats(0.2, 0.7), T=st.floats(1.5, 6.0))
def test_random_ring(OD, frac, T):
    from tabletcad.families import FAMILIES

    _check_random(FAMILIES["thesis.ring"].build(outer_diameter=OD, inner_diameter=frac * OD, thickness=T), 1)


# --------------------------------------------------------------------------- failures


def test_unreachable_tolerance_names_patch_and_deviation():
    t = load_design(ROOT / "samples" / "free_form_stadium.toml")
    with pytest.raises(GeometryError) as exc:
        tablet_solid(t, tol=1e-12, max_nu=24, max_nv=48, max_iterations=3)
    msg = str(exc.value)
    assert "misses tolerance" in msg and "max deviation" in msg
    assert t.patches[0].name in msg or "free_form_stadium" in msg


def test_build_exits_2_and_writes_nothing_when_the_fit_fails(tmp_path, monkeypatch, capsys):
    import tabletcad.cad.tablet_solid as ts
    from tabletcad.cli import main

    original = ts.tablet_solid
    monkeypatch.setattr(ts, "tablet_solid",
                        lambda tablet, tol=None, **kw: original(tablet, tol=1e-13, max_nv=40, max_iterations=2))
    out = tmp_path / "out"
    rc = main(["build", str(ROOT / "samples" / "spherical.toml"), "--out", str(out), "--quiet"])
    assert rc == 2
    err = capsys.readouterr().err
    assert "error:" in err and "misses tolerance" in err
    assert not out.exists() or not any(out.iterdir())
    assert not any(p.name.startswith(".out.") for p in tmp_path.iterdir())  # no staging folder left


def test_a_fit_within_tolerance_that_moves_the_volume_is_fitted_again(monkeypatch):
    """The thesis sphere at ``a = 5``: its first fit, 3.8e-5 mm from the PDE surface (within the 1e-4 mm
    tolerance), moves the volume by 1.6e-6 relative, more than the stage's agreement; the stage fits the
    faces again at a tenth of the tolerance and they agree (1.5e-7)."""
    import tabletcad.cad.stage as stage

    t = design_from_dict({"tablet": {"family": "thesis.spherical", "diameter": 5.0, "a": 5.0}}, "sphere_a5")
    first = tablet_solid(t)
    assert abs(abs(first.data_volume_area[0]) - t.volume()) > AGREE * t.volume()  # the case: a first fit that misses
    assert max(f.max_deviation for f in first.fits) <= t.tol.fit
    solid, _mesh, sections = stage.check_tablet_solid(t)
    b = sections["brep"]
    assert b["fit_tolerance_mm"] == pytest.approx(t.tol.fit / 10, rel=1e-12)
    assert b["fit_max_deviation_mm"] <= b["fit_tolerance_mm"]
    assert b["volume_mm3"] == pytest.approx(t.volume(), rel=AGREE)
    assert b["surface_area_mm2"] == pytest.approx(t.surface_area(), rel=AGREE)
    assert b["volume_mm3"] == abs(solid.data_volume_area[0])  # the solid handed on is the one that agrees
    # without the second fit the stage refuses it, saying at which fit tolerance
    monkeypatch.setattr(stage, "REFITS", 0)
    with pytest.raises(GeometryError, match=r"sphere_a5: B-rep volume/area differ .* at a fit tolerance of 1e-04 mm"):
        stage.check_tablet_solid(t)
    # a finer fit that cannot be made (too many poles, say) ends the refits: the miss is what is reported
    import tabletcad.cad.tablet_solid as ts

    monkeypatch.setattr(stage, "REFITS", 2)
    original = ts.tablet_solid

    def coarse_only(tablet, tol=None, **kw):
        if tol is not None and tol < t.tol.fit:
            raise GeometryError("B-spline fit of patch 0 misses tolerance", tablet)
        return original(tablet, tol, **kw)

    monkeypatch.setattr(ts, "tablet_solid", coarse_only)
    with pytest.raises(GeometryError, match=r"sphere_a5: B-rep volume/area differ .* at a fit tolerance of 1e-04 mm"):
        stage.check_tablet_solid(t)


def test_a_cut_away_whose_volume_misses_is_fitted_again():
    """The same sphere at ``a = 5`` cut in half (the whole solid in common with a wedge): fitted again as the
    whole tablet is (it had been refused, -1.56e-6 relative), its volume the quadrature's over the half."""
    import tabletcad.cad.stage as stage

    t = design_from_dict({"tablet": {"family": "thesis.spherical", "diameter": 5.0, "a": 5.0},
                          "trim": {"v": [0.0, math.pi]}}, "sphere_a5_half")
    made = stage.cutaway_shape(t, {"volume_mm3": t.volume()})
    assert made.fit_tolerance_mm == pytest.approx(t.tol.fit / 10, rel=1e-12)
    assert made.volume_mm3 == pytest.approx(t.volume(), rel=AGREE)
    assert abs(made.volume_rel_diff_vs_quadrature) <= AGREE


# --------------------------------------------------------------------------- end to end


def test_tabletcad_build_end_to_end(tmp_path):
    exe = Path(sys.executable).with_name("tabletcad")
    cmd = [str(exe)] if exe.exists() else [sys.executable, "-m", "tabletcad"]
    out = tmp_path / "spherical"
    proc = subprocess.run(
        [*cmd, "build", str(ROOT / "samples" / "spherical.toml"), "--out", str(out)],
        capture_output=True, text=True, timeout=300, check=False, env={**os.environ, "TABLETCAD_REQUIRE_CAD": "1"},
    )
    assert proc.returncode == 0, proc.stderr
    for name in ("tablet.step", "tablet.stl", "tablet.glb", "report.json"):
        assert (out / name).is_file() and (out / name).stat().st_size > 0, name
    rep = json.loads((out / "report.json").read_text())
    b, m = rep["brep"], rep["mesh"]
    assert b["valid"] is True and b["fit_max_deviation_mm"] <= 1e-4
    assert b["volume_mm3"] == pytest.approx(rep["volume_mm3"], rel=AGREE)
    assert b["surface_area_mm2"] == pytest.approx(rep["surface_area_mm2"], rel=AGREE)
    assert m["manifold"] is True and m["watertight"] is True and m["genus"] == 0 and m["triangles"] > 1000
    assert abs(m["volume_mm3"] - b["volume_mm3"]) <= MESH_LINEAR_MM * b["surface_area_mm2"]
    # the PDE surface stands for a 5 mm sphere (within its nominal deviation, ~0.4 % in volume)
    assert b["volume_mm3"] == pytest.approx(math.pi * 5.0**3 / 6.0, rel=1e-2)


# --------------------------------------------------------------------------- interop


def test_build123d_part_wraps_tablet_solid():
    bd = pytest.importorskip("build123d")
    from tabletcad.cad.interop import to_build123d, to_build123d_part

    _t, s, *_ = _built(str(ROOT / "samples" / "ring.toml"))
    part = to_build123d_part(s)
    assert isinstance(part, bd.Part)
    assert part.volume == pytest.approx(s.volume, rel=1e-6)
    solid = to_build123d(s)
    assert solid.wrapped.IsSame(s.shape) and solid.is_valid
    half = part - bd.Pos(50, 0, 0) * bd.Box(100, 100, 100)  # boolean on the B-spline solid
    assert half.is_valid and half.volume == pytest.approx(s.volume / 2, rel=1e-6)


def test_cadquery_wraps_tablet_solid():
    try:
        import cadquery as cq  # noqa: F401
    except Exception as exc:  # noqa: BLE001 - ImportError or an OCP mismatch inside cadquery
        pytest.skip(f"cadquery not importable with this OCP ({exc}); the CI venv installs cadquery 2.8 on OCP 7.9")
    from tabletcad.cad.interop import to_cadquery, to_cadquery_workplane

    _t, s, *_ = _built(str(ROOT / "samples" / "shallow_convex_round.toml"))
    solid = to_cadquery(s)
    assert solid.isValid() and solid.Volume() == pytest.approx(s.volume, rel=1e-6)
    wp = to_cadquery_workplane(s)
    assert wp.val().Volume() == pytest.approx(s.volume, rel=1e-6)


@pytest.mark.parametrize("tablet", [
    dict(family="ffre", diameter=10.0, thickness=3.0, edge_radius=1.5),  # no band: the pill
    dict(family="ffre", diameter=10.0, thickness=3.001, edge_radius=1.5),  # the least band
    dict(family="ffbe", diameter=10.0, thickness=2.001, bevel_angle=45, bevel_width=1.0),
    dict(family="ffbe", diameter=10.0, thickness=4.0, bevel_angle=10, bevel_width=4.999),  # the least flat face
])
def test_what_a_design_file_leaves_at_the_least_length_builds_a_solid(tablet):
    """The other side of ``test_left_lengths.py``: a band or face of 0 or the least length builds one
    valid solid whose volume is the core's (a band of 1e-9 mm had failed the sewing)."""
    from OCP.BRepCheck import BRepCheck_Analyzer

    t = design_from_dict({"tablet": tablet})
    s = tablet_solid(t)
    assert shape_type(s.shape) == "Solid" and BRepCheck_Analyzer(s.shape).IsValid()
    assert len(explore(s.shape, "Face")) == len(t.patches)
    assert s.volume == pytest.approx(t.volume(), rel=AGREE)
