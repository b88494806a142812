"""Face profiles of tablet tooling in the ``(d, z)`` plane (mm).

``d`` is the inward distance from the band edge, ``z`` the height above the
band's top edge.  Every function checks its input and raises
:class:`~tabletcad.errors.DesignError` naming the parameter, its value and the
allowed range.  Conventions (as drawn on TSM / EU-ISO 18084 tooling drawings):

* *land*: flat annulus at band height between the band edge and the cup;
* *cup depth*: height of the face above the band's top edge (the land plane);
* *single-radius cup*: one arc, horizontal at the centre, from the land's
  inner edge: radius ``ρ = (w² + h²) / (2 h)`` for cup half-width ``w`` and
  depth ``h`` (at most a hemisphere, ``h <= w``);
* *compound cup*: a central (major) radius tangent to an edge (minor) radius;
* *bevel*: a cone (or, swept, a plane) at ``bevel_angle`` to the face plane.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from tabletcad.errors import DesignError, check_finite, check_range, format_bound
from tabletcad.geometry.curves import Seg
from tabletcad.families.profile import profile_arc, profile_line
from tabletcad.tolerance import DEFAULT

__all__ = [
    "single_radius_cup",
    "compound_cup_profile",
    "land_line",
    "bevel_line",
    "cup_radius",
    "CompoundCup",
]


def cup_radius(half_width: float, depth: float) -> float:
    """Radius (mm) of a single-radius cup of ``half_width`` and ``depth`` (mm)."""
    return (half_width**2 + depth**2) / (2.0 * depth)


def land_line(land: float) -> list:
    """The land as a profile element (empty when ``land == 0``)."""
    return [profile_line((0.0, 0.0), (land, 0.0), "land")] if land > 0 else []


def bevel_line(angle_deg: float, width: float, d0: float = 0.0) -> Seg:
    """Bevel from ``(d0, 0)`` rising at ``angle_deg`` over ``width`` (mm)."""
    return profile_line((d0, 0.0), (d0 + width, width * math.tan(math.radians(angle_deg))), "bevel")


def single_radius_cup(d0: float, d1: float, depth: float, z0: float = 0.0, *, depth_name: str = "cup_depth") -> Seg:
    """Arc from ``(d0, z0)`` to ``(d1, z0 + depth)``, horizontal at ``d1``.

    Raises
    ------
    DesignError
        ``depth`` outside ``(0, d1 - d0]`` (deeper than a hemisphere).
    """
    w = d1 - d0
    h = check_finite(depth_name, depth, "mm")
    if not 0.0 < h <= w * (1 + 1e-12):
        raise DesignError(depth_name, h, f"must be > 0 and <= {format_bound(w, upper=True)} mm (a hemisphere over the {2 * w:.6g} mm wide cup)", "mm")
    h = min(h, w)
    rho = cup_radius(w, h)
    c = (d1, z0 + h - rho)
    phi0 = math.atan2(z0 - c[1], d0 - c[0])
    return profile_arc(c, rho, phi0, math.pi / 2, "cup")


class CompoundCup:
    """A compound cup: central radius ``Rc`` tangent to edge radius ``Re`` (mm).

    Work in ``(r, z)`` with ``r`` measured from the cup's centre line and
    ``z`` from the cup's edge: the edge arc passes through ``(w, 0)`` (``w``
    the cup half-width), the central arc is centred on the axis at
    ``(0, h - Rc)``, the arcs are internally tangent (centre distance
    ``Rc - Re``).  Given the depth ``h`` the edge arc's centre is an
    intersection of two circles; given the blend diameter ``2 r_b`` instead,
    the depth follows directly.

    Attributes
    ----------
    depth, blend_radius : float
        Cup depth and radius of the tangent (blend) circle (mm).
    edge_center, central_center : (float, float)
        Arc centres in ``(r, z)``.
    """

    def __init__(self, half_width: float, central_radius: float, edge_radius: float,
                 depth: float = 0.0, blend_diameter: float = 0.0, *, min_length: float = DEFAULT.min_length) -> None:
        w = half_width
        m = min_length
        Rc = check_range("central_radius", central_radius, 0.0, None, "mm", lo_open=True)
        Re = check_range("edge_radius", edge_radius, 0.0, None, "mm", lo_open=True)
        if Re >= Rc:
            raise DesignError("edge_radius", Re, f"must be < central_radius = {format_bound(Rc, upper=True)} mm (the radii must be internally tangent)", "mm")
        if Rc < w:
            # a central radius smaller than the half width cannot reach the edge as the upper arc
            pass
        if blend_diameter and depth:
            raise DesignError("blend_diameter", blend_diameter, "give cup_depth or blend_diameter, not both (set one to 0)", "mm")
        if blend_diameter:
            bd = check_finite("blend_diameter", blend_diameter, "mm")
            g = _blend_geometry(w, Rc, Re, bd / 2.0) if bd > 0.0 else None
            if g is None or min(_arc_lengths(w, *g[:3], Rc, Re)) < m:
                lo, hi = _blend_range(w, Rc, Re, m)
                if lo != lo:
                    raise DesignError("edge_radius", Re, f"leaves no blend diameter at which it reaches the edge of a {2 * w:g} mm cup from central_radius = {Rc:g} mm with both arcs at least {m:g} mm long (Tolerances.min_length)", "mm")
                raise DesignError("blend_diameter", bd, f"must be between {format_bound(2 * lo, upper=False)} and {format_bound(2 * hi, upper=True)} mm for a {2 * w:g} mm cup with radii {Rc:g} and {Re:g} mm (otherwise the edge radius cannot reach the cup edge from the blend, or the cup's edge or central arc is shorter than {m:g} mm, Tolerances.min_length)", "mm")
            C1, Ce, B, h = g
        else:
            h = check_finite("cup_depth", depth, "mm")
            if not 0.0 < h:
                raise DesignError("cup_depth", h, "must be > 0", "mm")
            if not _buildable(w, Rc, Re, h, m):
                lo, hi = _depth_range(w, Rc, Re, m)
                if lo != lo:
                    if not math.isnan(_depth_range(w, Rc, Re, 0.0)[0]):
                        raise DesignError("edge_radius", Re, f"leaves no depth at which both arcs of a {2 * w:g} mm cup with central_radius = {Rc:g} mm are at least {m:g} mm long (Tolerances.min_length)", "mm")
                    raise DesignError("edge_radius", Re, f"cannot be tangent to central_radius = {Rc:g} mm inside a {2 * w:g} mm cup for any depth", "mm")
                raise DesignError("cup_depth", h, f"must be between {format_bound(lo, upper=False)} and {format_bound(hi, upper=True)} mm for a {2 * w:g} mm cup with radii {Rc:g} and {Re:g} mm (otherwise the radii cannot be tangent inside the cup, or the cup's edge or central arc is shorter than {m:g} mm, Tolerances.min_length)", "mm")
            C1 = np.array([0.0, h - Rc])
            E = np.array([w, 0.0])
            Ce = _circle_intersection(C1, Rc - Re, E, Re, prefer_upper=True)
            B = C1 + Rc * (Ce - C1) / (Rc - Re)
        self.depth = float(h)
        self.half_width = w
        self.central_radius = Rc
        self.edge_radius = Re
        self.central_center = (float(C1[0]), float(C1[1]))
        self.edge_center = (float(Ce[0]), float(Ce[1]))
        self.blend_radius = float(B[0])
        self._B = B
        # (both ways in, the cup was checked whole: radii tangent inside it, blend inside the cup and
        # below its top, edge arc rising from the edge with no undercut, both arcs long enough)

    def elements(self, d0: float, z0: float = 0.0) -> list:
        """Edge arc then central arc in the ``(d, z)`` plane, the cup edge at ``(d0, z0)``
        (``d = d0 + w - r``)."""
        w = self.half_width
        ax = d0 + w  # d of the centre line
        Ce = (ax - self.edge_center[0], z0 + self.edge_center[1])
        C1 = (ax - self.central_center[0], z0 + self.central_center[1])
        B = (ax - self._B[0], z0 + self._B[1])
        phi_e0 = math.atan2(z0 - Ce[1], d0 - Ce[0])
        phi_b = math.atan2(B[1] - Ce[1], B[0] - Ce[0])
        phi_c0 = math.atan2(B[1] - C1[1], B[0] - C1[0])
        # the edge arc turns by less than a half turn: its centre may stand up to 1e-12 w above the cup
        # edge (an overhang that small is taken), where atan2 puts the edge at -pi, not pi, and the arc
        # had gone the long way round (a 282 degree arc at the deepest cup the radii allow)
        phi_b = phi_e0 + _wrap(phi_b - phi_e0)
        return [
            profile_arc(Ce, self.edge_radius, phi_e0, phi_b, "cup edge radius"),
            profile_arc(C1, self.central_radius, phi_c0, math.pi / 2, "cup central radius"),
        ]


def _circle_intersection(c1, r1, c2, r2, prefer_upper: bool):
    d = float(np.linalg.norm(c2 - c1))
    if d == 0 or d > r1 + r2 or d < abs(r1 - r2):
        return None
    a = (r1 * r1 - r2 * r2 + d * d) / (2 * d)
    h = math.sqrt(max(r1 * r1 - a * a, 0.0))
    e = (c2 - c1) / d
    p = c1 + a * e
    perp = np.array([-e[1], e[0]])
    s1, s2 = p + h * perp, p - h * perp
    # the edge-arc centre lies inward of the cup edge (smaller r) and below it
    cands = [s for s in (s1, s2) if s[0] < c2[0]]
    if not cands:
        return None
    return max(cands, key=lambda s: s[1]) if prefer_upper else min(cands, key=lambda s: s[1])


def _wrap(angle: float) -> float:
    """``angle`` (rad) taken into ``(-pi, pi]``."""
    return angle - 2.0 * math.pi * math.ceil((angle - math.pi) / (2.0 * math.pi))


def _geometry(w: float, Rc: float, Re: float, h: float):
    """``(C1, Ce, B)``, the central and edge arcs' centres and the blend point in ``(r, z)``, of a cup of
    depth ``h`` whose radii are tangent inside it, else None."""
    C1 = np.array([0.0, h - Rc])
    E = np.array([w, 0.0])
    Ce = _circle_intersection(C1, Rc - Re, E, Re, prefer_upper=True)
    if Ce is None:
        return None
    B = C1 + Rc * (Ce - C1) / (Rc - Re)
    if not (0.0 < B[0] < w and Ce[1] <= 1e-12 * w and 0.0 <= B[1] <= h):
        return None
    return C1, Ce, B


def _arc_lengths(w: float, C1, Ce, B, Rc: float, Re: float) -> tuple[float, float]:
    """Lengths (mm) of the edge arc, from the cup edge ``(w, 0)`` to the blend ``B``, and of the
    central arc, from ``B`` to the centre line (as :meth:`CompoundCup.elements` draws them)."""
    edge = Re * abs(_wrap(math.atan2(B[1] - Ce[1], B[0] - Ce[0]) - math.atan2(-Ce[1], w - Ce[0])))
    central = Rc * math.atan2(B[0], B[1] - C1[1])
    return edge, central


def _blend_geometry(w: float, Rc: float, Re: float, rb: float):
    """``(C1, Ce, B, h)`` of the cup whose radii meet at the blend radius ``rb`` (the cup edge at
    ``(w, 0)``), else None: the edge radius cannot reach the cup edge, or the blend lies outside the cup."""
    if not 0.0 < rb < min(w, Rc):
        return None
    C1 = np.array([0.0, -Rc])
    B = np.array([rb, -Rc + math.sqrt(Rc * Rc - rb * rb)])
    Ce = C1 + (Rc - Re) / Rc * (B - C1)
    if abs(w - Ce[0]) > Re:
        return None
    h = -(Ce[1] + math.sqrt(Re * Re - (w - Ce[0]) ** 2))
    shift = np.array([0.0, h])
    C1, Ce, B = C1 + shift, Ce + shift, B + shift
    if not (0.0 < B[0] < w and Ce[1] <= 1e-12 * w and 0.0 <= B[1] <= h):
        return None
    return C1, Ce, B, float(h)


def _blend_range(w: float, Rc: float, Re: float, min_length: float = DEFAULT.min_length) -> tuple[float, float]:
    """Blend radii (mm) at which a compound cup of half-width ``w`` with radii ``Rc > Re`` exists and
    leaves both arcs at least ``min_length`` long: its edge arc shrinks as the blend moves out, its
    central arc grows, so they are one interval (scanned, then bisected at both ends).  Remembered for
    the 256 latest radii, as :func:`_depth_range` is."""
    return _blend_range_of(float(w), float(Rc), float(Re), float(min_length))


@functools.lru_cache(maxsize=256)
def _blend_range_of(w: float, Rc: float, Re: float, min_length: float) -> tuple[float, float]:
    """:func:`_blend_range` of Python floats (its memo)."""
    def ok(rb: float) -> bool:
        g = _blend_geometry(w, Rc, Re, rb)
        return g is not None and min(_arc_lengths(w, *g[:3], Rc, Re)) >= min_length

    top = min(w, Rc)
    return _interval(ok, np.linspace(0.0, top, 2002)[1:-1], 0.0, top)


def _interval(ok, xs: np.ndarray, first: float, last: float) -> tuple[float, float]:
    """The ends of the one interval where ``ok`` holds, scanned on ``xs`` (increasing, within ``first``
    and ``last``, the ends used when the interval reaches past the scan) and bisected at both ends to
    rounding (60 halvings); NaNs when no sample holds."""
    good = np.array([ok(float(x)) for x in xs])
    if not good.any():
        return (math.nan, math.nan)
    i0, i1 = int(np.argmax(good)), len(good) - 1 - int(np.argmax(good[::-1]))

    def bisect(g: float, b: float) -> float:
        for _ in range(60):
            mid = 0.5 * (g + b)
            if ok(mid):
                g = mid
            else:
                b = mid
        return g

    lo = bisect(xs[i0], xs[i0 - 1] if i0 > 0 else first)
    hi = bisect(xs[i1], xs[i1 + 1] if i1 < len(xs) - 1 else last)
    return (float(lo), float(hi))


def _buildable(w: float, Rc: float, Re: float, h: float, min_length: float) -> bool:
    """Whether the radii are tangent inside a cup of depth ``h`` and leave both arcs at least
    ``min_length`` long (or, as :func:`_check_left_lengths` takes them, within 1e-9 of it)."""
    g = _geometry(w, Rc, Re, h)
    if g is None:
        return False
    return min(_arc_lengths(w, *g, Rc, Re)) >= min_length


def _depth_range(w: float, Rc: float, Re: float, min_length: float = DEFAULT.min_length) -> tuple[float, float]:
    """Depths (mm) for which a compound cup of half-width ``w`` with radii ``Rc > Re`` exists and
    leaves its edge and central arcs at least ``min_length`` long (0: the radii's tangency alone).
    Scanned on a fine grid, then bisected at both ends: the edge arc grows with the depth and the
    central arc shrinks, so the depths are one interval.

    Remembered for the 256 latest radii (a pure function of its numbers, ~2,100 constructions of
    the profile; a search of one family's dimension, such as ``tabletcad report --solve-for``, asks
    for it again at every depth or band it finds out of range)."""
    return _depth_range_of(float(w), float(Rc), float(Re), float(min_length))


@functools.lru_cache(maxsize=256)
def _depth_range_of(w: float, Rc: float, Re: float, min_length: float) -> tuple[float, float]:
    """:func:`_depth_range` of Python floats (its memo)."""
    hs = np.linspace(1e-6 * w, 2 * w, 2001)
    return _interval(lambda h: _buildable(w, Rc, Re, h, min_length), hs, hs[0], hs[-1])


def compound_cup_profile(d0: float, half_width: float, central_radius: float, edge_radius: float,
                         depth: float = 0.0, blend_diameter: float = 0.0, *,
                         min_length: float = DEFAULT.min_length) -> tuple[list, CompoundCup]:
    """Elements of a compound cup whose edge is at ``d0`` (and the :class:`CompoundCup`)."""
    cc = CompoundCup(half_width, central_radius, edge_radius, depth, blend_diameter, min_length=min_length)
    return cc.elements(d0), cc
