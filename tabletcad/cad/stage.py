"""The CAD stage of ``tabletcad build``: solid, checks, STEP/STL/GLB, report sections.

Registered with :func:`tabletcad.build.register_stage` on import.  It adds to
``report.json``:

* ``brep``: ``valid``, ``volume_mm3`` and ``surface_area_mm2`` (adaptive OCC
  mass properties), ``fit_max_deviation_mm``, ``faces``, the relative
  differences from the core's quadrature, and the time taken;
* ``mesh``: ``manifold``, ``watertight``, ``winding_consistent``, ``genus``,
  ``volume_mm3`` (manifold3d), ``triangles`` and the deflections used.

A tablet whose B-rep volume or area differs from the quadrature by more than
``1e-6`` relative, or whose mesh fails a check, is an error: nothing is written.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import OCP  # noqa: F401  (no OpenCascade: ImportError, and the build writes the core outputs only)

from tabletcad.build import register_stage
from tabletcad.errors import GeometryError
from tabletcad.tablet import Tablet

__all__ = ["cad_stage", "check_tablet_solid", "MESH_LINEAR_MM", "MESH_ANGULAR_RAD", "AGREEMENT_REL"]

MESH_LINEAR_MM = 0.005
MESH_ANGULAR_RAD = 0.2
AGREEMENT_REL = 1e-6


def check_tablet_solid(tablet: Tablet, report: dict[str, Any] | None = None):
    """Build the solid and its mesh and cross-check them; return ``(solid, mesh, sections)``."""
    from tabletcad.cad.mesh import tessellate
    from tabletcad.cad.tablet_solid import tablet_solid

    t0 = time.perf_counter()
    solid = tablet_solid(tablet)
    t1 = time.perf_counter()
    v_q = report["volume_mm3"] if report else tablet.volume()
    a_q = report["surface_area_mm2"] if report else tablet.surface_area()
    dv = (solid.volume - v_q) / v_q
    da = (solid.area - a_q) / a_q
    dev = max(f.max_deviation for f in solid.fits)
    if abs(dv) > AGREEMENT_REL or abs(da) > AGREEMENT_REL:
        raise GeometryError(
            f"{tablet.name}: B-rep volume/area differ from the quadrature by {dv:.2e}/{da:.2e} relative "
            f"(allowed {AGREEMENT_REL:g}; largest fit deviation {dev:.2e} mm)",
            solid,
        )
    mesh = tessellate(solid.shape, MESH_LINEAR_MM, MESH_ANGULAR_RAD)
    t2 = time.perf_counter()
    genus_expected = 1 if tablet.trim.w[0] > 0 else 0
    sections = dict(
        brep=dict(
            valid=True,
            volume_mm3=solid.volume,
            surface_area_mm2=solid.area,
            fit_max_deviation_mm=dev,
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
            volume_mm3=mesh.manifold_volume,
            volume_rel_diff_vs_brep=(mesh.volume - solid.volume) / solid.volume,
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


def cad_stage(*, tablet: Tablet, out: Path, report: dict[str, Any], design_path=None) -> None:
    """Write ``tablet.step``, ``tablet.stl`` and ``tablet.glb`` into ``out`` and extend ``report``."""
    from tabletcad.cad.export import export

    t = tablet.trim
    if t.u != (0.0, 1.0) or not t.full_v:
        report["brep"] = dict(valid=None, skipped="cut-away view (trimmed in u or v): picture and mesh only")
        return
    solid, mesh, sections = check_tablet_solid(tablet, report)
    t0 = time.perf_counter()
    export(solid, out / "tablet.step", name=tablet.name)
    export(solid, out / "tablet.stl", name=tablet.name, mesh=mesh)
    export(solid, out / "tablet.glb", name=tablet.name, mesh=mesh)
    sections["brep"]["export_seconds"] = time.perf_counter() - t0
    report.update(sections)


register_stage("cad", cad_stage)

try:  # the tooling stage (punches, die, drawings) registers itself after the CAD stage
    import tabletcad.tooling.stage  # noqa: F401,E402
except ImportError:  # pragma: no cover - tooling is optional
    pass
