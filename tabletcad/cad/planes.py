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
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakeWire
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepTools import BRepTools_ReShape, BRepTools_WireExplorer
from OCP.Geom import Geom_BSplineSurface, Geom_SurfaceOfRevolution
from OCP.gp import gp_Ax3, gp_Dir, gp_Pln, gp_Pnt
from OCP.Standard import Standard_Failure
from OCP.TopoDS import TopoDS_Face, TopoDS_Shape

from tabletcad.cad._occ import cast, explore

__all__ = ["flat_faces_as_planes", "made_poles", "plane_of"]

#: poles this far from their plane (relative to the face's size) still make a flat face
FLAT_REL_TOL = 1e-12
#: and each of its edges this far from that plane (mm)
EDGE_PLANE_TOL_MM = 1e-9


def plane_of(surf: Geom_BSplineSurface, poles: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray] | None:
    """``(point, unit normal)`` of the plane holding every pole of ``surf`` (the surface's own
    normal ``S_u × S_v`` sense), or None when the poles are not coplanar to :data:`FLAT_REL_TOL`
    of their extent.  A B-spline surface (rational or not) is an affine combination of its
    poles, so coplanar poles make it lie in their plane exactly.  ``poles``: the surface's
    ``(NbUPoles, NbVPoles, 3)`` poles (mm) when the caller made it from them (read from OCC
    one by one otherwise, 3 µs a pole)."""
    if poles is not None:
        P = np.asarray(poles, dtype=float)
    else:
        nu, nv = surf.NbUPoles(), surf.NbVPoles()
        P = np.array([[surf.Pole(i, j).Coord() for j in range(1, nv + 1)] for i in range(1, nu + 1)])
    pts = P.reshape(-1, 3)
    c = pts.mean(axis=0)
    size = float(np.max(np.ptp(pts, axis=0)))
    if size == 0.0:
        return None
    _, s, vt = np.linalg.svd(pts - c, full_matrices=False)
    n = vt[2]
    if s[1] <= 1e-9 * size or float(np.max(np.abs((pts - c) @ n))) > FLAT_REL_TOL * max(size, 1.0):
        return None
    # the surface's own normal: the polygon's cross products summed over the net (orientation of the face)
    du, dv = P[1:, :-1] - P[:-1, :-1], P[:-1, 1:] - P[:-1, :-1]
    sense = float(np.sum(np.cross(du, dv) @ n))
    if sense == 0.0:
        return None
    return c, (n if sense > 0 else -n)


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


def _in_plane(edge, point: np.ndarray, normal: np.ndarray, samples: int = 9) -> bool:
    """True when the edge's 3D curve lies in the plane to :data:`EDGE_PLANE_TOL_MM` at ``samples`` points
    (an edge shared with a face whose poles were moved, such as a collapsed corner's snapped row, may not:
    the plane face bounded by it would then enclose another region than the B-spline face did)."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve

    curve = BRepAdaptor_Curve(edge)
    value = curve.Value
    x = np.array([value(t).Coord() for t in np.linspace(curve.FirstParameter(), curve.LastParameter(), samples).tolist()])
    return float(np.max(np.abs((x - point) @ normal))) <= EDGE_PLANE_TOL_MM


def _plane_face(face: TopoDS_Face, point: np.ndarray, normal: np.ndarray) -> TopoDS_Face | None:
    """``face`` rebuilt on its plane from its own edges, with its orientation; the edges that bound no
    region are left out: degenerate ones (a pole's) and a seam (a round flat face's, the edge twice in the
    wire), so a disc becomes the plane inside its circle.  None when it has more than one wire or what
    is left is not one closed wire."""
    wires = explore(face, "Wire")
    if len(wires) != 1:
        return None
    edges = []
    it = BRepTools_WireExplorer(wires[0], face)
    while it.More():
        edges.append(it.Current())
        it.Next()
    mw = BRepBuilderAPI_MakeWire()
    for k, e in enumerate(edges):
        if BRep_Tool.Degenerated_s(e) or BRep_Tool.IsClosed_s(e, face):
            continue
        if any(e.IsSame(o) for o in edges[:k]):
            return None  # an edge twice that is no seam (a slit): not a plain boundary
        if not _in_plane(e, point, normal):
            return None
        mw.Add(e)
    if not mw.IsDone() or not BRep_Tool.IsClosed_s(mw.Wire()):
        return None
    pln = gp_Pln(gp_Ax3(gp_Pnt(*map(float, point)), gp_Dir(*map(float, normal))))
    mf = BRepBuilderAPI_MakeFace(pln, mw.Wire(), True)
    if not mf.IsDone():
        return None
    new = mf.Face()
    new.Orientation(face.Orientation())
    return new


def flat_faces_as_planes(solid: TopoDS_Shape, check: bool = True,
                         made: Mapping[int, tuple[Geom_BSplineSurface, np.ndarray]] | None = None,
                         ) -> tuple[TopoDS_Shape, int, BRepTools_ReShape | None]:
    """``(solid, n, reshape)``: ``solid`` with its flat B-spline faces and flat faces of revolution replaced
    by plane faces (``n`` of them; ``reshape.Value(face)`` is a face's replacement), or ``(solid, 0, None)``
    unchanged when there are none or the result is not a valid solid
    (``BRepCheck_Analyzer``: a face turned the wrong way fails it; ``check`` false leaves that check to the
    caller, who checks the solid anyway).  Each plane face is bounded by the
    B-spline face's own edges, so the solid encloses the same volume (the CAD stage's cross-check of
    the solid's volume against the surface data's holds it to that).

    ``made``: ``id(surface) -> (surface, poles)`` for the B-spline surfaces the caller made from numpy
    poles (:func:`made_poles`); a face on one of them (the very object) is tested on those poles."""
    made = made or {}
    rs = BRepTools_ReShape()
    n = 0
    try:
        for f in explore(solid, "Face"):
            surf = BRep_Tool.Surface_s(f)
            if isinstance(surf, Geom_BSplineSurface):
                hit = made.get(id(surf))
                plane = plane_of(surf, hit[1] if hit is not None and hit[0] is surf else None)
            elif isinstance(surf, Geom_SurfaceOfRevolution):
                plane = _revolved_plane_of(surf)
            else:
                continue
            new = None if plane is None else _plane_face(f, *plane)
            if new is not None:
                rs.Replace(f, new)
                n += 1
        if not n:
            return solid, 0, None
        out = cast(rs.Apply(solid), "Solid")
    except (Standard_Failure, ValueError):
        return solid, 0, None
    if out.IsNull() or (check and not BRepCheck_Analyzer(out).IsValid()):
        return solid, 0, None
    return out, n, rs
