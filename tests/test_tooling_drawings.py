"""Drawings a toolmaker can quote from: tolerances, title block, scale, punch and die sheet, no text on geometry."""

import math
import re
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("OCP")
pytest.importorskip("ezdxf")
pytest.importorskip("matplotlib")

from tabletcad.pipeline.design import load_design  # noqa: E402
from tabletcad.tooling import make_tooling  # noqa: E402
from tabletcad.tooling.drawing import drawing_model, sheet_figure, tooling_model, write_drawing  # noqa: E402
from tabletcad.pipeline.design import Design  # noqa: E402

pytestmark = pytest.mark.cad

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "samples" / "tooling" / "tsm_b_round.toml"


@pytest.fixture(scope="module")
def drawn(tmp_path_factory):
    ts = make_tooling(load_design(SAMPLE), Design.from_toml(SAMPLE).tooling_spec, check=False,
                      interference_check=False)
    out = tmp_path_factory.mktemp("drawings")
    files = write_drawing(ts, out)
    return ts, out, files


def test_sheets_carry_toleranced_dimensions_and_the_title_block(drawn):
    ts, out, files = drawn
    assert sorted(p.name for p in files) == sorted(f"{a}.{b}" for a in ("drawing", "tooling") for b in ("svg", "pdf", "dxf"))
    svg = (out / "drawing.svg").read_text(encoding="utf-8")
    for text in ("Ø10.00 ±0.076", "band 2.80 ±0.076", "cup 0.90 ±0.050", "T 4.60 ±0.076",  # cup from the design
                 "10 mm concave round, TSM B", "drawing no. TC-0001", "rev. A", "date: 2026-12-01",
                 "author: tabletcad sample", "material: punches and die", "general tolerance ±0.076 mm",
                 "SECTION A-A", "DETAIL B 10:1", "PLAN", "FRONT", "SIDE"):
        assert text in svg, text
    scale = ts.report["drawing"]["scale"]
    assert 1.0 < scale < 20.0 and f"scale {scale:.3g}:1   sheet A4" in svg
    # the punches do not reach 1:1 on A4: the sheet grows until they do
    td = ts.report["tooling_drawing"]
    assert td["paper"] in ("A3", "A2") and td["scale"] >= 1.0
    tsvg = (out / "tooling.svg").read_text(encoding="utf-8")
    # the cup's sphere through the land's inner edge (4.92 mm from the axis) and 0.9 mm deep; the land
    cup_r = (4.92 ** 2 + 0.9 ** 2) / (2 * 0.9)
    for text in (f"R{cup_r:.2f} ±0.076", "land 0.080 ±0.076"):
        assert text in svg, text
    for text in ("overall 133.35 ±0.076", "Ø19.00 ±0.076", "Ø25.40 ±0.076", "tip 8.00 ±0.076", "tip 25.40 ±0.076",
                 "Ø30.16 ±0.076", "H 22.22 ±0.076",
                 "UPPER PUNCH", "LOWER PUNCH", "DIE", "drawing no. TC-0001-T", "TSM B tooling, angled heads"):
        assert text in tsvg, text
    # what a toolmaker quotes from beyond the dimensions: the working length (overall less the 0.9 mm cup),
    # the die bore (the tablet's 10 mm) and the tips (less the 0.02 mm clearance per side)
    for which in ("upper_punch", "lower_punch"):
        body = ts.report[which]["body"]
        assert body["working_length_mm"] == pytest.approx(133.35 - 0.9, abs=1e-6)
    # (in the sheet's notes, whose lines wrap where the sheet's room puts them: every one of them on the
    # sheet is test_drawing_sheet_keeps_every_text_on_the_sheet's)
    notes = " ".join(tooling_model(ts).notes)
    for text in ("working length (head flat to cup bottom): upper 132.45, lower 132.45 ±0.076",
                 # the fit one-sided by default (a ±0.076 bore and tips had let a 10.036 tip meet a 9.924 bore)
                 "bore Ø10.000 +0.020/+0.000 (the tablet's",
                 "tips Ø9.960 +0.000/-0.020 (the bore less the clearance 0.020 per side; 0.020 to 0.040 a side at the "
                 "tolerances' limits)"):
        assert text in notes, text
    # the head that runs on the press's cams (a toolmaker's trial: only its diameters were on the sheet): the
    # TSM head's height is its rim, the underside cone over (25.4 - 12.7) / 2 at 37 deg and the top over
    # (25.4 - 12) / 2 at 10 deg
    h = 2.5 + 6.35 * math.tan(math.radians(37.0)) + 6.7 * math.tan(math.radians(10.0))
    assert (f"head Ø25.40 (flat Ø12.00), rim 2.50, inside head angle 37 deg, top angle 10 deg, head height {h:.2f}"
            in notes)
    flat = " ".join(re.sub(r"<[^>]+>", " ", tsvg).split())  # the sheet's text, wrapped lines joined
    assert "working length (head flat to cup bottom): upper 132.45," in flat and "tips Ø9.960" in flat
    dxf = (out / "tooling.dxf").read_text(encoding="utf-8", errors="replace")
    assert "overall 133.35" in dxf and "TC-0001" in dxf
    # read back by ezdxf: the cup radius is a radius DIMENSION measuring the sphere's radius
    import ezdxf

    dims = ezdxf.readfile(out / "drawing.dxf").modelspace().query("DIMENSION")
    (radius,) = [d for d in dims if d.dimtype == 4]  # 4: radius
    assert radius.get_measurement() == pytest.approx(cup_r, rel=1e-9) and radius.dxf.text == f"R{cup_r:.2f} ±0.076"
    assert sum(d.dimtype in (0, 1) for d in dims) == len(ts.report["drawing"]["dimension_texts"]) - 1  # linear


def test_dxf_dimensions_measure_what_their_texts_say(drawn):
    """A CAD program that recomputes a DXF dimension multiplies its measured length by DIMLFAC: ezdxf's
    EZDXF style has 100 (metre units shown in cm), so Ø10 measured 1000; and the land, drawn in the 10:1
    detail, measured 0.80.  Now every measurement (radius, linear, both sheets) times its style's or
    override's DIMLFAC is the number in its text, to the text's rounding."""
    import ezdxf

    _, out, _ = drawn
    checked = 0
    for name in ("drawing.dxf", "tooling.dxf"):
        doc = ezdxf.readfile(out / name)
        assert doc.header["$INSUNITS"] == 4  # millimetres
        assert doc.header["$DIMLFAC"] == 1.0  # (ezdxf's default 100 had stayed in the header)
        for d in doc.modelspace().query("DIMENSION"):
            number = float(re.search(r"\d+(?:\.\d+)?", d.dxf.text).group())
            lfac = d.override().get("dimlfac", 1.0)
            assert abs(d.get_measurement() * lfac - number) <= 0.0051, (name, d.dxf.text, d.get_measurement(), lfac)
            checked += 1
    assert checked >= 12


@pytest.fixture(scope="module")
def capsule():
    """A shaped tablet (length and width dimensioned in two views) with a score (section dimension)."""
    p = SAMPLE.parent / "capsule.toml"
    return make_tooling(load_design(p), Design.from_toml(p).tooling_spec, check=False, interference_check=False)


def _segments_display(ax, dr):
    pts = []
    for name, v in dr.views.items():
        ox, oy = dr.origins[name]
        for p in v["visible"] + v["hidden"]:
            q = np.asarray(p) + np.array([ox, oy])
            t = np.linspace(0.0, 1.0, 9)[:, None]
            dense = (q[:-1, None, :] * (1 - t) + q[1:, None, :] * t).reshape(-1, 2)  # points along every segment
            pts.append(ax.transData.transform(dense))
    return np.concatenate(pts)


@pytest.mark.parametrize("which", ["tablet", "tooling", "capsule", "capsule tips"])
def test_no_text_leaves_the_sheet_or_lies_on_the_views(drawn, capsule, which):
    import matplotlib.pyplot as plt

    from tabletcad.tooling.drawing import tips_model

    ts, _, _ = drawn
    if which == "capsule":
        dr, paper = drawing_model(capsule), "A4"
        assert {"L 14.00 ±0.076", "W 6.00 ±0.076", "score 0.30 ±0.076"} <= {d.text for d in dr.dims}
    elif which == "capsule tips":  # tips-only tooling's sheet (a toolmaker's trial: it had none)
        assert capsule.spec.body is None
        dr, paper = tips_model(capsule), "A4"
        fit = capsule.frame.tip_inset(capsule.spec.clearance_mm)
        assert [d.text for d in dr.dims] == ["tip 8.00 ±0.076", "tip 8.00 ±0.076", "Ø30.16 ±0.076", "H 22.22 ±0.076"]
        # (the fit one-sided, inside the 0.02 mm clearance: ±0.076 had let the tips jam in the bore)
        assert f"tips {14.0 - 2 * fit:.3f} x {6.0 - 2 * fit:.3f} +0.000/-0.020 (" in dr.notes[1]
        assert "0.020 to 0.040 a side at the tolerances' limits" in dr.notes[1]
    elif which == "tablet":
        dr, paper = drawing_model(ts), "A4"
    else:
        dr, paper = tooling_model(ts), ts.report["tooling_drawing"]["paper"]
    fig = sheet_figure(dr, paper)
    try:
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        ax = fig.axes[0]
        pts = _segments_display(ax, dr)
        labels = [t for t in ax.texts if t.get_text()]  # (the dimension arrows are empty annotations)
        texts = fig.texts + labels
        assert len(labels) == len(dr.dims) + len(dr.views)
        for t in texts:
            bb = t.get_window_extent(renderer)
            assert fig.bbox.x0 <= bb.x0 and bb.x1 <= fig.bbox.x1 and fig.bbox.y0 <= bb.y0 and bb.y1 <= fig.bbox.y1
        boxes = []
        for t in labels:
            bb = t.get_window_extent(renderer).expanded(0.98, 0.9)
            inside = (pts[:, 0] > bb.x0) & (pts[:, 0] < bb.x1) & (pts[:, 1] > bb.y0) & (pts[:, 1] < bb.y1)
            assert not inside.any(), f"{t.get_text()!r} lies on the {which} views"
            boxes.append((t.get_text(), bb))
        for k, (ta, a) in enumerate(boxes):  # and no two texts overlap
            for tb, b in boxes[k + 1:]:
                assert not a.overlaps(b), (ta, tb)
    finally:
        plt.close(fig)


def test_every_dimension_takes_its_own_tolerance():
    """Each dimension key of ``[tooling.drawing] tolerances`` reaches its dimension on the sheets, and
    the radius and land dimensions measure the drawn geometry (the detail is enlarged 10 times)."""
    import math
    from dataclasses import replace

    from tabletcad.tooling.drawing import _dim_geometry
    from tabletcad.tooling.spec import TOLERANCE_KEYS

    design = Design.from_toml(SAMPLE)
    spec = design.tooling_spec
    # a distinct tolerance per key: 0.001, 0.002, ... (none is the general 0.076)
    tols = {k: round(0.001 * (i + 1), 3) for i, k in enumerate(TOLERANCE_KEYS)}
    spec = replace(spec, drawing=replace(spec.drawing, tolerances=tuple(tols.items())), allowed_tip_pressure_MPa=300.0,
                   allowed_tip_pressure_source="a test value")
    ts = make_tooling(load_design(SAMPLE), spec, check=False, interference_check=False)
    dr, tr = drawing_model(ts), tooling_model(ts)
    texts = [d.text for d in dr.dims] + [d.text for d in tr.dims]
    assert all("±" in t for t in texts) and not any("±0.076" in t for t in texts)
    shown = {t.rsplit("±", 1)[1] for t in texts}
    # every key the tablet and punch sheets dimension (a round: no length or width) appears
    fit = ("working_length", "tip_diameter", "bore_diameter")  # the fit's sizes: in the punch sheet's notes
    expected = {k for k in TOLERANCE_KEYS if k not in ("length", "width", "score_depth", "bevel_width", "bevel_angle")
                + fit}
    assert {f"{tols[k]:.3f}" for k in expected} <= shown
    notes = " ".join(tr.notes)
    for k, text in zip(fit, ("lower 132.45 ±{:.3f}", "tips Ø9.960 ±{:.3f} (", "bore Ø10.000 ±{:.3f} (")):
        assert text.format(tols[k]) in notes, k
    radius = [d for d in dr.dims if d.radius]
    assert len(radius) == 1
    (cx, cy), (px, py) = radius[0].p1, radius[0].p2
    assert math.hypot(px - cx, py - cy) == pytest.approx((4.92 ** 2 + 0.9 ** 2) / 1.8, rel=1e-12)
    a, b, ext = _dim_geometry(radius[0])
    assert a == (px, py) and ext == [] and math.hypot(b[0] - a[0], b[1] - a[1]) == pytest.approx(3.0)
    (land,) = [d for d in dr.dims if d.text.startswith("land")]
    assert abs(land.p2[0] - land.p1[0]) == pytest.approx(10.0 * 0.08, rel=1e-12)
    assert f"cup radius R{(4.92 ** 2 + 0.81) / 1.8:.2f} ±{tols['cup_radius']:.3f} mm" in dr.notes
    assert f"land 0.080 ±{tols['land']:.3f} mm" in dr.notes
    # the key as the toolmaker makes it (a trial: on no sheet), from the sample's [tooling.punch] key_*
    assert "key 4.76 wide x 15.00 long x 1.50 proud, 25.00 up the barrel from the tip's back face, at 0 deg to +x" \
        in tr.notes
    # the tip-force rating on the punches' sheet too, where the toolmaker looks (a trial: the tablet's only)
    rating = [n for n in dr.notes if n.startswith("tip force rating")]
    assert len(rating) == 1 and rating[0] in tr.notes and "300 MPa x" in rating[0] and "(allowed pressure: a test value)" in rating[0]


def test_bevel_and_radii_notes_carry_tolerances():
    """A bevelled concave round: the cup radius is dimensioned on the section at a point of the sphere
    (inside the bevel), and the bevel's width and angle are noted with their tolerances (the angle's
    default is ISO 2768-m's for legs up to 10 mm)."""
    import math

    d = Design.from_dict({"tablet": dict(family="concave_bevel", diameter=10.0, band=2.5, cup_depth=0.8,
                                         bevel_angle=30.0, bevel_width=0.5),
                          "tooling": {"clearance_mm": 0.02, "drawing": {"tolerances": {"bevel_width": 0.02}}}})
    ts = make_tooling(d.build(), d.tooling_spec, check=False, interference_check=False)
    dr = drawing_model(ts)
    assert "bevel 0.50 ±0.020 mm wide at 30 deg ±1 deg (ISO 2768-m, legs up to 10 mm)" in dr.notes
    assert "no land" in dr.notes
    (radius,) = [x for x in dr.dims if x.radius]
    r = (4.5 ** 2 + 0.8 ** 2) / 1.6  # the sphere through the bevel's inner edge, 0.8 mm below the apex
    assert radius.text == f"R{r:.2f} ±0.076"
    (cx, cy), (px, py) = radius.p1, radius.p2
    assert math.hypot(px - cx, py - cy) == pytest.approx(r, rel=1e-12) and abs(px - cx) < 4.5


@pytest.mark.parametrize("scores, dimensioned", [
    ([{"kind": "bisect", "direction_deg": 90.0}], True),
    ([{"kind": "quadrisect", "direction_deg": 90.0}], False),  # the second groove runs along the section
    ([{"kind": "bisect", "direction_deg": 90.0}, {"kind": "bisect", "direction_deg": 0.0, "faces": "both"}], False),
    ([{"kind": "bisect", "direction_deg": 90.0}, {"kind": "bisect", "direction_deg": 0.0, "faces": "bottom"}], True),
])
def test_the_cup_radius_is_dimensioned_only_where_the_section_shows_the_cup(scores, dimensioned):
    """Section A-A runs across the first score: a groove along it on the top face (a quadrisect's, a
    crossing bisect's) replaces the top cup's arc there, and a radius dimension would point into empty
    space; a crossing groove on the bottom face alone leaves the top cup's arc, where R is drawn."""
    d = Design.from_dict({"tablet": dict(family="concave_round", diameter=10.0, band=2.8, cup_depth=0.9, land=0.08),
                          "tooling": {"clearance_mm": 0.02, "score": [dict(s, profile="v", depth_mm=0.3) for s in scores]}})
    ts = make_tooling(d.build(), d.tooling_spec, check=False, interference_check=False)
    dr = drawing_model(ts)
    assert any(x.radius for x in dr.dims) == dimensioned
    assert "cup radius R13.90 ±0.076 mm" in dr.notes


@pytest.mark.parametrize("sheet", ["tablet", "tooling"])
def test_the_longest_title_block_texts_stay_on_the_sheet_and_apart(drawn, sheet):
    """Every title-block text at its longest (``TITLE_MAX_CHARS``) in the widest letter: the sheet's
    texts stay inside the sheet and no two overlap (a 20,000-character name ran off the sheet)."""
    from dataclasses import replace

    import matplotlib.pyplot as plt

    from tabletcad.tooling.spec import TITLE_MAX_CHARS, DrawingSpec

    ts = replace(drawn[0], spec=replace(drawn[0].spec, drawing=DrawingSpec(**{k: "W" * n for k, n in TITLE_MAX_CHARS.items()})))
    dr = drawing_model(ts) if sheet == "tablet" else tooling_model(ts)
    fig = sheet_figure(dr, "A4")
    try:
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        assert any(t.get_text().startswith("W" * TITLE_MAX_CHARS["name"]) for t in fig.texts)  # whole, not cut
        _texts_inside_and_apart(fig, renderer, vertically=True)
    finally:
        plt.close(fig)


def _texts_inside_and_apart(fig, renderer, vertically: bool) -> None:
    """Every figure-level text inside the sheet (across, and up and down when ``vertically``) and no two
    of them overlapping."""
    boxes = [t.get_window_extent(renderer) for t in fig.texts if t.get_text()]
    for bb in boxes:
        assert fig.bbox.x0 <= bb.x0 and bb.x1 <= fig.bbox.x1
        assert not vertically or (fig.bbox.y0 <= bb.y0 and bb.y1 <= fig.bbox.y1)
    for k, a in enumerate(boxes):
        for b in boxes[k + 1:]:
            assert not a.overlaps(b)


@pytest.mark.parametrize("key, value, fragment", [
    ("name", "N" * 61, "at most 60 characters"),
    ("author", "A" * 31, "at most 30 characters"),
    ("material", "steel\nD2", "printable text on one line"),
    ("number", "A\x00", "printable text on one line"),
])
def test_title_block_texts_that_do_not_fit_are_refused_when_read(key, value, fragment):
    from tabletcad.errors import DesignError
    from tabletcad.tooling.spec import parse_tooling

    with pytest.raises(DesignError) as e:
        parse_tooling({"drawing": {key: value}})
    assert e.value.parameter == f"tooling.drawing.{key}" and fragment in str(e.value)


def test_an_unquoted_toml_date_is_the_drawings_date():
    """``date = 2026-12-01`` unquoted is a TOML date: the title block's date is its ISO text, as quoted (it had
    been refused as "must be a non-empty string"); a design holding it is written back as the same date."""
    import datetime
    import tomllib

    from tabletcad.pipeline.design import toml_text
    from tabletcad.tooling.spec import parse_tooling

    data = tomllib.loads('[tooling.drawing]\ndate = 2026-12-01\n')
    assert parse_tooling(data["tooling"]).drawing.date == "2026-12-01"
    assert parse_tooling({"drawing": {"date": "2026-12-01"}}).drawing.date == "2026-12-01"
    assert parse_tooling({"drawing": {"date": datetime.datetime(2026, 12, 1, 9, 30)}}).drawing.date == "2026-12-01T09:30:00"
    assert tomllib.loads(toml_text(data)) == data


def test_a_tablet_name_of_200_characters_is_cut_to_the_room_beside_the_title_block(drawn):
    """Without ``[tooling.drawing] name`` the title is the tablet's name, up to 200 characters: it
    overlapped the title block (and ran off the sheet in a wide letter); now cut with an ellipsis."""
    from dataclasses import replace

    import matplotlib.pyplot as plt

    from tabletcad.tooling.spec import DrawingSpec

    ts = replace(drawn[0], spec=replace(drawn[0].spec, drawing=DrawingSpec()), tablet=replace(drawn[0].tablet, name="W" * 200))
    fig = sheet_figure(drawing_model(ts), "A4")
    try:
        fig.canvas.draw()
        renderer = fig.canvas.get_renderer()
        title = next(t for t in fig.texts if t.get_text().startswith("WWW"))
        assert title.get_text().endswith("…") and 20 < len(title.get_text()) < 200
        _texts_inside_and_apart(fig, renderer, vertically=False)
    finally:
        plt.close(fig)


@pytest.mark.parametrize("spec, text", [
    (dict(profile="v", angle_deg=90.0), "bisect score V 90 deg, 0.30 mm deep, 0.60 mm wide at the face, at 90 deg on the "
                                        "top face, across the face"),
    (dict(profile="u", width_mm=0.6, cut_through=True), "bisect score U 0.60 mm wide, 0.30 mm deep, 0.60 mm wide at "
                                                        "the face, at 90 deg on the top face, cut through the band"),
    (dict(profile="pressure_sensitive", slot_width_mm=0.15, angle_deg=90.0),
     "bisect score pressure-sensitive, slot 0.15 mm, flanks 90 deg, 0.30 mm deep, 0.55 mm wide at the face"),
    (dict(length_mm=6.0, direction_deg=90.0), "at 90 deg on the top face, short, 6.00 mm long (decorative)"),
])
def test_score_notes_state_the_profile_and_extent(spec, text):
    """The tablet sheet's note of a score gives what makes it: V angle, U width or slot width, depth, width
    at the face, direction, face, and cut-through or short (it said only "bisect score v 0.30 mm deep")."""
    from tabletcad.tooling.drawing import _score_note
    from tabletcad.tooling.scores import groove_width
    from tabletcad.tooling.spec import ScoreSpec

    sc = ScoreSpec(depth_mm=0.3, **spec)
    info = dict(index=0, kind=sc.kind, profile=sc.profile, face="top", depth_mm=sc.depth_mm, cut_through=sc.cut_through,
                width_at_face_centre_mm=groove_width(sc), length_mm=sc.length_mm, direction_deg=sc.direction_deg)
    assert text in _score_note(info, sc)


def test_a_flat_face_has_no_cup_dimension():
    """A flat-faced round's sheet dimensioned "cup 0.000 ±0.076"; a face without a cup has no cup dimension."""
    from tabletcad.tooling.spec import ToolingSpec

    flat = Path(__file__).resolve().parents[1] / "samples" / "families" / "flat_face_round.toml"
    ts = make_tooling(load_design(flat), ToolingSpec(), check=False, interference_check=False)
    texts = [d.text for d in drawing_model(ts).dims]
    assert not any(t.startswith("cup") for t in texts) and any(t.startswith("T 3.50") for t in texts), texts


def test_texts_the_sheet_font_cannot_draw_are_escaped_not_boxed():
    """A tablet name (the default title, and the notes' first line) or an emboss text in a font of its own
    may hold characters DejaVu Sans has no glyph for: matplotlib drew empty boxes; they are written as
    \\uXXXX, and what the font has is kept."""
    from tabletcad.tooling.drawing import Drawing

    dr = Drawing(views={}, origins={}, notes=["錠剤10 (concave_round)", "deboss 'Paracétamol'"], title="錠剤10",
                 title_block=["material: acier"])
    assert dr.title == "\\u9320\\u526410" and dr.notes == ["\\u9320\\u526410 (concave_round)", "deboss 'Paracétamol'"]
    assert dr.title_block == ["material: acier"]


def test_a_tolerance_as_large_as_its_dimension_is_warned_of():
    """The general ±0.076 mm on a 0.050 mm land draws a negative lower limit (a toolmaker's trial: drawn in
    silence): one warning naming each such dimension and its key; a tolerance below the size, given or
    general, draws as before."""
    import warnings
    from types import SimpleNamespace

    from tabletcad.tooling.drawing import Dim, _toleranced
    from tabletcad.tooling.spec import DrawingSpec

    dims = [Dim((0.0, 0.0), (1.0, 0.0), 1.0, "land 0.050"), Dim((0.0, 0.0), (1.0, 0.0), 1.0, "cup 0.900"),
            Dim((0.0, 0.0), (1.0, 0.0), 1.0, "band 0.070")]
    general = SimpleNamespace(spec=SimpleNamespace(drawing=DrawingSpec()))
    with pytest.warns(UserWarning) as caught:
        texts = [d.text for d in _toleranced(dims, general)]
    assert texts == ["land 0.050 ±0.076", "cup 0.900 ±0.076", "band 0.070 ±0.076"]
    assert [str(w.message) for w in caught] == [
        "the drawing's tolerances reach below zero: land 0.050 ±0.076 ([tooling.drawing] tolerances.land); band 0.070 "
        "±0.076 ([tooling.drawing] tolerances.band): give each a tolerance smaller than its size"]
    given = SimpleNamespace(spec=SimpleNamespace(drawing=DrawingSpec(tolerances=(("land", 0.02), ("band", 0.05)))))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert [d.text for d in _toleranced(dims, given)] == ["land 0.050 ±0.020", "cup 0.900 ±0.076", "band 0.070 ±0.050"]


def test_fits_take_limit_deviations_and_the_working_length_its_own_tolerance(drawn):
    """A toolmaker's trial: working length, tip and bore could not be toleranced, and a barrel's fit could
    not be one-sided ([0.0, -0.013] was refused), so Ø19.00 ±0.076 was drawn for a barrel that must not
    exceed its guide's 19 mm."""
    from dataclasses import replace

    from tabletcad.errors import DesignError
    from tabletcad.tooling.spec import parse_tooling

    ts, _, _ = drawn
    table = {"clearance_mm": 0.02, "drawing": {"tolerances": {
        "barrel_diameter": [0.0, -0.013], "working_length": 0.025, "tip_diameter": [-0.005, -0.015],
        "bore_diameter": [0.012, 0.0], "bevel_angle": [1, -2]}}}
    dspec = parse_tooling(table).drawing
    assert dspec.tolerance_text("barrel_diameter") == "+0.000/-0.013" and dspec.tolerance("tip_diameter") == 0.015
    tm = tooling_model(replace(ts, spec=replace(ts.spec, drawing=dspec)))
    texts = [d.text for d in tm.dims]
    assert "Ø19.00 +0.000/-0.013" in texts and "H 22.22 ±0.076" in texts
    notes = " ".join(tm.notes)
    for text in ("upper 132.45, lower 132.45 ±0.025", "bore Ø10.000 +0.012/+0.000 (the tablet's",
                 "tips Ø9.960 -0.005/-0.015 (the bore less"):
        assert text in notes, text
    for bad, why in (([0.0, 0.013], "upper > lower"), ([0.01], "two limit deviations"), (["a", 0.0], "two limit"),
                     ([0.0, -11.0], "-10"), (0.0, "> 0")):
        with pytest.raises(DesignError, match=why):
            parse_tooling({"drawing": {"tolerances": {"tip_diameter": bad}}})


def _entity_points(kind: str, at: dict, n: int = 33) -> np.ndarray:
    """Points along a DXF entity as written (an ARC counter-clockwise from its start angle to its end angle)."""
    if kind == "LINE":
        t = np.linspace(0.0, 1.0, n)[:, None]
        return np.asarray(at["start"]) * (1 - t) + np.asarray(at["end"]) * t
    if kind in ("ARC", "CIRCLE"):
        a0, a1 = (math.radians(at["start_angle"]), math.radians(at["end_angle"])) if kind == "ARC" else (0.0, 2 * math.pi)
        a1 = a1 + 2 * math.pi if a1 <= a0 else a1
        a = np.linspace(a0, a1, n)
        return np.asarray(at["center"]) + at["radius"] * np.column_stack([np.cos(a), np.sin(a)])
    if kind == "ELLIPSE":
        c, M, k = np.asarray(at["center"]), np.asarray(at["major_axis"]), at["ratio"]
        m = k * np.array([-M[1], M[0]])
        a = np.linspace(0.0, 2 * math.pi, n)[:, None]
        return c + np.cos(a) * M + np.sin(a) * m
    return np.asarray(at["points"])


def _entity_length(kind: str, at: dict) -> float:
    if kind == "LINE":
        return math.dist(at["start"], at["end"])
    if kind == "CIRCLE":
        return 2 * math.pi * at["radius"]
    if kind == "ARC":
        sweep = (at["end_angle"] - at["start_angle"]) % 360.0
        return math.radians(sweep) * at["radius"]
    raise AssertionError(kind)


@pytest.mark.parametrize("family", ["capsule", "oval", "almond", "rounded_triangle", "rounded_rectangle",
                                    "modified_capsule", "custom_outline"])
def test_the_dxf_outline_entities_are_the_outline_exactly(family):
    """The DXF's OUTLINE entities (lines, arcs, circles) lie on the tablet's outline, run its whole length
    once and join end to end: an arc written clockwise would be its complement, off the outline."""
    from tabletcad.families.sweep import SweepNominal
    from tabletcad.tooling.drawing import _exact_entities
    from tabletcad.tooling.outline import segments_wire, wire_length

    t = load_design(ROOT / "samples" / "families" / f"{family}.toml")
    assert isinstance(t.nominal, SweepNominal)
    segs = t.nominal.outline.segs
    wire = segments_wire(segs)
    origin = (3.0, -7.0)
    ents = _exact_entities(wire, origin)
    kinds = sorted(k for k, _ in ents)
    assert set(kinds) <= {"LINE", "ARC", "CIRCLE"}
    assert len(ents) == len(segs)
    assert sum(_entity_length(k, a) for k, a in ents) == pytest.approx(wire_length(wire), rel=1e-12)
    # every point of every entity lies on the outline (its exact signed distance, moved back by the origin)
    for k, a in ents:
        pts = _entity_points(k, a) - np.asarray(origin)
        assert np.max(np.abs(t.nominal.outline.signed_distance(pts))) < 1e-9, (family, k, a)
    # end to end: each entity's end is another's start (as drawn, arcs counter-clockwise)
    ends = [(_entity_points(k, a)[0], _entity_points(k, a)[-1]) for k, a in ents if k != "CIRCLE"]
    for i, (s, e) in enumerate(ends):
        assert sum(min(np.linalg.norm(e - s2), np.linalg.norm(e - e2)) < 1e-9
                   for j, (s2, e2) in enumerate(ends) if j != i) >= 1


def test_the_sheets_dxf_carries_the_outline_on_its_own_layer(drawn, capsule, tmp_path):
    import ezdxf

    from tabletcad.tooling.drawing import _write_dxf

    ts, out, _ = drawn
    fr = ts.frame
    msp = ezdxf.readfile(out / "drawing.dxf").modelspace()
    circles = msp.query('CIRCLE[layer=="OUTLINE"]')
    assert len(msp.query('*[layer=="OUTLINE"]')) == len(circles) == 1
    (c,) = circles
    px, py = drawing_model(ts).origins["plan"]
    assert c.dxf.radius == pytest.approx(fr.round_radius, rel=1e-14)
    assert (c.dxf.center.x, c.dxf.center.y) == pytest.approx((px, py), abs=1e-12)
    # the capsule: two half circles of half its width and two straight sides, its length apart
    dr = drawing_model(capsule)
    _write_dxf(dr, tmp_path / "capsule.dxf")
    msp = ezdxf.readfile(tmp_path / "capsule.dxf").modelspace()
    arcs, lines = msp.query('ARC[layer=="OUTLINE"]'), msp.query('LINE[layer=="OUTLINE"]')
    assert len(arcs) == 2 and len(lines) == 2
    W, L = capsule.tablet.params["width"], capsule.tablet.params["length"]  # (the frame's: the PDE tablet's extents)
    assert all(a.dxf.radius == pytest.approx(W / 2, rel=1e-12) for a in arcs)
    assert all((a.dxf.end_angle - a.dxf.start_angle) % 360 == pytest.approx(180.0, abs=1e-9) for a in arcs)
    assert sorted(math.dist(ln.dxf.start, ln.dxf.end) for ln in lines) == pytest.approx([L - W] * 2, rel=1e-12)
    assert any("layer OUTLINE" in n for n in dr.notes)


def test_an_arc_turning_clockwise_is_written_counter_clockwise_between_the_same_ends():
    """An outline's concave arcs run clockwise (their circle's axis along -z): the ARC entity, always
    counter-clockwise, must go from the arc's end to its start, not round the rest of the circle."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeWire
    from OCP.GC import GC_MakeArcOfCircle
    from OCP.gp import gp_Pnt

    from tabletcad.tooling.drawing import _exact_entities

    s = math.sqrt(0.5)
    arc = GC_MakeArcOfCircle(gp_Pnt(0, 2, 0), gp_Pnt(2 * s, 2 * s, 0), gp_Pnt(2, 0, 0)).Value()  # clockwise, r = 2
    assert arc.BasisCurve().Axis().Direction().Z() < 0
    wire = BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(arc).Edge()).Wire()
    ((kind, at),) = _exact_entities(wire, (1.0, 1.0))
    assert kind == "ARC" and at["radius"] == pytest.approx(2.0, rel=1e-15)
    assert (at["start_angle"], at["end_angle"]) == pytest.approx((0.0, 90.0), abs=1e-12)
    pts = _entity_points(kind, at)
    assert pts[16] == pytest.approx((1 + 2 * s, 1 + 2 * s), abs=1e-12)  # through the arc's middle


@pytest.mark.parametrize("rx, ry", [(5.0, 3.0), (2.5, 4.0)])
def test_an_elliptic_outline_is_one_ellipse_entity_on_the_outline(rx, ry):
    """A thesis oval's band is an ellipse (its outline wire a gp_Elips, the major axis along x or y): one
    ELLIPSE entity whose points all lie on x²/rx² + y²/ry² = 1 about the plan origin, and a circle one CIRCLE."""
    from tabletcad.tooling.drawing import _exact_entities
    from tabletcad.tooling.outline import ellipse_wire

    origin = (-2.0, 11.0)
    ((kind, at),) = _exact_entities(ellipse_wire(rx, ry, (0.5, -0.25)), origin)
    assert kind == "ELLIPSE"
    pts = _entity_points(kind, at, 65) - np.asarray(origin) - np.array([0.5, -0.25])
    assert np.max(np.abs((pts[:, 0] / rx) ** 2 + (pts[:, 1] / ry) ** 2 - 1.0)) < 1e-12
    assert at["ratio"] == pytest.approx(min(rx, ry) / max(rx, ry), rel=1e-15)
    ((kind, at),) = _exact_entities(ellipse_wire(3.0, 3.0), (0.0, 0.0))
    assert kind == "CIRCLE" and at["radius"] == pytest.approx(3.0, rel=1e-15)


# ----------------------------------------------------------------------------- a new user's trial (session 50)
def test_the_fit_is_toleranced_so_that_the_clearance_survives():
    """A toolmaker's fit: with the general ±0.076 on the bore and the tips, a 9.960 tip at its largest
    (10.036) jammed in a 10.000 bore at its smallest (9.924).  By default the bore is +t/0 and the tips 0/-t,
    t the general tolerance but at most the clearance; given tolerances that can close the clearance are
    warned of (stderr and the sheets)."""
    from tabletcad.tooling.spec import fit_warnings, parse_tooling

    d = parse_tooling({"clearance_mm": 0.02}).drawing
    assert (d.tolerance_text("bore_diameter"), d.tolerance_text("tip_diameter")) == ("+0.020/+0.000", "+0.000/-0.020")
    assert d.fit_clearance() == pytest.approx((0.02, 0.04), abs=1e-12)
    assert d.tolerance_text("die_diameter") == "±0.076"  # (not a fit: the general tolerance)
    wide = parse_tooling({"clearance_mm": 0.2}).drawing  # the general 0.076 is below the clearance
    assert (wide.tolerance_text("bore_diameter"), wide.fit_clearance()[0]) == ("+0.076/+0.000", pytest.approx(0.2))
    fine = parse_tooling({"clearance_mm": 0.0125}).drawing  # to 0.1 µm where that is the size
    assert fine.tolerance_text("tip_diameter") == "+0.000/-0.0125"
    assert not [m for m in fit_warnings(parse_tooling({"clearance_mm": 0.02})) if "close" in m]
    # given: a ±0.076 bore with the default tips leaves 0.02 - 0.076 / 2 = -0.018 mm a side
    given = parse_tooling({"clearance_mm": 0.02, "drawing": {"tolerances": {"bore_diameter": 0.076}}})
    (msg,) = fit_warnings(given)
    assert msg.startswith("the fit's tolerances can close the 0.02 mm clearance: a tip at its largest in a bore at its "
                          "smallest leaves -0.018 mm a side (bore ±0.076, tips +0.000/-0.020)")
    # line to line at the limits closes it too; one-sided limits inside twice the clearance do not
    touching = {"bore_diameter": [0.02, -0.02], "tip_diameter": [0.02, -0.02]}
    assert len(fit_warnings(parse_tooling({"clearance_mm": 0.02, "drawing": {"tolerances": touching}}))) == 1
    ok = {"bore_diameter": [0.02, -0.01], "tip_diameter": [0.01, -0.02]}
    assert fit_warnings(parse_tooling({"clearance_mm": 0.02, "drawing": {"tolerances": ok}})) == []


def test_fit_and_clearance_warnings_are_on_the_sheets(drawn, tmp_path):
    """The README: a clearance of 0 or wider than 0.1 mm a side "is warned of and drawn"; 0.2 mm reached
    stderr but no sheet.  Now on both sheets' notes (SVG, PDF, DXF) as the overload is, and so is a fit
    whose tolerances can close the clearance."""
    import warnings
    from dataclasses import replace

    from tabletcad.tooling.outline import tablet_frame  # noqa: F401  (OCC present: the fixture built)
    from tabletcad.tooling.spec import parse_tooling
    from tabletcad.tooling.toolset import check_on_frame

    ts, _, _ = drawn
    wide = replace(ts, spec=replace(ts.spec, clearance_mm=0.2))
    want = ("WARNING: clearance_mm = 0.2: wider than 0.1 mm a side (presses use about 0.01-0.05 mm): powder flashes "
            "into the gap and the tablet's band edge gets a burr")
    assert want in tooling_model(wide).notes and want in drawing_model(wide).notes
    with warnings.catch_warnings(record=True) as got:  # stderr has the same line
        warnings.simplefilter("always")
        check_on_frame(ts.frame, wide.spec)
    assert want[len("WARNING: "):] in [str(w.message) for w in got]
    files = write_drawing(wide, tmp_path)
    for f in files:
        if f.suffix in (".svg", ".dxf"):
            text = " ".join(re.sub(r"<[^>]+>", " ", f.read_text(encoding="utf-8", errors="replace")).split())
            assert "WARNING: clearance_mm = 0.2: wider than 0.1 mm a side" in text.replace("\\P", " "), f.name
    closing = replace(ts, spec=replace(ts.spec, drawing=parse_tooling(
        {"drawing": {"tolerances": {"tip_diameter": 0.076}}}).drawing))
    assert any(n.startswith("WARNING: the fit's tolerances can close the 0.02 mm clearance") for n in
               tooling_model(closing).notes)
    assert not any(n.startswith("WARNING") for n in tooling_model(ts).notes)  # the sample's fit is sound


def test_an_overload_reads_true_and_a_rating_is_never_rounded_up():
    """A trial: a 14.967 kN rating read "tip force rating 15 kN" and "OVERLOADED: compaction force 15 kN is
    1 x the rated 15 kN".  The rating is rounded down, and the overload has the digits to read true."""
    from tabletcad.tooling.drawing import rating_notes

    rated = 14.967
    r = dict(rated_force_kN=rated, allowed_pressure_MPa=300.0, tip_projected_area_mm2=rated / 0.3,
             allowed_pressure_source="x", compaction_force_kN=15.0, utilisation=15.0 / rated, overloaded=True)
    first, over = rating_notes(r)
    assert first.startswith("tip force rating 14.96 kN = 300 MPa x")
    assert over == "OVERLOADED: compaction force 15 kN is 1.002 x the rated 14.96 kN"
    # a force that rounds onto the rating: more digits, until the force reads above it
    r.update(rated_force_kN=14.96012, compaction_force_kN=14.9604, utilisation=14.9604 / 14.96012)
    first, over = rating_notes(r)
    assert over == "OVERLOADED: compaction force 14.9604 kN is 1.00002 x the rated 14.9601 kN"
    assert first.startswith("tip force rating 14.9601 kN")
    r.update(overloaded=False, compaction_force_kN=14.0, utilisation=14.0 / 14.96012)
    assert rating_notes(r)[0].startswith("tip force rating 14.96 kN")  # (.4g had read 14.96 here too)
    r.update(rated_force_kN=9.99996)
    assert rating_notes(r)[0].startswith("tip force rating 9.999 kN")  # (.4g: "10")
    fe = {"allowed_force_kN": 20.998, "tips": {"upper": {"allowed_force_kN": 20.998}}, "yield_MPa": 1450.0,
          "safety_factor": 1.5, "yield_source": "y"}
    assert rating_notes({"fe": fe})[0].startswith("tip force rating 20.99 kN (FE punch analysis: upper 20.99 kN;")
    # one float step: a force 1 ulp above its rating reads above it (15 digits had read "30 kN is 1 x the rated
    # 30 kN"), and a rating a product's last bit under a round value is that value ("14.99" had been printed)
    from tabletcad.tooling.rating import overload_texts, rating_text

    assert overload_texts(30.000000000000004, 30.0) == ("30.000000000000004", "30", "1.0000000000000002")
    assert (rating_text(14.999999999999998), rating_text(99.99999999999999), rating_text(14.967)) == ("15", "100", "14.96")


def _outline_crossing(outline, direction_deg: float) -> float:
    """How far from the axis the plan outline crosses the ray across ``direction_deg`` on the section's
    positive side (section_view's ``n = (-sin, cos)``): the outline's edges sampled 0.0005 mm apart, the
    sign change of the cross product interpolated."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.GCPnts import GCPnts_UniformAbscissa

    from tabletcad.cad._occ import explore

    th = math.radians(direction_deg)
    n = np.array([-math.sin(th), math.cos(th)])
    best = []
    for e in explore(outline, "Edge"):
        c = BRepAdaptor_Curve(e)
        u = GCPnts_UniformAbscissa(c, 0.0005)
        pts = np.array([[c.Value(u.Parameter(i)).X(), c.Value(u.Parameter(i)).Y()] for i in range(1, u.NbPoints() + 1)])
        side = pts @ np.array([-n[1], n[0]])
        along = pts @ n
        for i in np.nonzero(np.sign(side[:-1]) != np.sign(side[1:]))[0]:
            t = side[i] / (side[i] - side[i + 1])
            best.append(along[i] + t * (along[i + 1] - along[i]))
    return max(best)


@pytest.mark.parametrize("direction", [90.0, 0.0])
def test_detail_b_looks_where_the_section_meets_the_band(direction):
    """A rounded triangle (a trial: tri_eud.toml): section A-A at y = 0 ends 4.667 mm out, where half the
    outline's 10.34 mm length had put detail B on a bare band line, its "land 0.080" hanging off the
    geometry, and the score's dimension line 0.5 mm off the section.  Now the detail is centred where the
    section meets the band (the outline's own crossing), showing the land and the band; the score
    dimension stands off that edge."""
    d = Design.from_dict({"tablet": dict(family="rounded_triangle", side=14.0, corner_radius=2.5, band=2.5, cup_depth=0.8,
                                         land=0.08),
                          "tooling": dict(clearance_mm=0.03, tip_length_mm=6.0,
                                          score=[dict(kind="bisect", depth_mm=0.3, direction_deg=direction)])})
    ts = make_tooling(d.build(), d.tooling_spec, check=False, interference_check=False)
    fr = ts.frame
    edge = _outline_crossing(fr.outline, direction)
    if direction == 90.0:
        assert edge == pytest.approx(4.6667, abs=1e-3) and fr.length / 2 > edge + 0.4  # the trial's numbers
    dr = drawing_model(ts)
    (land,) = [x for x in dr.dims if x.text.startswith("land")]
    ox, oy = dr.origins["detail B 10:1"]
    assert land.p2 == (ox, oy) and land.p1[0] == pytest.approx(ox - 0.8)
    # the detail shows the band's top corner at its centre: the land runs in from it, the band down from it
    pts = np.vstack(dr.views["detail B 10:1"]["visible"])
    near = lambda x, y: np.min(np.hypot(pts[:, 0] - x, pts[:, 1] - y))  # noqa: E731
    assert near(0.0, 0.0) < 0.05 and near(-0.8, 0.0) < 0.05 and near(0.0, -3.0) < 0.05
    sec = dr.views["section A-A"]["visible"]
    assert max(float(p[:, 0].max()) for p in sec) == pytest.approx(edge, abs=2e-3)
    (score,) = [x for x in dr.dims if x.text.startswith("score")]
    assert score.offset == pytest.approx(2.0 + edge, abs=2e-3)


def _die_bore_lines(view: dict, origin: tuple[float, float] = (0.0, 0.0)) -> dict:
    """The vertical hidden lines of a die's front view: ``{x (mm, 3 decimals): (lowest, highest z)}``."""
    out: dict = {}
    for p in view["hidden"]:
        p = np.asarray(p) + np.asarray(origin)
        if np.ptp(p[:, 0]) < 1e-6 and np.ptp(p[:, 1]) > 1e-3:
            x = round(float(p[0, 0]), 3)
            lo, hi = out.get(x, (np.inf, -np.inf))
            out[x] = (min(lo, float(p[:, 1].min())), max(hi, float(p[:, 1].max())))
    return out


@pytest.mark.parametrize("which", ["tsm_b_round", "capsule tips"])
def test_the_die_elevation_shows_the_bore_through_it_dashed(drawn, capsule, which, tmp_path):
    """The die's front elevation does not cut the bore: both of its walls are hidden lines the die's full
    height (the bore's cylinder and an oval's end arcs are outlines, not edges: a trial's die showed only
    the round bore's seam on one side, and an oval's bore not at all), and the DXF has them on HIDDEN."""
    import ezdxf

    from tabletcad.tooling.drawing import tips_model

    ts = drawn[0] if which == "tsm_b_round" else capsule
    dr = tooling_model(ts) if which == "tsm_b_round" else tips_model(ts)
    die = ts.report["die"]
    half = 5.0 if which == "tsm_b_round" else 7.0  # Ø10 bore; the 14 x 6 capsule's ends
    bores = _die_bore_lines(dr.views["die"])
    assert sorted(bores) == [-half, half], bores
    for lo, hi in bores.values():
        assert lo == pytest.approx(die["bottom_z_mm"], abs=1e-6) and hi == pytest.approx(die["top_z_mm"], abs=1e-6)
    # no hidden line lies on a visible one (the bore's ends at the die's faces are drawn once, solid)
    for p in dr.views["die"]["hidden"]:
        assert not (np.ptp(np.asarray(p)[:, 1]) < 1e-6 and abs(p[0, 1] - die["top_z_mm"]) < 1e-6)
    out = tmp_path / "tooling.dxf"
    from tabletcad.tooling.drawing import _write_dxf

    _write_dxf(dr, out)
    ox, oy = dr.origins["die"]
    hidden = [np.array([v[:2] for v in e.get_points()]) for e in ezdxf.readfile(out).modelspace().query("LWPOLYLINE")
              if e.dxf.layer == "HIDDEN"]
    assert sorted(_die_bore_lines({"hidden": hidden}, (-ox, -oy))) == [-half, half]


def _segment_meets_box(p, q, box) -> bool:
    """Whether the segment ``p``-``q`` meets (or touches) the box ``(x0, y0, x1, y1)``: Liang-Barsky."""
    t0, t1 = 0.0, 1.0
    d = (q[0] - p[0], q[1] - p[1])
    for k, lo, hi in ((0, box[0], box[2]), (1, box[1], box[3])):
        for a, b in ((-d[k], p[k] - lo), (d[k], hi - p[k])):
            if a == 0.0:
                if b < 0.0:
                    return False
            elif a < 0.0:
                t0 = max(t0, b / a)
            else:
                t1 = min(t1, b / a)
    return t0 <= t1


@pytest.fixture(scope="module", params=["tsm_b_round", "eu_d_oval", "capsule", "concave_round_bisect",
                                        "shallow_convex_round"])
def sample_sheets(request):
    """Each tooling sample's two sheets, as its build draws them: the tablet's and the tooling's (the TSM B
    round's and the capsule's tool sets are the ``drawn`` and ``capsule`` fixtures', built alike)."""
    from tabletcad.tooling.drawing import tips_model

    p = SAMPLE.parent / f"{request.param}.toml"
    shared = {SAMPLE.stem: lambda: request.getfixturevalue("drawn")[0], "capsule": lambda: request.getfixturevalue("capsule")}
    with __import__("warnings").catch_warnings():
        __import__("warnings").simplefilter("ignore")  # (the samples' fit and land warnings)
        ts = shared[request.param]() if request.param in shared else make_tooling(
            load_design(p), Design.from_toml(p).tooling_spec, check=False, interference_check=False)
        return request.param, [drawing_model(ts), tooling_model(ts) if ts.spec.body is not None else tips_model(ts)]


def test_no_dimension_text_meets_a_dimension_line_or_another_text(sample_sheets):
    """On every sample's sheets, every dimension's text box (the renderer's extent of the text, in sheet mm)
    meets no dimension line with its arrows (the arrows' own outlines), no extension line or leader and no other
    text (a trial: a band's text over the cup dimension's extension lines, a T's over its own, a tip's over
    its arrows)."""
    import matplotlib.pyplot as plt

    from tabletcad.tooling.drawing import _dim_geometry

    name, drawings = sample_sheets
    for dr in drawings:
        for paper in ("A4", "A3", "A2"):  # the sheet the build writes: the smallest at 1:1 or larger
            fig = sheet_figure(dr, paper)
            if dr.scale >= 1.0 or paper == "A2":
                break
            plt.close(fig)
        try:
            fig.canvas.draw()
            renderer = fig.canvas.get_renderer()
            ax = fig.axes[0]
            to_data = ax.transData.inverted()

            def box(t):
                bb = t.get_window_extent(renderer)
                (x0, y0), (x1, y1) = to_data.transform([(bb.x0, bb.y0), (bb.x1, bb.y1)])
                return min(x0, x1), min(y0, y1), max(x0, x1), max(y0, y1)

            dim_texts = {d.text for d in dr.dims}
            texts = [(t.get_text(), box(t)) for t in list(ax.texts) + list(fig.texts) if t.get_text()]
            lines = [np.array(e, float) for d in dr.dims for e in _dim_geometry(d)[2]]  # extension lines
            lines += [np.asarray(s, float) for c in ax.collections if c.get_gid() == "dimension lines"
                      for s in c.get_segments()]  # (and the leaders to texts beyond an arrow)
            arrows = [t.arrow_patch for t in ax.texts if getattr(t, "arrow_patch", None) is not None]
            assert len(arrows) == len(dr.dims)
            lines += [to_data.transform(poly) for a in arrows  # (the arrows' outlines: drawn in display units)
                      for poly in a.get_transform().transform_path(a.get_path()).to_polygons(closed_only=False)]
            assert sorted(t for t, _ in texts if t in dim_texts) == sorted(d.text for d in dr.dims)
            for k, (text, b) in enumerate(texts):
                if text not in dim_texts:
                    continue
                for p in lines:
                    for q0, q1 in zip(p[:-1], p[1:]):
                        assert not _segment_meets_box(q0, q1, b), (name, dr.title, text, q0, q1)
                for j, (other, c) in enumerate(texts):
                    if j != k:
                        assert not (b[0] <= c[2] and c[0] <= b[2] and b[1] <= c[3] and c[1] <= b[3]), \
                            (name, dr.title, text, other)
        finally:
            plt.close(fig)
