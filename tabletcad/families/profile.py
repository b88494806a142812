"""Meridian profiles of tablet faces: chains of lines and arcs in the ``(d, z)`` plane.

``d`` is the inward distance from the plan outline (mm, 0 on the band) and
``z`` the height (mm).  A face profile runs from the band edge (``d = 0``)
inward; revolved about the axis (round tablets, ``d = R - r``) or swept along
the inward offsets of an outline it is the tablet's exact nominal face.  Arcs
revolve or sweep into spheres and tori, lines into cones, planes and cylinders.

The elements are :class:`tabletcad.geometry.curves.Seg` lines and arcs (:func:`profile_line`,
:func:`profile_arc`).  Each element is split into *pieces* whose cubic Hermite interpolant (exact end
points, exact tangent directions) stays within a target distance of the
element; a piece becomes one PDE patch in Hermite form.  For an arc piece of
angle ``φ`` the tangent length is ``4 ρ tan(φ/4)`` (the length that makes the
cubic's midpoint lie on the arc), so the cubic error falls like ``ρ φ⁶``
instead of ``ρ φ⁴``; it is the exact derivative of a smooth
reparametrisation of the arc, so tangent directions are exact and seams inside
an arc or between tangent elements are G1 by construction.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tabletcad.geometry.curves import Seg, nearest_of
from tabletcad.geometry.vectors import linspace

__all__ = ["profile_line", "profile_arc", "Piece", "hermite_points", "pieces_for", "distance_to_chain",
           "joint_is_smooth"]


def profile_line(p0, p1, label: str = "line") -> Seg:
    """The profile element from ``p0`` to ``p1`` in the (d, z) plane (mm)."""
    return Seg.line(p0, p1, label)


def profile_arc(center, radius: float, phi0: float, phi1: float, label: str = "arc") -> Seg:
    """The profile element on the circle of ``radius`` about ``center`` from angle ``phi0`` to ``phi1`` (rad)."""
    return Seg.arc(center, radius, phi0, phi1 - phi0, label)


@dataclass(frozen=True)
class Piece:
    """Part ``[t0, t1]`` of an element: one PDE patch (traversed backwards when ``flip``)."""

    element: Seg
    t0: float
    t1: float
    flip: bool = False

    def hermite(self):
        """``(P0, P1, D0, D1)``: end points and u-derivatives (mm) in the (d, z) plane."""
        P0, P1, D0, D1 = self.element.hermite(self.t0, self.t1)
        if self.flip:
            return P1, P0, -D1, -D0
        return P0, P1, D0, D1

    def reversed(self) -> "Piece":
        return Piece(self.element, self.t0, self.t1, not self.flip)


def hermite_points(piece: Piece, u: np.ndarray) -> np.ndarray:
    """The cubic Hermite curve of a piece at ``u`` (m, 2)."""
    P0, P1, D0, D1 = piece.hermite()
    u = np.asarray(u, dtype=float)[:, None]
    h00 = 2 * u**3 - 3 * u**2 + 1
    h10 = u**3 - 2 * u**2 + u
    h01 = -2 * u**3 + 3 * u**2
    h11 = u**3 - u**2
    return h00 * P0 + h10 * D0 + h01 * P1 + h11 * D1


def pieces_for(element: Seg, target: float, max_angle: float = math.radians(45.0)) -> list[Piece]:
    """Split an element into the fewest equal pieces whose cubic Hermite
    interpolant is within ``target`` mm of it (lines: one piece)."""
    if element.kind == "line":
        return [Piece(element, 0.0, 1.0)]
    sweep = abs(element.sweep)
    n = max(1, math.ceil(sweep / max_angle - 1e-12))
    u = linspace(0.0, 1.0, 257)
    while True:
        ps = [Piece(element, i / n, (i + 1) / n) for i in range(n)]
        err = max(float(np.max(element.distance(hermite_points(p, u)))) for p in ps)
        if err <= target or n >= 4096:
            return ps
        # error ~ φ⁶: jump close to the needed count.  Capped before the list is built: when
        # rounding alone exceeds the target (coordinates ~1e100 mm) the jump asked for ~1e15 pieces
        n = min(4096, max(n + 1, math.ceil(n * (err / target) ** (1 / 6) * 1.02))) if math.isfinite(err) else 4096


def distance_to_chain(elements, q: np.ndarray) -> np.ndarray:
    """Exact distance (mm) from points ``q`` (m, 2) to a chain of elements.

    The smallest of the distances to every element, each measured only where it could win:
    every element's bounding circle (:meth:`~tabletcad.geometry.curves.Seg.bounding_circle`)
    gives the lower bound ``|q - c| - r`` of its distance; each point is first measured to
    the element of least bound (nearly always the nearest), then to the others whose bound
    is below that distance (near the joints), so a point usually meets one element or two.
    """
    q = np.asarray(q, dtype=float).reshape(-1, 2)
    return nearest_of(elements, q, lambda e, p: e.distance(p))[0]


def _unit_tangent(e, t: float) -> np.ndarray:
    d = e.derivative(np.array(t))
    return d / np.linalg.norm(d)


def joint_is_smooth(e_prev, e_next, tol_deg: float = 1e-6) -> bool:
    """Whether two consecutive elements meet tangentially (within ``tol_deg``)."""
    a = _unit_tangent(e_prev, 1.0)
    b = _unit_tangent(e_next, 0.0)
    ang = math.degrees(math.atan2(abs(a[0] * b[1] - a[1] * b[0]), float(a @ b)))
    return ang <= tol_deg
