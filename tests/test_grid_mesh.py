"""The structured mesh of a chain of B-spline faces (tabletcad.brep.grid_mesh) and the weld.

numpy only: the chains are fitted here from the family samples' PDE patches
(``tabletcad.brep.fit.fit_patches``, as the CAD stage does).  Checked against the exact
volume and area of the B-spline faces (Gauss-Legendre, ``volume_and_area``): a closed
mesh within chord height ``δ`` of surfaces of area ``A`` encloses a volume within
``δ A`` of theirs, and its error falls in proportion to ``δ`` (chords of length
``h ∝ sqrt(δ)`` miss by ``O(h²)``).  The distances to the faces measured by OpenCascade
are in ``tests/test_grid_mesh_cad.py``.
"""

from __future__ import annotations

from dataclasses import replace
from functools import lru_cache
from pathlib import Path

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from tabletcad.brep.fit import fit_patches
from tabletcad.brep.grid_mesh import grid_mesh
from tabletcad.brep.surface import volume_and_area
from tabletcad.brep.surfaces import fit_options, tablet_surface_functions
from tabletcad.brep.weld import is_closed, weld
from tabletcad.pipeline.design import load_design

FAMILIES = Path(__file__).resolve().parents[1] / "samples" / "families"
SHAPED = ["capsule", "rounded_rectangle", "rounded_triangle", "custom_outline", "almond", "oval"]


@lru_cache(maxsize=None)
def chain(name: str):
    """The fitted B-spline surfaces of a family sample's solid (the CAD stage's fit); ``name``
    relative to ``samples/families``."""
    tablet = load_design(FAMILIES / f"{name}.toml")
    funcs, names = tablet_surface_functions(tablet)
    fits = fit_patches(funcs, tablet.tol.fit, names=names, **fit_options(tablet))
    return tuple(f.surface for f in fits)


def signed_volume_area(V, T):
    a, b, c = V[T[:, 0]], V[T[:, 1]], V[T[:, 2]]
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6), float(0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1).sum())


# ------------------------------------------------------------------------------------------- weld


def octahedron():
    V = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], dtype=float)
    T = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])
    return V, T


def test_weld_merges_coincident_nodes_and_is_closed_tells_a_closed_surface():
    V, T = octahedron()
    assert is_closed(T)
    # every triangle with its own three nodes (a soup), nodes moved by less than the tolerance
    soup = V[T].reshape(-1, 3) + 1e-9 * np.random.default_rng(1).standard_normal((24, 3))
    Vw, Tw = weld(soup, np.arange(24).reshape(8, 3), 1e-7)
    assert Vw.shape == (6, 3) and is_closed(Tw)
    assert signed_volume_area(Vw, Tw)[0] == pytest.approx(4 / 3, rel=1e-7)
    assert not is_closed(T[1:])  # a hole
    assert not is_closed(np.vstack([T, T[:1]]))  # a fin: one edge in three triangles
    flipped = T.copy()
    flipped[0] = flipped[0, ::-1]
    assert not is_closed(flipped)  # one triangle wound the wrong way
    # a triangle whose nodes merge is dropped
    V2 = np.vstack([V, V[0] + 1e-9])
    Vw, Tw = weld(V2, np.vstack([T, [[0, 6, 2]]]), 1e-7)
    assert len(Tw) == 8 and is_closed(Tw)


# ------------------------------------------------------------------------------------------- mesh


@pytest.mark.parametrize("name", SHAPED)
def test_shaped_family_mesh_is_closed_outward_and_within_its_deflection(name):
    surfaces = chain(name)
    deflection, angle = 0.005, 0.2
    V, T, measured = grid_mesh(surfaces, deflection, angle)
    assert is_closed(T)
    assert 0.0 < measured <= deflection
    vol = signed_volume_area(V, T)[0]
    exact_vol, exact_area = volume_and_area(surfaces)
    assert vol > 0.0
    # chords lie inside a convex surface: within δ·A below its volume
    assert abs(vol - abs(exact_vol)) <= deflection * exact_area


def test_volume_error_falls_in_proportion_to_the_deflection():
    surfaces = chain("oval")
    exact = abs(volume_and_area(surfaces)[0])
    errors = []
    for d in (0.04, 0.01, 0.0025):
        V, T, _ = grid_mesh(surfaces, d, 1.0)  # the chord height alone sets the nodes
        errors.append(exact - signed_volume_area(V, T)[0])
    assert all(e > 0 for e in errors)  # chords inside the convex oval
    rates = [errors[k] / errors[k + 1] for k in range(2)]
    # quartering the chord height quarters the error (second order in the node spacing)
    assert all(2.5 <= r <= 6.5 for r in rates), rates


@settings(max_examples=12)
@given(deflection=st.floats(0.002, 0.05), angle=st.floats(0.1, 0.8), name=st.sampled_from(["oval", "capsule", "rounded_triangle"]))
def test_any_deflection_is_met_and_bounds_the_volume(deflection, angle, name):
    surfaces = chain(name)
    V, T, measured = grid_mesh(surfaces, deflection, angle)
    assert is_closed(T) and measured <= deflection
    exact_vol, exact_area = volume_and_area(surfaces)
    assert 0.0 <= abs(exact_vol) - signed_volume_area(V, T)[0] <= deflection * exact_area


def test_a_smaller_angle_alone_adds_nodes():
    surfaces = chain("oval")
    n_fine = len(grid_mesh(surfaces, 0.05, 0.05)[1])
    n_coarse = len(grid_mesh(surfaces, 0.05, 1.0)[1])
    assert n_fine > 4 * n_coarse  # the angle, not the chord height, sets the nodes at 0.05 rad


def test_a_ring_of_faces_closes_on_itself_with_genus_one():
    surfaces = chain("../ring")  # the hollow ring tablet as four B-spline faces: walls and end faces
    V, T, measured = grid_mesh(surfaces, 0.005, 0.2)
    assert len(surfaces) == 4 and is_closed(T) and measured <= 0.005
    edges = {tuple(sorted(e)) for e in np.vstack([T[:, [0, 1]], T[:, [1, 2]], T[:, [2, 0]]]).tolist()}
    assert len(V) - len(edges) + len(T) == 0  # Euler characteristic 2 - 2g with g = 1
    exact_vol, exact_area = volume_and_area(surfaces)
    assert 0.0 <= abs(exact_vol) - signed_volume_area(V, T)[0] <= 0.005 * exact_area


def test_surfaces_that_are_not_one_chain_are_left_to_the_caller():
    surfaces = chain("oval")
    assert grid_mesh(surfaces[:2], 0.005, 0.2) is None  # ends on an open row: the weld leaves a hole
    k = surfaces[1].v_knots
    shifted = replace(surfaces[1], v_knots=np.concatenate([k[:1], k[1:-1] + 1e-6, k[-1:]]))
    assert grid_mesh((surfaces[0], shifted, *surfaces[2:]), 0.005, 0.2) is None  # v knots differ
    moved = replace(surfaces[1], poles=surfaces[1].poles + np.array([0.0, 0.0, 1e-12]))
    assert grid_mesh((surfaces[0], moved, *surfaces[2:]), 0.005, 0.2) is None  # rows not shared bit for bit
    # unclamped in u: the end pole rows are not the boundary rows
    knots, mults = surfaces[1].u_knots, surfaces[1].u_mults
    unclamped = replace(surfaces[1], u_knots=np.concatenate([[knots[0] - 0.1], knots, [knots[-1] + 0.1]]),
                        u_mults=np.concatenate([[1], mults - np.eye(len(mults), dtype=int)[[0, -1]].sum(0), [1]]))
    assert grid_mesh((surfaces[0], unclamped, *surfaces[2:]), 0.005, 0.2) is None
    with pytest.raises(ValueError):
        grid_mesh(surfaces, 0.0, 0.2)


@lru_cache(maxsize=None)
def sphere(distortion: float, radius: float = 5.0):
    """A sphere fitted as one B-spline patch between its poles, ``v`` distorted to
    ``φ = v + distortion sin v`` (the parametrisation, not the surface)."""
    from tabletcad.brep.fit import fit_surface

    def f(u, v):
        u, v = np.broadcast_arrays(np.asarray(u, float), np.asarray(v, float))
        th, ph = np.pi * u, v + distortion * np.sin(v)
        return radius * np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), -np.cos(th)], -1)

    fit = fit_surface(f, 5, 5, 17, 32, True, 1e-6, max_nu=200, max_nv=300)
    return (fit.surface,), fit.max_deviation


@settings(max_examples=25)
@example(distortion=0.95, deflection=0.5, angle=1.5)
@given(distortion=st.sampled_from([0.0, 0.5, 0.95]), deflection=st.floats(0.002, 0.5), angle=st.floats(0.1, 1.5))
def test_distance_to_a_sphere_is_within_the_measured_deflection(distortion, deflection, angle):
    """Closed form: a point's distance to the sphere is ``| |p| - R |``.  Every point of a 9 × 9
    barycentric lattice of every triangle stays within the measured figure (plus the fit's
    deviation), also at coarse deflections on a strongly distorted parametrisation, where the
    tangent-plane estimate alone fell short (2.3 × the deflection at 0.5 mm / 1.5 rad)."""
    surfaces, fit_dev = sphere(distortion)
    V, T, measured = grid_mesh(surfaces, deflection, angle)
    assert is_closed(T) and measured <= deflection
    k = 8
    i, j = np.meshgrid(np.arange(k + 1), np.arange(k + 1), indexing="ij")
    keep = i + j <= k
    w = np.stack([i[keep], j[keep], k - i[keep] - j[keep]], axis=1) / k  # (points, 3)
    # the lattice points coordinate by coordinate, (triangles, points) each, and |P| from their squares:
    # the same sums in the same order as einsum("pc,tcx->tpx") and norm(axis=-1) (bit for bit, checked
    # on 15 meshes under numpy 2.4 and 1.24), in a third of the time
    A = V[T]
    P = [w[:, 0] * A[:, 0, x, None] + w[:, 1] * A[:, 1, x, None] + w[:, 2] * A[:, 2, x, None] for x in range(3)]
    dist = np.abs(np.sqrt(P[0] * P[0] + P[1] * P[1] + P[2] * P[2]) - 5.0)
    assert dist.max() <= measured + fit_dev + 1e-12


def test_a_deflection_not_reached_leaves_the_mesh_to_the_caller(monkeypatch):
    import tabletcad.brep.grid_mesh as gm

    monkeypatch.setattr(gm, "_cell_deviation", lambda *a, **k: np.full(a[5].shape, 1.0))  # never within 0.005
    assert gm.grid_mesh(chain("oval"), 0.005, 0.2, max_rounds=1) is None


@pytest.mark.parametrize("name", ["oval", "rounded_triangle"])
def test_the_measured_deviation_is_the_largest_on_every_cell_s_own_lattice(name):
    """The measurement takes each lattice point shared by neighbouring cells once (16 points a cell):
    its largest value is the largest over every cell's own 5 x 5 lattice with the surface evaluated
    point by point (the triangles agree along a cell's sides), to rounding."""
    import tabletcad.brep.grid_mesh as gm

    surfaces = chain(name)
    col = gm._Collocation()
    nodes = gm._Nodes(surfaces, 0.005, 0.2, col)
    us, v = nodes.place(1.0)
    V, row_ids, m = gm._assemble(surfaces, us, v, gm._is_chain(surfaces), col)
    n = gm._LATTICE
    for j in (0, len(surfaces) // 2):
        s, u = surfaces[j], us[j]
        corners, diag = gm._cells(V, row_ids[j], m)
        got = float(gm._cell_deviation(s, u, v, V, corners, diag, nodes.curvature[j], col).max())
        a, b = (x.ravel() / n for x in np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij"))
        worst = 0.0
        for i in range(diag.shape[0]):
            uu = u[i] + a * (u[i + 1] - u[i])
            vv = v[:-1, None] + b[None, :] * np.diff(v)[:, None]  # (m, 25)
            UU = np.broadcast_to(uu, vv.shape)
            S, Su, Sv = (s.evaluate(UU, vv, du, dv) for du, dv in ((0, 0), (1, 0), (0, 1)))
            N = np.cross(Su, Sv)
            size = np.linalg.norm(N, axis=-1)
            ok = size > 1e-9 * np.maximum((Su * Su).sum(-1), (Sv * Sv).sum(-1))
            N = N / np.where(ok, size, 1.0)[..., None]
            lo, up = a >= b, a + b <= 1
            lower = np.where(lo, [1 - a, a - b, 0 * a, b], [1 - b, 0 * a, b - a, a]).T  # (25, 4)
            upper = np.where(up, [1 - a - b, a, b, 0 * a], [0 * a, 1 - b, 1 - a, a + b - 1]).T
            w = np.where(diag[i][:, None, None], lower[None], upper[None])  # (m, 25, 4)
            M = sum(w[..., c, None] * V.T[corners[c][i]][:, None, :] for c in range(4))
            D = M - S
            h = (D * N).sum(-1)
            dd = (D * D).sum(-1)
            tang = np.maximum(dd - h * h, 0.0)
            k = nodes.curvature[j]
            near = ok & (k * k * tang <= 0.25)
            worst = max(worst, float(np.max(np.where(near, np.abs(h) + 0.5 * k * tang, np.sqrt(dd)))))
        assert got == pytest.approx(gm._LATTICE_ALLOWANCE * worst, rel=1e-9)


def _triangle_points(P00, P10, P01, P11, s_, t, diag):
    """The points at a cell's local parameters ``(s_, t)`` on the triangles the mesh makes of it, by the
    affine map of each triangle: cut along ``P00-P11`` (``diag``) into ``(P00, P10, P11)`` (``s_ >= t``) and
    ``(P00, P11, P01)``, else into ``(P00, P10, P01)`` (``s_ + t <= 1``) and ``(P10, P11, P01)``."""
    on_diag = np.where(s_ >= t, P00 + s_ * (P10 - P00) + t * (P11 - P10), P00 + t * (P01 - P00) + s_ * (P11 - P01))
    across = np.where(s_ + t <= 1.0, P00 + s_ * (P10 - P00) + t * (P01 - P00),
                      P11 + (1.0 - s_) * (P01 - P11) + (1.0 - t) * (P10 - P11))
    return np.where(diag, on_diag, across)


def test_the_deviation_is_measured_on_the_triangles_the_mesh_makes(monkeypatch):
    """Every lattice point's deviation is the surface's distance estimate from the point at the same local
    parameters on the triangle the mesh actually makes of its cell (the diagonal ``grid_mesh`` chooses),
    recomputed here by each triangle's affine map: a measurement on the other diagonal's triangles (its
    weights swapped) differs on the rounded triangle's cells and fails."""
    import tabletcad.brep.grid_mesh as gm

    calls = []
    measure = gm._cell_deviation

    def recorded(s, u, v, V, corners, diag, curvature, col):
        dev = measure(s, u, v, V, corners, diag, curvature, col)
        calls.append((s, u, v, V, corners, diag, curvature, col, dev))
        return dev

    monkeypatch.setattr(gm, "_cell_deviation", recorded)
    assert grid_mesh(chain("rounded_triangle"), 0.02, 0.5) is not None
    n = gm._LATTICE
    swapped_off = 0.0
    for s, u, v, V, (i00, i10, i01, i11), diag, curvature, col, dev in calls:
        S, N, ok = gm._points_normals(s, gm._subdivide(u, n), gm._subdivide(v, n), col)
        nu1, m = diag.shape
        ku, kv = np.arange(n * nu1 + 1), np.arange(n * m + 1)
        ci, cj = np.minimum(ku // n, nu1 - 1)[:, None], np.minimum(kv // n, m - 1)[None, :]
        s_, t = ((ku - n * ci[:, 0]) / n)[:, None], ((kv - n * cj[0]) / n)[None, :]
        P = [V[:, idx[ci, cj]] for idx in (i00, i10, i01, i11)]

        def estimate(cut):
            D = _triangle_points(*P, s_, t, cut) - S
            h, dd = np.einsum("i...,i...->...", D, N), np.einsum("i...,i...->...", D, D)
            tang = np.maximum(dd - h * h, 0.0)
            near = ok & (curvature * curvature * tang <= 0.25)
            return gm._LATTICE_ALLOWANCE * np.where(near, np.abs(h) + 0.5 * curvature * tang, np.sqrt(dd))

        cut = diag[ci, cj]
        # (the affine maps round differently from the weights: ~1e-15 mm on coordinates of a few mm)
        np.testing.assert_allclose(dev, estimate(cut), rtol=1e-9, atol=1e-12)
        swapped_off = max(swapped_off, float(np.abs(estimate(~cut) - dev).max()))
    assert len(calls) >= 9 and swapped_off > 1e-6, swapped_off
