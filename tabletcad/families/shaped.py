"""Shaped tablets: a cup profile swept over any closed plan outline.

The face at inward distance ``d`` from the outline is the outline offset by
``d`` (lines to lines, arcs to concentric arcs), raised to the cup profile's
height ``z(d)``.  The cup runs from the land's inner edge to ``cup_width``
(default: as far as the outline allows, i.e. its smallest convex corner radius
or its inscribed radius, and at least ``Tolerances.min_length`` short of the
centroid), where it is horizontal; if the offsets have not closed there, a flat
plateau finishes the face.  Offsets beyond the smallest
arc radius or the inscribed radius are refused with a DesignError naming
``cup_width``.

Families: ``rounded_triangle``, ``rounded_square``, ``rounded_rectangle``,
``almond`` and, from Python, :func:`outline_tablet` for any outline given as
points or as lines and arcs.  All lengths in mm.
"""

from __future__ import annotations

import math

import numpy as np

from tabletcad.errors import DesignError, check_positive, check_range, format_bound
from tabletcad.families.cups import CompoundCup, land_line, single_radius_cup
from tabletcad.families.outline import (
    PlanOutline,
    SplineOutline,
    check_numbers,
    four_arc_oval,
    outline_from_items,
    rounded_polygon,
    rounded_rectangle_outline,
)
from tabletcad.families.profile import profile_line
from tabletcad.families.round import smoothing
from tabletcad.families.family import lengths_checked
from tabletcad.families.sweep import DEFAULT_A, build_sweep_tablet
from tabletcad.geometry.tablet import Tablet
from tabletcad.tolerance import DEFAULT, Tolerances

__all__ = ["outline_tablet", "rounded_triangle", "rounded_square", "rounded_rectangle", "almond", "as_outline"]


def as_outline(outline) -> PlanOutline:
    """A :class:`PlanOutline` from an outline, a list of line/arc items or an (m, 2) array of points."""
    if isinstance(outline, PlanOutline):
        return outline
    if isinstance(outline, (list, tuple)) and outline and isinstance(outline[0], (list, tuple)) and outline[0] and isinstance(outline[0][0], str):
        return outline_from_items(outline)
    check_numbers("outline", outline)
    try:
        pts = np.asarray(outline, dtype=float)
    except (TypeError, ValueError):
        raise DesignError("outline", type(outline).__name__, "must be points [[x, y], ...] or line/arc items") from None
    return SplineOutline(pts)


@lengths_checked(skip=("outline",))
def outline_tablet(
    outline,
    band: float = 3.0,
    cup_depth: float = 0.6,
    land: float = 0.0,
    cup_width: float = 0.0,
    central_radius: float = 0.0,
    edge_radius: float = 0.0,
    *,
    name: str = "custom_outline",
    family: str = "custom_outline",
    params: dict | None = None,
    info: dict | None = None,
    reach: float | None = None,
    a=DEFAULT_A,
    tol: Tolerances = DEFAULT,
) -> Tablet:
    """Tablet with a cup profile swept over a plan outline.

    Parameters
    ----------
    outline : PlanOutline, line/arc items or (m, 2) points
        Closed plan outline (mm); must be simple and tangent-continuous.
    band : float
        Band (wall) height, mm (> 0).
    cup_depth : float
        Height of the face above the band's top edge, mm (0: flat face).
    land : float
        Flat land width between band and cup, mm (>= 0, < cup_width).
    cup_width : float
        Inward distance at which the cup becomes horizontal, mm; 0 takes the
        largest allowed (smallest convex corner radius or inscribed radius, and
        on an outline with a concave waist the centroid's distance to its nearest
        tangent line, beyond which the flat centre would fold: :func:`_star_limit`;
        a flat centre left is at least ``tol.min_length`` from the centroid to its
        rim: :func:`_centre_limit`).
    central_radius, edge_radius : float
        Both > 0: a compound cup across the cup width (mm); both 0: single radius.
    reach : float, optional
        The outline's inscribed radius if known exactly (mm).
    """
    ol = as_outline(outline)
    b = check_positive("band", band, "mm")
    h = check_range("cup_depth", cup_depth, 0.0, None, "mm")
    if reach is None:
        reach = ol.inscribed_radius()
    limit = min(ol.min_convex_radius, reach)
    if not ol._offset_is_clean(limit):
        limit = ol.offset_limit()
    star = _star_limit(ol, limit)
    centre = _centre_limit(ol, limit, reach, tol)
    cw = check_range("cup_width", cup_width, 0.0, None, "mm")
    if cw == 0.0:
        cw = min(limit, star, centre)
    bound, why = min((limit, "the outline's smallest corner radius / inscribed radius: offsets beyond it are not "
                             "offsets of the outline"),
                     (star, "the outline's centroid's distance to its nearest tangent line: offsets beyond it are "
                            "not star-shaped about the centroid, so the flat centre, a fan from the centroid, would "
                            "fold over itself"),
                     (centre, f"cupped further in, the flat centre would reach less than {tol.min_length:g} mm "
                              "from the centroid (Tolerances.min_length), too narrow to build"),
                     key=lambda item: item[0])
    if cw > bound * (1 + 1e-9):  # the tightest of the three, so that the range stated is the true one
        raise DesignError("cup_width", cw, f"must be <= {format_bound(bound, upper=True)} mm ({why})", "mm")
    cw = min(cw, limit, star, centre)
    ol.check_offset(cw, "cup_width")
    L = check_range("land", land, 0.0, cw, "mm", hi_open=True)
    Rc = check_range("central_radius", central_radius, 0.0, None, "mm")
    Re = check_range("edge_radius", edge_radius, 0.0, None, "mm")
    extra: dict = {}
    if h == 0.0:
        face = [profile_line((0.0, 0.0), (cw, 0.0), "flat face")]
    elif Rc > 0 or Re > 0:
        if not (Rc > 0 and Re > 0):
            raise DesignError("edge_radius" if Rc > 0 else "central_radius", Re if Rc > 0 else Rc, "must be > 0 for a compound cup (give both radii, or neither)", "mm")
        cc = CompoundCup(cw - L, Rc, Re, h, min_length=tol.min_length)
        face = land_line(L) + cc.elements(L)
        extra = dict(central_radius_mm=Rc, edge_radius_mm=Re, blend_offset_mm=cw - cc.blend_radius)
    else:
        cup = single_radius_cup(L, cw, h)
        face = land_line(L) + [cup]
        extra = dict(cup_radius_mm=cup.radius)
    ext = ol.extent()
    full = dict(shape=ol.name, face="convex" if h > 0 else "flat", cup_depth_mm=h, land_mm=L, band_mm=b,
                cup_width_mm=cw, length_mm=max(ext), width_mm=min(ext), **extra)
    full.update(info or {})
    p = dict(band=b, cup_depth=h, land=L, cup_width=float(cup_width), central_radius=Rc, edge_radius=Re)
    p.update(params or {})
    return build_sweep_tablet(ol, face, b, name=name, family=family, params=p,
                              reach=cw if cw >= reach * (1 - 1e-9) else reach, info=full, a=smoothing(a), tol=tol)


def _centre_limit(ol, limit: float, reach: float, tol: Tolerances) -> float:
    """The largest cup width (mm) that leaves a flat centre at least ``tol.min_length`` from the
    centroid to the plateau's rim (the centroid's distance to the outline less that), or ``inf`` when
    the cup may reach the centre (``limit`` is the outline's ``reach``: a stadium closes on its centre
    line) or stops short of it anyway.

    A cup ending nearer the centroid leaves a plateau too narrow to build: at a rounded triangle's
    largest corner radius it is 1e-5 mm across, and its patches' rows stand still within the B-rep's
    tolerance (the default cup width had been refused, naming ``cup_width``, from a corner radius of
    3 mm on an 11 mm triangle)."""
    if limit >= reach * (1.0 - 1e-9):
        return math.inf
    cap = ol.centroid_depth() - tol.min_length
    return cap if cap < limit else math.inf


def _star_limit(ol, limit: float) -> float:
    """The largest cup width (mm) whose offsets of ``ol`` are all star-shaped about its centroid
    (:meth:`~tabletcad.families.outline.PlanOutline.star_limit`): a swept face's plateau is a fan
    from the centroid to the offset at the cup width, and its cups' solid map runs from the
    centroid too.  ``inf`` when that is no tighter than ``limit`` (the offset limit; rounding
    aside: a stadium's straight sides are ``limit`` from its centroid), and when the outline itself
    is not star-shaped (its band's fold check refuses it)."""
    star = ol.star_limit()
    return star if 0.0 < star < limit * (1.0 - 1e-9) else math.inf


@lengths_checked()
def rounded_triangle(side: float = 10.0, corner_radius: float = 1.5, band: float = 2.5, cup_depth: float = 0.5,
                     land: float = 0.0, cup_width: float = 0.0, *, a=DEFAULT_A, tol: Tolerances = DEFAULT) -> Tablet:
    """Rounded equilateral triangle (``side`` of the sharp triangle, ``corner_radius``, mm), swept cup.

    The cup is horizontal at ``cup_width`` (default: the corner radius); the centre is flat.
    """
    s = check_positive("side", side, "mm")
    r_in = s / (2.0 * math.sqrt(3.0))
    rc = check_range("corner_radius", corner_radius, 0.0, r_in, "mm", lo_open=True, hi_open=True)
    R = s / math.sqrt(3.0)
    verts = [(R * math.cos(t), R * math.sin(t)) for t in (-math.pi / 6, math.pi / 2, 7 * math.pi / 6)]
    ol = rounded_polygon(verts, rc, name="rounded_triangle")
    return outline_tablet(ol, band, cup_depth, land, cup_width, name="rounded_triangle", family="rounded_triangle",
                          params=dict(side=s, corner_radius=rc), reach=r_in, a=a, tol=tol)


@lengths_checked()
def rounded_square(side: float = 9.0, corner_radius: float = 1.5, band: float = 2.5, cup_depth: float = 0.5,
                   land: float = 0.0, cup_width: float = 0.0, *, a=DEFAULT_A, tol: Tolerances = DEFAULT) -> Tablet:
    """Rounded square of ``side`` with ``corner_radius`` (mm), cup swept over the outline."""
    s = check_positive("side", side, "mm")
    rc = check_range("corner_radius", corner_radius, 0.0, s / 2.0, "mm", lo_open=True)
    ol = rounded_rectangle_outline(s, s, rc)
    ol.name = "rounded_square"
    return outline_tablet(ol, band, cup_depth, land, cup_width, name="rounded_square", family="rounded_square",
                          params=dict(side=s, corner_radius=rc), reach=s / 2.0, a=a, tol=tol)


@lengths_checked()
def rounded_rectangle(length: float = 14.0, width: float = 8.0, corner_radius: float = 2.0, band: float = 3.0,
                      cup_depth: float = 0.6, land: float = 0.0, cup_width: float = 0.0, *, a=DEFAULT_A,
                      tol: Tolerances = DEFAULT) -> Tablet:
    """Rounded rectangle ``length`` (x) × ``width`` (y), ``corner_radius`` (mm), cup swept over it."""
    Ln = check_positive("length", length, "mm")
    W = check_positive("width", width, "mm")
    if W > Ln:
        raise DesignError("width", W, f"must be <= length = {Ln:g} mm", "mm")
    ol = rounded_rectangle_outline(Ln, W, corner_radius)
    return outline_tablet(ol, band, cup_depth, land, cup_width, name="rounded_rectangle", family="rounded_rectangle",
                          params=dict(length=Ln, width=W, corner_radius=float(corner_radius)), reach=W / 2.0, a=a, tol=tol)


@lengths_checked()
def almond(length: float = 14.0, width: float = 7.0, end_radius: float = 1.2, band: float = 3.0,
           cup_depth: float = 0.5, land: float = 0.0, cup_width: float = 0.0, *, a=DEFAULT_A,
           tol: Tolerances = DEFAULT) -> Tablet:
    """Almond: two large side arcs meeting in small rounded tips of ``end_radius`` (mm)."""
    Ln = check_positive("length", length, "mm")
    W = check_positive("width", width, "mm")
    ol = four_arc_oval(Ln, W, end_radius)
    ol.name = "almond"
    return outline_tablet(ol, band, cup_depth, land, cup_width, name="almond", family="almond",
                          params=dict(length=Ln, width=W, end_radius=float(end_radius)), reach=W / 2.0, a=a, tol=tol)
