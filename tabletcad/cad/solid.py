"""Fit, sew and validate closed solids from chains of surface patches; adaptive mass properties.

The pipeline never returns a broken solid: every step is checked and a
:class:`tabletcad.errors.GeometryError` names the patch (and the deviation or
free edge) that failed.

1. :func:`tabletcad.brep.fit.fit_patches` - B-spline fit of every patch within
   ``tol`` (shared boundary rows are bit-identical between neighbours);
2. :func:`tabletcad.cad.faces.make_geom_surface` - one periodic B-spline surface per patch, or
   the whole chain cut alike into pieces where a boundary row stands still over part
   of its length (:func:`tabletcad.brep.slit.chain_face_surfaces`);
3. one closed shell: assembled edge by edge from the chain's known topology
   (:func:`tabletcad.cad.shell.assemble_shell`; a flat region one plane face), or, for a chain it
   cannot assemble or whose assembled solid fails its check, ``BRepBuilderAPI_Sewing`` with
   tolerance ``max(2 tol, 1e-6)`` mm - no free or multiple edges allowed;
4. ``BRepBuilderAPI_MakeSolid`` + ``BRepLib::OrientClosedSolid`` (matter
   inside, positive volume; faces of revolution: reversed if their volume is
   negative) + ``BRepCheck_Analyzer``; flat B-spline faces become exact planes, one per flat
   region (:mod:`tabletcad.cad.planes`);
5. volume/area/centroid by *adaptive* Gauss integration
   (``BRepGProp::VolumeProperties(shape, props, eps)``, ``eps`` = 1e-9): the
   default integration was measured up to ~1e-3 relative off on dense B-spline faces;
   the boundary p-curves carry the faces' C0/C1 ``v`` knots so that the
   integration splits there (:func:`tabletcad.cad.faces.knot_boundary_pcurves`).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeSolid, BRepBuilderAPI_Sewing
from OCP.BRepCheck import BRepCheck_Analyzer
from OCP.BRepExtrema import BRepExtrema_DistShapeShape
from OCP.BRepGProp import BRepGProp
from OCP.BRepLib import BRepLib
from OCP.GProp import GProp_GProps
from OCP.Standard import Standard_Failure
from OCP.TopAbs import TopAbs_Orientation
from OCP.TopoDS import TopoDS_Shape, TopoDS_Solid

from tabletcad.brep.revolved import RevolvedSurfaceData
from tabletcad.brep.fit import PatchFunction, SurfaceFit, chain_breakpoints, fit_patches
from tabletcad.brep.surface import BSplineSurfaceData, volume_and_area
from tabletcad.cad._occ import cast, explore, shape_type
from tabletcad.cad.content import ContentMemo, content_key, has_all_surfaces
from tabletcad.cad.faces import face_of, knot_boundary_pcurves, make_geom_surface
from tabletcad.cad.planes import flat_faces_as_planes, made_poles, planes_of
from tabletcad.cad.shell import assemble_shell
from tabletcad.errors import GeometryError
from tabletcad.brep.slit import chain_face_surfaces

__all__ = [
    "MassProperties",
    "TabletSolid",
    "mass_properties",
    "tight_bounds",
    "build_solid",
    "solid_from_surfaces",
    "solid_from_tablet",
    "revolved_solid",
    "sew_faces",
    "check_solid",
    "chain_breakpoints",
    "PatchFunction",
]

DEFAULT_EPS = 1e-9


@dataclass(frozen=True)
class MassProperties:
    """Volume (mm^3), area (mm^2), centroid (mm) and the integrator's relative error estimates."""

    volume: float
    area: float
    centroid: tuple[float, float, float]
    volume_error: float
    area_error: float
    eps: float | None


#: :func:`mass_properties` of the newest shapes by content (:mod:`tabletcad.cad.content`): a solid built
#: again (the same family sample in another stage or test) is not integrated again, when both copies
#: carry the same status flags (meshing a shape gives it a new key)
MASS_MEMO = ContentMemo(256)


def mass_properties(shape: TopoDS_Shape, eps: float | None = DEFAULT_EPS) -> MassProperties:
    """Volume, area and centroid of ``shape``.

    ``eps`` (relative, per face) selects OCCT's adaptive Gauss integration;
    ``eps=None`` uses OCCT's default (non-adaptive) integration, which is what
    FreeCAD's ``Shape.Volume`` does - only for comparisons.  Integrated once per shape content
    (:data:`MASS_MEMO`; the same result to the last bit, OCC reads nothing else), except for shapes
    with faces without a surface.
    """
    if eps is not None and not 0 < eps <= 1e-3:
        raise ValueError(f"eps = {eps} is not allowed: must be > 0 and <= 1e-3 (adaptive integration)")
    if not has_all_surfaces(shape):
        return _mass_properties(shape, eps)
    return MASS_MEMO.get((content_key(shape), eps), lambda: _mass_properties(shape, eps))


def _mass_properties(shape: TopoDS_Shape, eps: float | None) -> MassProperties:
    """:func:`mass_properties` integrated by OCC (``eps`` checked by the caller)."""
    vprops, sprops = GProp_GProps(), GProp_GProps()
    if eps is None:
        BRepGProp.VolumeProperties_s(shape, vprops)
        BRepGProp.SurfaceProperties_s(shape, sprops)
        verr = aerr = float("nan")
    else:
        verr = float(BRepGProp.VolumeProperties_s(shape, vprops, Eps=float(eps)))
        aerr = float(BRepGProp.SurfaceProperties_s(shape, sprops, Eps=float(eps)))
    c = vprops.CentreOfMass()
    return MassProperties(float(vprops.Mass()), float(sprops.Mass()), (c.X(), c.Y(), c.Z()), verr, aerr, eps)


def tight_bounds(shape: TopoDS_Shape) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """``(lo, hi)`` (mm): the axis-aligned box of ``shape``'s geometry (``BRepBndLib::AddOptimal`` on its
    curves and surfaces, neither its triangulation nor its tolerances; build123d's ``bounding_box(optimal=True)``
    also counts the tolerances, 1e-7 mm and more on a Boolean's edges)."""
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib

    box = Bnd_Box()
    BRepBndLib.AddOptimal_s(shape, box, False, False)
    lo, hi = box.CornerMin(), box.CornerMax()
    return (lo.X(), lo.Y(), lo.Z()), (hi.X(), hi.Y(), hi.Z())


@dataclass(frozen=True, eq=False)
class TabletSolid:
    """A validated, outward-oriented closed solid and how it was made (``sewn``: its shell by
    ``BRepBuilderAPI_Sewing``, else assembled edge by edge: :mod:`tabletcad.cad.shell`); ``planes``: how many
    flat B-spline faces became exact planes (:mod:`tabletcad.cad.planes`).

    ``volume_fit_bound`` = ``max_fit_deviation * area`` bounds the volume change
    caused by replacing the patches with their B-splines (the surfaces are at
    most ``max_fit_deviation`` apart, pointwise at equal parameters).
    """

    name: str
    shape: TopoDS_Solid
    faces: tuple
    surfaces: tuple[BSplineSurfaceData, ...]
    patch_names: tuple[str, ...]
    fits: tuple[SurfaceFit, ...]
    sew_tolerance: float
    eps: float | None = DEFAULT_EPS
    timings: dict[str, float] = field(default_factory=dict)
    sewn: bool = True
    planes: int = 0

    @property
    def mass(self) -> MassProperties:
        """Volume, area and centroid by OCC's integration (``eps``: see :func:`mass_properties`),
        computed on first use (the finite elements, for one, need only the shape)."""
        hit = self.__dict__.get("_mass")
        if hit is None:
            t0 = time.perf_counter()
            hit = mass_properties(self.shape, self.eps)
            object.__setattr__(self, "_mass", hit)
            self.timings["mass_properties"] = time.perf_counter() - t0
        return hit

    @property
    def data_volume_area(self) -> tuple[float, float]:
        """Signed volume (mm³, positive when the surfaces' ``S_u × S_v`` points outward) and area
        (mm²) of the faces' own surface data by Gauss-Legendre
        (:func:`~tabletcad.brep.surface.volume_and_area`), computed once."""
        hit = self.__dict__.get("_data_volume_area")
        if hit is None:
            hit = volume_and_area(self.surfaces)
            object.__setattr__(self, "_data_volume_area", hit)
        return hit

    @property
    def volume(self) -> float:
        return self.mass.volume

    @property
    def area(self) -> float:
        return self.mass.area

    @property
    def max_fit_deviation(self) -> float:
        return max((f.max_deviation for f in self.fits), default=0.0)

    @property
    def volume_fit_bound(self) -> float:
        return self.max_fit_deviation * self.mass.area

    def summary(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "faces": len(self.faces),
            "poles": [list(s.shape) for s in self.surfaces],
            "fit_deviation_mm": [f.max_deviation for f in self.fits],
            "volume_mm3": self.volume,
            "area_mm2": self.area,
            "volume_rel_error_estimate": self.mass.volume_error,
            "sew_tolerance_mm": self.sew_tolerance if self.sewn else None,  # (an assembled shell was not sewn)
            "sewn": self.sewn,
            "plane_faces": self.planes,
            "timings_s": dict(self.timings),
        }


# --------------------------------------------------------------------------- helpers


def _patch_function(p: Any) -> Callable[[np.ndarray, np.ndarray], np.ndarray]:
    if hasattr(p, "evaluate"):
        return PatchFunction(p)
    if callable(p):
        return p
    raise TypeError(f"a patch must be callable f(u, v) or have .evaluate(u, v), got {type(p).__name__}")


def _patch_names(patches: Sequence[Any], names: Sequence[str] | None) -> list[str]:
    if names is not None:
        names = [str(n) for n in names]
        if len(names) != len(patches):
            raise ValueError(f"{len(names)} names given for {len(patches)} patches")
        return names
    out = []
    for j, p in enumerate(patches):
        n = getattr(p, "name", None)
        out.append(f"patch {j} ({n})" if n else f"patch {j}")
    return out


def _owner(edge, faces: Sequence, names: Sequence[str]) -> str:
    best, best_d = "?", math.inf
    for f, n in zip(faces, names):
        d = BRepExtrema_DistShapeShape(edge, f)
        if d.IsDone() and d.Value() < best_d:
            best, best_d = n, d.Value()
    return best


def sew_faces(faces: Sequence, names: Sequence[str], tolerance: float):
    """Sew faces into exactly one closed shell; raise :class:`GeometryError` on free/multiple edges."""
    sew = BRepBuilderAPI_Sewing(float(tolerance), True, True, True, False)
    for f in faces:
        sew.Add(f)
    sew.Perform()
    shape = sew.SewedShape()
    if sew.NbFreeEdges() or sew.NbMultipleEdges():
        free = [sew.FreeEdge(i) for i in range(1, sew.NbFreeEdges() + 1)]
        owners = sorted({_owner(e, faces, names) for e in free})
        raise GeometryError(
            f"sewing with tolerance {tolerance:.3g} mm left {sew.NbFreeEdges()} free and "
            f"{sew.NbMultipleEdges()} multiple edges (free edges on: {', '.join(owners) or '-'})",
            shape,
        )
    shells = explore(shape, "Shell")
    if len(shells) != 1:
        raise GeometryError(f"sewing produced {len(shells)} shells, expected 1", shape)
    shell = shells[0]
    n_faces = len(explore(shell, "Face"))
    if n_faces != len(faces):
        raise GeometryError(f"sewn shell has {n_faces} faces, expected {len(faces)}", shell)
    if not BRep_Tool.IsClosed_s(shell):
        raise GeometryError("sewn shell is not closed", shell)
    return shell


def check_solid(solid: TopoDS_Shape, what: str = "solid") -> None:
    """Raise :class:`GeometryError` unless ``solid`` is a valid solid (``BRepCheck_Analyzer``)."""
    if solid.IsNull() or shape_type(solid) != "Solid":
        raise GeometryError(f"{what} is not a solid", solid)
    if not BRepCheck_Analyzer(solid).IsValid():
        raise GeometryError(f"{what} fails BRepCheck_Analyzer", solid)


def _make_solid(shell, name: str, data_volume: float, check: bool = True) -> TopoDS_Solid:
    """The solid of a sewn closed shell, turned outward.  ``data_volume``: the signed volume the
    faces enclose as made, from their own surface data (:attr:`TabletSolid.data_volume_area`; NaN:
    unknown).  When sewing turned no face, the shell encloses exactly that volume, so its sign says
    which side is inside (OCC's point classification, ``BRepLib::OrientClosedSolid``, took 46 ms
    of a 60 ms solid of revolution and 49 ms of the capsule's 0.47 s stage); otherwise the
    classification decides."""
    maker = BRepBuilderAPI_MakeSolid(shell)
    if not maker.IsDone():
        raise GeometryError(f"BRepBuilderAPI_MakeSolid failed for {name}", shell)
    solid = cast(maker.Solid(), "Solid")
    as_made = all(f.Orientation() == TopAbs_Orientation.TopAbs_FORWARD for f in explore(shell, "Face"))
    if as_made and math.isfinite(data_volume) and data_volume != 0.0:
        if data_volume < 0.0:
            solid = cast(solid.Reversed(), "Solid")
    elif not BRepLib.OrientClosedSolid_s(solid):
        raise GeometryError(f"{name}: the sewn shell cannot be oriented (open or incoherent)", solid)
    if check:
        check_solid(solid, name)
    return solid


# --------------------------------------------------------------------------- public builders


def solid_from_surfaces(
    surfaces: Sequence[BSplineSurfaceData],
    *,
    name: str = "tablet",
    names: Sequence[str] | None = None,
    sew_tolerance: float = 2e-4,
    eps: float = DEFAULT_EPS,
    fits: Sequence[SurfaceFit] = (),
    tol_degen: float = 1e-7,
    flat_regions: bool = True,
) -> TabletSolid:
    """Faces -> sewn closed shell -> outward solid, validated; adaptive mass properties.

    ``flat_regions``: neighbouring flat faces in one plane become one plane face (:mod:`tabletcad.cad.planes`,
    :func:`~tabletcad.cad.shell.assemble_shell`), else one plane each.  A shaped cut-away's chain is built
    without: the ruled cut faces of a flat patch lie in that patch's plane, over its pieces, and one face for
    the region would not count their area as the surface data does (1-2 % less on the rounded square's)."""
    t0 = time.perf_counter()
    names = list(names) if names is not None else [f"patch {j}" for j in range(len(surfaces))]
    # one face per surface; the whole chain cut alike where a boundary row stands still over
    # part of its length (the capsule's centre line, collapsed outline corners: tabletcad.brep.slit)
    pieces = chain_face_surfaces(surfaces, tol_degen, names)
    face_names: list[str] = []
    for ps, n in zip(pieces, names):
        face_names.extend([n] if len(ps) == 1 else [f"{n} (piece {k + 1})" for k in range(len(ps))])
    geoms: list[list] = [[None] * len(ps) for ps in pieces]  # each piece's OCC surface, made when asked for

    def geom(j: int, k: int):
        if geoms[j][k] is None:
            geoms[j][k] = make_geom_surface(pieces[j][k])
        return geoms[j][k]

    va = volume_and_area(surfaces)  # the faces' own volume and area (orientation, the stage's check)
    # the chain's topology is known: its shell is assembled edge by edge (tabletcad.cad.shell);
    # a chain that cannot be (a segment whose way back is not its way there reversed), or whose assembled solid
    # fails its check, is sewn.
    # A cut chain's flat regions are made plane faces there; if that fails, the chain is assembled in its pieces
    # (a curved patch cut only because its neighbours are, such as a band, stays in pieces: as one face on its
    # uncut surface, C0 where the pieces meet, the rounded rectangle's band made OCC's Common of the tablet with
    # the outside of the die bore's column non-empty, so the tooling's exact proof that they do not overlap failed)
    flat = planes_of([np.asarray(sd.poles) for sd in surfaces]) \
        if flat_regions and any(len(ps) > 1 for ps in pieces) else None

    def made():  # for the planes: the surfaces made so far, with their poles
        return made_poles((g, p.poles) for gs, ps in zip(geoms, pieces) for g, p in zip(gs, ps) if g is not None)

    for kw in ([dict(flat=flat)] if flat is not None else []) + [{}]:
        try:
            assembled = assemble_shell(pieces, geom, tol_degen, **kw)
        except Standard_Failure:  # an OCC exception while building it: the next way decides
            assembled = None
        if assembled is not None:
            shell, faces_a, n_flat = assembled
            try:
                return _solid_from_faces(tuple(faces_a), face_names, surfaces, names, fits, sew_tolerance, eps, name,
                                         t0, shell=shell, va=va, made=made(), planes=n_flat, merge=flat_regions)
            except GeometryError:
                pass
    geoms = [[geom(j, k) for k in range(len(ps))] for j, ps in enumerate(pieces)]
    # each face is checked as part of the solid (BRepCheck_Analyzer of the solid checks its
    # faces); only when that fails are they checked one by one, to name the bad one
    faces_l = [face_of(g, tol_degen=tol_degen, name=n) for gs, n in zip(geoms, names) for g in gs]
    try:
        return _solid_from_faces(tuple(faces_l), face_names, surfaces, names, fits, sew_tolerance, eps, name, t0,
                                 va=va, made=made(), merge=flat_regions)
    except GeometryError as exc:
        for face, n in zip(faces_l, face_names):
            if not BRepCheck_Analyzer(face).IsValid():
                raise GeometryError(f"face of {n} is not valid (BRepCheck_Analyzer)", face) from exc
        raise


def _solid_from_faces(faces: tuple, face_names: Sequence[str], surfaces: Sequence, names: Sequence[str],
                      fits: Sequence, sew_tolerance: float, eps: float, name: str, t0: float,
                      shell=None, va: tuple[float, float] | None = None, made=None, planes: int = 0,
                      merge: bool = True) -> TabletSolid:
    """Sew ``faces`` into one closed shell (unless the ``shell`` they make is given), make the
    outward solid and check it (its mass properties are integrated when first asked for:
    :attr:`TabletSolid.mass`).  ``va``: the surfaces' :func:`volume_and_area`, if known; ``made``: the
    faces' surfaces and their poles (:func:`~tabletcad.cad.planes.made_poles`), if known; ``planes``: how
    many of the faces are planes already (a flat region's, made by :func:`~tabletcad.cad.shell.assemble_shell`);
    ``merge``: whether coplanar flat faces that share an edge become one plane face
    (:func:`~tabletcad.cad.planes.flat_faces_as_planes`), else a plane each."""
    t1 = time.perf_counter()
    sewn = shell is None
    if sewn:
        shell = sew_faces(faces, face_names, sew_tolerance)
        # sewing may rebuild p-curves: make sure the boundary p-curves still carry the C0/C1
        # v knots that BRepGProp needs to integrate across them (see tabletcad.cad.faces)
        knot_boundary_pcurves(shell)
    if va is None:
        va = volume_and_area(surfaces)  # the faces' own volume and area, also the stage's check
    # a face of revolution is OCC's (angle, profile) surface, the data's (profile, angle) one with
    # the parameters swapped: its normal, and the volume its faces enclose, is the data's reversed
    revolved = [isinstance(sd, RevolvedSurfaceData) for sd in surfaces]
    enclosed = -va[0] if all(revolved) else va[0] if not any(revolved) else math.nan
    solid = _make_solid(shell, name, enclosed, check=False)
    # flat B-spline pieces as exact planes, one per flat region: OCCT's face merging, which build123d and
    # CadQuery run after every Boolean, crashed the process on the pieces (tabletcad.cad.planes); one check of
    # the solid with them, of the solid with a plane per piece only if that fails, of the solid as made last
    for merged in ((True, False) if merge else (False,)):
        planar, n_planes, reshape = flat_faces_as_planes(solid, check=False, made=made, merge=merged)
        try:
            check_solid(planar, name)
            solid = planar
            break
        except GeometryError:
            if not n_planes:
                raise
    else:
        check_solid(solid, name)
        n_planes, reshape = 0, None
    if sewn:  # the faces as sewing made them
        faces = tuple(explore(shell, "Face"))
    if reshape is not None:  # and with their planes (a flat region's pieces: its one face, once)
        kept: list = []
        for f in faces:
            g = reshape.Value(f)
            if not g.IsNull() and not any(g.IsSame(k) for k in kept):
                kept.append(cast(g, "Face"))
        faces = tuple(kept)
    t2 = time.perf_counter()
    out = TabletSolid(
        name=name,
        shape=solid,
        faces=faces,
        surfaces=tuple(surfaces),
        patch_names=tuple(names),
        fits=tuple(fits),
        sew_tolerance=float(sew_tolerance),
        eps=eps,
        timings={"faces": t1 - t0, "sew_and_check" if sewn else "shell_and_check": t2 - t1},
        sewn=sewn,
        planes=n_planes + planes,
    )
    object.__setattr__(out, "_data_volume_area", va)
    return out


def build_solid(
    patches: Sequence[Any],
    tol: float = 1e-4,
    *,
    name: str = "tablet",
    names: Sequence[str] | None = None,
    sew_tolerance: float | None = None,
    eps: float = DEFAULT_EPS,
    flat_regions: bool = True,
    **fit_kwargs: Any,
) -> TabletSolid:
    """Fit every patch (callable ``f(u, v)`` or object with ``.evaluate``) within ``tol`` mm and build the solid.

    Patches form a chain: patch ``j``'s ``u=1`` curve is patch ``j+1``'s ``u=0``
    curve (the chain may close on itself, e.g. a ring).  ``sew_tolerance``
    defaults to ``max(2 tol, 1e-6)`` mm; ``flat_regions``: see :func:`solid_from_surfaces`.  Extra keyword
    arguments go to
    :func:`tabletcad.brep.fit.fit_surface` (``nu``, ``nv``, ``max_nu``, ``v_breaks``...);
    ``v_breaks`` defaults to the union of the patches' ``breakpoints()`` (if they have any).
    """
    t0 = time.perf_counter()
    patches = list(patches)
    if not patches:
        raise GeometryError("no patches given", patches)
    names = _patch_names(patches, names)
    functions = [_patch_function(p) for p in patches]
    if "v_breaks" not in fit_kwargs:  # patches that know where they are not smooth in v
        fit_kwargs["v_breaks"] = chain_breakpoints(patches)
    fits = fit_patches(functions, tol, names=names, **fit_kwargs)
    for fit, n in zip(fits, names):
        if not fit.ok:  # fit_surface raises already; keep the guarantee explicit
            raise GeometryError(f"B-spline fit of {n} misses tolerance: {fit.max_deviation:.3g} mm > {tol:.3g} mm", fit)
    t1 = time.perf_counter()
    sew_tol = float(sew_tolerance) if sew_tolerance is not None else max(2.0 * tol, 1e-6)
    result = solid_from_surfaces(
        [f.surface for f in fits], name=name, names=names, sew_tolerance=sew_tol, eps=eps, fits=fits,
        flat_regions=flat_regions,
    )
    timings = {"fit": t1 - t0, **result.timings}
    timings["total"] = time.perf_counter() - t0
    object.__setattr__(result, "timings", timings)
    return result


def revolved_solid(
    profiles: Sequence[Callable[[np.ndarray], np.ndarray]],
    tol: float = 1e-4,
    *,
    name: str = "tablet",
    names: Sequence[str] | None = None,
    sew_tolerance: float | None = None,
    eps: float | None = None,
    degree: int = 5,
) -> TabletSolid:
    """The solid bounded by a chain of faces of revolution about the z axis.

    Each profile ``f(u) -> (R, Z)`` (mm, ``u`` in [0, 1]; profile ``j`` ends where ``j+1``
    starts) is fitted within ``tol`` by a clamped B-spline of ``degree``
    (:func:`tabletcad.brep.revolved.fit_profiles`: neighbours share their end points bit for bit)
    and revolved exactly (:func:`tabletcad.cad.faces.make_revolved_face`);
    then sewing, validation and mass properties as in :func:`solid_from_surfaces`.
    ``sew_tolerance`` defaults to ``max(2 tol, 1e-6)`` mm.

    ``eps`` defaults to OCCT's non-adaptive integration (``None``), which splits at the
    profile's knots: on these faces it reproduces the exact volume of the revolved
    B-splines (:func:`tabletcad.brep.revolved.revolved_volume`) to ~1e-11 relative, while
    the adaptive one with ``eps = 1e-9`` was measured 3.4e-7 low with an error estimate
    of 2e-15 (concave round sample).
    """
    from tabletcad.brep.revolved import fit_profiles
    from tabletcad.cad.faces import make_revolved_face

    t0 = time.perf_counter()
    names = list(names) if names is not None else [f"patch {j}" for j in range(len(profiles))]
    fits = fit_profiles(profiles, tol, names=names, degree=degree)
    t1 = time.perf_counter()
    surfaces = [f.surface for f in fits]
    # each face is checked as part of the solid (BRepCheck_Analyzer of the solid checks its faces; checking
    # each alone too took 0.8 ms of the compound cup's build); only when that fails one by one, to name it
    faces = tuple(make_revolved_face(sd, name=n, check=False) for sd, n in zip(surfaces, names))
    sew_tol = float(sew_tolerance) if sew_tolerance is not None else max(2.0 * tol, 1e-6)
    try:
        result = _solid_from_faces(faces, names, surfaces, names, fits, sew_tol, eps, name, t1)
    except GeometryError as exc:
        for face, sd, n in zip(faces, surfaces, names):
            if not BRepCheck_Analyzer(face).IsValid():
                raise GeometryError(f"face of {n} is not valid (BRepCheck_Analyzer)", sd) from exc
        raise
    timings = {"fit": t1 - t0, **result.timings}
    timings["total"] = time.perf_counter() - t0
    object.__setattr__(result, "timings", timings)
    return result


def solid_from_tablet(tablet: Any, tol: float = 1e-4, **kwargs: Any) -> TabletSolid:
    """:func:`build_solid` for an object with ``.patches`` (ordered chain) and optionally ``.name``."""
    name = kwargs.pop("name", None) or getattr(tablet, "name", None) or "tablet"
    return build_solid(tablet.patches, tol, name=str(name), **kwargs)
