"""The deepest point inside a chain of lines and arcs near a start: a local maximum of the signed distance.

:meth:`~tabletcad.families.outline.PlanOutline.inscribed_radius` polishes the best points of a grid with
:func:`deepest_near`.  Inside the outline the signed distance is ``f(x) = min_i d_i(x)``, the least of the
distances to the segments; each ``d_i`` is 1-Lipschitz and, near a point, nearly linear:
``d_i(x + s) ≈ d_i(x) + g_i · s`` (``g_i`` the unit vector from the segment's nearest point to ``x``).  A
step maximises ``t`` subject to ``t <= d_i + g_i · s`` for the segments that could be the nearest within
the step's box ``|s_x|, |s_y| <= Δ`` (a linear programme in ``(s_x, s_y, t)``, solved at its vertices), of
least length among the best (along a ridge of equal depth, such as the middle line between two parallel
sides, the step goes straight across it); it is kept when ``f`` grows, else the box shrinks four times.
Where the segments near the deepest point are lines (a polygon's vertex of the medial axis, a ridge
between parallel sides) the first step lands on it; arcs and the ends of segments bend the distances, and
the steps converge on them as Newton's method does, or by the shrinking box on a bent ridge.
"""

from __future__ import annotations

import math
from typing import Callable, Sequence

__all__ = ["distance_jets", "deepest_near", "plain_segments"]

#: A function of a plan point ``(x, y)`` (mm) giving, for every segment, its distance (mm) and that
#: distance's gradient ``(d, g_x, g_y)`` (a unit vector, or 0 on the segment).
Jets = Callable[[float, float], list]


def plain_segments(segs: Sequence) -> list[tuple]:
    """``segs`` (lines and arcs) as tuples of plain floats for the one-point loops here and in
    :meth:`~tabletcad.families.outline.PlanOutline._point_signed_distance`: a line
    ``(True, ax, ay, dx, dy, dx² + dy²)`` (its start and its run, mm); an arc
    ``(False, cx, cy, r, cos m, sin m, cos(|sweep|/2), sign of sweep, x0, y0, u0, w0, x1, y1, u1, w1)``
    (centre and radius, mm; ``m`` its middle angle; its ends and their unit tangents)."""
    items = []
    for sg in segs:
        (ax, ay), (bx, by) = sg.p0, sg.p1
        if sg.kind == "line":
            dx, dy = bx - ax, by - ay
            items.append((True, ax, ay, dx, dy, dx * dx + dy * dy))
        else:
            mid = sg.theta0 + 0.5 * sg.sweep
            t0, t1 = sg.tangent(0), sg.tangent(1)
            items.append((False, sg.center[0], sg.center[1], sg.radius, math.cos(mid), math.sin(mid),
                          math.cos(0.5 * abs(sg.sweep)), math.copysign(1.0, sg.sweep),
                          ax, ay, float(t0[0]), float(t0[1]), bx, by, float(t1[0]), float(t1[1])))
    return items


def distance_jets(segs: Sequence) -> Jets:
    """The distances of a plan point to each of ``segs`` (lines and arcs) with their gradients, in plain
    floats: :data:`Jets`.  A line's nearest point is its projection clipped to its ends; an arc's is the
    radial one within its span, else its nearer end."""
    items = plain_segments(segs)

    def unit(qx: float, qy: float) -> tuple[float, float, float]:
        d = math.hypot(qx, qy)
        return (d, qx / d, qy / d) if d > 0.0 else (0.0, 0.0, 0.0)

    def jets(x: float, y: float) -> list:
        out = []
        for it in items:
            if it[0]:
                _, ax, ay, dx, dy, dd = it
                t = min(max(((x - ax) * dx + (y - ay) * dy) / dd, 0.0), 1.0)
                out.append(unit(x - (ax + t * dx), y - (ay + t * dy)))
                continue
            _, cx, cy, rad, cm, sm, ch, _, x0, y0, _, _, x1, y1, _, _ = it
            rx, ry = x - cx, y - cy
            rho = math.hypot(rx, ry)
            if rho > 0.0 and rx * cm + ry * sm >= rho * ch:  # within the arc's span: radially
                sign = 1.0 if rho >= rad else -1.0
                out.append((abs(rho - rad), sign * rx / rho, sign * ry / rho))
            else:
                e0, e1 = unit(x - x0, y - y0), unit(x - x1, y - y1)
                out.append(e0 if e0[0] <= e1[0] else e1)
        return out

    return jets


def _solve3(rows: Sequence[tuple[float, float, float, float]]) -> tuple[float, float, float] | None:
    """The point ``(s_x, s_y, t)`` (mm) on the three planes ``a · (s_x, s_y, t) = b`` (rows
    ``(a_x, a_y, a_t, b)``), by Cramer's rule; None when they do not meet in one point."""
    (a1, b1, c1, r1), (a2, b2, c2, r2), (a3, b3, c3, r3) = rows
    det = a1 * (b2 * c3 - b3 * c2) - b1 * (a2 * c3 - a3 * c2) + c1 * (a2 * b3 - a3 * b2)
    if abs(det) < 1e-12:
        return None
    x = (r1 * (b2 * c3 - b3 * c2) - b1 * (r2 * c3 - r3 * c2) + c1 * (r2 * b3 - r3 * b2)) / det
    y = (a1 * (r2 * c3 - r3 * c2) - r1 * (a2 * c3 - a3 * c2) + c1 * (a2 * r3 - a3 * r2)) / det
    t = (a1 * (b2 * r3 - b3 * r2) - b1 * (a2 * r3 - a3 * r2) + r1 * (a2 * b3 - a3 * b2)) / det
    return x, y, t


def _least_on_segment(p: tuple[float, float], q: tuple[float, float]) -> tuple[float, float]:
    """The point of the segment ``p q`` (plan steps, mm) nearest the origin."""
    dx, dy = q[0] - p[0], q[1] - p[1]
    dd = dx * dx + dy * dy
    t = 0.0 if dd == 0.0 else min(max(-(p[0] * dx + p[1] * dy) / dd, 0.0), 1.0)
    return p[0] + t * dx, p[1] + t * dy


def _step(jet: list, f: float, box: float, scale: float) -> tuple[float, float, float]:
    """``(s_x, s_y, t)``: the least step within the box ``±box`` (mm) that maximises ``t <= d_i + g_i · s``
    over the segments within ``3 box`` of the least distance ``f`` (the others stay farther within the box),
    and that ``t`` (mm); ``scale``: the outline's size (mm), for the rounding allowed in the tests."""
    planes = [(-gx, -gy, 1.0, d) for d, gx, gy in jet if d <= f + 3.0 * box]  # t - g · s <= d
    walls = [(1.0, 0.0, 0.0, box), (-1.0, 0.0, 0.0, box), (0.0, 1.0, 0.0, box), (0.0, -1.0, 0.0, box)]
    rows = planes + walls
    slack = 1e-12 * (scale + box)
    best: list[tuple[float, float, float]] = []
    n = len(rows)
    for i in range(len(planes)):  # every vertex lies on one plane at least (t is bounded by the planes alone)
        for j in range(i + 1, n):
            for k in range(j + 1, n):
                p = _solve3((rows[i], rows[j], rows[k]))
                if p is None or any(a * p[0] + b * p[1] + c * p[2] > r + slack for a, b, c, r in rows):
                    continue
                best.append(p)
    if not best:
        return 0.0, 0.0, f
    top = max(p[2] for p in best)
    tops = [p for p in best if p[2] >= top - 1e-15 * scale]
    # the optimal vertices span a point or a segment (each distance has a unit gradient: no flat face);
    # its point nearest no step at all
    cands = [(p[0], p[1]) for p in tops]
    cands += [_least_on_segment(a, b) for i, a in enumerate(cands) for b in cands[i + 1 :]]
    sx, sy = min(cands, key=lambda s: s[0] * s[0] + s[1] * s[1])
    return sx, sy, top


def deepest_near(jets: Jets, depth: Callable[[float, float], float], x: float, y: float, box: float,
                 scale: float, rounds: int = 200) -> tuple[float, float] | None:
    """A local maximum of the signed distance ``depth`` (mm, > 0 inside) near the plan point ``(x, y)``
    from the steps of :func:`_step` (``jets``: :func:`distance_jets` of the same segments), starting
    with the box ``±box`` (mm); ``scale``: the outline's size (mm).  Stops when the box is below
    ``1e-13 scale`` or a step gains nothing; None when ``rounds`` steps do not get there (the caller then
    searches otherwise)."""
    f = depth(x, y)
    stop = 1e-13 * scale
    for _ in range(rounds):
        if box < stop:
            return x, y
        sx, sy, t = _step(jets(x, y), f, box, scale)
        if t <= f + 1e-15 * scale or (sx == 0.0 and sy == 0.0):  # no gain foreseen beyond rounding
            return x, y
        xn, yn = x + sx, y + sy
        fn = depth(xn, yn)
        if fn > f:
            x, y, f = xn, yn, fn
            box = max(min(box, 2.0 * max(abs(sx), abs(sy))), stop)
        else:
            box *= 0.25
    return None
