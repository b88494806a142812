"""Drafted (stroke-angle) prisms of emboss figures: ruled lofts of in-plane offsets.

A drafted prism of a plan face, nominal at z = 0, narrowing over ``n`` mm upwards and widening over
``w`` mm downwards with walls at angle ``a`` to the axis (t = tan a), has at height z the section
offset inwards by ``z t``.  Its volume is the integral of the section's area
A(s) = A + P s + K s² (s the outward offset; P the perimeter, K the corner term: π for a circle,
4 for a square with sharp corners), i.e.

    V = A h - P t (n² - w²) / 2 + K t² (n³ + w³) / 3,   h = n + w,

exact for a disc (the frustum π h (R₁² + R₁R₂ + R₂²) / 3) and a square (the pyramid frustum
h (A₁ + A₂ + √(A₁A₂)) / 3).  For glyphs (Bézier outlines whose offsets OCC approximates, lofted
through paired polygons where the two ends' edges do not pair up) the volume lies between the
straight prisms of the narrow and the wide end sections and within 0.15 · P h² t / 2 of the linear
part ``A h - P t (n² - w²) / 2`` (the corner term |K| t² (n³ + w³) / 3 of the glyphs' sharp corners:
measured at most 0.041 of P h² t / 2 at 15° ("X") and 0.107 at 30° ("M") for DejaVu Sans Bold).

``LocOpe_DPrism``, used before, segfaulted the process on "6", "8" and "9"."""

import math
import string
from pathlib import Path

import pytest

pytest.importorskip("OCP")

from tabletcad.pipeline.design import load_design  # noqa: E402
from tabletcad.tooling.spec import EmbossSpec, ToolingSpec, font_path  # noqa: E402

pytestmark = pytest.mark.cad

ROOT = Path(__file__).resolve().parents[1]
N, W = 0.2, 0.1  # narrowing upwards and widening downwards (mm): a deboss 0.12 deep on a flat face


def _volume(shape) -> float:
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    p = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, p, 1e-9)  # adaptive: the default Gauss rule is 20 % off on
    return p.Mass()                                # the walls through a resampled B-spline section


def _area(face) -> float:
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    p = GProp_GProps()
    BRepGProp.SurfaceProperties_s(face, p, 1e-9)
    return abs(p.Mass())


def _valid(shape) -> bool:
    from OCP.BRepCheck import BRepCheck_Analyzer

    return BRepCheck_Analyzer(shape).IsValid()


def _end_areas(solid, z_lo: float, z_hi: float) -> tuple[float, float]:
    """Areas (mm²) of the solid's planar faces at ``z_lo`` and ``z_hi``."""
    from tabletcad.cad._occ import explore
    from tabletcad.tooling.punch import tight_z_range as _z_range

    lo = hi = 0.0
    for f in explore(solid, "Face"):
        if _vertex_z_span(f) > 1e-6:  # a wall: its z range is wider still (skips its optimal box)
            continue
        a, b = _z_range(f)
        if b - a < 1e-6:  # the boxes are 1e-7 mm wider than the shapes
            if abs(a - z_lo) < 1e-6:
                lo += _area(f)
            elif abs(a - z_hi) < 1e-6:
                hi += _area(f)
    return lo, hi


def _vertex_z_span(face) -> float:
    """A lower bound (mm) of the z extent of ``face``: its vertices' z range, each vertex moved
    towards the others by its tolerance (the face passes within that of its vertices)."""
    from OCP.BRep import BRep_Tool

    from tabletcad.cad._occ import explore

    lows, highs = [], []
    for v in explore(face, "Vertex"):
        z, tol = BRep_Tool.Pnt_s(v).Z(), BRep_Tool.Tolerance_s(v)
        lows.append(z + tol)
        highs.append(z - tol)
    return max(highs) - min(lows) if lows else 0.0


def _polygon(points):
    from tabletcad.tooling.outline import polyline_wire

    return polyline_wire(tuple(points))


def _square(c: float, x0: float = 0.0):
    return _polygon([(x0 - c, -c), (x0 + c, -c), (x0 + c, c), (x0 - c, c)])


@pytest.mark.parametrize("a", [15.0, 30.0])
def test_disc_gives_the_frustum(a):
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeWire
    from OCP.gp import gp_Ax2, gp_Circ, gp_Dir, gp_Pnt

    from tabletcad.tooling.emboss import figure_prism
    from tabletcad.tooling.punch import tight_z_range as _z_range
    from tabletcad.tooling.outline import plan_face

    r, t = 1.5, math.tan(math.radians(a))
    wire = BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(gp_Circ(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), r)).Edge()).Wire()
    z_n = 0.7
    solid = figure_prism(plan_face(wire), z_n - W, z_n + N, a, z_nominal=z_n)  # narrower upwards
    assert _valid(solid)
    assert _z_range(solid) == pytest.approx((z_n - W, z_n + N), abs=2e-7)
    r1, r2 = r + W * t, r - N * t
    assert _volume(solid) == pytest.approx(math.pi * (N + W) * (r1 * r1 + r1 * r2 + r2 * r2) / 3.0, rel=1e-9)
    assert _end_areas(solid, z_n - W, z_n + N) == pytest.approx((math.pi * r1 * r1, math.pi * r2 * r2), rel=1e-9)


@pytest.mark.parametrize("a", [15.0, 30.0])
@pytest.mark.parametrize("up", [True, False])
def test_square_with_square_hole_gives_the_pyramid_frusta(a, up):
    """A square of half-side c with a square hole of half-side b: the outer frustum minus the hole's,
    the hole growing where the outer shrinks (sharp corners: the offsets' intersection join)."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace

    from tabletcad.cad._occ import explore
    from tabletcad.tooling.emboss import figure_prism
    from tabletcad.tooling.punch import tight_z_range as _z_range
    from tabletcad.tooling.outline import plan_face

    c, b, t = 1.0, 0.4, math.tan(math.radians(a))
    from OCP.TopoDS import TopoDS

    mk = BRepBuilderAPI_MakeFace(plan_face(_square(c)))
    mk.Add(TopoDS.Wire_s(_square(b).Reversed()))
    face = mk.Face()
    n, w = (N, W) if up else (W, N)
    z0, z1 = (-w, n) if up else (w, -n)  # narrow over n towards z1, wide over w towards z0
    solid = figure_prism(face, z0, z1, a, z_nominal=0.0)
    assert _valid(solid) and len(explore(solid, "Solid")) == 1
    assert _z_range(solid) == pytest.approx((min(z0, z1), max(z0, z1)), abs=2e-7)

    def frustum(a1, a2):
        return (n + w) * (a1 + a2 + math.sqrt(a1 * a2)) / 3.0

    outer = frustum((2 * (c + w * t)) ** 2, (2 * (c - n * t)) ** 2)
    hole = frustum((2 * (b - w * t)) ** 2, (2 * (b + n * t)) ** 2)
    assert _volume(solid) == pytest.approx(outer - hole, rel=1e-9)
    # the closed form of the module docstring: K = 4 - 4 (the hole's corners turn the other way)
    A, P = 4 * (c * c - b * b), 8 * (c + b)
    assert _volume(solid) == pytest.approx(A * (n + w) - P * t * (n * n - w * w) / 2.0, rel=1e-9)
    narrow_end = _end_areas(solid, z1, z0)[0]
    assert narrow_end == pytest.approx((2 * (c - n * t)) ** 2 - (2 * (b + n * t)) ** 2, rel=1e-9)


@pytest.mark.parametrize("a", [15.0, 30.0])
@pytest.mark.parametrize("text", [string.digits, string.ascii_uppercase])
def test_every_glyph_gives_one_valid_drafted_solid(a, text):
    from tabletcad.cad._occ import explore
    from tabletcad.tooling.emboss import figure_prism, text_faces
    from tabletcad.tooling.punch import tight_z_range as _z_range
    from tabletcad.tooling.outline import face_area, wire_length

    t = math.tan(math.radians(a))
    for ch in text:
        for face in explore(text_faces(ch, 2.5, font_path("DejaVuSans-Bold")), "Face"):
            solid = figure_prism(face, -W, N, a, z_nominal=0.0)
            assert len(explore(solid, "Solid")) == 1 and _valid(solid), ch
            assert _z_range(solid) == pytest.approx((-W, N), abs=2e-7), ch
            A = face_area(face)
            P = sum(wire_length(w) for w in explore(face, "Wire"))
            h, V = N + W, _volume(solid)
            wide_end, narrow_end = _end_areas(solid, -W, N)
            assert narrow_end * h < V < wide_end * h, ch
            assert narrow_end < A < wide_end, ch
            linear = A * h - P * t * (N * N - W * W) / 2.0
            assert abs(V - linear) <= 0.15 * P * h * h * t / 2.0, (ch, V, linear)


def test_floor_cut_down_to_the_prism_box_cuts_the_same():
    """The letter floor (the tablet offset inwards) cut down to the box around the drafted prism
    (``_around``) takes the same part of the prism away: one solid, valid, the same volume to
    1e-9 (OCC's section curves on a face ending near the walls)."""
    from tabletcad.cad._occ import explore
    from tabletcad.tooling.booleans import raw_boolean
    from tabletcad.tooling.emboss import _around, _offset_base, figure_prism, offset_solid, text_faces
    from tabletcad.tooling.outline import tablet_frame

    frame = tablet_frame(load_design(ROOT / "samples" / "families" / "concave_round.toml"))
    floor = offset_solid(_offset_base(frame), -0.12)
    prism = figure_prism(text_faces("A", 2.5, font_path("DejaVuSans-Bold")), frame.z_max + 0.05, 3.8, 15.0,
                         z_nominal=4.3)
    part = _around(floor, prism)
    assert len(explore(part, "Face")) < len(explore(floor, "Face")) + 5 and _valid(part)
    assert _volume(part) < 0.5 * _volume(floor)
    whole, near = (explore(raw_boolean("cut", prism, f), "Solid") for f in (floor, part))
    assert len(whole) == len(near) == 1 and _valid(near[0])
    assert _volume(near[0]) == pytest.approx(_volume(whole[0]), rel=1e-9)


@pytest.mark.parametrize("family", ["concave_round", "capsule"])
def test_debossed_digits_with_stroke_angle_build_checked(family):
    """'A8 69' debossed at 15° (LocOpe_DPrism crashed on 8, 6, 9): valid single-solid tablet, every
    Boolean cross-checked with manifold3d, the volume removed close to the letters' area x depth."""
    from tabletcad.cad._occ import explore
    from tabletcad.tooling.emboss import text_faces
    from tabletcad.tooling.outline import face_area, wire_length
    from tabletcad.tooling.toolset import make_tooling

    t = load_design(ROOT / "samples" / "families" / f"{family}.toml")
    d = 0.12
    e = EmbossSpec(text="A8 69", mode="deboss", height_mm=2.5, depth_mm=d, draft_deg=15.0)
    ts = make_tooling(t, ToolingSpec(emboss=(e,)), check=True, interference_check=False)
    tablet = ts.parts["tablet"]
    assert len(explore(tablet, "Solid")) == 1 and _valid(tablet)
    removed = ts.report["tablet"]["volume_plain_mm3"] - ts.report["tablet"]["volume_mm3"]
    area = sum(face_area(f) for f in explore(text_faces(e.text, e.height_mm, font_path(e.font)), "Face"))
    # walls narrowing into a floor at normal depth d on a cup tilted < 20° under the letters: the flat
    # face's A d - P t d² / 2 (next test) within 8 % (measured -4.5 % on the concave round, where the
    # letters reach up the cup, +0.06 % on the capsule)
    P = sum(wire_length(w) for f in explore(text_faces(e.text, e.height_mm, font_path(e.font)), "Face")
            for w in explore(f, "Wire"))
    flat = area * d - P * math.tan(math.radians(15.0)) * d * d / 2.0
    assert removed == pytest.approx(flat, rel=0.08)
    assert removed < area * d / math.cos(math.radians(20.0))


def test_debossed_text_on_a_flat_face_narrows_towards_the_floor():
    """On the flat-faced bevelled edge tablet, text debossed d deep at stroke angle a removes
    A d - P t d² / 2 (+ the corner term, within 0.15 P t d² / 2): letters narrower at the floor.
    LocOpe_DPrism's prisms removed more than A d (0.5127 vs A d = 0.4643 mm³ for 'AB' on the concave
    round, 15°): drafted the wrong way, an undercut."""
    from tabletcad.cad._occ import explore
    from tabletcad.tooling.emboss import text_faces
    from tabletcad.tooling.outline import face_area, wire_length
    from tabletcad.tooling.toolset import make_tooling

    t = load_design(ROOT / "samples" / "families" / "ffbe.toml")
    d, a = 0.12, 15.0
    e = EmbossSpec(text="AB", mode="deboss", height_mm=2.5, depth_mm=d, draft_deg=a)
    ts = make_tooling(t, ToolingSpec(emboss=(e,)), check=False, interference_check=False)
    faces = explore(text_faces(e.text, e.height_mm, font_path(e.font)), "Face")
    A = sum(face_area(f) for f in faces)
    P = sum(wire_length(w) for f in faces for w in explore(f, "Wire"))
    tn = math.tan(math.radians(a))
    removed = ts.report["tablet"]["volume_plain_mm3"] - ts.report["tablet"]["volume_mm3"]
    assert abs(removed - (A * d - P * tn * d * d / 2.0)) < 0.15 * P * tn * d * d / 2.0
    assert removed < A * d


def test_a_vanishing_offset_is_not_paired():
    """A wire too short to hold three points 0.008 mm apart (an offset of a stroke about to vanish) has
    no polygon to pair: None, and the draft is shortened instead (it stopped the build with numpy's
    "argmin of an empty sequence")."""
    from tabletcad.tooling.emboss import _paired
    from tabletcad.tooling.outline import polyline_wire

    square = lambda s: polyline_wire([(-s, -s), (s, -s), (s, s), (-s, s)])  # noqa: E731
    assert _paired(square(1.0), square(0.0005)) is None and _paired(square(0.0005), square(1.0)) is None
    a, b = _paired(square(1.0), square(0.9))
    assert a is not None and b is not None


def test_drafted_digits_on_a_scored_radius_edge_face():
    """Found by a random sweep of tooling designs: "10" debossed at 30 deg beside a 37 deg bisect on a
    flat-faced radius-edged round.  The finished tablet is one valid solid, every Boolean agreeing with
    manifold3d, the punches leave no gap beyond the clearance."""
    from tabletcad.cad._occ import explore
    from tabletcad.pipeline.design import Design
    from tabletcad.tooling.toolset import make_tooling

    d = Design.from_dict({"tablet": dict(family="ffre", diameter=10.96, thickness=3.55, edge_radius=0.934),
                          "tooling": {"clearance_mm": 0.02,
                                      "score": [dict(kind="bisect", profile="v", depth_mm=0.549, direction_deg=37.0)],
                                      "emboss": [dict(text="10", mode="deboss", face="top", height_mm=1.947,
                                                      depth_mm=0.1588, stroke_angle_deg=30.0)]}})
    ts = make_tooling(d.build(), d.tooling_spec, check=True, interference_check=True)
    tablet = ts.parts["tablet"]
    assert len(explore(tablet, "Solid")) == 1 and _valid(tablet)
    assert all(c["ok"] for c in ts.report["booleans"])
    assert ts.report["interference_mm3"] <= 1e-6 and ts.report["interference"]["gap_within_clearance"]


@pytest.mark.parametrize("glyph", ["6", "9"])
def test_paired_points_stay_on_the_normal_where_a_stroke_end_vanishes(glyph):
    """The outline of "6" or "9" (DejaVu Sans Bold, 2.5 mm) offset out by W t and in by N t, as the
    concave round's deboss prism of "A8 69" at 15° has them (W = 0.2377, N = 0.6040 mm): the inner
    offset has lost the tail's end, and the nearest points on it to the outer offset's points go
    back along it there.  Held in order there, the other pairs lie on the normal, the offsets'
    distance (N + W) t = 0.2255 mm apart (measured: 75 % within 1e-3 mm, the median 0.2256 mm).
    Spreading the steps back over the whole wire (before) twisted the walls: no pair on the normal,
    the median 0.966 mm apart, and "A8 69" removed 1.25 % too little."""
    import numpy as np
    from OCP.BRepTools import BRepTools

    from tabletcad.cad._occ import explore
    from tabletcad.tooling.emboss import _offset_section, _paired_points, text_faces

    t, n, w = math.tan(math.radians(15.0)), 0.6040, 0.2377
    outline = BRepTools.OuterWire_s(explore(text_faces(glyph, 2.5, font_path("DejaVuSans-Bold")), "Face")[0])
    pa, pb = _paired_points(_offset_section(outline, w * t), _offset_section(outline, -n * t))
    d = np.linalg.norm(pa - pb, axis=1)
    assert np.median(d) == pytest.approx((n + w) * t, abs=1e-3)
    assert np.mean(np.abs(d - (n + w) * t) < 1e-3) >= 0.7


def test_held_in_order_holds_the_steps_back_and_goes_once_round():
    """Positions on a wire of perimeter 10 mm that step back over a lost feature (6 -> 5 -> 4) are
    held where they stepped back (6 + eps, 6 + 2 eps) and the rest kept; positions that do not go
    once round (all at one point) have no order (None: the rescaled one is used)."""
    import numpy as np

    from tabletcad.tooling.emboss import _held_in_order

    sig = np.array([0.0, 2.0, 4.0, 6.0, 5.0, 4.0, 7.0, 9.0])
    near = np.array([0.2, 0.2, 0.2, 0.2, 0.9, 1.0, 0.2, 0.2])
    held = _held_in_order(sig, near, 10.0, 1e-3)
    assert held == pytest.approx([0.0, 2.0, 4.0, 6.0, 6.001, 6.002, 7.0, 9.0], abs=1e-12)
    assert _held_in_order(np.full(8, 3.0), near, 10.0, 1e-3) is None


def test_tool_check_catches_a_wrong_prism_cut():
    """The deboss cutter (drafted prism of "8" - letter floor) is cross-checked with manifold3d
    (:func:`tool_check`): the right cutter passes with the meshes' difference well inside the bound,
    a wrong one (the floor cut 0.05 mm lower: valid, 0.1-0.2 mm^3 off, as the merged walls of an
    earlier attempt came out) raises."""
    from tabletcad.errors import GeometryError
    from tabletcad.tooling.booleans import raw_boolean, translated
    from tabletcad.tooling.emboss import (_around, _offset_base, figure_prism, offset_solid, text_faces,
                                          tool_check)
    from tabletcad.tooling.outline import tablet_frame

    frame = tablet_frame(load_design(ROOT / "samples" / "families" / "concave_round.toml"))
    floor = offset_solid(_offset_base(frame), -0.12)
    prism = figure_prism(text_faces("8", 2.5, font_path("DejaVuSans-Bold")), frame.z_max + 0.05, 3.8, 15.0,
                         z_nominal=4.3)
    part = _around(floor, prism)
    tool = raw_boolean("cut", prism, part)
    ok = tool_check("cut", prism, part, tool, "8")
    assert ok["abs_diff_mm3"] < 0.25 * ok["bound_mm3"]
    wrong = raw_boolean("cut", prism, translated(part, dz=-0.05))
    assert abs(_volume(wrong) - _volume(tool)) > ok["bound_mm3"]
    with pytest.raises(GeometryError, match="disagree on the prism cut"):
        tool_check("cut", prism, part, wrong, "8")


def test_an_svg_circle_of_one_arc_and_a_sliver_drafts(tmp_path):
    """An SVG ring drawn as one arc closed by a 0.01-unit line (a common way to write a circle): OCC's
    inward offset of such a wire can come out open, which :func:`_offset_section` takes for "no offset"
    (before: ``plan_face`` raised "outline wire is not a planar closed wire" out of the drafted prism)."""
    from tabletcad.cad._occ import explore
    from tabletcad.tooling.emboss import check_emboss, figure_prism
    from tabletcad.tooling.outline import tablet_frame

    svg = tmp_path / "ring.svg"
    svg.write_text('<svg xmlns="http://www.w3.org/2000/svg" width="100" height="60" viewBox="0 0 100 60">'
                   '<path fill="black" fill-rule="evenodd" d="M30 5 A25 25 0 1 0 30.01 5 Z '
                   'M30 18 A12 12 0 1 1 29.99 18 Z"/>'
                   '<path fill="black" d="M70 15 L77 22 L95 22 L81 33 L86 52 L70 41 L60 52 Z"/></svg>')
    frame = tablet_frame(load_design(ROOT / "samples" / "families" / "concave_round.toml"))
    spec = EmbossSpec(svg=str(svg), height_mm=2.5, depth_mm=0.1, draft_deg=25.0)
    figure, _ = check_emboss(frame, spec, 0.02)
    prism = figure_prism(figure, 4.5, 3.7, 25.0, z_nominal=4.0)
    solids = explore(prism, "Solid")
    assert len(solids) == 2 and all(_valid(s) for s in solids)


def test_nearest_positions_near_are_the_brute_force_ones():
    """The k-d tree's candidate segments (:func:`_nearest_positions_near`, all points at once) give
    the brute force's positions and distances bit for bit, on the offsets of "6" where a stroke end
    vanishes (points whose nearest segment is far along the wire) and on points with exact ties."""
    import numpy as np
    from OCP.BRepTools import BRepTools

    from tabletcad.cad._occ import explore
    from tabletcad.tooling.emboss import (_nearest_positions, _nearest_positions_near, _offset_section,
                                          _wire_points, text_faces)

    t = math.tan(math.radians(15.0))
    outline = BRepTools.OuterWire_s(explore(text_faces("6", 2.5, font_path("DejaVuSans-Bold")), "Face")[0])
    wa, wb = _offset_section(outline, 0.2377 * t), _offset_section(outline, -0.6040 * t)
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    ties = np.array([[0.5, 0.5], [0.5, 0.0], [1.0, 1.0], [2.0, 0.5]])  # centre and a vertex: equidistant segments
    for pa, pb in ((_wire_points(wa, 0.04), _wire_points(wb, 0.01)), (ties, square)):
        near, brute = _nearest_positions_near(pa, pb), _nearest_positions(pa, pb)
        assert all(np.array_equal(x, y) for x, y in zip(near[:2], brute[:2])) and near[2] == brute[2]
