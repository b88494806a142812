"""Die tapers for every family, and the largest gap between the finished tablet and its tools.

* The tapered bore is drafted exactly (``LocOpe_DPrism``): its volume is Steiner's
  ``A h + P h² tan/2 + π h³ tan²/3`` for a convex outline.
* Every family sample gets punches and a die tapered 1° with no overlap and no gap above the
  clearance (issue 13 item 10: the almond was refused with an 8.9e-6 mm³ "overlap", slivers of an
  exact Boolean between the band and a bore 1e-6 mm away): in
  ``tests/test_tooling_parts.py::test_every_family_sample_gets_valid_tooling``, one build each.
* The reported largest gap is checked against its closed form: on a flat land wider than the
  clearance the gap peaks at clearance / 2 (a land point ``s`` in from the outline is ``s`` from
  the die bore and ``clearance - s`` from the punch tip's edge).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("OCP")
pytest.importorskip("manifold3d")
pytest.importorskip("trimesh")

from support.family_tablets import family_tablet  # noqa: E402
from tabletcad.cli.report import load_family_design  # noqa: E402
from tabletcad.tooling import ToolingSpec, make_tooling  # noqa: E402

pytestmark = pytest.mark.cad

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("deg", [1.0, 5.0])
def test_tapered_bore_volume_is_steiner(deg):
    from tabletcad.cad.solid import check_solid
    from tabletcad.tooling.booleans import volume
    from tabletcad.tooling.die import tapered_prism
    from tabletcad.tooling.outline import face_area, plan_face, tablet_frame, wire_length

    t, _ = load_family_design(ROOT / "samples" / "families" / "almond.toml")
    frame = tablet_frame(t, None)
    A, P = face_area(plan_face(frame.outline)), wire_length(frame.outline)
    h, tn = 3.0, math.tan(math.radians(deg))
    shape = tapered_prism(frame.outline, 1.0, 1.0 + h, deg)
    check_solid(shape, "tapered bore")
    assert volume(shape) == pytest.approx(A * h + P * h * h * tn / 2 + math.pi * h**3 * tn**2 / 3, rel=1e-12)


def test_largest_gap_on_a_flat_land_is_half_the_clearance():
    """Rounded triangle (0.1 mm land) at 0.035 mm clearance: a land point ``s`` in from the outline
    is ``s`` from the die bore and ``0.035 - s`` from the punch tip's edge, so the largest gap is
    0.0175 mm (the earlier measure, at mesh vertices only, reported 4.7e-11 mm)."""
    t, shape = family_tablet(ROOT / "samples" / "families" / "rounded_triangle.toml")
    r = make_tooling(t, ToolingSpec(clearance_mm=0.035), shape=shape, check=False).report
    assert r["tablet"]["land_mm"] > 0.035
    assert r["max_gap_mm"] == pytest.approx(0.0175, abs=2e-3)
    assert r["max_gap_mm"] <= 0.0175 + 1e-9  # exact distances of surface points cannot exceed the peak
    assert r["interference"]["gap_within_clearance"]


def _cloud(V: np.ndarray, T: np.ndarray, per_mm2: float, rng: np.random.Generator) -> np.ndarray:
    """Random points (n, 3) on the triangles ``T`` (m, 3) of vertices ``V`` (k, 3), mm: on each
    triangle, uniformly, ``ceil(area * per_mm2)`` of them (its area in mm², ``per_mm2`` points per
    mm²), so that no triangle gets fewer than its share (an area-weighted draw of the same total
    leaves some bare)."""
    a, b, c = V[T[:, 0]], V[T[:, 1]], V[T[:, 2]]
    ab, ac = b - a, c - a
    n = np.ceil(0.5 * np.linalg.norm(np.cross(ab, ac), axis=1) * per_mm2).astype(np.intp)
    u, v = rng.random((2, int(n.sum())))
    folded = u + v > 1.0  # the parallelogram's far half folded back onto the triangle
    u[folded], v[folded] = 1.0 - u[folded], 1.0 - v[folded]
    # a + u ab + v ac, summed in that order, in place on the repeated corners (millions of points)
    out = np.repeat(ab, n, axis=0)
    out *= u[:, None]
    out += np.repeat(a, n, axis=0)
    step = np.repeat(ac, n, axis=0)
    step *= v[:, None]
    out += step
    return out


def _near_triangles(V: np.ndarray, T: np.ndarray, points: np.ndarray,
                    reach: float) -> tuple[np.ndarray, np.ndarray]:
    """``(V, T)`` of the triangles of ``(V, T)`` (mm; split first to edges of 0.5 mm at most: a die's
    long bore triangles) that may come within ``reach`` (mm) of one of ``points`` (n, 3): a triangle
    lies within its centre-to-corner radius of its centre."""
    import trimesh.remesh
    from scipy.spatial import cKDTree

    lo, hi = points.min(axis=0) - reach, points.max(axis=0) + reach
    tri = V[T]
    box = np.all(tri.max(axis=1) >= lo, axis=1) & np.all(tri.min(axis=1) <= hi, axis=1)
    V, T = trimesh.remesh.subdivide_to_size(V, T[box], 0.5)
    tri = V[T]
    c = tri.mean(axis=1)
    r = np.linalg.norm(tri - c[:, None, :], axis=2).max(axis=1)
    near = cKDTree(points).query(c, distance_upper_bound=reach + r.max())[0] <= reach + r
    return V, T[near]


def _largest_least_distance(points, measures) -> float:
    """``max`` over ``points`` of ``min`` over ``measures`` (exact distance functions, mm) of the point's
    distance: a point's remaining measures are skipped once one of them is no more than the largest
    found so far (its least distance cannot raise the maximum), so the result is the full double loop's."""
    largest = -math.inf
    for q in points:
        least = math.inf
        for measure in measures:
            least = min(least, measure(q))
            if least <= largest:
                break
        largest = max(largest, least)
    return float(largest)


@pytest.mark.slow
def test_largest_gap_agrees_with_an_independent_dense_sampling():
    """Rounded triangle with raised "A1" on the top cup, 0.035 mm clearance (issue 13 item 10: the
    letters' side walls were missed).  Independently of the report's method: 400,000 random points
    on a 1e-3 mm tessellation of the finished tablet; a random cloud on each tool's tessellation
    (at least one point per 25 µm² of each of its triangles, on its triangles within reach of the
    points still open) gives an upper bound of every point's distance (plus twice the chord height:
    the cloud and the points lie within it of the B-reps); a point whose bound stays below 80 % of
    the reported gap is closed, and every point left open after the three tools is moved onto the
    tablet's B-rep and measured exactly (BRepExtrema's point-to-face and point-to-edge extrema,
    :class:`~tabletcad.tooling.interference.ExactDistance`).  No sampled point (letter walls
    included) lies farther from the tools than the reported gap plus its stated resolution, and the
    sampling finds the land's closed-form peak.  (The random points are about 20 µm apart, coarser
    than the report's refined 4.4 µm: the check is independent, not finer.)"""
    import trimesh
    from scipy.spatial import cKDTree

    from tabletcad.cad._occ import explore
    from tabletcad.tooling.booleans import mesh_arrays
    from tabletcad.tooling.interference import ExactDistance
    from tabletcad.tooling.spec import EmbossSpec

    t, shape = family_tablet(ROOT / "samples" / "families" / "rounded_triangle.toml")
    spec = ToolingSpec(clearance_mm=0.035, emboss=(EmbossSpec(text="A1", mode="emboss", face="top", height_mm=2.5,
                                                              depth_mm=0.12),))
    ts = make_tooling(t, spec, shape=shape, check=False)
    gap, res = ts.report["max_gap_mm"], ts.report["interference"]["max_gap_resolution_mm"]
    tools = {k: s for k, s in ts.parts.items() if k != "tablet"}

    chord = 1e-3
    V, T = mesh_arrays(ts.parts["tablet"], chord, 0.05)
    P, _ = trimesh.sample.sample_surface(trimesh.Trimesh(V, T, process=False), 400_000, seed=1)
    # a bound below 0.8 gap - 2 chord closes a point: cloud points farther than 0.8 gap decide nothing
    reach = 0.8 * gap
    is_open = np.ones(len(P), dtype=bool)
    rng = np.random.default_rng(2)
    for s in tools.values():
        Vs, Ts = _near_triangles(*mesh_arrays(s, chord, 0.05), P[is_open], reach)
        tree = cKDTree(_cloud(Vs, Ts, 1.0 / 2.5e-5, rng), balanced_tree=False, compact_nodes=False)
        bound = tree.query(P[is_open], distance_upper_bound=reach)[0]  # inf beyond the reach
        is_open[np.flatnonzero(is_open)[bound + 2.0 * chord < 0.8 * gap]] = False
    candidates = np.flatnonzero(is_open)
    assert 0 < len(candidates) < 5000
    onto = ExactDistance(explore(ts.parts["tablet"], "Shell")[0])
    # the die first: its measure is the cheapest (0.1 ms against the punches' 0.5 ms) and often the least
    exact_to = [ExactDistance(tools[k]) for k in sorted(tools, key=lambda k: k != "die")]
    # each candidate moved onto the tablet once (the generator had moved it again for every tool)
    sampled = _largest_least_distance((onto.nearest(P[i])[1] for i in candidates), exact_to)
    assert res == pytest.approx(0.125 * 0.035 / math.sqrt(3.0))
    assert sampled <= gap + res  # points of the tablet's B-rep, measured exactly
    assert gap <= 0.0175 + 1e-9  # a real distance of a surface point: not above the land's peak
    assert sampled == pytest.approx(0.0175, abs=1e-4)  # the land's peak, clearance / 2, found by the sampling


def _round_die(bore_radius: float, taper_deg: float):
    """A die on the z axis with a round bore of ``bore_radius`` (mm) from z = -5 to 3 and tapered by
    ``taper_deg`` above, to its top at z = 6 (as :func:`tabletcad.tooling.die.die` builds one)."""
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeCylinder
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt

    from tabletcad.tooling.booleans import boolean
    from tabletcad.tooling.die import tapered_prism
    from tabletcad.tooling.outline import circle_wire, prism

    blank = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, -5), gp_Dir(0, 0, 1)), 12.0, 11.0).Shape()
    bore = circle_wire(bore_radius)
    shape = boolean("cut", blank, prism(bore, -6.0, 3.0))
    return boolean("cut", shape, tapered_prism(bore, 3.0, 7.0, taper_deg))


def _round_tablet(radius: float, dx: float = 0.0):
    """A flat round "tablet" of ``radius`` (mm), z from 0 to 3 (its top edge where the taper starts), moved by ``dx``."""
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeCylinder
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt

    return BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(dx, 0, 0), gp_Dir(0, 0, 1)), radius, 3.0).Shape()


def _bumped_tablet():
    """The round tablet of radius 5 mm with a 0.4 x 0.4 x 1 mm bump standing 0.1 mm out of its band at
    ``x = 5``: its overlap with the die lies at the tablet's extreme, at the edge of its bounding box."""
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
    from OCP.gp import gp_Pnt

    from tabletcad.tooling.booleans import boolean

    bump = BRepPrimAPI_MakeBox(gp_Pnt(4.9, -0.2, 1.0), gp_Pnt(5.1, 0.2, 2.0)).Shape()
    return boolean("fuse", _round_tablet(5.0), bump)


def test_the_bore_proof_holds_only_where_the_tablet_stays_in_the_bore():
    """:func:`~tabletcad.tooling.interference.inside_bore` proves a zero overlap only when both of its
    Commons are empty: a tablet touching the bore wall up to the taper passes; moved 0.05 mm into the
    wall it fails; and a bore wire wider than the die's real bore (so that the tablet's Common with the
    column's outside is empty though the tablet cuts 0.05 mm into the die) fails on the die's Common
    with the column; a bump standing 0.1 mm out of the band fails.  Where it fails, the overlap check
    falls back on the tablet's Common with the die and reports the overlap."""
    from tabletcad.tooling.interference import BORE_PROOF, _overlaps, inside_bore
    from tabletcad.tooling.outline import circle_wire

    die = _round_die(5.0, 1.0)
    assert inside_bore(_round_tablet(5.0), die, circle_wire(5.0))
    assert not inside_bore(_round_tablet(5.0, dx=0.05), die, circle_wire(5.0))
    assert not inside_bore(_round_tablet(5.05), die, circle_wire(5.1))
    assert not inside_bore(_bumped_tablet(), die, circle_wire(5.0))
    (touching,) = _overlaps(_round_tablet(5.0), {"die": die}, 0.005, circle_wire(5.0))
    assert touching["occ_mm3"] == 0.0 and touching["occ_method"] == BORE_PROOF
    for tablet, bore, least in ((_round_tablet(5.0, dx=0.05), circle_wire(5.0), 0.1),
                                (_round_tablet(5.05), circle_wire(5.1), 0.1), (_bumped_tablet(), circle_wire(5.0), 0.01)):
        (pair,) = _overlaps(tablet, {"die": die}, 0.005, bore)
        (plain,) = _overlaps(tablet, {"die": die}, 0.005)  # without the bore: the Common with the die alone
        assert pair["occ_method"] != BORE_PROOF
        assert pair["occ_mm3"] == plain["occ_mm3"] > least  # the crescent, the ring or the bump in the die wall


def test_a_failing_column_boolean_proves_nothing(monkeypatch):
    """A Boolean of :func:`~tabletcad.tooling.interference.inside_bore` that fails (``GeometryError``)
    is no proof and no error: the overlap check falls back on the tablet's Common with the die."""
    import tabletcad.tooling.interference as I
    from tabletcad.errors import GeometryError
    from tabletcad.tooling.outline import circle_wire

    die, tablet = _round_die(5.0, 1.0), _round_tablet(5.0)
    plain = I.raw_boolean

    def failing_cut(op, a, b, **kw):
        if op == "cut":
            raise GeometryError("a test's failing Boolean", (a, b))
        return plain(op, a, b, **kw)

    monkeypatch.setattr(I, "raw_boolean", failing_cut)
    assert not I.inside_bore(tablet, die, circle_wire(5.0))
    (pair,) = I._overlaps(tablet, {"die": die}, 0.005, circle_wire(5.0))
    assert pair["occ_method"] != I.BORE_PROOF and pair["occ_mm3"] == 0.0


def test_the_distance_skips_only_a_test_that_cannot_find_an_overlap():
    """:func:`~tabletcad.tooling.interference._distance_shapes` loads the first solid as its shell when a
    vertex of the second lies outside its box (that one is then not inside it): the same float as the
    distance of the two solids, apart or overlapping; and a second solid inside the first, or a first one
    inside the second, is still found (distance 0)."""
    from OCP.BRepExtrema import BRepExtrema_DistShapeShape
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox, BRepPrimAPI_MakeCylinder
    from OCP.gp import gp_Pnt

    from tabletcad.tooling.interference import _distance_shapes

    def box(lo, hi):
        return BRepPrimAPI_MakeBox(gp_Pnt(*lo), gp_Pnt(*hi)).Shape()

    def solids_distance(a, b):
        return BRepExtrema_DistShapeShape(a, b).Value()

    big, small = box((0, 0, 0), (10, 10, 10)), box((4, 4, 4), (6, 6, 6))
    rod = BRepPrimAPI_MakeCylinder(1.0, 20.0).Shape()  # through the big box's corner
    cases = [(big, box((10.5, 1, 1), (12, 3, 3))), (big, rod), (rod, big),
             (small, box((6.25, 4, 4), (7, 6, 7.5))), (rod, small)]
    for a, b in cases:  # apart or meeting: the solids' distance to the last bit
        assert _distance_shapes(a, b).Value() == solids_distance(a, b)
    assert _distance_shapes(big, box((10.5, 1, 1), (12, 3, 3))).Value() == pytest.approx(0.5)
    assert _distance_shapes(big, small).Value() == 0.0  # the second inside the first: no vertex out of its box
    assert _distance_shapes(small, big).Value() == 0.0  # the first inside the second: its vertices are inside
