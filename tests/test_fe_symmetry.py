"""Mirror symmetry in FE: a quarter of the body solved with symmetry planes and unfolded must give the
whole body's solution (closed forms on a box; the full model and Hondros on a thin disc)."""

from __future__ import annotations

import numpy as np
import pytest

pytestmark = pytest.mark.fe
pytest.importorskip("skfem")
pytest.importorskip("gmsh")
build123d = pytest.importorskip("build123d")

from tabletcad.fe.diametral import diametral, hondros_centre_stress  # noqa: E402
from tabletcad.fe.elasticity import Material, PressureLoad, _skfem_mesh, boundary_facets, solve_elasticity  # noqa: E402
from tabletcad.fe.mesh import CutPlane, mesh_solid  # noqa: E402
from tabletcad.pipeline.design import design_from_dict  # noqa: E402

SIGMA = 3.0  # MPa, the uniaxial compression of the box
QUARTER = ((0, 0.0), (2, 0.0))  # mirror planes x = 0 and z = 0


@pytest.fixture(scope="module")
def box():
    return build123d.Box(4.0, 3.0, 2.0).wrapped  # centred at the origin


def _uniaxial(mesh, material, symmetry=()):
    m = _skfem_mesh(mesh)
    bf = boundary_facets(m)
    ends = [PressureLoad(np.flatnonzero(s * bf.normals[:, 0] > 0.999), SIGMA) for s in (-1.0, 1.0)]
    loads = [ld for ld in ends if ld.facets.size]  # the quarter has only the x = +2 end
    return solve_elasticity(mesh, material, loads, support_centre=(0, 0, 0), support_arm=1.0, facets=bf, skmesh=m,
                            symmetry=symmetry)


def test_keep_meshes_only_the_quarter(box):
    q = mesh_solid(box, 1.0, keep=[CutPlane((1.0, 0.0, 0.0), 0.0), CutPlane((0.0, 0.0, 1.0), 0.0)])
    assert q.volume() == pytest.approx(6.0, rel=1e-12)
    assert q.points.min(axis=0) == pytest.approx([0.0, -1.5, 0.0], abs=1e-12)
    assert q.points.max(axis=0) == pytest.approx([2.0, 1.5, 1.0], abs=1e-12)


def test_quarter_box_in_uniaxial_compression_unfolds_to_the_exact_whole(box):
    """σ_xx = -3 MPa everywhere, the strain (-σ/E, νσ/E, νσ/E) and the load work σ²V/E = 2U of the whole box,
    from the quarter x, z >= 0 with the normal displacement held on x = 0 and z = 0."""
    mat = Material(E=1000.0, nu=0.25)
    quarter = mesh_solid(box, 1.0, keep=[CutPlane((1.0, 0.0, 0.0), 0.0), CutPlane((0.0, 0.0, 1.0), 0.0)])
    sol = _uniaxial(quarter, mat, QUARTER)
    expect = np.zeros((3, 3))
    expect[0, 0] = -SIGMA
    assert np.abs(sol.vertex_stress - expect).max() < 1e-8
    # the unfolded mesh is the whole box, four times the quarter, no vertex doubled on the planes
    p = sol.mesh.p.T
    assert sol.elements == 4 * quarter.elements
    assert len(np.unique(np.round(p, 9), axis=0)) == len(p)
    assert p.min(axis=0) == pytest.approx([-2.0, -1.5, -1.0], abs=1e-12)
    assert p.max(axis=0) == pytest.approx([2.0, 1.5, 1.0], abs=1e-12)
    xv = p[sol.mesh.t.T]  # (m, 4, 3)
    vol6 = np.linalg.det(xv[:, 1:] - xv[:, :1])
    assert np.abs(vol6).sum() / 6.0 == pytest.approx(24.0, rel=1e-12)
    assert np.sign(vol6).min() == np.sign(vol6).max()  # reflected tetrahedra keep the orientation
    # the displacement is the affine field u = ε x (+ a translation along y), mirrored with the mesh
    X = np.hstack([p, np.ones((len(p), 1))])
    coef, *_ = np.linalg.lstsq(X, sol.displacement, rcond=None)
    assert np.abs(X @ coef - sol.displacement).max() < 1e-10 * np.abs(sol.displacement).max()
    G = coef[:3].T
    eps = np.diag([-SIGMA / mat.E, mat.nu * SIGMA / mat.E, mat.nu * SIGMA / mat.E])
    assert 0.5 * (G + G.T) == pytest.approx(eps, abs=1e-10)
    assert sol.work == pytest.approx(SIGMA**2 * 24.0 / mat.E, rel=1e-9)
    assert sol.reaction < 1e-9 * SIGMA * 6.0
    full = _uniaxial(mesh_solid(box, 1.0), mat)
    assert full.work == pytest.approx(sol.work, rel=1e-9)


def test_symmetry_needs_two_or_three_distinct_planes(box):
    quarter = mesh_solid(box, 1.0, keep=[CutPlane((1.0, 0.0, 0.0), 0.0), CutPlane((0.0, 0.0, 1.0), 0.0)])
    for bad in (((0, 0.0),), ((0, 0.0), (0, 0.0))):
        with pytest.raises(ValueError, match="two or three mirror planes"):
            _uniaxial(quarter, Material(), bad)


def test_quarter_model_of_a_thin_disc_matches_the_full_model_and_hondros():
    """Thin flat disc 10 x 1 mm across x, default mesh: the quarter model (``symmetric=True``) against
    the whole disc and Hondros' centre stress; the unfolded field is exactly mirror symmetric."""
    t = design_from_dict({"tablet": {"family": "flat_face_round", "diameter": 10.0, "thickness": 1.0}})
    q = diametral(t, 100.0, "x", symmetric=True, error_estimate=False)
    f = diametral(t, 100.0, "x", error_estimate=False)
    h = hondros_centre_stress(100.0, q.diameter_mm, q.thickness_mm, q.strip_width_mm)
    print(f"\nthin disc 10 x 1, 100 N: centre {q.centre_tensile_stress_MPa:.4f} MPa (quarter, {q.dofs} unknowns), "
          f"{f.centre_tensile_stress_MPa:.4f} (whole, {f.dofs}), Hondros {h:.4f}; largest "
          f"{q.max_tensile_stress_MPa:.4f} / {f.max_tensile_stress_MPa:.4f}")
    assert q.centre_tensile_stress_MPa == pytest.approx(h, rel=0.02)
    assert q.centre_tensile_stress_MPa == pytest.approx(f.centre_tensile_stress_MPa, rel=0.01)
    assert q.max_tensile_stress_MPa == pytest.approx(f.max_tensile_stress_MPa, rel=0.01)
    assert q.work_Nmm == pytest.approx(f.work_Nmm, rel=0.01)
    assert q.dofs < 0.5 * f.dofs
    # mirror images across x = 0 and z = mid-thickness: σ(Qx) = Q σ(x) Q
    sol, c = q.solution, np.array(q.centre_mm)
    x = c + np.array([2.1, 0.7, 0.3])
    for ax in (0, 2):
        y = x.copy()
        y[ax] = 2.0 * c[ax] - x[ax]
        Q = np.eye(3)
        Q[ax, ax] = -1.0
        assert sol.stress_at(y) == pytest.approx(Q @ sol.stress_at(x) @ Q, abs=1e-9 * q.centre_tensile_stress_MPa)


@pytest.mark.parametrize("design, offsets", [
    ("families/capsule.toml", (0.0, 0.0, 0.0)),
    ("families/oval.toml", (0.0, 0.0, 0.0)),
    ("flat_faced_round.toml", (0.0, 0.0, 0.0)),
    ("caplet.toml", (0.0, 0.0, 0.0)),  # no nominal: the dense sample
    ("families/rounded_triangle.toml", (0.0, 1.76, 0.0)),  # a vertex up: not symmetric about y = centre
    ("families/custom_outline.toml", (0.828, 0.0, 0.0)),
])
def test_mirror_offset_tells_a_symmetric_tablet_from_one_that_is_not(design, offsets):
    from pathlib import Path

    from tabletcad.fe.diametral import mirror_offset
    from tabletcad.pipeline.design import load_design

    t = load_design(Path(__file__).resolve().parents[1] / "samples" / design)
    for axis, want in enumerate(offsets):
        got = mirror_offset(t, axis)
        if want == 0.0:
            assert got <= 1e-8, (axis, got)  # rounding (a custom outline's points: 3e-10 mm)
        else:
            assert got == pytest.approx(want, abs=0.01), (axis, got)


def test_a_quarter_model_of_an_unsymmetric_tablet_is_refused(tmp_path, capsys):
    """symmetric = true on a rounded triangle loaded across its width had solved the quarter of another
    shape: 107 N against the whole tablet's 128 N, without a word.  Refused before any mesh, in the
    Python API and in an optimisation file (exit 2, nothing written)."""
    from pathlib import Path

    from tabletcad.cli import main
    from tabletcad.errors import DesignError
    from tabletcad.pipeline.design import load_design

    t = load_design(Path(__file__).resolve().parents[1] / "samples" / "families" / "rounded_triangle.toml")
    with pytest.raises(DesignError, match=r"^symmetric = true is not allowed: needs a tablet mirror symmetric about "
                                          r"its centre's y plane"):
        diametral(t, 100.0, "width", symmetric=True, solid=object())  # refused before the solid is read
    prob = tmp_path / "tri.toml"
    prob.write_text('[problem]\nkind = "family"\nfamily = "rounded_triangle"\nsense = "max"\n'
                    'objective = "fe_breaking_force_N"\n[variables]\ncup_depth = { lower = 0.8, upper = 1.2 }\n'
                    '[fixed]\nside = 10.0\ncorner_radius = 1.5\nband = 2.5\n'
                    '[fe]\ntensile_strength_MPa = 2.0\nsymmetric = true\n')
    out = tmp_path / "o"
    assert main(["optimise", str(prob), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: fe.symmetric = true is not allowed: needs a tablet mirror")
    assert not out.exists()


def test_a_symmetric_tablet_without_a_nominal_sampled_off_its_mirror_is_accepted():
    """A free-form round whose rings of points start at 10 deg: its mirrored samples fall between the
    dense samples (0.027 mm from the nearest, above the 0.01 mm limit of a 10 mm tablet); the distance
    to the surface itself is 1.7e-4 mm (the point interpolation's own asymmetry)."""
    import math

    from tabletcad.fe.diametral import check_symmetric, mirror_offset
    from tabletcad.pipeline.design import Design

    def ring(r, z, n=64):
        th = math.radians(10.0) + np.linspace(0.0, 2.0 * math.pi, n, endpoint=False)
        return {"type": "points", "points": [[r * math.cos(a), r * math.sin(a)] for a in th], "z": z}

    t = Design.from_dict({"tablet": {"family": "free_form", "name": "rotated", "a": "auto"}, "patch": [
        {"curves": [{"type": "circle", "radius": 0.0, "z": 0.0}, ring(2.0, 0.0), ring(4.0, 0.0), ring(5.0, 0.0)]},
        {"curves": ["previous", ring(5.0, 1.0), ring(5.0, 2.0), ring(5.0, 3.0)]},
        {"curves": ["previous", ring(4.0, 3.0), ring(2.0, 3.0), {"type": "circle", "radius": 0.0, "z": 3.0}]},
    ]}).build()
    assert t.nominal is None
    assert mirror_offset(t, 0) < 1e-3 and mirror_offset(t, 2) < 1e-9
    check_symmetric(t, "x")  # accepted
