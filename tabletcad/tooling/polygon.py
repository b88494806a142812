"""Is a closed polyline a simple polygon?  The check of an emboss outline when the design is read.

A bow-tie outline reached OCC and stopped the build after the tablet was built; it is refused here,
in the design file's terms.  Lengths are compared with a tolerance, not exactly: an outline written
by a script closes on ``sin(2π) = -2.4e-16`` and repeats its first point, and ``0.15`` is not a
binary fraction.  Points closer than the tolerance are one point; an edge that comes within it of
another (not its neighbour) touches it.  numpy alone; the pairs of edges are tested in blocks, so
the cost is about n² / 2 vectorised segment distances.
"""

from __future__ import annotations

import numpy as np

__all__ = ["POLYGON_TOL_MM", "polygon_problem"]

#: points closer than this (mm) are one point; edges closer than it touch (OCC's confusion tolerance)
POLYGON_TOL_MM = 1e-7


def _segment_distance(a, b, c, d) -> np.ndarray:
    """Distances between segments ``a-b`` and ``c-d`` (arrays of 2D points, broadcast)."""

    def orient(p, q, r):
        return (q[..., 0] - p[..., 0]) * (r[..., 1] - p[..., 1]) - (q[..., 1] - p[..., 1]) * (r[..., 0] - p[..., 0])

    def point_segment(p, s, e):
        se = e - s
        den = np.maximum(np.einsum("...i,...i", se, se), 1e-300)
        t = np.clip(np.einsum("...i,...i", p - s, se) / den, 0.0, 1.0)
        return np.linalg.norm(p - (s + t[..., None] * se), axis=-1)

    o1, o2, o3, o4 = orient(a, b, c), orient(a, b, d), orient(c, d, a), orient(c, d, b)
    crossing = (np.sign(o1) * np.sign(o2) < 0) & (np.sign(o3) * np.sign(o4) < 0)
    dist = np.minimum(np.minimum(point_segment(c, a, b), point_segment(d, a, b)),
                      np.minimum(point_segment(a, c, d), point_segment(b, c, d)))
    return np.where(crossing, 0.0, dist)


def polygon_problem(points, tol: float = POLYGON_TOL_MM) -> str | None:
    """Why the closed polyline through ``points`` (mm) is not a simple polygon, or None.

    Points within ``tol`` of the one after them (and the last of the first) are dropped; what is
    left must have three points and an area, no edge may double back over the one before it, and
    no two other edges may come within ``tol`` of each other (a bow-tie's crossing, a vertex on
    another edge).  Edges and points are numbered as given: edge ``k`` runs from point ``k``.
    """
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    keep: list[int] = []  # the last point of each run of points closer than tol (its edge starts there)
    for k in range(len(p)):
        if keep and np.linalg.norm(p[k] - p[keep[-1]]) <= tol:
            keep[-1] = k
        else:
            keep.append(k)
    while len(keep) > 1 and np.linalg.norm(p[keep[-1]] - p[keep[0]]) <= tol:
        keep.pop()
    n = len(keep)
    if n < 3:
        return "fewer than 3 distinct points"
    q = p[keep]
    a, b, c = q, np.roll(q, -1, axis=0), np.roll(q, -2, axis=0)
    # an edge doubling back: the next edge's end lies on this edge's segment, or this edge's start on the next's
    back = np.minimum(_segment_distance(c, c, a, b), _segment_distance(a, a, b, c)) <= tol
    if back.any():
        k = int(np.argmax(back))
        j = keep[(k + 1) % n]
        return f"the edges at point {j} ({p[j, 0]:g}, {p[j, 1]:g}) double back over each other"
    for i0 in range(0, n, 256):  # every pair i < j of edges that do not share a point
        i = np.arange(i0, min(i0 + 256, n))[:, None]
        j = np.arange(n)[None, :]
        pair = (j > i + 1) & ~((i == 0) & (j == n - 1))
        d = _segment_distance(a[i], b[i], a[j], b[j])
        hit = pair & (d <= tol)
        if hit.any():
            ii, jj = np.argwhere(hit)[0]
            return f"edges {keep[int(i[ii, 0])]} and {keep[int(jj)]} cross or touch"
    area2 = float(np.sum(a[:, 0] * b[:, 1] - b[:, 0] * a[:, 1]))
    if abs(area2) <= tol * float(np.sum(np.linalg.norm(b - a, axis=1))):
        return "it encloses no area"
    return None
