"""Meridian profiles of tablet faces: chains of lines and arcs in the ``(d, z)`` plane.

``d`` is the inward distance from the plan outline (mm, 0 on the band) and
``z`` the height (mm).  A face profile runs from the band edge (``d = 0``)
inward; revolved about the axis (round tablets, ``d = R - r``) or swept along
the inward offsets of an outline it is the tablet's exact nominal face.  Arcs
revolve or sweep into spheres and tori, lines into cones, planes and cylinders.

Each element is split into *pieces* whose cubic Hermite interpolant (exact end
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

__all__ = ["Line2", "Arc2", "Piece", "hermite_points", "pieces_for", "distance_to_chain", "joint_is_smooth"]


@dataclass(frozen=True)
class Line2:
    """Segment from ``p0`` to ``p1`` in the (d, z) plane (mm)."""

    p0: tuple[float, float]
    p1: tuple[float, float]
    label: str = "line"

    def point(self, t) -> np.ndarray:
        t = np.asarray(t, dtype=float)[..., None]
        return (1 - t) * np.asarray(self.p0) + t * np.asarray(self.p1)

    def tangent(self, t) -> np.ndarray:
        t = np.asarray(t, dtype=float)
        d = np.subtract(self.p1, self.p0)
        return np.broadcast_to(d, t.shape + (2,)).copy()

    @property
    def length(self) -> float:
        return float(math.hypot(self.p1[0] - self.p0[0], self.p1[1] - self.p0[1]))

    def hermite(self, t0: float, t1: float):
        P0, P1 = self.point(t0), self.point(t1)
        D = P1 - P0
        return P0, P1, D, D

    def distance(self, q: np.ndarray) -> np.ndarray:
        a = np.asarray(self.p0)
        d = np.subtract(self.p1, self.p0)
        t = np.clip(((q - a) @ d) / float(d @ d), 0.0, 1.0)
        r = q - (a + t[:, None] * d)
        return np.hypot(r[:, 0], r[:, 1])

    def mirrored(self, zm: float) -> "Line2":
        return Line2((self.p1[0], 2 * zm - self.p1[1]), (self.p0[0], 2 * zm - self.p0[1]), self.label)


@dataclass(frozen=True)
class Arc2:
    """Arc of ``radius`` about ``center`` from angle ``phi0`` to ``phi1`` (rad) in the (d, z) plane."""

    center: tuple[float, float]
    radius: float
    phi0: float
    phi1: float
    label: str = "arc"

    def point(self, t) -> np.ndarray:
        ph = self.phi0 + (self.phi1 - self.phi0) * np.asarray(t, dtype=float)
        return np.stack([self.center[0] + self.radius * np.cos(ph), self.center[1] + self.radius * np.sin(ph)], -1)

    def tangent(self, t) -> np.ndarray:
        ph = self.phi0 + (self.phi1 - self.phi0) * np.asarray(t, dtype=float)
        k = self.radius * (self.phi1 - self.phi0)
        return np.stack([-k * np.sin(ph), k * np.cos(ph)], -1)

    @property
    def length(self) -> float:
        return abs(self.radius * (self.phi1 - self.phi0))

    def hermite(self, t0: float, t1: float):
        dphi = (self.phi1 - self.phi0) * (t1 - t0)
        k = 4.0 * math.tan(dphi / 4.0) * self.radius  # signed with dphi
        P0, P1 = self.point(t0), self.point(t1)
        ph0 = self.phi0 + (self.phi1 - self.phi0) * t0
        ph1 = self.phi0 + (self.phi1 - self.phi0) * t1
        D0 = k * np.array([-math.sin(ph0), math.cos(ph0)])
        D1 = k * np.array([-math.sin(ph1), math.cos(ph1)])
        return P0, P1, D0, D1

    def distance(self, q: np.ndarray) -> np.ndarray:
        c = np.asarray(self.center)
        r = q - c
        rho = np.hypot(r[:, 0], r[:, 1])
        ang = np.arctan2(r[:, 1], r[:, 0])
        sw = self.phi1 - self.phi0
        rel = np.mod((ang - self.phi0) * math.copysign(1.0, sw), 2 * math.pi)
        on = rel <= abs(sw)
        e0 = np.linalg.norm(q - self.point(0.0), axis=1)
        e1 = np.linalg.norm(q - self.point(1.0), axis=1)
        return np.where(on, np.abs(rho - self.radius), np.minimum(e0, e1))

    def mirrored(self, zm: float) -> "Arc2":
        return Arc2((self.center[0], 2 * zm - self.center[1]), self.radius, -self.phi1, -self.phi0, self.label)


Element = Line2 | Arc2


@dataclass(frozen=True)
class Piece:
    """Part ``[t0, t1]`` of an element: one PDE patch (traversed backwards when ``flip``)."""

    element: Line2 | Arc2
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


def pieces_for(element: Line2 | Arc2, target: float, max_angle: float = math.radians(45.0)) -> list[Piece]:
    """Split an element into the fewest equal pieces whose cubic Hermite
    interpolant is within ``target`` mm of it (lines: one piece)."""
    if isinstance(element, Line2):
        return [Piece(element, 0.0, 1.0)]
    sweep = abs(element.phi1 - element.phi0)
    n = max(1, math.ceil(sweep / max_angle - 1e-12))
    u = np.linspace(0.0, 1.0, 257)
    while True:
        ps = [Piece(element, i / n, (i + 1) / n) for i in range(n)]
        err = max(float(np.max(element.distance(hermite_points(p, u)))) for p in ps)
        if err <= target or n >= 4096:
            return ps
        # error ~ φ⁶: jump close to the needed count.  Capped before the list is built: when
        # rounding alone exceeds the target (coordinates ~1e100 mm) the jump asked for ~1e15 pieces
        n = min(4096, max(n + 1, math.ceil(n * (err / target) ** (1 / 6) * 1.02))) if math.isfinite(err) else 4096


def distance_to_chain(elements, q: np.ndarray) -> np.ndarray:
    """Exact distance (mm) from points ``q`` (m, 2) to a chain of elements."""
    q = np.asarray(q, dtype=float).reshape(-1, 2)
    out = np.full(len(q), np.inf)
    for e in elements:
        out = np.minimum(out, e.distance(q))
    return out


def _unit_tangent(e, t: float) -> np.ndarray:
    d = e.tangent(np.array(t))
    return d / np.linalg.norm(d)


def joint_is_smooth(e_prev, e_next, tol_deg: float = 1e-6) -> bool:
    """Whether two consecutive elements meet tangentially (within ``tol_deg``)."""
    a = _unit_tangent(e_prev, 1.0)
    b = _unit_tangent(e_next, 0.0)
    ang = math.degrees(math.atan2(abs(a[0] * b[1] - a[1] * b[0]), float(a @ b)))
    return ang <= tol_deg
