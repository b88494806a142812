"""Upper and lower punch tips whose faces are the tablet's cups.

A tip is the plan outline inset by the radial clearance, extruded from inside
the tablet (mid band) to ``tip_length_mm`` beyond the band edge, minus the
tablet solid: its face is the cup (scores become bars, debossed figures
raised ones and embossed figures engravings).  Parts are made in the closed
position (the tip edges at the band edges).

Working-length datum: the tip's back face (``datum_plane_z_mm``) is the
reference plane; the working-length point is the bottom of the punch cup
(the tablet's extreme point on that face), recorded with its distance from
the datum.  The full punch length is the toolmaker's; the datum distances let
it be added.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from tabletcad.errors import GeometryError
from tabletcad.tooling.spec import EDGE_SNAP_MM
from tabletcad.tooling.booleans import CACHE, boolean, checked_boolean, reference_point, split_cells, volume
from tabletcad.tooling.outline import TabletFrame, face_area, plan_face, prism, spline_offset_deviation, wire_length

__all__ = ["PunchTip", "punch_tip", "cup_volume_within", "elliptic_tip_quadrature", "punch_volume_quadrature"]


@dataclass(eq=False)
class PunchTip:
    """A punch tip solid (mm) at the closed position and its facts."""

    name: str
    shape: object
    volume_mm3: float
    info: dict = field(default_factory=dict)


def punch_tip(frame: TabletFrame, tablet_shape, which: str, clearance: float, tip_length: float, *,
              check: bool = True, deflection: float = 0.005, tablet_manifold=None):
    """The ``"upper"`` or ``"lower"`` punch tip; returns ``(PunchTip, BooleanCheck or None)``.

    The tip's edge is where its wall meets the tablet's face: the band's edge when the tablet has a
    land wider than the tip's inset, else higher up the cup (a tablet without a land: 0.013 mm on a
    2.5 mm-deep oval cup at 0.025 mm clearance).  ``tip_length`` runs from that edge, so the punch's
    overall length, measured from its tip edge, is the one its body gives."""
    inset = frame.tip_inset(clearance)  # the tip follows the die bore, the clearance inside it
    tip_wire = frame.offset(-inset)
    z_mid = 0.5 * (frame.band_z[0] + frame.band_z[1])
    up = which == "upper"
    edge = frame.band_z[1] if up else frame.band_z[0]
    # the tip's face is the tablet's: its volume is integrated about the tablet's point where that is
    # near its own (the letters on this face), so that the faces they share are integrated once
    about = reference_point(tablet_shape)

    # a wall within the band's certified micrometre of the outline (no clearance: a line-to-line fit) meets
    # a PDE band that bows inward: the prism then starts at the band's edge (see _ON_OUTLINE_MM)
    on_outline = inset <= _ON_OUTLINE_MM
    z_near = edge if on_outline else z_mid

    def checked(body, exact, checking: bool):
        # the manifold check is on "prism minus tablet": the removed volume is the tablet inside the prism
        return checked_boolean("cut", body, tablet_shape, what=f"{which} punch tip", deflection=deflection,
                               check=checking, a_manifold=None, sliver=1e-4, about=about, exact=exact)

    def tip_prism(edge_z: float, length: float):
        z0, z1 = (z_near, edge_z + length) if up else (edge_z - length, z_near)
        return z0, z1, prism(tip_wire, z0, z1)

    def cut(edge_z: float, length: float):
        z0, z1, body = tip_prism(edge_z, length)
        if on_outline:  # (tip_cell's split needs the prism's inner end inside the tablet; fuzzy: _ON_OUTLINE_MM)
            return body, boolean("cut", body, tablet_shape, what=f"{which} punch tip", sliver=1e-4, fuzzy=1e-5)
        return body, tip_cell(body, tablet_shape, z_mid, z0, z1, which, memo=(frame, inset))

    def measured_edge(tip) -> float:  # the tip's end nearest the tablet: where its wall meets the face
        # (the band's edge itself when within EDGE_SNAP_MM of it: a land's edge is the band's)
        return tight_edge(tip, edge, EDGE_SNAP_MM, low=up)

    # The tip's edge is measured on a tip cut from the band's edge.  Where it may lie higher up the cup (no
    # land wider than the inset), that tip is cut longer than its length plus the tablet's thickness and,
    # its edge measured, trimmed to its length by the plane of the prism's end (tip_trimmed): OCC had
    # split the prism by the tablet's face twice, the second time only to end it higher.  Elsewhere, or
    # when the trim fails, the tip from the band's edge is kept when its edge is the band's and else cut
    # again from its edge.  Only the tip kept is checked (the first one's check had been thrown away).
    body = shape = None
    if _edge_may_rise(frame, inset, up):
        reach = frame.z_max - frame.z_min + 1.0  # farther than any edge of the tip can rise
        _, long_tip = cut(edge, tip_length + reach)
        tip_edge = measured_edge(long_tip)
        if abs(tip_edge - edge) < reach - 0.5:
            try:
                end = tip_edge + tip_length if up else tip_edge - tip_length
                # (a long tip reused from an earlier build, tip_cell's memo, has its trimmed tip too)
                shape = CACHE.get(long_tip, ("tip end", float(end), up), lambda: tip_trimmed(long_tip, tip_wire, end, up))
            except GeometryError:
                shape = None
        if shape is None:
            body, shape = cut(tip_edge, tip_length)
    else:
        body, shape = cut(edge, tip_length)
        tip_edge = measured_edge(shape)
        if tip_edge != edge:
            body, shape = cut(tip_edge, tip_length)
    if body is None:
        body = tip_prism(tip_edge, tip_length)[2]  # the prism the tip is cut from, for its check
    found = shape
    shape, chk = checked(body, lambda: found, check)
    cup_point = frame.z_max if up else frame.z_min
    datum = tip_edge + tip_length if up else tip_edge - tip_length
    vol = volume(shape, about=about)
    cup = frame.cup_depth_top if which == "upper" else frame.cup_depth_bottom
    land = None if frame.land is None or cup < 1e-9 else frame.land - inset  # a flat tip has no land
    quad = punch_volume_quadrature(frame, clearance, tip_length + abs(tip_edge - edge), which)
    info = dict(
        tip_outline=frame.outline_kind,
        tip_plan_area_mm2=face_area(plan_face(tip_wire)),
        tip_perimeter_mm=wire_length(tip_wire),
        tip_diameter_mm=None if frame.round_radius is None else 2.0 * (frame.round_radius - inset),
        tip_length_mm=tip_length,
        clearance_mm=clearance,
        tip_inset_from_outline_mm=inset,
        land_mm=land,
        tip_edge_z_mm=tip_edge,
        cup_depth_mm=frame.cup_depth_top if which == "upper" else frame.cup_depth_bottom,  # the tablet's, from its band
        # the cup as the punch has it: from the tip's edge (higher up the cup than the band without a land wider
        # than the tip's inset) to the face's deepest point (a toolmaker's trial: 0.887, not 0.9 mm, on an oval)
        cup_depth_on_tip_mm=abs(cup_point - tip_edge),
        working_length_datum=dict(
            datum_plane_z_mm=datum,
            cup_bottom_point_mm=[0.0, 0.0, cup_point],
            datum_to_cup_bottom_mm=abs(datum - cup_point),
            datum_to_tip_edge_mm=abs(datum - tip_edge),
            note="datum = back face of the tip; working length = head flat to cup bottom, i.e. "
                 "(head flat to datum) + datum_to_cup_bottom_mm",
        ),
        volume_mm3=vol,
        volume_quadrature_mm3=quad,
        volume_rel_diff_vs_quadrature=None if quad is None else (vol - quad) / quad,
    )
    if frame.spline is not None:  # the tip's B-spline against the spline outline's exact offset, measured densely
        info.update(spline_offset_deviation(frame, -inset, "tip_outline"))
    return PunchTip(f"{which}_punch", shape, vol, info), chk


#: a punch tip's wall this near the outline (mm, inside it) may meet the tablet's band, which a PDE surface
#: leaves by up to ``Tolerances.nominal`` (1 µm): its prism then runs from the band's edge, not from inside the
#: tablet.  From the band's middle, an almond's tips at no clearance held the skin between their walls and a
#: band bowing inward by a fraction of a micrometre: their edges were measured in the band's middle (2.1 mm,
#: the band running from 0.6 to 3.6 mm), the tips cut 1.5 mm short, and OCC's Common of a tip with the die
#: gave the whole tip, so the closed-position check refused the build.  The cut from the band's edge is
#: fuzzy (1e-5 mm): exact, it left strips of the prism's end face 1e-7 mm wide (6e-7 mm^2) where the band
#: bows inward, faces BRepMesh cannot mesh.
_ON_OUTLINE_MM = 1e-3


def _edge_may_rise(frame: TabletFrame, inset: float, up: bool) -> bool:
    """Whether a tip's edge may stand above the band's edge, up the face: a cupped face without a land wider
    than the tip's inset (a flat face's tip ends at the band's edge; a radius or bevel edge rises too)."""
    cup = frame.cup_depth_top if up else frame.cup_depth_bottom
    return cup > 1e-9 and (frame.land is None or frame.land - inset <= 1e-9)


def tip_trimmed(tip, wire, z: float, up: bool):
    """The punch ``tip`` (a cell of the prism of the plan ``wire``, longer than wanted) ending at height ``z``
    (mm): split by the plan face of ``wire`` at ``z`` (the end face a prism of ``wire`` ending there has, so
    the trimmed tip's walls, faces and volume are the shorter prism's cell's: on the family samples the
    same face, edge and vertex counts and volumes within 2e-12 relative), the part towards the tablet kept."""
    from tabletcad.tooling.booleans import translated

    end = translated(plan_face(wire), dz=z)

    def keep(cell) -> bool:
        lo, hi = _z_range(cell)
        return lo < z - 1e-3 if up else hi > z + 1e-3

    return split_cells(tip, [end], keep, what="punch tip end")




def tight_z_range(shape, *, low: bool = True, high: bool = True) -> tuple[float | None, float | None]:
    """The lowest and highest z (mm) of ``shape``'s geometry itself (OCC's optimal box: the surfaces'
    extrema, not their poles or a tolerance-widened box); a side not asked for (``low``/``high``
    false) is None.

    OCC's optimal box of a shape is the union of its faces' (and of any edge or vertex that bounds
    no face).  Here a B-spline or Bézier face's optimal box is only computed where its quick box (the
    hull of its poles, which contains the surface), widened by the face's largest edge or vertex
    tolerance (how far its edges' curves may leave the surface), reaches past the extremes found so
    far, the faces reaching farthest first; every other face (whose quick box is made from samples
    of the surface, which can miss a bump) is always computed.  A shape with free edges or vertices
    takes OCC's box of the whole shape.  Before a B-spline or Bézier face is optimised, a tighter bound
    is tried (:func:`_hull_z_bound`: its poles' z range and its edges' optimal boxes, where its quick
    box is widened by a Boolean's section edges' tolerance).  The result equals OCC's box of the whole
    shape (tests/test_tooling_parts.py);
    a punch tip needs one side, and most of its B-spline faces (0.1-0.5 s of OCC's optimisation
    each solid) lie within it.  Computed once per shape and sides (:data:`~tabletcad.tooling.booleans.CACHE`)."""
    return CACHE.get(shape, ("tight z range", bool(low), bool(high)), lambda: _tight_z_range(shape, low, high))


def tight_edge(shape, z: float, tol: float, *, low: bool = True) -> float:
    """``z`` (mm) when ``shape``'s lowest (``low``; else highest) z of :func:`tight_z_range` lies within ``tol``
    (mm) of it (``abs(extreme - z) <= tol``), else that extreme itself, bit for bit.

    A face is optimised only where it may change the answer: besides :func:`tight_z_range`'s faces whose
    quick box lies beyond the extreme found so far, those whose quick box (widened by their tolerance)
    lies within ``tol`` of ``z`` once the extreme found so far does (the extreme can then only move within
    that window: the answer is ``z`` whatever their optimal boxes).  A punch tip over a land (its edge the
    band's) skips its cup's B-spline faces, 0.03-0.28 s of OCC's optimisation a tip, and, by their poles'
    and edges' bound, the land's pieces cut at the tip's wall (0.03 s a tip of the concave round, whose
    section edges' tolerance widens their quick box out of the window).  Computed once per
    shape, ``z``, ``tol`` and side (:data:`~tabletcad.tooling.booleans.CACHE`)."""
    return CACHE.get(shape, ("tight edge", float(z), float(tol), bool(low)),
                     lambda: _tight_z_range(shape, low, not low, window=(float(z), float(tol))))


def _tight_z_range(shape, low: bool, high: bool, window: tuple[float, float] | None = None):
    """:func:`tight_z_range` (``window`` None) or :func:`tight_edge` (``window = (z, tol)``, one side asked)."""
    from OCP.BRep import BRep_Tool
    from OCP.BRepAdaptor import BRepAdaptor_Surface
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib
    from OCP.GeomAbs import GeomAbs_SurfaceType
    from OCP.TopAbs import TopAbs_ShapeEnum
    from OCP.TopExp import TopExp_Explorer

    from tabletcad.cad._occ import explore

    def free(kind, outside) -> bool:  # a sub-shape of ``kind`` not inside any ``outside``
        return TopExp_Explorer(shape, kind, outside).More()

    def optimal(s) -> Bnd_Box:
        box = Bnd_Box()
        BRepBndLib.AddOptimal_s(s, box, False, False)
        return box

    faces = explore(shape, "Face")
    if not faces or free(TopAbs_ShapeEnum.TopAbs_EDGE, TopAbs_ShapeEnum.TopAbs_FACE) \
            or free(TopAbs_ShapeEnum.TopAbs_VERTEX, TopAbs_ShapeEnum.TopAbs_EDGE):
        box = optimal(shape)
        lo, hi = box.CornerMin().Z(), box.CornerMax().Z()
        if window is not None:
            return _snapped(lo if low else hi, window)
        return (lo if low else None), (hi if high else None)
    hull_kinds = (GeomAbs_SurfaceType.GeomAbs_BSplineSurface, GeomAbs_SurfaceType.GeomAbs_BezierSurface)
    entries = []
    for f in faces:
        if BRepAdaptor_Surface(f, False).GetType() in hull_kinds:
            quick = Bnd_Box()
            BRepBndLib.Add_s(f, quick, False)
            tol = max([BRep_Tool.Tolerance_s(e) for e in explore(f, "Edge")]
                      + [BRep_Tool.Tolerance_s(v) for v in explore(f, "Vertex")] + [0.0])
            entries.append((quick.CornerMin().Z() - tol, quick.CornerMax().Z() + tol, f))
        else:
            entries.append((-math.inf, math.inf, f))
    q_lo, q_hi = min(e[0] for e in entries), max(e[1] for e in entries)
    entries.sort(key=lambda e: min(e[0] - q_lo if low else math.inf, q_hi - e[1] if high else math.inf))
    def face_z(face) -> tuple[float, float] | None:  # a face's optimal z range, None for a void box
        box = optimal(face)
        return None if box.IsVoid() else (box.CornerMin().Z(), box.CornerMax().Z())

    def near(x: float) -> bool:  # within the window (a float interval: x - z is monotone in x)
        return window is not None and abs(x - window[0]) <= window[1]

    def needed(f_lo: float, f_hi: float) -> bool:  # whether a face within (f_lo, f_hi) may move the answer
        if not ((low and f_lo <= lo) or (high and f_hi >= hi)):
            return False
        # (in the window: the extreme stays in it, between the face's bound and the extreme so far)
        return not ((near(lo) and near(f_lo)) if low else (near(hi) and near(f_hi)))

    lo, hi = math.inf, -math.inf
    for f_lo, f_hi, face in entries:
        if needed(f_lo, f_hi):
            # a B-spline or Bézier face (the others' entries are unbounded) whose poles and edges' optimal
            # boxes bound it tighter (its quick box is widened by its edges' tolerance) cannot move the answer
            if math.isfinite(f_lo) and not needed(*CACHE.faces.get(face, ("z bound",),
                                                                   lambda f=face: _hull_z_bound(f))):
                continue
            # once per face (CACHE.faces): a shape asked for one side and then the other, or a face
            # another shape shares, is not optimised again (the same OCC computation of the same face)
            z = CACHE.faces.get(face, ("optimal z range",), lambda f=face: face_z(f))
            if z is not None:  # (a face of a triangulation alone: OCC's whole box skips it too)
                lo, hi = min(lo, z[0]), max(hi, z[1])
    if window is not None:
        return _snapped(lo if low else hi, window)
    return (lo if low else None), (hi if high else None)


#: how far (mm) OCC's optimal box of a B-spline or Bézier surface may reach beyond its poles' z range: the
#: box of its points is widened by ``Precision::Confusion`` (1e-7 mm); the other 1e-7 mm is margin for the
#: round-off of the points (its samples step a rounding past the parameter range's end)
HULL_WIDENING_MM = 2e-7


def _hull_z_bound(face) -> tuple[float, float]:
    """Bounds ``(lo, hi)`` (mm) of OCC's optimal z range of the B-spline or Bézier ``face``
    (``BRepBndLib::AddOptimal`` without triangulation or tolerance), tighter than its quick box where
    its edges' tolerance is large (a Boolean's section edges: 1e-5 mm and more).

    OCC's box of such a face (``BRepBndLib.cxx``, OCCT 7.9) is, on each side, either the box of its
    surface over the pcurves' parameter rectangle, clipped to the surface's bounds (a sampled and
    optimised one: surface points, widened by 1e-7 mm), or the union of its edges' optimal boxes
    (``BndLib_Add3dCurve::AddOptimal``: what the edges' curves reach, not their tolerance), which replaces
    the surface's side where the surface's extreme lies outside the face, and is the whole box of a
    B-spline of degree 1 along one direction.  The surface lies in its poles' hull (a B-spline's, rational
    too, is a convex combination of its poles), so the first lies within the poles' z range widened by
    :data:`HULL_WIDENING_MM`; the second is computed here as OCC computes it (the same calls on the same
    edges, ~0.1 ms a face against 15-40 ms for the face).  The bound is the wider of the two on each
    side (tests/test_tooling_parts.py checks it on a land's tip)."""
    from OCP.BRep import BRep_Tool
    from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Surface
    from OCP.Bnd import Bnd_Box
    from OCP.BndLib import BndLib_Add3dCurve
    from OCP.GeomAbs import GeomAbs_SurfaceType

    from tabletcad.cad._occ import explore

    adaptor = BRepAdaptor_Surface(face, False)
    bspline = adaptor.GetType() == GeomAbs_SurfaceType.GeomAbs_BSplineSurface
    surface = adaptor.BSpline() if bspline else adaptor.Bezier()  # (located: in the face's place)
    nu, nv = surface.NbUPoles(), surface.NbVPoles()
    zs = [surface.Pole(i, j).Z() for i in range(1, nu + 1) for j in range(1, nv + 1)]
    lo, hi = min(zs) - HULL_WIDENING_MM, max(zs) + HULL_WIDENING_MM
    edges = Bnd_Box()
    for e in explore(face, "Edge"):
        if not BRep_Tool.Degenerated_s(e) and BRep_Tool.IsGeometric_s(e):  # (the edges OCC adds)
            box = Bnd_Box()
            BndLib_Add3dCurve.AddOptimal_s(BRepAdaptor_Curve(e), 0.0, box)
            edges.Add(box)
    if edges.IsVoid():
        return lo, hi
    return min(lo, edges.CornerMin().Z()), max(hi, edges.CornerMax().Z())


def _snapped(x: float, window: tuple[float, float]) -> float:
    """``z`` when ``x`` lies within ``tol`` of it (``window = (z, tol)``, mm), else ``x``."""
    z, tol = window
    return z if abs(x - z) <= tol else x


def _z_range(shape) -> tuple[float, float]:
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib

    box = Bnd_Box()
    BRepBndLib.Add_s(shape, box, False)
    return box.CornerMin().Z(), box.CornerMax().Z()


def tip_cell(body, tablet_shape, z_mid: float, z0: float, z1: float, which: str, *, memo=None):
    """``body - tablet_shape`` for the tip prism ``body`` (``z0`` to ``z1``, its inner end ``z_mid`` inside the
    tablet): the prism split by the tablet's faces beyond the band's middle only, the cell at the tip's far
    end kept (:func:`~tabletcad.tooling.booleans.split_cells`).

    Inside the prism the tablet's boundary is its face (cup, scores, figures): the band lies on the
    outline, outside the prism inset by the clearance (or on its wall), and is left out, so OCC never
    intersects the band with the prism's wall running parallel to it (the full Boolean took 0.5-2 s, the
    split ~0.1 s, with the same volume to 1e-12).  A cell that reaches the prism's inner end would have
    leaked into the tablet past a missing face: it is refused and the full Boolean is done instead, as
    when the split does not give one such cell.

    ``memo``: ``(frame, inset)`` when ``body`` is the prism of ``frame``'s outline inset by ``inset`` (mm)
    from ``z0`` to ``z1``: a split of the same faces (``IsEqual``, in :func:`_faces_in_order`) by the prism
    of the same frame's outline (its tablet the same object, its plain solid the same shape, so the same
    outline: :func:`~tabletcad.tooling.outline.tablet_frame` is a function of them) is the cell found
    before, kept in :data:`~tabletcad.tooling.booleans.CACHE` (the plain and the scored tooling of one
    tablet cut the same lower tip from the same faces; 0.1-0.6 s a split)."""
    from tabletcad.cad._occ import explore

    up = which == "upper"
    faces = _faces_in_order([f for f in explore(tablet_shape, "Face")
                             if (_z_range(f)[0] > z_mid if up else _z_range(f)[1] < z_mid)])
    far, near = (z1, z0) if up else (z0, z1)
    tol = 1e-6

    def keep(cell) -> bool:
        lo, hi = _z_range(cell)
        reaches_far = hi > far - tol if up else lo < far + tol
        reaches_near = lo < near + tol if up else hi > near - tol
        return reaches_far and not reaches_near

    def split():
        return split_cells(body, faces, keep, what=f"{which} punch tip")

    try:
        if memo is None:
            return split()
        frame, inset = memo
        return _memo_cell(frame, (which, float(inset), float(z_mid), float(z0), float(z1)), faces, split)
    except GeometryError:
        return _full_cut(body, tablet_shape, which)


def _full_cut(body, tablet_shape, which: str):
    """``body - tablet_shape`` by OCC's Boolean, for a tip prism the split of :func:`tip_cell` failed on.

    Where the prism's wall runs within a micrometre of an edge of the tablet's face (a shaped tablet's tip
    at a clearance equal to its land: the tips follow the die bore, which stands the band's 1 µm bulge
    outside the outline, so the wall cuts the land 1 µm outside its inner edge) the splitter gave no cell and
    the Boolean left the prism whole, nothing removed (a capsule's tip: 377.351 of 377.351 mm^3 kept;
    manifold3d removed 240 mm^3, so the check refused the build).  A tip always removes the tablet's part inside the prism (from the
    band's middle up): the cut is taken again with OCC's fuzzy tolerance 1e-5 mm, which joins the two
    edges (the parts then pass every check, the closed-position one too)."""
    what = f"{which} punch tip"
    cut = boolean("cut", body, tablet_shape, what=what, sliver=1e-4)
    whole = volume(body)
    if whole - volume(cut) > 1e-6 * whole:
        return cut
    return boolean("cut", body, tablet_shape, what=what, sliver=1e-4, fuzzy=1e-5)


def _faces_in_order(faces: list) -> list:
    """``faces`` sorted by their boxes' corners (``BRepBndLib.Add``, mm: x, y, z low then high; ties in
    the order given), an order set by the faces alone.

    The splitter's cell depends on the order of its faces, and a Boolean that leaves a face as it was
    may list it elsewhere: a scored tablet's unscored bottom faces are the plain tablet's, reordered by
    the score's cut (the oval's and the capsule's), so :func:`_memo_cell`, which needs them in the same
    order, missed the lower tip a scored build after a plain one shares with it, and cut it again."""
    def corners(face) -> tuple[float, ...]:
        from OCP.Bnd import Bnd_Box
        from OCP.BRepBndLib import BRepBndLib

        box = Bnd_Box()
        BRepBndLib.Add_s(face, box, False)
        return (*box.CornerMin().Coord(), *box.CornerMax().Coord())

    return [f for _, _, f in sorted(((corners(f), k, f) for k, f in enumerate(faces)), key=lambda e: e[:2])]


def _memo_cell(frame: TabletFrame, numbers: tuple, faces: list, compute):
    """``compute()`` (a tip's cell split from ``faces``), or the cell an earlier call found for the same
    frame (tablet object and plain solid), ``numbers`` and faces (see :func:`tip_cell`); an error is not kept."""
    found = CACHE.get(frame.shape, ("tip cells", numbers), lambda: [])  # [(tablet, faces, cell)]
    for tablet, kept, cell in found:
        if tablet is frame.tablet and len(kept) == len(faces) and all(a.IsEqual(b) for a, b in zip(kept, faces)):
            return cell
    cell = compute()
    found.append((frame.tablet, list(faces), cell))
    del found[:-4]  # (the last few finished tablets' faces)
    return cell


# ----------------------------------------------------------------------------- quadrature
def _face_patches(frame: TabletFrame, which: str):
    """Patches of the tablet's upper (lower) face: everything at or beyond the band edge."""
    out = []
    u = np.linspace(0.0, 1.0, 9)
    for p in frame.tablet.patches:
        z = p.evaluate(u, np.zeros_like(u))[:, 2]
        if which == "upper" and np.all(z >= frame.band_z[1] - 1e-9) and np.ptp(z) + np.ptp(p.evaluate(u, 0.0 * u)[:, 0]) > 0:
            out.append(p)
        if which == "lower" and np.all(z <= frame.band_z[0] + 1e-9) and np.ptp(z) + np.ptp(p.evaluate(u, 0.0 * u)[:, 0]) > 0:
            out.append(p)
    return out


def cup_volume_within(frame: TabletFrame, rho: float, which: str = "upper", n: int = 48) -> float | None:
    """Volume (mm^3) between a round tablet's face and its band-edge plane inside radius ``rho``:
    ``∫_0^ρ 2π r |z(r) - z_edge| dr`` by Gauss-Legendre on each face patch's profile (the
    patches of a round tablet are surfaces of revolution); None for other tablets."""
    from scipy.optimize import brentq

    if frame.round_radius is None:
        return None
    z_e = frame.band_z[1] if which == "upper" else frame.band_z[0]
    x, w = np.polynomial.legendre.leggauss(n)
    total = 0.0
    for p in _face_patches(frame, which):
        def r_of(u, p=p):
            return float(np.hypot(*p.evaluate(u, 0.0)[:2]))

        r0, r1 = r_of(0.0), r_of(1.0)
        lo, hi = 0.0, 1.0
        if min(r0, r1) >= rho:
            continue
        if max(r0, r1) > rho:
            us = brentq(lambda u: r_of(u) - rho, 0.0, 1.0, xtol=1e-15)
            lo, hi = (0.0, us) if r0 < r1 else (us, 1.0)
        u = 0.5 * (hi - lo) * (x + 1.0) + lo
        X = p.evaluate(u, np.zeros_like(u))
        Xu = p.evaluate(u, np.zeros_like(u), du=1)
        r = np.hypot(X[:, 0], X[:, 1])
        dr = (X[:, 0] * Xu[:, 0] + X[:, 1] * Xu[:, 1]) / np.maximum(r, 1e-300)
        total += abs(float(np.sum(0.5 * (hi - lo) * w * 2.0 * math.pi * r * np.abs(X[:, 2] - z_e) * dr)))
    return total


def punch_volume_quadrature(frame: TabletFrame, clearance: float, tip_length: float, which: str = "upper") -> float | None:
    """Volume (mm^3) of a plain round punch tip: cylinder of radius ``R - inset`` (the clearance less
    the die bore's offset, :meth:`~tabletcad.tooling.outline.TabletFrame.tip_inset`) and ``tip_length``
    (its length beyond the band's edge plane: the tip's own plus its edge's rise up a cup without a
    land) minus the cup inside it (:func:`cup_volume_within`); for a tablet of elliptic sections on
    an elliptic outline (the thesis's ovals and caplet) the same with the tip's plan, the ellipse
    inset, and the cup within it (:func:`elliptic_tip_quadrature`); None for other tablets."""
    inset = frame.tip_inset(clearance)
    if frame.round_radius is None:
        found = elliptic_tip_quadrature(frame, inset, which)
        return None if found is None else found[0] * tip_length - found[1]
    rho = frame.round_radius - inset
    cup = cup_volume_within(frame, rho, which)
    return math.pi * rho * rho * tip_length - cup


def _outline_ellipse(frame: TabletFrame):
    """The frame's outline as a ``gp_Elips`` when it is one ellipse, else None."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.GeomAbs import GeomAbs_CurveType

    from tabletcad.cad._occ import explore

    edges = explore(frame.outline, "Edge")
    if frame.outline_kind != "ellipse" or len(edges) != 1:
        return None
    curve = BRepAdaptor_Curve(edges[0])
    return curve.Ellipse() if curve.GetType() == GeomAbs_CurveType.GeomAbs_Ellipse else None


def _inset_ellipse(ellipse, inset: float, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Points ``P(t)`` (n, 2) of ``ellipse`` (a ``gp_Elips`` in z = 0) moved ``inset`` mm along its inward
    normal, and ``P × P'`` (n,) at the ellipse's parameters ``t``."""
    a, b = ellipse.MajorRadius(), ellipse.MinorRadius()
    c, x, y = ellipse.Location(), ellipse.XAxis().Direction(), ellipse.YAxis().Direction()
    X, Y = np.array([x.X(), x.Y()]), np.array([y.X(), y.Y()])
    ct, st = np.cos(t), np.sin(t)
    w = np.hypot(b * ct, a * st)  # |E'(t)|: the outward normal is (b cos t, a sin t) / w in the (X, Y) frame
    dw = (a * a - b * b) * st * ct / w
    ex, ey = a * ct - inset * b * ct / w, b * st - inset * a * st / w
    dex = -a * st - inset * b * (-st * w - ct * dw) / (w * w)
    dey = b * ct - inset * a * (ct * w - st * dw) / (w * w)
    P = np.array([c.X(), c.Y()]) + ex[:, None] * X + ey[:, None] * Y
    return P, (ex * dey - ey * dex) * float(X[0] * Y[1] - X[1] * Y[0])


def _u_at_radius(sec, rho: np.ndarray, rising: bool, steps: int = 60) -> np.ndarray:
    """The ``u`` where ``|R(u)| = ρ`` on the profile ``sec`` (``|R|`` rising or falling in ``u`` through
    it), for each ``ρ`` at once, by bisection to ``2^-steps``."""
    a, b = np.zeros_like(rho), np.ones_like(rho)
    for _ in range(steps):
        m = 0.5 * (a + b)
        inside = (np.abs(sec.profile(m)[:, 0]) < rho) == rising  # the crossing lies above m
        a, b = np.where(inside, m, a), np.where(inside, b, m)
    return 0.5 * (a + b)


def _section_cup(sections, rho: np.ndarray, z_e: float, n: int = 48) -> np.ndarray:
    """``∫_0^ρ 2π r |Z - z_e| dr`` (mm^3) for each ``ρ`` over the face profiles ``sections``
    (:class:`~tabletcad.geometry.revolution.Section`, ``r = |R(u)|`` monotone where it is below ``ρ``): the
    cup within the section ``xᵀ S⁻¹ x = ρ²`` (area ``π ρ²``, ``det S = 1``).  Each patch's part within
    ``ρ`` (:func:`_u_at_radius`) by Gauss-Legendre, as :func:`cup_volume_within` for a round tablet."""
    x, w = np.polynomial.legendre.leggauss(n)
    total = np.zeros_like(rho)
    for sec in sections:
        r0, r1 = np.abs(sec.profile(np.array([0.0, 1.0]))[:, 0])
        rising = r0 < r1
        us = np.where(rho >= max(r0, r1), float(rising), _u_at_radius(sec, np.minimum(rho, max(r0, r1)), rising))
        lo, hi = (np.zeros_like(rho), us) if rising else (us, np.ones_like(rho))
        u = 0.5 * (hi - lo)[:, None] * (x + 1.0) + lo[:, None]
        RZ, dRZ = sec.profile(u), sec.profile(u, du=1)
        f = 2.0 * math.pi * np.abs(RZ[..., 0]) * np.abs(RZ[..., 1] - z_e) * np.abs(dRZ[..., 0])
        total += 0.5 * (hi - lo) * (f @ w)
    return total


def elliptic_tip_quadrature(frame: TabletFrame, inset: float, which: str = "upper",
                            m: int = 256) -> tuple[float, float] | None:
    """Plan area (mm^2) of a punch tip whose outline is the tablet's elliptic outline inset by ``inset`` mm,
    and the volume (mm^3) of the tablet's cup (above or below the band's edge plane) within it, by
    quadrature of the face patches' profiles; None unless the outline is one ellipse and every face patch
    is a :class:`~tabletcad.geometry.revolution.Section` of one shape ``S`` (the thesis's ovals and caplet).

    The face's height above the edge plane depends on the section radius ``ρ = √(xᵀ S⁻¹ x)`` alone, so
    over the star-shaped tip plan bounded by ``P(t)`` (the ellipse inset along its normal)
    ``∫∫ h dA = ∫_0^{2π} C(ρ(P)) / (2π ρ(P)²) (P × P') dt``, ``C(ρ)`` the cup within the section
    :func:`_section_cup`; the plan area is ``∫ (P × P') / 2 dt``.  Both integrands are smooth and
    periodic: the trapezoid rule on ``m`` points."""
    ellipse = _outline_ellipse(frame)
    sections = [p.section for p in _face_patches(frame, which)]
    if ellipse is None or not sections or any(s is None for s in sections):
        return None
    shape = sections[0].shape
    if any(not np.allclose(s.shape, shape, rtol=0.0, atol=1e-12) for s in sections):
        return None
    t = np.linspace(0.0, 2.0 * math.pi, m, endpoint=False)
    P, cross = _inset_ellipse(ellipse, inset, t)
    rho = np.sqrt(np.einsum("ij,jk,ik->i", P, np.linalg.inv(shape), P))
    z_e = frame.band_z[1] if which == "upper" else frame.band_z[0]
    cup = _section_cup(sections, rho, z_e) / (2.0 * math.pi * rho * rho)
    h = 2.0 * math.pi / m
    return abs(0.5 * h * float(np.sum(cross))), abs(h * float(np.sum(cup * cross)))
