"""Exact OCC Booleans on solids, each cross-checked with manifold3d on meshes.

:func:`boolean` runs ``BRepAlgoAPI_Cut/Fuse/Common`` (non-destructive,
parallel), merges faces split on the same surface
(``ShapeUpgrade_UnifySameDomain``) and insists on exactly one solid that
passes ``BRepCheck_Analyzer``.  :func:`checked_boolean` repeats the operation
on manifold3d meshes (``Mesh64``, tessellated by :func:`tabletcad.cad.mesh.triangulate`)
and compares the volume removed or added: a triangulation with chord height
``d`` misplaces each surface by at most ``d``, so the two volume changes may
differ by about ``d`` times the area of the tool's surface (``bound_mm3``).
:func:`split_cells` gets one piece of such a result from ``BRepAlgoAPI_Splitter`` with only the
faces that bound it (a punch tip: the prism split by the tablet's face, not by its band).
Meshes, manifolds, volumes and areas are computed once per shape (:data:`CACHE`).
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from OCP.BRepAlgoAPI import BRepAlgoAPI_Common, BRepAlgoAPI_Cut, BRepAlgoAPI_Fuse
from OCP.BRepBuilderAPI import BRepBuilderAPI_Transform
from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
from OCP.gp import gp_Pnt, gp_Trsf, gp_Vec
from OCP.ShapeUpgrade import ShapeUpgrade_UnifySameDomain
from OCP.TopoDS import TopoDS_Shape

from tabletcad.cad._occ import cast, explore
from tabletcad.cad.content import content_key
from tabletcad.cad.solid import check_solid, mass_properties
from tabletcad.errors import GeometryError
from tabletcad.io.forked import OCC_PARALLEL
from tabletcad.tooling.shape_cache import ShapeCache, frozen

try:  # OCP >= 8.0
    from OCP.collections import List_TopoDS_Shape as _ShapeList
except ImportError:  # pragma: no cover - OCP 7.x
    from OCP.TopTools import TopTools_ListOfShape as _ShapeList

__all__ = ["boolean", "bound_area", "volume_centroid", "split_cells", "split_solid", "compound", "checked_boolean", "BooleanCheck", "to_manifold", "manifold_volume", "translated",
           "volume", "reference_point", "area", "TIMER", "CACHE"]

_ALGOS = {"cut": BRepAlgoAPI_Cut, "fuse": BRepAlgoAPI_Fuse, "common": BRepAlgoAPI_Common}

#: seconds spent in OCC Booleans and in manifold3d (meshing + Booleans), for the benchmarks
TIMER = {"occ_boolean_s": 0.0, "manifold_s": 0.0, "occ_booleans": 0, "manifold_booleans": 0}

#: meshes, manifolds, volumes and areas of the shapes a build asks about more than once; the faces'
#: volume integrals in ``CACHE.faces`` (:func:`volume_centroid`).  Kept from one build to the next (the
#: newest entries: a second build of the same tablet asks again about its plain solid and the faces it
#: shares); each entry holds its shape, so a shape that matches one is that shape
CACHE = ShapeCache(faces=20_000)

#: a point (mm)
Point = tuple[float, float, float]



def _list(*shapes: TopoDS_Shape):
    lst = _ShapeList()
    for s in shapes:
        lst.Append(s)
    return lst


def raw_boolean(op: str, a: TopoDS_Shape, b: TopoDS_Shape, fuzzy: float = 0.0, glue: bool = False) -> TopoDS_Shape:
    """The OCC Boolean ``a op b`` as it comes (a compound, possibly empty).

    ``glue``: ``BOPAlgo_GlueFull``, for arguments that only touch along shared faces."""
    t0 = time.perf_counter()
    algo = _ALGOS[op]()
    algo.SetArguments(_list(a))
    algo.SetTools(_list(b))
    algo.SetRunParallel(OCC_PARALLEL[0])
    algo.SetNonDestructive(True)
    if fuzzy > 0:
        algo.SetFuzzyValue(float(fuzzy))
    if glue:
        from OCP.BOPAlgo import BOPAlgo_GlueEnum

        algo.SetGlue(BOPAlgo_GlueEnum.BOPAlgo_GlueFull)
    algo.Build()
    TIMER["occ_boolean_s"] += time.perf_counter() - t0
    TIMER["occ_booleans"] += 1
    if not algo.IsDone() or (hasattr(algo, "HasErrors") and algo.HasErrors()):
        raise GeometryError(f"OCC Boolean {op} failed", (a, b))
    return algo.Shape()


def _bspline_face_edges(shape):
    """The edges of the B-spline faces of ``shape``, for ``UnifySameDomain.KeepShapes``.

    The tablet's faces are exact pieces of its B-splines and are never merged; asking
    OCCT 7.9 to try (faces mode) crashed the process on an almond's punch tip, whose cup
    has pieces with a pole at the collapsed end arcs (tabletcad.brep.slit).
    """
    from OCP.BRep import BRep_Tool
    from OCP.Geom import Geom_BSplineSurface
    from OCP.TopTools import TopTools_MapOfShape

    keep = TopTools_MapOfShape()
    for f in explore(shape, "Face"):
        if isinstance(BRep_Tool.Surface_s(f), Geom_BSplineSurface):
            for e in explore(f, "Edge"):
                keep.Add(e)
    return keep


def boolean(op: str, a: TopoDS_Shape, b: TopoDS_Shape, *, what: str = "result", fuzzy: float = 0.0,
            sliver: float = 0.0) -> TopoDS_Shape:
    """``a op b`` as exactly one valid solid (faces on one surface merged).

    ``sliver`` > 0: solids smaller than ``sliver`` times the largest are dropped (e.g. the hair-thin
    ring between a zero-clearance punch tip and a PDE band that bows inward by a micrometre)."""
    try:
        shape = raw_boolean(op, a, b, fuzzy)
    except GeometryError:
        if fuzzy > 0:
            raise
        # retry with a sub-micrometre fuzzy tolerance: B-spline faces that meet a tool
        # exactly along a seam (e.g. a score across a capsule's centre-line seam) need it
        shape = raw_boolean(op, a, b, 1e-5)
    return _one_solid(explore(shape, "Solid"), shape, what=what, how=f"the {op}", sliver=sliver)


def _one_solid(solids: list, shape, *, what: str, how: str, sliver: float = 0.0) -> TopoDS_Shape:
    """The one solid of ``solids`` (those below ``sliver`` times the largest dropped), faces on one
    surface merged, checked by ``BRepCheck_Analyzer``."""
    if sliver > 0 and len(solids) > 1:
        vols = [mass_properties(s, 1e-7).volume for s in solids]
        solids = [s for s, v in zip(solids, vols) if v >= sliver * max(vols)]
    if len(solids) != 1:
        vols = ", ".join(f"{mass_properties(s, 1e-7).volume:.4g}" for s in solids[:6])
        raise GeometryError(f"{what}: {how} gave {len(solids)} solids (volumes {vols} mm^3), expected one", shape)
    unify = ShapeUpgrade_UnifySameDomain(solids[0], True, True, False)
    unify.KeepShapes(_bspline_face_edges(solids[0]))
    unify.Build()
    solid = explore(unify.Shape(), "Solid")
    solid = solid[0] if len(solid) == 1 else solids[0]
    try:
        check_solid(solid, what)
    except GeometryError:
        check_solid(solids[0], what)  # unification broke it: keep the raw result
        solid = solids[0]
    return solid


def compound(shapes) -> TopoDS_Shape:
    """The shapes as one ``TopoDS_Compound``."""
    from OCP.BRep import BRep_Builder
    from OCP.TopoDS import TopoDS_Compound

    comp = TopoDS_Compound()
    b = BRep_Builder()
    b.MakeCompound(comp)
    for s in shapes:
        b.Add(comp, s)
    return comp


def split_cells(a: TopoDS_Shape, faces, keep, *, what: str = "result") -> TopoDS_Shape:
    """The cell of solid ``a`` cut apart by ``faces`` (``BRepAlgoAPI_Splitter``) for which ``keep`` holds,
    as one valid solid (faces on one surface merged).

    ``keep(cell)`` gets each cell (a solid).  When the faces are the only part of a solid ``b``'s
    boundary that lies inside ``a`` near the kept cell, that cell is a piece of ``a - b`` computed
    without intersecting ``a`` with the rest of ``b`` (e.g. a punch tip: the prism on the tablet's
    outline split by the tablet's cup faces only, not by its band, which runs parallel to the prism's
    wall a clearance away and is the costly part of the full Boolean).  Raises :class:`GeometryError`
    unless exactly one cell is kept."""
    shape, cells = _split(a, [compound(faces)], what)  # one tool: OCC does not intersect its faces with each other
    return _one_solid([c for c in cells if keep(c)], shape, what=what, how="the split")


def split_solid(a: TopoDS_Shape, tools, *, what: str = "result") -> list:
    """The cells (solids) of solid ``a`` cut apart by the ``tools`` (faces or shells, intersected with
    each other too: ``BRepAlgoAPI_Splitter``)."""
    return _split(a, list(tools), what)[1]


def _split(a: TopoDS_Shape, tools: list, what: str):
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Splitter

    t0 = time.perf_counter()
    algo = BRepAlgoAPI_Splitter()
    algo.SetArguments(_list(a))
    algo.SetTools(_list(*tools))
    algo.SetRunParallel(OCC_PARALLEL[0])
    algo.SetNonDestructive(True)
    algo.Build()
    TIMER["occ_boolean_s"] += time.perf_counter() - t0
    TIMER["occ_booleans"] += 1
    if not algo.IsDone() or (hasattr(algo, "HasErrors") and algo.HasErrors()):
        raise GeometryError(f"{what}: OCC splitter failed", a)
    shape = algo.Shape()
    return shape, explore(shape, "Solid")


def translated(shape: TopoDS_Shape, dx: float = 0.0, dy: float = 0.0, dz: float = 0.0) -> TopoDS_Shape:
    """A copy of ``shape`` moved by ``(dx, dy, dz)`` mm (geometry copied, no location)."""
    tr = gp_Trsf()
    tr.SetTranslation(gp_Vec(float(dx), float(dy), float(dz)))
    return BRepBuilderAPI_Transform(shape, tr, True).Shape()


def volume(shape: TopoDS_Shape, eps: float = 1e-9, about: Point | None = None) -> float:
    """Volume (mm^3) by OCC's adaptive integration (once per shape: :data:`CACHE`; ``about``: see
    :func:`volume_centroid`)."""
    return volume_centroid(shape, eps, about)[0]


def volume_centroid(shape: TopoDS_Shape, eps: float = 1e-9,
                    about: Point | None = None) -> tuple[float, Point]:
    """Volume (mm^3) and centroid (mm) by OCC's adaptive integration to ``eps``, once per shape
    (:data:`CACHE`; :func:`volume` reads the same entry) and once per face.

    ``BRepGProp.VolumeProperties`` sums, face by face, the divergence-theorem integrals about one
    point, the mean of the shape's vertices (:func:`reference_point`; ``BRepGProp_Vinert``, each
    face integrated adaptively to ``eps`` of its own integral); here the same sums, each face's
    integral kept (``CACHE.faces``, by face and point) for the next solid that has the face
    (reversed: negated), and by the face's content (``CACHE.content``) for a face made again, and the
    volume is ``VolumeProperties``'s to the last bit.

    ``about``: a point (mm) to integrate about instead, where it lies within :data:`NEAR_MM` of the
    shape's own, e.g. a punch tip about the finished tablet's point when the tablet's detail (its
    letters) is on the tip's face, so that the faces they share are integrated once (398 of the 401
    faces of a tip under debossed letters, 3 s a build).  The sums depend on the point only through
    the integration's error (the faces' integrals do not close exactly): such a tip's volume
    differs from ``VolumeProperties``'s by 1e-12 to 1e-10 relative.  A shape with a face without
    surface or wires goes to ``VolumeProperties`` whole."""
    done = CACHE.get(shape, ("volume", eps), lambda: {"own": reference_point(shape)})  # results by point
    point = own = done["own"]
    if about is not None and own is not None and math.dist(about, own) <= NEAR_MM:
        point = (float(about[0]), float(about[1]), float(about[2]))
    if point not in done:
        done[point] = _volume_about(shape, eps, point)
    return done[point]


#: how near (mm) the point a volume is asked about must lie to the shape's own to be used
NEAR_MM = 1.0


def reference_point(shape: TopoDS_Shape) -> Point | None:
    """The point ``BRepGProp.VolumeProperties`` integrates ``shape`` about: the mean of its vertices
    as the explorer meets them (each as often), summed in its order (None without vertices)."""
    from OCP.BRep import BRep_Tool
    from OCP.TopAbs import TopAbs_VERTEX
    from OCP.TopExp import TopExp_Explorer

    x = y = z = 0.0
    n, exp = 0, TopExp_Explorer(shape, TopAbs_VERTEX)
    while exp.More():
        p = BRep_Tool.Pnt_s(cast(exp.Current(), "Vertex"))
        x, y, z, n = x + p.X(), y + p.Y(), z + p.Z(), n + 1
        exp.Next()
    return None if n == 0 else (x / n, y / n, z / n)


def _volume_about(shape: TopoDS_Shape, eps: float, point: Point | None) -> tuple[float, Point]:
    """:func:`volume_centroid` computed about ``point``: the forward and reversed faces' integrals
    (as ``BRepGProp`` counts them, each as often as the explorer meets it) summed in its order."""
    from OCP.BRep import BRep_Tool
    from OCP.TopAbs import TopAbs_FACE, TopAbs_Orientation
    from OCP.TopExp import TopExp_Explorer

    faces, exp = [], TopExp_Explorer(shape, TopAbs_FACE)
    while exp.More():
        faces.append(cast(exp.Current(), "Face"))
        exp.Next()
    if point is None or any(BRep_Tool.Surface_s(f) is None or f.NbChildren() == 0 for f in faces):
        return _integral(shape, eps, "Volume", centroid=True)  # (mesh-only or unbounded faces: OCC's way)
    fwd, rev = TopAbs_Orientation.TopAbs_FORWARD, TopAbs_Orientation.TopAbs_REVERSED
    mass, moments = 0.0, np.zeros(3)
    for f in faces:
        if f.Orientation() not in (fwd, rev):  # internal and external faces bound nothing
            continue
        forward = cast(f.Oriented(fwd), "Face")
        key = ("volume", eps, point)
        m, s = CACHE.faces.get(forward, key, lambda g=forward: _face_volume_once(g, eps, point))
        sign = 1.0 if f.Orientation() == fwd else -1.0
        mass += sign * m
        moments += sign * s
    centre = moments / mass if mass != 0.0 else np.zeros(3)
    return mass, (float(centre[0]), float(centre[1]), float(centre[2]))


def _face_volume_once(face, eps: float, point: Point) -> tuple[float, np.ndarray]:
    """:func:`_face_volume`, once per face content (``CACHE.content``: the same face made again by
    another build of the same tablet gives the same integral to the last bit)."""
    return CACHE.content.get((content_key(face), "volume", eps, point), lambda: _face_volume(face, eps, point))


def _face_volume(face, eps: float, point: Point) -> tuple[float, np.ndarray]:
    """The forward ``face``'s volume integral (mm^3) about ``point`` and its static moments about the
    origin (mm^4), by ``BRepGProp_Vinert`` adaptive to ``eps`` (what ``BRepGProp.VolumeProperties``
    adds for the face)."""
    from OCP.BRepGProp import BRepGProp_Domain, BRepGProp_Face, BRepGProp_Vinert
    from OCP.gp import gp_Pnt

    face = _integrable(face)
    props, surface, domain = BRepGProp_Vinert(), BRepGProp_Face(), BRepGProp_Domain()
    props.SetLocation(gp_Pnt(*point))
    surface.Load(face)
    domain.Init(face)
    props.Perform(surface, domain, float(eps))
    m, c = float(props.Mass()), props.CentreOfMass()
    return m, np.array([m * c.X(), m * c.Y(), m * c.Z()])


def has_periodic_bspline_curve(shape: TopoDS_Shape) -> bool:
    """Whether an edge of ``shape`` lies on a periodic B-spline curve: a spline outline's
    (:func:`tabletcad.tooling.outline.spline_offset_wire`; OCC's offsets never give one)."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.GeomAbs import GeomAbs_CurveType

    for edge in explore(shape, "Edge"):
        c = BRepAdaptor_Curve(cast(edge, "Edge"))
        if c.GetType() == GeomAbs_CurveType.GeomAbs_BSplineCurve and c.IsPeriodic():
            return True
    return False


def _integrable(face):
    """``face``, or where it lies on the linear extrusion of a periodic B-spline (a spline outline's prism: a
    punch tip's wall, a die bore) the same face on the B-spline surface that extrusion is
    (``BRepBuilderAPI_NurbsConvert``, exact): ``BRepGProp_Vinert`` adaptive to 1e-9 had given a 1 mm prism of
    a rounded square through 24 points 60.449 mm³ for 64.674 (its plan area times its height; 64.674 on the
    B-spline surface), and the punch tips' cross-check against manifold3d failed on it.  (The prism itself
    keeps the extrusion: OCC's Booleans on the B-spline surface took six times as long.)"""
    from OCP.BRep import BRep_Tool
    from OCP.BRepBuilderAPI import BRepBuilderAPI_NurbsConvert
    from OCP.Geom import Geom_BSplineCurve, Geom_SurfaceOfLinearExtrusion

    surface = BRep_Tool.Surface_s(face)
    if not isinstance(surface, Geom_SurfaceOfLinearExtrusion):
        return face
    basis = surface.BasisCurve()
    if not (isinstance(basis, Geom_BSplineCurve) and basis.IsPeriodic()):
        return face
    return cast(BRepBuilderAPI_NurbsConvert(face, True).Shape(), "Face")


def area(shape: TopoDS_Shape, eps: float = 1e-6) -> float:
    """Surface area (mm^2) by OCC's adaptive integration (once per shape: :data:`CACHE`)."""
    return CACHE.get(shape, ("area", eps), lambda: _integral(shape, eps, "Surface"))


def bound_area(shape: TopoDS_Shape, deflection: float = 0.005, angular: float = 0.2) -> float:
    """An upper estimate of the surface area (mm^2) that scales the manifold3d bounds (``deflection x
    area``): the area of the tessellation the manifold is made of (:func:`mesh_arrays`, already computed)
    over ``cos(angular)``.  A face whose normals stay within ``angular`` of its triangle's normal has at
    most the triangle's area over that cosine.  On the parts of the five tooling samples this is 1.0198
    to 1.0203 times OCC's adaptive integration to 1e-6, which cost 0.3 s a tooling build."""
    from tabletcad.cad.mesh import _signed_volume_area

    return _signed_volume_area(*mesh_arrays(shape, deflection, angular))[1] / math.cos(angular)


def _integral(shape: TopoDS_Shape, eps: float, kind: str, centroid: bool = False):
    """``BRepGProp.VolumeProperties`` or ``SurfaceProperties`` alone (what :func:`mass_properties` computes,
    without the other one), adaptive to ``eps``: the mass, or with ``centroid`` the mass and the centre."""
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    props = GProp_GProps()
    getattr(BRepGProp, f"{kind}Properties_s")(shape, props, Eps=float(eps))
    if not centroid:
        return float(props.Mass())
    c = props.CentreOfMass()
    return float(props.Mass()), (c.X(), c.Y(), c.Z())


# ----------------------------------------------------------------------------- manifold3d
def mesh_arrays(shape: TopoDS_Shape, deflection: float = 0.005, angular: float = 0.2):
    """``(V, T)`` of the tessellation (Delabella, falling back to Watson for faces it leaves empty),
    read-only and computed once per shape and deflections (:data:`CACHE`)."""
    return _mesh_with_faces(shape, deflection, angular)[:2]


def mesh_face_ids(shape: TopoDS_Shape, deflection: float = 0.005, angular: float = 0.2) -> np.ndarray:
    """Each triangle's face in :func:`mesh_arrays` ``(shape, deflection, angular)``: its index in
    ``explore(shape, "Face")`` (read-only, computed with the mesh)."""
    return _mesh_with_faces(shape, deflection, angular)[2]


def _mesh_with_faces(shape: TopoDS_Shape, deflection: float, angular: float):
    from tabletcad.cad.mesh import triangulate

    def compute():
        # Delabella leaves some trimmed faces (letters' floors and walls) untriangulated: Watson then, and
        # straight away at the shape's other deflections (a failed Delabella pass cost 0.3-0.5 s)
        if not CACHE.get(shape, ("delabella_fails",), lambda: [False])[0]:
            try:
                return frozen(*triangulate(shape, deflection, angular, face_ids=True))
            except GeometryError:
                CACHE.get(shape, ("delabella_fails",), lambda: [False])[0] = True
        return frozen(*triangulate(shape, deflection, angular, algo="watson", face_ids=True))

    return CACHE.get(shape, ("mesh", float(deflection), float(angular)), compute)


def to_manifold(shape: TopoDS_Shape, deflection: float = 0.005, angular: float = 0.2):
    """A ``manifold3d.Manifold`` from the OCC tessellation of ``shape`` (double precision; once per
    shape and deflections, :data:`CACHE`)."""
    return CACHE.get(shape, ("manifold", float(deflection), float(angular)), lambda: _to_manifold(shape, deflection, angular))


def _to_manifold(shape: TopoDS_Shape, deflection: float, angular: float):
    import manifold3d

    t0 = time.perf_counter()
    V, T = mesh_arrays(shape, deflection, angular)
    m = manifold3d.Manifold(manifold3d.Mesh64(vert_properties=np.array(V, dtype=np.float64, order="C"),  # writable copies
                                              tri_verts=np.array(T, dtype=np.uint32, order="C")))
    status = getattr(m.status(), "name", str(m.status()))
    TIMER["manifold_s"] += time.perf_counter() - t0
    if not str(status).endswith("NoError"):
        raise GeometryError(f"manifold3d refused the tessellation: {status}", shape)
    return m


def manifold_volume(m) -> float:
    """Volume (mm^3) of a manifold, by manifold3d (float64 vertices since manifold3d 3.0: the same sum as
    the signed tetrahedra of its ``Mesh64`` to 2e-16 relative, without copying the mesh out)."""
    return 0.0 if m.is_empty() else float(m.volume())


def manifold_op(op: str, ma, mb):
    t0 = time.perf_counter()
    out = {"cut": lambda: ma - mb, "fuse": lambda: ma + mb, "common": lambda: ma ^ mb}[op]()
    TIMER["manifold_s"] += time.perf_counter() - t0
    TIMER["manifold_booleans"] += 1
    return out


@dataclass(frozen=True)
class BooleanCheck:
    """One Boolean and its manifold3d cross-check (volumes in mm^3)."""

    what: str
    op: str
    occ_change_mm3: float
    mesh_change_mm3: float
    abs_diff_mm3: float
    rel_diff: float
    bound_mm3: float
    deflection_mm: float
    valid: bool
    ok: bool

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


def checked_boolean(
    op: str,
    a: TopoDS_Shape,
    b: TopoDS_Shape,
    *,
    what: str,
    deflection: float = 0.005,
    check: bool = True,
    a_manifold=None,
    fuzzy: float = 0.0,
    sliver: float = 0.0,
    exact=None,
    about: Point | None = None,
) -> tuple[TopoDS_Shape, BooleanCheck | None]:
    """:func:`boolean` plus the manifold3d check; raises :class:`GeometryError` if they disagree.

    The "change" is the volume removed (cut), added (fuse) or kept (common).  ``exact``: a function
    that returns the exact result another way (e.g. :func:`split_cells`); the manifold3d check
    still runs the whole ``a op b`` on the meshes of ``a`` and ``b``.  ``about``: the point the
    result's volume is integrated about (:func:`volume_centroid`).
    """
    result = boolean(op, a, b, what=what, fuzzy=fuzzy, sliver=sliver) if exact is None else exact()
    if not check:
        return result, None
    va, vr = volume(a), volume(result, about=about)
    occ_change = {"cut": va - vr, "fuse": vr - va, "common": vr}[op]
    ma = a_manifold if a_manifold is not None else to_manifold(a, deflection)
    mb = to_manifold(b, deflection)
    mr = manifold_op(op, ma, mb)
    mva, mvr = manifold_volume(ma), manifold_volume(mr)
    mesh_change = {"cut": mva - mvr, "fuse": mvr - mva, "common": mvr}[op]
    bound = deflection * bound_area(b, deflection)
    diff = abs(occ_change - mesh_change)
    chk = BooleanCheck(what, op, occ_change, mesh_change, diff, diff / max(abs(occ_change), 1e-300), bound,
                       deflection, True, diff <= bound)
    if not chk.ok:
        raise GeometryError(
            f"{what}: OCC and manifold3d disagree on the {op}: {occ_change:.6g} vs {mesh_change:.6g} mm^3 "
            f"(allowed {bound:.3g} mm^3 at {deflection} mm deflection)", (a, b))
    return result, chk


def box_solid(lo, hi, margin: float = 0.0) -> TopoDS_Shape:
    """The box solid from corner ``lo`` to corner ``hi`` (3 numbers each, mm), grown by ``margin`` (mm) on
    every side: a block holding a part whose bounding box is ``lo``-``hi`` (emboss's floor cut, the
    tablet-die proof of :func:`~tabletcad.tooling.interference.inside_bore`)."""
    return BRepPrimAPI_MakeBox(gp_Pnt(*(float(x) - margin for x in lo)),
                               gp_Pnt(*(float(x) + margin for x in hi))).Shape()
