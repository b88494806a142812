"""Plan outlines for swept tablet faces, with exact inward offsets and distances.

A tablet family with a shaped plan is a *sweep*: at every height of the cup
profile the face is the outline offset inward by the profile's distance ``d``
(section "sweep" in :mod:`tabletcad.families.sweep`).  This module supplies the
outline: a closed, counter-clockwise, tangent-continuous (G1) chain of straight
lines and circular arcs (:class:`PlanOutline`) or a periodic spline through
given points (:class:`SplineOutline`).  Both offer

* ``point(v, der)``, ``normal(v, der)``: the outline ``O(v)`` and its unit
  inward normal ``N(v)`` (and ``v``-derivatives), ``v = 2π s / P`` with ``s``
  the arc length of the *original* outline, so every offset ``O + d N`` is
  parametrised by its foot point (offsets of lines stay lines, of arcs stay
  concentric arcs of radius ``r ∓ d``);
* ``signed_distance(xy)``: exact distance (mm) from plan points to the outline,
  positive inside;
* ``check_offset(d, parameter)``: refuse (``DesignError``) an inward offset
  beyond the smallest convex arc radius or the inscribed radius.

All lengths are millimetres, angles radians.
"""

from __future__ import annotations

import math
from typing import Any, Callable

import numpy as np

from tabletcad.geometry.curves import _MEASURE_ALL, Seg, nearest_of, signed_area
from tabletcad.errors import DesignError, check_finite, check_positive, check_range, format_bound
from tabletcad.tolerance import DEFAULT
from tabletcad.geometry.quadrature import gauss_legendre
from tabletcad.geometry.vectors import clip, length2, linspace

__all__ = [
    "Seg",
    "PlanOutline",
    "SplineOutline",
    "circle_outline",
    "stadium_outline",
    "four_arc_oval",
    "four_arc_oval_from_side_radius",
    "rounded_polygon",
    "offset_bounds_inset",
    "rounded_rectangle_outline",
    "outline_from_items",
]



_line, _arc = Seg.line, Seg.arc

#: How many ``v`` sample arrays an outline remembers the frames of (:meth:`PlanOutline.frame`).
_FRAME_MEMO = 16

#: Results of the outline checks (:meth:`PlanOutline._offset_is_clean`, ``extent``, ``star_limit``, the
#: simplicity check) by the exact chain of segments (``repr``: every float to its last bit, -0.0 apart from 0.0)
#: and the question: a family builds a new, equal outline on every build, and a search of the tablet's band or
#: cup depth builds it some hundred times (:mod:`tabletcad.families.inverse`).  The latest ``_SHAPE_MEMO_SIZE``.
_SHAPE_MEMO: dict = {}
_SHAPE_MEMO_SIZE = 2048


class PlanOutline:
    """Closed CCW G1 chain of lines and arcs in the plane (mm).

    Parameters
    ----------
    segs : list of Seg
        Joined end to start; reversed automatically when clockwise.
    name : str
    parameter : str
        Name used in error messages (e.g. ``"outline"``).

    Raises
    ------
    DesignError
        Gaps between segments, corners (tangent jumps), zero-length segments
        or a self-intersecting outline.
    """

    def __init__(self, segs: list[Seg], name: str = "outline", parameter: str = "outline") -> None:
        if not segs:
            raise DesignError(parameter, "no segments", "an outline needs at least one line or arc")
        segs = list(segs)
        scale = max(max(abs(c) for s in segs for c in (*s.p0, *s.p1)), 1.0)
        for i, s in enumerate(segs):
            if not s.length > 1e-9 * scale:
                raise DesignError(parameter, f"segment {i} of length {s.length:.3g} mm", "every segment must have length > 0")
            if s.kind == "arc" and not s.radius > 0:
                raise DesignError(parameter, f"arc {i} radius {s.radius:g}", "arc radii must be > 0 mm")
        for i, s in enumerate(segs):
            prev = segs[i - 1]
            gap = math.hypot(prev.p1[0] - s.p0[0], prev.p1[1] - s.p0[1])
            if gap > DEFAULT.seam_gap * scale:
                raise DesignError(parameter, f"gap of {gap:.3g} mm before segment {i}", "segments must join end to start")
            t_prev, t_next = prev.tangent(1), s.tangent(0)
            ang = math.degrees(math.atan2(abs(float(t_prev[0] * t_next[1] - t_prev[1] * t_next[0])), float(np.dot(t_prev, t_next))))
            if ang > 1e-4:
                raise DesignError(
                    parameter, f"corner of {ang:.3g} deg before segment {i}",
                    "the outline must be tangent-continuous (round every corner with an arc)",
                )
        self.name = name
        self.parameter = parameter
        if signed_area(segs) < 0:
            segs = [s.reversed() for s in reversed(segs)]
        self.segs = tuple(segs)
        self._len = np.array([s.length for s in self.segs])
        self._cum = np.concatenate([[0.0], np.cumsum(self._len)])
        self.perimeter = float(self._cum[-1])
        self.area = abs(signed_area(list(self.segs)))
        self._shape_key = repr(self.segs)
        self._remembered(("simple", self.parameter), self._check_simple)  # (a refusal raises: never remembered)

    def _remembered(self, question: tuple, answer: Callable[[], Any]) -> Any:
        """``answer()``, remembered for every outline of the same segments (:data:`_SHAPE_MEMO`), or for this
        outline only when it has no chain of segments (a :class:`SplineOutline`).  Immutable answers only."""
        key = getattr(self, "_shape_key", None)
        store = _SHAPE_MEMO if key is not None else self.__dict__.setdefault("_memo", {})
        full = (key, question)
        try:
            return store[full]
        except KeyError:
            pass
        value = answer()
        if len(store) >= _SHAPE_MEMO_SIZE:
            store.pop(next(iter(store)), None)
        store[full] = value
        return value

    # ------------------------------------------------------------------ geometry
    @property
    def breaks(self) -> np.ndarray:
        """Parameters ``v`` (rad) of the segment joins, including 0 and 2π."""
        return self._cum * (math.tau / self.perimeter)

    @property
    def smooth_breaks(self) -> np.ndarray:
        """Joins in ``[0, 2π)`` where the curvature jumps (none for a single circle)."""
        if len(self.segs) == 1:
            return np.zeros(0)
        return self.breaks[:-1]

    @property
    def is_circle(self) -> bool:
        """True when the outline is one full circle (then, parametrised by arc length, its
        points and offsets are Fourier mode 1 only)."""
        return len(self.segs) == 1 and self.segs[0].kind == "arc" and abs(abs(self.segs[0].sweep) - math.tau) <= 1e-12

    @property
    def diameter(self) -> float:
        """The largest distance (mm) between two points of the outline: its diameter (largest Feret
        width; the diagonal of a rounded square, the length of a capsule), in closed form.

        The distance from a point to a line's points is convex along it, so a line contributes only its
        ends; the point of an arc farthest from ``p`` lies on the ray from ``p`` through its centre
        (``|p - c| + r``) when that direction is within the arc's span; the farthest pair of points of
        two arcs lies on the line through their centres (``|c_a - c_b| + r_a + r_b``) when both
        directions are within their spans (an arc of at least half a turn holds a pair ``2 r`` apart).
        The maximum over the joins' pairs, each join and arc, and each pair of arcs is the diameter."""
        if "_diameter" not in self.__dict__:
            ends = np.array([s.p0 for s in self.segs], dtype=float)
            best = float(np.max(np.linalg.norm(ends[:, None, :] - ends[None, :, :], axis=2)))
            arcs = [s for s in self.segs if s.kind == "arc"]

            def within(a, u) -> bool:
                return bool(a.within_sweep(np.float64(u[0]), np.float64(u[1]), np.float64(1.0)))

            for k, a in enumerate(arcs):
                ca = np.asarray(a.center)
                for p in ends:  # a join and the arc: the arc's point across its centre from the join
                    w = ca - p
                    rho = float(np.linalg.norm(w))
                    if rho > 0.0 and within(a, w / rho):
                        best = max(best, rho + a.radius)
                for b in arcs[k:]:
                    w = ca - np.asarray(b.center)
                    rho = float(np.linalg.norm(w))
                    if b is a:
                        if abs(a.sweep) >= math.pi:
                            best = max(best, 2.0 * a.radius)
                    elif rho > 1e-12 * max(a.radius, b.radius):
                        u = w / rho
                        if within(a, u) and within(b, -u):
                            best = max(best, rho + a.radius + b.radius)
                    else:  # concentric: a direction of a's span whose opposite is in b's
                        ends_a = [a.theta0, a.theta0 + a.sweep]
                        ends_b = [b.theta0, b.theta0 + b.sweep]
                        if any(within(b, (-math.cos(t), -math.sin(t))) for t in ends_a) or \
                                any(within(a, (-math.cos(t), -math.sin(t))) for t in ends_b):
                            best = max(best, a.radius + b.radius)
            self.__dict__["_diameter"] = best
        return self.__dict__["_diameter"]

    @property
    def min_convex_radius(self) -> float:
        """Smallest radius of a convex arc (inf without arcs), mm."""
        r = [s.radius for s in self.segs if s.kind == "arc" and s.sweep > 0]
        return min(r) if r else math.inf

    def _locate(self, v: np.ndarray):
        s = np.mod(v, math.tau) * (self.perimeter / math.tau)
        # clipped to the segments in place (np.clip's cost per call)
        idx = np.searchsorted(self._cum, s, side="right") - 1
        np.maximum(idx, 0, out=idx)
        np.minimum(idx, len(self.segs) - 1, out=idx)
        return s, idx

    def frame(self, v) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Point ``O``, unit tangent ``T``, inward normal ``N`` (each (m, 2)) and
        signed curvature ``κ`` (m,) (1/mm, > 0 on convex arcs) at ``v``; read-only arrays.

        A swept tablet's patches evaluate their boundary data (offsets of this outline) on
        the same ``v`` samples again and again, so frames of ``v`` arrays up to 8192 samples
        are remembered (the last :data:`_FRAME_MEMO` of them, keyed on the samples' bytes;
        grid-sized arrays and short ones, such as a polish's few samples that a patch's four
        data ask for in turn, in two memos, so that the short ones never push out the grids).
        """
        v = np.asarray(v, dtype=float).reshape(-1)
        if v.size > 8192:
            return self._frame(v)
        memo = self.__dict__.setdefault("_frame_memo" if v.size >= 64 else "_frame_memo_short", {})
        key = v.tobytes()
        hit = memo.get(key)
        if hit is None:
            hit = self._frame(v)
            for a in hit:
                a.setflags(write=False)
            if len(memo) >= _FRAME_MEMO:
                memo.pop(next(iter(memo)))
            memo[key] = hit
        return hit

    def _frame(self, v: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        s, idx = self._locate(v)
        arc, p0, d, centre, radius, theta0, sg = self._segment_table()
        # every point by its own segment's formula, gathered from the table (the same arithmetic as
        # segment by segment, without a Python loop over segments)
        # (rows of the (segments, 2) tables by take: fancy indexing steps an iterator per row)
        # (pairs of columns written into (m, 2) arrays: column_stack's cost per call, the same values)
        t = s - self._cum[idx]
        a = arc[idx]
        g = sg[idx]
        r = radius[idx]
        th = theta0[idx] + g * t / r
        c, sn = np.cos(th), np.sin(th)
        dk = np.take(d, idx, axis=0)
        rim = np.empty((v.size, 2))
        np.multiply(r, c, out=rim[:, 0])
        np.multiply(r, sn, out=rim[:, 1])
        O = np.where(a[:, None], np.take(centre, idx, axis=0) + rim,
                     np.take(p0, idx, axis=0) + t[:, None] * dk)
        turn = np.empty((v.size, 2))
        np.multiply(-g, sn, out=turn[:, 0])
        np.multiply(g, c, out=turn[:, 1])
        T = np.where(a[:, None], turn, dk)
        k = np.where(a, g / r, 0.0)
        N = np.empty((v.size, 2))
        np.negative(T[:, 1], out=N[:, 0])
        N[:, 1] = T[:, 0]
        return O, T, N, k

    def _segment_table(self) -> tuple[np.ndarray, ...]:
        """Per segment: whether it is an arc, a line's start and unit direction, an arc's centre,
        radius, start angle and turning sign (an arc's line entries and a line's arc entries are
        harmless fillers).  Built once."""
        hit = self.__dict__.get("_segtab")
        if hit is None:
            n = len(self.segs)
            arc = np.array([q.kind != "line" for q in self.segs])
            p0, d, centre = np.zeros((n, 2)), np.zeros((n, 2)), np.zeros((n, 2))
            radius, theta0, sg = np.ones(n), np.zeros(n), np.zeros(n)
            for i, q in enumerate(self.segs):
                if q.kind == "line":
                    p0[i] = q.p0
                    d[i] = np.subtract(q.p1, q.p0) / q.length
                else:
                    centre[i], radius[i], theta0[i] = q.center, q.radius, q.theta0
                    sg[i] = math.copysign(1.0, q.sweep)
            hit = (arc, p0, d, centre, radius, theta0, sg)
            for x in hit:
                x.setflags(write=False)
            self.__dict__["_segtab"] = hit
        return hit

    @property
    def speed(self) -> float:
        """``ds/dv = P / 2π`` (mm per rad)."""
        return self.perimeter / math.tau

    def point(self, v, der: int = 0) -> np.ndarray:
        """``d^der O / dv^der``, shape (m, 2)."""
        O, T, N, k = self.frame(v)
        g = self.speed
        if der == 0:
            return O
        if der == 1:
            return T * g
        if der == 2:
            return (k * g * g)[:, None] * N
        raise ValueError(f"der = {der} is not allowed: must be 0, 1 or 2")

    def normal(self, v, der: int = 0) -> np.ndarray:
        """``d^der N / dv^der`` of the unit inward normal, shape (m, 2)."""
        O, T, N, k = self.frame(v)
        g = self.speed
        if der == 0:
            return N
        if der == 1:
            return -(k * g)[:, None] * T
        if der == 2:
            return -(k * k * g * g)[:, None] * N
        raise ValueError(f"der = {der} is not allowed: must be 0, 1 or 2")

    def offset(self, v, der: int, alpha: float, beta: float) -> np.ndarray:
        """``d^der/dv^der (alpha O + beta N)`` (mm), shape (m, 2): :meth:`point` and
        :meth:`normal` combined from one :meth:`frame` (a swept tablet's boundary data)."""
        return self.offsets(v, der, np.array([alpha]), np.array([beta]))[0]

    def offsets(self, v, der: int, alphas: np.ndarray, betas: np.ndarray) -> np.ndarray:
        """:meth:`offset` for several weights at once, ``(len(alphas), m, 2)`` (mm), from one :meth:`frame`
        (the same arithmetic as each :meth:`offset`)."""
        if der not in (0, 1, 2):
            raise ValueError(f"der = {der} is not allowed: must be 0, 1 or 2")
        O, T, N, k = self.frame(v)
        g = self.speed
        a = np.asarray(alphas, dtype=float).reshape(-1, 1)
        b = np.asarray(betas, dtype=float).reshape(-1, 1)
        if der == 0:
            return a[:, :, None] * O + b[:, :, None] * N
        if der == 1:
            return (g * (a - b * k))[:, :, None] * T
        return ((a * k - b * k * k) * g * g)[:, :, None] * N

    def centroid(self) -> np.ndarray:
        """Area centroid (mm), exact for lines and arcs."""
        sx = sy = 0.0
        for s in self.segs:
            if s.kind == "line":  # the same integrals as the arcs' (the triangle fan's moments are another
                # split of the total: mixed with the arcs' they had put a rounded triangle's centroid
                # 0.068 mm off its centre at a corner radius of 3 mm on an 11 mm side)
                (x0, y0), (x1, y1) = s.p0, s.p1
                sx += (y1 - y0) * (x0 * x0 + x0 * x1 + x1 * x1) / 6.0
                sy -= (x1 - x0) * (y0 * y0 + y0 * y1 + y1 * y1) / 6.0
            else:
                # ∮ x² dy / 2 and -∮ y² dx / 2 over the arc, by Gauss-Legendre (exact to rounding)
                xg, wg = gauss_legendre(24)
                th = s.theta0 + 0.5 * s.sweep * (xg + 1)
                w = 0.5 * s.sweep * wg
                x = s.center[0] + s.radius * np.cos(th)
                y = s.center[1] + s.radius * np.sin(th)
                dx = -s.radius * np.sin(th)
                dy = s.radius * np.cos(th)
                sx += float(np.sum(w * x * x * dy)) / 2.0
                sy -= float(np.sum(w * y * y * dx)) / 2.0
        a = signed_area(list(self.segs))
        return np.array([sx / a, sy / a])

    def extent(self) -> tuple[float, float]:
        """Length (x) and width (y) of the outline's bounding box (mm)."""
        return self._remembered(("extent",), self._extent)

    def _extent(self) -> tuple[float, float]:
        p = self.frame(linspace(0, math.tau, 4096, endpoint=False))[0]
        for s in self.segs:
            if s.kind == "arc":
                for ang in (0.0, math.pi / 2, math.pi, 1.5 * math.pi):
                    rel = (ang - s.theta0) * math.copysign(1.0, s.sweep) % math.tau
                    if rel <= abs(s.sweep):
                        p = np.vstack([p, [s.center[0] + s.radius * math.cos(ang), s.center[1] + s.radius * math.sin(ang)]])
        ext = np.ptp(p, axis=0)
        return float(ext[0]), float(ext[1])

    # ------------------------------------------------------------------ distances
    def signed_distance(self, xy) -> np.ndarray:
        """Exact distance (mm) from plan points ``xy`` (m, 2) to the outline, > 0 inside.

        The distance and side of the nearest segment (the first of equals in the chain's
        order): for up to 1,024 points every segment measured at every point at once
        (:class:`_SegmentColumns`), for more each segment only where its bounding circle allows
        it to be the nearest (:func:`~tabletcad.geometry.curves.nearest_of`); a circle's is
        ``R - |xy - c|``.
        """
        if self.is_circle:
            s = self.segs[0]
            p = np.asarray(xy, dtype=float).reshape(-1, 2)
            return s.radius - np.hypot(p[:, 0] - s.center[0], p[:, 1] - s.center[1])
        p = np.asarray(xy, dtype=float).reshape(-1, 2)
        if len(p) <= _MEASURE_ALL:  # every segment measured at every point: all segments at once
            table = self._remembered(("segment columns",), lambda: _SegmentColumns(self.segs))
            return table.signed_distance(p)
        best, _, sign = nearest_of(self.segs, p, _signed_to_segment)
        return sign * best

    def inscribed_radius(self) -> float:
        """Largest inward distance reached inside the outline (mm), to ~1e-9 mm (:meth:`_inscribed_radius`,
        remembered: the tooling's checks ask for it once a figure)."""
        return self._remembered(("inscribed_radius",), self._inscribed_radius)

    def _inscribed_radius(self) -> float:
        """Largest inward distance reached inside the outline (mm), to ~1e-9 mm.

        The best of an 81 × 81 grid over the outline's box, polished from every peak of the grid that
        could lead to the largest: the signed distance changes by at most the distance moved, so the
        deepest point lies within half a cell's diagonal ``δ`` of a grid point reading at least the grid's
        best less ``δ``.  The grid's local maxima (no neighbour higher) above that level are the starts,
        adjacent ones as one, from its best (a ridge of equal depth along the grid's rows or columns, as a
        capsule's sides: one start; across them, as a turned capsule's, a staircase of starts a cell or two
        apart, each polished); two lobes of an outline, with their own deepest points, are two starts.  On
        a chain of lines and arcs each start is polished by the steps of
        :func:`~tabletcad.families.deepest.deepest_near` (linear programmes in the distances to the
        segments near it, within a box of ``2 δ`` that shrinks as they converge: on lines the first step
        lands on the deepest point) reading :meth:`_point_signed_distance` (plain floats, the arithmetic
        of :meth:`signed_distance` without numpy's cost per call on one point), by Nelder–Mead where those
        steps do not settle and on a circle; the result is :meth:`signed_distance` at the point found.
        (Nelder–Mead alone, ~200 calls a start, had taken 3.6 ms on the custom_outline sample, the steps
        1.7; on 514 random filleted polygons, convex and concave, 9.1 against 3.7 ms, the steps' radius
        as deep as Nelder–Mead's or deeper, by at most 3.2e-12 mm, 1.3e-12 relative.)
        """
        from scipy.ndimage import label, maximum_filter
        from scipy.optimize import minimize

        from tabletcad.families.deepest import deepest_near, distance_jets

        n = 81
        c0 = self.frame(linspace(0, math.tau, 512, endpoint=False))[0]
        lo, hi = c0.min(axis=0), c0.max(axis=0)
        g = np.stack(np.meshgrid(linspace(lo[0], hi[0], n), linspace(lo[1], hi[1], n)), -1).reshape(-1, 2)
        sd = self.signed_distance(g)
        delta = 0.5 * math.hypot(*((hi - lo) / (n - 1)))  # half a cell's diagonal (mm)
        grid = sd.reshape(n, n)
        peaks = (grid >= maximum_filter(grid, size=3, mode="constant", cval=-np.inf)) & (grid >= grid.max() - delta)
        regions, count = label(peaks, structure=np.ones((3, 3), bool))
        regions = regions.reshape(-1)
        one = self._point_signed_distance() if self.segs and not self.is_circle else None
        jets = distance_jets(self.segs) if one is not None else None
        objective = ((lambda x: -one(float(x[0]), float(x[1]))) if one is not None
                     else (lambda x: -float(self.signed_distance(x[None])[0])))
        scale = float(max(hi - lo))
        best = float(sd.max())
        for k in range(1, count + 1):
            inside = np.flatnonzero(regions == k)
            x0 = g[inside[int(np.argmax(sd[inside]))]]
            found = (None if jets is None
                     else deepest_near(jets, one, float(x0[0]), float(x0[1]), 2.0 * delta, scale))
            if found is not None:
                best = max(best, float(self.signed_distance(np.array([found]))[0]))
                continue
            r = minimize(objective, x0, method="Nelder-Mead", options=dict(xatol=1e-11, fatol=1e-13, maxiter=4000))
            best = max(best, float(self.signed_distance(r.x[None])[0]) if one is not None else float(-r.fun))
        return best

    def _point_signed_distance(self):
        """``f(x, y)``: :meth:`signed_distance` of one point (mm, > 0 inside) in plain floats, for a chain of
        lines and arcs: the nearest segment (the first of equals in the chain's order) and the side it puts
        the point on, by the arithmetic of :func:`_signed_to_segment` term for term."""
        from tabletcad.families.deepest import plain_segments

        items = plain_segments(self.segs)
        sqrt = math.sqrt

        def f(x: float, y: float) -> float:
            best, side = math.inf, 1.0
            for it in items:
                if it[0]:
                    _, ax, ay, dx, dy, dd = it
                    t = min(max(((x - ax) * dx + (y - ay) * dy) / dd, 0.0), 1.0)
                    qx, qy = x - (ax + t * dx), y - (ay + t * dy)
                    d = sqrt(qx * qx + qy * qy)
                    if d < best:
                        best, side = d, (1.0 if qx * -dy + qy * dx >= 0.0 else -1.0)
                    continue
                _, cx, cy, rad, cm, sm, ch, turn, x0, y0, u0, w0, x1, y1, u1, w1 = it
                rx, ry = x - cx, y - cy
                rho = sqrt(rx * rx + ry * ry)
                if rx * cm + ry * sm >= rho * ch:  # within the arc's span
                    d = abs(rho - rad)
                    if d < best:
                        best, side = d, (1.0 if (rad - rho) * turn >= 0.0 else -1.0)
                    continue
                e0 = sqrt((x - x0) * (x - x0) + (y - y0) * (y - y0))
                e1 = sqrt((x - x1) * (x - x1) + (y - y1) * (y - y1))
                d = min(e0, e1)
                if d < best:
                    best = d
                    if e0 <= e1:
                        side = 1.0 if (x - x0) * -w0 + (y - y0) * u0 >= 0.0 else -1.0
                    else:
                        side = 1.0 if (x - x1) * -w1 + (y - y1) * u1 >= 0.0 else -1.0
            return side * best

        return f

    def centroid_depth(self) -> float:
        """The centroid's :meth:`signed_distance` to the outline (mm, > 0 inside), remembered (:meth:`_remembered`)."""
        return self._remembered(("centroid depth",), lambda: float(self.signed_distance(self.centroid()[None])[0]))

    def _offset_is_clean(self, d: float) -> bool:
        """Whether the inward offset by ``d`` (mm) stays ``d`` from the outline at 2,048 samples and the
        joins.  Remembered for every outline of the same segments (:meth:`_remembered`): every build of a
        tablet over it asks for its limit and its cup width (most often the same offset), and a search of
        the tablet's band or cup depth builds it, a new equal outline each time, again and again (3,836
        checks of 1,507 offsets, 5 of 25 CPU-s, in tests/test_inverse_all_families.py)."""
        d = float(d)

        def clean() -> bool:
            v = linspace(0.0, math.tau, 2048, endpoint=False)
            v = np.concatenate([v, self.breaks[:-1]])
            O, T, N, k = self.frame(v)
            dist = self.signed_distance(O + d * N)
            return bool(np.min(dist) >= d - 1e-7 * max(1.0, d))

        return self._remembered(("clean", d), clean)

    def offset_limit(self) -> float:
        """Largest inward offset (mm) that is a clean offset of the outline: at most
        the smallest convex arc radius, and no offset point closer than ``d`` to
        the outline (bisection to ~1e-9 mm)."""
        hi = min(self.min_convex_radius, self.inscribed_radius())
        if self._offset_is_clean(hi):
            return hi
        lo = 0.0
        for _ in range(40):
            mid = 0.5 * (lo + hi)
            if self._offset_is_clean(mid):
                lo = mid
            else:
                hi = mid
        return lo

    def support(self, v, center) -> np.ndarray:
        """Signed distance (mm) from ``center`` to the outline's tangent line at ``v``, positive when
        ``center`` lies on the inner side: ``h(v) = (O(v) - center) × T(v)``, shape (m,)."""
        O, T, _, _ = self.frame(v)
        P = O - np.asarray(center, dtype=float)
        return P[:, 0] * T[:, 1] - P[:, 1] * T[:, 0]

    def star_limit(self) -> float:
        """Largest inward offset (mm) up to which every offset is star-shaped about the centroid ``c``
        (negative when the outline itself is not), to ~1e-12 mm.

        The offset by ``d`` is ``R(v) = O + d N`` with ``R' = |O'| (1 - κ d) T``, so the fan from
        ``c`` over it (a swept tablet's plateau, its cups' solid map) has the Jacobian
        ``(R - c) × R' = |O'| (1 - κ d) (h(v) - d)``, ``h`` the :meth:`support` of ``c``.  Within the
        smallest convex radius ``1 - κ d >= 0``, so the fan does not fold exactly when
        ``d <= min h``: the distance from ``c`` to the nearest tangent line.  On a convex outline that
        is no tighter than :meth:`offset_limit` while ``c`` stays inside the offsets (a stadium's:
        its half width); a concave waist brings the tangent lines at its ends closer to ``c`` than
        the waist's half width (a peanut cupped to its waist folded its flat centre).  ``h`` is sampled
        (4096 values of ``v`` and the joins) and its lowest local minima polished by bounded Brent; on
        lines and arcs it is exact (:meth:`_star_limit_of_segments`).  Cached.
        """
        exact = bool(getattr(self, "segs", ()))
        return self._remembered(("star",), self._star_limit_of_segments if exact else self._star_limit_sampled)

    def _star_limit_sampled(self) -> float:
        """:meth:`star_limit` from samples of ``h`` polished by bounded Brent (any outline)."""
        from scipy.optimize import minimize_scalar

        c = self.centroid()
        v = np.unique(np.concatenate([linspace(0.0, math.tau, 4096, endpoint=False), self.breaks[:-1]]))
        h = self.support(v, c)
        lows = np.flatnonzero((h <= np.roll(h, 1)) & (h <= np.roll(h, -1)))
        best = float(np.min(h))
        ext = np.concatenate([[v[-1] - math.tau], v, [v[0] + math.tau]])  # neighbours across 0 = 2π
        for i in lows[np.argsort(h[lows])[:8]]:
            r = minimize_scalar(lambda x: float(self.support(np.array([x]), c)[0]),
                                bounds=(ext[i], ext[i + 2]), method="bounded", options=dict(xatol=1e-13))
            best = min(best, float(r.fun))
        return best

    def _star_limit_of_segments(self) -> float:
        """:meth:`star_limit` of a chain of lines and arcs, exactly: the least support ``h`` of the
        centroid ``c`` over each segment.  A line's tangent line is the line itself; on an arc of centre
        ``C``, radius ``r`` and sweep sign ``s`` (+1 convex), ``T = s e⊥(θ)`` gives
        ``h(θ) = s (r + (C - c)·e(θ))``, least at an end of the span or where ``e(θ)`` points away from
        ``C - c`` (convex) or along it (concave), when that direction lies within the span."""
        c = self.centroid()
        best = math.inf
        for sg in self.segs:
            if sg.kind == "line":
                (x0, y0), (x1, y1) = sg.p0, sg.p1
                dx, dy = x1 - x0, y1 - y0
                best = min(best, ((x0 - c[0]) * dy - (y0 - c[1]) * dx) / math.hypot(dx, dy))
                continue
            s = math.copysign(1.0, sg.sweep)
            ax, ay = sg.center[0] - c[0], sg.center[1] - c[1]
            thetas = [sg.theta0, sg.theta0 + sg.sweep]
            rho = math.hypot(ax, ay)
            if rho > 0.0:
                ex, ey = -s * ax / rho, -s * ay / rho  # the direction where s (C - c)·e is least
                if bool(sg.within_sweep(np.array(ex), np.array(ey), np.array(1.0))):
                    thetas.append(math.atan2(ey, ex))
            best = min(best, min(s * (sg.radius + ax * math.cos(t) + ay * math.sin(t)) for t in thetas))
        return best

    def check_offset(self, d: float, parameter: str) -> None:
        """Refuse an inward offset ``d`` (mm) that is not a clean offset of this outline.

        The offset is valid when ``d`` does not exceed the smallest convex arc
        radius (arcs would turn inside out) and every offset point stays at
        distance ``d`` from the outline (it has not passed the medial axis,
        i.e. ``d`` is within the inscribed radius locally).
        """
        rmin = self.min_convex_radius
        tol = 1e-9 * max(1.0, self.perimeter)
        if d > rmin + tol:
            raise DesignError(parameter, d, f"must be <= {format_bound(rmin, upper=True)} mm, the smallest corner (arc) radius of the outline", "mm")
        if not self._offset_is_clean(d):
            lim = self.offset_limit()
            raise DesignError(parameter, d, f"must be <= {format_bound(lim, upper=True)} mm (the outline's inscribed radius where it is narrowest: the offset would cross itself)", "mm")

    # ------------------------------------------------------------------ checks
    def _check_simple(self) -> None:
        v = linspace(0.0, math.tau, 1537, endpoint=False)
        v = np.unique(np.concatenate([v, self.breaks[:-1]]))
        _check_polyline_simple(self.frame(v)[0], self.parameter)


class SplineOutline(PlanOutline):
    """Closed plan outline through given points: a periodic cubic spline (mm).

    ``v`` is proportional to the chord length of the points.  Distances are
    computed by nearest sample and Newton refinement (to ~1e-10 mm).
    """

    def __init__(self, points, name: str = "outline", parameter: str = "outline") -> None:
        p = np.asarray(points, dtype=float)
        if p.ndim != 2 or p.shape[1] != 2 or len(p) < 4 or not np.all(np.isfinite(p)):
            raise DesignError(parameter, f"array of shape {p.shape}", "must be at least 4 finite (x, y) points in mm")
        if np.linalg.norm(p[0] - p[-1]) == 0.0:
            p = p[:-1]
        seg = np.linalg.norm(np.diff(np.vstack([p, p[:1]]), axis=0), axis=1)
        if np.any(seg == 0.0):
            raise DesignError(parameter, "repeated point", "consecutive points must differ")
        a = 0.5 * float(np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1]))
        if a < 0:
            p = p[::-1]
            seg = np.linalg.norm(np.diff(np.vstack([p, p[:1]]), axis=0), axis=1)
        _check_polyline_simple(p, parameter)
        t = np.concatenate([[0.0], np.cumsum(seg)]) * (math.tau / float(np.sum(seg)))
        self.points = p
        from scipy.interpolate import CubicSpline  # here: scipy.interpolate takes ~0.3 s to import

        self._sp = CubicSpline(t, np.vstack([p, p[:1]]), bc_type="periodic", axis=0)
        self.name = name
        self.parameter = parameter
        self.segs = ()
        vs = linspace(0.0, math.tau, 8192, endpoint=False)
        self._vs = vs
        self._ps = self._sp(vs)
        sp1 = self._sp(vs, 1)
        self.perimeter = float(np.sum(np.hypot(sp1[:, 0], sp1[:, 1])) * math.tau / vs.size)
        self.area = abs(0.5 * float(np.sum(self._ps[:, 0] * sp1[:, 1] - self._ps[:, 1] * sp1[:, 0])) * math.tau / vs.size)
        if not self.area > 1e-9 * self.perimeter ** 2:  # points on one line: the spline runs there and back
            raise DesignError(parameter, f"an outline enclosing {self.area:.3g} mm^2",
                              "the points must enclose an area (they lie on one line)")
        _check_polyline_simple(self._ps[::4], parameter)
        from scipy.spatial import cKDTree

        self._tree = cKDTree(self._ps)
        self._kmax: float | None = None

    @property
    def breaks(self) -> np.ndarray:
        return np.array([0.0, math.tau])

    @property
    def diameter(self) -> float:
        """The largest distance (mm) between two of the outline's 8,192 samples (its diameter, low by
        at most the square of the samples' spacing over the curvature radius: ~1e-6 mm on tablets)."""
        if "_diameter" not in self.__dict__:
            self.__dict__["_diameter"] = point_set_diameter(self._ps)
        return self.__dict__["_diameter"]

    @property
    def smooth_breaks(self) -> np.ndarray:
        return np.asarray(self._sp.x[:-1], dtype=float)

    @property
    def max_curvature(self) -> float:
        """Largest signed curvature of the spline (1/mm), to ~1e-12 relative.

        Sampling alone misses a peak between samples (the offset at the sampled radius
        would then loop); the largest sampled peaks are refined by bounded Brent
        searches, and the knots, where the curvature of a cubic spline has corners,
        are evaluated exactly.
        """
        if self._kmax is None:
            self._kmax = self._curvature_peak(1.0)
        return self._kmax

    @property
    def max_concave_curvature(self) -> float:
        """Largest curvature (1/mm) of the spline's concave parts (> 0 where it has any, else <= 0: the
        negated least signed curvature), refined as :attr:`max_curvature`."""
        if "_kneg" not in self.__dict__:
            self.__dict__["_kneg"] = self._curvature_peak(-1.0)
        return self.__dict__["_kneg"]

    def _curvature_peak(self, sign: float) -> float:
        """The largest of ``sign * κ`` (1/mm) over the spline: the largest sampled peaks polished by
        bounded Brent, the knots (corners of a cubic spline's curvature) evaluated exactly."""
        from scipy.optimize import minimize_scalar

        k = sign * self.frame(self._vs)[3]
        h = float(self._vs[1] - self._vs[0])
        peaks = np.flatnonzero((k >= np.roll(k, 1)) & (k >= np.roll(k, -1)))
        best = max(float(np.max(k)), float(np.max(sign * self.frame(self.smooth_breaks)[3])))
        for i in peaks[np.argsort(k[peaks])[::-1][:8]]:
            r = minimize_scalar(lambda v: -sign * float(self.frame(v)[3][0]), bounds=(self._vs[i] - h, self._vs[i] + h),
                                method="bounded", options=dict(xatol=1e-13))
            best = max(best, -float(r.fun))
        return best

    @property
    def min_concave_radius(self) -> float:
        """The largest outward offset whose curve is regular (mm): the smallest radius of curvature of
        the concave parts less the relative margin ``Tolerances.offset_regularity`` (as
        :attr:`min_convex_radius` inward); ``inf`` for a convex outline."""
        kneg = self.max_concave_curvature
        return (1.0 - DEFAULT.offset_regularity) / kneg if kneg > 0 else math.inf

    def _outward_offset_is_clean(self, e: float) -> bool:
        """Whether the outward offset by ``e`` (mm) stays ``e`` outside the outline at 2,048 samples and the
        knots (no two parts of the outline, across a notch, bring their offsets together)."""
        e = float(e)

        def clean() -> bool:
            v = np.concatenate([linspace(0.0, math.tau, 2048, endpoint=False), self.smooth_breaks])
            O, T, N, k = self.frame(v)
            return bool(np.max(self.signed_distance(O - e * N)) <= -e + 1e-7 * max(1.0, e))

        return self._remembered(("outward clean", e), clean)

    def outward_offset_limit(self) -> float:
        """Largest outward offset (mm) that is a regular, clean offset of the outline: at most
        :attr:`min_concave_radius` (``inf`` for a convex outline, whose outward offsets are all clean),
        and no offset point nearer than the offset to the outline (bisection to ~1e-9 mm)."""
        hi = self.min_concave_radius
        if math.isinf(hi) or self._outward_offset_is_clean(hi):
            return hi
        lo = 0.0
        for _ in range(40):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if self._outward_offset_is_clean(mid) else (lo, mid)
        return lo

    def offset_bound(self, distance: float) -> tuple[float, str] | None:
        """For an offset of the outline by ``distance`` mm (> 0 outward, < 0 inward: a die bore, a punch
        tip) that is no regular offset of it, ``(limit, why)``: the largest regular offset that way (mm) and
        what sets it; ``None`` for a regular one.  Inward the limit is :meth:`offset_limit` (the smallest
        convex radius of curvature less ``Tolerances.offset_regularity``, or the inscribed radius where it is
        narrowest), outward :meth:`outward_offset_limit` (the smallest concave radius of curvature less that
        margin, or where a notch between two parts of the outline closes)."""
        d = float(distance)
        if d < 0.0 and not (-d <= self.min_convex_radius and self._offset_is_clean(-d)):
            lim = self.offset_limit()
            if -d > lim:
                return lim, (f"its smallest convex radius of curvature is {1.0 / self.max_curvature:.4g} mm, and the "
                             "offset must stay regular and clear of the narrowest place")
        elif d > 0.0 and not (d <= self.min_concave_radius and self._outward_offset_is_clean(d)):
            lim = self.outward_offset_limit()
            if d > lim:
                return lim, (f"its smallest concave radius of curvature is {1.0 / self.max_concave_curvature:.4g} mm, "
                             "and the offset must stay regular and keep its notches open")
        return None

    @property
    def min_convex_radius(self) -> float:
        """The largest inward offset whose curve is regular (mm): the smallest radius of
        curvature less the relative margin ``Tolerances.offset_regularity``.

        At exactly the smallest radius of curvature the offset stands still at one point
        (its speed ``|O'|(1 - d κ)`` vanishes there): a singular rim whose B-spline faces
        fold (duplicate triangles, a mesh that is not watertight).  Arc outlines collapse
        whole corner arcs instead, which the sweep handles with a ring patch; a spline has
        no such arcs, so its cups stop short of the singular offset.
        """
        kmax = self.max_curvature
        return (1.0 - DEFAULT.offset_regularity) / kmax if kmax > 0 else math.inf

    def _frame(self, v):
        v = np.mod(v, math.tau)
        O = self._sp(v)
        d1 = self._sp(v, 1)
        d2 = self._sp(v, 2)
        g = np.hypot(d1[:, 0], d1[:, 1])
        T = d1 / g[:, None]
        N = np.column_stack([-T[:, 1], T[:, 0]])
        k = (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]) / g**3
        return O, T, N, k

    def point(self, v, der: int = 0) -> np.ndarray:
        if der not in (0, 1, 2):
            raise ValueError(f"der = {der} is not allowed: must be 0, 1 or 2")
        return self._sp(np.mod(np.asarray(v, dtype=float).reshape(-1), math.tau), der)

    def normal(self, v, der: int = 0) -> np.ndarray:
        v = np.asarray(v, dtype=float).reshape(-1)
        O, T, N, k = self.frame(v)
        if der == 0:
            return N
        g = np.hypot(*self._sp(np.mod(v, math.tau), 1).T)
        if der == 1:
            return -(k * g)[:, None] * T
        if der == 2:  # central difference of the exact first derivative
            h = 1e-5
            return (self.normal(v + h, 1) - self.normal(v - h, 1)) / (2 * h)
        raise ValueError(f"der = {der} is not allowed: must be 0, 1 or 2")

    def offset(self, v, der: int, alpha: float, beta: float) -> np.ndarray:
        return alpha * self.point(v, der) + beta * self.normal(v, der)

    def offsets(self, v, der: int, alphas: np.ndarray, betas: np.ndarray) -> np.ndarray:
        return np.stack([self.offset(v, der, float(a), float(b)) for a, b in zip(alphas, betas)])

    def centroid(self) -> np.ndarray:
        p, d1 = self._ps, self._sp(self._vs, 1)
        w = math.tau / self._vs.size
        a = 0.5 * float(np.sum(p[:, 0] * d1[:, 1] - p[:, 1] * d1[:, 0])) * w
        sx = 0.5 * float(np.sum(p[:, 0] ** 2 * d1[:, 1])) * w
        sy = -0.5 * float(np.sum(p[:, 1] ** 2 * d1[:, 0])) * w
        return np.array([sx / a, sy / a])

    def extent(self) -> tuple[float, float]:
        ext = np.ptp(self._sp(linspace(0, math.tau, 20000, endpoint=False)), axis=0)
        return float(ext[0]), float(ext[1])

    def signed_distance(self, xy) -> np.ndarray:
        p = np.asarray(xy, dtype=float).reshape(-1, 2)
        _, i = self._tree.query(p)
        t = self._vs[i]
        for _ in range(6):
            c = self._sp(t)
            c1 = self._sp(t, 1)
            c2 = self._sp(t, 2)
            q = c - p
            f = np.einsum("ij,ij->i", q, c1)
            fp = np.einsum("ij,ij->i", c1, c1) + np.einsum("ij,ij->i", q, c2)
            step = np.divide(f, fp, out=np.zeros_like(f), where=np.abs(fp) > 1e-300)
            t = t - clip(step, -0.01, 0.01)
        O, T, N, k = self.frame(t)
        q = p - O
        return np.einsum("ij,ij->i", q, N)  # q is along N at the foot point

    def _check_simple(self) -> None:  # pragma: no cover - done in __init__
        pass


def point_set_diameter(points: np.ndarray) -> float:
    """The largest distance (mm) between two of the plan ``points`` (n, 2): their convex hull's
    diameter by rotating calipers (Shamos 1978), O(h) after the hull, in constant memory (the pairwise
    distances of 8,192 hull points took 3 GB)."""
    from scipy.spatial import ConvexHull, QhullError

    P = np.asarray(points, dtype=float).reshape(-1, 2)
    try:
        H = P[ConvexHull(P).vertices].tolist()  # counter-clockwise
    except (QhullError, ValueError):  # fewer than 3 points, or all on one line: the farthest of the extremes
        d = P - P.mean(axis=0)
        k = int(np.argmax(np.einsum("ij,ij->i", d, d)))
        return float(np.max(np.linalg.norm(P - P[k], axis=1))) if len(P) else 0.0
    n = len(H)

    def cross(o, a, b) -> float:  # twice the area of (o, a, b)
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    best, j = 0.0, 1
    for i in range(n):
        a, b = H[i], H[(i + 1) % n]
        while cross(a, b, H[(j + 1) % n]) > cross(a, b, H[j]):  # the vertex farthest from edge a-b
            j = (j + 1) % n
        for q in (a, b):
            best = max(best, math.hypot(q[0] - H[j][0], q[1] - H[j][1]))
    return best


def _signed_to_segment(s, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distance (mm) from plan points ``p`` (m, 2) to one segment of a CCW outline, and the side
    (+1 inward, -1 outward) it puts them on: the inward normal at the nearest point of a line or
    an arc's span, and the side of the end's tangent at an arc's nearer end."""
    px, py = p[:, 0], p[:, 1]
    if s.kind == "line":
        (ax, ay), (bx, by) = s.p0, s.p1
        dx, dy = bx - ax, by - ay
        t = clip(((px - ax) * dx + (py - ay) * dy) / (dx * dx + dy * dy), 0.0, 1.0)
        qx, qy = px - (ax + t * dx), py - (ay + t * dy)
        return length2(qx, qy), np.where(qx * -dy + qy * dx >= 0.0, 1.0, -1.0)

    rx, ry = px - s.center[0], py - s.center[1]
    rho = length2(rx, ry)
    dist = np.abs(rho - s.radius)
    # inward normal of a convex (ccw) arc points to the centre
    sg = np.where((s.radius - rho) * math.copysign(1.0, s.sweep) >= 0.0, 1.0, -1.0)
    off = np.flatnonzero(~s.within_sweep(rx, ry, rho))  # beyond the arc's span: its nearer end decides
    if off.size:  # (measured there alone: the same values, elementwise)
        dist[off], sg[off] = _arc_ends(s, px[off], py[off])
    return dist, sg


def offset_bounds_inset(outline, inset: float, tol: float = 1e-9) -> bool:
    """Whether the lines-and-arcs ``outline``'s inward offset by ``inset`` mm is the boundary of its inset region
    ``{p : distance inside >= inset}``, the curve :func:`tabletcad.geometry.lettering.outside_area` closes along: ``inset`` below every convex
    arc's radius and no point of the offset nearer than ``inset - tol`` to another segment of the outline than
    its own (else the offset crosses itself or parts in two at a neck).

    That clearance ``min_{j != own} d_j(O + inset N) - inset`` is smooth where the signed distance is flat (0 on
    a clean offset), so it is sampled (4,096 and the joins) and every low local minimum polished by bounded
    Brent: a neck is found to round-off, where
    :meth:`PlanOutline.offset_limit` (2,048 samples of the signed distance, to
    1e-7) takes a peanut's neck of half width 0.687434 mm for 0.687451."""
    from scipy.optimize import minimize_scalar

    if not inset < outline.min_convex_radius:
        return False
    segs, breaks = outline.segs, outline.breaks

    def clearance(vs: np.ndarray) -> np.ndarray:
        own = np.clip(np.searchsorted(breaks, np.mod(vs, math.tau), side="right") - 1, 0, len(segs) - 1)
        q = outline.offset(vs, 0, 1.0, inset)
        dist = np.stack([_signed_to_segment(sg, q)[0] for sg in segs])
        dist[own, np.arange(len(vs))] = np.inf
        return dist.min(axis=0) - inset

    v = np.unique(np.concatenate([np.linspace(0.0, math.tau, 4096, endpoint=False), breaks[:-1]]))
    h = clearance(v)
    if float(h.min()) < -tol:
        return False
    # the offset point moves (1 + inset / r) times as fast as the outline's, so the clearance changes by at most
    # that a millimetre: a minimum between two samples lies within it times their spacing of both
    speed = 1.0 + inset * max([1.0 / sg.radius for sg in segs if sg.kind != "line"] or [0.0])
    reach = 2.0 * speed * outline.perimeter / len(v)
    low = (h <= np.roll(h, 1)) & (h <= np.roll(h, -1)) & (h < reach)
    ext = np.concatenate([[v[-1] - math.tau], v, [v[0] + math.tau]])  # neighbours across 0 = 2 pi
    for i in _lowest_of_runs(low, h):
        r = minimize_scalar(lambda x: float(clearance(np.array([x]))[0]), bounds=(ext[i], ext[i + 2]),
                            method="bounded", options=dict(xatol=1e-13))
        if float(r.fun) < -tol:
            return False
    return True


def whole_inset_limit(outline, below: float, tol: float = 1e-9) -> float:
    """The largest inset (mm) below ``below`` whose inward offset of the lines-and-arcs ``outline`` is still
    the boundary of its inset region (:func:`offset_bounds_inset`), by bisection to about ``tol``: where an
    inset by ``below`` parts in two at a neck, the neck's half width (the peanut of
    tests/test_report_refusals.py: 0.6874342092 mm for 0.6874342087); ``0.0`` when even the least inset
    is no clean offset."""
    lo, hi = 0.0, float(below)
    if offset_bounds_inset(outline, hi, tol):
        return hi
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if offset_bounds_inset(outline, mid, tol) else (lo, mid)
    return lo


def _lowest_of_runs(mask: np.ndarray, h: np.ndarray) -> list[int]:
    """The index of the least ``h`` in each run of adjacent ``True`` of the cyclic ``mask`` (a flat stretch of
    local minima, as a capsule's parallel sides give, polished once)."""
    if mask.all():
        return [int(np.argmin(h))]
    start = int(np.flatnonzero(~mask)[0])  # runs read from a False, so none wraps
    order = np.roll(np.arange(mask.size), -start)
    out, run = [], []
    for k in list(order) + [start]:
        if mask[k]:
            run.append(k)
        elif run:
            out.append(min(run, key=lambda j: h[j]))
            run = []
    return [int(k) for k in out]


class _SegmentColumns:
    """A chain's lines and arcs as columns of their constants, for :meth:`PlanOutline.signed_distance` of up
    to :data:`~tabletcad.geometry.curves._MEASURE_ALL` points: every segment measured at every point in one
    pass of (segments, points) arrays, where :func:`~tabletcad.geometry.curves.nearest_of` measures them one
    by one (:func:`_signed_to_segment`), some twenty numpy calls each (0.3 ms a point on 16 segments).

    The same arithmetic term for term (each element is the same IEEE operations on the same numbers): a
    line's projection clipped to its ends, an arc's radial distance within its span and the nearer end's
    beyond it (here computed at every point, then chosen), the nearest the first of equals in the chain's
    order.  Immutable: shared by every outline of the same segments (:meth:`PlanOutline._remembered`)."""

    def __init__(self, segs) -> None:
        lines = [(i, s) for i, s in enumerate(segs) if s.kind == "line"]
        arcs = [(i, s) for i, s in enumerate(segs) if s.kind != "line"]
        self.n = len(segs)
        self.lines = np.array([i for i, _ in lines], dtype=np.intp)
        self.arcs = np.array([i for i, _ in arcs], dtype=np.intp)

        def column(values: list) -> np.ndarray:
            col = np.array(values, dtype=float).reshape(-1, 1)
            col.setflags(write=False)
            return col

        run = [(s.p0[0], s.p0[1], s.p1[0] - s.p0[0], s.p1[1] - s.p0[1]) for _, s in lines]
        self.ax, self.ay, self.dx, self.dy = (column([r[k] for r in run]) for k in range(4))
        self.dd = column([dx * dx + dy * dy for _, _, dx, dy in run])  # (as _signed_to_segment: floats)
        self.ndy = column([-dy for _, _, _, dy in run])
        mid = [s.theta0 + 0.5 * s.sweep for _, s in arcs]
        self.cx, self.cy = column([s.center[0] for _, s in arcs]), column([s.center[1] for _, s in arcs])
        self.rad = column([s.radius for _, s in arcs])
        self.cm, self.sm = column([math.cos(m) for m in mid]), column([math.sin(m) for m in mid])
        self.ch = column([math.cos(0.5 * abs(s.sweep)) for _, s in arcs])
        self.turn = column([math.copysign(1.0, s.sweep) for _, s in arcs])
        self.x0, self.y0 = column([s.p0[0] for _, s in arcs]), column([s.p0[1] for _, s in arcs])
        self.x1, self.y1 = column([s.p1[0] for _, s in arcs]), column([s.p1[1] for _, s in arcs])
        tangents = [s.end_tangents for _, s in arcs]
        self.u0, self.nw0 = column([t[0][0] for t in tangents]), column([-t[0][1] for t in tangents])
        self.u1, self.nw1 = column([t[1][0] for t in tangents]), column([-t[1][1] for t in tangents])

    def signed_distance(self, p: np.ndarray) -> np.ndarray:
        """Signed distance (mm, > 0 inside) of plan points ``p`` (m, 2): the nearest segment's distance and
        side, as :meth:`PlanOutline.signed_distance` by :func:`_signed_to_segment` (the same numbers)."""
        px, py = p[:, 0], p[:, 1]
        dist, side = np.empty((self.n, len(p))), np.empty((self.n, len(p)))
        if self.lines.size:
            dx, dy = self.dx, self.dy
            t = clip(((px - self.ax) * dx + (py - self.ay) * dy) / self.dd, 0.0, 1.0)
            qx, qy = px - (self.ax + t * dx), py - (self.ay + t * dy)
            dist[self.lines] = length2(qx, qy)
            side[self.lines] = np.where(qx * self.ndy + qy * dx >= 0.0, 1.0, -1.0)
        if self.arcs.size:
            rx, ry = px - self.cx, py - self.cy
            rho = length2(rx, ry)
            within = rx * self.cm + ry * self.sm >= rho * self.ch
            e0, e1 = length2(px - self.x0, py - self.y0), length2(px - self.x1, py - self.y1)
            s0 = np.where((px - self.x0) * self.nw0 + (py - self.y0) * self.u0 >= 0.0, 1.0, -1.0)
            s1 = np.where((px - self.x1) * self.nw1 + (py - self.y1) * self.u1 >= 0.0, 1.0, -1.0)
            inside = np.where((self.rad - rho) * self.turn >= 0.0, 1.0, -1.0)
            dist[self.arcs] = np.where(within, np.abs(rho - self.rad), np.minimum(e0, e1))
            side[self.arcs] = np.where(within, inside, np.where(e0 <= e1, s0, s1))
        # the first of equals; a NaN distance never wins, but where every one is NaN (as nearest_of)
        which = np.argmin(np.where(np.isnan(dist), np.inf, dist), axis=0)
        cols = np.arange(len(p))
        return side[which, cols] * dist[which, cols]


def _arc_ends(s, px: np.ndarray, py: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distance (mm) from plan points ``(px, py)`` to the nearer end of the arc ``s`` and the side (+1
    inward, -1 outward) of that end's tangent they lie on (the start's where the two are equally far)."""

    def side(x0: float, y0: float, t) -> np.ndarray:  # +1 left of the direction t through (x0, y0)
        return np.where((px - x0) * -t[1] + (py - y0) * t[0] >= 0.0, 1.0, -1.0)

    e0 = length2(px - s.p0[0], py - s.p0[1])
    e1 = length2(px - s.p1[0], py - s.p1[1])
    t0, t1 = s.end_tangents
    return np.minimum(e0, e1), np.where(e0 <= e1, side(*s.p0, t0), side(*s.p1, t1))


def _check_polyline_simple(p: np.ndarray, parameter: str) -> None:
    """Raise DesignError if the closed polyline ``p`` (m, 2) crosses itself."""
    # Sufficient and cheap: vertices that turn once around an inner point with strictly
    # increasing polar angle bound a star-shaped, hence simple, polygon (every tablet
    # outline so far); the exact pairwise test below serves the rest.
    c = p.mean(axis=0)
    phi = np.arctan2(p[:, 1] - c[1], p[:, 0] - c[0])
    dphi = np.mod(np.diff(np.concatenate([phi, phi[:1]])), 2.0 * math.pi)
    if np.all(dphi > 1e-12) and np.all(dphi < math.pi) and abs(float(np.sum(dphi)) - 2.0 * math.pi) < 1e-9:
        return
    a = p
    b = np.roll(p, -1, axis=0)
    m = len(p)
    # bounding-box prefilter, then exact orientation tests, non-adjacent pairs only
    lo = np.minimum(a, b)
    hi = np.maximum(a, b)
    step = 256
    for i0 in range(0, m, step):
        i1 = min(m, i0 + step)
        I = np.arange(i0, i1)[:, None]
        J = np.arange(m)[None, :]
        ov = (
            (lo[I, 0] <= hi[J, 0]) & (lo[J, 0] <= hi[I, 0]) & (lo[I, 1] <= hi[J, 1]) & (lo[J, 1] <= hi[I, 1])
        )
        adj = (np.abs(I - J) <= 1) | (np.abs(I - J) == m - 1)
        ii, jj = np.nonzero(ov & ~adj & (J > I))
        if ii.size == 0:
            continue
        ii = ii + i0
        p1, p2, p3, p4 = a[ii], b[ii], a[jj], b[jj]

        def orient(x, y, z):
            return (y[:, 0] - x[:, 0]) * (z[:, 1] - x[:, 1]) - (y[:, 1] - x[:, 1]) * (z[:, 0] - x[:, 0])

        d1, d2 = orient(p3, p4, p1), orient(p3, p4, p2)
        d3, d4 = orient(p1, p2, p3), orient(p1, p2, p4)
        hit = (d1 * d2 < 0) & (d3 * d4 < 0)
        if np.any(hit):
            k = int(np.argmax(hit))
            x, y = p1[k]
            raise DesignError(parameter, f"self-intersecting near ({x:.3g}, {y:.3g}) mm", "must be a simple closed curve (it must not cross itself)")


# ---------------------------------------------------------------------- constructors
def check_numbers(parameter: str, value) -> None:
    """Refuse text, booleans and non-finite values anywhere in nested lists of numbers (a quoted
    ``"4.5"`` is not a coordinate, although numpy would read it as one)."""
    if isinstance(value, np.ndarray) and value.dtype.kind in "fiu":
        if not np.all(np.isfinite(value)):
            raise DesignError(parameter, "a value that is not finite", "must hold finite numbers (mm)")
    elif isinstance(value, (list, tuple, np.ndarray)):
        for i, item in enumerate(value):
            check_numbers(f"{parameter}[{i}]", item)
    else:
        check_finite(parameter, value, "mm")


def outline_from_items(items, name: str = "outline", parameter: str = "outline") -> PlanOutline:
    """Outline from ``("line", (x0, y0), (x1, y1))`` and
    ``("arc", (cx, cy), radius, theta0, sweep)`` items (mm, rad), as in
    :meth:`tabletcad.geometry.curves.Outline.from_segments`."""
    segs = []
    for i, it in enumerate(items):
        if not isinstance(it, (list, tuple)) or not it:
            raise DesignError(f"{parameter} item {i}", it, "must be ('line', p0, p1) or ('arc', center, radius, theta0, sweep)")
        kind = it[0]
        for k, part in enumerate(it[1:], start=1):  # no text where a number goes ("3" is not a radius)
            check_numbers(f"{parameter}[{i}][{k}]", part)
        # a point is (x, y): a third coordinate had been dropped in silence (the outline lies in the plan)
        for k in ((1, 2) if kind == "line" else (1,) if kind == "arc" else ()):
            if k < len(it) and isinstance(it[k], (list, tuple, np.ndarray)) and len(it[k]) != 2:
                raise DesignError(f"{parameter}[{i}][{k}]", list(np.asarray(it[k]).tolist()),
                                  "must be a point [x, y] in mm (the outline lies in the plan)")
        try:
            if kind == "line" and len(it) == 3:
                segs.append(_line(it[1], it[2]))
            elif kind == "arc" and len(it) == 5:
                segs.append(_arc(it[1], float(it[2]), float(it[3]), float(it[4])))
            else:
                raise TypeError
        except (TypeError, ValueError, IndexError):
            raise DesignError(f"{parameter} item {i}", it, "must be ('line', p0, p1) or ('arc', center, radius, theta0, sweep)") from None
    return PlanOutline(segs, name=name, parameter=parameter)


def circle_outline(radius: float) -> PlanOutline:
    """Circle of ``radius`` (mm) about the origin, starting on +x (``v`` = polar angle)."""
    r = check_positive("radius", radius, "mm")
    return PlanOutline([_arc((0.0, 0.0), r, 0.0, math.tau)], name="circle")


def stadium_outline(length: float, width: float, parameter: str = "width") -> PlanOutline:
    """Stadium (capsule plan): ``length`` along x, ``width`` along y, end radius ``width/2`` (mm)."""
    L = check_positive("length", length, "mm")
    W = check_positive("width", width, "mm")
    if W > L:
        raise DesignError(parameter, W, f"must be <= length = {format_bound(L, upper=True)} mm", "mm")
    r = W / 2.0
    h = L / 2.0 - r
    if h <= 1e-12 * L:
        return circle_outline(r)
    return PlanOutline(
        [
            _arc((h, 0.0), r, -math.pi / 2, math.pi),
            _line((h, r), (-h, r)),
            _arc((-h, 0.0), r, math.pi / 2, math.pi),
            _line((-h, -r), (h, -r)),
        ],
        name="stadium",
    )


def four_arc_oval(length: float, width: float, end_radius: float) -> PlanOutline:
    """Oval of two end arcs (``end_radius``) and two side arcs, tangent (mm).

    The side radius follows from tangency:
    ``R_s = ((L/2 - r)² + W²/4 - r²) / (W - 2 r)``.  ``end_radius = width/2``
    gives the stadium.
    """
    L = check_positive("length", length, "mm")
    W = check_positive("width", width, "mm")
    if W > L:
        raise DesignError("width", W, f"must be <= length = {format_bound(L, upper=True)} mm", "mm")
    r = check_range("end_radius", end_radius, 0.0, W / 2.0, "mm", lo_open=True)
    if abs(r - W / 2.0) <= 1e-12 * W:
        return stadium_outline(L, W)
    if not W < L * (1.0 - 1e-12):  # the side arcs are then the circle of diameter W: no end arcs are left
        raise DesignError("width", W, f"must be < length = {format_bound(L, upper=True)} mm for ends of radius {r:g} mm (an oval as wide as it "
                          "is long is a circle, with no end arcs; or give end_radius = width/2)", "mm")
    hx = L / 2.0 - r
    Rs = (hx * hx + W * W / 4.0 - r * r) / (W - 2.0 * r)
    if Rs <= r:
        raise DesignError("end_radius", r, f"gives a side radius {Rs:.4g} mm not larger than the end radius", "mm")
    cy = W / 2.0 - Rs  # centre of the upper side arc is (0, cy) (below the axis)
    # tangent point between the right end arc (centre (hx, 0)) and the upper side arc
    ang = math.atan2(0.0 - cy, hx - 0.0)  # direction from side-arc centre to end-arc centre
    segs = [
        _arc((hx, 0.0), r, -ang, 2 * ang),
        _arc((0.0, cy), Rs, ang, math.pi - 2 * ang),
        _arc((-hx, 0.0), r, math.pi - ang, 2 * ang),
        _arc((0.0, -cy), Rs, math.pi + ang, math.pi - 2 * ang),
    ]
    return PlanOutline(segs, name="oval")


def four_arc_oval_from_side_radius(length: float, width: float, side_radius: float) -> PlanOutline:
    """Four-arc oval given its side radius (mm); the end radius follows from tangency:
    ``r = (R_s W - (L² + W²)/4) / (2 R_s - L)``, and must be at least ``Tolerances.min_length``
    like any length a design gives, so ``R_s >= ((L² + W²)/4 - m L) / (W - 2 m)``, ``m`` that length
    (:func:`_side_radius_limit`)."""
    L = check_positive("length", length, "mm")
    W = check_positive("width", width, "mm")
    if not W < L:  # (a side radius then gives ends of radius W/2 or more: no oval)
        raise DesignError("width", W, f"must be < length = {format_bound(L, upper=True)} mm for a modified capsule", "mm")
    if not W > 2.0 * DEFAULT.min_length:  # (ends narrower than W/2 cannot reach the least length)
        raise DesignError("width", W, f"must be > {2.0 * DEFAULT.min_length:g} mm for a modified capsule (its end "
                          f"radius, below width/2, must be at least {DEFAULT.min_length:g} mm)", "mm")
    Rs = check_positive("side_radius", side_radius, "mm")
    lo = _side_radius_limit(L, W)
    r = (Rs * W - (L * L + W * W) / 4.0) / (2.0 * Rs - L) if Rs > L / 2.0 else 0.0
    if not (Rs >= lo and DEFAULT.min_length * (1.0 - 1e-9) <= r < W / 2.0):
        raise DesignError("side_radius", Rs, f"must be >= {format_bound(lo, upper=False)} mm for a {L:g} x {W:g} mm "
                          f"oval (its end radius would be below {DEFAULT.min_length:g} mm, Tolerances.min_length)",
                          "mm")
    return four_arc_oval(L, W, r)


def _side_radius_limit(length: float, width: float) -> float:
    """The least side radius (mm) of a four-arc oval ``length`` × ``width`` (``2 m < width < length``)
    whose end radius is ``Tolerances.min_length``: the side radius must be > ``(L² + W²)/(4 W)``, where
    the ends vanish, and a few µm more (it had said "> length/2", refusing 9.51 mm for a 19 × 8.5 mm
    oval with "> 12.7426 mm")."""
    m = DEFAULT.min_length
    return ((length * length + width * width) / 4.0 - m * length) / (width - 2.0 * m)


def rounded_polygon(vertices, corner_radius: float, name: str = "polygon") -> PlanOutline:
    """Convex polygon (vertices CCW, mm) with every corner rounded to ``corner_radius``."""
    V = np.asarray(vertices, dtype=float)
    n = len(V)
    rc = check_positive("corner_radius", corner_radius, "mm")
    segs: list[Seg] = []
    tangent_pts = []
    for i in range(n):
        a, b, c = V[i - 1], V[i], V[(i + 1) % n]
        u1 = (a - b) / np.linalg.norm(a - b)
        u2 = (c - b) / np.linalg.norm(c - b)
        half = 0.5 * math.acos(float(np.clip(u1 @ u2, -1, 1)))
        t = rc / math.tan(half)
        if t > 0.5 * min(np.linalg.norm(a - b), np.linalg.norm(c - b)) + 1e-12:
            raise DesignError("corner_radius", rc, f"must be <= {format_bound(0.5 * min(np.linalg.norm(a - b), np.linalg.norm(c - b)) * math.tan(half), upper=True)} mm (the rounded corners would overlap)", "mm")
        bis = (u1 + u2) / np.linalg.norm(u1 + u2)
        centre = b + bis * rc / math.sin(half)
        p_in = b + u1 * t
        p_out = b + u2 * t
        th0 = math.atan2(p_in[1] - centre[1], p_in[0] - centre[0])
        th1 = math.atan2(p_out[1] - centre[1], p_out[0] - centre[0])
        sw = (th1 - th0) % math.tau
        tangent_pts.append((p_in, p_out, centre, th0, sw))
    for i in range(n):
        p_in, p_out, centre, th0, sw = tangent_pts[i]
        segs.append(_arc(centre, rc, th0, sw))
        nxt = tangent_pts[(i + 1) % n][0]
        if np.linalg.norm(nxt - p_out) > 1e-12:
            segs.append(_line(p_out, nxt))
    return PlanOutline(segs, name=name)


def rounded_rectangle_outline(length: float, width: float, corner_radius: float) -> PlanOutline:
    """Rectangle ``length`` (x) × ``width`` (y) with corners of ``corner_radius`` (mm)."""
    L = check_positive("length", length, "mm")
    W = check_positive("width", width, "mm")
    rc = check_range("corner_radius", corner_radius, 0.0, min(L, W) / 2.0, "mm", lo_open=True)
    hx, hy = L / 2.0, W / 2.0
    return rounded_polygon([(hx, -hy), (hx, hy), (-hx, hy), (-hx, -hy)], rc, name="rounded_rectangle")
