"""Complete TSM/EU punches and dies: the standards file, the spec checks, the solids and their closed forms."""

import math
import re
from pathlib import Path

import pytest

from tabletcad.errors import DesignError
from tabletcad.tooling.spec import parse_tooling
from tabletcad.tooling.standards import load_standards, resolve_body

ROOT = Path(__file__).resolve().parents[1]
SAMPLES = ROOT / "samples" / "tooling"
INCH = 25.4

#: a complete EU B set: every [tooling.punch] key the standards file cannot supply
EU_B = dict(standard="EU", type="B", die_height_mm=22.0, tip_length_mm=8.0, lower_tip_length_mm=25.4,
            clearance_mm=0.025,
            punch=dict(head_diameter_mm=25.0, head_flat_diameter_mm=12.0, head_rim_mm=3.0, dome_radius_mm=30.0,
                       neck_diameter_mm=13.0, neck_length_mm=10.0, tip_straight_mm=4.0, tip_relief_mm=0.1))


def _with(**kw):
    t = {**EU_B, "punch": dict(EU_B["punch"])}
    for k, v in kw.items():
        if k.startswith("punch_"):
            t["punch"][k[6:]] = v
        elif v is None:
            t.pop(k, None)
        else:
            t[k] = v
    return t


# ----------------------------------------------------------------------------- the data file
def test_every_standard_number_cites_a_listed_public_source():
    data = load_standards()
    sources = data["sources"]
    assert all(re.match(r"https://", s["url"]) and s["says"] for s in sources.values())
    n = 0
    for std in ("TSM", "EU"):
        for kind in ("B", "D"):
            for key, entry in data[std][kind].items():
                if isinstance(entry, dict):
                    assert entry["source"] and set(entry["source"]) <= set(sources), (std, kind, key)
                    n += 1
    assert n == 22


def test_standard_values_agree_with_the_published_inch_figures_and_differences():
    d = load_standards()
    assert d["TSM"]["D"]["barrel_diameter_mm"]["value"] == pytest.approx(1.0 * INCH)
    assert d["TSM"]["B"]["die_outer_diameter_mm"]["value"] == pytest.approx(1.1875 * INCH, abs=0.005)
    assert d["TSM"]["D"]["die_outer_diameter_mm"]["value"] == pytest.approx(1.5 * INCH, abs=0.005)
    # EU punches are 0.010 in longer than TSM (kos_differences); TSM is then 5.25 in
    assert d["EU"]["B"]["overall_length_mm"]["value"] - d["TSM"]["B"]["overall_length_mm"]["value"] == \
        pytest.approx(0.010 * INCH, abs=0.005)
    assert d["TSM"]["B"]["overall_length_mm"]["value"] == pytest.approx(5.25 * INCH, abs=0.005)
    assert (d["TSM"]["B"]["head"], d["EU"]["B"]["head"]) == ("angled", "domed")


@pytest.mark.parametrize("size, shaped, kind", [(16.0, False, "B"), (16.005, False, "B"), (16.02, False, "D"),
                                                 (16.02, True, "B"), (19.0, True, "B"), (19.000001, True, "B"),
                                                 (19.02, True, "D"), (25.0, False, "D"), (25.0, True, "D")])
def test_the_placeholder_die_is_the_smallest_tsm_type_the_standard_lets_take_the_tablet(size, shaped, kind):
    """Tips only, no die size given: the TSM B blank for round tablets up to 16 mm and shaped ones up to 19 mm
    (the standards file's ``max_round_tablet_mm``/``max_shaped_tablet_mm``; an 18 mm capsule had been given
    a D die), D up to 25 mm; larger is refused, naming the die's outer diameter.  A PDE surface's micrometres
    beyond the nominal size keep its die (a 19 mm rounded rectangle measured 19.00000088 mm and got a D)."""
    from tabletcad.tooling.spec import standard_die_size

    d = load_standards()["TSM"]
    od, h, name = standard_die_size(size, shaped=shaped)
    assert name == kind
    assert od == d[kind]["die_outer_diameter_mm"]["value"] and h == {"B": 22.22, "D": 23.81}[kind]
    with pytest.raises(DesignError, match=r"die_outer_diameter_mm = \(not given\).*TSM 'D' die takes, 25 mm"):
        standard_die_size(25.02, shaped=shaped)


# ----------------------------------------------------------------------------- spec checks (no geometry)
def test_standard_fills_barrel_length_angle_and_die_and_records_sources():
    s = parse_tooling(EU_B)
    b = s.body
    assert (b.barrel_diameter_mm, b.overall_length_mm, b.inside_head_angle_deg) == (19.0, 133.60, 30.0)
    assert s.die_outer_diameter_mm == 30.16 and s.die_height_mm == 22.0 and s.lower_tip == 25.4
    assert set(b.sources) >= {"barrel_diameter_mm", "overall_length_mm", "inside_head_angle_deg", "die_outer_diameter_mm"}
    assert "head_diameter_mm" not in b.sources  # the user's
    # the overall length is tip + barrel + neck + head exactly
    assert 8.0 + b.barrel_length_mm(8.0) + b.neck_length_mm + b.head_height_mm == pytest.approx(133.60, abs=1e-12)


def test_user_defined_set_needs_every_dimension():
    with pytest.raises(DesignError) as e:
        parse_tooling(_with(standard="custom", type=None))
    assert "tooling.punch.head" in str(e.value) or "overall_length_mm" in str(e.value)


@pytest.mark.parametrize("table, parameter", [
    (_with(standard="JIS"), "tooling.standard"),
    (_with(type="E"), "tooling.type"),
    (_with(type=None), "tooling.type"),
    (_with(tip_length_mm=120.0), "tooling.tip_length_mm"),          # a tip longer than the punch
    (_with(lower_tip_length_mm=130.0), "tooling.lower_tip_length_mm"),
    (_with(punch_head_diameter_mm=None), "tooling.punch.head_diameter_mm"),
    (_with(die_height_mm=None), "tooling.die_height_mm"),
    (_with(punch_neck_diameter_mm=20.0), "tooling.punch.neck_diameter_mm"),
    (_with(punch_dome_radius_mm=10.0), "tooling.punch.dome_radius_mm"),
    (_with(punch_tip_straight_mm=9.0), "tooling.punch.tip_straight_mm"),
    (_with(punch_key=True), "tooling.punch.key_width_mm"),
    (_with(punch_bogus=1), "tooling.punch.bogus"),
    (_with(punch_key=True, punch_key_width_mm=25.0, punch_key_length_mm=20.0, punch_key_height_mm=2.0,
           punch_key_offset_mm=10.0), "tooling.punch.key_width_mm"),  # wider than the barrel: was built
    (_with(tip_length_mm=1e300), "tooling.tip_length_mm"),  # reached OCC as a zero vector (exit 1)
    (_with(gap_mm=1e308), "tooling.gap_mm"),  # an assembly of volume 0
    (_with(die_height_mm=1e7), "tooling.die_height_mm"),
])
def test_bad_complete_tooling_is_one_design_error(table, parameter):
    if "punch" in table:
        table["punch"] = {k: v for k, v in table["punch"].items() if v is not None}
    with pytest.raises(DesignError) as e:
        parse_tooling(table)
    assert str(e.value).startswith(parameter) and "\n" not in str(e.value)


def test_tip_longer_than_the_punch_names_the_room_left():
    # (the EU set's punch table less its dome radius, which a TSM angled head now refuses)
    tsm = {k: v for k, v in EU_B["punch"].items() if k != "dome_radius_mm"}
    b = resolve_body("TSM", "B", dict(tsm, head_top_angle_deg=10.0), 8.0, 19.0)
    room = b.overall_length_mm - b.neck_length_mm - b.head_height_mm
    with pytest.raises(DesignError, match=f"must be < {room:.4g} mm"):
        resolve_body("TSM", "B", dict(tsm, head_top_angle_deg=10.0), room + 0.01, 19.0)


@pytest.mark.parametrize("standard, extra, key, value", [
    ("TSM", {"head_top_angle_deg": 10.0}, "dome_radius_mm", "40 mm"),   # EU_B's dome radius, set to 40 here
    ("EU", {"head_top_angle_deg": 10.0}, "head_top_angle_deg", "10 deg"),
    ("custom", {"head": "angled", "head_top_angle_deg": 10.0, "overall_length_mm": 133.35, "barrel_diameter_mm": 19.0,
                "inside_head_angle_deg": 37.0}, "dome_radius_mm", "40 mm"),
])
def test_a_head_value_the_head_style_does_not_use_is_refused(standard, extra, key, value):
    """A trial: dome_radius_mm = 40 on a TSM (angled) head and head_top_angle_deg on an EU (domed) one were
    ignored in silence; now the one-line error names the key and the head style."""
    head = "domed" if standard == "EU" else "angled"
    other = "angled" if head == "domed" else "domed"
    table = dict(EU_B, standard=standard, punch=dict(EU_B["punch"], dome_radius_mm=40.0, **extra))
    if standard == "custom":
        table.pop("type")
        table["die_outer_diameter_mm"] = 30.16
    with pytest.raises(DesignError) as e:
        parse_tooling(table)
    takes = "head_top_angle_deg" if head == "angled" else "dome_radius_mm"
    assert str(e.value) == (f"tooling.punch.{key} = {value} is not allowed: not used by the {standard} punches' "
                            f"{head} head, which takes {takes}: remove it, or set head = '{other}'")
    # the same table without the other style's key is taken
    parse_tooling(dict(table, punch={k: v for k, v in table["punch"].items() if k != key}))


# ----------------------------------------------------------------------------- solids (OCC)
@pytest.fixture(scope="module")
def eu_b():
    pytest.importorskip("OCP")
    pytest.importorskip("manifold3d")
    from tabletcad.families.thesis import shallow_convex_round
    from tabletcad.tooling.toolset import make_tooling

    return make_tooling(shallow_convex_round(), parse_tooling(EU_B), check=False)


@pytest.mark.cad
def test_complete_parts_are_valid_single_solids_and_enclose_the_tablet(eu_b):
    from tabletcad.cad.solid import check_solid

    for name, shape in eu_b.parts.items():
        check_solid(shape, name)
    r = eu_b.report
    assert r["interference_mm3"] == pytest.approx(0.0, abs=1e-9)
    assert 0.0 < r["max_gap_mm"] <= 0.025
    # punch to die: the clearance asked for (the tips follow the bore, which clears the PDE band's bulge)
    assert r["die"]["bore_enlarged_by_band_bulge_mm"] > 0.0
    f = r["interference"]  # to the B-rep's own precision (a cup rim is a Boolean's section edge)
    assert f["punch_die_clearance_mm"] == pytest.approx(0.025, abs=f["punch_die_clearance_tolerance_mm"] + 1e-7)
    assert f["punch_die_clearance_tolerance_mm"] < 1e-4


@pytest.mark.cad
@pytest.mark.parametrize("which", ["upper_punch", "lower_punch"])
def test_punch_volume_is_tip_minus_relief_plus_closed_form_body(eu_b, which):
    info = eu_b.report[which]
    body = info["body"]
    expected = info["tip_volume_mm3"] - body["relief_volume_mm3"] + body["body_volume_closed_form_mm3"]
    assert body["volume_mm3"] == pytest.approx(expected, rel=1e-7)
    # relief: the ring between the tip's circle (the 10 mm outline inset by the clearance less the bore's
    # growth) and that circle 0.1 mm smaller, over tip - straight
    tip = body["tip_length_mm"]
    r = 5.0 - info["tip_inset_from_outline_mm"]
    assert info["tip_inset_from_outline_mm"] == pytest.approx(0.025 - eu_b.report["die"]["bore_enlarged_by_band_bulge_mm"],
                                                             abs=1e-15)
    ring = math.pi * (r ** 2 - (r - 0.1) ** 2) * (tip - 4.0)
    assert body["relief_volume_mm3"] == pytest.approx(ring, rel=1e-9)


@pytest.mark.cad
def test_punch_extents_are_the_overall_length_and_the_barrel(eu_b):
    from tabletcad.cad.solid import mass_properties  # noqa: F401 (OCC loaded)
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib

    z_lo, z_hi = eu_b.frame.band_z
    for name, band_edge, sign in (("upper_punch", z_hi, 1.0), ("lower_punch", z_lo, -1.0)):
        box = Bnd_Box()
        BRepBndLib.AddOptimal_s(eu_b.parts[name], box, False, False)
        x0, y0, zmin, x1, y1, zmax = box.Get()
        head_flat, tip_end = (zmax, zmin) if sign > 0 else (zmin, zmax)
        # the overall length runs from the tip's own end: on this tablet without a land the tip's wall meets
        # the cup above the band's edge (the punch had been that much short of 133.60 mm)
        assert sign * (head_flat - tip_end) == pytest.approx(133.60, abs=1e-6)
        assert eu_b.report[name]["tip_edge_z_mm"] == pytest.approx(tip_end, abs=1e-6)
        assert 1e-3 < sign * (tip_end - band_edge) < 0.02
        assert x1 - x0 == pytest.approx(25.0, abs=1e-6)  # the head is the widest part
        assert eu_b.report[name]["body"]["head_flat_z_mm"] == pytest.approx(head_flat, abs=1e-6)


@pytest.mark.cad
def test_barrel_smaller_than_the_tablet_and_oversize_tablets_are_design_errors():
    pytest.importorskip("OCP")
    from tabletcad.families.thesis import shallow_convex_round
    from tabletcad.tooling.toolset import make_tooling

    t = shallow_convex_round()
    custom = _with(standard="custom", type=None, die_outer_diameter_mm=30.0,
                   punch_overall_length_mm=133.0, punch_barrel_diameter_mm=9.0, punch_inside_head_angle_deg=30.0,
                   punch_neck_diameter_mm=7.0, punch_head="domed")
    with pytest.raises(DesignError, match=r"barrel_diameter_mm = 9 mm .* circumscribed diameter 9.955 mm"):
        make_tooling(t, parse_tooling(custom), check=False, interference_check=False)
    # at ejection the lower tip edge is at the die's top face: the tip must outreach the 22 mm die (20 mm
    # clears the die's bottom face at the closed position, 17 mm below the tip edge, and is still refused)
    for short in (12.0, 20.0, 22.0):
        with pytest.raises(DesignError, match=rf"lower_tip_length_mm = {short:g} mm .* must be > 22 mm, the die's height"):
            make_tooling(t, parse_tooling(_with(lower_tip_length_mm=short)), check=False, interference_check=False)


@pytest.mark.cad
@pytest.mark.parametrize("extra", [
    '[tooling]\nstandard = "JIS"\ntype = "B"\ndie_height_mm = 22.0\n',                       # unknown standard
    '[tooling]\nstandard = "EU"\ntype = "B"\ndie_height_mm = 22.0\ntip_length_mm = 130.0\n'  # tip longer than the punch
    '[tooling.punch]\nhead_diameter_mm = 25.0\nhead_flat_diameter_mm = 12.0\nhead_rim_mm = 3.0\ndome_radius_mm = 30.0\n'
    'neck_diameter_mm = 13.0\nneck_length_mm = 10.0\ntip_straight_mm = 4.0\ntip_relief_mm = 0.1\n',
    '[tooling]\nstandard = "TSM"\ntype = "B"\n',                                               # required inputs missing
])
def test_cli_bad_complete_tooling_exits_2_with_one_line_and_writes_nothing(tmp_path, capsys, extra):
    pytest.importorskip("OCP")
    from tabletcad.cli import main

    d = tmp_path / "bad.toml"
    d.write_text('[tablet]\nfamily = "thesis.shallow_convex_round"\ndiameter = 10.0\nthickness = 3.0\nband = 2.0\n\n' + extra)
    out = tmp_path / "out"
    assert main(["build", str(d), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("error: tooling")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.toml"]


def test_a_given_die_height_is_kept_whatever_its_value():
    """22.22 mm given was taken for the default and replaced by the die table's height (23.81 mm for a
    D die): the spec now keeps None for "not given"."""
    from tabletcad.tooling.spec import ToolingSpec

    assert parse_tooling({"die_height_mm": 22.22}).die_height_mm == 22.22
    assert parse_tooling({}).die_height_mm is None and ToolingSpec().die_height_mm is None


@pytest.mark.cad
def test_a_tip_relief_leaving_no_tip_names_tip_relief_mm():
    """``tip_relief_mm = 6`` on a 10 mm tablet stopped with "offsetting the outline by -6.025 mm failed"
    after the tablet was built; the relief is now refused by name before any tooling geometry, and a
    relief that leaves a tip passes."""
    pytest.importorskip("OCP")
    from dataclasses import replace

    from tabletcad.families.thesis import shallow_convex_round
    from tabletcad.tooling.outline import tablet_frame
    from tabletcad.tooling.toolset import _check_relief, make_tooling

    tablet = shallow_convex_round()
    with pytest.raises(DesignError) as e:
        make_tooling(tablet, parse_tooling(_with(punch_tip_relief_mm=6.0)), check=False)
    assert str(e.value).startswith("tooling.punch.tip_relief_mm = 6 mm is not allowed: must leave a relieved tip")
    frame = tablet_frame(tablet)
    spec = parse_tooling(EU_B)
    R = 0.5 * frame.width  # the round's radius: the tip's outline is R - clearance
    for relief, ok in ((R - 0.025 - 0.05, True), (R - 0.025 + 1e-3, False), (R, False)):
        s = replace(spec, body=replace(spec.body, tip_relief_mm=relief))
        if ok:
            _check_relief(frame, s)
        else:
            with pytest.raises(DesignError, match="tip_relief_mm"):
                _check_relief(frame, s)


@pytest.mark.cad
def test_cupped_tips_without_a_land_warn_of_a_sharp_edge():
    """The EU D oval sample's tablet has no land: its tips' land is -0.02 mm (0 - the clearance),
    which was reported without a word; a cupped tablet with a land wider than the clearance is quiet,
    and so are a flat face (it meets the tip's wall square) and a designed edge (bevels, FFRE's radius)."""
    pytest.importorskip("OCP")
    import warnings

    from tabletcad.pipeline.design import Design
    from tabletcad.tooling.outline import tablet_frame
    from tabletcad.tooling.toolset import _warn_sharp_edge

    def warned(tablet: dict, clearance: float) -> list[str]:
        frame = tablet_frame(Design.from_dict({"tablet": tablet}).build())
        with warnings.catch_warnings(record=True) as w:
            warnings.simplefilter("always")
            _warn_sharp_edge(frame, clearance)
        return [str(x.message) for x in w]

    oval = dict(family="oval", length=14.0, width=8.0, end_radius=3.0, band=3.0, cup_depth=0.9)
    (msg,) = warned(oval, 0.02)
    assert "no land (0 mm tablet land - 0.02 mm clearance = -0.02 mm)" in msg and "sharp edge" in msg
    landed = dict(family="concave_round", diameter=10.0, band=2.8, cup_depth=0.9, land=0.08)
    assert warned(landed, 0.02) == [] and len(warned(landed, 0.1)) == 1
    flat = dict(family="flat_face_round", diameter=10.0, thickness=3.0)
    assert warned(flat, 0.02) == []
    assert len(warned(landed, 0.08)) == 1  # a land equal to the clearance leaves the tip none
    for edge in (dict(family="concave_bevel", diameter=10.0, band=2.5, cup_depth=0.8, bevel_angle=30.0, bevel_width=0.5),
                 dict(family="ffbe", diameter=10.0, thickness=3.5, bevel_angle=30.0, bevel_width=0.5),
                 dict(family="ffre", diameter=10.0, thickness=3.5, edge_radius=0.8)):
        assert warned(edge, 0.02) == [], edge["family"]
