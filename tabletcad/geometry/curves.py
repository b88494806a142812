"""Closed boundary curves ``c(v)``, ``v ∈ [0, 2π)``, in millimetres.

A curve is any object with ``evaluate(v, der=0)`` returning points (or
``v``-derivatives) of shape ``(m, 3)``.  The PDE patch reads curves only
through that method and through :meth:`Curve.fourier`, so analytic curves
(circle, ellipse, outlines made of lines and arcs) are exact at every ``v``;
curves given as points are interpolated by a periodic cubic spline.

Plan outlines (stadium, rounded rectangle, any lines-and-arcs outline) are
parametrised by arc length, starting on the +x axis and running
counter-clockwise, so that scaled copies of one outline correspond point by
point across a patch.  Circles and ellipses use the polar angle, which is the
same thing for a circle.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass, field
from functools import cached_property, lru_cache
from collections.abc import Sequence
from typing import Protocol, runtime_checkable

import numpy as np

from tabletcad.errors import DesignError, check_finite, check_positive, check_range, format_bound
from tabletcad.tolerance import DEFAULT
from tabletcad.geometry.vectors import clip, length2

__all__ = [
    "Seg",
    "signed_area",
    "Curve",
    "CurveLike",
    "Circle",
    "Ellipse",
    "Outline",
    "Stadium",
    "RoundedRectangle",
    "PointCurve",
    "Transformed",
    "fourier_coefficients",
    "modes_needed",
    "sample_v",
    "nearest_of",
    "evaluate_curves",
    "combination_of",
]



def sample_v(m: int) -> np.ndarray:
    """``m`` equally spaced parameters on ``[0, 2π)``."""
    return np.arange(m) * (math.tau / m)


#: :func:`fourier_samples` rounds up to a multiple of this (2⁴ · 3 · 5)
SYMMETRY_SAMPLES = 240


def fourier_samples(modes: int, least: int | None = None) -> int:
    """Samples per turn for the ``modes`` Fourier coefficients of a curve that is not band-limited:
    the least multiple of :data:`SYMMETRY_SAMPLES` (240) that is at least ``least`` (default
    ``DEFAULT.samples``, 512) and ``8 modes + 8``: 720 for up to 89 modes at the default.

    Sampled ``m`` times, mode ``n`` takes on the aliased content of modes ``n ± j m``.  A curve with
    ``k``-fold symmetry about the z axis, parametrised alike (``C(v + 2π/k)`` is ``C(v)`` turned by
    ``2π/k``), has plan content (``x + i y``) only at frequencies ``≡ 1 (mod k)``; when ``k`` divides
    ``m`` the aliased content keeps that residue, so the modes the curve lacks come out zero to rounding
    (and are skipped: :class:`~tabletcad.geometry.patch.PDEPatch`'s active modes) and its centre stays
    on the axis, for every ``k`` dividing 240 (2, 3, 4, 5, 6, 8, 10, 12, 15, 16, 20, 24, …).  At 512
    samples a rounded triangle's modes 3, 6, 9, … carried 2e-5 mm of aliased content (a third more
    modes in every evaluation, for nothing: the remainder term holds whatever the series leaves)
    and its spine wandered 6e-6 mm about the axis (so its cut-aways had no plan area:
    :meth:`~tabletcad.geometry.tablet.Tablet.plan_area`).
    """
    least = DEFAULT.samples if least is None else int(least)
    m = max(least, 8 * int(modes) + 8)
    return -(-m // SYMMETRY_SAMPLES) * SYMMETRY_SAMPLES


def _vec3(name: str, value) -> np.ndarray:
    arr = np.asarray(value, dtype=float).reshape(-1)
    if arr.shape != (3,) or not np.all(np.isfinite(arr)):
        raise DesignError(name, value, "must be three finite numbers (x, y, z) in mm")
    return arr


def evaluate_curves(curves: Sequence, v: np.ndarray, der: int = 0) -> np.ndarray:
    """``(len(curves), len(v), 3)``: each curve (or its ``der``-th derivative, mm) at ``v``, a curve given twice
    evaluated once; curves all of one class that shares work between them (an outline's frame: a swept
    tablet's data) in one :meth:`Curve.evaluate_several` call."""
    v = np.asarray(v, dtype=float).reshape(-1)
    kind = type(curves[0])
    several = getattr(kind, "evaluate_several", None)
    if several is not None and all(type(c) is kind for c in curves):
        hit = several(curves, v, der)
        if hit is not None:
            return hit
    out = np.empty((len(curves), v.size, 3))
    for k, c in enumerate(curves):
        j = next(j for j in range(k + 1) if curves[j] is c)
        out[k] = out[j] if j < k else c.evaluate(v, der)
    return out


def combination_of(curves: Sequence) -> tuple | None:
    """``(basis, weights, const)`` when every curve is ``weights[j] · basis + const[j]``: a fixed
    combination of the ``k`` curves of one shared ``basis`` (an object with ``evaluate(v, der)``
    giving ``(k, len(v), 3)`` mm) and a constant point, as a swept tablet's data are of its
    outline and its inward normal (:meth:`Curve.combination`); ``weights`` is
    ``(len(curves), k)``, ``const`` ``(len(curves), 3)`` mm.  None for any other curves.

    A patch whose data are such takes their Fourier coefficients and their residuals above its
    modes from the basis's, shared by every patch on it (both are linear in the curve)."""
    kind = type(curves[0])
    combination = getattr(kind, "combination", None)
    if combination is None or any(type(c) is not kind for c in curves):
        return None
    return combination(curves)


@runtime_checkable
class CurveLike(Protocol):
    def evaluate(self, v: np.ndarray, der: int = 0) -> np.ndarray: ...


class Curve:
    """Base class: closed curve in 3-D parametrised over ``v ∈ [0, 2π)``."""

    def evaluate(self, v, der: int = 0) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def __call__(self, v) -> np.ndarray:
        return self.evaluate(v)

    @classmethod
    def evaluate_several(cls, curves: Sequence["Curve"], v: np.ndarray, der: int = 0) -> np.ndarray | None:
        """Every curve of ``curves`` (all of this class) at ``v``: ``(len(curves), len(v), 3)`` mm, or None
        when this class has no shared work to save (then each is evaluated on its own: :func:`evaluate_curves`)."""
        return None

    @property
    def flat(self) -> bool:
        """True when the curve's z does not change with ``v`` by construction (a plan curve lifted to a
        height): a patch whose data are all flat has a z that is its spine's alone,
        :meth:`~tabletcad.geometry.patch.PDEPatch.level`.  False unless a class knows it."""
        return False

    # -- convenience ------------------------------------------------------------------
    def fourier(self, modes: int, samples: int | None = None):
        """Fourier coefficients ``(a0, a, b)`` up to ``modes``; see :func:`fourier_coefficients`."""
        return fourier_coefficients(self, modes, samples)

    def modes_needed(self, tol: float | None = None, max_modes: int = 256, samples: int | None = None) -> int:
        """Fewest Fourier modes representing the curve within ``tol`` mm; see :func:`modes_needed`."""
        return modes_needed(self, tol, max_modes, samples)

    def centroid(self, samples: int = 256) -> np.ndarray:
        """Mean of the curve over ``v`` (the ``n = 0`` Fourier term), shape (3,)."""
        return self.evaluate(sample_v(samples)).mean(axis=0)

    def moved(self, offset) -> "Transformed":
        """This curve translated by ``offset`` (mm)."""
        return Transformed(self, np.eye(3), _vec3("offset", offset))

    def at_height(self, z: float) -> "Transformed":
        """This curve translated by ``z`` mm along the z axis."""
        return self.moved((0.0, 0.0, check_finite("z", z, "mm")))

    def scaled_about_centroid(self, sxy: float = 1.0, sz: float = 1.0) -> "Transformed":
        """Scale in the plane (``sxy``) and along z (``sz``) about the curve's centroid."""
        c = self.centroid()
        m = np.diag([sxy, sxy, sz])
        return Transformed(self, m, c - m @ c)

    def breakpoints(self) -> np.ndarray:
        """Parameters ``v`` in [0, 2π) where the curve is not infinitely smooth (empty if none)."""
        return np.zeros(0)

    def band_limit(self) -> int | None:
        """Highest Fourier mode the curve has, when it is a finite trigonometric sum (None otherwise).

        Lets :func:`modes_needed` stop there: a circle or an ellipse has mode 1 only.
        """
        return None

    @property
    def is_point(self) -> bool:
        """True when the curve is a single point (a pole of a patch)."""
        pts = self.evaluate(sample_v(16))
        return bool(np.max(np.ptp(pts, axis=0)) == 0.0)


@dataclass(frozen=True)
class Circle(Curve):
    """Circle of ``radius`` (mm, >= 0; 0 gives a point) in the plane z = center[2].

    ``c(v) = center + radius (cos v, sin v, 0)`` (thesis eq 4.2).
    """

    radius: float
    center: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        check_range("radius", self.radius, 0.0, None, "mm")
        object.__setattr__(self, "center", tuple(_vec3("center", self.center)))

    def evaluate(self, v, der: int = 0) -> np.ndarray:
        v = np.asarray(v, dtype=float).reshape(-1)
        r = self.radius
        c, s = np.cos(v), np.sin(v)
        z = np.zeros_like(v)
        if der == 0:
            out = np.stack([r * c, r * s, z], axis=-1) + np.asarray(self.center)
        elif der == 1:
            out = np.stack([-r * s, r * c, z], axis=-1)
        elif der == 2:
            out = np.stack([-r * c, -r * s, z], axis=-1)
        else:
            raise ValueError(f"der = {der} is not allowed: must be 0, 1 or 2")
        return out

    @property
    def is_point(self) -> bool:
        return self.radius == 0.0

    @property
    def flat(self) -> bool:
        return True

    def band_limit(self) -> int:
        return 1


@dataclass(frozen=True)
class Ellipse(Curve):
    """Ellipse with semi-axes ``rx`` and ``ry`` (mm) in the plane z = center[2].

    ``c(v) = center + (rx cos v, ry sin v, 0)``.
    """

    rx: float
    ry: float
    center: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        check_range("rx", self.rx, 0.0, None, "mm")
        check_range("ry", self.ry, 0.0, None, "mm")
        object.__setattr__(self, "center", tuple(_vec3("center", self.center)))

    def evaluate(self, v, der: int = 0) -> np.ndarray:
        v = np.asarray(v, dtype=float).reshape(-1)
        c, s = np.cos(v), np.sin(v)
        z = np.zeros_like(v)
        if der == 0:
            return np.stack([self.rx * c, self.ry * s, z], axis=-1) + np.asarray(self.center)
        if der == 1:
            return np.stack([-self.rx * s, self.ry * c, z], axis=-1)
        if der == 2:
            return np.stack([-self.rx * c, -self.ry * s, z], axis=-1)
        raise ValueError(f"der = {der} is not allowed: must be 0, 1 or 2")

    @property
    def flat(self) -> bool:
        return True

    def band_limit(self) -> int:
        return 1


@dataclass(frozen=True)
class Seg:
    """One line or circular arc in a plane (mm): the one 2-D segment type of tabletcad.

    ``kind == "line"``: from ``p0`` to ``p1``.  ``kind == "arc"``: centre
    ``center``, ``radius`` (mm), start angle ``theta0`` and signed ``sweep``
    (rad, > 0 counter-clockwise = convex for a CCW outline); ``p0`` and ``p1`` are its
    end points.  Build with :meth:`line` and :meth:`arc`.
    """

    kind: str
    p0: tuple[float, float]
    p1: tuple[float, float]
    center: tuple[float, float] = (0.0, 0.0)
    radius: float = 0.0
    theta0: float = 0.0
    sweep: float = 0.0
    label: str = ""

    @classmethod
    def line(cls, p0, p1, label: str = "") -> Seg:
        """The line from ``p0`` to ``p1`` (mm)."""
        return cls("line", (float(p0[0]), float(p0[1])), (float(p1[0]), float(p1[1])), label=label)

    @classmethod
    def arc(cls, c, r: float, t0: float, sw: float, label: str = "") -> Seg:
        """The arc about ``c`` of radius ``r`` (mm) from angle ``t0`` through the signed ``sw`` (rad)."""
        c = (float(c[0]), float(c[1]))
        p0 = (c[0] + r * math.cos(t0), c[1] + r * math.sin(t0))
        p1 = (c[0] + r * math.cos(t0 + sw), c[1] + r * math.sin(t0 + sw))
        return cls("arc", p0, p1, c, float(r), float(t0), float(sw), label)

    def point(self, t) -> np.ndarray:
        """Points at ``t in [0, 1]`` (``(..., 2)``, mm): linear in length along a line, in angle on an arc."""
        t = np.asarray(t, dtype=float)
        if self.kind == "line":
            return (1 - t)[..., None] * np.asarray(self.p0) + t[..., None] * np.asarray(self.p1)
        ph = self.theta0 + self.sweep * t
        return np.stack([self.center[0] + self.radius * np.cos(ph), self.center[1] + self.radius * np.sin(ph)], -1)

    def derivative(self, t) -> np.ndarray:
        """``d point / dt`` at ``t`` (``(..., 2)``, mm)."""
        t = np.asarray(t, dtype=float)
        if self.kind == "line":
            return np.broadcast_to(np.subtract(self.p1, self.p0), t.shape + (2,)).copy()
        ph = self.theta0 + self.sweep * t
        k = self.radius * self.sweep
        return np.stack([-k * np.sin(ph), k * np.cos(ph)], -1)

    def hermite(self, t0: float, t1: float):
        """``(P0, P1, D0, D1)`` of the cubic Hermite curve standing for ``[t0, t1]`` (mm).

        A line's is exact.  An arc's end tangents have length ``4 ρ tan(φ/4)`` for its angle
        ``φ``, which puts the cubic's midpoint on the arc (error ~ ``ρ φ⁶``).
        """
        P0, P1 = self.point(t0), self.point(t1)
        if self.kind == "line":
            D = P1 - P0
            return P0, P1, D, D
        k = 4.0 * math.tan(self.sweep * (t1 - t0) / 4.0) * self.radius  # signed with the sweep
        ph0, ph1 = self.theta0 + self.sweep * t0, self.theta0 + self.sweep * t1
        return P0, P1, k * np.array([-math.sin(ph0), math.cos(ph0)]), k * np.array([-math.sin(ph1), math.cos(ph1)])

    def distance(self, q: np.ndarray) -> np.ndarray:
        """Exact distance (mm) from points ``q`` (m, 2) to the segment."""
        if self.kind == "line":
            a = np.asarray(self.p0)
            d = np.subtract(self.p1, self.p0)
            t = clip(((q - a) @ d) / float(d @ d), 0.0, 1.0)
            r = q - (a + t[:, None] * d)
            return length2(r[:, 0], r[:, 1])
        rx, ry = q[:, 0] - self.center[0], q[:, 1] - self.center[1]
        rho = length2(rx, ry)
        (x0, y0), (x1, y1) = self.ends
        # (the type the ends' distances take, as where() had mixed them in: float32 points give float64 on
        # numpy >= 2 and float32 on 1.24)
        out = np.abs(rho - self.radius).astype(np.result_type(rho, q[:0, 0] - x0), copy=False)
        off = np.flatnonzero(~self.within_sweep(rx, ry, rho))  # beyond the span: the nearer end's distance
        if off.size:  # (measured there alone: the same values, elementwise)
            qx, qy = q[off, 0], q[off, 1]
            out[off] = np.minimum(length2(qx - x0, qy - y0), length2(qx - x1, qy - y1))
        return out

    def bounding_circle(self) -> tuple[float, float, float]:
        """``(x, y, r)``: a circle holding the whole segment (mm), about its middle point.

        A line's middle and half length.  On an arc the distance from its middle point,
        ``2 ρ sin(Δθ / 2)``, grows with the angle ``Δθ <= |sweep| / 2 <= π`` to it, so the ends
        are farthest: ``r = 2 ρ sin(|sweep| / 4)``.
        """
        if self.kind == "line":
            (x0, y0), (x1, y1) = self.p0, self.p1
            return 0.5 * (x0 + x1), 0.5 * (y0 + y1), 0.5 * math.hypot(x1 - x0, y1 - y0)
        mid = self.theta0 + 0.5 * self.sweep
        return (self.center[0] + self.radius * math.cos(mid), self.center[1] + self.radius * math.sin(mid),
                2.0 * self.radius * math.sin(0.25 * abs(self.sweep)))

    def within_sweep(self, rx: np.ndarray, ry: np.ndarray, rho: np.ndarray) -> np.ndarray:
        """Whether directions ``(rx, ry)`` from an arc's centre (of lengths ``rho``) fall inside
        its angular span: within half the sweep of the arc's middle direction, i.e.
        ``r · m >= |r| cos(|sweep| / 2)`` (no arctangent; right for any sweep up to 2π)."""
        mid = self.theta0 + 0.5 * self.sweep
        return rx * math.cos(mid) + ry * math.sin(mid) >= rho * math.cos(0.5 * abs(self.sweep))

    def mirrored(self, ym: float) -> Seg:
        """The mirror image in the line ``y = ym``, run the other way (so a chain stays a chain)."""
        if self.kind == "line":
            return Seg.line((self.p1[0], 2 * ym - self.p1[1]), (self.p0[0], 2 * ym - self.p0[1]), self.label)
        return Seg.arc((self.center[0], 2 * ym - self.center[1]), self.radius, -(self.theta0 + self.sweep), self.sweep,
                       self.label)

    def translated(self, dx: float, dy: float) -> Seg:
        """The same segment moved by ``(dx, dy)`` (mm)."""
        if self.kind == "line":
            return Seg.line((self.p0[0] + dx, self.p0[1] + dy), (self.p1[0] + dx, self.p1[1] + dy), self.label)
        return Seg.arc((self.center[0] + dx, self.center[1] + dy), self.radius, self.theta0, self.sweep, self.label)

    @property
    def length(self) -> float:
        """Arc length (mm)."""
        if self.kind == "line":
            return float(math.hypot(self.p1[0] - self.p0[0], self.p1[1] - self.p0[1]))
        return abs(self.radius * self.sweep)

    @cached_property
    def ends(self) -> tuple[np.ndarray, np.ndarray]:
        """``point(0.0)`` and ``point(1.0)`` (mm; read-only), computed once: a distance to an arc measures
        points beyond its span from its ends at every call."""
        out = (self.point(0.0), self.point(1.0))
        for a in out:
            a.setflags(write=False)
        return out

    @cached_property
    def end_tangents(self) -> tuple[np.ndarray, np.ndarray]:
        """``tangent(0)`` and ``tangent(1)`` (read-only), computed once (the side an arc's end puts a
        point on)."""
        out = (self.tangent(0), self.tangent(1))
        for a in out:
            a.setflags(write=False)
        return out

    def tangent(self, end: int) -> np.ndarray:
        """Unit tangent at the start (0) or end (1)."""
        if self.kind == "line":
            d = np.subtract(self.p1, self.p0)
            return d / np.linalg.norm(d)
        th = self.theta0 + (self.sweep if end else 0.0)
        sg = math.copysign(1.0, self.sweep)
        return sg * np.array([-math.sin(th), math.cos(th)])

    def reversed(self) -> Seg:
        """The same segment run the other way."""
        if self.kind == "line":
            return Seg("line", self.p1, self.p0, label=self.label)
        return Seg("arc", self.p1, self.p0, self.center, self.radius, self.theta0 + self.sweep, -self.sweep, self.label)


def signed_area(segs) -> float:
    """Signed area (mm²) enclosed by a closed chain of :class:`Seg` (positive counter-clockwise):
    Green's theorem ``A = 1/2 ∮ (x dy - y dx)``, exact for lines and arcs."""
    a = 0.0
    for s in segs:
        if s.kind == "line":
            (x0, y0), (x1, y1) = s.p0, s.p1
            a += 0.5 * (x0 * y1 - x1 * y0)
        else:
            cx, cy = s.center
            r, t0, sw = s.radius, s.theta0, s.sweep
            t1 = t0 + sw
            a += 0.5 * (r * r * sw + cx * r * (math.sin(t1) - math.sin(t0)) - cy * r * (math.cos(t1) - math.cos(t0)))
    return a


class Outline(Curve):
    """Closed plan outline of straight lines and circular arcs, parametrised by arc length.

    Build with :meth:`from_segments`.  ``v = 2π s / P`` where ``s`` is the arc
    length from the start point and ``P`` the perimeter; the outline lies in the
    plane ``z``.
    """

    def __init__(self, segments: list[Seg], z: float = 0.0, name: str = "outline") -> None:
        if not segments:
            raise DesignError("segments", 0, "an outline needs at least one segment")
        self._segs = tuple(segments)
        self._z = float(z)
        self.name = name
        lengths = np.array([s.length for s in segments])
        if np.any(lengths <= 0):
            raise DesignError("segments", "zero-length segment", "every segment must have length > 0")
        self._cum = np.concatenate([[0.0], np.cumsum(lengths)])
        self.perimeter = float(self._cum[-1])

    @property
    def segs(self) -> tuple[Seg, ...]:
        """The lines and arcs, in order (mm)."""
        return self._segs

    @classmethod
    def from_segments(cls, items, z: float = 0.0, name: str = "outline") -> "Outline":
        """Outline from a list of ``("line", (x0, y0), (x1, y1))`` and
        ``("arc", (cx, cy), radius, theta0, sweep)`` items (angles in radians,
        ``sweep > 0`` counter-clockwise), which must join end to start.
        """
        segs: list[Seg] = []
        for it in items:
            if it[0] == "line":
                segs.append(Seg.line(it[1], it[2]))
            elif it[0] == "arc":
                segs.append(Seg.arc(it[1], float(it[2]), float(it[3]), float(it[4])))
            else:
                raise DesignError("segment kind", it[0], "must be 'line' or 'arc'")
        # check closure
        ends = []
        for s in segs:
            if s.kind == "line":
                ends.append(np.asarray(s.p1))
            else:
                t1 = s.theta0 + s.sweep
                ends.append(np.asarray(s.center) + s.radius * np.array([math.cos(t1), math.sin(t1)]))
        for i, s in enumerate(segs):
            gap = float(np.hypot(*(ends[i - 1] - np.asarray(s.p0))))
            if gap > 1e-9 * max(1.0, max(x.length for x in segs)):
                raise DesignError("segments", f"gap {gap:.3g} mm before segment {i}", "segments must join end to start")
        return cls(segs, z=z, name=name)

    def evaluate(self, v, der: int = 0) -> np.ndarray:
        v = np.asarray(v, dtype=float).reshape(-1)
        s = np.mod(v, math.tau) * (self.perimeter / math.tau)
        k = math.tau / self.perimeter  # dv/ds
        idx = np.clip(np.searchsorted(self._cum, s, side="right") - 1, 0, len(self._segs) - 1)
        out = np.zeros((v.size, 3))
        for i, seg in enumerate(self._segs):
            m = idx == i
            if not np.any(m):
                continue
            t = s[m] - self._cum[i]
            if seg.kind == "line":
                p0, p1 = np.asarray(seg.p0), np.asarray(seg.p1)
                d = (p1 - p0) / seg.length
                if der == 0:
                    out[m, :2] = p0 + t[:, None] * d
                elif der == 1:
                    out[m, :2] = d / k
                # der 2: zero
            else:
                sgn = math.copysign(1.0, seg.sweep)
                th = seg.theta0 + sgn * t / seg.radius
                c, sn = np.cos(th), np.sin(th)
                if der == 0:
                    out[m, 0] = seg.center[0] + seg.radius * c
                    out[m, 1] = seg.center[1] + seg.radius * sn
                elif der == 1:
                    out[m, 0] = -sgn * sn / k
                    out[m, 1] = sgn * c / k
                elif der == 2:
                    out[m, 0] = -c / (seg.radius * k * k)
                    out[m, 1] = -sn / (seg.radius * k * k)
        if der == 0:
            out[:, 2] = self._z
        elif der not in (1, 2):
            raise ValueError(f"der = {der} is not allowed: must be 0, 1 or 2")
        return out

    def breakpoints(self) -> np.ndarray:
        """Parameters of the segment junctions (curvature may jump there)."""
        if len(self._segs) == 1:
            return np.zeros(0)
        return self._cum[:-1] * (math.tau / self.perimeter)

    def area(self) -> float:
        """Enclosed plan area (mm²), exact for lines and arcs (Green's theorem)."""
        return abs(signed_area(self._segs))


def Stadium(length: float, width: float, z: float = 0.0) -> Outline:
    """Stadium (capsule/oblong plan): two semicircles of diameter ``width`` joined by
    straight sides; overall ``length`` along x and ``width`` along y (mm).
    ``length == width`` gives a circle.
    """
    L = check_positive("length", length, "mm")
    W = check_positive("width", width, "mm")
    if W > L:
        raise DesignError("width", W, f"must be <= length = {format_bound(L, upper=True)} mm", "mm")
    r = W / 2.0
    h = L / 2.0 - r  # half straight length
    if h == 0.0:
        return Outline.from_segments([("arc", (0.0, 0.0), r, 0.0, math.tau)], z=z, name="stadium")
    items = [
        ("arc", (h, 0.0), r, 0.0, math.pi / 2),
        ("line", (h, r), (-h, r)),
        ("arc", (-h, 0.0), r, math.pi / 2, math.pi),
        ("line", (-h, -r), (h, -r)),
        ("arc", (h, 0.0), r, -math.pi / 2, math.pi / 2),
    ]
    return Outline.from_segments(items, z=z, name="stadium")


def RoundedRectangle(length: float, width: float, corner_radius: float, z: float = 0.0) -> Outline:
    """Rectangle ``length`` × ``width`` (mm, along x and y) with corners rounded to ``corner_radius``."""
    L = check_positive("length", length, "mm")
    W = check_positive("width", width, "mm")
    rc = check_range("corner_radius", corner_radius, 0.0, min(L, W) / 2.0, "mm", lo_open=True)
    hx, hy = L / 2.0 - rc, W / 2.0 - rc
    items = []
    if hy > 0:
        items.append(("line", (L / 2, 0.0), (L / 2, hy)))
    items.append(("arc", (hx, hy), rc, 0.0, math.pi / 2))
    if hx > 0:
        items.append(("line", (hx, W / 2), (-hx, W / 2)))
    items.append(("arc", (-hx, hy), rc, math.pi / 2, math.pi / 2))
    if hy > 0:
        items.append(("line", (-L / 2, hy), (-L / 2, -hy)))
    items.append(("arc", (-hx, -hy), rc, math.pi, math.pi / 2))
    if hx > 0:
        items.append(("line", (-hx, -W / 2), (hx, -W / 2)))
    items.append(("arc", (hx, -hy), rc, 1.5 * math.pi, math.pi / 2))
    if hy > 0:
        items.append(("line", (L / 2, -hy), (L / 2, 0.0)))
    if hx == 0 and hy == 0:
        return Outline.from_segments([("arc", (0.0, 0.0), rc, 0.0, math.tau)], z=z, name="rounded_rectangle")
    # the start point must be on +x axis: rotate list so it starts at (L/2, 0)
    if hy == 0:
        # first item is the arc from angle 0: split the last arc to start at angle 0 (already does)
        pass
    return Outline.from_segments(items, z=z, name="rounded_rectangle")


class PointCurve(Curve):
    """Closed curve through given points (mm), a periodic cubic spline in chord length.

    Parameters
    ----------
    points : array_like, shape (m, 3) or (m, 2)
        Points in order around the curve, not repeating the first one (2-D
        points lie in the plane ``z``).
    z : float
        Height (mm) for 2-D points.
    """

    def __init__(self, points, z: float = 0.0) -> None:
        p = np.asarray(points, dtype=float)
        if p.ndim != 2 or p.shape[1] not in (2, 3) or p.shape[0] < 3:
            raise DesignError("points", f"array of shape {p.shape}", "must be at least 3 points of 2 or 3 coordinates")
        if not np.all(np.isfinite(p)):
            raise DesignError("points", "non-finite value", "all coordinates must be finite numbers")
        if p.shape[1] == 2:
            p = np.column_stack([p, np.full(len(p), float(z))])
        if np.linalg.norm(p[0] - p[-1]) == 0.0:
            p = p[:-1]
        seg = np.linalg.norm(np.diff(np.vstack([p, p[:1]]), axis=0), axis=1)
        if np.any(seg == 0.0):
            raise DesignError("points", "repeated point", "consecutive points must differ")
        t = np.concatenate([[0.0], np.cumsum(seg)])
        t = t * (math.tau / t[-1])
        self.points = p
        self._knots = t[:-1]
        from scipy.interpolate import CubicSpline  # here: scipy.interpolate takes ~0.3 s to import

        self._spline = CubicSpline(t, np.vstack([p, p[:1]]), bc_type="periodic", axis=0)

    def breakpoints(self) -> np.ndarray:
        """The spline's knots (the third derivative jumps there)."""
        return self._knots.copy()

    def evaluate(self, v, der: int = 0) -> np.ndarray:
        v = np.mod(np.asarray(v, dtype=float).reshape(-1), math.tau)
        if der not in (0, 1, 2):
            raise ValueError(f"der = {der} is not allowed: must be 0, 1 or 2")
        return self._spline(v, der)


@dataclass(frozen=True)
class Transformed(Curve):
    """``matrix @ base(v) + offset``: a curve moved, rotated or scaled (mm)."""

    base: Curve
    matrix: np.ndarray = field(default_factory=lambda: np.eye(3))
    offset: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def __post_init__(self) -> None:
        m = np.asarray(self.matrix, dtype=float)
        o = np.asarray(self.offset, dtype=float)
        if m.shape != (3, 3) or o.shape != (3,) or not (np.all(np.isfinite(m)) and np.all(np.isfinite(o))):
            raise DesignError("transform", "matrix/offset", "must be a finite 3×3 matrix and 3-vector")
        object.__setattr__(self, "matrix", m)
        object.__setattr__(self, "offset", o)

    def breakpoints(self) -> np.ndarray:
        bp = getattr(self.base, "breakpoints", None)
        return bp() if bp is not None else np.zeros(0)

    def band_limit(self) -> int | None:
        bl = getattr(self.base, "band_limit", None)  # an affine map keeps a trigonometric sum's modes
        return bl() if bl is not None else None

    @property
    def flat(self) -> bool:
        """A flat curve stays flat when its new z takes nothing from its x and y (a move, a turn about z, a scale)."""
        return getattr(self.base, "flat", False) is True and bool(self.matrix[2, 0] == 0.0 and self.matrix[2, 1] == 0.0)

    def evaluate(self, v, der: int = 0) -> np.ndarray:
        p = self.base.evaluate(v, der) @ self.matrix.T
        return p + self.offset if der == 0 else p

    @property
    def is_point(self) -> bool:
        return bool(self.base.is_point) or not np.any(self.matrix[:, :2])


_MEMO: dict[int, tuple[weakref.ref, dict]] = {}


def _memo(curve: CurveLike) -> dict | None:
    """Results cached for one of tabletcad's own curves (immutable), or None for other objects.

    A patch chain shares curves between neighbouring patches and checks each
    datum more than once; the cache lives as long as the curve.
    """
    if not isinstance(curve, Curve):
        return None
    key = id(curve)
    hit = _MEMO.get(key)
    if hit is not None and hit[0]() is curve:
        return hit[1]
    try:
        ref = weakref.ref(curve, lambda r, key=key: _MEMO.pop(key, None) if _MEMO.get(key, (None,))[0] is r else None)
    except TypeError:
        return None
    table: dict = {}
    _MEMO[key] = (ref, table)
    return table


def fourier_coefficients(curve: CurveLike, modes: int, samples: int | None = None):
    """Real Fourier coefficients of a curve by FFT.

    ``c(v) ≈ a0 + Σ_{n=1}^{N} (a_n cos nv + b_n sin nv)``.

    Parameters
    ----------
    curve : curve
    modes : int
        ``N``, number of modes returned.
    samples : int, optional
        Number of equally spaced samples (default :func:`fourier_samples`: at least
        ``DEFAULT.samples`` and ``8 N + 8``, a multiple of 240).

    Returns
    -------
    a0 : ndarray (3,)
    a, b : ndarray (N, 3)
        Cosine and sine coefficients (mm).
    """
    m = samples or fourier_samples(modes)
    memo = _memo(curve)
    if memo is not None:
        key = ("fourier", modes, m)
        if key not in memo:
            memo[key] = _fourier(curve, modes, m)
        return tuple(x.copy() for x in memo[key])
    return _fourier(curve, modes, m)


def _fourier(curve: CurveLike, modes: int, m: int):
    return _fourier_and_tail(curve, modes, m)[:3]


def _fourier_and_tail(curve: CurveLike, modes: int, m: int):
    """``(a0, a, b, tail)``: the coefficients of :func:`fourier_coefficients` and ``tail``, the
    root mean square (mm) over the ``m`` samples of the curve minus its series truncated after
    ``modes`` modes (by discrete Parseval, from the coefficients above ``modes``)."""
    pts = curve.evaluate(sample_v(m))
    f = np.fft.rfft(pts, axis=0) / m
    a0 = f[0].real
    n = min(modes, m // 2 - 1)
    a = np.zeros((modes, 3))
    b = np.zeros((modes, 3))
    a[:n] = 2.0 * f[1 : n + 1].real
    b[:n] = -2.0 * f[1 : n + 1].imag
    power = np.sum(np.abs(f) ** 2, axis=1)  # |f_k|² summed over x, y, z
    top = m // 2 if m % 2 == 0 else m // 2 + 1  # the Nyquist term (even m) counts once
    tail = 2.0 * float(np.sum(power[n + 1 : top])) + (float(power[m // 2]) if m % 2 == 0 and n < m // 2 else 0.0)
    return a0, a, b, math.sqrt(tail)


def fourier_tail(curve: CurveLike, modes: int, samples: int) -> float:
    """Root mean square (mm), over ``samples`` equally spaced samples, of the curve's distance from
    its Fourier series truncated after ``modes`` modes: a lower bound of the largest distance at
    those samples (shares the samples of :func:`fourier_coefficients`)."""
    memo = _memo(curve)
    if memo is None:
        return _fourier_and_tail(curve, modes, samples)[3]
    key = ("fourier_tail", modes, samples)
    if key not in memo:
        a0, a, b, tail = _fourier_and_tail(curve, modes, samples)
        memo.setdefault(("fourier", modes, samples), (a0, a, b))
        memo[key] = tail
    return memo[key]


@lru_cache(maxsize=8)
def _trig_table(m: int, modes: int) -> tuple[np.ndarray, np.ndarray]:
    """``cos(n v_j)``, ``sin(n v_j)`` for ``v_j = 2πj/m`` and ``n = 1..modes``, shape (m, modes), read-only."""
    nv = np.outer(sample_v(m), np.arange(1, modes + 1))
    c, s = np.cos(nv), np.sin(nv)
    c.setflags(write=False)
    s.setflags(write=False)
    return c, s


def modes_needed(curve: CurveLike, tol: float | None = None, max_modes: int = 256, samples: int | None = None) -> int:
    """Fewest modes ``N`` whose truncated series is within ``tol`` (mm) of the curve.

    The error is measured at ``samples`` points (default 4096), not only at
    the FFT nodes.  Returns ``max_modes + 1`` when even ``max_modes`` is not
    enough (the remainder term then carries the rest).
    """
    tol = DEFAULT.fourier if tol is None else tol
    m = samples or 4096
    memo = _memo(curve)
    if memo is None:
        return _modes_needed(curve, tol, max_modes, m)
    key = ("modes_needed", float(tol), int(max_modes), m)
    if key not in memo:
        memo[key] = _modes_needed(curve, tol, max_modes, m)
    return memo[key]


def _truncation_errors(pts, approx, a, b, cos, sin, k0: int, k1: int) -> np.ndarray:
    """Largest distance of ``pts`` from ``approx`` plus modes ``k0+1 .. N``, for each ``N`` in ``k0+1 .. k1``."""
    terms = cos[:, k0:k1, None] * a[None, k0:k1] + sin[:, k0:k1, None] * b[None, k0:k1]  # (m, block, 3)
    run = np.broadcast_to(approx, pts.shape)[:, None, :] + np.cumsum(terms, axis=1)
    return np.max(np.linalg.norm(pts[:, None, :] - run, axis=2), axis=0)


def basis_memo(basis) -> dict:
    """The results kept on a shared curve basis (:func:`combination_of`): they live as long as it
    does (the outline that owns it)."""
    memo = basis.__dict__.get("_pde_memo")
    if memo is None:
        memo = {}
        basis.__dict__["_pde_memo"] = memo
    return memo


def basis_spectrum(basis, modes: int, m: int) -> tuple[np.ndarray, ...]:
    """``(a0, a, b, gram)`` of the ``k`` curves of ``basis`` from ``m`` samples: the coefficients of
    :func:`fourier_coefficients` ``(k, 3)``, ``(k, modes, 3)``, ``(k, modes, 3)`` mm, and the ``(k, k)``
    matrix whose form ``w·gram·w`` is the square of :func:`fourier_tail` of the combination
    ``w · basis + const`` (discrete Parseval: the tail's coefficients are linear in the curve, the
    constant moves ``a0`` alone).  Read-only, once per basis, modes and samples."""
    memo = basis_memo(basis)
    key = ("spectrum", modes, m)
    hit = memo.get(key)
    if hit is None:
        pts = np.asarray(basis.evaluate(sample_v(m), 0), dtype=float)  # (k, m, 3)
        f = np.fft.rfft(pts, axis=1) / m
        n = min(modes, m // 2 - 1)
        k = pts.shape[0]
        a, b = np.zeros((k, modes, 3)), np.zeros((k, modes, 3))
        a[:, :n] = 2.0 * f[:, 1 : n + 1].real
        b[:, :n] = -2.0 * f[:, 1 : n + 1].imag
        top = m // 2 if m % 2 == 0 else m // 2 + 1  # as in _fourier_and_tail: the Nyquist term counts once
        t = f[:, n + 1 : top].reshape(k, -1)
        gram = 2.0 * (t.conj() @ t.T).real
        if m % 2 == 0 and n < m // 2:
            ny = f[:, m // 2].real  # (the Nyquist term of real samples is real)
            gram += ny @ ny.T
        hit = (np.ascontiguousarray(f[:, 0].real), a, b, gram)
        for x in hit:
            x.setflags(write=False)
        memo[key] = hit
    return hit


def _basis_subset_residuals(basis, max_modes: int, m: int, n_fft: int) -> np.ndarray:
    """``(k, max_modes + 1, 3, s)``: each curve of ``basis`` less its Fourier series (``n_fft``
    samples' coefficients) truncated after ``N = 0 .. max_modes`` modes, at :func:`_subset_errors`'s
    ``s`` samples, mm (read-only, once per basis): a combination's are the same combination of these."""
    memo = basis_memo(basis)
    key = ("subset_residuals", max_modes, m, n_fft)
    hit = memo.get(key)
    if hit is None:
        a0, a, b, _ = basis_spectrum(basis, max_modes, n_fft)
        pts = np.asarray(basis.evaluate(sample_v(m)[:: max(1, m // 256)], 0), dtype=float)  # (k, s, 3)
        hit = np.stack([_partial_sums(p, c0, ca, cb, max_modes, m) for p, c0, ca, cb in zip(pts, a0, a, b)])
        hit.setflags(write=False)
        memo[key] = hit
    return hit


def _modes_needed(curve: CurveLike, tol: float, max_modes: int, m: int) -> int:
    limit = curve.band_limit() if isinstance(curve, Curve) else None
    if limit is not None and limit <= 1 and limit <= max_modes:
        # c(v) = a0 + a cos v + b sin v exactly (eight samples give a0, a, b): N = 0 when its
        # largest distance from a0, max |a cos v + b sin v| (the larger singular value of [a b]),
        # is within tol, else the whole curve
        f = np.fft.rfft(curve.evaluate(sample_v(8)), axis=0) / 8.0
        a, b = 2.0 * f[1].real, -2.0 * f[1].imag
        aa, bb, ab = float(a @ a), float(b @ b), float(a @ b)
        amplitude = math.sqrt(max(0.5 * (aa + bb) + math.hypot(0.5 * (aa - bb), ab), 0.0))
        return 0 if amplitude <= tol else limit
    n_fft = max(4 * max_modes + 8, 1024)
    comb = combination_of([curve]) if isinstance(curve, Curve) else None
    if comb is not None:  # w · basis + const: the basis's spectrum and residuals, shared by its curves
        basis, W, const = comb
        w = W[0]
        if not w.any():  # the constant point: its series is itself (the samples' errors are all 0)
            return 0
        a0B, aB, bB, gram = basis_spectrum(basis, max_modes, n_fft)
        tail = math.sqrt(max(float(w @ gram @ w), 0.0))
    else:
        tail = fourier_tail(curve, max_modes, n_fft) if m % n_fft == 0 else 0.0
    if m % n_fft == 0 and tail > tol * (1.0 + 1e-6) + 1e-15:
        # even max_modes leaves a root-mean-square error above tol at the FFT's samples, which are
        # among the m checked below: every N <= max_modes would fail there (the answer below, sooner)
        return max_modes + 1
    # The error at a subset of the samples is a lower bound of the error at all of them:
    # every N failing on the subset fails, so the full scan starts at the subset's first pass.
    memo = _memo(curve)
    key = ("subset_errors", int(max_modes), m)
    errs = memo.get(key) if memo is not None else None
    if comb is not None:
        a0 = w @ a0B + const[0]
        a, b = np.tensordot(w, aB, axes=1), np.tensordot(w, bB, axes=1)
        if errs is None:
            errs = _errors_of(np.tensordot(w, _basis_subset_residuals(basis, max_modes, m, n_fft), axes=1))
    else:
        a0, a, b = fourier_coefficients(curve, max_modes, samples=n_fft)
        if errs is None:
            errs = _subset_errors(curve, a0, a, b, max_modes, m)
    if memo is not None:
        memo[key] = errs
    passing = np.flatnonzero(errs <= tol)
    if not passing.size:
        return max_modes + 1
    pts = curve.evaluate(sample_v(m))
    first = int(passing[0])
    if first == 0:
        if np.max(np.linalg.norm(pts - a0, axis=1)) <= tol:
            return 0
        if passing.size == 1:
            return max_modes + 1
        first = int(passing[1])
    cos, sin = _trig_table(m, max_modes)
    start = first - 1  # modes 1..start fail; the full scan resumes after mode `start`
    approx = a0 + cos[:, :start] @ a[:start] + sin[:, :start] @ b[:start]
    k0 = start
    while k0 < max_modes:  # the subset's answer usually holds: try it alone, then blocks of 16
        k1 = min(k0 + (1 if k0 == start else 16), max_modes)
        err = _truncation_errors(pts, approx, a, b, cos, sin, k0, k1)
        hit = np.flatnonzero(err <= tol)
        if hit.size:
            return k0 + int(hit[0]) + 1
        approx = approx + cos[:, k0:k1] @ a[k0:k1] + sin[:, k0:k1] @ b[k0:k1]
        k0 = k1
    return max_modes + 1


def _subset_errors(curve: CurveLike, a0, a, b, max_modes: int, m: int) -> np.ndarray:
    """Largest distance (mm), over every ``(m // 256)``-th of ``m`` equally spaced samples, of the
    curve from its Fourier series truncated after ``N`` modes, for ``N = 0 .. max_modes``
    (one array, read-only: :func:`modes_needed` asks it once per curve for every tolerance)."""
    pts = curve.evaluate(sample_v(m)[:: max(1, m // 256)])
    return _errors_of(_partial_sums(pts, a0, a, b, max_modes, m))


@lru_cache(maxsize=8)
def _trig_subset(m: int, modes: int) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_trig_table`'s rows at every ``(m // 256)``-th sample, transposed and contiguous: ``(modes, s)``
    each, read-only (:func:`_partial_sums` multiplies along the samples; the table's strided columns had
    cost it half its time)."""
    step = max(1, m // 256)
    cos, sin = _trig_table(m, modes)
    c, s = np.ascontiguousarray(cos[::step].T), np.ascontiguousarray(sin[::step].T)
    c.setflags(write=False)
    s.setflags(write=False)
    return c, s


def _partial_sums(pts: np.ndarray, a0, a, b, max_modes: int, m: int) -> np.ndarray:
    """``(max_modes + 1, 3, s)``: the Fourier series ``a0, a, b`` truncated after ``N = 0 .. max_modes``
    modes less the curve's points ``pts`` (s, 3), at every ``(m // 256)``-th of ``m`` samples (mm)."""
    cos, sin = _trig_subset(m, max_modes)
    # laid out (N, coordinate, sample): the running sum over the modes adds whole contiguous rows
    run = np.empty((max_modes + 1, 3, pts.shape[0]))
    run[0] = np.asarray(a0, dtype=float)[:, None]
    run[1:] = a[:, :, None] * cos[:, None, :] + b[:, :, None] * sin[:, None, :]
    for n in range(1, max_modes + 1):  # the partial sums a0 + modes 1..N, row by row (numpy's cumsum
        np.add(run[n], run[n - 1], out=run[n])  # along this axis runs element by element: 6x slower)
    run -= pts.T[None]
    return run


def _errors_of(run: np.ndarray) -> np.ndarray:
    """Largest length over the samples of each ``N``'s residuals ``run`` (N, 3, s): (N,) mm, read-only."""
    errs = np.sqrt((run[:, 0] * run[:, 0] + run[:, 1] * run[:, 1] + run[:, 2] * run[:, 2]).max(axis=1))
    errs.setflags(write=False)
    return errs


#: Points per chunk of :func:`nearest_of` (its bounds are an (elements, points) array: a few MB).
_NEAREST_CHUNK = 65536

#: Up to this many points :func:`nearest_of` measures every element at every point: screening them
#: by their bounding circles costs more than it saves (0.49 against 0.21 ms on 972 points near a
#: rounded triangle's six segments; 1.8 to 2.8x on 256 to 1000 points and 4 to 128 segments).
_MEASURE_ALL = 1024


def nearest_of(elements, q: np.ndarray, measure):
    """``(best, which, extra)``: the least ``measure(e, q)`` over ``elements`` (segments with a
    ``bounding_circle``) at each point of ``q`` (m, 2), the index of the element giving it (the
    first of equals, as a plain scan in order would pick) and that element's ``extra``.

    Each element is measured only where its bounding circle's lower bound ``|q - c| - r`` is not
    above the best so far, starting at each point from the element of least bound (nearly
    always the nearest), so a point usually meets one element or two, not all of them; up to
    :data:`_MEASURE_ALL` points every element is measured everywhere (cheaper there: the same
    values, elements and extras).
    ``measure(e, points)`` returns distances (mm) to ``e``, or ``(distances, extra)`` with a
    per-point ``extra`` such as a side (then ``extra`` is returned, else None).
    """
    q = np.asarray(q, dtype=float).reshape(-1, 2)
    if len(q) <= _NEAREST_CHUNK:
        return _nearest_of(list(elements), q, measure)
    parts = [_nearest_of(list(elements), q[i : i + _NEAREST_CHUNK], measure) for i in range(0, len(q), _NEAREST_CHUNK)]
    extra = None if parts[0][2] is None else np.concatenate([x for _, _, x in parts])
    return np.concatenate([b for b, _, _ in parts]), np.concatenate([w for _, w, _ in parts]), extra


def _nearest_of(elements: list, q: np.ndarray, measure):
    m, n = len(q), len(elements)
    if n == 0:
        return np.full(m, np.inf), np.full(m, -1, dtype=np.intp), None
    if m <= _MEASURE_ALL:
        return _nearest_of_all(elements, q, measure)
    qx, qy = np.ascontiguousarray(q[:, 0]), np.ascontiguousarray(q[:, 1])
    # rows of q by take: fancy indexing steps an iterator per row (some 30x slower on numpy 2 for 20,000
    # rows of two, 5x on 1.24); q made contiguous once (take copies a strided array whole at every call)
    q = np.ascontiguousarray(q)
    lb = np.empty((n, m))
    t = np.empty(m)
    least = np.full(m, np.inf)  # the least bound so far, and its element (running: an argmin over
    first = np.zeros(m, dtype=np.intp)  # the first axis would copy the bounds transposed)
    mask = np.empty(m, dtype=bool)
    for j, e in enumerate(elements):
        cx, cy, r = e.bounding_circle()
        row = lb[j]
        np.subtract(qx, cx, out=row)
        np.multiply(row, row, out=row)
        np.subtract(qy, cy, out=t)
        np.multiply(t, t, out=t)
        row += t
        np.sqrt(row, out=row)
        row -= r * (1.0 + 1e-9) + 1e-12 * r  # (slack for rounding)
        np.less(row, least, out=mask)
        np.copyto(least, row, where=mask)
        np.copyto(first, j, where=mask)
    best = np.empty(m)
    which = first.copy()
    extra = None
    for j, e in enumerate(elements):
        idx = np.flatnonzero(first == j)
        if idx.size:
            res = measure(e, np.take(q, idx, axis=0))
            if isinstance(res, tuple):
                if extra is None:
                    extra = np.empty(m)
                best[idx], extra[idx] = res
            else:
                best[idx] = res
    for j, e in enumerate(elements):
        idx = np.flatnonzero(lb[j] <= best)
        idx = idx[first[idx] != j]
        if not idx.size:
            continue
        res = measure(e, np.take(q, idx, axis=0))
        d, x = res if isinstance(res, tuple) else (res, None)
        # the first element of equal distance wins, as in a plain scan in chain order
        win = (d < best[idx]) | ((d == best[idx]) & (j < which[idx]))
        k = idx[win]
        best[k], which[k] = d[win], j
        if x is not None:
            extra[k] = x[win]
    return best, which, extra


def _nearest_of_all(elements: list, q: np.ndarray, measure):
    """:func:`nearest_of` by measuring every element at every point: a plain scan in element order
    (``argmin`` takes the first of equals; a NaN distance never wins, but where every one is NaN)."""
    res = [measure(e, q) for e in elements]
    pairs = isinstance(res[0], tuple)
    D = np.stack([np.asarray(r[0] if pairs else r, dtype=float) for r in res])
    which = np.argmin(np.where(np.isnan(D), np.inf, D), axis=0)
    cols = np.arange(len(q))
    extra = np.stack([np.asarray(r[1], dtype=float) for r in res])[which, cols] if pairs else None
    return D[which, cols], which, extra
