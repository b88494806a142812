"""A structured triangle mesh of a chain of B-spline faces, its deflection measured (numpy only).

The faces of a shaped tablet are a chain of B-spline surfaces: ``u`` runs across a
patch, ``v`` once around the outline, every surface has the same periodic ``v`` knots
and neighbours share their boundary pole rows bit for bit
(:func:`tabletcad.brep.fit.fit_patches`).  Such a chain needs no general surface
mesher: :func:`grid_mesh` lays a grid of parameter lines over each surface (one ``v``
node set for the whole chain, so a shared boundary row is one row of vertices), splits
every grid cell along its shorter diagonal and welds the rows that collapse to a point
(a cup's centre, a corner cupped to its radius).

The nodes follow the surfaces' geometry, sampled once on a fine grid (four steps per
knot span): along each parameter line the second difference of the points projected on
the surface normal (the sagitta a chord would have; the tangential part of a parametric
error is not a distance from the surface) and the tangent's turn, across a cell the
normal part of the twist ``S_uv``, which bends a cell's diagonal.  Each interval gets
the nodes that keep these within half the deflection and the turn within the
angular deflection.

The deflection is then *measured* on 25 parameter points of every cell (a 5 × 5
lattice: the corners, edge midpoints and 9 interior points of both triangles, a point on a
side shared with the neighbouring cell measured once; the largest
value raised by 1/15, what a triangle can hide between lattice points): with
``Δ`` from the surface point to the triangle point of the same parameters, ``n`` the
surface normal there and ``κ`` the surface's largest principal curvature, the distance
from that point of the mesh to the surface is at most about ``|n·Δ| + κ |Δ - (n·Δ) n|² / 2``
(the surface leaves its tangent plane by ``κ r² / 2`` at distance ``r``) while that
tangential step ``r`` is at most half the radius ``1/κ``; ``|Δ|`` itself (a distance to a
point of the surface, so a bound) where it is longer or the normal is undefined (a collapsed
row).  Until it is within the deflection the
densities grow by half (at most ``max_rounds`` times).

Arrays are components first, ``(3, nu, nv)``: dot and cross products are then sums of
contiguous planes.  Surfaces with the same knots share their collocation matrices
(:meth:`~tabletcad.brep.surface.BSplineSurfaceData.collocation`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from functools import lru_cache

import numpy as np

from tabletcad.brep.surface import BSplineSurfaceData
from tabletcad.brep.weld import is_closed, weld

__all__ = ["grid_mesh"]

# the interval criteria's share of the deflection: at a half, the sampled families measure
# 0.5-0.98 of the deflection (a quarter gave 0.3-0.5 with twice the triangles)
_SHARE = 0.5
_LATTICE = 4  # parameter steps per cell edge in the measurement
# the lattice's largest value is raised by this allowance: a quadratic error's maximum on a
# triangle (its circumcentre on a sphere-like face) can fall between lattice points, and on an
# equilateral triangle the lattice then sees 6.25 % less (found in review: the stadium 2.4 %,
# a sheared sphere 5.8 % above the lattice's figure, by OCC's projection and in closed form)
_LATTICE_ALLOWANCE = 16.0 / 15.0


def _subdivide(nodes: np.ndarray, k) -> np.ndarray:
    """``nodes`` with interval ``i`` cut into ``k[i]`` equal parts (``k >= 1``, or one count for
    all); ends kept exactly."""
    k = np.broadcast_to(np.asarray(k, dtype=np.int64), (len(nodes) - 1,))
    if np.all(k == 1):
        return nodes
    starts = np.repeat(nodes[:-1], k)
    widths = np.repeat(np.diff(nodes), k)
    j = np.arange(int(k.sum())) - np.repeat(np.cumsum(k) - k, k)
    out = np.empty(int(k.sum()) + 1)
    out[:-1] = starts + widths * (j / np.repeat(k, k))
    out[-1] = nodes[-1]
    return out


def _is_chain(surfaces: Sequence) -> bool | None:
    """True for a closed ring of surfaces, False for a chain between two pole rows, None if
    the surfaces are not a chain this mesher handles."""
    if not surfaces or not all(isinstance(s, BSplineSurfaceData) for s in surfaces):
        return None
    s0 = surfaces[0]
    for s in surfaces:
        if s.u_periodic or not s.v_periodic or s.v_degree != s0.v_degree:
            return None
        if s.u_mults[0] != s.u_degree + 1 or s.u_mults[-1] != s.u_degree + 1:
            return None  # not clamped in u: a shared end pole row is not a shared boundary row
        if not (np.array_equal(s.v_knots, s0.v_knots) and np.array_equal(s.v_mults, s0.v_mults)):
            return None
    for a, b in zip(surfaces[:-1], surfaces[1:]):
        if not np.array_equal(a.poles[-1], b.poles[0]):
            return None
    return bool(len(surfaces) > 1 and np.array_equal(surfaces[-1].poles[-1], s0.poles[0]))


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


class _Collocation:
    """Value and first-derivative collocation matrices (each computed once per knot vector and
    samples, and shared between surfaces: :data:`tabletcad.geometry.tables.COLLOCATION`)."""

    def __call__(self, s: BSplineSurfaceData, which: str, x: np.ndarray):
        return s.collocation(which, x), s.collocation(which, x, 1)


def _points_normals(s: BSplineSurfaceData, u: np.ndarray, v: np.ndarray, col: _Collocation):
    """Points and unit normals ``S_u × S_v`` on the grid ``u × v``, each ``(3, len(u), len(v))``,
    and where the normal is defined (not on a collapsed row, where the cross product vanishes)."""
    S, Su, Sv = s.grid_components(u, v, lambda which, x: col(s, which, x))
    N = np.empty_like(Su)  # the cross product written in place (no stacked copy)
    for c, (i, j) in enumerate(((1, 2), (2, 0), (0, 1))):
        np.subtract(Su[i] * Sv[j], Su[j] * Sv[i], out=N[c])
    size = np.sqrt(_dot(N, N))
    ok = size > 1e-9 * np.maximum(_dot(Su, Su), _dot(Sv, Sv))
    N /= np.where(ok, size, 1.0)
    return S, N, ok


def _normal_part(D: np.ndarray, N: np.ndarray, ok: np.ndarray) -> np.ndarray:
    """``|n·D|`` where the normal is defined, ``|D|`` elsewhere (components first)."""
    return np.where(ok, np.abs(_dot(D, N)), np.sqrt(_dot(D, D)))


def _needs(G: np.ndarray, N: np.ndarray, ok: np.ndarray, kinks: np.ndarray, target: float,
           angle: float) -> np.ndarray:
    """Nodes each interval of the fine lines ``G[:, :, k]`` (axis 1 along the lines) calls for,
    the largest over the lines.  A chord over ``H`` fine steps leaves the curve's middle by
    about ``|n·D2| H² / 8`` off the surface (``D2`` the second difference of the samples, ``n``
    the normal ``N``), so an interval needs ``sqrt(|n·D2| / (8 target))`` nodes, and
    ``turn / angle`` for the tangent's turn; neither is measured across a ``kinks`` node."""
    d = np.diff(G, axis=1)
    L = np.sqrt(_dot(d, d))
    sag = _normal_part(d[:, 1:] - d[:, :-1], N[:, 1:-1], ok[1:-1])
    good = (L[:-1] > 1e-9) & (L[1:] > 1e-9)
    cos = np.where(good, _dot(d[:, :-1], d[:, 1:]) / np.where(good, L[:-1] * L[1:], 1.0), 1.0)
    per_node = np.maximum(np.sqrt(sag / (8.0 * target)), np.arccos(np.clip(cos, -1.0, 1.0)) / angle)
    per_node[kinks[1:-1]] = 0.0  # a C0 knot is a node of its own: nothing measured across it
    need = np.zeros_like(L)
    need[:-1] = per_node
    np.maximum(need[1:], per_node, out=need[1:])
    return need.max(axis=1)


def _largest_curvature(G: np.ndarray, N: np.ndarray, ok: np.ndarray, u_kinks: np.ndarray,
                       v_kinks: np.ndarray) -> float:
    """Largest principal curvature (1/mm) on the fine grid, from finite-difference fundamental
    forms at its interior nodes (invariant to the steps' size), kinks and collapsed rows left out."""
    Gc = G[:, 1:-1, 1:-1]
    Su, Sv = 0.5 * (G[:, 2:, 1:-1] - G[:, :-2, 1:-1]), 0.5 * (G[:, 1:-1, 2:] - G[:, 1:-1, :-2])
    Suu, Svv = G[:, 2:, 1:-1] - 2 * Gc + G[:, :-2, 1:-1], G[:, 1:-1, 2:] - 2 * Gc + G[:, 1:-1, :-2]
    Suv = 0.25 * (G[:, 2:, 2:] - G[:, 2:, :-2] - G[:, :-2, 2:] + G[:, :-2, :-2])
    n = N[:, 1:-1, 1:-1]
    E, F, Gg = _dot(Su, Su), _dot(Su, Sv), _dot(Sv, Sv)
    L_, M_, N_ = _dot(Suu, n), _dot(Suv, n), _dot(Svv, n)
    det = E * Gg - F * F
    use = ok[1:-1, 1:-1] & (det > 1e-12 * np.maximum(E, Gg) ** 2)
    use &= ~u_kinks[1:-1, None] & ~v_kinks[None, 1:-1]
    if not np.any(use):
        return 0.0
    det = np.where(use, det, 1.0)
    H = (E * N_ - 2 * F * M_ + Gg * L_) / (2 * det)  # mean curvature
    K = (L_ * N_ - M_ * M_) / det  # Gaussian curvature
    k = np.abs(H) + np.sqrt(np.maximum(H * H - K, 0.0))
    return float(np.max(np.where(use, k, 0.0)))


def _fine(knots: np.ndarray, per_span: int) -> np.ndarray:
    """``per_span`` equal steps in every knot span (the knots included)."""
    return _subdivide(np.asarray(knots, dtype=float), per_span)


def _kinks(x: np.ndarray, knots: np.ndarray, mults: np.ndarray, degree: int) -> np.ndarray:
    """Whether each fine sample is an end or a knot of multiplicity >= ``degree`` (a C0 knot)."""
    c0 = np.asarray(knots, dtype=float)[np.asarray(mults) >= degree]
    k = np.isin(x, c0)
    k[0] = k[-1] = True
    return k


def _place(x: np.ndarray, need: np.ndarray, kinks: np.ndarray, density: float) -> np.ndarray:
    """Nodes equidistributed in the cumulative ``need`` (times ``density``) between consecutive
    kink nodes of the fine samples ``x``; the kinks and both ends kept exactly."""
    cuts = np.flatnonzero(kinks)
    out = [x[:1]]
    for a, b in zip(cuts[:-1], cuts[1:]):
        c = np.concatenate([[0.0], np.cumsum(need[a:b] * density)])
        n = max(1, int(math.ceil(c[-1] - 1e-9)))
        nodes = np.interp(np.linspace(0.0, c[-1], n + 1), c, x[a:b + 1]) if c[-1] > 0 else np.array([x[a], x[b]])
        nodes[-1] = x[b]
        out.append(nodes[1:])
    return np.concatenate(out)


def _per_interval(fine: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    """Nodes per fine interval: each fine interval's length over that of the node interval holding it."""
    mid = 0.5 * (fine[:-1] + fine[1:])
    k = np.clip(np.searchsorted(nodes, mid) - 1, 0, len(nodes) - 2)
    return np.diff(fine) / np.diff(nodes)[k]


class _Nodes:
    """The node densities of a chain, measured once on fine samples (``per_span`` steps per knot
    span): :meth:`place` gives per-surface ``u`` nodes and the chain's ``v`` nodes for a density.

    A cell's triangles also miss the surface by the twist, about ``|n·S_uv| H_u H_v / 4`` at
    the middle of its diagonal: with the ``v`` nodes placed, each ``u`` interval gets the
    nodes that keep that within the target (``u`` nodes are the cheap ones: ``v`` nodes run
    round every surface of the chain)."""

    def __init__(self, surfaces: Sequence[BSplineSurfaceData], deflection: float, angle: float,
                 col: _Collocation, per_span: int = 4) -> None:
        self.target = _SHARE * deflection
        s0 = surfaces[0]
        self.v = _fine(s0.v_knots, per_span)
        self.v_kinks = _kinks(self.v, s0.v_knots, s0.v_mults, s0.v_degree)
        self.u, self.u_kinks, self.u_need, self.twist, self.curvature = [], [], [], [], []
        v_need = np.zeros(len(self.v) - 1)
        for s in surfaces:
            u = _fine(s.u_knots, per_span)
            kinks = _kinks(u, s.u_knots, s.u_mults, s.u_degree)
            G, N, ok = _points_normals(s, u, self.v, col)
            self.u.append(u)
            self.u_kinks.append(kinks)
            self.u_need.append(_needs(G, N, ok, kinks, self.target, angle))
            vt = (G.transpose(0, 2, 1), N.transpose(0, 2, 1), ok.T)
            np.maximum(v_need, _needs(*vt, self.v_kinks, self.target, angle), out=v_need)
            # a cell's normal: the sum of its corners' defined unit normals (a cell on a collapsed
            # row has one or two; only a cell with none falls back to the whole twist)
            Nc = sum(np.where(ok[a, b], N[:, a, b], 0.0) for a, b in (
                (np.s_[:-1], np.s_[:-1]), (np.s_[1:], np.s_[:-1]), (np.s_[:-1], np.s_[1:]), (np.s_[1:], np.s_[1:])))
            size = np.sqrt(_dot(Nc, Nc))
            twist = G[:, 1:, 1:] - G[:, 1:, :-1] - G[:, :-1, 1:] + G[:, :-1, :-1]
            self.twist.append(_normal_part(twist, Nc / np.maximum(size, 1e-300), size > 0.5))
            self.curvature.append(_largest_curvature(G, N, ok, kinks, self.v_kinks))
        self.v_need = v_need

    def place(self, density: float) -> tuple[list[np.ndarray], np.ndarray]:
        v = _place(self.v, self.v_need, self.v_kinks, density)
        n_v = _per_interval(self.v, v)
        us = []
        for u, need, kinks, twist in zip(self.u, self.u_need, self.u_kinks, self.twist):
            twist_need = (twist / (4.0 * self.target * n_v)).max(axis=1) * density ** 2
            us.append(_place(u, np.maximum(need * density, twist_need), kinks, 1.0))
        return us, v


def _assemble(surfaces, us, v, ring: bool, col: _Collocation):
    """Vertices ``(3, n)`` before welding (row ``r``'s vertex ``k`` at ``r m + k``), per-surface
    global row indices, and ``m`` (vertices per row: the period's ``v`` nodes but the last)."""
    m = len(v) - 1
    rows, row_ids, r = [], [], 0
    for j, s in enumerate(surfaces):
        (Bu, _), (Bv, _) = col(s, "u", us[j]), col(s, "v", v)
        P = (Bu @ np.ascontiguousarray(s.poles.transpose(2, 0, 1))) @ Bv[:-1].T  # (3, rows, m)
        ids = list(range(r, r + len(us[j])))
        if j > 0:  # this surface's first row is the previous surface's last
            ids = [row_ids[-1][-1]] + ids[:-1]
            P = P[:, 1:]
        if ring and j == len(surfaces) - 1:  # and the ring's last row is the first surface's first
            ids[-1] = 0
            P = P[:, :-1]
        rows.append(P.reshape(3, -1))
        row_ids.append(ids)
        r += P.shape[1]
    return np.concatenate(rows, axis=1), [np.asarray(ids, dtype=np.int64) for ids in row_ids], m


def _cells(V: np.ndarray, ids: np.ndarray, m: int):
    """Corner indices ``(i00, i10, i01, i11)``, each ``(nu - 1, m)``, of one surface's cells and
    whether each is cut along its ``(0, 0)-(1, 1)`` diagonal (the shorter one)."""
    col = np.arange(m)
    nxt = (col + 1) % m
    i00, i10 = ids[:-1, None] * m + col, ids[1:, None] * m + col
    i01, i11 = ids[:-1, None] * m + nxt, ids[1:, None] * m + nxt
    d1, d2 = V[:, i11] - V[:, i00], V[:, i01] - V[:, i10]
    return (i00, i10, i01, i11), _dot(d1, d1) <= _dot(d2, d2)


def _lattice_weights(s_: np.ndarray, t: np.ndarray, diag: np.ndarray) -> tuple[np.ndarray, ...]:
    """Weights of the corners ``P00, P10, P01, P11`` of a cell at its local parameters ``(s_, t)``
    (in [0, 1]) on the triangle holding that point, for a cell cut along ``P00-P11`` (``diag``) or
    along ``P10-P01``; arrays broadcast together."""
    z = np.zeros(np.broadcast_shapes(s_.shape, t.shape, diag.shape))
    lo = s_ >= t
    up = s_ + t <= 1
    w00 = np.where(diag, np.where(lo, 1 - s_, 1 - t), np.where(up, 1 - s_ - t, z))
    w10 = np.where(diag, np.where(lo, s_ - t, z), np.where(up, s_, 1 - t))
    w01 = np.where(diag, np.where(lo, z, t - s_), np.where(up, t, 1 - s_))
    w11 = np.where(diag, np.where(lo, t, s_), np.where(up, z, s_ + t - 1))
    return w00, w10, w01, w11


def _lattice_cells(n_cells: int, n: int) -> tuple[np.ndarray, np.ndarray]:
    """For each of the ``n n_cells + 1`` lattice lines across ``n_cells`` cells (``n`` steps a cell),
    its cell and its step in that cell (``0..n``; a line between two cells goes to the later one,
    the last line to the last cell)."""
    k = np.arange(n * n_cells + 1)
    cell = np.minimum(k // n, n_cells - 1)
    return cell, k - n * cell


@lru_cache(maxsize=4)
def _lattice_table(n: int) -> tuple[np.ndarray, ...]:
    """:func:`_lattice_weights` of every step ``(a, b)`` of an ``n``-step lattice in a cell, for both
    diagonals: four read-only ``(2, n + 1, n + 1)`` arrays (the same for every surface and round: made once)."""
    steps = np.arange(n + 1) / n
    table = _lattice_weights(steps[None, :, None], steps[None, None, :], np.array([False, True])[:, None, None])
    for w in table:
        w.setflags(write=False)
    return table


def _cell_deviation(s: BSplineSurfaceData, u: np.ndarray, v: np.ndarray, V: np.ndarray, corners, diag,
                    curvature: float, col: _Collocation) -> np.ndarray:
    """Distance (mm) from the triangles to the surface, estimated at every point of the lattice of
    ``_LATTICE`` steps per cell edge over the whole surface (module docstring; ``curvature`` the
    surface's largest): ``(n nu1 + 1, n m + 1)``, the caller takes the largest.  A lattice point on
    a cell's side is measured once, in one of the cells it bounds: both triangulations agree there
    (along a side the triangles are linear between its two vertices).  This is the per-cell
    ``(_LATTICE + 1)²`` lattice with its shared points taken once, 16 points a cell instead of 25, and
    the surface's points and normals on it used in place (no gathered copies)."""
    n = _LATTICE
    S, Nrm, ok = _points_normals(s, _subdivide(u, n), _subdivide(v, n), col)
    nu1, m = diag.shape
    ci, a = _lattice_cells(nu1, n)
    cj, b = _lattice_cells(m, n)

    def spread(x: np.ndarray) -> np.ndarray:
        """Per-cell values ``(..., nu1, m)`` at every lattice point of their cells: one take along each
        axis (a two-dimensional index over the whole lattice took three times as long)."""
        return x.take(cj, axis=-1).take(ci, axis=-2)

    # the weights depend only on a point's steps (a, b) in its cell and the cell's diagonal: a table of
    # the 2 (n + 1)² values (_lattice_weights' own arithmetic on the same numbers), taken at each point
    table = _lattice_table(n)
    code = spread(diag.astype(np.intp)) * (n + 1) ** 2 + (a[:, None] * (n + 1) + b[None, :])
    M = None  # (3, n nu1 + 1, n m + 1): the weighted corners, summed in place (the same sums, fewer arrays)
    for w, idx in zip(table, corners):
        term = spread(V[:, idx])
        term *= w.ravel().take(code)
        if M is None:
            M = term
            M += 0.0  # (as sum() did, from 0: 0 + x, a -0.0 made +0.0)
        else:
            M += term
    D = np.subtract(M, S, out=M)  # (M is this function's own array)
    h = _dot(D, Nrm)
    dd = _dot(D, D)
    tang = np.maximum(dd - h * h, 0.0)
    # the tangent-plane estimate holds while the step along the surface is small against its radius
    # of curvature; beyond that (very coarse deflections on a distorted parametrisation) |Δ| itself
    near = ok & (curvature * curvature * tang <= 0.25)
    est = np.where(near, np.abs(h) + 0.5 * curvature * tang, np.sqrt(dd))
    return _LATTICE_ALLOWANCE * est


def grid_mesh(surfaces: Sequence[BSplineSurfaceData], deflection: float, angle: float, *,
              max_rounds: int = 4, weld_tol: float = 1e-7):
    """A closed, welded, outward triangle mesh of a chain of B-spline faces, or None.

    Parameters
    ----------
    surfaces : the chain (surface ``j``'s ``u`` end row is surface ``j + 1``'s ``u`` start row,
        bit for bit; every ``v`` periodic with the same knots), a ring or closed by pole rows.
    deflection : largest distance (mm) from the mesh to the surfaces, measured.
    angle : largest turn (rad) of a surface's tangent along one cell edge, estimated.
    max_rounds : rounds of growing the densities while the measured deviation exceeds ``deflection``.

    Returns
    -------
    ``(V (n, 3), T (t, 3) int, measured)`` with ``measured`` the largest deviation found (mm),
    or None when the surfaces are not such a chain, the deflection is not reached in
    ``max_rounds`` or the welded mesh is not closed: the caller then meshes the B-rep.
    """
    if deflection <= 0 or angle <= 0:
        raise ValueError("deflection and angle must be > 0")
    ring = _is_chain(surfaces)
    if ring is None:
        return None
    col = _Collocation()
    nodes = _Nodes(surfaces, deflection, angle, col)
    density, measured, before = 1.0, math.inf, math.inf
    for _ in range(max_rounds + 1):
        us, v = nodes.place(density)
        V, row_ids, m = _assemble(surfaces, us, v, ring, col)
        tris, measured = [], 0.0
        for j, s in enumerate(surfaces):
            corners, diag = _cells(V, row_ids[j], m)
            dev = _cell_deviation(s, us[j], v, V, corners, diag, nodes.curvature[j], col)
            measured = max(measured, float(dev.max()))
            d = diag.ravel()[:, None]
            a, b, c, e = (x.ravel() for x in corners)
            tris.append(np.where(d, np.column_stack([a, b, e]), np.column_stack([a, b, c])))
            tris.append(np.where(d, np.column_stack([a, e, c]), np.column_stack([b, e, c])))
        if measured <= deflection:
            Vw, Tw = weld(np.ascontiguousarray(V.T), np.concatenate(tris), weld_tol)
            if not is_closed(Tw):
                return None
            p, q, r = Vw[Tw[:, 0]], Vw[Tw[:, 1]], Vw[Tw[:, 2]]
            if float(np.einsum("ij,ij->i", p, np.cross(q, r)).sum()) < 0.0:
                Tw = np.ascontiguousarray(Tw[:, ::-1])
            return Vw, Tw, measured
        if measured > 0.7 * before:  # 1.5 times the density cuts a smooth face's deviation to 1/2.25; this one
            return None  # barely moved (a fold or a kink inside a cell: a shaped cut-away's cut faces): give up
        before = measured
        density *= 1.5
    return None  # the deflection not reached (e.g. rows shared by unclamped surfaces): the caller meshes the B-rep
