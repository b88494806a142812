"""Boundary rows that stand still over part of their length, and how a chain is cut into faces.

Two tablets give a patch whose boundary row is not a regular closed curve:

* the capsule's innermost cup patch ends on the centre line - the offsets of a
  stadium shrink to a segment at the inscribed radius, so the row runs along that
  segment and back (a *slit*), its end arcs collapsed to points;
* an outline cupped exactly to its corner radius (the default of the rounded
  polygons) has a rim whose corner arcs are collapsed to points.

As one face, such a row is a closed edge whose 3-D curve stops over those ``v``
intervals (or uses the segment twice): sewing leaves free edges, STEP readers
tear the face open and OCCT's Booleans fail where a tool crosses it.
:func:`chain_face_surfaces` therefore cuts every surface of the chain in ``v``
at the row's C0 knots (the outline junctions, where the fit puts knots of
multiplicity ``degree``), each piece an exact clamped part of the same B-spline
(:func:`tabletcad.brep.surface.segment_v`).  A piece's row then either moves or is a
single pole (a degenerated edge, like a sphere's pole); a capsule cup becomes two
cylinder-like runs meeting along the segment and two dome-like fans at its ends,
the topology a toolmaker's CAD gives it.

numpy only: the OCP layer (:mod:`tabletcad.cad.solid`) and the FreeCAD workbench
cut the same data the same way.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from tabletcad.brep.surface import BSplineSurfaceData, segments_v
from tabletcad.errors import GeometryError
from tabletcad.geometry.vectors import norm3

__all__ = ["chain_face_surfaces", "row_pieces"]


def row_pieces(data: BSplineSurfaceData, row: int, tol: float = 1e-7):
    """Boundary row ``row`` (0: ``u`` first, -1: ``u`` last) cut at the C0 ``v`` knots, or None.

    Returns ``(pieces, samples, u_row)`` with ``pieces`` = ``[(v0, v1, kind), ...]``:
    ``kind`` is ``"point"`` where the row stays within ``tol`` mm of one point over
    the piece, else ``"run"``; ``samples`` are the row's points on each piece.  None
    for a non-periodic surface or a row without C0 knots.
    """
    if not data.v_periodic or data.u_periodic:
        return None
    u_row = float(data.u_knots[0] if row == 0 else data.u_knots[-1])
    knots = np.asarray(data.v_knots, dtype=float)
    mults = np.asarray(data.v_mults)
    cuts = sorted({float(knots[0]), float(knots[-1]), *[float(k) for k, m in zip(knots, mults) if m >= data.v_degree]})
    if len(cuts) < 3:
        return None
    t = np.linspace(0.0, 1.0, 17)
    spans = list(zip(cuts[:-1], cuts[1:]))
    v = np.concatenate([a + (b - a) * t for a, b in spans])
    clamped = data.u_mults[0 if row == 0 else -1] == data.u_degree + 1
    if clamped:  # the row is the curve of the boundary pole row: one product for every piece
        rows = data.collocation("v", v) @ np.asarray(data.poles[0 if row == 0 else -1])
    else:
        rows = np.asarray(data.evaluate(np.full_like(v, u_row), v), dtype=float)
    pts, pieces = [], []
    for k, (a, b) in enumerate(spans):
        p = rows[k * t.size:(k + 1) * t.size]
        pts.append(p)
        pieces.append((a, b, "point" if float(np.max(norm3(p - p[0]))) <= tol else "run"))
    return pieces, pts, u_row


def _is_c0_knot(data: BSplineSurfaceData, v: float) -> bool:
    knots = np.asarray(data.v_knots, dtype=float)
    i = int(np.argmin(np.abs(knots - v)))
    return abs(float(knots[i]) - v) <= 1e-12 * max(1.0, abs(v)) and int(data.v_mults[i]) >= data.v_degree


def _standing_rows(data: BSplineSurfaceData, tol: float, made: dict | None = None) -> dict[int, list]:
    """``{row: pieces}`` for the boundary rows of ``data`` that stand still over part of their
    length (both ``"point"`` and ``"run"`` pieces, as :func:`row_pieces` gives them).

    A row of a surface clamped in ``u`` is its pole row, and over a piece between C0 knots
    the row's curve is a convex combination of that piece's poles: it stands within ``tol``
    of its start wherever they do.  The pieces' poles (:func:`~tabletcad.brep.surface.segments_v`)
    then say it without evaluating the row, when they are clearly within ``tol`` or beyond
    ``100 tol``; a row not clamped, a piece across the seam or poles in between are sampled
    (:func:`row_pieces`), as before.
    The pieces go into ``made[id(data)]`` with their cuts, for :func:`_pieces` to take."""
    if not data.v_periodic or data.u_periodic:
        return {}
    knots = np.asarray(data.v_knots, dtype=float)
    cuts = sorted({float(knots[0]), float(knots[-1]),
                   *[float(k) for k, m in zip(knots, data.v_mults) if m >= data.v_degree]})
    if len(cuts) < 3:
        return {}
    spans = list(zip(cuts[:-1], cuts[1:]))
    wrap = not _is_c0_knot(data, float(knots[0]))  # the first and last spans: one piece across the seam
    pieces = None
    out = {}
    for k in (0, -1):
        kinds = None
        if data.u_mults[k] == data.u_degree + 1 and not wrap:
            if pieces is None:
                pieces = segments_v(data, spans)
                if made is not None:
                    made[id(data)] = (cuts, pieces)
            spread = [float(np.max(norm3(q.poles[k] - q.poles[k][0]))) for q in pieces]
            if all(x <= tol or x > 100.0 * tol for x in spread):  # clear either way: the poles say it
                kinds = ["point" if x <= tol else "run" for x in spread]
        if kinds is None:  # not clamped, across the seam, or poles just beyond tol: the row's samples
            found = row_pieces(data, k, tol)
            kinds = None if found is None else [kind for _, _, kind in found[0]]
            spans_k = None if found is None else [(a, b) for a, b, _ in found[0]]
        else:
            spans_k = spans
        if kinds is not None and len(set(kinds)) == 2:
            out[k] = [(a, b, kind) for (a, b), kind in zip(spans_k, kinds)]
    return out


def _pieces(data: BSplineSurfaceData, cuts: list[float], tol: float,
            made: dict | None = None) -> tuple[BSplineSurfaceData, ...]:
    period = float(data.v_knots[-1] - data.v_knots[0])
    cuts = sorted({float(data.v_knots[0]), float(data.v_knots[-1]), *cuts})
    spans = list(zip(cuts[:-1], cuts[1:]))
    if not _is_c0_knot(data, float(data.v_knots[0])):
        spans = [(spans[-1][0], spans[0][1] + period), *spans[1:-1]]
    hit = (made or {}).get(id(data))
    out = []
    for piece in hit[1] if hit is not None and hit[0] == cuts else segments_v(data, spans):
        poles = None
        for k in (0, -1):
            r = piece.poles[k]
            spread = float(np.max(norm3(r - r[0])))
            if 0.0 < spread <= 10.0 * tol:  # a collapsed row: one pole, so every kernel makes it degenerate
                poles = np.array(piece.poles) if poles is None else poles
                poles[k] = r.mean(axis=0)
        out.append(piece if poles is None else replace(piece, poles=poles))
    return tuple(out)


def chain_face_surfaces(surfaces, tol: float = 1e-7, names=None) -> list[tuple[BSplineSurfaceData, ...]]:
    """Per surface of a chain (neighbours share boundary rows), the surfaces to make faces of:
    ``(surface,)``, or its exact pieces.

    A boundary row that stands still over part of its length - the slit of the capsule's
    centre line, or an outline whose corners collapse at the offset the row lies on (a
    rounded square cupped exactly to its corner radius) - gives a closed edge whose 3-D
    curve stops over those ``v`` intervals: sewing leaves free edges there and Booleans
    fail across it.  Cut in ``v`` at the boundaries of such pieces, each face has either a
    moving row or a pole there.  Every surface of the chain is cut at the same ``v`` values
    (the chain shares its C0 knots), so that neighbouring faces meet edge to edge and
    sewing never has to split an edge (it would re-project the p-curves, which measurably
    spoils OCCT's mass properties: 1.8e-4 relative on a rounded square).  A row whose poles
    spread by at most ``10 tol`` mm over a piece is snapped to one pole.  If the period's
    start is not a C0 knot, the first and last pieces are one piece across it.
    """
    surfaces = list(surfaces)
    names = list(names) if names is not None else [f"surface {j}" for j in range(len(surfaces))]
    cuts: set[float] = set()
    made: dict = {}  # pieces cut while looking, kept for the cut (when at the same cuts)
    for data, name in zip(surfaces, names):
        for k, pieces in _standing_rows(data, tol, made).items():
            other = np.asarray(data.poles[-1 if k == 0 else 0])
            if float(np.max(norm3(other - other[0]))) <= tol:
                raise GeometryError(f"{name}: a row that stands still in part opposite a pole is not supported", data)
            cuts.update(x for a, b, _ in pieces for x in (a, b))
    if not cuts:
        return [(s,) for s in surfaces]
    out = []
    for data, name in zip(surfaces, names):
        if not data.v_periodic:
            raise GeometryError(f"{name}: cannot be cut at v = {sorted(cuts)} with its neighbours (not periodic in v)",
                                data)
        out.append(_pieces(data, sorted(cuts), tol, made))
    return out
