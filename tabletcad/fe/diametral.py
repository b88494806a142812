"""Diametral compression (the breaking-force test of USP <1217>) of any tablet by finite elements.

The tablet's own B-rep solid is meshed with tetrahedra (:mod:`tabletcad.fe.mesh`)
and loaded across a plan direction by two flat platens.  Each platen is
modelled as a uniform normal pressure on the part of the surface it would
touch if it were pressed a small depth ``δ`` into the tablet: the boundary
within ``δ`` of the tablet's extreme plane that faces the platen (outward
normal within 37° of the load axis).  ``δ`` is set from a strip width ``b``
(mm): it is the depth at which a flat platen cuts a chord ``b`` from a circle
of diameter ``D`` (the extent along the load), so on a round tablet the loaded
region is exactly a strip of width ``b`` across the band, and on an elongated
tablet loaded across its width it covers the straight flanks.  The solid is
split at the depth ``δ`` before meshing, so the loaded region is bounded by
mesh facets.  Each pressure is scaled so that its resultant along the load is
exactly ``P``.  The body is held by a 3-2-1 support at its centre, which
carries no load (the two platens balance).

Default strip width: ``b = D/10`` with ``D`` the tablet's extent along the
load.  It is the width over which a platen spreads on a tablet in practice
(a few tenths of a mm to 1 mm) and it keeps the centre stress within about
1 % of the line-load value ``2P/(πDt)`` (Hondros factor 0.988), while the
strip is wide enough to be resolved by a few elements instead of a singular
line load.

Results: the tensile stress at the centre (normal stress perpendicular to the
load, at mid-thickness; recovered by a quadratic least-squares fit of the
element stresses within ``1.5 h`` of the centre, see
:meth:`~tabletcad.fe.elasticity.ElasticSolution.recovered_stress_at`), the
largest tensile stress and where it is (below), and the shape factor
``σ_t,centre · πDt/(2P)``.

The largest tensile stress
--------------------------
``max_tensile_stress_MPa`` is the largest maximum principal stress of the
stress *averaged over a ball of radius* ``R`` (default ``R = min(b, t/6)``,
``b`` the strip width, ``t`` the thickness: 0.77 mm on a 10 mm round 4.6 mm
thick), sampled on a fixed grid of the *loaded
diametral plane* (the plane through the centre holding the load axis and the
tablet's axis), farther than ``b`` from the platens' planes
(:func:`split_plane_points`: 41 points along the load, 9 from face to face,
faces included; :meth:`~tabletcad.fe.elasticity.ElasticSolution.averaged_stress`).

Why this quantity.  A valid diametral test ends in a split along the loaded
diametral plane (USP <1217>); the stress that opens it is the normal stress
across that plane, a principal stress there whenever the tablet is mirror
symmetric about it, so the first crack of a valid test starts where this
quantity peaks (the centre of a thin disc, the cup faces of a deep convex
tablet).  A pointwise maximum is not a usable figure: the uniform pressure
jumps at the strip's edges, so the elastic stress near the platens is set by
the idealised contact, grows under refinement there, and the vertex value of
the largest stress jumps with the mesh (on a 10 mm concave round with 0.9 mm
cups at σ_t = 2 MPa, the coarse-mesh breaking force read 31, 73, 53, 74, 52,
71 N for bands 1.5-4 mm).  Averaging over a ball no wider than the strip ``b`` gives the
stress on the scale the load model resolves (how the force spreads within
``b`` is not modelled) and, like the critical-distance (volume) criteria of
brittle fracture, asks for tension over a volume of material, not at a
point.  The cap ``t/6`` keeps the ball's diameter within a third of the
thickness, so the average still tells the faces from the mid-plane (which of
them peaks decides where a convex tablet cracks first); on thin or elongated
tablets ``b = D/10`` alone would average over the whole thickness.  ``R``
scales with the tablet, so the prediction stays self-similar: a tablet scaled
by ``k`` breaks at ``k²`` times the force, as eq 2.4 assumes.

Why it converges.  The average is an integral of the stress against a fixed
smooth weight (``(1 - r²/R²)²``) over a ball fixed in space, and the sample
points are fixed in coordinates normalised by the tablet's extent and its
faces' heights; only the quadrature of that integral depends on the mesh.
Measured on that concave round (band 2.8 mm, ``R`` = 0.767 mm, meshes 1.6,
1.2, 0.9 mm): 0.01658, 0.01555, 0.01508 MPa per N, differences falling by 2.2
(observed order 2.8), Richardson limit 0.01470; with ``R = b`` = 1 mm the
differences fall by about 3 per 4/3 refinement (order 3.5-4).  The vertex
maximum of the old definition never settled (``tests/test_fe_diametral.py``).
Symmetric designs may declare it (``symmetric=True``): the four mirror images
of every sample point are then averaged, which cancels the part of the error
an unsymmetric mesh puts on them.

Hondros' solution
-----------------
For a disc of diameter ``D`` and thickness ``t`` in plane stress with a radial
pressure ``p`` on two opposite arcs of half-angle ``α`` (Hondros, Aust. J.
Appl. Sci. 10 (1959) 243-268), superposing Flamant's radial stress of every
load element (``-2f cos θ'/(π r')``) and the uniform tension ``f/(πD)`` that each
radial boundary load adds (Michell's disc solution) gives at the centre, in the
direction perpendicular to the load,

    σ_t = (2 p / π) (sin 2α - α).

The arcs' resultant along the load is ``P = 2 p R t sin α = p D t sin α``, hence

    σ_t = 2P/(π D t) · (sin 2α - α)/sin α,  α = arcsin(b/D),

which tends to the line-load value ``2P/(πDt)`` (thesis eq 2.4) as ``b → 0``.
(Hondros wrote ``P ≈ 2αpRt``, i.e. ``(sin 2α - α)/α``; the two differ by
``O(α²)``; the form above matches the FE load, whose resultant is exactly P.)
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from tabletcad.errors import MISSING, DesignError, GeometryError, check_positive, check_range, format_bound
from tabletcad.tolerance import DEFAULT
from tabletcad.tolerance import MIN_FORCE_N
from tabletcad.fe.elasticity import Material, PressureLoad, boundary_facets, principal_stresses, solve_elasticity
from tabletcad.fe.mesh import (MAX_DOFS, CutPlane, Refinement, check_mesh_size, estimated_dofs, finest_size,
                               mesh_solid)

__all__ = ["DIRECTIONS", "DiametralResult", "diametral", "hondros_centre_stress", "line_load_stress",
           "load_axis", "STRIP_FRACTION", "default_averaging_radius", "largest_tensile", "split_plane_points",
           "PLANE_MESH_FACTOR", "COARSENING", "RECOVERY_RADIUS", "contact_depth"]

DIRECTIONS = ("width", "length", "x", "y")
#: Default strip width as a fraction of the extent along the load.
STRIP_FRACTION = 0.1
#: Ratio of the coarse to the fine mesh size used for the discretisation-error estimate.
COARSENING = 1.5
#: Radius of the centre-stress recovery, in units of the bulk element size.
RECOVERY_RADIUS = 1.5
#: Radius of the ball the largest tensile stress is averaged over, as a fraction of the strip width ...
AVERAGING_FRACTION = 1.0
#: ... and at most this fraction of the tablet's thickness (the ball's diameter at most a third of it).
AVERAGING_THICKNESS_FRACTION = 1.0 / 6.0
#: Element size near the loaded diametral plane on the optimiser's coarse mesh, as a multiple of R
#: (1.2 fitted concave rounds better, 0.91 % against 1.34 % rms, but read a thin 8 x 2 mm disc 11 % high).
PLANE_MESH_FACTOR = 1.5
#: Sample points of the largest tensile stress along the load (see :func:`split_plane_points`).
SAMPLES_ALONG_LOAD = 41
#: Sample points of the largest tensile stress through the thickness, faces included.
SAMPLES_THROUGH_THICKNESS = 9
#: Cosine of the largest angle between a loaded facet's outward normal and the load axis.
_FACING = 0.8


def line_load_stress(P: float, D: float, t: float) -> float:
    """``2P/(π D t)``, MPa: the centre stress of a disc under a line load (thesis eq 2.4)."""
    return 2.0 * P / (math.pi * D * t)


def hondros_centre_stress(P: float, D: float, t: float, b: float) -> float:
    """Hondros' plane-stress centre stress (MPa) for two strips of width ``b`` (mm) carrying ``P`` (N) each.

    ``2P/(πDt) · (sin 2α - α)/sin α`` with ``α = arcsin(b/D)`` (see the module text).
    """
    P = check_positive("force", P, "N")
    D = check_positive("diameter", D, "mm")
    t = check_positive("thickness", t, "mm")
    b = check_positive("strip_width", b, "mm")
    if b >= D:
        raise DesignError("strip_width", b, f"must be < the diameter {format_bound(D, upper=True)} mm", "mm")
    a = math.asin(b / D)
    return line_load_stress(P, D, t) * (math.sin(2.0 * a) - a) / math.sin(a)


def load_axis(direction: str, extents: np.ndarray) -> int:
    """Plan axis (0 = x, 1 = y) along which the platens push, for ``direction``.

    ``width``: along the shorter plan extent (the platens touch the long sides);
    ``length``: along the longer one; ties (round tablets) give x.
    """
    if direction not in DIRECTIONS:
        raise DesignError("direction", direction, "must be one of " + ", ".join(DIRECTIONS))
    if direction == "x":
        return 0
    if direction == "y":
        return 1
    ex, ey = float(extents[0]), float(extents[1])
    if abs(ex - ey) <= 1e-6 * max(ex, ey):
        return 0
    short = 0 if ex < ey else 1
    return short if direction == "width" else 1 - short


@dataclass(frozen=True, eq=False)
class DiametralResult:
    """Result of :func:`diametral` (MPa, mm, N)."""

    force_N: float
    direction: str
    axis: str
    diameter_mm: float
    thickness_mm: float
    strip_width_mm: float
    mesh_size_mm: float
    centre_mm: tuple[float, float, float]
    centre_tensile_stress_MPa: float
    centre_load_stress_MPa: float
    centre_max_principal_stress_MPa: float
    centre_max_principal_direction: tuple[float, float, float]
    max_tensile_stress_MPa: float
    max_tensile_location_mm: tuple[float, float, float]
    averaging_radius_mm: float
    nodes: int
    elements: int
    dofs: int
    reaction_N: float
    discretisation_error_MPa: float | None
    coarse_centre_tensile_stress_MPa: float | None
    material: Material
    work_Nmm: float
    solution: Any = field(repr=False, default=None)

    @property
    def line_load_MPa(self) -> float:
        return line_load_stress(self.force_N, self.diameter_mm, self.thickness_mm)

    @property
    def shape_factor(self) -> float:
        """``σ_t,centre · π D t / (2P)``: 1 for a thin disc under a line load."""
        return self.centre_tensile_stress_MPa / self.line_load_MPa

    @property
    def stress_per_force_per_mm2(self) -> float:
        """Centre tensile stress per newton, MPa/N = 1/mm²: tensile strength = breaking force × this."""
        return self.centre_tensile_stress_MPa / self.force_N

    def to_dict(self) -> dict[str, Any]:
        return {
            "force_N": self.force_N,
            "direction": self.direction,
            "load_axis": self.axis,
            "diameter_mm": self.diameter_mm,
            "thickness_mm": self.thickness_mm,
            "strip_width_mm": self.strip_width_mm,
            "mesh_size_mm": self.mesh_size_mm,
            "E_MPa": self.material.E,
            "nu": self.material.nu,
            "centre_mm": list(self.centre_mm),
            "centre_tensile_stress_MPa": self.centre_tensile_stress_MPa,
            "centre_load_stress_MPa": self.centre_load_stress_MPa,
            "centre_max_principal_stress_MPa": self.centre_max_principal_stress_MPa,
            "centre_max_principal_direction": list(self.centre_max_principal_direction),
            "max_tensile_stress_MPa": self.max_tensile_stress_MPa,
            "max_tensile_location_mm": list(self.max_tensile_location_mm),
            "averaging_radius_mm": self.averaging_radius_mm,
            "line_load_stress_MPa": self.line_load_MPa,
            "shape_factor": self.shape_factor,
            "stress_per_force_per_mm2": self.stress_per_force_per_mm2,
            "nodes": self.nodes,
            "elements": self.elements,
            "dofs": self.dofs,
            "reaction_N": self.reaction_N,
            "discretisation_error_MPa": self.discretisation_error_MPa,
            "discretisation_error_relative": (None if self.discretisation_error_MPa is None
                                              else self.discretisation_error_MPa / self.centre_tensile_stress_MPa),
            "coarse_centre_tensile_stress_MPa": self.coarse_centre_tensile_stress_MPa,
            "work_Nmm": self.work_Nmm,
        }


#: the largest mirror offset (relative to the tablet's largest extent) that ``symmetric=True`` accepts
MIRROR_TOLERANCE = 1e-3


def mirror_offset(tablet: Any, axis: int) -> float:
    """How far the tablet is from its mirror image about the plane through its centre normal to ``axis``
    (0: x, 1: y, 2: z), mm.

    The surface is sampled on every patch (17 × 128) and mirrored.  The offset is the largest difference
    between a mirrored point's signed distance from the tablet's nominal shape (its closed form: a
    family's or a thesis shape's) and the point's own; for a tablet without one, the largest distance
    of a mirrored point from the surface (from the nearest of a 4 × 4 times denser sample, polished by
    Gauss-Newton on its patch).  A symmetric tablet gives rounding (1e-15 mm, or the polish's 1e-9); a
    rounded triangle across its flat side, millimetres.  Only the tablet is checked, not a ``solid``
    given to :func:`diametral` (a scored one is the caller's to declare).
    """
    lo, hi = (np.asarray(a, float) for a in tablet.bounds())
    c = 0.5 * (lo[axis] + hi[axis])
    u, v = np.linspace(0.0, 1.0, 17), np.linspace(0.0, 2.0 * math.pi, 128, endpoint=False)
    pts = np.concatenate([p.evaluate_grid(u, v).reshape(-1, 3) for p in tablet.patches])
    own = None if getattr(tablet, "nominal", None) is None else tablet.nominal(pts)
    pts[:, axis] = 2.0 * c - pts[:, axis]
    if own is not None:  # a mirrored point is as far from a symmetric nominal as the point itself
        return float(np.max(np.abs(tablet.nominal(pts) - own)))
    from scipy.spatial import cKDTree

    # nearest of a dense sample, then Gauss-Newton on that sample's patch: the distance to the surface,
    # not to the samples (a round whose rings start at 10 deg read 0.027 mm off from the samples alone)
    u, v = np.linspace(0.0, 1.0, 65), np.linspace(0.0, 2.0 * math.pi, 512, endpoint=False)
    dense = np.concatenate([p.evaluate_grid(u, v).reshape(-1, 3) for p in tablet.patches])
    dist, k = cKDTree(dense).query(pts)
    per = u.size * v.size
    far = dist > 1e-9 * float(np.max(hi - lo))  # a mirrored point on a sample is on the surface already
    for j, patch in enumerate(tablet.patches):
        sel = np.flatnonzero((k // per == j) & far)
        if not sel.size:
            continue
        q, uu, vv = pts[sel], u[(k[sel] % per) // v.size], v[k[sel] % v.size]
        for _ in range(6):
            r = patch.evaluate(uu, vv) - q
            xu, xv = patch.evaluate(uu, vv, du=1), patch.evaluate(uu, vv, dv=1)
            a11, a12, a22 = (np.einsum("ij,ij->i", a, b) for a, b in ((xu, xu), (xu, xv), (xv, xv)))
            b1, b2 = np.einsum("ij,ij->i", xu, r), np.einsum("ij,ij->i", xv, r)
            lam = 1e-9 * (a11 + a22) + 1e-300  # a pole's v-derivative vanishes
            det = (a11 + lam) * (a22 + lam) - a12 * a12
            step_u = np.clip(-((a22 + lam) * b1 - a12 * b2) / det, -u[1], u[1])
            step_v = np.clip(-((a11 + lam) * b2 - a12 * b1) / det, -2.0 * v[1], 2.0 * v[1])
            uu, vv = np.clip(uu + step_u, 0.0, 1.0), vv + step_v
        dist[sel] = np.minimum(dist[sel], np.linalg.norm(patch.evaluate(uu, vv) - q, axis=1))
    return float(np.max(dist))


def check_symmetric(tablet: Any, direction: str = "width", parameter: str = "symmetric") -> None:
    """Refuse (:class:`DesignError` for ``parameter``) a quarter model of a tablet that is not mirror
    symmetric about the plane across the load and its mid-thickness plane: the mirrored quarter would
    be another shape (a rounded triangle's read 16 % low)."""
    lo, hi = (np.asarray(a, float) for a in tablet.bounds())
    ax = load_axis(direction, hi - lo)
    size = float(np.max(hi - lo))
    for axis in (ax, 2):
        off = mirror_offset(tablet, axis)
        if off > MIRROR_TOLERANCE * size:
            plane = ("x", "y", "z")[axis]
            raise DesignError(parameter, True, f"needs a tablet mirror symmetric about its centre's {plane} plane "
                              f"(across the load) and its mid-thickness: {getattr(tablet, 'name', 'the tablet')}'s mirror "
                              f"image is {off:.3g} mm from it (at most {MIRROR_TOLERANCE * size:.3g} mm): set it false")


def default_averaging_radius(strip_width: float, thickness: float) -> float:
    """``min(b, t/6)``, mm: the default radius of the ball the largest tensile stress is averaged over."""
    return min(AVERAGING_FRACTION * strip_width, AVERAGING_THICKNESS_FRACTION * thickness)


def contact_depth(D: float, b: float) -> float:
    """Depth (mm) of a flat platen into a circle of diameter ``D`` whose contact chord is ``b`` (mm)."""
    return 0.5 * D - math.sqrt(max(0.25 * D * D - 0.25 * b * b, 0.0))


@contextlib.contextmanager
def _meshable(mesh_size: float | None, size: float, which: str = "") -> Iterator[None]:
    """A given ``mesh_size`` (mm) at which gmsh makes no tetrahedra of the solid, refused by its name: a size within
    its stated range (at most the tablet's largest extent) can be too coarse for the solid's faces, at ``size`` mm
    (``which`` mesh); ``--mesh-size 10`` on the 10 mm concave round had printed "mesh: gmsh produced no tetrahedra".
    A default size's failure stays what it is."""
    try:
        yield
    except GeometryError as exc:
        if mesh_size is None or "no tetrahedra" not in str(exc):
            raise
        raise DesignError("mesh_size", mesh_size, f"gmsh makes no tetrahedra of this solid at {size:.4g} mm{which}: "
                          "give a finer size", "mm") from None


def _solve_once(solid: Any, lo: np.ndarray, hi: np.ndarray, ax: int, P: float, b: float, h: float,
                hs: float, material: Material, R: float, hp: float, hc: float, rc: float,
                symmetric: bool = False) -> tuple[Any, np.ndarray, Any, Any]:
    """Mesh, load and solve once; with ``symmetric`` only the quarter on the ``+`` side of the plane
    across the load and of the mid-thickness plane is meshed and solved (one platen, ``P/2``), and
    the solution is unfolded to the whole tablet."""
    from tabletcad.fe.elasticity import _skfem_mesh

    c = 0.5 * (lo + hi)
    px = 1 - ax
    D = float(hi[ax] - lo[ax])
    depth = contact_depth(D, b)
    e = np.eye(3)[ax]
    platens = ((1.0, hi[ax] - depth),) if symmetric else ((-1.0, lo[ax] + depth), (1.0, hi[ax] - depth))
    cuts = [CutPlane(tuple(e), float(plane)) for _, plane in platens]
    planes = ((ax, float(c[ax])), (2, float(c[2]))) if symmetric else ()
    keep = [CutPlane(tuple(np.eye(3)[a]), v) for a, v in planes]
    refs = []
    for s in (-1.0, 1.0):
        blo, bhi = lo.copy() - 1.0, hi.copy() + 1.0
        if s > 0:
            blo[ax] = hi[ax] - b / 2
        else:
            bhi[ax] = lo[ax] + b / 2
        refs.append(Refinement(tuple(blo), tuple(bhi), hs))
    refs.append(Refinement(tuple(c), tuple(c), hc, radius=rc))
    if hp < h:  # the slab about the loaded diametral plane that the averaging balls reach
        slo, shi = lo.copy() - 1.0, hi.copy() + 1.0
        slo[px], shi[px] = c[px] - R - hp, c[px] + R + hp
        refs.append(Refinement(tuple(slo), tuple(shi), hp))
    mesh = mesh_solid(solid, h, refinements=refs, cuts=cuts, keep=keep)
    m = _skfem_mesh(mesh)
    bf = boundary_facets(m)
    loads = []
    tol = 1e-7 * D
    for s, plane in platens:
        cos = s * (bf.normals @ e)
        sel = np.flatnonzero((s * (bf.centroids[:, ax] - plane) >= -tol) & (cos >= _FACING))
        if sel.size == 0:
            raise GeometryError("diametral: no boundary facet faces the platen", solid)
        push = float((cos[sel] * bf.areas[sel]).sum())
        loads.append(PressureLoad(sel, (0.5 * P if symmetric else P) / push))
    sol = solve_elasticity(mesh, material, loads, support_centre=c, support_arm=D / 4, facets=bf, skmesh=m,
                           symmetry=planes)
    if symmetric:
        m = sol.mesh
        bf = boundary_facets(m)
    s_c = sol.recovered_stress_at(c, RECOVERY_RADIUS * h)
    return sol, s_c, m, bf


def section_heights(m: Any, bf: Any, xy: np.ndarray) -> np.ndarray:
    """Bottom and top of the body (mm) on vertical lines through the plan points ``xy`` (k, 2), mm.

    Vertical rays are cut with the boundary facets of the mesh (shape (k, 2): lowest and highest
    crossing; NaN where a line misses the body).  The facets lie within the mesh's chordal error
    (``h²/8ρ`` for a face of curvature radius ρ) of the B-rep faces.
    """
    m_tri = m.p[:, m.facets[:, bf.ids]].transpose(2, 1, 0)  # (k, 3 vertices, 3)
    a, b, c = m_tri[:, 0, :2], m_tri[:, 1, :2], m_tri[:, 2, :2]
    det = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1])
    ok = np.abs(det) > 1e-12 * np.maximum(bf.areas, 1e-300)  # facets not seen edge-on from above
    out = np.full((len(xy), 2), np.nan)
    for i, (x, y) in enumerate(np.asarray(xy, float)):
        l1 = ((x - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (y - a[:, 1])) / np.where(ok, det, 1.0)
        l2 = ((b[:, 0] - a[:, 0]) * (y - a[:, 1]) - (x - a[:, 0]) * (b[:, 1] - a[:, 1])) / np.where(ok, det, 1.0)
        eps = 1e-9
        hit = ok & (l1 >= -eps) & (l2 >= -eps) & (l1 + l2 <= 1 + eps)
        if hit.any():
            z = (1 - l1[hit] - l2[hit]) * m_tri[hit, 0, 2] + l1[hit] * m_tri[hit, 1, 2] + l2[hit] * m_tri[hit, 2, 2]
            out[i] = z.min(), z.max()
    return out


def split_plane_points(m: Any, bf: Any, lo: np.ndarray, hi: np.ndarray, ax: int, b: float,
                       n_load: int = SAMPLES_ALONG_LOAD, n_thick: int = SAMPLES_THROUGH_THICKNESS) -> np.ndarray:
    """The fixed sample points (k, 3), mm, of the largest tensile stress: a grid on the loaded diametral plane.

    The plane holds the load axis and the tablet's axis through the centre of its bounding box
    (the plane a valid diametral test splits along).  ``n_load`` points are spread evenly along
    the load over the part farther than ``b`` from the platens' planes, and at each of them
    ``n_thick`` points evenly from the bottom face to the top face (both faces included).  The
    grid is fixed in these normalised coordinates, so it moves smoothly with the design and
    does not depend on the mesh except through the faces' heights (chordal error, see
    :func:`section_heights`).
    """
    c = 0.5 * (lo + hi)
    half = 0.5 * float(hi[ax] - lo[ax]) - b
    s = c[ax] + half * np.linspace(-1.0, 1.0, n_load)
    xy = np.tile(c[:2], (n_load, 1))
    xy[:, ax] = s
    zz = section_heights(m, bf, xy)
    good = np.all(np.isfinite(zz), axis=1)
    xy, zz = xy[good], zz[good]
    f = np.linspace(0.0, 1.0, n_thick)
    z = zz[:, :1] + (zz[:, 1:] - zz[:, :1]) * f[None, :]
    pts = np.concatenate([np.repeat(xy, n_thick, axis=0), z.reshape(-1, 1)], axis=1)
    return pts


def largest_tensile(sol: Any, bf: Any, lo: np.ndarray, hi: np.ndarray, ax: int, b: float,
                    radius: float, symmetric: bool = False) -> tuple[float, np.ndarray, float]:
    """Largest maximum principal stress (MPa) of the averaged stress on the split-plane grid, its location (mm),
    and the averaged opening stress there (MPa); see :func:`diametral`.

    ``symmetric``: the tablet is mirror symmetric about the plane across the load through its centre
    and about its mid-thickness plane, so the exact field takes the same value at the four mirror
    images of every grid point; their values are averaged, which cancels the part of the
    discretisation error that an unsymmetric mesh gives them (the grid is symmetric by construction).
    :func:`diametral` solves such a tablet on its quarter and unfolds the solution (an exactly
    symmetric field), so the averaged stress is evaluated at one image of each point only (the
    largest principal stress and the opening stress are the same at the other images).
    """
    n_load, n_thick = SAMPLES_ALONG_LOAD, SAMPLES_THROUGH_THICKNESS
    pts = split_plane_points(sol.mesh, bf, lo, hi, ax, b, n_load, n_thick)
    if len(pts) == 0:
        raise GeometryError("diametral: the loaded diametral plane misses the body", sol.mesh)
    if symmetric and len(pts) == n_load * n_thick:
        i, j = np.meshgrid(np.arange(n_load), np.arange(n_thick), indexing="ij")
        rep = (np.maximum(i, n_load - 1 - i) * n_thick + np.maximum(j, n_thick - 1 - j)).ravel()
        first, inverse = np.unique(rep, return_inverse=True)
        s, _ = sol.averaged_stress(pts[first], radius)
        s = s[inverse.ravel()]
    else:
        s, _ = sol.averaged_stress(pts, radius)
    px = 1 - ax
    pr = principal_stresses(s)[:, -1]
    op = s[:, px, px]
    if symmetric and len(pts) == n_load * n_thick:
        g = pr.reshape(n_load, n_thick)
        pr = (0.25 * (g + g[::-1] + g[:, ::-1] + g[::-1, ::-1])).ravel()
        g = op.reshape(n_load, n_thick)
        op = (0.25 * (g + g[::-1] + g[:, ::-1] + g[::-1, ::-1])).ravel()
    k = int(np.argmax(pr))
    return float(pr[k]), pts[k], float(op[k])


def diametral(
    tablet: Any,
    force: float,
    direction: str = "width",
    *,
    strip_width: float | None = None,
    mesh_size: float | None = None,
    strip_mesh_size: float | None = None,
    averaging_radius: float | None = None,
    plane_mesh_size: float | None = None,
    centre_mesh_size: float | None = None,
    symmetric: bool = False,
    material: Material | None = None,
    error_estimate: bool = True,
    solid: Any = None,
) -> DiametralResult:
    """Diametral compression of ``tablet`` by ``force`` N across ``direction`` (FE, quadratic tetrahedra).

    Parameters
    ----------
    tablet : Tablet
        The design (its B-rep solid is built by the CAD layer unless ``solid`` is given).
    force : float
        Force on each platen, N (> 0).
    direction : {"width", "length", "x", "y"}
        Load direction in plan (see :func:`load_axis`).
    strip_width : float, optional
        Width of each loaded strip, mm; default ``D/10`` (``D`` = extent along the load).
    mesh_size : float, optional
        Element size away from the strips, mm; default ``min(t/2, min(plan extents)/12)``.
        Near the centre the size is ``mesh_size/1.5``.
    strip_mesh_size : float, optional
        Element size within ``strip_width/2`` of the platens, mm; default ``min(mesh_size, strip_width/3)``.
    averaging_radius : float, optional
        Radius of the ball the largest tensile stress is averaged over, mm; default
        ``min(strip_width, thickness/6)``; at most a quarter of the smaller plan extent.
    plane_mesh_size : float, optional
        Element size within ``R + plane_mesh_size`` of the loaded diametral plane, mm (where the
        averaging balls reach); default: ``min(mesh_size, PLANE_MESH_FACTOR · R)``, as on the coarse mesh of
        :func:`tabletcad.fe.objective.breaking_force` (a 10 × 2 mm disc's largest tensile stress read
        1.096 × eq 2.4 with ``mesh_size`` there, 1.019 × with it; finer meshes 1.012 ×), but no finer than
        leaves that band half the unknowns that fit in memory (``MAX_DOFS``).
    centre_mesh_size : float, optional
        Element size within ``max(D/8, RECOVERY_RADIUS · mesh_size)`` of the centre (the ball the
        centre stress is recovered from), mm; default: ``mesh_size/1.5`` within ``D/8``.  The
        coarse mesh of :func:`tabletcad.fe.objective.breaking_force` uses ``mesh_size/2``.
    symmetric : bool
        Declare the tablet mirror symmetric about the plane across the load and about its
        mid-thickness plane (every round and capsule family without one-sided embossing or
        score): only the quarter of the solid on the ``+`` side of both planes is meshed and
        solved, with the normal displacement held on the two planes and one platen carrying
        ``P/2``, and the solution is unfolded to the whole tablet
        (:func:`tabletcad.fe.elasticity.unfold`), an exactly symmetric field read like the full
        model's (see :func:`largest_tensile`).  About a third of the unknowns of the whole tablet
        with the same sizes and 1.8-6 times less time (``benchmarks/bench_fe.py``); ``dofs``
        counts the quarter's unknowns, ``nodes`` and ``elements`` the unfolded mesh's.  The
        optimiser's coarse evaluations use it.
    material : Material, optional
        E and ν (stresses do not depend on E).
    error_estimate : bool
        Also solve on a mesh ``COARSENING`` times coarser and estimate the
        discretisation error of the centre stress by Richardson extrapolation
        with the nominal order 2 of quadratic elements: ``(σ_h - σ_1.5h)/(1.5² - 1)``.
    """
    P = check_range("force", force, MIN_FORCE_N, 1e9, "N")  # (1e308 overflowed the solve, 1e-320 gave -0 MPa)
    material = material or Material()
    trim = getattr(tablet, "trim", None)
    if trim is not None and trim.w[0] > 0:  # named as the design makes it hollow: a ring's hole, else its [trim] w
        inner = (getattr(tablet, "params", None) or {}).get("inner_diameter")
        if getattr(tablet, "family", None) == "thesis.ring" and inner is not None:
            raise DesignError("tablet.inner_diameter", inner, "a hollow tablet (a ring) is not supported by the "
                              "diametral FE test, which loads solid tablets only", "mm")
        raise DesignError("[trim] w", list(trim.w), "a hollow tablet (w from above 0) is not supported by the diametral "
                          "FE test, which loads solid tablets only: remove [trim] w or start it at 0")
    if trim is not None and (trim.u != (0.0, 1.0) or not trim.full_v):
        key = "v" if not trim.full_v else "u"
        raise DesignError(f"[trim] {key}", list(getattr(trim, key)), "the diametral test needs the whole tablet, not a "
                          "cut-away view")
    if symmetric:
        check_symmetric(tablet, direction)
    lo, hi = (np.asarray(a, float) for a in tablet.bounds())
    ext = hi - lo
    ax = load_axis(direction, ext)
    px = 1 - ax
    D, t = float(ext[ax]), float(ext[2])
    b = D * STRIP_FRACTION if strip_width is None else check_positive("strip_width", strip_width, "mm")
    if b < DEFAULT.min_length:
        raise DesignError("strip_width", b, f"must be >= {DEFAULT.min_length:g} mm (Tolerances.min_length)", "mm")
    if b > 0.5 * D:
        raise DesignError("strip_width", b, f"must be <= half the tablet's extent along the load "
                          f"({0.5 * D:.4g} mm)", "mm")
    h = min(t / 2.0, float(min(ext[0], ext[1])) / 12.0) if mesh_size is None else check_range(
        "mesh_size", mesh_size, 0.0, float(max(ext)), "mm", lo_open=True)  # at most the tablet's largest extent
    R = default_averaging_radius(b, t) if averaging_radius is None else check_positive("averaging_radius", averaging_radius,
                                                                                "mm")
    if R > 0.25 * float(min(ext[0], ext[1])):
        raise DesignError("averaging_radius", R, f"must be <= a quarter of the smaller plan extent "
                          f"({0.25 * float(min(ext[0], ext[1])):.4g} mm)", "mm")
    hs = min(h, b / 3.0) if strip_mesh_size is None else check_positive("strip_mesh_size", strip_mesh_size, "mm")
    box = float(np.prod(ext))  # the volume is at most the bounding box's: computed only when the box's is too large
    if max(estimated_dofs(box, h), estimated_dofs(box * min(1.0, b / D), hs)) > MAX_DOFS:
        vol = float(tablet.volume())
        if mesh_size is None and estimated_dofs(vol, h) > MAX_DOFS:  # the default, which the user never set: say so
            raise DesignError("mesh_size", MISSING, f"its default for this tablet, min(thickness/2, plan width/12) = "
                              f"{h:.3g} mm, gives about {estimated_dofs(vol, h):.3g} unknowns, more than the "
                              f"{MAX_DOFS:.3g} that fit in memory: give a mesh size of at least {finest_size(vol):.3g} mm")
        check_mesh_size(vol, h)
        try:
            check_mesh_size(vol * min(1.0, b / D), hs, "strip_mesh_size")
        except DesignError as exc:  # named by what was given: the strip width, unless its mesh size was
            if strip_mesh_size is not None or hs == h:
                raise
            raise DesignError("strip_width", b, f"meshes its strips at b/3 = {hs:.3g} mm, a size that "
                              f"{exc.allowed}", "mm") from None
    # near the loaded plane the balls of radius R are resolved as on the optimiser's coarse mesh: a thin
    # disc's R = t/6 under elements of t/2 read its largest tensile stress 9.6 % high (10 x 2 mm); the
    # band within R + h of the plane is kept to half the unknowns that fit (a 25 x 0.1 mm disc's 1.5 R would not)
    in_band = min(1.0, 2.0 * (R + h) / float(ext[px]))  # the band's share of the tablet
    if plane_mesh_size is None:
        hp = min(h, max(PLANE_MESH_FACTOR * R, finest_size(box * in_band, 0.5 * MAX_DOFS)))
    else:
        hp = min(h, check_positive("plane_mesh_size", plane_mesh_size, "mm"))
        if estimated_dofs(box * in_band, hp) > MAX_DOFS:
            check_mesh_size(float(tablet.volume()) * in_band, hp, "plane_mesh_size")
    if solid is None:
        from tabletcad.cad.tablet_solid import tablet_solid

        solid = tablet_solid(tablet, revolved=False)  # the faces the FE results were validated on

    def centre_ball(h: float, hc: float | None) -> tuple[float, float]:
        return (h / 1.5, D / 8.0) if hc is None else (min(h, hc), max(D / 8.0, RECOVERY_RADIUS * h))

    hc = None if centre_mesh_size is None else check_positive("centre_mesh_size", centre_mesh_size, "mm")
    with _meshable(mesh_size, h):
        sol, s_c, m, bf = _solve_once(solid, lo, hi, ax, P, b, h, hs, material, R, hp, *centre_ball(h, hc), symmetric)
    s_max, loc, _ = largest_tensile(sol, bf, lo, hi, ax, b, R, symmetric)
    s_t, s_l = float(s_c[px, px]), float(s_c[ax, ax])
    w, vec = np.linalg.eigh(s_c)
    err = coarse = None
    if error_estimate:
        with _meshable(mesh_size, COARSENING * h, f" (the error estimate's mesh, {COARSENING:g} times coarser)"):
            _, s_cc, *_ = _solve_once(solid, lo, hi, ax, P, b, COARSENING * h, COARSENING * hs, material, R,
                                      COARSENING * hp, *centre_ball(COARSENING * h, None if hc is None else COARSENING * hc),
                                      symmetric)
        coarse = float(s_cc[px, px])
        err = (s_t - coarse) / (COARSENING**2 - 1.0)
    c = 0.5 * (lo + hi)
    return DiametralResult(
        force_N=P, direction=direction, axis="xy"[ax], diameter_mm=D, thickness_mm=t, strip_width_mm=b,
        mesh_size_mm=h, centre_mm=tuple(float(v) for v in c), centre_tensile_stress_MPa=s_t,
        centre_load_stress_MPa=s_l, centre_max_principal_stress_MPa=float(w[-1]),
        centre_max_principal_direction=tuple(float(v) for v in vec[:, -1] * np.sign(vec[np.argmax(np.abs(vec[:, -1])), -1])),
        max_tensile_stress_MPa=s_max,
        max_tensile_location_mm=tuple(float(v) for v in loc), averaging_radius_mm=R, nodes=sol.nodes, elements=sol.elements,
        dofs=sol.dofs, reaction_N=sol.reaction, discretisation_error_MPa=err,
        coarse_centre_tensile_stress_MPa=coarse, material=material, work_Nmm=sol.work, solution=sol)
