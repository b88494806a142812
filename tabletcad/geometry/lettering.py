"""An engraved figure's plan outline and how much of it lies outside a face, from numbers alone.

The tooling (:mod:`tabletcad.tooling.emboss`) builds a figure's faces with OpenCascade and cuts them
with the punch tip's face (the outline offset inwards by the clearance, land and margin) to refuse a
figure that does not fit.  ``tabletcad report`` builds no solid, so the same decision is taken here
on the same curves:

* **Text** (:func:`text_contours`): the glyph contours read from the font file with fontTools, laid out
  as OCC's ``StdPrs_BRepTextBuilder`` lays them out with ``Graphic3d_HTA_CENTER`` and
  ``Graphic3d_VTA_CENTER``: each glyph at the pen, the pen advanced by the glyph's advance width plus
  the legacy ``kern`` table's pair value (FreeType's ``FT_Get_Kerning``, which OCC calls, reads no
  GPOS; OCC 7.9's formatter pairs the last of several symbols with itself, so "LT" in DejaVu Sans Bold
  is 47 units wider than its advances), the line centred on that total advance, and the baseline at
  ``-ascender + line spacing / 2``.  OCC reads the outlines through FreeType at 4800 pixels per em in
  26.6 fixed point: a TrueType font's points, advances and kerning are rounded to that grid as
  FreeType rounds them and laid out in OCC's single precision (:mod:`tabletcad.geometry.glyphs`), so
  the curves are OCC's to round-off for any units per em (2048: DejaVu, cmr10; 1000: STIX; 1024;
  ``tests/test_report_refusals.py`` compares them vertex by vertex: the plain scaling had left STIX
  5e-6 mm off, 7e-6 relative in area).  A CFF font's cubics are scaled in double precision (FreeType's
  CFF scaling is not reproduced).
* **A polyline** (``outline = [[x, y], ...]``): its segments.
* Placed as :func:`tabletcad.tooling.emboss.figure_faces` places it: turned by ``rotation_deg``, moved
  to ``position_mm`` and, on the bottom face, mirrored ``x -> -x``.

:func:`outside_area` is the area of the figure outside ``{p : distance inside the outline >= inset}``
(the outline's inward offset by ``inset``) by Green's theorem, exactly: ``∮ x dy`` over the figure's
curves where they lie outside (Gauss–Legendre, exact on polynomials), their crossings of the offset
found by Brent's method on the outline's exact signed distance, and closed along the offset curve
(its lines and arcs) between the crossings.  It needs that offset curve to be the inset region's
boundary (:func:`tabletcad.families.outline.offset_bounds_inset`: ``inset`` below every convex arc's radius, and no neck where
the offset would cross itself or part in two: there the closing integral would run along the
crossing offset, 0.464 mm² instead of 0.440 on a peanut's neck; the caller leaves those to OCC); a
crossing point is found between 64 samples of each Bézier, so a tangential touch thinner than their
spacing (area < 1e-9 mm² on tablet lettering) is missed, far below the refusal threshold.
"""

from __future__ import annotations

import math
from functools import lru_cache
from pathlib import Path

import numpy as np

__all__ = ["text_contours", "polyline_contours", "placed", "figure_area", "figure_box", "figure_length",
           "outside_area"]

#: Gauss-Legendre nodes and weights on [0, 1] (exact for polynomials of degree 15)
_GX, _GW = np.polynomial.legendre.leggauss(8)
_GX, _GW = 0.5 * (_GX + 1.0), 0.5 * _GW

#: samples per Bézier in which its crossings of the offset are bracketed
_SAMPLES = 64


@lru_cache(maxsize=8)
def _font(path: str):
    from fontTools.ttLib import TTFont

    return TTFont(path, lazy=True)


class _Recorder:
    """A fontTools pen (``moveTo``, ``lineTo``, ``qCurveTo``, ``curveTo``, ``closePath``) that keeps each
    contour as a list of Bézier control arrays (font units): lines (2, 2), quadratics (3, 2), cubics (4, 2)."""

    def __init__(self, glyphs):
        from fontTools.pens.basePen import BasePen

        class Pen(BasePen):  # (a composite glyph's components drawn from ``glyphs``)
            def __init__(pen):
                super().__init__(glyphs)
                pen.contours, pen.current = [], []

            def _moveTo(pen, p):
                pen.start = p

            def _lineTo(pen, p):
                pen.current.append(np.array([pen._getCurrentPoint(), p], dtype=float))

            def _qCurveToOne(pen, p1, p2):
                pen.current.append(np.array([pen._getCurrentPoint(), p1, p2], dtype=float))

            def _curveToOne(pen, p1, p2, p3):
                pen.current.append(np.array([pen._getCurrentPoint(), p1, p2, p3], dtype=float))

            def _closePath(pen):
                end = pen._getCurrentPoint()
                if end is not None and tuple(end) != tuple(pen.start):
                    pen.current.append(np.array([end, pen.start], dtype=float))
                if pen.current:
                    pen.contours.append(pen.current)
                pen.current = []

            _endPath = _closePath

        self.pen = Pen()


def _kerning(font, left: str, right: str) -> float:
    """The legacy ``kern`` table's value (font units) for the glyph pair, 0 without one."""
    if "kern" not in font:
        return 0.0
    for table in font["kern"].kernTables:
        value = getattr(table, "kernTable", {}).get((left, right))
        if value is not None:
            return float(value)
    return 0.0


def text_contours(text: str, size: float, path: str | Path) -> list[list[np.ndarray]]:
    """The contours (mm) of ``text`` at ``size`` mm per em in the font file ``path``, laid out and centred as
    OCC's text builder centres them (see the module docstring); each contour a list of Bézier control arrays."""
    font = _font(str(path))
    cmap = font.getBestCmap() or {}
    names = [cmap.get(ord(c), ".notdef") for c in text]
    # OCC's formatter pairs the last of several symbols with itself (its iterator's next symbol)
    following = [names[i + 1] if i + 1 < len(names) else name if len(names) > 1 else None
                 for i, name in enumerate(names)]
    if "glyf" in font:
        return _truetype_contours(font, names, following, size)
    return _pen_contours(font, names, following, size)


def _truetype_contours(font, names: list[str], following: list, size: float) -> list[list[np.ndarray]]:
    """A TrueType font's glyphs as FreeType gives them to OCC (:mod:`tabletcad.geometry.glyphs`), laid out."""
    from tabletcad.geometry import glyphs

    scale = glyphs.face_scale(font)
    scale_mm = size / 72.0 * 72.0 / glyphs.PPEM  # (StdPrs_BRepFont's getScale, in its order)
    loaded, advances = [], []
    for name, nxt in zip(names, following):
        pts, on, ends, advance = glyphs.glyph_outline(font, name, scale)
        kern = glyphs.mul_fix(int(_kerning(font, name, nxt)), scale) if nxt is not None else 0
        loaded.append(glyphs.glyph_contours(pts, on, ends, scale_mm))
        advances.append(advance + kern)
    xs, y = glyphs.layout(advances, font, scale_mm)
    return [[c + (x, y) for c in contour] for x, contours in zip(xs, loaded) for contour in contours]


def _pen_contours(font, names: list[str], following: list, size: float) -> list[list[np.ndarray]]:
    """A CFF font's glyphs scaled by ``size / unitsPerEm`` in double precision (FreeType's CFF scaling is
    not reproduced: these may differ from OCC's by its 26.6 rounding), laid out as OCC lays them out."""
    from tabletcad.geometry.glyphs import face_metrics

    upm = float(font["head"].unitsPerEm)
    glyphs = font.getGlyphSet()
    hmtx = font["hmtx"]
    pens, x = [], 0.0
    for name, nxt in zip(names, following):
        rec = _Recorder(glyphs)
        glyphs[name].draw(rec.pen)
        pens.append((x, rec.pen.contours))
        x += hmtx[name][0] + (_kerning(font, name, nxt) if nxt is not None else 0.0)
    ascender, height = face_metrics(font)  # the first baseline at -ascender, up by half the line spacing
    dx, dy = -0.5 * x, -ascender + 0.5 * height
    k = size / upm
    return [[(c + (x0 + dx, dy)) * k for c in contour] for x0, contours in pens for contour in contours]


def polyline_contours(points) -> list[list[np.ndarray]]:
    """The closed polyline ``points`` ((m, 2), mm) as one contour of line segments."""
    p = np.asarray(points, dtype=float)
    return [[np.array([p[i], p[(i + 1) % len(p)]]) for i in range(len(p))]]


def placed(contours, rotation_deg: float, position, mirror: bool) -> list[list[np.ndarray]]:
    """``contours`` turned by ``rotation_deg`` about the origin, moved by ``position`` (mm) and, with ``mirror``,
    mirrored ``x -> -x`` (the bottom face's figure, read from below), as the tooling places its faces."""
    a = math.radians(rotation_deg)
    rot = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
    m = np.array([-1.0, 1.0]) if mirror else np.ones(2)
    return [[(c @ rot.T + np.asarray(position, dtype=float)) * m for c in contour] for contour in contours]


def _bezier(c: np.ndarray, t: np.ndarray, der: int = 0) -> np.ndarray:
    """Points (or first derivatives) of the Bézier with control points ``c`` (n+1, 2) at ``t`` (m,)."""
    n = len(c) - 1
    if der:
        c, n = n * np.diff(c, axis=0), n - 1
    t = np.asarray(t, dtype=float)[:, None]
    out = np.zeros((t.shape[0], 2))
    for i in range(n + 1):
        out += math.comb(n, i) * t**i * (1.0 - t) ** (n - i) * c[i]
    return out


def _x_dy(c: np.ndarray, t0: float, t1: float) -> float:
    """``∫ x dy`` (mm²) along the Bézier ``c`` from ``t0`` to ``t1`` (exact: a polynomial of degree <= 5)."""
    t = t0 + (t1 - t0) * _GX
    p, d = _bezier(c, t), _bezier(c, t, 1)
    return float(np.sum(_GW * p[:, 0] * d[:, 1]) * (t1 - t0))


def figure_area(contours) -> float:
    """The signed area (mm²) the contours enclose (the font's winding: negative for TrueType's clockwise outers)."""
    return sum(_x_dy(c, 0.0, 1.0) for contour in contours for c in contour)


def figure_length(contours) -> float:
    """The total length (mm) of the contours' curves (Gauss–Legendre on 8 pieces of each)."""
    total = 0.0
    for contour in contours:
        for c in contour:
            t = (np.arange(8)[:, None] + _GX[None, :]).ravel() / 8.0
            total += float(np.sum(np.tile(_GW, 8) * np.hypot(*_bezier(c, t, 1).T))) / 8.0
    return total


def figure_box(contours) -> tuple[float, float]:
    """Width and height (mm) of the contours' exact box: each Bézier's ends and the roots of its derivative."""
    lo, hi = np.full(2, np.inf), np.full(2, -np.inf)
    for contour in contours:
        for c in contour:
            ts = [0.0, 1.0]
            d = (len(c) - 1) * np.diff(c, axis=0)  # the derivative's control points
            for k in range(2):
                if len(d) == 2:  # linear: (1 - t) d0 + t d1
                    den = d[0, k] - d[1, k]
                    ts += [d[0, k] / den] if den != 0 else []
                elif len(d) == 3:  # quadratic in Bernstein form, as a power series
                    poly = [d[0, k] - 2 * d[1, k] + d[2, k], 2 * (d[1, k] - d[0, k]), d[0, k]]
                    ts += [r.real for r in np.roots(poly) if abs(r.imag) < 1e-12] if any(poly) else []
            ts = [t for t in ts if 0.0 <= t <= 1.0]
            p = _bezier(c, ts)
            lo, hi = np.minimum(lo, p.min(axis=0)), np.maximum(hi, p.max(axis=0))
    return float(hi[0] - lo[0]), float(hi[1] - lo[1])


def _foot(outline, p: np.ndarray) -> float:
    """The parameter ``v`` (rad) of the point of the lines-and-arcs ``outline`` nearest to ``p``."""
    best, v = math.inf, 0.0
    cum = outline._cum
    for i, s in enumerate(outline.segs):
        if s.kind == "line":
            a, b = np.asarray(s.p0, dtype=float), np.asarray(s.p1, dtype=float)
            u = float(np.clip(np.dot(p - a, b - a) / np.dot(b - a, b - a), 0.0, 1.0))
            dist, arc = float(np.hypot(*(a + u * (b - a) - p))), u * s.length
        else:
            ang = math.atan2(p[1] - s.center[1], p[0] - s.center[0]) - s.theta0
            ang = math.remainder(ang - 0.5 * s.sweep, math.tau) + 0.5 * s.sweep  # nearest to the sweep's middle
            u = min(max(ang / s.sweep, 0.0), 1.0)
            q = np.asarray(s.center) + s.radius * np.array([math.cos(s.theta0 + u * s.sweep), math.sin(s.theta0 + u * s.sweep)])
            dist, arc = float(np.hypot(*(q - p))), u * s.length
        if dist < best:
            best, v = dist, (cum[i] + arc) * math.tau / outline.perimeter
    return v


def _offset_x_dy(outline, inset: float, v0: float, v1: float) -> float:
    """``∫ x dy`` (mm²) along the outline's inward offset by ``inset`` from ``v0`` to ``v1`` (rad, ``v0 <= v1``,
    unwrapped), piece by piece between the segment joins (Gauss–Legendre on each: exact to round-off)."""
    joins = outline.breaks
    cuts = [v0] + [b + k * math.tau for k in range(int(math.floor(v0 / math.tau)), int(math.floor(v1 / math.tau)) + 1)
                   for b in joins if v0 < b + k * math.tau < v1] + [v1]
    total = 0.0
    for a, b in zip(cuts[:-1], cuts[1:]):
        if b <= a:
            continue
        for k in range(4):  # four pieces each: an arc's trigonometric integrand to round-off
            lo, hi = a + (b - a) * k / 4, a + (b - a) * (k + 1) / 4
            v = lo + (hi - lo) * _GX
            q = outline.offset(v, 0, 1.0, inset)
            dq = outline.offset(v, 1, 1.0, inset)
            total += float(np.sum(_GW * q[:, 0] * dq[:, 1]) * (hi - lo))
    return total


def outside_area(contours, outline, inset: float) -> tuple[float, float]:
    """``(area, outside)`` (mm²): the figure's area and the part of it farther out than the lines-and-arcs
    ``outline`` (a :class:`~tabletcad.families.outline.PlanOutline`) offset inwards by ``inset`` mm (see the
    module docstring).  The offset must bound the inset region (:func:`tabletcad.families.outline.offset_bounds_inset`), else the result is not
    the area outside."""
    signed = figure_area(contours)
    sign = 1.0 if signed >= 0 else -1.0  # the fill's orientation made counter-clockwise
    area = sign * signed

    def g(points):  # > 0 outside the inset region
        return inset - outline.signed_distance(np.atleast_2d(points))

    ts = np.linspace(0.0, 1.0, _SAMPLES + 1)
    curves = [c for contour in contours for c in contour]
    gs = g(np.vstack([_bezier(c, ts) for c in curves])).reshape(len(curves), ts.size)  # (at once: one call)
    out_part, exits, entries = 0.0, [], []
    for c, gv in zip(curves, gs):
        if np.any(gv > 0):
            out_part += _outside_part(c, ts, gv, g, sign, outline, exits, entries)
    if not exits and not entries:  # the offset runs wholly outside the figure (or inside: a figure enclosing
        return area, out_part      # the whole face, which the inset region's own area then bounds)
    # closed along the offset, clockwise from each entry to the next exit: sum of F(exit) - F(entry), F the
    # integral from a reference point of the offset that lies outside the figure (no closing arc passes it)
    ref = _reference(contours, outline, inset, exits + entries)
    F = lambda v: _offset_x_dy(outline, inset, ref, ref + (v - ref) % math.tau)  # noqa: E731
    closing = sum(F(v) for v in exits) - sum(F(v) for v in entries)
    return area, out_part + closing


def _outside_part(c, ts, gv, g, sign: float, outline, exits: list, entries: list) -> float:
    """``∫ x dy`` (mm², the fill made counter-clockwise by ``sign``) of the Bézier ``c`` where ``g`` > 0 (its
    samples ``gv`` at ``ts``); the feet of its crossings of ``g = 0`` appended to ``exits`` and ``entries``."""
    from scipy.optimize import brentq

    cuts = [0.0]
    for j in np.flatnonzero(np.sign(gv[:-1]) * np.sign(gv[1:]) < 0):
        r = brentq(lambda t: float(g(_bezier(c, [t]))[0]), ts[j], ts[j + 1], xtol=1e-15)
        cuts.append(r)
        # leaving the region along the figure's own direction (made counter-clockwise): an exit
        (exits if (gv[j + 1] > 0) == (sign > 0) else entries).append(_foot(outline, _bezier(c, [r])[0]))
    cuts.append(1.0)
    return sum(sign * _x_dy(c, a, b) for a, b in zip(cuts[:-1], cuts[1:])
               if b > a and float(g(_bezier(c, [0.5 * (a + b)]))[0]) > 0)


def _reference(contours, outline, inset: float, feet: list[float]) -> float:
    """A parameter of the offset outline away from every crossing whose point lies outside the figure: the
    middle of the widest gap between the crossings' feet that the figure does not cover there."""
    from matplotlib.path import Path as MplPath

    vs = np.sort(np.mod(feet, math.tau))
    gaps = np.diff(np.concatenate([vs, [vs[0] + math.tau]]))
    polys = [MplPath(np.vstack([_bezier(c, np.linspace(0, 1, 9)) for c in contour])) for contour in contours]
    for j in np.argsort(gaps)[::-1]:
        v = float(vs[j] + 0.5 * gaps[j])
        q = outline.offset(np.array([v]), 0, 1.0, inset)[0]
        if not any(p.contains_point(q) for p in polys):
            return v
    return float(vs[0] + 0.5 * gaps[0])
