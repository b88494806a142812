"""Flat B-spline faces of a solid as exact planes.

A tablet's flat regions (a shaped family's plateau, a flat face cut into pieces where its
spine collapses: :mod:`tabletcad.brep.slit`) are B-spline faces whose poles lie in one plane,
so the surface lies in it exactly.  Handed to other tools as B-splines they are a trap:
``ShapeUpgrade_UnifySameDomain``, which build123d's Booleans and ``clean()`` and
CadQuery's ``clean=True`` run after every operation, merges coplanar faces, and on
OCCT 7.9 it crashed the process (a segmentation fault) on such pieces with a pole at a
collapsed end (the oval, almond, rounded triangle, square and rectangle, modified capsule).
As ``Geom_Plane`` faces bounded by the same edges they merge cleanly, and a CAD user gets
the planes they expect.

Faces of revolution whose profile is flat (a round's disc) are replaced too.  A face is
replaced only when it has one wire and every edge of it lies in the plane; its pole's
degenerate edge and its seam bound no region and are left out.  The solid with its planes
must be valid, else it is returned unchanged.

Each plane face is built with ``BRep_Builder`` from the B-spline face's own edges, in their own
order and orientation (the plane's normal is the surface's ``S_u × S_v`` sense, so the loop that
bounded the B-spline face bounds the same region of the plane; a plane turned the other way
fails ``BRepCheck_Analyzer``, and the solid is then kept as made; edges that do not chain vertex
to vertex go to ``BRepBuilderAPI_MakeWire`` and ``MakeFace`` as before), and each edge gets its p-curve
on the plane stored (``BRepLib::BuildPCurveForEdgeOnPlane``, the exact projection of its 3D
curve).  OCC computes a plane's p-curves on the fly when none is stored, every time a check,
an exporter or a mesher asks: ``BRepCheck_Analyzer`` of the rounded square's solid took
17 ms with them computed so, 13.5 ms with them stored.  ``BRepBuilderAPI_MakeFace(plane, wire,
Inside=True)``, which classified the wire's inside once more, had taken 6.8 of the 21 ms the
planes took (2026-12-06).  The faces are held as ``MakeFace`` held them (:func:`_plane_face`):
the STEP files are the same but for the last digits of the planes' origins.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence

import numpy as np
from OCP.BRep import BRep_Builder, BRep_Tool
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakeWire
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepLib import BRepLib
from OCP.BRepTools import BRepTools_ReShape, BRepTools_WireExplorer
from OCP.Geom import Geom_BSplineSurface, Geom_Plane, Geom_SurfaceOfRevolution
from OCP.gp import gp_Ax3, gp_Dir, gp_Pln, gp_Pnt
from OCP.Standard import Standard_Failure
from OCP.TopAbs import TopAbs_Orientation
from OCP.TopExp import TopExp
from OCP.TopoDS import TopoDS_Edge, TopoDS_Face, TopoDS_Iterator, TopoDS_Shape, TopoDS_Wire

from tabletcad.cad._occ import cast, explore

__all__ = ["coplanar", "flat_faces_as_planes", "made_poles", "plane_axes", "plane_face_of_loops", "plane_of",
           "planes_of"]

Plane = tuple[np.ndarray, np.ndarray]  # (point (3,) mm, unit normal (3,))

#: poles this far from their plane (relative to the face's size) still make a flat face
FLAT_REL_TOL = 1e-12
#: and each of its edges this far from that plane (mm)
EDGE_PLANE_TOL_MM = 1e-9


def plane_of(surf: Geom_BSplineSurface, poles: np.ndarray | None = None) -> Plane | None:
    """``(point, unit normal)`` of the plane holding every pole of ``surf`` (the surface's own
    normal ``S_u × S_v`` sense), or None when the poles are not coplanar to :data:`FLAT_REL_TOL`
    of their extent.  A B-spline surface (rational or not) is an affine combination of its
    poles, so coplanar poles make it lie in their plane exactly.  ``poles``: the surface's
    ``(NbUPoles, NbVPoles, 3)`` poles (mm) when the caller made it from them (read from OCC
    one by one otherwise, 3 µs a pole).  One surface's :func:`planes_of`."""
    return planes_of([_poles(surf) if poles is None else poles])[0]


def _poles(surf: Geom_BSplineSurface) -> np.ndarray:
    """The ``(NbUPoles, NbVPoles, 3)`` poles of ``surf`` (mm), read from OCC one by one."""
    nu, nv = surf.NbUPoles(), surf.NbVPoles()
    return np.array([[surf.Pole(i, j).Coord() for j in range(1, nv + 1)] for i in range(1, nu + 1)])


def planes_of(nets: Sequence[np.ndarray]) -> list[Plane | None]:
    """:func:`plane_of` of each pole net ``(nu, nv, 3)`` (mm) in ``nets``, the nets of one shape
    stacked into one singular value decomposition (a tablet's pieces come in a few shapes:
    0.8 ms for the rounded square's 56 faces in two shapes, against 5 ms one by one).

    Each net's test is the one surface's: its poles' centre ``c`` and extent ``size`` (the
    largest coordinate range); the plane's normal ``n`` is the singular vector of the least
    singular value of the centred poles; the net is flat when ``size > 0``, the middle singular
    value exceeds ``1e-9 size`` (not a line) and every pole lies within
    ``FLAT_REL_TOL max(size, 1 mm)`` of the plane.  ``n`` then takes the sense of the net's
    polygon normals summed (``S_u × S_v``: the face's orientation), None if they sum to zero.
    """
    out: list[Plane | None] = [None] * len(nets)
    groups: dict[tuple[int, ...], list[int]] = {}
    for k, P in enumerate(nets):
        groups.setdefault(np.shape(P), []).append(k)
    for shape, ks in groups.items():
        P = np.stack([np.asarray(nets[k], dtype=float) for k in ks])  # (g, nu, nv, 3)
        for k, plane in zip(ks, _planes_of_stack(P)):
            out[k] = plane
    return out


def _planes_of_stack(P: np.ndarray) -> list[Plane | None]:
    """:func:`planes_of` for nets of one shape, stacked ``(g, nu, nv, 3)``; the reductions run over
    the last, contiguous axis of each coordinate's ``(g, nu nv)`` array."""
    g = P.shape[0]
    X = np.ascontiguousarray(P.reshape(g, -1, 3).transpose(2, 0, 1))  # (3, g, poles)
    c = X.mean(axis=2)  # (3, g)
    size = np.max(X.max(axis=2) - X.min(axis=2), axis=0)
    D = X - c[:, :, None]
    _, s, vt = np.linalg.svd(D.transpose(1, 2, 0), full_matrices=False)
    n = vt[:, 2]  # (g, 3)
    off = np.max(np.abs(D[0] * n[:, :1] + D[1] * n[:, 1:2] + D[2] * n[:, 2:]), axis=1)
    flat = (size > 0.0) & (s[:, 1] > 1e-9 * size) & (off <= FLAT_REL_TOL * np.maximum(size, 1.0))
    out: list[Plane | None] = [None] * g
    if not flat.any():
        return out
    # the surface's own normal: the polygon's cross products summed over the net (orientation of the face)
    F = P[flat]
    du, dv = F[:, 1:, :-1] - F[:, :-1, :-1], F[:, :-1, 1:] - F[:, :-1, :-1]
    sense = np.einsum("gk,gk->g", np.cross(du, dv).sum(axis=(1, 2)), n[flat])
    for k, sg in zip(np.flatnonzero(flat), sense):
        if sg != 0.0:
            out[k] = (c[:, k].copy(), n[k] if sg > 0 else -n[k])
    return out


def made_poles(pairs: Iterable[tuple[Geom_BSplineSurface, np.ndarray]]) -> dict[int, tuple[Geom_BSplineSurface, np.ndarray]]:
    """The ``made`` mapping of :func:`flat_faces_as_planes` for ``(surface, poles)`` pairs; it holds
    the surfaces, so an ``id`` cannot be reused while it lives."""
    return {id(g): (g, p) for g, p in pairs}


def _revolved_plane_of(surf) -> tuple[np.ndarray, np.ndarray] | None:
    """``(point, unit normal)`` of a surface of revolution whose profile's poles lie in one plane normal to its
    axis (a round flat face: the disc), in the surface's own normal sense; else None."""
    from OCP.Geom import Geom_BSplineCurve
    from OCP.gp import gp_Vec

    basis = surf.BasisCurve()
    if not isinstance(basis, Geom_BSplineCurve):
        return None
    ax = surf.Axis()
    o, d = np.array(ax.Location().Coord()), np.array(ax.Direction().Coord())
    P = np.array([basis.Pole(i).Coord() for i in range(1, basis.NbPoles() + 1)])
    h = (P - o) @ d
    size = float(np.max(np.ptp(P, axis=0)))
    if size == 0.0 or float(np.ptp(h)) > FLAT_REL_TOL * max(size, 1.0):
        return None
    u0, u1, v0, v1 = surf.Bounds()
    for fv in (0.5, 0.25, 0.75):  # the normal's sense where the profile is off the axis
        p, du, dv = gp_Pnt(), gp_Vec(), gp_Vec()
        surf.D1(u0 + 0.3 * (u1 - u0), v0 + fv * (v1 - v0), p, du, dv)
        sense = float(np.array(du.Crossed(dv).Coord()) @ d)
        if abs(sense) > 1e-12:
            return o + float(np.mean(h)) * d, (d if sense > 0 else -d)
    return None


EdgeSamples = dict[int, tuple[TopoDS_Edge, np.ndarray | None]]  # hash(edge) -> (edge, its samples)


def _edge_samples(edge: TopoDS_Edge, samples: int, cache: EdgeSamples) -> np.ndarray | None:
    """The edge's 3D curve (``BRep_Tool::Curve``, placed by the edge's location) at ``samples`` equally
    spaced parameters of its range, ``(samples, 3)`` mm, or None when it has no 3D curve; kept in
    ``cache`` (by ``hash``, which is ``IsSame``'s: an edge between two plane faces is read once)."""
    key = hash(edge)
    hit = cache.get(key)
    if hit is not None and hit[0].IsSame(edge) and (hit[1] is None or len(hit[1]) == samples):
        return hit[1]
    curve = BRep_Tool.Curve_s(edge, 0.0, 0.0)
    x = None
    if curve is not None:
        a, b = BRep_Tool.Range_s(edge)
        value, h = curve.Value, (b - a) / (samples - 1)
        x = np.array([value(a + h * k).Coord() for k in range(samples - 1)] + [value(b).Coord()])
    cache[key] = (edge, x)
    return x


def _edges_in_plane(edges: Sequence[TopoDS_Edge], point: np.ndarray, normal: np.ndarray, samples: int = 9,
                    cache: EdgeSamples | None = None) -> bool:
    """True when every edge's 3D curve lies in the plane through ``point`` (mm) normal to ``normal``
    to :data:`EDGE_PLANE_TOL_MM` at ``samples`` equally spaced parameters of its range
    (:func:`_edge_samples`, read once per edge with ``cache``), the distances taken in one numpy
    product; False for an edge without a 3D curve.  (An edge shared with a face whose poles were
    moved, such as a collapsed corner's snapped row, may not lie in it: the plane face bounded by
    it would then enclose another region than the B-spline face did.)"""
    cache = {} if cache is None else cache
    x = [_edge_samples(e, samples, cache) for e in edges]
    if not x or any(p is None for p in x):
        return False
    return float(np.max(np.abs((np.concatenate(x) - point) @ normal))) <= EDGE_PLANE_TOL_MM


def _boundary(face: TopoDS_Face) -> tuple[list[TopoDS_Edge], bool] | None:
    """The edges of ``face`` that bound a region, in their wire's order and with their orientation in
    the face (``BRepTools_WireExplorer``): its one wire's edges but degenerated ones (a pole's) and a seam
    (a round flat face's, the edge twice in the wire); and whether they make one loop, each edge
    starting at the vertex where the one before ends.  None when the face has another number of
    wires, an edge twice that is no seam (a slit), or no edge left."""
    wires = []
    it = TopoDS_Iterator(face)
    while it.More():
        wires.append(it.Value())
        it.Next()
    if len(wires) != 1:
        return None
    edges: list[TopoDS_Edge] = []
    walk = BRepTools_WireExplorer(cast(wires[0], "Wire"), face)
    while walk.More():
        e = walk.Current()
        walk.Next()
        if BRep_Tool.Degenerated_s(e) or BRep_Tool.IsClosed_s(e, face):
            continue
        if any(e.IsSame(o) for o in edges):
            return None  # an edge twice that is no seam (a slit): not a plain boundary
        edges.append(e)
    if not edges:
        return None
    loop = all(TopExp.LastVertex_s(e, True).IsSame(TopExp.FirstVertex_s(nxt, True))
               for e, nxt in zip(edges, edges[1:] + edges[:1]))
    return edges, loop


def _plane_face(face: TopoDS_Face, point: np.ndarray, normal: np.ndarray,
                cache: EdgeSamples | None = None,
                found: tuple[list[TopoDS_Edge], bool] | None = None) -> TopoDS_Face | None:
    """``face`` rebuilt on its plane from its own edges, with its orientation; the edges that bound no
    region are left out (:func:`_boundary`), so a disc becomes the plane inside its circle.  ``normal``
    must be the face's surface normal sense (:func:`plane_of`): the loop then runs round the region
    on the plane as on the surface.  Each edge gets its p-curve on the plane stored.  None when the
    face has more than one wire, an edge is off the plane, or (:func:`_made_face`) what is left is
    not one closed wire (``cache``: the edges' samples, :func:`_edge_samples`; ``found``: the face's
    :func:`_boundary`, if known).

    The wire holds the edges as the face (in the solid) runs them, and a reversed face holds it
    reversed: the structure ``BRepBuilderAPI_MakeFace(plane, wire, Inside=True)`` made (it reversed
    the wire of a reversed face to bound the finite region).  The same bound held the other way
    round (the wire of the face taken forward) is as valid, but OCC's STEP reader turned the almond
    cut-away's solid inside out when one of its planes was written so."""
    found = _boundary(face) if found is None else found
    if found is None or not _edges_in_plane(found[0], point, normal, cache=cache):
        return None
    edges, loop = found
    if not loop:
        return _made_face(edges, point, normal, face)
    B = BRep_Builder()
    wire = TopoDS_Wire()
    B.MakeWire(wire)
    for e in edges:
        B.Add(wire, e)
    wire.Closed(True)
    new = TopoDS_Face()
    B.MakeFace(new, Geom_Plane(plane_axes(point, normal)), 1e-7)
    B.Add(new, wire if face.Orientation() == TopAbs_Orientation.TopAbs_FORWARD else wire.Reversed())
    for e in edges:  # stored, not recomputed by every reader of the face
        BRepLib.BuildPCurveForEdgeOnPlane_s(e, new)
    new.Orientation(face.Orientation())
    return new


def plane_face_of_loops(plane: Plane, loops: Sequence[Sequence[TopoDS_Shape]], tol: float,
                        reversed_wires: bool = False) -> TopoDS_Face:
    """A face on ``plane`` (point and unit normal, mm) bounded by ``loops``, each a closed chain of edges held
    with the orientation the wire runs them (``reversed_wires``: each wire held reversed, as a reversed face
    holds its loop), built with ``BRep_Builder`` (no classification); ``tol``: the face's tolerance (mm)."""
    B = BRep_Builder()
    f = TopoDS_Face()
    B.MakeFace(f, Geom_Plane(plane_axes(*plane)), tol)
    for loop in loops:
        w = TopoDS_Wire()
        B.MakeWire(w)
        for e in loop:
            B.Add(w, e)
        w.Closed(True)
        B.Add(f, w.Reversed() if reversed_wires else w)
    return f


def plane_axes(point: np.ndarray, normal: np.ndarray) -> gp_Ax3:
    """The plane's axes: origin ``point`` (mm), main direction ``normal``, OCC's x direction for it."""
    return gp_Ax3(gp_Pnt(*map(float, point)), gp_Dir(*map(float, normal)))


def _made_face(edges: Sequence[TopoDS_Edge], point: np.ndarray, normal: np.ndarray,
               face: TopoDS_Face) -> TopoDS_Face | None:
    """The plane face ``BRepBuilderAPI_MakeWire`` and ``BRepBuilderAPI_MakeFace(plane, wire, Inside=True)``
    make of ``edges`` (which do not chain vertex to vertex), with the orientation of ``face``, or None
    when they make no closed wire: edges in two loops (a flat ring's two circles) fail, and
    MakeWire joins a gap between distinct vertices at one point (a degenerated edge between two,
    left out: the almond's and the rounded square's cut-aways) with new edges, whose solid then fails
    its check and keeps its B-spline faces, as it did before the faces were built here."""
    mw = BRepBuilderAPI_MakeWire()
    for e in edges:
        mw.Add(e)
    if not mw.IsDone() or not BRep_Tool.IsClosed_s(mw.Wire()):
        return None
    mf = BRepBuilderAPI_MakeFace(gp_Pln(plane_axes(point, normal)), mw.Wire(), True)
    if not mf.IsDone():
        return None
    new = mf.Face()
    new.Orientation(face.Orientation())
    return new


def coplanar(a: Plane, b: Plane) -> bool:
    """True when planes ``a`` and ``b`` are one plane with one normal sense (to :data:`EDGE_PLANE_TOL_MM`
    over 1 mm)."""
    return float(a[1] @ b[1]) >= 1.0 - 1e-12 and abs(float((b[0] - a[0]) @ a[1])) <= EDGE_PLANE_TOL_MM


def _flat_regions(flat: Sequence[tuple[TopoDS_Face, Plane, tuple[list[TopoDS_Edge], bool]]]) -> list[list[int]]:
    """The indices of ``flat`` (faces with their plane and :func:`_boundary`) in groups:
    faces that share an edge, lie in one plane and are oriented alike in the solid are one flat region;
    each group in the order of ``flat``, the groups in the order of their first face."""
    parent = list(range(len(flat)))

    def root(k: int) -> int:
        while parent[k] != k:
            parent[k] = parent[parent[k]]
            k = parent[k]
        return k

    owner: dict[int, list[tuple[TopoDS_Edge, int]]] = {}
    for k, (face, plane, (edges, _)) in enumerate(flat):
        for e in edges:
            for other, j in owner.setdefault(hash(e), []):
                fj, pj, _ = flat[j]
                if j != k and other.IsSame(e) and fj.Orientation() == face.Orientation() and coplanar(pj, plane):
                    parent[root(k)] = root(j)
            owner[hash(e)].append((e, k))
    groups: dict[int, list[int]] = {}
    for k in range(len(flat)):
        groups.setdefault(root(k), []).append(k)
    return sorted(groups.values(), key=lambda g: g[0])


def _region_loops(edge_lists: Sequence[Sequence[TopoDS_Edge]]) -> list[list[TopoDS_Edge]] | None:
    """The loops bounding the union of faces whose boundary edges (each face's in its wire's order and
    orientation) are ``edge_lists``: an edge run by two of the faces, in opposite senses, is inside the union
    and left out; the others are chained vertex to vertex into closed loops, each edge starting where the one
    before ends.  None when an edge is run twice in one sense or by more than two faces, or the edges left do
    not make loops with one edge leaving each vertex."""
    seen: dict[int, list[TopoDS_Edge]] = {}
    for edges in edge_lists:
        for e in edges:
            seen.setdefault(hash(e), []).append(e)
    kept: list[TopoDS_Edge] = []
    for edges in edge_lists:
        for e in edges:
            same = [o for o in seen[hash(e)] if o.IsSame(e)]
            if len(same) == 1:
                kept.append(e)
            elif len(same) != 2 or same[0].Orientation() == same[1].Orientation():
                return None
    leaving: dict[int, list[TopoDS_Edge]] = {}
    for e in kept:
        leaving.setdefault(hash(TopExp.FirstVertex_s(e, True)), []).append(e)
    if any(len(v) != 1 for v in leaving.values()) or len(leaving) != len(kept):
        return None
    loops, used = [], set()
    for e in kept:
        if id(e) in used:
            continue
        loop, start, cur = [], TopExp.FirstVertex_s(e, True), e
        while True:
            loop.append(cur)
            used.add(id(cur))
            end = TopExp.LastVertex_s(cur, True)
            if end.IsSame(start):
                break
            nxt = leaving.get(hash(end))
            if not nxt or id(nxt[0]) in used or not TopExp.FirstVertex_s(nxt[0], True).IsSame(end):
                return None
            cur = nxt[0]
        loops.append(loop)
    return loops if len(used) == len(kept) else None


def _region_face(faces: Sequence[TopoDS_Face], point: np.ndarray, normal: np.ndarray,
                 edge_lists: Sequence[Sequence[TopoDS_Edge]], cache: EdgeSamples) -> TopoDS_Face | None:
    """One plane face for a flat region made of several ``faces`` (:func:`_flat_regions`): bounded by the
    loops of the edges that bound their union (:func:`_region_loops`), each edge checked to lie in the plane,
    held as :func:`_plane_face` holds one face's loop (a land's outer and inner loops are two wires); the
    region's orientation is its faces'.  None when the loops cannot be made or an edge is off the plane."""
    loops = _region_loops(edge_lists)
    if loops is None or not _edges_in_plane([e for lp in loops for e in lp], point, normal, cache=cache):
        return None
    forward = faces[0].Orientation() == TopAbs_Orientation.TopAbs_FORWARD
    new = plane_face_of_loops((point, normal), loops, 1e-7, reversed_wires=not forward)
    for loop in loops:
        for e in loop:
            BRepLib.BuildPCurveForEdgeOnPlane_s(e, new)
    new.Orientation(faces[0].Orientation())
    return new


def flat_faces_as_planes(solid: TopoDS_Shape, check: bool = True,
                         made: Mapping[int, tuple[Geom_BSplineSurface, np.ndarray]] | None = None,
                         merge: bool = True) -> tuple[TopoDS_Shape, int, BRepTools_ReShape | None]:
    """``(solid, n, reshape)``: ``solid`` with its flat B-spline faces and flat faces of revolution replaced
    by plane faces (``n`` plane faces in the result; ``reshape.Value(face)`` is a face's replacement, a null
    shape for a face merged into another's), or ``(solid, 0, None)``
    unchanged when there are none or the result is not a valid solid
    (``BRepCheck_Analyzer``: a face turned the wrong way fails it; ``check`` false leaves that check to the
    caller, who checks the solid anyway).  Each plane face is bounded by the
    B-spline faces' own edges, so the solid encloses the same volume (the CAD stage's cross-check of
    the solid's volume against the surface data's holds it to that).

    With ``merge``, flat faces that share an edge and lie in one plane (a shaped tablet's plateau and
    land, made in pieces where the chain is cut: :mod:`tabletcad.brep.slit`) become one plane face per
    flat region (:func:`_region_face`): a CAD user selects the flat face as one face, and every reader
    of the solid has fewer faces to go through (the rounded rectangle's 72 faces are 28; its check and
    STEP transfer were 21 and 36 ms with 48 plane pieces, 9 and 22 ms with four planes).  A region whose
    loops cannot be made keeps its pieces, each a plane.

    ``made``: ``id(surface) -> (surface, poles)`` for the B-spline surfaces the caller made from numpy
    poles (:func:`made_poles`); a face on one of them (the very object) is tested on those poles."""
    made = made or {}
    rs = BRepTools_ReShape()
    n = 0
    try:
        faces = explore(solid, "Face")
        planes: list[Plane | None] = [None] * len(faces)
        nets, at = [], []
        for k, f in enumerate(faces):
            surf = BRep_Tool.Surface_s(f)
            if isinstance(surf, Geom_BSplineSurface):
                hit = made.get(id(surf))
                nets.append(hit[1] if hit is not None and hit[0] is surf else _poles(surf))
                at.append(k)
            elif isinstance(surf, Geom_SurfaceOfRevolution):
                planes[k] = _revolved_plane_of(surf)
        for k, plane in zip(at, planes_of(nets)):
            planes[k] = plane
        cache: EdgeSamples = {}
        flat = []  # (face, plane, its boundary: edges and whether they chain) of the flat faces with a plain one
        for f, plane in zip(faces, planes):
            found = None if plane is None else _boundary(f)
            if found is not None:
                flat.append((f, plane, found))
        for group in _flat_regions(flat) if merge else [[k] for k in range(len(flat))]:
            members = [flat[k] for k in group]
            new = None
            if len(members) > 1:
                new = _region_face([m[0] for m in members], *members[0][1], [m[2][0] for m in members], cache)
            if new is not None:
                rs.Replace(members[0][0], new)
                for m in members[1:]:
                    rs.Remove(m[0])
                n += 1
                continue
            for f, plane, found in members:
                one = _plane_face(f, *plane, cache, found)
                if one is not None:
                    rs.Replace(f, one)
                    n += 1
        if not n:
            return solid, 0, None
        out = cast(rs.Apply(solid), "Solid")
    except (Standard_Failure, ValueError):
        return solid, 0, None
    if out.IsNull() or (check and not BRepCheck_Analyzer(out).IsValid()):
        return solid, 0, None
    return out, n, rs
