"""Tetrahedral meshes of B-rep solids, made by gmsh from the exact OpenCascade solid.

The solid is written as a BREP file in a temporary folder (by the CAD layer)
and read back by gmsh's own OpenCascade kernel (``gmsh.model.occ.importShapes``).
Optional cutting planes split the solid (``occ.fragment``) so that a loaded
strip is bounded exactly by mesh facets; the pieces share their faces, so the
mesh stays conforming.  Box and ball size fields refine the mesh near loaded
strips and at points of interest.  The result is plain arrays (linear
tetrahedra); the quadratic field is added by :mod:`tabletcad.fe.elasticity`.
"""

from __future__ import annotations

import contextlib
import tempfile
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from tabletcad.errors import DesignError, GeometryError

__all__ = ["TetMesh", "Refinement", "CutPlane", "mesh_solid", "estimated_dofs", "check_mesh_size", "MAX_DOFS"]

#: Largest number of quadratic-tetrahedron unknowns accepted: a sparse direct solve of about 90,000
#: takes 2-3 GB and its fill grows about as n^(4/3), so 200,000 about 7 GB (1.5 million ran out of
#: 22 GB in SuperLU after minutes, a new user's trial).
MAX_DOFS = 200_000


@dataclass(frozen=True)
class Refinement:
    """A region meshed finer: an axis-aligned box ``lo``-``hi`` (mm) or a ball (``radius`` mm).

    Attributes
    ----------
    lo, hi : tuple of float
        Box corners (mm); for a ball ``lo`` is the centre and ``hi`` is unused.
    size : float
        Element size inside the region (mm).
    radius : float or None
        Ball radius (mm); None for a box.
    """

    lo: tuple[float, float, float]
    hi: tuple[float, float, float]
    size: float
    radius: float | None = None


@dataclass(frozen=True)
class CutPlane:
    """A plane ``normal · x = offset`` (mm) that splits the solid before meshing."""

    normal: tuple[float, float, float]
    offset: float


@dataclass(frozen=True, eq=False)
class TetMesh:
    """A conforming linear tetrahedral mesh.

    Attributes
    ----------
    points : ndarray, shape (n, 3)
        Vertex coordinates, mm.
    tets : ndarray, shape (m, 4)
        Vertex indices of each tetrahedron (positive orientation not assumed).
    size : float
        Nominal element size away from refinements, mm.
    """

    points: np.ndarray
    tets: np.ndarray
    size: float

    @property
    def nodes(self) -> int:
        return int(len(self.points))

    @property
    def elements(self) -> int:
        return int(len(self.tets))

    def volume(self) -> float:
        """Sum of the tetrahedra volumes, mm³."""
        p = self.points[self.tets]
        d = np.einsum("ij,ij->i", p[:, 1] - p[:, 0], np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 0]))
        return float(np.abs(d).sum() / 6.0)


def estimated_dofs(volume: float, size: float) -> float:
    """Rough number of quadratic-tetrahedron unknowns for a solid of ``volume`` mm³ meshed at ``size`` mm.

    A mesh of size ``h`` has about ``7 V / h³`` tetrahedra and about ``1.4 V / h³``
    vertices, and ``ElementTetP2`` has about 8 nodes per vertex, three unknowns each.
    """
    return 3.0 * 8.0 * 1.4 * volume / size / size / size  # (size**3 underflows to 0 below ~1e-103 mm: inf here)


def finest_size(volume: float, dofs: float = MAX_DOFS) -> float:
    """The element size (mm) at which a solid of ``volume`` mm³ has about ``dofs`` unknowns
    (the inverse of :func:`estimated_dofs`)."""
    return (3.0 * 8.0 * 1.4 * volume / dofs) ** (1.0 / 3.0)


def check_mesh_size(volume: float, size: float, name: str = "mesh_size") -> float:
    """Refuse (DesignError) a mesh size whose system would not fit in memory; return ``size``."""
    if not (np.isfinite(size) and size > 0):
        raise DesignError(name, size, "must be > 0", "mm")
    largest = 10.0 * max(volume, 0.0) ** (1.0 / 3.0)  # far coarser than the solid is no mesh (1e200 overflowed)
    if volume > 0 and size > largest:
        raise DesignError(name, size, f"must be <= {largest:.3g} mm (10 x the cube root of the solid's volume)", "mm")
    n = estimated_dofs(volume, size)
    if n > MAX_DOFS:
        smallest = finest_size(volume)
        raise DesignError(name, size, f"must be >= {smallest:.3g} mm for this solid "
                          f"(about {n:.3g} unknowns; at most {MAX_DOFS:.3g} fit in memory)", "mm")
    return size


@contextlib.contextmanager
def _gmsh_session() -> Iterator[Any]:
    import gmsh

    gmsh.initialize(readConfigFiles=False, interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.NumThreads", 1)
        gmsh.model.add("tabletcad")
        yield gmsh
    finally:
        gmsh.finalize()


def _add_plane(gmsh: Any, plane: CutPlane, lo: np.ndarray, hi: np.ndarray) -> tuple[int, int]:
    """A rectangle in ``plane`` covering the box ``lo``-``hi`` (with margin)."""
    n = np.asarray(plane.normal, float)
    n = n / np.linalg.norm(n)
    c = 0.5 * (lo + hi)
    c = c + (plane.offset - n @ c) * n
    big = 2.0 * float(np.linalg.norm(hi - lo)) + 1.0
    a = np.cross(n, [0.0, 0.0, 1.0]) if abs(n[2]) < 0.9 else np.cross(n, [1.0, 0.0, 0.0])
    a /= np.linalg.norm(a)
    b = np.cross(n, a)
    corners = [c + big * (sa * a + sb * b) for sa, sb in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    occ = gmsh.model.occ
    pts = [occ.addPoint(*q) for q in corners]
    lines = [occ.addLine(pts[i], pts[(i + 1) % 4]) for i in range(4)]
    loop = occ.addCurveLoop(lines)
    return (2, occ.addPlaneSurface([loop]))


def _box_centre(occ: Any, dimtag: tuple[int, int]) -> np.ndarray:
    """Centre of an entity's bounding box (mm): on the side of a cutting plane normal to an axis
    where the piece lies (and much cheaper than the centre of mass of a B-spline piece)."""
    b = np.asarray(occ.getBoundingBox(*dimtag), float)
    return 0.5 * (b[:3] + b[3:])


#: What :func:`mesh_solid` changes, in order, when gmsh fails to mesh a solid: a surface mesh that
#: follows the curvature (a coarse one can leave facets of the curved cup crossing the band's, "PLC
#: Error: A segment and a facet intersect"), then the Frontal-Delaunay surface and HXT volume algorithms.
RETRIES = ({"Mesh.MeshSizeFromCurvature": 16}, {"Mesh.Algorithm": 6, "Mesh.Algorithm3D": 10})


def _generate(gmsh, solid) -> None:
    """``gmsh.model.mesh.generate(3)``, retried with the settings of :data:`RETRIES`; a solid none of
    them meshes is a :class:`GeometryError` naming gmsh's message."""
    first = None
    for settings in ({}, *RETRIES):
        for k, v in settings.items():
            gmsh.option.setNumber(k, v)
        try:
            gmsh.model.mesh.generate(3)
            return
        except Exception as exc:  # gmsh raises Exception with its last error message
            first = first or str(exc)
            gmsh.model.mesh.clear()
    raise GeometryError(f"mesh: gmsh could not mesh the solid ({first}), also with {len(RETRIES)} other settings",
                        solid)


def mesh_solid(
    solid: Any,
    size: float,
    *,
    refinements: Sequence[Refinement] = (),
    cuts: Sequence[CutPlane] = (),
    keep: Sequence[CutPlane] = (),
) -> TetMesh:
    """Mesh a B-rep solid (TopoDS_Shape / TabletSolid / build123d or cadquery solid) with tetrahedra.

    Parameters
    ----------
    solid
        The solid; written to a temporary BREP file by :func:`tabletcad.cad.export.export_brep`.
    size : float
        Element size away from refinements, mm.
    refinements : sequence of Refinement
        Finer regions (box or ball size fields, combined by their minimum).
    cuts : sequence of CutPlane
        Planes splitting the solid before meshing (conforming pieces).
    keep : sequence of CutPlane
        Half-spaces ``normal · x >= offset`` to keep, ``normal`` a coordinate axis: the solid is
        also split by these planes and only the pieces inside all of them are meshed (a
        symmetric part of the solid, e.g. the quarter of a tablet cut by two mirror planes).
    """
    from tabletcad.cad.export import export_brep

    with tempfile.TemporaryDirectory(prefix="tabletcad-fe-") as tmp:
        path = Path(tmp) / "solid.brep"
        export_brep(solid, path)
        with _gmsh_session() as gmsh:
            occ = gmsh.model.occ
            ents = occ.importShapes(str(path))
            occ.synchronize()
            vols = [e for e in ents if e[0] == 3]
            if len(vols) != 1:
                raise GeometryError(f"mesh: expected one solid, gmsh read {len(vols)}", solid)
            lo = np.array(gmsh.model.getBoundingBox(-1, -1)[:3])
            hi = np.array(gmsh.model.getBoundingBox(-1, -1)[3:])
            if cuts or keep:
                tools = [_add_plane(gmsh, c, lo, hi) for c in (*cuts, *keep)]
                occ.fragment(vols, tools)
                occ.synchronize()
                out = [v for v in gmsh.model.getEntities(3) if any(np.dot(k.normal, _box_centre(occ, v)) < k.offset
                                                                    for k in keep)]
                if out:
                    occ.remove(out, recursive=True)
                    occ.synchronize()
                if not gmsh.model.getEntities(3):
                    raise GeometryError("mesh: no part of the solid is inside the kept half-spaces", solid)
                keep = {f[1] for v in gmsh.model.getEntities(3)
                        for f in gmsh.model.getBoundary([v], oriented=False)}
                loose = [e for e in gmsh.model.getEntities(2) if e[1] not in keep]
                if loose:
                    occ.remove(loose, recursive=True)
                    occ.synchronize()
            fld = gmsh.model.mesh.field
            ids = []
            for r in refinements:
                if r.radius is not None:
                    f = fld.add("Ball")
                    for k, v in zip(("XCenter", "YCenter", "ZCenter"), r.lo):
                        fld.setNumber(f, k, float(v))
                    fld.setNumber(f, "Radius", float(r.radius))
                else:
                    f = fld.add("Box")
                    for k, v in zip(("XMin", "YMin", "ZMin", "XMax", "YMax", "ZMax"), (*r.lo, *r.hi)):
                        fld.setNumber(f, k, float(v))
                fld.setNumber(f, "VIn", float(r.size))
                fld.setNumber(f, "VOut", float(size))
                ids.append(f)
            if ids:
                f = fld.add("Min")
                fld.setNumbers(f, "FieldsList", ids)
                fld.setAsBackgroundMesh(f)
                gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
                gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
            gmsh.option.setNumber("Mesh.MeshSizeMax", float(size))
            gmsh.option.setNumber("Mesh.MeshSizeMin", float(min([size] + [r.size for r in refinements])) / 4)
            _generate(gmsh, solid)
            tags, xyz, _ = gmsh.model.mesh.getNodes()
            etypes, _, enodes = gmsh.model.mesh.getElements(3)
        tets_tags = np.concatenate([n for t, n in zip(etypes, enodes) if t == 4]) if len(etypes) else np.zeros(0)
    if tets_tags.size == 0:
        raise GeometryError("mesh: gmsh produced no tetrahedra", solid)
    tags = tags.astype(np.int64)
    index = np.full(int(tags.max()) + 1, -1, dtype=np.int64)
    index[tags] = np.arange(len(tags))
    tets = index[tets_tags.astype(np.int64)].reshape(-1, 4)
    used = np.unique(tets)
    remap = np.full(len(tags), -1, dtype=np.int64)
    remap[used] = np.arange(len(used))
    points = xyz.reshape(-1, 3)[used]
    return TetMesh(points=points, tets=remap[tets], size=float(size))
