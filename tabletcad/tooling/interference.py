"""Do the punches and the die enclose exactly the tablet at the closed position?

* overlap: the volume common to every pair of parts (tablet, upper punch,
  lower punch, die), by OCC (``BRepAlgoAPI_Common``, exact) and by manifold3d
  on meshes (``^``); touching parts share surfaces, so the mesh figure is
  bounded by the chord height times the shared area, not zero (each punch's mesh is first moved
  :data:`MANIFOLD_LIFT_MM` away from the tablet's, off their coincident cup triangles, and the bound
  grows by what that move can change, :func:`lift_allowance`); parts that need not touch are
  proved apart by an exact minimum distance (``BRepExtrema_DistShapeShape``) or, when their
  bounding boxes are already apart (the two punches), by the boxes' distance; the tablet and the
  die, given the die's bore, by two exact Commons without the die's taper (:func:`inside_bore`);
* gap: the largest distance from the tablet's surface to the nearest part.
  Points on every face of the finished tablet (its mesh vertices, its PDE
  patches sampled densely, and a grid inside every B-rep face: letter walls
  and score flanks have no mesh vertices inside them) are measured against the parts' meshes (exact
  point-to-triangle distances, libigl's AABB tree);
  the worst points are re-measured exactly on the B-reps (:class:`ExactDistance`: the
  vertex-to-shape extrema of ``BRepExtrema_DistShapeShape``, each face's solver set up once).  It should not exceed the radial clearance
  (the ring between the punch tip and the die wall).
"""

from __future__ import annotations

import itertools
import math
import time

import numpy as np
from OCP.BRepExtrema import BRepExtrema_DistShapeShape

from tabletcad.cad._occ import explore
from tabletcad.errors import GeometryError
from tabletcad.geometry.tablet import coordinate_range
from tabletcad.io.forked import OCC_PARALLEL
from tabletcad.tooling.booleans import (bound_area, box_solid, mesh_arrays, mesh_face_ids, manifold_op, manifold_volume,
                                        raw_boolean, to_manifold, volume)
from tabletcad.tolerance import DEFAULT
from tabletcad.tooling.outline import face_area, prism
from tabletcad.tooling.spec import MIN_BORE_OFFSET_MM

__all__ = ["interference", "inside_bore", "MeshDistance", "mesh_distance", "largest_inside", "ExactDistance"]


def refine_triangles(V: np.ndarray, T: np.ndarray, h: float, lo=None, hi=None) -> tuple[np.ndarray, np.ndarray]:
    """Split triangles at the midpoint of their longest edge until every edge is <= ``h``; triangles
    whose box misses the box ``[lo, hi]`` are dropped first (they cannot be nearest)."""
    A, B, C = V[T[:, 0]], V[T[:, 1]], V[T[:, 2]]
    tris = np.stack([A, B, C], axis=1)
    out = []
    for _ in range(40):
        if lo is not None:
            tmin, tmax = tris.min(axis=1), tris.max(axis=1)
            tris = tris[np.all((tmax >= lo) & (tmin <= hi), axis=1)]
        e = np.stack([np.linalg.norm(tris[:, 1] - tris[:, 0], axis=1), np.linalg.norm(tris[:, 2] - tris[:, 1], axis=1),
                      np.linalg.norm(tris[:, 0] - tris[:, 2], axis=1)], axis=1)
        long = e.max(axis=1) > h
        out.append(tris[~long])
        tris = tris[long]
        if not len(tris):
            break
        k = np.argmax(e[long], axis=1)  # edge k joins vertex k and k+1
        i0, i1, i2 = k, (k + 1) % 3, (k + 2) % 3
        r = np.arange(len(tris))
        a, b, c = tris[r, i0], tris[r, i1], tris[r, i2]
        m = 0.5 * (a + b)
        tris = np.concatenate([np.stack([a, m, c], axis=1), np.stack([m, b, c], axis=1)])
    allt = np.concatenate(out + [tris]) if out else tris
    return allt.reshape(-1, 3), np.arange(len(allt) * 3).reshape(-1, 3)


class MeshDistance:
    """Exact distance (mm) from points to one triangle mesh ``(V, T)``; ``inf`` beyond ``reach``.

    libigl's AABB tree of the triangles (built once; exact point-to-triangle distances
    in C++), asked only for the points within ``reach``: a point outside every cell of
    :class:`_ReachCells` (a grid of cubes marking each triangle's box grown by ``reach``)
    is farther than ``reach`` from every triangle (an AABB search far from the mesh is slow).
    Agrees with a brute-force minimum over all triangles to rounding
    (``tests/test_tooling_gap_distance.py``).
    """

    def __init__(self, V: np.ndarray, T: np.ndarray, reach: float = np.inf) -> None:
        import igl

        self.V = np.ascontiguousarray(V, dtype=float)
        self.T = np.ascontiguousarray(T, dtype=np.int64).reshape(-1, 3)
        self.reach = float(reach)
        self.tree = None
        self.cells = None
        if len(self.T):
            self.tree = igl.AABB()
            self.tree.init(self.V, self.T)
            if math.isfinite(self.reach):
                self.cells = _ReachCells(self.V, self.T, self.reach)

    def __call__(self, points: np.ndarray, closest: bool = False):
        """Distances (mm) of ``points``: exact within ``reach``, ``inf`` beyond it.  With ``closest``,
        also the mesh's point nearest to each point (NaN where the distance is ``inf``)."""
        P = np.ascontiguousarray(points, dtype=float).reshape(-1, 3)
        out = np.full(len(P), np.inf)
        Q = np.full((len(P), 3), np.nan) if closest else None
        if not len(P) or self.tree is None:
            return (out, Q) if closest else out
        # a point outside the cells is farther than reach: its answer is inf whether measured or not
        near = np.arange(len(P)) if self.cells is None else np.flatnonzero(self.cells(P))
        if len(near):
            d2, _, C = self.tree.squared_distance(self.V, self.T, np.ascontiguousarray(P[near]))
            out[near] = np.sqrt(np.maximum(d2, 0.0))
            if closest:
                Q[near] = C
        far = out > self.reach
        out[far] = np.inf  # the same answer whatever the triangles' size
        if closest:
            Q[far] = np.nan
            return out, Q
        return out


class _ReachCells:
    """Which points may lie within ``reach`` (mm) of a triangle of ``(V, T)``: the cells of a regular grid of
    cubes that meet some triangle's bounding box grown by ``reach``.

    A point within ``reach`` of a triangle lies in that triangle's grown box, so in a marked cell; a point in
    no marked cell (or outside the grid) is farther than ``reach`` from every triangle.  The boxes are grown
    by ``reach (1 + 1e-9)``: far more than the rounding of the box corners and of the cell indices, which are
    monotonic in the coordinates (each a correctly rounded difference and quotient, then ``floor``), so a
    point within ``reach (1 + 1e-9)`` is never dropped.  The cubes' side is ``reach / CELLS_PER_REACH`` but
    the grid keeps at most :data:`MAX_CELLS` cells (larger cubes then).  The marks are counted by a
    difference array: ``+-1`` at each box's eight corner cells, then running sums along the three axes.

    Replaces a k-d tree of the triangles' centres (the nearest centre farther than ``reach`` plus the
    largest centre-to-corner radius): on the gap's tools that screen cost 0.77 us a point and passed
    points up to 0.74 mm away (1 mm triangles), this one about 0.03 us.
    """

    #: cubes of ``reach / CELLS_PER_REACH`` (mm); at most MAX_CELLS of them
    CELLS_PER_REACH, MAX_CELLS = 1.0, 250_000

    def __init__(self, V: np.ndarray, T: np.ndarray, reach: float) -> None:
        grow = reach * (1.0 + 1e-9)
        a, b, c = V[T[:, 0]], V[T[:, 1]], V[T[:, 2]]
        tmin = np.minimum(np.minimum(a, b), c) - grow
        tmax = np.maximum(np.maximum(a, b), c) + grow
        self.origin = coordinate_range([tmin], 3)[0]
        extent = coordinate_range([tmax], 3)[1] - self.origin
        side = reach / self.CELLS_PER_REACH
        while np.prod(np.floor(extent / side) + 1.0) > self.MAX_CELLS:
            side *= 1.25
        self.side = side
        self.shape = tuple(int(n) for n in np.floor(extent / side) + 1.0)
        i0, i1 = self._index(tmin), self._index(tmax) + 1  # each box's cells: [i0, i1) along each axis
        np.clip(i0, 0, self.shape, out=i0)
        np.clip(i1, 0, self.shape, out=i1)
        self.marked = _boxes_union(i0, i1, self.shape)

    def _index(self, P: np.ndarray) -> np.ndarray:
        """The cell index (n, 3) of each point ``P`` (n, 3) (mm), not clipped to the grid."""
        return np.floor((P - self.origin) / self.side).astype(np.int64)

    def __call__(self, P: np.ndarray) -> np.ndarray:
        """Mask (n,) of the points ``P`` (n, 3) (mm) that may lie within ``reach`` of a triangle."""
        k = self._index(P)
        nx, ny, nz = self.shape
        ok = (k[:, 0] >= 0) & (k[:, 0] < nx) & (k[:, 1] >= 0) & (k[:, 1] < ny) & (k[:, 2] >= 0) & (k[:, 2] < nz)
        i = np.flatnonzero(ok)
        ok[i] = self.marked[(k[i, 0] * ny + k[i, 1]) * nz + k[i, 2]]
        return ok


def _boxes_union(i0: np.ndarray, i1: np.ndarray, shape: tuple[int, int, int]) -> np.ndarray:
    """Flat mask (``prod(shape)``,) of the cells of a grid ``shape`` in at least one box of cells
    ``[i0, i1)`` (rows of (n, 3) integer corner indices, already clipped to the grid): ``+1`` at the
    corners with an even count of upper indices, ``-1`` at the others, summed along each axis."""
    nx, ny, nz = shape
    size = (nx + 1) * (ny + 1) * (nz + 1)
    plus, minus = [], []
    for corner in itertools.product((0, 1), repeat=3):
        x, y, z = ((i1 if up else i0)[:, j] for j, up in enumerate(corner))
        (minus if sum(corner) % 2 else plus).append((x * (ny + 1) + y) * (nz + 1) + z)
    diff = (np.bincount(np.concatenate(plus), minlength=size)
            - np.bincount(np.concatenate(minus), minlength=size)).reshape(nx + 1, ny + 1, nz + 1)
    count = np.cumsum(np.cumsum(np.cumsum(diff, axis=0), axis=1), axis=2)
    return (count[:nx, :ny, :nz] > 0).reshape(-1)


def _used(T: np.ndarray, n: int) -> np.ndarray:
    """Mask (n,) of the vertices that triangles ``T`` use (``np.unique(T)`` as a mask: no sort)."""
    used = np.zeros(n, dtype=bool)
    used[T] = True
    return used


def mesh_distance(points: np.ndarray, V: np.ndarray, T: np.ndarray, reach: float = np.inf) -> np.ndarray:
    """Exact distance (mm) from every point to the triangle mesh ``(V, T)`` (see :class:`MeshDistance`)."""
    return MeshDistance(V, T, reach)(points)


def largest_inside(tris: np.ndarray, values: np.ndarray, f, spacing: float, best: float,
                   anchors: np.ndarray | None = None):
    """Points where the 1-Lipschitz function ``f`` may exceed ``best`` inside triangles, by branch and bound.

    ``tris`` (n, 3, 3) with ``values`` (n, 3), ``f`` at their corners.  Every point of a
    triangle lies within its :func:`covering_radius` ``r <= L / √3`` (longest edge ``L``) of a
    corner, so ``f`` there is at most ``max(corner values) + r``.  A triangle is split at the midpoint of its
    longest edge (``f`` measured there) while that bound exceeds the largest value found by
    more than ``spacing / √3``; the others are dropped.  A triangle whose edges are
    ``<= spacing`` is always dropped (its bound is within ``spacing / √3`` of a corner), so
    no value exceeds every one returned by more than ``spacing / √3``, as with uniformly
    refined triangles of edge ``spacing``, at a fraction of the points: where ``f`` is
    nearly flat at its peak (the gap over a land: clearance / 2 all round) the triangles
    stop splitting as soon as their bound is within the resolution of the peak.

    With ``anchors`` (n, 3, 3), ``f`` is a distance to a set and each corner's nearest point of
    that set is known (``f`` then returns ``(values, nearest points)``, NaN where there is none):
    ``f(y) <= |y - q|`` for every point ``q`` of the set, and ``|y - q|`` is convex, so over a
    triangle it is at most its largest value at the corners.  The bound taken is the smaller of
    the two, ``min_c max_k |v_k - q_c|`` being second order where the triangle runs along the set
    (along a land's ridge: ``sqrt(f² + h²)``) where the first is ``f + h``; the guarantee is the same.

    ``f`` must be a function of each point alone (its value at a point does not depend on the other
    points asked with it): a midpoint met again (two triangles that share their longest edge split it
    both, in the same round or later) is measured once (:class:`_Memo`; 42 % of the midpoints on the
    rounded rectangle's land).

    Returns the measured points (m, 3) and their values (m,).
    """
    slack = spacing / math.sqrt(3.0)
    f = _Memo(f, anchors is not None)
    pts, vals = [], []
    e = _edge_lengths(tris)  # then each round's children's from their parents' (half of them are those)
    for _ in range(200):
        if not len(tris):
            break
        live = _lipschitz_live(tris, values, e, best + slack)
        if anchors is not None and np.any(live):  # the anchored bound, where the first did not prune
            k = np.flatnonzero(live)
            live[k] = _anchored_bound(tris[k], anchors[k]) > best + slack
        split = np.flatnonzero(live)
        if not len(split):
            break
        i0, i1, i2 = _longest_edge_corners(e, split)  # (the live rows are not copied: their corners are read)
        a, b, c = (tris.reshape(-1, 3)[i] for i in (i0, i1, i2))
        m = 0.5 * (a + b)
        if anchors is None:
            fm = f(m)
        else:
            fm, qm = f(m)
            anchors = _halves(*(anchors.reshape(-1, 3)[i] for i in (i0, i1, i2)), qm)
        pts.append(m)
        vals.append(fm)
        best = max(best, float(np.max(fm)))
        e = _half_edges(e.reshape(-1)[i1], e.reshape(-1)[i2], a, b, c, m)
        tris = _halves(a, b, c, m)
        values = _halves(*(values.reshape(-1)[i] for i in (i0, i1, i2)), fm)
    if not pts:
        return np.zeros((0, 3)), np.zeros(0)
    return np.concatenate(pts), np.concatenate(vals)


def _lipschitz_live(tris: np.ndarray, values: np.ndarray, e: np.ndarray, threshold: float) -> np.ndarray:
    """Whether ``max(values) + covering_radius(tris, e) > threshold`` (mm) for each triangle.

    The radius lies between half the longest edge ``L`` and ``L / √3`` (the same floats as in
    :func:`covering_radius`; float sums are monotonic), which decide alone for all but 8 % of the
    branch and bound's triangles (the capsule, rounded rectangle and almond): the radius is computed
    for those."""
    vmax = np.maximum(np.maximum(values[:, 0], values[:, 1]), values[:, 2])
    longest = np.maximum(np.maximum(e[:, 0], e[:, 1]), e[:, 2])
    live = vmax + 0.5 * longest > threshold
    k = np.flatnonzero(~live & (vmax + longest / math.sqrt(3.0) > threshold))
    live[k] = vmax[k] + covering_radius(tris[k], e[k]) > threshold
    return live


def _edge_lengths(tris: np.ndarray) -> np.ndarray:
    """``|t1 - t0|, |t2 - t1|, |t0 - t2|`` (mm) of triangles ``tris`` (n, 3, 3): edge ``k`` joins corners
    ``k`` and ``k + 1``."""
    return np.stack([np.linalg.norm(tris[:, 1] - tris[:, 0], axis=1),
                     np.linalg.norm(tris[:, 2] - tris[:, 1], axis=1),
                     np.linalg.norm(tris[:, 0] - tris[:, 2], axis=1)], axis=1)


def _longest_edge_corners(e: np.ndarray, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Flat indices (``3 row + corner``) of the corners ``k``, ``k + 1`` and ``k + 2`` of triangles ``rows``,
    ``k`` the longest edge in their lengths ``e[rows]`` (``e`` (n, 3); the first of equal ones)."""
    k = np.argmax(e[rows], axis=1)
    base = 3 * rows
    k1 = k + 1
    k1[k1 == 3] = 0
    k2 = k1 + 1
    k2[k2 == 3] = 0
    return base + k, base + k1, base + k2


def _halves(a: np.ndarray, b: np.ndarray, c: np.ndarray, m: np.ndarray) -> np.ndarray:
    """The two halves ``(a, m, c)`` then ``(m, b, c)`` of triangles split at ``m`` on their edge ``ab``: an
    array (2 n, 3, ...) of whatever is given per corner (points, values, nearest points)."""
    n = len(a)
    out = np.empty((2 * n, 3) + a.shape[1:], dtype=np.result_type(a, m))
    out[:n, 0], out[:n, 1], out[:n, 2] = a, m, c
    out[n:, 0], out[n:, 1], out[n:, 2] = m, b, c
    return out


def _half_edges(ebc: np.ndarray, eca: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray,
                m: np.ndarray) -> np.ndarray:
    """:func:`_edge_lengths` (mm) of :func:`_halves` ``(a, b, c, m)``, given the parents' edges ``|c - b|``
    and ``|a - c|`` (n,): the same numbers (each the norm of the same difference, or of its negation)."""
    n = len(a)
    emc = np.linalg.norm(c - m, axis=1)
    out = np.empty((2 * n, 3))
    out[:n, 0], out[:n, 1], out[:n, 2] = np.linalg.norm(m - a, axis=1), emc, eca
    out[n:, 0], out[n:, 1], out[n:, 2] = np.linalg.norm(b - m, axis=1), ebc, emc
    return out


class _Memo:
    """``f`` of points (n, 3), each point measured once: a point met again (the same three float64
    bit patterns) takes the value (and, ``paired``, the nearest point) that ``f`` gave it before,
    so every answer is ``f``'s own.

    Points are found by a 64-bit hash of their bits (a sorted array searched with ``searchsorted``)
    and every match is checked bit for bit: a hash shared by two different points costs a second
    measurement, never a wrong value (in a call where it happens, every point of it is measured)."""

    def __init__(self, f, paired: bool) -> None:
        self.f, self.paired = f, paired
        self.hashes = np.zeros(0, dtype=np.uint64)  # sorted
        self.rows = np.zeros(0, dtype=np.int64)  # the stored row of each hash
        self.size = 0  # rows stored in the buffers below (grown by doubling)
        self.bits = np.zeros((0, 3), dtype=np.uint64)
        self.values = np.zeros(0)
        self.nearest = np.zeros((0, 3))

    @staticmethod
    def _hash(bits: np.ndarray) -> np.ndarray:
        h = bits[:, 0] * np.uint64(0x9E3779B97F4A7C15)
        h ^= (h >> np.uint64(29)) ^ (bits[:, 1] * np.uint64(0xBF58476D1CE4E5B9))
        h ^= (h >> np.uint64(31)) ^ (bits[:, 2] * np.uint64(0x94D049BB133111EB))
        return h ^ (h >> np.uint64(32))

    def _measure(self, P: np.ndarray):
        out = self.f(P)
        if self.paired:
            return np.asarray(out[0], dtype=float).reshape(-1), np.asarray(out[1], dtype=float).reshape(-1, 3)
        return np.asarray(out, dtype=float).reshape(-1), None

    def __call__(self, P: np.ndarray):
        P = np.ascontiguousarray(P, dtype=float).reshape(-1, 3)
        bits = P.view(np.uint64)
        hashes, first, inverse = np.unique(self._hash(bits), return_index=True, return_inverse=True)
        inverse = inverse.reshape(-1)
        if not np.array_equal(bits[first][inverse], bits):  # two points of this call share a hash
            v, q = self._measure(P)
            return (v, q) if self.paired else v
        n = len(self.hashes)
        pos = np.searchsorted(self.hashes, hashes)
        row = np.full(len(hashes), -1, dtype=np.int64)
        hit = np.flatnonzero(pos < n)
        hit = hit[self.hashes[pos[hit]] == hashes[hit]]
        same = np.all(self.bits[self.rows[pos[hit]]] == bits[first[hit]], axis=1)  # bit for bit
        row[hit[same]] = self.rows[pos[hit[same]]]
        new = np.flatnonzero(row < 0)
        if len(new):
            v, q = self._measure(P[first[new]])
            a, b = self.size, self.size + len(new)
            if b > len(self.values):
                cap = max(b, 2 * len(self.values))
                self.values = np.concatenate([self.values[:a], np.zeros(cap - a)])
                self.nearest = np.concatenate([self.nearest[:a], np.zeros((cap - a, 3))])
                self.bits = np.concatenate([self.bits[:a], np.zeros((cap - a, 3), dtype=np.uint64)])
            row[new] = np.arange(a, b)
            self.values[a:b] = v
            if self.paired:
                self.nearest[a:b] = q
            self.bits[a:b] = bits[first[new]]
            self.size = b
            self.hashes = np.insert(self.hashes, pos[new], hashes[new])  # still sorted
            self.rows = np.insert(self.rows, pos[new], row[new])
        rows = row[inverse]
        return (self.values[rows], self.nearest[rows]) if self.paired else self.values[rows]


def _anchored_bound(tris: np.ndarray, anchors: np.ndarray) -> np.ndarray:
    """``min_c max_k |corner k - anchor c|`` per triangle (``inf`` where every anchor is NaN)."""
    out = np.full(len(tris), np.inf)
    for c in range(3):
        q = anchors[:, c]
        far = np.zeros(len(tris))
        for k in range(3):
            d = tris[:, k] - q
            np.maximum(far, np.einsum("ij,ij->i", d, d), out=far)
        np.fmin(out, np.sqrt(far), out=out)  # NaN (no anchor) never wins
    return out


def covering_radius(tris: np.ndarray, e: np.ndarray | None = None) -> np.ndarray:
    """The largest distance from a point of each triangle to its nearest corner (mm).

    The distance to the nearest corner is convex inside each corner's Voronoi cell and along each
    bisector, so its maximum over the triangle lies at the circumcentre (when inside) or where a
    bisector of two corners meets an edge.  Acute triangle: the circumradius ``abc / 4A``.  Otherwise
    half the longest edge ``AB``: with ``AB`` on the x axis, an angle at ``C`` of 90° or more puts ``C``
    in the circle on ``AB`` (``|AC|² <= |AB| x_C``), so the bisector of ``AC`` meets ``AB`` at
    ``|AC|² / 2 x_C <= |AB| / 2`` from ``A`` (that of ``BC`` likewise from ``B``), the midpoint of ``AB`` is
    no farther from ``C`` than from ``A``, and the other edges' midpoints are nearer still.  Never above
    ``L / √3`` (the equilateral triangle); a right isosceles triangle, as longest-edge bisection makes,
    has ``L / 2``.
    """
    if e is None:
        e = _edge_lengths(tris)
    a, b, c = _sorted3(e[:, 0], e[:, 1], e[:, 2])
    half = 0.5 * c
    acute = a * a + b * b > c * c
    area2 = np.linalg.norm(_cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]), axis=1)  # twice the area
    with np.errstate(divide="ignore", invalid="ignore"):
        R = a * b * c / (2.0 * area2)
    # rounding: never below half the longest edge (any triangle's bound) nor above L / √3
    return np.where(acute & np.isfinite(R), np.clip(R, half, c / math.sqrt(3.0)), half)


def _sorted3(x: np.ndarray, y: np.ndarray, z: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Elementwise smallest, middle and largest of three arrays (``np.sort`` of their columns; no NaN)."""
    lo, hi = np.minimum(x, y), np.maximum(x, y)
    return np.minimum(lo, z), np.maximum(lo, np.minimum(hi, z)), np.maximum(hi, z)


def _cross(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Cross products (n, 3) of rows ``u`` and ``v`` (n, 3): ``np.cross``'s products and differences,
    without its axis handling."""
    out = np.empty((len(u), 3))
    out[:, 0] = u[:, 1] * v[:, 2] - u[:, 2] * v[:, 1]
    out[:, 1] = u[:, 2] * v[:, 0] - u[:, 0] * v[:, 2]
    out[:, 2] = u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]
    return out


class ExactDistance:
    """Exact distance (mm) from points to one OCC shape (0 inside a solid), asked for many points.

    What ``BRepExtrema_DistShapeShape`` computes for a vertex and the shape - the least of the
    point's distances to every vertex, its extrema on every edge (``BRepExtrema_ExtPC``) and its
    projections inside every face (``BRepExtrema_ExtPF``, which classifies them against the face's
    boundary) - with each edge's and face's extremum solver set up once (a B-spline face's sample
    grid: 40 ms a point for a punch's cup when set up per point, 5 ms once) and the edges and faces
    whose bounding box (``BRepBndLib``: never nearer than its shape) is no nearer than the best
    distance found skipped.  As there, a point inside a solid is at distance 0: when its nearest
    boundary point lies inside a face, the side of the face's outward normal it lies on decides
    (the segment to it crosses no other boundary), when it lies inside an edge the sum of the edge's
    two face normals (see :meth:`_inside`), else ``BRepClass3d_SolidClassifier``.  It agrees
    with ``BRepExtrema_DistShapeShape`` to 1e-7 mm, never above it (that one keeps a solution
    within ``Precision::Confusion`` of a nearer one), except that ``DistShapeShape`` sometimes gives
    a point just inside a solid its distance to the boundary where this gives 0 (a review found it
    within about 1e-3 mm of the boundary); see ``tests/test_tooling_gap_distance.py``, which checks
    inside points against closed-form inside tests.
    """

    def __init__(self, shape) -> None:
        from OCP.BRep import BRep_Tool
        from OCP.BRepExtrema import BRepExtrema_ExtPC, BRepExtrema_ExtPF
        from OCP.Extrema import Extrema_ExtAlgo, Extrema_ExtFlag

        self.vertices = np.array([BRep_Tool.Pnt_s(v).Coord() for v in explore(shape, "Vertex")], dtype=float).reshape(-1, 3)
        self.solid = shape if explore(shape, "Solid") else None
        self._classifier = None
        self._edge_faces = None  # edge -> its faces, made when first asked
        self.items = []  # (kind, sub-shape, solver)
        boxes = []
        for e in explore(shape, "Edge"):
            if BRep_Tool.Degenerated_s(e):
                continue
            ext = BRepExtrema_ExtPC()
            ext.Initialize(e)
            self.items.append(("edge", e, ext))
            boxes.append(_box_corners(e))
        for f in explore(shape, "Face"):
            ext = BRepExtrema_ExtPF()
            ext.Initialize(f, Extrema_ExtFlag.Extrema_ExtFlag_MIN, Extrema_ExtAlgo.Extrema_ExtAlgo_Grad)
            self.items.append(("face", f, ext))
            boxes.append(_box_corners(f))
        b = np.array(boxes, dtype=float).reshape(-1, 2, 3)
        self.lo, self.hi = b[:, 0], b[:, 1]

    def nearest(self, p) -> tuple[float, np.ndarray]:
        """The distance (mm) from ``p`` to the shape and the shape's point nearest to ``p``."""
        from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeVertex
        from OCP.gp import gp_Pnt

        p = np.asarray(p, dtype=float).reshape(3)
        best, point, where = math.inf, p, None
        if len(self.vertices):
            dv = np.linalg.norm(self.vertices - p, axis=1)
            k = int(np.argmin(dv))
            best, point = float(dv[k]), self.vertices[k]
        box_d = np.linalg.norm(np.maximum(np.maximum(self.lo - p, p - self.hi), 0.0), axis=1)
        vertex, edge_best, edge_hit = None, math.inf, None
        for i in np.argsort(box_d, kind="stable"):
            if box_d[i] >= best:
                break  # this box and every later one are no nearer than the best distance found
            if vertex is None:
                vertex = BRepBuilderAPI_MakeVertex(gp_Pnt(*map(float, p))).Vertex()
            kind, sub, ext = self.items[i]
            if kind == "edge":
                ext.Perform(vertex)
            else:
                ext.Perform(vertex, sub)
            if not ext.IsDone():
                continue
            for k in range(1, ext.NbExt() + 1):
                d = math.sqrt(max(ext.SquareDistance(k), 0.0))
                if d < best or (kind == "edge" and d < edge_best):
                    q = ext.Point(k)
                    qk = np.array((q.Value() if hasattr(q, "Value") else q).Coord())
                    if kind == "edge" and d < edge_best:
                        edge_best, edge_hit = d, (kind, sub, ext.Parameter(k), qk)
                    if d < best:
                        best, point, where = d, qk, (kind, sub, ext.Parameter(k), qk)
        if self.solid is not None and best > 0.0:
            # a face's extremum on its boundary (p - q along the face): the edge there, if one was found as
            # near to within the edge's tolerance (its curve and the face's boundary differ by that much)
            tie = None
            if edge_hit is not None:
                from OCP.BRep import BRep_Tool

                if edge_best <= best + max(1e-9 * max(1.0, best), BRep_Tool.Tolerance_s(edge_hit[1])):
                    tie = edge_hit
            if self._inside(p, where, tie):
                return 0.0, p
        return best, np.asarray(point, dtype=float)

    def _inside(self, p: np.ndarray, where, tie=None) -> bool:
        """Whether ``p`` lies inside the solid; ``where`` = ``(kind, sub-shape, parameter, q)`` of its
        nearest boundary point ``q`` (None: a vertex), ``tie`` the same of an edge point as near.

        ``q`` inside a face: ``p - q`` lies along the face's normal there, whose side decides (only
        then: ``BRepExtrema_ExtPF`` may return a point on the face's boundary, off the normal).  ``q``
        inside an edge: ``p - q`` lies in the solid's normal cone there, spanned by the two faces'
        outward normals at ``q`` (outside, at a convex edge) or by their opposites (inside, at a
        concave one: the nearest boundary point of a point on the other side cannot lie on such an
        edge), so the sign of ``(p - q) . (n1 + n2)`` decides (the pseudo-normal of Bærentzen and
        Aanæs, 2005); ``tie`` is asked first.  Otherwise (a vertex, a seam, a knife edge) ``BRepClass3d_SolidClassifier``
        decides (8 ms a point on a punch)."""
        from OCP.BRepClass3d import BRepClass3d_SolidClassifier
        from OCP.gp import gp_Pnt
        from OCP.TopAbs import TopAbs_State

        for hit in (tie, where):  # an edge as near first: a face's extremum may lie on its boundary
            if hit is None:
                continue
            kind, sub, t, q = hit
            n = self._face_normal(sub, *t) if kind == "face" else self._edge_pseudo_normal(sub, t)
            if n is not None:
                side = float(np.dot(n, p - q)) / max(float(np.linalg.norm(n) * np.linalg.norm(p - q)), 1e-300)
                # a face decides only at a true projection (p - q along its normal: not an extremum
                # on its boundary, where the normal can point either way at a sharp edge)
                if abs(side) > (1.0 - 1e-6 if kind == "face" else 1e-3):
                    return side < 0.0
        if self._classifier is None:
            self._classifier = BRepClass3d_SolidClassifier(self.solid)
        self._classifier.Perform(gp_Pnt(*map(float, p)), 1e-7)
        return self._classifier.State() == TopAbs_State.TopAbs_IN

    @staticmethod
    def _face_normal(face, u: float, v: float) -> np.ndarray:
        """The outward (for the face's orientation) normal of ``face`` at ``(u, v)``, not unit."""
        from OCP.BRepAdaptor import BRepAdaptor_Surface
        from OCP.gp import gp_Pnt, gp_Vec
        from OCP.TopAbs import TopAbs_Orientation

        pt, du, dv = gp_Pnt(), gp_Vec(), gp_Vec()
        BRepAdaptor_Surface(face).D1(u, v, pt, du, dv)
        (ax, ay, az), (bx, by, bz) = du.Coord(), dv.Coord()
        # np.cross's products and differences, in Python floats (np.cross of two 3-vectors: 56 us)
        n = np.array([ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx])
        if face.Orientation() == TopAbs_Orientation.TopAbs_REVERSED:
            n = -n
        return n

    def _edge_pseudo_normal(self, edge, t: float) -> np.ndarray | None:
        """``n1 + n2`` (unit outward normals of the edge's two faces at parameter ``t``), or None when
        ``t`` is at the edge's end, the edge is a seam or does not bound exactly two faces, its
        p-curves may not share its parameter, or a normal vanishes."""
        from OCP.BRep import BRep_Tool
        from OCP.BRepAdaptor import BRepAdaptor_Curve2d
        from OCP.TopAbs import TopAbs_ShapeEnum
        from OCP.TopExp import TopExp
        from OCP.TopoDS import TopoDS
        from OCP.TopTools import TopTools_IndexedDataMapOfShapeListOfShape

        a, b = BRep_Tool.Range_s(edge)
        if not BRep_Tool.SameParameter_s(edge) or not a + 1e-9 * (b - a) < t < b - 1e-9 * (b - a):
            return None
        if self._edge_faces is None:
            self._edge_faces = TopTools_IndexedDataMapOfShapeListOfShape()
            TopExp.MapShapesAndAncestors_s(self.solid, TopAbs_ShapeEnum.TopAbs_EDGE, TopAbs_ShapeEnum.TopAbs_FACE,
                                           self._edge_faces)
        if not self._edge_faces.Contains(edge):
            return None
        ancestors = self._edge_faces.FindFromKey(edge)  # (iterating the list from Python: 0.8 ms)
        if ancestors.Size() != 2:
            return None
        faces = [TopoDS.Face_s(ancestors.First()), TopoDS.Face_s(ancestors.Last())]
        if faces[0].IsSame(faces[1]):
            return None
        total = np.zeros(3)
        for f in faces:
            u, v = BRepAdaptor_Curve2d(edge, f).Value(t).Coord()
            n = self._face_normal(f, u, v)
            size = float(np.linalg.norm(n))
            if not size > 0.0:
                return None
            total += n / size
        return total

    def __call__(self, p) -> float:
        """The distance (mm) from ``p`` to the shape."""
        return self.nearest(p)[0]


def _mesh_near(shape, boxes: list, margin: float, deflection: float) -> tuple[np.ndarray, np.ndarray]:
    """:func:`~tabletcad.tooling.booleans.mesh_arrays` of the faces of ``shape`` whose boxes come within
    ``margin`` (mm) of one of ``boxes``; the whole shape's (cached) when every face is that near.
    ``BRepBndLib`` boxes hold analytic and B-spline faces whole (poles) but other surfaces (an
    extrusion) from samples, which may fall short by a sliver: the margin (twice the search reach,
    0.32 mm at 0.02 mm clearance) is far wider (a review found every point of a 0.02 mm grid of every
    sample tool's faces inside its box)."""
    from OCP.BRep import BRep_Builder
    from OCP.TopoDS import TopoDS_Compound

    from tabletcad.cad.mesh import triangulate

    faces = explore(shape, "Face")
    near = [f for f, box in zip(faces, map(_box, faces)) if min(box.Distance(b) for b in boxes) <= margin]
    if len(near) == len(faces):
        return mesh_arrays(shape, deflection, 0.2)
    if not near:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
    comp = TopoDS_Compound()
    builder = BRep_Builder()
    builder.MakeCompound(comp)
    for f in near:
        builder.Add(comp, f)
    try:  # as mesh_arrays: Delabella, Watson where it leaves a trimmed face empty
        return triangulate(comp, deflection, 0.2)
    except GeometryError:
        return triangulate(comp, deflection, 0.2, algo="watson")


def _contact_faces(faces: list, parts: dict) -> set[int]:
    """Indices of ``faces`` that are also faces of one of ``parts`` (``IsSame``: the same face, either way round)."""
    from OCP.TopTools import TopTools_IndexedMapOfShape

    tool_faces = TopTools_IndexedMapOfShape()
    for s in parts.values():
        for f in explore(s, "Face"):
            tool_faces.Add(f)
    return {k for k, f in enumerate(faces) if tool_faces.Contains(f)}


def _box_corners(shape) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    box = _box(shape)
    lo, hi = box.CornerMin(), box.CornerMax()
    return (lo.X(), lo.Y(), lo.Z()), (hi.X(), hi.Y(), hi.Z())


def _box(shape):
    """A box holding ``shape`` (``BRepBndLib.Add``: poles of B-splines, exact for analytic surfaces, with
    the shapes' tolerances: never smaller than the shape)."""
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib

    box = Bnd_Box()
    BRepBndLib.Add_s(shape, box, False)
    return box


def _surface_samples(tablet, nu: int = 49, nv: int = 384) -> np.ndarray:
    """Points of every patch on Chebyshev-spaced ``u`` (dense at the patch edges, where the
    punch tip, land and die wall meet) times equally spaced ``v``."""
    u = 0.5 * (1.0 - np.cos(np.linspace(0.0, np.pi, nu)))
    v = np.linspace(0.0, 2.0 * np.pi, nv, endpoint=False)
    return np.concatenate([p.evaluate_grid(u, v).reshape(-1, 3) for p in tablet.patches])


def face_samples(shape, spacing: float = 0.05, max_per_face: int = 2500, faces=None) -> np.ndarray:
    """Points (n, 3) on every face of ``shape`` (mm; or on ``faces`` of it): a grid in each face's ``(u, v)`` box about
    ``spacing`` mm apart on the surface (at most ``max_per_face`` per face), kept where
    ``BRepTopAdaptor_FClass2d`` puts them inside the face or on its boundary.

    A tessellation has vertices only on the edges of a planar face (a letter's wall, a score's
    flank); these samples reach the inside of every face.
    """
    from OCP.BRepAdaptor import BRepAdaptor_Surface
    from OCP.BRepTools import BRepTools
    from OCP.BRepTopAdaptor import BRepTopAdaptor_FClass2d
    from OCP.gp import gp_Pnt2d
    from OCP.TopAbs import TopAbs_State

    keep_states = (TopAbs_State.TopAbs_IN, TopAbs_State.TopAbs_ON)
    out = []
    for face in explore(shape, "Face") if faces is None else faces:
        surf = BRepAdaptor_Surface(face)
        u0, u1, v0, v1 = BRepTools.UVBounds_s(face)
        g = np.linspace(0.0, 1.0, 9)
        P = np.array([[surf.Value(u0 + (u1 - u0) * a, v0 + (v1 - v0) * b).Coord() for b in g] for a in g])
        lu = float(np.max(np.sum(np.linalg.norm(np.diff(P, axis=0), axis=2), axis=0)))  # longest u line
        lv = float(np.max(np.sum(np.linalg.norm(np.diff(P, axis=1), axis=2), axis=1)))
        nu = int(np.clip(np.ceil(lu / spacing) + 1, 3, max_per_face // 3))
        nv = int(np.clip(np.ceil(lv / spacing) + 1, 3, max(3, max_per_face // nu)))
        us, vs = np.linspace(u0, u1, nu).tolist(), np.linspace(v0, v1, nv).tolist()
        if _fills_uv_box(face, u0, u1, v0, v1):  # every grid point lies inside the face or on its edges
            out.append(_surface_points(surf, itertools.product(us, vs), nu * nv))
            continue
        U, V = (a.ravel() for a in np.meshgrid(us, vs, indexing="ij"))
        # the face's wires as (u, v) polygons decide every point farther from them than a twentieth of
        # the grid's step; nearer ones (and every point of a face whose polygons cannot be made) go to
        # the classifier
        margin = 0.05 * min((u1 - u0) / (nu - 1), (v1 - v0) / (nv - 1)) if min(nu, nv) > 1 else 0.0
        inside, near = _polygon_classes(face, us, vs, margin)
        keep = inside.ravel().copy()
        ask = np.flatnonzero(near.ravel())
        if len(ask):
            cls = BRepTopAdaptor_FClass2d(face, 1e-9)
            keep[ask] = [cls.Perform(gp_Pnt2d(u, v)) in keep_states for u, v in zip(U[ask].tolist(), V[ask].tolist())]
        k = np.flatnonzero(keep)
        out.append(_surface_points(surf, zip(U[k].tolist(), V[k].tolist()), len(k)))
    return np.concatenate(out) if out else np.zeros((0, 3))


def _surface_points(surf, uv, n: int) -> np.ndarray:
    """``surf.Value(u, v)`` (mm) at the ``n`` pairs ``uv``, as an array (n, 3) (one C++ call per point, no Python frame)."""
    from OCP.gp import gp_Pnt

    return np.fromiter(itertools.chain.from_iterable(map(gp_Pnt.Coord, itertools.starmap(surf.Value, uv))), dtype=float,
                       count=3 * n).reshape(n, 3)


def _wire_polygons(face, tol: float, max_points: int = 4097) -> list[np.ndarray] | None:
    """Each wire of ``face`` as a closed ``(u, v)`` polygon (m, 2) through its edges' p-curves in
    wire order, every edge sampled until no chord leaves its p-curve by more than ``tol`` (checked at
    the chords' midpoints); None when an edge needs more than ``max_points``, has no p-curve, or the
    wire explorer does not visit every edge of a wire (it stops at a wire not closed in 2-D; the
    classifier then falls back on its own)."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve2d
    from OCP.BRepTools import BRepTools_WireExplorer
    from OCP.TopAbs import TopAbs_Orientation
    from OCP.TopoDS import TopoDS_Iterator

    bounding = (TopAbs_Orientation.TopAbs_FORWARD, TopAbs_Orientation.TopAbs_REVERSED)
    polygons = []
    for wire in explore(face, "Wire"):
        n_edges, it = 0, TopoDS_Iterator(wire)
        while it.More():
            n_edges += it.Value().Orientation() in bounding
            it.Next()
        pts = []
        ex = BRepTools_WireExplorer(wire, face)
        while ex.More():
            edge = ex.Current()
            try:
                c = BRepAdaptor_Curve2d(edge, face)
            except Exception:  # Standard_Failure: no p-curve on this face
                return None
            a, b = c.FirstParameter(), c.LastParameter()
            n = 9
            while True:
                t = np.linspace(a, b, 2 * n - 1)
                P = np.array([c.Value(x).Coord() for x in t.tolist()])
                chord = 0.5 * (P[:-2:2] + P[2::2])
                if np.max(np.linalg.norm(P[1::2] - chord, axis=1), initial=0.0) <= tol:
                    break
                if 2 * n - 1 > max_points:
                    return None
                n = 2 * n - 1
            if edge.Orientation() == TopAbs_Orientation.TopAbs_REVERSED:
                P = P[::-1]
            pts.append(P)
            ex.Next()
        if not pts or len(pts) != n_edges:
            return None
        poly = np.concatenate(pts)
        polygons.append(np.vstack([poly, poly[:1]]))
    return polygons or None


def _polygon_classes(face, us, vs, margin: float) -> tuple[np.ndarray, np.ndarray]:
    """``(inside, near)`` masks (nu, nv) of the grid ``us x vs`` on ``face``: inside by the even-odd rule
    on the wires' polygons (:func:`_wire_polygons`, within ``margin / 4`` of the p-curves: a ray along
    ``+u`` on each grid line ``v = const`` counts the crossings), near (a superset) where a grid point
    lies within ``margin`` of a polygon's segment (Euclidean in ``(u, v)``), where the polygon may
    disagree with the face (a point farther than ``margin`` from the polygon is farther than
    ``3 margin / 4`` from the p-curves, on the same side of both); every point near when the polygons cannot be made."""
    us, vs = np.asarray(us, dtype=float), np.asarray(vs, dtype=float)
    shape = (len(us), len(vs))
    polygons = _wire_polygons(face, 0.25 * margin) if margin > 0.0 else None
    if polygons is None:
        return np.zeros(shape, dtype=bool), np.ones(shape, dtype=bool)
    du, dv = us[1] - us[0], vs[1] - vs[0]
    # segments no longer than four grid steps, so that their boxes stay close to them
    A, B = [], []
    for poly in polygons:
        a, b = poly[:-1], poly[1:]
        k = np.maximum(1, np.ceil(np.max(np.abs(b - a) / (4.0 * np.array([du, dv])), axis=1))).astype(int)
        j = np.concatenate([np.arange(n) for n in k])
        i = np.repeat(np.arange(len(a)), k)
        A.append(a[i] + (j / k[i])[:, None] * (b[i] - a[i]))
        last = (j == k[i] - 1)[:, None]  # the last piece ends exactly at b: no rounding gap at a vertex
        B.append(np.where(last, b[i], a[i] + ((j + 1) / k[i])[:, None] * (b[i] - a[i])))
    A, B = np.concatenate(A), np.concatenate(B)
    near = np.zeros(shape, dtype=bool)
    lo, hi = np.minimum(A, B) - margin, np.maximum(A, B) + margin
    i0 = np.clip(np.ceil((lo[:, 0] - us[0]) / du), 0, shape[0]).astype(int)
    i1 = np.clip(np.floor((hi[:, 0] - us[0]) / du) + 1, 0, shape[0]).astype(int)
    j0 = np.clip(np.ceil((lo[:, 1] - vs[0]) / dv), 0, shape[1]).astype(int)
    j1 = np.clip(np.floor((hi[:, 1] - vs[0]) / dv) + 1, 0, shape[1]).astype(int)
    # the grid points in each segment's box grown by the margin, kept where they lie within the margin
    # of the segment itself (a diagonal segment's box holds many points far from it)
    ni, nj = np.maximum(i1 - i0, 0), np.maximum(j1 - j0, 0)
    count = ni * nj
    seg = np.repeat(np.arange(len(A)), count)
    if len(seg):
        k = np.arange(len(seg)) - np.repeat(np.cumsum(count) - count, count)  # index inside the segment's box
        gi, gj = i0[seg] + k // nj[seg], j0[seg] + k % nj[seg]
        P = np.stack([us[gi], vs[gj]], axis=1)
        a, ab = A[seg], B[seg] - A[seg]
        L2 = np.einsum("ij,ij->i", ab, ab)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.clip(np.where(L2 > 0.0, np.einsum("ij,ij->i", P - a, ab) / L2, 0.0), 0.0, 1.0)
        d = P - (a + t[:, None] * ab)
        close = np.einsum("ij,ij->i", d, d) <= margin * margin
        near[gi[close], gj[close]] = True
    inside = np.zeros(shape, dtype=bool)
    ay, by = A[:, 1], B[:, 1]
    for j, v in enumerate(vs.tolist()):
        c = (ay > v) != (by > v)
        if not c.any():
            continue
        ax, bx, cy, dy = A[c, 0], B[c, 0], ay[c], by[c]
        x = np.sort(ax + (v - cy) * (bx - ax) / (dy - cy))
        inside[:, j] = (len(x) - np.searchsorted(x, us, side="right")) % 2 == 1
    on = _on_straight_sides(face, us, vs)  # on the boundary: kept, as the classifier keeps them
    return inside | on, near & ~on


def _on_straight_sides(face, us, vs) -> np.ndarray:
    """Mask (nu, nv) of the grid points on the first or last row or column of the grid ``us x vs``
    that lie on an edge of ``face`` whose p-curve runs along that side of the grid: a line, or a
    B-spline whose poles all lie on it (the curve lies in their convex hull), with both ends on it
    to ``1e-12`` of the parameter range and the point between its ends (the curve passes every value
    between them).  Those are points of the face's boundary, which the classifier puts ON the face
    (a cup's rim and seam after the Boolean that cut letters into it: 1,668 points a face)."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve2d
    from OCP.GeomAbs import GeomAbs_CurveType
    from OCP.TopAbs import TopAbs_Orientation

    on = np.zeros((len(us), len(vs)), dtype=bool)
    eps = (1e-12 * max(1.0, abs(us[0]), abs(us[-1])), 1e-12 * max(1.0, abs(vs[0]), abs(vs[-1])))
    sides = ((0, us[0]), (0, us[-1]), (1, vs[0]), (1, vs[-1]))
    bounding = (TopAbs_Orientation.TopAbs_FORWARD, TopAbs_Orientation.TopAbs_REVERSED)
    for e in explore(face, "Edge"):
        if e.Orientation() not in bounding:  # an INTERNAL or EXTERNAL edge bounds nothing
            continue
        try:
            c = BRepAdaptor_Curve2d(e, face)
        except Exception:  # no p-curve on this face: the classifier decides
            continue
        kind = c.GetType()
        if kind == GeomAbs_CurveType.GeomAbs_Line:
            pts = np.array([c.Value(c.FirstParameter()).Coord(), c.Value(c.LastParameter()).Coord()])
        elif kind == GeomAbs_CurveType.GeomAbs_BSplineCurve:
            b = c.BSpline()
            pts = np.array([b.Pole(i).Coord() for i in range(1, b.NbPoles() + 1)]
                           + [c.Value(c.FirstParameter()).Coord(), c.Value(c.LastParameter()).Coord()])
        else:
            continue
        p, q = pts[-2], pts[-1]
        for axis, x in sides:
            if np.all(np.abs(pts[:, axis] - x) <= eps[axis]):
                other = 1 - axis
                lo, hi = min(p[other], q[other]) - eps[other], max(p[other], q[other]) + eps[other]
                if axis == 0:
                    on[0 if x == us[0] else -1] |= (vs >= lo) & (vs <= hi)
                else:
                    on[:, 0 if x == vs[0] else -1] |= (us >= lo) & (us <= hi)
    return on


def _fills_uv_box(face, u0: float, u1: float, v0: float, v1: float) -> bool:
    """Whether ``face`` is the whole of its ``(u, v)`` box: one wire, every edge a straight
    p-curve along a side of the box (a closed wire on the box's sides is its whole boundary),
    as the faces of an untrimmed patch are.  False whenever in doubt."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve2d
    from OCP.GeomAbs import GeomAbs_CurveType

    wires = explore(face, "Wire")
    if len(wires) != 1:
        return False
    eps = 1e-9 * max(1.0, abs(u0), abs(u1), abs(v0), abs(v1))
    for e in explore(wires[0], "Edge"):
        c = BRepAdaptor_Curve2d(e, face)
        if c.GetType() != GeomAbs_CurveType.GeomAbs_Line:
            return False
        p, q = c.Value(c.FirstParameter()), c.Value(c.LastParameter())
        if not (any(abs(p.X() - x) <= eps and abs(q.X() - x) <= eps for x in (u0, u1))
                or any(abs(p.Y() - y) <= eps and abs(q.Y() - y) <= eps for y in (v0, v1))):
            return False
    return True


def _largest_tolerance(shape) -> float:
    """The largest tolerance (mm) of a shape's vertices, edges and faces: how far its B-rep may stand
    from its exact geometry (``ShapeAnalysis_ShapeTolerance``)."""
    from OCP.ShapeAnalysis import ShapeAnalysis_ShapeTolerance

    return float(ShapeAnalysis_ShapeTolerance().Tolerance(shape, 1))


def _distance_shapes(a, b) -> BRepExtrema_DistShapeShape:
    """``BRepExtrema_DistShapeShape`` of two shapes, its sub-shape pairs on every core
    (``SetMultiThread``: the same distance; tablet to die 0.34 -> 0.18 s on two cores).

    ``a`` is loaded as its boundary when :func:`_not_inside` proves that ``b`` is not inside it: the
    distance then skips classifying every vertex of ``b`` in ``a`` (a punch's B-spline cup: 0.09-0.12 of
    0.18-0.21 CPU s a punch and die) and is the same float (its extrema are those of the same vertices,
    edges and faces, met in the same order)."""
    dss = BRepExtrema_DistShapeShape()
    dss.SetMultiThread(OCC_PARALLEL[0])
    shell = _one_shell(a)
    dss.LoadS1(shell if shell is not None and _not_inside(b, a) else a)
    dss.LoadS2(b)
    dss.Perform()
    return dss


def _one_shell(shape):
    """The shell of ``shape`` when it is one solid bounded by one shell (no void), else None."""
    solids = explore(shape, "Solid")
    if len(solids) != 1 or not solids[0].IsSame(shape):
        return None
    shells = explore(shape, "Shell")
    return shells[0] if len(shells) == 1 else None


#: how far (mm) a vertex of one solid must lie outside the other's box (:func:`_box`) to prove it is not
#: inside it: such boxes hold B-spline and analytic faces whole but sample other surfaces (an extruded
#: outline), which may fall short by a sliver (see :func:`_mesh_near`); a die's corners lie centimetres out
NOT_INSIDE_MARGIN_MM = 1.0


def _not_inside(b, a) -> bool:
    """Whether a vertex of the one solid ``b`` lies more than :data:`NOT_INSIDE_MARGIN_MM` outside the
    bounding box of ``a`` (:func:`_box`): then ``b`` is not inside ``a``.

    With ``b`` not inside ``a``, the distance of ``a``'s boundary to the solid ``b`` still proves them
    apart: ``BRepExtrema_DistShapeShape`` classifies the vertices of the first shape in the second when
    that one is a solid.  If their boundaries are apart and their insides meet, a path inside ``b``
    from a common point to a point of ``b`` outside ``a`` crosses ``a``'s boundary inside ``b``; so a
    whole piece of ``a``'s boundary lies inside ``b``, and its vertices are classified in ``b``, as
    without this shortcut.  The shortcut drops only the other test, the vertices of ``b`` in ``a``."""
    from OCP.BRep import BRep_Tool

    if len(explore(b, "Solid")) != 1:
        return False
    box = _box(a)
    box.Enlarge(NOT_INSIDE_MARGIN_MM)
    return any(box.IsOut(BRep_Tool.Pnt_s(v)) for v in explore(b, "Vertex"))


def interference(tablet, parts: dict, clearance: float, *, deflection: float = 0.005, refine: int = 40,
                 tablet_model=None, forked: bool = False, bore=None, band_gap: float = 0.0) -> dict:
    """Overlaps (mm^3) between all pairs of ``{"tablet": shape, **parts}`` and the tablet's largest gap (mm).

    ``tablet_model``: the :class:`~tabletcad.geometry.tablet.Tablet`, whose patches add surface samples.
    ``forked``: the gap is measured by a forked process (:class:`tabletcad.io.forked.Forked`) while this
    one checks the overlaps; the same result (the gap uses neither manifold3d nor OCC's thread pool).
    ``bore``: the die bore's plan wire at ``z = 0`` (:func:`~tabletcad.tooling.die.bore_wire`), with which
    the tablet is first proved apart from ``parts["die"]`` without its taper (:func:`inside_bore`).
    ``band_gap``: how far (mm) the tablet's B-rep band may stand inside that bore (the bore's offset from
    the outline, :attr:`~tabletcad.tooling.outline.TabletFrame.bore_offset`, plus the PDE band's inward
    bow, :attr:`~tabletcad.geometry.tablet.Band.inward`, plus the B-rep's fit to the PDE surface,
    ``Tolerances.fit``); the largest gap allowed is the larger of it and ``clearance`` (a PDE band's bulge
    puts the bore at least 1e-6 mm out, for which a line-to-line fit, clearance 0, had been refused: a
    rounded rectangle's largest gap 9.9e-7 mm, a capsule's 1.09e-6, another rounded rectangle's 3.1e-6)."""
    t0 = time.perf_counter()
    gap_args = (tablet, parts, clearance, deflection, refine, tablet_model)
    if forked:
        from tabletcad.io.forked import Forked

        mesh_arrays(tablet, deflection, 0.2)  # meshed here on every core, before the child, which needs it too
        with Forked(lambda: _largest_gap(*gap_args)) as child:
            pairs = _overlaps(tablet, parts, deflection, bore)
            t1 = time.perf_counter()
            gap = child.result()
    else:
        pairs = _overlaps(tablet, parts, deflection, bore)
        t1 = time.perf_counter()
        gap = _largest_gap(*gap_args)
    gap_s = gap.pop("_seconds")  # its own time (beside the overlaps' when forked)
    occ_max = max(p["occ_mm3"] for p in pairs)
    man_max = max(p["manifold3d_mm3"] for p in pairs)
    return dict(
        interference_mm3=occ_max,
        interference_method="OCC, largest over all pairs of parts: BRepAlgoAPI_Common with the tablet "
                            "(BOPAlgo_GlueFull for the punches, which share its faces; for the die, first the tablet "
                            "with the outside of the bore's column and the die with the column), exact distance "
                            "between tools (or their bounding boxes' distance when the boxes are apart)",
        interference_manifold3d_mm3=man_max,
        interference_manifold3d_bound_mm3=max(p["manifold3d_bound_mm3"] for p in pairs),
        **gap,
        punch_die_clearance_mm=min(p["min_distance_mm"] for p in pairs if p["parts"][1] == "die" and p["parts"][0].endswith("punch")),
        # the precision of that distance: the punches' and the die's largest B-rep tolerance (a tip's cup
        # rim is a Boolean's section edge, a few micrometres from the exact curve at most)
        punch_die_clearance_tolerance_mm=max(_largest_tolerance(s) for n, s in parts.items()
                                             if n == "die" or n.endswith("punch")),
        clearance_mm=clearance,
        gap_allowed_mm=max(clearance, band_gap),
        gap_within_clearance=bool(gap["max_gap_mm"] <= max(clearance, band_gap) * (1 + 1e-6) + 1e-7),
        pairs=pairs,
        deflection_mm=deflection,
        seconds=dict(overlap=t1 - t0, gap=gap_s),
    )


def _overlaps(tablet, parts: dict, deflection: float, bore=None) -> list[dict]:
    """Every pair of ``{"tablet": tablet, **parts}``: its overlap by OCC (or a proof that it is 0) and by manifold3d.

    ``bore``: the die bore's plan wire (see :func:`interference`).  The tablet's Common with a punch is taken
    with the punch's mesh moved :data:`PUNCH_LIFT` along z (``manifold3d_lift_mm``), its bound grown by
    :func:`lift_allowance` (7.7e-5 to 1.1e-3 mm^3 on the samples, on bounds of 0.8 to 2.3 mm^3)."""
    shapes = {"tablet": tablet, **parts}
    manifolds = {k: to_manifold(s, deflection) for k, s in shapes.items()}
    areas = {k: bound_area(s, deflection) for k, s in shapes.items()}  # for the manifold3d bounds only
    pairs = []
    for a, b in itertools.combinations(shapes, 2):
        entry = dict(parts=[a, b])
        if (a, b) == ("tablet", "die") and bore is not None and inside_bore(tablet, parts["die"], bore):
            occ, how = 0.0, BORE_PROOF
        else:
            occ, how = _occ_overlap(a, b, shapes, entry)
        mb, bound = manifolds[b], deflection * min(areas[a], areas[b])
        lift = PUNCH_LIFT.get(b, 0.0) if a == "tablet" else 0.0
        if lift:
            mb = mb.translate((0.0, 0.0, lift))
            bound += lift_allowance(*mesh_arrays(shapes[b], deflection, 0.2), abs(lift))
            entry["manifold3d_lift_mm"] = lift
        mv = manifold_volume(manifold_op("common", manifolds[a], mb))
        entry.update(occ_mm3=occ, occ_method=how, manifold3d_mm3=mv, manifold3d_bound_mm3=bound)
        pairs.append(entry)
    return pairs


#: how far (mm, along z) each punch's mesh is moved away from the tablet's for manifold3d's Common with it:
#: a punch tip shares its cup with the tablet (the same faces, meshed alike, where the tablet has a land), and
#: manifold3d's Common of coincident triangles took 0.28-0.39 CPU s a punch on the capsule against 0.04 s
#: with the meshes 1e-11 to 1e-5 mm apart (manifold3d's own tolerance is ~1e-12 of the coordinates)
MANIFOLD_LIFT_MM = 1e-6
PUNCH_LIFT = {"upper_punch": MANIFOLD_LIFT_MM, "lower_punch": -MANIFOLD_LIFT_MM}


def lift_allowance(V: np.ndarray, T: np.ndarray, lift: float) -> float:
    """How much (mm^3) moving the closed mesh ``(V, T)`` by ``lift`` along z can change its overlap with anything.

    A vertical line meets the mesh's solid in ``n`` intervals and crosses its boundary ``2 n`` times; the
    moved solid's section leaves at most ``lift`` of each interval uncovered (and covers at most ``lift``
    more beyond it), so the overlap changes by at most ``lift`` times the integral of ``n`` over the plane,
    which is half the triangles' area projected on the xy plane (each crossing is one triangle over the point).

    Parameters
    ----------
    V, T : numpy.ndarray
        The mesh's vertices (n, 3) (mm) and triangles (m, 3), closed.
    lift : float
        The move's length (mm, >= 0).

    Returns
    -------
    float
        ``lift`` times half the projected area (mm^3): reached by a solid resting on flat faces it sinks into.
    """
    a, b, c = V[T[:, 0]], V[T[:, 1]], V[T[:, 2]]
    u, v = b - a, c - a
    projected = 0.5 * np.abs(u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0])  # (the z of each triangle's area vector)
    return float(lift * 0.5 * projected.sum())


#: the method of a tablet-die overlap proved 0 by :func:`inside_bore`
BORE_PROOF = ("disjoint (inside the die bore's column: BRepAlgoAPI_Common of the tablet with the column's "
              "outside and of the die with the column, both empty)")

#: how far (mm) the block around the tablet in :func:`inside_bore` stands outside its bounding box
BLOCK_MARGIN_MM = 1.0


def inside_bore(tablet, die, bore) -> bool:
    """Whether two exact Commons prove that ``tablet`` and ``die`` do not overlap.

    The block is the tablet's bounding box (``BRepBndLib``: never smaller than the tablet) grown by
    :data:`BLOCK_MARGIN_MM`, the column the ``bore`` wire extruded through the block (1 mm beyond it).
    The tablet lies in the block, so its overlap with the die is at most its overlap with the block
    less the column plus the die's overlap with the column: 0 when both Commons are empty.  Neither
    meets the die's taper cone along the tablet's rim, the costly part of the tablet-die Common, and
    neither needs the fuzzy value that Common needs: an exact proof.  A taper only widens the die's
    opening above the bore, so the die's Common with the column is empty for a die made with that bore.
    On the 14 family samples at a 1 deg taper: 3.5 CPU s in all against 11.1 s for the exact distance
    and the fuzzy Common with the die (the almond 0.16 against 2.81 s; the modified capsule 0.91
    against 0.76 s; ``benchmarks/bench_overlap.py``).

    Parameters
    ----------
    tablet, die : TopoDS_Shape
        Solids at the closed position (mm).
    bore : TopoDS_Wire
        The die bore's plan wire at ``z = 0`` (:func:`~tabletcad.tooling.die.bore_wire`).

    Returns
    -------
    bool
        True when both Commons have volume 0 mm^3 (then the overlap is 0); False otherwise (a Boolean
        that fails included), and then nothing is proved: the tablet's Common with the die itself decides.
    """
    block, (z0, z1) = _block(tablet, BLOCK_MARGIN_MM)
    try:
        column = prism(bore, z0 - 1.0, z1 + 1.0)
        outside = raw_boolean("cut", block, column)
        if volume(raw_boolean("common", tablet, outside)) != 0.0:
            return False
        return volume(raw_boolean("common", die, column)) == 0.0
    except GeometryError:  # a Boolean that fails proves nothing
        return False


def _block(shape, margin: float) -> tuple[object, tuple[float, float]]:
    """A box solid holding ``shape`` with ``margin`` (mm) to spare, and its z range ``(z0, z1)`` (mm)."""
    box = _box(shape)
    lo, hi = box.CornerMin().Coord(), box.CornerMax().Coord()
    return box_solid(lo, hi, margin), (lo[2] - margin, hi[2] + margin)


def _occ_overlap(a: str, b: str, shapes: dict, entry: dict) -> tuple[float, str]:
    """The OCC overlap (mm^3) of parts ``a`` and ``b`` of ``shapes`` and how it was found; a minimum
    distance measured on the way goes into ``entry``."""
    if not (a == "tablet" and b.endswith("punch")):
        # parts that need not touch: an exact minimum distance > 0 proves a zero overlap
        # (a Common of the punch's cup against the die's taper cone can take 20 s; a Common of
        # the tablet's band against a bore 1e-6 mm away returns slivers of ~1e-6 mm^3 that are
        # not there - the tapered almond die)
        gap = _box(shapes[a]).Distance(_box(shapes[b]))
        if gap > 1e-7:
            # bounding boxes apart (the two punches, a band apart): a lower bound of the distance
            # proves the zero overlap (BRepExtrema took 2 s on two punches carrying letters)
            entry["min_distance_lower_bound_mm"] = float(gap)
            return 0.0, "disjoint (bounding boxes apart, Bnd_Box)"
        dss = _distance_shapes(shapes[a], shapes[b])
        entry["min_distance_mm"] = float(dss.Value()) if dss.IsDone() else None
        if entry["min_distance_mm"] is not None and entry["min_distance_mm"] > 1e-7:
            return 0.0, "disjoint (BRepExtrema_DistShapeShape)"
    # a punch's face *is* the tablet's face: OCC's full gluing mode skips re-intersecting the
    # shared surfaces (a plain Common takes 10-20 s on them); manifold3d checks independently
    glue = a == "tablet" and b.endswith("punch")
    # the tablet's band touches the die's bore (or lies MIN_BORE_OFFSET_MM inside it): an exact
    # Common of such near-coincident faces returns slivers of ~1e-6 mm^3 that are not there (a
    # 1 deg taper on the almond: 8.9e-6 mm^3); the fuzzy Boolean treats closer faces as touching
    fuzzy = MIN_BORE_OFFSET_MM if (a == "tablet" and b == "die") else 0.0
    common = raw_boolean("common", shapes[a], shapes[b], glue=glue, fuzzy=fuzzy)
    how = "BRepAlgoAPI_Common" + (" (BOPAlgo_GlueFull: shared faces)" if glue else "") + (
        f" (fuzzy {fuzzy:g} mm: the band touches the bore)" if fuzzy else "")
    if not fuzzy:
        return volume(common), how
    # pieces thinner than the B-rep's fit are the B-rep's: an almond with 1.235 mm end arcs has its band's
    # B-spline faces (4.3e-5 mm from the PDE surface) 7.5e-6 mm through a bore 1e-6 mm out at its ends,
    # four slivers of 1.2e-5 mm^3 the build had been refused for
    solids = explore(common, "Solid")
    thin = [_thickness(s) <= FIT_MM for s in solids]
    if not any(thin):
        return volume(common), how
    entry["occ_thinner_than_the_fit_mm3"] = sum(volume(s) for s, t in zip(solids, thin) if t)
    how += f"; {sum(thin)} solids thinner than the B-rep's fit ({FIT_MM:g} mm) left out"
    return float(sum(volume(s) for s, t in zip(solids, thin) if not t)), how


#: how thin (mm) a piece of a tablet's Common with its die may be and be taken as the B-rep's, not the design's:
#: the tablet's faces stand within ``Tolerances.fit`` of its PDE surface, which the bore clears
FIT_MM = DEFAULT.fit


def _thickness(solid) -> float:
    """A solid's mean thickness (mm): twice its volume over its boundary's area (a slab's thickness)."""
    area = sum(face_area(f) for f in explore(solid, "Face"))
    return 2.0 * volume(solid) / area if area > 0.0 else 0.0


def _largest_gap(tablet, parts: dict, clearance: float, deflection: float, refine: int, tablet_model) -> dict:
    """The tablet's largest gap to the tools (mm), where it is and how it was found (the ``max_gap_*`` keys)."""
    t1 = time.perf_counter()
    # gap: points on the tablet's surface (its mesh vertices, plus its PDE patches sampled densely
    # towards their edges, kept where they lie on the featured solid) against the parts' meshes.
    # A face of the tablet that is also a face of a tool (IsSame: a punch's tip is cut from the
    # tablet and keeps its cup, score and letter faces) lies on that tool's boundary, at distance 0
    # from it everywhere: only the others (the lands, the band) can hold the largest gap
    faces = explore(tablet, "Face")
    contact = _contact_faces(faces, parts)
    free = [f for k, f in enumerate(faces) if k not in contact]
    V, T = mesh_arrays(tablet, deflection, 0.2)
    if contact and free:
        T = T[~np.isin(mesh_face_ids(tablet, deflection, 0.2), sorted(contact))]
        used = _used(T, len(V))
        V, T = V[used], (np.cumsum(used) - 1)[T]  # (the vertices kept, renumbered in their order)
    if tablet_model is not None:
        S = _surface_samples(tablet_model)
        keep = mesh_distance(S, V, T, reach=2.0 * deflection) <= 2.0 * deflection  # farther: inf, dropped as before
        V = np.vstack([V, S[keep]])
    n_mesh = len(V)
    V = np.vstack([V, face_samples(tablet, spacing=max(0.25 * clearance, 0.005), faces=free)])  # inside every B-rep face
    # the tools' chord heights must be well below the gaps to be ranked (a gap of clearance/2 on a
    # land against chords of 5 µm would be outranked by chord artefacts on the cups)
    tool_deflection = min(deflection, max(0.1 * clearance, 1e-3))
    # each tool's triangles near the tablet, long ones split (slivers of a die's flat faces
    # make an AABB tree slow): distances are unchanged, only the search is cheaper.  Distances
    # beyond ``reach`` are not needed (the gap is a fraction of it).  Triangles of 50 clearances
    # (1 mm at 0.02 mm) search fastest: split to 0.32 mm, longest-edge bisection keeps a bore's
    # slivers thin and multiplies them (a capsule's die 1,804 -> 176,178 triangles, its tree 0.6 s
    # to build and slower to ask; at 1 mm 21,296), unsplit ones defeat the centres' prefilter
    reach = 2.0 * max(4.0 * clearance, 0.05)
    h_split = max(50.0 * clearance, 1.0)
    lo, hi = coordinate_range([V], 3)
    lo, hi = lo - 2 * reach, hi + 2 * reach
    # each tool meshed where it can be within reach of those faces (a punch's letters and head are not)
    boxes = [_box(f) for f in (free if contact and free else [tablet])]
    tools = [MeshDistance(*refine_triangles(*_mesh_near(s, boxes, 2.0 * reach, tool_deflection), h_split, lo, hi),
                          reach=reach) for s in parts.values()]

    def measure(P):
        # the nearest tool, its distance and its point nearest to P
        best, which = np.full(len(P), np.inf), np.zeros(len(P), dtype=np.int64)
        q = np.full((len(P), 3), np.nan)
        for j, tool in enumerate(tools):
            d, c = tool(P, closest=True)
            nearer = d < best
            best[nearer], which[nearer], q[nearer] = d[nearer], j, c[nearer]
        return best, which, q

    dist, near, nearest = measure(V)
    # tablet triangles whose corners are nearest to different tools (the land between a punch tip and
    # the die bore): the gap peaks inside such triangles, away from every vertex - search them
    n_t = int(T.max()) + 1 if len(T) else 0
    nc = near[:n_t][T]
    sel = nc.min(axis=1) != nc.max(axis=1)
    n_refined = 0
    # the distance to the tools has slope <= 1: within triangles of edges <= h every point lies within
    # h / sqrt(3) of a corner, so a peak inside a searched triangle is missed by at most that much
    refined_spacing = max(0.125 * clearance, 1e-3)
    if np.any(sel):
        Vs, ds = largest_inside(V[:n_t][T[sel]], dist[:n_t][T[sel]], lambda P: measure(P)[::2], refined_spacing,
                                float(np.max(dist)), anchors=nearest[:n_t][T[sel]])
        V, dist = np.vstack([V, Vs]), np.concatenate([dist, ds])
        n_refined = len(Vs)
    order = np.argsort(dist)[::-1][:refine]
    # the worst points, moved onto the tablet's B-rep surface (mesh points lie within the chord height
    # of it), measured exactly against every tool's B-rep
    on_surface = [p for _, p in map(ExactDistance(explore(tablet, "Shell")[0]).nearest, V[order])]
    # a tool whose mesh is farther than the nearest tool's by more than ten chord heights cannot be
    # the nearest B-rep (its exact distance is within a chord height of its mesh distance)
    exact_tools = [ExactDistance(s) for s in parts.values()]
    d_mesh = np.stack([tool(np.array(on_surface).reshape(-1, 3)) for tool in tools]) if on_surface else None
    exact = [min(exact_tools[j](q) for j in range(len(tools))
                 if d_mesh[j, i] <= d_mesh[:, i].min() + 10.0 * tool_deflection + 1e-9)
             for i, q in enumerate(on_surface)]
    i_max = int(np.argmax(exact)) if exact else 0
    return dict(
        max_gap_mm=float(exact[i_max]) if exact else float(np.max(dist)),
        max_gap_point_mm=[float(x) for x in on_surface[i_max]] if exact else None,
        max_gap_method=(f"{len(contact)} of the tablet's {len(faces)} faces are faces of a tool (distance 0); on the others, "
                        if contact and free else "") +
                       f"tablet surface points ({len(V)}: {n_mesh} mesh vertices and PDE samples, "
                       f"{len(V) - n_mesh - n_refined} on a (u, v) grid in every B-rep face, {n_refined} by branch and bound in "
                       f"triangles between tools) vs part meshes at {tool_deflection:.3g} mm (exact point-to-mesh distances, libigl; largest {float(np.max(dist)):.6g} mm), "
                       f"worst {len(order)} moved onto the tablet's B-rep and re-measured exactly (BRepExtrema_ExtPF/ExtPC on every "
                       f"face and edge, as BRepExtrema_DistShapeShape)",
        max_gap_mesh_mm=float(np.max(dist)),
        max_gap_resolution_mm=refined_spacing / math.sqrt(3.0) if n_refined else None,
        _seconds=time.perf_counter() - t1,
    )
