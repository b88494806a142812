"""A closed shell assembled edge by edge from a chain of B-spline faces, without sewing.

The faces of a tablet come as a chain (:func:`tabletcad.brep.slit.chain_face_surfaces`):
patch ``j``'s ``u``-last pole row is patch ``j+1``'s ``u``-first row, bit for bit, and every
patch is cut at the same ``v`` values.  The topology is therefore known before any face is
made, and :func:`assemble_shell` builds it directly with ``BRep_Builder``:

* one vertex per distinct corner point of each boundary row;
* one edge per piece of each boundary row (the surface's exact ``u`` iso-curve, shared by the
  faces on both sides), or, where the piece's row is one pole, a degenerated edge of each face;
* one edge per cut of each patch (its exact ``v`` iso-curve, shared by the pieces on both
  sides), or a seam edge, used twice by its face, where a patch is one periodic piece;
* at an open end of the chain, one edge for a segment run there and back by two pieces (the
  capsule's slit: the way back's row is the way there's reversed, its p-curve ``v = c - t``);
* every p-curve a straight line of the face's parameter rectangle; along the rows it is a
  degree-1 B-spline with knots at the surface's C0/C1 ``v`` knots, which OCCT's mass
  properties need to integrate across them (see :mod:`tabletcad.cad.faces`);
* with ``flat``, one plane face per flat region (neighbouring patches in one plane), bounded by
  the rows round it; its pieces and the edges between them are not made.

Each 3-D curve is an iso-curve of one of the faces it bounds, with the same parameter as its
p-curves, so the edges are same-parameter by construction, and BRepCheck_Analyzer of the solid
checks it.  ``BRepBuilderAPI_Sewing`` found the same topology by searching for it and took most
of the solid's time on the shaped families (31 of 116 ms on a rounded rectangle of 72 faces).

A chain this cannot assemble - a segment whose way back is not its way there reversed, a cut
whose iso-curve is a point, rows that do not match - gives ``None``, and the caller sews.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from OCP.BRep import BRep_Builder
from OCP.BRepLib import BRepLib
from OCP.Geom import Geom_BSplineSurface
from OCP.Geom2d import Geom2d_Line
from OCP.gp import gp_Dir2d, gp_Pnt, gp_Pnt2d
from OCP.TopAbs import TopAbs_Orientation
from OCP.TopoDS import TopoDS_Edge, TopoDS_Face, TopoDS_Shell, TopoDS_Vertex, TopoDS_Wire

from tabletcad.brep.surface import BSplineSurfaceData
from tabletcad.cad.faces import iso_u_pcurve, v_breaks
from tabletcad.cad.planes import coplanar, plane_face_of_loops
from tabletcad.geometry.vectors import norm3

__all__ = ["assemble_shell"]

_FORWARD = TopAbs_Orientation.TopAbs_FORWARD
_REVERSED = TopAbs_Orientation.TopAbs_REVERSED
EDGE_TOL = 1e-7  # mm: Precision::Confusion, the tolerance MakeFace gives its edges


def _spread(points: np.ndarray) -> float:
    return float(np.max(norm3(points - points[0])))


def assemble_shell(pieces: Sequence[Sequence[BSplineSurfaceData]],
                   surfaces: Sequence[Sequence[Geom_BSplineSurface]] | Callable[[int, int], Geom_BSplineSurface],
                   tol_degen: float = 1e-7,
                   flat: Sequence[tuple[np.ndarray, np.ndarray] | None] | None = None):
    """The closed shell of a chain of faces, or None when it is not a chain this can assemble.

    Parameters
    ----------
    pieces : per patch, its pieces' data (:func:`tabletcad.brep.slit.chain_face_surfaces`):
        every patch has the same number of pieces over the same ``v`` ranges; one piece is
        the whole patch, periodic in ``v``.
    surfaces : the OCCT surfaces of the same pieces (:func:`tabletcad.cad.faces.make_geom_surface`), or
        ``surfaces(j, k)`` making patch ``j``'s piece ``k`` when asked (a flat region's pieces are not).
    tol_degen : float
        A boundary row whose poles stay within this distance (mm) of one point over a piece
        is a degenerated edge.
    flat : optional; per patch, ``(point, unit normal)`` of the plane holding its poles in its
        ``S_u x S_v`` sense (:func:`tabletcad.cad.planes.planes_of`), or None.  Neighbouring patches
        in one plane (a shaped tablet's flat centre and its ring; a land) cut into pieces are one
        flat region, made one plane face bounded by the row edges round it (:func:`_region_plane`):
        its pieces, their surfaces and the edges between them are not made.

    Returns
    -------
    ``(shell, faces, planes)`` - the shell (its faces all ``FORWARD``: the surfaces' own normals),
    its faces in the order of ``pieces`` (a flat region: its plane face, once) and how many of them
    are flat regions' planes - or None.
    """
    surface = surfaces if callable(surfaces) else (lambda j, k: surfaces[j][k])
    n_patch = len(pieces)
    n_piece = len(pieces[0]) if n_patch else 0
    if n_patch == 0 or any(len(p) != n_piece for p in pieces):
        return None
    periodic = n_piece == 1
    for p in pieces:
        for d in p:
            if d.u_periodic or d.v_periodic != periodic or d.u_mults[0] != d.u_degree + 1 \
                    or d.u_mults[-1] != d.u_degree + 1:
                return None
    v_ranges = [(float(d.v_knots[0]), float(d.v_knots[-1])) for d in pieces[0]]
    for p in pieces[1:]:  # every patch's piece k: the same v knots, multiplicities and degree
        for a, b in zip(pieces[0], p):
            if a.v_degree != b.v_degree or not (np.array_equal(a.v_knots, b.v_knots)
                                                and np.array_equal(a.v_mults, b.v_mults)):
                return None
    for j in range(n_patch - 1):  # neighbours share their rows, piece by piece
        for a, b in zip(pieces[j], pieces[j + 1]):
            if not np.array_equal(a.poles[-1], b.poles[0]):
                return None
    closed = all(np.array_equal(a.poles[-1], b.poles[0]) for a, b in zip(pieces[-1], pieces[0]))
    if closed and n_patch == 1:  # one patch closed on itself: its one row would bound it twice
        return None
    n_row = n_patch if closed else n_patch + 1
    # flat regions: runs of neighbouring patches in one plane (not across the closed chain's start)
    region = [-1] * n_patch
    if flat is not None and not periodic:
        for j in range(n_patch):
            if flat[j] is not None:
                region[j] = region[j - 1] if j > 0 and region[j - 1] >= 0 and coplanar(flat[j - 1], flat[j]) else j
    inner = [0 < r < n_patch and region[r] >= 0 and region[r] == region[r - 1] for r in range(n_row)]

    def row_data(r: int, k: int) -> tuple[BSplineSurfaceData, int, int]:
        """The piece whose boundary gives row ``r``, piece ``k``: its data, its patch and which of its rows
        (0 or -1): the patch's above the row, or below it where the one above is flat (a flat region's
        pieces' surfaces are made only where nothing else gives the row)."""
        below = r - 1 if r > 0 else (n_patch - 1 if closed else -1)
        if r < n_patch and (region[r] < 0 or below < 0 or region[below] >= 0):
            return pieces[r][k], r, 0
        return pieces[below][k], below, -1

    def ends(r: int, k: int) -> tuple[np.ndarray, np.ndarray]:
        """The points where row ``r``'s piece ``k`` starts and ends, mm: its end poles (clamped
        in ``v``), or the periodic row's point at the period's start, twice."""
        d, j, i = row_data(r, k)
        if not periodic:
            row = d.poles[i]
            return row[0], row[-1]
        q = surface(j, k).Value(float(d.u_knots[i]), v_ranges[k][0])
        p = np.array([q.X(), q.Y(), q.Z()])
        return p, p

    B = BRep_Builder()

    # ---- vertices: per row, per cut (the start of each piece); equal points share one vertex,
    # its tolerance the largest distance to the piece ends it stands for
    vertices: list[list[TopoDS_Vertex]] = []
    for r in range(n_row):
        se = [ends(r, k) for k in range(n_piece)]
        pool: list[list] = []  # [point, vertex, tolerance]
        row_v = []
        for k in range(n_piece):
            p = se[k][0]
            for item in pool:
                dist = float(np.linalg.norm(p - item[0]))
                if dist <= 10.0 * tol_degen:
                    item[2] = max(item[2], dist)
                    break
            else:
                item = [p, TopoDS_Vertex(), 0.0]
                pool.append(item)
            row_v.append(item)
        for k in range(n_piece):  # each piece ends where the next starts
            item = row_v[(k + 1) % n_piece]
            item[2] = max(item[2], float(np.linalg.norm(se[k][1] - item[0])))
        for p, v, tol in pool:
            B.MakeVertex(v, gp_Pnt(*p.tolist()), EDGE_TOL + 1.01 * tol)
        vertices.append([item[1] for item in row_v])

    # ---- row edges per row and piece: shared by the faces on both sides, or None where the
    # piece's row is one pole (each face gets its own degenerated edge there, as sewing leaves it)
    row_edges: list[list[TopoDS_Edge | None]] = []
    ranged: list[tuple[TopoDS_Edge, float, float]] = []  # every row edge, with its v range
    mirrored: dict[tuple[int, int], int] = {}  # (row, piece): the piece whose edge it runs back along
    for r in range(n_row):
        out: list[TopoDS_Edge | None] = []
        if inner[r]:  # inside a flat region: bounds no face
            row_edges.append(out)
            continue
        open_end = not closed and r in (0, n_row - 1)  # an end of the chain that is not one pole
        partner = _runs_back([row_data(r, k) for k in range(n_piece)], tol_degen) if open_end else {}
        for k in range(n_piece):
            d, j, i = row_data(r, k)
            v0, v1 = vertices[r][k], vertices[r][(k + 1) % n_piece]
            if _spread(np.asarray(d.poles[i])) <= tol_degen:
                if not v0.IsSame(v1):
                    return None
                out.append(None)
                continue
            if open_end:  # the capsule's slit: the same segment run there and back by two pieces
                m = partner.get(k)
                if m is None:
                    return None
                if m < k:  # the way back: the way there's edge, which ends where this piece starts
                    if not (v0.IsSame(vertices[r][(m + 1) % n_piece]) and v1.IsSame(vertices[r][m])):
                        return None
                    out.append(out[m])
                    mirrored[(r, k)] = m
                    continue
            e = TopoDS_Edge()
            B.MakeEdge(e, surface(j, k).UIso(float(d.u_knots[i])), EDGE_TOL)
            B.Add(e, v0.Oriented(_FORWARD))
            B.Add(e, v1.Oriented(_REVERSED))
            out.append(e)
            ranged.append((e, *v_ranges[k]))
        row_edges.append(out)

    def degenerated(r: int, k: int) -> TopoDS_Edge:
        e = TopoDS_Edge()
        B.MakeEdge(e)
        B.Degenerated(e, True)
        B.Add(e, vertices[r][k].Oriented(_FORWARD))
        B.Add(e, vertices[r][k].Oriented(_REVERSED))
        ranged.append((e, *v_ranges[k]))
        return e

    # ---- column edges: per patch and cut (the start of each piece); a periodic patch's seam
    # (its curve is piece k's; piece k - 1's side may differ where a collapsed row was snapped to
    # one pole, by at most its poles' difference: the edge's tolerance covers that)
    col_edges: list[list[TopoDS_Edge]] = []
    col_tol: list[list[float]] = []
    for j in range(n_patch):
        out, tols = [], []
        if region[j] >= 0:  # a flat region's cuts bound no face
            col_edges.append(out)
            col_tol.append(tols)
            continue
        for k in range(n_piece):
            d, s = pieces[j][k], surface(j, k)
            if _spread(np.asarray(d.poles)[:, 0]) <= tol_degen:
                return None
            tol = EDGE_TOL
            if not periodic:
                prev = pieces[j][(k - 1) % n_piece].poles[:, -1]
                if prev.shape != d.poles[:, 0].shape:
                    return None
                tol += 1.01 * float(np.max(norm3(prev - d.poles[:, 0])))
            e = TopoDS_Edge()
            B.MakeEdge(e, s.VIso(v_ranges[k][0]), tol)
            B.Add(e, vertices[j][k].Oriented(_FORWARD))
            B.Add(e, vertices[(j + 1) % n_row][k].Oriented(_REVERSED))
            out.append(e)
            tols.append(tol)
        col_edges.append(out)
        col_tol.append(tols)

    # ---- faces: the parameter rectangle, counter-clockwise; p-curves on each face
    shell = TopoDS_Shell()
    B.MakeShell(shell)
    faces = []
    planes: list[tuple[TopoDS_Face, list[TopoDS_Edge]]] = []
    for j in range(n_patch):
        if region[j] >= 0:
            if j + 1 < n_patch and region[j + 1] == region[j]:
                continue  # the region's face comes with its last patch
            made_plane = _region_plane(B, flat[j], row_edges[region[j]], row_edges[(j + 1) % n_row])
            if made_plane is None:
                return None
            B.Add(shell, made_plane[0])
            faces.append(made_plane[0])
            planes.append(made_plane)
            continue
        for k in range(n_piece):
            d, s = pieces[j][k], surface(j, k)
            u0, u1 = float(d.u_knots[0]), float(d.u_knots[-1])
            a, b = v_ranges[k]
            f = TopoDS_Face()
            B.MakeFace(f, s, EDGE_TOL)
            breaks = v_breaks(d.v_knots, d.v_mults, d.v_degree)
            low = row_edges[j][k] or degenerated(j, k)
            high = row_edges[(j + 1) % n_row][k] or degenerated((j + 1) % n_row, k)
            start, start_tol = col_edges[j][k], col_tol[j][k]
            back = set()  # rows whose edge runs back along the partner's: t in its range -> v = c - t
            for e, u, r in ((low, u0, j), (high, u1, (j + 1) % n_row)):
                m = mirrored.get((r, k))
                if m is None:
                    B.UpdateEdge(e, iso_u_pcurve(u, a, b, breaks), f, EDGE_TOL)
                else:
                    back.add(r)
                    B.UpdateEdge(e, iso_u_pcurve(u, v_ranges[m][0], v_ranges[m][1], breaks, mirror=a + v_ranges[m][1]),
                                 f, EDGE_TOL)
            if periodic:
                B.UpdateEdge(start, Geom2d_Line(gp_Pnt2d(0.0, a), gp_Dir2d(1.0, 0.0)),
                             Geom2d_Line(gp_Pnt2d(0.0, b), gp_Dir2d(1.0, 0.0)), f, start_tol)
                end = start
            else:
                end, end_tol = col_edges[j][(k + 1) % n_piece], col_tol[j][(k + 1) % n_piece]
                B.UpdateEdge(start, Geom2d_Line(gp_Pnt2d(0.0, a), gp_Dir2d(1.0, 0.0)), f, start_tol)
                B.UpdateEdge(end, Geom2d_Line(gp_Pnt2d(0.0, b), gp_Dir2d(1.0, 0.0)), f, end_tol)
            w = TopoDS_Wire()
            B.MakeWire(w)
            B.Add(w, start.Oriented(_FORWARD))
            B.Add(w, high.Oriented(_REVERSED if (j + 1) % n_row in back else _FORWARD))
            B.Add(w, end.Oriented(_REVERSED))
            B.Add(w, low.Oriented(_FORWARD if j in back else _REVERSED))
            B.Add(f, w)
            B.Add(shell, f)
            faces.append(f)

    # ---- ranges and flags, once every p-curve is in place
    for e, a, b in ranged:
        B.Range(e, a, b)
        B.SameRange(e, True)
        B.SameParameter(e, True)
    for j in range(n_patch):
        d = pieces[j][0]
        for e in col_edges[j]:
            B.Range(e, float(d.u_knots[0]), float(d.u_knots[-1]))
            B.SameRange(e, True)
            B.SameParameter(e, True)
    for f, edges in planes:  # stored, not recomputed by every reader of the face (tabletcad.cad.planes)
        for e in edges:
            BRepLib.BuildPCurveForEdgeOnPlane_s(e, f)
    shell.Closed(True)
    return shell, faces, len(planes)


def _region_plane(B: BRep_Builder, plane: tuple[np.ndarray, np.ndarray], low: Sequence[TopoDS_Edge | None],
                  high: Sequence[TopoDS_Edge | None]) -> tuple[TopoDS_Face, list[TopoDS_Edge]] | None:
    """A flat region's plane face (``plane``: point and unit normal, the patches' ``S_u x S_v`` sense),
    bounded by its first patch's ``low`` row and its last patch's ``high`` row, each a loop of its pieces'
    edges (a degenerated piece, None, leaves its vertex: the loop goes on from it; an edge run there and
    back, a slit, lies inside the region), run as the patches' faces ran them: ``high`` forward, ``low``
    back.  A row that is one point (a pole, all None) or bounds no face (``[]``) gives no loop; None when
    neither gives one.  Returns the face and its edges, whose
    p-curves on the plane the caller stores once every edge has its range."""
    loops, bounding = [], []
    for row, forward in ((high, True), (low, False)):
        edges = [e for e in row if e is not None]
        # a segment run there and back (the capsule's slit: one edge twice) lies inside the region
        edges = [e for e in edges if sum(e.IsSame(o) for o in edges) == 1]
        bounding += edges
        if edges:
            loops.append([e.Oriented(_FORWARD) for e in edges] if forward
                         else [e.Oriented(_REVERSED) for e in reversed(edges)])
    if not loops:
        return None
    return plane_face_of_loops(plane, loops, EDGE_TOL), bounding


def _runs_back(rows: Sequence[tuple[BSplineSurfaceData, int, int]], tol_degen: float) -> dict[int, int]:
    """At an open end of the chain (``rows``: each piece's data, patch and which of its rows gives the end), the
    pieces whose row runs back along another's: ``{k: m}`` both ways, for each piece whose row moves
    (``_spread`` > ``tol_degen``) and has exactly one partner whose row poles are its own reversed (to
    ``tol_degen``) over a knot sequence that is its own mirrored (to 1e-12), so that ``v_m = c - v_k``
    along the shared segment.  A moving row without one such partner is left out (the caller gives up)."""
    runs = [k for k, (d, _, i) in enumerate(rows) if _spread(np.asarray(d.poles[i])) > tol_degen]
    out: dict[int, int] = {}
    for k in runs:
        dk, _, ik = rows[k]
        Pk = np.asarray(dk.poles[ik])
        found = []
        for m in runs:
            dm, _, im = rows[m]
            Pm = np.asarray(dm.poles[im])
            if m == k or Pm.shape != Pk.shape or len(dm.v_knots) != len(dk.v_knots):
                continue
            if float(np.max(norm3(Pk - Pm[::-1]))) > tol_degen:
                continue
            if not (np.allclose(np.diff(dk.v_knots), np.diff(dm.v_knots)[::-1], rtol=0.0, atol=1e-12)
                    and np.array_equal(dk.v_mults, dm.v_mults[::-1])):
                continue
            found.append(m)
        if len(found) == 1:
            out[k] = found[0]
    return out
