"""Named constructors for the thesis's tablets (Tables 4.1 and 4.5), in mm.

Every tablet stands on the plane z = 0 with its axis on the z axis (the
thesis's dome curves make the spine run backwards just before a pole, so a
dome dips up to 1.6 µm below its pole: see ``PDEPatch.fold_depth``).  Round
tablets use circles, oval ones ellipses; each patch takes four curves at
``u = 0, 1/3, 2/3, 1``.  Interior curves of a dome lie on its nominal
spherical cap at equal angular steps (thesis eq 4.1); interior curves of a
band are copies of its rim at equal heights; interior curves of a flat face
are concentric at equal radial steps.  The Table 4.5 shapes are also
reachable the thesis's way, by scaling coefficients of a Table 4.1 shape
(:mod:`tabletcad.families.reshape`).
"""

from __future__ import annotations

import math
from types import MappingProxyType
from typing import Mapping

import numpy as np

from tabletcad.geometry import nominal as nom
from tabletcad.geometry.curves import Circle, Curve, Ellipse
from tabletcad.errors import DesignError, check_positive, check_range, format_bound
from tabletcad.families.family import Family, lengths_checked
from tabletcad.geometry.patch import PDEPatch
from tabletcad.geometry.tablet import TRIM_MIN_WIDTH, Tablet, Trim
from tabletcad.tolerance import DEFAULT, Tolerances

__all__ = [
    "THESIS_SHAPES",
    "NO_LAND",
    "coaxial_tablet",
    "flat_faced_round",
    "spherical",
    "shallow_convex_round",
    "shallow_convex_oval",
    "oblong",
    "ring",
    "deep_convex_round",
    "oblate_spheroid",
    "prolate_spheroid",
    "rod",
    "caplet",
    "deep_convex_oval",
]


def _plan(rx: float, ry: float, z: float) -> Curve:
    if rx == ry:
        return Circle(rx, (0.0, 0.0, z))
    return Ellipse(rx, ry, (0.0, 0.0, z))


def coaxial_tablet(
    sections: list[list[tuple[float, float]]],
    aspect: float = 1.0,
    *,
    a: float | str = 1.0,
    name: str = "tablet",
    family: str = "free_form",
    params: dict | None = None,
    nominal=None,
    trim: Trim | None = None,
    tol: Tolerances = DEFAULT,
    modes: int | None = None,
    check: bool = True,
) -> Tablet:
    """Tablet from patches of coaxial plan curves: the one coaxial builder.

    Parameters
    ----------
    sections : list of patches, each a list of four ``(radius, z)`` pairs (mm)
        Consecutive patches must share their end/start pair.  ``radius`` is the
        semi-axis along y; along x it is ``radius * aspect`` (ellipses when
        ``aspect != 1``).
    aspect : float
        Plan length / width.
    modes : int, optional
        Fourier modes per patch (default: as many as the curves need; 1 is exact for circles,
        the optimiser's fast builds, :func:`tabletcad.optimise.thesis.coaxial_fast`).
    check : bool
        Run each patch's stray and fold checks (default True).
    """
    patches = []
    prev_last: Curve | None = None
    for j, sec in enumerate(sections):
        if len(sec) != 4:
            raise DesignError(f"patch {j} curves", len(sec), "each patch needs 4 (radius, z) pairs")
        curves = []
        for k, (r, z) in enumerate(sec):
            check_range(f"patch {j} curve {k} radius", r, 0.0, None, "mm")
            if k == 0 and prev_last is not None:
                curves.append(prev_last)
            else:
                curves.append(_plan(r * aspect, r, z))
        prev_last = curves[-1]
        patches.append(PDEPatch(tuple(curves), a=a, modes=modes, tol=tol, name=f"{name}[{j}]", check=check))
    return Tablet(
        tuple(patches),
        name=name,
        family=family,
        params=dict(params or {}),
        nominal=nominal,
        trim=trim or Trim(),
        tol=tol,
    )


def _disc(r: float, z: float, inward: bool) -> list[tuple[float, float]]:
    radii = [r, 2 * r / 3, r / 3, 0.0]
    if not inward:
        radii = radii[::-1]
    return [(x, z) for x in radii]


def _band(r: float, z0: float, z1: float) -> list[tuple[float, float]]:
    return [(r, z0 + (z1 - z0) * k / 3.0) for k in range(4)]


def _cap(r: float, z_rim: float, depth: float, up: bool) -> list[tuple[float, float]]:
    """Curves on a spherical cap of rim radius ``r`` and ``depth`` at equal angles."""
    if depth == 0.0:
        return _disc(r, z_rim, inward=up) if up else _disc(r, z_rim, inward=False)
    # a spherical cap up to a hemisphere; deeper domes are the hemisphere
    # stretched along z (a half spheroid), as the thesis's coefficient scaling does
    d_s = min(depth, r)
    rc = (r * r + d_s * d_s) / (2.0 * d_s)
    half = math.asin(min(1.0, r / rc))
    stretch = depth / d_s
    out = []
    for k in range(4):
        th = half * (1.0 - k / 3.0)  # polar angle from the apex
        rad = rc * math.sin(th)
        h = stretch * rc * (1.0 - math.cos(th))  # height below the apex
        z = z_rim + depth - h if up else z_rim - depth + h
        out.append((rad, z))
    return out if up else out[::-1]


# ---------------------------------------------------------------------------- Table 4.1
@lengths_checked()
def flat_faced_round(diameter: float = 10.0, thickness: float = 6.0, *, a: float | str = 1.0, tol=DEFAULT) -> Tablet:
    """Flat-faced round tablet, 3 patches, 10 curves (Table 4.1: 10 × 6 mm)."""
    D = check_positive("diameter", diameter, "mm")
    T = check_positive("thickness", thickness, "mm")
    R = D / 2
    secs = [_disc(R, 0.0, inward=False), _band(R, 0.0, T), _disc(R, T, inward=True)]
    return coaxial_tablet(
        secs, a=a, name="flat_faced_round", family="thesis.flat_faced_round",
        params=dict(diameter=D, thickness=T), nominal=nom.cylinder(R, 0.0, T), tol=tol,
    )


@lengths_checked()
def spherical(diameter: float = 5.0, *, a: float | str = 1.0, tol=DEFAULT) -> Tablet:
    """Spherical tablet, 2 patches, 7 curves at 30° steps (eqs 4.1-4.3; Table 4.1: 5 mm)."""
    D = check_positive("diameter", diameter, "mm")
    r = D / 2
    psi = [-math.pi / 2, -math.pi / 3, -math.pi / 6, 0.0, math.pi / 6, math.pi / 3, math.pi / 2]
    pts = [(r * math.cos(p) if abs(p) != math.pi / 2 else 0.0, r + r * math.sin(p)) for p in psi]
    return coaxial_tablet(
        [pts[0:4], pts[3:7]], a=a, name="spherical", family="thesis.spherical",
        params=dict(diameter=D), nominal=nom.sphere(r, (0, 0, r)), tol=tol,
    )


def _convex(name, D, T, band, aspect=1.0, a=1.0, tol=DEFAULT, params=None):
    R = D / 2
    if not 0 < band <= T:
        raise DesignError("band", band, f"must be > 0 and <= thickness = {format_bound(T, upper=True)} mm", "mm")
    d = (T - band) / 2
    if d > R and aspect == 1.0:
        raise DesignError("band", band, f"must be >= thickness - diameter = {format_bound(T - D, upper=False)} mm (cup deeper than a hemisphere)", "mm")
    secs = [_cap(R, d, d, up=False), _band(R, d, d + band), _cap(R, d + band, d, up=True)]
    nominal = nom.convex_round(R, d, d + band, d) if aspect == 1.0 else None
    return coaxial_tablet(secs, aspect, a=a, name=name, family=f"thesis.{name}", params=params, nominal=nominal, tol=tol)


@lengths_checked()
def shallow_convex_round(diameter: float = 10.0, thickness: float = 3.0, band: float = 2.0, *, a=1.0, tol=DEFAULT) -> Tablet:
    """Shallow convex round tablet: spherical caps on a cylindrical band (Table 4.1: 10 × 3 mm)."""
    D = check_positive("diameter", diameter, "mm")
    T = check_positive("thickness", thickness, "mm")
    b = check_positive("band", band, "mm")
    return _convex("shallow_convex_round", D, T, b, a=a, tol=tol, params=dict(diameter=D, thickness=T, band=b))


@lengths_checked()
def shallow_convex_oval(width: float = 6.0, length: float = 12.0, thickness: float = 3.0, band: float = 2.0, *, a=1.0, tol=DEFAULT) -> Tablet:
    """Shallow convex oval: elliptical plan ``length`` (x) × ``width`` (y), caps scaled
    from the round cap profile (Table 4.1: 6 × 12 × 3 mm)."""
    W = check_positive("width", width, "mm")
    L = check_positive("length", length, "mm")
    T = check_positive("thickness", thickness, "mm")
    b = check_positive("band", band, "mm")
    if L < W:
        raise DesignError("length", L, f"must be >= width = {W:g} mm", "mm")
    return _convex("shallow_convex_oval", W, T, b, aspect=L / W, a=a, tol=tol,
                   params=dict(width=W, length=L, thickness=T, band=b))


@lengths_checked()
def oblong(diameter: float = 5.0, length: float = 15.0, dome: float = 1.0, *, a=1.0, tol=DEFAULT) -> Tablet:
    """Oblong tablet standing on its axis: round section ``diameter``, overall
    ``length`` along z, spherical domes of height ``dome`` (Table 4.1: 5 × 15 mm)."""
    D = check_positive("diameter", diameter, "mm")
    L = check_positive("length", length, "mm")
    d = check_positive("dome", dome, "mm")
    if d > D / 2:
        raise DesignError("dome", d, f"must be <= diameter/2 = {D / 2:g} mm", "mm")
    if 2 * d >= L:
        raise DesignError("dome", d, f"must be < length/2 = {L / 2:g} mm", "mm")
    R = D / 2
    secs = [_cap(R, d, d, up=False), _band(R, d, L - d), _cap(R, L - d, d, up=True)]
    return coaxial_tablet(secs, a=a, name="oblong", family="thesis.oblong", params=dict(diameter=D, length=L, dome=d),
                          nominal=nom.convex_round(R, d, L - d, d), tol=tol)


# ---------------------------------------------------------------------------- Table 4.5
def _ring_inner_limit(Do: float, tol: Tolerances = DEFAULT) -> float:
    """The largest inner diameter (mm) of a ring of outer diameter ``Do``: its ``w`` range
    ``[inner/outer, 1]`` at least :data:`~tabletcad.geometry.tablet.TRIM_MIN_WIDTH` wide (a trim's
    least) and its wall at least ``tol.min_length`` thick (a ring 11.999 mm inside 12 had been
    refused naming ``trim.w``, a table the design did not have)."""
    hi = min(Do * (1.0 - TRIM_MIN_WIDTH), Do - 2.0 * tol.min_length)
    if not hi > 0.0:
        raise DesignError("outer_diameter", Do, f"must be > {2.0 * tol.min_length:g} mm for a ring (a wall of at least "
                          f"{tol.min_length:g} mm, Tolerances.min_length, around a hole)", "mm")
    return hi


@lengths_checked()
def ring(outer_diameter: float = 12.0, inner_diameter: float = 6.0, thickness: float = 4.5, *, a=1.0, tol=DEFAULT) -> Tablet:
    """Ring tablet: the band of a flat-faced round tablet as a solid with
    ``w ∈ [inner/outer, 1]`` (Table 4.5: 12 × 4.5 mm with a 6 mm hole)."""
    Do = check_positive("outer_diameter", outer_diameter, "mm")
    Di = check_range("inner_diameter", inner_diameter, 0.0, _ring_inner_limit(Do, tol), "mm", lo_open=True)
    T = check_positive("thickness", thickness, "mm")
    R = Do / 2
    t = coaxial_tablet([_band(R, 0.0, T)], a=a, name="ring", family="thesis.ring",
                       params=dict(outer_diameter=Do, inner_diameter=Di, thickness=T), tol=tol)
    from dataclasses import replace

    ri = Di / 2
    f_out = nom.cylinder(R, 0.0, T)
    return replace(t, trim=Trim(w=(Di / Do, 1.0)), nominal=lambda p: np.maximum(f_out(p), ri - np.hypot(p[:, 0], p[:, 1])))


@lengths_checked()
def deep_convex_round(diameter: float = 10.0, thickness: float = 4.0, band: float = 1.0, *, a=1.0, tol=DEFAULT) -> Tablet:
    """Deep convex round (Table 4.5: 10 × 4 mm)."""
    D = check_positive("diameter", diameter, "mm")
    T = check_positive("thickness", thickness, "mm")
    b = check_positive("band", band, "mm")
    return _convex("deep_convex_round", D, T, b, a=a, tol=tol, params=dict(diameter=D, thickness=T, band=b))


def _spheroid(name: str, diameter: float, height: float, a, tol) -> Tablet:
    rx = diameter / 2
    c = height / 2
    psi = [-math.pi / 2, -math.pi / 3, -math.pi / 6, 0.0, math.pi / 6, math.pi / 3, math.pi / 2]
    pts = [(rx * math.cos(p) if abs(p) != math.pi / 2 else 0.0, c + c * math.sin(p)) for p in psi]
    return coaxial_tablet([pts[0:4], pts[3:7]], a=a, name=name, family=f"thesis.{name}",
                          params=dict(diameter=diameter, height=height), nominal=nom.spheroid(rx, c, (0, 0, c)), tol=tol)


@lengths_checked()
def oblate_spheroid(diameter: float = 10.0, height: float = 2.5, *, a=1.0, tol=DEFAULT) -> Tablet:
    """Oblate spheroid (Table 4.5: 10 × 2.5 mm)."""
    D = check_positive("diameter", diameter, "mm")
    H = check_positive("height", height, "mm")
    if H > D:
        raise DesignError("height", H, f"must be <= diameter = {D:g} mm for an oblate spheroid", "mm")
    return _spheroid("oblate_spheroid", D, H, a, tol)


@lengths_checked()
def prolate_spheroid(diameter: float = 5.0, height: float = 10.0, *, a=1.0, tol=DEFAULT) -> Tablet:
    """Prolate spheroid (Table 4.5: 5 × 10 mm)."""
    D = check_positive("diameter", diameter, "mm")
    H = check_positive("height", height, "mm")
    if H < D:
        raise DesignError("height", H, f"must be >= diameter = {D:g} mm for a prolate spheroid", "mm")
    return _spheroid("prolate_spheroid", D, H, a, tol)


@lengths_checked()
def rod(diameter: float = 3.0, length: float = 7.5, dome: float = 0.2, *, a=1.0, tol=DEFAULT) -> Tablet:
    """Rod: a short oblong (Table 4.5: 3 × 7.5 mm)."""
    t = oblong(diameter, length, dome, a=a, tol=tol)
    from dataclasses import replace

    return replace(t, name="rod", family="thesis.rod")


@lengths_checked()
def caplet(width: float = 3.5, length: float = 7.0, height: float = 15.0, band: float = 10.0, *, a=1.0, tol=DEFAULT) -> Tablet:
    """Caplet: an oval tablet stretched along its axis (Table 4.5: 3.5 × 7 × 15 mm)."""
    try:
        t = shallow_convex_oval(width, length, height, band, a=a, tol=tol)
    except DesignError as exc:  # the oval's "thickness" is the caplet's "height"
        if exc.parameter == "thickness":
            raise exc.renamed("height") from None
        raise DesignError(exc.parameter, exc.value, exc.allowed.replace("thickness", "height"), exc.unit) from None
    from dataclasses import replace

    return replace(t, name="caplet", family="thesis.caplet")


@lengths_checked()
def deep_convex_oval(width: float = 6.0, length: float = 12.0, thickness: float = 3.1, band: float = 1.1, *, a=1.0, tol=DEFAULT) -> Tablet:
    """Deep convex oval (Table 4.5: 6 × 12 × 3.1 mm)."""
    t = shallow_convex_oval(width, length, thickness, band, a=a, tol=tol)
    from dataclasses import replace

    return replace(t, name="deep_convex_oval", family="thesis.deep_convex_oval")


# ---------------------------------------------------------------------------- catalogue
#: The thesis's shapes with a band whose faces meet it at its edge: their land (the flat ring
#: between the cup and the band) is 0 mm by construction (the face patch starts on the band's
#: edge curve).  The tooling reads it; the industry families carry ``land_mm`` in their nominal.
NO_LAND: frozenset[str] = frozenset(f"thesis.{n}" for n in (
    "flat_faced_round", "shallow_convex_round", "deep_convex_round", "shallow_convex_oval", "deep_convex_oval",
    "caplet", "oblong", "rod"))

#: The thesis's shapes (Tables 4.1 and 4.5, in that order), a static mapping; every parameter in mm.
#: Every family is in :data:`tabletcad.families.FAMILIES`, where these are named ``thesis.<name>``
#: (``thesis.flat_faced_round``): the plain names belong to the industry families.
THESIS_SHAPES: Mapping[str, Family] = MappingProxyType({
    f.__name__: Family.of(f)
    for f in (flat_faced_round, spherical, shallow_convex_round, shallow_convex_oval, oblong, ring,
              deep_convex_round, oblate_spheroid, prolate_spheroid, rod, caplet, deep_convex_oval)
})
