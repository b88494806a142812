"""Tooling for a custom outline through points (a periodic cubic spline): punches and a die.

``build`` and ``report`` had refused every such design ("tooling needs an outline OpenCascade can
offset"): OCC's planar offset failed on the band section's periodic B-spline edge.  The tips and the bore
are now B-splines built from the outline's exact offset ``O + d N``
(:func:`tabletcad.tooling.outline.spline_offset_wire`), within 1e-6 mm of it; an offset beyond the
outline's regular ones is refused in one line (tests/test_report_refusals.py, and the core's bounds in
tests/test_families_spline_outline.py).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("OCP")
pytest.importorskip("build123d")
pytest.importorskip("manifold3d")
pytest.importorskip("ezdxf")

from tabletcad.cad.solid import check_solid  # noqa: E402
from tabletcad.families.shaped import outline_tablet  # noqa: E402
from tabletcad.tooling import ToolingSpec, make_tooling  # noqa: E402
from tabletcad.tooling.outline import SPLINE_OFFSET_TOL_MM  # noqa: E402

pytestmark = pytest.mark.cad

CLEARANCE = 0.02

#: a rounded square through 24 points (corners' least radius of curvature 0.276 mm; its spline has
#: shallow concave stretches along the sides, least concave radius 5.6 mm)
SQUARE = [[4.0, -1.8], [4.0, 0.0], [4.0, 1.8], [3.9864, 3.7035], [3.8828, 3.8828], [3.7035, 3.9864], [1.8, 4.0],
          [0.0, 4.0], [-1.8, 4.0], [-3.7035, 3.9864], [-3.8828, 3.8828], [-3.9864, 3.7035], [-4.0, 1.8], [-4.0, 0.0],
          [-4.0, -1.8], [-3.9864, -3.7035], [-3.8828, -3.8828], [-3.7035, -3.9864], [-1.8, -4.0], [0.0, -4.0],
          [1.8, -4.0], [3.7035, -3.9864], [3.8828, -3.8828], [3.9864, -3.7035]]


@pytest.fixture(scope="module")
def square():
    """Plain tooling of the rounded square (every Boolean cross-checked with manifold3d, the closed position
    checked)."""
    t = outline_tablet(SQUARE, band=2.5, cup_depth=0.2)
    with pytest.warns(UserWarning, match="the punch tips have no land"):
        return make_tooling(t, ToolingSpec(clearance_mm=CLEARANCE, tip_length_mm=8.0))


def _edge_points(wire, v: np.ndarray) -> np.ndarray:
    """Plan points of the wire's one edge at its curve's parameters ``v``."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve

    from tabletcad.cad._occ import cast, explore

    edges = explore(wire, "Edge")
    assert len(edges) == 1
    c = BRepAdaptor_Curve(cast(edges[0], "Edge"))
    assert (c.FirstParameter(), c.LastParameter()) == (0.0, math.tau)
    return np.array([[c.Value(float(x)).X(), c.Value(float(x)).Y()] for x in v])


def test_parts_are_single_valid_solids(square):
    assert set(square.parts) == {"tablet", "upper_punch", "lower_punch", "die"}
    for name, shape in square.parts.items():
        check_solid(shape, name)
    assert square.report["upper_punch"]["tip_outline"] == "spline" and square.report["die"]["bore"] == "spline"


@pytest.mark.parametrize("distance", [0.0, -CLEARANCE, 1e-6, -0.2, 0.5])
def test_offsets_are_the_exact_offsets_within_the_tolerance(square, distance):
    """The outline's wire (distance 0: the spline itself, to round-off) and its offsets, sampled by OCC at
    20,001 parameters, against the core's exact offset at the same parameters (an upper bound of the
    distance between the curves); the deviation reported is within the tolerance too."""
    frame = square.frame
    outline = square.tablet.nominal.outline
    wire = frame.offset(distance) if distance else frame.outline
    v = np.linspace(0.0, math.tau, 20_001)
    gap = np.linalg.norm(_edge_points(wire, v) - outline.offset(v, 0, 1.0, -distance), axis=1)
    assert float(gap.max()) <= (1e-12 if distance == 0.0 else SPLINE_OFFSET_TOL_MM)
    if distance:
        assert 0.0 < frame.offset_deviation(distance) <= SPLINE_OFFSET_TOL_MM


def test_the_tips_are_the_outline_inset_by_the_clearance(square):
    """The tips' plan is the exact offset: its area is Steiner's A - P d + pi d^2 (a regular inward offset of a
    closed curve turning once), to the B-spline's deviation; the deviation is reported."""
    outline = square.tablet.nominal.outline
    r = square.report
    for which in ("upper_punch", "lower_punch"):
        tip = r[which]
        d = tip["tip_inset_from_outline_mm"]
        assert d == pytest.approx(CLEARANCE - r["die"]["bore_enlarged_by_band_bulge_mm"], abs=1e-15)
        steiner = outline.area - outline.perimeter * d + math.pi * d * d
        assert tip["tip_plan_area_mm2"] == pytest.approx(steiner, abs=outline.perimeter * SPLINE_OFFSET_TOL_MM)
        assert 0.0 < tip["tip_outline_deviation_mm"] <= tip["tip_outline_tolerance_mm"] == SPLINE_OFFSET_TOL_MM
    assert 0.0 < r["die"]["bore_deviation_mm"] <= SPLINE_OFFSET_TOL_MM


def test_die_bore_to_punch_tip_is_the_clearance(square):
    """OCC's distance between the bore's and the tips' outlines, and the report's punch-to-die clearance
    measured on the solids, are the clearance asked for."""
    from OCP.BRepExtrema import BRepExtrema_DistShapeShape

    from tabletcad.tooling.die import bore_wire

    frame = square.frame
    dss = BRepExtrema_DistShapeShape(bore_wire(frame), frame.offset(-frame.tip_inset(CLEARANCE)))
    assert dss.IsDone()
    assert dss.Value() == pytest.approx(CLEARANCE, abs=2 * SPLINE_OFFSET_TOL_MM)
    f = square.report["interference"]
    assert f["punch_die_clearance_mm"] == pytest.approx(CLEARANCE, abs=f["punch_die_clearance_tolerance_mm"] + 1e-7)
    assert f["gap_within_clearance"] is True


def test_closed_position_encloses_exactly_the_tablet(square):
    r = square.report
    assert r["interference_mm3"] == pytest.approx(0.0, abs=1e-9)
    for p in r["interference"]["pairs"]:
        assert p["occ_mm3"] == pytest.approx(0.0, abs=1e-9)
        assert p["manifold3d_mm3"] <= p["manifold3d_bound_mm3"]
    assert 0.0 < r["max_gap_mm"] <= CLEARANCE


def test_volumes(square):
    """The die is its blank less the bore's prism (Steiner's area of the outline grown by the bore's offset
    times the height); each punch tip is its prism less the tablet inside it, OCC's volume agreeing with
    manifold3d's (every Boolean cross-checked) and with the tip's prism and the tablet's exact volume."""
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Common

    from tabletcad.tooling.booleans import volume
    from tabletcad.tooling.outline import prism

    outline, r, frame = square.tablet.nominal.outline, square.report, square.frame
    die = r["die"]
    e = die["bore_enlarged_by_band_bulge_mm"]
    bore = outline.area + outline.perimeter * e + math.pi * e * e
    blank = math.pi * (0.5 * die["outer_diameter_mm"]) ** 2
    # (to the bore's deviation from the exact offset over its perimeter and height)
    assert die["volume_mm3"] == pytest.approx((blank - bore) * die["height_mm"],
                                              abs=outline.perimeter * SPLINE_OFFSET_TOL_MM * die["height_mm"])
    assert r["boolean_max_rel_diff_occ_vs_manifold3d"] < 2e-3
    tip = frame.offset(-frame.tip_inset(CLEARANCE))
    z_mid = 0.5 * sum(frame.band_z)
    up = r["upper_punch"]
    body = prism(tip, z_mid, up["working_length_datum"]["datum_plane_z_mm"])
    inside = volume(BRepAlgoAPI_Common(body, square.parts["tablet"]).Shape())
    assert up["volume_mm3"] == pytest.approx(volume(body) - inside, rel=1e-9)
    assert volume(body) == pytest.approx(up["tip_plan_area_mm2"] * (up["working_length_datum"]["datum_plane_z_mm"]
                                                                     - z_mid), rel=1e-9)
    assert volume(square.parts["tablet"]) == pytest.approx(square.tablet.properties()["volume_mm3"], rel=1e-7)


def test_the_tooling_is_written(square, tmp_path):
    """The files ``tabletcad build`` writes of such tooling (the stage's writer on the fixture's tool set: the
    command's own path, check and all, is the one ``report`` and ``build`` take alike in
    tests/test_report_refusals.py): the parts, assembly and drawings, the deviations within the tolerance."""
    from tabletcad.tooling.stage import write_tooling

    written = {p.name for p in write_tooling(square, tmp_path)}
    for name in ("assembly.step", "upper_punch.step", "lower_punch.step", "die.step", "tooling.dxf"):
        assert name in written and (tmp_path / name).stat().st_size > 0, name
    r = square.report
    assert r["upper_punch"]["tip_outline"] == "spline"
    assert r["upper_punch"]["tip_outline_deviation_mm"] <= SPLINE_OFFSET_TOL_MM
    assert r["interference_mm3"] == pytest.approx(0.0, abs=1e-9)


def test_the_tip_rating_s_section_is_the_exact_offset_s(square):
    """The tips' projected area and least second moment (the pressure rating's and the buckling check's figures)
    are those of the outline's exact offset by the tips' inset (a 200,000-gon of it, by the shoelace sums):
    OCC's fixed integration rule had given them 0.21 % and 2.4 % off on the spline's offsets."""
    from tabletcad.tooling.rating import section_properties

    frame, outline = square.frame, square.tablet.nominal.outline
    inset = frame.tip_inset(CLEARANCE)
    v = np.linspace(0.0, 2 * math.pi, 200_000, endpoint=False)
    x, y = outline.offset(v, 0, 1.0, inset).T
    x1, y1 = np.roll(x, -1), np.roll(y, -1)
    c = x * y1 - x1 * y
    a = 0.5 * c.sum()
    cx, cy = ((x + x1) * c).sum() / (6 * a), ((y + y1) * c).sum() / (6 * a)
    ixx = ((y * y + y * y1 + y1 * y1) * c).sum() / 12 - a * cy * cy
    iyy = ((x * x + x * x1 + x1 * x1) * c).sum() / 12 - a * cx * cx
    ixy = ((x * y1 + 2 * x * y + 2 * x1 * y1 + x1 * y) * c).sum() / 24 - a * cx * cy
    i_min = 0.5 * (ixx + iyy) - math.sqrt(0.25 * (ixx - iyy) ** 2 + ixy * ixy)
    area, i_occ = section_properties(frame.offset(-inset))
    assert area == pytest.approx(a, rel=1e-7) and i_occ == pytest.approx(i_min, rel=1e-7)
    assert square.report["tip_rating"]["tip_projected_area_mm2"] == pytest.approx(a, rel=1e-7)


def test_a_tapered_bore_is_the_exact_offset_at_every_height(square):
    """LocOpe_DPrism's draft of the spline bore failed BRepCheck_Analyzer (``build`` exit 1 with taper_deg);
    the ruled solid between the bore and its exact offset at the top is valid, and the die's volume is the
    blank less the straight bore and the drafted one: the integral of Steiner's area of the outline grown by
    ``e(z) = bulge + z tan(taper)``."""
    from tabletcad.tooling.die import die

    frame, outline = square.frame, square.tablet.nominal.outline
    shape, info = die(frame, None, None, taper_deg=1.0)
    check_solid(shape, "die")
    t, h = math.tan(math.radians(1.0)), info["top_z_mm"] - info["taper_start_z_mm"]
    e = info["bore_enlarged_by_band_bulge_mm"]
    A, P = outline.area, outline.perimeter
    straight = (A + P * e + math.pi * e * e) * (info["taper_start_z_mm"] - info["bottom_z_mm"])
    drafted = A * h + P * (e * h + t * h * h / 2) + math.pi * (e * e * h + e * t * h * h + t * t * h ** 3 / 3)
    blank = math.pi * (0.5 * info["outer_diameter_mm"]) ** 2 * info["height_mm"]
    assert info["bore_growth_at_top_mm"] == pytest.approx(info["punch_entry_mm"] * t, rel=1e-12)
    assert info["volume_mm3"] == pytest.approx(blank - straight - drafted,
                                               abs=P * SPLINE_OFFSET_TOL_MM * info["height_mm"])


def _dxf_splines(entities: list) -> list:
    """The SPLINE entities of ``entities`` (:func:`tabletcad.tooling.drawing._exact_entities`' data) as a DXF
    written and read back by ezdxf."""
    import io

    import ezdxf

    from tabletcad.tooling.drawing import _add_spline

    doc = ezdxf.new("R2010")
    for kind, at in entities:
        assert kind == "SPLINE"
        _add_spline(doc.modelspace(), at, {"layer": "OUTLINE"})
    stream = io.StringIO()
    doc.write(stream)
    return list(ezdxf.read(io.StringIO(stream.getvalue())).modelspace().query('SPLINE[layer=="OUTLINE"]'))


def _de_boor(knots: np.ndarray, cp: np.ndarray, p: int, v: np.ndarray) -> np.ndarray:
    """The standard (non-rational) B-spline of degree ``p``, ``knots`` and control points ``cp`` at ``v`` (de
    Boor's algorithm; ``v`` within ``[knots[p], knots[len(cp)]]``)."""
    end = knots[len(cp)]  # (the domain's end: in the last span of nonzero length before it)
    k = np.where(v < end, np.searchsorted(knots, v, side="right"), np.searchsorted(knots, end, side="left")) - 1
    d = np.stack([cp[k - p + j] for j in range(p + 1)], axis=1)  # (len(v), p + 1, 2)
    for r in range(1, p + 1):
        for j in range(p, r - 1, -1):
            lo, hi = knots[j + k - p], knots[j + 1 + k - r]
            a = ((v - lo) / (hi - lo))[:, None]
            d[:, j] = (1.0 - a) * d[:, j - 1] + a * d[:, j]
    return d[:, p]


def _spline_points(spline, v: np.ndarray) -> np.ndarray:
    """The plan points of the DXF ``spline`` at its knots' parameters ``v``: de Boor's on its data as read,
    which ezdxf's own B-spline of it (its knots scaled to run from 0 to 1 and rounded to its
    ``knot_tolerance``, 1e-10) agrees with within 1e-8 mm."""
    kn, cp = np.asarray(spline.knots), np.asarray(spline.control_points)[:, :2]
    pts = _de_boor(kn, cp, spline.dxf.degree, v)
    u = (v - kn[0]) / (kn[-1] - kn[0])
    ez = np.asarray(list(spline.construction_tool().points(u)))[:, :2]
    assert float(np.abs(ez - pts).max()) <= 1e-8
    return pts


def _check_closed_spline(spline, exact, origin=(0.0, 0.0), tol=1e-12) -> None:
    """A closed periodic cubic SPLINE as AutoCAD and ezdxf write one (flags CLOSED | PERIODIC, knots = control
    points + degree + 1, control points wrapped by the degree), whose B-spline over its domain
    ``[knots[3], knots[-4]] = [0, 2 pi]`` is ``exact(v)`` (the core's points, moved by ``origin``) within ``tol``
    mm at 20,001 parameters."""
    from ezdxf.entities import Spline

    assert spline.dxf.degree == 3 and spline.closed
    assert spline.dxf.flags & Spline.PERIODIC and not spline.dxf.flags & Spline.RATIONAL
    cp, kn = np.asarray(spline.control_points)[:, :2], np.asarray(spline.knots)
    assert len(kn) == len(cp) + 3 + 1 and spline.fit_point_count() == 0
    assert np.array_equal(cp[:3], cp[-3:])  # wrapped: the curve closes C1 (the spline's own continuity)
    assert (kn[3], kn[-4]) == pytest.approx((0.0, math.tau), abs=1e-15)
    v = np.linspace(0.0, math.tau, 20_001)
    gap = np.linalg.norm(_spline_points(spline, v) - (exact(v) + np.asarray(origin)), axis=1)
    assert float(gap.max()) <= tol


def test_the_drawing_dxf_holds_the_outline_as_a_spline(square, tmp_path):
    """The tablet sheet's DXF has the nominal outline on its OUTLINE layer as one exact SPLINE (it had nothing
    there for a spline outline): read back by ezdxf, its B-spline is the core's outline at the same parameter
    to round-off, placed at the plan's origin; the sheet's note says so."""
    import ezdxf

    from tabletcad.tooling.drawing import _write_dxf, drawing_model

    dr = drawing_model(square)
    _write_dxf(dr, tmp_path / "drawing.dxf")
    msp = ezdxf.readfile(tmp_path / "drawing.dxf").modelspace()
    assert len(msp.query('*[layer=="OUTLINE"]')) == 1
    (spline,) = msp.query('SPLINE[layer=="OUTLINE"]')
    outline = square.tablet.nominal.outline
    _check_closed_spline(spline, lambda v: outline.offset(v, 0, 1.0, 0.0), dr.origins["plan"], tol=1e-12)
    assert any("layer OUTLINE" in n and "SPLINE" in n for n in dr.notes)


@pytest.mark.parametrize("distance", [-CLEARANCE, 0.5])
def test_an_offset_outline_becomes_its_exact_spline(square, distance):
    """A tip's and a bore's B-spline as SPLINE entities: the exact offset within the offset's tolerance."""
    from tabletcad.tooling.drawing import _exact_entities

    outline = square.tablet.nominal.outline
    (spline,) = _dxf_splines(_exact_entities(square.frame.offset(distance), (1.5, -2.0)))
    _check_closed_spline(spline, lambda v: outline.offset(v, 0, 1.0, -distance), (1.5, -2.0),
                         tol=SPLINE_OFFSET_TOL_MM)


def test_part_of_a_periodic_bspline_becomes_a_clamped_spline(square):
    """An edge on part of a periodic B-spline is written open and clamped (OCC's own non-periodic form of the
    part): knots = control points + degree + 1, its ends its end points, its points OCC's."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeWire

    from tabletcad.cad._occ import explore
    from tabletcad.tooling.drawing import _exact_entities

    curve = BRepAdaptor_Curve(explore(square.frame.outline, "Edge")[0]).BSpline()
    a, b = 5.9, 7.1  # across the period's end
    wire = BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(curve, a, b).Edge()).Wire()
    (spline,) = _dxf_splines(_exact_entities(wire, (0.0, 0.0)))
    assert spline.dxf.degree == 3 and not spline.closed and spline.dxf.flags == 0
    kn = np.asarray(spline.knots)
    assert len(kn) == spline.control_point_count() + 4
    assert (kn[0], kn[-1]) == pytest.approx((a, b), abs=1e-12)
    v = np.linspace(a, b, 2001)
    pts = _spline_points(spline, v)
    occ = np.array([[curve.Value(float(x)).X(), curve.Value(float(x)).Y()] for x in v])
    assert float(np.abs(pts - occ).max()) <= 1e-12


@pytest.mark.parametrize("degree, mults", [(3, [1] * 9), (2, [1, 2, 1, 1, 2, 1]), (4, [1] * 8), (3, [3, 1, 2, 1, 1])])
def test_a_periodic_bspline_is_written_as_the_same_closed_spline(degree, mults):
    """Any periodic B-spline (degree, knots' multiplicities, random knots and poles) as a closed SPLINE: its
    data's de Boor is OCC's curve to round-off over the whole period (OCC's first pole is the coefficient
    of the basis function that starts ``degree`` flat knots before the last copy of its first knot)."""
    from OCP.Geom import Geom_BSplineCurve
    from OCP.gp import gp_Pnt
    from OCP.TColgp import TColgp_Array1OfPnt
    from OCP.TColStd import TColStd_Array1OfInteger, TColStd_Array1OfReal

    from tabletcad.tooling.drawing import _spline_entity

    rng = np.random.default_rng(sum(mults) * degree)
    m, n = len(mults) + 1, sum(mults)
    knots = np.cumsum(np.r_[0.0, rng.uniform(0.5, 1.5, m - 1)])
    kn, mu = TColStd_Array1OfReal(1, m), TColStd_Array1OfInteger(1, m)
    for i in range(m):
        kn.SetValue(i + 1, float(knots[i]))
        mu.SetValue(i + 1, mults[i % len(mults)])
    poles = TColgp_Array1OfPnt(1, n)
    for i, (x, y) in enumerate(rng.normal(size=(n, 2)), start=1):
        poles.SetValue(i, gp_Pnt(float(x), float(y), 0.0))
    curve = Geom_BSplineCurve(poles, kn, mu, degree, True)
    at = _spline_entity(curve, curve.FirstParameter(), curve.LastParameter(), (0.0, 0.0))
    assert at["closed"] and len(at["knots"]) == len(at["control_points"]) + degree + 1 == n + 2 * degree + 1
    v = np.linspace(curve.FirstParameter(), curve.LastParameter(), 1001)
    ours = _de_boor(np.asarray(at["knots"]), np.asarray(at["control_points"]), degree, v)
    occ = np.array([[curve.Value(float(x)).X(), curve.Value(float(x)).Y()] for x in v])
    assert float(np.abs(ours - occ).max()) <= 1e-14
