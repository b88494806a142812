"""Core tablet -> FreeCAD Part solids (FreeCAD's Python: numpy/scipy, tabletcad's pure core, Part).

The chain is the one of :mod:`tabletcad.cad.tablet_solid` without OCP:

1. ``tablet_chain``: the tablet's surface functions (its patches, or for a
   hollow tablet such as the ring: outer wall -> end -> inner wall -> end) and
   the union of their ``v`` breakpoints;
2. :func:`tabletcad.brep.fit.fit_patches` (quintic in ``u`` and ``v``, like
   ``tablet_solid``) -> kernel-neutral :class:`~tabletcad.brep.surface.BSplineSurfaceData`;
   for a tablet of revolution only the profiles (:func:`tabletcad.brep.revolved.fit_profiles`);
3. ``Part.BSplineSurface().buildFromPolesMultsKnots`` (or ``Part.SurfaceOfRevolution`` of a
   ``Part.BSplineCurve``) -> faces -> sewn
   ``Part.Shell`` -> ``Part.Solid`` (outward, ``isValid()``, exactly one solid).

Tooling is made with Part Booleans from the tablet's *rims* (the boundary rows
of the chain that lie on the tablet's silhouette, taken from the fitted poles,
so the tool's edge is the very curve of the tablet's edge):

* upper punch: prism on the upper rim(s) offset inward by ``clearance`` (a ring's hole
  outward), ``length`` up, minus the tablet;
* lower punch: the same on the lower rim(s), ``length`` down;
* die: cylinder of ``outer_diameter`` and ``height`` centred on the band, minus the
  prism on the outer rim: the bore is the tablet's outline, as ``tabletcad build``
  makes it (the tablet's size is the die's; the punch tips are smaller by the clearance).

Nothing here imports OCP or build123d.
"""

from __future__ import annotations

import json
import math
import time

import numpy as np

__all__ = [
    "TabletGeometry",
    "build_tablet",
    "die_shape",
    "punch_shape",
    "rims_from_json",
    "tablet_chain",
    "tablet_from_spec",
]



# --------------------------------------------------------------------------- core side (numpy only)
def tablet_chain(tablet):
    """(surface functions, names, v breakpoints) of the tablet's closed solid.

    The same chain as :func:`tabletcad.cad.tablet_solid.tablet_surface_functions`
    (numpy only: it imports no OCP), with the union of the patches' breakpoints.
    """
    from tabletcad.brep.surfaces import tablet_breakpoints, tablet_surface_functions

    funcs, names = tablet_surface_functions(tablet)
    return funcs, names, tablet_breakpoints(tablet)


def tablet_from_spec(family=None, params=None, design=None):
    """A core Tablet from a family name and its parameters (mm, deg), or from a design file: both
    through :class:`tabletcad.pipeline.design.Design`, so the workbench refuses what ``tabletcad
    build`` refuses, with the same message (a size beyond ±1000 mm, a length below the tolerance)."""
    from tabletcad.pipeline.design import Design, load_design

    if design:
        return load_design(design)
    return Design.from_dict({"tablet": {"family": family, **(params or {})}}).build()


def _rims(surfaces, hollow):
    """Rim rows of the fitted chain: boundary rows (u = 0 or 1) that are horizontal
    and lie on the silhouette (per v, as far out as the surface gets), plus, for a
    hollow tablet, the boundary rows of the inner wall.  Returns a list of dicts
    ``{z, inner, poles, knots, mults, degree}`` (the row's B-spline curve in v)."""
    u = np.linspace(0.0, 1.0, 65)
    out = []
    v = np.linspace(0.0, math.tau, 181)[:-1]
    rho = np.zeros(v.size)
    for s in surfaces:
        P = s.evaluate_grid(u, v)
        rho = np.maximum(rho, np.hypot(P[..., 0], P[..., 1]).max(axis=0))
    scale = max(float(rho.max()), 1e-9)
    seen = []
    for k, s in enumerate(surfaces):
        for end in (0, -1):
            row = s.poles[end]
            z = row[:, 2]
            if np.ptp(z) > 1e-7 * max(1.0, scale):
                continue
            pts = s.evaluate_grid(np.array([0.0 if end == 0 else 1.0]), v)[0]
            r = np.hypot(pts[:, 0], pts[:, 1])
            if r.max() < 1e-6 * scale:  # a pole (point row)
                continue
            # the thesis's PDE bands bulge between their curves by ~5e-4 of the radius
            outer = bool(np.all(r >= rho - 2e-3 * scale))
            inner = bool(hollow and k == 2)
            if not (outer or inner):
                continue
            key = (round(float(z.mean()), 9), round(float(r.mean()), 9))
            if key in seen:  # shared rows appear twice in the chain
                continue
            seen.append(key)
            out.append(
                dict(
                    z=float(z.mean()),
                    inner=inner and not outer,
                    poles=row.tolist(),
                    knots=list(map(float, s.v_knots)),
                    mults=list(map(int, s.v_mults)),
                    degree=int(s.v_degree),
                )
            )
    if not any(not r["inner"] for r in out):
        return []
    return out


class TabletGeometry:
    """Result of :func:`build_tablet`: the Part solid and the core's figures."""

    def __init__(self, tablet, solid, fits, props, rims, timings):
        self.tablet = tablet
        self.solid = solid
        self.fits = fits
        self.props = props
        self.rims = rims
        self.timings = timings

    @property
    def volume(self):
        """Core quadrature volume (mm^3) of the PDE tablet (tabletcad's report value)."""
        return self.props["volume_mm3"]

    @property
    def area(self):
        return self.props["surface_area_mm2"]

    @property
    def max_fit_deviation(self):
        return max(f.max_deviation for f in self.fits)

    def rims_json(self):
        return json.dumps(self.rims)


# --------------------------------------------------------------------------- FreeCAD side
def bspline_face(data):
    """``Part.Face`` of a kernel-neutral BSplineSurfaceData (the surface's natural bounds)."""
    import FreeCAD
    import Part

    bs = Part.BSplineSurface()
    poles = [[FreeCAD.Vector(*map(float, p)) for p in row] for row in np.asarray(data.poles)]
    bs.buildFromPolesMultsKnots(
        poles,
        [int(m) for m in data.u_mults],
        [int(m) for m in data.v_mults],
        [float(k) for k in data.u_knots],
        [float(k) for k in data.v_knots],
        bool(data.u_periodic),
        bool(data.v_periodic),
        int(data.u_degree),
        int(data.v_degree),
    )
    return bs.toShape()


def solid_from_faces(faces, sew_tolerance, what="tablet"):
    """Sew faces into one closed shell and make an outward, valid solid (or raise).

    ``Part.Solid`` orients the solid outward itself (``BRepLib::OrientClosedSolid``, in FreeCAD 0.20 and
    1.0 alike): the ``solid.Volume < 0`` check that followed it never turned one, and OCC's default
    volume integration it ran took 231 of a rounded triangle's 430 ms recompute."""
    import Part

    from tabletcad.errors import GeometryError

    shell = Part.Shell(faces)
    shell.sewShape(sew_tolerance)
    shells = shell.Shells if shell.ShapeType != "Shell" else [shell]
    if len(shells) != 1:
        raise GeometryError(f"{what}: sewing gave {len(shells)} shells, expected 1", shell)
    shell = shells[0]
    if not shell.isClosed():
        raise GeometryError(f"{what}: sewn shell is not closed", shell)
    solid = Part.Solid(shell)  # (oriented outward: the tests read Volume > 0 on every family in both FreeCADs)
    if not solid.isValid():
        raise GeometryError(f"{what}: solid is not valid (BRepCheck)", solid)
    return solid


def revolved_face(data):
    """``Part.Face`` of a kernel-neutral RevolvedSurfaceData: its B-spline profile (plane y = 0,
    x = R) turned a full circle about the z axis (a surface of revolution, exact in the angle)."""
    import FreeCAD
    import Part

    c = Part.BSplineCurve()
    c.buildFromPolesMultsKnots([FreeCAD.Vector(float(r), 0.0, float(z)) for r, z in np.asarray(data.poles)],
                               [int(m) for m in data.mults], [float(k) for k in data.knots], False, int(data.degree))
    return Part.Face(Part.SurfaceOfRevolution(c, FreeCAD.Vector(0, 0, 0), FreeCAD.Vector(0, 0, 1)))


def _revolved_rims(surfaces, hollow):
    """Rims of a chain of faces of revolution: the profile ends on the silhouette (as far from
    the axis as the profiles get), each an exact circle ``{z, inner, radius}``; for a hollow
    tablet also the ends of the inner wall."""
    u = np.linspace(0.0, 1.0, 257)
    rho = max(float(np.max(s.profile(u)[:, 0])) for s in surfaces)
    out, seen = [], []
    for k, s in enumerate(surfaces):
        for r, z in np.asarray(s.poles)[[0, -1]]:
            if r < 1e-6 * rho:  # a pole
                continue
            outer = bool(r >= rho - 2e-3 * rho)
            inner = bool(hollow and k == 2)
            key = (round(float(z), 9), round(float(r), 9))
            if not (outer or inner) or key in seen:
                continue
            seen.append(key)
            out.append(dict(z=float(z), inner=inner and not outer, radius=float(r)))
    return out if any(not r["inner"] for r in out) else []


def build_tablet(tablet, tol=None):
    """Fit the tablet's chain, build the Part solid, compute the core's figures.

    A tablet of revolution gets faces of revolution of its fitted profiles
    (:func:`tabletcad.brep.revolved.fit_profiles`, as ``tablet_solid`` does), any other
    B-spline faces (:func:`tabletcad.brep.fit.fit_patches`)."""
    from tabletcad.brep.fit import fit_patches
    from tabletcad.brep.revolved import fit_profiles
    from tabletcad.brep.surface import enclosed_volume
    from tabletcad.brep.surfaces import fit_options, tablet_profiles
    from tabletcad.brep.slit import chain_face_surfaces

    t0 = time.perf_counter()
    tol = float(tablet.tol.fit if tol is None else tol)
    profiles = tablet_profiles(tablet) if tablet.trim.u == (0.0, 1.0) and tablet.trim.full_v else None
    if profiles is not None:
        fits = fit_profiles(profiles[0], tol, names=profiles[1], degree=fit_options(tablet)["u_degree"])
        t1 = time.perf_counter()
        faces = [revolved_face(f.surface) for f in fits]
    else:
        funcs, names, breaks = tablet_chain(tablet)
        fits = fit_patches(funcs, tol, names=names, **fit_options(tablet, v_breaks=breaks))
        t1 = time.perf_counter()
        # cut alike where a boundary row stands still over part of its length (tabletcad.brep.slit)
        pieces = chain_face_surfaces([f.surface for f in fits], 1e-7, names)
        faces = [bspline_face(p) for ps in pieces for p in ps]
    solid = solid_from_faces(faces, max(2.0 * tol, 1e-6), tablet.name)
    t2 = time.perf_counter()
    props = tablet.properties()
    t3 = time.perf_counter()
    hollow = tablet.trim.w[0] > 0.0
    rims = (_revolved_rims if profiles is not None else _rims)([f.surface for f in fits], hollow=hollow)
    outline = outline_segments(tablet)
    band = tablet.band()
    from tabletcad.pipeline.designreport import plan_diameter

    lo, hi = tablet.bounds()
    for r in rims:
        if not r["inner"]:
            if outline:  # the die bore follows the exact outline (lines and arcs), not the fitted rim
                r["outline"] = outline
            # how far the tablet's plan leaves the outline (mm): the band's PDE bulge, or a dome's overhang
            # (the caplet's); the bore clears it, as build's does
            r["band_bulge"] = float(tablet.plan_overhang())
            r["band"] = band is not None
            # a TSM B die takes round tablets up to 16 mm and shaped ones up to 19 mm (the standard die's size)
            r["shaped"] = tablet.revolution is None
            # the core's largest plan extent (its polished bounds, as tabletcad build sizes its die): the
            # solid's box is looser (0.20 has no tight box: an 18.9 mm capsule's read 19.02 mm, a D die)
            # in any direction (a rounded square's diagonal: tabletcad.pipeline.designreport.plan_diameter)
            r["plan_size"] = float(plan_diameter(tablet))
            # the tablet's lowest and highest z (mm, the core's polished bounds): a face flat at its rim
            # gives the punch its whole prism (punch_shape)
            r["tablet_z"] = [float(lo[2]), float(hi[2])]
    # exact volume of the B-spline solid (FreeCAD's Shape.Volume is OCCT's default integration,
    # measured 8.5e-4 relative off on a free-form stadium tablet)
    props = dict(props, solid_volume_mm3=abs(enclosed_volume([f.surface for f in fits])))
    props["plan_area_mm2"] = plan_area(tablet, rims)
    timings = dict(fit=t1 - t0, part=t2 - t1, properties=t3 - t2, total=time.perf_counter() - t0)
    return TabletGeometry(tablet, solid, fits, props, rims, timings)


def outline_segments(tablet):
    """The tablet's exact plan outline as plain data (``[{kind, p0, p1, center, radius, theta0,
    sweep}, ...]``, mm and rad), or None for a tablet without a nominal outline of lines and
    arcs (the thesis's free-form tablets, round families whose rim is a circle anyway)."""
    segs = getattr(getattr(getattr(tablet, "nominal", None), "outline", None), "segs", None)
    if not segs or len(segs) == 1:  # none, or one circle
        return None
    return [dict(kind=sg.kind, p0=[float(x) for x in sg.p0], p1=[float(x) for x in sg.p1],
                 center=[float(x) for x in sg.center], radius=float(sg.radius), theta0=float(sg.theta0),
                 sweep=float(sg.sweep)) for sg in segs]


def offset_outline_wire(segments, distance, z=0.0):
    """``Part.Wire`` of the outline (:func:`outline_segments`) offset outward by ``distance`` mm
    at height ``z``: lines move along their outward normal, arcs keep their centre and change
    radius by ``distance`` (convex) or ``-distance`` (concave) - exact for a G1 outline.  The
    segments run counter-clockwise (``PlanOutline`` reverses clockwise input)."""
    import FreeCAD
    import Part

    from tabletcad.errors import GeometryError

    edges = []
    for sg in segments:
        if sg["kind"] == "line":
            (x0, y0), (x1, y1) = sg["p0"], sg["p1"]
            L = math.hypot(x1 - x0, y1 - y0)
            nx, ny = (y1 - y0) / L, -(x1 - x0) / L  # right of the direction: outward
            a = FreeCAD.Vector(x0 + distance * nx, y0 + distance * ny, z)
            b = FreeCAD.Vector(x1 + distance * nx, y1 + distance * ny, z)
            edges.append(Part.LineSegment(a, b).toShape())
        else:
            r = sg["radius"] + distance * math.copysign(1.0, sg["sweep"])
            if not r > 0:
                raise GeometryError(f"offsetting the outline by {distance} mm collapses an arc of radius {sg['radius']} mm",
                                    sg)
            circle = Part.Circle(FreeCAD.Vector(sg["center"][0], sg["center"][1], z), FreeCAD.Vector(0, 0, 1), r)
            t0, t1 = sg["theta0"], sg["theta0"] + sg["sweep"]
            edges.append(Part.ArcOfCircle(circle, min(t0, t1), max(t0, t1)).toShape())
    wire = Part.Wire(Part.__sortEdges__(edges))
    if not wire.isClosed():
        raise GeometryError(f"the outline offset by {distance} mm is not closed (an outline corner is not G1)", wire)
    return wire


def rims_from_json(text):
    return json.loads(text) if text else []


def _rim_wire(rim, dz=0.0):
    import FreeCAD
    import Part

    if "radius" in rim:  # an exact circle (a tablet of revolution)
        circle = Part.Circle(FreeCAD.Vector(0, 0, rim["z"] + dz), FreeCAD.Vector(0, 0, 1), rim["radius"])
        return Part.Wire([circle.toShape()])
    c = Part.BSplineCurve()
    c.buildFromPolesMultsKnots(
        [FreeCAD.Vector(x, y, z + dz) for x, y, z in rim["poles"]],
        rim["mults"],
        rim["knots"],
        True,
        rim["degree"],
    )
    # one edge per C0 span (knots of multiplicity >= degree, where the fit put the outline's
    # junctions): a single periodic edge with C0 knots makes Part's offset and Booleans fail
    knots = [float(k) for k, m in zip(rim["knots"], rim["mults"]) if int(m) >= int(rim["degree"])]
    lo, hi = float(rim["knots"][0]), float(rim["knots"][-1])
    cuts = sorted({lo, hi, *knots})
    if len(cuts) <= 2:
        return Part.Wire([c.toShape()])
    spans = list(zip(cuts[:-1], cuts[1:]))
    if int(rim["mults"][0]) < int(rim["degree"]):  # the period's start is smooth: one span across it
        spans = [(spans[-1][0], spans[0][1] + (hi - lo))] + spans[1:-1]
    edges = []
    for a, b in spans:
        seg = c.copy()
        seg.segment(a, b)  # a clamped, smooth piece: Part.OffsetCurve refuses C0 curves
        edges.append(seg.toShape())
    return Part.Wire(edges)


def _offset_rim_wire(rim, distance):
    """The rim's curve offset outward (away from the area it encloses) by ``distance`` mm: the exact
    outline's offset when the rim has one, a concentric circle, else Part's 2-D offset as B-splines."""
    import Part

    if rim.get("outline"):
        return offset_outline_wire(rim["outline"], float(distance), rim["z"])
    if "radius" in rim:
        return _rim_wire(dict(rim, radius=rim["radius"] + float(distance)))
    rim_wire = _rim_wire(rim)
    try:
        wire = rim_wire.makeOffset2D(float(distance), 0, False, False, False)
        failed = wire.isNull()
    except Exception:  # noqa: BLE001 - Part.OCCError, or FreeCAD's CADKernelError ("result of offsetting is null")
        failed = True
    if failed:
        # OCC 7.6 (FreeCAD 0.20) refused every 2-D offset of a free-form stadium's rim after a last-bit
        # change of its fit (BLAS on one thread): each smooth edge offset on its own instead
        return offset_edges_wire(rim_wire, float(distance))
    # offset curves as B-splines: FreeCAD 1.0's STEP writer drops extrusions of offset
    # curves (a die came back as an open shell of 3 of its 5 faces); an inward offset leaves
    # zero-length edges at the rim's C0 joins, which no face takes (Geom_TrimmedCurve::U1 == U2)
    edges = [e for e in wire.OrderedEdges if e.Length > 1e-9 * max(1.0, wire.Length)]
    return Part.Wire([e.toNurbs().Edges[0] for e in edges])


#: how far apart (mm) the ends of two consecutive offset edges may lie for :func:`offset_edges_wire`
#: to join them: the rim's edges meet tangentially (a free-form stadium's: 7e-9 mm)
OFFSET_JOIN_MM = 1e-6


def offset_edges_wire(wire, distance: float):
    """The closed plan ``wire`` offset outward (away from the area it encloses) by ``distance`` mm, edge by
    edge: each edge's exact offset curve (``Part.OffsetCurve``, as a B-spline within 1e-9 mm).  For a rim whose edges meet
    tangentially (a fit's C0 knots at an outline's G1 joins: the offsets of two edges then start and end at
    the same point); :class:`~tabletcad.errors.GeometryError` where two of them end more than
    :data:`OFFSET_JOIN_MM` apart (a corner, which needs a join)."""
    import FreeCAD
    import Part

    from tabletcad.errors import GeometryError

    pts = wire.discretize(512)
    twice_area = sum(a.x * b.y - b.x * a.y for a, b in zip(pts, pts[1:] + pts[:1]))
    # Geom_OffsetCurve moves a point along T x Z: to the right of travel, outward on a counter-clockwise curve
    side = 1.0 if twice_area > 0.0 else -1.0
    edges, ends = [], []
    for e in wire.OrderedEdges:
        if e.Length <= 1e-9 * max(1.0, wire.Length):
            continue
        back = e.Orientation == "Reversed"  # travelled against its curve: the curve's right is the wire's left
        curve = Part.OffsetCurve(e.Curve, (-side if back else side) * float(distance), FreeCAD.Vector(0, 0, 1))
        a, b = e.FirstParameter, e.LastParameter
        # as a B-spline to 1e-9 mm where the edge is its whole curve (a rim's edges are: _rim_wire), since
        # toNurbs' own approximation lost 2e-7 of the area (the parallel curve's Steiner area A + P d + π d²
        # and Part's offset of the whole rim agree to 1e-12); else toNurbs
        whole = max(abs(a - curve.FirstParameter), abs(b - curve.LastParameter)) <= 1e-12 * max(1.0, abs(b - a))
        edges.append(curve.approximateBSpline(1e-9, 200, 9, "C2").toShape() if whole
                     else curve.toShape(a, b).toNurbs().Edges[0])
        ends.append((curve.value(b), curve.value(a)) if back else (curve.value(a), curve.value(b)))
    gaps = [(p[1] - q[0]).Length for p, q in zip(ends, ends[1:] + ends[:1])]
    if not edges or max(gaps) > OFFSET_JOIN_MM:
        raise GeometryError(f"the rim's offset by {distance:g} mm: its edges' offsets end {max(gaps, default=0):.3g} mm "
                            "apart (a corner)", wire)
    out = Part.Wire(edges)
    if not out.isClosed():
        raise GeometryError(f"the rim's offset by {distance:g} mm is not closed", wire)
    return out


def _rim_face(rims, clearance=0.0, hole_clearance=None):
    """The plan face inside the rims (a ring's hole cut out); with ``clearance`` > 0 a punch tip's:
    the outer rims offset inward by it and the holes outward by ``hole_clearance`` (``clearance`` when
    not given)."""
    import Part

    outer = [r for r in rims if not r["inner"]]
    inner = [r for r in rims if r["inner"]]
    hole = clearance if hole_clearance is None else hole_clearance
    if clearance > 0 or hole > 0:
        wires = ([_offset_rim_wire(r, -clearance) if clearance > 0 else _rim_wire(r) for r in outer]
                 + [_offset_rim_wire(r, hole) if hole > 0 else _rim_wire(r) for r in inner])
    else:
        wires = [_rim_wire(r) for r in outer + inner]
    if len(wires) == 1:
        return Part.Face(wires[0])
    return Part.Face(wires, "Part::FaceMakerBullseye")


def plan_area(tablet, rims):
    """Area (mm²) of the tablet's silhouette along z: the core's ``tablet.plan_area()``, the report's
    figure (the rim's face had left out a PDE band's bulge and a dome's overhang: 78.540 for the deep
    convex round's 78.619 mm²); the face inside its upper rim (minus the hole of a ring) only where
    the core gives none (a hollow shaped cut-away)."""
    core = tablet.plan_area()
    if core is not None and math.isfinite(core):
        return float(core)
    sel, _ = _select(rims, "upper")
    return float(_rim_face(sel).Area)


def _select(rims, which):
    from tabletcad.errors import GeometryError

    outer_z = [r["z"] for r in rims if not r["inner"]]
    if not outer_z:
        raise GeometryError(
            "the tablet has no horizontal rim on its silhouette (no band edge to make tooling from)", rims
        )
    z = max(outer_z) if which == "upper" else min(outer_z)
    return [r for r in rims if abs(r["z"] - z) <= 1e-7 * max(1.0, abs(z))], z


def _require_band(rims):
    """DesignError unless the tablet has a band (as ``tabletcad build``: a sphere or a spheroid has only a
    seam at its equator, which its domes overhang; a die made on it overlapped the tablet)."""
    from tabletcad.errors import DesignError

    if any(r.get("band") is False for r in rims if not r["inner"]):
        raise DesignError("Tablet", "no band", "tooling needs a tablet with a band (a cylindrical side wall the die "
                          "forms); this one has none")


def punch_shape(tablet_shape, rims, which="upper", length=10.0, clearance=0.025):
    """Punch tip: prism on the upper (lower) rims offset inward by ``clearance`` (the radial room
    between tip and die bore), ``length`` mm up (down), minus the tablet: the prism itself where nothing of
    the tablet lies beyond the rim's plane (a face flat at the rim)."""
    import FreeCAD
    import Part

    from tabletcad.errors import DesignError, GeometryError
    from tabletcad.tolerance import DEFAULT
    from tabletcad.tooling.spec import EDGE_SNAP_MM, MAX_CLEARANCE_MM, MIN_TIP_BACKING_MM

    if not 0.0 < length <= DEFAULT.max_length:
        raise DesignError("punch Length", length, f"must be > 0 and <= {DEFAULT.max_length:g}", "mm")
    if not 0.0 <= clearance <= MAX_CLEARANCE_MM:
        raise DesignError("punch Clearance", clearance, f"must be >= 0 and <= {MAX_CLEARANCE_MM:g}", "mm")
    _require_band(rims)
    sel, _ = _select(rims, which)
    sign = 1.0 if which == "upper" else -1.0
    z = float(sel[0]["z"])
    span = sel[0].get("tablet_z")  # (documents saved before it was kept: the cut)
    rise = None if span is None else (span[1] - z if which == "upper" else z - span[0])
    if rise is not None and not length >= rise + MIN_TIP_BACKING_MM:  # (a 1e-6 mm tip: "Boolean gave 0 solids")
        raise DesignError("punch Length", length, f"must be >= {rise + MIN_TIP_BACKING_MM:.4g} mm: the tablet's face rises "
                          f"{rise:.4g} mm beyond its band edge and the tip keeps {MIN_TIP_BACKING_MM:g} mm of steel "
                          "behind it (as tabletcad build)", "mm")
    # the tip follows the die bore (:func:`die_shape`), the clearance inside it, as tabletcad build's tips
    from tabletcad.tooling.spec import tip_inset

    try:
        face = _rim_face(sel, tip_inset(clearance, _bore_offset(sel)), clearance)
    except (GeometryError, Part.OCCError) as exc:
        raise DesignError("punch Clearance", clearance, f"leaves no punch tip inside the tablet's outline ({exc})",
                          "mm") from None
    prism = face.extrude(FreeCAD.Vector(0, 0, sign * float(length)))
    if rise is not None and rise <= 1e-9 * max(1.0, abs(z)):
        # nothing of the tablet beyond the rim's plane (a flat face at the rim: the free-form stadium's):
        # the prism only touches it, and is the tip.  OCC's cut of a prism lying on a B-spline plane took
        # 10 s (FreeCAD 0.20) for the same solid to 1e-11 of its volume.
        result = prism
    else:
        result = prism.cut(tablet_shape)
    punch = _valid_solid(result.Solids, which)
    if result is not prism:
        # the tip's edge, where its wall meets the tablet's face, stands above the band's edge where the cup runs
        # into the wall (no land wider than the tip's inset): the length runs from that edge, as tabletcad
        # build's tips (tabletcad.tooling.punch.punch_tip: the same optimal box); the tips had been that rise
        # shorter (10.4 µm on a 9 mm round with a land below the clearance)
        edge = _tight_z(punch, low=which == "upper")
        rise_edge = sign * (edge - z)
        if rise_edge > EDGE_SNAP_MM:
            prism = face.extrude(FreeCAD.Vector(0, 0, sign * (float(length) + rise_edge)))
            punch = _valid_solid(prism.cut(tablet_shape).Solids, which)
    return punch


def _valid_solid(solids, which):
    """The one solid of a punch's Boolean, fixed if OCC's check finds it invalid; GeometryError else."""
    from tabletcad.errors import GeometryError

    if len(solids) != 1:
        raise GeometryError(f"{which} punch: Boolean gave {len(solids)} solids, expected 1", solids)
    punch = solids[0]
    if not punch.isValid():
        punch.fix(1e-7, 1e-7, 1e-7)
    if not punch.isValid():
        raise GeometryError(f"{which} punch: Boolean result is not valid", punch)
    return punch


def _tight_box(shape):
    """``shape``'s box from its geometry: OCC's optimal box without triangulation or tolerances, as tabletcad
    build measures (FreeCAD 0.20 takes no second argument: ``(False, False)`` had always fallen back); the
    loose box in a FreeCAD without it."""
    try:
        return shape.optimalBoundingBox(False)
    except Exception:
        return shape.BoundBox


def _tight_z(shape, low: bool) -> float:
    """The lowest (``low``) or highest z (mm) of ``shape``'s geometry (:func:`_tight_box`), as tabletcad build
    measures a tip's edge."""
    box = _tight_box(shape)
    return float(box.ZMin if low else box.ZMax)


def _bore_offset(rims) -> float:
    """The die bore's offset (mm) outside the outer rims: their plan overhang (stored as ``band_bulge``, the
    key older documents' RimData has) cleared as ``tabletcad build`` clears it (``tooling.spec.bore_offset``)."""
    from tabletcad.tooling.spec import bore_offset

    return bore_offset(max((float(r.get("band_bulge", 0.0)) for r in rims if not r["inner"]), default=0.0))


def plan_size(shape) -> float:
    """The tablet's largest plan extent (mm) from its solid's tight box (the surfaces' extrema, as the
    core's dimensions: the loose box of B-spline poles could cross a TSM die's size limit)."""
    box = _tight_box(shape)
    return max(box.XLength, box.YLength)


def die_shape(rims, height=22.22, outer_diameter=30.16):
    """Die: cylinder (``outer_diameter``, ``height``, centred on the band) minus the bore, the
    tablet's exact plan outline when it has one, else its outer rim, offset by the band's bulge
    where its PDE surface leaves the outline (as ``tabletcad build``: the punch tips take the
    clearance)."""
    import FreeCAD
    import Part

    from tabletcad.errors import DesignError, GeometryError
    from tabletcad.tolerance import DEFAULT
    from tabletcad.tooling.spec import MIN_DIE_WALL_MM

    for name, value in (("die Height", height), ("die OuterDiameter", outer_diameter)):
        if not 0.0 < value <= DEFAULT.max_length:  # (a NaN outer diameter had reached the Boolean)
            raise DesignError(name, value, f"must be > 0 and <= {DEFAULT.max_length:g}", "mm")
    _require_band(rims)
    outer = [r for r in rims if not r["inner"]]
    if not outer:
        raise GeometryError(
            "the tablet has no horizontal rim on its silhouette (no band to make a die for)", rims
        )
    lo = min(outer, key=lambda r: r["z"])
    z_lo, z_hi = lo["z"], max(r["z"] for r in outer)
    if not height >= z_hi - z_lo + 2.0:  # centred on the band, 1 mm of it past each band edge at least
        raise DesignError("die Height", height, f"must be >= {z_hi - z_lo + 2.0:.4g} mm: the band is {z_hi - z_lo:.4g} mm "
                          "high and the die, centred on it, reaches 1 mm past each of its edges", "mm")
    bulge = _bore_offset([lo])  # (a thesis band bulges 2.5 µm)
    if bulge > 0:
        bore_wire = _offset_rim_wire(lo, bulge)
    else:
        bore_wire = offset_outline_wire(lo["outline"], 0.0, z_lo) if lo.get("outline") else _rim_wire(lo)
    reach = bulge + (lo["radius"] if "radius" in lo else float(np.max(np.hypot(*np.asarray(lo["poles"])[:, :2].T))))
    if outer_diameter / 2.0 - reach < MIN_DIE_WALL_MM:  # tabletcad build's rule
        raise DesignError(
            "die OuterDiameter",
            outer_diameter,
            f"must be >= {2 * (reach + MIN_DIE_WALL_MM):.4g} mm (the tablet reaches {reach:.4g} mm from the axis, "
            f"the die's walls need {MIN_DIE_WALL_MM} mm)",
            "mm",
        )
    zc = 0.5 * (z_lo + z_hi)
    base = zc - height / 2.0
    body = Part.makeCylinder(outer_diameter / 2.0, height, FreeCAD.Vector(0, 0, base))
    bore = Part.Face(bore_wire)
    bore.translate(FreeCAD.Vector(0, 0, base - 1.0 - z_lo))
    bore_solid = bore.extrude(FreeCAD.Vector(0, 0, height + 2.0))
    result = body.cut(bore_solid)
    if len(result.Solids) != 1 or not result.Solids[0].isValid():
        raise GeometryError("die: Boolean did not give one valid solid", result)
    return result.Solids[0]
