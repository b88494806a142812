"""Round tablet families: flat face (plain, bevel edge, radius edge), concave, compound cup, concave bevel.

Every function returns a certified :class:`~tabletcad.geometry.tablet.Tablet` standing
on ``z = 0`` with its axis on z; all lengths in mm, angles in degrees.  The
nominal is the face profile revolved about the axis (cylinder band, planes,
cones, spheres, tori); see :mod:`tabletcad.families.sweep`.
"""

from __future__ import annotations

import math

from tabletcad.errors import DesignError, check_positive, check_range, format_bound
from tabletcad.families.cups import CompoundCup, bevel_line, land_line, single_radius_cup
from tabletcad.families.outline import circle_outline
from tabletcad.families.profile import profile_arc, profile_line
from tabletcad.families.family import lengths_checked
from tabletcad.families.sweep import DEFAULT_A, build_sweep_tablet
from tabletcad.geometry.tablet import Tablet
from tabletcad.tolerance import DEFAULT, Tolerances

__all__ = ["flat_face_round", "ffbe", "ffre", "concave_round", "compound_cup", "concave_bevel", "smoothing"]


def smoothing(a) -> float:
    """The smoothing parameter to use (``"auto"`` or None give the family default)."""
    if a is None or a == "auto":
        return DEFAULT_A
    return check_range("a", a, 0.0, 1.0, lo_open=True)


def _round(name: str, D: float, face: list, band: float, params: dict, info: dict, a, tol) -> Tablet:
    R = D / 2.0
    info = dict(info, shape="round", diameter_mm=D, width_mm=D, length_mm=D, band_mm=band)
    return build_sweep_tablet(circle_outline(R), face, band, name=name, family=name, params=params,
                              reach=R, info=info, a=smoothing(a), tol=tol)


@lengths_checked()
def flat_face_round(diameter: float = 10.0, thickness: float = 4.0, *, a=DEFAULT_A, tol: Tolerances = DEFAULT) -> Tablet:
    """Round flat-face plain tablet (sharp edges): a cylinder ``diameter`` × ``thickness`` (mm)."""
    D = check_positive("diameter", diameter, "mm")
    T = check_positive("thickness", thickness, "mm")
    face = [profile_line((0.0, 0.0), (D / 2.0, 0.0), "flat face")]
    return _round("flat_face_round", D, face, T, dict(diameter=D, thickness=T),
                  dict(face="flat", cup_depth_mm=0.0, land_mm=0.0), a, tol)  # a flat face: no land


def _bevel_dims(R: float, T: float, angle: float, width: float, depth: float) -> tuple[float, float]:
    ang = check_range("bevel_angle", angle, 0.0, 90.0, "deg", lo_open=True, hi_open=True)
    t = math.tan(math.radians(ang))
    w = check_range("bevel_width", width, 0.0, None, "mm")
    dep = check_range("bevel_depth", depth, 0.0, None, "mm")
    if w > 0 and dep > 0 and abs(dep - w * t) > 1e-9 * max(1.0, dep):
        raise DesignError("bevel_depth", dep, f"must equal bevel_width * tan(bevel_angle) = {w * t:.6g} mm, or give only one of them (set the other to 0)", "mm")
    if w == 0 and dep == 0:
        raise DesignError("bevel_width", w, "must be > 0 (or give bevel_depth > 0)", "mm")
    if w == 0:
        w = dep / t
    dep = w * t
    if not w < R:
        raise DesignError("bevel_width", w, f"must be < radius = {format_bound(R, upper=True)} mm", "mm")
    if not 2 * dep < T:
        raise DesignError("bevel_depth" if depth else "bevel_width", depth or width,
                          f"must leave a band: bevel depth {dep:.4g} mm must be < thickness/2 = {format_bound(T / 2, upper=True)} mm", "mm")
    return w, dep


@lengths_checked(skip=("bevel_angle",))
def ffbe(diameter: float = 10.0, thickness: float = 4.0, bevel_angle: float = 30.0, bevel_width: float = 0.5,
         bevel_depth: float = 0.0, *, a=DEFAULT_A, tol: Tolerances = DEFAULT) -> Tablet:
    """Round flat-face bevel-edge tablet (bevel angle in deg from the face, bevel width or depth in mm).

    ``bevel_width`` is radial, ``bevel_depth`` axial; give one and set the other to 0.
    """
    D = check_positive("diameter", diameter, "mm")
    T = check_positive("thickness", thickness, "mm")
    R = D / 2.0
    w, dep = _bevel_dims(R, T, bevel_angle, bevel_width, bevel_depth)
    face = [bevel_line(bevel_angle, w), profile_line((w, dep), (R, dep), "flat face")]
    return _round("ffbe", D, face, T - 2 * dep,
                  dict(diameter=D, thickness=T, bevel_angle=float(bevel_angle), bevel_width=float(bevel_width), bevel_depth=float(bevel_depth)),
                  dict(face="flat", cup_depth_mm=dep, bevel_width_mm=w, bevel_depth_mm=dep, bevel_angle_deg=float(bevel_angle), land_mm=0.0), a, tol)


@lengths_checked()
def ffre(diameter: float = 10.0, thickness: float = 4.0, edge_radius: float = 1.0, *, a=DEFAULT_A,
         tol: Tolerances = DEFAULT) -> Tablet:
    """Round flat-face radius-edge tablet: toroidal edge of ``edge_radius`` (mm), all seams G1."""
    D = check_positive("diameter", diameter, "mm")
    T = check_positive("thickness", thickness, "mm")
    R = D / 2.0
    re = check_range("edge_radius", edge_radius, 0.0, min(R, T / 2.0), "mm", lo_open=True)
    face = [profile_arc((re, 0.0), re, math.pi, math.pi / 2, "edge radius")]
    if re < R:
        face.append(profile_line((re, re), (R, re), "flat face"))
    return _round("ffre", D, face, T - 2 * re, dict(diameter=D, thickness=T, edge_radius=re),
                  dict(face="flat", cup_depth_mm=re, edge_radius_mm=re, land_mm=0.0), a, tol)


@lengths_checked()
def concave_round(diameter: float = 10.0, band: float = 3.0, cup_depth: float = 1.0, land: float = 0.0, *,
                  a=DEFAULT_A, tol: Tolerances = DEFAULT) -> Tablet:
    """Round standard-concave tablet: spherical cups of ``cup_depth`` on a band, optional ``land`` (mm).

    The land is the flat annulus between the band and the cup.
    """
    D = check_positive("diameter", diameter, "mm")
    b = check_positive("band", band, "mm")
    R = D / 2.0
    L = check_range("land", land, 0.0, R, "mm", hi_open=True)
    cup = single_radius_cup(L, R, cup_depth)
    return _round("concave_round", D, land_line(L) + [cup], b, dict(diameter=D, band=b, cup_depth=float(cup_depth), land=L),
                  dict(face="convex", cup_depth_mm=float(cup_depth), land_mm=L, cup_radius_mm=cup.radius), a, tol)


@lengths_checked()
def compound_cup(diameter: float = 10.0, band: float = 2.5, cup_depth: float = 1.2, central_radius: float = 15.0,
                 edge_radius: float = 3.0, land: float = 0.0, blend_diameter: float = 0.0, *, a=DEFAULT_A,
                 tol: Tolerances = DEFAULT) -> Tablet:
    """Round compound-cup tablet: ``central_radius`` tangent to ``edge_radius`` (mm), G1 junction.

    Give ``cup_depth`` or ``blend_diameter`` (the other 0).
    """
    D = check_positive("diameter", diameter, "mm")
    b = check_positive("band", band, "mm")
    R = D / 2.0
    L = check_range("land", land, 0.0, R, "mm", hi_open=True)
    cc = CompoundCup(R - L, central_radius, edge_radius, cup_depth, blend_diameter, min_length=tol.min_length)
    face = land_line(L) + cc.elements(L)
    return _round("compound_cup", D, face, b,
                  dict(diameter=D, band=b, cup_depth=float(cup_depth), central_radius=float(central_radius),
                       edge_radius=float(edge_radius), land=L, blend_diameter=float(blend_diameter)),
                  dict(face="convex", cup_depth_mm=cc.depth, land_mm=L, central_radius_mm=cc.central_radius,
                       edge_radius_mm=cc.edge_radius, blend_diameter_mm=2 * cc.blend_radius), a, tol)


@lengths_checked(skip=("bevel_angle",))
def concave_bevel(diameter: float = 10.0, band: float = 2.5, cup_depth: float = 0.8, bevel_angle: float = 30.0,
                  bevel_width: float = 0.6, *, a=DEFAULT_A, tol: Tolerances = DEFAULT) -> Tablet:
    """Round concave bevel-edge tablet: bevel (deg, mm) from the band, then a spherical cup whose
    ``cup_depth`` (mm) is measured from the bevel's inner edge (the design report's ``cup_depth_mm`` is
    the whole depth, bevel included, and ``cup_depth_below_bevel_mm`` this one).
    """
    D = check_positive("diameter", diameter, "mm")
    b = check_positive("band", band, "mm")
    R = D / 2.0
    ang = check_range("bevel_angle", bevel_angle, 0.0, 90.0, "deg", lo_open=True, hi_open=True)
    w = check_range("bevel_width", bevel_width, 0.0, R, "mm", lo_open=True, hi_open=True)
    bev = bevel_line(ang, w)
    dep = float(bev.p1[1])
    cup = single_radius_cup(w, R, cup_depth, z0=dep)
    return _round("concave_bevel", D, [bev, cup], b,
                  dict(diameter=D, band=b, cup_depth=float(cup_depth), bevel_angle=ang, bevel_width=w),
                  dict(face="convex", cup_depth_mm=dep + float(cup_depth), cup_depth_below_bevel_mm=float(cup_depth),
                       land_mm=0.0, bevel_width_mm=w,
                       bevel_depth_mm=dep, bevel_angle_deg=ang, cup_radius_mm=cup.radius), a, tol)
