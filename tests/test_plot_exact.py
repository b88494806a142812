"""tabletcad.pipeline.plot against exact geometry, for every sample design.

* The dimensions the picture writes (diameter or length × width, thickness, band, cup depth)
  are the design report's, to the picture's three significant figures.
* The plan outline has the tablet's plan area (:meth:`Tablet.plan_area`) and lies on the
  exact outline (an industry family's lines and arcs, or the closed-form circle, ellipse,
  stadium of the thesis's shapes): no spike or notch.
* The side profile of the sphere and the spheroids is their closed-form ellipse, reaching
  its extreme x, by both silhouette methods (meridian, and crossings of a dense sample).
* ``plot_tablets`` takes Tablets and TabletModels; ``tabletcad report --plot``.
"""

from __future__ import annotations

import functools
import math
import struct
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import cKDTree

import tabletcad
from tabletcad.cli import main
from tabletcad.pipeline import plot

ROOT = Path(__file__).resolve().parents[1]
SAMPLES = sorted((ROOT / "samples").glob("*.toml")) + sorted((ROOT / "samples" / "families").glob("*.toml"))
NAMES = [p.stem for p in SAMPLES]
_CACHE: dict[str, object] = {}


def _tablet(name: str):
    if name not in _CACHE:
        _CACHE[name] = tabletcad.load(SAMPLES[NAMES.index(name)]).tablet
    return _CACHE[name]


def test_there_are_28_samples():
    assert len(SAMPLES) == 28


def _report(tablet, path: Path) -> dict:
    from tabletcad.families.sweep import SweepNominal
    from tabletcad.pipeline.design import Design
    from tabletcad.pipeline.designreport import design_report, shape_report

    opts = Design.from_toml(path).report_options
    sec = design_report(tablet, opts) if isinstance(tablet.nominal, SweepNominal) else shape_report(tablet, opts)
    return sec["design_report"]


@pytest.mark.parametrize("name", NAMES)
def test_picture_dimensions_are_the_reports(name):
    """Every label of the profile and plan panels is a report figure at ``.3g`` (where the report
    has no band or cup depth, as for a caplet or a rod, only the others are compared)."""
    t = _tablet(name)
    r = _report(t, SAMPLES[NAMES.index(name)])
    fig = plot.tablet_figure(t)
    _, prof, plan = fig.axes
    texts = {x.get_text() for a in (prof, plan) for x in a.texts}
    L, W, T = r["length_mm"], r["width_mm"], r["overall_thickness_mm"]
    assert f"{T:.3g}" in texts
    if abs(L - W) <= 1e-3 * max(L, W):
        assert f"⌀ {L:.3g}" in texts
    else:
        assert {f"{L:.3g}", f"{W:.3g}"} <= texts
    bands = {x for x in texts if x.startswith("band ")}
    cups = {x for x in texts if x.startswith("cup ")}
    if r["band_mm"] is not None:
        assert bands == {f"band {r['band_mm']:.3g}"}
    if r["cup_depth_mm"] is not None:
        assert cups == ({f"cup {r['cup_depth_mm']:.3g}"} if r["cup_depth_mm"] > 1e-6 else set())
    if t.band() is None:  # a sphere, a spheroid: no band and no cups drawn
        assert bands == set() and cups == set()


def _polyline_area(P: np.ndarray) -> float:
    x, y = P[:, 0], P[:, 1]
    return 0.5 * abs(float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)))


def _densify(P: np.ndarray, step: float) -> np.ndarray:
    out = [P[:1]]
    for a, b in zip(P[:-1], P[1:]):
        k = max(1, int(math.ceil(np.linalg.norm(b - a) / step)))
        out.append(a + (b - a) * (np.arange(1, k + 1) / k)[:, None])
    return np.vstack(out)


def _exact_outline(name: str, t) -> tuple[np.ndarray, list[np.ndarray]]:
    """The exact plan outline (dense points) and its holes, from the family's lines and arcs or
    the thesis shape's closed form (not from the PDE surface)."""
    th = np.linspace(0.0, math.tau, 20001)
    p = t.params
    outline = getattr(t.nominal, "outline", None)
    if getattr(outline, "segs", None) is not None:
        return outline.point(th), []
    if name == "free_form_stadium":  # 12 × 6 stadium: semicircles of radius 3 about x = ±3
        a = np.linspace(-math.pi / 2, math.pi / 2, 5001)
        right = np.c_[3 + 3 * np.cos(a), 3 * np.sin(a)]
        return _densify(np.vstack([right, -right, right[:1]]), 0.001), []
    if name == "ring":
        ro, ri = p["outer_diameter"] / 2, p["inner_diameter"] / 2
        return ro * np.c_[np.cos(th), np.sin(th)], [ri * np.c_[np.cos(th), np.sin(th)]]
    if "diameter" in p:
        a = b = p["diameter"] / 2
    else:
        a, b = p["length"] / 2, p["width"] / 2
    pts = np.c_[a * np.cos(th), b * np.sin(th)]
    if name == "cutaway_convex_round":  # v in [π/2, 2π]: three quarters, cut along the axes
        keep = th >= math.pi / 2
        r = np.linspace(0.0, a, 2001)[:, None]
        pts = np.vstack([pts[keep], r * [1.0, 0.0], r * [0.0, 1.0]])
    return pts, []


@pytest.mark.parametrize("name", NAMES)
def test_plan_outline_has_the_plan_area_and_no_spike(name):
    """Area: an industry family's outline is exact and its surface within 1 µm of it, so the
    outline's area is ``plan_area()`` within 2e-5 (the 0.25° polygon of the arcs: 3e-6).  The
    thesis's PDE surfaces bulge up to 4 µm beyond their band edge (``Band.bulge``, a caplet's
    domes 3.8 µm), which ``plan_area()`` includes: perimeter × 4 µm more.  Spike: every point of
    the outline within 0.01 mm of the exact outline and every exact point within 0.01 mm of the
    drawn one (a 0.1 % of the size at most; the reviewer's notch was 0.8 mm)."""
    t = _tablet(name)
    o = plot.side_profile(t)
    loops = [o.plan, *o.plan_holes]
    area = _polyline_area(o.plan) - sum(_polyline_area(h) for h in o.plan_holes)
    expected = t.plan_area()
    if name == "cutaway_convex_round":
        # the plan of this cut-away view (v from π/2 to 2π) is three quarters of the untrimmed tablet's
        assert expected == pytest.approx(0.75 * t.trimmed(v=(0.0, math.tau)).plan_area(), rel=1e-14)
    perimeter = sum(float(np.sum(np.linalg.norm(np.diff(L, axis=0), axis=1))) for L in loops)
    exact_outline = getattr(getattr(t.nominal, "outline", None), "segs", None) is not None
    tol = 2e-5 * expected + (0.0 if exact_outline else perimeter * 4e-3)
    assert abs(area - expected) <= tol, (area, expected, tol)

    ref, ref_holes = _exact_outline(name, t)
    assert len(ref_holes) == len(o.plan_holes)
    size = max(o.length, o.width)
    for drawn, exact in zip(loops, [ref, *ref_holes]):
        d_out = cKDTree(exact).query(drawn)[0].max()  # drawn vertices off the exact outline
        d_in = cKDTree(_densify(drawn, 0.002)).query(exact)[0].max()  # exact points the drawing misses
        assert max(d_out, d_in) < min(0.01, 0.005 * size), (d_out, d_in)


@functools.lru_cache(maxsize=None)
def _ellipse_tree(a: float, c: float) -> cKDTree:
    """A k-d tree of 200,001 points of the ellipse of semi-axes ``a`` and ``c`` (mm), built once for the
    module (each spheroid's is asked for by both methods, each twice)."""
    th = np.linspace(0.0, math.tau, 200001)
    return cKDTree(np.c_[a * np.cos(th), c * np.sin(th)])


def _ellipse_distance(x: np.ndarray, z: np.ndarray, a: float, c: float) -> np.ndarray:
    return _ellipse_tree(a, c).query(np.c_[x, z])[0]


@pytest.mark.parametrize("general", [False, True], ids=["meridian", "crossings"])
@pytest.mark.parametrize("name, a, c", [("spherical", 2.5, 2.5), ("prolate_spheroid", 2.5, 5.0),
                                        ("oblate_spheroid", 5.0, 1.25)])
def test_side_profile_is_the_spheroids_ellipse(monkeypatch, name, a, c, general):
    """The silhouette along y of a spheroid of semi-axes ``a`` (plan) and ``c`` (height), standing
    on z = 0, is the ellipse ``(x/a)² + ((z - c)/c)² = 1``.  The thesis's PDE surface is itself
    ``dev`` = 12–20 µm from that closed form (:meth:`Tablet.nominal_deviation`), so: every profile
    point within ``dev`` + 2 µm of the ellipse, the profile reaching x = ±a within ``dev`` + 2 µm,
    and the half-height at |x| ≤ a/2 (slope ≤ 1.2) within 2 (``dev`` + 2 µm) of
    ``c √(1 - (x/a)²)``.  Both methods: the meridian (a tablet of revolution) and the crossings of
    a dense sample (any tablet, forced here)."""
    t = _tablet(name)
    dev = t.nominal_deviation()
    assert 0.005 < dev < 0.025
    if general:
        monkeypatch.setattr(plot, "_revolution_axis", lambda tablet: None)
    o = plot.side_profile(t)
    tol = dev + 2e-3
    assert o.x[0] == pytest.approx(-a, abs=tol) and o.x[-1] == pytest.approx(a, abs=tol)
    for z in (o.z_low, o.z_high):
        assert _ellipse_distance(o.x, z - c, a, c).max() < tol
    inner = np.abs(o.x) <= 0.5 * a
    half = c * np.sqrt(1.0 - (o.x[inner] / a) ** 2)
    assert np.abs(0.5 * (o.z_high - o.z_low)[inner] - half).max() < 2 * tol
    assert np.abs(0.5 * (o.z_high + o.z_low) - c).max() < tol  # symmetric about the equator
    assert not o.has_band


def test_the_reviewers_sphere_point():
    """At x = 2.48 the picture showed the sphere's whole height (a flat side at z 2.0–3.0 and x
    sampled only to ±2.48).  The profile now reaches x = ±2.5027 (the PDE sphere's equator
    radius) and at x = 2.48 has the surface's own height there: the crossing of its meridian
    (20,001 points, found here independently) within 1 µm; ±0.398 about the centre, where
    the exact sphere has ±0.316 (the PDE surface is 12 µm off it, steeply seen here)."""
    m = tabletcad.load(ROOT / "samples" / "spherical.toml")  # a TabletModel
    o = plot.side_profile(m)
    u = np.linspace(0.0, 1.0, 20001)
    M = m.tablet.patches[1].evaluate(u, np.zeros_like(u))  # the upper hemisphere's meridian, x > 0
    k = np.flatnonzero(np.diff(np.sign(M[:, 0] - 2.48)))[0]
    s = (2.48 - M[k, 0]) / (M[k + 1, 0] - M[k, 0])
    z_exact = M[k, 2] + s * (M[k + 1, 2] - M[k, 2])
    assert float(np.interp(2.48, o.x, o.z_high)) == pytest.approx(z_exact, abs=1e-3)
    assert float(np.interp(2.48, o.x, o.z_low)) == pytest.approx(5.0 - z_exact, abs=1e-3)
    assert o.x[-1] == pytest.approx(2.5027, abs=1e-4) and 0.3 < z_exact - 2.5 < 0.45


def _png_size(path: Path) -> tuple[int, int]:
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", data[16:24])


def test_plot_tablets_takes_tablets_and_models(tmp_path):
    m = tabletcad.make("concave_round", diameter=10, band=3, cup_depth=1)
    out = plot.plot_tablets([m, _tablet("spherical")], tmp_path / "x.png")
    assert _png_size(out)[0] > 0
    fig = plot.tablets_figure([m, m.tablet])
    assert [a.get_title().splitlines()[0] for a in fig.axes[:2]] == [m.tablet.name] * 2
    with pytest.raises(TypeError, match="TabletModel"):
        plot.tablets_figure(["concave_round"])


def test_report_plot_many_side_by_side_and_one_picture(tmp_path, capsys):
    designs = [ROOT / "samples" / "families" / "concave_round.toml", ROOT / "samples" / "families" / "capsule.toml",
               ROOT / "samples" / "spherical.toml"]
    many, one = tmp_path / "many.png", tmp_path / "one.png"
    assert main(["report", *map(str, designs), "--plot", str(many)]) == 0
    assert f"plot -> {many}" in capsys.readouterr().out
    assert main(["report", str(designs[1]), "--plot", str(one)]) == 0
    # the side-by-side figure is (2.6 k + 0.6) × 5 in, the single picture 11 × 4 in, at 110 dpi
    assert _png_size(many) == (round((2.6 * 3 + 0.6) * 110), 5 * 110)
    assert _png_size(one) == (11 * 110, 4 * 110)


@pytest.mark.parametrize("value, why", [
    ("OUT/r.jpg", "must end in .png"),
    ("OUT/r", "must end in .png"),
    ("OUT/d.png", "is a folder"),
    ("OUT/f.txt/r.png", "cannot be created"),
])
def test_report_plot_bad_output_is_one_line_and_writes_nothing(tmp_path, capsys, value, why):
    out = tmp_path / "OUT"
    out.mkdir()
    (out / "d.png").mkdir()
    (out / "f.txt").write_text("x")
    before = sorted(out.rglob("*"))
    argv = ["report", str(ROOT / "samples" / "families" / "concave_round.toml"), "--csv", str(out / "r.csv"),
            "--plot", value.replace("OUT", str(out))]
    assert main(argv) == 2
    cap = capsys.readouterr()
    assert cap.out == "" and cap.err.splitlines() == [cap.err.strip()]
    assert cap.err.startswith("error: --plot = ") and " is not allowed: " in cap.err and why in cap.err
    assert sorted(out.rglob("*")) == before


def test_an_outline_through_points_is_drawn_from_its_band_edge(tmp_path):
    """A custom outline through points (a spline, no line/arc segments) draws its plan from the band's
    edge curve: the drawn outline's area is the tablet's plan area (the build's picture had crashed)."""
    from tabletcad.pipeline.design import Design

    th = np.linspace(0.0, math.tau, 21)[:-1]
    pts = [[float(4.5 * math.cos(a)), float(3.0 * math.sin(a))] for a in th]
    t = Design.from_dict({"tablet": {"family": "custom_outline", "outline": pts, "band": 2.5,
                                     "cup_depth": 0.19}}).build()
    o = plot.side_profile(t)
    perimeter = float(np.sum(np.linalg.norm(np.diff(o.plan, axis=0), axis=1)))
    assert abs(_polyline_area(o.plan) - t.plan_area()) <= 2e-5 * t.plan_area() + perimeter * 4e-3
    assert plot.plot_tablet(t, tmp_path / "t.png").stat().st_size > 10_000
