"""TrueType glyphs as OpenCascade's text builder receives them from FreeType, in FreeType's integers.

OCC's ``StdPrs_BRepFont`` (which :func:`tabletcad.tooling.emboss.text_faces` uses) sets every font to 72
points at 4800 dpi (``FT_Set_Char_Size(face, 0, 72 * 64, 4800, 4800)``: 4800 pixels per em) and loads each
glyph with ``FT_LOAD_NO_HINTING``.  FreeType then hands it the outline in 26.6 fixed point (1/64 pixel):

* the scale ``x_scale = FT_DivFix(4800 * 64, unitsPerEm)`` (16.16; a TrueType font whose ``head`` flags ask
  for integer ppem gets ``FT_DivFix(ppem << 6, unitsPerEm)``, the same at 4800 ppem);
* every point of a simple glyph ``FT_MulFix(coordinate, x_scale)`` (rounded half away from zero): exact for
  2048 units per em (150 steps a unit), rounded for any other (1000: 300 steps a unit, 0.2 steps off);
* a composite's components loaded the same way, their 2x2 matrix (2.14, made 16.16) applied to the scaled
  points by ``FT_Vector_Transform`` and their offset scaled on its own (not rounded to the pixel grid
  unhinted);
* the outline moved by ``-pp1`` (the scaled ``xMin - lsb``) and the advance ``pp2 - pp1`` (both scaled);
* a kerning pair ``FT_MulFix(value, x_scale)`` (``FT_KERNING_UNFITTED``).

OCC makes millimetres of them as ``(scale * v) / 64`` with ``scale = size / 72 * 72 / 4800`` and lays the
glyphs out in single precision (``Font_TextFormatter``: the pen, the ascender and the line spacing are
``float``).  :func:`layout` does all of it in the same order, so that the vertices are OCC's to round-off
for any units per em (``tests/test_report_refusals.py`` compares them vertex by vertex).
"""

from __future__ import annotations

import numpy as np

__all__ = ["PPEM", "mul_fix", "div_fix", "face_scale", "glyph_outline", "glyph_contours", "layout"]

#: pixels per em at which OCC's StdPrs_BRepFont loads every glyph (72 pt at 4800 dpi)
PPEM = 4800
#: OCC's requested character size, 72 points in 26.6
_CHAR_SIZE = 72 * 64

#: composite glyph flags (TrueType ``glyf``; fontTools keeps these, and tells point matching by ``firstPt``)
_USE_MY_METRICS, _SCALED_COMPONENT_OFFSET = 0x0200, 0x0800

#: OCC's ``Precision::Confusion()`` (mm): a shorter line of a glyph is left out, a wider gap closed
_CONFUSION = 1e-7

_F32 = np.float32


def mul_fix(a, b: int):
    """FreeType's ``FT_MulFix``: ``a * b / 65536`` rounded half away from zero (integers or an int64 array)."""
    ab = np.asarray(a, dtype=np.int64) * np.int64(b)
    out = (ab + 0x8000 - (ab < 0)) >> 16
    return int(out) if np.ndim(out) == 0 else out


def div_fix(a: int, b: int) -> int:
    """FreeType's ``FT_DivFix``: ``a * 65536 / b`` rounded half up in magnitude, the sign applied after."""
    sign = -1 if (a < 0) != (b < 0) else 1
    a, b = abs(a), abs(b)
    return sign * (((a << 16) + (b >> 1)) // b) if b else 0x7FFFFFFF


def face_scale(font) -> int:
    """``x_scale`` (16.16) of the fontTools ``font`` at OCC's size, as ``FT_Set_Char_Size`` and the TrueType
    driver's size reset compute it."""
    upem = int(font["head"].unitsPerEm)
    scaled = (_CHAR_SIZE * PPEM + 36) // 72  # FT_REQUEST_WIDTH (26.6 pixels)
    scale = div_fix(scaled, upem)
    if int(font["head"].flags) & 8:  # integer ppem asked for: the scale of the rounded ppem
        scale = div_fix(((scaled + 32) & -64), upem)
    return scale


def _transform(points: np.ndarray, matrix: tuple[int, int, int, int]) -> np.ndarray:
    """``FT_Vector_Transform`` of 26.6 ``points`` by the 16.16 ``(xx, xy, yx, yy)``."""
    xx, xy, yx, yy = matrix
    x, y = points[:, 0], points[:, 1]
    return np.column_stack([mul_fix(x, xx) + mul_fix(y, xy), mul_fix(x, yx) + mul_fix(y, yy)])


def _component_offset(comp, matrix, base: np.ndarray, points: np.ndarray, scale: int) -> np.ndarray:
    """The 26.6 offset of a composite's component (its scaled ``points``; ``base``: the points before it)."""
    if hasattr(comp, "firstPt"):  # point matching (no ARGS_ARE_XY_VALUES): the parent's point onto the component's
        return base[comp.firstPt] - points[comp.secondPt]
    x, y = int(comp.x), int(comp.y)
    if matrix is not None and comp.flags & _SCALED_COMPONENT_OFFSET:  # (Apple's convention; rare)
        x = mul_fix(x, int(round(np.hypot(matrix[0], matrix[1]))))
        y = mul_fix(y, int(round(np.hypot(matrix[3], matrix[2]))))
    return np.array([mul_fix(x, scale), mul_fix(y, scale)], dtype=np.int64)


def _points(glyf, name: str, scale: int, depth: int = 0):
    """``(points (n, 2) int64 26.6, on-curve (n,), contour ends, metrics name)`` of glyph ``name``, unhinted."""
    g = glyf[name]
    if g.numberOfContours == 0 or depth > 16:
        return np.zeros((0, 2), np.int64), np.zeros(0, bool), [], name
    if not g.isComposite():
        coords = np.array(g.coordinates, dtype=np.int64).reshape(-1, 2)
        on = (np.array(g.flags, dtype=np.uint8) & 1).astype(bool)
        return mul_fix(coords, scale), on, list(g.endPtsOfContours), name
    pts, on, ends, metrics = np.zeros((0, 2), np.int64), np.zeros(0, bool), [], name
    for comp in g.components:
        p, o, e, _ = _points(glyf, comp.glyphName, scale, depth + 1)
        matrix = None
        if hasattr(comp, "transform"):  # 2.14 values (fontTools' floats are exact) made 16.16
            (a, b), (c, d) = comp.transform
            matrix = tuple(int(round(v * 16384)) * 4 for v in (a, c, b, d))  # xx, xy, yx, yy
            p = _transform(p, matrix) if len(p) else p
        if len(p):
            p = p + _component_offset(comp, matrix, pts, p, scale)
        ends += [len(pts) + k for k in e]
        pts, on = np.vstack([pts, p]), np.concatenate([on, o])
        if comp.flags & _USE_MY_METRICS:
            metrics = comp.glyphName
    return pts, on, ends, metrics


def glyph_outline(font, name: str, scale: int):
    """``(points, on, ends, advance)``: glyph ``name``'s outline (26.6 integers, moved by ``-pp1`` as FreeType
    moves it) and its advance (26.6), as ``FT_Load_Glyph(..., FT_LOAD_NO_HINTING)`` gives them."""
    glyf, hmtx = font["glyf"], font["hmtx"]
    pts, on, ends, metrics = _points(glyf, name, scale)
    g = glyf[metrics]
    advance, lsb = hmtx[metrics]
    pp1 = (int(g.xMin) if g.numberOfContours else 0) - int(lsb)  # the phantom point (font units)
    left = mul_fix(pp1, scale)
    if left and len(pts):
        pts = pts - np.array([left, 0], dtype=np.int64)
    return pts, on, ends, mul_fix(pp1 + int(advance), scale) - left


def glyph_contours(points: np.ndarray, on: np.ndarray, ends: list[int], scale_mm: float) -> list[list[np.ndarray]]:
    """The glyph's contours (mm, each a list of Bézier control arrays) as OCC's ``StdPrs_BRepFont`` builds its
    edges from the 26.6 ``points``: ``(scale_mm * v) / 64``; a line between consecutive on-curve points, a
    quadratic for each off-curve point from its neighbour (or the midpoint with an off-curve neighbour) to the
    next; contours of fewer than 3 points and lines shorter than 1e-7 mm left out, a gap closed by a line."""
    xy = (scale_mm * points.astype(float)) / 64.0
    contours, start = [], 0
    for end in ends:
        p, o = xy[start:end + 1], on[start:end + 1]
        start = end + 1
        if len(p) >= 3:
            curves = _contour(p, o)
            if curves:
                contours.append(curves)
    return contours


def _contour(p: np.ndarray, on: np.ndarray) -> list[np.ndarray]:
    """One contour's curves (see :func:`glyph_contours`)."""
    n, curves = len(p), []
    line_from = p[-1] if on[-1] else None  # a line runs from here to the next on-curve point
    for i in range(n):
        prev, nxt = p[i - 1], p[(i + 1) % n]
        if on[i]:
            if line_from is not None:
                if float(np.hypot(*(p[i] - line_from))) <= _CONFUSION:
                    line_from = p[i]
                    continue
                curves.append(np.array([line_from, p[i]]))
            line_from = p[i]
            continue
        line_from = None
        a = prev if on[i - 1] else (p[i] + prev) * 0.5
        b = nxt if on[(i + 1) % n] else (p[i] + nxt) * 0.5
        curves.append(np.array([a, p[i], b]))
    if curves and float(np.hypot(*(curves[-1][-1] - curves[0][0]))) > _CONFUSION:
        curves.append(np.array([curves[-1][-1], curves[0][0]]))
    return curves


def layout(advances: list[int], font, scale_mm: float) -> tuple[np.ndarray, float]:
    """The pen ``x`` (mm) of each glyph and the baseline ``y`` (mm) of one line laid out by OCC's
    ``Font_TextFormatter`` with ``Graphic3d_HTA_CENTER`` / ``Graphic3d_VTA_CENTER`` from the glyphs' 26.6
    ``advances`` (kerning included), in its single precision, then made millimetres in double."""
    pen, corners = _F32(0.0), []
    for adv in advances:
        corners.append(pen)
        pen = _F32(pen + _F32(_F32(adv) / _F32(64.0)))
    width = pen
    right = _F32(corners[-1] + _F32(pen - corners[-1])) if corners else _F32(0.0)
    half = _F32(0.5)
    move_x = _F32(_F32(-_F32(0.0) + _F32(half * _F32(width - _F32(right - _F32(0.0))))) - _F32(half * width))
    ascender, line = _vertical_metrics(font)
    y = _F32(-ascender + _F32(half * _F32(line * _F32(1.0))))
    xs = np.array([float(_F32(c + move_x)) for c in corners]) * scale_mm
    return xs, float(y) * scale_mm


def _vertical_metrics(font) -> tuple[np.float32, np.float32]:
    """``(Ascender(), LineSpacing())`` of OCC's ``Font_FTFont`` (pixels, single precision) from FreeType's face
    ascender and height (:func:`face_metrics`)."""
    asc, height = face_metrics(font)
    k = _F32(_F32(PPEM) / _F32(int(font["head"].unitsPerEm)))
    return _F32(_F32(asc) * k), _F32(_F32(height) * k)


def face_metrics(font) -> tuple[int, int]:
    """FreeType's ``face->ascender`` and ``face->height`` (font units) of a TrueType font: OS/2's typographic
    metrics when its ``fsSelection`` asks for them (USE_TYPO_METRICS), else ``hhea``'s (ascender - descender +
    line gap), and where those are both 0, OS/2's typographic or, failing those, its Windows metrics."""
    os2 = font["OS/2"] if "OS/2" in font else None
    if os2 is not None and int(os2.fsSelection) & 128:
        return int(os2.sTypoAscender), int(os2.sTypoAscender) - int(os2.sTypoDescender) + int(os2.sTypoLineGap)
    hhea = font["hhea"]
    asc, desc = int(hhea.ascent), int(hhea.descent)
    if asc or desc or os2 is None:
        return asc, asc - desc + int(hhea.lineGap)
    if os2.sTypoAscender or os2.sTypoDescender:
        return int(os2.sTypoAscender), int(os2.sTypoAscender) - int(os2.sTypoDescender) + int(os2.sTypoLineGap)
    return int(os2.usWinAscent), int(os2.usWinAscent) + int(os2.usWinDescent)
