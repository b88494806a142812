"""tabletcad.pipeline.plot: pictures to scale, true side profiles, dimensions, several tablets at one scale."""

import subprocess
import sys

import numpy as np
import pytest

from tabletcad.families import capsule, concave_round, flat_face_round
from tabletcad.pipeline.plot import side_profile, tablet_figure, tablet_png, tablets_figure

D, BAND, CUP = 10.0, 2.0, 1.0
R = ((D / 2) ** 2 + CUP**2) / (2 * CUP)


@pytest.fixture(scope="module")
def pair():
    return concave_round(diameter=D, band=BAND, cup_depth=CUP), flat_face_round(diameter=D, thickness=BAND + 2 * CUP)


def test_profiles_differ_where_the_cup_is(pair):
    cc, ff = (side_profile(t) for t in pair)
    hc, hf = cc.z_high - cc.z_low, ff.z_high - ff.z_low
    assert np.allclose(cc.x, ff.x)
    centre = np.abs(cc.x) < 0.3
    rim = np.abs(cc.x) > 4.8
    # same overall thickness at the centre, half of it at the rim for the cupped tablet
    assert np.allclose(hc[centre], hf[centre], atol=0.02)
    assert np.all(hf[rim] - hc[rim] > 1.5)
    assert np.allclose(hf, BAND + 2 * CUP, atol=1e-9)
    # the cupped silhouette is the spherical cup: z = band top + sqrt(R^2 - x^2) - (R - cup)
    inner = np.abs(cc.x) < 4.5
    exact = (BAND + CUP) + np.sqrt(R**2 - cc.x[inner] ** 2) - (R - CUP)
    half_bin = 0.5 * (cc.x[1] - cc.x[0])
    slope = np.abs(cc.x[inner]) / np.sqrt(R**2 - cc.x[inner] ** 2)
    assert np.all(np.abs(cc.z_high[inner] - exact) <= slope * half_bin + 2e-3)


def test_main_dimensions(pair):
    o = side_profile(pair[0])
    assert (o.band, o.cup_depth, o.thickness, o.length, o.width, o.round) == (
        pytest.approx(BAND, abs=1e-9), pytest.approx(CUP, abs=1e-6), pytest.approx(BAND + 2 * CUP, abs=1e-6),
        pytest.approx(D, abs=1e-6), pytest.approx(D, abs=1e-6), True)
    assert np.allclose(np.hypot(*o.plan.T), D / 2, atol=1e-6)
    f = side_profile(pair[1])
    assert f.cup_depth == pytest.approx(0.0, abs=1e-9) and f.band == pytest.approx(BAND + 2 * CUP, abs=1e-9)
    c = side_profile(capsule(length=18, width=8, band=3, cup_depth=1.2))
    assert not c.round and c.length == pytest.approx(18, abs=1e-6) and c.width == pytest.approx(8, abs=1e-6)
    assert c.band == pytest.approx(3, abs=1e-9) and c.cup_depth == pytest.approx(1.2, abs=1e-6)
    # a quarter cut-away of the round is as long as wide but no circle: length and width, not "⌀ 5"
    from dataclasses import replace

    from tabletcad.geometry.tablet import Trim

    q = side_profile(replace(pair[0], trim=Trim(v=(0.0, 0.5 * np.pi))))
    assert not q.round and q.length == pytest.approx(D / 2, abs=1e-6) and q.width == pytest.approx(D / 2, abs=1e-6)


def test_figure_is_to_scale_and_dimensioned(pair):
    fig = tablet_figure(pair[1], elev=18.0, azim=-60.0)
    view, prof, plan = fig.axes
    assert view.get_aspect() == prof.get_aspect() == plan.get_aspect() == 1.0
    # the 3-D view is an orthographic projection to scale: the flat-faced round (a cylinder
    # D x T) spans D across and T cos(elev) + D sin(elev) up (its 72-gon rims: within 0.1 %)
    quads = _drawn_quads(view)
    width, height = np.ptp(quads.reshape(-1, 2), axis=0)
    e = np.radians(18.0)
    assert width == pytest.approx(D, rel=1e-3)
    assert height == pytest.approx((BAND + 2 * CUP) * np.cos(e) + D * np.sin(e), rel=1e-3)
    # only faces turned towards the viewer are drawn: the bottom face of the cylinder is not
    assert len(quads) < 0.75 * 3 * 24 * 72
    _, prof, plan = tablet_figure(pair[0]).axes
    texts = {t.get_text() for a in (prof, plan) for t in a.texts}
    assert {"band 2", "cup 1", "4", "⌀ 10"} <= texts
    png = tablet_png(pair[1])
    assert png[:8] == b"\x89PNG\r\n\x1a\n"


def _drawn_quads(ax) -> np.ndarray:
    """The shaded quads an axes draws, (k, 4, 2): a PolyCollection's polygons, or a QuadMesh's
    cells that are not transparent (a convex tablet's faces, one mesh each)."""
    from matplotlib.collections import PolyCollection, QuadMesh

    out = []
    for c in ax.collections:
        if isinstance(c, QuadMesh):
            C = c.get_coordinates()
            cells = np.stack([C[:-1, :-1], C[1:, :-1], C[1:, 1:], C[:-1, 1:]], axis=2).reshape(-1, 4, 2)
            out.append(cells[c.get_facecolor()[:, 3] > 0.0])
        elif isinstance(c, PolyCollection):
            out.append(np.stack([p.vertices[:4] for p in c.get_paths()]))
    return np.concatenate(out)


def test_only_convex_tablets_are_drawn_as_meshes():
    """``_convex`` decides from the exact nominal: a concave round without a land is convex, with
    a land its cup rises from the land (a re-entrant edge) and it is not; a capsule with a land
    is not, but its faces turned up still never overlap in plan (``_graph_from_above``)."""
    from tabletcad.pipeline import plot

    assert plot._convex(concave_round(diameter=D, band=BAND, cup_depth=CUP))
    assert not plot._convex(concave_round(diameter=D, band=BAND, cup_depth=CUP, land=0.08))
    c = capsule(length=14.0, width=6.0, band=2.5, cup_depth=0.8, land=0.1)
    assert not plot._convex(c) and plot._graph_from_above(c)
    assert plot._convex(flat_face_round(diameter=D, thickness=3.0))


def _cover(quads: np.ndarray) -> float:
    """Summed area of the quads (k, 4, 2) over the area of their convex hull."""
    from scipy.spatial import ConvexHull

    x, y = quads[..., 0], quads[..., 1]  # shoelace area of every quad
    areas = 0.5 * np.abs(np.sum(x * np.roll(y, -1, axis=1) - np.roll(x, -1, axis=1) * y, axis=1))
    return float(areas.sum() / ConvexHull(quads.reshape(-1, 2)).volume)


@pytest.mark.parametrize("factory", [flat_face_round, concave_round])
def test_meshes_of_a_convex_tablet_paint_what_the_depth_sorted_polygons_paint(monkeypatch, factory):
    """A convex tablet's faces are drawn as one mesh each in any order (``_convex``), the others
    as polygons sorted far to near.  For a convex tablet both draw the same quads, and those
    quads do not overlap on screen (their areas add up to the area of their convex hull, the
    silhouette, but for slivers along it), so the order cannot matter: the two pictures differ
    only in which of two neighbouring quads owns the pixels along their edges."""
    from tabletcad.pipeline import plot

    t = factory(diameter=D, thickness=BAND + 2 * CUP) if factory is flat_face_round else factory(
        diameter=D, band=BAND, cup_depth=CUP)
    assert plot._convex(t)

    def picture():
        fig = tablet_figure(t)
        fig.canvas.draw()
        return np.asarray(fig.canvas.buffer_rgba())[..., :3].astype(int), _drawn_quads(fig.axes[0])

    img, quads = picture()
    monkeypatch.setattr(plot, "_convex", lambda tablet: False)
    monkeypatch.setattr(plot, "_graph_from_above", lambda tablet, convex=None: False)
    ref, ref_quads = picture()
    assert len(quads) == len(ref_quads)
    np.testing.assert_allclose(np.sort(quads.reshape(-1, 8), axis=0), np.sort(ref_quads.reshape(-1, 8), axis=0),
                               atol=1e-12)
    assert _cover(quads) == pytest.approx(1.0, abs=1e-6)
    # where quads do overlap (a cup rising from a land hides part of the land) the sum exceeds the hull
    landed = tablet_figure(concave_round(diameter=D, band=BAND, cup_depth=1.5, land=0.5))
    assert _cover(_drawn_quads(landed.axes[0])) > 1.01
    differ = np.any(np.abs(img - ref) > 8, axis=-1)
    assert differ.mean() < 5e-3, f"{differ.sum()} pixels differ"


def test_the_drawn_side_profile_is_a_closed_outline(pair):
    """The profile's outline line comes back to its start: the band on the left is drawn too."""
    fig = tablet_figure(pair[0])
    prof = fig.axes[1]
    outline = max(prof.lines, key=lambda ln: len(ln.get_xdata()))
    xy = np.c_[outline.get_xdata(), outline.get_ydata()]
    assert np.array_equal(xy[0], xy[-1])
    left = xy[np.isclose(xy[:, 0], xy[:, 0].min())]
    assert np.ptp(left[:, 1]) == pytest.approx(BAND, abs=1e-6)  # the left band edge, bottom to top


def test_several_tablets_share_one_scale(pair):
    t3 = capsule(length=18, width=8, band=3, cup_depth=1.2)
    fig = tablets_figure([*pair, t3])
    rows = np.array(fig.axes).reshape(2, 3)
    spans = [[np.ptp(a.get_xlim()) for a in row] for row in rows]
    assert np.allclose(spans, spans[0][0])
    assert all(np.ptp(a.get_ylim()) == pytest.approx(np.ptp(rows[0, 0].get_ylim())) for a in rows[0])
    with pytest.raises(ValueError):
        tablets_figure([])


def test_no_global_backend_is_set():
    code = ("import sys, matplotlib; b = matplotlib.rcParams._get_backend_or_none(); "
            "from tabletcad.families.thesis import flat_faced_round; from tabletcad.pipeline.plot import tablet_png; "
            "tablet_png(flat_faced_round()); "
            "assert 'matplotlib.pyplot' not in sys.modules; "
            "assert matplotlib.rcParams._get_backend_or_none() == b; print('ok')")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0 and out.stdout.strip() == "ok", out.stderr


def test_no_module_sets_the_backend_or_uses_pyplot():
    """Every figure tabletcad draws owns an Agg canvas: no ``matplotlib.use`` (which switches a
    notebook's or FreeCAD's backend for the whole process) and no pyplot state anywhere in the package."""
    from pathlib import Path

    root = Path(__file__).resolve().parents[1] / "tabletcad"
    offenders = [f"{p.relative_to(root.parent)}:{i}" for p in sorted(root.rglob("*.py"))
                 for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1)
                 if "matplotlib.use(" in line or "matplotlib.pyplot" in line]
    assert offenders == []
