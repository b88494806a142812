"""The tooling gap's point-to-mesh distance (libigl's AABB tree) against a brute-force minimum
over every triangle computed by a second library (trimesh's closest point on each triangle)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

pytest.importorskip("igl")
trimesh = pytest.importorskip("trimesh")

from tabletcad.tooling.interference import mesh_distance  # noqa: E402

pytestmark = pytest.mark.cad


@pytest.fixture(scope="module")
def bisect_tablet():
    """The finished tablet (scored, debossed) of ``samples/tooling/concave_round_bisect.toml``, built once
    for the tests that read its faces (read-only)."""
    from pathlib import Path

    from tabletcad.pipeline.design import Design
    from tabletcad.tooling.toolset import make_tooling

    d = Design.from_toml(Path(__file__).resolve().parents[1] / "samples" / "tooling" / "concave_round_bisect.toml")
    return make_tooling(d.build(), d.tooling_spec, check=False, interference_check=False).parts["tablet"]


def _brute_force(P: np.ndarray, V: np.ndarray, T: np.ndarray) -> np.ndarray:
    """Each point's least distance to every triangle, by trimesh's closest point on each triangle: every
    (point, triangle) pair in one call: the same numbers, bit for bit, as one call per point (checked on
    the 73 calls of this file's tests and 400 random cases of their kind), in 0.6 of its time."""
    tri = V[T]  # (m, 3, 3)
    n, m = len(P), len(tri)
    R = np.repeat(np.asarray(P, dtype=float).reshape(-1, 3), m, axis=0)  # each point once per triangle
    q = trimesh.triangles.closest_point(np.tile(tri, (n, 1, 1)), R)
    return np.min(np.linalg.norm(q - R, axis=1).reshape(n, m), axis=1)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), noise=st.floats(0.0, 0.3), spread=st.floats(0.01, 3.0))
def test_mesh_distance_is_the_exact_minimum_over_all_triangles(seed, noise, spread):
    rng = np.random.default_rng(seed)
    mesh = trimesh.creation.icosphere(subdivisions=2)
    V = np.asarray(mesh.vertices) * (1.0 + noise * rng.uniform(-1, 1, (len(mesh.vertices), 1)))
    T = np.asarray(mesh.faces)
    P = rng.normal(size=(60, 3)) * spread
    assert np.allclose(mesh_distance(P, V, T), _brute_force(P, V, T), rtol=0, atol=1e-12)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), reach=st.floats(0.05, 2.0), spread=st.floats(0.2, 3.0))
def test_mesh_distance_with_a_reach(seed, reach, spread):
    """Beyond ``reach`` a point is ``inf`` (the reach cells rule it out without the tree), within it
    the brute-force minimum."""
    from tabletcad.tooling.interference import MeshDistance

    rng = np.random.default_rng(seed)
    mesh = trimesh.creation.icosphere(subdivisions=2)
    V, T = np.asarray(mesh.vertices), np.asarray(mesh.faces)
    P = rng.normal(size=(80, 3)) * spread
    exact = _brute_force(P, V, T)
    md = MeshDistance(V, T, reach=reach)
    d = md(P)
    assert np.allclose(d[exact <= reach * (1 - 1e-9)], exact[exact <= reach * (1 - 1e-9)], rtol=0, atol=1e-12)
    assert np.all(np.isinf(d[exact > reach * (1 + 1e-9)]))


@pytest.mark.parametrize("near", [True, False])
def test_mesh_distance_reach_cells_drop_only_points_beyond_reach(monkeypatch, near):
    """6,000 points within 0.05 of the sphere (all within reach) or all over its box (half of them too
    far): every finite distance is the brute-force minimum, every point within reach is measured, the
    answers (distances and nearest points) are those of the same mesh measured without a reach, bit for
    bit, and the reach cells drop most of the points more than 2.5 times the reach away before the tree
    is asked; with the grid capped at 64 cells (larger cubes) the same answers."""
    from tabletcad.tooling.interference import MeshDistance, _ReachCells

    rng = np.random.default_rng(7)
    mesh = trimesh.creation.icosphere(subdivisions=3)
    V, T = np.asarray(mesh.vertices), np.asarray(mesh.faces)
    if near:
        P = rng.normal(size=(6000, 3))
        P = P / np.linalg.norm(P, axis=1)[:, None] * (1.0 + 0.05 * rng.uniform(-1, 1, (len(P), 1)))
    else:
        P = rng.uniform(-1.2, 1.2, size=(6000, 3))
    md = MeshDistance(V, T, reach=0.2)
    d, q = md(P, closest=True)
    k = np.arange(0, len(P), 20)  # the brute force on 300 of them
    exact, dk = _brute_force(P[k], V, T), d[k]
    fin = np.isfinite(dk)
    assert np.allclose(dk[fin], exact[fin], rtol=0, atol=1e-12)
    assert np.all(fin[exact <= 0.2 * (1 - 1e-9)])
    d0, q0 = MeshDistance(V, T)(P, closest=True)  # no reach: every point asked of the tree
    within = d0 <= 0.2
    assert np.array_equal(d[within], d0[within]) and np.array_equal(q[within], q0[within])
    assert np.all(np.isinf(d[~within])) and np.all(np.isnan(q[~within]))
    far = d0 > 0.5
    assert near or (np.count_nonzero(far) > 1000 and np.count_nonzero(md.cells(P)[far]) < 0.5 * np.count_nonzero(far))
    monkeypatch.setattr(_ReachCells, "MAX_CELLS", 64)
    coarse = MeshDistance(V, T, reach=0.2)
    assert np.prod(coarse.cells.shape) <= 64
    dc, qc = coarse(P, closest=True)
    assert np.array_equal(dc, d) and np.array_equal(qc, q, equal_nan=True)


@pytest.mark.parametrize("reach", [1e-3, 0.01, 0.2, 1.5])
def test_reach_cells_keep_points_at_the_reach(reach):
    """Points just inside the reach of a box's faces, edges and corners (``reach (1 - 1e-12)`` along the
    outward normal, the edge's bisector and the corner's diagonal) all lie in marked cells; points three times the
    reach out do not when the cubes are small beside the reach (``reach / 4``: a grown box's last cell
    stands out of it by less than that)."""
    from tabletcad.tooling.interference import _ReachCells

    centre, half = np.array([10.0, -3.0, 1.25]), np.array([10.0, 15.0, 2.5]) * reach  # (a grid of ~3e5 cubes)
    mesh = trimesh.creation.box(extents=2.0 * half)
    V, T = np.asarray(mesh.vertices) + centre, np.asarray(mesh.faces)
    dirs = np.array([s for s in np.ndindex(3, 3, 3) if s != (1, 1, 1)], dtype=float) - 1.0  # 26 directions
    unit = dirs / np.linalg.norm(dirs, axis=1)[:, None]
    foot = centre + dirs * half  # the face centre, edge midpoint or corner each direction points out of
    cells = _ReachCells(V, T, reach)
    assert np.all(cells(foot + unit * reach * (1.0 - 1e-12)))
    assert np.all(cells(foot))
    fine = _ReachCells.__new__(_ReachCells)
    fine.CELLS_PER_REACH, fine.MAX_CELLS = 4.0, 10**9
    fine.__init__(V, T, reach)
    assert not np.any(fine(foot + unit * 3.0 * reach))


def test_mesh_distance_of_points_on_the_mesh_and_of_nothing():
    mesh = trimesh.creation.box(extents=(2.0, 3.0, 4.0))
    V, T = np.asarray(mesh.vertices), np.asarray(mesh.faces)
    assert np.max(mesh_distance(V, V, T)) <= 1e-15
    centre = mesh_distance(np.zeros((1, 3)), V, T)
    assert centre[0] == pytest.approx(1.0, abs=1e-15)  # the nearest face is x = ±1
    assert mesh_distance(np.zeros((0, 3)), V, T).shape == (0,)
    assert np.isinf(mesh_distance(np.zeros((2, 3)), V, T[:0])).all()


def test_exact_distance_matches_closed_forms_and_brepextrema():
    """:class:`ExactDistance` (each face's extremum solver set up once) against closed forms - a box's
    boundary, a sphere converted to a NURBS face (0 inside both solids, as OCC's distance of a point
    and a solid) - and against ``BRepExtrema_DistShapeShape`` of a vertex and the thesis tablet's
    B-spline solid and its shell (its boundary only): never above it, below it by less than OCC's
    confusion precision (1e-7 mm)."""
    pytest.importorskip("OCP")
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeVertex, BRepBuilderAPI_NurbsConvert
    from OCP.BRepExtrema import BRepExtrema_DistShapeShape
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox, BRepPrimAPI_MakeSphere
    from OCP.gp import gp_Pnt

    from tabletcad.cad._occ import explore
    from tabletcad.cad.tablet_solid import tablet_solid
    from tabletcad.families.thesis import shallow_convex_round
    from tabletcad.tooling.interference import ExactDistance

    rng = np.random.default_rng(7)
    h = np.array([1.0, 1.5, 2.0])
    solid = BRepPrimAPI_MakeBox(gp_Pnt(*-h), gp_Pnt(*h)).Shape()
    box, box_shell = ExactDistance(solid), ExactDistance(explore(solid, "Shell")[0])
    P = rng.uniform(-3.0, 3.0, (60, 3))
    q = np.abs(P) - h
    inside = np.all(q <= 0, axis=1)
    closed = np.where(inside, -q.max(axis=1), np.linalg.norm(np.maximum(q, 0.0), axis=1))
    assert 5 < inside.sum() < 50
    assert np.allclose([box_shell(p) for p in P], closed, rtol=0, atol=1e-12)
    assert np.allclose([box(p) for p in P], np.where(inside, 0.0, closed), rtol=0, atol=1e-12)
    sphere = ExactDistance(BRepBuilderAPI_NurbsConvert(BRepPrimAPI_MakeSphere(2.0).Shape(), True).Shape())
    P = rng.normal(size=(40, 3)) * 2.0
    r = np.linalg.norm(P, axis=1)
    got = [sphere.nearest(p) for p in P]
    assert 5 < np.sum(r < 2.0) < 35
    assert np.allclose([d for d, _ in got], np.maximum(r - 2.0, 0.0), rtol=0, atol=1e-7)
    assert np.allclose([np.linalg.norm(x) for (_, x), ri in zip(got, r) if ri > 2.0], 2.0, rtol=0, atol=1e-7)
    shape = tablet_solid(shallow_convex_round(), revolved=False).shape
    P = rng.uniform(-6.0, 6.0, (30, 3)) * np.array([1.0, 1.0, 0.5])
    for s in (shape, explore(shape, "Shell")[0]):
        ext = ExactDistance(s)
        for p in P:
            dss = BRepExtrema_DistShapeShape(BRepBuilderAPI_MakeVertex(gp_Pnt(*p)).Vertex(), s)
            assert dss.Value() - 1e-7 <= ext(p) <= dss.Value() + 1e-12


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), flat=st.floats(0.0, 1.0))
def test_covering_radius_is_the_largest_distance_to_the_nearest_corner(seed, flat):
    """:func:`covering_radius` (the branch and bound's bound on a triangle) against a dense barycentric
    grid: no grid point lies farther from its nearest corner, for an acute triangle the grid's worst
    comes within the grid's spacing of it (an obtuse one gets half its longest edge, an upper bound),
    and it never exceeds ``L / √3``; closed forms for the equilateral and the right isosceles triangle."""
    from tabletcad.tooling.interference import covering_radius

    rng = np.random.default_rng(seed)
    tri = rng.normal(size=(3, 3))
    tri[2] = tri[0] + flat * (tri[2] - tri[0]) + (1 - flat) * 0.5 * (tri[1] - tri[0])  # down to nearly flat
    r = float(covering_radius(tri[None])[0])
    n = 120
    i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
    keep = i + j <= n
    w = np.stack([i[keep], j[keep], n - i[keep] - j[keep]], axis=1) / n
    P = w @ tri
    worst = float(np.max(np.min(np.linalg.norm(P[:, None, :] - tri[None], axis=2), axis=1)))
    L = max(np.linalg.norm(tri[a] - tri[b]) for a, b in ((0, 1), (1, 2), (2, 0)))
    assert worst <= r * (1 + 1e-12) + 1e-15
    e = np.sort([np.linalg.norm(tri[a] - tri[b]) for a, b in ((0, 1), (1, 2), (2, 0))])
    if e[0] ** 2 + e[1] ** 2 > e[2] ** 2 * (1 + 1e-9):  # acute: the circumcentre, a tight bound
        assert worst >= r - 2.0 * L / n
    assert r <= L / np.sqrt(3.0) * (1 + 1e-12)
    eq = np.array([[[0, 0, 0], [1, 0, 0], [0.5, np.sqrt(3) / 2, 0]]])
    assert covering_radius(eq)[0] == pytest.approx(1 / np.sqrt(3), rel=1e-12)
    assert covering_radius(np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]]], float))[0] == pytest.approx(np.sqrt(2) / 2, rel=1e-12)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), scale=st.floats(1e-3, 10.0))
def test_branch_and_bound_shortcuts_give_the_direct_formulas_bit_for_bit(seed, scale):
    """The branch and bound's shortcuts are the direct formulas to the last bit: the halves' edge lengths
    from their parents' (:func:`_half_edges`) against :func:`_edge_lengths` of the halves, the live test
    decided by the covering radius's bounds (:func:`_lipschitz_live`) against ``max + covering_radius``
    on every triangle, and ``covering_radius``'s own sort and cross product against ``np.sort``/``np.cross``
    (on random, nearly flat and degenerate triangles, thresholds among their bounds)."""
    from tabletcad.tooling.interference import (_cross, _edge_lengths, _half_edges, _halves, _lipschitz_live,
                                                _longest_edge_corners, _sorted3, covering_radius)

    rng = np.random.default_rng(seed)
    tris = rng.normal(size=(3000, 3, 3)) * scale
    tris[:300, 2] = tris[:300, 0] + rng.uniform(0, 1, (300, 1)) * (tris[:300, 1] - tris[:300, 0])  # flat
    tris[300:400, 1] = tris[300:400, 0]  # a zero edge
    values = rng.uniform(0, scale, (3000, 3))
    e = _edge_lengths(tris)
    for threshold in np.quantile(values.max(axis=1) + covering_radius(tris, e), [0.1, 0.5, 0.9]):
        direct = values.max(axis=1) + covering_radius(tris, e) > threshold
        assert np.array_equal(_lipschitz_live(tris, values, e, threshold), direct)
    rows = np.flatnonzero(rng.random(3000) < 0.7)
    i0, i1, i2 = _longest_edge_corners(e, rows)
    assert np.array_equal(i0 - 3 * rows, np.argmax(e[rows], axis=1))
    a, b, c = (tris.reshape(-1, 3)[i] for i in (i0, i1, i2))
    m = 0.5 * (a + b)
    halves = _halves(a, b, c, m)
    assert np.array_equal(halves, np.concatenate([np.stack([a, m, c], axis=1), np.stack([m, b, c], axis=1)]))
    edges = _half_edges(e.reshape(-1)[i1], e.reshape(-1)[i2], a, b, c, m)
    assert np.array_equal(edges, _edge_lengths(halves))
    u, v = tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]
    assert np.array_equal(_cross(u, v), np.cross(u, v))
    assert np.array_equal(np.stack(_sorted3(*e.T), axis=1), np.sort(e, axis=1))


def test_mesh_distance_closest_points_lie_on_the_mesh_at_the_distance():
    """With ``closest``, each finite distance comes with a point of the mesh that far away (the
    branch and bound's anchors); NaN where the distance is ``inf``."""
    from tabletcad.tooling.interference import MeshDistance

    rng = np.random.default_rng(7)
    mesh = trimesh.creation.icosphere(subdivisions=2)
    V, T = np.asarray(mesh.vertices), np.asarray(mesh.faces)
    P = rng.normal(size=(200, 3)) * 1.5
    d, Q = MeshDistance(V, T, reach=0.8)(P, closest=True)
    fin = np.isfinite(d)
    assert 20 < np.count_nonzero(fin) < len(P)
    assert np.allclose(np.linalg.norm(P[fin] - Q[fin], axis=1), d[fin], rtol=0, atol=1e-12)
    assert np.max(_brute_force(Q[fin], V, T)) < 1e-12  # the points lie on the mesh (a second library's distance)
    assert np.all(np.isnan(Q[~fin]))


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), anchored=st.booleans(), height=st.floats(0.0, 0.05))
def test_branch_and_bound_misses_no_peak_by_more_than_its_resolution(seed, anchored, height):
    """``largest_inside`` of the distance to a set of points (a ridge between two rows of them,
    as a land lies between a punch tip and a die wall): no point of any triangle, sampled densely,
    is farther from the set than the largest value found plus ``spacing / √3`` - with the
    Lipschitz bound alone and with the anchored bound (each corner's nearest point), which
    refines fewer points along the ridge."""
    from scipy.spatial import cKDTree

    from tabletcad.tooling.interference import largest_inside

    rng = np.random.default_rng(seed)
    xs = np.linspace(-1.0, 1.0, 400)
    S = np.concatenate([np.column_stack([xs, np.full_like(xs, -0.1), np.zeros_like(xs)]),
                        np.column_stack([xs, np.full_like(xs, 0.1 + 0.05 * rng.uniform()), np.zeros_like(xs)])])
    tree = cKDTree(S)

    def f(P):
        d, i = tree.query(P)
        return (d, S[i]) if anchored else d

    corners = rng.uniform([-0.9, -0.2, height - 0.01], [0.9, 0.25, height + 0.01], size=(12, 3, 3))
    d0, i0 = tree.query(corners.reshape(-1, 3))
    values = d0.reshape(-1, 3)
    spacing = 0.005
    best = float(values.max())
    anchors = S[i0].reshape(-1, 3, 3) if anchored else None
    Vs, ds = largest_inside(corners, values, f, spacing, best, anchors=anchors)
    found = max(best, float(ds.max()) if len(ds) else best)
    assert np.allclose(tree.query(Vs)[0], ds, rtol=0, atol=0) if len(Vs) else True
    w = rng.dirichlet(np.ones(3), size=4000)  # dense random points of every triangle
    inside = np.einsum("sk,tkc->tsc", w, corners).reshape(-1, 3)
    assert float(tree.query(inside)[0].max()) <= found + spacing / np.sqrt(3.0) + 1e-12


def _ridge():
    """Two parallel lines of points 0.2 mm apart along x (a land's ridge between two tools) and their
    k-d tree."""
    from scipy.spatial import cKDTree

    xs = np.linspace(-2.0, 2.0, 4001)
    S = np.concatenate([np.column_stack([xs, np.full_like(xs, -0.1), np.zeros_like(xs)]),
                        np.column_stack([xs, np.full_like(xs, 0.1), np.zeros_like(xs)])])
    return S, cKDTree(S)


def test_anchored_bound_refines_fewer_points_along_a_ridge():
    """Along a straight ridge the anchored bound is second order (``sqrt(f² + h²)``), the Lipschitz
    one first order (``f + h``): the same guarantee with fewer refined points."""
    from tabletcad.tooling.interference import largest_inside

    S, tree = _ridge()
    g = np.linspace(-1.0, 1.0, 41)
    corners = np.array([[[a, -0.1, 0.0], [b, -0.1, 0.0], [a, 0.1, 0.0]] for a, b in zip(g[:-1], g[1:])]
                       + [[[b, -0.1, 0.0], [b, 0.1, 0.0], [a, 0.1, 0.0]] for a, b in zip(g[:-1], g[1:])])
    d0, i0 = tree.query(corners.reshape(-1, 3))
    values, best = d0.reshape(-1, 3), float(d0.max())
    plain, dp = largest_inside(corners, values, lambda P: tree.query(P)[0], 0.004, best)
    anch, da = largest_inside(corners, values, lambda P: (tree.query(P)[0], S[tree.query(P)[1]]), 0.004, best,
                              anchors=S[i0].reshape(-1, 3, 3))
    assert dp.max() == pytest.approx(0.1, abs=0.004 / np.sqrt(3)) and da.max() == pytest.approx(0.1, abs=0.004 / np.sqrt(3))
    assert len(anch) < 0.7 * len(plain)


@pytest.mark.parametrize("collide", [False, True])
def test_branch_and_bound_measures_each_point_once(monkeypatch, collide):
    """``largest_inside`` asks ``f`` once per distinct point (two triangles that share their longest edge
    both split it: the ridge's triangles in pairs), and returns every midpoint with ``f``'s own value and
    nearest point; with every point hashed alike (``collide``) the memo may not merge different points:
    the same points and values, each bit for bit."""
    from tabletcad.tooling import interference
    from tabletcad.tooling.interference import largest_inside

    S, tree = _ridge()
    g = np.linspace(-1.0, 1.0, 11)
    corners = np.array([[[a, -0.1, 0.0], [b, -0.1, 0.0], [a, 0.1, 0.0]] for a, b in zip(g[:-1], g[1:])]
                       + [[[b, 0.1, 0.0], [a, 0.1, 0.0], [b, -0.1, 0.0]] for a, b in zip(g[:-1], g[1:])])
    d0, i0 = tree.query(corners.reshape(-1, 3))
    asked = []

    def f(P):
        asked.append(np.array(P))
        d, i = tree.query(P)
        return d, S[i]

    if collide:
        monkeypatch.setattr(interference._Memo, "_hash", staticmethod(lambda bits: np.zeros(len(bits), dtype=np.uint64)))
    Vs, ds = largest_inside(corners, d0.reshape(-1, 3), f, 0.004, float(d0.max()), anchors=S[i0].reshape(-1, 3, 3))
    asked = np.concatenate(asked)
    assert np.array_equal(ds, tree.query(Vs)[0])  # every value f's own, to the bit
    distinct = np.unique(Vs, axis=0)
    assert len(distinct) < 0.9 * len(Vs)  # the shared edges' midpoints come twice (371 of 450)...
    if not collide:
        assert len(asked) == len(distinct)  # ... and are measured once
        assert len(np.unique(asked, axis=0)) == len(asked)
    else:
        assert len(asked) == len(Vs)  # every call's points collide: each measured, none merged wrongly


def test_faces_that_fill_their_box_keep_the_same_samples_unclassified(monkeypatch):
    """``face_samples`` keeps the whole grid of a face that is its entire (u, v) box without
    classifying each point: on a tablet's B-spline faces the points are the classified ones to
    the last bit; a face with a hole, or a trimmed one, is never taken for a whole box."""
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox, BRepPrimAPI_MakeCylinder
    from OCP.BRepTools import BRepTools
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt

    import tabletcad.tooling.interference as I
    from tabletcad.cad._occ import explore
    from tabletcad.cad.tablet_solid import tablet_solid
    from tabletcad.families import FAMILIES

    shape = tablet_solid(FAMILIES["concave_round"].build(diameter=8.0, band=2.0, cup_depth=0.8), revolved=False).shape
    assert all(I._fills_uv_box(f, *BRepTools.UVBounds_s(f)) for f in explore(shape, "Face"))
    fast = I.face_samples(shape, spacing=0.05)
    monkeypatch.setattr(I, "_fills_uv_box", lambda *a: False)
    assert np.array_equal(fast, I.face_samples(shape, spacing=0.05))
    monkeypatch.undo()
    plate = BRepPrimAPI_MakeBox(4.0, 4.0, 1.0).Shape()
    holed = BRepAlgoAPI_Cut(plate, BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(2, 2, -1), gp_Dir(0, 0, 1)), 0.5, 3.0).Shape()).Shape()
    whole = [I._fills_uv_box(f, *BRepTools.UVBounds_s(f)) for f in explore(plate, "Face")]
    assert all(whole) and len(whole) == 6
    holed_faces = explore(holed, "Face")
    flags = [I._fills_uv_box(f, *BRepTools.UVBounds_s(f)) for f in holed_faces]
    assert flags.count(False) >= 2  # the top and bottom with their holes (and the bore, not a line-bounded box)
    P = I.face_samples(holed, spacing=0.1)
    assert np.all(np.hypot(P[:, 0] - 2.0, P[:, 1] - 2.0) >= 0.5 - 1e-9)  # no sample inside the hole


def test_trimmed_faces_classified_by_their_polygons_keep_the_classifier_samples(monkeypatch, bisect_tablet):
    """``face_samples`` of trimmed faces decides points away from the wires by the even-odd rule on
    the wires' (u, v) polygons and asks ``BRepTopAdaptor_FClass2d`` only near them: on a debossed,
    scored tablet (letter floors and walls, a cup with holes, a periodic cup cut by a score) the
    samples are the classifier's to the last bit; a polygon with its parity flipped fails it."""
    import tabletcad.tooling.interference as I

    shape = bisect_tablet
    fast = I.face_samples(shape, spacing=0.02)
    polygons = I._polygon_classes
    asked = []

    def every_point_near(face, us, vs, margin):
        asked.append(len(us) * len(vs))
        return np.zeros((len(us), len(vs)), dtype=bool), np.ones((len(us), len(vs)), dtype=bool)

    monkeypatch.setattr(I, "_polygon_classes", every_point_near)
    slow = I.face_samples(shape, spacing=0.02)
    assert len(asked) >= 10 and np.array_equal(fast, slow)

    def flipped(face, us, vs, margin):
        inside, near = polygons(face, us, vs, margin)
        return ~inside, near

    monkeypatch.setattr(I, "_polygon_classes", flipped)
    assert not np.array_equal(I.face_samples(shape, spacing=0.02), slow)


def test_grid_points_on_straight_boundary_sides_are_the_classifiers_on_points(bisect_tablet):
    """``_on_straight_sides`` marks grid points that lie on an edge running along a side of the face's
    (u, v) box (the lettered cup's rim and seam, B-spline p-curves after the Boolean): every one is
    ON (or IN) by ``BRepTopAdaptor_FClass2d``, there are over a thousand of them on the sample, and a
    point one step inside the box is never marked."""
    from OCP.BRepTools import BRepTools
    from OCP.BRepTopAdaptor import BRepTopAdaptor_FClass2d
    from OCP.gp import gp_Pnt2d
    from OCP.TopAbs import TopAbs_State

    import tabletcad.tooling.interference as I
    from tabletcad.cad._occ import explore

    marked = 0
    for face in explore(bisect_tablet, "Face"):
        u0, u1, v0, v1 = BRepTools.UVBounds_s(face)
        us, vs = np.linspace(u0, u1, 61), np.linspace(v0, v1, 41)
        on = I._on_straight_sides(face, us, vs)
        assert not on[1:-1, 1:-1].any()
        cls = BRepTopAdaptor_FClass2d(face, 1e-9)
        for i, j in zip(*np.nonzero(on)):
            assert cls.Perform(gp_Pnt2d(us[i], vs[j])) in (TopAbs_State.TopAbs_ON, TopAbs_State.TopAbs_IN)
        marked += int(on.sum())
    assert marked > 1000


@pytest.mark.parametrize("radius, height", [(5.0, 3.0), (0.8, 12.0), (15.0, 0.5)])
def test_bound_area_is_at_least_the_exact_area_and_close_to_it(radius, height):
    """``bound_area`` (the mesh's area over ``cos(angle)``, scaling the manifold3d bounds) is at least a
    cylinder's closed-form area and within the cosine's 2.03 % of it; a box's planar faces mesh exactly."""
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox, BRepPrimAPI_MakeCylinder

    from tabletcad.tooling.booleans import CACHE, bound_area

    CACHE.clear()
    cyl = BRepPrimAPI_MakeCylinder(radius, height).Shape()
    exact = 2.0 * np.pi * radius * (radius + height)
    assert exact <= bound_area(cyl, 0.005) <= exact / np.cos(0.2) * (1 + 1e-12)
    box = BRepPrimAPI_MakeBox(radius, height, 2.0).Shape()
    assert bound_area(box, 0.005) == pytest.approx(2 * (radius * height + 2 * radius + 2 * height) / np.cos(0.2), rel=1e-12)


def test_lift_allowance_bounds_the_overlap_change_of_a_moved_mesh_and_is_reached():
    """``lift_allowance`` (what moving a punch's mesh along z for manifold3d's Common can change): two unit
    cubes stacked 1 mm apart (a vertical line meets them twice) sunk by ``d`` into two slabs they rest on
    gain exactly ``2 d`` of overlap, the allowance: half the triangles' projected area, 4 mm², times ``d``
    (the plan area alone, 1 mm², would allow half of it)."""
    import manifold3d

    from tabletcad.tooling.booleans import manifold_volume
    from tabletcad.tooling.interference import lift_allowance

    cube = manifold3d.Manifold.cube((1.0, 1.0, 1.0))
    moved = cube + cube.translate((0.0, 0.0, 2.0))  # z in [0, 1] and [2, 3]
    rests = manifold3d.Manifold.cube((3.0, 3.0, 1.0)).translate((-1.0, -1.0, -1.0)) \
        + manifold3d.Manifold.cube((3.0, 3.0, 0.5)).translate((-1.0, -1.0, 1.5))  # touching both from below
    mesh = moved.to_mesh()
    V, T = np.asarray(mesh.vert_properties, dtype=float)[:, :3], np.asarray(mesh.tri_verts, dtype=np.int64)
    for d in (1e-3, 0.25):
        before = manifold_volume(rests ^ moved)
        after = manifold_volume(rests ^ moved.translate((0.0, 0.0, -d)))
        allowance = lift_allowance(V, T, d)
        assert allowance == pytest.approx(2.0 * d, rel=1e-12)
        assert abs(after - before) <= allowance * (1 + 1e-9)
        assert abs(after - before) == pytest.approx(allowance, rel=1e-6)


def _classifier_spy(monkeypatch):
    """Count ``BRepClass3d_SolidClassifier.Perform`` calls (the classifier ``ExactDistance`` falls back on)."""
    import OCP.BRepClass3d as C

    calls, real = [], C.BRepClass3d_SolidClassifier

    class Spy:
        def __init__(self, *a):
            self.c = real(*a)

        def Perform(self, *a):
            calls.append(a)
            return self.c.Perform(*a)

        def State(self):
            return self.c.State()

    monkeypatch.setattr(C, "BRepClass3d_SolidClassifier", Spy)
    return calls


def _box_distance(P, lo, hi):
    return np.linalg.norm(np.maximum(np.maximum(np.asarray(lo) - P, P - np.asarray(hi)), 0.0), axis=1)


@pytest.mark.parametrize("nurbs", [False, True])
def test_exact_distance_signs_points_nearest_to_edges_without_the_classifier(monkeypatch, nurbs):
    """Inside or outside, for a point whose nearest boundary point lies on an edge, follows from the
    edge's two face normals (the solid's normal cone there): on an L-shaped solid (a concave edge
    along which inside points are nearest, convex edges for outside ones), plain and converted to
    B-spline faces (where a face's extremum on its boundary ties with the edge's), ``ExactDistance``
    gives the closed form (0 inside; outside, the nearer of the two boxes' distances) to 1e-7 mm
    and asks the solid classifier for few points (those nearest to a vertex)."""
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut
    from OCP.BRepBuilderAPI import BRepBuilderAPI_NurbsConvert
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
    from OCP.gp import gp_Pnt

    from tabletcad.cad._occ import explore
    from tabletcad.tooling.interference import ExactDistance

    L = BRepAlgoAPI_Cut(BRepPrimAPI_MakeBox(gp_Pnt(0, 0, 0), gp_Pnt(2, 2, 1)).Shape(),
                        BRepPrimAPI_MakeBox(gp_Pnt(1, 1, -1), gp_Pnt(3, 3, 2)).Shape()).Shape()
    if nurbs:
        L = BRepBuilderAPI_NurbsConvert(L, True).Shape()
    calls = _classifier_spy(monkeypatch)
    rng = np.random.default_rng(3)
    # points near the concave edge (x = y = 1) and a convex edge, inside and out, and anywhere
    P = np.concatenate([np.array([1.0, 1.0, 0.5]) + rng.uniform(-0.15, 0.15, (60, 3)) * [1, 1, 0],
                        np.array([2.0, 0.5, 1.0]) + rng.uniform(-0.15, 0.15, (60, 3)) * [1, 0, 1],
                        rng.uniform(-0.3, 2.3, (80, 3)) * [1, 1, 0.6]])
    a = _box_distance(P, (0, 0, 0), (2, 1, 1))  # the L is the union of two boxes
    b = _box_distance(P, (0, 0, 0), (1, 2, 1))
    closed = np.minimum(a, b)  # 0 inside either box
    got = np.array([ExactDistance(explore(L, "Solid")[0])(p) for p in P])
    assert np.allclose(got, closed, rtol=0, atol=1e-7)
    near_concave = (P[:60, 0] < 1.0) & (P[:60, 1] < 1.0)  # inside, nearest to the concave edge
    assert near_concave.sum() > 5 and np.all(got[:60][near_concave] == 0.0)
    assert (closed > 1e-3).sum() > 20 and (closed == 0.0).sum() > 20
    assert len(calls) <= 0.1 * len(P)


def test_exact_distance_at_a_sharp_bspline_edge_asks_the_edge_not_the_face():
    """Near a 20° edge of a prism converted to B-spline faces, ``BRepExtrema_ExtPF`` returns points on a
    face's boundary, off its normal, where the face's normal points the wrong way: the edge (as near,
    within its tolerance) decides, and every point gets 0 inside the wedge (its three half-planes
    and two heights) and ``BRepExtrema_DistShapeShape``'s distance outside."""
    from OCP.BRepBuilderAPI import (BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakePolygon, BRepBuilderAPI_MakeVertex,
                                    BRepBuilderAPI_NurbsConvert)
    from OCP.BRepExtrema import BRepExtrema_DistShapeShape
    from OCP.BRepPrimAPI import BRepPrimAPI_MakePrism
    from OCP.gp import gp_Pnt, gp_Vec

    from tabletcad.cad._occ import explore
    from tabletcad.tooling.interference import ExactDistance

    tan = np.tan(np.radians(20.0))
    poly = BRepBuilderAPI_MakePolygon(gp_Pnt(0, 0, 0), gp_Pnt(3, 0, 0), gp_Pnt(3, 3 * tan, 0), True)
    wedge = BRepPrimAPI_MakePrism(BRepBuilderAPI_MakeFace(poly.Wire()).Face(), gp_Vec(0, 0, 1)).Shape()
    solid = explore(BRepBuilderAPI_NurbsConvert(wedge, True).Shape(), "Solid")[0]
    ext = ExactDistance(solid)
    rng = np.random.default_rng(11)
    P = np.concatenate([[[-0.025170148887782406, -0.07608190636709793, 0.9518072884633912]],  # outside, 0.0801
                        rng.uniform(-0.1, 0.1, (150, 3)) + [0.1, 0.02, 0.5],  # around the sharp edge on the z axis
                        rng.uniform(-0.2, 0.2, (100, 3)) + [3.0, 0.5, 0.5]])
    inside = (P[:, 1] >= 0) & (P[:, 0] <= 3) & (P[:, 1] <= P[:, 0] * tan) & (P[:, 2] >= 0) & (P[:, 2] <= 1)
    got = np.array([ext(p) for p in P])
    assert 20 < inside.sum() < len(P) - 20
    assert np.all(got[inside] == 0.0)
    for p, d in zip(P[~inside], got[~inside]):
        dss = BRepExtrema_DistShapeShape(BRepBuilderAPI_MakeVertex(gp_Pnt(*p)).Vertex(), solid).Value()
        assert d == pytest.approx(dss, abs=1e-7)
    assert got[0] == pytest.approx(0.0801373375617, abs=1e-9)


def test_grid_points_on_an_external_edge_are_not_kept_as_boundary():
    """An EXTERNAL edge of a face (not part of its boundary, though ``UVBounds`` counts it) along a
    side of the (u, v) box marks no grid point ON: the square face's samples stay inside it."""
    from OCP.BRep import BRep_Builder, BRep_Tool
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakeVertex
    from OCP.BRepLib import BRepLib
    from OCP.BRepTools import BRepTools
    from OCP.Geom import Geom_Plane
    from OCP.Geom2d import Geom2d_Line
    from OCP.gp import gp_Dir, gp_Dir2d, gp_Pln, gp_Pnt, gp_Pnt2d
    from OCP.TopAbs import TopAbs_Orientation
    from OCP.TopoDS import TopoDS, TopoDS_Iterator, TopoDS_Wire

    import tabletcad.tooling.interference as I
    from tabletcad.cad._occ import explore

    plane = Geom_Plane(gp_Pln(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)))
    face = BRepBuilderAPI_MakeFace(plane, 0.0, 1.0, 0.0, 1.0, 1e-7).Face()
    corner = next(v for v in explore(face, "Vertex") if BRep_Tool.Pnt_s(v).Distance(gp_Pnt(0, 0, 0)) < 1e-9)
    start = BRepBuilderAPI_MakeVertex(gp_Pnt(0, -0.5, 0)).Vertex()
    edge = BRepBuilderAPI_MakeEdge(Geom2d_Line(gp_Pnt2d(0, -0.5), gp_Dir2d(0, 1)), plane, start, corner, 0.0, 0.5).Edge()
    BRepLib.BuildCurves3d_s(edge)
    b, w = BRep_Builder(), TopoDS_Wire()
    b.MakeWire(w)
    it = TopoDS_Iterator(BRepTools.OuterWire_s(face))
    while it.More():
        b.Add(w, it.Value())
        it.Next()
    b.Add(w, edge.Oriented(TopAbs_Orientation.TopAbs_EXTERNAL))
    f2 = TopoDS.Face_s(face.EmptyCopied())
    b.Add(f2, w)
    assert BRepTools.UVBounds_s(f2)[2] == pytest.approx(-0.5)
    u0, u1, v0, v1 = BRepTools.UVBounds_s(f2)
    on = I._on_straight_sides(f2, np.linspace(u0, u1, 11), np.linspace(v0, v1, 13))
    assert on.any() and not on[:, np.linspace(v0, v1, 13) < -1e-9].any()
    P = I.face_samples(f2, spacing=0.1)
    assert len(P) > 50 and P[:, 1].min() >= -1e-9
