"""The CAD stage of ``tabletcad build``: solid, checks, STEP/STL/GLB, report sections.

:func:`tabletcad.pipeline.build.build_tablet` calls :func:`cad_stage`, which adds to
``report.json``:

* ``brep``: ``valid``, ``volume_mm3`` and ``surface_area_mm2`` (Gauss-Legendre on the
  faces' own B-spline data, :func:`~tabletcad.brep.surface.volume_and_area`),
  ``fit_max_deviation_mm``, ``faces``, the relative
  differences from the core's quadrature, and the time taken;
* ``mesh``: ``manifold``, ``watertight``, ``winding_consistent``, ``genus``,
  ``volume_mm3`` (manifold3d), ``triangles`` and the deflections used.

A tablet whose B-rep volume or area differs from the quadrature by more than
``1e-6`` relative is fitted again at a tenth of the fit tolerance (twice at most;
``fit_tolerance_mm`` says which fit was kept); one that still differs, or whose mesh
fails a check, is an error: nothing is written.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from tabletcad.errors import GeometryError
from tabletcad.geometry.tablet import Tablet
from tabletcad.tolerance import DEFAULT

__all__ = ["cad_stage", "check_tablet_solid", "MESH_LINEAR_MM", "MESH_ANGULAR_RAD", "AGREEMENT_REL"]

MESH_LINEAR_MM = DEFAULT.mesh_deflection
MESH_ANGULAR_RAD = DEFAULT.mesh_angle
AGREEMENT_REL = DEFAULT.brep_agreement
#: fits after the first, each a tenth as far from the PDE surface, tried when the faces' volume or area misses
#: the quadrature by more than AGREEMENT_REL
REFITS = 2


def refitted(tol: float, measured, refused):
    """The first of the fits at ``tol``, ``tol / 10``, ... (``REFITS`` after the first) whose solid agrees with
    the core's quadrature: ``(solid, tol, differences)``.

    A fit within its distance tolerance may still move the volume or area by more than the agreement asked
    for (a tolerance of 1e-4 mm over a 5 mm sphere's 79 mm² allows 1e-4 of its volume): the faces are then
    fitted again, a tenth as far from the PDE surface.  ``measured(tol)`` makes the solid and returns
    ``(solid, *relative differences)``; ``refused(solid, tol, *differences)`` the error raised for the last
    fit made when it still misses (a finer fit that cannot be made ends the refits).
    """
    last = None
    for _ in range(REFITS + 1):
        try:
            solid, *diffs = measured(tol)
        except GeometryError:
            if last is None:
                raise
            break  # a finer fit that cannot be made (too many poles, sewing): the last one made is reported
        if all(abs(d) <= AGREEMENT_REL for d in diffs):  # (a NaN difference is no agreement)
            return solid, tol, diffs
        last = (solid, tol, diffs)
        tol /= 10.0
    solid, tol, diffs = last
    raise refused(solid, tol, *diffs)


def check_tablet_solid(tablet: Tablet, report: dict[str, Any] | None = None):
    """Build the solid and its mesh and cross-check them; return ``(solid, mesh, sections)``.

    A tablet of revolution gets faces of revolution (:func:`~tabletcad.cad.tablet_solid.tablet_solid`)."""
    from tabletcad.cad.mesh import tessellate_solid
    from tabletcad.cad.tablet_solid import tablet_solid

    t0 = time.perf_counter()
    v_q = report["volume_mm3"] if report else tablet.volume()
    a_q = report["surface_area_mm2"] if report else tablet.surface_area()

    def measured(tol: float):
        solid = tablet_solid(tablet, tol)
        # the B-rep's own surfaces (poles, knots) integrated by Gauss-Legendre: exact for the volume,
        # within ~1e-9 for the area, and 5-25x cheaper than OCC's adaptive integration of the faces
        volume, area = abs(solid.data_volume_area[0]), solid.data_volume_area[1]
        dev = max(f.max_deviation for f in solid.fits)
        return (solid, volume, area, dev), (volume - v_q) / v_q, (area - a_q) / a_q

    def refused(made, tol: float, dv: float, da: float) -> GeometryError:
        return GeometryError(
            f"{tablet.name}: B-rep volume/area differ from the quadrature by {dv:.2e}/{da:.2e} relative "
            f"(allowed {AGREEMENT_REL:g}; largest fit deviation {made[3]:.2e} mm at a fit tolerance of {tol:.0e} mm)",
            made[0],
        )

    (solid, volume, area, dev), tol, (dv, da) = refitted(tablet.tol.fit, measured, refused)
    t1 = time.perf_counter()
    mesh = tessellate_solid(solid, MESH_LINEAR_MM, MESH_ANGULAR_RAD)
    t2 = time.perf_counter()
    genus_expected = 1 if tablet.trim.w[0] > 0 else 0
    sections = dict(
        brep=dict(
            valid=True,
            volume_mm3=volume,
            surface_area_mm2=area,
            integration="Gauss-Legendre on the faces' B-spline data",
            fit_max_deviation_mm=dev,
            fit_tolerance_mm=tol,
            faces=len(solid.faces),
            poles=[[int(n) for n in s.shape] for s in solid.surfaces],  # (nu, nv) poles of each face
            volume_rel_diff_vs_quadrature=dv,
            area_rel_diff_vs_quadrature=da,
            seconds=t1 - t0,
        ),
        mesh=dict(
            manifold=mesh.is_manifold,
            watertight=bool(mesh.watertight),
            winding_consistent=bool(mesh.winding_consistent),
            genus=mesh.manifold_genus,
            genus_expected=genus_expected,
            # the written mesh's own volume (divergence theorem on its triangles), and manifold3d's of the same
            # triangles beside it (float32 vertices; on a folded mesh the two part: a trial)
            volume_mm3=mesh.volume,
            manifold3d_volume_mm3=mesh.manifold_volume,
            volume_rel_diff_vs_brep=(mesh.volume - volume) / volume,
            triangles=int(len(mesh.triangles)),
            linear_deflection_mm=MESH_LINEAR_MM,
            angular_deflection_rad=MESH_ANGULAR_RAD,
            seconds=t2 - t1,
        ),
    )
    if not mesh.ok or mesh.manifold_genus != genus_expected:
        raise GeometryError(
            f"{tablet.name}: mesh check failed (manifold3d {mesh.manifold_status}, genus {mesh.manifold_genus} "
            f"expected {genus_expected}, watertight {mesh.watertight}, winding {mesh.winding_consistent})",
            mesh,
        )
    return solid, mesh, sections


def _cut_plane_angle(tablet: Tablet, v: float) -> float | None:
    """Plan angle (rad) of the half-plane holding the solid map's ``v = const`` face
    ``A0(u) + w (X(u, v) - A0(u))`` of every patch, or None when that face is not such a
    half-plane (spine off the z axis, or the section turning with ``u``)."""
    u = np.linspace(0.0, 1.0, 33)
    size = max(tablet.dimensions().values())
    angles = []
    for p in tablet.patches:
        A = p.spine(u)
        X = p.evaluate(u, np.full_like(u, v))
        if np.max(np.abs(A[:, :2])) > 1e-9 * size:
            return None
        d = X[:, :2] - A[:, :2]
        r = np.hypot(d[:, 0], d[:, 1])
        ok = r > 1e-9 * size
        angles.extend(np.arctan2(d[ok, 1], d[ok, 0]))
    if not angles:
        return None
    a = np.unwrap(np.asarray(angles))
    return float(a[0]) if np.ptp(a) <= 1e-9 else None


def _wedge(phi0: float, phi1: float, radius: float, z0: float, z1: float):
    """Prism over the plan sector ``phi0 <= φ <= phi1`` of the given radius (mm), z from z0 to z1."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakePolygon
    from OCP.BRepPrimAPI import BRepPrimAPI_MakePrism
    from OCP.gp import gp_Pnt, gp_Vec

    n = max(2, int(np.ceil((phi1 - phi0) / (np.pi / 6.0))))
    R = radius / np.cos((phi1 - phi0) / (2.0 * n))  # the polygon's chords stay outside the circle
    poly = BRepBuilderAPI_MakePolygon()
    poly.Add(gp_Pnt(0.0, 0.0, z0))
    for f in np.linspace(phi0, phi1, n + 1):
        poly.Add(gp_Pnt(R * np.cos(f), R * np.sin(f), z0))
    poly.Close()
    face = BRepBuilderAPI_MakeFace(poly.Wire(), True).Face()
    return BRepPrimAPI_MakePrism(face, gp_Vec(0.0, 0.0, z1 - z0)).Shape()


class CutawayShape(NamedTuple):
    """The checked solid of a cut-away view (:func:`cutaway_shape`), before its mesh
    (:func:`cutaway_mesh`)."""

    name: str  #: the tablet's name
    shape: Any  #: the ``TopoDS_Solid``
    chain: Any  #: the fitted and sewn chain (a ``TabletSolid``) of a cut-away with ruled cut faces, else None
    volume_mm3: float  #: OCC's volume of the solid
    surface_area_mm2: float  #: OCC's area of the solid
    volume_rel_diff_vs_quadrature: float
    how: str  #: how the solid was made (``brep.cutaway``)
    seconds: float
    fit_tolerance_mm: float  #: the fit tolerance of the faces kept (:func:`refitted`)


def cutaway_solid(tablet: Tablet, report: dict[str, Any]):
    """The solid of a tablet trimmed in ``v`` (a cut-away view): ``(solid shape, mesh, sections)``,
    or a string saying why it is not built: :func:`cutaway_shape`, then :func:`cutaway_mesh`.

    When every patch's ``v = v0`` and ``v = v1`` faces of the solid map are half-planes
    through the z axis (tablets of revolution: circles about the spine), the cut-away is the
    whole solid (hollow if ``[trim] w`` says so) in common with a wedge between those
    half-planes (``BRepAlgoAPI_Common``).  Otherwise (shaped outlines, whose cut faces are
    ruled surfaces between the spine and the section curve) the cut-away of a full solid
    is fitted and sewn directly as one closed chain
    (:func:`~tabletcad.brep.surfaces.cutaway_surface_functions`).  Its volume must agree
    with the core's quadrature over the trimmed domain within ``AGREEMENT_REL`` and its mesh
    must pass the checks.
    """
    made = cutaway_shape(tablet, report, _stacklevel=3)
    return made if isinstance(made, str) else cutaway_mesh(made)


def cutaway_shape(tablet: Tablet, report: dict[str, Any], *, _stacklevel: int = 2) -> CutawayShape | str:
    """The solid of :func:`cutaway_solid`, made and checked (BRepCheck, its volume against the quadrature
    ``report["volume_mm3"]``), without its mesh: a :class:`CutawayShape`, or a string saying why it is
    not built (what :meth:`tabletcad.pipeline.model.TabletModel.to_occ` needs; the mesh when asked for)."""
    from dataclasses import replace

    from OCP.BRepAlgoAPI import BRepAlgoAPI_Common

    from tabletcad.cad.solid import check_solid, mass_properties
    from tabletcad.cad.tablet_solid import tablet_solid
    from tabletcad.geometry.tablet import Trim

    t = tablet.trim
    if t.u != (0.0, 1.0):
        return "trimmed in u (its cut faces are not planes)"
    v0, v1 = t.v
    from tabletcad.cad._occ import explore

    phi0, phi1 = _cut_plane_angle(tablet, v0), _cut_plane_angle(tablet, v1)
    t0 = time.perf_counter()
    sewn = phi0 is None or phi1 is None
    if sewn:
        if t.w != (0.0, 1.0):
            return "hollow ([trim] w) with cut faces that are not planes through the axis"
        from tabletcad.cad.solid import build_solid
        from tabletcad.brep.surfaces import cutaway_surface_functions, fit_options

        funcs, breaks = cutaway_surface_functions(tablet)
        names = [f"{p.name or f'patch {j}'} cut-away" for j, p in enumerate(tablet.patches)]
        how = ("fitted and sewn as one chain: the outer surface between the cuts and the ruled cut faces "
               f"A0(u) + w (X(u, v) - A0(u)) at v = {v0:.6g} and {v1:.6g}")
        import warnings

        # a trial: the ruled cut faces of a patch without volume (a flat plateau or land) lie on that patch's
        # own face, and where a cup's spine runs off-centre they can cross the neighbouring cut face; OCC's
        # BRepCheck passes the solid, gmsh refuses to mesh it ("overlapping facets")
        warnings.warn(f"{tablet.name}: the cut-away of a shaped tablet is a view: its ruled cut faces can overlap "
                      "where a patch has no volume (a flat plateau or land), so a mesher or a Boolean may refuse "
                      "tablet.step (BRepCheck passes it); cut the whole tablet's STEP in your CAD program for a "
                      "solid to mesh", UserWarning, stacklevel=_stacklevel)
    else:
        # angles grow with v (counter-clockwise sections); the kept sector runs from phi0 to phi1
        span = (phi1 - phi0) % (2.0 * np.pi) or 2.0 * np.pi
        size = 10.0 * max(tablet.dimensions().values())
        how = (f"whole solid in common with the wedge between the half-planes at {phi0:.6g} and "
               f"{phi0 + span:.6g} rad (BRepAlgoAPI_Common)")
    v_q = report["volume_mm3"]

    def measured(tol: float):
        """The cut-away's shape and fitted chain (None for the wedge's) at fit tolerance ``tol``, checked, its
        mass properties and their volume's difference from the quadrature."""
        chain = None
        if sewn:
            chain = build_solid(funcs, tol, name=f"{tablet.name} cut-away", names=names, flat_regions=False,
                                **fit_options(tablet, v_breaks=breaks))
            shape = chain.shape
        else:
            whole = tablet_solid(replace(tablet, trim=Trim(w=t.w)), tol)
            common = BRepAlgoAPI_Common(whole.shape, _wedge(phi0, phi0 + span, size, -size, size))
            if not common.IsDone():
                raise GeometryError(f"{tablet.name}: cutting the cut-away solid failed", tablet)
            solids = explore(common.Shape(), "Solid")
            if len(solids) != 1:
                raise GeometryError(f"{tablet.name}: the cut-away gave {len(solids)} solids, not one", tablet)
            shape = solids[0]
        check_solid(shape, f"{tablet.name} cut-away")
        mass = mass_properties(shape)
        return (shape, chain, mass), (mass.volume - v_q) / v_q

    def refused(made, tol: float, dv: float) -> GeometryError:
        return GeometryError(f"{tablet.name}: cut-away B-rep volume differs from the quadrature by {dv:.2e} relative "
                             f"(allowed {AGREEMENT_REL:g} at a fit tolerance of {tol:.0e} mm)", made[0])

    (shape, chain, mass), tol, (dv,) = refitted(tablet.tol.fit, measured, refused)
    t1 = time.perf_counter()
    return CutawayShape(tablet.name, shape, chain, mass.volume, mass.area, dv, how, t1 - t0, tol)


def cutaway_mesh(made: CutawayShape):
    """The rest of :func:`cutaway_solid` for the solid ``made`` by :func:`cutaway_shape`: its mesh, checked,
    and the report's sections: ``(solid shape, mesh, sections)``.  A wedge-cut solid whose mesh fails a
    check is an error; a directly sewn one's (ruled cut faces) gets no mesh (None) and says why."""
    from tabletcad.cad._occ import explore
    from tabletcad.cad.mesh import tessellate, tessellate_solid

    shape, chain = made.shape, made.chain
    # the sewn chain is meshed on its faces' parameter grids (BRepMesh left cracks in the almond's
    # ruled cut faces), the wedge-cut solid by BRepMesh
    mesh = (tessellate_solid(chain, MESH_LINEAR_MM, MESH_ANGULAR_RAD) if chain is not None
            else tessellate(shape, MESH_LINEAR_MM, MESH_ANGULAR_RAD))
    genus_expected = 0
    brep = dict(valid=True, volume_mm3=made.volume_mm3, surface_area_mm2=made.surface_area_mm2,
                faces=len(explore(shape, "Face")),
                volume_rel_diff_vs_quadrature=made.volume_rel_diff_vs_quadrature, cutaway=made.how,
                fit_tolerance_mm=made.fit_tolerance_mm, seconds=made.seconds)
    if not mesh.ok or mesh.manifold_genus != genus_expected:
        failed = (f"manifold3d {mesh.manifold_status}, genus {mesh.manifold_genus}, watertight {mesh.watertight}, "
                  f"winding {mesh.winding_consistent}")
        if chain is not None:
            # the directly sewn cut-away is a valid B-rep of the right volume, but where its grid does not
            # close, OCC's tessellation of its ruled cut faces can leave cracks (it did on the almond):
            # the STEP is written, no STL/GLB
            return shape, None, dict(brep=brep, mesh=dict(skipped=f"the tessellation is not a closed mesh ({failed}): "
                                                                 "tablet.step only, no tablet.stl/.glb"))
        raise GeometryError(f"{made.name}: cut-away mesh check failed ({failed})", mesh)
    sections = dict(
        brep=brep,
        mesh=dict(manifold=mesh.is_manifold, watertight=bool(mesh.watertight), winding_consistent=bool(mesh.winding_consistent),
                  genus=mesh.manifold_genus, genus_expected=genus_expected, volume_mm3=mesh.volume,
                  manifold3d_volume_mm3=mesh.manifold_volume,
                  volume_rel_diff_vs_brep=(mesh.volume - made.volume_mm3) / made.volume_mm3,
                  triangles=int(len(mesh.triangles)),
                  linear_deflection_mm=MESH_LINEAR_MM, angular_deflection_rad=MESH_ANGULAR_RAD),
    )
    return shape, mesh, sections


def _open_end(tablet: Tablet) -> str | None:
    """``"first"`` or ``"last"`` when the chain's first or last boundary curve encloses an area (a
    free-form band without caps): the core closes it with the solid map's flat end face, the fitted
    chain of patch surfaces does not.  A pole and a cup folded onto a segment enclose none."""
    for name, patch, u in (("first", tablet.patches[0], 0.0), ("last", tablet.patches[-1], 1.0)):
        v = np.linspace(0.0, 2.0 * np.pi, 257)
        x = patch.evaluate(np.full(v.shape, u), v)
        size = float(np.ptp(x, axis=0).max())
        if size <= 1e-9 * max(1.0, float(np.max(np.abs(x)))):  # a pole, to rounding
            continue
        x = x - x.mean(axis=0)  # about its centre: no rounding of the position magnified into an area
        area = 0.5 * np.sum(np.cross(x[:-1], x[1:] - x[:-1]), axis=0)  # the curve's vector area
        if float(np.linalg.norm(area)) > 1e-6 * size * size:
            return name
    return None


def cad_stage(*, tablet: Tablet, out: Path, report: dict[str, Any]):
    """Write ``tablet.step``, ``tablet.stl`` and ``tablet.glb`` into ``out`` and extend ``report``.

    Returns the ``TopoDS_Shape`` written (the solid, or its cut-away), or None when no solid
    is built (a cut-away of a kind the CAD layer does not make: the report says why).
    """
    from tabletcad.cad.export import export

    t = tablet.trim
    if t.w != (0.0, 1.0) and len(tablet.patches) != 1:  # (tabletcad.brep.surfaces makes one-patch ones)
        report["brep"] = dict(valid=None, skipped=f"hollow ([trim] w) tablet of {len(tablet.patches)} patches: "
                              "hollow solids are made of one-patch tablets only; picture only")
        return None
    open_end = _open_end(tablet) if t.w == (0.0, 1.0) and t.u == (0.0, 1.0) else None
    if open_end is not None:
        report["brep"] = dict(valid=None, skipped=f"the chain's {open_end} curve encloses an area: its solid "
                              "would need a flat end face, which the CAD layer does not add (give the chain a "
                              "pole or a cap patch there); picture only")
        return None
    if t.u != (0.0, 1.0) or not t.full_v:
        cut = cutaway_solid(tablet, report)
        if isinstance(cut, str):
            report["brep"] = dict(valid=None, skipped=f"cut-away view: {cut}; picture only")
            return None
        shape, mesh, sections = cut
    else:
        solid, mesh, sections = check_tablet_solid(tablet, report)
        shape = solid.shape
    t0 = time.perf_counter()
    export(shape, out / "tablet.step", name=tablet.name)
    if mesh is not None:  # a cut-away whose tessellation failed its checks writes the STEP only
        export(shape, out / "tablet.stl", name=tablet.name, mesh=mesh)
        export(shape, out / "tablet.glb", name=tablet.name, mesh=mesh)
    sections["brep"]["export_seconds"] = time.perf_counter() - t0
    report.update(sections)
    return shape
